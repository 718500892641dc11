//! Small numeric helpers shared by the whole core.

use glam::{Vec3, Vec3A, Vec4};

/// An orthonormal basis with `n` as its z axis: the local shading frame of the BSDFs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    pub s: Vec3,
    pub t: Vec3,
    pub n: Vec3,
}

impl Frame {
    /// A frame around the unit vector `n`, after Duff et al. 2017, "Building an
    /// Orthonormal Basis, Revisited" (branchless, no singularity).
    #[inline]
    pub fn from_z(n: Vec3) -> Frame {
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let s = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = Vec3::new(b, sign + n.y * n.y * a, -n.y);
        Frame { s, t, n }
    }

    #[inline(always)]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    #[inline(always)]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}

/// Relative luminance of a linear Rec.709 colour (ITU-R BT.709 weights).
#[inline]
pub fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// The odd degree-15 polynomial of Abramowitz & Stegun 4.4.49 for atan on [0, 1], by
/// its coefficients of a, a³, …, a¹⁵.
const ATAN_POLY: [f32; 8] = [
    0.999_999_33,
    -0.333_298_56,
    0.199_465_36,
    -0.139_085_34,
    0.096_420_04,
    -0.055_909_886,
    0.021_861_23,
    -0.004_054_058,
];

/// What π/2 and π as f32 leave out: added to the small part before the large one, so
/// that the constants' own rounding (4e-8, 9e-8) does not add to the error.
const HALF_PI_LO: f32 = -4.371_139e-8;
const PI_LO: f32 = -8.742_278e-8;

/// atan2(y, x) in [−π, π]: the odd degree-15 polynomial of Abramowitz & Stegun 4.4.49
/// for atan on [0, 1] (error ≤ 10⁻⁸ in exact arithmetic), evaluated by Horner's rule in
/// f32 after folding the angle into the first octant, then unfolded with one rounding.
/// Within 2.4·10⁻⁷ rad of the exact angle over a test of 600,000 angles, as libm's
/// `atan2f` (both about one ulp near π), for a fifth of its instructions. The sign of y's zero is kept, as
/// `atan2` keeps it; (0, 0) gives ±0; infinities and NaN are not special-cased.
#[inline]
pub fn atan2_poly(y: f32, x: f32) -> f32 {
    use std::f32::consts::{FRAC_PI_2, PI};
    let (ax, ay) = (x.abs(), y.abs());
    let steep = ay > ax;
    let (lo, hi) = if steep { (ax, ay) } else { (ay, ax) };
    let a = if hi > 0.0 { lo / hi } else { 0.0 };
    let s = a * a;
    let mut r = ATAN_POLY[7];
    for &c in ATAN_POLY[..7].iter().rev() {
        r = r * s + c;
    }
    r *= a;
    // The octant: θ = r, π/2 − r, π/2 + r or π − r.
    let r = match (steep, x < 0.0) {
        (false, false) => r,
        (true, false) => FRAC_PI_2 + (HALF_PI_LO - r),
        (true, true) => FRAC_PI_2 + (HALF_PI_LO + r),
        (false, true) => PI + (PI_LO - r),
    };
    r.copysign(y)
}

/// [`atan2_poly`] of four pairs at once, in SIMD lanes: bit for bit the scalar function
/// in every lane (the same operations in the same order, the octant's cases chosen by
/// masks; π/2 − r as π/2 + (−r), which rounds the same). For a direction's two angles in
/// one pass (the panorama's longitude and colatitude).
#[inline]
pub fn atan2_poly_lanes(y: Vec4, x: Vec4) -> Vec4 {
    use std::f32::consts::{FRAC_PI_2, PI};
    let (ax, ay) = (x.abs(), y.abs());
    let steep = ay.cmpgt(ax);
    let (lo, hi) = (Vec4::select(steep, ax, ay), Vec4::select(steep, ay, ax));
    let a = Vec4::select(hi.cmpgt(Vec4::ZERO), lo / hi, Vec4::ZERO);
    let s = a * a;
    let mut r = Vec4::splat(ATAN_POLY[7]);
    for &c in ATAN_POLY[..7].iter().rev() {
        r = r * s + Vec4::splat(c);
    }
    r *= a;
    // θ = hi + (lo ± r): (0, 0, +) in the first octant, (π/2, HALF_PI_LO, −) in the
    // second, (π/2, HALF_PI_LO, +) in the third, (π, PI_LO, −) in the fourth.
    let left = x.cmplt(Vec4::ZERO);
    let (big, small) = (
        Vec4::select(left, Vec4::splat(PI), Vec4::ZERO),
        Vec4::select(left, Vec4::splat(PI_LO), Vec4::ZERO),
    );
    let big = Vec4::select(steep, Vec4::splat(FRAC_PI_2), big);
    let small = Vec4::select(steep, Vec4::splat(HALF_PI_LO), small);
    let r = Vec4::select(steep ^ left, -r, r);
    (big + (small + r)).copysign(y)
}

/// Offsets a ray origin `p` off a surface with geometric normal `n`, towards the side of
/// `n`, by an amount that scales with the magnitude of `p`'s coordinates. Wächter and
/// Binder, "A Fast and Robust Method for Avoiding Self-Intersection", Ray Tracing Gems
/// ch. 6: integer ulp steps far from the origin, a small float step near it. `n` is a unit
/// vector (each |n_i| ≤ 1).
///
/// On x86-64 the three coordinates go through SSE2 lanes together (three times per bounce:
/// the next ray and both ends of the shadow ray), bit for bit the scalar
/// [`offset_ray_origin_scalar`].
#[inline]
pub fn offset_ray_origin(p: Vec3, n: Vec3) -> Vec3 {
    offset_ray_origin_a(p.into(), n.into()).into()
}

/// [`offset_ray_origin`] of points and normals held in SIMD lanes ([`Vec3A`]), as the
/// set-up of the shadow and bounce rays keeps them: no packing of the three coordinates
/// into lanes and back around the offset (about 10 instructions each way).
#[inline]
pub fn offset_ray_origin_a(p: Vec3A, n: Vec3A) -> Vec3A {
    #[cfg(target_arch = "x86_64")]
    {
        Vec3A::from(offset_ray_origin_sse2(p.into(), n.into()))
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        offset_ray_origin_scalar(p.into(), n.into()).into()
    }
}

const ORIGIN: f32 = 1.0 / 32.0;
const FLOAT_SCALE: f32 = 1.0 / 65536.0;
const INT_SCALE: f32 = 256.0;
// 1.5·2²³: adding it to |x| < 2²² leaves round(x) in the low mantissa bits, so the
// integer step costs an add and a subtract instead of `as i32`'s saturating
// conversion (a third of this function's instructions in callgrind). Rounding
// instead of the paper's truncation changes a step by at most one ulp.
const ROUND: f32 = 12_582_912.0;

/// [`offset_ray_origin`], one coordinate at a time.
pub fn offset_ray_origin_scalar(p: Vec3, n: Vec3) -> Vec3 {
    let offset = |p: f32, n: f32| -> f32 {
        let of_i = (INT_SCALE * n + ROUND).to_bits() as i32 - ROUND.to_bits() as i32;
        let bits = p.to_bits() as i32;
        let stepped = f32::from_bits((bits + if p < 0.0 { -of_i } else { of_i }) as u32);
        if p.abs() < ORIGIN {
            p + FLOAT_SCALE * n
        } else {
            stepped
        }
    };
    Vec3::new(offset(p.x, n.x), offset(p.y, n.y), offset(p.z, n.z))
}

/// [`offset_ray_origin_scalar`] in SSE2 lanes: the same float operations in the same
/// order, the sign choice as a mask from `p < 0` (so −0 and NaN go the scalar way). The
/// fourth lane is ignored.
#[cfg(target_arch = "x86_64")]
#[inline]
fn offset_ray_origin_sse2(
    pv: std::arch::x86_64::__m128,
    nv: std::arch::x86_64::__m128,
) -> std::arch::x86_64::__m128 {
    use std::arch::x86_64::*;
    // SAFETY: SSE2 is part of the x86-64 baseline; no memory is touched.
    unsafe {
        let scaled = _mm_add_ps(_mm_mul_ps(_mm_set1_ps(INT_SCALE), nv), _mm_set1_ps(ROUND));
        let of_i = _mm_sub_epi32(
            _mm_castps_si128(scaled),
            _mm_set1_epi32(ROUND.to_bits() as i32),
        );
        // −of_i where p < 0: (of_i ^ m) − m with m = −1 there, 0 elsewhere.
        let m = _mm_castps_si128(_mm_cmplt_ps(pv, _mm_setzero_ps()));
        let step = _mm_sub_epi32(_mm_xor_si128(of_i, m), m);
        let stepped = _mm_castsi128_ps(_mm_add_epi32(_mm_castps_si128(pv), step));
        let abs = _mm_and_ps(pv, _mm_castsi128_ps(_mm_set1_epi32(0x7fff_ffff)));
        let near = _mm_cmplt_ps(abs, _mm_set1_ps(ORIGIN));
        let nudged = _mm_add_ps(pv, _mm_mul_ps(_mm_set1_ps(FLOAT_SCALE), nv));
        _mm_or_ps(_mm_and_ps(near, nudged), _mm_andnot_ps(near, stepped))
    }
}

/// `n` flipped, if needed, to lie on the same side as `v`.
pub fn face_forward(n: Vec3, v: Vec3) -> Vec3 {
    if n.dot(v) < 0.0 {
        -n
    } else {
        n
    }
}

/// Whether every channel of a colour is zero.
pub fn is_black(c: Vec3) -> bool {
    c == Vec3::ZERO
}

/// Largest channel of a colour.
#[inline]
pub fn max_component(c: Vec3) -> f32 {
    c.x.max(c.y).max(c.z)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atan2_poly_is_as_close_to_the_exact_angle_as_libm() {
        let mut worst = 0.0f64;
        let mut libm_worst = 0.0f64;
        let mut check = |y: f32, x: f32| {
            let exact = (y as f64).atan2(x as f64);
            let err = (atan2_poly(y, x) as f64 - exact).abs();
            let libm = ((y.atan2(x)) as f64 - exact).abs();
            libm_worst = libm_worst.max(libm);
            assert!(
                err < 3e-7,
                "atan2({y}, {x}): {} against {exact}",
                atan2_poly(y, x)
            );
            worst = worst.max(err);
        };
        // Every angle on a fine circle, and lengths far from 1.
        for i in 0..200_000 {
            let t = (i as f64 / 200_000.0 - 0.5) * std::f64::consts::TAU;
            for r in [1.0f64, 1e-3, 7e4] {
                check((r * t.sin()) as f32, (r * t.cos()) as f32);
            }
        }
        for (y, x) in [
            (0.0, 1.0),
            (1.0, 0.0),
            (0.0, -1.0),
            (-1.0, 0.0),
            (1.0, 1.0),
            (-2.0, -2.0),
        ] {
            check(y, x);
        }
        eprintln!("largest error {worst:e} rad, libm {libm_worst:e}");
        assert!(worst > 1e-7, "the bound is near the error: {worst}");
        assert!(libm_worst > 1e-7, "the exact angle is in f64: {libm_worst}");
        assert_eq!(atan2_poly(0.0, 0.0), 0.0);
        assert_eq!(atan2_poly(-0.0, 1.0).to_bits(), (-0.0f32).to_bits());
        assert_eq!(atan2_poly(0.0, -1.0), std::f32::consts::PI);
    }

    #[test]
    fn atan2_poly_lanes_give_the_scalar_bits() {
        // Every octant, its edges (ties, axes, signed zeros) and lengths far from 1, each
        // lane fed a different pair.
        let mut pairs = vec![
            (0.0, 0.0),
            (-0.0, 0.0),
            (0.0, -0.0),
            (-0.0, -0.0),
            (1.0, 1.0),
            (-1.0, 1.0),
            (1.0, -1.0),
            (-1.0, -1.0),
        ];
        for i in 0..40_000 {
            let t = (i as f64 / 40_000.0 - 0.5) * std::f64::consts::TAU;
            let r = [1.0f64, 3e-4, 2e5][i % 3];
            pairs.push(((r * t.sin()) as f32, (r * t.cos()) as f32));
        }
        for (k, chunk) in pairs.chunks_exact(4).enumerate() {
            let y = Vec4::from_array(std::array::from_fn(|i| chunk[i].0));
            let x = Vec4::from_array(std::array::from_fn(|i| chunk[i].1));
            let lanes = atan2_poly_lanes(y, x).to_array();
            for (lane, &(y, x)) in lanes.iter().zip(chunk) {
                assert_eq!(
                    lane.to_bits(),
                    atan2_poly(y, x).to_bits(),
                    "atan2({y}, {x}) in chunk {k}"
                );
            }
        }
    }

    #[test]
    fn frame_is_orthonormal_for_every_axis_sign() {
        for n in [
            Vec3::Z,
            -Vec3::Z,
            Vec3::X,
            -Vec3::Y,
            Vec3::new(0.3, -0.4, 0.866).normalize(),
        ] {
            let f = Frame::from_z(n);
            assert!((f.s.length() - 1.0).abs() < 1e-5);
            assert!((f.t.length() - 1.0).abs() < 1e-5);
            assert!(
                f.s.dot(f.t).abs() < 1e-5 && f.s.dot(n).abs() < 1e-5 && f.t.dot(n).abs() < 1e-5
            );
            assert!((f.s.cross(f.t) - n).length() < 1e-5, "right-handed");
            let v = Vec3::new(0.2, 0.5, -0.7);
            assert!((f.to_world(f.to_local(v)) - v).length() < 1e-5);
        }
    }

    #[test]
    fn offset_steps_are_the_rounded_scaled_normal() {
        // Far from the origin the step is round(256·n) ulps, on the side of n.
        let p = Vec3::new(3.0, -5.0, 1000.0);
        for n in [
            Vec3::X,
            -Vec3::Y,
            Vec3::new(0.6, 0.0, -0.8),
            Vec3::new(0.001, 0.7, 0.714),
        ] {
            let q = offset_ray_origin(p, n);
            for i in 0..3 {
                let steps = q[i].to_bits() as i64 - p[i].to_bits() as i64;
                let want = (256.0 * n[i]).round() as i64 * p[i].signum() as i64;
                assert_eq!(steps, want, "n = {n}, axis {i}");
            }
        }
    }

    #[test]
    fn offset_lanes_equal_the_scalar_offset_bit_for_bit() {
        let mut rng = crate::sampler::Pcg32::new(11, 5);
        let mut u = || rng.uniform_f32();
        let specials = [
            0.0,
            -0.0,
            1.0 / 32.0,
            -1.0 / 32.0,
            1e-30,
            -3e5,
            4e6,
            f32::NAN,
        ];
        for i in 0..20_000 {
            // Magnitudes from 1e-6 to 1e6 of both signs, and special values.
            let mut c = || {
                let v = (2.0 * u() - 1.0) * 10f32.powf(12.0 * u() - 6.0);
                if i % 7 == 0 {
                    specials[(u() * 8.0) as usize % 8]
                } else {
                    v
                }
            };
            let p = Vec3::new(c(), c(), c());
            let n = Vec3::new(2.0 * u() - 1.0, 2.0 * u() - 1.0, 2.0 * u() - 1.0).normalize();
            let (a, b) = (offset_ray_origin(p, n), offset_ray_origin_scalar(p, n));
            for k in 0..3 {
                assert_eq!(a[k].to_bits(), b[k].to_bits(), "p = {p}, n = {n}");
            }
        }
    }

    #[test]
    fn offset_moves_to_the_normal_side_at_every_scale() {
        for scale in [0.0f32, 1e-3, 1.0, 1e3, 1e5] {
            let p = Vec3::new(scale, -scale, scale * 0.5);
            let n = Vec3::new(0.0, 1.0, 0.0);
            let q = offset_ray_origin(p, n);
            assert!(q.y > p.y, "scale {scale}: {q:?}");
            assert_eq!(q.x, p.x);
        }
    }
}
