//! The two compiled copies of the render loop (`candela_core::isa`) render the same films,
//! bit for bit: every example scene (every BSDF, light kind, texture, the thin lens, the
//! environment, the light BVH, a glTF file, a splatted filter) rendered small with each copy the CPU has.
//!
//! Bit equality is the right test, not a statistical one: both copies run the same
//! source with the same samples, and without `mul_add` or fast-math the compiler may
//! not change an operation's rounding, so any difference is a bug (an FMA contracted,
//! a reduction reordered).

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use candela_core::desc::Isa;
use candela_core::integrator::render;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Every pixel's sums and counts, as bits, and the ray count, of `file` rendered at
/// 40×30 with 4 spp by the copy `isa`.
fn film_bits(file: &str, isa: Isa) -> (Vec<i128>, u64) {
    let mut desc = candela_scene::load_scene(&root().join("scenes").join(file)).unwrap();
    desc.render.width = 40;
    desc.render.height = 30;
    desc.render.spp = 4;
    desc.render.isa = isa;
    let scene = candela_core::build::build(&desc).unwrap();
    let result = render(&scene, 0..4, &AtomicBool::new(false), &|_| {});
    let bits = result
        .film
        .pixels
        .iter()
        .flat_map(|p| {
            let [r, g, b] = p.radiance_sum.map(|s| s.to_bits());
            [
                r,
                g,
                b,
                p.weight_sum.to_bits(),
                p.samples.into(),
                p.rejected.into(),
            ]
        })
        .collect();
    (bits, result.stats.rays)
}

const SCENES: [&str; 14] = [
    "cornell.toml",
    "glass_sphere.toml",
    "rough_metals.toml",
    "microfacets.toml",
    "plastics.toml",
    "isometric.toml",
    "mix.toml",
    "dof.toml",
    "ies-room.toml",
    "textured-light.toml",
    "environment.toml",
    "many_lights.toml",
    "gltf/spheres.gltf",
    // A thin lens and a splatted Gaussian filter (the splat's AVX2 shares).
    "../bench/scenes/thin-lens.xml",
];

#[test]
fn every_copy_renders_the_same_films() {
    let available = Isa::available();
    assert_eq!(available[0], Isa::Baseline);
    if !Isa::V3.is_supported() {
        eprintln!(
            "NOTE: this CPU lacks x86-64-v3: only the baseline copy runs, so this test \
             compares nothing; it checks that the baseline renders, that auto picks it and \
             that asking for v3 is refused"
        );
        let refused = std::panic::catch_unwind(|| film_bits("cornell.toml", Isa::V3));
        assert!(refused.is_err(), "a v3 render ran on a CPU without v3");
    }
    assert_eq!(Isa::Auto.resolve(), *available.last().unwrap());
    for file in SCENES {
        let (base, base_rays) = film_bits(file, Isa::Baseline);
        assert!(base_rays > 0, "{file}: no rays");
        assert!(
            base.iter().any(|&b| b != 0),
            "{file}: an empty film compares equal to anything"
        );
        for &isa in &available[1..] {
            let (other, rays) = film_bits(file, isa);
            assert_eq!(rays, base_rays, "{file}: {isa:?} traced other rays");
            let differ = base.iter().zip(&other).filter(|(a, b)| a != b).count();
            assert_eq!(
                differ, 0,
                "{file}: {differ} film words differ under {isa:?}"
            );
        }
    }
}
