//! Inputs the fuzz targets (`fuzz/`) found crashing, hanging or over their allocation
//! budget, minimized by hand to what triggers the bug, each with the fix's outcome: a
//! located one-line error (or a successful parse), never a panic.

use std::path::Path;

/// A one-line error located in `file`.
fn assert_located(message: &str, file: &str) {
    assert!(
        message.starts_with(file),
        "not located in {file}: {message}"
    );
    assert!(!message.contains('\n'), "not one line: {message:?}");
}

/// fuzz target `ies`: a Latin-1 header line with a two-byte character across byte 5 was
/// sliced there while looking for `TILT=` (parse.rs: "byte index 5 is not a char
/// boundary").
#[test]
fn ies_latin1_header_line_across_byte_5() {
    let bytes = b"IESNA:LM-63-2002\n\xca\xca\xca TILT=NONE\n[TEST] x\n";
    let e = candela_scene::ies::parse_ies(bytes, "f.ies").unwrap_err();
    assert_located(&e.to_string(), "f.ies:");
    // The same line with TILT= first still counts as the tilt line.
    let ok = b"IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 90\n0\n10 10\n";
    assert!(candela_scene::ies::parse_ies(ok, "f.ies").is_ok());
}

/// fuzz target `mitsuba`: roxmltree's message quotes the unexpected character, here a
/// newline, which broke the error across two lines.
#[test]
fn mitsuba_xml_error_quoting_a_newline_stays_on_one_line() {
    let options = candela_scene::LoadOptions::default();
    let text = "<scene version=\"3.0.0\">\n<shape/\n></scene>";
    let e = candela_scene::mitsuba::parse_mitsuba(text, Path::new("f.xml"), &options)
        .unwrap_err()
        .to_string();
    assert_located(&e, "f.xml:2:8: XML: ");
    assert!(
        e.contains("not '\\n'"),
        "the newline is written as an escape: {e}"
    );
}
