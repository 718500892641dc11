//! The glass-sphere and rough-metal-row example scenes, rendered small and compared per
//! tile with a committed reference.
//!
//! Each scene is rendered at 32×24 pixels, split into 4×3 tiles of 8×8; a tile's value is
//! the mean luminance of its pixels. The test renders K = 8 independent seeds at 16 spp
//! and compares the mean over seeds with the reference by Welch's t statistic (standard
//! error from the spread of the K seed means, combined with the reference's own). With
//! 24 tiles tested and heavy-tailed caustic noise, a tile fails only beyond |t| = 6
//! (7 degrees of freedom: two-sided p ≈ 5·10⁻⁴ per tile, ≈ 1% for the file by
//! Bonferroni), plus 1% of the value for f32 summation.
//!
//! The reference (`scenes/reference/*.tiles`) was made by this same renderer with 64
//! seeds × 64 spp (`CANDELA_WRITE_REFERENCE=1 cargo test --release -p candela-scene
//! --test material_scenes`). It is a regression guard; the BSDFs themselves are checked
//! independently by `candela-core/tests/bsdf_chi2.rs` and `bsdf_energy.rs`.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use candela_core::math::luminance;

const W: u32 = 32;
const H: u32 = 24;
const TILE: u32 = 8;
const TILES: usize = ((W / TILE) * (H / TILE)) as usize;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Tile means of one render of `spp` samples with `seed`.
fn render_tiles(scene_file: &str, seed: u64, spp: u32) -> Vec<f64> {
    let mut desc = candela_scene::load_scene(&root().join("scenes").join(scene_file)).unwrap();
    desc.render.width = W;
    desc.render.height = H;
    desc.render.spp = spp;
    desc.render.seed = seed;
    let scene = candela_core::build::build(&desc).unwrap();
    let film =
        candela_core::integrator::render(&scene, 0..spp, &AtomicBool::new(false), &|_| {}).film;
    let pixels = film.resolve();
    let mut tiles = vec![0.0; TILES];
    for y in 0..H {
        for x in 0..W {
            let t = ((y / TILE) * (W / TILE) + x / TILE) as usize;
            tiles[t] += luminance(pixels[(y * W + x) as usize]) as f64 / (TILE * TILE) as f64;
        }
    }
    tiles
}

/// Mean and standard error of the mean over `seeds` renders (seeds `first_seed..`), per
/// tile.
fn estimate(scene_file: &str, first_seed: u64, seeds: u64, spp: u32) -> Vec<(f64, f64)> {
    let runs: Vec<Vec<f64>> = (0..seeds)
        .map(|s| render_tiles(scene_file, first_seed + s, spp))
        .collect();
    (0..TILES)
        .map(|t| {
            let k = seeds as f64;
            let mean = runs.iter().map(|r| r[t]).sum::<f64>() / k;
            let var = runs.iter().map(|r| (r[t] - mean).powi(2)).sum::<f64>() / (k - 1.0);
            (mean, (var / k).sqrt())
        })
        .collect()
}

fn check(scene_file: &str, reference: &str) {
    let ref_path = root().join("scenes/reference").join(reference);
    if std::env::var("CANDELA_WRITE_REFERENCE").is_ok() {
        let est = estimate(scene_file, 5000, 64, 64);
        let text: String = est
            .iter()
            .map(|(m, se)| format!("{m:.6} {se:.6}\n"))
            .collect();
        std::fs::write(&ref_path, format!("# tile mean luminance, standard error ({W}x{H}, {TILE}px tiles, 64 seeds x 64 spp)\n{text}")).unwrap();
        return;
    }
    let text = std::fs::read_to_string(&ref_path).unwrap();
    let reference: Vec<(f64, f64)> = text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            (v[0], v[1])
        })
        .collect();
    assert_eq!(reference.len(), TILES);
    // Seeds disjoint from the reference's, so the two estimates are independent.
    let est = estimate(scene_file, 1000, 8, 16);
    for (t, ((m, se), (r, rse))) in est.iter().zip(&reference).enumerate() {
        let tol = 6.0 * (se * se + rse * rse).sqrt() + 0.01 * r;
        assert!(
            (m - r).abs() <= tol,
            "{scene_file} tile {t}: {m:.5} ± {se:.5} vs reference {r:.5} ± {rse:.5}"
        );
    }
}

#[test]
fn glass_sphere_matches_reference() {
    check("glass_sphere.toml", "glass_sphere.tiles");
}

#[test]
fn rough_metal_row_matches_reference() {
    check("rough_metals.toml", "rough_metals.tiles");
}
