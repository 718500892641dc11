//! Image textures through `image`: the first byte picks the decoder (PNG, JPEG, TGA,
//! BMP, HDR), the rest is the file.
#![no_main]

use std::path::Path;

use candela_scene::image_texture::{decode_image, Encoding};
use libfuzzer_sys::fuzz_target;

const NAMES: [&str; 5] = ["f.png", "f.jpg", "f.tga", "f.bmp", "f.hdr"];

fuzz_target!(|data: &[u8]| {
    let Some((&pick, file)) = data.split_first() else {
        return;
    };
    let name = NAMES[pick as usize % NAMES.len()];
    candela_fuzz::with_budget(file, |file| {
        if let Err(e) = decode_image(file, Path::new(name), Encoding::Srgb) {
            candela_fuzz::check_message(&e);
        }
    });
});
