//! Queries of trees that are one node: a scene whose primitives fit eight leaves (a
//! room, a Cornell box). They need none of the traversal's machinery (stack, pops,
//! child ranks): one leaf is tested straight away, and one node over several leaves
//! takes its box test, then its blocks near to far, each only while it is entered before
//! the nearest hit so far. Each finds the traversal's hits, bit for bit: the same block
//! tests with the same `t_max`, in the traversal's order. The root's unused lanes hold
//! its blocks' spheres' boxes, so that its box test also tells which spheres a ray
//! cannot meet ([`SmallRoot`]); under AVX2 the set-up is made in registers (`setup`).
//!
//! Apart from the traversal, so that its code is as it was for other trees (a check
//! inside it cost the spot room 1–5 instructions a query, and an arm beside it changed
//! its register use: +8 %). As for the traversal, a dispatch inlined into the caller
//! and one call: the AVX2 query compiled for AVX2, the others out of line (an
//! out-of-line dispatch cost 42 instructions a query).

pub(super) mod setup;

#[cfg(target_arch = "x86_64")]
use crate::bvh::Avx2Boxes;
#[cfg(target_arch = "x86_64")]
use crate::bvh::SseBoxes;
use crate::bvh::{BoxTest, Node8, Planes8, Ray8, ScalarBoxes, Simd, WideBvh, T_MAX_SCALE};
use crate::geometry::{Ray, TriangleHit, WatertightRay};

use super::block::{self, Block, LaneHit};
use super::{Accel, LeafBlocks, Leaves, NodeLayout};

/// A tree of one node, as its queries want it: at most one of the two is set. Two
/// options checked one after the other, not one enum: the one-leaf query's dispatch
/// stays one compare (an enum's cost the one-leaf scenes 9–11 instructions a path).
#[derive(Clone, Debug, Default)]
pub(super) struct SmallTree {
    /// One leaf: its block test alone, without the root's box test, which only culls
    /// (the block test is exact).
    pub(super) leaf: Option<SoleLeaf>,
    /// A root whose two to eight children are all leaves (a tree of one node has no
    /// interior child). Boxed: the structure stays small for trees that are not one node.
    pub(super) root: Option<Box<SmallRoot>>,
}

/// The root of a tree of one node over several leaves, with the boxes of its blocks'
/// spheres in the lanes its leaves leave free: the root's box test then tells, for
/// nothing more, which spheres the ray cannot meet, and their lanes skip the vector
/// sphere test (about 50 instructions a block, paid on the rooms by nearly every query,
/// whose sphere shares a block with walls).
#[derive(Clone, Debug)]
pub(super) struct SmallRoot {
    /// The root node; a sphere's lane has its box and no primitives (count 0).
    pub(super) node: Node8,
    /// The lanes that are leaves (bit i for lane i).
    pub(super) leaves: u32,
    /// By leaf lane: the lanes that hold its spheres' boxes, in the order of…
    sphere_boxes: [u8; 8],
    /// …its spheres' lanes in its block.
    spheres: [u8; 8],
}

impl SmallRoot {
    /// `node` with the boxes of the spheres of `blocks` (its leaves' blocks, where the
    /// leaves are inline) in its free lanes, as many as fit.
    ///
    /// A sphere's box is widened by 1/256 of the radius plus the largest coordinate of
    /// the root's box: the sphere test's distance is rounded (its discriminant to a few
    /// ulps of the ray origin's distance from the centre), so a ray it reports hit may
    /// pass just outside the sphere, and the margin keeps every such ray inside the box
    /// (for origins within 2^16 scene sizes of it), so that culling changes no hit.
    fn new(node: Node8, blocks: Option<&[Block]>) -> SmallRoot {
        let leaves = (0..8)
            .filter(|&l| node.count[l] > 0)
            .fold(0, |m, l| m | 1 << l);
        let mut root = SmallRoot {
            node,
            leaves,
            sphere_boxes: [0; 8],
            spheres: [0; 8],
        };
        let Some(blocks) = blocks else {
            return root;
        };
        let scale = (0..8)
            .filter(|&l| leaves & 1 << l != 0)
            .flat_map(|l| node.planes.iter().map(move |row| row[l].abs()))
            .fold(0.0f32, f32::max);
        let mut free = !leaves & 0xff;
        for lane in 0..8 {
            if leaves & 1 << lane == 0 {
                continue;
            }
            let block = &blocks[node.child[lane] as usize];
            for (sphere, centre, radius) in block.spheres(node.count[lane] as u32) {
                if free == 0 {
                    return root;
                }
                let at = free.trailing_zeros() as usize;
                free &= free - 1;
                let extent = radius + (radius + scale) / 256.0;
                for axis in 0..3 {
                    root.node.planes[2 * axis][at] = centre[axis] - extent;
                    root.node.planes[2 * axis + 1][at] = centre[axis] + extent;
                }
                root.sphere_boxes[lane] |= 1 << at;
                root.spheres[lane] |= 1 << sphere;
            }
        }
        root
    }

    /// The sphere lanes of leaf `lane`'s block whose boxes the box test `hits` missed.
    #[inline(always)]
    fn missed_spheres(&self, lane: usize, hits: u32) -> u32 {
        let (mut boxes, mut spheres) = (self.sphere_boxes[lane] as u32, self.spheres[lane] as u32);
        let mut missed = 0;
        while spheres != 0 {
            let sphere = spheres & spheres.wrapping_neg();
            if hits & boxes & boxes.wrapping_neg() == 0 {
                missed |= sphere;
            }
            spheres ^= sphere;
            boxes &= boxes - 1;
        }
        missed
    }
}

/// A leaf as a wide node's lane names it (its block, or its first record), and its
/// primitive count.
#[derive(Clone, Copy, Debug)]
pub(super) struct SoleLeaf {
    pub(super) leaf: u32,
    pub(super) count: u32,
}

impl SmallTree {
    /// What the queries of `bvh` (with its leaves already named as the leaf layout
    /// names them) can shortcut, if anything. One node over several leaves only with
    /// full-precision boxes: the quantized layout keeps the traversal, whose hits on
    /// its wider boxes it would not reproduce bit for bit otherwise.
    /// `blocks`: the leaves' blocks where they are inline (the root's sphere boxes,
    /// [`SmallRoot`]).
    pub(super) fn of(
        bvh: &WideBvh<Node8>,
        nodes: NodeLayout,
        blocks: Option<&[Block]>,
    ) -> SmallTree {
        if let Some((leaf, count)) = bvh.sole_leaf() {
            return SmallTree {
                leaf: Some(SoleLeaf { leaf, count }),
                root: None,
            };
        }
        SmallTree {
            leaf: None,
            root: match (bvh.sole_node(), nodes) {
                (Some(root), NodeLayout::Full) => Some(Box::new(SmallRoot::new(*root, blocks))),
                _ => None,
            },
        }
    }
}

impl Accel {
    /// The query of a tree of one node `tree` ([`SmallTree`]); with `ANY`, any hit (see
    /// [`super::Block::intersect`]). Each kind of tree has its own out-of-line query,
    /// so that the one-leaf query keeps its lean frame.
    #[inline(always)]
    pub(super) fn small_hit<T: SmallQuery, const ANY: bool, F: Fn(u32, &TriangleHit) -> bool>(
        &self,
        tree: &T,
        ray: &Ray,
        t_max: f32,
        filter: &F,
    ) -> Option<LaneHit> {
        match &self.leaves {
            // SAFETY: `finish` checked that the CPU supports `self.simd`.
            #[cfg(target_arch = "x86_64")]
            Leaves::Inline(blocks) if self.simd == Simd::Avx2 => unsafe {
                if self.plain {
                    small_avx2::<T, ANY, true, _, _>(&blocks[..], tree, ray, t_max, filter)
                } else {
                    small_avx2::<T, ANY, false, _, _>(&blocks[..], tree, ray, t_max, filter)
                }
            },
            Leaves::Inline(blocks) => {
                self.small_hit_other::<T, ANY, _, _>(&blocks[..], tree, ray, t_max, filter)
            }
            Leaves::Indexed(x) => self.small_hit_other::<T, ANY, _, _>(x, tree, ray, t_max, filter),
        }
    }

    /// [`Accel::small_hit`] with every kernel on indexed leaves, and with the SSE and
    /// scalar kernels on inline blocks.
    #[inline(never)]
    fn small_hit_other<T: SmallQuery, const ANY: bool, L, F>(
        &self,
        leaves: &L,
        tree: &T,
        ray: &Ray,
        t_max: f32,
        filter: &F,
    ) -> Option<LaneHit>
    where
        L: LeafBlocks + ?Sized,
        F: Fn(u32, &TriangleHit) -> bool,
    {
        // SAFETY: `finish` checked that the CPU supports `self.simd`.
        unsafe {
            match self.simd {
                #[cfg(target_arch = "x86_64")]
                Simd::Avx2 if self.plain => {
                    small_avx2::<T, ANY, true, _, _>(leaves, tree, ray, t_max, filter)
                }
                #[cfg(target_arch = "x86_64")]
                Simd::Avx2 => small_avx2::<T, ANY, false, _, _>(leaves, tree, ray, t_max, filter),
                #[cfg(target_arch = "x86_64")]
                Simd::Sse => T::query::<SseBoxes, { block::SSE }, ANY, false, _>(
                    tree, leaves, ray, t_max, filter,
                ),
                _ => T::query::<ScalarBoxes, { block::SCALAR }, ANY, false, _>(
                    tree, leaves, ray, t_max, filter,
                ),
            }
        }
    }
}

/// [`SmallQuery::query`] compiled with AVX2 enabled, so that the box and block tests
/// inline.
///
/// # Safety
/// The CPU must support AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,bmi1,bmi2,lzcnt")]
unsafe fn small_avx2<T: SmallQuery, const ANY: bool, const PLAIN: bool, L, F>(
    leaves: &L,
    tree: &T,
    ray: &Ray,
    t_max: f32,
    filter: &F,
) -> Option<LaneHit>
where
    L: LeafBlocks + ?Sized,
    F: Fn(u32, &TriangleHit) -> bool,
{
    T::query::<Avx2Boxes, { block::AVX2 }, ANY, PLAIN, _>(tree, leaves, ray, t_max, filter)
}

/// The query of one kind of small tree.
pub(super) trait SmallQuery {
    /// The nearest hit (with `ANY`, any hit) with box kernel `K` and block kernel
    /// `LEAF`. Rays that are not finite find nothing, as in the traversal.
    ///
    /// # Safety
    /// The CPU must support `K` and `LEAF`.
    unsafe fn query<K: BoxTest, const LEAF: u8, const ANY: bool, const PLAIN: bool, L>(
        &self,
        leaves: &L,
        ray: &Ray,
        t_max: f32,
        filter: &impl Fn(u32, &TriangleHit) -> bool,
    ) -> Option<LaneHit>
    where
        L: LeafBlocks + ?Sized;
}

impl SmallQuery for SoleLeaf {
    /// The block test of the one leaf.
    #[inline(always)]
    unsafe fn query<K: BoxTest, const LEAF: u8, const ANY: bool, const PLAIN: bool, L>(
        &self,
        leaves: &L,
        ray: &Ray,
        t_max: f32,
        filter: &impl Fn(u32, &TriangleHit) -> bool,
    ) -> Option<LaneHit>
    where
        L: LeafBlocks + ?Sized,
    {
        if !crate::bvh::finite(ray) {
            return None;
        }
        // The same bits as the traversal's `from_recip` (the same division); under AVX2
        // made in registers.
        #[cfg(target_arch = "x86_64")]
        let wray = if LEAF == block::AVX2 {
            setup::watertight_new(ray)
        } else {
            WatertightRay::new(ray)
        };
        #[cfg(not(target_arch = "x86_64"))]
        let wray = WatertightRay::new(ray);
        let SoleLeaf { leaf, count } = *self;
        leaves.with_block(
            leaf,
            count,
            #[inline(always)]
            |block| block.intersect::<LEAF, ANY, PLAIN>(ray, &wray, count, t_max, filter),
        )
    }
}

impl SmallQuery for SmallRoot {
    #[inline(always)]
    unsafe fn query<K: BoxTest, const LEAF: u8, const ANY: bool, const PLAIN: bool, L>(
        &self,
        leaves: &L,
        ray: &Ray,
        t_max: f32,
        filter: &impl Fn(u32, &TriangleHit) -> bool,
    ) -> Option<LaneHit>
    where
        L: LeafBlocks + ?Sized,
    {
        root_query::<K, LEAF, ANY, PLAIN, _>(leaves, self, ray, t_max, filter)
    }
}

/// One node over leaves: its box test, then the blocks of the children entered. A
/// closest-hit query tests them nearest entry first (the higher lane first among equal
/// entries), and stops at the first entered beyond the nearest hit so far (widened by
/// [`T_MAX_SCALE`]): the order and the cut of [`WideBvh::intersect`], whose pops skip
/// every farther one too. An any-hit query tests them in lane order, as
/// [`WideBvh::occluded`] does. The spheres whose boxes the ray misses are not tested.
///
/// # Safety
/// The CPU must support `K` and `LEAF`.
#[inline(always)]
unsafe fn root_query<K: BoxTest, const LEAF: u8, const ANY: bool, const PLAIN: bool, L>(
    leaves: &L,
    root: &SmallRoot,
    ray: &Ray,
    t_max: f32,
    filter: &impl Fn(u32, &TriangleHit) -> bool,
) -> Option<LaneHit>
where
    L: LeafBlocks + ?Sized,
{
    let mut t_box = t_max * T_MAX_SCALE;
    #[cfg(target_arch = "x86_64")]
    let set_up = if LEAF == block::AVX2 {
        setup::root_setup(ray, &root.node.planes, t_box)
    } else {
        root_setup::<K>(ray, &root.node.planes, t_box)
    };
    #[cfg(not(target_arch = "x86_64"))]
    let set_up = root_setup::<K>(ray, &root.node.planes, t_box);
    let (hits, t_near, wray) = set_up?;
    let mut mask = hits & root.leaves;
    let mut t_max = t_max;
    let mut best = None;
    while mask != 0 {
        let lane = if ANY {
            mask.trailing_zeros() as usize
        } else {
            let lane = nearest(mask, &t_near);
            if t_near[lane] > t_box {
                break;
            }
            lane
        };
        mask &= !(1 << lane);
        let count = root.node.count[lane] as u32;
        let culled = if PLAIN {
            0
        } else {
            root.missed_spheres(lane, hits)
        };
        // Opaque, as in the traversal: the block test's broadcasts are made where a
        // block is tested, not hoisted into the set-up and spilled.
        let (ray, wray) = std::hint::black_box((ray, &wray));
        let hit = leaves.with_block(
            root.node.child[lane],
            count,
            #[inline(always)]
            |block| {
                block.intersect_culled::<LEAF, ANY, PLAIN>(ray, wray, count, t_max, culled, filter)
            },
        );
        if let Some(h) = hit {
            if ANY {
                return Some(h);
            }
            t_max = h.hit.t;
            t_box = t_max * T_MAX_SCALE;
            best = Some(h);
        }
    }
    best
}

/// The root's box test of `ray` with kernel `K` within `t_box` (the children entered
/// and where) and its watertight constants; `None` for a ray that is not finite. (AVX2
/// takes [`setup::root_setup`], the same bits for fewer instructions.)
///
/// # Safety
/// The CPU must support `K`.
#[inline(always)]
unsafe fn root_setup<K: BoxTest>(
    ray: &Ray,
    planes: &Planes8,
    t_box: f32,
) -> Option<(u32, [f32; 8], WatertightRay)> {
    let r8 = Ray8::new(ray);
    if !r8.finite {
        return None;
    }
    let wray = WatertightRay::from_recip(ray, r8.inv_d);
    let (hits, t_near) = K::hit8(&K::prepare(&r8), planes, t_box);
    Some((hits, t_near, wray))
}

/// The lane of `mask` with the least `t` (never NaN: the box test's entry distances),
/// the highest among equals.
#[inline(always)]
pub(super) fn nearest(mask: u32, t: &[f32; 8]) -> usize {
    let mut rest = mask;
    let mut best = rest.trailing_zeros() as usize;
    rest &= rest - 1;
    while rest != 0 {
        let lane = rest.trailing_zeros() as usize;
        rest &= rest - 1;
        if t[lane] <= t[best] {
            best = lane;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::accel::{accept_all, Shape};

    /// Three clusters of four triangles and a sphere amid them, far apart: a root over
    /// a leaf a cluster, with free lanes. Each sphere's box goes to a free lane and
    /// encloses the sphere with a margin; a ray that passes far from every sphere culls
    /// them all, one aimed at a sphere's centre keeps it, and both find the traversal's
    /// hits.
    #[test]
    fn sphere_boxes_fill_free_lanes_and_cull_only_missed_spheres() {
        let mut shapes = Vec::new();
        let centres = [
            Vec3::ZERO,
            Vec3::new(6.0, 0.0, 6.0),
            Vec3::new(0.0, 6.0, -6.0),
        ];
        for c in centres {
            for k in 0..4 {
                let z = k as f32 * 0.3;
                shapes.push(Shape::Triangle([
                    c + Vec3::new(-1.0, -1.0, z),
                    c + Vec3::new(1.0, -1.0, z),
                    c + Vec3::new(0.0, 1.0, z),
                ]));
            }
            shapes.push(Shape::Sphere {
                center: c + Vec3::new(0.0, 0.0, 0.45),
                radius: 0.25,
            });
        }
        let accel = Accel::build(&shapes, |_| false);
        let root = accel.small.root.as_deref().expect("a tree of one node");
        let Leaves::Inline(blocks) = &accel.leaves else {
            panic!("inline leaves")
        };
        let mut boxed = 0;
        for lane in 0..8 {
            let (boxes, spheres) = (root.sphere_boxes[lane], root.spheres[lane]);
            assert_eq!(boxes.count_ones(), spheres.count_ones(), "lane {lane}");
            assert_eq!(boxes as u32 & root.leaves, 0, "a leaf's lane holds a box");
            if root.leaves & 1 << lane == 0 {
                continue;
            }
            let count = root.node.count[lane] as u32;
            let block = &blocks[root.node.child[lane] as usize];
            let mut at = boxes as u32;
            for (sphere, centre, radius) in block.spheres(count) {
                assert!(
                    spheres & 1 << sphere != 0,
                    "lane {lane}: sphere {sphere} unboxed"
                );
                let b = at.trailing_zeros() as usize;
                at &= at - 1;
                for axis in 0..3 {
                    let (lo, hi) = (
                        root.node.planes[2 * axis][b],
                        root.node.planes[2 * axis + 1][b],
                    );
                    assert!(lo < centre[axis] - radius && hi > centre[axis] + radius);
                    assert!(hi - lo < 2.0 * radius + 0.2, "box {b} too wide");
                }
                boxed += 1;
            }
        }
        assert_eq!(boxed, 3);

        let traversal = accel.clone().without_shortcut();
        let query = |ray: &Ray| {
            let r8 = Ray8::new(ray);
            // SAFETY: the scalar kernel runs on every CPU.
            let (hits, _) = unsafe {
                ScalarBoxes::hit8(&ScalarBoxes::prepare(&r8), &root.node.planes, f32::INFINITY)
            };
            (0..8)
                .filter(|&l| root.leaves & 1 << l != 0)
                .map(|l| root.missed_spheres(l, hits).count_ones())
                .sum::<u32>()
        };
        // Along -z through the first cluster's triangles, outside every sphere's box
        // (half-width about 0.28): all three culled.
        let past = Ray::new(Vec3::new(0.5, -0.5, 5.0), -Vec3::Z);
        assert_eq!(query(&past), 3);
        // At the first sphere, between the triangles' planes: it stays, and the hit is
        // the sphere's.
        let at = Ray::new(Vec3::new(-5.0, 0.0, 0.45), Vec3::X);
        assert_eq!(query(&at), 2);
        for ray in [past, at] {
            let (a, b) = (
                accel.intersect(&ray, f32::INFINITY, accept_all),
                traversal.intersect(&ray, f32::INFINITY, accept_all),
            );
            assert_eq!(a, b);
            assert!(a.is_some());
        }
        let hit = accel.intersect(&at, f32::INFINITY, accept_all).unwrap();
        assert_eq!(hit.prim, 4);
    }
}
