//! The camera (pinhole, thin lens or orthographic), validated, and the pixel filter.

use crate::camera::Camera;
use crate::desc::{
    ApertureDesc, ApertureSizeDesc, CameraDesc, FocusDesc, LensDesc, PixelFilterDesc, SceneDesc,
    Span,
};
use crate::filter::PixelFilter;

use super::validate::{check_finite, err, BuildError};

pub(super) fn build_camera(desc: &SceneDesc) -> Result<Camera, BuildError> {
    let c = &desc.camera;
    check_finite(
        &c.span,
        "camera",
        &[c.position.to_array(), c.look_at.to_array(), c.up.to_array()].concat(),
    )?;
    let view = c.look_at - c.position;
    if view.length_squared() == 0.0 {
        return err(&c.span, "camera position and look_at coincide");
    }
    if view
        .normalize()
        .cross(c.up.normalize_or_zero())
        .length_squared()
        < 1e-10
    {
        return err(
            &c.span,
            "camera up vector is parallel to the view direction (or zero)",
        );
    }
    if let Some(f) = c.focal_length_mm {
        if !(f.is_finite() && f > 0.0) {
            return err(&c.span, format!("focal length {f} mm must be positive"));
        }
    }
    if !(c.sensor_mm.is_finite() && c.sensor_mm.min_element() > 0.0) {
        return err(
            &c.span,
            format!("sensor size {} mm must be positive", c.sensor_mm),
        );
    }
    if !(c.fov_y_deg > 0.0 && c.fov_y_deg < 180.0) {
        return err(
            &c.span,
            format!(
                "fov {} must lie strictly between 0 and 180 degrees",
                c.fov_y_deg
            ),
        );
    }
    if let Some(h) = c.ortho_height {
        if !(h.is_finite() && h > 0.0) {
            return err(
                &c.span,
                format!("orthographic view height {h} must be positive"),
            );
        }
        if c.lens.is_some() {
            return err(&c.span, "an orthographic camera takes no lens");
        }
    }
    if let Some(lens) = &c.lens {
        validate_lens(c, lens)?;
    }
    Ok(Camera::new(c, desc.render.width, desc.render.height))
}

fn validate_lens(c: &CameraDesc, lens: &LensDesc) -> Result<(), BuildError> {
    let forward = (c.look_at - c.position).normalize();
    let focus = match lens.focus {
        FocusDesc::LookAt => (c.look_at - c.position).length(),
        FocusDesc::Distance(d) => d,
        FocusDesc::Point(p) => {
            check_finite(&c.span, "focus point", &p.to_array())?;
            (p - c.position).dot(forward)
        }
    };
    if !(focus.is_finite() && focus > 0.0) {
        return err(
            &c.span,
            format!("focus distance {focus} must be positive (in front of the camera)"),
        );
    }
    match lens.size {
        ApertureSizeDesc::Radius(r) if !(r.is_finite() && r >= 0.0) => {
            return err(&c.span, format!("aperture radius {r} must not be negative"));
        }
        ApertureSizeDesc::FNumber(n) if !(n.is_finite() && n > 0.0) => {
            return err(&c.span, format!("f-number {n} must be positive"));
        }
        _ => {}
    }
    match &lens.aperture {
        ApertureDesc::Disc => {}
        ApertureDesc::Polygon {
            blades,
            rotation_deg,
        } => {
            if !(3..=64).contains(blades) {
                return err(
                    &c.span,
                    format!("aperture blades {blades} must be between 3 and 64"),
                );
            }
            check_finite(&c.span, "aperture rotation", &[*rotation_deg])?;
        }
        ApertureDesc::Image {
            width,
            height,
            luminance,
        } => {
            if *width == 0 || *height == 0 {
                return err(&c.span, "aperture image is empty");
            }
            if luminance.len() != *width as usize * *height as usize {
                return err(
                    &c.span,
                    format!(
                        "aperture image has {} values for {width}x{height} pixels",
                        luminance.len()
                    ),
                );
            }
            if luminance.iter().any(|v| !v.is_finite() || *v < 0.0) {
                return err(&c.span, "aperture image has a negative or non-finite value");
            }
            if !luminance.iter().any(|&v| v > 0.0) {
                return err(&c.span, "aperture image is black: no light passes");
            }
        }
    }
    Ok(())
}

pub(super) fn build_filter(f: PixelFilterDesc) -> Result<PixelFilter, BuildError> {
    let (radius, stddev) = match f {
        PixelFilterDesc::Box => (1.0, 1.0),
        PixelFilterDesc::Tent { radius } => (radius, 1.0),
        PixelFilterDesc::Gaussian { stddev, radius } => (radius, stddev),
    };
    if !(radius.is_finite() && radius > 0.0 && stddev.is_finite() && stddev > 0.0) {
        return err(
            &Span::code(),
            format!("pixel filter {f:?} needs a positive, finite radius and stddev"),
        );
    }
    Ok(PixelFilter::new(f))
}
