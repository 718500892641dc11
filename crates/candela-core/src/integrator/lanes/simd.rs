//! Eight-lane `f32` vectors and their masks for the lanes integrator, on stable Rust: plain
//! arrays with element-wise operations marked `#[inline(always)]`. Inside the x86-64-v3
//! copy of the render loop (see `integrator::copies`) LLVM compiles each operation to one
//! ymm instruction; in the baseline copy to two xmm ones. Every operation is the scalar
//! IEEE operation lane by lane, so a lane computes bit for bit what the scalar code does
//! with the same operations in the same order.

use std::ops::{Add, Div, Mul, Neg, Sub};

use glam::Vec3;

/// Lanes per vector: the paths the lanes integrator follows at once (AVX2's eight f32).
pub const LANES: usize = 8;

/// Eight `f32`, one per lane.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct F32x8(pub [f32; LANES]);

/// Eight lane flags, each all ones (true) or zero (false), as a vector comparison makes
/// them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C, align(32))]
pub struct M32x8(pub [u32; LANES]);

/// `f(a[i], b[i])` in each lane.
#[inline(always)]
fn zip<T: Copy, U: Copy, R: Copy + Default>(
    a: [T; LANES],
    b: [U; LANES],
    f: impl Fn(T, U) -> R,
) -> [R; LANES] {
    let mut r = [R::default(); LANES];
    for i in 0..LANES {
        r[i] = f(a[i], b[i]);
    }
    r
}

/// `f(a[i])` in each lane.
#[inline(always)]
fn map<T: Copy, R: Copy + Default>(a: [T; LANES], f: impl Fn(T) -> R) -> [R; LANES] {
    let mut r = [R::default(); LANES];
    for i in 0..LANES {
        r[i] = f(a[i]);
    }
    r
}

#[inline(always)]
fn flag(b: bool) -> u32 {
    if b {
        u32::MAX
    } else {
        0
    }
}

impl F32x8 {
    pub const ZERO: F32x8 = F32x8([0.0; LANES]);
    pub const ONE: F32x8 = F32x8([1.0; LANES]);

    #[inline(always)]
    pub fn splat(v: f32) -> F32x8 {
        F32x8([v; LANES])
    }

    #[inline(always)]
    pub fn abs(self) -> F32x8 {
        F32x8(map(self.0, f32::abs))
    }

    /// `max(self, o)` lane by lane, as `f32::max` (the other operand where one is NaN).
    #[inline(always)]
    pub fn max(self, o: F32x8) -> F32x8 {
        F32x8(zip(self.0, o.0, f32::max))
    }

    #[inline(always)]
    pub fn sqrt(self) -> F32x8 {
        F32x8(map(self.0, f32::sqrt))
    }

    /// `copysign(self, sign)` lane by lane.
    #[inline(always)]
    pub fn copysign(self, sign: F32x8) -> F32x8 {
        F32x8(zip(self.0, sign.0, f32::copysign))
    }

    #[inline(always)]
    pub fn lt(self, o: F32x8) -> M32x8 {
        M32x8(zip(self.0, o.0, |a, b| flag(a < b)))
    }

    #[inline(always)]
    pub fn gt(self, o: F32x8) -> M32x8 {
        M32x8(zip(self.0, o.0, |a, b| flag(a > b)))
    }

    #[inline(always)]
    pub fn eq(self, o: F32x8) -> M32x8 {
        M32x8(zip(self.0, o.0, |a, b| flag(a == b)))
    }

    /// Lanes that are neither infinite nor NaN.
    #[inline(always)]
    pub fn is_finite(self) -> M32x8 {
        M32x8(map(self.0, |a| flag(a.is_finite())))
    }
}

macro_rules! lane_op {
    ($tr:ident, $f:ident, $op:tt) => {
        impl $tr for F32x8 {
            type Output = F32x8;
            #[inline(always)]
            fn $f(self, o: F32x8) -> F32x8 {
                F32x8(zip(self.0, o.0, |a, b| a $op b))
            }
        }
    };
}
lane_op!(Add, add, +);
lane_op!(Sub, sub, -);
lane_op!(Mul, mul, *);
lane_op!(Div, div, /);

impl Neg for F32x8 {
    type Output = F32x8;
    #[inline(always)]
    fn neg(self) -> F32x8 {
        F32x8(map(self.0, |a| -a))
    }
}

impl M32x8 {
    pub const NONE: M32x8 = M32x8([0; LANES]);

    #[inline(always)]
    pub fn from_bools(b: [bool; LANES]) -> M32x8 {
        M32x8(map(b, flag))
    }

    #[inline(always)]
    pub fn get(self, i: usize) -> bool {
        self.0[i] != 0
    }

    #[inline(always)]
    pub fn and(self, o: M32x8) -> M32x8 {
        M32x8(zip(self.0, o.0, |a, b| a & b))
    }

    #[inline(always)]
    pub fn or(self, o: M32x8) -> M32x8 {
        M32x8(zip(self.0, o.0, |a, b| a | b))
    }

    #[inline(always)]
    pub fn not(self) -> M32x8 {
        M32x8(map(self.0, |a| !a))
    }

    /// `a` where the lane is set, else `b`: a bitwise blend, exact for every value.
    #[inline(always)]
    pub fn select(self, a: F32x8, b: F32x8) -> F32x8 {
        F32x8(std::array::from_fn(|i| {
            let m = self.0[i];
            f32::from_bits((a.0[i].to_bits() & m) | (b.0[i].to_bits() & !m))
        }))
    }
}

/// Eight 3-vectors in structure-of-arrays form: lane `i` is `(x[i], y[i], z[i])`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vec3x8 {
    pub x: F32x8,
    pub y: F32x8,
    pub z: F32x8,
}

impl Vec3x8 {
    pub const ZERO: Vec3x8 = Vec3x8 {
        x: F32x8::ZERO,
        y: F32x8::ZERO,
        z: F32x8::ZERO,
    };
    pub const ONE: Vec3x8 = Vec3x8 {
        x: F32x8::ONE,
        y: F32x8::ONE,
        z: F32x8::ONE,
    };

    /// Lane `i` as a [`Vec3`].
    #[inline(always)]
    pub fn lane(&self, i: usize) -> Vec3 {
        Vec3::new(self.x.0[i], self.y.0[i], self.z.0[i])
    }

    /// Sets lane `i` to `v`.
    #[inline(always)]
    pub fn set_lane(&mut self, i: usize, v: Vec3) {
        (self.x.0[i], self.y.0[i], self.z.0[i]) = (v.x, v.y, v.z);
    }

    /// The dot product in each lane, summed as [`Vec3::dot`]: (x + y) + z.
    #[inline(always)]
    pub fn dot(&self, o: &Vec3x8) -> F32x8 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// Each component times `s`, as `Vec3 * f32`.
    #[inline(always)]
    pub fn scale(&self, s: F32x8) -> Vec3x8 {
        Vec3x8 {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }

    /// Component-wise product, as `Vec3 * Vec3`.
    #[inline(always)]
    pub fn mul(&self, o: &Vec3x8) -> Vec3x8 {
        Vec3x8 {
            x: self.x * o.x,
            y: self.y * o.y,
            z: self.z * o.z,
        }
    }

    /// `a` where the lane is set, else `b`.
    #[inline(always)]
    pub fn select(m: M32x8, a: &Vec3x8, b: &Vec3x8) -> Vec3x8 {
        Vec3x8 {
            x: m.select(a.x, b.x),
            y: m.select(a.y, b.y),
            z: m.select(a.z, b.z),
        }
    }

    /// The largest component in each lane, as [`crate::math::max_component`].
    #[inline(always)]
    pub fn max_component(&self) -> F32x8 {
        self.x.max(self.y).max(self.z)
    }

    /// Lanes whose three components are finite.
    #[inline(always)]
    pub fn is_finite(&self) -> M32x8 {
        self.x
            .is_finite()
            .and(self.y.is_finite())
            .and(self.z.is_finite())
    }

    /// Lanes whose three components are zero.
    #[inline(always)]
    pub fn is_zero(&self) -> M32x8 {
        self.x
            .eq(F32x8::ZERO)
            .and(self.y.eq(F32x8::ZERO))
            .and(self.z.eq(F32x8::ZERO))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn select_blends_lane_by_lane_and_keeps_bits() {
        let m = M32x8::from_bools([true, false, true, false, true, false, true, false]);
        let a = F32x8([-0.0, 1.0, f32::NAN, 3.0, 4.0, 5.0, f32::INFINITY, 7.0]);
        let b = F32x8::splat(9.0);
        let r = m.select(a, b);
        for i in 0..LANES {
            let want = if i % 2 == 0 { a.0[i] } else { b.0[i] };
            assert_eq!(r.0[i].to_bits(), want.to_bits(), "lane {i}");
        }
    }

    #[test]
    fn dot_and_max_component_match_glam_lane_by_lane() {
        let vs: [Vec3; LANES] = std::array::from_fn(|i| {
            let t = i as f32 * 0.37 + 0.1;
            Vec3::new(t.sin(), (2.0 * t).cos(), t * t - 1.0)
        });
        let ws: [Vec3; LANES] = std::array::from_fn(|i| Vec3::new(0.3 * i as f32, -1.5, 0.7));
        let (mut a, mut b) = (Vec3x8::ZERO, Vec3x8::ZERO);
        for i in 0..LANES {
            a.set_lane(i, vs[i]);
            b.set_lane(i, ws[i]);
        }
        let d = a.dot(&b);
        let m = a.max_component();
        for i in 0..LANES {
            assert_eq!(d.0[i].to_bits(), vs[i].dot(ws[i]).to_bits());
            assert_eq!(m.0[i], crate::math::max_component(vs[i]));
            assert_eq!(a.lane(i), vs[i]);
        }
    }
}
