//! Sample ranges merge into the single render bit for bit: for several splits of 0..N
//! (uneven, single samples, many parts, merged out of order), every pixel filter and
//! every sampler, through the library and through part files; and end to end through
//! `candela render --samples` and `candela merge`, with clear refusals of parts that do
//! not belong together.

use std::ops::Range;
use std::sync::atomic::AtomicBool;

use candela_cli::merge::{merge_parts, NamedPart};
use candela_cli::part::{decode_part, encode_part, PartInfo};
use candela_core::desc::{PixelFilterDesc, SamplerKind, SceneDesc};
use candela_core::film::Film;
use candela_core::fingerprint::fingerprint;
use candela_core::integrator::render;

mod common;
use common::{candela, s, SCENE};

const SPP: u32 = 12;

fn desc(filter: PixelFilterDesc, sampler: SamplerKind) -> SceneDesc {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, SCENE).unwrap();
    let mut d = candela_scene::load_scene(&path).unwrap();
    d.render.spp = SPP;
    d.render.filter = filter;
    d.render.sampler = sampler;
    d
}

fn film(desc: &SceneDesc, samples: Range<u32>) -> Film {
    let scene = candela_core::build::build(desc).unwrap();
    render(&scene, samples, &AtomicBool::new(false), &|_| {}).film
}

fn part(desc: &SceneDesc, samples: Range<u32>) -> NamedPart {
    let info = PartInfo {
        fingerprint: fingerprint(desc),
        seed: desc.render.seed,
        spp: desc.render.spp,
        samples: vec![samples.clone()],
    };
    // Through the file format, so that it too is proved exact.
    let bytes = encode_part(&film(desc, samples.clone()), &info).unwrap();
    let (film, info) = decode_part(&bytes).unwrap();
    NamedPart {
        name: format!("{}..{}", samples.start, samples.end),
        film,
        info,
    }
}

#[test]
fn every_split_merges_to_the_single_render_bit_for_bit() {
    let splits: [&[u32]; 5] = [
        &[6],                                 // halves
        &[1, 11],                             // uneven, single samples at both ends
        &[5],                                 // uneven
        &[1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11], // single samples
        &[3, 4, 9],                           // many, mixed
    ];
    let filters = [
        PixelFilterDesc::Box,
        PixelFilterDesc::Tent { radius: 1.5 },
        PixelFilterDesc::Gaussian {
            stddev: 0.5,
            radius: 2.0,
        },
    ];
    let samplers = [
        SamplerKind::Independent,
        SamplerKind::Sobol,
        SamplerKind::SobolCmj,
        SamplerKind::Zsobol,
    ];
    for filter in filters {
        for sampler in samplers {
            let d = desc(filter, sampler);
            let whole = film(&d, 0..SPP);
            for cuts in splits {
                let mut bounds = vec![0];
                bounds.extend_from_slice(cuts);
                bounds.push(SPP);
                let mut parts: Vec<NamedPart> =
                    bounds.windows(2).map(|b| part(&d, b[0]..b[1])).collect();
                // Out of order: last first, then the rest rotated.
                parts.reverse();
                parts.rotate_left(1);
                let (merged, info) = merge_parts(&parts).unwrap();
                assert!(info.is_complete());
                assert!(
                    merged == whole,
                    "{filter:?} {sampler:?} split at {cuts:?}: sums differ"
                );
                let same_bits =
                    merged.resolve().iter().zip(whole.resolve()).all(|(a, b)| {
                        a.to_array().map(f32::to_bits) == b.to_array().map(f32::to_bits)
                    });
                assert!(
                    same_bits,
                    "{filter:?} {sampler:?} split at {cuts:?}: image differs"
                );
            }
        }
    }
}

/// The pixels of an EXR's R, G, B channels, as bits.
fn rgb_bits(path: &std::path::Path) -> Vec<u32> {
    use exr::prelude::*;
    let image = read_first_flat_layer_from_file(path).unwrap();
    let mut out = Vec::new();
    for name in ["R", "G", "B"] {
        let c = image
            .layer_data
            .channel_data
            .list
            .iter()
            .find(|c| c.name == *name)
            .unwrap();
        match &c.sample_data {
            FlatSamples::F32(v) => out.extend(v.iter().map(|x| x.to_bits())),
            _ => panic!("{name} is not f32"),
        }
    }
    out
}

#[test]
fn cli_parts_merge_to_the_plain_render_and_mismatches_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(&scene, SCENE).unwrap();
    let p = |name: &str| dir.path().join(name);
    let run = |args: &[&str]| {
        let o = candela(args);
        assert!(
            o.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    };
    run(&["render", s(&scene), "--spp", "8", "-o", s(&p("whole.exr"))]);
    for (range, name) in [("5..8", "c.exr"), ("0..1", "a.exr"), ("1..5", "b.exr")] {
        run(&[
            "render",
            s(&scene),
            "--spp",
            "8",
            "--samples",
            range,
            "-o",
            s(&p(name)),
        ]);
    }
    run(&[
        "merge",
        s(&p("c.exr")),
        s(&p("a.exr")),
        s(&p("b.exr")),
        "-o",
        s(&p("m.exr")),
    ]);
    assert_eq!(rgb_bits(&p("m.exr")), rgb_bits(&p("whole.exr")));
    // A merged part merges again: (a + b) + c.
    run(&[
        "merge",
        s(&p("a.exr")),
        s(&p("b.exr")),
        "-o",
        s(&p("ab.exr")),
    ]);
    run(&[
        "merge",
        s(&p("ab.exr")),
        s(&p("c.exr")),
        "-o",
        s(&p("abc.pfm")),
    ]);
    let pfm = std::fs::read(p("abc.pfm")).unwrap();
    assert!(pfm.starts_with(b"PF\n24 16\n"));

    let refused = |args: &[&str], needle: &str| {
        let o = candela(args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        assert!(err.contains(needle), "{args:?}: {err}");
    };
    run(&[
        "render",
        s(&scene),
        "--spp",
        "8",
        "--seed",
        "3",
        "--samples",
        "5..8",
        "-o",
        s(&p("seed.exr")),
    ]);
    refused(
        &[
            "merge",
            s(&p("a.exr")),
            s(&p("seed.exr")),
            "-o",
            s(&p("x.exr")),
        ],
        "seed 3 differs from 0",
    );
    run(&[
        "render",
        s(&scene),
        "--spp",
        "8",
        "--res",
        "8x8",
        "--samples",
        "5..8",
        "-o",
        s(&p("res.exr")),
    ]);
    refused(
        &[
            "merge",
            s(&p("a.exr")),
            s(&p("res.exr")),
            "-o",
            s(&p("x.exr")),
        ],
        "resolution 8x8 differs",
    );
    run(&[
        "render",
        s(&scene),
        "--spp",
        "8",
        "--max-depth",
        "1",
        "--samples",
        "5..8",
        "-o",
        s(&p("depth.exr")),
    ]);
    refused(
        &[
            "merge",
            s(&p("a.exr")),
            s(&p("depth.exr")),
            "-o",
            s(&p("x.exr")),
        ],
        "different scene or settings",
    );
    refused(
        &[
            "merge",
            s(&p("ab.exr")),
            s(&p("b.exr")),
            "-o",
            s(&p("x.exr")),
        ],
        "overlap",
    );
    refused(
        &["merge", s(&p("whole.exr")), "-o", s(&p("x.exr"))],
        "not a Candela film part",
    );
    refused(
        &[
            "render",
            s(&scene),
            "--spp",
            "8",
            "--samples",
            "4..9",
            "-o",
            s(&p("x.exr")),
        ],
        "beyond the render's 8 spp",
    );
    refused(
        &[
            "render",
            s(&scene),
            "--samples",
            "0..2",
            "-o",
            s(&p("x.png")),
        ],
        "needs an .exr output",
    );
}
