//! A leaf's primitives as one block of four lanes, coordinates side by side
//! (structure of arrays), so that the watertight test runs on four triangles at once.
//!
//! The four-lane test performs exactly the operations of [`WatertightRay::intersect`] in
//! the same order (Rust never fuses a multiply and an add on its own), so each lane's
//! distance and barycentrics are the same bits as the scalar test's. Lanes where an edge
//! function is exactly zero take the scalar test, which retries those in double precision
//! as the paper does. Blocks holding a sphere or a filtered triangle take the scalar path
//! lane by lane, and so does everything under [`Simd::Scalar`], the reference the tests
//! compare the four-lane path against.

use glam::Vec3;

#[cfg(doc)]
use crate::bvh::Simd;
use crate::geometry::{intersect_sphere, Ray, TriangleHit, WatertightRay};

pub const SPHERE: u32 = 1 << 31;
pub const FILTERED: u32 = 1 << 30;
pub const ID_MASK: u32 = FILTERED - 1;

/// Up to four primitives. `v[vertex][axis][lane]`; a sphere lane holds its centre in
/// vertex 0 and its radius in vertex 1's x. `id[lane]` is the primitive index with the
/// flag bits; unused lanes have NaN vertices, which no test hits, and id 0. 160 bytes,
/// aligned so that each block spans three cache lines, not four.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub struct Block {
    v: [[[f32; 4]; 3]; 3],
    id: [u32; 4],
}

/// The nearest hit in a block: lane, and the triangle test's result.
pub struct LaneHit {
    pub id: u32,
    pub hit: TriangleHit,
}

impl Block {
    /// Packs up to four primitives given as (vertices, id with flags).
    pub fn new(prims: &[([Vec3; 3], u32)]) -> Block {
        debug_assert!(prims.len() <= 4);
        let mut b = Block {
            v: [[[f32::NAN; 4]; 3]; 3],
            id: [0; 4],
        };
        for (lane, (v, id)) in prims.iter().enumerate() {
            for (vertex, p) in v.iter().enumerate() {
                for axis in 0..3 {
                    b.v[vertex][axis][lane] = p[axis];
                }
            }
            b.id[lane] = *id;
        }
        b
    }

    fn vertex(&self, vertex: usize, lane: usize) -> Vec3 {
        let v = &self.v[vertex];
        Vec3::new(v[0][lane], v[1][lane], v[2][lane])
    }

    /// Whether every lane is an unfiltered triangle (the four-lane path).
    #[inline(always)]
    fn plain(&self) -> bool {
        (self.id[0] | self.id[1] | self.id[2] | self.id[3]) & (SPHERE | FILTERED) == 0
    }

    /// The nearest hit among the first `count` lanes within (0, t_max) that `filter`
    /// accepts (asked only for flagged triangles). Spheres report zero barycentrics.
    /// `SIMD` chooses the four-lane test for plain blocks (x86-64 only). With `ANY`, the
    /// first hit found is returned, not the nearest, and from the four-lane test without
    /// barycentrics (a shadow ray needs only whether).
    #[inline(always)]
    pub fn intersect<const SIMD: bool, const ANY: bool>(
        &self,
        ray: &Ray,
        wray: &WatertightRay,
        count: u32,
        t_max: f32,
        filter: &impl Fn(u32, &TriangleHit) -> bool,
    ) -> Option<LaneHit> {
        #[cfg(target_arch = "x86_64")]
        if SIMD && self.plain() {
            // SAFETY: SSE is part of the x86-64 baseline.
            return unsafe { self.intersect4_sse::<ANY>(wray, count, t_max) };
        }
        let mut best = None;
        let mut t_max = t_max;
        for lane in 0..count as usize {
            let id = self.id[lane];
            let hit = if id & SPHERE != 0 {
                intersect_sphere(ray, self.vertex(0, lane), self.v[1][0][lane], t_max).map(|t| {
                    TriangleHit {
                        t,
                        b1: 0.0,
                        b2: 0.0,
                    }
                })
            } else {
                let [p0, p1, p2] = [0, 1, 2].map(|k| self.vertex(k, lane));
                wray.intersect(p0, p1, p2, t_max)
                    .filter(|h| id & FILTERED == 0 || filter(id & ID_MASK, h))
            };
            if let Some(hit) = hit {
                t_max = hit.t;
                best = Some(LaneHit {
                    id: id & ID_MASK,
                    hit,
                });
                if ANY {
                    break;
                }
            }
        }
        best
    }

    /// [`WatertightRay::intersect`] on four lanes; the nearest hit, the lowest lane
    /// among equals (as a sequential loop that narrows `t_max` would find).
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    unsafe fn intersect4_sse<const ANY: bool>(
        &self,
        w: &WatertightRay,
        count: u32,
        t_max: f32,
    ) -> Option<LaneHit> {
        use std::arch::x86_64::*;
        let (kx, ky, kz) = (w.kx, w.ky, w.kz);
        let o = w.o.to_array();
        let (ox, oy, oz) = (_mm_set1_ps(o[kx]), _mm_set1_ps(o[ky]), _mm_set1_ps(o[kz]));
        let (sx, sy, sz) = (
            _mm_set1_ps(w.shear.x),
            _mm_set1_ps(w.shear.y),
            _mm_set1_ps(w.shear.z),
        );
        // Vertex relative to the origin, sheared: (x, y) and the unscaled z. (A macro:
        // closures here were left out of line, three calls a block.)
        macro_rules! rel {
            ($vertex:expr) => {{
                let ld = |axis: usize| _mm_load_ps(self.v[$vertex][axis].as_ptr());
                let z = _mm_sub_ps(ld(kz), oz);
                let x = _mm_sub_ps(_mm_sub_ps(ld(kx), ox), _mm_mul_ps(sx, z));
                let y = _mm_sub_ps(_mm_sub_ps(ld(ky), oy), _mm_mul_ps(sy, z));
                (x, y, z)
            }};
        }
        let (ax, ay, a_z) = rel!(0);
        let (bx, by, b_z) = rel!(1);
        let (cx, cy, c_z) = rel!(2);
        let u = _mm_sub_ps(_mm_mul_ps(cx, by), _mm_mul_ps(cy, bx));
        let v = _mm_sub_ps(_mm_mul_ps(ax, cy), _mm_mul_ps(ay, cx));
        let ww = _mm_sub_ps(_mm_mul_ps(bx, ay), _mm_mul_ps(by, ax));
        let zero = _mm_setzero_ps();
        let used = (1u32 << count) - 1;
        let on_edge = _mm_or_ps(
            _mm_or_ps(_mm_cmpeq_ps(u, zero), _mm_cmpeq_ps(v, zero)),
            _mm_cmpeq_ps(ww, zero),
        );
        let on_edge = _mm_movemask_ps(on_edge) as u32 & used;
        let any_neg = _mm_or_ps(
            _mm_or_ps(_mm_cmplt_ps(u, zero), _mm_cmplt_ps(v, zero)),
            _mm_cmplt_ps(ww, zero),
        );
        let any_pos = _mm_or_ps(
            _mm_or_ps(_mm_cmpgt_ps(u, zero), _mm_cmpgt_ps(v, zero)),
            _mm_cmpgt_ps(ww, zero),
        );
        let det = _mm_add_ps(_mm_add_ps(u, v), ww);
        let t_scaled = _mm_add_ps(
            _mm_add_ps(
                _mm_mul_ps(u, _mm_mul_ps(sz, a_z)),
                _mm_mul_ps(v, _mm_mul_ps(sz, b_z)),
            ),
            _mm_mul_ps(ww, _mm_mul_ps(sz, c_z)),
        );
        let t_max4 = _mm_set1_ps(t_max);
        let limit = _mm_mul_ps(t_max4, det);
        let bad_neg = _mm_and_ps(
            _mm_cmplt_ps(det, zero),
            _mm_or_ps(_mm_cmpge_ps(t_scaled, zero), _mm_cmplt_ps(t_scaled, limit)),
        );
        let bad_pos = _mm_and_ps(
            _mm_cmpgt_ps(det, zero),
            _mm_or_ps(_mm_cmple_ps(t_scaled, zero), _mm_cmpgt_ps(t_scaled, limit)),
        );
        let inv_det = _mm_div_ps(_mm_set1_ps(1.0), det);
        let t = _mm_mul_ps(t_scaled, inv_det);
        let rejected = _mm_or_ps(
            _mm_or_ps(_mm_and_ps(any_neg, any_pos), _mm_cmpeq_ps(det, zero)),
            _mm_or_ps(bad_neg, bad_pos),
        );
        let in_range = _mm_and_ps(_mm_cmpgt_ps(t, zero), _mm_cmplt_ps(t, t_max4));
        let ok = _mm_andnot_ps(rejected, in_range);
        let mask = _mm_movemask_ps(ok) as u32 & used & !on_edge;
        if mask == 0 && on_edge == 0 {
            return None;
        }
        let mut ts = [0.0f32; 4];
        _mm_storeu_ps(ts.as_mut_ptr(), t);
        if ANY && mask != 0 {
            // Some lane is hit; a shadow ray needs no more (nor the barycentrics).
            let lane = mask.trailing_zeros() as usize;
            return Some(LaneHit {
                id: self.id[lane] & ID_MASK,
                hit: TriangleHit {
                    t: ts[lane],
                    b1: 0.0,
                    b2: 0.0,
                },
            });
        }
        if on_edge == 0 {
            // The nearest lane without a loop: the minimum of the hit lanes' distances
            // (misses at +∞), then the lowest lane that has it.
            let tm = _mm_or_ps(
                _mm_and_ps(ok, t),
                _mm_andnot_ps(ok, _mm_set1_ps(f32::INFINITY)),
            );
            let m = _mm_min_ps(tm, _mm_shuffle_ps::<0b10_11_00_01>(tm, tm));
            let m = _mm_min_ps(m, _mm_shuffle_ps::<0b01_00_11_10>(m, m));
            let lane = (_mm_movemask_ps(_mm_cmpeq_ps(tm, m)) as u32 & mask).trailing_zeros();
            let lane = lane as usize;
            let mut vs = [0.0f32; 4];
            let mut ws = [0.0f32; 4];
            _mm_storeu_ps(vs.as_mut_ptr(), _mm_mul_ps(v, inv_det));
            _mm_storeu_ps(ws.as_mut_ptr(), _mm_mul_ps(ww, inv_det));
            return Some(LaneHit {
                id: self.id[lane] & ID_MASK,
                hit: TriangleHit {
                    t: ts[lane],
                    b1: vs[lane],
                    b2: ws[lane],
                },
            });
        }
        let mut best: Option<(usize, TriangleHit)> = None;
        let mut best_t = t_max;
        for (lane, &t_lane) in ts.iter().enumerate().take(count as usize) {
            let hit = if on_edge & (1 << lane) != 0 {
                let [p0, p1, p2] = [0, 1, 2].map(|k| self.vertex(k, lane));
                w.intersect(p0, p1, p2, best_t)
            } else if mask & (1 << lane) != 0 && t_lane < best_t {
                Some(TriangleHit {
                    t: t_lane,
                    b1: 0.0,
                    b2: 0.0,
                })
            } else {
                None
            };
            if let Some(h) = hit {
                best_t = h.t;
                best = Some((lane, h));
            }
        }
        let (lane, mut hit) = best?;
        if on_edge & (1 << lane) == 0 {
            let mut vs = [0.0f32; 4];
            let mut ws = [0.0f32; 4];
            _mm_storeu_ps(vs.as_mut_ptr(), _mm_mul_ps(v, inv_det));
            _mm_storeu_ps(ws.as_mut_ptr(), _mm_mul_ps(ww, inv_det));
            hit.b1 = vs[lane];
            hit.b2 = ws[lane];
        }
        Some(LaneHit {
            id: self.id[lane] & ID_MASK,
            hit,
        })
    }
}
