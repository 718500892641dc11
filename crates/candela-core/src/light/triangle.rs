use std::f32::consts::PI;
use std::sync::Arc;

use glam::{Vec2, Vec3};

use super::{flat_importance, LightBounds, LightProfile, LightSample, ShadingCtx};
use crate::geometry::Aabb;
use crate::geometry::{Ray, WatertightRay};
use crate::math::luminance;
use crate::sampling::sample_uniform_triangle;
use crate::texture::Texture;

/// One emitting triangle of a mesh. Emits `le` on the side its normal `n` points to.
/// Sampled uniformly by area; the density is converted to solid angle at the shading
/// point, p_ω = d² / (|cos θ_l| · A).
///
/// With a `profile` (an IES-shaped area light) the radiance leaving towards ω is
/// `le` · I(ω)/I_max, the profile's nadir along `n`: each point of the surface emits with
/// the profile's shape times the Lambertian cos θ, so the triangle's intensity is
/// A · `le` · cos θ · I(ω)/I_max. Sampling stays uniform by area (its density does not
/// depend on the emitted radiance; only the value does).
///
/// With a `texture` the radiance is `le` × the texture at the point's uv, and the
/// triangle still samples uniformly by area: light selection weighs the triangle by its
/// mean radiance (see [`EmissionTexture`]), so a triangle over a dark part of an image
/// is picked rarely.
#[derive(Clone, Debug)]
pub struct TriangleLight {
    pub p: [Vec3; 3],
    pub n: Vec3,
    pub area: f32,
    pub le: Vec3,
    pub profile: Option<LightProfile>,
    /// ∫ (radiance / `le`) cos θ dω over the hemisphere: π without a profile.
    pub projected_solid_angle: f32,
    pub texture: Option<EmissionTexture>,
}

/// The texture of a textured area light's triangle, its corners' uvs, and its mean over
/// the triangle.
#[derive(Clone, Debug)]
pub struct EmissionTexture {
    pub texture: Arc<Texture>,
    pub uv: [Vec2; 3],
    /// The texture's mean over the triangle's area, estimated at build (see
    /// [`EmissionTexture::new`]): what light selection sees in place of the texture.
    pub mean: Vec3,
}

impl EmissionTexture {
    /// The texture on the triangle with corner uvs `uv`. Its mean is the average of
    /// k² lookups at stratified points, k from the texels (or checker squares) the
    /// triangle covers, 1 to 32 a side. Light selection only weighs triangles by it, so it
    /// needs to be close, not exact. It is kept at least 10⁻³ of `floor` (the texture's
    /// [`Texture::mean`]) so that no triangle with light in it becomes unselectable
    /// because its lookups all fell on black.
    pub fn new(texture: Arc<Texture>, uv: [Vec2; 3], floor: Vec3) -> EmissionTexture {
        let uv_area = 0.5 * (uv[1] - uv[0]).perp_dot(uv[2] - uv[0]).abs();
        let k = (uv_area * texture.detail()).sqrt().ceil().clamp(1.0, 32.0) as u32;
        let mut sum = Vec3::ZERO;
        for i in 0..k {
            for j in 0..k {
                let u = Vec2::new(i as f32 + 0.5, j as f32 + 0.5) / k as f32;
                let b = sample_uniform_triangle(u);
                sum += texture.eval(uv[0] * b.x + uv[1] * b.y + uv[2] * b.z);
            }
        }
        let mean = (sum / (k * k) as f32).max(floor * 1e-3);
        EmissionTexture { texture, uv, mean }
    }

    /// The texture at barycentrics `b` (weights of the three corners).
    #[inline]
    fn at(&self, b: Vec3) -> Vec3 {
        self.texture
            .eval(self.uv[0] * b.x + self.uv[1] * b.y + self.uv[2] * b.z)
    }
}

impl TriangleLight {
    /// A light for a triangle with unit normal `n` (the emitting side).
    pub fn new(p: [Vec3; 3], n: Vec3, le: Vec3) -> TriangleLight {
        let area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length();
        TriangleLight {
            p,
            n,
            area,
            le,
            profile: None,
            projected_solid_angle: PI,
            texture: None,
        }
    }

    /// The same triangle with its radiance multiplied by `texture`.
    pub fn with_texture(self, texture: EmissionTexture) -> TriangleLight {
        TriangleLight {
            texture: Some(texture),
            ..self
        }
    }

    /// The radiance factor light selection sees: `le`, times the texture's mean.
    fn mean_le(&self) -> Vec3 {
        match &self.texture {
            None => self.le,
            Some(t) => self.le * t.mean,
        }
    }

    /// The same triangle shaped by `profile` (its nadir should be `n`), whose
    /// [`LightProfile::projected_solid_angle`] is `projected`.
    pub fn with_profile(self, profile: LightProfile, projected: f32) -> TriangleLight {
        TriangleLight {
            profile: Some(profile),
            projected_solid_angle: projected,
            ..self
        }
    }

    /// Radiance leaving towards the unit direction `w` on the emitting side, where the
    /// texture (if any) gives `tex`.
    fn emitted(&self, tex: Vec3, w: Vec3) -> Vec3 {
        let le = self.le * tex;
        match &self.profile {
            None => le,
            Some(p) => le * p.relative(w),
        }
    }

    pub fn sample_li(&self, ctx: &ShadingCtx, u: Vec2) -> Option<LightSample> {
        let b = sample_uniform_triangle(u);
        let p = self.p[0] * b.x + self.p[1] * b.y + self.p[2] * b.z;
        LightSample::uniform_area(ctx.p, p, self.n, self.area, |wi| {
            let tex = self.texture.as_ref().map_or(Vec3::ONE, |t| t.at(b));
            self.emitted(tex, -wi)
        })
    }

    pub fn pdf_li(&self, ctx: &ShadingCtx, wi: Vec3) -> f32 {
        let cos_l = -wi.dot(self.n);
        if cos_l <= 0.0 || self.area == 0.0 {
            return 0.0;
        }
        let ray = Ray::new(ctx.p, wi);
        match WatertightRay::new(&ray).intersect(self.p[0], self.p[1], self.p[2], f32::INFINITY) {
            Some(hit) => hit.t * hit.t / (cos_l * self.area),
            None => 0.0,
        }
    }

    /// Radiance leaving the point with texture coordinates `uv` (the mesh's, interpolated
    /// as [`crate::scene::Mesh::uv_at`] does) towards `w`.
    pub fn radiance(&self, n: Vec3, uv: Vec2, w: Vec3) -> Vec3 {
        if n.dot(w) > 0.0 {
            let tex = self
                .texture
                .as_ref()
                .map_or(Vec3::ONE, |t| t.texture.eval(uv));
            self.emitted(tex, w)
        } else {
            Vec3::ZERO
        }
    }

    /// Φ = A · L · ∫ shape · cos θ dω: π · A · L for a one-sided Lambertian emitter (L the
    /// texture's mean where there is one).
    pub fn power(&self) -> f32 {
        self.projected_solid_angle * self.area * luminance(self.mean_le())
    }

    /// L × Ω × the largest |cos| at the receiver over the three corners, where Ω is the
    /// exact solid angle of the triangle (Van Oosterom & Strackee 1983):
    /// tan(Ω/2) = |a·(b×c)| / (abc + (a·b)c + (a·c)b + (b·c)a).
    /// Zero where the point lies behind the emitting side: the plane through the triangle
    /// separates the point from the whole emitting hemisphere, so nothing reaches it.
    pub fn importance(&self, ctx: &ShadingCtx) -> f32 {
        if (ctx.p - self.p[0]).dot(self.n) <= 0.0 || self.area == 0.0 {
            return 0.0;
        }
        let [a, b, c] = self.p.map(|q| q - ctx.p);
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let omega = solid_angle([a, b, c], [la, lb, lc]);
        flat_importance(ctx, self.mean_le(), omega, &[a / la, b / lb, c / lc])
    }

    /// One-sided Lambertian emitter: normal cone of zero width, emission up to 90°;
    /// peak intensity L·A along the normal.
    pub fn bounds(&self) -> LightBounds {
        LightBounds {
            aabb: Aabb::from_points(&self.p),
            w: self.n,
            intensity: luminance(self.mean_le()) * self.area,
            cos_theta_o: 1.0,
            cos_theta_e: 0.0,
            two_sided: false,
        }
    }
}

/// Solid angle of the triangle with corners `v` relative to the viewer, whose lengths are
/// `len` (Van Oosterom & Strackee 1983).
pub(super) fn solid_angle(v: [Vec3; 3], len: [f32; 3]) -> f32 {
    let ([a, b, c], [la, lb, lc]) = (v, len);
    let num = a.dot(b.cross(c)).abs();
    let den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
    2.0 * num.atan2(den)
}

#[cfg(test)]
mod tests {
    use glam::Affine2;

    use super::*;

    fn checker(a: f32, b: f32, scale: f32) -> Arc<Texture> {
        Arc::new(Texture::Checker {
            a: Vec3::splat(a),
            b: Vec3::splat(b),
            uv_transform: Affine2::from_scale(Vec2::splat(scale)),
        })
    }

    /// The triangle uv (0, 0), (1, 0), (0, 1) over a checker of thirds holds 2.5 cells of
    /// `a` (the three on its diagonal are half inside) and 2 of `b`: mean (2.5a + 2b)/4.5.
    /// The estimate takes 5² lookups there (36 lookups a unit of uv area), so it is only
    /// close; 5 % is what its stratified points miss of the cells cut by the diagonal.
    #[test]
    fn the_mean_of_an_emission_texture_weighs_its_area() {
        let uv = [Vec2::ZERO, Vec2::X, Vec2::Y];
        let t = EmissionTexture::new(checker(4.0, 1.0, 3.0), uv, Vec3::ZERO);
        let exact = (2.5 * 4.0 + 2.0 * 1.0) / 4.5;
        assert!(
            (t.mean.x / exact - 1.0).abs() < 0.05,
            "{} vs {exact}",
            t.mean.x
        );
        // Inside one cell of `b`: exactly `b`, whatever the number of lookups.
        let small = [
            Vec2::new(0.4, 0.1),
            Vec2::new(0.5, 0.1),
            Vec2::new(0.4, 0.2),
        ];
        let t = EmissionTexture::new(checker(4.0, 1.0, 3.0), small, Vec3::ZERO);
        assert_eq!(t.mean, Vec3::ONE);
        // All black: the floor keeps it selectable.
        let t = EmissionTexture::new(checker(0.0, 0.0, 3.0), uv, Vec3::splat(2.0));
        assert_eq!(t.mean, Vec3::splat(2e-3));
    }

    /// Light selection sees the texture's mean, and the radiance its value at the point.
    #[test]
    fn a_textured_triangle_emits_its_texture() {
        let p = [Vec3::ZERO, Vec3::X, Vec3::Z];
        let uv = [Vec2::ZERO, Vec2::X, Vec2::Y];
        let tex = EmissionTexture::new(checker(4.0, 1.0, 2.0), uv, Vec3::ZERO);
        let mean = tex.mean;
        let light = TriangleLight::new(p, Vec3::Y, Vec3::splat(0.5)).with_texture(tex);
        let plain = TriangleLight::new(p, Vec3::Y, Vec3::splat(0.5));
        assert!((light.power() / plain.power() - luminance(mean)).abs() < 1e-5);
        assert_eq!(
            light.radiance(Vec3::Y, Vec2::new(0.1, 0.1), Vec3::Y),
            Vec3::splat(2.0)
        );
        assert_eq!(
            light.radiance(Vec3::Y, Vec2::new(0.6, 0.1), Vec3::Y),
            Vec3::splat(0.5)
        );
        assert_eq!(
            light.radiance(Vec3::Y, Vec2::new(0.6, 0.1), -Vec3::Y),
            Vec3::ZERO
        );
        // A sample's radiance is the texture at the sampled point's uv: here the point's
        // x and z are its u and v.
        let ctx = ShadingCtx {
            p: Vec3::new(0.2, 1.0, 0.3),
            n: -Vec3::Y,
        };
        let mut rng = crate::sampler::Pcg32::new(5, 7);
        for _ in 0..1000 {
            let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
            let s = light.sample_li(&ctx, u).expect("a point in front");
            let uv = Vec2::new(s.p_light.x, s.p_light.z);
            let want = 0.5 * light.texture.as_ref().unwrap().texture.eval(uv);
            assert!((s.radiance - want).abs().max_element() < 1e-5, "{uv}");
        }
    }
}
