//! Wavefront OBJ meshes.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    candela_fuzz::with_budget(data, |data| {
        if let Err(e) = candela_scene::obj::parse_obj(data, Path::new("fuzz.obj")) {
            candela_fuzz::check_message(&e.to_string());
        }
    });
});
