//! Comparing two estimators' renders tile by tile (`mis_consistency.rs`,
//! `filter_splat.rs`): each render's mean luminance per square tile is one observation,
//! and Welch's t-test compares two sets of renders tile by tile.

use candela_core::chi2::welch_p_samples;
use candela_core::math::luminance;
use glam::Vec3;

/// Appends to `out[t]` the mean luminance of tile t of `img` (`res` × `res` pixels, row
/// major, tiles `tile` pixels square, row major).
pub fn push_tile_means(out: &mut [Vec<f64>], img: &[Vec3], res: u32, tile: u32) {
    let mut sums = vec![0.0f64; out.len()];
    for (i, v) in img.iter().enumerate() {
        let (x, y) = (i as u32 % res, i as u32 / res);
        sums[((y / tile) * (res / tile) + x / tile) as usize] += luminance(*v) as f64;
    }
    for (t, s) in sums.iter().enumerate() {
        out[t].push(s / (tile * tile) as f64);
    }
}

/// Tiles (index, p-value) whose Welch test rejects equality at `alpha`.
pub fn failing_tiles(a: &[Vec<f64>], b: &[Vec<f64>], alpha: f64) -> Vec<(usize, f64)> {
    a.iter()
        .zip(b)
        .enumerate()
        .map(|(i, (x, y))| (i, welch_p_samples(x, y)))
        .filter(|&(_, p)| p < alpha)
        .collect()
}
