//! One ray against eight boxes at once: the slab test of [`crate::geometry::Aabb::hit`]
//! in eight lanes. Three kernels give the same bits: AVX2 (one 8-lane register, where
//! the CPU has it, checked once at build time), SSE (two 4-lane halves; part of the
//! x86-64 baseline) and plain scalar code (other targets, and the reference the tests
//! compare the others with). [`Simd`] names them; the traversal is generic over
//! [`BoxTest`] and so compiled once per kernel.

use glam::Vec3;

use super::quant8::QBoxes8;
use crate::geometry::{gamma, Ray};

/// Eight boxes, planes as `[min_x, max_x, min_y, max_y, min_z, max_z]`, eight lanes each.
pub type Planes8 = [[f32; 8]; 6];

/// Robustness factor on far distances (pbrt-v4 §6.8.2), as in `Aabb::hit`. It is folded
/// into the far planes' reciprocal direction: one more rounding, well inside the 2γ₃
/// (≈ 3.6·10⁻⁷ relative) margin.
pub(crate) const FAR_SCALE: f32 = 1.0 + 2.0 * gamma(3);

/// Traversal widens `t_max` by this factor before box tests. A box's entry distance is
/// rounded, and a triangle test's distance is rounded more (its barycentric sums cancel
/// at grazing angles), so the box of a hit just nearer than the best so far can appear
/// to start just beyond it; culling it would return the farther of two hits some ulps
/// apart. 2⁻¹⁶ (≈ 128 ulps) covers the cases the tests find, and the extra boxes it
/// opens are too few to measure.
pub const T_MAX_SCALE: f32 = 1.0 + 1.0 / 65536.0;

/// Per-ray constants of the eight-wide slab test.
#[derive(Clone, Copy, Debug)]
pub struct Ray8 {
    pub o: Vec3,
    pub inv_d: Vec3,
    /// `inv_d * FAR_SCALE`, for the far planes.
    pub inv_far: Vec3,
    /// Index into [`Planes8`] of each axis's near plane (0/2/4 for a positive direction,
    /// 1/3/5 for a negative one); the far plane is the other one.
    pub near: [usize; 3],
    /// Whether the ray's origin and direction are finite (traversal finds nothing for
    /// one that is not).
    pub finite: bool,
}

impl Ray8 {
    pub fn new(ray: &Ray) -> Ray8 {
        let inv_d = ray.d.recip();
        let near = |axis: usize, inv: f32| 2 * axis + (inv < 0.0) as usize;
        Ray8 {
            o: ray.o,
            inv_d,
            inv_far: inv_d * FAR_SCALE,
            near: [near(0, inv_d.x), near(1, inv_d.y), near(2, inv_d.z)],
            finite: finite(ray),
        }
    }
}

/// Whether the ray's origin and direction are finite: `x · 0` is ±0 for a finite `x`
/// and NaN otherwise, so one sum tests all six (a third of the instructions of six
/// `is_finite`s and no branches; callgrind, Cornell render).
#[inline(always)]
pub(crate) fn finite(ray: &Ray) -> bool {
    let z = ray.o * 0.0 + ray.d * 0.0;
    z.x + z.y + z.z == 0.0
}

/// Which SIMD kernels the traversal and the triangle blocks use. All give the same bits;
/// [`Simd::best`] is what the CPU runs fastest, and the tests run every one it has.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Simd {
    /// Plain Rust, lane by lane (the default: it runs everywhere).
    #[default]
    Scalar,
    /// 4-lane SSE (x86-64 baseline): eight boxes or triangles as two halves.
    Sse,
    /// 8-lane AVX2 box and triangle tests (on CPUs that also have BMI1, BMI2 and LZCNT).
    Avx2,
}

impl Simd {
    /// The fastest kernel this CPU supports (`is_x86_feature_detected!` caches its
    /// answer; this is asked once per acceleration-structure build, not per ray).
    pub fn best() -> Simd {
        #[cfg(target_arch = "x86_64")]
        {
            // The AVX2 traversal is also compiled for BMI1, BMI2 and LZCNT, which every
            // AVX2 CPU (Haswell, Zen and later) has; asked anyway, as a VM may hide them.
            use std::arch::is_x86_feature_detected as has;
            if has!("avx2") && has!("bmi1") && has!("bmi2") && has!("lzcnt") {
                Simd::Avx2
            } else {
                Simd::Sse
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            Simd::Scalar
        }
    }

    /// Every kernel this CPU can run, scalar first.
    pub fn available() -> Vec<Simd> {
        [Simd::Scalar, Simd::Sse, Simd::Avx2]
            .into_iter()
            .filter(|s| s.is_supported())
            .collect()
    }

    pub fn is_supported(self) -> bool {
        match self {
            Simd::Scalar => true,
            Simd::Sse => cfg!(target_arch = "x86_64"),
            Simd::Avx2 => Simd::best() == Simd::Avx2,
        }
    }
}

/// An eight-box slab test. Which of the eight boxes the ray meets within (0, t_max)
/// (bit i for box i), and the entry distances. A plane whose distance is NaN (the ray
/// lies in it) does not constrain the interval, as in `Aabb::hit`; empty boxes
/// (min = +∞, max = −∞) are missed by every finite ray.
pub trait BoxTest {
    /// The ray's constants as the kernel wants them, made once per ray.
    type Prepared;

    /// # Safety
    /// The CPU must support the kernel (see [`Simd::is_supported`]).
    unsafe fn prepare(ray: &Ray8) -> Self::Prepared;

    /// # Safety
    /// As for [`BoxTest::prepare`].
    unsafe fn hit8(ray: &Self::Prepared, planes: &Planes8, t_max: f32) -> (u32, [f32; 8]);

    /// [`BoxTest::hit8`] on quantized boxes, dequantized in the kernel: the same bits
    /// as `hit8` on [`QBoxes8::planes`].
    ///
    /// # Safety
    /// As for [`BoxTest::prepare`].
    unsafe fn hit8q(ray: &Self::Prepared, boxes: &QBoxes8, t_max: f32) -> (u32, [f32; 8]);

    /// Which lanes of `t` are greater than `x`, and which equal it (bit i for lane i):
    /// the traversal's ranks of the children it enters.
    ///
    /// # Safety
    /// As for [`BoxTest::prepare`].
    unsafe fn order(t: &[f32; 8], x: f32) -> (u32, u32);
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

/// The portable kernel.
pub struct ScalarBoxes;

impl BoxTest for ScalarBoxes {
    type Prepared = Ray8;

    #[inline(always)]
    unsafe fn prepare(ray: &Ray8) -> Ray8 {
        *ray
    }

    #[inline(always)]
    unsafe fn hit8(ray: &Ray8, planes: &Planes8, t_max: f32) -> (u32, [f32; 8]) {
        hit8_scalar(ray, planes, t_max)
    }

    #[inline(always)]
    unsafe fn hit8q(ray: &Ray8, boxes: &QBoxes8, t_max: f32) -> (u32, [f32; 8]) {
        hit8_scalar(ray, &boxes.planes(), t_max)
    }

    #[inline(always)]
    unsafe fn order(t: &[f32; 8], x: f32) -> (u32, u32) {
        t.iter().enumerate().fold((0, 0), |(gt, eq), (j, &tj)| {
            (gt | ((tj > x) as u32) << j, eq | ((tj == x) as u32) << j)
        })
    }
}

/// [`ScalarBoxes`]' test as a safe function, for tests.
#[inline(always)]
pub fn hit8_scalar(ray: &Ray8, planes: &Planes8, t_max: f32) -> (u32, [f32; 8]) {
    let o = ray.o.to_array();
    let (inv, inv_far) = (ray.inv_d.to_array(), ray.inv_far.to_array());
    let mut mask = 0;
    let mut t_near8 = [0.0; 8];
    for lane in 0..8 {
        let mut t_near = 0.0f32;
        let mut t_far = t_max;
        for axis in 0..3 {
            let n = ray.near[axis];
            t_near = max_ps((planes[n][lane] - o[axis]) * inv[axis], t_near);
            t_far = min_ps((planes[n ^ 1][lane] - o[axis]) * inv_far[axis], t_far);
        }
        t_near8[lane] = t_near;
        if t_near <= t_far {
            mask |= 1 << lane;
        }
    }
    (mask, t_near8)
}

#[cfg(target_arch = "x86_64")]
pub use x86::{Avx2Boxes, SseBoxes};

#[cfg(target_arch = "x86_64")]
mod x86 {
    use std::arch::x86_64::*;

    use super::{BoxTest, Planes8, QBoxes8, Ray8};

    /// Two 4-lane SSE halves.
    pub struct SseBoxes;

    /// Per axis: origin, reciprocal direction (near and far), near plane row.
    #[derive(Clone, Copy)]
    pub struct SseRay {
        o: [__m128; 3],
        inv: [__m128; 3],
        inv_far: [__m128; 3],
        near: [usize; 3],
    }

    impl BoxTest for SseBoxes {
        type Prepared = SseRay;

        #[inline(always)]
        unsafe fn prepare(r: &Ray8) -> SseRay {
            let (o, i, f) = (r.o.to_array(), r.inv_d.to_array(), r.inv_far.to_array());
            SseRay {
                o: o.map(|x| _mm_set1_ps(x)),
                inv: i.map(|x| _mm_set1_ps(x)),
                inv_far: f.map(|x| _mm_set1_ps(x)),
                near: r.near,
            }
        }

        #[inline(always)]
        unsafe fn hit8(r: &SseRay, planes: &Planes8, t_max: f32) -> (u32, [f32; 8]) {
            slab_sse(r, t_max, |_, row, half| {
                _mm_loadu_ps(planes.get_unchecked(row).as_ptr().add(4 * half))
            })
        }

        #[inline(always)]
        unsafe fn hit8q(r: &SseRay, boxes: &QBoxes8, t_max: f32) -> (u32, [f32; 8]) {
            slab_sse(r, t_max, |axis, row, half| {
                // Four bytes to four floats with SSE2 only: widen with zeros twice, convert.
                let bytes = boxes.q.get_unchecked(row).as_ptr().add(4 * half);
                let v = _mm_cvtsi32_si128((bytes as *const i32).read_unaligned());
                let zero = _mm_setzero_si128();
                let q = _mm_cvtepi32_ps(_mm_unpacklo_epi16(_mm_unpacklo_epi8(v, zero), zero));
                let step = _mm_set1_ps(*boxes.step.get_unchecked(axis));
                _mm_add_ps(
                    _mm_mul_ps(q, step),
                    _mm_set1_ps(*boxes.origin.get_unchecked(axis)),
                )
            })
        }

        #[inline(always)]
        unsafe fn order(t: &[f32; 8], x: f32) -> (u32, u32) {
            let x = _mm_set1_ps(x);
            let (lo, hi) = (_mm_loadu_ps(t.as_ptr()), _mm_loadu_ps(t.as_ptr().add(4)));
            let bits = |lo, hi| _mm_movemask_ps(lo) as u32 | (_mm_movemask_ps(hi) as u32) << 4;
            (
                bits(_mm_cmpgt_ps(lo, x), _mm_cmpgt_ps(hi, x)),
                bits(_mm_cmpeq_ps(lo, x), _mm_cmpeq_ps(hi, x)),
            )
        }
    }

    /// The slab test in two halves; `plane(axis, row, half)` gives four lanes of plane
    /// row `row` (of [`Planes8`]'s order).
    #[inline(always)]
    unsafe fn slab_sse(
        r: &SseRay,
        t_max: f32,
        plane: impl Fn(usize, usize, usize) -> __m128,
    ) -> (u32, [f32; 8]) {
        let mut out = [0.0f32; 8];
        let mut mask = 0;
        for half in 0..2 {
            let mut t_near = _mm_setzero_ps();
            let mut t_far = _mm_set1_ps(t_max);
            for axis in 0..3 {
                let n = r.near[axis];
                let (near, far) = (plane(axis, n, half), plane(axis, n ^ 1, half));
                t_near = _mm_max_ps(_mm_mul_ps(_mm_sub_ps(near, r.o[axis]), r.inv[axis]), t_near);
                t_far = _mm_min_ps(
                    _mm_mul_ps(_mm_sub_ps(far, r.o[axis]), r.inv_far[axis]),
                    t_far,
                );
            }
            mask |= (_mm_movemask_ps(_mm_cmple_ps(t_near, t_far)) as u32) << (4 * half);
            _mm_storeu_ps(out.as_mut_ptr().add(4 * half), t_near);
        }
        (mask, out)
    }

    /// One 8-lane AVX2 register.
    pub struct Avx2Boxes;

    #[derive(Clone, Copy)]
    pub struct Avx2Ray {
        o: [__m256; 3],
        inv: [__m256; 3],
        inv_far: [__m256; 3],
        near: [usize; 3],
    }

    impl BoxTest for Avx2Boxes {
        type Prepared = Avx2Ray;

        #[inline]
        #[target_feature(enable = "avx2")]
        unsafe fn prepare(r: &Ray8) -> Avx2Ray {
            let (o, i, f) = (r.o.to_array(), r.inv_d.to_array(), r.inv_far.to_array());
            Avx2Ray {
                o: o.map(|x| _mm256_set1_ps(x)),
                inv: i.map(|x| _mm256_set1_ps(x)),
                inv_far: f.map(|x| _mm256_set1_ps(x)),
                near: r.near,
            }
        }

        #[inline]
        #[target_feature(enable = "avx2")]
        unsafe fn hit8(r: &Avx2Ray, planes: &Planes8, t_max: f32) -> (u32, [f32; 8]) {
            slab_avx2(r, t_max, |_, row| {
                _mm256_loadu_ps(planes.get_unchecked(row).as_ptr())
            })
        }

        #[inline]
        #[target_feature(enable = "avx2")]
        unsafe fn hit8q(r: &Avx2Ray, boxes: &QBoxes8, t_max: f32) -> (u32, [f32; 8]) {
            slab_avx2(r, t_max, |axis, row| {
                let bytes = boxes.q.get_unchecked(row).as_ptr() as *const __m128i;
                let q = _mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(_mm_loadl_epi64(bytes)));
                // Multiply, then add: not fused, so as the scalar kernel rounds.
                let step = _mm256_set1_ps(*boxes.step.get_unchecked(axis));
                _mm256_add_ps(
                    _mm256_mul_ps(q, step),
                    _mm256_set1_ps(*boxes.origin.get_unchecked(axis)),
                )
            })
        }

        #[inline]
        #[target_feature(enable = "avx2")]
        unsafe fn order(t: &[f32; 8], x: f32) -> (u32, u32) {
            let (t, x) = (_mm256_loadu_ps(t.as_ptr()), _mm256_set1_ps(x));
            (
                _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_GT_OQ>(t, x)) as u32,
                _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_EQ_OQ>(t, x)) as u32,
            )
        }
    }

    /// The slab test; `plane(axis, row)` gives plane row `row` (of [`Planes8`]'s order).
    #[inline]
    #[target_feature(enable = "avx2")]
    unsafe fn slab_avx2(
        r: &Avx2Ray,
        t_max: f32,
        plane: impl Fn(usize, usize) -> __m256,
    ) -> (u32, [f32; 8]) {
        let mut t_near = _mm256_setzero_ps();
        let mut t_far = _mm256_set1_ps(t_max);
        for axis in 0..3 {
            let n = r.near[axis];
            let (near, far) = (plane(axis, n), plane(axis, n ^ 1));
            t_near = _mm256_max_ps(
                _mm256_mul_ps(_mm256_sub_ps(near, r.o[axis]), r.inv[axis]),
                t_near,
            );
            t_far = _mm256_min_ps(
                _mm256_mul_ps(_mm256_sub_ps(far, r.o[axis]), r.inv_far[axis]),
                t_far,
            );
        }
        let mask = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(t_near, t_far)) as u32;
        let mut out = [0.0f32; 8];
        _mm256_storeu_ps(out.as_mut_ptr(), t_near);
        (mask, out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::Pcg32;

    /// Every kernel the CPU has gives the scalar kernel's mask and entry bits on random
    /// boxes, empty slots, flat boxes and rays lying in box planes, with full planes and
    /// with quantized ones; the quantized boxes are hit wherever the exact ones are, and
    /// entered no later.
    #[test]
    #[allow(clippy::needless_range_loop)] // lanes index two arrays at once
    fn kernels_agree_bit_for_bit() {
        let mut rng = Pcg32::new(3, 9);
        let mut u = || rng.uniform_f32();
        let mut hits = 0;
        let simds = Simd::available();
        assert!(simds.contains(&Simd::best()));
        eprintln!("kernels on this CPU: {simds:?}");
        for k in 0..20000 {
            let mut planes: Planes8 = [[0.0; 8]; 6];
            for lane in 0..8 {
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
            let ray = Ray8::new(&Ray::new(o, d));
            let t_max = if k % 2 == 0 { f32::INFINITY } else { u() * 3.0 };
            let (m0, t0) = hit8_scalar(&ray, &planes, t_max);
            // The same boxes quantized: the kernels dequantize to `qplanes`' bits, and
            // the quantized boxes are entered wherever the exact ones are.
            let used = (0..8)
                .filter(|&l| (k + l) % 5 != 0)
                .fold(0u8, |m, l| m | 1 << l);
            let bounds = (0..8)
                .filter(|&l| used & (1 << l) != 0)
                .map(|l| crate::geometry::Aabb {
                    min: Vec3::new(planes[0][l], planes[2][l], planes[4][l]),
                    max: Vec3::new(planes[1][l], planes[3][l], planes[5][l]),
                })
                .fold(crate::geometry::Aabb::EMPTY, crate::geometry::Aabb::union);
            let quantized = QBoxes8::new(&planes, bounds, used);
            let qplanes = quantized.planes();
            let (qm0, qt0) = hit8_scalar(&ray, &qplanes, t_max);
            assert_eq!(
                m0 & !qm0 & used as u32,
                0,
                "case {k}: a quantized box missed where the exact one is hit"
            );
            for lane in (0..8).filter(|&l| m0 & (1 << l) != 0) {
                assert!(qt0[lane] <= t0[lane], "case {k}: entered later");
            }
            for &simd in &simds {
                // SAFETY: `simds` holds only kernels this CPU supports.
                let ((m, t), (qm, qt)) = unsafe {
                    match simd {
                        Simd::Scalar => {
                            let r = ScalarBoxes::prepare(&ray);
                            (
                                ScalarBoxes::hit8(&r, &planes, t_max),
                                ScalarBoxes::hit8q(&r, &quantized, t_max),
                            )
                        }
                        #[cfg(target_arch = "x86_64")]
                        Simd::Sse => {
                            let r = SseBoxes::prepare(&ray);
                            (
                                SseBoxes::hit8(&r, &planes, t_max),
                                SseBoxes::hit8q(&r, &quantized, t_max),
                            )
                        }
                        #[cfg(target_arch = "x86_64")]
                        Simd::Avx2 => {
                            let r = Avx2Boxes::prepare(&ray);
                            (
                                Avx2Boxes::hit8(&r, &planes, t_max),
                                Avx2Boxes::hit8q(&r, &quantized, t_max),
                            )
                        }
                        #[cfg(not(target_arch = "x86_64"))]
                        _ => unreachable!(),
                    }
                };
                assert_eq!(m, m0, "{simd:?} case {k}");
                assert_eq!(
                    t.map(f32::to_bits),
                    t0.map(f32::to_bits),
                    "{simd:?} case {k}"
                );
                assert_eq!(qm, qm0, "{simd:?} quantized, case {k}");
                assert_eq!(
                    qt.map(f32::to_bits),
                    qt0.map(f32::to_bits),
                    "{simd:?} quantized, case {k}"
                );
            }
            // The slab test agrees with `Aabb::hit` on which boxes the ray meets.
            for lane in 0..8 {
                let b = crate::geometry::Aabb {
                    min: Vec3::new(planes[0][lane], planes[2][lane], planes[4][lane]),
                    max: Vec3::new(planes[1][lane], planes[3][lane], planes[5][lane]),
                };
                if b.hit(o, ray.inv_d, t_max).is_some() {
                    assert!(
                        m0 & (1 << lane) != 0,
                        "case {k} lane {lane}: Aabb::hit meets it"
                    );
                }
            }
            hits += m0.count_ones();
        }
        assert!(hits > 10000, "only {hits} box hits");
    }

    /// `order` (the traversal's child ranks) of every kernel the CPU has: the lanes
    /// greater than and equal to a value, on distances with many ties, ±0 and ∞.
    #[test]
    fn kernels_order_as_plain_comparisons() {
        let mut rng = Pcg32::new(4, 4);
        let values = [0.0, -0.0, 0.5, 1.0, 1.5, 2.0, f32::INFINITY];
        let (mut greater, mut equal) = (0, 0);
        for k in 0..5000 {
            let t: [f32; 8] = std::array::from_fn(|_| values[rng.next_u32() as usize % 7]);
            let x = if k % 2 == 0 { t[k % 8] } else { values[k % 7] };
            let plain = (0..8).fold((0, 0), |(g, e), j| {
                (g | ((t[j] > x) as u32) << j, e | ((t[j] == x) as u32) << j)
            });
            greater += plain.0.count_ones();
            equal += plain.1.count_ones();
            for simd in Simd::available() {
                // SAFETY: `available` lists only kernels this CPU supports.
                let got = unsafe {
                    match simd {
                        #[cfg(target_arch = "x86_64")]
                        Simd::Sse => SseBoxes::order(&t, x),
                        #[cfg(target_arch = "x86_64")]
                        Simd::Avx2 => Avx2Boxes::order(&t, x),
                        _ => ScalarBoxes::order(&t, x),
                    }
                };
                assert_eq!(got, plain, "{simd:?}: {t:?} against {x}");
            }
        }
        // Seven values: about 3/7 of the lanes are greater and 1/7 equal (more on the
        // trials whose x is one of the lanes).
        assert!(
            greater > 10000 && equal > 5000,
            "{greater} greater, {equal} equal"
        );
    }
}
