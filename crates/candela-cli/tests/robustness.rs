//! The CLI under hostile input and failure: every loader's error is one located line
//! with exit 2, a panic is exit 101 asking for a report, SIGTERM and Ctrl-C write the
//! partial image atomically, and a write that fails (disk full, a path that cannot
//! exist, a read-only folder) leaves the previous output byte for byte.

use std::path::PathBuf;
use std::process::{Command, Output, Stdio};

mod common;
use common::{candela, command, s, SCENE};

/// A folder holding `scene.toml` (SCENE plus `extra`) and the given files.
fn scene_with(extra: &str, files: &[(&str, &[u8])]) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(&scene, format!("{SCENE}\n{extra}")).unwrap();
    for (name, bytes) in files {
        std::fs::write(dir.path().join(name), bytes).unwrap();
    }
    (dir, scene)
}

/// Exit 2 and one line on stderr holding every needle.
fn assert_user_error(o: &Output, needles: &[&str]) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
    for n in needles {
        assert!(err.contains(n), "{n:?} missing from: {err}");
    }
}

/// A scene addition, the file it refers to (name, bytes), and what its error must hold.
type Case<'a> = (String, (&'a str, &'a [u8]), Vec<&'a str>);

const MESH_SHAPE: &str = "[[shape]]\ntype = \"mesh\"\nfile = \"FILE\"\nmaterial = \"white\"\n";

#[test]
fn every_loader_error_is_one_located_line_with_exit_2() {
    let huge_hdr: &[u8] = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 100000 +X 100000\n\x80\x80";
    let ply = b"ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\n\
        property float x\nproperty float y\nproperty float z\nelement face 1\n\
        property list uchar int vertex_indices\nend_header\n\0\0";
    let cases: Vec<Case> = vec![
        (
            MESH_SHAPE.replace("FILE", "bad.obj"),
            ("bad.obj", b"v 0 0 0\nv 1 0 0\nv 0 x 0\nf 1 2 3\n"),
            vec!["scene.toml:", "bad.obj:3:"],
        ),
        (
            MESH_SHAPE.replace("FILE", "huge.ply"),
            ("huge.ply", ply),
            vec!["scene.toml:", "huge.ply", "truncated or corrupt"],
        ),
        (
            "[[light]]\ntype = \"point\"\nposition = [0, 2, 0]\nintensity = 1\nies = \"bad.ies\"\n"
                .into(),
            ("bad.ies", b"IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 3 1 1 2 0 0 0\n1 1 0\n0 45\n"),
            vec!["bad.ies:"],
        ),
        (
            "[environment]\nequirect = \"huge.hdr\"\n".into(),
            ("huge.hdr", huge_hdr),
            vec!["scene.toml:", "huge.hdr", "100000x100000"],
        ),
        (
            "[environment]\nequirect = \"bad.exr\"\n".into(),
            ("bad.exr", b"v/1\x01\x02\0\0\0junk"),
            vec!["scene.toml:", "bad.exr"],
        ),
        (
            "[materials.tex]\ntype = \"diffuse\"\nalbedo = { type = \"image\", file = \"bad.png\" }\n"
                .into(),
            ("bad.png", b"\x89PNG\r\n\x1a\nnot really"),
            vec!["scene.toml:", "bad.png"],
        ),
    ];
    for (extra, file, needles) in cases {
        let (dir, scene) = scene_with(&extra, &[file]);
        let o = candela(&["render", s(&scene), "-o", s(&dir.path().join("x.png"))]);
        assert_user_error(&o, &needles);
        assert!(!dir.path().join("x.png").exists());
    }
}

#[test]
fn mitsuba_errors_are_located_lines_with_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&str, &[&str]); 2] = [
        (
            "<scene version=\"3.0.0\">\n  <shape type=\"obj\">\n</scene>\n",
            &["m.xml:3:", "XML"],
        ),
        (
            "<scene version=\"3.0.0\">\n<shape type=\"ply\"><string name=\"filename\" \
             value=\"huge.ply\"/></shape>\n</scene>\n",
            &["m.xml:2:", "huge.ply", "truncated or corrupt"],
        ),
    ];
    std::fs::write(
        dir.path().join("huge.ply"),
        "ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\nend_header\n",
    )
    .unwrap();
    for (xml, needles) in cases {
        let scene = dir.path().join("m.xml");
        std::fs::write(&scene, xml).unwrap();
        let o = candela(&["render", s(&scene), "-o", s(&dir.path().join("x.png"))]);
        assert_user_error(&o, needles);
    }
}

#[test]
fn an_internal_error_exits_101_and_asks_for_a_report() {
    let o = command()
        .args(["info", "x.toml"])
        .env("CANDELA_TEST_INTERNAL_ERROR", "1")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(101));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("candela: internal error:"), "{err}");
    assert!(err.contains("please report it"), "{err}");
}

/// Sends `signal` to a long render and checks that the previous file was replaced by a
/// whole partial image, atomically, and exited with the shell's `status` for it.
fn a_signal_writes_the_partial_image_atomically(signal: &str, status: i32) {
    let (dir, scene) = scene_with("", &[]);
    let out = dir.path().join("partial.pfm");
    std::fs::write(&out, b"previous image").unwrap();
    let child = command()
        .args([
            "render",
            s(&scene),
            "-o",
            s(&out),
            "--spp",
            "2000000",
            "--threads",
            "1",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1500));
    let killed = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(status), "{err}");
    assert!(err.contains("partial image"), "{err}");
    // A whole image replaced the old file: header, exactly 24·16·3 floats, all finite.
    let bytes = std::fs::read(&out).unwrap();
    let header = b"PF\n24 16\n-1.0\n";
    assert!(
        bytes.starts_with(header),
        "{:?}",
        &bytes[..16.min(bytes.len())]
    );
    let floats: Vec<f32> = bytes[header.len()..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
        .collect();
    assert_eq!(floats.len(), 24 * 16 * 3);
    assert!(floats.iter().any(|&v| v > 0.0) && floats.iter().all(|v| v.is_finite()));
    // No temporary file is left beside it.
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    assert!(names.iter().all(|n| !n.ends_with(".tmp")), "{names:?}");
}

#[cfg(unix)]
#[test]
fn sigterm_writes_the_partial_image_atomically() {
    a_signal_writes_the_partial_image_atomically("-TERM", 143);
}

#[cfg(unix)]
#[test]
fn ctrl_c_writes_the_partial_image_atomically() {
    a_signal_writes_the_partial_image_atomically("-INT", 130);
}

/// Whether this process runs as root (for whom a read-only folder is still writable).
fn is_root() -> bool {
    let o = Command::new("id").arg("-u").output().unwrap();
    String::from_utf8_lossy(&o.stdout).trim() == "0"
}

#[cfg(unix)]
#[test]
fn a_full_disk_keeps_the_previous_output_intact() {
    // RLIMIT_FSIZE holds for root too: a file may not grow past 1 KiB, and the write
    // fails with EFBIG as on a full disk (SIGXFSZ ignored, as `trap ''` passes on).
    let (dir, scene) = scene_with("", &[]);
    let out = dir.path().join("keep.pfm");
    let previous: Vec<u8> = (0..=255).collect();
    std::fs::write(&out, &previous).unwrap();
    let o = Command::new("sh")
        .args(["-c", "trap '' XFSZ; ulimit -f 2; exec \"$0\" \"$@\""])
        .arg(env!("CARGO_BIN_EXE_candela"))
        .args(["render", s(&scene), "-o", s(&out)])
        .output()
        .unwrap();
    assert_user_error(&o, &["keep.pfm: cannot write:", "too large"]);
    assert_eq!(std::fs::read(&out).unwrap(), previous);
    let left = std::fs::read_dir(dir.path()).unwrap().count();
    assert_eq!(left, 2, "only the scene and the old image remain");
}

#[cfg(unix)]
#[test]
fn paths_that_cannot_be_written_are_clear_errors() {
    let (dir, scene) = scene_with("", &[]);
    // Under a regular file (ENOTDIR), and in /proc: both fail for root too.
    let file = dir.path().join("a-file");
    std::fs::write(&file, b"x").unwrap();
    for out in [file.join("x.png"), PathBuf::from("/proc/candela-test.png")] {
        let o = candela(&["render", s(&scene), "-o", s(&out)]);
        assert_user_error(&o, &[&format!("{}: cannot write:", out.display())]);
    }
    assert_eq!(std::fs::read(&file).unwrap(), b"x");
}

#[cfg(unix)]
#[test]
fn a_read_only_folder_keeps_the_previous_output_intact() {
    use std::os::unix::fs::PermissionsExt;
    if is_root() {
        eprintln!("skipping: root writes into read-only folders (see the full-disk test)");
        return;
    }
    let (dir, scene) = scene_with("", &[]);
    let ro = dir.path().join("ro");
    std::fs::create_dir(&ro).unwrap();
    let out = ro.join("keep.png");
    std::fs::write(&out, b"previous image").unwrap();
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
    let o = candela(&["render", s(&scene), "-o", s(&out)]);
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o755)).unwrap();
    assert_user_error(&o, &["keep.png: cannot write:"]);
    assert_eq!(std::fs::read(&out).unwrap(), b"previous image");
}

#[test]
fn a_resolution_past_the_pixel_cap_is_an_error_not_an_abort() {
    let (dir, scene) = scene_with("", &[]);
    let huge = dir.path().join("huge.toml");
    std::fs::write(
        &huge,
        SCENE.replace("resolution = [24, 16]", "resolution = [100000, 100000]"),
    )
    .unwrap();
    let out = dir.path().join("x.png");
    let o = candela(&["render", s(&huge), "-o", s(&out)]);
    assert_user_error(&o, &["huge.toml:3:14:", "100000x100000", "more than"]);
    let o = candela(&["render", s(&scene), "-o", s(&out), "--res", "100000x100000"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("more than"));
    // A wide image under the cap is not refused.
    let o = candela(&[
        "render",
        s(&scene),
        "-o",
        s(&out),
        "--res",
        "8192x1",
        "--spp",
        "1",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}
