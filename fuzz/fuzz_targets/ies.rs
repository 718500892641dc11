//! IES LM-63 profiles: the parser, the goniometric table and the summary the CLI prints.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    candela_fuzz::with_budget(data, |data| {
        let ies = match candela_scene::ies::parse_ies(data, "fuzz.ies") {
            Ok(ies) => ies,
            Err(e) => return candela_fuzz::check_message(&e.to_string()),
        };
        if let Err(e) = ies.table() {
            candela_fuzz::check_message(&e.to_string());
        }
        if let Err(e) = candela_scene::ies::summary(&ies) {
            candela_fuzz::check_message(&e.to_string());
        }
    });
});
