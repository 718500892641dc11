//! OpenEXR images (environment maps, textures, projectors).
#![no_main]

use std::path::Path;

use candela_scene::image_texture::{decode_image, Encoding};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    candela_fuzz::with_budget(data, |data| {
        if let Err(e) = decode_image(data, Path::new("f.exr"), Encoding::Srgb) {
            candela_fuzz::check_message(&e);
        }
    });
});
