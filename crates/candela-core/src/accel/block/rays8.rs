//! One block against eight rays: each primitive of the block tested against eight rays
//! at once, one ray an AVX2 lane (the transpose of [`Block::intersect`], which tests
//! eight primitives against one ray). For coherent rays (a packet of camera rays).
//!
//! Each ray's answer is the single-ray block test's, bit for bit: the same operations of
//! [`WatertightRay::intersect`] in the same order, each lane on its own ray's constants
//! (the axis permutation picked per lane by `vpermilps`, which moves bits and rounds
//! nothing); the primitives in lane order, each hit taken only where it is nearer than
//! the ray's nearest so far (the lowest lane among equal distances); the distance range
//! of the vector test the ray's `t_max` on entering the block, as the single-ray vector
//! test has it. What the single-ray test hands to its scalar code goes to the same scalar
//! code here, ray by ray: filtered triangles ([`Block::lane_test`]). A sphere takes a vector test of its own
//! against the eight rays, the scalar [`intersect_sphere`]'s operations in each lane.

use std::arch::x86_64::*;

use super::{Block, FILTERED, ID_MASK, SPHERE};
#[cfg(doc)]
use crate::geometry::intersect_sphere;
use crate::geometry::{Ray, TriangleHit, WatertightRay};

/// Eight rays as [`Block::intersect_rays8`] reads them: the rays (for the scalar
/// tests of filtered triangles, which make their watertight constants again: the same bits) and, component
/// by component in lanes, their origins, directions and watertight constants.
pub(crate) struct Rays8<'a> {
    pub rays: &'a [Ray; 8],
    o: [[f32; 8]; 3],
    d: [[f32; 8]; 3],
    /// Each ray's `kx`, `ky`, `kz`: `vpermilps` indices into (x, y, z, _).
    k: [[i32; 8]; 3],
    o_k: [[f32; 8]; 3],
    shear: [[f32; 8]; 3],
}

impl<'a> Rays8<'a> {
    /// The eight rays in lanes, and which of them are finite (bits): the constants of
    /// [`WatertightRay::new`] made in lanes with its operations (the reciprocal of the
    /// direction's largest component, the same division; the rest selections and
    /// multiplies), so each lane holds the bits the single query's ray has.
    ///
    /// # Safety
    /// The CPU must support AVX2.
    #[inline]
    #[target_feature(enable = "avx2")]
    pub unsafe fn new(rays: &'a [Ray; 8]) -> (Rays8<'a>, u32) {
        const _: () = assert!(size_of::<Ray>() == 24);
        let base = rays.as_ptr() as *const f32;
        let stride = _mm256_setr_epi32(0, 6, 12, 18, 24, 30, 36, 42);
        let gather =
            |c: i32| _mm256_i32gather_ps::<4>(base, _mm256_add_epi32(stride, _mm256_set1_epi32(c)));
        let o = [gather(0), gather(1), gather(2)];
        let d = [gather(3), gather(4), gather(5)];
        // Finite where every component times zero is not NaN (as `bvh::finite`).
        let zero = _mm256_setzero_ps();
        let finite =
            o.iter()
                .chain(&d)
                .fold(_mm256_castsi256_ps(_mm256_set1_epi32(-1)), |m, &v| {
                    let z = _mm256_mul_ps(v, zero);
                    _mm256_and_ps(m, _mm256_cmp_ps::<_CMP_ORD_Q>(z, z))
                });
        let finite = _mm256_movemask_ps(finite) as u32;
        // `kz`: the axis of the largest |d| (the first of equals).
        let abs = |v| _mm256_andnot_ps(_mm256_set1_ps(-0.0), v);
        let a = d.map(abs);
        let y_wins = _mm256_cmp_ps::<_CMP_GT_OQ>(a[1], a[0]);
        let max = _mm256_blendv_ps(a[0], a[1], y_wins);
        let z_wins = _mm256_cmp_ps::<_CMP_GT_OQ>(a[2], max);
        let (one, two) = (_mm256_set1_epi32(1), _mm256_set1_epi32(2));
        let kz = _mm256_castps_si256(_mm256_blendv_ps(
            _mm256_castsi256_ps(_mm256_and_si256(_mm256_castps_si256(y_wins), one)),
            _mm256_castsi256_ps(two),
            z_wins,
        ));
        // Component `k` (0, 1 or 2 in each lane) of the rows `v`.
        let pick = |v: &[__m256; 3], k: __m256i| {
            let is0 = _mm256_castsi256_ps(_mm256_cmpeq_epi32(k, _mm256_setzero_si256()));
            let is1 = _mm256_castsi256_ps(_mm256_cmpeq_epi32(k, one));
            _mm256_blendv_ps(_mm256_blendv_ps(v[2], v[1], is1), v[0], is0)
        };
        let dz = pick(&d, kz);
        // `AXES`: the next two axes cyclically, swapped where d[kz] < 0.
        let next = |k: __m256i| {
            let k1 = _mm256_add_epi32(k, one);
            _mm256_andnot_si256(_mm256_cmpeq_epi32(k1, _mm256_set1_epi32(3)), k1)
        };
        let (k1, k2) = (next(kz), next(next(kz)));
        let neg = _mm256_castps_si256(_mm256_cmp_ps::<_CMP_LT_OQ>(dz, zero));
        let kx = _mm256_blendv_epi8(k1, k2, neg);
        let ky = _mm256_blendv_epi8(k2, k1, neg);
        let inv = d.map(|v| _mm256_div_ps(_mm256_set1_ps(1.0), v));
        let sz = pick(&inv, kz);
        let mut r = Rays8 {
            rays,
            o: [[0.0; 8]; 3],
            d: [[0.0; 8]; 3],
            k: [[0; 8]; 3],
            o_k: [[0.0; 8]; 3],
            shear: [[0.0; 8]; 3],
        };
        let store = |row: &mut [f32; 8], v| _mm256_storeu_ps(row.as_mut_ptr(), v);
        let storei =
            |row: &mut [i32; 8], v| _mm256_storeu_si256(row.as_mut_ptr() as *mut __m256i, v);
        for axis in 0..3 {
            store(&mut r.o[axis], o[axis]);
            store(&mut r.d[axis], d[axis]);
        }
        storei(&mut r.k[0], kx);
        storei(&mut r.k[1], ky);
        storei(&mut r.k[2], kz);
        store(&mut r.o_k[0], pick(&o, kx));
        store(&mut r.o_k[1], pick(&o, ky));
        store(&mut r.o_k[2], pick(&o, kz));
        store(&mut r.shear[0], _mm256_mul_ps(pick(&d, kx), sz));
        store(&mut r.shear[1], _mm256_mul_ps(pick(&d, ky), sz));
        store(&mut r.shear[2], sz);
        (r, finite)
    }
}

/// The nearest hit so far of each of eight rays: its distance (the ray's `t_max` where
/// none), barycentrics and primitive id (flags cleared), and which rays have one.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Best8 {
    pub t: [f32; 8],
    pub b1: [f32; 8],
    pub b2: [f32; 8],
    pub id: [u32; 8],
    pub found: u32,
}

impl Best8 {
    /// No hit yet, each ray within (0, `t_max[i]`).
    pub fn new(t_max: [f32; 8]) -> Best8 {
        Best8 {
            t: t_max,
            b1: [0.0; 8],
            b2: [0.0; 8],
            id: [0; 8],
            found: 0,
        }
    }

    /// Takes `hit` on primitive `id` as ray `ray`'s nearest.
    #[inline(always)]
    fn take(&mut self, ray: usize, id: u32, hit: &TriangleHit) {
        self.t[ray] = hit.t;
        self.b1[ray] = hit.b1;
        self.b2[ray] = hit.b2;
        self.id[ray] = id;
        self.found |= 1 << ray;
    }
}

/// The bits of `mask`, lowest first.
#[inline(always)]
fn bits(mut mask: u32) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (mask != 0).then(|| {
            let i = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            i
        })
    })
}

impl Block {
    /// The first `count` primitives against the rays `group` names (bits of `rays`),
    /// each ray's nearest hit so far in `best`, which is narrowed to the block's: what
    /// [`Block::intersect`] (closest hit) with the ray's `t_max` = `best.t` finds, for
    /// every ray of `group`, bit for bit. `filter(ray, id, hit)` is asked for filtered
    /// triangles. `PLAIN` vouches that the block holds only unfiltered triangles.
    ///
    /// With `ANY`, any hit: a ray of `group` is marked in `best.found` where
    /// [`Block::intersect`] with `ANY` finds a hit within its `t_max` = `best.t` (the same
    /// test of each primitive), and is tested no further; `best`'s distances,
    /// barycentrics and ids are then not meaningful. The block is left once every ray of
    /// `group` is blocked.
    ///
    /// # Safety
    /// The CPU must support AVX2.
    #[inline]
    #[target_feature(enable = "avx2,bmi1,bmi2,lzcnt")]
    pub(crate) unsafe fn intersect_rays8<const PLAIN: bool, const ANY: bool>(
        &self,
        rays: &Rays8<'_>,
        group: u32,
        count: u32,
        best: &mut Best8,
        filter: &impl Fn(usize, u32, &TriangleHit) -> bool,
    ) {
        let load = |row: &[f32; 8]| _mm256_loadu_ps(row.as_ptr());
        let loadi = |row: &[i32; 8]| _mm256_loadu_si256(row.as_ptr() as *const __m256i);
        let (kx, ky, kz) = (loadi(&rays.k[0]), loadi(&rays.k[1]), loadi(&rays.k[2]));
        let (ox, oy, oz) = (load(&rays.o_k[0]), load(&rays.o_k[1]), load(&rays.o_k[2]));
        let (sx, sy, sz) = (
            load(&rays.shear[0]),
            load(&rays.shear[1]),
            load(&rays.shear[2]),
        );
        let lane_bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
        let lanes_of = |rays: u32| {
            _mm256_castsi256_ps(_mm256_cmpeq_epi32(
                _mm256_and_si256(_mm256_set1_epi32(rays as i32), lane_bit),
                lane_bit,
            ))
        };
        let mut in_group = lanes_of(group);
        let zero = _mm256_setzero_ps();
        // The distance range of the single-ray vector test: the ray's `t_max` on entering
        // the block.
        let t_max = load(&best.t);
        let mut bt = t_max;
        let mut bb1 = load(&best.b1);
        let mut bb2 = load(&best.b2);
        let mut bid = load(&*(best.id.as_ptr() as *const [f32; 8]));
        let mut found = best.found;
        // Spills the nearest hits for the scalar code of one primitive, and reloads them.
        macro_rules! spilled {
            ($body:block) => {{
                _mm256_storeu_ps(best.t.as_mut_ptr(), bt);
                _mm256_storeu_ps(best.b1.as_mut_ptr(), bb1);
                _mm256_storeu_ps(best.b2.as_mut_ptr(), bb2);
                _mm256_storeu_ps(best.id.as_mut_ptr() as *mut f32, bid);
                best.found = found;
                $body
                bt = load(&best.t);
                bb1 = load(&best.b1);
                bb2 = load(&best.b2);
                bid = load(&*(best.id.as_ptr() as *const [f32; 8]));
                found = best.found;
            }};
        }
        for lane in 0..count as usize {
            // A shadow ray needs one hit: the rays blocked so far are tested no further.
            if ANY && lane > 0 {
                let open = group & !found;
                if open == 0 {
                    break;
                }
                in_group = lanes_of(open);
            }
            let id = self.id[lane];
            if !PLAIN && id & SPHERE != 0 {
                let centre = [0, 1, 2].map(|axis| self.v[0][axis][lane]);
                let (hit, t) = sphere_rays8(rays, centre, self.v[1][0][lane], t_max);
                let take = _mm256_and_ps(
                    _mm256_and_ps(hit, in_group),
                    _mm256_cmp_ps::<_CMP_LT_OQ>(t, bt),
                );
                let taken = _mm256_movemask_ps(take) as u32;
                if taken != 0 {
                    bt = _mm256_blendv_ps(bt, t, take);
                    bb1 = _mm256_andnot_ps(take, bb1);
                    bb2 = _mm256_andnot_ps(take, bb2);
                    let idv = _mm256_castsi256_ps(_mm256_set1_epi32((id & ID_MASK) as i32));
                    bid = _mm256_blendv_ps(bid, idv, take);
                    found |= taken;
                }
                continue;
            }
            if !PLAIN && id & FILTERED != 0 {
                spilled!({
                    for r in bits(if ANY { group & !found } else { group }) {
                        let accept = |i: u32, h: &TriangleHit| filter(r, i, h);
                        let (ray, w) = (&rays.rays[r], WatertightRay::new(&rays.rays[r]));
                        let hit = self.lane_test(ray, &w, lane, best.t[r], &accept);
                        if let Some(h) = hit {
                            best.take(r, id & ID_MASK, &h);
                        }
                    }
                });
                continue;
            }
            // Vertex `k` as (x, y, z, 0) in each half; each lane picks its ray's axes.
            // (Where the rays share their axes, broadcasting the components instead
            // measured no fewer instructions: callgrind, spot-point-room depth 1.)
            macro_rules! rel {
                ($k:expr) => {{
                    let v = &self.v[$k];
                    let p = _mm256_setr_ps(
                        v[0][lane], v[1][lane], v[2][lane], 0.0, v[0][lane], v[1][lane],
                        v[2][lane], 0.0,
                    );
                    let z = _mm256_sub_ps(_mm256_permutevar_ps(p, kz), oz);
                    let x = _mm256_sub_ps(
                        _mm256_sub_ps(_mm256_permutevar_ps(p, kx), ox),
                        _mm256_mul_ps(sx, z),
                    );
                    let y = _mm256_sub_ps(
                        _mm256_sub_ps(_mm256_permutevar_ps(p, ky), oy),
                        _mm256_mul_ps(sy, z),
                    );
                    (x, y, z)
                }};
            }
            let (ax, ay, a_z) = rel!(0);
            let (bx, by, b_z) = rel!(1);
            let (cx, cy, c_z) = rel!(2);
            let u = _mm256_sub_ps(_mm256_mul_ps(cx, by), _mm256_mul_ps(cy, bx));
            let v = _mm256_sub_ps(_mm256_mul_ps(ax, cy), _mm256_mul_ps(ay, cx));
            let ww = _mm256_sub_ps(_mm256_mul_ps(bx, ay), _mm256_mul_ps(by, ax));
            let mixed_signs = _mm256_and_ps(
                _mm256_cmp_ps::<_CMP_LT_OQ>(_mm256_min_ps(_mm256_min_ps(u, v), ww), zero),
                _mm256_cmp_ps::<_CMP_GT_OQ>(_mm256_max_ps(_mm256_max_ps(u, v), ww), zero),
            );
            let det = _mm256_add_ps(_mm256_add_ps(u, v), ww);
            let t_scaled = _mm256_add_ps(
                _mm256_add_ps(
                    _mm256_mul_ps(u, _mm256_mul_ps(sz, a_z)),
                    _mm256_mul_ps(v, _mm256_mul_ps(sz, b_z)),
                ),
                _mm256_mul_ps(ww, _mm256_mul_ps(sz, c_z)),
            );
            let sign = _mm256_and_ps(det, _mm256_set1_ps(-0.0));
            let det_abs = _mm256_xor_ps(det, sign);
            let t_signed = _mm256_xor_ps(t_scaled, sign);
            let before = _mm256_andnot_ps(
                _mm256_cmp_ps::<_CMP_GT_OQ>(t_signed, _mm256_mul_ps(t_max, det_abs)),
                _mm256_cmp_ps::<_CMP_GT_OQ>(t_signed, zero),
            );
            let open = _mm256_andnot_ps(mixed_signs, _mm256_and_ps(before, in_group));
            if _mm256_movemask_ps(open) != 0 {
                // Some ray of the group passes the tests before the division.
                let inv_det = _mm256_div_ps(_mm256_set1_ps(1.0), det);
                let t = _mm256_mul_ps(t_scaled, inv_det);
                let in_range = _mm256_and_ps(
                    _mm256_cmp_ps::<_CMP_GT_OQ>(t, zero),
                    _mm256_cmp_ps::<_CMP_LT_OQ>(t, t_max),
                );
                let take = _mm256_and_ps(
                    _mm256_and_ps(open, in_range),
                    _mm256_cmp_ps::<_CMP_LT_OQ>(t, bt),
                );
                let taken = _mm256_movemask_ps(take) as u32;
                if taken != 0 {
                    if !ANY {
                        bt = _mm256_blendv_ps(bt, t, take);
                        bb1 = _mm256_blendv_ps(bb1, _mm256_mul_ps(v, inv_det), take);
                        bb2 = _mm256_blendv_ps(bb2, _mm256_mul_ps(ww, inv_det), take);
                        let idv = _mm256_castsi256_ps(_mm256_set1_epi32((id & ID_MASK) as i32));
                        bid = _mm256_blendv_ps(bid, idv, take);
                    }
                    found |= taken;
                }
            }
        }
        _mm256_storeu_ps(best.t.as_mut_ptr(), bt);
        _mm256_storeu_ps(best.b1.as_mut_ptr(), bb1);
        _mm256_storeu_ps(best.b2.as_mut_ptr(), bb2);
        _mm256_storeu_ps(best.id.as_mut_ptr() as *mut f32, bid);
        best.found = found;
    }
}

/// [`intersect_sphere`] of one sphere (`centre`, `radius`) on the eight rays, each
/// lane the scalar test's operations in its order (as [`super::super::sphere`] does for
/// eight spheres and one ray): the lanes hit within (ε, `t_max`) as all-ones lanes, and
/// there the distance, the nearer root where it is in range, else the farther one.
///
/// # Safety
/// The CPU must support AVX2.
#[inline]
#[target_feature(enable = "avx2")]
unsafe fn sphere_rays8(
    rays: &Rays8<'_>,
    centre: [f32; 3],
    radius: f32,
    t_max: __m256,
) -> (__m256, __m256) {
    let load = |row: &[f32; 8]| _mm256_loadu_ps(row.as_ptr());
    let (mul, add, sub) = (_mm256_mul_ps, _mm256_add_ps, _mm256_sub_ps);
    let (dx, dy, dz) = (load(&rays.d[0]), load(&rays.d[1]), load(&rays.d[2]));
    // `ray.o - center`, and the dot products as glam sums them (x·x + y·y + z·z).
    let ox = sub(load(&rays.o[0]), _mm256_set1_ps(centre[0]));
    let oy = sub(load(&rays.o[1]), _mm256_set1_ps(centre[1]));
    let oz = sub(load(&rays.o[2]), _mm256_set1_ps(centre[2]));
    let a = add(add(mul(dx, dx), mul(dy, dy)), mul(dz, dz));
    let b = mul(
        _mm256_set1_ps(2.0),
        add(add(mul(dx, ox), mul(dy, oy)), mul(dz, oz)),
    );
    let r = _mm256_set1_ps(radius);
    let c = sub(add(add(mul(ox, ox), mul(oy, oy)), mul(oz, oz)), mul(r, r));
    let s = _mm256_div_ps(b, mul(_mm256_set1_ps(2.0), a));
    let vx = sub(ox, mul(s, dx));
    let vy = sub(oy, mul(s, dy));
    let vz = sub(oz, mul(s, dz));
    let len = _mm256_sqrt_ps(add(add(mul(vx, vx), mul(vy, vy)), mul(vz, vz)));
    let discrim = mul(mul(mul(_mm256_set1_ps(4.0), a), add(r, len)), sub(r, len));
    let zero = _mm256_setzero_ps();
    if _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_GE_OQ>(discrim, zero)) == 0 {
        return (zero, zero);
    }
    // A negative discriminant's root is NaN, and so are both distances, which no
    // comparison below passes: the scalar test's early `None`.
    let root = _mm256_sqrt_ps(discrim);
    let half = _mm256_set1_ps(-0.5);
    let q = _mm256_blendv_ps(
        mul(half, add(b, root)),
        mul(half, sub(b, root)),
        _mm256_cmp_ps::<_CMP_LT_OQ>(b, zero),
    );
    let t0 = _mm256_div_ps(q, a);
    let t1 = _mm256_div_ps(c, q);
    let swap = _mm256_cmp_ps::<_CMP_GT_OQ>(t0, t1);
    let (near, far) = (
        _mm256_blendv_ps(t0, t1, swap),
        _mm256_blendv_ps(t1, t0, swap),
    );
    let eps = mul(_mm256_set1_ps(1e-4), r);
    let in_range = |t| {
        _mm256_and_ps(
            _mm256_cmp_ps::<_CMP_GT_OQ>(t, eps),
            _mm256_cmp_ps::<_CMP_LT_OQ>(t, t_max),
        )
    };
    let (near_ok, far_ok) = (in_range(near), in_range(far));
    (
        _mm256_or_ps(near_ok, far_ok),
        _mm256_blendv_ps(far, near, near_ok),
    )
}
