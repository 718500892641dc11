//! Mitsuba's binary volume grids (`.vol`, version 3), as its `gridvolume` reads them:
//!
//! | bytes | content |
//! |---|---|
//! | 0–2 | `VOL` |
//! | 3 | version, 3 |
//! | 4–7 | encoding (i32 LE): 1 = float32, the only one Mitsuba 3 reads |
//! | 8–19 | resolution x, y, z (i32 LE each) |
//! | 20–23 | channels (i32 LE): 1 or 3 here |
//! | 24–47 | bounding box: min x, y, z, max x, y, z (f32 LE) |
//! | 48– | x·y·z·channels f32 LE, index ((z·ny + y)·nx + x)·channels + c |
//!
//! The declared size is checked against the file's length before anything is allocated
//! (it must match exactly), so a grid allocates no more than its file's size.

use std::path::Path;

use candela_core::desc::{GridDesc, Span};
use glam::Vec3;

use crate::LoadError;

/// A grid read from a `.vol` file, with the bounding box its header declares.
#[derive(Clone, Debug, PartialEq)]
pub struct VolGrid {
    pub grid: GridDesc,
    pub bbox_min: Vec3,
    pub bbox_max: Vec3,
}

const HEADER: usize = 48;

/// Reads a `.vol` file.
pub fn load_vol(path: &Path) -> Result<VolGrid, LoadError> {
    let data = std::fs::read(path).map_err(|e| {
        LoadError::new(
            Span::new(path.display().to_string(), 0, 0),
            format!("cannot read: {e}"),
        )
    })?;
    parse_vol(&data, path)
}

/// Parses the bytes of a `.vol` file; `path` names it in errors, which give the byte
/// offset of what is wrong.
pub fn parse_vol(data: &[u8], path: &Path) -> Result<VolGrid, LoadError> {
    let fail = |offset: usize, m: String| {
        LoadError::new(
            Span::new(path.display().to_string(), 0, 0),
            format!("byte {offset}: {m}"),
        )
    };
    if data.len() < HEADER {
        return Err(fail(
            data.len(),
            format!(
                "a .vol header is {HEADER} bytes, the file has {}",
                data.len()
            ),
        ));
    }
    if &data[0..3] != b"VOL" {
        return Err(fail(
            0,
            "not a Mitsuba volume: it does not start with \"VOL\"".into(),
        ));
    }
    if data[3] != 3 {
        return Err(fail(
            3,
            format!("version {} is not supported (only 3)", data[3]),
        ));
    }
    let i32_at = |o: usize| i32::from_le_bytes(data[o..o + 4].try_into().expect("4 bytes"));
    let f32_at = |o: usize| f32::from_le_bytes(data[o..o + 4].try_into().expect("4 bytes"));
    let encoding = i32_at(4);
    if encoding != 1 {
        return Err(fail(
            4,
            format!("encoding {encoding} is not supported (only 1, float32)"),
        ));
    }
    let mut res = [0u32; 3];
    for (i, r) in res.iter_mut().enumerate() {
        let v = i32_at(8 + 4 * i);
        if v <= 0 {
            return Err(fail(8 + 4 * i, format!("resolution {v} must be positive")));
        }
        *r = v as u32;
    }
    let channels = i32_at(20);
    if channels != 1 && channels != 3 {
        return Err(fail(
            20,
            format!("{channels} channels are not supported (1 or 3)"),
        ));
    }
    let bbox: [f32; 6] = std::array::from_fn(|i| f32_at(24 + 4 * i));
    if let Some(i) = bbox.iter().position(|v| !v.is_finite()) {
        return Err(fail(24 + 4 * i, "the bounding box is not finite".into()));
    }
    let values = res.iter().map(|&r| r as u128).product::<u128>() * channels as u128;
    let need = values * 4;
    let have = (data.len() - HEADER) as u128;
    if need != have {
        return Err(fail(
            HEADER,
            format!(
                "the header declares {}x{}x{}x{channels} values ({need} bytes), the file \
                 holds {have} bytes of data",
                res[0], res[1], res[2]
            ),
        ));
    }
    let mut values = Vec::with_capacity(values as usize);
    for (i, c) in data[HEADER..].chunks_exact(4).enumerate() {
        let v = f32::from_le_bytes(c.try_into().expect("4 bytes"));
        if !(v.is_finite() && v >= 0.0) {
            return Err(fail(
                HEADER + 4 * i,
                format!("value {v} is not finite and non-negative"),
            ));
        }
        values.push(v);
    }
    Ok(VolGrid {
        grid: GridDesc {
            res,
            channels: channels as u32,
            data: values,
        },
        bbox_min: Vec3::new(bbox[0], bbox[1], bbox[2]),
        bbox_max: Vec3::new(bbox[3], bbox[4], bbox[5]),
    })
}

/// The bytes of a `.vol` file holding `grid` in the box [`min`, `max`] (for tests and
/// tools that write grids).
pub fn write_vol(grid: &GridDesc, min: Vec3, max: Vec3) -> Vec<u8> {
    let mut out = Vec::with_capacity(HEADER + 4 * grid.data.len());
    out.extend_from_slice(b"VOL\x03");
    out.extend_from_slice(&1i32.to_le_bytes());
    for r in grid.res {
        out.extend_from_slice(&(r as i32).to_le_bytes());
    }
    out.extend_from_slice(&(grid.channels as i32).to_le_bytes());
    for v in min.to_array().into_iter().chain(max.to_array()) {
        out.extend_from_slice(&v.to_le_bytes());
    }
    for v in &grid.data {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Vec<u8> {
        let grid = GridDesc {
            res: [2, 3, 1],
            channels: 3,
            data: (0..18).map(|i| i as f32 * 0.5).collect(),
        };
        write_vol(&grid, Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0))
    }

    #[test]
    fn a_written_grid_reads_back() {
        let v = parse_vol(&sample(), Path::new("g.vol")).unwrap();
        assert_eq!(v.grid.res, [2, 3, 1]);
        assert_eq!(v.grid.channels, 3);
        assert_eq!(v.grid.data[17], 8.5);
        assert_eq!(v.bbox_max, Vec3::new(1.0, 2.0, 3.0));
    }

    #[test]
    fn bad_headers_are_located() {
        let err = |d: &[u8]| parse_vol(d, Path::new("g.vol")).unwrap_err().to_string();
        let mut d = sample();
        d[3] = 2;
        assert_eq!(
            err(&d),
            "g.vol: byte 3: version 2 is not supported (only 3)"
        );
        let mut d = sample();
        d[20] = 2;
        assert_eq!(
            err(&d),
            "g.vol: byte 20: 2 channels are not supported (1 or 3)"
        );
        let mut d = sample();
        d[8..12].copy_from_slice(&i32::MAX.to_le_bytes());
        assert!(err(&d).starts_with("g.vol: byte 48: the header declares 2147483647x3x1x3"));
        let mut d = sample();
        d[48..52].copy_from_slice(&f32::NAN.to_le_bytes());
        assert_eq!(
            err(&d),
            "g.vol: byte 48: value NaN is not finite and non-negative"
        );
        assert!(err(b"VOL").starts_with("g.vol: byte 3: a .vol header is 48 bytes"));
    }

    #[test]
    fn every_truncation_and_flipped_byte_is_an_error_or_a_grid() {
        // No panic, whatever the damage; truncations are always errors (the size must
        // match); a flipped byte in the header is an error or (a bounding box or value
        // still in range) a grid of the declared size.
        let d = sample();
        for n in 0..d.len() {
            assert!(
                parse_vol(&d[..n], Path::new("g.vol")).is_err(),
                "truncated at {n}"
            );
        }
        for i in 0..d.len() {
            for bit in 0..8 {
                let mut e = d.clone();
                e[i] ^= 1 << bit;
                if let Ok(v) = parse_vol(&e, Path::new("g.vol")) {
                    assert_eq!(v.grid.data.len() * 4 + HEADER, e.len());
                }
            }
        }
    }
}
