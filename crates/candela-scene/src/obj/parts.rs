//! An OBJ file rendered alone, through `tobj`: its faces split by material into one
//! mesh each (polygons triangulated as fans, positions, normals and uvs deduplicated
//! together), with the materials of its `mtllib`s.

use std::fs::File;
use std::io::{self, BufRead, BufReader, Read};
use std::path::Path;

use candela_core::desc::MeshDesc;
use glam::{Vec2, Vec3};

use crate::MeshError;

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
