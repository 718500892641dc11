//! Resource limits: hostile headers are rejected before anything is allocated for them,
//! and no loader allocates more than its file's budget (`candela_scene::limits`: 64 ×
//! the file's size + 256 MiB). A counting allocator measures each parse's peak heap.

use std::alloc::{GlobalAlloc, Layout, System};
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

use candela_scene::image_texture::{decode_image, Encoding};
use candela_scene::limits::allocation_budget;

struct Counting;

static LIVE: AtomicU64 = AtomicU64::new(0);
static PEAK: AtomicU64 = AtomicU64::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        grow(layout.size() as u64);
        System.alloc(layout)
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        grow(layout.size() as u64);
        System.alloc_zeroed(layout)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        LIVE.fetch_sub(layout.size() as u64, Ordering::SeqCst);
        System.dealloc(ptr, layout)
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if new_size >= layout.size() {
            grow((new_size - layout.size()) as u64);
        } else {
            LIVE.fetch_sub((layout.size() - new_size) as u64, Ordering::SeqCst);
        }
        System.realloc(ptr, layout, new_size)
    }
}

fn grow(bytes: u64) {
    let live = LIVE.fetch_add(bytes, Ordering::SeqCst) + bytes;
    PEAK.fetch_max(live, Ordering::SeqCst);
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Tests share the counters: one measures at a time.
static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

/// Runs `f` and returns its result and the peak heap growth while it ran.
fn peak_of<R>(f: impl FnOnce() -> R) -> (R, u64) {
    let base = LIVE.load(Ordering::SeqCst);
    PEAK.store(base, Ordering::SeqCst);
    let r = f();
    (r, PEAK.load(Ordering::SeqCst) - base)
}

/// CRC-32 (ISO-HDLC, as PNG uses) of `bytes`.
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 == 1 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

/// A PNG whose IHDR claims `w × h` RGB pixels, with one tiny IDAT and valid CRCs.
fn png_claiming(w: u32, h: u32) -> Vec<u8> {
    let chunk = |kind: &[u8], data: &[u8]| {
        let mut c = (data.len() as u32).to_be_bytes().to_vec();
        let mut body = kind.to_vec();
        body.extend_from_slice(data);
        c.extend_from_slice(&body);
        c.extend_from_slice(&crc32(&body).to_be_bytes());
        c
    };
    let mut ihdr = w.to_be_bytes().to_vec();
    ihdr.extend_from_slice(&h.to_be_bytes());
    ihdr.extend_from_slice(&[8, 2, 0, 0, 0]);
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    png.extend(chunk(b"IHDR", &ihdr));
    png.extend(chunk(
        b"IDAT",
        &[0x78, 0x9c, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01],
    ));
    png.extend(chunk(b"IEND", &[]));
    png
}

/// An EXR of 1×1 pixel whose data window is then widened to `w × h`.
fn exr_claiming(w: i32, h: i32) -> Vec<u8> {
    use exr::prelude::*;
    let mut bytes = Vec::new();
    let image = Image::from_channels((1, 1), SpecificChannels::rgb(|_| (0.5f32, 0.5f32, 0.5f32)));
    image
        .write()
        .to_buffered(std::io::Cursor::new(&mut bytes))
        .unwrap();
    let key = b"dataWindow\0box2i\0\x10\0\0\0";
    let at = bytes.windows(key.len()).position(|w| w == key).unwrap() + key.len();
    bytes[at + 8..at + 12].copy_from_slice(&(w - 1).to_le_bytes());
    bytes[at + 12..at + 16].copy_from_slice(&(h - 1).to_le_bytes());
    bytes
}

#[test]
fn images_claiming_100000_squared_pixels_are_rejected_within_budget() {
    let _one = ONE_AT_A_TIME.lock().unwrap();
    let hdr =
        b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 100000 +X 100000\n\x80\x80\x80\x81".to_vec();
    let cases = [
        ("huge.png", png_claiming(100_000, 100_000)),
        ("huge.hdr", hdr),
        ("huge.exr", exr_claiming(100_000, 100_000)),
    ];
    for (name, bytes) in cases {
        let (result, peak) = peak_of(|| decode_image(&bytes, Path::new(name), Encoding::Srgb));
        let e = result.unwrap_err();
        assert!(
            e.starts_with(&format!("{name}: cannot read image: ")),
            "{e}"
        );
        assert!(
            e.contains("100000x100000"),
            "{name}: says what was declared: {e}"
        );
        assert!(!e.contains('\n'), "{e}");
        // Rejected from the header: well under a megabyte, not the budget's 256 MiB.
        assert!(peak < 1 << 20, "{name}: peak {peak} bytes");
    }
    // The same files with honest sizes decode: the check is not what fails above.
    let ok = exr_claiming(1, 1);
    assert!(decode_image(&ok, Path::new("ok.exr"), Encoding::Srgb).is_ok());
}

#[test]
fn hostile_mesh_headers_are_errors_without_large_allocations() {
    let _one = ONE_AT_A_TIME.lock().unwrap();
    let ply = "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\n\
        property float x\nproperty float y\nproperty float z\n\
        element face 4000000000\nproperty list uchar int vertex_indices\nend_header\n\0\0\0\0";
    let (r, peak) = peak_of(|| candela_scene::ply::parse_ply(ply.as_bytes(), Path::new("h.ply")));
    assert!(r.unwrap_err().message.contains("truncated or corrupt"));
    assert!(peak < 1 << 20, "ply: peak {peak} bytes");

    // Indices far past the vertices, and past u32.
    for face in [
        "f 1 2 4000000000",
        "f 1 2 99999999999999999999",
        "f -4000000000 1 2",
    ] {
        let obj = format!("v 0 0 0\nv 1 0 0\nv 0 1 0\n{face}\n");
        let (r, peak) =
            peak_of(|| candela_scene::obj::parse_obj(obj.as_bytes(), Path::new("h.obj")));
        assert!(r.is_err(), "{face}");
        assert!(peak < 1 << 20, "obj {face}: peak {peak} bytes");
    }

    // 10⁹ × 10⁹ angles with no data behind them.
    let ies = "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 1000000000 1000000000 1 2 0 0 0\n1 1 0\n0\n";
    let (r, peak) = peak_of(|| candela_scene::ies::parse_ies(ies.as_bytes(), "h.ies"));
    let e = r.unwrap_err();
    assert!(e.to_string().starts_with("h.ies:"), "{e}");
    assert!(peak < 1 << 20, "ies: peak {peak} bytes");
}

/// A binary PLY grid of `n × n` vertices with normals and uvs, two triangles a cell.
fn ply_grid(n: u32) -> Vec<u8> {
    let cells = (n - 1) * (n - 1);
    let mut bytes = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\n\
         property float y\nproperty float z\nproperty float nx\nproperty float ny\n\
         property float nz\nproperty float u\nproperty float v\nelement face {}\n\
         property list uchar uint vertex_indices\nend_header\n",
        n * n,
        2 * cells
    )
    .into_bytes();
    for y in 0..n {
        for x in 0..n {
            for v in [x as f32, y as f32, 0.0, 0.0, 0.0, 1.0, x as f32, y as f32] {
                bytes.extend(v.to_le_bytes());
            }
        }
    }
    for y in 0..n - 1 {
        for x in 0..n - 1 {
            let i = y * n + x;
            for t in [[i, i + 1, i + n], [i + 1, i + n + 1, i + n]] {
                bytes.push(3);
                for v in t {
                    bytes.extend(v.to_le_bytes());
                }
            }
        }
    }
    bytes
}

#[test]
fn honest_large_files_stay_within_the_multiple() {
    let _one = ONE_AT_A_TIME.lock().unwrap();
    // About 4 MB: the multiple, not the 256 MiB constant, is what is measured.
    let ply = ply_grid(300);
    let (mesh, peak) = peak_of(|| candela_scene::ply::parse_ply(&ply, Path::new("g.ply")));
    assert_eq!(mesh.unwrap().indices.len(), 2 * 299 * 299);
    let ratio = peak as f64 / ply.len() as f64;
    eprintln!(
        "binary ply: {} bytes, peak {peak} bytes ({ratio:.1}x)",
        ply.len()
    );
    assert!(
        peak <= allocation_budget(ply.len()) - (256 << 20),
        "{ratio:.1}x its size"
    );
    // Read straight into the mesh: about one byte of mesh a byte of file.
    assert!(peak <= 2 * ply.len() as u64, "{ratio:.1}x its size");

    // Ascii with one-digit numbers: the most elements per byte an ascii PLY can hold.
    let mut ascii = ply_grid(2)[..0].to_vec();
    let header = String::from_utf8_lossy(
        &ply[..ply.windows(11).position(|w| w == b"end_header\n").unwrap() + 11],
    )
    .replace("binary_little_endian", "ascii")
    .replace("element face 178802", "element face 0");
    ascii.extend(header.as_bytes());
    for _ in 0..300 * 300 {
        ascii.extend(b"0 0 0 0 0 1 0 0\n");
    }
    let (r, peak) = peak_of(|| candela_scene::ply::parse_ply(&ascii, Path::new("a.ply")));
    assert!(r.unwrap_err().message.contains("no faces"));
    let ratio = peak as f64 / ascii.len() as f64;
    eprintln!(
        "ascii ply: {} bytes, peak {peak} bytes ({ratio:.1}x)",
        ascii.len()
    );
    // The reader puts each number in its place in the mesh, 4 bytes for at least 2 of
    // the file: twice its size, and the header's own structures.
    assert!(peak <= 3 * ascii.len() as u64, "{ratio:.1}x its size");
    assert!(peak <= allocation_budget(ascii.len()));
    // Twenty times as many vertices load in the same proportion.
    let big_header = header.replace("element vertex 90000", "element vertex 1800000");
    let mut big = big_header.into_bytes();
    for _ in 0..1_800_000 {
        big.extend(b"0 0 0 0 0 1 0 0\n");
    }
    let (r, peak) = peak_of(|| candela_scene::ply::parse_ply(&big, Path::new("b.ply")));
    assert!(r.unwrap_err().message.contains("no faces"));
    assert!(
        peak <= 3 * big.len() as u64,
        "peak {peak} bytes for {}",
        big.len()
    );

    let mut obj = String::new();
    for y in 0..300 {
        for x in 0..300 {
            obj += &format!("v {x} {y} 0\nvt {x} {y}\n");
        }
    }
    for y in 0..299 {
        for x in 0..299 {
            let i = y * 300 + x + 1;
            obj += &format!("f {i}/{i} {}/{} {}/{}\n", i + 1, i + 1, i + 300, i + 300);
        }
    }
    let (mesh, peak) =
        peak_of(|| candela_scene::obj::parse_obj(obj.as_bytes(), Path::new("g.obj")));
    assert_eq!(mesh.unwrap().indices.len(), 299 * 299);
    let ratio = peak as f64 / obj.len() as f64;
    eprintln!("obj: {} bytes, peak {peak} bytes ({ratio:.1}x)", obj.len());
    assert!(
        peak <= allocation_budget(obj.len()) - (256 << 20),
        "{ratio:.1}x its size"
    );
}
