//! Synthetic LM-63 files: each edition, tilt data, each horizontal symmetry, separators,
//! and every malformed case with the line its error must point at.

use candela_core::photometry::{GoniometricTable, HorizontalSymmetry};
use candela_scene::ies::{parse_ies, IesFile, IesVersion, Tilt};

/// A file from its header lines and its data (everything after TILT=NONE).
fn file(header: &str, data: &str) -> String {
    format!("{header}\nTILT=NONE\n{data}")
}

fn parse(text: &str) -> IesFile {
    parse_ies(text.as_bytes(), "t.ies").unwrap_or_else(|e| panic!("{e}"))
}

/// Error display and line for a malformed file.
fn error(text: &str) -> (String, u32) {
    let e = parse_ies(text.as_bytes(), "bad.ies").expect_err("malformed file must not parse");
    (e.to_string(), e.span.line)
}

/// 3 vertical angles (0, 45, 90), one plane, candela 100 80 0, multiplier 2.
const SIMPLE: &str = "1 1000 2 3 1 1 2 0.1 0.1 0\n1 1 50\n0 45 90\n0\n100 80 0\n";

/// The table's intensity 45° from the nadir axis, at azimuth `phi` degrees.
fn intensity_at_45_degrees(table: &GoniometricTable, phi: f64) -> f32 {
    let p = phi.to_radians();
    let s = std::f64::consts::FRAC_1_SQRT_2;
    table.intensity(glam::Vec3::new(
        (s * p.cos()) as f32,
        (s * p.sin()) as f32,
        s as f32,
    ))
}

#[test]
fn each_edition_is_recognized() {
    let cases = [
        ("ACME LIGHTING\nSPOT 12", IesVersion::Lm63_1986),
        ("IESNA91\n[TEST] 1", IesVersion::Lm63_1991),
        ("IESNA:LM-63-1995\n[TEST] 1", IesVersion::Lm63_1995),
        ("IESNA:LM-63-2002\n[TEST] 1", IesVersion::Lm63_2002),
        ("IES:LM-63-2019\n[TEST] 1", IesVersion::Lm63_2019),
    ];
    for (header, version) in cases {
        let ies = parse(&file(header, SIMPLE));
        assert_eq!(ies.version, version);
        assert_eq!(ies.candela, vec![200.0, 160.0, 0.0], "multiplier 2 applied");
        assert_eq!(ies.stated_lumens(), Some(1000.0));
    }
    let old = parse(&file("ACME LIGHTING\nSPOT 12", SIMPLE));
    assert_eq!(old.text, vec!["ACME LIGHTING", "SPOT 12"]);
    assert!(old.keywords.is_empty());
}

#[test]
fn keywords_more_lines_and_latin1_bytes() {
    let mut bytes = b"IESNA:LM-63-2002\n[TEST] T-1\n[MANUFAC] ACME \xB0 GmbH\n[LUMINAIRE] Spot\n[MORE] with lens\n[LAMP]\n".to_vec();
    bytes.extend_from_slice(
        b"TILT=NONE\r\n1 -1 1 3 1 1 2 0 0 0\r\n1 1 50\r\n0 45 90\r\n0\r\n100 80 0\r\nEND\r\n\x1a",
    );
    let ies = parse_ies(&bytes, "t.ies").unwrap();
    assert_eq!(ies.keyword("test"), Some("T-1"));
    assert_eq!(ies.keyword("MANUFAC"), Some("ACME \u{b0} GmbH"));
    assert_eq!(ies.keyword("LUMINAIRE"), Some("Spot\nwith lens"));
    assert_eq!(ies.keyword("LAMP"), Some(""));
    assert_eq!(ies.stated_lumens(), None, "lumens -1 = absolute photometry");
}

#[test]
fn ballast_factors_are_applied_as_each_edition_says() {
    let data = "1 1000 1 3 1 1 2 0 0 0\n0.5 0.8 50\n0 45 90\n0\n100 80 0\n";
    // 1995: ballast factor × ballast-lamp photometric factor.
    assert_eq!(
        parse(&file("IESNA:LM-63-1995", data)).candela,
        vec![40.0, 32.0, 0.0]
    );
    // 2002 ("future use") and 2019 ("file generation type"): ballast factor only.
    assert_eq!(
        parse(&file("IESNA:LM-63-2002", data)).candela,
        vec![50.0, 40.0, 0.0]
    );
    assert_eq!(
        parse(&file("IES:LM-63-2019", data)).candela,
        vec![50.0, 40.0, 0.0]
    );
}

#[test]
fn tilt_include_is_read_and_applied() {
    // Lamp geometry 1, 3 tilt angles; the factor at 0° (installed as measured) is 0.5.
    let text = "IESNA:LM-63-2002\nTILT=INCLUDE\n1\n3\n0 45 90\n0.5 0.75 1.0\n1 1000 1 3 1 1 2 0 0 0\n1 1 50\n0 45 90\n0\n100 80 0\n";
    let ies = parse(text);
    let Tilt::Include(t) = &ies.tilt else {
        panic!("tilt not read: {:?}", ies.tilt)
    };
    assert_eq!(t.lamp_geometry, 1);
    assert_eq!(t.factor(22.5), 0.625);
    assert_eq!(t.factor(120.0), 1.0);
    assert_eq!(ies.candela, vec![50.0, 40.0, 0.0]);
}

#[test]
fn tilt_file_is_read_next_to_the_ies_file_or_reported_missing() {
    let dir = tempfile::tempdir().unwrap();
    let ies_path = dir.path().join("lamp.ies");
    let text =
        "IESNA:LM-63-1995\nTILT=lamp.tlt\n1 1000 1 3 1 1 2 0 0 0\n1 1 50\n0 45 90\n0\n100 80 0\n";
    let e = parse_ies(text.as_bytes(), &ies_path.display().to_string()).unwrap_err();
    assert_eq!(e.span.line, 2, "{e}");
    assert!(
        e.to_string()
            .contains("TILT file \"lamp.tlt\" cannot be read"),
        "{e}"
    );
    std::fs::write(dir.path().join("lamp.tlt"), "2\n2\n0 90\n0.25 1\n").unwrap();
    std::fs::write(&ies_path, text).unwrap();
    let ies = candela_scene::ies::load_ies(&ies_path).unwrap();
    assert!(matches!(&ies.tilt, Tilt::File(n, t) if n == "lamp.tlt" && t.lamp_geometry == 2));
    assert_eq!(ies.candela, vec![25.0, 20.0, 0.0]);
}

#[test]
fn each_horizontal_symmetry() {
    let cases = [
        ("0", HorizontalSymmetry::Rotational),
        ("0 45 90", HorizontalSymmetry::Quadrant),
        ("0 90 180", HorizontalSymmetry::BilateralC0),
        ("90 180 270", HorizontalSymmetry::BilateralC90),
        ("0 90 180 270 360", HorizontalSymmetry::None),
    ];
    for (angles, sym) in cases {
        let n = angles.split(' ').count();
        // Plane k has candela 10 (k + 1) at nadir, half of it at 45°, 0 at 90°.
        let values: String = (0..n)
            .map(|k| format!("{} {} 0\n", 10 * (k + 1), 5 * (k + 1)))
            .collect();
        let text = file(
            "IESNA:LM-63-2002",
            &format!("1 -1 1 3 {n} 1 2 0 0 0\n1 1 0\n0 45 90\n{angles}\n{values}"),
        );
        let ies = parse(&text);
        assert_eq!(ies.symmetry(), sym, "{angles}");
        let table = ies.table().unwrap();
        let at = |phi| intensity_at_45_degrees(&table, phi);
        match sym {
            HorizontalSymmetry::Rotational => assert_eq!(at(123.0), 5.0),
            HorizontalSymmetry::Quadrant => {
                // Measured 0° → 5, 45° → 10, 90° → 15; mirrored into every quadrant.
                assert_eq!((at(0.0), at(45.0), at(90.0)), (5.0, 10.0, 15.0));
                assert_eq!(
                    (at(135.0), at(180.0), at(225.0), at(315.0)),
                    (10.0, 5.0, 10.0, 10.0)
                );
            }
            HorizontalSymmetry::BilateralC0 => {
                assert_eq!((at(90.0), at(180.0), at(270.0)), (10.0, 15.0, 10.0));
                assert!((at(300.0) - at(60.0)).abs() < 1e-5);
            }
            HorizontalSymmetry::BilateralC90 => {
                // 90° → 5, 180° → 10, 270° → 15; C0 mirrors C180, C45 mirrors C135.
                assert_eq!(
                    (at(90.0), at(180.0), at(270.0), at(0.0)),
                    (5.0, 10.0, 15.0, 10.0)
                );
                assert!(
                    (at(45.0) - at(135.0)).abs() < 1e-5 && (at(315.0) - at(225.0)).abs() < 1e-5
                );
            }
            HorizontalSymmetry::None => {
                assert_eq!((at(90.0), at(270.0)), (10.0, 20.0));
                assert!(
                    (at(0.0) - 5.0).abs() < 1e-5
                        && (at(359.0) - (20.0 + 5.0 * 89.0 / 90.0)).abs() < 1e-3
                );
            }
        }
    }
}

#[test]
fn commas_and_values_split_across_lines() {
    let spaced = parse(&file("IESNA91", SIMPLE));
    let commas = parse(&file(
        "IESNA91",
        "1,1000,2,3,1,1,2,0.1,0.1,0\n1,1,50\n0,45,90\n0\n100,80,0\n",
    ));
    let split = parse(&file(
        "IESNA91",
        "1\n1000\n2 3\n1\n1 2 0.1\n0.1 0\n1 1\n50\n0 45\n90\n0\n100\n80\n0\n",
    ));
    let fortran = parse(&file(
        "IESNA91",
        "1 1000. 2.0 3 1 1 2 .1 .1 .000\n1. 1. 50.\n0. 45. 90.\n0.\n100. 80. .0\n",
    ));
    assert_eq!(spaced, commas);
    assert_eq!(spaced, split);
    assert_eq!(spaced.candela, fortran.candela);
}

#[test]
fn malformed_files_report_the_right_line() {
    let h = "IESNA:LM-63-2002\n[TEST] x\n"; // data starts on line 4
    let cases: [(&str, String, u32, &str); 9] = [
        // The header announces 2 planes, the data has one: too few numbers.
        (
            "truncated data",
            format!("{h}TILT=NONE\n1 1000 1 3 2 1 2 0 0 0\n1 1 50\n0 45 90\n0 90\n100 80 0\n"),
            8,
            "truncated data",
        ),
        // The header announces 2 vertical angles, the data has 3: too many numbers.
        (
            "count mismatch",
            format!("{h}TILT=NONE\n1 1000 1 2 1 1 2 0 0 0\n1 1 50\n0 45 90\n0\n100 80 0\n"),
            4,
            "counts do not match",
        ),
        (
            "non-monotonic vertical",
            format!("{h}TILT=NONE\n1 1000 1 3 1 1 2 0 0 0\n1 1 50\n0\n90\n45\n0\n100 80 0\n"),
            8,
            "not increasing",
        ),
        (
            "non-monotonic horizontal",
            format!("{h}TILT=NONE\n1 1000 1 2 2 1 2 0 0 0\n1 1 50\n0 90\n90 0\n1 1 1 1\n"),
            7,
            "not increasing",
        ),
        (
            "negative candela",
            format!("{h}TILT=NONE\n1 1000 1 3 1 1 2 0 0 0\n1 1 50\n0 45 90\n0\n100\n-80\n0\n"),
            9,
            "negative candela",
        ),
        (
            "garbage number",
            format!("{h}TILT=NONE\n1 1000 1 3 1 1 2 0 0 0\n1 1 50\n0 45 90\n0\n100 8o 0\n"),
            8,
            "found \"8o\"",
        ),
        (
            "type B",
            format!("{h}TILT=NONE\n1 1000 1 3 1\n2 2 0 0 0\n1 1 50\n0 45 90\n0\n100 80 0\n"),
            5,
            "type B is not supported",
        ),
        (
            "type A",
            format!("{h}TILT=NONE\n1 1000 1 3 1 3 2 0 0 0\n1 1 50\n0 45 90\n0\n100 80 0\n"),
            4,
            "type A is not supported",
        ),
        (
            "bad horizontal range",
            format!("{h}TILT=NONE\n1 1000 1 2 2 1 2 0 0 0\n1 1 50\n0 90\n\n10 100\n1 1 1 1\n"),
            8,
            "not one of the LM-63 ranges",
        ),
    ];
    for (what, text, line, message) in cases {
        let (shown, got_line) = error(&text);
        assert_eq!(got_line, line, "{what}: {shown}");
        assert!(
            shown.starts_with(&format!("bad.ies:{line}")),
            "{what}: {shown}"
        );
        assert!(shown.contains(message), "{what}: {shown}");
    }
}

#[test]
fn degenerate_input_never_panics() {
    let cases = [
        "",
        "\n\n",
        "IESNA:LM-63-2002\n",
        "IESNA:LM-63-2002\nTILT=NONE",
        "IESNA:LM-63-2002\nTILT=INCLUDE\n1 2 0",
        "IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 0 1 1 2 0 0 0\n1 1 0\n",
        "IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 3 1 1 2 0 0 0\n1 1 0\n0 45 90\n0\n1 nan 1\n",
        "IESNA:LM-63-2002\nTILT=NONE\n1 1000 0 3 1 1 2 0 0 0\n1 1 0\n0 45 90\n0\n1 1 1\n",
        "IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 3 1 1 2 0 0 0\n1 1 0\n0 45 200\n0\n1 1 1\n",
        "IESNA:LM-63-2077\nTILT=NONE\n",
    ];
    for text in cases {
        let e = parse_ies(text.as_bytes(), "bad.ies").expect_err(text);
        assert!(e.to_string().starts_with("bad.ies"), "{e}");
    }
    // Arbitrary bytes, including invalid UTF-8.
    let junk: Vec<u8> = (0..=255u8).cycle().take(2000).collect();
    assert!(parse_ies(&junk, "bad.ies").is_err());
}

#[test]
fn bilateral_c90_files_without_a_180_plane_fold_through_it() {
    // I(φ) = I(180° − φ) about the C90–C270 plane. Where the file has no 180° plane the
    // intensity there, and so at 0°, lies on the line between the planes around 180°:
    // halfway between 170° and 190° (20° steps), or between 90° and 270° (two planes).
    // Plane k has 10 (k + 1) at 45° from nadir.
    for step in [20usize, 180] {
        let angles: Vec<usize> = (90..=270).step_by(step).collect();
        let n = angles.len();
        let values: String = (0..n)
            .map(|k| format!("{} {} 0\n", 20 * (k + 1), 10 * (k + 1)))
            .collect();
        let list: Vec<String> = angles.iter().map(|a| a.to_string()).collect();
        let text = file(
            "IES:LM-63-2019",
            &format!(
                "1 -1 1 3 {n} 1 2 0 0 0\n1 1 0\n0 45 90\n{}\n{values}",
                list.join(" ")
            ),
        );
        let ies = parse(&text);
        assert_eq!(ies.symmetry(), HorizontalSymmetry::BilateralC90);
        let table = ies.table().unwrap();
        let at = |phi| intensity_at_45_degrees(&table, phi);
        // The mean of the two planes around 180°: 10 (k + 1) for k = n/2 − 1 and n/2.
        let at_180 = 10.0 * (n as f32 + 1.0) / 2.0;
        for (phi, want) in [
            (90.0, 10.0),
            (270.0, 10.0 * n as f32),
            (180.0, at_180),
            (0.0, at_180),
        ] {
            assert!(
                (at(phi) - want).abs() < 1e-3,
                "step {step}: I({phi}°) = {}, expected {want}",
                at(phi)
            );
        }
        for (a, b) in [(45.0, 135.0), (10.0, 170.0), (315.0, 225.0), (350.0, 190.0)] {
            assert!(
                (at(a) - at(b)).abs() < 1e-3,
                "step {step}: I({a}°) = {} but I({b}°) = {}",
                at(a),
                at(b)
            );
        }
    }
}

#[test]
fn byte_order_marks_and_classic_mac_line_ends_are_read() {
    let lf = file("IESNA:LM-63-2002\n[TEST] 1", SIMPLE);
    let plain = parse(&lf);
    assert_eq!(plain.version, IesVersion::Lm63_2002);
    // A UTF-8 byte-order mark before the version line: still LM-63-2002 (and so the
    // third ballast number is not applied).
    let bom = parse(&format!("\u{feff}{lf}"));
    assert_eq!(bom.version, IesVersion::Lm63_2002);
    assert_eq!(bom.candela, plain.candela);
    // Lone CR line ends, and CR LF with tabs and trailing blank lines.
    assert_eq!(parse(&lf.replace('\n', "\r")), plain);
    let crlf = lf.replace('\n', "\r\n").replace(' ', "\t") + "\r\n\r\n  \r\n";
    assert_eq!(parse(&crlf).candela, plain.candela);
}

#[test]
fn missing_values_point_just_past_the_last_one() {
    // Two planes announced, one given: the error is at line 8, just after the last "0".
    let text = file(
        "IES:LM-63-2019\n[TEST] 1",
        "1 1000 1 3 2 1 2 0 0 0\n1 1 50\n0 45 90\n0 90\n100 80 0",
    );
    let (shown, line) = error(&text);
    assert_eq!(line, 8, "{shown}");
    assert!(shown.starts_with("bad.ies:8:9: truncated data"), "{shown}");
}
