//! An order-free sum of film contributions, so that a render split into sample ranges
//! (or into threads, tiles, splats) adds up to the same bits as the render in one piece.
//!
//! Float addition is not associative: Σ(0..64) + Σ(64..128) in `f64` is not in general
//! the sequential Σ(0..128). [`ExactSum`] instead keeps a fixed-point integer: each
//! contribution `x` (a product of two `f32`, exact in `f64`) is rounded **once, on its
//! own** to the nearest multiple of 2⁻⁵⁶ ([`RESOLUTION`]) and the integers are added with
//! wrapping `i128` arithmetic. Integer addition modulo 2¹²⁸ is associative and
//! commutative, so every grouping and order of the same contributions gives the same
//! integer, by construction; the only rounding is per contribution, which does not
//! depend on the grouping.
//!
//! Range: a contribution is accepted when |x| < 2⁴⁰ ≈ 1.1·10¹² ([`MAX_CONTRIBUTION`]);
//! one beyond is refused (the film counts it as rejected, as it does NaN). The integer
//! sum of up to 2³¹ accepted contributions then stays below 2⁹⁶·2³¹ = 2¹²⁷ in magnitude,
//! so it is the true sum (no wrap) for any pixel of a render under 2³¹ samples per pixel
//! (times the number of pixels that splat into one). Resolution: 2⁻⁵⁶ ≈ 1.4·10⁻¹⁷ per
//! contribution, far below what an `f32` image can show of a pixel above 10⁻⁹.

/// Fixed-point units per 1.0: 2⁵⁶.
const SCALE: f64 = (1u64 << 56) as f64;

/// The smallest step a contribution is rounded to: 2⁻⁵⁶.
pub const RESOLUTION: f64 = 1.0 / SCALE;

/// Contributions must be smaller than this in magnitude: 2⁴⁰.
pub const MAX_CONTRIBUTION: f64 = (1u64 << 40) as f64;

/// 2⁵², above which every `f64` is an integer.
const TWO_52: f64 = (1u64 << 52) as f64;

/// A sum of `f64` contributions in units of [`RESOLUTION`]; see the module docs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ExactSum(i128);

impl ExactSum {
    pub const ZERO: ExactSum = ExactSum(0);

    /// One contribution as a sum, or `None` if it is not finite or not below
    /// [`MAX_CONTRIBUTION`] in magnitude.
    #[inline]
    pub fn of(x: f64) -> Option<ExactSum> {
        if x.abs() < MAX_CONTRIBUTION {
            Some(ExactSum(to_fixed(x)))
        } else {
            None
        }
    }

    /// The sum rounded to the nearest `f64`.
    #[inline]
    pub fn to_f64(self) -> f64 {
        // One rounding (i128 → f64, to nearest), then an exact power-of-two scaling.
        self.0 as f64 * RESOLUTION
    }

    /// The fixed-point integer, for storing a film in a file.
    pub fn to_bits(self) -> i128 {
        self.0
    }

    /// The sum stored by [`Self::to_bits`].
    pub fn from_bits(bits: i128) -> ExactSum {
        ExactSum(bits)
    }
}

/// `(x * SCALE).round_ties_even() as i128` for |x| < [`MAX_CONTRIBUTION`]: an exact
/// scaling by a power of two, then one rounding to an integer (|x·2⁵⁶| < 2⁹⁶ fits the
/// i128 with room for 2³¹ of them). Computed from the float's bits with integer
/// operations, some 15 instructions: the expression above is a call to `rint` and one to
/// the software f64 → i128 conversion (`__fixdfti`) on the baseline x86-64 target, ~100
/// instructions, four times per film contribution and 16 times that per splatted sample.
#[inline]
fn to_fixed(x: f64) -> i128 {
    let y = (x * SCALE).abs();
    let magnitude = if y < TWO_52 {
        // 2⁵² + y lies in [2⁵², 2⁵³], where the floats are the integers spaced by one:
        // the addition rounds y to an integer, ties to even (2⁵² is even), and the bits
        // above those of 2⁵² are that integer (2⁵³'s bits are 2⁵² above them).
        ((y + TWO_52).to_bits() - TWO_52.to_bits()) as u128
    } else {
        // y ≥ 2⁵² is an integer: its significand shifted left by its exponent less 52
        // (0 to 43 here).
        let bits = y.to_bits();
        let significand = (bits & ((1 << 52) - 1)) | (1 << 52);
        let shift = (bits >> 52) as u32 - 1075;
        (significand as u128) << shift
    };
    if x.is_sign_negative() {
        (magnitude as i128).wrapping_neg()
    } else {
        magnitude as i128
    }
}

/// Wrapping addition, so associative and commutative without exception.
impl std::ops::Add for ExactSum {
    type Output = ExactSum;

    #[inline]
    fn add(self, other: ExactSum) -> ExactSum {
        ExactSum(self.0.wrapping_add(other.0))
    }
}

impl std::ops::AddAssign for ExactSum {
    #[inline]
    fn add_assign(&mut self, other: ExactSum) {
        *self = *self + other;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sums_do_not_depend_on_grouping_or_order() {
        // Values of wildly different magnitudes, where f64 addition loses the small ones
        // in one order and not in another.
        let xs = [1e11, 3.0e-9, -1e11, 0.1, 7.25e-12, 2.5, 1e-3, 123456.789];
        let f64_fwd: f64 = xs.iter().sum();
        let f64_rev: f64 = xs.iter().rev().sum();
        assert_ne!(f64_fwd, f64_rev, "the example must defeat plain f64 sums");
        let exact = |it: &mut dyn Iterator<Item = &f64>| {
            it.fold(ExactSum::ZERO, |s, &x| s + ExactSum::of(x).unwrap())
        };
        let fwd = exact(&mut xs.iter());
        assert_eq!(fwd, exact(&mut xs.iter().rev()));
        let (a, b) = xs.split_at(3);
        assert_eq!(fwd, exact(&mut b.iter()) + exact(&mut a.iter()));
    }

    #[test]
    fn contributions_round_once_to_the_resolution() {
        assert_eq!(ExactSum::of(1.0).unwrap().to_bits(), 1 << 56);
        assert_eq!(ExactSum::of(0.75 * RESOLUTION).unwrap().to_bits(), 1);
        assert_eq!(
            ExactSum::of(0.5 * RESOLUTION).unwrap().to_bits(),
            0,
            "ties to even"
        );
        assert_eq!(ExactSum::of(-2.5).unwrap().to_f64(), -2.5);
        // A product of two f32 (48 significant bits) above 2⁻⁸ survives exactly.
        let x = 1.1f32 as f64 * 0.3f32 as f64;
        assert_eq!(ExactSum::of(x).unwrap().to_f64(), x);
    }

    /// The integer path gives the bits of the float rounding it stands for, on values of
    /// every magnitude in range (2⁻¹⁰⁷⁴ to 2⁴⁰, both signs), on exact ties and on the
    /// neighbours of 2⁵² · 2⁻⁵⁶ where it changes method.
    #[test]
    fn fixed_point_matches_the_float_rounding() {
        let reference = |x: f64| (x * SCALE).round_ties_even() as i128;
        let mut state = 0x1234_5678_9abc_def0u64;
        let mut next = move || {
            state = crate::sampler::mix64(state);
            state
        };
        let mut values = vec![0.0, -0.0, f64::MIN_POSITIVE, 5e-324, RESOLUTION];
        for k in -70i32..40 {
            let p = 2f64.powi(k);
            values.extend([p, p.next_up(), p.next_down(), -p, 1.5 * p, -1.5 * p]);
        }
        for i in 0..2000u32 {
            // Exact ties: (i + ½)·2⁻⁵⁶, and near the switch at 2⁻⁴.
            let tie = (i as f64 + 0.5) * RESOLUTION;
            values.extend([tie, -tie, tie.next_up(), tie.next_down()]);
            let near = 0.0625 + (i as f64 - 1000.0) * RESOLUTION * 0.5;
            values.extend([near, -near]);
        }
        for _ in 0..200_000 {
            // Random significands and signs at exponents spread over the range.
            let bits = next();
            let exp = (bits >> 53) % 1064; // biased exponents 0 (subnormal) … 1063 (2⁴⁰)
            let x = f64::from_bits((bits & (1 << 63)) | (exp << 52) | (next() >> 12));
            values.push(x);
            let (a, b) = (f32::from_bits(next() as u32), f32::from_bits(next() as u32));
            values.push(a as f64 * b as f64);
        }
        for x in values {
            if x.abs() < MAX_CONTRIBUTION {
                assert_eq!(to_fixed(x), reference(x), "{x:e}");
            }
        }
    }

    #[test]
    fn out_of_range_contributions_are_refused() {
        assert!(ExactSum::of(MAX_CONTRIBUTION).is_none());
        assert!(ExactSum::of(-MAX_CONTRIBUTION).is_none());
        assert!(ExactSum::of(f64::NAN).is_none());
        assert!(ExactSum::of(f64::INFINITY).is_none());
        let big = ExactSum::of(MAX_CONTRIBUTION * (1.0 - f64::EPSILON)).unwrap();
        // 2³¹ of the largest contributions still fit without wrapping.
        let n = 1i128 << 31;
        assert!(big.to_bits().checked_mul(n).is_some());
    }

    #[test]
    fn bits_round_trip() {
        let s = ExactSum::of(-1234.5678).unwrap();
        assert_eq!(ExactSum::from_bits(s.to_bits()), s);
    }
}
