//! OpenEXR images (environment maps, textures, projectors). Files declaring over 256²
//! pixels are skipped, as in the `image` target: decoding millions of blank pixels kept
//! the campaign at a few hundred executions a second.
#![no_main]

use std::path::Path;

use candela_scene::image_texture::{decode_image, Encoding};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(meta) = exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(data), false) {
        let pixels = |h: &exr::meta::header::Header| h.layer_size.area() as u64;
        if meta.headers.iter().any(|h| pixels(h) > 256 * 256) {
            return;
        }
    }
    candela_fuzz::with_budget(data, |data| {
        if let Err(e) = decode_image(data, Path::new("f.exr"), Encoding::Srgb) {
            candela_fuzz::check_message(&e);
        }
    });
});
