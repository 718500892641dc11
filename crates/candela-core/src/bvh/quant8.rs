//! Eight child boxes in 8-bit fixed point (Ylitie, Karras and Laine 2017, "Efficient
//! Incoherent Ray Traversal on GPUs Using Compressed Wide BVHs"; Embree's quantized
//! nodes): per axis an origin and a power-of-two step, and per child and plane one byte,
//! the number of steps from the origin. A plane is `origin + q · step`: the product is
//! exact (eight bits times a power of two), so the only rounding is the add, which the
//! scalar, SSE and AVX2 kernels perform alike (a multiply, then an add, never fused), and
//! so they give the same bits.
//!
//! The bytes are rounded *outward* and checked with that same arithmetic, so that each
//! dequantized box contains its exact child box. The slab test's rounding is monotone in
//! the plane, so a ray that meets the exact box meets the quantized one too: traversal
//! can only open more boxes than with full planes, never fewer, and the primitive tests
//! decide the hits as before. 72 bytes instead of 192 for eight boxes.

use super::box8::Planes8;
use crate::geometry::Aabb;

/// Eight boxes quantized against a common frame. Row `r` of `q` is plane `r` of
/// [`Planes8`] (`[min_x, max_x, min_y, max_y, min_z, max_z]`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct QBoxes8 {
    pub origin: [f32; 3],
    /// A power of two per axis.
    pub step: [f32; 3],
    pub q: [[u8; 8]; 6],
}

/// The smallest and largest steps: normal powers of two, so `q · step` stays exact.
const MIN_EXP: i32 = -126;
const MAX_EXP: i32 = 127;

fn pow2(e: i32) -> f32 {
    f32::from_bits(((e.clamp(MIN_EXP, MAX_EXP) + 127) as u32) << 23)
}

/// The plane `q` steps from `origin`, rounded as every kernel rounds it.
#[inline(always)]
pub fn dequantize(origin: f32, step: f32, q: u8) -> f32 {
    q as f32 * step + origin
}

impl QBoxes8 {
    /// Quantizes the eight boxes of `planes` within `bounds` (which must contain every
    /// box of a lane in `used`; the other lanes get arbitrary bytes and must be masked
    /// off by the caller).
    pub fn new(planes: &Planes8, bounds: Aabb, used: u8) -> QBoxes8 {
        let mut out = QBoxes8 {
            origin: bounds.min.to_array(),
            step: [1.0; 3],
            q: [[0; 8]; 6],
        };
        for axis in 0..3 {
            let (lo, hi) = (bounds.min[axis], bounds.max[axis]);
            debug_assert!(lo <= hi && lo.is_finite() && hi.is_finite());
            // The smallest power of two whose 255 steps reach `hi`, with the add's rounding.
            let mut e = ((hi - lo) as f64 / 255.0).log2().ceil().max(MIN_EXP as f64) as i32;
            while e < MAX_EXP && dequantize(lo, pow2(e), 255) < hi {
                e += 1;
            }
            let step = pow2(e);
            out.step[axis] = step;
            let deq = |q: u8| dequantize(lo, step, q);
            for lane in (0..8).filter(|l| used & (1 << l) != 0) {
                let (cmin, cmax) = (planes[2 * axis][lane], planes[2 * axis + 1][lane]);
                // A first guess from the division, then moved outward until it holds
                // (deq is monotone; deq(0) = lo <= cmin and deq(255) >= hi >= cmax).
                let guess = |x: f32| ((x - lo) / step).clamp(0.0, 255.0);
                let mut qmin = guess(cmin).floor() as u8;
                while deq(qmin) > cmin {
                    qmin -= 1;
                }
                let mut qmax = guess(cmax).ceil() as u8;
                while deq(qmax) < cmax {
                    qmax += 1;
                }
                out.q[2 * axis][lane] = qmin;
                out.q[2 * axis + 1][lane] = qmax;
            }
        }
        out
    }

    /// The dequantized planes, as the kernels compute them.
    pub fn planes(&self) -> Planes8 {
        let mut p = [[0.0; 8]; 6];
        for (row, (out, q)) in p.iter_mut().zip(&self.q).enumerate() {
            let axis = row / 2;
            for lane in 0..8 {
                out[lane] = dequantize(self.origin[axis], self.step[axis], q[lane]);
            }
        }
        p
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::Pcg32;
    use glam::Vec3;

    /// Every quantized box contains its exact box, and is not much larger: within one
    /// step (and the add's rounding) of it on each side, a step being at most 4/255 of
    /// the node's extent (the power of two above 1/255 of it, doubled where the add
    /// rounds short), or the smallest step where the node is flat.
    #[test]
    fn quantized_boxes_contain_the_exact_ones() {
        let mut rng = Pcg32::new(11, 4);
        let mut u = || rng.uniform_f32();
        for k in 0..20000 {
            let scale = [1.0, 1e-30, 1e30, 3.0e-5, 7.0e5][k % 5];
            let shift = [0.0, -1.0, 1e3, 1.0e7][k / 5 % 4] * scale;
            let mut planes: Planes8 = [[0.0; 8]; 6];
            let mut bounds = Aabb::EMPTY;
            let used = (u() * 255.0) as u8 | 1;
            for lane in (0..8).filter(|l| used & (1 << l) != 0) {
                let mut b = Aabb::EMPTY;
                for _ in 0..2 {
                    let mut p = Vec3::new(u(), u(), u()) * scale + shift;
                    if k % 7 == 0 {
                        p.y = shift; // flat along y
                    }
                    b = b.union(Aabb { min: p, max: p });
                }
                for axis in 0..3 {
                    planes[2 * axis][lane] = b.min[axis];
                    planes[2 * axis + 1][lane] = b.max[axis];
                }
                bounds = bounds.union(b);
            }
            let q = QBoxes8::new(&planes, bounds, used);
            let deq = q.planes();
            for lane in (0..8).filter(|l| used & (1 << l) != 0) {
                for axis in 0..3 {
                    let (lo, hi) = (planes[2 * axis][lane], planes[2 * axis + 1][lane]);
                    let (qlo, qhi) = (deq[2 * axis][lane], deq[2 * axis + 1][lane]);
                    assert!(qlo <= lo && hi <= qhi, "case {k} lane {lane} axis {axis}");
                    let extent = bounds.max[axis] - bounds.min[axis];
                    let ulp = f32::EPSILON * bounds.min[axis].abs().max(bounds.max[axis].abs());
                    let step = q.step[axis];
                    assert!(
                        step <= (4.0 * extent / 255.0).max(pow2(MIN_EXP)),
                        "case {k}"
                    );
                    assert!(
                        lo - qlo <= step + 2.0 * ulp && qhi - hi <= step + 2.0 * ulp,
                        "case {k}: [{qlo}, {qhi}] too loose around [{lo}, {hi}]"
                    );
                }
            }
        }
    }
}
