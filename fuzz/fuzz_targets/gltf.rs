//! glTF 2.0 and GLB files held in memory (embedded buffers and images only: external
//! files do not resolve), then the scene builder on what loads.
#![no_main]

use std::path::Path;

use candela_scene::LoadOptions;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    candela_fuzz::with_budget(data, |data| {
        let path = Path::new("/nonexistent/fuzz.gltf");
        match candela_scene::gltf::parse_gltf(data, path, None, &LoadOptions::default()) {
            Ok(loaded) => {
                if let Err(e) = candela_core::build::build(&loaded.desc) {
                    candela_fuzz::check_message(&e.to_string());
                }
            }
            Err(e) => candela_fuzz::check_message(&e.to_string()),
        }
    });
});
