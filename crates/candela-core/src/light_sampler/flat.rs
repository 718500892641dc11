//! The light BVH's pick among at most [`LANES`] lights: every light weighed by the
//! importance of its own bounds at the shading point, all in one lane evaluation
//! ([`ImportanceLanes`]), and one chosen in proportion to its weight.
//!
//! On CPUs with AVX2 the evaluation and the pick are one function compiled for AVX2, so
//! that the lanes' arithmetic inlines into it, and that function inlines into callers
//! compiled for AVX2 (the render loop's x86-64-v3 copy, through
//! [`super::LightBvh::sample`]): called out of line from the pick behind a run-time
//! feature check, the evaluation stored its eight results to memory for the pick to load
//! back, and the calls with their saves cost about half as much as the arithmetic
//! (bench/RESULTS.md, shade: fourth round). The numbers are the same either way (the
//! lanes give the scalar bits, see [`ImportanceLanes`]).

use crate::light::{ImportanceBounds, ImportanceLanes, ShadingCtx, LANES};

/// Up to [`LANES`] lights weighed by their own bounds; see the module documentation.
#[derive(Clone, Debug)]
pub struct FlatLights {
    /// The lights' bounds, one a lane (boxed: 384 bytes).
    lanes: Box<ImportanceLanes>,
    /// The light id of each lane; lanes past `len` are never picked.
    ids: [u32; LANES],
    /// Number of lights, 1 to [`LANES`].
    len: usize,
    /// Whether the CPU has AVX2 (asked once, here, not at every pick).
    avx2: bool,
    /// Whether every light is a point (radius 0: point lights and spots), whose lanes
    /// evaluate in fewer instructions for the same bits
    /// ([`ImportanceLanes::importance_of_points_avx2`]).
    points: bool,
}

impl FlatLights {
    /// The lights `ids` with bounds `bounds` (one each, 1 to [`LANES`] of them).
    pub fn new(ids: &[u32], bounds: &[ImportanceBounds]) -> FlatLights {
        assert_eq!(ids.len(), bounds.len(), "one bounds a light");
        let mut lane_ids = [0; LANES];
        lane_ids[..ids.len()].copy_from_slice(ids);
        let lanes = Box::new(ImportanceLanes::new(bounds));
        FlatLights {
            points: lanes.all_points(),
            lanes,
            ids: lane_ids,
            len: ids.len(),
            avx2: has_avx2(),
        }
    }

    /// Bytes held on the heap (the lanes).
    pub fn memory_bytes(&self) -> usize {
        size_of::<ImportanceLanes>()
    }

    /// A light in proportion to its importance at `ctx` (`u ∈ [0, 1)`) and its
    /// probability; `None` where no light can reach the point.
    #[inline(always)]
    pub fn sample(&self, ctx: &ShadingCtx, u: f32) -> Option<(u32, f32)> {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: the CPU has AVX2 (`has_avx2`).
            return unsafe {
                if self.points {
                    self.sample_points_avx2(ctx, u)
                } else {
                    self.sample_avx2(ctx, u)
                }
            };
        }
        self.pick(&self.lanes.importance_scalar(ctx), u)
    }

    /// Probability that [`Self::sample`] picks `light` at `ctx` (0 for a light not here).
    #[inline(always)]
    pub fn pmf(&self, ctx: &ShadingCtx, light: u32) -> f32 {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: the CPU has AVX2 (`has_avx2`).
            return unsafe {
                if self.points {
                    self.pmf_points_avx2(ctx, light)
                } else {
                    self.pmf_avx2(ctx, light)
                }
            };
        }
        self.probability(&self.lanes.importance_scalar(ctx), light)
    }

    /// [`Self::sample`] compiled for AVX2, the lanes' evaluation inlined.
    ///
    /// # Safety
    ///
    /// The CPU must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2")]
    #[inline]
    unsafe fn sample_avx2(&self, ctx: &ShadingCtx, u: f32) -> Option<(u32, f32)> {
        self.pick(&self.lanes.importance_avx2(ctx), u)
    }

    /// [`Self::sample_avx2`] where every light is a point (`points`): the lanes'
    /// evaluation for points, the same bits.
    ///
    /// # Safety
    ///
    /// The CPU must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2")]
    #[inline]
    unsafe fn sample_points_avx2(&self, ctx: &ShadingCtx, u: f32) -> Option<(u32, f32)> {
        self.pick(&self.lanes.importance_of_points_avx2(ctx), u)
    }

    /// [`Self::pmf`] compiled for AVX2, the lanes' evaluation inlined.
    ///
    /// # Safety
    ///
    /// The CPU must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2")]
    #[inline]
    unsafe fn pmf_avx2(&self, ctx: &ShadingCtx, light: u32) -> f32 {
        self.probability(&self.lanes.importance_avx2(ctx), light)
    }

    /// [`Self::pmf_avx2`] where every light is a point, as [`Self::sample_points_avx2`].
    ///
    /// # Safety
    ///
    /// The CPU must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2")]
    #[inline]
    unsafe fn pmf_points_avx2(&self, ctx: &ShadingCtx, light: u32) -> f32 {
        self.probability(&self.lanes.importance_of_points_avx2(ctx), light)
    }

    /// The sum of the lights' weights `w`, in lane order.
    #[inline(always)]
    fn total(&self, w: &[f32; LANES]) -> f32 {
        let mut total = 0.0;
        for &w in &w[..self.len.min(LANES)] {
            total += w;
        }
        total
    }

    /// The light whose share of the running sum of the weights `w` holds `u · total`
    /// (weights are never negative or NaN: the importance is clamped to 0).
    #[inline(always)]
    fn pick(&self, w: &[f32; LANES], u: f32) -> Option<(u32, f32)> {
        let total = self.total(w);
        if !positive_finite(total) {
            return None;
        }
        let target = u * total;
        // The running sum only grows at positive weights, so the first lane whose sum
        // passes the target has a positive weight; where round-off leaves the target at
        // the total, the last positive lane. A positive total has one.
        let mut acc = 0.0;
        let mut last = 0;
        for (k, &w) in w[..self.len.min(LANES)].iter().enumerate() {
            if w > 0.0 {
                last = k;
                acc += w;
                if target < acc {
                    break;
                }
            }
        }
        Some((self.ids[last], w[last] / total))
    }

    /// What [`Self::pick`] gives `light` with the weights `w`.
    #[inline(always)]
    fn probability(&self, w: &[f32; LANES], light: u32) -> f32 {
        let total = self.total(w);
        if !positive_finite(total) {
            return 0.0;
        }
        self.ids[..self.len.min(LANES)]
            .iter()
            .position(|&id| id == light)
            .map_or(0.0, |k| w[k] / total)
    }
}

/// Whether `x` is positive and finite (what a sum of weights must be to pick by it): the
/// lights' bit test (`x > 0.0 && x < f32::INFINITY` compiled to ~20 integer instructions
/// of a float class test, a pick's largest overhead after the lanes).
pub(super) use crate::light::positive_finite;

fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::light::{Light, PointLight, SphereLight};

    /// The pick of the old flat sampler, loop for loop: weights summed in lane order, the
    /// running sum over positive weights, `w / total` of the last positive lane seen.
    fn reference(w: &[f32], u: f32) -> Option<(usize, f32)> {
        let total: f32 = w.iter().fold(0.0, |t, &w| t + w);
        if !positive_finite(total) {
            return None;
        }
        let target = u * total;
        let (mut acc, mut last) = (0.0, None);
        for (k, &w) in w.iter().enumerate() {
            if w > 0.0 {
                last = Some((k, w / total));
                acc += w;
                if target < acc {
                    break;
                }
            }
        }
        last
    }

    /// Random lights (points, spheres) at random points: the AVX2 and scalar picks and
    /// pmfs are the reference's, bit for bit, and the pmfs sum to one.
    #[test]
    fn picks_and_pmfs_are_the_reference_bits() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut uniform = move || {
            state = crate::sampler::mix64(state);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let mut checked = 0;
        for round in 0..400 {
            let n = 1 + round % LANES;
            let mut r = |lo: f32, hi: f32| lo + (hi - lo) * uniform();
            let lights: Vec<Light> = (0..n)
                .map(|i| {
                    let at = Vec3::new(r(-3.0, 3.0), r(-3.0, 3.0), r(-3.0, 3.0));
                    if i % 2 == 0 {
                        Light::Point(PointLight {
                            position: at,
                            intensity: Vec3::splat(r(0.1, 10.0)),
                        })
                    } else {
                        Light::Sphere(SphereLight {
                            center: at,
                            radius: r(0.01, 1.0),
                            le: Vec3::splat(r(0.1, 10.0)),
                            inward: false,
                        })
                    }
                })
                .collect();
            let bounds: Vec<ImportanceBounds> = lights
                .iter()
                .map(|l| ImportanceBounds::new(&l.bounds().unwrap()))
                .collect();
            // Ids out of order, as a tree's leaves are.
            let ids: Vec<u32> = (0..n as u32).map(|i| (i * 5 + 3) % 17).collect();
            let flat = FlatLights::new(&ids, &bounds);
            for _ in 0..16 {
                let ctx = ShadingCtx {
                    p: Vec3::new(r(-4.0, 4.0), r(-4.0, 4.0), r(-4.0, 4.0)),
                    n: Vec3::new(r(-1.0, 1.0), r(-1.0, 1.0), r(-1.0, 1.0)).normalize(),
                };
                let w: Vec<f32> = bounds.iter().map(|b| b.importance(&ctx)).collect();
                let u = r(0.0, 1.0);
                let want = reference(&w, u).map(|(k, p)| (ids[k], p.to_bits()));
                let got = flat.sample(&ctx, u).map(|(id, p)| (id, p.to_bits()));
                let scalar = flat
                    .pick(&flat.lanes.importance_scalar(&ctx), u)
                    .map(|(id, p)| (id, p.to_bits()));
                assert_eq!(got, want, "{round}");
                assert_eq!(scalar, want, "{round}");
                let mut sum = 0.0;
                for (k, &id) in ids.iter().enumerate() {
                    let pmf = flat.pmf(&ctx, id);
                    let want = reference(&w, 0.0).map_or(0.0, |_| w[k] / w.iter().sum::<f32>());
                    assert!((pmf - want).abs() <= 1e-6 * want, "{round} {k}");
                    sum += pmf;
                }
                if want.is_some() {
                    assert!((sum - 1.0).abs() < 1e-5, "{sum}");
                    checked += 1;
                }
                assert_eq!(flat.pmf(&ctx, 99), 0.0);
            }
        }
        // Most points see some light (a test of empty picks alone would prove little).
        assert!(checked > 4000, "{checked}");
    }
}
