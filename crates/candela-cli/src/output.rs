//! Image output. The format follows the file extension: `.exr` (linear float, OpenEXR),
//! `.pfm` (linear float, portable float map), `.png` (8-bit sRGB after exposure and the tone curve, see `tonemap`). Every
//! image is encoded in memory, written to a temporary file in the destination folder and
//! renamed over the destination, so an existing file is never left half-written.

use std::io::{Cursor, Write};
use std::path::Path;

use glam::Vec3;

use crate::tonemap::DisplayTransform;
use crate::UserError;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    Exr,
    Pfm,
    Png,
}

impl ImageFormat {
    pub fn from_path(path: &Path) -> Result<ImageFormat, UserError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("exr") => Ok(ImageFormat::Exr),
            Some("pfm") => Ok(ImageFormat::Pfm),
            Some("png") => Ok(ImageFormat::Png),
            _ => Err(UserError(format!(
                "{}: unsupported output format (use .exr, .pfm or .png)",
                path.display()
            ))),
        }
    }
}

/// Linear pixels, row-major from the top row.
pub struct LinearImage<'a> {
    pub width: u32,
    pub height: u32,
    pub pixels: &'a [Vec3],
}

/// Encodes and atomically writes an image. The display transform (exposure, tone curve,
/// OETF) applies to PNG only; EXR and PFM stay linear.
pub fn write_image(
    path: &Path,
    image: &LinearImage,
    display: &DisplayTransform,
) -> Result<(), UserError> {
    let bytes = match ImageFormat::from_path(path)? {
        ImageFormat::Exr => encode_exr(image),
        ImageFormat::Pfm => Ok(encode_pfm(image)),
        ImageFormat::Png => encode_png(image, display),
    }
    .map_err(|e| UserError(format!("{}: cannot encode image: {e}", path.display())))?;
    write_atomically(path, &bytes)
}

/// Writes `bytes` to a temporary file beside `path`, then renames it into place. The
/// file gets the permissions of any newly created file (0666 less the umask, as
/// `File::create` gives), not the temporary file's private 0600.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), UserError> {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let fail = |e: std::io::Error| UserError(format!("{}: cannot write: {e}", path.display()));
    let mut builder = tempfile::Builder::new();
    builder.prefix(".candela-").suffix(".tmp");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        // Passed to open(2) with O_CREAT, so the kernel applies the umask.
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let mut tmp = builder.tempfile_in(dir).map_err(fail)?;
    tmp.write_all(bytes).map_err(fail)?;
    tmp.as_file().sync_all().map_err(fail)?;
    tmp.persist(path).map_err(|e| fail(e.error))?;
    Ok(())
}

fn encode_exr(image: &LinearImage) -> Result<Vec<u8>, String> {
    use exr::prelude::*;
    let w = image.width as usize;
    let channels = SpecificChannels::rgb(|pos: Vec2<usize>| {
        let p = image.pixels[pos.y() * w + pos.x()];
        (p.x, p.y, p.z)
    });
    // The default's tiles and RLE, but written in increasing order: with the default
    // "unspecified" order the tiles land in the order the compressing threads finish, so
    // two runs of the same render gave files with equal pixels and different bytes.
    let encoding = Encoding {
        line_order: LineOrder::Increasing,
        ..Encoding::FAST_LOSSLESS
    };
    let exr_image = Image::from_encoded_channels((w, image.height as usize), encoding, channels);
    let mut out = Cursor::new(Vec::new());
    exr_image
        .write()
        .to_buffered(&mut out)
        .map_err(|e| e.to_string())?;
    Ok(out.into_inner())
}

/// PFM: a text header, then little-endian floats from the bottom row up.
fn encode_pfm(image: &LinearImage) -> Vec<u8> {
    let mut out = format!("PF\n{} {}\n-1.0\n", image.width, image.height).into_bytes();
    for row in image.pixels.chunks(image.width as usize).rev() {
        for p in row {
            for c in p.to_array() {
                out.extend_from_slice(&c.to_le_bytes());
            }
        }
    }
    out
}

fn encode_png(image: &LinearImage, display: &DisplayTransform) -> Result<Vec<u8>, String> {
    let rgb = image::RgbImage::from_fn(image.width, image.height, |x, y| {
        image::Rgb(display.encode(image.pixels[(y * image.width + x) as usize]))
    });
    let mut out = Cursor::new(Vec::new());
    rgb.write_to(&mut out, image::ImageFormat::Png)
        .map_err(|e| e.to_string())?;
    Ok(out.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pfm_is_bottom_up_little_endian() {
        let px = [Vec3::new(1.0, 2.0, 3.0), Vec3::new(4.0, 5.0, 6.0)];
        let bytes = encode_pfm(&LinearImage {
            width: 1,
            height: 2,
            pixels: &px,
        });
        let header = b"PF\n1 2\n-1.0\n";
        assert_eq!(&bytes[..header.len()], header);
        let first = f32::from_le_bytes(bytes[header.len()..header.len() + 4].try_into().unwrap());
        assert_eq!(first, 4.0, "the bottom row comes first");
    }

    #[test]
    fn exr_bytes_depend_only_on_the_pixels() {
        // 64 tiles of 64², compressed in parallel: the file must still be the same bytes
        // every time, and say its tiles are in increasing order.
        let px: Vec<Vec3> = (0..512 * 512)
            .map(|i| Vec3::new((i % 7) as f32, (i % 13) as f32 * 0.5, (i / 512) as f32))
            .collect();
        let image = LinearImage {
            width: 512,
            height: 512,
            pixels: &px,
        };
        let first = encode_exr(&image).unwrap();
        let meta = exr::meta::MetaData::read_from_buffered(Cursor::new(&first), false).unwrap();
        assert_eq!(
            meta.headers[0].line_order,
            exr::meta::attribute::LineOrder::Increasing
        );
        for _ in 0..10 {
            assert!(
                encode_exr(&image).unwrap() == first,
                "the bytes changed between runs"
            );
        }
    }

    /// An image is readable as any file the user creates is, not private like the
    /// temporary file it is written through.
    #[cfg(unix)]
    #[test]
    fn written_file_has_a_new_files_permissions() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let reference = dir.path().join("reference");
        std::fs::File::create(&reference).unwrap();
        let out = dir.path().join("out.pfm");
        write_atomically(&out, b"bytes").unwrap();
        let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode(&out), mode(&reference));
        assert_eq!(std::fs::read(&out).unwrap(), b"bytes");
    }

    #[test]
    fn unknown_extension_is_an_error() {
        assert!(ImageFormat::from_path(Path::new("a.jpg")).is_err());
        assert_eq!(
            ImageFormat::from_path(Path::new("a.EXR")).unwrap(),
            ImageFormat::Exr
        );
    }
}
