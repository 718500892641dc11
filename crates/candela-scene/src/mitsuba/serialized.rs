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

use std::io::Read;
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

/// Reads mesh number `index` (from 0) of a serialized file. Vertex colours are read and
/// dropped, as Mitsuba keeps them for a `mesh_attribute` texture only.
pub fn load_serialized(path: &Path, index: u32) -> Result<MeshDesc, MeshError> {
    let err = |m: String| MeshError::new(path, None, m);
    let bytes = std::fs::read(path).map_err(|e| err(format!("cannot read: {e}")))?;
    let version = header(&bytes, 0).map_err(err)?;
    let start = mesh_offset(&bytes, version, index).map_err(err)?;
    let version_here = header(&bytes, start).map_err(err)?;
    if version_here != version {
        return Err(err(format!(
            "mesh {index} is version {version_here}, the file's first is {version}"
        )));
    }
    let budget = allocation_budget(bytes.len());
    let mut z = ZlibDecoder::new(&bytes[start + 4..]).take(budget);
    read_mesh(&mut z, version, budget).map_err(|m| err(format!("mesh {index}: {m}")))
}

/// The version of the mesh header at `at`.
fn header(bytes: &[u8], at: usize) -> Result<u16, String> {
    let h = bytes
        .get(at..at + 4)
        .ok_or_else(|| format!("the file ends at byte {} before a mesh header", bytes.len()))?;
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

/// Where mesh `index` starts, from the dictionary at the end of the file.
fn mesh_offset(bytes: &[u8], version: u16, index: u32) -> Result<usize, String> {
    let n = bytes.len();
    let tail = |from: usize, len: usize| {
        bytes
            .get(from..from + len)
            .ok_or_else(|| "the mesh dictionary at the end of the file is cut short".to_string())
    };
    let count = u32::from_le_bytes(tail(n.saturating_sub(4), 4)?.try_into().expect("4"));
    if index >= count {
        return Err(format!(
            "shape_index {index} is out of range: the file holds {count} mesh(es)"
        ));
    }
    let width = if version == 4 { 8 } else { 4 };
    let table = n
        .checked_sub(4 + width * count as usize)
        .ok_or("the mesh dictionary is longer than the file")?;
    let entry = tail(table + width * index as usize, width)?;
    let offset = if width == 8 {
        u64::from_le_bytes(entry.try_into().expect("8"))
    } else {
        u32::from_le_bytes(entry.try_into().expect("4")) as u64
    };
    match usize::try_from(offset) {
        Ok(o) if o < table => Ok(o),
        _ => Err(format!("mesh {index}'s offset {offset} lies past its data")),
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
    let mut reals = |n: usize| -> Result<Vec<f32>, String> {
        let mut buf = vec![0u8; n * real as usize];
        z.read_exact(&mut buf).map_err(truncated)?;
        Ok(if double {
            buf.chunks_exact(8)
                .map(|c| f64::from_le_bytes(c.try_into().expect("8")) as f32)
                .collect()
        } else {
            buf.chunks_exact(4)
                .map(|c| f32::from_le_bytes(c.try_into().expect("4")))
                .collect()
        })
    };
    let vec3s = |v: Vec<f32>| -> Vec<Vec3> { v.chunks_exact(3).map(Vec3::from_slice).collect() };
    let positions = vec3s(reals(3 * vertices)?);
    let normals = match flags & HAS_NORMALS {
        0 => Vec::new(),
        _ => vec3s(reals(3 * vertices)?),
    };
    let uvs = match flags & HAS_UVS {
        0 => Vec::new(),
        _ => reals(2 * vertices)?
            .chunks_exact(2)
            .map(Vec2::from_slice)
            .collect(),
    };
    if flags & HAS_COLORS != 0 {
        reals(3 * vertices)?;
    }
    let mut buf = vec![0u8; triangles * per_triangle as usize];
    z.read_exact(&mut buf).map_err(truncated)?;
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
    let width = per_triangle as usize / 3;
    let indices = buf
        .chunks_exact(per_triangle as usize)
        .map(|t| {
            Ok([
                index(&t[..width])?,
                index(&t[width..2 * width])?,
                index(&t[2 * width..])?,
            ])
        })
        .collect::<Result<Vec<_>, String>>()?;
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

fn read_array<const N: usize>(z: &mut impl Read) -> Result<[u8; N], String> {
    let mut b = [0u8; N];
    z.read_exact(&mut b).map_err(truncated)?;
    Ok(b)
}

fn truncated(e: std::io::Error) -> String {
    format!("the compressed mesh data ends early or is corrupt ({e})")
}
