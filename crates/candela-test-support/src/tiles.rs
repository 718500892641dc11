//! Comparing two estimators' renders tile by tile (`candela-core`'s `mis_consistency` and
//! `filter_splat` tests): each render's mean luminance per square tile is one observation,
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

/// Per tile (`tile` pixels square, of a `res` × `res` image), its mean luminance in each
/// of `renders` independent renders, `render(k)` making render k (its pixels, row major).
pub fn tile_means(
    renders: u64,
    res: u32,
    tile: u32,
    mut render: impl FnMut(u64) -> Vec<Vec3>,
) -> Vec<Vec<f64>> {
    let tiles = (res / tile) as usize;
    let mut out = vec![Vec::new(); tiles * tiles];
    for k in 0..renders {
        push_tile_means(&mut out, &render(k), res, tile);
    }
    out
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
