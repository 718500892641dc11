//! Eight rays at a time through the eight-wide BVH (AVX2): the packet rung of issue #35,
//! kept as a measured kernel, not used by the renderer.
//!
//! Each ray sits in a lane; at a node, each child box is broadcast and tested against the
//! eight rays at once (the slab test of [`super::box8`], lane for lane the same operations
//! and so the same bits as the single-ray test), and a subtree is entered with the mask
//! of the rays that reach it (Wald, Slusallek, Benthin and Wagner 2001; Embree's packet
//! and hybrid modes). Where a subtree is reached by `single_below` rays or fewer, each
//! finishes it alone with the single-ray traversal (Benthin, Wald, Woop, Ernst and Mark
//! 2012, "Combining Single and Packet-Ray Tracing"): on incoherent rays few lanes stay
//! together below the root's levels.
//!
//! The `traversal` benchmark measures it against eight single-ray queries on the same
//! rays (`bench/README.md`, "Packets of eight rays"): on incoherent bounce and shadow rays
//! it costs more instructions than single rays, which is why the renderer traces single
//! rays; on coherent primary rays (4 × 2 pixel tiles) it saves about 10 %.

#![cfg(target_arch = "x86_64")]

use std::arch::x86_64::*;
use std::mem::MaybeUninit;

use super::box8::{Avx2Boxes, BoxTest, Ray8, T_MAX_SCALE};
use super::wide::{Node8, WideBvh};

/// How a packet finds the children of a node its rays enter: for each child slot in use,
/// which lanes enter it, and (with `KEYS`) the least entry distance among them.
pub trait PacketTest {
    /// Bit `i` when ray `i` is finite (the others find nothing, as single rays).
    fn finite(&self) -> u32;

    /// # Safety
    /// The CPU must have AVX2.
    unsafe fn children<const KEYS: bool>(
        &self,
        node: &Node8,
        reach: u32,
        t_box: &[f32; 8],
    ) -> Children;
}

/// What [`PacketTest::children`] finds: the child slots some lane enters, the lanes of
/// each, and the least entry distance of those lanes (with `KEYS`).
pub struct Children {
    pub slots: u32,
    pub lanes: [u32; 8],
    pub key: [f32; 8],
}

/// Each child box broadcast and tested against the eight rays, one a lane.
#[derive(Clone, Copy)]
pub struct BoxAgainstRays {
    o: [__m256; 3],
    inv: [__m256; 3],
    inv_far: [__m256; 3],
    /// All ones in lanes whose direction is negative on the axis (near plane = max).
    neg: [__m256; 3],
    finite: u32,
}

impl BoxAgainstRays {
    /// # Safety
    /// The CPU must have AVX2.
    #[inline]
    #[target_feature(enable = "avx2")]
    pub unsafe fn new(rays: &[Ray8; 8]) -> BoxAgainstRays {
        let lanes = |f: &dyn Fn(&Ray8) -> f32| -> __m256 {
            let v: [f32; 8] = std::array::from_fn(|i| f(&rays[i]));
            _mm256_loadu_ps(v.as_ptr())
        };
        let o = [lanes(&|r| r.o.x), lanes(&|r| r.o.y), lanes(&|r| r.o.z)];
        let inv = [
            lanes(&|r| r.inv_d.x),
            lanes(&|r| r.inv_d.y),
            lanes(&|r| r.inv_d.z),
        ];
        let inv_far = [
            lanes(&|r| r.inv_far.x),
            lanes(&|r| r.inv_far.y),
            lanes(&|r| r.inv_far.z),
        ];
        // `Ray8::near` picks the odd (max) row where `inv_d < 0`: the same choice.
        let neg = inv.map(|i| _mm256_cmp_ps::<_CMP_LT_OQ>(i, _mm256_setzero_ps()));
        BoxAgainstRays {
            o,
            inv,
            inv_far,
            neg,
            finite: finite_lanes(rays),
        }
    }

    /// Child `c` of `node` against the eight rays: which lanes enter it within
    /// (0, `t_far`) and where. Lane for lane the operations of the single-ray kernels.
    ///
    /// # Safety
    /// The CPU must have AVX2; `c < 8`.
    #[inline]
    #[target_feature(enable = "avx2")]
    unsafe fn hit(&self, node: &Node8, c: usize, t_far: __m256) -> (u32, __m256) {
        let mut t_near = _mm256_setzero_ps();
        let mut t_far = t_far;
        for axis in 0..3 {
            let lo = _mm256_broadcast_ss(node.planes.get_unchecked(2 * axis).get_unchecked(c));
            let hi = _mm256_broadcast_ss(node.planes.get_unchecked(2 * axis + 1).get_unchecked(c));
            let near = _mm256_blendv_ps(lo, hi, self.neg[axis]);
            let far = _mm256_blendv_ps(hi, lo, self.neg[axis]);
            t_near = _mm256_max_ps(
                _mm256_mul_ps(_mm256_sub_ps(near, self.o[axis]), self.inv[axis]),
                t_near,
            );
            t_far = _mm256_min_ps(
                _mm256_mul_ps(_mm256_sub_ps(far, self.o[axis]), self.inv_far[axis]),
                t_far,
            );
        }
        let mask = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(t_near, t_far)) as u32;
        (mask, t_near)
    }
}

impl PacketTest for BoxAgainstRays {
    fn finite(&self) -> u32 {
        self.finite
    }

    #[inline]
    #[target_feature(enable = "avx2")]
    unsafe fn children<const KEYS: bool>(
        &self,
        node: &Node8,
        reach: u32,
        t_box: &[f32; 8],
    ) -> Children {
        let far = _mm256_loadu_ps(t_box.as_ptr());
        let mut out = Children {
            slots: 0,
            lanes: [0; 8],
            key: [0.0; 8],
        };
        let mut slots = used(node);
        while slots != 0 {
            let c = slots.trailing_zeros() as usize;
            slots &= slots - 1;
            let (hit, t) = self.hit(node, c, far);
            let hit = hit & reach;
            if hit != 0 {
                out.slots |= 1 << c;
                out.lanes[c] = hit;
                if KEYS {
                    let mut v = [0.0f32; 8];
                    _mm256_storeu_ps(v.as_mut_ptr(), t);
                    out.key[c] = min_lanes(&v, hit);
                }
            }
        }
        out
    }
}

/// Each ray's single-ray test of the node's eight boxes (as [`Avx2Boxes::hit8`]), the
/// eight masks then transposed to lanes a child.
pub struct RaysAgainstBoxes {
    rays: [<Avx2Boxes as BoxTest>::Prepared; 8],
    finite: u32,
}

impl RaysAgainstBoxes {
    /// # Safety
    /// The CPU must have AVX2.
    #[inline]
    #[target_feature(enable = "avx2")]
    pub unsafe fn new(rays: &[Ray8; 8]) -> RaysAgainstBoxes {
        RaysAgainstBoxes {
            rays: std::array::from_fn(|i| Avx2Boxes::prepare(&rays[i])),
            finite: finite_lanes(rays),
        }
    }
}

impl PacketTest for RaysAgainstBoxes {
    fn finite(&self) -> u32 {
        self.finite
    }

    #[inline]
    #[target_feature(enable = "avx2")]
    unsafe fn children<const KEYS: bool>(
        &self,
        node: &Node8,
        reach: u32,
        t_box: &[f32; 8],
    ) -> Children {
        let mut rows = 0u64;
        let mut t = [[0.0f32; 8]; 8];
        let mut todo = reach;
        while todo != 0 {
            let lane = todo.trailing_zeros() as usize;
            todo &= todo - 1;
            let (mask, t_near) = Avx2Boxes::hit8(&self.rays[lane], &node.planes, t_box[lane]);
            rows |= (mask as u64) << (8 * lane);
            if KEYS {
                t[lane] = t_near;
            }
        }
        let columns = transpose8x8(rows);
        let mut out = Children {
            slots: 0,
            lanes: [0; 8],
            key: [0.0; 8],
        };
        // Bit c of `slots` where byte c of `columns` is not zero.
        let mut nonzero = columns;
        nonzero |= nonzero >> 4;
        nonzero |= nonzero >> 2;
        nonzero |= nonzero >> 1;
        out.slots = _pext_u64(nonzero, 0x0101_0101_0101_0101) as u32;
        let mut slots = out.slots;
        while slots != 0 {
            let c = slots.trailing_zeros() as usize;
            slots &= slots - 1;
            let lanes = (columns >> (8 * c)) as u32 & 0xff;
            out.lanes[c] = lanes;
            if KEYS {
                let mut key = f32::INFINITY;
                let mut l = lanes;
                while l != 0 {
                    let lane = l.trailing_zeros() as usize;
                    l &= l - 1;
                    key = key.min(t[lane][c]);
                }
                out.key[c] = key;
            }
        }
        out
    }
}

/// The 8 × 8 bit matrix `x` (row r in byte r, column c in bit c) transposed (Hacker's
/// Delight, 7-3): byte c then holds column c.
#[inline(always)]
fn transpose8x8(mut x: u64) -> u64 {
    let t = (x ^ (x >> 7)) & 0x00AA_00AA_00AA_00AA;
    x ^= t ^ (t << 7);
    let t = (x ^ (x >> 14)) & 0x0000_CCCC_0000_CCCC;
    x ^= t ^ (t << 14);
    let t = (x ^ (x >> 28)) & 0x0000_0000_F0F0_F0F0;
    x ^ t ^ (t << 28)
}

fn finite_lanes(rays: &[Ray8; 8]) -> u32 {
    (0..8).fold(0, |m, i| m | (rays[i].finite as u32) << i)
}

/// The child slots of `node` in use (an unused one's link is `u32::MAX`).
#[inline]
#[target_feature(enable = "avx2")]
unsafe fn used(node: &Node8) -> u32 {
    let links = _mm256_loadu_si256(node.child.as_ptr() as *const __m256i);
    !(_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(
        links,
        _mm256_set1_epi32(-1),
    ))) as u32)
        & 0xff
}

/// The least of `t`'s lanes in `lanes`.
#[inline(always)]
fn min_lanes(t: &[f32; 8], mut lanes: u32) -> f32 {
    let mut best = f32::INFINITY;
    while lanes != 0 {
        let lane = lanes.trailing_zeros() as usize;
        lanes &= lanes - 1;
        best = best.min(t[lane]);
    }
    best
}

/// Pending subtrees a packet traversal holds (as [`super::wide`]'s single-ray stack).
const STACK: usize = 7 * 84;

/// A subtree waiting with the lanes that reach it and the least entry distance of them.
#[derive(Clone, Copy)]
struct Pending {
    child: u32,
    count: u32,
    lanes: u32,
    t: f32,
}

impl WideBvh<Node8> {
    /// Any-hit for the rays of `packet` in `lanes`: bit `i` set when ray `i` is blocked.
    /// `leaf(lane, first, count)` tests a leaf for one ray (true stops that ray);
    /// `single(lane, node)` finishes the subtree under `node` for one ray alone, and is
    /// called where `single_below` lanes or fewer reach a node. `t_max` is per lane.
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[inline(always)]
    pub unsafe fn occluded8<P: PacketTest>(
        &self,
        packet: &P,
        t_max: &[f32; 8],
        lanes: u32,
        single_below: u32,
        mut leaf: impl FnMut(usize, u32, u32) -> bool,
        mut single: impl FnMut(usize, u32) -> bool,
    ) -> u32 {
        let mut alive = lanes & packet.finite();
        if self.nodes.is_empty() || alive == 0 {
            return 0;
        }
        let t_box = t_max.map(|t| t * T_MAX_SCALE);
        let mut blocked = 0;
        let mut stack = [const { MaybeUninit::<(u32, u32)>::uninit() }; STACK];
        let mut sp = 0;
        let (mut current, mut reach) = (0u32, alive);
        'nodes: loop {
            if reach.count_ones() <= single_below {
                let mut todo = reach;
                while todo != 0 {
                    let lane = todo.trailing_zeros() as usize;
                    todo &= todo - 1;
                    if single(lane, current) {
                        blocked |= 1 << lane;
                        alive &= !(1 << lane);
                    }
                }
            } else {
                let node = &self.nodes[current as usize];
                let found = packet.children::<false>(node, reach, &t_box);
                // Leaves first (a blocker ends a lane), then the first interior child.
                let mut leaves = found.slots & node.leaves as u32;
                while leaves != 0 {
                    let c = leaves.trailing_zeros() as usize;
                    leaves &= leaves - 1;
                    let mut hit = found.lanes[c] & alive;
                    while hit != 0 {
                        let lane = hit.trailing_zeros() as usize;
                        hit &= hit - 1;
                        if leaf(lane, node.child[c], node.count[c] as u32) {
                            blocked |= 1 << lane;
                            alive &= !(1 << lane);
                        }
                    }
                }
                if alive == 0 {
                    return blocked;
                }
                let mut inner = found.slots & !(node.leaves as u32);
                if inner != 0 {
                    let c = inner.trailing_zeros() as usize;
                    inner &= inner - 1;
                    while inner != 0 {
                        let o = inner.trailing_zeros() as usize;
                        inner &= inner - 1;
                        stack[sp].write((node.child[o], found.lanes[o]));
                        sp += 1;
                    }
                    (current, reach) = (node.child[c], found.lanes[c] & alive);
                    if reach != 0 {
                        continue 'nodes;
                    }
                }
            }
            loop {
                if sp == 0 || alive == 0 {
                    return blocked;
                }
                sp -= 1;
                // SAFETY: every slot below the old `sp` has been written.
                let (n, r) = stack[sp].assume_init();
                if r & alive != 0 {
                    (current, reach) = (n, r & alive);
                    continue 'nodes;
                }
            }
        }
    }

    /// Closest hit for the rays of `packet` in `lanes`, each within (0, `t_max[lane]`),
    /// which is narrowed to each ray's nearest hit. `leaf(lane, first, count, t_max)`
    /// tests a leaf for one ray and returns its nearest distance (or `t_max`);
    /// `single(lane, node, t_max)` does the same for the subtree under `node`, called
    /// where `single_below` lanes or fewer reach it. Subtrees go nearest first by the
    /// least entry distance among their lanes, and a lane whose nearest hit so far is
    /// nearer than that leaves the subtree.
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[inline(always)]
    pub unsafe fn intersect8<P: PacketTest>(
        &self,
        packet: &P,
        t_max: &mut [f32; 8],
        lanes: u32,
        single_below: u32,
        mut leaf: impl FnMut(usize, u32, u32, f32) -> f32,
        mut single: impl FnMut(usize, u32, f32) -> f32,
    ) {
        let active = lanes & packet.finite();
        if self.nodes.is_empty() || active == 0 {
            return;
        }
        let mut t_box = t_max.map(|t| t * T_MAX_SCALE);
        let narrow = |lane: usize, t: f32, t_max: &mut [f32; 8], t_box: &mut [f32; 8]| {
            t_max[lane] = t;
            t_box[lane] = t * T_MAX_SCALE;
        };
        let mut stack = [const { MaybeUninit::<Pending>::uninit() }; STACK];
        let mut sp = 0;
        let (mut current, mut reach) = (0u32, active);
        'nodes: loop {
            if reach.count_ones() <= single_below {
                let mut todo = reach;
                while todo != 0 {
                    let lane = todo.trailing_zeros() as usize;
                    todo &= todo - 1;
                    let t = single(lane, current, t_max[lane]);
                    narrow(lane, t, t_max, &mut t_box);
                }
            } else {
                let node = &self.nodes[current as usize];
                let found = packet.children::<true>(node, reach, &t_box);
                // Onto the stack farthest first, by insertion.
                let base = sp;
                let mut slots = found.slots;
                while slots != 0 {
                    let c = slots.trailing_zeros() as usize;
                    slots &= slots - 1;
                    let pending = Pending {
                        child: node.child[c],
                        count: node.count[c] as u32,
                        lanes: found.lanes[c],
                        t: found.key[c],
                    };
                    let mut at = sp;
                    while at > base && stack[at - 1].assume_init_ref().t < pending.t {
                        stack[at] = stack[at - 1];
                        at -= 1;
                    }
                    stack[at].write(pending);
                    sp += 1;
                }
            }
            loop {
                if sp == 0 {
                    return;
                }
                sp -= 1;
                // SAFETY: every slot below the old `sp` has been written.
                let e = stack[sp].assume_init();
                let still = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(
                    _mm256_set1_ps(e.t),
                    _mm256_loadu_ps(t_box.as_ptr()),
                )) as u32;
                let mut lanes = e.lanes & still;
                if lanes == 0 {
                    continue;
                }
                if e.count == 0 {
                    (current, reach) = (e.child, lanes);
                    continue 'nodes;
                }
                while lanes != 0 {
                    let lane = lanes.trailing_zeros() as usize;
                    lanes &= lanes - 1;
                    let t = leaf(lane, e.child, e.count, t_max[lane]);
                    narrow(lane, t, t_max, &mut t_box);
                }
            }
        }
    }
}
