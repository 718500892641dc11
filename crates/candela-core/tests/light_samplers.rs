//! Light selection: every sampler's pmf sums to one and matches the frequencies of its
//! picks (chi-square), and RIS's weight is unbiased per light (z-tests).
//!
//! The chi-square is `candela_core::chi2::discrete` (cells with fewer than 5 expected
//! picks pooled, p-value from the incomplete gamma function; it also fails on any pick of
//! a probability-0 light and on a pmf that does not sum to one).

use candela_core::chi2::{discrete, sidak_alpha};
use candela_core::desc::LightSamplerKind;
use candela_core::light::{Light, LightId, PointLight, ShadingCtx, SphereLight, TriangleLight};
use candela_core::light_sampler::LightSampler;
use candela_core::sampler::Pcg32;
use glam::Vec3;

/// 64 lights around the origin with powers log-uniform over three decades: triangles
/// facing in random directions (some away from every test point), spheres and points.
fn lights() -> Vec<Light> {
    let mut rng = Pcg32::new(7, 1);
    let mut u = move || rng.uniform_f32();
    let mut out = Vec::new();
    for i in 0..64 {
        let c = Vec3::new(8.0 * u() - 4.0, 3.0 * u() + 0.5, 8.0 * u() - 4.0);
        let scale = 10f32.powf(3.0 * u());
        let color = Vec3::new(0.2 + u(), 0.2 + u(), 0.2 + u()) * scale;
        out.push(match i % 4 {
            0 | 1 => {
                let a = Vec3::new(u() - 0.5, u() - 0.5, u() - 0.5) * 0.6;
                let b = Vec3::new(u() - 0.5, u() - 0.5, u() - 0.5) * 0.6;
                let n = a.cross(b).normalize();
                Light::Triangle(TriangleLight::new([c, c + a, c + b], n, color))
            }
            2 => Light::Sphere(SphereLight {
                center: c,
                radius: 0.05 + 0.1 * u(),
                le: color,
                inward: false,
            }),
            _ => Light::Point(PointLight {
                position: c,
                intensity: color,
            }),
        });
    }
    out
}

fn contexts() -> [ShadingCtx; 4] {
    [
        ShadingCtx {
            p: Vec3::ZERO,
            n: Vec3::Y,
        },
        ShadingCtx {
            p: Vec3::new(3.0, 0.0, -3.0),
            n: Vec3::new(-1.0, 1.0, 0.0).normalize(),
        },
        ShadingCtx {
            p: Vec3::new(0.5, 2.0, 0.5),
            n: Vec3::ZERO,
        },
        ShadingCtx {
            p: Vec3::new(-6.0, 1.0, 6.0),
            n: Vec3::X,
        },
    ]
}

const SAMPLES: usize = 200_000;

#[test]
fn pmfs_sum_to_one_and_match_pick_frequencies() {
    let lights = lights();
    let kinds = [
        LightSamplerKind::Uniform,
        LightSamplerKind::Power,
        LightSamplerKind::Array,
        LightSamplerKind::Bvh,
    ];
    // 16 tests; Šidák-corrected so that the suite falsely fails with probability 1%.
    let alpha = sidak_alpha(0.01, kinds.len() * contexts().len());
    for kind in kinds {
        let sampler = LightSampler::new(kind, 8, &lights);
        for (ci, ctx) in contexts().iter().enumerate() {
            let pmf: Vec<f64> = (0..lights.len() as u32)
                .map(|i| sampler.pmf(ctx, LightId(i)) as f64)
                .collect();
            let mut counts = vec![0u64; lights.len()];
            let mut rng = Pcg32::new(11, ci as u64);
            for _ in 0..SAMPLES {
                let pick = sampler
                    .sample(ctx, rng.uniform_f32(), &lights)
                    .expect("some light reaches every test point");
                let i = pick.id.0 as usize;
                // The pmf a pick reports is the one `pmf` gives for MIS.
                assert!((pick.pmf as f64 / pmf[i] - 1.0).abs() < 1e-4);
                assert_eq!(pick.pmf, pick.mis_pmf);
                counts[i] += 1;
            }
            let report = discrete(&format!("{kind:?} at ctx {ci}"), &counts, &pmf, alpha);
            eprintln!(
                "{kind:?} ctx {ci}: χ² = {:.1}, dof {}, p = {:.3}",
                report.statistic, report.dof, report.p_value
            );
            report.assert_passed();
        }
    }
}

/// Trees of at most `FLAT_MAX` lights are sampled flat: each light in proportion to its
/// own bounds' importance at the point (checked exactly against `LightBounds::importance`),
/// and the picks follow that pmf (chi-square, 3, 6 and 8 lights at the four points).
#[test]
fn small_bvh_picks_each_light_by_its_own_importance() {
    use candela_core::light_sampler::FLAT_MAX;
    let all = lights();
    let sizes = [3, 6, FLAT_MAX];
    // 12 tests; Šidák-corrected so that the suite falsely fails with probability 1%.
    let alpha = sidak_alpha(0.01, sizes.len() * contexts().len());
    for n in sizes {
        // Every fourth light is a point (which reaches every test point), so each set
        // has some light that can contribute everywhere.
        let lights: Vec<Light> = all.iter().skip(1).step_by(2).take(n).cloned().collect();
        let sampler = LightSampler::new(LightSamplerKind::Bvh, 8, &lights);
        for (ci, ctx) in contexts().iter().enumerate() {
            let importance: Vec<f64> = lights
                .iter()
                .map(|l| l.bounds().unwrap().importance(ctx) as f64)
                .collect();
            let total: f64 = importance.iter().sum();
            let pmf: Vec<f64> = (0..n as u32)
                .map(|i| sampler.pmf(ctx, LightId(i)) as f64)
                .collect();
            for i in 0..n {
                let want = importance[i] / total;
                assert!(
                    (pmf[i] - want).abs() <= 1e-5 * want.max(1e-3),
                    "n {n} ctx {ci} light {i}"
                );
            }
            let mut counts = vec![0u64; n];
            let mut rng = Pcg32::new(29, ci as u64);
            for _ in 0..SAMPLES {
                let pick = sampler
                    .sample(ctx, rng.uniform_f32(), &lights)
                    .expect("some light reaches every test point");
                assert_eq!(pick.pmf, sampler.pmf(ctx, pick.id));
                counts[pick.id.0 as usize] += 1;
            }
            let report = discrete(
                &format!("flat BVH of {n} at ctx {ci}"),
                &counts,
                &pmf,
                alpha,
            );
            report.assert_passed();
        }
    }
}

/// The check above has teeth: the BVH's picks at one point tested against its pmf at
/// another point (a plausible bug: a stale shading context) fail.
#[test]
fn chi_square_catches_a_pmf_from_the_wrong_point() {
    let lights = lights();
    let sampler = LightSampler::new(LightSamplerKind::Bvh, 8, &lights);
    let [a, b, ..] = contexts();
    let pmf: Vec<f64> = (0..lights.len() as u32)
        .map(|i| sampler.pmf(&b, LightId(i)) as f64)
        .collect();
    let mut counts = vec![0u64; lights.len()];
    let mut rng = Pcg32::new(17, 0);
    for _ in 0..SAMPLES {
        if let Some(pick) = sampler.sample(&a, rng.uniform_f32(), &lights) {
            counts[pick.id.0 as usize] += 1;
        }
    }
    assert!(!discrete("wrong point", &counts, &pmf, 0.01).passed());
}

#[test]
fn bvh_gives_zero_only_to_lights_that_cannot_reach_the_point() {
    let lights = lights();
    let sampler = LightSampler::new(LightSamplerKind::Bvh, 8, &lights);
    for ctx in contexts() {
        for (i, l) in lights.iter().enumerate() {
            if sampler.pmf(&ctx, LightId(i as u32)) == 0.0 {
                // Zero only for one-sided triangles seen from behind.
                let Light::Triangle(t) = l else {
                    panic!("light {i} ({l:?}) got pmf 0 at {ctx:?}");
                };
                assert!((ctx.p - t.p[0]).dot(t.n) <= 0.0, "triangle {i} got pmf 0");
            }
        }
    }
}

#[test]
fn array_rounding_leaves_no_emitting_light_without_slots() {
    use candela_core::light_sampler::LightArray;
    // One light 10⁹ times brighter than the others: they would round to zero slots.
    let mut powers = vec![1.0f32; 100];
    powers[0] = 1e9;
    powers[1] = 0.0;
    let a = LightArray::new(&powers).unwrap();
    assert_eq!(a.pmf(1), 0.0);
    let total: f64 = (0..100).map(|i| a.pmf(i) as f64).sum();
    assert!((total - 1.0).abs() < 1e-5);
    assert!((2..100).all(|i| a.pmf(i) > 0.0));
    // M is the power of two at or above 4N, and every slot is accounted for.
    assert_eq!(a.len(), 512);
    let slots: f64 = (0..100).map(|i| a.pmf(i) as f64 * 512.0).sum();
    assert_eq!(slots.round() as usize, 512);
    // The faint lights hold exactly one slot each: the one they are guaranteed.
    assert!((2..100).all(|i| a.pmf(i) == 1.0 / 512.0));
}

/// With M a power of two, the 2²⁴ values an `f32` uniform takes hit every slot equally
/// often: picks follow the pmf exactly, with no quantization bias.
#[test]
fn array_picks_are_exact_over_all_f32_uniforms() {
    use candela_core::light_sampler::LightArray;
    let powers: Vec<f32> = (0..300).map(|i| 1.0 + (i * 37 % 101) as f32).collect();
    let a = LightArray::new(&powers).unwrap();
    let mut counts = vec![0u64; powers.len()];
    for j in 0..1u32 << 24 {
        let (i, _) = a.sample(j as f32 / (1u32 << 24) as f32);
        counts[i as usize] += 1;
    }
    for (i, &c) in counts.iter().enumerate() {
        assert_eq!(
            c as f64,
            a.pmf(i as u32) as f64 * (1u64 << 24) as f64,
            "light {i}"
        );
    }
}

/// RIS picks are not described by a tractable pmf; what must hold is that for every
/// light i, E[1{pick = i} / pick.pmf] = 1 if the light can contribute (target > 0), and 0
/// otherwise: unbiasedness of the RIS weight, light by light. Lights RIS rarely picks give
/// heavy-tailed estimates, so the per-light z-test covers lights picked ≥ 400 times, and
/// sums over all lights, E[Σᵢ gᵢ 1{pick = i} / pick.pmf] = Σᵢ gᵢ, cover the rest for
/// g = the target (the variance RIS minimizes) and g = 1 (every light counted once).
#[test]
fn ris_weight_is_unbiased_for_every_light() {
    let lights = lights();
    for kind in [LightSamplerKind::Ris, LightSamplerKind::RisBvh] {
        for m in [1, 4] {
            let sampler = LightSampler::new(kind, m, &lights);
            for (ci, ctx) in contexts().iter().enumerate() {
                let target: Vec<f64> = lights.iter().map(|l| l.importance(ctx) as f64).collect();
                let mut count = vec![0u64; lights.len()];
                let mut sum = vec![0.0f64; lights.len()];
                let mut sum2 = vec![0.0f64; lights.len()];
                let (mut g_target, mut g_target2) = (0.0f64, 0.0f64);
                let mut rng = Pcg32::new(13, ci as u64);
                for _ in 0..SAMPLES {
                    let Some(pick) = sampler.sample(ctx, rng.uniform_f32(), &lights) else {
                        continue;
                    };
                    let i = pick.id.0 as usize;
                    let x = 1.0 / pick.pmf as f64;
                    count[i] += 1;
                    sum[i] += x;
                    sum2[i] += x * x;
                    g_target += target[i] * x;
                    g_target2 += (target[i] * x).powi(2);
                    // The MIS surrogate is the source's pmf, and is never zero for a pick.
                    assert_eq!(pick.mis_pmf, sampler.pmf(ctx, pick.id));
                    assert!(pick.mis_pmf > 0.0);
                }
                let n = SAMPLES as f64;
                let z_of = |s: f64, s2: f64, expected: f64| {
                    let mean = s / n;
                    let var = (s2 / n - mean * mean).max(0.0);
                    (mean - expected) / (var / n).sqrt().max(1e-12 * expected)
                };
                // 64 lights × 4 points × 4 settings ≈ 1000 tests; α = 10⁻⁶ each (|z| < 4.9)
                // keeps the family-wise false alarm rate near 0.1%.
                let z_max = 4.9;
                let mut worst: f64 = 0.0;
                for i in 0..lights.len() {
                    if target[i] == 0.0 {
                        assert_eq!(count[i], 0, "light {i} without target was picked");
                    } else if count[i] >= 400 {
                        let z = z_of(sum[i], sum2[i], 1.0);
                        worst = worst.max(z.abs());
                        assert!(z.abs() < z_max, "{kind:?} M={m} ctx {ci} light {i}: z {z}");
                    }
                }
                let reachable = target.iter().filter(|&&t| t > 0.0).count() as f64;
                let (s1, s2) = (sum.iter().sum::<f64>(), sum2.iter().sum::<f64>());
                // Σ over lights of 1{pick = i}/pmf: the same variable as sum of x per pick.
                let z_count = z_of(s1, s2, reachable);
                let z_target = z_of(g_target, g_target2, target.iter().sum());
                eprintln!(
                    "{kind:?} M={m} ctx {ci}: max per-light |z| = {worst:.2}, \
                     z(Σ1) = {z_count:.2}, z(Σtarget) = {z_target:.2}"
                );
                assert!(z_count.abs() < z_max && z_target.abs() < z_max);
            }
        }
    }
}

/// Where a light's importance (the RIS target) is zero, its samples must carry nothing a
/// BSDF could scatter: no direction with radiance and a non-zero receiver cosine.
#[test]
fn zero_importance_means_no_contribution() {
    let lights = lights();
    let mut rng = Pcg32::new(23, 0);
    let mut zeros = 0;
    for _ in 0..200 {
        let p = Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32()) * 10.0
            - Vec3::new(5.0, 3.0, 5.0);
        let ctx = ShadingCtx { p, n: Vec3::Y };
        for l in &lights {
            if l.importance(&ctx) > 0.0 {
                continue;
            }
            zeros += 1;
            for _ in 0..64 {
                let u = glam::Vec2::new(rng.uniform_f32(), rng.uniform_f32());
                if let Some(s) = l.sample_li(&ctx, u) {
                    let c = s.radiance * s.wi.dot(ctx.n).abs();
                    assert_eq!(c, Vec3::ZERO, "{l:?} at {p}: zero importance, sample {s:?}");
                }
            }
        }
    }
    // The check is not vacuous: about half the triangles face away from any point.
    assert!(zeros > 1000, "only {zeros} zero-importance cases");
}

/// A sun, an even sky and a sky with a bright patch beside the 64 lights: the BVH picks
/// among the three infinite lights by their importance at the point (the sun's irradiance;
/// each sky's light above its mean, plus a sixteenth of the whole), its picks follow its
/// pmf (chi-square at the four points), and every infinite light keeps a positive pmf.
#[test]
fn bvh_picks_infinite_lights_by_their_importance() {
    use candela_core::light::envmap::{Equirect, Image};
    use candela_core::light::{DirectionalLight, EnvironmentLight, EnvironmentMap};
    use glam::Mat3;

    let mut lights = lights();
    let sun = lights.len() as u32;
    lights.push(Light::Directional(DirectionalLight {
        direction: Vec3::new(-0.4, -0.8, -0.45).normalize(),
        irradiance: Vec3::new(4.0, 3.6, 3.0),
        scene_radius: 10.0,
    }));
    let even = lights.len() as u32;
    let sky = |map| EnvironmentLight::new(map, 1.0, Mat3::IDENTITY, 10.0);
    lights.push(Light::Environment(sky(EnvironmentMap::Constant(
        Vec3::new(0.3, 0.45, 0.8),
    ))));
    let patchy = lights.len() as u32;
    let mut pixels = vec![Vec3::splat(0.2); 32 * 16];
    pixels[3 * 32 + 20] = Vec3::splat(500.0);
    lights.push(Light::Environment(sky(EnvironmentMap::Equirect(
        Equirect::new(Image {
            width: 32,
            height: 16,
            pixels,
        }),
    ))));
    let sampler = LightSampler::new(LightSamplerKind::Bvh, 8, &lights);
    let alpha = sidak_alpha(0.01, contexts().len());
    for (ci, ctx) in contexts().iter().enumerate() {
        let pmf: Vec<f64> = (0..lights.len() as u32)
            .map(|i| sampler.pmf(ctx, LightId(i)) as f64)
            .collect();
        for i in [sun, even, patchy] {
            assert!(
                pmf[i as usize] > 0.0,
                "infinite light {i} refused at ctx {ci}"
            );
        }
        let mut counts = vec![0u64; lights.len()];
        let mut rng = Pcg32::new(29, ci as u64);
        for _ in 0..SAMPLES {
            let pick = sampler.sample(ctx, rng.uniform_f32(), &lights).unwrap();
            assert!((pick.pmf as f64 / pmf[pick.id.0 as usize] - 1.0).abs() < 1e-4);
            counts[pick.id.0 as usize] += 1;
        }
        discrete(&format!("infinite at ctx {ci}"), &counts, &pmf, alpha).assert_passed();
    }
    // Facing the sun (n = y): E·cos θ ≈ 2.9 against π·0.43/16 ≈ 0.08 for the even sky.
    let up = contexts()[0];
    let p = |i: u32| sampler.pmf(&up, LightId(i));
    assert!(p(sun) > 20.0 * p(even), "sun {} sky {}", p(sun), p(even));
    // The patch (500 over 0.024 sr, 37° from the zenith: ≈ 9 on this surface) outweighs
    // the sun's 2.9.
    assert!(
        p(patchy) > p(sun),
        "patchy sky {} sun {}",
        p(patchy),
        p(sun)
    );
}
