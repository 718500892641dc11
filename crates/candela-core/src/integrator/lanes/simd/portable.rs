//! The portable backend of the lane types: arrays of eight and loops over them, for any
//! target (the baseline copy of the render loop).

use super::{LaneIsa, Lanes32, LANES};

/// Arrays and loops: any target.
#[derive(Clone, Copy, Debug)]
pub struct Portable;

#[inline(always)]
fn flag(b: bool) -> u32 {
    if b {
        u32::MAX
    } else {
        0
    }
}

#[inline(always)]
fn zip<T: Copy, R>(a: [T; LANES], b: [T; LANES], f: impl Fn(T, T) -> R) -> [R; LANES] {
    std::array::from_fn(|i| f(a[i], b[i]))
}

impl LaneIsa for Portable {
    type F = Lanes32;
    type M = [u32; LANES];
    #[inline(always)]
    fn splat(v: f32) -> Lanes32 {
        [v; LANES]
    }
    #[inline(always)]
    fn load(a: &Lanes32) -> Lanes32 {
        *a
    }
    #[inline(always)]
    fn store(v: Lanes32) -> Lanes32 {
        v
    }
    #[inline(always)]
    fn add(a: Lanes32, b: Lanes32) -> Lanes32 {
        zip(a, b, |a, b| a + b)
    }
    #[inline(always)]
    fn sub(a: Lanes32, b: Lanes32) -> Lanes32 {
        zip(a, b, |a, b| a - b)
    }
    #[inline(always)]
    fn mul(a: Lanes32, b: Lanes32) -> Lanes32 {
        zip(a, b, |a, b| a * b)
    }
    #[inline(always)]
    fn div(a: Lanes32, b: Lanes32) -> Lanes32 {
        zip(a, b, |a, b| a / b)
    }
    #[inline(always)]
    fn neg(a: Lanes32) -> Lanes32 {
        a.map(|a| -a)
    }
    #[inline(always)]
    fn abs(a: Lanes32) -> Lanes32 {
        a.map(f32::abs)
    }
    #[inline(always)]
    fn max(a: Lanes32, b: Lanes32) -> Lanes32 {
        zip(a, b, f32::max)
    }
    #[inline(always)]
    fn sqrt(a: Lanes32) -> Lanes32 {
        a.map(f32::sqrt)
    }
    #[inline(always)]
    fn copysign(a: Lanes32, sign: Lanes32) -> Lanes32 {
        zip(a, sign, f32::copysign)
    }
    #[inline(always)]
    fn lt(a: Lanes32, b: Lanes32) -> [u32; LANES] {
        zip(a, b, |a, b| flag(a < b))
    }
    #[inline(always)]
    fn gt(a: Lanes32, b: Lanes32) -> [u32; LANES] {
        zip(a, b, |a, b| flag(a > b))
    }
    #[inline(always)]
    fn eq(a: Lanes32, b: Lanes32) -> [u32; LANES] {
        zip(a, b, |a, b| flag(a == b))
    }
    #[inline(always)]
    fn is_finite(a: Lanes32) -> [u32; LANES] {
        a.map(|a| flag(a.is_finite()))
    }
    #[inline(always)]
    fn mask_from_bools(b: [bool; LANES]) -> [u32; LANES] {
        b.map(flag)
    }
    #[inline(always)]
    fn mask_bits(m: [u32; LANES]) -> u8 {
        (0..LANES).fold(0, |bits, i| bits | (((m[i] != 0) as u8) << i))
    }
    #[inline(always)]
    fn and(a: [u32; LANES], b: [u32; LANES]) -> [u32; LANES] {
        zip(a, b, |a, b| a & b)
    }
    #[inline(always)]
    fn or(a: [u32; LANES], b: [u32; LANES]) -> [u32; LANES] {
        zip(a, b, |a, b| a | b)
    }
    #[inline(always)]
    fn xor(a: [u32; LANES], b: [u32; LANES]) -> [u32; LANES] {
        zip(a, b, |a, b| a ^ b)
    }
    #[inline(always)]
    fn not(a: [u32; LANES]) -> [u32; LANES] {
        a.map(|a| !a)
    }
    #[inline(always)]
    fn select(m: [u32; LANES], a: Lanes32, b: Lanes32) -> Lanes32 {
        std::array::from_fn(|i| f32::from_bits((a[i].to_bits() & m[i]) | (b[i].to_bits() & !m[i])))
    }
}
