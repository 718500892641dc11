//! Mitsuba 3 XML scenes (strict and lenient), then the scene builder on what maps.
#![no_main]

use candela_scene::LoadOptions;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    candela_fuzz::with_budget(data, |data| {
        let Ok(text) = std::str::from_utf8(data) else {
            return;
        };
        let options = LoadOptions {
            lenient: data.len() % 2 == 1,
            ..Default::default()
        };
        let path = candela_fuzz::scene_path("fuzz.xml");
        match candela_scene::mitsuba::parse_mitsuba(text, &path, &options) {
            Ok(loaded) => {
                if let Err(e) = candela_core::build::build(&loaded.desc) {
                    candela_fuzz::check_message(&e.to_string());
                }
            }
            Err(e) => candela_fuzz::check_message(&e.to_string()),
        }
    });
});
