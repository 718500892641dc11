//! One ray against four boxes at once: the slab test of [`crate::geometry::Aabb::hit`]
//! in four lanes, with SSE on x86-64 (part of the x86-64 baseline, so no run-time check
//! is needed) and a scalar version elsewhere that gives the same bits.

use glam::Vec3;

use crate::geometry::{gamma, Ray};

/// Four boxes, planes as `[min_x, max_x, min_y, max_y, min_z, max_z]`, four lanes each.
pub type Planes4 = [[f32; 4]; 6];

/// Per-ray constants of the four-wide slab test.
#[derive(Clone, Copy, Debug)]
pub struct Ray4 {
    pub o: Vec3,
    pub inv_d: Vec3,
    /// Index into [`Planes4`] of each axis's near plane (0/2/4 for a positive direction,
    /// 1/3/5 for a negative one); the far plane is the other one.
    pub near: [usize; 3],
}

/// Robustness factor on far distances (pbrt-v4 §6.8.2), as in `Aabb::hit`.
const FAR_SCALE: f32 = 1.0 + 2.0 * gamma(3);

/// Traversal widens `t_max` by this factor before box tests. A box's entry distance is
/// rounded, and a triangle test's distance is rounded more (its barycentric sums cancel
/// at grazing angles), so the box of a hit just nearer than the best so far can appear
/// to start just beyond it; culling it would return the farther of two hits some ulps
/// apart. 2⁻¹⁶ (≈ 128 ulps) covers the cases the tests find, and the extra boxes it
/// opens are too few to measure.
pub const T_MAX_SCALE: f32 = 1.0 + 1.0 / 65536.0;

impl Ray4 {
    pub fn new(ray: &Ray) -> Ray4 {
        let inv_d = ray.d.recip();
        let near = |axis: usize, inv: f32| 2 * axis + (inv < 0.0) as usize;
        Ray4 {
            o: ray.o,
            inv_d,
            near: [near(0, inv_d.x), near(1, inv_d.y), near(2, inv_d.z)],
        }
    }

    /// Which of the four boxes the ray meets within (0, t_max) (bit i for box i), and the
    /// entry distances. A plane whose distance is NaN (the ray lies in it) does not
    /// constrain the interval, as in `Aabb::hit`; empty boxes (min = +∞, max = −∞) are
    /// missed by every finite ray.
    #[inline(always)]
    pub fn hit4(&self, planes: &Planes4, t_max: f32) -> (u32, [f32; 4]) {
        #[cfg(target_arch = "x86_64")]
        {
            // SAFETY: SSE is part of the x86-64 baseline.
            unsafe { hit4_sse(self, planes, t_max) }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            hit4_scalar(self, planes, t_max)
        }
    }
}

/// `maxps` semantics: the second operand when either is NaN.
#[inline(always)]
fn max_ps(a: f32, b: f32) -> f32 {
    if a > b {
        a
    } else {
        b
    }
}

/// `minps` semantics: the second operand when either is NaN.
#[inline(always)]
fn min_ps(a: f32, b: f32) -> f32 {
    if a < b {
        a
    } else {
        b
    }
}

/// The portable four-box test; [`Ray4::hit4`] uses it where there is no SSE. Public so
/// that tests can check both give the same bits.
#[inline(always)]
pub fn hit4_scalar(ray: &Ray4, planes: &Planes4, t_max: f32) -> (u32, [f32; 4]) {
    let o = ray.o.to_array();
    let inv = ray.inv_d.to_array();
    let mut mask = 0;
    let mut t_near4 = [0.0; 4];
    for lane in 0..4 {
        let mut t_near = 0.0f32;
        let mut t_far = t_max;
        for axis in 0..3 {
            let n = ray.near[axis];
            let f = n ^ 1;
            t_near = max_ps((planes[n][lane] - o[axis]) * inv[axis], t_near);
            t_far = min_ps((planes[f][lane] - o[axis]) * inv[axis] * FAR_SCALE, t_far);
        }
        t_near4[lane] = t_near;
        if t_near <= t_far {
            mask |= 1 << lane;
        }
    }
    (mask, t_near4)
}

#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn hit4_sse(ray: &Ray4, planes: &Planes4, t_max: f32) -> (u32, [f32; 4]) {
    use std::arch::x86_64::*;
    let mut t_near = _mm_setzero_ps();
    let mut t_far = _mm_set1_ps(t_max);
    let scale = _mm_set1_ps(FAR_SCALE);
    let o = ray.o.to_array();
    let inv = ray.inv_d.to_array();
    for axis in 0..3 {
        let n = ray.near[axis];
        let oa = _mm_set1_ps(o[axis]);
        let ia = _mm_set1_ps(inv[axis]);
        let near = _mm_loadu_ps(planes.get_unchecked(n).as_ptr());
        let far = _mm_loadu_ps(planes.get_unchecked(n ^ 1).as_ptr());
        t_near = _mm_max_ps(_mm_mul_ps(_mm_sub_ps(near, oa), ia), t_near);
        t_far = _mm_min_ps(
            _mm_mul_ps(_mm_mul_ps(_mm_sub_ps(far, oa), ia), scale),
            t_far,
        );
    }
    let mask = _mm_movemask_ps(_mm_cmple_ps(t_near, t_far)) as u32;
    let mut out = [0.0f32; 4];
    _mm_storeu_ps(out.as_mut_ptr(), t_near);
    (mask, out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::Pcg32;

    /// The SSE path and the scalar path give the same mask and the same entry bits on
    /// random boxes, empty slots, flat boxes and rays lying in box planes.
    #[test]
    #[allow(clippy::needless_range_loop)] // lanes index two arrays at once
    fn sse_and_scalar_agree_bit_for_bit() {
        let mut rng = Pcg32::new(3, 9);
        let mut u = || rng.uniform_f32();
        let mut hits = 0;
        for k in 0..20000 {
            let mut planes: Planes4 = [[0.0; 4]; 6];
            for lane in 0..4 {
                for axis in 0..3 {
                    let (a, b) = ((u() * 4.0).floor() / 2.0, (u() * 4.0).floor() / 2.0);
                    let (lo, hi) = match (k + lane) % 5 {
                        0 => (f32::INFINITY, f32::NEG_INFINITY),
                        1 => (a, a),
                        _ => (a.min(b), a.max(b) + 1.0),
                    };
                    planes[2 * axis][lane] = lo;
                    planes[2 * axis + 1][lane] = hi;
                }
            }
            // Origins on the half-integer grid put them in box planes; some direction
            // components are ±0.
            let o = Vec3::new(u(), u(), u()) * 4.0 - 1.0;
            let o = if k % 3 == 0 {
                (o * 2.0).floor() / 2.0
            } else {
                o
            };
            let mut d = Vec3::new(u(), u(), u()) - 0.5;
            if k % 4 == 0 {
                d.y = 0.0;
            }
            if k % 7 == 0 {
                d.x = -0.0;
            }
            let ray = Ray4::new(&Ray::new(o, d));
            let t_max = if k % 2 == 0 { f32::INFINITY } else { u() * 3.0 };
            let (m1, t1) = ray.hit4(&planes, t_max);
            let (m2, t2) = hit4_scalar(&ray, &planes, t_max);
            assert_eq!(m1, m2, "case {k}");
            assert_eq!(t1.map(f32::to_bits), t2.map(f32::to_bits), "case {k}");
            hits += m1.count_ones();
        }
        assert!(hits > 5000, "only {hits} box hits");
    }
}
