//! Benchmark of the samplers (issue 10): each scene is rendered at equal spp with the
//! independent and the Sobol' sampler, several seeds each, and compared with one long
//! reference by relMSE = mean over pixels and channels of (x − ref)² / (ref² + 10⁻²), the
//! metric of `bench/compare_mitsuba`.
//!
//! Not part of CI. Run it through `bench/sampler.sh` (arguments below). The reference is
//! rendered with the Sobol' sampler at `--ref-spp` (seeds apart from the measured ones);
//! its own error adds to every relMSE alike and so pulls the ratio towards 1. The table
//! shows it, estimated from the reference's two halves, independent renders of two seeds
//! (their relMSE against each other is about twice a half's error, and their average has
//! half a half's error).
//!
//! ```text
//! sampler_relmse [--downscale N] [--spp 4,16,64] [--seeds N] [--ref-spp N]
//!                [--threads N] SCENE...
//! ```

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use candela_core::desc::{SamplerKind, SceneDesc};
use candela_core::integrator::render;
use glam::Vec3;

struct Args {
    scenes: Vec<PathBuf>,
    downscale: u32,
    spp: Vec<u32>,
    seeds: u64,
    ref_spp: u32,
    threads: usize,
}

fn parse_args() -> Result<Args, String> {
    let mut a = Args {
        scenes: Vec::new(),
        downscale: 2,
        spp: vec![4, 16, 64],
        seeds: 4,
        ref_spp: 4096,
        threads: 2,
    };
    let mut it = std::env::args().skip(1);
    while let Some(arg) = it.next() {
        let mut value = || it.next().ok_or(format!("{arg} needs a value"));
        let bad = |e: std::num::ParseIntError| format!("{arg}: {e}");
        match arg.as_str() {
            "--downscale" => a.downscale = value()?.parse().map_err(bad)?,
            "--spp" => {
                a.spp = value()?
                    .split(',')
                    .map(|s| s.trim().parse().map_err(bad))
                    .collect::<Result<_, _>>()?
            }
            "--seeds" => a.seeds = value()?.parse().map_err(bad)?,
            "--ref-spp" => a.ref_spp = value()?.parse().map_err(bad)?,
            "--threads" => a.threads = value()?.parse().map_err(bad)?,
            s if s.starts_with("--") => return Err(format!("unknown option {s}")),
            s => a.scenes.push(s.into()),
        }
    }
    if a.scenes.is_empty() || a.downscale == 0 || a.seeds == 0 || a.ref_spp < 2 {
        return Err(
            "usage: sampler_relmse [--downscale N] [--spp 4,16,64] [--seeds N] \
                    [--ref-spp N] [--threads N] SCENE..."
                .into(),
        );
    }
    Ok(a)
}

/// Renders samples `range` with a sampler and seed; returns the image and the seconds.
fn image(
    desc: &SceneDesc,
    sampler: SamplerKind,
    seed: u64,
    range: std::ops::Range<u32>,
) -> (Vec<Vec3>, f64) {
    let mut desc = desc.clone();
    desc.render.sampler = sampler;
    desc.render.seed = seed;
    let scene = candela_core::build::build(&desc).expect("scene builds");
    let t = Instant::now();
    let r = render(&scene, range, &AtomicBool::new(false), &|_| {});
    (r.film.resolve(), t.elapsed().as_secs_f64())
}

fn rel_mse(x: &[Vec3], reference: &[Vec3]) -> f64 {
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

/// Mean and standard error of the mean.
fn mean_se(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    (m, (var / n).sqrt())
}

fn main() {
    let args = match parse_args() {
        Ok(a) => a,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads)
        .build_global()
        .expect("thread pool");
    println!(
        "`bench/sampler.sh --downscale {} --spp {} --seeds {} --ref-spp {} --threads {} {}`\n",
        args.downscale,
        args.spp
            .iter()
            .map(u32::to_string)
            .collect::<Vec<_>>()
            .join(","),
        args.seeds,
        args.ref_spp,
        args.threads,
        args.scenes
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(" ")
    );
    println!(
        "| scene | res | spp | relMSE independent | relMSE Sobol' | independent ÷ Sobol' | \
         time ind. s | time Sobol' s |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for path in &args.scenes {
        let mut desc = match candela_scene::load_scene(path) {
            Ok(d) => d,
            Err(e) => {
                eprintln!("{e}");
                std::process::exit(2);
            }
        };
        let r = &mut desc.render;
        r.width = (r.width / args.downscale).max(1);
        r.height = (r.height / args.downscale).max(1);
        let res = format!("{}×{}", r.width, r.height);
        // The reference: two independent renders (two seeds) averaged, and their
        // disagreement.
        let half = args.ref_spp / 2;
        let (a, _) = image(&desc, SamplerKind::Sobol, 1_000_003, 0..half);
        let (b, _) = image(&desc, SamplerKind::Sobol, 1_000_004, 0..half);
        let reference: Vec<Vec3> = a.iter().zip(&b).map(|(x, y)| (*x + *y) * 0.5).collect();
        let ref_noise = rel_mse(&a, &b) / 4.0;
        for &spp in &args.spp {
            let mut rows = Vec::new();
            for kind in [SamplerKind::Independent, SamplerKind::Sobol] {
                let (mut errs, mut time) = (Vec::new(), 0.0);
                for seed in 0..args.seeds {
                    let (img, t) = image(&desc, kind, seed, 0..spp);
                    errs.push(rel_mse(&img, &reference));
                    time += t / args.seeds as f64;
                }
                rows.push((mean_se(&errs), time));
            }
            let (((mi, si), ti), ((ms, ss), ts)) = (rows[0], rows[1]);
            println!(
                "| {} | {res} | {spp} | {mi:.3e} ± {si:.1e} | {ms:.3e} ± {ss:.1e} | {:.2} | \
                 {ti:.2} | {ts:.2} |",
                path.display(),
                mi / ms
            );
        }
        println!(
            "| {} | {res} | reference {} | its own relMSE ≈ {ref_noise:.1e} | | | | |",
            path.display(),
            2 * half
        );
    }
    println!(
        "\nrelMSE = mean (x − ref)²/(ref² + 10⁻²); mean ± standard error over {} seeds.",
        args.seeds
    );
}
