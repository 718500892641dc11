//! Environment maps from files: Radiance `.hdr` and OpenEXR (half or float) panoramas
//! and cube maps, and 8-bit (or 16-bit) sRGB images decoded to linear light; cube maps
//! as six face files or one horizontal or vertical cross. All come out as linear RGB
//! [`ImageDesc`]s, top row first.
//!
//! Cross layouts (face size `n`; the face table is in `candela_core::light::envmap::cubemap`):
//!
//! - horizontal, 4n × 3n: row 0 holds +y in column 1; row 1 holds −x, +z, +x, −z; row 2
//!   holds −y in column 1;
//! - vertical, 3n × 4n: +y at (1, 0); −x, +z, +x in row 1; −y at (1, 2); −z at (1, 3),
//!   stored turned by 180° (so that its edge meets −y's), which the loader undoes.

use std::path::Path;

use candela_core::desc::ImageDesc;

use crate::image_texture::{load_image, Encoding};

/// Loads an image as linear RGB through [`crate::image_texture::load_image`]: `.hdr` and
/// `.exr` are linear; PNG, JPEG, TGA and BMP are taken as sRGB-encoded. An environment
/// must also be non-empty and have finite, non-negative pixels.
pub fn load_linear_image(path: &Path) -> Result<ImageDesc, String> {
    let img = load_image(path, Encoding::Srgb)?;
    if img.width == 0 || img.height == 0 {
        return Err("image is empty".into());
    }
    if let Some(p) = img
        .pixels
        .iter()
        .find(|p| !p.is_finite() || p.min_element() < 0.0)
    {
        return Err(format!("image has a negative or non-finite pixel {p}"));
    }
    Ok(img)
}

/// The `n × n` square at face position (`col`, `row`) of a cross.
fn crop(img: &ImageDesc, n: u32, col: u32, row: u32) -> ImageDesc {
    let mut pixels = Vec::with_capacity((n * n) as usize);
    for y in row * n..(row + 1) * n {
        let start = (y * img.width + col * n) as usize;
        pixels.extend_from_slice(&img.pixels[start..start + n as usize]);
    }
    ImageDesc {
        width: n,
        height: n,
        pixels,
    }
}

/// Splits a horizontal (4:3) or vertical (3:4) cross into faces +x, −x, +y, −y, +z, −z.
pub fn split_cross(img: &ImageDesc) -> Result<[ImageDesc; 6], String> {
    let (w, h) = (img.width, img.height);
    if w % 4 == 0 && 3 * w == 4 * h {
        let n = w / 4;
        let at = |c, r| crop(img, n, c, r);
        Ok([at(2, 1), at(0, 1), at(1, 0), at(1, 2), at(1, 1), at(3, 1)])
    } else if h % 4 == 0 && 4 * w == 3 * h {
        let n = h / 4;
        let at = |c, r| crop(img, n, c, r);
        let mut nz = at(1, 3);
        nz.pixels.reverse(); // a turn by 180°
        Ok([at(2, 1), at(0, 1), at(1, 0), at(1, 2), at(1, 1), nz])
    } else {
        Err(format!(
            "a cube map cross must be 4:3 (horizontal) or 3:4 (vertical) with square faces, \
             found {w}x{h}"
        ))
    }
}

/// The image turned upside down: for cube map faces stored bottom row first.
pub fn flip_vertical(img: &ImageDesc) -> ImageDesc {
    let w = img.width as usize;
    ImageDesc {
        pixels: img
            .pixels
            .chunks_exact(w)
            .rev()
            .flatten()
            .copied()
            .collect(),
        ..*img
    }
}

/// Loads six face files in the order +x, −x, +y, −y, +z, −z, checking that they are
/// square and of one size. Errors name the face's index.
pub fn load_cube_faces(paths: &[&Path; 6]) -> Result<[ImageDesc; 6], (usize, String)> {
    let mut faces: Vec<ImageDesc> = Vec::with_capacity(6);
    for (i, p) in paths.iter().enumerate() {
        let f = load_linear_image(p).map_err(|e| (i, e))?;
        if f.width != f.height {
            return Err((
                i,
                format!("cube map face is {}x{}, not square", f.width, f.height),
            ));
        }
        if let Some(first) = faces.first() {
            if f.width != first.width {
                return Err((
                    i,
                    format!(
                        "cube map face is {0}x{0}, the +x face {1}x{1}",
                        f.width, first.width
                    ),
                ));
            }
        }
        faces.push(f);
    }
    Ok(faces.try_into().expect("six faces"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn numbered(w: u32, h: u32) -> ImageDesc {
        ImageDesc {
            width: w,
            height: h,
            pixels: (0..w * h).map(|i| Vec3::splat(i as f32)).collect(),
        }
    }

    #[test]
    fn crosses_split_into_the_documented_faces() {
        let n = 2;
        let h = numbered(4 * n, 3 * n);
        let faces = split_cross(&h).unwrap();
        // +x is at column 2, row 1: its top-left pixel is (4, 2).
        assert_eq!(faces[0].pixels[0].x, (2 * 8 + 4) as f32);
        assert_eq!(faces[2].pixels[0].x, 2.0); // +y at (2, 0)
        assert_eq!(faces[5].pixels[1].x, (2 * 8 + 7) as f32); // −z at (6, 2), second pixel

        let v = numbered(3 * n, 4 * n);
        let faces = split_cross(&v).unwrap();
        assert_eq!(faces[4].pixels[0].x, (2 * 6 + 2) as f32); // +z at (2, 2)
                                                              // −z at (2, 6) turned by 180°: its first pixel is the square's last, (3, 7).
        assert_eq!(faces[5].pixels[0].x, (7 * 6 + 3) as f32);
        assert!(split_cross(&numbered(5, 3)).is_err());
    }
}
