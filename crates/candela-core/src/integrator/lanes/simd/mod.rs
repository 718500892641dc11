//! Eight-lane `f32` vectors and their masks for the lanes integrator, on stable Rust.
//!
//! The vector types [`F32x8`], [`M32x8`] and [`Vec3x8`] are generic over a backend
//! ([`LaneIsa`]): [`Portable`] holds plain arrays and loops over them (the baseline copy of
//! the render loop; LLVM makes SSE of it where it can), [`Avx2`] holds `__m256` and calls
//! `std::arch` (the x86-64-v3 copy only). Arrays alone were not enough: after inlining,
//! LLVM split the arrays into scalars and rebuilt them as a mix of scalar and 4-wide
//! operations (callgrind: ~450 instructions for one lane stage of ~100 operations). Every
//! operation is the scalar IEEE operation lane by lane, with `f32`'s semantics (including
//! `f32::max`'s with NaN), so a lane computes bit for bit what the scalar code does with
//! the same operations in the same order.
//!
//! Between stages the lanes' state lives in memory as [`Lanes32`] and [`Vec3Lanes`] (plain
//! arrays that the per-lane scalar code reads and writes); a stage loads them into vectors.

use std::marker::PhantomData;
use std::ops::{Add, Div, Mul, Neg, Sub};

use glam::Vec3;

/// Lanes per vector: the paths the lanes integrator follows at once (AVX2's eight f32).
pub const LANES: usize = 8;

/// Eight `f32` in memory, one per lane.
pub type Lanes32 = [f32; LANES];

/// Eight 3-vectors in memory, structure of arrays: lane `i` is `(x[i], y[i], z[i])`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vec3Lanes {
    pub x: Lanes32,
    pub y: Lanes32,
    pub z: Lanes32,
}

impl Vec3Lanes {
    pub const ZERO: Vec3Lanes = Vec3Lanes::splat(Vec3::ZERO);

    pub const fn splat(v: Vec3) -> Vec3Lanes {
        Vec3Lanes {
            x: [v.x; LANES],
            y: [v.y; LANES],
            z: [v.z; LANES],
        }
    }

    /// Lane `i` as a [`Vec3`].
    #[inline(always)]
    pub fn lane(&self, i: usize) -> Vec3 {
        Vec3::new(self.x[i], self.y[i], self.z[i])
    }

    /// Sets lane `i` to `v`.
    #[inline(always)]
    pub fn set_lane(&mut self, i: usize, v: Vec3) {
        (self.x[i], self.y[i], self.z[i]) = (v.x, v.y, v.z);
    }
}

/// The operations of eight lanes, on a backend's vector types. Each is the `f32` (or
/// bitwise) operation lane by lane; masks are all ones (true) or zero (false) a lane.
pub trait LaneIsa: Copy {
    type F: Copy;
    type M: Copy;
    fn splat(v: f32) -> Self::F;
    fn load(a: &Lanes32) -> Self::F;
    fn store(v: Self::F) -> Lanes32;
    fn add(a: Self::F, b: Self::F) -> Self::F;
    fn sub(a: Self::F, b: Self::F) -> Self::F;
    fn mul(a: Self::F, b: Self::F) -> Self::F;
    fn div(a: Self::F, b: Self::F) -> Self::F;
    fn neg(a: Self::F) -> Self::F;
    fn abs(a: Self::F) -> Self::F;
    /// As `f32::max`: the other operand where one is NaN (and, as `f32::max`, either
    /// zero for +0 against −0; no caller's result depends on that sign).
    fn max(a: Self::F, b: Self::F) -> Self::F;
    fn sqrt(a: Self::F) -> Self::F;
    /// `a`'s magnitude with `sign`'s sign.
    fn copysign(a: Self::F, sign: Self::F) -> Self::F;
    /// Ordered comparisons (false where either is NaN), as Rust's `<`, `>`, `==`.
    fn lt(a: Self::F, b: Self::F) -> Self::M;
    fn gt(a: Self::F, b: Self::F) -> Self::M;
    fn eq(a: Self::F, b: Self::F) -> Self::M;
    fn is_finite(a: Self::F) -> Self::M;
    fn mask_from_bools(b: [bool; LANES]) -> Self::M;
    /// The lanes of a mask, bit `i` for lane `i`.
    fn mask_bits(m: Self::M) -> u8;
    fn and(a: Self::M, b: Self::M) -> Self::M;
    fn or(a: Self::M, b: Self::M) -> Self::M;
    fn xor(a: Self::M, b: Self::M) -> Self::M;
    fn not(a: Self::M) -> Self::M;
    /// `a` where the mask is set, else `b`, bit for bit.
    fn select(m: Self::M, a: Self::F, b: Self::F) -> Self::F;
}

mod portable;
pub use portable::Portable;

#[cfg(target_arch = "x86_64")]
mod avx2;
#[cfg(target_arch = "x86_64")]
pub use avx2::Avx2;

/// Eight `f32`, one per lane, on backend `I`.
#[derive(Clone, Copy)]
pub struct F32x8<I: LaneIsa>(pub I::F, PhantomData<I>);

/// Eight lane flags on backend `I`.
#[derive(Clone, Copy)]
pub struct M32x8<I: LaneIsa>(pub I::M, PhantomData<I>);

impl<I: LaneIsa> F32x8<I> {
    #[inline(always)]
    fn new(v: I::F) -> F32x8<I> {
        F32x8(v, PhantomData)
    }
    #[inline(always)]
    pub fn splat(v: f32) -> F32x8<I> {
        F32x8::new(I::splat(v))
    }
    #[inline(always)]
    pub fn load(a: &Lanes32) -> F32x8<I> {
        F32x8::new(I::load(a))
    }
    #[inline(always)]
    pub fn store(self) -> Lanes32 {
        I::store(self.0)
    }
    #[inline(always)]
    pub fn abs(self) -> F32x8<I> {
        F32x8::new(I::abs(self.0))
    }
    /// `max(self, o)` lane by lane, as `f32::max`.
    #[inline(always)]
    pub fn max(self, o: F32x8<I>) -> F32x8<I> {
        F32x8::new(I::max(self.0, o.0))
    }
    #[inline(always)]
    pub fn sqrt(self) -> F32x8<I> {
        F32x8::new(I::sqrt(self.0))
    }
    /// `self`'s magnitudes with `sign`'s signs.
    #[inline(always)]
    pub fn copysign(self, sign: F32x8<I>) -> F32x8<I> {
        F32x8::new(I::copysign(self.0, sign.0))
    }
    #[inline(always)]
    pub fn lt(self, o: F32x8<I>) -> M32x8<I> {
        M32x8::new(I::lt(self.0, o.0))
    }
    #[inline(always)]
    pub fn gt(self, o: F32x8<I>) -> M32x8<I> {
        M32x8::new(I::gt(self.0, o.0))
    }
    #[inline(always)]
    pub fn eq(self, o: F32x8<I>) -> M32x8<I> {
        M32x8::new(I::eq(self.0, o.0))
    }
    /// Lanes that are neither infinite nor NaN.
    #[inline(always)]
    pub fn is_finite(self) -> M32x8<I> {
        M32x8::new(I::is_finite(self.0))
    }
}

macro_rules! lane_op {
    ($tr:ident, $f:ident) => {
        impl<I: LaneIsa> $tr for F32x8<I> {
            type Output = F32x8<I>;
            #[inline(always)]
            fn $f(self, o: F32x8<I>) -> F32x8<I> {
                F32x8::new(I::$f(self.0, o.0))
            }
        }
    };
}
lane_op!(Add, add);
lane_op!(Sub, sub);
lane_op!(Mul, mul);
lane_op!(Div, div);

impl<I: LaneIsa> Neg for F32x8<I> {
    type Output = F32x8<I>;
    #[inline(always)]
    fn neg(self) -> F32x8<I> {
        F32x8::new(I::neg(self.0))
    }
}

impl<I: LaneIsa> M32x8<I> {
    #[inline(always)]
    fn new(m: I::M) -> M32x8<I> {
        M32x8(m, PhantomData)
    }
    #[inline(always)]
    pub fn from_bools(b: [bool; LANES]) -> M32x8<I> {
        M32x8::new(I::mask_from_bools(b))
    }
    /// Bit `i` set for lane `i`.
    #[inline(always)]
    pub fn bits(self) -> u8 {
        I::mask_bits(self.0)
    }
    #[inline(always)]
    pub fn and(self, o: M32x8<I>) -> M32x8<I> {
        M32x8::new(I::and(self.0, o.0))
    }
    #[inline(always)]
    pub fn or(self, o: M32x8<I>) -> M32x8<I> {
        M32x8::new(I::or(self.0, o.0))
    }
    /// Lanes set in exactly one of the two.
    #[inline(always)]
    pub fn xor(self, o: M32x8<I>) -> M32x8<I> {
        M32x8::new(I::xor(self.0, o.0))
    }
    #[inline(always)]
    pub fn not(self) -> M32x8<I> {
        M32x8::new(I::not(self.0))
    }
    /// `a` where the lane is set, else `b`: a bitwise blend, exact for every value.
    #[inline(always)]
    pub fn select(self, a: F32x8<I>, b: F32x8<I>) -> F32x8<I> {
        F32x8::new(I::select(self.0, a.0, b.0))
    }
}

/// Eight 3-vectors on backend `I`: lane `i` is `(x[i], y[i], z[i])`.
#[derive(Clone, Copy)]
pub struct Vec3x8<I: LaneIsa> {
    pub x: F32x8<I>,
    pub y: F32x8<I>,
    pub z: F32x8<I>,
}

impl<I: LaneIsa> Vec3x8<I> {
    #[inline(always)]
    pub fn load(v: &Vec3Lanes) -> Vec3x8<I> {
        Vec3x8 {
            x: F32x8::load(&v.x),
            y: F32x8::load(&v.y),
            z: F32x8::load(&v.z),
        }
    }

    #[inline(always)]
    pub fn store(&self) -> Vec3Lanes {
        Vec3Lanes {
            x: self.x.store(),
            y: self.y.store(),
            z: self.z.store(),
        }
    }

    /// The dot product in each lane, summed as [`Vec3::dot`]: (x + y) + z.
    #[inline(always)]
    pub fn dot(&self, o: &Vec3x8<I>) -> F32x8<I> {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// Each component times `s`, as `Vec3 * f32`.
    #[inline(always)]
    pub fn scale(&self, s: F32x8<I>) -> Vec3x8<I> {
        Vec3x8 {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }

    /// Component-wise product, as `Vec3 * Vec3`.
    #[inline(always)]
    pub fn mul(&self, o: &Vec3x8<I>) -> Vec3x8<I> {
        Vec3x8 {
            x: self.x * o.x,
            y: self.y * o.y,
            z: self.z * o.z,
        }
    }

    /// `a` where the lane is set, else `b`.
    #[inline(always)]
    pub fn select(m: M32x8<I>, a: &Vec3x8<I>, b: &Vec3x8<I>) -> Vec3x8<I> {
        Vec3x8 {
            x: m.select(a.x, b.x),
            y: m.select(a.y, b.y),
            z: m.select(a.z, b.z),
        }
    }

    /// The largest component in each lane, as [`crate::math::max_component`].
    #[inline(always)]
    pub fn max_component(&self) -> F32x8<I> {
        self.x.max(self.y).max(self.z)
    }

    /// Lanes whose three components are finite.
    #[inline(always)]
    pub fn is_finite(&self) -> M32x8<I> {
        self.x
            .is_finite()
            .and(self.y.is_finite())
            .and(self.z.is_finite())
    }

    /// Lanes whose three components are zero.
    #[inline(always)]
    pub fn is_zero(&self) -> M32x8<I> {
        let zero = F32x8::splat(0.0);
        self.x.eq(zero).and(self.y.eq(zero)).and(self.z.eq(zero))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Odd values for every operation: signed zeros, NaN, infinities, subnormals.
    const A: Lanes32 = [-0.0, 1.5, f32::NAN, -3.0, f32::INFINITY, 1e-40, 7.0, -2.5];
    const B: Lanes32 = [
        0.0,
        f32::NAN,
        2.0,
        -3.0,
        1.0,
        -1e-40,
        f32::NEG_INFINITY,
        4.0,
    ];

    /// Every operation of backend `I` on `A` and `B` against `f32`'s own, bit for bit.
    fn ops_match_f32<I: LaneIsa>() {
        let (a, b) = (F32x8::<I>::load(&A), F32x8::<I>::load(&B));
        let bits = |v: Lanes32| v.map(f32::to_bits);
        let want = |f: fn(f32, f32) -> f32| bits(std::array::from_fn(|i| f(A[i], B[i])));
        assert_eq!(bits((a + b).store()), want(|x, y| x + y));
        assert_eq!(bits((a - b).store()), want(|x, y| x - y));
        assert_eq!(bits((a * b).store()), want(|x, y| x * y));
        assert_eq!(bits((a / b).store()), want(|x, y| x / y));
        // `f32::max` may give either zero for (+0, −0) (its documentation says so, and
        // constant folding and the machine disagree): zeros compare by value.
        let unsigned_zero = |v: [u32; LANES]| v.map(|b| if b == 1 << 31 { 0 } else { b });
        assert_eq!(
            unsigned_zero(bits(a.max(b).store())),
            unsigned_zero(want(f32::max))
        );
        assert_eq!(
            unsigned_zero(bits(b.max(a).store())),
            unsigned_zero(want(|x, y| y.max(x)))
        );
        assert_eq!(bits(a.copysign(b).store()), want(f32::copysign));
        assert_eq!(bits((-a).store()), want(|x, _| -x));
        assert_eq!(bits(a.abs().store()), want(|x, _| x.abs()));
        assert_eq!(bits(a.abs().sqrt().store()), want(|x, _| x.abs().sqrt()));
        let mask =
            |f: fn(f32, f32) -> bool| (0..LANES).fold(0u8, |m, i| m | ((f(A[i], B[i]) as u8) << i));
        assert_eq!(a.lt(b).bits(), mask(|x, y| x < y));
        assert_eq!(a.gt(b).bits(), mask(|x, y| x > y));
        assert_eq!(a.eq(b).bits(), mask(|x, y| x == y));
        assert_eq!(a.is_finite().bits(), mask(|x, _| x.is_finite()));
        let m = a.lt(b);
        assert_eq!(m.not().bits(), !m.bits());
        assert_eq!(m.and(a.eq(b)).bits(), m.bits() & a.eq(b).bits());
        assert_eq!(m.or(a.gt(b)).bits(), m.bits() | a.gt(b).bits());
        assert_eq!(m.xor(a.gt(b)).bits(), m.bits() ^ a.gt(b).bits());
        let pick = [true, false, true, true, false, false, true, false];
        let s = M32x8::<I>::from_bools(pick).select(a, b).store();
        let want_pick: Lanes32 = std::array::from_fn(|i| if pick[i] { A[i] } else { B[i] });
        assert_eq!(bits(s), bits(want_pick));
    }

    #[test]
    fn portable_lanes_are_f32_lane_by_lane() {
        ops_match_f32::<Portable>();
    }

    #[cfg(target_arch = "x86_64")]
    #[test]
    fn avx2_lanes_are_f32_lane_by_lane() {
        if !std::arch::is_x86_feature_detected!("avx2") {
            eprintln!("NOTE: no AVX2 on this CPU: the AVX2 lanes are not tested");
            return;
        }
        // SAFETY: the CPU has AVX2 (checked above).
        #[target_feature(enable = "avx,avx2")]
        unsafe fn run() {
            ops_match_f32::<Avx2>();
        }
        unsafe { run() }
    }

    #[test]
    fn vec3_lanes_dot_and_max_component_match_glam() {
        let vs: [Vec3; LANES] = std::array::from_fn(|i| {
            let t = i as f32 * 0.37 + 0.1;
            Vec3::new(t.sin(), (2.0 * t).cos(), t * t - 1.0)
        });
        let ws: [Vec3; LANES] = std::array::from_fn(|i| Vec3::new(0.3 * i as f32, -1.5, 0.7));
        let (mut a, mut b) = (Vec3Lanes::ZERO, Vec3Lanes::ZERO);
        for i in 0..LANES {
            a.set_lane(i, vs[i]);
            b.set_lane(i, ws[i]);
        }
        let (a8, b8) = (Vec3x8::<Portable>::load(&a), Vec3x8::<Portable>::load(&b));
        let d = a8.dot(&b8).store();
        let m = a8.max_component().store();
        for i in 0..LANES {
            assert_eq!(d[i].to_bits(), vs[i].dot(ws[i]).to_bits());
            assert_eq!(m[i], crate::math::max_component(vs[i]));
            assert_eq!(a8.store().lane(i), vs[i]);
        }
    }
}
