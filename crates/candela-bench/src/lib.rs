//! Candela's benchmark programs, one binary each in `src/bin/` (run by the scripts in
//! `bench/`, not by CI; `bench/README.md` says what each measures and `bench/RESULTS.md`
//! holds their current figures):
//!
//! - `traversal`: BVH build and closest-/any-hit rays per second (`bench/traversal.sh`);
//! - `many_lights`: light sampler build cost and equal-time relMSE
//!   (`bench/many_lights/run.sh`);
//! - `env_mis`: environment-light sampling strategies at equal spp (`bench/env_mis.sh`);
//! - `sampler_relmse`: the samplers at equal spp (`bench/sampler.sh`);
//! - `instancing`: memory and build time of instanced against flattened meshes;
//! - `lamp_sample_cost`: the cost of one next-event sample of a flat lamp.
//!
//! ```text
//! cargo run --release -p candela-bench --bin NAME -- ARGS
//! ```
//!
//! This library holds what several of them measure the same way.

use glam::Vec3;

/// CPU seconds (user + system, all threads) this process has used, from `/proc/self/stat`
/// (Linux; NaN elsewhere): on a shared machine wall time overstates the cost, CPU time
/// shows the work.
pub fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<f64> = after
        .split_whitespace()
        .filter_map(|x| x.parse().ok())
        .collect();
    // Fields 14 and 15 (utime, stime) in clock ticks, usually 100 per second; after the
    // ")" the first field is the state letter, which does not parse.
    f.get(10)
        .zip(f.get(11))
        .map_or(f64::NAN, |(u, s)| (u + s) / 100.0)
}

/// The relative mean squared error of an image against a reference: the mean over pixels
/// and channels of (x − ref)² / (ref² + 10⁻²), the metric of `bench/compare_mitsuba`
/// (the 10⁻² keeps black pixels from dominating).
pub fn rel_mse(x: &[Vec3], reference: &[Vec3]) -> f64 {
    let sum: f64 = x
        .iter()
        .zip(reference)
        .map(|(a, r)| {
            (0..3)
                .map(|c| {
                    let (a, r) = (a[c] as f64, r[c] as f64);
                    (a - r).powi(2) / (r * r + 1e-2)
                })
                .sum::<f64>()
        })
        .sum();
    sum / (3 * x.len()) as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rel_mse_is_the_mean_relative_squared_error() {
        let r = [Vec3::new(1.0, 0.0, 2.0), Vec3::ZERO];
        assert_eq!(rel_mse(&r, &r), 0.0);
        let x = [Vec3::new(2.0, 0.1, 2.0), Vec3::ZERO];
        // (1/1.01 + 0.01/0.01 + 0) / 6.
        let want = (1.0 / 1.01 + 1.0) / 6.0;
        assert!((rel_mse(&x, &r) - want).abs() < 1e-6, "{}", rel_mse(&x, &r));
    }

    #[test]
    fn cpu_seconds_grow_with_work() {
        let before = cpu_seconds();
        if before.is_nan() {
            return; // not Linux
        }
        // Spin until the clock (in ticks of 10 ms) shows 50 ms of work; a parse that
        // read the wrong fields would stand still and time out.
        let (mut x, t) = (0u64, std::time::Instant::now());
        while cpu_seconds() - before < 0.05 {
            assert!(t.elapsed().as_secs_f64() < 30.0, "CPU time did not grow");
            for _ in 0..100_000 {
                x = std::hint::black_box(x.wrapping_mul(6364136223846793005).wrapping_add(1));
            }
        }
    }
}
