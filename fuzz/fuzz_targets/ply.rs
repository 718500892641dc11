//! Stanford PLY meshes, ascii and binary.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    candela_fuzz::with_budget(data, |data| {
        if let Err(e) = candela_scene::ply::parse_ply(data, Path::new("fuzz.ply")) {
            candela_fuzz::check_message(&e.to_string());
        }
    });
});
