//! Mitsuba XML import of BSDFs, textures, emitters and `hide_emitters`. Where Mitsuba's
//! behaviour is not plain from its documentation, the expected numbers were computed once
//! with Mitsuba 3.9.1 (`mitsuba` from PyPI, `scalar_rgb`); the script is quoted.

use std::sync::atomic::AtomicBool;

use candela_core::bsdf::{Conductor, Dielectric, Lobe, Microfacet};
use candela_core::build::{build, build_texture};
use candela_core::desc::*;
use candela_core::geometry::Ray;
use candela_scene::{load_scene_with, LoadOptions};
use candela_test_support::assert_close;
use candela_test_support::files::{load_files, options};
use candela_test_support::mitsuba::{load, load_err, scene};
use glam::{Vec2, Vec3};

/// The BSDF of the only material.
fn bsdf(body: &str) -> BsdfDesc {
    let desc = load(&scene(&format!("<shape type=\"cube\">{body}</shape>"))).desc;
    desc.materials[0].bsdf.clone()
}

/// Mitsuba 3.9.1's RGB (η, k) of its `Cu` conductor: `mi.traverse(mi.load_dict({'type':
/// 'conductor', 'material': 'Cu'}))` in `scalar_rgb`.
const MITSUBA_CU: ([f32; 3], [f32; 3]) =
    ([0.201005, 0.92375, 1.10222], [3.91326, 2.45305, 2.14209]);

#[test]
fn conductors_take_presets_or_eta_and_k_and_are_one_sided() {
    // Every material name Mitsuba knows, with the (η, k) its RGB variants use (3.9.1,
    // read as for MITSUBA_CU): four of its 71 names, one a dielectric (k = 0).
    for (name, eta, k) in [
        (
            "Au",
            [0.143036, 0.375307, 1.44205],
            [3.983, 2.38556, 1.60336],
        ),
        ("Cu", MITSUBA_CU.0, MITSUBA_CU.1),
        (
            "W",
            [4.37082, 3.30025, 2.99841],
            [3.50064, 2.60487, 2.27323],
        ),
        ("CsI_palik", [2.1449, 1.70232, 1.66243], [0.0, 0.0, 0.0]),
    ] {
        let body =
            format!(r#"<bsdf type="conductor"><string name="material" value="{name}"/></bsdf>"#);
        match bsdf(&body) {
            BsdfDesc::OneSided(inner) => match *inner {
                BsdfDesc::Conductor {
                    eta: e,
                    k: kk,
                    alpha_u,
                    alpha_v,
                    ..
                } => {
                    assert_eq!((e, kk, alpha_u, alpha_v), (eta.into(), k.into(), 0.0, 0.0));
                }
                other => panic!("{other:?}"),
            },
            other => panic!("{other:?}"),
        }
    }
    // Mitsuba's default material "none" reflects everything: η = 0, k = 1.
    match bsdf(r#"<bsdf type="twosided"><bsdf type="conductor"/></bsdf>"#) {
        BsdfDesc::Conductor { eta, k, .. } => assert_eq!((eta, k), (Vec3::ZERO, Vec3::ONE)),
        other => panic!("twosided is not one-sided: {other:?}"),
    }
    let rough = r#"<bsdf type="twosided"><bsdf type="roughconductor">
        <rgb name="eta" value="0.2, 0.9, 1.1"/><rgb name="k" value="3.9, 2.4, 1.6"/>
        <float name="alpha_u" value="0.05"/><float name="alpha_v" value="0.3"/>
        <string name="distribution" value="ggx"/></bsdf></bsdf>"#;
    match bsdf(rough) {
        BsdfDesc::Conductor {
            eta,
            k,
            specular,
            alpha_u,
            alpha_v,
            distribution,
        } => {
            assert_eq!(specular, Vec3::ONE);
            assert_eq!(eta, Vec3::new(0.2, 0.9, 1.1));
            assert_eq!(k, Vec3::new(3.9, 2.4, 1.6));
            assert_eq!((alpha_u, alpha_v), (0.05, 0.3));
            assert_eq!(distribution, MicrofacetDesc::Ggx);
        }
        other => panic!("{other:?}"),
    }
    // Mitsuba's default roughness is α = 0.1.
    match bsdf(r#"<bsdf type="twosided"><bsdf type="roughconductor"/></bsdf>"#) {
        BsdfDesc::Conductor {
            alpha_u, alpha_v, ..
        } => assert_eq!((alpha_u, alpha_v), (0.1, 0.1)),
        other => panic!("{other:?}"),
    }
    // The distribution maps exactly and silently: Mitsuba's default is beckmann, an
    // explicit beckmann or ggx is what it says, for conductors and dielectrics alike.
    let distribution = |d: &BsdfDesc| match d {
        BsdfDesc::Conductor { distribution, .. } | BsdfDesc::Dielectric { distribution, .. } => {
            *distribution
        }
        BsdfDesc::OneSided(inner) => match **inner {
            BsdfDesc::Conductor { distribution, .. } => distribution,
            ref other => panic!("{other:?}"),
        },
        other => panic!("{other:?}"),
    };
    for (body, want) in [
        (r#"<bsdf type="roughconductor"/>"#, MicrofacetDesc::Beckmann),
        (
            r#"<bsdf type="roughconductor"><string name="distribution" value="beckmann"/></bsdf>"#,
            MicrofacetDesc::Beckmann,
        ),
        (
            r#"<bsdf type="roughconductor"><string name="distribution" value="ggx"/></bsdf>"#,
            MicrofacetDesc::Ggx,
        ),
        (
            r#"<bsdf type="roughdielectric"/>"#,
            MicrofacetDesc::Beckmann,
        ),
        (
            r#"<bsdf type="roughdielectric"><string name="distribution" value="ggx"/>
               <float name="alpha_u" value="0.1"/><float name="alpha_v" value="0.2"/></bsdf>"#,
            MicrofacetDesc::Ggx,
        ),
    ] {
        let loaded = load(&scene(&format!(r#"<shape type="cube">{body}</shape>"#)));
        assert_eq!(distribution(&loaded.desc.materials[0].bsdf), want, "{body}");
        assert!(loaded.warnings.is_empty(), "{body}: {:?}", loaded.warnings);
        // And the build renders it with that distribution.
        let scene = build(&loaded.desc).unwrap();
        let lobe = match &scene.materials[0] {
            candela_core::material::Material::OneSided(inner) => match **inner {
                candela_core::material::Material::Fixed(lobe) => lobe,
                ref other => panic!("{other:?}"),
            },
            candela_core::material::Material::Fixed(lobe) => *lobe,
            other => panic!("{other:?}"),
        };
        let built = match lobe {
            Lobe::Conductor(Conductor { distrib, .. })
            | Lobe::Dielectric(Dielectric { distrib, .. }) => distrib,
            other => panic!("{other:?}"),
        };
        assert_eq!(
            matches!(built, Microfacet::Beckmann(_)),
            want == MicrofacetDesc::Beckmann,
            "{body}: {built:?}"
        );
    }
    // An unknown distribution is an error at the property's position.
    let e = load_err(&scene(
        r#"<shape type="cube"><bsdf type="roughdielectric">
           <string name="distribution" value="phong"/></bsdf></shape>"#,
    ));
    assert!(
        e.contains("scene.xml:3:") && e.contains("unknown microfacet distribution \"phong\""),
        "{e}"
    );
    for (body, what) in [
        (
            r#"<bsdf type="conductor"><string name="material" value="au"/></bsdf>"#,
            "\"au\" is not one of Mitsuba's conductor materials",
        ),
        (
            r#"<bsdf type="conductor"><rgb name="eta" value="1"/></bsdf>"#,
            "both eta and k",
        ),
        (
            r#"<bsdf type="roughconductor"><float name="alpha_u" value="0.1"/></bsdf>"#,
            "alpha_u and alpha_v",
        ),
        (
            r#"<bsdf type="roughconductor"><string name="distribution" value="phong"/></bsdf>"#,
            "phong",
        ),
        (
            r#"<bsdf type="conductor"><texture type="checkerboard" name="specular_reflectance"/></bsdf>"#,
            "\"specular_reflectance\" other than 1 is not supported",
        ),
    ] {
        let e = load_err(&scene(&format!("<shape type=\"cube\">{body}</shape>")));
        assert!(e.contains(what), "{e}");
    }
}

#[test]
fn a_conductors_specular_reflectance_scales_its_fresnel_term() {
    // Mitsuba's conductor.cpp and roughconductor.cpp multiply the Fresnel term by
    // specular_reflectance. The importer carries the colour over, and the built lobe is
    // the plain conductor's times it, for every direction (a closed form: same D, G).
    let (eta, k) = (Vec3::from(MITSUBA_CU.0), Vec3::from(MITSUBA_CU.1));
    let scale = Vec3::new(0.5, 0.7, 0.9);
    let body = r#"<bsdf type="twosided"><bsdf type="roughconductor"><string name="material" value="Cu"/>
        <rgb name="specular_reflectance" value="0.5, 0.7, 0.9"/><float name="alpha" value="0.3"/></bsdf></bsdf>"#;
    let d = bsdf(body);
    match &d {
        BsdfDesc::Conductor { specular, .. } => assert_eq!(*specular, scale),
        other => panic!("{other:?}"),
    }
    let scene = build(&load(&scene(&format!("<shape type=\"cube\">{body}</shape>"))).desc).unwrap();
    let scaled = match &scene.materials[0] {
        candela_core::material::Material::Fixed(Lobe::Conductor(c)) => *c,
        other => panic!("{other:?}"),
    };
    assert_eq!(
        scaled.fresnel,
        candela_core::bsdf::ConductorFresnel::ScaledComplex { eta, k, scale }
    );
    let plain = Conductor {
        fresnel: candela_core::bsdf::ConductorFresnel::Complex { eta, k },
        ..scaled
    };
    for (wo, wi) in [
        (Vec3::Z, Vec3::new(0.6, 0.0, 0.8)),
        (Vec3::new(0.0, 0.8, 0.6), Vec3::new(-0.28, 0.0, 0.96)),
    ] {
        assert_close(scaled.f(wo, wi), scale * plain.f(wo, wi), 1e-6);
    }
}

#[test]
fn dielectrics_read_numbers_and_named_indices() {
    match bsdf(r#"<bsdf type="dielectric"/>"#) {
        // Mitsuba's defaults: BK7 inside (1.5046), air outside (1.000277).
        BsdfDesc::Dielectric {
            eta, alpha_u, thin, ..
        } => {
            assert!((eta - 1.5046 / 1.000277).abs() < 1e-6);
            assert_eq!((alpha_u, thin), (0.0, false));
        }
        other => panic!("{other:?}"),
    }
    let water_in_glass = r#"<bsdf type="roughdielectric"><string name="int_ior" value="water"/>
        <float name="ext_ior" value="1.5"/><float name="alpha" value="0.2"/></bsdf>"#;
    match bsdf(water_in_glass) {
        BsdfDesc::Dielectric {
            eta,
            alpha_u,
            alpha_v,
            thin,
            ..
        } => {
            assert!((eta - 1.333 / 1.5).abs() < 1e-6);
            assert_eq!((alpha_u, alpha_v, thin), (0.2, 0.2, false));
        }
        other => panic!("{other:?}"),
    }
    match bsdf(r#"<bsdf type="thindielectric"><string name="int_ior" value="diamond"/></bsdf>"#) {
        BsdfDesc::Dielectric { eta, thin, .. } => {
            assert!((eta - 2.419 / 1.000277).abs() < 1e-6);
            assert!(thin);
        }
        other => panic!("{other:?}"),
    }
    for (body, what) in [
        (
            r#"<bsdf type="dielectric"><string name="int_ior" value="unobtainium"/></bsdf>"#,
            "unobtainium",
        ),
        (
            r#"<bsdf type="dielectric"><float name="int_ior" value="-1"/></bsdf>"#,
            "positive",
        ),
        (
            r#"<bsdf type="dielectric"><rgb name="specular_reflectance" value="0.5"/></bsdf>"#,
            "specular_reflectance",
        ),
    ] {
        let e = load_err(&scene(&format!("<shape type=\"cube\">{body}</shape>")));
        assert!(e.contains(what), "{e}");
    }
}

#[test]
fn a_dielectrics_specular_transmittance_is_its_tint() {
    // Mitsuba's dielectric and roughdielectric multiply every refraction by
    // specular_transmittance, which is what Candela's tint does (the transmitted lobe
    // only); thin sheets have no tint, so there it stays refused unless it is 1.
    let tint = |body: &str| match bsdf(body) {
        BsdfDesc::Dielectric { tint, .. } => tint,
        other => panic!("{other:?}"),
    };
    match tint(
        r#"<bsdf type="dielectric"><rgb name="specular_transmittance" value="0.9, 0.5, 0.2"/></bsdf>"#,
    ) {
        TextureDesc::Constant(c) => assert_eq!(c, Vec3::new(0.9, 0.5, 0.2)),
        t => panic!("{t:?}"),
    }
    assert!(matches!(
        tint(
            r#"<bsdf type="roughdielectric"><texture type="checkerboard" name="specular_transmittance"/></bsdf>"#
        ),
        TextureDesc::Checker { .. }
    ));
    match tint(r#"<bsdf type="dielectric"/>"#) {
        TextureDesc::Constant(c) => assert_eq!(c, Vec3::ONE),
        t => panic!("{t:?}"),
    }
    let e = load_err(&scene(
        r#"<shape type="cube"><bsdf type="thindielectric">
             <rgb name="specular_transmittance" value="0.5"/></bsdf></shape>"#,
    ));
    assert!(
        e.contains("scene.xml:3:14:") && e.contains("\"specular_transmittance\" other than 1"),
        "{e}"
    );
}

#[test]
fn plastics_become_candelas_plastic_smooth_or_rough_linear_or_not() {
    let plastic = |body: &str| match bsdf(body) {
        BsdfDesc::OneSided(inner) => match *inner {
            BsdfDesc::Plastic {
                albedo: TextureDesc::Constant(c),
                eta,
                alpha,
                distribution,
                linear,
                specular,
            } => {
                assert_eq!(
                    specular,
                    Vec3::ONE,
                    "clear unless specular_reflectance says"
                );
                (c, eta, alpha, distribution, linear)
            }
            other => panic!("{other:?}"),
        },
        other => panic!("{other:?}"),
    };
    let (c, eta, alpha, distribution, linear) = plastic(
        r#"<bsdf type="roughplastic">
           <rgb name="diffuse_reflectance" value="0.1, 0.2, 0.3"/>
           <float name="int_ior" value="1.6"/><float name="alpha" value="0.3"/>
           <string name="distribution" value="ggx"/>
           <boolean name="nonlinear" value="true"/></bsdf>"#,
    );
    assert_eq!(c, Vec3::new(0.1, 0.2, 0.3));
    assert!((eta - 1.6 / 1.000277).abs() < 1e-6);
    assert_eq!(
        (alpha, distribution, linear),
        (0.3, MicrofacetDesc::Ggx, false)
    );
    // Mitsuba's defaults: α 0.1, Beckmann, the linear base term, η 1.49 / 1.000277.
    let (c, eta, alpha, distribution, linear) = plastic(r#"<bsdf type="roughplastic"/>"#);
    assert_eq!(c, Vec3::splat(0.5));
    assert!((eta - 1.49 / 1.000277).abs() < 1e-6);
    assert_eq!(
        (alpha, distribution, linear),
        (0.1, MicrofacetDesc::Beckmann, true)
    );
    // A smooth plastic has no roughness to give.
    let (_, _, alpha, _, linear) = plastic(r#"<bsdf type="plastic"/>"#);
    assert_eq!((alpha, linear), (0.0, true));
    // specular_reflectance tints the coat.
    let b = bsdf(
        r#"<bsdf type="plastic"><rgb name="specular_reflectance" value="0.2, 0.5, 0.9"/></bsdf>"#,
    );
    let BsdfDesc::OneSided(inner) = b else {
        panic!("{b:?}")
    };
    assert!(
        matches!(*inner, BsdfDesc::Plastic { specular, .. } if specular == Vec3::new(0.2, 0.5, 0.9)),
        "{inner:?}"
    );
    let e = load_err(&scene(
        r#"<shape type="cube"><bsdf type="plastic">
             <float name="alpha" value="0.2"/></bsdf></shape>"#,
    ));
    assert!(e.contains("scene.xml:3:") && e.contains("alpha"), "{e}");
    let e = load_err(&scene(
        r#"<shape type="cube"><bsdf type="roughplastic">
             <float name="alpha_u" value="0.2"/><float name="alpha_v" value="0.1"/></bsdf></shape>"#,
    ));
    assert!(e.contains("scene.xml:2:") && e.contains("one alpha"), "{e}");
}

#[test]
fn a_linear_plastic_evaluates_to_mitsubas_diffuse_term() {
    use candela_core::bsdf::fresnel::{fresnel_dielectric, fresnel_diffuse_reflectance};
    use candela_core::bsdf::Plastic;
    // Mitsuba's default plastic (nonlinear=false), its plastic.cpp:
    //   f_d = ρ (1 − F(θi)) (1 − F(θo)) / (π η² (1 − F_dr)),
    // F_dr the coat's internal diffuse reflectance, and a nonlinear one ρ/(1 − ρ F_dr).
    let rho = Vec3::new(0.7, 0.2, 0.05);
    let eta = 1.5f32;
    let fdr = fresnel_diffuse_reflectance(1.0 / eta);
    for linear in [true, false] {
        let plastic = Plastic {
            linear,
            ..Plastic::new(rho, eta)
        };
        for (wo, wi) in [
            (Vec3::Z, Vec3::new(0.6, 0.0, 0.8)),
            (Vec3::new(0.0, 0.8, 0.6), Vec3::new(-0.28, 0.0, 0.96)),
        ] {
            let (fo, fi) = (fresnel_dielectric(wo.z, eta), fresnel_dielectric(wi.z, eta));
            let denom = if linear {
                Vec3::splat(1.0 - fdr)
            } else {
                Vec3::ONE - rho * fdr
            };
            let mitsuba =
                rho * (1.0 - fi) * (1.0 - fo) / (std::f32::consts::PI * eta * eta) / denom;
            assert_close(plastic.f(wo, wi), mitsuba, 1e-6);
        }
    }
}

#[test]
fn a_rough_plastic_evaluates_close_to_mitsubas_roughplastic() {
    // f·cos θi of Mitsuba's roughplastic at five pairs (ωo towards the camera, ωi towards
    // the light; a normal-incidence view, two off-specular pairs, a mirror pair, a
    // grazing pair):
    //   b = mi.load_string("<bsdf version='3.0.0' type='roughplastic'>...</bsdf>")
    //   si.wi = ωo; b.eval(mi.BSDFContext(), si, ωi)
    // Bound: 1.5 % of each channel. Mitsuba integrates the coat's internal reflectance
    // F_dr as 2·mean(R(μ)μ) over 64 cosines from 0 to 1 inclusive, about 1.4 % low (0.5882
    // for a smooth η = 1.5 coat, whose exact F_dr is 0.5963), so its linear base term
    // ρ/(1 − F_dr) is up to 1.3 % below Candela's; the nonlinear one differs by ≤ 0.5 %,
    // and the coat lobes (height-correlated masking here, separable there) by ≤ 0.5 %.
    // Roughplastic as a smooth coat was 18 % off on a rendered sphere.
    let pairs = [
        ([0.0, 0.0, 1.0], [0.6, 0.0, 0.8]),
        ([0.0, 0.8, 0.6], [-0.28, 0.0, 0.96]),
        ([0.5, 0.0, 0.866], [-0.5, 0.0, 0.866]),
        ([0.9, 0.1, 0.3], [-0.8, 0.0, 0.5]),
        ([0.2, 0.1, 0.97], [0.95, 0.1, 0.2]),
    ];
    let ggx_linear = [
        [0.146794, 0.0668420, 0.0268660],
        [0.166372, 0.0731256, 0.0265024],
        [0.246119, 0.159626, 0.116380],
        [0.320675, 0.276857, 0.254948],
        [0.0294463, 0.0128604, 0.00456748],
    ];
    // The first case with specular_reflectance (0.2, 0.5, 0.9), which multiplies the
    // coat's reflection and nothing else.
    let ggx_linear_tinted = [
        [0.141292, 0.063403, 0.0261782],
        [0.163819, 0.0715302, 0.0261834],
        [0.170314, 0.112248, 0.106904],
        [0.12548, 0.15486, 0.230549],
        [0.0291095, 0.0126499, 0.00452538],
    ];
    let beckmann_nonlinear = [
        [0.114713, 0.0457590, 0.0206900],
        [0.133109, 0.0527549, 0.0235409],
        [0.128157, 0.0536373, 0.0265444],
        [0.160454, 0.120671, 0.106207],
        [0.0246088, 0.00890474, 0.00319532],
    ];
    for (props, want) in [
        (
            r#"<string name="distribution" value="ggx"/><float name="alpha" value="0.2"/>
               <float name="int_ior" value="1.5"/><float name="ext_ior" value="1"/>"#,
            ggx_linear,
        ),
        (
            r#"<string name="distribution" value="ggx"/><float name="alpha" value="0.2"/>
               <float name="int_ior" value="1.5"/><float name="ext_ior" value="1"/>
               <rgb name="specular_reflectance" value="0.2, 0.5, 0.9"/>"#,
            ggx_linear_tinted,
        ),
        (
            r#"<float name="alpha" value="0.5"/><boolean name="nonlinear" value="true"/>"#,
            beckmann_nonlinear,
        ),
    ] {
        let body = format!(
            r#"<shape type="cube"><bsdf type="roughplastic">{props}
               <rgb name="diffuse_reflectance" value="0.7, 0.3, 0.1"/></bsdf></shape>"#
        );
        let scene = build(&load(&scene(&body)).desc).unwrap();
        let bsdf = scene.materials[0].bsdf(Vec3::Z, Vec3::Z, Vec2::ZERO);
        for ((wo, wi), want) in pairs.iter().zip(want) {
            let (wo, wi) = (Vec3::from(*wo).normalize(), Vec3::from(*wi).normalize());
            let ratio = bsdf.f(wo, wi) * wi.z / Vec3::from(want);
            assert!(
                (ratio - Vec3::ONE).abs().max_element() < 0.015,
                "{props} {wo} {wi}: Candela / Mitsuba = {ratio}"
            );
        }
    }
}

/// A 2 × 2 8-bit RGB PNG: top row red, green; bottom row blue, white, each channel at 128.
fn png_2x2() -> Vec<u8> {
    let mut img = image::RgbImage::new(2, 2);
    img.put_pixel(0, 0, image::Rgb([128, 0, 0]));
    img.put_pixel(1, 0, image::Rgb([0, 128, 0]));
    img.put_pixel(0, 1, image::Rgb([0, 0, 128]));
    img.put_pixel(1, 1, image::Rgb([128, 128, 128]));
    let mut bytes = std::io::Cursor::new(Vec::new());
    img.write_to(&mut bytes, image::ImageFormat::Png).unwrap();
    bytes.into_inner()
}

fn albedo(desc: &SceneDesc) -> candela_core::texture::Texture {
    let BsdfDesc::OneSided(inner) = &desc.materials[0].bsdf else {
        panic!("{:?}", desc.materials[0].bsdf)
    };
    let BsdfDesc::Diffuse { albedo } = inner.as_ref() else {
        panic!("{inner:?}")
    };
    build_texture(albedo, &Span::code(), "albedo").unwrap()
}

#[test]
fn a_linear_bitmap_plastic_divides_each_lookup_by_one_minus_f_dr() {
    use candela_core::bsdf::fresnel::{fresnel_dielectric, fresnel_diffuse_reflectance};
    // Mitsuba's linear base term ρ(uv)/(1 − F_dr) at every uv, the texture looked up as it
    // is (an albedo remapped per texel and then filtered was 8 % darker than Mitsuba's on
    // a plastic of random 8 × 8 texels).
    let x = scene(
        r#"<shape type="rectangle"><bsdf type="plastic"><float name="int_ior" value="1.5"/>
           <float name="ext_ior" value="1"/>
           <texture type="bitmap" name="diffuse_reflectance"><string name="filename" value="t.png"/></texture>
           </bsdf></shape>"#,
    );
    let png = png_2x2();
    let loaded = load_files(
        &[("scene.xml", x.as_bytes()), ("t.png", &png)],
        &options(&[], false),
    )
    .1
    .map_err(|e| e.to_string())
    .unwrap();
    let scene = build(&loaded.desc).unwrap();
    let fdr = fresnel_diffuse_reflectance(1.0 / 1.5);
    let srgb_128 = 0.215_861;
    let (wo, wi) = (Vec3::Z, Vec3::new(0.6, 0.0, 0.8));
    let t = (1.0 - fresnel_dielectric(1.0, 1.5)) * (1.0 - fresnel_dielectric(0.8, 1.5));
    // The top-left texel (red), the middle of the image (the mean of all four), and a
    // quarter of the way across the top row (half red, half green).
    for (uv, rho) in [
        (Vec2::new(0.25, 0.25), Vec3::new(srgb_128, 0.0, 0.0)),
        (Vec2::new(0.5, 0.5), Vec3::splat(srgb_128 / 2.0)),
        (
            Vec2::new(0.5, 0.25),
            Vec3::new(srgb_128, srgb_128, 0.0) / 2.0,
        ),
    ] {
        let bsdf = scene.materials[0].bsdf(Vec3::Z, Vec3::Z, uv);
        let want = rho * t / (std::f32::consts::PI * 1.5 * 1.5 * (1.0 - fdr));
        assert_close(bsdf.f(wo, wi), want, 1e-5);
    }
}

#[test]
fn bitmaps_are_looked_up_as_mitsuba_does() {
    let png = png_2x2();
    let xml = |extra: &str| {
        scene(&format!(
            r#"<shape type="cube"><bsdf type="diffuse">
               <texture type="bitmap" name="reflectance"><string name="filename" value="t.png"/>{extra}</texture>
               </bsdf></shape>"#
        ))
    };
    let load_tex = |extra: &str| {
        let x = xml(extra);
        let loaded = load_files(
            &[("scene.xml", x.as_bytes()), ("t.png", &png)],
            &options(&[], false),
        )
        .1
        .map_err(|e| e.to_string())
        .unwrap_or_else(|e| panic!("{e}"));
        albedo(&loaded.desc)
    };
    // Mitsuba's uv (0, 0) is the image's top-left texel: red. sRGB 128 is 0.2158 linear.
    let srgb_128 = 0.215_861;
    let t = load_tex("");
    assert_close(
        t.eval(Vec2::new(0.25, 0.25)),
        Vec3::new(srgb_128, 0.0, 0.0),
        1e-4,
    );
    assert_close(
        t.eval(Vec2::new(0.75, 0.25)),
        Vec3::new(0.0, srgb_128, 0.0),
        1e-4,
    );
    assert_close(
        t.eval(Vec2::new(0.25, 0.75)),
        Vec3::new(0.0, 0.0, srgb_128),
        1e-4,
    );
    // `raw` keeps the stored values: 128/255.
    let t = load_tex(r#"<boolean name="raw" value="true"/>"#);
    assert_close(
        t.eval(Vec2::new(0.75, 0.75)),
        Vec3::splat(128.0 / 255.0),
        1e-4,
    );
    // to_uv scales before the lookup: u = 0.25 · 3 = 0.75 lands on the green texel.
    let t = load_tex(r#"<transform name="to_uv"><scale x="3" y="1"/></transform>"#);
    assert_close(
        t.eval(Vec2::new(0.25, 0.25)),
        Vec3::new(0.0, srgb_128, 0.0),
        1e-4,
    );
    // Clamping keeps the edge texel beyond the image; repeating wraps around.
    let t = load_tex(r#"<string name="wrap_mode" value="clamp"/>"#);
    assert_close(
        t.eval(Vec2::new(1.75, 0.25)),
        Vec3::new(0.0, srgb_128, 0.0),
        1e-4,
    );
    let t = load_tex("");
    assert_close(
        t.eval(Vec2::new(1.25, 0.25)),
        Vec3::new(srgb_128, 0.0, 0.0),
        1e-4,
    );
    let x = xml(r#"<string name="wrap_mode" value="spiral"/>"#);
    let e = load_files(
        &[("scene.xml", x.as_bytes()), ("t.png", &png)],
        &options(&[], false),
    )
    .1
    .map_err(|e| e.to_string())
    .unwrap_err();
    assert!(e.contains("spiral") && e.contains("scene.xml:3:"), "{e}");
    let e = load_files(&[("scene.xml", xml("").as_bytes())], &options(&[], false))
        .1
        .map_err(|e| e.to_string())
        .unwrap_err();
    assert!(e.contains("t.png"), "{e}");
}

#[test]
fn checkerboards_and_texture_references() {
    // Mitsuba's checkerboard: colour0 where the fractional parts of u and v are on the
    // same side of ½ (its `checkerboard.cpp`); defaults 0.4 and 0.2.
    let loaded = load(&scene(
        r#"<texture type="checkerboard" id="checks"><rgb name="color1" value="0.9, 0.1, 0.1"/></texture>
           <shape type="cube"><bsdf type="diffuse"><ref name="reflectance" id="checks"/></bsdf></shape>"#,
    ));
    let t = albedo(&loaded.desc);
    let (c0, c1) = (Vec3::splat(0.4), Vec3::new(0.9, 0.1, 0.1));
    for (uv, c) in [
        ((0.25, 0.25), c0),
        ((0.75, 0.75), c0),
        ((0.75, 0.25), c1),
        ((0.25, 0.75), c1),
        ((1.25, 0.25), c0),
        ((-0.25, 0.25), c1),
    ] {
        assert_eq!(t.eval(Vec2::new(uv.0, uv.1)), c, "at {uv:?}");
    }
    let e = load_err(&scene(
        r#"<shape type="cube"><bsdf type="diffuse"><ref name="reflectance" id="nope"/></bsdf></shape>"#,
    ));
    assert!(e.contains("nope"), "{e}");
    let e = load_err(&scene(r#"<texture type="checkerboard"/>"#));
    assert!(e.contains("needs an id"), "{e}");
}

#[test]
fn textured_spheres_carry_mitsubas_uvs() {
    // Mitsuba 3.9.1, scalar_rgb: rays towards the centre from five directions; si.p, si.uv.
    //   sc = mi.load_string(<the shape below, without the bsdf>)
    //   c = sc.shapes()[0].bbox().center()   # (1.433013, 2.25, 3)
    //   n = dr.normalize(mi.Vector3f(d)); si = sc.ray_intersect(mi.Ray3f(c + 10*n, -n))
    let shape = |bsdf: &str| {
        format!(
            r#"<shape type="sphere"><point name="center" x="0.5" y="0" z="0"/>
               <float name="radius" value="2"/>{bsdf}
               <transform name="to_world"><rotate x="1" angle="90"/><rotate z="1" angle="30"/>
               <translate x="1" y="2" z="3"/></transform></shape>"#
        )
    };
    let plain = load(&scene(&shape(""))).desc;
    assert!(matches!(
        plain.shapes[0].geometry,
        GeometryDesc::Sphere { .. }
    ));
    let desc = load(&scene(&shape(
        r#"<bsdf type="diffuse"><texture type="checkerboard" name="reflectance"/></bsdf>"#,
    )))
    .desc;
    assert!(matches!(desc.shapes[0].geometry, GeometryDesc::Mesh(_)));
    let scene = build(&desc).unwrap();
    let centre = Vec3::new(1.433013, 2.25, 3.0);
    for (p, uv) in [
        ([3.314455, 2.814432, 3.376289], [0.030933, 0.42745]),
        ([0.759291, 3.934304, 3.842152], [0.202567, 0.854803]),
        ([1.809301, 1.685567, 1.118558], [0.753693, 0.390088]),
        ([-0.189201, 1.276671, 3.648886], [0.447405, 0.494935]),
        ([2.007709, 3.782522, 1.850609], [0.88255, 0.674041]),
    ] {
        let n = (Vec3::from(p) - centre).normalize();
        let si = scene
            .intersect(&Ray::new(centre + 10.0 * n, -n), f32::INFINITY)
            .expect("hits the sphere");
        // Tessellated at 1/128 in u, 1/64 in v: within a triangle the uv is linear in the
        // position, off by second-order terms (< 10⁻³); a mirrored u or a pole on another
        // axis is off by 0.1 or more.
        assert!(
            (si.uv - Vec2::from(uv)).abs().max_element() < 2e-3,
            "{} vs {uv:?}",
            si.uv
        );
        assert_close(si.p, Vec3::from(p), 2e-3);
        assert!(si.ns.dot(n) > 0.999, "normal {} at {p:?}", si.ns);
    }
}

/// The one light of a scene.
fn light(body: &str) -> LightKindDesc {
    let desc = load(&scene(body)).desc;
    assert_eq!(desc.lights.len(), 1);
    desc.lights[0].kind.clone()
}

#[test]
fn spot_and_directional_emitters_map_with_mitsubas_defaults() {
    let spot = light(
        r#"<emitter type="spot"><rgb name="intensity" value="2, 3, 4"/>
           <float name="cutoff_angle" value="30"/>
           <transform name="to_world"><lookat origin="1, 2, 3" target="1, 2, 2" up="0, 1, 0"/></transform>
           </emitter>"#,
    );
    match spot {
        LightKindDesc::Spot(s) => {
            assert_close(s.position, Vec3::new(1.0, 2.0, 3.0), 1e-6);
            assert_close(s.direction, Vec3::new(0.0, 0.0, -1.0), 1e-6);
            // beam_width defaults to ¾ of the cutoff angle.
            assert_eq!((s.inner_angle_deg, s.outer_angle_deg), (22.5, 30.0));
            assert_eq!(s.falloff, SpotFalloff::Mitsuba);
            assert_eq!(s.color, LightColorDesc::Rgb(Vec3::new(2.0, 3.0, 4.0)));
            assert_eq!(s.amount, LightAmountDesc::WattsPerSr(1.0));
        }
        other => panic!("{other:?}"),
    }
    let e = load_err(&scene(
        r#"<emitter type="spot"><float name="cutoff_angle" value="10"/><float name="beam_width" value="20"/></emitter>"#,
    ));
    assert!(e.contains("beam_width"), "{e}");
    match light(
        r#"<emitter type="directional"><vector name="direction" value="0, -1, 0"/>
           <rgb name="irradiance" value="5"/></emitter>"#,
    ) {
        LightKindDesc::Directional(d) => {
            assert_eq!(d.direction, Vec3::NEG_Y);
            assert_eq!(d.color, LightColorDesc::Rgb(Vec3::splat(5.0)));
            assert_eq!(d.amount, LightAmountDesc::WattsPerSr(1.0));
        }
        other => panic!("{other:?}"),
    }
    // Without a direction, to_world sends the light along its local +z.
    match light(
        r#"<emitter type="directional"><transform name="to_world"><rotate x="1" angle="90"/></transform></emitter>"#,
    ) {
        LightKindDesc::Directional(d) => assert_close(d.direction, Vec3::NEG_Y, 1e-6),
        other => panic!("{other:?}"),
    }
}

/// An 8 × 4 EXR whose texel (i, j) is (i + 1, j + 1, 1).
#[test]
fn projectors_cast_their_irradiance_as_mitsubas_do() {
    // Radiant intensity towards points, as Mitsuba 3.9.1 scalar_rgb gives it: for a
    // projector `e` and a point p, `ds, spec = e.sample_direction(it, ...)` with
    // it.p = p, then spec · ds.dist². The bitmap is 4 × 2, pixel (i, j) = (i + 1, j + 1,
    // 10) with j = 0 the top row; Mitsuba looks it up bilinearly with repeat wrapping (the
    // fourth point lies within half a texel of the corner, so it reads the opposite
    // edges), and I = π · scale · E / cos³θ.
    let dir = tempfile::tempdir().unwrap();
    let pixels: Vec<f32> = (0..2)
        .flat_map(|j| (0..4).flat_map(move |i| [i as f32 + 1.0, j as f32 + 1.0, 10.0]))
        .collect();
    exr::prelude::write_rgb_file(dir.path().join("p.exr"), 4, 2, |x, y| {
        let k = 3 * (y * 4 + x);
        (pixels[k], pixels[k + 1], pixels[k + 2])
    })
    .unwrap();
    let bitmap = r#"<texture type="bitmap" name="irradiance"><string name="filename" value="p.exr"/></texture>"#;
    /// Points and Mitsuba's intensity towards each.
    type Points = [(Vec3, [f32; 3]); 5];
    let cases: [(&str, Points); 3] = [
        (
            r#"<float name="fov" value="90"/><float name="scale" value="2"/>"#,
            [
                (Vec3::new(0.0, 0.0, 1.0), [15.708, 9.42478, 62.8319]),
                (Vec3::new(0.25, 0.125, 1.0), [14.0674, 8.79212, 70.3369]),
                (Vec3::new(-0.75, -0.25, 2.0), [25.3887, 13.6709, 78.1192]),
                (Vec3::new(0.95, 0.45, 1.0), [42.2163, 26.8649, 191.893]),
                (Vec3::new(0.5, -0.1, 0.7), [12.748, 21.2466, 118.981]),
            ],
        ),
        (
            r#"<float name="fov" value="60"/>
               <transform name="to_world"><lookat origin="1, 2, 3" target="1, 2, 0" up="0, 1, 0"/></transform>"#,
            [
                (Vec3::new(1.0, 2.0, 2.0), [7.85398, 4.71239, 31.4159]),
                (Vec3::new(0.75, 2.125, 2.0), [5.74644, 3.75243, 35.1685]),
                (Vec3::new(1.75, 1.75, 1.0), [14.8389, 7.55027, 39.0596]),
                (Vec3::new(0.05, 2.45, 2.0), [0.0, 0.0, 0.0]),
                (Vec3::new(0.5, 1.9, 2.3), [0.0, 0.0, 0.0]),
            ],
        ),
        // A constant irradiance of 1 (a 1 × 1 image, so a square frustum).
        (
            r#"<rgb name="irradiance" value="1"/><float name="fov" value="90"/>"#,
            [
                (Vec3::new(0.0, 0.0, 1.0), [std::f32::consts::PI; 3]), // Mitsuba: 3.14159
                (Vec3::new(0.5, 0.0, 1.0), [4.39051; 3]),
                (Vec3::new(0.0, 0.5, 1.0), [4.39051; 3]),
                (Vec3::new(0.9, 0.4, 1.0), [8.68659; 3]),
                (Vec3::new(2.0, 0.0, 1.0), [0.0; 3]),
            ],
        ),
    ];
    for (props, points) in cases {
        let texture = if props.contains("irradiance") {
            ""
        } else {
            bitmap
        };
        let xml = scene(&format!(
            r#"<emitter type="projector">{texture}{props}</emitter>"#
        ));
        std::fs::write(dir.path().join("scene.xml"), &xml).unwrap();
        let loaded =
            load_scene_with(&dir.path().join("scene.xml"), &LoadOptions::default()).unwrap();
        let built = build(&loaded.desc).unwrap();
        let candela_core::light::Light::Projector(p) = &built.lights[0] else {
            panic!("{:?}", loaded.desc.lights)
        };
        for (point, want) in points {
            let i = p.intensity_towards((point - p.position).normalize());
            let want = Vec3::from(want);
            assert!(
                (i - want).abs().max_element() <= 2e-5 * want.max_element().max(1.0),
                "{props} {point}: {i} against Mitsuba's {want}"
            );
        }
    }
}

fn exr_8x4(path: &std::path::Path) {
    exr::prelude::write_rgb_file(path, 8, 4, |i, j| ((i + 1) as f32, (j + 1) as f32, 1.0f32))
        .unwrap();
}

#[test]
fn envmaps_face_where_mitsuba_faces_them() {
    // Reference values from Mitsuba 3.9.1 (scalar_rgb), the same 8 × 4 map:
    //   s = mi.load_dict({'type': 'scene', 'env': {'type': 'envmap', 'filename': 'env.exr',
    //        'to_world': mi.ScalarTransform4f.rotate([0, 1, 0], rot)}})
    //   si = mi.SurfaceInteraction3f(); si.wi = -d; s.emitters()[0].eval(si)
    // On the horizon Mitsuba and Candela both give the mean of rows 1 and 2 in green
    // (2.5); red tells the longitude.
    let expected = [
        (0.0, Vec3::new(0.0, 0.0, -1.0), 4.5),
        (0.0, Vec3::new(1.0, 0.0, 0.0), 2.5),
        (0.0, Vec3::new(0.0, 0.0, 1.0), 4.5),
        (0.0, Vec3::new(-1.0, 0.0, 0.0), 6.5),
        (0.0, Vec3::new(0.6, 0.0, -0.8), 1.31933),
        (90.0, Vec3::new(0.0, 0.0, -1.0), 2.5),
        (90.0, Vec3::new(1.0, 0.0, 0.0), 4.5),
        (90.0, Vec3::new(0.0, 0.0, 1.0), 6.5),
        (90.0, Vec3::new(-1.0, 0.0, 0.0), 4.5),
        (90.0, Vec3::new(0.6, 0.0, -0.8), 3.31933),
    ];
    let dir = tempfile::tempdir().unwrap();
    exr_8x4(&dir.path().join("env.exr"));
    for rot in [0.0, 90.0] {
        let xml = scene(&format!(
            r#"<emitter type="envmap"><string name="filename" value="env.exr"/>
               <float name="scale" value="2"/>
               <transform name="to_world"><rotate y="1" angle="{rot}"/></transform></emitter>"#
        ));
        std::fs::write(dir.path().join("scene.xml"), xml).unwrap();
        let desc = load_scene_with(&dir.path().join("scene.xml"), &LoadOptions::default())
            .unwrap()
            .desc;
        let scene = build(&desc).unwrap();
        let env = scene.light(scene.infinite_lights[0]);
        for &(_, d, red) in expected.iter().filter(|e| e.0 == rot) {
            let le = env.le(&Ray::new(Vec3::ZERO, d));
            // `scale` 2 doubles the map.
            assert_close(le, 2.0 * Vec3::new(red, 2.5, 1.0), 1e-3);
        }
    }
    let e = load_err(&scene(
        r#"<emitter type="envmap"><string name="filename" value="missing.exr"/></emitter>"#,
    ));
    assert!(e.contains("missing.exr"), "{e}");
}

#[test]
fn constant_emitters_and_hidden_emitters() {
    let desc = load(&scene(
        r#"<emitter type="constant"><rgb name="radiance" value="0.5, 0.25, 1"/></emitter>"#,
    ))
    .desc;
    let built = build(&desc).unwrap();
    let env = built.light(built.infinite_lights[0]);
    assert_eq!(
        env.le(&Ray::new(Vec3::ZERO, Vec3::Y)),
        Vec3::new(0.5, 0.25, 1.0)
    );
    let e = load_err(&scene(
        r#"<emitter type="constant"/><emitter type="constant"/>"#,
    ));
    assert!(e.contains("at most one"), "{e}");

    // Mitsuba 3.9.1: rectangle scaled 0.5 with area radiance 3 and no BSDF, constant sky
    // 0.5, camera at z = 5, fov 40, 16 × 16, max_depth 3: centre pixel exactly 3 (an
    // emitter without a BSDF does not reflect) and corner 0.5; with hide_emitters both
    // are 0. With a diffuse BSDF on the square, the centre is 3.26 without and 0 with
    // hide_emitters: a camera ray that hits an emitter returns nothing at all.
    let body = |hide: bool| {
        format!(
            r#"<integrator type="path"><integer name="max_depth" value="3"/>
               <boolean name="hide_emitters" value="{hide}"/></integrator>
               <sensor type="perspective"><float name="fov" value="40"/>
                 <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
                 <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/>
                   <rfilter type="box"/></film>
                 <sampler type="independent"><integer name="sample_count" value="4"/></sampler></sensor>
               <shape type="rectangle"><transform name="to_world"><scale x="0.5" y="0.5"/></transform>
                 <emitter type="area"><rgb name="radiance" value="3"/></emitter></shape>
               <emitter type="constant"><rgb name="radiance" value="0.5"/></emitter>"#
        )
    };
    for (hide, centre, corner) in [(false, 3.0, 0.5), (true, 0.0, 0.0)] {
        let desc = load(&scene(&body(hide))).desc;
        assert_eq!(desc.render.hide_emitters, hide);
        let built = build(&desc).unwrap();
        let spp = desc.render.spp;
        let r = candela_core::integrator::render(&built, 0..spp, &AtomicBool::new(false), &|_| {});
        let img = r.film.resolve();
        let px = |x: usize, y: usize| img[y * 16 + x];
        assert_close(px(8, 8), Vec3::splat(centre), 1e-4);
        assert_close(px(0, 0), Vec3::splat(corner), 1e-4);
    }
}

#[test]
fn masks_become_stochastic_alpha_and_normalmaps_get_mitsubas_bitangent() {
    use candela_core::alpha::AlphaMode;
    // Mitsuba's `mask` keeps a hit with probability α (default 0.5) around the nested
    // BSDF, whose sidedness it keeps.
    let alpha = |b: &BsdfDesc| match b {
        BsdfDesc::Alpha { alpha, inner } => (alpha.clone(), inner.as_ref().clone()),
        b => panic!("{b:?}"),
    };
    let (a, inner) = alpha(&bsdf(
        r#"<bsdf type="mask"><float name="opacity" value="0.4"/><bsdf type="diffuse"/></bsdf>"#,
    ));
    assert_eq!(
        (a.mode, a.factor, a.texture.is_none()),
        (AlphaMode::Blend, 0.4, true)
    );
    assert!(matches!(inner, BsdfDesc::OneSided(_)), "{inner:?}");
    let (a, inner) = alpha(&bsdf(
        r#"<bsdf type="mask"><bsdf type="twosided"><bsdf type="diffuse"/></bsdf></bsdf>"#,
    ));
    assert_eq!(a.factor, 0.5);
    assert!(matches!(inner, BsdfDesc::Diffuse { .. }), "{inner:?}");
    let (a, _) = alpha(&bsdf(
        r#"<bsdf type="mask"><texture type="checkerboard" name="opacity"/><bsdf type="diffuse"/></bsdf>"#,
    ));
    assert!(matches!(a.texture, Some(TextureDesc::Checker { .. })) && a.factor == 1.0);
    let e = load_err(&scene(r#"<shape type="cube"><bsdf type="mask"/></shape>"#));
    assert!(
        e.contains("scene.xml:2:20:") && e.contains("one nested <bsdf>"),
        "{e}"
    );

    // A normal map on an OBJ: Mitsuba's bitangent is n × ∂p/∂u, so the importer gives
    // the mesh tangents ∂p/∂u with handedness +1 (the OBJ's flipped v would otherwise
    // flip Candela's bitangent).
    let obj = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
               f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
    let xml = scene(
        r#"<shape type="obj"><string name="filename" value="quad.obj"/>
             <bsdf type="normalmap"><texture type="checkerboard" name="normalmap"/>
               <bsdf type="diffuse"/></bsdf></shape>
           <shape type="obj"><string name="filename" value="quad.obj"/></shape>"#,
    );
    let desc = load_files(
        &[("scene.xml", xml.as_bytes()), ("quad.obj", obj.as_bytes())],
        &options(&[], false),
    )
    .1
    .map_err(|e| e.to_string())
    .unwrap()
    .desc;
    match &desc.materials[0].bsdf {
        BsdfDesc::NormalMap { map, inner } => {
            assert!(matches!(map, TextureDesc::Checker { .. }));
            assert!(matches!(inner.as_ref(), BsdfDesc::OneSided(_)), "{inner:?}");
        }
        b => panic!("{b:?}"),
    }
    let mesh = |i: usize| match &desc.shapes[i].geometry {
        GeometryDesc::Mesh(m) => m.clone(),
        g => panic!("{g:?}"),
    };
    assert_eq!(
        mesh(0).tangents,
        vec![glam::Vec4::new(1.0, 0.0, 0.0, 1.0); 4]
    );
    assert!(
        mesh(1).tangents.is_empty(),
        "only normal-mapped meshes get tangents"
    );
    let e = load_err(&scene(
        r#"<shape type="cube"><bsdf type="normalmap"><bsdf type="diffuse"/></bsdf></shape>"#,
    ));
    assert!(
        e.contains("scene.xml:2:20:") && e.contains("normalmap needs"),
        "{e}"
    );
}

#[test]
fn blendbsdfs_become_mixes_of_their_two_bsdfs_in_order() {
    let mix = |b: BsdfDesc| match b {
        BsdfDesc::Mix { weight, a, b } => (weight, *a, *b),
        b => panic!("{b:?}"),
    };
    let one_sided = |b: &BsdfDesc| match b {
        BsdfDesc::OneSided(inner) => inner.as_ref().clone(),
        b => panic!("{b:?}"),
    };
    // Weight 0 is the first BSDF, 1 the second; each keeps its own (one-)sidedness, as
    // in Mitsuba, where the blend of two one-sided BSDFs is black from the back.
    let (w, a, b) = mix(bsdf(
        r#"<bsdf type="blendbsdf"><float name="weight" value="0.3"/>
           <bsdf type="diffuse"/><bsdf type="conductor"/></bsdf>"#,
    ));
    assert!(matches!(w, TextureDesc::Constant(c) if c == Vec3::splat(0.3)));
    assert!(matches!(one_sided(&a), BsdfDesc::Diffuse { .. }), "{a:?}");
    assert!(matches!(one_sided(&b), BsdfDesc::Conductor { .. }), "{b:?}");
    // Inside a twosided both are two-sided.
    let (_, a, b) = mix(bsdf(
        r#"<bsdf type="twosided"><bsdf type="blendbsdf"><float name="weight" value="0.3"/>
           <bsdf type="diffuse"/><bsdf type="plastic"/></bsdf></bsdf>"#,
    ));
    assert!(matches!(a, BsdfDesc::Diffuse { .. }), "{a:?}");
    assert!(matches!(b, BsdfDesc::Plastic { .. }), "{b:?}");
    // References, in their order; an RGB weight is its mean (Mitsuba 3.9.1, scalar_rgb:
    // a blend of white and black diffuse with weight (0.2, 0.5, 0.9) evaluates to
    // 0.46667/π towards the normal, so w = 0.53333).
    let desc = load(&scene(
        r#"<bsdf type="diffuse" id="d"/><bsdf type="roughconductor" id="c"/>
           <bsdf type="blendbsdf" id="m"><rgb name="weight" value="0.2, 0.5, 0.9"/>
             <ref id="c"/><ref id="d"/></bsdf>
           <shape type="cube"><ref id="m"/></shape>"#,
    ))
    .desc;
    let m = desc.materials.iter().find(|m| m.name == "m").unwrap();
    let (w, a, b) = mix(m.bsdf.clone());
    assert!(
        matches!(w, TextureDesc::Constant(c) if (c - Vec3::splat(0.533_333)).abs().max_element() < 1e-6)
    );
    assert!(matches!(one_sided(&a), BsdfDesc::Conductor { .. }), "{a:?}");
    assert!(matches!(one_sided(&b), BsdfDesc::Diffuse { .. }), "{b:?}");
    build(&desc).expect("a blend builds");
    // A twosided around a <ref> to the blend makes both its BSDFs two-sided, as a blend
    // nested in the twosided would be.
    let desc = load(&scene(
        r#"<bsdf type="blendbsdf" id="m"><float name="weight" value="0.5"/>
             <bsdf type="diffuse"/><bsdf type="normalmap"><texture type="checkerboard" name="normalmap"/>
               <bsdf type="conductor"/></bsdf></bsdf>
           <shape type="cube"><bsdf type="twosided"><ref id="m"/></bsdf></shape>"#,
    ))
    .desc;
    let shape_material = &desc.shapes[0].material;
    let m = desc
        .materials
        .iter()
        .find(|m| &m.name == shape_material)
        .unwrap();
    let (_, a, b) = mix(m.bsdf.clone());
    assert!(matches!(a, BsdfDesc::Diffuse { .. }), "{a:?}");
    assert!(
        matches!(&b, BsdfDesc::NormalMap { inner, .. } if matches!(**inner, BsdfDesc::Conductor { .. })),
        "{b:?}"
    );
}

#[test]
fn blend_weights_and_mask_opacities_read_a_bitmap_as_its_luminance() {
    // Mitsuba reads a scalar parameter's bitmap through `eval_1`, the luminance of its
    // colour (3.9.1: a blend weight and a mask opacity of (0.2, 0.5, 0.9) both evaluate
    // to 0.46507, the Rec. 709 Y 0.4651). An inline colour is its mean (0.53333).
    let png = png_2x2();
    let srgb_128 = 0.215_861f32;
    let y = |c: Vec3| c.dot(Vec3::new(0.2126, 0.7152, 0.0722));
    for (wrapper, slot) in [("blendbsdf", "weight"), ("mask", "opacity")] {
        let second = if wrapper == "blendbsdf" {
            "<bsdf type=\"conductor\"/>"
        } else {
            ""
        };
        let x = scene(&format!(
            r#"<shape type="rectangle"><bsdf type="{wrapper}">
                 <texture type="bitmap" name="{slot}"><string name="filename" value="t.png"/></texture>
                 <bsdf type="diffuse"/>{second}</bsdf></shape>"#
        ));
        let loaded = load_files(
            &[("scene.xml", x.as_bytes()), ("t.png", &png)],
            &options(&[], false),
        )
        .1
        .map_err(|e| e.to_string())
        .unwrap();
        let texture = match &loaded.desc.materials[0].bsdf {
            BsdfDesc::Mix { weight, .. } => weight.clone(),
            BsdfDesc::Alpha { alpha, .. } => alpha.texture.clone().unwrap(),
            b => panic!("{b:?}"),
        };
        let t = build_texture(&texture, &Span::code(), slot).unwrap();
        // The top-left texel (red) and the middle (the mean of all four).
        for (uv, rgb) in [
            (Vec2::new(0.25, 0.25), Vec3::new(srgb_128, 0.0, 0.0)),
            (Vec2::new(0.5, 0.5), Vec3::splat(srgb_128 / 2.0)),
        ] {
            assert_close(t.eval(uv), Vec3::splat(y(rgb)), 1e-6);
        }
    }
    let (a, _) = match bsdf(
        r#"<bsdf type="mask"><rgb name="opacity" value="0.2, 0.5, 0.9"/><bsdf type="diffuse"/></bsdf>"#,
    ) {
        BsdfDesc::Alpha { alpha, inner } => (alpha, inner),
        b => panic!("{b:?}"),
    };
    assert!(
        (a.factor - 0.533_333).abs() < 1e-6 && a.texture.is_none(),
        "{a:?}"
    );

    // A checkerboard's squares swap: Mitsuba 3.9.1's checkerboard (color0 0.9, color1
    // 0.15, `to_uv` scale 4) evaluates at uv (0.05, 0.05) to 0.9 through `eval` (as a
    // reflectance) but to 0.15 through `eval_1` (as a weight).
    let checker = r#"<texture type="checkerboard" name="NAME"><float name="color0" value="0.9"/>
          <float name="color1" value="0.15"/><transform name="to_uv"><scale value="4"/></transform></texture>"#;
    let at = |t: &TextureDesc| {
        build_texture(t, &Span::code(), "checker")
            .unwrap()
            .eval(Vec2::splat(0.05))
            .x
    };
    let BsdfDesc::Mix { weight, a, .. } = bsdf(&format!(
        r#"<bsdf type="blendbsdf">{}<bsdf type="diffuse">{}</bsdf><bsdf type="diffuse"/></bsdf>"#,
        checker.replace("NAME", "weight"),
        checker.replace("NAME", "reflectance")
    )) else {
        panic!()
    };
    let BsdfDesc::OneSided(a) = *a else {
        panic!("{a:?}")
    };
    let BsdfDesc::Diffuse { albedo } = *a else {
        panic!("{a:?}")
    };
    assert_eq!((at(&albedo), at(&weight)), (0.9, 0.15));
}

#[test]
fn a_blendbsdf_without_a_weight_or_two_bsdfs_is_an_error_at_its_place() {
    for (body, what) in [
        (
            r#"<shape type="cube"><bsdf type="blendbsdf"><bsdf type="diffuse"/><bsdf type="diffuse"/></bsdf></shape>"#,
            "scene.xml:2:20: blendbsdf needs a `weight`",
        ),
        (
            r#"<shape type="cube"><bsdf type="blendbsdf"><float name="weight" value="0.5"/><bsdf type="diffuse"/></bsdf></shape>"#,
            "scene.xml:2:20: blendbsdf needs exactly two nested <bsdf> or <ref>, not 1",
        ),
    ] {
        let e = load_err(&scene(body));
        assert!(e.contains(what), "{e}");
    }
    // A mask belongs around the blend: inside it, it would have to blend coverage.
    let desc = load(&scene(
        r#"<shape type="cube"><bsdf type="blendbsdf"><float name="weight" value="0.5"/>
             <bsdf type="mask"><bsdf type="diffuse"/></bsdf><bsdf type="diffuse"/></bsdf></shape>"#,
    ))
    .desc;
    let e = build(&desc).map(|_| ()).unwrap_err().to_string();
    assert!(
        e.contains("an alpha mask inside a mix is not supported"),
        "{e}"
    );
}

#[test]
fn unknown_plugins_name_themselves() {
    for (body, what) in [
        (
            r#"<shape type="cube"><bsdf type="principled"/></shape>"#,
            "<bsdf type=\"principled\"> is not supported",
        ),
        (
            r#"<shape type="cube"><bsdf type="diffuse"><texture type="wireframe" name="reflectance"/></bsdf></shape>"#,
            "<texture type=\"wireframe\"> is not supported",
        ),
        (
            r#"<emitter type="sunsky"/>"#,
            "<emitter type=\"sunsky\"> is not supported",
        ),
    ] {
        let e = load_err(&scene(body));
        assert!(e.contains(what) && e.contains("scene.xml:2:"), "{e}");
        let loaded = load_files(
            &[("scene.xml", scene(body).as_bytes())],
            &options(&[], true),
        )
        .1
        .map_err(|e| e.to_string())
        .unwrap();
        assert!(
            loaded.warnings.iter().any(|w| w.contains(what)),
            "{:?}",
            loaded.warnings
        );
    }
}

#[test]
fn max_depth_counts_as_in_mitsuba() {
    // Inside a closed sphere that emits 1 and reflects ½ (diffuse, both sides), Mitsuba's
    // max_depth m sums m terms: L = Σ_{k<m} ½ᵏ = 1, 1.5, 1.75, 1.875. Mitsuba 3.9.1 gives
    // 1.0, 1.511, 1.765, 1.892 at 256 spp on this very scene (8 × 8, fov 60, centre).
    // Candela must agree within 4 standard errors of its pixel mean (two-sided, p ≈ 6e-5
    // per depth).
    for m in 1..=4 {
        let desc = load(&scene(&format!(
            r#"<integrator type="path"><integer name="max_depth" value="{m}"/></integrator>
               <sensor type="perspective"><float name="fov" value="60"/>
                 <transform name="to_world"><lookat origin="0, 0, 0" target="0, 0, -1" up="0, 1, 0"/></transform>
                 <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/>
                   <rfilter type="box"/></film>
                 <sampler type="independent"><integer name="sample_count" value="256"/></sampler></sensor>
               <shape type="sphere"><boolean name="flip_normals" value="true"/>
                 <bsdf type="twosided"><bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></bsdf>
                 <emitter type="area"><rgb name="radiance" value="1"/></emitter></shape>"#
        )))
        .desc;
        let scene = build(&desc).unwrap();
        let r = candela_core::integrator::render(&scene, 0..256, &AtomicBool::new(false), &|_| {});
        let px: Vec<f64> = r.film.resolve().iter().map(|p| p.x as f64).collect();
        let n = px.len() as f64;
        let mean = px.iter().sum::<f64>() / n;
        let se = (px.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt();
        let expected = 2.0 - 0.5f64.powi(m - 1);
        assert!(
            (mean - expected).abs() <= 4.0 * se.max(1e-6),
            "max_depth {m}: {mean} ± {se}, expected {expected}"
        );
    }
}

#[test]
fn pixel_filters_follow_the_film() {
    let filter = |rfilter: &str| {
        load(&scene(&format!(
            r#"<sensor type="perspective"><float name="fov" value="40"/><film type="hdrfilm">{rfilter}</film></sensor>"#
        )))
        .desc
        .render
        .filter
    };
    // Mitsuba's default is a Gaussian of σ = 0.5 truncated at 4σ.
    assert_eq!(
        filter(""),
        PixelFilterDesc::Gaussian {
            stddev: 0.5,
            radius: 2.0
        }
    );
    assert_eq!(filter(r#"<rfilter type="box"/>"#), PixelFilterDesc::Box);
    assert_eq!(
        filter(r#"<rfilter type="tent"><float name="radius" value="1.5"/></rfilter>"#),
        PixelFilterDesc::Tent { radius: 1.5 }
    );
    assert_eq!(
        filter(r#"<rfilter type="gaussian"><float name="stddev" value="0.25"/></rfilter>"#),
        PixelFilterDesc::Gaussian {
            stddev: 0.25,
            radius: 1.0
        }
    );
    let e = load_err(&scene(
        r#"<sensor type="perspective"><float name="fov" value="40"/><film type="hdrfilm"><rfilter type="tent"><float name="radius" value="0"/></rfilter></film></sensor>"#,
    ));
    assert!(e.contains("radius must be positive"), "{e}");
    let e = load_err(&scene(
        r#"<sensor type="perspective"><float name="fov" value="40"/><film type="hdrfilm"><rfilter type="lanczos"/></film></sensor>"#,
    ));
    assert!(
        e.contains("<rfilter type=\"lanczos\"> is not supported"),
        "{e}"
    );
}
