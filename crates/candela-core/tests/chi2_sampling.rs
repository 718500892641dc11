//! Chi-square tests of every sampling routine of the foundation against the density it
//! claims: the warps (the bilinear one too), the sphere, triangle (plain and textured),
//! parallelogram and rectangle lights' `sample_li` against `pdf_li` (the triangle and
//! rectangle under `LampSampling::SolidAngle` too: near, drawn on the sphere, and far, by
//! area), the diffuse BSDF, and the alias table. Each uses 10⁶ samples and a fixed seed;
//! the suite's family-wise significance is 0.01, split over its tests by the Šidák
//! correction.

use std::f32::consts::PI;
use std::sync::Arc;

use candela_core::bsdf::{Bsdf, Diffuse, Lobe};
use candela_core::chi2::{discrete, sidak_alpha, Chi2Report, ChiSquareTest};
use candela_core::desc::LampSampling;
use candela_core::light::{
    EmissionTexture, Light, ParallelogramLight, ShadingCtx, SphereLight, TriangleLight,
};
use candela_core::math::Frame;
use candela_core::sampler::Pcg32;
use candela_core::sampling::{
    bilinear_pdf, cosine_hemisphere_pdf, sample_bilinear, sample_cosine_hemisphere,
    sample_uniform_cone, sample_uniform_sphere, uniform_cone_pdf, AliasTable, UNIFORM_SPHERE_PDF,
};
use candela_core::texture::Texture;
use glam::{Affine2, Vec2, Vec3};

/// Number of chi-square tests in this file, for the Šidák correction.
const TESTS: usize = 51;

fn test() -> ChiSquareTest {
    ChiSquareTest {
        alpha: sidak_alpha(0.01, TESTS),
        ..Default::default()
    }
}

#[test]
fn cosine_hemisphere() {
    test()
        .spherical(
            "cosine hemisphere",
            |u| Some(sample_cosine_hemisphere(u)),
            |d| cosine_hemisphere_pdf(d.z),
        )
        .assert_passed();
}

#[test]
fn uniform_sphere() {
    test()
        .spherical(
            "uniform sphere",
            |u| Some(sample_uniform_sphere(u)),
            |_| UNIFORM_SPHERE_PDF,
        )
        .assert_passed();
}

#[test]
fn uniform_cones() {
    for cos_max in [0.3f32, -0.5, 0.9] {
        test()
            .spherical(
                &format!("uniform cone, cos θmax = {cos_max}"),
                |u| Some(sample_uniform_cone(u, cos_max)),
                |d| {
                    if d.z >= cos_max {
                        uniform_cone_pdf(cos_max)
                    } else {
                        0.0
                    }
                },
            )
            .assert_passed();
    }
}

/// Tests a light's `sample_li` against its `pdf_li` at `p`, and checks that the pdf a
/// sample reports equals `pdf_li` of its direction.
fn light_test(name: &str, light: &Light, p: Vec3) -> Chi2Report {
    light_test_seen_by(name, light, ShadingCtx { p, n: Vec3::Y })
}

/// [`light_test`] at a receiver of normal `ctx.n`: the spherical triangle and rectangle
/// weigh their directions by the receiver's cosine (none where `n` is zero, in a medium).
fn light_test_seen_by(name: &str, light: &Light, ctx: ShadingCtx) -> Chi2Report {
    let (mut mismatches, mut samples) = (0usize, 0usize);
    let t = ChiSquareTest {
        // `pdf_li` finds the light again by casting a ray from the shading point. Seen at
        // grazing incidence, a triangle's edge zone of barycentric width ~10⁻⁵ projects to
        // less than f32 resolution, so such samples may miss their own triangle (measured:
        // 8 in 10⁶ at the grazing placement below). A wrong support misses far more.
        zero_pdf_tolerance: 1e-4,
        ..test()
    };
    let report = t.spherical(
        name,
        |u| {
            let s = light.sample_li(&ctx, u)?;
            let pdf = light.pdf_li(&ctx, s.wi);
            samples += 1;
            // Both sides compute d²/(cos·A) (or the cone's constant) from the same inputs
            // along different paths (sampled point vs ray intersection); 10⁻³ covers the
            // f32 round-off of the intersection (measured worst: 2.4·10⁻⁵).
            mismatches += ((pdf / s.pdf - 1.0).abs() > 1e-3) as usize;
            Some(s.wi)
        },
        |wi| light.pdf_li(&ctx, wi),
    );
    assert!(
        mismatches as f64 <= 1e-4 * samples.max(1) as f64,
        "{name}: sample_li's pdf differs from pdf_li for {mismatches} of {samples} samples"
    );
    report
}

fn sphere(center: Vec3, radius: f32, inward: bool) -> Light {
    Light::Sphere(SphereLight {
        center,
        radius,
        le: Vec3::ONE,
        inward,
    })
}

#[test]
fn sphere_light_from_outside_samples_its_cone() {
    let light = sphere(Vec3::new(0.5, 1.0, -0.3), 0.8, false);
    for p in [Vec3::new(0.2, -0.4, 0.9), Vec3::new(2.0, 1.5, -0.8)] {
        light_test(&format!("sphere light seen from {p}"), &light, p).assert_passed();
    }
}

#[test]
fn sphere_light_from_inside_samples_its_area() {
    // An inward-emitting sphere seen from inside, off centre (area sampling, the pdf
    // varies with distance and angle), and an outward one seen from inside, which
    // emits away from the point: no sample succeeds and the pdf is zero everywhere.
    let light = sphere(Vec3::new(0.1, -0.2, 0.3), 1.5, true);
    for p in [Vec3::new(0.1, -0.2, 0.3), Vec3::new(0.9, 0.4, -0.5)] {
        light_test(&format!("inward sphere light seen from {p}"), &light, p).assert_passed();
    }
    let outward = sphere(Vec3::ZERO, 1.0, false);
    let r = light_test(
        "outward sphere light seen from inside",
        &outward,
        Vec3::new(0.3, 0.0, 0.0),
    );
    r.assert_passed();
    assert_eq!(r.success_fraction, 0.0);
}

/// The triangle lights' corners, and their normal by the right-hand rule.
fn slanted_triangle() -> ([Vec3; 3], Vec3) {
    let tri = [
        Vec3::new(-0.5, 1.0, -0.4),
        Vec3::new(0.7, 1.2, -0.2),
        Vec3::new(0.1, 0.9, 0.8),
    ];
    (tri, (tri[1] - tri[0]).cross(tri[2] - tri[0]).normalize())
}

/// Whether a lamp whose widest extent is `extent2` (squared) is near enough from `p` to
/// be drawn in the solid angle it covers: wider than its centre is far, the bound of the
/// light module's `spherical::near`. The placements below fall on both sides of it.
fn drawn_on_the_sphere(extent2: f32, centre: Vec3, p: Vec3) -> bool {
    extent2 > centre.distance_squared(p)
}

/// Points in front of a flat lamp (its centre, the unit normal of its emitting side, one
/// of its corners), with their names: one facing it as far away as the lamp is wide,
/// close, oblique, grazing (`graze` in front of its plane, half again as far out as the
/// corner) and the same three times as far out, and far. The lamps here (1.3 and 1.5
/// wide) are near, in the sense of [`drawn_on_the_sphere`], from the first four and far
/// from the last two.
fn front_placements(
    centre: Vec3,
    front: Vec3,
    corner: Vec3,
    graze: f32,
) -> [(&'static str, Vec3); 6] {
    let out = corner - centre;
    [
        ("facing", centre + front),
        ("close", centre + front * 0.05),
        ("oblique", centre + front * 0.6 + out * 1.2),
        ("grazing", centre + front * graze + out * 1.5),
        ("grazing, far", centre + front * graze + out * 3.0),
        ("far", centre + front * 3.0 + out),
    ]
}

/// Tests a light from a point that sees its front: the chi-square test passes and nearly
/// every sample reaches the light (a placement behind it would pass with no samples).
fn assert_lit(report: Chi2Report) {
    report.assert_passed();
    assert!(report.success_fraction > 0.99, "{report}");
}

#[test]
fn triangle_light_from_a_point() {
    let (tri, n) = slanted_triangle();
    let centroid = (tri[0] + tri[1] + tri[2]) / 3.0;
    for sampling in [LampSampling::Area, LampSampling::SolidAngle] {
        // Emitting towards -n, the side the placements are on.
        let mut plain = TriangleLight::new(tri, -n, Vec3::ONE);
        plain.sampling = sampling;
        let extent2 = tri[0].distance_squared(tri[2]);
        let light = Light::Triangle(plain);
        for (i, (what, p)) in front_placements(centroid, -n, tri[0], 0.02)
            .into_iter()
            .enumerate()
        {
            assert_eq!(drawn_on_the_sphere(extent2, centroid, p), i < 4, "{what}");
            let name = format!("triangle light, {sampling:?}, {what}, from {p}");
            assert_lit(light_test(&name, &light, p));
        }
        // Close, with the cosine warp's weights far apart (a receiver facing along the
        // lamp) and without them (in a medium); area sampling ignores the receiver.
        if sampling == LampSampling::SolidAngle {
            for (what, receiver) in [("sideways", Vec3::X), ("in a medium", Vec3::ZERO)] {
                let ctx = ShadingCtx {
                    p: centroid - n * 0.3 + (tri[2] - centroid) * 0.4,
                    n: receiver,
                };
                let name = format!("triangle light, {sampling:?}, close, {what}");
                assert_lit(light_test_seen_by(&name, &light, ctx));
            }
        }
        // From behind, the triangle shows its back: nothing is sampled, the pdf is zero.
        let name = format!("triangle light, {sampling:?}, from behind");
        let r = light_test(&name, &light, centroid + n);
        r.assert_passed();
        assert_eq!(r.success_fraction, 0.0);
    }
}

/// A triangle with a checker emission draws its points where the checker is bright (its
/// density over its cells, see `EmissionTexture`): the solid-angle density that reaches
/// the shading point then has the cells' steps in it, and `pdf_li` must find the cell of
/// the point its ray hits.
#[test]
fn textured_triangle_light_from_a_point() {
    let (tri, n) = slanted_triangle();
    let checker = Arc::new(Texture::Checker {
        a: Vec3::new(6.0, 3.0, 1.0),
        b: Vec3::splat(0.2),
        uv_transform: Affine2::from_scale(Vec2::splat(3.0)),
    });
    let uv = [Vec2::ZERO, Vec2::new(1.0, 0.2), Vec2::new(0.3, 0.9)];
    let texture = EmissionTexture::new(checker.clone(), uv, Vec3::ONE, checker.mean());
    let light = Light::Triangle(TriangleLight::new(tri, -n, Vec3::ONE).with_texture(texture));
    let centroid = (tri[0] + tri[1] + tri[2]) / 3.0;
    for (what, p) in front_placements(centroid, -n, tri[0], 0.02)
        .into_iter()
        .take(3)
    {
        let name = format!("textured triangle light, {what}, from {p}");
        assert_lit(light_test(&name, &light, p));
    }
}

#[test]
fn parallelogram_light_from_a_point() {
    // A slanted, non-rectangular parallelogram (the merge accepts any), drawn by area
    // under either `LampSampling`; the triangle's placements.
    let p0 = Vec3::new(-0.5, 1.0, -0.4);
    let (e1, e2) = (Vec3::new(1.2, 0.2, 0.2), Vec3::new(0.3, -0.1, 1.1));
    let n = e1.cross(e2).normalize();
    let mut quad = ParallelogramLight::new(p0, e1, e2, -n, Vec3::ONE).unwrap();
    quad.sampling = LampSampling::SolidAngle;
    let light = Light::Parallelogram(quad);
    let centre = p0 + 0.5 * (e1 + e2);
    // Grazing about 1° above the plane (at 0.5°, as for the triangle, the sliver is
    // thinner than the adaptive quadrature resolves: ∫pdf came out 0.9985 with all else
    // passing).
    for (what, p) in front_placements(centre, -n, p0, 0.05) {
        assert_lit(light_test(
            &format!("parallelogram light, {what}, from {p}"),
            &light,
            p,
        ));
    }
    let r = light_test("parallelogram light from behind", &light, centre + n);
    r.assert_passed();
    assert_eq!(r.success_fraction, 0.0);
}

/// A rectangle light under [`LampSampling::SolidAngle`], which is drawn on the sphere
/// where it is near (Ureña et al.'s spherical rectangle, cosine-warped), from the
/// triangle's placements.
#[test]
fn rectangle_light_from_a_point() {
    let p0 = Vec3::new(-0.5, 1.0, -0.4);
    let e1 = Vec3::new(1.2, 0.3, 0.2);
    let e2 = e1.cross(Vec3::new(0.1, 1.0, -0.3)).normalize() * 0.9;
    let n = e1.cross(e2).normalize();
    let mut rect = ParallelogramLight::new(p0, e1, e2, -n, Vec3::ONE).unwrap();
    rect.sampling = LampSampling::SolidAngle;
    let light = Light::Parallelogram(rect);
    let centre = p0 + 0.5 * (e1 + e2);
    let extent2 = (e1 + e2).length_squared();
    for (i, (what, p)) in front_placements(centre, -n, p0, 0.05)
        .into_iter()
        .enumerate()
    {
        assert_eq!(drawn_on_the_sphere(extent2, centre, p), i < 4, "{what}");
        assert_lit(light_test(
            &format!("rectangle light, {what}, from {p}"),
            &light,
            p,
        ));
    }
    for (what, receiver) in [("sideways", e1.normalize()), ("in a medium", Vec3::ZERO)] {
        let ctx = ShadingCtx {
            p: centre - n * 0.1 + e2 * 0.3,
            n: receiver,
        };
        assert_lit(light_test_seen_by(
            &format!("rectangle light, close, {what}"),
            &light,
            ctx,
        ));
    }
    let r = light_test("rectangle light from behind", &light, centre + n * 0.1);
    r.assert_passed();
    assert_eq!(r.success_fraction, 0.0);
}

/// The bilinear warp that weighs a spherical polygon's directions by the receiver's
/// cosine, against its density: weights near alike, and far apart with a zero.
#[test]
fn bilinear_warp() {
    for w in [[1.0f32, 1.2, 0.9, 1.1], [0.01, 3.0, 0.5, 0.0]] {
        test()
            .planar(
                &format!("bilinear warp, corner weights {w:?}"),
                Vec2::ZERO,
                Vec2::ONE,
                |u| Some(sample_bilinear(u, w)),
                |p| bilinear_pdf(p, w),
            )
            .assert_passed();
    }
}

#[test]
fn diffuse_bsdf() {
    let lobe = Diffuse {
        albedo: Vec3::splat(0.5),
    };
    for wo in [
        Vec3::new(0.3, -0.2, 0.8).normalize(),
        Vec3::new(0.1, 0.5, -0.4).normalize(),
    ] {
        test()
            .spherical(
                &format!("diffuse lobe, wo = {wo}"),
                |u| lobe.sample(wo, 0.5, u).map(|s| s.wi),
                |wi| lobe.pdf(wo, wi),
            )
            .assert_passed();
    }
    // Placed in the world with a tilted normal: the frame must carry sample and pdf alike.
    let ns = Vec3::new(0.6, 0.0, -0.8);
    let bsdf = Bsdf::new(ns, ns, Lobe::Diffuse(lobe));
    let wo = Frame::from_z(ns).to_world(Vec3::new(0.2, 0.1, 0.9).normalize());
    test()
        .spherical(
            "diffuse BSDF, tilted frame",
            |u| bsdf.sample(wo, 0.5, u).map(|s| s.wi),
            |wi| bsdf.pdf(wo, wi),
        )
        .assert_passed();
}

#[test]
fn alias_table_frequencies_match_its_pmf() {
    let weights = [1.0, 0.0, 3.0, 0.5, 10.0, 2.5, 1e-3, 7.0, 0.25, 4.0];
    let table = AliasTable::new(&weights).unwrap();
    let mut counts = vec![0u64; weights.len()];
    let mut rng = Pcg32::new(11, 12);
    for _ in 0..1_000_000 {
        let (i, pmf) = table.sample(rng.uniform_f32());
        assert_eq!(pmf, table.pmf(i));
        counts[i] += 1;
    }
    let pmf: Vec<f64> = (0..weights.len()).map(|i| table.pmf(i) as f64).collect();
    let total: f64 = weights.iter().sum::<f32>() as f64;
    for (p, w) in pmf.iter().zip(weights) {
        assert!((p - w as f64 / total).abs() < 1e-6);
    }
    discrete("alias table", &counts, &pmf, sidak_alpha(0.01, TESTS)).assert_passed();
}

#[test]
fn alias_table_sweep_reproduces_its_pmf() {
    // A deterministic sweep of u over [0, 1) hits each index with frequency pmf ± 1/M;
    // a bin left without its alias (q = 0 for a bin that should be full) shows up as an
    // error of the order of 1/n.
    let weights = [1.0, 0.0, 3.0, 0.5, 10.0, 2.5, 1e-3, 7.0, 0.25, 4.0];
    let table = AliasTable::new(&weights).unwrap();
    const M: usize = 1 << 20;
    let mut counts = vec![0usize; weights.len()];
    for k in 0..M {
        counts[table.sample((k as f32 + 0.5) / M as f32).0] += 1;
    }
    for (i, &c) in counts.iter().enumerate() {
        let f = c as f64 / M as f64;
        assert!(
            (f - table.pmf(i) as f64).abs() < 1e-5,
            "index {i}: frequency {f}, pmf {}",
            table.pmf(i)
        );
    }
}

#[test]
fn cone_sampler_uses_the_whole_cone() {
    // Guards the cone test above against a vacuous pass: its samples reach the rim.
    let rim = (0..1000)
        .map(|i| sample_uniform_cone(Vec2::new(0.9999, i as f32 / 1000.0), 0.3))
        .all(|d| (d.z - 0.3).abs() < 1e-3);
    assert!(rim);
    assert!((uniform_cone_pdf(-1.0) - 1.0 / (4.0 * PI)).abs() < 1e-7);
}
