//! [`ImportanceBounds::importance`] of up to eight lights at once, in AVX2 lanes, with
//! the same bits: for the light BVH's flat picks (at most `FLAT_MAX` lights, each weighed
//! by its own bounds at every pick and every pmf) and for its descent, two levels (a
//! node's children and grandchildren) an evaluation, where the scalar form spent ~125
//! instructions a node.
//!
//! The lanes repeat the scalar operations one for one, in the same order and without
//! fused multiply-adds (the scalar code has none): IEEE `sqrt`, division, products and
//! sums round the same in a lane as in a scalar register, and each branch becomes a
//! blend of its two sides (both finite or discarded). `tests` compares both forms bit for
//! bit on random bounds and points.

#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::*;

use super::bounds::ImportanceBounds;
use super::ShadingCtx;

/// Lanes of one evaluation.
pub const LANES: usize = 8;

/// Up to [`LANES`] [`ImportanceBounds`], one per lane, field by field (lanes past the
/// lights repeat the first light; their results are to be ignored). Evaluated in AVX2
/// where the CPU has it, else lane by lane by the scalar code: the same bits either way.
#[derive(Clone, Debug)]
#[repr(C, align(32))]
pub struct ImportanceLanes {
    center: [[f32; LANES]; 3],
    radius: [f32; LANES],
    w: [[f32; LANES]; 3],
    intensity: [f32; LANES],
    cos_theta_o: [f32; LANES],
    sin_theta_o: [f32; LANES],
    cos_theta_e: [f32; LANES],
    /// All ones where two-sided, else 0 (a blend mask).
    two_sided: [u32; LANES],
}

impl ImportanceLanes {
    /// The lanes of `bounds`, one to [`LANES`] of them (lanes past them repeat the first).
    pub fn new(bounds: &[ImportanceBounds]) -> ImportanceLanes {
        assert!(
            (1..=LANES).contains(&bounds.len()),
            "{} bounds for {LANES} lanes",
            bounds.len()
        );
        let at = |i: usize| &bounds[if i < bounds.len() { i } else { 0 }];
        let lanes = |f: &dyn Fn(&ImportanceBounds) -> f32| std::array::from_fn(|i| f(at(i)));
        ImportanceLanes {
            center: [
                lanes(&|b| b.center.x),
                lanes(&|b| b.center.y),
                lanes(&|b| b.center.z),
            ],
            radius: lanes(&|b| b.radius),
            w: [lanes(&|b| b.w.x), lanes(&|b| b.w.y), lanes(&|b| b.w.z)],
            intensity: lanes(&|b| b.intensity),
            cos_theta_o: lanes(&|b| b.cos_theta_o),
            sin_theta_o: lanes(&|b| b.sin_theta_o),
            cos_theta_e: lanes(&|b| b.cos_theta_e),
            two_sided: std::array::from_fn(|i| if at(i).two_sided { u32::MAX } else { 0 }),
        }
    }

    /// Lane `i`'s bounds, field for field as they were given.
    fn bounds(&self, i: usize) -> ImportanceBounds {
        ImportanceBounds {
            center: glam::Vec3::new(self.center[0][i], self.center[1][i], self.center[2][i]),
            radius: self.radius[i],
            w: glam::Vec3::new(self.w[0][i], self.w[1][i], self.w[2][i]),
            intensity: self.intensity[i],
            cos_theta_o: self.cos_theta_o[i],
            sin_theta_o: self.sin_theta_o[i],
            cos_theta_e: self.cos_theta_e[i],
            two_sided: self.two_sided[i] != 0,
        }
    }

    /// Each lane's [`ImportanceBounds::importance`] by the scalar code: what
    /// [`Self::importance`] gives where the CPU lacks AVX2.
    pub fn importance_scalar(&self, ctx: &ShadingCtx) -> [f32; LANES] {
        std::array::from_fn(|i| self.bounds(i).importance(ctx))
    }

    /// Each lane's [`ImportanceBounds::importance`] at `ctx`, bit for bit.
    #[inline]
    pub fn importance(&self, ctx: &ShadingCtx) -> [f32; LANES] {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2.
            return unsafe { self.importance_avx2(ctx) };
        }
        self.importance_scalar(ctx)
    }

    /// [`Self::importance`] in AVX2; inlined into AVX2 callers that evaluate several
    /// lanes at one point, which then splat the point once.
    ///
    /// # Safety
    ///
    /// The CPU must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2")]
    #[inline]
    pub fn importance_avx2(&self, ctx: &ShadingCtx) -> [f32; LANES] {
        self.loaded().importance(ctx)
    }

    /// Whether every lane's radius is 0 (point and spot lights): then
    /// [`Self::importance_of_points_avx2`] gives [`Self::importance`]'s bits.
    pub fn all_points(&self) -> bool {
        self.radius.iter().all(|&r| r == 0.0)
    }

    /// [`Self::importance_avx2`] of lanes that are all points ([`Self::all_points`]), in
    /// fewer instructions ([`LoadedLanes::importance_of_points`]).
    ///
    /// # Safety
    ///
    /// The CPU must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2")]
    #[inline]
    pub fn importance_of_points_avx2(&self, ctx: &ShadingCtx) -> [f32; LANES] {
        debug_assert!(self.all_points());
        self.loaded().importance_of_points(ctx)
    }

    /// The lanes in AVX2 registers.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2")]
    #[inline]
    fn loaded(&self) -> LoadedLanes {
        // SAFETY (loads): every array is LANES f32 in a 32-byte aligned struct, at offsets
        // that are multiples of 32.
        let load = |a: &[f32; LANES]| unsafe { _mm256_load_ps(a.as_ptr()) };
        LoadedLanes {
            center: [
                load(&self.center[0]),
                load(&self.center[1]),
                load(&self.center[2]),
            ],
            radius: load(&self.radius),
            w: [load(&self.w[0]), load(&self.w[1]), load(&self.w[2])],
            intensity: load(&self.intensity),
            cos_theta_o: load(&self.cos_theta_o),
            sin_theta_o: load(&self.sin_theta_o),
            cos_theta_e: load(&self.cos_theta_e),
            // SAFETY: as the loads above.
            two_sided: unsafe { _mm256_load_ps(self.two_sided.as_ptr() as *const f32) },
        }
    }
}

/// Eight [`ImportanceBounds`] field by field in AVX2 registers: what
/// [`ImportanceLanes::importance_avx2`] evaluates, and what other layouts of bounds (the
/// light BVH's blocks) load theirs into.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy)]
pub struct LoadedLanes {
    pub center: [__m256; 3],
    pub radius: __m256,
    pub w: [__m256; 3],
    pub intensity: __m256,
    pub cos_theta_o: __m256,
    pub sin_theta_o: __m256,
    pub cos_theta_e: __m256,
    /// Two-sided where the sign bit is set (a blend mask).
    pub two_sided: __m256,
}

#[cfg(target_arch = "x86_64")]
impl LoadedLanes {
    /// Each lane's [`ImportanceBounds::importance`] at `ctx`, bit for bit; inlined into
    /// AVX2 callers.
    ///
    /// # Safety
    ///
    /// The CPU must have AVX2.
    #[target_feature(enable = "avx,avx2")]
    #[inline]
    pub fn importance(&self, ctx: &ShadingCtx) -> [f32; LANES] {
        self.evaluate::<false>(ctx)
    }

    /// [`Self::importance`] where every lane's radius is 0 (point and spot lights), the
    /// same bits for ~20 fewer instructions: the bounding sphere subtends no cone
    /// (sin θ_b = 0; cos θ_b = 1, or −1 at the light itself), so θ' = θ_x and the
    /// receiver's cosine need no sines. `tests` compares it with the scalar code.
    ///
    /// # Safety
    ///
    /// The CPU must have AVX2.
    #[target_feature(enable = "avx,avx2")]
    #[inline]
    pub fn importance_of_points(&self, ctx: &ShadingCtx) -> [f32; LANES] {
        self.evaluate::<true>(ctx)
    }

    /// [`Self::importance`], or where `POINTS` [`Self::importance_of_points`].
    #[target_feature(enable = "avx,avx2")]
    #[inline]
    fn evaluate<const POINTS: bool>(&self, ctx: &ShadingCtx) -> [f32; LANES] {
        let splat = _mm256_set1_ps;
        let (zero, one) = (_mm256_setzero_ps(), splat(1.0));
        let select = |mask: __m256, yes: __m256, no: __m256| _mm256_blendv_ps(no, yes, mask);
        let dot = |a: [__m256; 3], b: [__m256; 3]| {
            _mm256_add_ps(
                _mm256_add_ps(_mm256_mul_ps(a[0], b[0]), _mm256_mul_ps(a[1], b[1])),
                _mm256_mul_ps(a[2], b[2]),
            )
        };
        // `safe_sqrt`: maxps returns its second operand, 0, for a NaN, as `f32::max`.
        let safe_sqrt = |x: __m256| _mm256_sqrt_ps(_mm256_max_ps(x, zero));
        let one_minus_sq = |x: __m256| _mm256_sub_ps(one, _mm256_mul_ps(x, x));
        // `cos_sub_clamped` and `sin_sub_clamped`.
        let cos_sub = |sin_a, cos_a, sin_b, cos_b| {
            let v = _mm256_add_ps(_mm256_mul_ps(cos_a, cos_b), _mm256_mul_ps(sin_a, sin_b));
            select(_mm256_cmp_ps::<_CMP_GT_OQ>(cos_a, cos_b), one, v)
        };
        let sin_sub = |sin_a, cos_a, sin_b, cos_b| {
            let v = _mm256_sub_ps(_mm256_mul_ps(sin_a, cos_b), _mm256_mul_ps(cos_a, sin_b));
            select(_mm256_cmp_ps::<_CMP_GT_OQ>(cos_a, cos_b), zero, v)
        };

        let to = [
            _mm256_sub_ps(splat(ctx.p.x), self.center[0]),
            _mm256_sub_ps(splat(ctx.p.y), self.center[1]),
            _mm256_sub_ps(splat(ctx.p.z), self.center[2]),
        ];
        let d2 = dot(to, to);
        let positive = _mm256_cmp_ps::<_CMP_GT_OQ>(d2, zero);
        let inv_d = select(positive, _mm256_div_ps(one, _mm256_sqrt_ps(d2)), zero);
        let wi = [
            select(positive, _mm256_mul_ps(to[0], inv_d), zero),
            select(positive, _mm256_mul_ps(to[1], inv_d), zero),
            select(positive, _mm256_mul_ps(to[2], inv_d), one),
        ];
        let radius = self.radius;
        let d2c = _mm256_max_ps(d2, radius);
        let cos_w = dot(self.w, wi);
        let cos_w = select(self.two_sided, _mm256_andnot_ps(splat(-0.0), cos_w), cos_w);
        let sin_w = safe_sqrt(one_minus_sq(cos_w));
        let (sin_o, cos_o) = (self.sin_theta_o, self.cos_theta_o);
        let cos_x = cos_sub(sin_w, cos_w, sin_o, cos_o);
        // With a radius of 0, sin θ_b = 0·(1/d) = 0 and cos θ_b = √(1 − 0) = 1 but at the
        // light (d² = 0, "inside"), where it is −1. The products with sin θ_b are then
        // zeros, which leave a sum unchanged but for the sign of a zero, and a zero
        // importance comes out +0 from the final `max` whatever its sign.
        let (cos_p, cos_b, sin_b) = if POINTS {
            let inside = _mm256_cmp_ps::<_CMP_LE_OQ>(d2, zero);
            let cos_b = select(inside, splat(-1.0), one);
            let v = _mm256_mul_ps(cos_x, cos_b);
            let cos_p = select(_mm256_cmp_ps::<_CMP_GT_OQ>(cos_x, cos_b), one, v);
            (cos_p, cos_b, zero)
        } else {
            let inside = _mm256_cmp_ps::<_CMP_LE_OQ>(d2, _mm256_mul_ps(radius, radius));
            let sin_b_out = _mm256_mul_ps(radius, inv_d);
            let sin_b = select(inside, zero, sin_b_out);
            let cos_b = select(inside, splat(-1.0), safe_sqrt(one_minus_sq(sin_b_out)));
            let sin_x = sin_sub(sin_w, cos_w, sin_o, cos_o);
            (cos_sub(sin_x, cos_x, sin_b, cos_b), cos_b, sin_b)
        };
        let refused = _mm256_cmp_ps::<_CMP_LT_OQ>(cos_p, self.cos_theta_e);
        let mut importance = _mm256_div_ps(_mm256_mul_ps(self.intensity, cos_p), d2c);
        if ctx.n != glam::Vec3::ZERO {
            let n = [splat(ctx.n.x), splat(ctx.n.y), splat(ctx.n.z)];
            let cos_i = _mm256_andnot_ps(splat(-0.0), dot(wi, n));
            let receiver = if POINTS {
                let v = _mm256_mul_ps(cos_i, cos_b);
                select(_mm256_cmp_ps::<_CMP_GT_OQ>(cos_i, cos_b), one, v)
            } else {
                let sin_i = safe_sqrt(one_minus_sq(cos_i));
                cos_sub(sin_i, cos_i, sin_b, cos_b)
            };
            importance = _mm256_mul_ps(importance, receiver);
        }
        let importance = select(refused, zero, _mm256_max_ps(importance, zero));
        // Stored here, where the intrinsic inlines (outside AVX2 code it was a call).
        let mut out = [0.0f32; LANES];
        // SAFETY: `out` holds LANES f32.
        unsafe { _mm256_storeu_ps(out.as_mut_ptr(), importance) };
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Aabb;
    use crate::light::LightBounds;
    use glam::Vec3;

    /// Random bounds (one- and two-sided, narrow and wide cones, boxes the points fall
    /// in) at random points with and without a normal: the lanes give the scalar bits.
    #[test]
    fn lanes_give_the_scalar_bits() {
        let mut state = 0x853c_49e6_748f_ea9bu64;
        let mut uniform = move || {
            state = crate::sampler::mix64(state);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let mut r = |lo: f32, hi: f32| lo + (hi - lo) * uniform();
        let (mut compared, mut compared_points) = (0, 0);
        for round in 0..2000 {
            let n = 1 + round % LANES;
            // Every third set of bounds is points (a radius of 0: point and spot lights).
            let points = round % 3 == 0;
            let bounds: Vec<ImportanceBounds> = (0..n)
                .map(|_| {
                    let c = Vec3::new(r(-4.0, 4.0), r(-4.0, 4.0), r(-4.0, 4.0));
                    let e = Vec3::new(r(0.0, 1.5), r(0.0, 1.5), r(0.0, 1.5));
                    let e = if points { Vec3::ZERO } else { e };
                    let w = Vec3::new(r(-1.0, 1.0), r(-1.0, 1.0), r(-1.0, 1.0));
                    let lb = LightBounds {
                        aabb: Aabb {
                            min: c - e,
                            max: c + e,
                        },
                        w: w.try_normalize().unwrap_or(Vec3::Y),
                        intensity: r(0.0, 100.0),
                        cos_theta_o: r(-1.0, 1.0),
                        cos_theta_e: if r(0.0, 1.0) < 0.5 { 0.0 } else { r(-1.0, 1.0) },
                        two_sided: r(0.0, 1.0) < 0.5,
                    };
                    ImportanceBounds::new(&lb)
                })
                .collect();
            let lanes = ImportanceLanes::new(&bounds);
            for k in 0..8 {
                let p = Vec3::new(r(-5.0, 5.0), r(-5.0, 5.0), r(-5.0, 5.0));
                let normal = Vec3::new(r(-1.0, 1.0), r(-1.0, 1.0), r(-1.0, 1.0));
                let ctx = ShadingCtx {
                    p: if k == 7 { bounds[0].center } else { p },
                    n: if k % 3 == 0 {
                        Vec3::ZERO
                    } else {
                        normal.normalize()
                    },
                };
                let got = lanes.importance(&ctx);
                let fallback = lanes.importance_scalar(&ctx);
                #[cfg(target_arch = "x86_64")]
                if points && std::arch::is_x86_feature_detected!("avx2") {
                    // SAFETY: the CPU has AVX2.
                    let of_points = unsafe { lanes.importance_of_points_avx2(&ctx) };
                    for i in 0..n {
                        assert_eq!(of_points[i].to_bits(), got[i].to_bits(), "{round} {k} {i}");
                    }
                    compared_points += 1;
                }
                for (i, b) in bounds.iter().enumerate() {
                    let want = b.importance(&ctx);
                    assert_eq!(got[i].to_bits(), want.to_bits(), "{round} {k} {i}: {b:?}");
                    assert_eq!(fallback[i].to_bits(), want.to_bits(), "{round} {k} {i}");
                    compared += (want > 0.0) as u32;
                }
            }
        }
        // Most pairs weigh something (a test of zeros alone would prove little).
        assert!(compared > 30_000, "{compared}");
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            assert!(compared_points > 5000, "{compared_points}");
        }
    }
}
