//! Candela's loaders: bytes in, [`SceneDesc`] out. All file I/O and format knowledge lives
//! here; errors carry the file, line and column they refer to.
//!
//! One module per format: [`toml`] reads Candela's own scene format (see
//! `docs/scene-format.md`), [`mitsuba`] a subset of Mitsuba 3's XML (see
//! `docs/mitsuba.md`), [`gltf`] glTF 2.0, [`obj`] and [`ply`] read triangle meshes. A new scene format
//! plugs in as a module and one arm of the match in [`load_scene`].
//!
//! ```
//! use std::path::Path;
//!
//! let text = r#"
//! [materials.white]
//! type = "diffuse"
//! albedo = 0.8
//!
//! [[shape]]
//! type = "sphere"
//! material = "white"
//! emission = 1
//! "#;
//! let desc = candela_scene::parse_toml_scene(text, Path::new("scene.toml")).unwrap();
//! assert_eq!(desc.shapes.len(), 1);
//! assert!(candela_core::build::build(&desc).is_ok());
//!
//! let err = candela_scene::parse_toml_scene("[camera]\nfvo = 3", Path::new("s.toml"));
//! assert!(err.unwrap_err().to_string().starts_with("s.toml:2:1: unknown field `fvo`"));
//! ```

use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use candela_core::desc::{MeshDesc, SceneDesc, Span};

pub mod envmap;
pub mod gltf;
pub mod image_texture;
pub mod limits;
mod mesh_scene;
pub mod obj;
pub mod ply;
mod ply_body;
pub mod toml;
pub mod vol;

pub use crate::toml::parse_toml_scene;

pub mod ies;
pub mod mitsuba;

/// How to load a scene: parameters and strictness (used by formats that have them).
#[derive(Clone, Debug, Default)]
pub struct LoadOptions {
    /// `name=value` parameters, e.g. Mitsuba's `$name` (`-D name=value` on the CLI); they
    /// take precedence over the file's own defaults.
    pub defines: Vec<(String, String)>,
    /// Warn about and skip what Candela does not support, instead of failing.
    pub lenient: bool,
    /// Which of a glTF file's scenes to load (default: its default scene, else the first).
    pub scene: Option<usize>,
}

/// A loaded scene and the warnings met on the way (already `file:line:col: …`).
#[derive(Clone, Debug)]
pub struct LoadedScene {
    pub desc: SceneDesc,
    pub warnings: Vec<String>,
}

/// A file that could not be loaded, with where and why. Displays as
/// `file:line:col: message`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LoadError {
    pub span: Span,
    pub message: String,
}

impl LoadError {
    /// An error at `span`.
    pub fn new(span: Span, message: impl Into<String>) -> LoadError {
        LoadError {
            span,
            message: message.into(),
        }
    }
}

impl fmt::Display for LoadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.span, self.message)
    }
}

impl std::error::Error for LoadError {}

/// A mesh file that could not be read: the file, the line where the parser knows it,
/// and why. Displays as `file:line: message` (or `file: message`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MeshError {
    pub file: PathBuf,
    pub line: Option<usize>,
    pub message: String,
}

impl MeshError {
    pub(crate) fn new(file: &Path, line: Option<usize>, message: impl Into<String>) -> MeshError {
        MeshError {
            file: file.to_path_buf(),
            line,
            message: message.into(),
        }
    }
}

impl fmt::Display for MeshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "{}:{line}: {}", self.file.display(), self.message),
            None => write!(f, "{}: {}", self.file.display(), self.message),
        }
    }
}

impl std::error::Error for MeshError {}

/// Loads a triangle mesh file, choosing the format by its extension (`.obj`, `.ply`).
pub fn load_mesh(path: &Path) -> Result<MeshDesc, MeshError> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "obj" => obj::load_obj(path),
        "ply" => ply::load_ply(path),
        _ => Err(MeshError::new(
            path,
            None,
            format!("unsupported mesh format \".{ext}\"; supported: .obj, .ply"),
        )),
    }
}

/// Loads a scene file, choosing the format by its extension, with default options and
/// warnings dropped; see [`load_scene_with`].
pub fn load_scene(path: &Path) -> Result<SceneDesc, LoadError> {
    load_scene_with(path, &LoadOptions::default()).map(|l| l.desc)
}

/// Loads a scene file (`.toml`, Mitsuba `.xml`, glTF `.gltf`/`.glb`, or a bare `.obj` or
/// `.ply` mesh, see the `mesh_scene` module), choosing the format by its extension.
pub fn load_scene_with(path: &Path, options: &LoadOptions) -> Result<LoadedScene, LoadError> {
    let file_span = || Span::new(path.display().to_string(), 1, 1);
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "toml" => {
            let text = std::fs::read_to_string(path)
                .map_err(|e| LoadError::new(file_span(), format!("cannot read scene file: {e}")))?;
            let (desc, warnings) = crate::toml::parse_toml_scene_with_warnings(&text, path)?;
            Ok(LoadedScene { desc, warnings })
        }
        "xml" => mitsuba::load_mitsuba(path, options),
        "gltf" | "glb" => crate::gltf::load_gltf(path, options),
        "obj" | "ply" => mesh_scene::load_mesh_scene(path, &ext),
        "" => Err(LoadError::new(
            file_span(),
            "scene file has no extension; expected .toml, .xml, .gltf, .glb, .obj or .ply",
        )),
        other => Err(LoadError::new(
            file_span(),
            format!(
                "unsupported scene format \".{other}\"; supported: .toml, .xml, .gltf, .glb, \
                 .obj, .ply"
            ),
        )),
    }
}

/// `text` with control characters (a quoted newline, say) written as escapes, so that
/// a message stays on one line.
pub(crate) fn escape_control(text: &str) -> String {
    text.chars()
        .map(|c| {
            if c.is_control() {
                c.escape_default().to_string()
            } else {
                c.to_string()
            }
        })
        .collect()
}

/// A text being parsed and the name it is reported under: turns byte offsets into
/// 1-based `line:col` spans (columns count characters, not bytes).
#[derive(Clone, Debug)]
pub(crate) struct Source<'a> {
    pub file: Arc<str>,
    pub text: &'a str,
}

impl<'a> Source<'a> {
    pub fn new(file: &Path, text: &'a str) -> Source<'a> {
        Source {
            file: file.display().to_string().into(),
            text,
        }
    }

    /// The span of a byte offset into the text (clamped to its end).
    pub fn span(&self, offset: usize) -> Span {
        let mut offset = offset.min(self.text.len());
        while !self.text.is_char_boundary(offset) {
            offset -= 1;
        }
        let before = &self.text[..offset];
        let line = before.matches('\n').count() + 1;
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        let col = before[line_start..].chars().count() + 1;
        Span::new(self.file.clone(), line as u32, col as u32)
    }

    pub fn error(&self, offset: usize, message: impl Into<String>) -> LoadError {
        LoadError::new(self.span(offset), message)
    }

    /// Converts a `toml` error, keeping its location.
    pub fn toml_error(&self, e: &::toml::de::Error) -> LoadError {
        let offset = e.span().map_or(0, |s| s.start);
        self.error(offset, e.message().trim().replace('\n', " "))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offsets_become_one_based_lines_and_columns() {
        let text = "a = 1\nbé = 2\n\nc";
        let src = Source::new(Path::new("s.toml"), text);
        assert_eq!(src.span(0), Span::new("s.toml", 1, 1));
        assert_eq!(src.span(4), Span::new("s.toml", 1, 5));
        assert_eq!(src.span(6), Span::new("s.toml", 2, 1));
        // 'é' is two bytes but one column.
        assert_eq!(src.span(10), Span::new("s.toml", 2, 4));
        assert_eq!(src.span(text.len() - 1), Span::new("s.toml", 4, 1));
        assert_eq!(src.span(10_000), Span::new("s.toml", 4, 2));
    }

    #[test]
    fn other_extensions_are_named_in_the_error() {
        for ext in ["fbx", "usd"] {
            let name = format!("scene.{ext}");
            let e = load_scene(Path::new(&name)).unwrap_err();
            assert_eq!(e.span, Span::new(name.as_str(), 1, 1));
            assert!(e.message.contains(&format!(".{ext}")), "{e}");
        }
    }

    #[test]
    fn a_missing_scene_file_is_an_error() {
        let e = load_scene(Path::new("/nonexistent/scene.toml")).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("/nonexistent/scene.toml:1:1: cannot read"),
            "{e}"
        );
    }
}
