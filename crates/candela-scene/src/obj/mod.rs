//! Wavefront OBJ. As a shape of a scene, a file is one mesh, read as it streams
//! ([`reader`]: polygons as fans, every object and group merged, materials ignored: the
//! scene assigns one). Rendered alone ([`load_obj_parts`], through `tobj`), its faces are
//! split by material and its `mtllib`s read.

mod parts;
mod reader;

use std::fs::File;
use std::io::{BufRead, BufReader};
use std::path::Path;

use candela_core::desc::MeshDesc;

use crate::MeshError;

pub use parts::{load_obj_parts, ObjParts};

/// Loads an OBJ file into one mesh.
pub fn load_obj(path: &Path) -> Result<MeshDesc, MeshError> {
    let file =
        File::open(path).map_err(|e| MeshError::new(path, None, format!("cannot open: {e}")))?;
    parse_obj(BufReader::with_capacity(1 << 16, file), path)
}

/// Parses OBJ text into one mesh; `path` names the file in errors.
pub fn parse_obj(reader: impl BufRead, path: &Path) -> Result<MeshDesc, MeshError> {
    reader::read_mesh(reader, path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn parse(text: &str) -> Result<MeshDesc, MeshError> {
        parse_obj(text.as_bytes(), Path::new("m.obj"))
    }

    #[test]
    fn quads_are_triangulated_and_objects_merged() {
        let mesh = parse(
            "o a\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n\
             o b\nv 0 0 1\nv 1 0 1\nv 1 1 1\nf 5 6 7\n",
        )
        .unwrap();
        assert_eq!(mesh.indices.len(), 3);
        assert_eq!(mesh.positions.len(), 7);
        assert!(mesh.normals.is_empty() && mesh.uvs.is_empty());
        // Every triangle indexes positions of its own object.
        let [a, b, c] = mesh.indices[2];
        for i in [a, b, c] {
            assert_eq!(mesh.positions[i as usize].z, 1.0);
        }
        // The quad's fan covers all four corners.
        let mut used: Vec<u32> = mesh.indices[..2].iter().flatten().copied().collect();
        used.sort();
        used.dedup();
        assert_eq!(used.len(), 4);
    }

    #[test]
    fn normals_and_uvs_are_carried_through() {
        let mesh = parse(
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvt 0 0\nvt 1 0\nvt 0 1\n\
             f 1/1/1 2/2/1 3/3/1\n",
        )
        .unwrap();
        assert_eq!(mesh.normals, vec![Vec3::Z; 3]);
        assert_eq!(mesh.uvs.len(), 3);
        for (p, uv) in mesh.positions.iter().zip(&mesh.uvs) {
            assert_eq!(p.truncate(), *uv, "vt follows v in this file");
        }
    }

    #[test]
    fn partial_normals_are_dropped() {
        let mesh = parse(
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvn 0 0 1\n\
             f 1//1 2//1 3//1\nf 2 4 3\n",
        )
        .unwrap();
        assert_eq!(mesh.indices.len(), 2);
        assert!(mesh.normals.is_empty());
    }

    #[test]
    fn a_file_without_faces_is_an_error() {
        let e = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\n").unwrap_err();
        assert_eq!(e.to_string(), "m.obj: OBJ file has no faces");
    }

    #[test]
    fn parse_errors_name_the_line() {
        let e = parse("v 0 0 0\nv 1 0 0\nv 0 x 0\nf 1 2 3\n").unwrap_err();
        assert_eq!(e.line, Some(3), "{e}");
        assert!(e.to_string().starts_with("m.obj:3: "), "{e}");
        // Also on a last line without a newline.
        let e = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x").unwrap_err();
        assert_eq!(e.line, Some(4), "{e}");
    }

    #[test]
    fn out_of_range_faces_are_errors() {
        assert!(parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n").is_err());
    }
}
