//! The AVX2 set-up of a one-node query: the root's box test and the watertight ray's
//! constants made in vector registers from the ray's two loads, with the bits of
//! [`Ray8::new`], [`Avx2Boxes`]' test and [`WatertightRay::from_recip`] (the same
//! operations on the same values), for about half their instructions: no stack round
//! trips to index the ray's axes, the near and far planes picked by blends on the
//! direction's sign rather than by computed row offsets, one division for the three
//! reciprocals.

#![cfg(target_arch = "x86_64")]

use std::arch::x86_64::*;

use glam::{Vec3, Vec3A};

#[cfg(doc)]
use crate::bvh::{Avx2Boxes, Ray8};
use crate::bvh::{Planes8, FAR_SCALE};
use crate::geometry::{Ray, WatertightRay};

/// `[kx, ky, kz, kz]` by `2 kz + (d[kz] < 0)`: [`WatertightRay`]'s axes (the two other
/// axes in cyclic order, swapped for a negative `d[kz]`), as `vpermilps` indices.
static AXES: [[i32; 4]; 6] = [
    [1, 2, 0, 0],
    [2, 1, 0, 0],
    [2, 0, 1, 1],
    [0, 2, 1, 1],
    [0, 1, 2, 2],
    [1, 0, 2, 2],
];

/// The root's box test of `ray` against `planes` within `t_box` (which children it
/// enters, bit i for lane i, and where) and the ray's watertight constants; `None` for a
/// ray that is not finite.
///
/// # Safety
/// The CPU must support AVX2.
#[inline]
#[target_feature(enable = "avx2")]
pub(super) unsafe fn root_setup(
    ray: &Ray,
    planes: &Planes8,
    t_box: f32,
) -> Option<(u32, [f32; 8], WatertightRay)> {
    let (o, d) = ray_lanes(ray);
    // `crate::bvh::finite`: each of x · 0 is ±0 for a finite x and NaN otherwise, so the
    // three sums are zero exactly where each lane is.
    let zero = _mm_setzero_ps();
    let z = _mm_add_ps(_mm_mul_ps(o, zero), _mm_mul_ps(d, zero));
    if _mm_movemask_ps(_mm_cmpeq_ps(z, zero)) & 7 != 7 {
        return None;
    }
    let inv = _mm_div_ps(_mm_set1_ps(1.0), d);
    let inv_far = _mm_mul_ps(inv, _mm_set1_ps(FAR_SCALE));

    // The slab test of `Avx2Boxes`, the near plane the max where the reciprocal is
    // negative (its sign bit: never NaN for a finite direction).
    let lane = |v: __m128, axis: usize| -> __m256 {
        match axis {
            0 => _mm256_broadcastss_ps(v),
            1 => _mm256_broadcastss_ps(_mm_movehdup_ps(v)),
            _ => _mm256_broadcastss_ps(_mm_unpackhi_ps(v, v)),
        }
    };
    let mut t_near = _mm256_setzero_ps();
    let mut t_far = _mm256_set1_ps(t_box);
    for axis in 0..3 {
        let (lo, hi) = (
            _mm256_loadu_ps(planes[2 * axis].as_ptr()),
            _mm256_loadu_ps(planes[2 * axis + 1].as_ptr()),
        );
        let (o, inv, inv_far) = (lane(o, axis), lane(inv, axis), lane(inv_far, axis));
        let near = _mm256_blendv_ps(lo, hi, inv);
        let far = _mm256_blendv_ps(hi, lo, inv);
        t_near = _mm256_max_ps(_mm256_mul_ps(_mm256_sub_ps(near, o), inv), t_near);
        t_far = _mm256_min_ps(_mm256_mul_ps(_mm256_sub_ps(far, o), inv_far), t_far);
    }
    let hits = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(t_near, t_far)) as u32;
    let mut entry = [0.0f32; 8];
    _mm256_storeu_ps(entry.as_mut_ptr(), t_near);

    Some((hits, entry, watertight(ray, o, d, inv)))
}

/// `ray`'s watertight constants made in registers from its origin `o` and direction `d`
/// (x, y, z in the first three lanes) and their reciprocals `inv` (`1/d`, the division
/// [`WatertightRay::new`] makes): the bits of `WatertightRay::with_sz`, the largest
/// |d| (the first of equals), then the other two axes, and every per-axis value picked by
/// one permute (no stack round trips to index the axes).
///
/// # Safety
/// The CPU must support AVX2.
#[inline]
#[target_feature(enable = "avx2")]
pub(crate) unsafe fn watertight(ray: &Ray, o: __m128, d: __m128, inv: __m128) -> WatertightRay {
    let a = Vec3A::from(_mm_andnot_ps(_mm_set1_ps(-0.0), d));
    let y_wins = a.y > a.x;
    let max = if y_wins { a.y } else { a.x };
    let kz = if a.z > max { 2 } else { y_wins as usize };
    let negative = (_mm_movemask_ps(_mm_cmplt_ps(d, _mm_setzero_ps())) as usize >> kz) & 1;
    let axes = AXES.get_unchecked(2 * kz + negative);
    let pick = _mm_loadu_si128(axes.as_ptr() as *const __m128i);
    let sz = _mm_permutevar_ps(inv, pick);
    let sz = _mm_shuffle_ps::<0b10_10_10_10>(sz, sz);
    let shear = _mm_blend_ps::<0b0100>(_mm_mul_ps(_mm_permutevar_ps(d, pick), sz), sz);
    WatertightRay {
        o: ray.o,
        kx: axes[0] as usize,
        ky: axes[1] as usize,
        kz,
        shear: Vec3::from(Vec3A::from(shear)),
        o_k: Vec3::from(Vec3A::from(_mm_permutevar_ps(o, pick))),
    }
}

/// [`watertight`] of a ray whose reciprocal direction is `inv_d` (`ray.d.recip()`).
///
/// # Safety
/// The CPU must support AVX2.
#[inline]
#[target_feature(enable = "avx2")]
pub(crate) unsafe fn watertight_from_recip(ray: &Ray, inv_d: Vec3) -> WatertightRay {
    let (o, d) = ray_lanes(ray);
    watertight(ray, o, d, Vec3A::from(inv_d).into())
}

/// [`watertight`] of a ray, its one division made here.
///
/// # Safety
/// The CPU must support AVX2.
#[inline]
#[target_feature(enable = "avx2")]
pub(crate) unsafe fn watertight_new(ray: &Ray) -> WatertightRay {
    let (o, d) = ray_lanes(ray);
    watertight(ray, o, d, _mm_div_ps(_mm_set1_ps(1.0), d))
}

/// `ray`'s origin and direction in the first three lanes of two registers, from two
/// loads (`Ray` is six floats: the first four, and the last four turned to d).
#[inline(always)]
unsafe fn ray_lanes(ray: &Ray) -> (__m128, __m128) {
    let p = ray as *const Ray as *const f32;
    let o = _mm_loadu_ps(p);
    let d = _mm_loadu_ps(p.add(2));
    (o, _mm_shuffle_ps::<0b11_11_10_01>(d, d))
}
