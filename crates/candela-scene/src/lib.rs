//! Candela's loaders: bytes in, [`SceneDesc`] out. All file I/O and format knowledge lives
//! here; errors carry the file, line and column they refer to.

use std::fmt;
use std::path::Path;

use candela_core::desc::{SceneDesc, Span};

pub mod ies;

/// A file that could not be loaded, with where and why. Displays as
/// `file:line:col: message`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LoadError {
    pub span: Span,
    pub message: String,
}

impl fmt::Display for LoadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.span, self.message)
    }
}

impl std::error::Error for LoadError {}

/// Loads a scene file, choosing the format by its extension.
pub fn load_scene(path: &Path) -> Result<SceneDesc, LoadError> {
    Err(LoadError {
        span: Span::new(path.display().to_string(), 0, 0),
        message: "not implemented yet".into(),
    })
}
