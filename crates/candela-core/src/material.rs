//! Materials: what a surface is made of, turned into a [`Bsdf`] at each shading point.

use glam::{Vec2, Vec3};

use crate::bsdf::{Bsdf, Dielectric, Diffuse, Lobe, MetalRough, Plastic};
use crate::math::Frame;
use crate::sampler::hash_uniform;
use crate::scene::SurfaceInteraction;
pub use crate::texture::Texture;

/// Index of a material in [`crate::Scene::materials`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MaterialId(pub u32);

/// A material: textures to look up, and the lobe they parameterize.
#[derive(Clone, Debug)]
pub enum Material {
    Diffuse {
        albedo: Texture,
    },
    /// Lobes with no textured parameter, ready made at build time.
    Fixed(Lobe),
    Plastic {
        albedo: Texture,
        /// A template holding η, the coat and F_dr (computed once); the albedo is replaced.
        coat: Plastic,
    },
    MetalRough {
        base_color: Texture,
        metallic: Texture,
        roughness: Texture,
    },
    /// A rough or smooth dielectric whose transmission is tinted by a texture (times the
    /// vertex colour); `lobe` is a template whose tint is replaced.
    Dielectric {
        tint: Texture,
        lobe: Dielectric,
    },
    /// Bends the shading normal by a tangent-space normal map before the inner material.
    NormalMap {
        map: Texture,
        inner: Box<Material>,
    },
    /// Black from the back: see [`crate::desc::BsdfDesc::OneSided`].
    OneSided(Box<Material>),
    /// `a` with probability 1 − w and `b` with probability w at each shading point, w the
    /// weight texture's first channel clamped to [0, 1]. In expectation this is the BSDF
    /// (1 − w)·f_a + w·f_b, so the estimator stays unbiased; it costs one of the two
    /// lobes per hit rather than both (pbrt-v4's `MixMaterial` chooses the same way).
    /// The number deciding is a hash of the hit point, so a render stays reproducible
    /// and NEE and BSDF sampling at a vertex see the same lobe.
    Mix {
        weight: Texture,
        a: Box<Material>,
        b: Box<Material>,
        /// 1 + the highest `level` among the mixes inside this one. It salts the hash, so
        /// that a mix and any mix nested in it (whose levels are always lower) decide
        /// independently at the same point.
        level: u32,
    },
}

impl Material {
    /// The BSDF at a point with shading normal `ns`, geometric normal `ng` and texture
    /// coordinates `uv`, with the tangent taken from the shading frame (so a normal map's
    /// orientation is arbitrary; see [`Material::bsdf_with_tangent`]). The point is the
    /// origin, so a [`Material::Mix`] always chooses the side it chooses there.
    pub fn bsdf(&self, ns: Vec3, ng: Vec3, uv: Vec2) -> Bsdf {
        self.bsdf_with_tangent(ns, ng, uv, Frame::from_z(ns).s)
    }

    /// The BSDF with `dpdu` (the surface's ∂p/∂u) giving the tangent of the shading frame.
    pub fn bsdf_with_tangent(&self, ns: Vec3, ng: Vec3, uv: Vec2, dpdu: Vec3) -> Bsdf {
        self.bsdf_at(&SurfaceInteraction {
            p: Vec3::ZERO,
            t: 0.0,
            ng,
            ns,
            uv,
            dpdu,
            bitangent_sign: 1.0,
            color: Vec3::ONE,
            material: MaterialId(0),
            light: None,
        })
    }

    /// The BSDF at a surface interaction: its shading frame (tangent `dpdu`, bitangent
    /// sign), uvs, and vertex colour multiplying the base colour (diffuse and plastic
    /// albedo, metal_rough base colour; other lobes ignore it).
    ///
    /// A Lambertian material of constant or checkerboard albedo, most scenes' walls, is
    /// handled here and inlined into the caller, which then need not read the BSDF back
    /// from memory; the rest goes through `Self::bsdf_at_general`. (Out of line, the
    /// checkerboard walls of `bench/scenes/cornell-textured.xml` spent ~60 instructions a
    /// hit on the call's prologue and on writing the 164-byte BSDF out and reading it
    /// back.)
    #[inline(always)]
    pub fn bsdf_at(&self, si: &SurfaceInteraction) -> Bsdf {
        if let Material::Diffuse {
            albedo: albedo @ (Texture::Constant(_) | Texture::Checker { .. }),
        } = self
        {
            // The texture's `eval` inlines here to the constant, or the checker's choice,
            // times the vertex colour, as `lobe` computes it.
            let albedo = albedo.eval(si.uv) * si.color;
            return Bsdf::new(si.ns, si.ng, Lobe::Diffuse(Diffuse { albedo }));
        }
        self.bsdf_at_general(si)
    }

    /// [`Self::bsdf_at`] of every material but a Lambertian one of constant or checkerboard
    /// albedo.
    #[inline(never)]
    fn bsdf_at_general(&self, si: &SurfaceInteraction) -> Bsdf {
        match self {
            Material::NormalMap { map, inner } => {
                let texel = map.eval(si.uv);
                let ns = normal_mapped(si.ns, si.ng, si.dpdu, si.bitangent_sign, texel);
                inner.bsdf_at(&SurfaceInteraction { ns, ..*si })
            }
            Material::OneSided(inner) => Bsdf {
                one_sided: true,
                ..inner.bsdf_at(si)
            },
            Material::Mix {
                weight,
                a,
                b,
                level,
            } => {
                let w = weight.eval_scalar(si.uv).clamp(0.0, 1.0);
                if hash_uniform(*level as u64, &si.p.to_array()) < w {
                    b.bsdf_at(si)
                } else {
                    a.bsdf_at(si)
                }
            }
            // An isotropic lobe (Lambertian, or of one roughness on both axes) looks the
            // same in every frame around ns, so it skips orthogonalizing the tangent (a
            // square root and a division per hit).
            _ => {
                let lobe = self.lobe(si.uv, si.color);
                if lobe.is_isotropic() {
                    Bsdf::new(si.ns, si.ng, lobe)
                } else {
                    Bsdf::with_tangent(si.ns, si.ng, si.dpdu, lobe)
                }
            }
        }
    }

    #[inline(always)]
    fn lobe(&self, uv: Vec2, color: Vec3) -> Lobe {
        match self {
            Material::Diffuse { albedo } => Lobe::Diffuse(Diffuse {
                albedo: albedo.eval(uv) * color,
            }),
            Material::Fixed(lobe) => *lobe,
            Material::Dielectric { tint, lobe } => Lobe::Dielectric(Dielectric {
                tint: tint.eval(uv) * color,
                ..*lobe
            }),
            Material::Plastic { albedo, coat } => Lobe::Plastic(Plastic {
                albedo: (albedo.eval(uv) * color).min(Vec3::ONE),
                ..*coat
            }),
            Material::MetalRough {
                base_color,
                metallic,
                roughness,
            } => Lobe::MetalRough(MetalRough::new(
                base_color.eval(uv) * color,
                metallic.eval_scalar(uv),
                roughness.eval_scalar(uv),
            )),
            Material::NormalMap { inner, .. } | Material::OneSided(inner) => inner.lobe(uv, color),
            Material::Mix { .. } => unreachable!("bsdf_at_general chooses a mix's side"),
        }
    }

    /// Whether [`Self::bsdf_at`] reads the hit's uvs: a texture that is not constant, or
    /// a normal map.
    pub fn reads_uv(&self) -> bool {
        let varies = |t: &Texture| !matches!(t, Texture::Constant(_));
        match self {
            Material::Diffuse { albedo } => varies(albedo),
            Material::Fixed(_) => false,
            Material::Plastic { albedo, .. } => varies(albedo),
            Material::MetalRough {
                base_color,
                metallic,
                roughness,
            } => varies(base_color) || varies(metallic) || varies(roughness),
            Material::Dielectric { tint, .. } => varies(tint),
            Material::NormalMap { .. } => true,
            Material::OneSided(inner) => inner.reads_uv(),
            Material::Mix { weight, a, b, .. } => varies(weight) || a.reads_uv() || b.reads_uv(),
        }
    }

    /// Whether [`Self::bsdf_at`] reads the hit's ∂p/∂u or bitangent sign: the frame of an
    /// anisotropic lobe (see [`Lobe::is_isotropic`]), and normal maps.
    pub fn reads_dpdu(&self) -> bool {
        match self {
            Material::Diffuse { .. } => false,
            Material::Fixed(lobe) => !lobe.is_isotropic(),
            Material::Plastic { coat, .. } => !Lobe::Plastic(*coat).is_isotropic(),
            Material::Dielectric { lobe, .. } => !Lobe::Dielectric(*lobe).is_isotropic(),
            // One roughness on both axes (`MetalRough::new`).
            Material::MetalRough { .. } => false,
            Material::NormalMap { .. } => true,
            Material::OneSided(inner) => inner.reads_dpdu(),
            Material::Mix { a, b, .. } => a.reads_dpdu() || b.reads_dpdu(),
        }
    }

    /// The [`Material::Mix`] of `a` and `b` by `weight`, its level one above theirs.
    pub fn mix(weight: Texture, a: Material, b: Material) -> Material {
        Material::Mix {
            weight,
            level: 1 + a.mix_level().max(b.mix_level()),
            a: Box::new(a),
            b: Box::new(b),
        }
    }

    /// The [`Material::Mix`] `level` of this material: 0 for one holding no mix.
    fn mix_level(&self) -> u32 {
        match self {
            Material::Mix { level, .. } => *level,
            Material::NormalMap { inner, .. } | Material::OneSided(inner) => inner.mix_level(),
            _ => 0,
        }
    }
}

/// The shading normal a tangent-space normal map asks for, decoded as glTF stores it
/// (c·2 − 1), in the frame (t, sign·(ns × t), ns) with t = `dpdu` made orthogonal to
/// `ns` (glTF's bitangent rule: `sign` is TANGENT's w, or −1 where the uvs are mirrored). Never NaN, and never more than ~84° from the geometric normal's side: a
/// degenerate map value or one that would face away from the surface falls back to `ns`,
/// so the reflection/transmission test against `ng` stays meaningful.
pub fn normal_mapped(ns: Vec3, ng: Vec3, dpdu: Vec3, sign: f32, texel: Vec3) -> Vec3 {
    let m = texel * 2.0 - Vec3::ONE;
    let t = (dpdu - ns * ns.dot(dpdu)).normalize_or_zero();
    let t = if t == Vec3::ZERO {
        Frame::from_z(ns).s
    } else {
        t
    };
    let b = ns.cross(t) * sign;
    let n = (t * m.x + b * m.y + ns * m.z).normalize_or_zero();
    let ng = if ng.dot(ns) < 0.0 { -ng } else { ng };
    if !n.is_finite() || n.dot(ng) < 0.1 {
        ns
    } else {
        n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_map_follows_the_tangent_and_never_faces_away() {
        let (ns, ng, dpdu) = (Vec3::Z, Vec3::Z, Vec3::X);
        // The flat texel (0.5, 0.5, 1) keeps the normal.
        let flat = normal_mapped(ns, ng, dpdu, 1.0, Vec3::new(0.5, 0.5, 1.0));
        assert!((flat - Vec3::Z).length() < 1e-6);
        // Tilted towards +u.
        let n = normal_mapped(ns, ng, dpdu, 1.0, Vec3::new(0.85, 0.5, 0.85));
        assert!(
            n.x > 0.3 && n.y.abs() < 1e-6 && (n.length() - 1.0).abs() < 1e-5,
            "{n}"
        );
        // Degenerate or back-facing texels and tangents fall back to the shading normal.
        for texel in [
            Vec3::splat(0.5),
            Vec3::new(0.5, 0.5, 0.0),
            Vec3::new(1.0, 0.5, 0.5),
            Vec3::NAN,
        ] {
            for t in [Vec3::X, Vec3::ZERO, Vec3::Z, Vec3::NAN] {
                let n = normal_mapped(ns, ng, t, 1.0, texel);
                assert!(n.is_finite() && n.dot(ng) >= 0.1, "{texel} {t}: {n}");
            }
        }
    }
}

#[cfg(test)]
mod one_sided_tests {
    use super::*;

    #[test]
    fn one_sided_is_black_from_the_back_only() {
        let diffuse = Material::Diffuse {
            albedo: Texture::Constant(Vec3::splat(0.5)),
        };
        let two = diffuse.bsdf(Vec3::Z, Vec3::Z, Vec2::ZERO);
        let one = Material::OneSided(Box::new(diffuse)).bsdf(Vec3::Z, Vec3::Z, Vec2::ZERO);
        let (front, back) = (Vec3::new(0.3, 0.0, 0.9).normalize(), -Vec3::Z);
        let wi = Vec3::new(-0.2, 0.1, 0.8).normalize();
        assert_eq!(one.f(front, wi), two.f(front, wi));
        assert_eq!(one.pdf(front, wi), two.pdf(front, wi));
        assert!(one.sample(front, 0.5, Vec2::splat(0.3)).is_some());
        // From the back the two-sided diffuse reflects; the one-sided one is black.
        assert!(two.f(back, -wi).max_element() > 0.0);
        assert_eq!(one.f(back, -wi), Vec3::ZERO);
        assert_eq!(one.pdf(back, -wi), 0.0);
        assert!(one.sample(back, 0.5, Vec2::splat(0.3)).is_none());
    }
}

#[cfg(test)]
mod mix_tests {
    use super::*;

    fn diffuse(albedo: f32) -> Material {
        Material::Diffuse {
            albedo: Texture::Constant(Vec3::splat(albedo)),
        }
    }

    /// The albedo of the lobe `m` chooses at point `p` and texture coordinates `uv`.
    fn chosen(m: &Material, p: Vec3, uv: Vec2) -> f32 {
        let si = SurfaceInteraction {
            p,
            t: 1.0,
            ng: Vec3::Z,
            ns: Vec3::Z,
            uv,
            dpdu: Vec3::X,
            bitangent_sign: 1.0,
            color: Vec3::ONE,
            material: MaterialId(0),
            light: None,
        };
        match m.bsdf_at(&si).lobe {
            Lobe::Diffuse(d) => d.albedo.x,
            lobe => panic!("{lobe:?}"),
        }
    }

    /// Points spread over a few metres, none repeated.
    fn points(n: usize) -> impl Iterator<Item = Vec3> {
        (0..n).map(|i| {
            let t = i as f32;
            Vec3::new(
                t * 1.37e-3,
                (t * 0.618_034).fract() * 3.0,
                (t * 0.414_213).fract(),
            )
        })
    }

    #[test]
    fn a_mix_chooses_its_second_material_with_the_weights_probability() {
        // A mix of 0.3 around a mix of 0.6: the lobes' frequencies over 60 000 points
        // against 0.7, 0.3·0.4 and 0.3·0.6, by chi-square with 2 degrees of freedom at
        // α = 10⁻³ (13.82). The inner mix's choice would be fixed by the outer one's if
        // both hashed the point alike (then 0.3·0.4 would never come up).
        let m = Material::mix(
            Texture::Constant(Vec3::splat(0.3)),
            diffuse(0.1),
            Material::mix(
                Texture::Constant(Vec3::splat(0.6)),
                diffuse(0.2),
                diffuse(0.4),
            ),
        );
        let n = 60_000;
        let mut counts = [0f64; 3];
        for p in points(n) {
            let albedo = chosen(&m, p, Vec2::ZERO);
            assert_eq!(
                albedo,
                chosen(&m, p, Vec2::ZERO),
                "the same point, the same lobe"
            );
            counts[[0.1, 0.2, 0.4].iter().position(|&a| a == albedo).unwrap()] += 1.0;
        }
        let expected = [0.7, 0.12, 0.18].map(|q| q * n as f64);
        let chi2: f64 = (0..3)
            .map(|k| (counts[k] - expected[k]).powi(2) / expected[k])
            .sum();
        eprintln!("mix frequencies {counts:?} against {expected:?}: chi2 {chi2:.2}");
        assert!(chi2 < 13.82, "chi2 {chi2}: {counts:?} against {expected:?}");
    }

    #[test]
    fn a_mix_weight_is_read_where_the_point_is_and_clamped_to_0_1() {
        // A checker weight of 1.5 and −0.5: the second material on the squares above 1,
        // the first on those below 0, at every point.
        let m = Material::mix(
            Texture::Checker {
                a: Vec3::splat(1.5),
                b: Vec3::splat(-0.5),
                uv_transform: glam::Affine2::IDENTITY,
            },
            diffuse(0.1),
            diffuse(0.2),
        );
        let a_square = Texture::Checker {
            a: Vec3::ONE,
            b: Vec3::ZERO,
            uv_transform: glam::Affine2::IDENTITY,
        };
        for (i, p) in points(2000).enumerate() {
            let uv = Vec2::new((i % 37) as f32 / 37.0, (i % 53) as f32 / 53.0) * 4.0;
            let expected = if a_square.eval_scalar(uv) == 1.0 {
                0.2
            } else {
                0.1
            };
            assert_eq!(chosen(&m, p, uv), expected, "uv {uv}");
        }
    }

    /// What a material's BSDF reads of the hit: uvs where a texture varies or a normal
    /// map bends the normal, ∂p/∂u for every frame but a Lambertian one's, through
    /// one-sided and mixed materials.
    #[test]
    fn materials_say_which_surface_parameters_they_read() {
        let checker = Texture::Checker {
            a: Vec3::ZERO,
            b: Vec3::ONE,
            uv_transform: glam::Affine2::IDENTITY,
        };
        let textured = Material::Diffuse {
            albedo: checker.clone(),
        };
        let metal = Material::MetalRough {
            base_color: Texture::Constant(Vec3::ONE),
            metallic: Texture::Constant(Vec3::ONE),
            roughness: Texture::Constant(Vec3::splat(0.3)),
        };
        let reads = |m: &Material| (m.reads_uv(), m.reads_dpdu());
        assert_eq!(reads(&diffuse(0.5)), (false, false));
        assert_eq!(reads(&textured), (true, false));
        // Isotropic GGX: its frame's tangent is arbitrary.
        assert_eq!(reads(&metal), (false, false));
        let anisotropic = Material::Fixed(Lobe::Conductor(crate::bsdf::Conductor {
            distrib: crate::bsdf::Microfacet::beckmann(0.1, 0.3),
            fresnel: crate::bsdf::ConductorFresnel::Schlick { f0: Vec3::ONE },
        }));
        assert_eq!(reads(&anisotropic), (false, true));
        let normal_mapped = Material::NormalMap {
            map: Texture::Constant(Vec3::new(0.5, 0.5, 1.0)),
            inner: Box::new(diffuse(0.5)),
        };
        assert_eq!(reads(&normal_mapped), (true, true));
        assert_eq!(
            reads(&Material::OneSided(Box::new(diffuse(0.5)))),
            (false, false)
        );
        let constant_weight = Texture::Constant(Vec3::splat(0.5));
        let mix = Material::mix(constant_weight.clone(), diffuse(0.2), diffuse(0.8));
        assert_eq!(reads(&mix), (false, false));
        assert_eq!(
            reads(&Material::mix(checker, diffuse(0.2), diffuse(0.8))),
            (true, false)
        );
        assert_eq!(
            reads(&Material::mix(constant_weight, diffuse(0.2), anisotropic)),
            (false, true)
        );
    }
}
