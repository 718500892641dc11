//! Energy and symmetry of the BSDFs: white furnace, no BSDF returning more than it
//! receives, reciprocity of reflection, and the shading-normal light-leak rule.
//!
//! Albedo estimates average the sample weight f·|cos θᵢ|/pdf over N = 200 000 samples of
//! fixed seed; bounds allow 5 standard errors of that mean (so a correct BSDF fails a
//! bound with probability < 10⁻⁶ per check) plus 10⁻³ for f32 rounding.

use candela_core::bsdf::{
    Bsdf, Conductor, ConductorFresnel, Dielectric, Diffuse, Lobe, MetalRough, Microfacet, Plastic,
    ThinDielectric,
};
use candela_core::sampler::Pcg32;
use glam::{Vec2, Vec3};

const N: usize = 200_000;

fn dir(theta_deg: f32, phi_deg: f32) -> Vec3 {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

/// Mean and standard error of the flux albedo from `wo` (red channel). For transmission
/// the radiance scaling 1/η'² is undone (× η'²), so the estimate is of energy, which must
/// not exceed 1, rather than of radiance, which legitimately grows leaving glass.
fn albedo(lobe: Lobe, wo: Vec3, seed: u64) -> (f64, f64) {
    let mut rng = Pcg32::new(seed, 11);
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for _ in 0..N {
        let u_lobe = rng.uniform_f32();
        let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
        let Some(s) = lobe.sample(wo, u_lobe, u) else {
            continue;
        };
        let mut w = (s.f.x * s.wi.z.abs() / s.pdf) as f64;
        if s.wi.z * wo.z < 0.0 {
            if let Lobe::Dielectric(d) = lobe {
                let etap = if wo.z > 0.0 { d.eta } else { 1.0 / d.eta };
                w *= (etap * etap) as f64;
            }
        }
        assert!(w.is_finite() && w >= 0.0, "{lobe:?} {s:?}");
        sum += w;
        sum2 += w * w;
    }
    let mean = sum / N as f64;
    let var = (sum2 / N as f64 - mean * mean).max(0.0);
    (mean, (var / N as f64).sqrt())
}

fn white_conductor(distrib: Microfacet) -> Lobe {
    Lobe::Conductor(Conductor {
        distrib,
        fresnel: ConductorFresnel::Schlick { f0: Vec3::ONE },
    })
}

/// E(θo = 0) of a white conductor by 1D quadrature over θh (independent of the sampling
/// code, in f64 from the textbook formulas): with ωo = z, ωi is at 2θh, |dωi/dωh| =
/// 4 cos θh and E = ∫ D(θh) cos θh G₁(ωi) dωh over 2θh < 90°. GGX (Walter et al. 2007,
/// eqs. 33, 34 with Λ from Heitz 2014, eq. 72) or Beckmann (eq. 25 with the exact Λ of
/// Walter's eq. 24 / Heitz's eq. 71, erf from `libm`).
fn normal_incidence_albedo(a: f64, beckmann: bool) -> f64 {
    use std::f64::consts::PI;
    let n = 200_000;
    (0..n)
        .map(|i| {
            let th = (i as f64 + 0.5) / n as f64 * PI / 4.0;
            let (s, c) = th.sin_cos();
            let t = (2.0 * th).tan();
            let (d, lambda) = if beckmann {
                let d = (-(s / (a * c)).powi(2)).exp() / (PI * a * a * c.powi(4));
                let mu = 1.0 / (a * t);
                let lambda =
                    (libm::erf(mu) - 1.0) / 2.0 + (-mu * mu).exp() / (2.0 * mu * PI.sqrt());
                (d, lambda)
            } else {
                let d = 1.0 / (PI * a * a * ((s / a).powi(2) + c * c).powi(2));
                (d, ((1.0 + a * a * t * t).sqrt() - 1.0) / 2.0)
            };
            d * c / (1.0 + lambda) * s * 2.0 * PI * (PI / 4.0 / n as f64)
        })
        .sum()
}

const ANGLES: [f32; 6] = [0.0, 30.0, 60.0, 75.0, 85.0, 89.0];

#[test]
fn diffuse_of_albedo_one_returns_exactly_one() {
    let lobe = Lobe::Diffuse(Diffuse { albedo: Vec3::ONE });
    for th in ANGLES {
        let (e, se) = albedo(lobe, dir(th, 0.0), 1);
        assert!((e - 1.0).abs() < 1e-4 && se < 1e-5, "θ={th}: {e} ± {se}");
    }
}

/// A white (F = 1) conductor loses only what single scattering misses: light that
/// the microsurface sends downwards or shadows (Heitz et al. 2016, "Multiple-Scattering
/// Microfacet BSDFs with the Smith Model", fig. 2; Kulla & Conty 2017). At normal
/// incidence the loss is checked against an independent 1D quadrature
/// ([`normal_incidence_albedo`]: for GGX 0.877 at α = 0.3, 0.31 at α = 1, where half of
/// the projected microfacet area is steeper than 45° and reflects downwards). At other
/// angles E must lie between 1 and a loose lower envelope of those curves; a smooth
/// conductor is a perfect mirror and returns exactly 1. Beckmann's shorter tails lose
/// less than GGX at equal α, so GGX's envelope bounds it too (measured: see the log).
#[test]
fn white_furnace_conductor() {
    let mut seed = 10;
    // (α, minimum E for θ < 75°, minimum E at 75°–89°, where shadowing grows as α·tan θ).
    for (alpha, min_e, min_grazing) in [
        (0.0f32, 1.0, 1.0),
        (0.01, 0.99, 0.85),
        (0.1, 0.95, 0.75),
        (0.3, 0.8, 0.75),
        (0.6, 0.55, 0.6),
        (1.0, 0.28, 0.5),
    ] {
        for (name, beckmann) in [("GGX", false), ("Beckmann", true)] {
            let a = alpha.max(1e-4);
            let distrib = if beckmann {
                Microfacet::beckmann(a, a)
            } else {
                Microfacet::ggx(a, a)
            };
            for th in ANGLES {
                seed += 1;
                let min_e = if th >= 75.0 { min_grazing } else { min_e };
                let (e, se) = albedo(white_conductor(distrib), dir(th, 0.0), seed);
                let tol = 5.0 * se + 1e-3;
                eprintln!("white {name} conductor α={alpha} θ={th}: E = {e:.4} ± {se:.4}");
                assert!(e <= 1.0 + tol, "{name} α={alpha} θ={th}: E = {e} > 1");
                assert!(
                    e >= min_e - tol,
                    "{name} α={alpha} θ={th}: E = {e} < {min_e}"
                );
                if th == 0.0 && alpha > 0.0 {
                    let exact = normal_incidence_albedo(alpha as f64, beckmann);
                    assert!(
                        (e - exact).abs() < tol,
                        "{name} α={alpha}: E = {e}, quadrature {exact}"
                    );
                }
            }
        }
    }
}

#[test]
fn no_bsdf_returns_more_than_it_receives() {
    let glass = |eta, distrib| {
        Lobe::Dielectric(Dielectric {
            tint: Vec3::ONE,
            eta,
            distrib,
        })
    };
    let mut lobes = vec![
        ("conductor Ag α=0.2", {
            let (eta, k) = candela_core::desc::metal_preset("Ag").unwrap();
            Lobe::Conductor(Conductor {
                distrib: Microfacet::ggx(0.2, 0.05),
                fresnel: ConductorFresnel::Complex { eta, k },
            })
        }),
        (
            "thin glass",
            Lobe::ThinDielectric(ThinDielectric { eta: 1.5 }),
        ),
        ("plastic ρ=1", Lobe::Plastic(Plastic::new(Vec3::ONE, 1.5))),
        (
            "plastic ρ=1 η=1.9",
            Lobe::Plastic(Plastic::new(Vec3::ONE, 1.9)),
        ),
    ];
    lobes.push(("Beckmann conductor Ag α=(0.2,0.05)", {
        let (eta, k) = candela_core::desc::metal_preset("Ag").unwrap();
        Lobe::Conductor(Conductor {
            distrib: Microfacet::beckmann(0.2, 0.05),
            fresnel: ConductorFresnel::Complex { eta, k },
        })
    }));
    for eta in [1.5, 1.0 / 1.5] {
        for a in [1e-4, 0.05, 0.3, 0.8] {
            lobes.push(("dielectric", glass(eta, Microfacet::ggx(a, a))));
            lobes.push((
                "Beckmann dielectric",
                glass(eta, Microfacet::beckmann(a, a)),
            ));
        }
    }
    for eta in [1.5, 1.9] {
        for a in [0.05, 0.3, 1.0] {
            lobes.push((
                "rough plastic ρ=1",
                Lobe::Plastic(Plastic::rough(Vec3::ONE, eta, Microfacet::ggx(a, a))),
            ));
            lobes.push((
                "Beckmann rough plastic ρ=1",
                Lobe::Plastic(Plastic::rough(Vec3::ONE, eta, Microfacet::beckmann(a, a))),
            ));
        }
    }
    for m in [0.0, 0.5, 1.0] {
        for r in [0.05, 0.4, 1.0] {
            lobes.push((
                "metal_rough white",
                Lobe::MetalRough(MetalRough::new(Vec3::ONE, m, r)),
            ));
        }
    }
    let mut seed = 100;
    for (name, lobe) in lobes {
        for th in ANGLES.iter().chain(&[120.0, 178.0]) {
            seed += 1;
            let (e, se) = albedo(lobe, dir(*th, 10.0), seed);
            assert!(
                e <= 1.0 + 5.0 * se + 1e-3,
                "{name} {lobe:?} θ={th}: E = {e} ± {se}"
            );
        }
    }
}

/// Energy closes exactly where nothing absorbs: a smooth dielectric's R + T = 1 (in flux)
/// and a plastic over a white base (the model sums all inner bounces) return 1.
#[test]
fn lossless_layers_return_one() {
    let smooth = Lobe::Dielectric(Dielectric {
        tint: Vec3::ONE,
        eta: 1.5,
        distrib: Microfacet::ggx(1e-4, 1e-4),
    });
    let plastic = Lobe::Plastic(Plastic::new(Vec3::ONE, 1.5));
    let thin = Lobe::ThinDielectric(ThinDielectric { eta: 1.5 });
    for (i, th) in ANGLES.iter().enumerate() {
        for (name, lobe) in [
            ("smooth glass", smooth),
            ("plastic", plastic),
            ("thin", thin),
        ] {
            let (e, se) = albedo(lobe, dir(*th, 0.0), 500 + i as u64);
            assert!(
                (e - 1.0).abs() < 5.0 * se + 2e-3,
                "{name} θ={th}: E = {e} ± {se}"
            );
        }
        let (e, _) = albedo(smooth, dir(180.0 - th, 0.0), 600 + i as u64);
        assert!((e - 1.0).abs() < 2e-3, "glass from inside θ={th}: E = {e}");
    }
}

/// A plastic's coat roughened a little reflects as the smooth one does: at α = 0.01 the
/// albedo of a ρ = 0.5 plastic is the smooth plastic's within 5 standard errors plus
/// 3·10⁻³ (the microfacet coat's own loss to masking at this α, ~10⁻³, and the
/// transmittance table's interpolation). A rough coat that dropped its Fresnel term, or
/// counted the base without the coat's transmittance, misses by ≥ 4 %.
#[test]
fn a_slightly_rough_coat_reflects_as_the_smooth_one() {
    let rho = Vec3::splat(0.5);
    for (i, th) in [0.0, 30.0, 60.0, 80.0].iter().enumerate() {
        let wo = dir(*th, 20.0);
        let smooth = albedo(Lobe::Plastic(Plastic::new(rho, 1.5)), wo, 700 + i as u64);
        for m in [
            Microfacet::ggx(0.01, 0.01),
            Microfacet::beckmann(0.01, 0.01),
        ] {
            let rough = albedo(
                Lobe::Plastic(Plastic::rough(rho, 1.5, m)),
                wo,
                710 + i as u64,
            );
            let se = (smooth.1.powi(2) + rough.1.powi(2)).sqrt();
            assert!(
                (rough.0 - smooth.0).abs() < 5.0 * se + 3e-3,
                "{m:?} θ={th}: rough {rough:?} vs smooth {smooth:?}"
            );
        }
    }
}

#[test]
fn reflection_is_reciprocal() {
    let copper = |distrib| {
        Lobe::Conductor(Conductor {
            distrib,
            fresnel: ConductorFresnel::Complex {
                eta: Vec3::new(0.2, 0.9, 1.1),
                k: Vec3::new(3.9, 2.4, 2.1),
            },
        })
    };
    let glass = |distrib| {
        Lobe::Dielectric(Dielectric {
            tint: Vec3::ONE,
            eta: 1.5,
            distrib,
        })
    };
    let lobes = [
        Lobe::Diffuse(Diffuse {
            albedo: Vec3::splat(0.5),
        }),
        copper(Microfacet::ggx(0.3, 0.1)),
        glass(Microfacet::ggx(0.4, 0.4)),
        copper(Microfacet::beckmann(0.3, 0.1)),
        glass(Microfacet::beckmann(0.4, 0.2)),
        Lobe::Plastic(Plastic::new(Vec3::new(0.3, 0.6, 0.9), 1.5)),
        Lobe::Plastic(Plastic::rough(
            Vec3::new(0.3, 0.6, 0.9),
            1.5,
            Microfacet::ggx(0.3, 0.3),
        )),
        Lobe::MetalRough(MetalRough::new(Vec3::new(0.9, 0.5, 0.2), 0.3, 0.5)),
    ];
    let mut rng = Pcg32::new(5, 5);
    for lobe in lobes {
        for _ in 0..2000 {
            let a = dir(rng.uniform_f32() * 89.0, rng.uniform_f32() * 360.0);
            let b = dir(rng.uniform_f32() * 89.0, rng.uniform_f32() * 360.0);
            let (fab, fba) = (lobe.f(a, b), lobe.f(b, a));
            let scale = fab.max_element().max(1e-3);
            assert!(
                (fab - fba).abs().max_element() < 1e-4 * scale,
                "{lobe:?}: {fab} vs {fba}"
            );
        }
    }
}

/// A shading normal tilted 40° from the geometric one: no pair that is a reflection
/// for one and a transmission for the other gets any value, and no sampled direction
/// crosses the geometric surface while claiming reflection.
#[test]
fn tilted_shading_normal_does_not_leak() {
    let ng = Vec3::Z;
    let ns = dir(40.0, 0.0);
    let bsdf = Bsdf::new(ns, ng, Lobe::Diffuse(Diffuse { albedo: Vec3::ONE }));
    let mut rng = Pcg32::new(9, 9);
    let mut leaked = 0;
    for _ in 0..20_000 {
        let wo = dir(rng.uniform_f32() * 89.0, rng.uniform_f32() * 360.0);
        let wi = dir(rng.uniform_f32() * 180.0, rng.uniform_f32() * 360.0);
        if wi.dot(ng) < 0.0 && (bsdf.f(wo, wi) != Vec3::ZERO || bsdf.pdf(wo, wi) != 0.0) {
            leaked += 1;
        }
        let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
        if let Some(s) = bsdf.sample(wo, 0.5, u) {
            assert!(
                s.wi.dot(ng) > 0.0,
                "a reflection sample went below the surface"
            );
        }
    }
    assert_eq!(leaked, 0);
}

/// Rough glass scatters from inside as from outside: seen from below (ωo.z < 0, inside
/// an η = 1.5 body, as on every exit hit) the lobe is the mirror image of η = 1/1.5 seen
/// from above, so the two energy albedos agree within 5 standard errors of their
/// difference; and single-scattering GGX loses only what its microsurface sends back
/// across or shadows: < 2 % at α = 0.05, < 25 % at α = 0.3 (most from inside at 60°,
/// where the total internal reflection off tilted microfacets is scattered again), so
/// each albedo must exceed 0.98 or 0.75. Inside
/// rays used to get no sample at all (the visible-normal density was zero from below).
/// The same holds for Beckmann, whose shorter tails lose less at equal α.
#[test]
fn rough_glass_scatters_from_both_sides() {
    let mut seed = 700;
    for (alpha, min_e) in [(0.05f32, 0.98), (0.3, 0.75)] {
        for th in [0.0f32, 30.0, 60.0] {
            for (eta, distrib) in [1.5f32, 1.0 / 1.5].into_iter().flat_map(|eta| {
                [
                    (eta, Microfacet::ggx(alpha, alpha)),
                    (eta, Microfacet::beckmann(alpha, alpha)),
                ]
            }) {
                seed += 2;
                let glass = |eta| {
                    Lobe::Dielectric(Dielectric {
                        tint: Vec3::ONE,
                        eta,
                        distrib,
                    })
                };
                let (below, se_b) = albedo(glass(eta), dir(180.0 - th, 10.0), seed);
                let (above, se_a) = albedo(glass(1.0 / eta), dir(th, 10.0), seed + 1);
                let se = (se_a * se_a + se_b * se_b).sqrt();
                let what = format!("{distrib:?} θ={th} η={eta}");
                eprintln!("glass {what}: below {below:.4}, mirrored {above:.4}");
                assert!(below > min_e, "{what}: E below = {below}");
                assert!(
                    (below - above).abs() < 5.0 * se + 1e-3,
                    "{what}: E below {below} ± {se_b}, mirrored {above} ± {se_a}"
                );
            }
        }
    }
}

#[test]
fn eta_crossed_sq_undoes_the_radiance_scaling_of_refraction() {
    // A refracted sample's weight f·|cos θᵢ|/pdf carries 1/η′²; `eta_crossed_sq` is the
    // η′² that undoes it (η′ = η entering from the normal's side, 1/η leaving), and 1 for
    // a reflection. Smooth glass picks T with probability T, so its energy weight is 1.
    let ns = Vec3::new(0.1, -0.2, 1.0).normalize();
    let frame_z = |d: Vec3| d.dot(ns);
    for (eta, alpha) in [(1.5f32, 1e-4f32), (1.0 / 1.33, 1e-4), (1.5, 0.3)] {
        let bsdf = Bsdf::new(
            ns,
            ns,
            Lobe::Dielectric(Dielectric {
                tint: Vec3::ONE,
                eta,
                distrib: Microfacet::ggx(alpha, alpha),
            }),
        );
        let (mut refracted, mut reflected) = (0, 0);
        // From the normal's side and from the other, near normal and oblique.
        let wos = [
            Vec3::new(0.3, 0.25, 0.4),
            Vec3::new(-0.6, 0.25, 1.3),
            Vec3::new(0.8, -0.25, -0.1),
            Vec3::new(-0.2, 0.1, -0.9),
        ];
        for (k, wo) in wos.map(Vec3::normalize).into_iter().enumerate() {
            for i in 0..64 {
                let u_lobe = (i as f32 + 0.5) / 64.0;
                let u = Vec2::new(0.37 + 0.005 * k as f32, (i as f32 * 0.618).fract());
                let Some(s) = bsdf.sample(wo, u_lobe, u) else {
                    continue;
                };
                let scale = bsdf.eta_crossed_sq(wo, &s);
                if frame_z(wo) * frame_z(s.wi) < 0.0 {
                    refracted += 1;
                    let etap = if frame_z(wo) > 0.0 { eta } else { 1.0 / eta };
                    assert_eq!(scale, etap * etap, "η {eta}, wo {wo}");
                    if alpha < 1e-3 {
                        let w = s.f.x * bsdf.abs_cos(s.wi) / s.pdf;
                        assert!((w * scale - 1.0).abs() < 1e-5, "η {eta}: {w} × {scale}");
                    }
                } else {
                    reflected += 1;
                    assert_eq!(scale, 1.0, "η {eta}, wo {wo}");
                }
            }
        }
        assert!(
            refracted > 0 && reflected > 0,
            "η {eta}: {refracted} / {reflected}"
        );
    }
    let diffuse = Bsdf::new(ns, ns, Lobe::Diffuse(Diffuse { albedo: Vec3::ONE }));
    let wo = Vec3::new(0.2, 0.1, 0.9).normalize();
    let s = diffuse.sample(wo, 0.5, Vec2::new(0.3, 0.8)).unwrap();
    assert_eq!(diffuse.eta_crossed_sq(wo, &s), 1.0);
}
