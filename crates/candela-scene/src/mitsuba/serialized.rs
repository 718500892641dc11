//! Mitsuba's binary `serialized` mesh format (its `serialized` shape), version 3 or 4.
//!
//! A file holds one or more meshes, then a dictionary of where each starts. Each mesh is
//! a little-endian header, the identifier `0x041C` and the version (two `u16`s), then a
//! zlib stream of:
//! - `u32` flags: vertex normals `0x0001`, texture coordinates `0x0002`, vertex colours
//!   `0x0008`, a face-normals hint `0x0010` (which Mitsuba 3.9.1 ignores, as Candela
//!   does), single `0x1000` or double `0x2000` precision;
//! - version 4 only: the mesh's name, zero-terminated;
//! - `u64` vertex count, `u64` triangle count;
//! - positions, then normals, texture coordinates and colours where flagged (3, 3, 2 and
//!   3 numbers a vertex, `f32` or `f64`);
//! - three indices a triangle, `u32` (or `u64` past 2³² vertices).
//!
//! The dictionary is each mesh's byte offset (`u64` in version 4, `u32` in version 3),
//! then the mesh count as a `u32` ending the file.

use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::Path;

use candela_core::desc::MeshDesc;
use flate2::read::ZlibDecoder;
use glam::{Vec2, Vec3};

use crate::limits::allocation_budget;
use crate::MeshError;

const FORMAT_ID: u16 = 0x041C;
const HAS_NORMALS: u32 = 0x0001;
const HAS_UVS: u32 = 0x0002;
const HAS_COLORS: u32 = 0x0008;
const SINGLE: u32 = 0x1000;
const DOUBLE: u32 = 0x2000;

/// Bytes decompressed at a time into the mesh's arrays: the only buffer beside them.
const CHUNK: usize = 1 << 16;

/// Reads mesh number `index` (from 0) of a serialized file. Vertex colours are read and
/// dropped, as Mitsuba keeps them for a `mesh_attribute` texture only.
///
/// Only the file's first header, its dictionary and the mesh's own compressed bytes are
/// read (a file of many meshes is not read once a shape), and the decompressed numbers go
/// straight into the mesh's vectors.
pub fn load_serialized(path: &Path, index: u32) -> Result<MeshDesc, MeshError> {
    let err = |m: String| MeshError::new(path, None, m);
    let cannot_read = |e: std::io::Error| err(format!("cannot read: {e}"));
    let mut file = File::open(path).map_err(cannot_read)?;
    let len = file.metadata().map_err(cannot_read)?.len();
    let version = header(&mut file, len, 0).map_err(err)?;
    let start = mesh_offset(&mut file, len, version, index).map_err(err)?;
    let version_here = header(&mut file, len, start).map_err(err)?;
    if version_here != version {
        return Err(err(format!(
            "mesh {index} is version {version_here}, the file's first is {version}"
        )));
    }
    let budget = allocation_budget(usize::try_from(len).unwrap_or(usize::MAX));
    file.seek(SeekFrom::Start(start + 4)).map_err(cannot_read)?;
    let mut z = ZlibDecoder::new(BufReader::new(file)).take(budget);
    read_mesh(&mut z, version, budget).map_err(|m| err(format!("mesh {index}: {m}")))
}

/// `len` bytes of the file from `at`, or why not (`what` names them for the message).
fn read_at(file: &mut File, at: u64, len: usize, what: &str) -> Result<Vec<u8>, String> {
    let mut bytes = vec![0u8; len];
    file.seek(SeekFrom::Start(at))
        .and_then(|_| file.read_exact(&mut bytes))
        .map_err(|e| format!("cannot read {what} at byte {at}: {e}"))?;
    Ok(bytes)
}

/// The version of the mesh header at `at` in a file of `len` bytes.
fn header(file: &mut File, len: u64, at: u64) -> Result<u16, String> {
    if at + 4 > len {
        return Err(format!("the file ends at byte {len} before a mesh header"));
    }
    let h = read_at(file, at, 4, "a mesh header")?;
    let (id, version) = (
        u16::from_le_bytes([h[0], h[1]]),
        u16::from_le_bytes([h[2], h[3]]),
    );
    if id != FORMAT_ID {
        return Err(format!(
            "not a Mitsuba serialized mesh at byte {at} (identifier {id:#06x}, not {FORMAT_ID:#06x})"
        ));
    }
    match version {
        3 | 4 => Ok(version),
        v => Err(format!(
            "serialized version {v} is not supported (3 or 4 are)"
        )),
    }
}

/// Where mesh `index` starts, from the dictionary at the end of a file of `len` bytes.
fn mesh_offset(file: &mut File, len: u64, version: u16, index: u32) -> Result<u64, String> {
    const CUT: &str = "the mesh dictionary at the end of the file is cut short";
    let count_at = len.checked_sub(4).ok_or(CUT)?;
    let count = u32::from_le_bytes(
        read_at(file, count_at, 4, "the mesh count")?
            .try_into()
            .expect("4"),
    );
    if index >= count {
        return Err(format!(
            "shape_index {index} is out of range: the file holds {count} mesh(es)"
        ));
    }
    let width: u64 = if version == 4 { 8 } else { 4 };
    let table = count_at
        .checked_sub(width * count as u64)
        .ok_or("the mesh dictionary is longer than the file")?;
    let entry = read_at(
        file,
        table + width * index as u64,
        width as usize,
        "the mesh dictionary",
    )?;
    let offset = if width == 8 {
        u64::from_le_bytes(entry.try_into().expect("8"))
    } else {
        u32::from_le_bytes(entry.try_into().expect("4")) as u64
    };
    if offset < table {
        Ok(offset)
    } else {
        Err(format!("mesh {index}'s offset {offset} lies past its data"))
    }
}

fn read_mesh(z: &mut impl Read, version: u16, budget: u64) -> Result<MeshDesc, String> {
    let flags = u32::from_le_bytes(read_array(z)?);
    let double = match (flags & SINGLE != 0, flags & DOUBLE != 0) {
        (true, false) => false,
        (false, true) => true,
        _ => {
            return Err(format!(
                "flags {flags:#x} name neither single nor double precision"
            ))
        }
    };
    if version == 4 {
        // The name, which Candela does not use.
        let mut byte = [0u8];
        loop {
            z.read_exact(&mut byte).map_err(truncated)?;
            if byte[0] == 0 {
                break;
            }
        }
    }
    let vertices = u64::from_le_bytes(read_array(z)?);
    let triangles = u64::from_le_bytes(read_array(z)?);
    let real = if double { 8 } else { 4 };
    let per_vertex = real
        * (3 + 3 * (flags & HAS_NORMALS != 0) as u64
            + 2 * (flags & HAS_UVS != 0) as u64
            + 3 * (flags & HAS_COLORS != 0) as u64);
    let wide = vertices > u32::MAX as u64;
    let per_triangle = 3 * if wide { 8 } else { 4 };
    let need = (vertices as u128) * (per_vertex as u128 + 12 * 3)
        + (triangles as u128) * (per_triangle as u128 + 12);
    if need > budget as u128 {
        return Err(format!(
            "{vertices} vertices and {triangles} triangles do not fit what the file's size allows"
        ));
    }
    let (vertices, triangles) = (vertices as usize, triangles as usize);
    let mut reals = Reals { z, double };
    let positions = reals.read(vertices, |a: &[f32; 3]| Vec3::from_array(*a))?;
    let normals = match flags & HAS_NORMALS {
        0 => Vec::new(),
        _ => reals.read(vertices, |a: &[f32; 3]| Vec3::from_array(*a))?,
    };
    let uvs = match flags & HAS_UVS {
        0 => Vec::new(),
        _ => reals.read(vertices, |a: &[f32; 2]| Vec2::from_array(*a))?,
    };
    if flags & HAS_COLORS != 0 {
        reals.read(vertices, |_: &[f32; 3]| ())?;
    }
    let width = per_triangle as usize / 3;
    let index = |c: &[u8]| -> Result<u32, String> {
        let i = if wide {
            u64::from_le_bytes(c.try_into().expect("8"))
        } else {
            u32::from_le_bytes(c.try_into().expect("4")) as u64
        };
        match u32::try_from(i) {
            Ok(i) if (i as usize) < vertices => Ok(i),
            _ => Err(format!("index {i} is out of range ({vertices} vertices)")),
        }
    };
    let mut indices = Vec::with_capacity(triangles);
    for_chunks(reals.z, triangles, per_triangle as usize, |t| {
        indices.push([
            index(&t[..width])?,
            index(&t[width..2 * width])?,
            index(&t[2 * width..])?,
        ]);
        Ok(())
    })?;
    if positions.iter().any(|p| !p.is_finite()) {
        return Err("a vertex position is not a finite number".into());
    }
    Ok(MeshDesc {
        positions,
        normals,
        uvs,
        indices,
        ..Default::default()
    })
}

/// Reads arrays of `f32` or `f64` numbers (stored as `f32`) from the zlib stream.
struct Reals<'a, R: Read> {
    z: &'a mut R,
    double: bool,
}

impl<R: Read> Reals<'_, R> {
    /// `count` items of `N` numbers each, each made by `make` from its numbers.
    fn read<const N: usize, T>(
        &mut self,
        count: usize,
        make: impl Fn(&[f32; N]) -> T,
    ) -> Result<Vec<T>, String> {
        let real = if self.double { 8 } else { 4 };
        let double = self.double;
        let mut items = Vec::with_capacity(count);
        for_chunks(self.z, count, N * real, |bytes| {
            let numbers: [f32; N] = std::array::from_fn(|i| {
                let b = &bytes[i * real..(i + 1) * real];
                if double {
                    f64::from_le_bytes(b.try_into().expect("8")) as f32
                } else {
                    f32::from_le_bytes(b.try_into().expect("4"))
                }
            });
            items.push(make(&numbers));
            Ok(())
        })?;
        Ok(items)
    }
}

/// Decompresses `count` records of `size` bytes, a [`CHUNK`] at a time, and hands each
/// record to `each` in order.
fn for_chunks(
    z: &mut impl Read,
    count: usize,
    size: usize,
    mut each: impl FnMut(&[u8]) -> Result<(), String>,
) -> Result<(), String> {
    let per_chunk = (CHUNK / size).max(1);
    let mut buf = vec![0u8; per_chunk.min(count) * size];
    let mut left = count;
    while left > 0 {
        let n = per_chunk.min(left);
        let bytes = &mut buf[..n * size];
        z.read_exact(bytes).map_err(truncated)?;
        bytes.chunks_exact(size).try_for_each(&mut each)?;
        left -= n;
    }
    Ok(())
}

fn read_array<const N: usize>(z: &mut impl Read) -> Result<[u8; N], String> {
    let mut b = [0u8; N];
    z.read_exact(&mut b).map_err(truncated)?;
    Ok(b)
}

fn truncated(e: std::io::Error) -> String {
    format!("the compressed mesh data ends early or is corrupt ({e})")
}
