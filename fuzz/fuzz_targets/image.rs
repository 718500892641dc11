//! Image textures through `image`: the first byte picks the decoder (PNG, JPEG, TGA,
//! BMP, HDR), the rest is the file. Files declaring over 256² pixels are skipped: the
//! budget lets a small file decode millions of (blank) pixels, tens of milliseconds each
//! time, which slowed the campaign to a few executions a second; the size check itself
//! is tested in `crates/candela-scene/tests/limits.rs`.
#![no_main]

use std::path::Path;

use candela_scene::image_texture::{decode_image, Encoding};
use libfuzzer_sys::fuzz_target;

const NAMES: [&str; 5] = ["f.png", "f.jpg", "f.tga", "f.bmp", "f.hdr"];
const FORMATS: [image::ImageFormat; 5] = [
    image::ImageFormat::Png,
    image::ImageFormat::Jpeg,
    image::ImageFormat::Tga,
    image::ImageFormat::Bmp,
    image::ImageFormat::Hdr,
];

fuzz_target!(|data: &[u8]| {
    let Some((&pick, file)) = data.split_first() else {
        return;
    };
    let name = NAMES[pick as usize % NAMES.len()];
    let format = FORMATS[pick as usize % NAMES.len()];
    let reader = image::ImageReader::with_format(std::io::Cursor::new(file), format);
    if reader
        .into_dimensions()
        .is_ok_and(|(w, h)| u64::from(w) * u64::from(h) > 256 * 256)
    {
        return;
    }
    candela_fuzz::with_budget(file, |file| {
        if let Err(e) = decode_image(file, Path::new(name), Encoding::Srgb) {
            candela_fuzz::check_message(&e);
        }
    });
});
