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

/// An image of each format Candela reads, 5×3 pixels, encoded in memory.
fn small_images() -> Vec<(&'static str, Vec<u8>)> {
    let rgb = image::RgbImage::from_fn(5, 3, |x, y| image::Rgb([x as u8 * 50, y as u8 * 80, 7]));
    let mut out = Vec::new();
    for (name, format) in [
        ("t.png", image::ImageFormat::Png),
        ("t.jpg", image::ImageFormat::Jpeg),
        ("t.tga", image::ImageFormat::Tga),
        ("t.bmp", image::ImageFormat::Bmp),
    ] {
        let mut bytes = std::io::Cursor::new(Vec::new());
        rgb.write_to(&mut bytes, format).unwrap();
        out.push((name, bytes.into_inner()));
    }
    let hdr = image::DynamicImage::ImageRgb8(rgb).to_rgb32f();
    let mut bytes = std::io::Cursor::new(Vec::new());
    hdr.write_to(&mut bytes, image::ImageFormat::Hdr).unwrap();
    out.push(("t.hdr", bytes.into_inner()));
    let mut bytes = Vec::new();
    use exr::prelude::*;
    Image::from_channels(
        (5, 3),
        SpecificChannels::rgb(|p: Vec2<usize>| (p.0 as f32, p.1 as f32, 0.5f32)),
    )
    .write()
    .to_buffered(std::io::Cursor::new(&mut bytes))
    .unwrap();
    out.push(("t.exr", bytes));
    out
}

/// fuzz target `image`: a truncated JPEG's message ended in a newline. Every truncation
/// of a small file of every format is now a one-line error naming the file (or, where
/// the format tolerates a short file, a 5×3 image).
#[test]
fn every_truncation_of_every_image_format_is_a_one_line_error() {
    use candela_scene::image_texture::{decode_image, Encoding};
    for (name, bytes) in small_images() {
        let whole = decode_image(&bytes, Path::new(name), Encoding::Srgb).unwrap();
        assert_eq!((whole.width, whole.height), (5, 3), "{name}");
        for len in 0..bytes.len() {
            match decode_image(&bytes[..len], Path::new(name), Encoding::Srgb) {
                Err(e) => assert_located(&e, &format!("{name}: cannot read image: ")),
                Ok(img) => assert_eq!((img.width, img.height), (5, 3), "{name} at {len}"),
            }
        }
    }
}

/// Found by hand after the campaign (the fuzzer's 64 KiB inputs did not reach it): XML
/// nested 200000 deep overflowed the stack in the recursive conversion of the tree.
#[test]
fn mitsuba_deeply_nested_xml_is_an_error_not_a_stack_overflow() {
    let n = 200_000;
    let text = format!(
        "<scene version=\"3.0.0\">{}{}</scene>",
        "<a>".repeat(n),
        "</a>".repeat(n)
    );
    let options = candela_scene::LoadOptions::default();
    let e = candela_scene::mitsuba::parse_mitsuba(&text, Path::new("deep.xml"), &options)
        .unwrap_err()
        .to_string();
    assert_located(&e, "deep.xml:1:");
    assert!(e.contains("nest deeper than"), "{e}");
    // TOML's parser has its own recursion limit.
    let text = format!("a = {}{}\n", "[".repeat(n), "]".repeat(n));
    let e = candela_scene::parse_toml_scene(&text, Path::new("deep.toml")).unwrap_err();
    assert_located(&e.to_string(), "deep.toml:1:");
}
