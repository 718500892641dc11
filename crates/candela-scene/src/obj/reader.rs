//! A streaming reader of one OBJ mesh: each line parsed as it is read, straight into the
//! mesh's arrays, so that loading holds little beyond the mesh itself (through `tobj`,
//! an 8M-triangle file peaked at 1450 MB in loading: its line strings, per-object arrays,
//! the vertex-deduplication map and the merged copy).
//!
//! OBJ indexes positions, texture coordinates and normals separately; a mesh has one
//! index a vertex. While every face corner's `vt` and `vn` are absent or equal to its
//! `v` (files of positions only, and files written with aligned attributes), a corner
//! is its position index and no map is needed. The first corner that breaks this
//! switches to a map from (v, vt, vn) to vertex, as `tobj`'s single-index mode.
//!
//! Polygons are fans from their first corner; `o`, `g`, `s`, `usemtl`, `mtllib`, `l`,
//! `p` and unknown keywords are skipped. Indices may be negative (counted back from the
//! last element read) and must name an element already read. `v` takes x y z, then an
//! optional w (which divides them) or an r g b colour (ignored). Normals and uvs are kept
//! only if every face corner has them.

use std::collections::HashMap;
use std::io::BufRead;
use std::path::Path;

use candela_core::desc::MeshDesc;
use glam::{Vec2, Vec3};

use crate::MeshError;

/// Reads an OBJ mesh; `path` names the file in errors.
pub fn read_mesh(mut reader: impl BufRead, path: &Path) -> Result<MeshDesc, MeshError> {
    let mut parser = Parser::default();
    let mut line = Vec::new();
    let mut number = 0;
    loop {
        line.clear();
        let read = reader
            .read_until(b'\n', &mut line)
            .map_err(|e| MeshError::new(path, Some(number + 1), format!("cannot read: {e}")))?;
        if read == 0 {
            break;
        }
        number += 1;
        parser
            .line(&line)
            .map_err(|m| MeshError::new(path, Some(number), m))?;
    }
    parser.finish().map_err(|m| MeshError::new(path, None, m))
}

/// A face corner's indices, from 0; [`NONE`] where absent.
type Corner = [u32; 3];
const NONE: u32 = u32::MAX;

#[derive(Default)]
struct Parser {
    positions: Vec<Vec3>,
    texcoords: Vec<Vec2>,
    normals: Vec<Vec3>,
    /// Triangles of vertex ids: position indices until [`Parser::split`] is made.
    indices: Vec<[u32; 3]>,
    /// Whether a corner so far lacked a `vt`, a `vn`.
    missing_vt: bool,
    missing_vn: bool,
    /// Once some corner's `vt` or `vn` differs from its `v`: the vertex of each
    /// (v, vt, vn) met, and those triples in vertex order.
    split: Option<Split>,
    /// The current face's corners and their vertex ids (reused).
    face: Vec<Corner>,
    ids: Vec<u32>,
}

struct Split {
    ids: HashMap<Corner, u32>,
    vertices: Vec<Corner>,
}

impl Parser {
    fn line(&mut self, line: &[u8]) -> Result<(), String> {
        let line = std::str::from_utf8(line).map_err(|_| "not UTF-8 text".to_string())?;
        let mut words = line.split_ascii_whitespace();
        match words.next() {
            Some("v") => {
                let [x, y, z] = floats(&mut words, "v")?;
                let p = Vec3::new(x, y, z);
                let p = match (words.next(), words.next(), words.next(), words.next()) {
                    (None, ..) => p,
                    (Some(w), None, ..) => match number(w, "v")? {
                        0.0 => return Err("v: a w of 0 scales by zero".into()),
                        w => p / w,
                    },
                    (Some(r), Some(g), Some(b), None) => {
                        for c in [r, g, b] {
                            number(c, "v")?;
                        }
                        p
                    }
                    _ => return Err("v takes x y z, then an optional w or r g b".into()),
                };
                self.positions.push(p);
            }
            Some("vt") => {
                let [u, v] = floats(&mut words, "vt")?;
                self.texcoords.push(Vec2::new(u, v));
            }
            Some("vn") => {
                let [x, y, z] = floats(&mut words, "vn")?;
                self.normals.push(Vec3::new(x, y, z));
            }
            Some("f") => self.face(words)?,
            _ => {}
        }
        Ok(())
    }

    fn face<'a>(&mut self, words: impl Iterator<Item = &'a str>) -> Result<(), String> {
        let mut face = std::mem::take(&mut self.face);
        face.clear();
        for word in words {
            face.push(self.corner(word)?);
        }
        if face.len() < 3 {
            return Err(format!(
                "f: a face needs 3 vertices, this has {}",
                face.len()
            ));
        }
        let mut ids = std::mem::take(&mut self.ids);
        ids.clear();
        for &corner in &face {
            ids.push(self.vertex(corner));
        }
        for k in 1..ids.len() - 1 {
            self.indices.push([ids[0], ids[k], ids[k + 1]]);
        }
        self.ids = ids;
        self.face = face;
        Ok(())
    }

    /// `v`, `v/vt`, `v//vn` or `v/vt/vn`, each checked against the elements read.
    fn corner(&self, word: &str) -> Result<Corner, String> {
        let mut parts = word.split('/');
        let mut corner = [NONE; 3];
        let counts = [
            self.positions.len(),
            self.texcoords.len(),
            self.normals.len(),
        ];
        for (k, what) in ["vertex", "texture coordinate", "normal"]
            .iter()
            .enumerate()
        {
            match parts.next() {
                Some("") if k > 0 => {}
                Some(s) => corner[k] = index(s, counts[k], what)?,
                None if k > 0 => {}
                None => unreachable!("split yields at least one part"),
            }
        }
        if parts.next().is_some() {
            return Err(format!("f: \"{word}\" has more than v/vt/vn"));
        }
        Ok(corner)
    }

    /// The vertex id of a corner, made if new.
    fn vertex(&mut self, corner: Corner) -> u32 {
        let [v, vt, vn] = corner;
        self.missing_vt |= vt == NONE;
        self.missing_vn |= vn == NONE;
        let aligned = (vt == NONE || vt == v) && (vn == NONE || vn == v);
        if self.split.is_none() && aligned {
            return v;
        }
        let split = self.split.get_or_insert_with(|| {
            // The corners so far were their positions (with vt, vn absent or equal):
            // every position becomes the vertex (v, v, v), keeping their ids.
            let vertices: Vec<Corner> = (0..self.positions.len() as u32).map(|v| [v; 3]).collect();
            let ids = vertices.iter().map(|&c| (c, c[0])).collect();
            Split { ids, vertices }
        });
        // A corner without vt (or vn) shares a vertex with any of its position's: that
        // attribute is dropped in the end.
        let key = [
            v,
            if vt == NONE { v } else { vt },
            if vn == NONE { v } else { vn },
        ];
        let next = split.vertices.len() as u32;
        let id = *split.ids.entry(key).or_insert(next);
        if id == next {
            split.vertices.push(key);
        }
        id
    }

    fn finish(self) -> Result<MeshDesc, String> {
        if self.indices.is_empty() {
            return Err("OBJ file has no faces".into());
        }
        let keep_uvs = !self.missing_vt;
        let keep_normals = !self.missing_vn;
        let mut mesh = MeshDesc {
            indices: self.indices,
            ..MeshDesc::default()
        };
        match self.split {
            None => {
                if keep_uvs {
                    mesh.uvs = (0..self.positions.len() as u32)
                        .map(|i| attribute(&self.texcoords, i))
                        .collect();
                }
                if keep_normals {
                    mesh.normals = (0..self.positions.len() as u32)
                        .map(|i| attribute(&self.normals, i))
                        .collect();
                }
                mesh.positions = self.positions;
            }
            Some(split) => {
                drop(split.ids);
                // Vertices in the order faces first use them, without those of positions
                // only the faces before the split used alone.
                let mut renumbered = vec![NONE; split.vertices.len()];
                let mut v = Vec::new();
                for i in mesh.indices.as_flattened_mut() {
                    let new = &mut renumbered[*i as usize];
                    if *new == NONE {
                        *new = v.len() as u32;
                        v.push(split.vertices[*i as usize]);
                    }
                    *i = *new;
                }
                drop(renumbered);
                mesh.positions = v.iter().map(|c| self.positions[c[0] as usize]).collect();
                if keep_uvs {
                    mesh.uvs = v.iter().map(|c| attribute(&self.texcoords, c[1])).collect();
                }
                if keep_normals {
                    mesh.normals = v.iter().map(|c| attribute(&self.normals, c[2])).collect();
                }
            }
        }
        Ok(mesh)
    }
}

/// Element `i` of `list`, or zero where a vertex no face uses has none.
fn attribute<T: Copy + Default>(list: &[T], i: u32) -> T {
    list.get(i as usize).copied().unwrap_or_default()
}

/// The next `N` words as numbers; `what` names the keyword in errors.
fn floats<'a, const N: usize>(
    words: &mut impl Iterator<Item = &'a str>,
    what: &str,
) -> Result<[f32; N], String> {
    let mut out = [0.0; N];
    for x in &mut out {
        let word = words
            .next()
            .ok_or_else(|| format!("{what} needs {N} numbers"))?;
        *x = number(word, what)?;
    }
    Ok(out)
}

fn number(word: &str, what: &str) -> Result<f32, String> {
    word.parse()
        .map_err(|_| format!("{what}: \"{word}\" is not a number"))
}

/// An index from 1 (or from -1 back from the last) into `count` elements read so far, as
/// an index from 0.
fn index(word: &str, count: usize, what: &str) -> Result<u32, String> {
    let i: i64 = word
        .parse()
        .map_err(|_| format!("f: \"{word}\" is not a {what} index"))?;
    let at = if i < 0 { count as i64 + i } else { i - 1 };
    if i == 0 || at < 0 || at >= count as i64 {
        return Err(format!(
            "f: {what} index {word} is out of range ({count} read so far)"
        ));
    }
    Ok(at as u32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use candela_core::sampler::Pcg32;

    fn read(text: &str) -> Result<MeshDesc, MeshError> {
        read_mesh(text.as_bytes(), Path::new("t.obj"))
    }

    /// Each triangle as its corners' (position, uv, normal), the uv and normal zero where
    /// the mesh has none.
    fn corners(m: &MeshDesc) -> Vec<[(Vec3, Vec2, Vec3); 3]> {
        m.indices
            .iter()
            .map(|t| {
                t.map(|i| {
                    let i = i as usize;
                    (
                        m.positions[i],
                        m.uvs.get(i).copied().unwrap_or_default(),
                        m.normals.get(i).copied().unwrap_or_default(),
                    )
                })
            })
            .collect()
    }

    /// `tobj`'s reading of the same text (single index, triangulated, models merged).
    fn tobj_corners(text: &str) -> Vec<[(Vec3, Vec2, Vec3); 3]> {
        let options = tobj::LoadOptions {
            triangulate: true,
            single_index: true,
            ..Default::default()
        };
        let (models, _) = tobj::load_obj_buf(&mut text.as_bytes(), &options, |_| {
            Err(tobj::LoadError::OpenFileFailed)
        })
        .unwrap();
        let mut out = Vec::new();
        for m in &models {
            let m = &m.mesh;
            let at = |list: &[f32], n: usize, i: usize| -> [f32; 3] {
                let mut v = [0.0; 3];
                if list.len() >= n * (i + 1) {
                    v[..n].copy_from_slice(&list[n * i..n * (i + 1)]);
                }
                v
            };
            for t in m.indices.chunks_exact(3) {
                out.push([0, 1, 2].map(|k| {
                    let i = t[k] as usize;
                    let uv = at(&m.texcoords, 2, i);
                    (
                        Vec3::from(at(&m.positions, 3, i)),
                        Vec2::new(uv[0], uv[1]),
                        Vec3::from(at(&m.normals, 3, i)),
                    )
                }));
            }
        }
        out
    }

    /// Random files: polygons of 3–6 corners, indices positive or negative, uvs and
    /// normals on every corner or on none, their indices equal to the position's (the
    /// aligned path) or independent (the split path, in some files only after the first
    /// faces): every triangle's corners are `tobj`'s, value for value.
    #[test]
    fn random_files_read_as_tobj_reads_them() {
        let mut rng = Pcg32::new(40, 7);
        let (mut aligned, mut split) = (0, 0);
        for file in 0..300 {
            let n = 4 + rng.next_u32() as usize % 40;
            let (with_vt, with_vn) = (file % 3 != 0, file % 4 != 1);
            let independent = file % 2 == 0;
            let aligned_faces = if independent {
                rng.next_u32() % 5
            } else {
                u32::MAX
            };
            let mut text = String::from("o first\n");
            let r = |rng: &mut Pcg32| (rng.uniform_f32() * 8.0 - 4.0).to_string();
            for _ in 0..n {
                text += &format!("v {} {} {}\n", r(&mut rng), r(&mut rng), r(&mut rng));
                text += &format!("vt {} {}\n", r(&mut rng), r(&mut rng));
                text += &format!("vn {} {} {}\n", r(&mut rng), r(&mut rng), r(&mut rng));
            }
            for face in 0..30 {
                if face == 10 {
                    text += "g second\nusemtl none\ns 1\n";
                }
                let corners = 3 + rng.next_u32() as usize % 4;
                text += "f";
                for _ in 0..corners {
                    let v = rng.next_u32() as usize % n;
                    let other = |rng: &mut Pcg32| {
                        if face < aligned_faces as usize {
                            v
                        } else {
                            rng.next_u32() as usize % n
                        }
                    };
                    let (vt, vn) = (other(&mut rng), other(&mut rng));
                    let write = |i: usize, rng: &mut Pcg32| {
                        if rng.next_u32().is_multiple_of(3) {
                            format!("-{}", n - i)
                        } else {
                            format!("{}", i + 1)
                        }
                    };
                    text += &format!(" {}", write(v, &mut rng));
                    match (with_vt, with_vn) {
                        (true, true) => {
                            text += &format!("/{}/{}", write(vt, &mut rng), write(vn, &mut rng))
                        }
                        (true, false) => text += &format!("/{}", write(vt, &mut rng)),
                        (false, true) => text += &format!("//{}", write(vn, &mut rng)),
                        (false, false) => {}
                    }
                }
                text += "\n";
            }
            let mesh = read(&text).unwrap();
            assert_eq!(mesh.uvs.is_empty(), !with_vt, "file {file}");
            assert_eq!(mesh.normals.is_empty(), !with_vn, "file {file}");
            assert_eq!(corners(&mesh), tobj_corners(&text), "file {file}:\n{text}");
            if independent && (with_vt || with_vn) {
                split += 1;
            } else {
                aligned += 1;
            }
        }
        assert!(
            aligned > 100 && split > 100,
            "{aligned} aligned, {split} split"
        );
    }

    #[test]
    fn w_divides_colours_are_skipped_and_bad_vertices_are_errors() {
        let m = read("v 2 4 6 2\nv 1 0 0 0.5 0.5 0.5\nv 0 1 0\nf 1 2 3\n").unwrap();
        assert_eq!(m.positions[0], Vec3::new(1.0, 2.0, 3.0));
        assert_eq!(m.positions[1], Vec3::X);
        for bad in [
            "v 1 2",
            "v 1 2 3 0",
            "v 1 2 3 4 5",
            "v 1 2 3 4 5 6 7",
            "vt 1",
            "vn 1 x 0",
        ] {
            let e = read(&format!("v 0 0 0\n{bad}\n")).unwrap_err();
            assert_eq!(e.line, Some(2), "{bad}: {e}");
        }
    }

    #[test]
    fn faces_name_only_elements_already_read() {
        for (face, line) in [
            ("f 1 2 4", 4),
            ("f 0 1 2", 4),
            ("f -4 1 2", 4),
            ("f 1/1 2 3", 4),
            ("f 1//2 2 3", 4),
            ("f 1 2", 4),
            ("f 1/1/1/1 2 3", 4),
        ] {
            let e = read(&format!("v 0 0 0\nv 1 0 0\nv 0 1 0\n{face}\nv 1 1 1\n")).unwrap_err();
            assert_eq!(e.line, Some(line), "{face}: {e}");
            assert!(
                e.to_string().starts_with(&format!("t.obj:{line}: f")),
                "{e}"
            );
        }
        let m = read("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\r\n").unwrap();
        assert_eq!(m.indices, [[0, 1, 2]]);
    }
}
