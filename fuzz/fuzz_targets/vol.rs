//! Mitsuba `.vol` volume grids.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    candela_fuzz::with_budget(data, |data| {
        if let Err(e) = candela_scene::vol::parse_vol(data, Path::new("fuzz.vol")) {
            candela_fuzz::check_message(&e.to_string());
        }
    });
});
