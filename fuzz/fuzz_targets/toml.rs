//! Candela's TOML scene format, then the scene builder on what parses.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    candela_fuzz::with_budget(data, |data| {
        let Ok(text) = std::str::from_utf8(data) else {
            return;
        };
        match candela_scene::parse_toml_scene(text, &candela_fuzz::scene_path("fuzz.toml")) {
            Ok(desc) => {
                if let Err(e) = candela_core::build::build(&desc) {
                    candela_fuzz::check_message(&e.to_string());
                }
            }
            Err(e) => candela_fuzz::check_message(&e.to_string()),
        }
    });
});
