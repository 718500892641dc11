use glam::{Vec2, Vec3};

use super::source::one_sided;
use super::spherical::{self, SphericalRectangle};
use super::triangle::solid_angle;
use super::{
    flat_importance, LightBounds, LightFlags, LightSample, LightSource, ShadingCtx, TriangleLight,
};
use crate::geometry::Aabb;
use crate::math::luminance;
use crate::options::LampSampling;

/// An emitting parallelogram p₀ + a·e₁ + b·e₂, (a, b) ∈ [0, 1]²: the two triangles of an
/// emitting quad (a rectangle light, the Cornell box's lamp) made one light at build time
/// (see [`ParallelogramLight::from_triangles`]). Emits `le` on the side its normal `n`
/// points to, Lambertian.
///
/// Why one light rather than two triangles: the light point is then one 2D sample over
/// the whole quad, p = p₀ + u.x·e₁ + u.y·e₂, so a stratified 2D request (Sobol') is
/// stratified over the whole lamp; with two triangle lights, the 1D light pick splits the
/// samples between the triangles and each triangle gets a random half of the net. The
/// warp is also cheaper (no fold) and the light sampler has one light fewer to pick.
///
/// Sampled uniformly by area; the density in solid angle at the shading point is
/// p_ω = d² / (|cos θ_l| · A), as for [`TriangleLight`]. With
/// [`LampSampling::SolidAngle`], a rectangle that is near (see `spherical::near`) has
/// its direction drawn in the spherical rectangle it covers instead, weighted by the
/// receiver's cosine (`SphericalRectangle`); a parallelogram with skewed corners stays
/// sampled by area.
#[derive(Clone, Debug)]
pub struct ParallelogramLight {
    pub p0: Vec3,
    pub e1: Vec3,
    pub e2: Vec3,
    /// Unit normal of the emitting side.
    pub n: Vec3,
    pub area: f32,
    pub le: Vec3,
    /// Dual vectors of (e₁, e₂) in the plane: (q − p₀)·`d1` = a, (q − p₀)·`d2` = b.
    d1: Vec3,
    d2: Vec3,
    /// Where the edges are orthogonal: their unit vectors and lengths.
    rectangle: Option<Rectangle>,
    /// Whether a near point is drawn in the solid angle the rectangle covers.
    pub sampling: LampSampling,
}

/// The frame of a rectangular [`ParallelogramLight`].
#[derive(Clone, Copy, Debug)]
struct Rectangle {
    x: Vec3,
    y: Vec3,
    lx: f32,
    ly: f32,
}

impl ParallelogramLight {
    /// A light for the parallelogram p0 + a·e1 + b·e2 with unit normal `n` (the emitting
    /// side; it should be ±(e1 × e2) normalized). `None` where it is degenerate.
    pub fn new(p0: Vec3, e1: Vec3, e2: Vec3, n: Vec3, le: Vec3) -> Option<ParallelogramLight> {
        let c = e1.cross(e2);
        let area = c.length();
        if !(area > 0.0 && area.is_finite()) {
            return None;
        }
        // Solve q = a·e1 + b·e2 in the plane: a = q·(e2 × c)/|c|², b = q·(c × e1)/|c|².
        let inv = 1.0 / (area * area);
        let (lx, ly) = (e1.length(), e2.length());
        // Orthogonal to 10⁻⁵ rad: the spherical rectangle is then exact to f32 precision.
        let rectangle = (e1.dot(e2).abs() <= 1e-5 * lx * ly).then(|| Rectangle {
            x: e1 / lx,
            y: e2 / ly,
            lx,
            ly,
        });
        Some(ParallelogramLight {
            p0,
            e1,
            e2,
            n,
            area,
            le,
            d1: e2.cross(c) * inv,
            d2: c.cross(e1) * inv,
            rectangle,
            sampling: LampSampling::Area,
        })
    }

    /// The parallelogram the two triangles `a` and `b` tile exactly, if they do: they
    /// share an edge, their other two corners are opposite (the diagonals bisect each
    /// other, to a relative 10⁻⁶ of the size), both emit `le` towards the same normal and
    /// neither is shaped by a profile or a texture. Then sampling the parallelogram
    /// samples the union of the triangles, so a ray that hits either finds this light with
    /// the same pdf.
    pub fn from_triangles(a: &TriangleLight, b: &TriangleLight) -> Option<ParallelogramLight> {
        let plain = |t: &TriangleLight| t.profile.is_none() && t.texture.is_none();
        if !plain(a) || !plain(b) || a.le != b.le {
            return None;
        }
        if a.n.dot(b.n) < 1.0 - 1e-6 || a.area == 0.0 || b.area == 0.0 {
            return None;
        }
        // The corner of `a` that `b` lacks, and the corner of `b` that `a` lacks.
        let lone = |t: &TriangleLight, o: &TriangleLight| -> Option<usize> {
            let shared = t.p.map(|q| o.p.contains(&q));
            if shared.iter().filter(|s| **s).count() != 2 {
                return None;
            }
            shared.iter().position(|s| !s)
        };
        let (ia, ib) = (lone(a, b)?, lone(b, a)?);
        let (x, y) = (a.p[ia], b.p[ib]);
        let s0 = a.p[(ia + 1) % 3];
        let s1 = a.p[(ia + 2) % 3];
        let size = (s0 - x).abs().max((s1 - x).abs()).max_element();
        if ((x + y) - (s0 + s1)).abs().max_element() > 1e-6 * size {
            return None;
        }
        let quad = ParallelogramLight::new(x, s0 - x, s1 - x, a.n, a.le)?;
        Some(ParallelogramLight {
            sampling: a.sampling,
            ..quad
        })
    }

    /// The rectangle as the spherical rectangle it covers seen from `p`, where it is near
    /// enough to be drawn there (see [`spherical::near`]). Not from behind, where nothing
    /// is drawn either way.
    #[inline]
    fn spherical(&self, p: Vec3) -> Option<SphericalRectangle> {
        if self.sampling == LampSampling::Area || (p - self.p0).dot(self.n) <= 0.0 {
            return None;
        }
        let r = self.rectangle?;
        let centre = self.p0 + 0.5 * (self.e1 + self.e2);
        if !spherical::near(r.lx * r.lx + r.ly * r.ly, centre.distance_squared(p)) {
            return None;
        }
        SphericalRectangle::new(p, self.p0, r.x, r.y, r.lx, r.ly)
    }

    fn corners(&self) -> [Vec3; 4] {
        [
            self.p0,
            self.p0 + self.e1,
            self.p0 + self.e1 + self.e2,
            self.p0 + self.e2,
        ]
    }
}

impl LightSource for ParallelogramLight {
    const FLAGS: LightFlags = LightFlags::SURFACE;

    #[inline]
    fn sample_li(&self, ctx: &ShadingCtx, u: Vec2) -> Option<LightSample> {
        if let Some(sphere) = self.spherical(ctx.p) {
            let (q, pdf) = sphere.sample(ctx, u);
            return LightSample::uniform_area(ctx.p, q, self.n, self.area, |_| self.le)
                .map(|s| LightSample { pdf, ..s });
        }
        let p = self.p0 + self.e1 * u.x + self.e2 * u.y;
        LightSample::uniform_area(ctx.p, p, self.n, self.area, |_| self.le)
    }

    #[inline]
    fn pdf_li(&self, ctx: &ShadingCtx, wi: Vec3) -> f32 {
        let cos_l = -wi.dot(self.n);
        if cos_l <= 0.0 {
            return 0.0;
        }
        // Ray–plane distance, then the point's parallelogram coordinates.
        let t = (self.p0 - ctx.p).dot(self.n) / -cos_l;
        if !(t > 0.0 && t.is_finite()) {
            return 0.0;
        }
        let q = ctx.p + wi * t - self.p0;
        let (a, b) = (q.dot(self.d1), q.dot(self.d2));
        if !((0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b)) {
            return 0.0;
        }
        if let Some(sphere) = self.spherical(ctx.p) {
            return sphere.pdf(ctx, self.p0 + q);
        }
        t * t / (cos_l * self.area)
    }

    #[inline]
    fn radiance(&self, n: Vec3, _uv: Vec2, w: Vec3) -> Vec3 {
        one_sided(n, w, self.le)
    }

    /// Φ = π · A · L for a one-sided Lambertian emitter.
    fn power(&self) -> f32 {
        std::f32::consts::PI * self.area * luminance(self.le)
    }

    /// As [`TriangleLight::importance`], with the solid angle of the two triangles
    /// (p₀, p₁, p₂) and (p₀, p₂, p₃) summed.
    fn importance(&self, ctx: &ShadingCtx) -> f32 {
        if (ctx.p - self.p0).dot(self.n) <= 0.0 {
            return 0.0;
        }
        let [a, b, c, d] = self.corners().map(|q| q - ctx.p);
        let (la, lb, lc, ld) = (a.length(), b.length(), c.length(), d.length());
        let omega = solid_angle([a, b, c], [la, lb, lc]) + solid_angle([a, c, d], [la, lc, ld]);
        flat_importance(ctx, self.le, omega, &[a / la, b / lb, c / lc, d / ld])
    }

    /// One-sided Lambertian emitter: normal cone of zero width, emission up to 90°;
    /// peak intensity L·A along the normal.
    fn bounds(&self) -> Option<LightBounds> {
        Some(LightBounds {
            aabb: Aabb::from_points(&self.corners()),
            w: self.n,
            intensity: luminance(self.le) * self.area,
            cos_theta_o: 1.0,
            cos_theta_e: 0.0,
            two_sided: false,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(p: [Vec3; 3], le: Vec3) -> TriangleLight {
        let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
        TriangleLight::new(p, n, le)
    }

    #[test]
    fn a_quad_split_on_its_diagonal_is_one_parallelogram() {
        // The Cornell box lamp: f 1 2 3, f 1 3 4.
        let v = [
            Vec3::new(0.343, 0.5487, 0.227),
            Vec3::new(0.343, 0.5487, 0.332),
            Vec3::new(0.213, 0.5487, 0.332),
            Vec3::new(0.213, 0.5487, 0.227),
        ];
        let le = Vec3::new(17.0, 12.0, 4.0);
        let (a, b) = (tri([v[0], v[1], v[2]], le), tri([v[0], v[2], v[3]], le));
        let p = ParallelogramLight::from_triangles(&a, &b).expect("a parallelogram");
        assert!((p.area - (a.area + b.area)).abs() < 1e-7);
        assert_eq!(p.n, a.n);
        assert!((p.power() - (a.power() + b.power())).abs() < 1e-4 * p.power());
        let mut corners = p.corners().to_vec();
        corners.sort_by(|x, y| x.to_array().partial_cmp(&y.to_array()).unwrap());
        let mut want = v.to_vec();
        want.sort_by(|x, y| x.to_array().partial_cmp(&y.to_array()).unwrap());
        for (c, w) in corners.iter().zip(&want) {
            assert!((*c - *w).length() < 1e-6, "{c} vs {w}");
        }
        // The importance is that of the two triangles' solid angles together.
        let ctx = ShadingCtx {
            p: Vec3::new(0.3, 0.1, 0.25),
            n: Vec3::Y,
        };
        // (L·(Ω_a + Ω_b)·max cos over four corners, each triangle's max over three; below
        // the lamp the corners' cosines differ by a few per cent.)
        let sum = a.importance(&ctx) + b.importance(&ctx);
        assert!(
            p.importance(&ctx) >= sum * (1.0 - 1e-5),
            "{} vs {sum}",
            p.importance(&ctx)
        );
        assert!(
            p.importance(&ctx) < sum * 1.1,
            "{} vs {sum}",
            p.importance(&ctx)
        );
    }

    #[test]
    fn triangles_that_do_not_tile_a_parallelogram_stay_apart() {
        let le = Vec3::ONE;
        let (o, x, y) = (Vec3::ZERO, Vec3::X, Vec3::Y);
        let a = tri([o, x, y], le);
        // A kite: shares the edge x–y, but its far corner is not x + y.
        assert!(
            ParallelogramLight::from_triangles(&a, &tri([x, Vec3::new(1.2, 1.1, 0.0), y], le))
                .is_none()
        );
        // Folded: the far corner is off the plane.
        assert!(
            ParallelogramLight::from_triangles(&a, &tri([x, Vec3::new(1.0, 1.0, 0.3), y], le))
                .is_none()
        );
        // Different emission, or no shared edge.
        assert!(ParallelogramLight::from_triangles(&a, &tri([x, x + y, y], le * 2.0)).is_none());
        let far = Vec3::new(5.0, 0.0, 0.0);
        assert!(
            ParallelogramLight::from_triangles(&a, &tri([far + x, far + x + y, far + y], le))
                .is_none()
        );
        // Opposite windings (normals) are two lights.
        assert!(ParallelogramLight::from_triangles(&a, &tri([x, y, x + y], le)).is_none());
        assert!(ParallelogramLight::from_triangles(&a, &tri([x, x + y, y], le)).is_some());
    }

    /// By area the density towards the lamp's centre is d²/(A cos θ): 1/2 from 1 away,
    /// 50 from 10 away. Under [`LampSampling::SolidAngle`] the lamp is drawn on the sphere
    /// from 1 away (its density there is the chi-square suite's) and still by area from 10.
    /// Neither finds it off its outline or from behind.
    #[test]
    fn pdf_li_is_zero_off_the_parallelogram_and_behind_it() {
        let mut p =
            ParallelogramLight::new(Vec3::ZERO, Vec3::X, Vec3::Y * 2.0, -Vec3::Z, Vec3::ONE)
                .unwrap();
        let far = ShadingCtx {
            p: Vec3::new(0.5, 1.0, -10.0),
            n: Vec3::Z,
        };
        let ctx = ShadingCtx {
            p: Vec3::new(0.5, 1.0, -1.0),
            n: Vec3::Z,
        };
        assert!((p.pdf_li(&far, Vec3::Z) - 50.0).abs() < 1e-4);
        assert!((p.pdf_li(&ctx, Vec3::Z) - 0.5).abs() < 1e-6);
        p.sampling = LampSampling::SolidAngle;
        assert!((p.pdf_li(&far, Vec3::Z) - 50.0).abs() < 1e-4);
        let near = p.pdf_li(&ctx, Vec3::Z);
        assert!(near > 0.0 && (near - 0.5).abs() > 1e-3, "{near}");
        let off = (Vec3::new(1.2, 1.0, 0.0) - ctx.p).normalize();
        assert_eq!(p.pdf_li(&ctx, off), 0.0);
        assert_eq!(p.pdf_li(&ctx, -Vec3::Z), 0.0);
        let behind = ShadingCtx {
            p: Vec3::new(0.5, 1.0, 1.0),
            n: Vec3::Z,
        };
        assert_eq!(p.pdf_li(&behind, -Vec3::Z), 0.0);
        assert!(p.sample_li(&behind, Vec2::splat(0.5)).is_none());
        assert_eq!(p.importance(&behind), 0.0);
    }
}
