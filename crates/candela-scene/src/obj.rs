//! Wavefront OBJ meshes through `tobj`: polygons triangulated as fans, one index per
//! vertex (positions, normals and uvs deduplicated together), all objects and groups of
//! the file merged into one mesh. As a shape of a scene its materials (`mtllib`) are
//! ignored: the scene assigns one. Rendered alone ([`load_obj_parts`]), its faces are
//! split by material.

use std::fs::File;
use std::io::{self, BufRead, BufReader, Read};
use std::path::Path;

use candela_core::desc::MeshDesc;
use glam::{Vec2, Vec3};

use crate::MeshError;

/// Loads an OBJ file into one mesh.
pub fn load_obj(path: &Path) -> Result<MeshDesc, MeshError> {
    let file =
        File::open(path).map_err(|e| MeshError::new(path, None, format!("cannot open: {e}")))?;
    parse_obj(BufReader::new(file), path)
}

/// Parses OBJ text; `path` names the file in errors. `mtllib`s are not read.
pub fn parse_obj(reader: impl BufRead, path: &Path) -> Result<MeshDesc, MeshError> {
    let (models, _) = read_models(reader, path, |_| Err(tobj::LoadError::OpenFileFailed))?;
    merge(&models.iter().collect::<Vec<_>>(), path)
}

/// An OBJ file as parts of a scene: one mesh for each material its faces use (`None`:
/// faces under no `usemtl`), the materials of its `mtllib`s (read relative to the OBJ
/// file), and why they could not be read if they could not.
pub struct ObjParts {
    pub meshes: Vec<(Option<usize>, MeshDesc)>,
    pub materials: Vec<tobj::Material>,
    pub mtl_error: Option<String>,
}

/// Loads an OBJ file with its materials (see [`ObjParts`]).
pub fn load_obj_parts(path: &Path) -> Result<ObjParts, MeshError> {
    let file =
        File::open(path).map_err(|e| MeshError::new(path, None, format!("cannot open: {e}")))?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let (models, materials) = read_models(BufReader::new(file), path, |mtl| {
        tobj::load_mtl(dir.join(mtl))
    })?;
    let mut ids: Vec<Option<usize>> = models.iter().map(|m| m.mesh.material_id).collect();
    ids.sort_unstable();
    ids.dedup();
    let mut meshes = Vec::new();
    for id in ids {
        let group: Vec<&tobj::Model> = models
            .iter()
            .filter(|m| m.mesh.material_id == id && !m.mesh.indices.is_empty())
            .collect();
        if !group.is_empty() {
            meshes.push((id, merge(&group, path)?));
        }
    }
    if meshes.is_empty() {
        return Err(MeshError::new(path, None, "OBJ file has no faces"));
    }
    let (materials, mtl_error) = match materials {
        Ok(m) => (m, None),
        Err(e) => (Vec::new(), Some(e.to_string())),
    };
    Ok(ObjParts {
        meshes,
        materials,
        mtl_error,
    })
}

/// An OBJ file's models, and its materials or why they could not be read.
type Models = (
    Vec<tobj::Model>,
    Result<Vec<tobj::Material>, tobj::LoadError>,
);

/// The models of an OBJ file, polygons triangulated, and its materials as `mtl` loads
/// each `mtllib`.
fn read_models(
    reader: impl BufRead,
    path: &Path,
    mtl: impl Fn(&Path) -> tobj::MTLLoadResult,
) -> Result<Models, MeshError> {
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let mut reader = LineCounter::new(reader);
    tobj::load_obj_buf(&mut reader, &options, mtl).map_err(|e| {
        let line = line_local(&e).then(|| reader.line());
        MeshError::new(path, line, e.to_string())
    })
}

/// The models as one mesh. Normals and uvs survive only if every vertex of every model
/// has them.
fn merge(models: &[&tobj::Model], path: &Path) -> Result<MeshDesc, MeshError> {
    let all_normals = models
        .iter()
        .all(|m| m.mesh.normals.len() == m.mesh.positions.len());
    let all_uvs = models
        .iter()
        .all(|m| m.mesh.texcoords.len() / 2 == m.mesh.positions.len() / 3);
    let mut mesh = MeshDesc::default();
    for m in models {
        let m = &m.mesh;
        let base = mesh.positions.len() as u32;
        mesh.positions
            .extend(m.positions.chunks_exact(3).map(Vec3::from_slice));
        if all_normals {
            mesh.normals
                .extend(m.normals.chunks_exact(3).map(Vec3::from_slice));
        }
        if all_uvs {
            mesh.uvs
                .extend(m.texcoords.chunks_exact(2).map(Vec2::from_slice));
        }
        mesh.indices.extend(
            m.indices
                .chunks_exact(3)
                .map(|t| [t[0] + base, t[1] + base, t[2] + base]),
        );
    }
    if mesh.indices.is_empty() {
        return Err(MeshError::new(path, None, "OBJ file has no faces"));
    }
    Ok(mesh)
}

/// Whether `tobj` raises this error on the line it is reading (others come when an object
/// is finished, so the current line would mislead).
fn line_local(e: &tobj::LoadError) -> bool {
    use tobj::LoadError::*;
    matches!(
        e,
        UnrecognizedCharacter
            | PositionParseError
            | ScalingByZeroError
            | ColorParseError
            | NormalParseError
            | TexcoordParseError
            | FaceParseError
            | MaterialParseError
            | InvalidObjectName
    )
}

/// Counts the lines a `BufRead` has handed out, so that a parser error can name its line.
struct LineCounter<R> {
    inner: R,
    newlines: usize,
    mid_line: bool,
}

impl<R: BufRead> LineCounter<R> {
    fn new(inner: R) -> Self {
        LineCounter {
            inner,
            newlines: 0,
            mid_line: false,
        }
    }

    /// 1-based number of the line read last.
    fn line(&self) -> usize {
        self.newlines + usize::from(self.mid_line)
    }
}

impl<R: BufRead> Read for LineCounter<R> {
    fn read(&mut self, out: &mut [u8]) -> io::Result<usize> {
        let n = {
            let buf = self.fill_buf()?;
            let n = buf.len().min(out.len());
            out[..n].copy_from_slice(&buf[..n]);
            n
        };
        self.consume(n);
        Ok(n)
    }
}

impl<R: BufRead> BufRead for LineCounter<R> {
    fn fill_buf(&mut self) -> io::Result<&[u8]> {
        self.inner.fill_buf()
    }

    fn consume(&mut self, amt: usize) {
        // The buffer is still filled, so this returns it without reading.
        if let Ok(buf) = self.inner.fill_buf() {
            let taken = &buf[..amt.min(buf.len())];
            self.newlines += taken.iter().filter(|&&b| b == b'\n').count();
            if let Some(&last) = taken.last() {
                self.mid_line = last != b'\n';
            }
        }
        self.inner.consume(amt);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
