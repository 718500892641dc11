//! The `candela` command's reusable parts, shared with the Python package: image output
//! and display transforms, film part files and their exact merge.

pub mod merge;
pub mod output;
pub mod part;
pub mod tonemap;

/// A user-facing failure: printed as one line, exit code 2.
#[derive(Debug)]
pub struct UserError(pub String);

impl<E: std::fmt::Display> From<E> for UserError {
    fn from(e: E) -> Self {
        UserError(e.to_string())
    }
}
