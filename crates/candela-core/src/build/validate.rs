//! The build's error type and the checks that every part of the build shares: finite
//! numbers, non-negative colours, well-formed images, a resolution within bounds.

use std::fmt;

use glam::Vec3;

use crate::desc::{ImageDesc, Span};

/// A description that cannot be built, with the place that caused it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BuildError {
    pub span: Span,
    pub message: String,
}

impl fmt::Display for BuildError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.span, self.message)
    }
}

impl std::error::Error for BuildError {}

pub(super) fn err<T>(span: &Span, message: impl Into<String>) -> Result<T, BuildError> {
    Err(BuildError {
        span: span.clone(),
        message: message.into(),
    })
}

pub(super) fn check_finite(span: &Span, what: &str, values: &[f32]) -> Result<(), BuildError> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        err(span, format!("{what} must be finite"))
    }
}

pub(super) fn check_color(span: &Span, what: &str, c: Vec3) -> Result<(), BuildError> {
    check_finite(span, what, &c.to_array())?;
    if c.min_element() < 0.0 {
        return err(span, format!("{what} must not be negative"));
    }
    Ok(())
}

/// The most pixels an image may have: 2²⁶ (8192 × 8192), whose film takes 4.8 GB. A
/// resolution is two numbers in a small file, so without a cap a scene of a hundred bytes
/// could ask for terabytes.
pub const MAX_PIXELS: u64 = 1 << 26;

/// Checks a resolution: not empty, at most [`MAX_PIXELS`].
pub fn check_resolution(width: u32, height: u32) -> Result<(), String> {
    if width == 0 || height == 0 {
        return Err(format!("resolution {width}x{height} is empty"));
    }
    if width as u64 * height as u64 > MAX_PIXELS {
        return Err(format!(
            "resolution {width}x{height} has more than {MAX_PIXELS} pixels (8192x8192)"
        ));
    }
    Ok(())
}

pub(super) fn check_image(span: &Span, what: &str, img: &ImageDesc) -> Result<(), BuildError> {
    if img.width == 0 || img.height == 0 {
        return err(
            span,
            format!("{what} is empty ({}x{})", img.width, img.height),
        );
    }
    if img.pixels.len() != img.width as usize * img.height as usize {
        return err(
            span,
            format!(
                "{what} has {} pixels for {}x{}",
                img.pixels.len(),
                img.width,
                img.height
            ),
        );
    }
    if img
        .pixels
        .iter()
        .any(|p| !p.is_finite() || p.min_element() < 0.0)
    {
        return err(span, format!("{what} has a negative or non-finite pixel"));
    }
    Ok(())
}
