//! A leaf's primitives as one block of eight lanes, coordinates side by side
//! (structure of arrays), so that the watertight test runs on eight triangles at once:
//! one AVX2 register where the CPU has it, two SSE halves otherwise (the second skipped
//! when the block holds four or fewer, or when an any-hit query's first half hit).
//!
//! The vector test performs exactly the operations of [`WatertightRay::intersect`] in
//! the same order (Rust never fuses a multiply and an add on its own), so each lane's
//! distance and barycentrics are the same bits as the scalar test's (an edge function
//! that is exactly zero counts as inside in both, without a retry, so no lane leaves
//! the vector test). Sphere lanes take the vector sphere test ([`super::sphere`]) in the
//! same pass, with the same bits as the scalar one; a filtered-triangle lane takes the
//! scalar test inside the vector path (the block's triangles are still tested together),
//! and everything under [`Simd::Scalar`] goes lane by lane: the reference the tests
//! compare the vector paths against.

#[cfg(target_arch = "x86_64")]
mod rays8;

use glam::Vec3;

#[cfg(target_arch = "x86_64")]
use super::lanes::Wide;
#[cfg(target_arch = "x86_64")]
use super::sphere;
#[cfg(doc)]
use crate::bvh::Simd;
use crate::geometry::{intersect_sphere, Ray, TriangleHit, WatertightRay};

#[cfg(target_arch = "x86_64")]
pub(crate) use rays8::{Best8, Rays8};

pub const SPHERE: u32 = 1 << 31;
pub const FILTERED: u32 = 1 << 30;
pub const ID_MASK: u32 = FILTERED - 1;
// `Block::flag_lanes` reads the flags as the ids' two top bits.
const _: () = assert!(SPHERE == 1 << 31 && FILTERED == 1 << 30);

/// Primitives a block holds: what the build's leaves are sized for.
pub const LANES: usize = 8;

/// Which test [`Block::intersect`] runs on blocks of plain triangles.
pub const SCALAR: u8 = 0;
pub const SSE: u8 = 1;
pub const AVX2: u8 = 2;

/// Up to eight primitives. `v[vertex][axis][lane]`; a sphere lane holds its centre in
/// vertex 0 and its radius in vertex 1's x. `id[lane]` is the primitive index with the
/// flag bits; unused lanes have NaN vertices, which no test hits, and id 0. 320 bytes,
/// five cache lines (the ids in the last), each row of eight floats one aligned load.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct Block {
    v: [[[f32; LANES]; 3]; 3],
    id: [u32; LANES],
}

/// The nearest hit in a block: lane, and the triangle test's result.
pub struct LaneHit {
    pub id: u32,
    pub hit: TriangleHit,
}

/// The vector test's per-lane results, written only for registers that hit something
/// and read only in lanes that did.
#[cfg(target_arch = "x86_64")]
struct Lanes {
    t: [f32; LANES],
    b1: [f32; LANES],
    b2: [f32; LANES],
}

impl Block {
    /// Packs up to eight primitives given as (vertices, id with flags).
    #[cfg(test)]
    pub fn new(prims: &[([Vec3; 3], u32)]) -> Block {
        Block::gather(prims.iter().copied())
    }

    /// Packs the first eight (or fewer) primitives `prims` gives as (vertices, id with
    /// flags): how an indexed leaf becomes the block the inline layout holds.
    #[inline(always)]
    pub fn gather(prims: impl Iterator<Item = ([Vec3; 3], u32)>) -> Block {
        // NaN vertices in every lane to begin with (written here, not copied from a
        // constant: that was a `memcpy` call, 12 % of an any-hit query's instructions
        // on indexed leaves).
        let mut b = Block {
            v: [[[f32::NAN; LANES]; 3]; 3],
            id: [0; LANES],
        };
        for (lane, (v, id)) in (0..LANES).zip(prims) {
            for (vertex, p) in v.iter().enumerate() {
                b.v[vertex][0][lane] = p.x;
                b.v[vertex][1][lane] = p.y;
                b.v[vertex][2][lane] = p.z;
            }
            b.id[lane] = id;
        }
        b
    }

    fn vertex(&self, vertex: usize, lane: usize) -> Vec3 {
        let v = &self.v[vertex];
        Vec3::new(v[0][lane], v[1][lane], v[2][lane])
    }

    /// The sphere lanes among the first `count`: lane, centre and radius.
    pub fn spheres(&self, count: u32) -> impl Iterator<Item = (usize, Vec3, f32)> + '_ {
        (0..count as usize)
            .filter(|&lane| self.id[lane] & SPHERE != 0)
            .map(|lane| (lane, self.vertex(0, lane), self.v[1][0][lane]))
    }

    /// Whether every lane is an unfiltered triangle.
    pub fn is_plain(&self) -> bool {
        self.id.iter().all(|&id| id & (SPHERE | FILTERED) == 0)
    }

    /// Bits of the first `count` lanes that are spheres, and of those that are filtered
    /// triangles: the flag bits (31 and 30) of the ids read as sign bits, one `movmskps`
    /// each (SSE: two), not a loop over the lanes (callgrind: about 45 instructions a
    /// block test fewer on blocks that hold a sphere).
    ///
    /// # Safety
    /// The CPU must support `KERNEL` (SSE or AVX2).
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    unsafe fn flag_lanes<const KERNEL: u8>(&self, count: u32) -> (u32, u32) {
        use std::arch::x86_64::*;
        let used = (1u32 << count) - 1;
        let ids = self.id.as_ptr();
        let (spheres, filtered) = if KERNEL == AVX2 {
            let v = _mm256_loadu_si256(ids as *const __m256i);
            let sph = _mm256_movemask_ps(_mm256_castsi256_ps(v));
            let fil = _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_slli_epi32::<1>(v)));
            (sph as u32, fil as u32)
        } else {
            let (lo, hi) = (
                _mm_loadu_si128(ids as *const __m128i),
                _mm_loadu_si128(ids.add(4) as *const __m128i),
            );
            let bits = |v: __m128i| _mm_movemask_ps(_mm_castsi128_ps(v)) as u32;
            (
                bits(lo) | bits(hi) << 4,
                bits(_mm_slli_epi32::<1>(lo)) | bits(_mm_slli_epi32::<1>(hi)) << 4,
            )
        };
        (spheres & used, filtered & used)
    }

    /// The nearest hit among the first `count` lanes within (0, t_max) that `filter`
    /// accepts (asked only for flagged triangles). Spheres report zero barycentrics.
    /// `KERNEL` chooses the vector test for plain blocks ([`SSE`], [`AVX2`]: x86-64
    /// only, and the CPU must have it). With `ANY`, the first hit found is returned, not
    /// the nearest, and from the vector test without barycentrics (a shadow ray needs
    /// only whether). `PLAIN` vouches that the block holds only unfiltered triangles
    /// (the whole structure does), which skips the vector kernels' check.
    #[inline(always)]
    pub fn intersect<const KERNEL: u8, const ANY: bool, const PLAIN: bool>(
        &self,
        ray: &Ray,
        wray: &WatertightRay,
        count: u32,
        t_max: f32,
        filter: &impl Fn(u32, &TriangleHit) -> bool,
    ) -> Option<LaneHit> {
        self.intersect_culled::<KERNEL, ANY, PLAIN>(ray, wray, count, t_max, 0, filter)
    }

    /// [`Block::intersect`] without testing the sphere lanes `culled` (bit i for lane
    /// i): spheres the caller knows the ray misses within `t_max` (the one-node query's
    /// box test of their boxes, `super::small`). A sphere lane costs the vector sphere
    /// test whether one or eight are tested; where every sphere lane of a register is
    /// culled, the test is skipped.
    #[inline(always)]
    pub fn intersect_culled<const KERNEL: u8, const ANY: bool, const PLAIN: bool>(
        &self,
        ray: &Ray,
        wray: &WatertightRay,
        count: u32,
        t_max: f32,
        culled: u32,
        filter: &impl Fn(u32, &TriangleHit) -> bool,
    ) -> Option<LaneHit> {
        #[cfg(target_arch = "x86_64")]
        if KERNEL != SCALAR {
            // A filtered lane takes the scalar test within the vector one, so a mixed
            // block still tests its plain triangles together (a sphere among seven
            // triangles made the whole block scalar: +20 % time on a Cornell box with one);
            // sphere lanes take the vector sphere test alongside.
            // With `PLAIN`, a copy without the sphere test's branches (they cost the
            // Cornell box, which has no sphere, +3 % instructions a path: callgrind).
            // Otherwise one copy for every block: a second one for plain blocks, inlined
            // too, cost sphere scenes 1–3 % more than it saved.
            // SAFETY: SSE is part of the x86-64 baseline, and the caller vouches for AVX2.
            return unsafe {
                if PLAIN {
                    self.intersect_lanes::<KERNEL, ANY, false>(
                        ray, wray, count, t_max, 0, 0, 0, filter,
                    )
                } else {
                    let (spheres, filtered) = self.flag_lanes::<KERNEL>(count);
                    self.intersect_lanes::<KERNEL, ANY, true>(
                        ray,
                        wray,
                        count,
                        t_max,
                        spheres,
                        spheres & !culled,
                        filtered,
                        filter,
                    )
                }
            };
        }
        let mut best = None;
        let mut t_max = t_max;
        for lane in 0..count as usize {
            if culled & (1 << lane) != 0 {
                continue;
            }
            if let Some(hit) = self.lane_test(ray, wray, lane, t_max, filter) {
                t_max = hit.t;
                best = Some(LaneHit {
                    id: self.id[lane] & ID_MASK,
                    hit,
                });
                if ANY {
                    break;
                }
            }
        }
        best
    }

    /// The scalar test of one lane: a sphere, or a triangle that `filter` accepts where
    /// it is flagged.
    #[inline(always)]
    fn lane_test(
        &self,
        ray: &Ray,
        wray: &WatertightRay,
        lane: usize,
        t_max: f32,
        filter: &impl Fn(u32, &TriangleHit) -> bool,
    ) -> Option<TriangleHit> {
        let id = self.id[lane];
        if id & SPHERE != 0 {
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
        }
    }

    /// The vector test of a block: the nearest hit, the lowest lane among equals (as a
    /// sequential loop that narrows `t_max` would find). The `spheres` lanes are not
    /// triangles, and those of them in `live` take the vector sphere test; the `special`
    /// lanes (filtered triangles) take [`Block::lane_test`] in that loop instead.
    ///
    /// # Safety
    /// The CPU must support `KERNEL`.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    unsafe fn intersect_lanes<const KERNEL: u8, const ANY: bool, const MIXED: bool>(
        &self,
        ray: &Ray,
        w: &WatertightRay,
        count: u32,
        t_max: f32,
        spheres: u32,
        live: u32,
        special: u32,
        filter: &impl Fn(u32, &TriangleHit) -> bool,
    ) -> Option<LaneHit> {
        use std::arch::x86_64::{__m128, __m256};
        use std::mem::MaybeUninit;
        let used = (1u32 << count) - 1;
        let mut out = MaybeUninit::<Lanes>::uninit();
        let out = out.as_mut_ptr();
        let hit = if KERNEL == AVX2 {
            self.test_lanes::<__m256, ANY, MIXED>(ray, w, 0, used, spheres, live, t_max, out)
        } else {
            let h0 = self.test_lanes::<__m128, ANY, MIXED>(
                ray,
                w,
                0,
                used & 15,
                spheres,
                live,
                t_max,
                out,
            );
            // (A special lane's bit says nothing: only a triangle's hit ends a shadow ray.)
            if count <= 4 || (ANY && h0 & !special != 0) {
                h0
            } else {
                let h1 = self.test_lanes::<__m128, ANY, MIXED>(
                    ray,
                    w,
                    4,
                    used >> 4,
                    spheres,
                    live,
                    t_max,
                    out,
                );
                h0 | h1
            }
        };
        // What the vector test says of a special lane is not about its primitive.
        let hit = hit & !special;
        if hit | special == 0 {
            return None;
        }
        // SAFETY: `test_lanes` wrote `t` (and without `ANY`, `b1` and `b2`) in every
        // register that has a `hit` bit.
        let lane_of = |row: *const [f32; LANES], lane: usize| unsafe { (*row)[lane] };
        let t = |lane| lane_of(std::ptr::addr_of!((*out).t), lane);
        // Some lane is hit and a shadow ray needs no more (nor the barycentrics); or one
        // lane alone is hit and none needs the scalar test, so it is the nearest (its
        // distance is below `t_max`): the commonest case of a closest-hit query, 1.03 hit
        // lanes a hit block on the Cornell render, which the loop below would find with
        // its bookkeeping (callgrind, Cornell 128² 1 spp: 573.9 -> 569.5 instructions a
        // closest-hit query).
        let alone = hit & hit.wrapping_sub(1) == 0 && special == 0;
        if hit != 0 && (ANY || alone) {
            let lane = hit.trailing_zeros() as usize;
            let (b1, b2) = if ANY {
                (0.0, 0.0)
            } else {
                (
                    lane_of(std::ptr::addr_of!((*out).b1), lane),
                    lane_of(std::ptr::addr_of!((*out).b2), lane),
                )
            };
            return Some(LaneHit {
                id: self.id[lane] & ID_MASK,
                hit: TriangleHit { t: t(lane), b1, b2 },
            });
        }
        let mut best = None;
        let mut best_t = t_max;
        let mut todo = hit | special;
        while todo != 0 {
            let lane = todo.trailing_zeros() as usize;
            todo &= todo - 1;
            let found = if special & (1 << lane) != 0 {
                self.lane_test(ray, w, lane, best_t, filter)
            } else if t(lane) < best_t {
                Some(TriangleHit {
                    t: t(lane),
                    b1: lane_of(std::ptr::addr_of!((*out).b1), lane),
                    b2: lane_of(std::ptr::addr_of!((*out).b2), lane),
                })
            } else {
                None
            };
            if let Some(h) = found {
                best_t = h.t;
                best = Some(LaneHit {
                    id: self.id[lane] & ID_MASK,
                    hit: h,
                });
                if ANY {
                    break;
                }
            }
        }
        best
    }

    /// [`WatertightRay::intersect`] on the `V::LANES` lanes from `first` on (`used`: the
    /// filled ones, bit 0 = lane `first`) that `spheres` does not name (bits of the
    /// block's lanes), and [`intersect_sphere`] on those that `live` (a part of
    /// `spheres`) names: which are hit, as bits of the block's lanes. Where some lane is,
    /// the distances (and without `ANY` the barycentrics, zero for a sphere) go to `out`.
    ///
    /// # Safety
    /// The CPU must support `V`; `first + V::LANES <= LANES`.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    unsafe fn test_lanes<V: Wide, const ANY: bool, const MIXED: bool>(
        &self,
        ray: &Ray,
        w: &WatertightRay,
        first: usize,
        used: u32,
        spheres: u32,
        live: u32,
        t_max: f32,
        out: *mut Lanes,
    ) -> u32 {
        debug_assert!(first + V::LANES <= LANES);
        let row = |r: *mut [f32; LANES]| (r as *mut f32).add(first);
        let zero = V::splat(0.0);
        // The sphere lanes of this register, tested together; a block of triangles only
        // pays this branch.
        let sph = if MIXED { (spheres >> first) & used } else { 0 };
        let live = if MIXED { (live >> first) & used } else { 0 };
        let (sphere_hit, sphere_t) = if live != 0 {
            let at = |vertex: usize, axis: usize| self.v[vertex][axis].as_ptr().add(first);
            let (hit, t) = sphere::intersect_spheres::<V>(
                ray,
                [0, 1, 2].map(|k| at(0, k)),
                at(1, 0),
                t_max,
                live,
            );
            (hit.and(V::from_bits(live)), t)
        } else {
            (zero, zero)
        };
        let sphere_bits = sphere_hit.bits();
        let tris = used & !sph;
        if MIXED && tris == 0 {
            if sphere_bits == 0 {
                return 0;
            }
            sphere_t.store(row(std::ptr::addr_of_mut!((*out).t)));
            if !ANY {
                zero.store(row(std::ptr::addr_of_mut!((*out).b1)));
                zero.store(row(std::ptr::addr_of_mut!((*out).b2)));
            }
            return sphere_bits << first;
        }
        let (kx, ky, kz) = (w.kx, w.ky, w.kz);
        let (ox, oy, oz) = (V::splat(w.o_k.x), V::splat(w.o_k.y), V::splat(w.o_k.z));
        let (sx, sy, sz) = (
            V::splat(w.shear.x),
            V::splat(w.shear.y),
            V::splat(w.shear.z),
        );
        // Vertex relative to the origin, sheared: (x, y) and the unscaled z. (A macro,
        // not a closure: a closure would not be compiled for AVX2, nor its loads inline.)
        macro_rules! rel {
            ($vertex:expr) => {{
                // SAFETY: `WatertightRay::new` makes every axis index below 3.
                let row = |axis: usize| self.v[$vertex].get_unchecked(axis).as_ptr().add(first);
                let z = V::load(row(kz)).sub(oz);
                let x = V::load(row(kx)).sub(ox).sub(sx.mul(z));
                let y = V::load(row(ky)).sub(oy).sub(sy.mul(z));
                (x, y, z)
            }};
        }
        let (ax, ay, a_z) = rel!(0);
        let (bx, by, b_z) = rel!(1);
        let (cx, cy, c_z) = rel!(2);
        let u = cx.mul(by).sub(cy.mul(bx));
        let v = ax.mul(cy).sub(ay.mul(cx));
        let ww = bx.mul(ay).sub(by.mul(ax));
        // Unused lanes need no mask here: their NaN vertices give NaN edge functions and
        // distances, which no lane passes. Sphere lanes' are not about a triangle (masked
        // below). Some edge function negative and some positive: the scalar test's six
        // comparisons as the sign of the least and the greatest. (They differ only where
        // one is NaN, and there `det` and `t` are NaN too, which no lane passes.)
        let mixed_signs = u.min(v).min(ww).lt(zero).and(u.max(v).max(ww).gt(zero));
        let det = u.add(v).add(ww);
        let t_scaled = u
            .mul(sz.mul(a_z))
            .add(v.mul(sz.mul(b_z)))
            .add(ww.mul(sz.mul(c_z)));
        // The determinant's sign moved onto the distance (exact sign flips): a comparison
        // with zero and one with `t_max · |det|`, the scalar test's two pairs chosen by
        // `det`'s sign in fewer operations and with the same outcome (see there).
        let sign = det.and(V::splat(-0.0));
        let det_abs = det.xor(sign);
        let t_signed = t_scaled.xor(sign);
        let t_max_v = V::splat(t_max);
        let before = t_signed.gt(t_max_v.mul(det_abs)).andnot(t_signed.gt(zero));
        let passed = mixed_signs.andnot(before);
        if !ANY && passed.bits() & tris | sphere_bits == 0 {
            // Every lane is rejected before the division, as in the scalar test (for a
            // shadow ray, whose blocks are hit more often, the check costs more than it
            // saves: callgrind, any-hit instructions per ray on the room 468 -> 480).
            return 0;
        }
        let inv_det = V::splat(1.0).div(det);
        let t = t_scaled.mul(inv_det);
        let in_range = t.gt(zero).and(t.lt(t_max_v));
        let hit = passed.and(in_range).bits();
        let hit = if MIXED { hit & !sph | sphere_bits } else { hit };
        if hit == 0 {
            return 0;
        }
        let (t, b1, b2) = (t, v.mul(inv_det), ww.mul(inv_det));
        let (t, b1, b2) = if MIXED {
            (
                sphere_hit.select(sphere_t, t),
                sphere_hit.andnot(b1),
                sphere_hit.andnot(b2),
            )
        } else {
            (t, b1, b2)
        };
        t.store(row(std::ptr::addr_of_mut!((*out).t)));
        if !ANY {
            b1.store(row(std::ptr::addr_of_mut!((*out).b1)));
            b2.store(row(std::ptr::addr_of_mut!((*out).b2)));
        }
        hit << first
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::Simd;
    use crate::sampler::Pcg32;

    fn v3(rng: &mut Pcg32) -> Vec3 {
        Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32())
    }

    /// `Block::intersect` with the kernel `simd` names (which the CPU must have).
    fn trace<const ANY: bool>(
        simd: Simd,
        block: &Block,
        ray: &Ray,
        count: u32,
        t_max: f32,
        filter: &impl Fn(u32, &TriangleHit) -> bool,
    ) -> Option<(u32, [u32; 3])> {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2")]
        unsafe fn avx2<const ANY: bool>(
            block: &Block,
            ray: &Ray,
            count: u32,
            t_max: f32,
            filter: &impl Fn(u32, &TriangleHit) -> bool,
        ) -> Option<LaneHit> {
            block.intersect::<AVX2, ANY, false>(ray, &WatertightRay::new(ray), count, t_max, filter)
        }
        let w = WatertightRay::new(ray);
        let hit = match simd {
            Simd::Scalar => block.intersect::<SCALAR, ANY, false>(ray, &w, count, t_max, filter),
            Simd::Sse => block.intersect::<SSE, ANY, false>(ray, &w, count, t_max, filter),
            // SAFETY: the caller passes only kernels from `Simd::available`.
            #[cfg(target_arch = "x86_64")]
            Simd::Avx2 => unsafe { avx2::<ANY>(block, ray, count, t_max, filter) },
            #[cfg(not(target_arch = "x86_64"))]
            Simd::Avx2 => unreachable!(),
        };
        hit.map(|h| (h.id, [h.hit.t, h.hit.b1, h.hit.b2].map(f32::to_bits)))
    }

    /// The nearest hit of a plain loop over `intersect_sphere` and
    /// `WatertightRay::intersect` on `prims` (filtered triangles accepted where their lane
    /// is even), as (lane, bits of t, b1, b2); asserts that the scalar kernel finds it and
    /// that every kernel the CPU has finds the scalar kernel's bits (any-hit: whether).
    fn check_every_kernel(
        trial: u32,
        prims: &[([Vec3; 3], u32)],
        block: &Block,
        ray: &Ray,
        t_max: f32,
    ) -> Option<(u32, [u32; 3])> {
        let accept_even = |id: u32, _: &TriangleHit| id.is_multiple_of(2);
        let count = prims.len() as u32;
        let mut reference = None;
        let mut best = t_max;
        for (lane, (v, id)) in prims.iter().enumerate() {
            let hit = if id & SPHERE != 0 {
                intersect_sphere(ray, v[0], v[1].x, best).map(|t| TriangleHit {
                    t,
                    b1: 0.0,
                    b2: 0.0,
                })
            } else {
                WatertightRay::new(ray)
                    .intersect(v[0], v[1], v[2], best)
                    .filter(|h| id & FILTERED == 0 || accept_even(lane as u32, h))
            };
            if let Some(h) = hit {
                best = h.t;
                reference = Some((lane as u32, [h.t, h.b1, h.b2].map(f32::to_bits)));
            }
        }
        let scalar = trace::<false>(Simd::Scalar, block, ray, count, t_max, &accept_even);
        assert_eq!(
            scalar, reference,
            "trial {trial}: scalar kernel vs a plain loop"
        );
        for simd in Simd::available() {
            let nearest = trace::<false>(simd, block, ray, count, t_max, &accept_even);
            assert_eq!(nearest, scalar, "trial {trial}: {simd:?}, {count} lanes");
            let any = trace::<true>(simd, block, ray, count, t_max, &accept_even);
            assert_eq!(
                any.is_some(),
                scalar.is_some(),
                "trial {trial}: {simd:?} any-hit"
            );
        }
        scalar
    }

    /// Every fill from one lane to eight, plain blocks and blocks mixing spheres and
    /// filtered triangles in: each kernel the CPU has returns the scalar kernel's lane,
    /// distance and barycentrics bit for bit, and that is the nearest hit of a plain loop
    /// over `WatertightRay::intersect` (the lowest lane among equal distances). Rays aim
    /// at points inside the triangles, at their vertices (exactly zero edge functions,
    /// which count as inside) and along the axes.
    #[test]
    fn every_kernel_gives_the_scalar_bits_at_every_fill() {
        let mut rng = Pcg32::new(8, 8);
        let simds = Simd::available();
        let (mut hits, mut vertex_hits, mut mixed) = (0, 0, 0);
        for trial in 0..40000u32 {
            let count = 1 + trial % 8;
            let kind = |lane: u32| (trial / 8 + lane) % 11;
            let mut prims = Vec::new();
            // Vertices on a coarse grid half the time, so triangles share edges.
            let grid = |v: Vec3| {
                if trial % 2 == 0 {
                    (v * 4.0).floor() / 4.0
                } else {
                    v
                }
            };
            for lane in 0..count {
                let v = [0; 3].map(|_| grid(v3(&mut rng)));
                let flags = match kind(lane) {
                    0 if trial % 3 == 0 => SPHERE,
                    1 if trial % 3 == 0 => FILTERED,
                    _ => 0,
                };
                let v = if flags == SPHERE {
                    [
                        v[0],
                        Vec3::new(0.1 + 0.2 * rng.uniform_f32(), 0.0, 0.0),
                        Vec3::ZERO,
                    ]
                } else {
                    v
                };
                prims.push((v, lane | flags));
            }
            mixed += prims.iter().any(|p| p.1 & (SPHERE | FILTERED) != 0) as u32;
            let block = Block::new(&prims);
            let target = prims[rng.next_u32() as usize % count as usize].0;
            let o = v3(&mut rng) * 3.0 - 1.0;
            let at_vertex = trial % 4 == 0 && prims.iter().all(|p| p.1 & SPHERE == 0);
            let aim = if at_vertex {
                target[trial as usize / 4 % 3]
            } else {
                let (a, b) = (rng.uniform_f32(), rng.uniform_f32());
                let (a, b) = if a + b > 1.0 {
                    (1.0 - a, 1.0 - b)
                } else {
                    (a, b)
                };
                target[0] + (target[1] - target[0]) * a + (target[2] - target[0]) * b
            };
            let mut d = aim - o;
            if trial % 7 == 0 {
                d.x = 0.0;
            }
            let ray = Ray::new(o, d.normalize_or(Vec3::Y));
            let t_max = if trial % 5 == 0 {
                2.0 * rng.uniform_f32()
            } else {
                f32::INFINITY
            };

            let scalar = check_every_kernel(trial, &prims, &block, &ray, t_max);
            hits += scalar.is_some() as u32;
            vertex_hits += (at_vertex && scalar.is_some()) as u32;
        }
        // Thresholds: about half the rays aim inside a triangle and meet it unless
        // something nearer or `t_max` intervenes; a quarter aim at vertices.
        assert!(hits > 15000, "only {hits} hits");
        assert!(vertex_hits > 2000, "only {vertex_hits} hits at vertices");
        assert!(mixed > 3000, "only {mixed} mixed blocks");
        eprintln!(
            "kernels {simds:?}: {hits} hits, {vertex_hits} at vertices, {mixed} mixed blocks"
        );
    }

    /// Blocks mostly of spheres (some overlapping, some rays starting inside one, some
    /// grazing): each kernel the CPU has returns the scalar kernel's lane and distance bit
    /// for bit, and that is the nearest hit of a plain loop over `intersect_sphere` and
    /// `WatertightRay::intersect`. The vector sphere test must reproduce the scalar one's
    /// rounding in every lane, so the comparison is exact.
    #[test]
    fn sphere_lanes_give_the_scalar_bits() {
        let mut rng = Pcg32::new(35, 1);
        let simds = Simd::available();
        let (mut hits, mut sphere_hits, mut inside) = (0, 0, 0);
        for trial in 0..40000u32 {
            let count = 1 + trial % 8;
            let mut prims = Vec::new();
            for lane in 0..count {
                let kind = rng.next_u32() % 8;
                let v = [0; 3].map(|_| v3(&mut rng));
                let prim = if kind < 6 {
                    let radius = 0.02 + 0.3 * rng.uniform_f32();
                    (
                        [v[0], Vec3::new(radius, 0.0, 0.0), Vec3::ZERO],
                        lane | SPHERE,
                    )
                } else if kind == 6 {
                    (v, lane | FILTERED)
                } else {
                    (v, lane)
                };
                prims.push(prim);
            }
            let block = Block::new(&prims);
            let (target, id) = prims[rng.next_u32() as usize % count as usize];
            let centre = if id & SPHERE != 0 {
                target[0]
            } else {
                (target[0] + target[1] + target[2]) / 3.0
            };
            let radius = if id & SPHERE != 0 { target[1].x } else { 0.1 };
            // A quarter start inside the aimed-at sphere (the far root); the others aim
            // within 1.2 radii of its centre, so some graze or miss.
            let o = if trial % 4 == 0 {
                centre + (v3(&mut rng) - 0.5) * radius
            } else {
                v3(&mut rng) * 4.0 - 1.5
            };
            let aim = centre + (v3(&mut rng) * 2.0 - 1.0) * 1.2 * radius;
            let ray = Ray::new(o, (aim - o).normalize_or(Vec3::Y));
            let t_max = if trial % 5 == 0 {
                3.0 * rng.uniform_f32()
            } else {
                f32::INFINITY
            };
            let scalar = check_every_kernel(trial, &prims, &block, &ray, t_max);
            if let Some((lane, _)) = scalar {
                hits += 1;
                if prims[lane as usize].1 & SPHERE != 0 {
                    sphere_hits += 1;
                    inside += (trial % 4 == 0) as u32;
                }
            }
        }
        // Thresholds: three quarters of the lanes are spheres and most rays aim within
        // their radius, a quarter from inside (which always hit unless t_max cuts).
        assert!(
            sphere_hits > 15000,
            "only {sphere_hits} sphere hits of {hits}"
        );
        assert!(inside > 4000, "only {inside} hits from inside a sphere");
        eprintln!("kernels {simds:?}: {hits} hits, {sphere_hits} on spheres, {inside} from inside");
    }
}
