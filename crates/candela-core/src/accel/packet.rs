//! Queries of eight rays at once: the packet traversal of [`crate::bvh::RayPacket`] over
//! the scene's tree, each leaf tested for one ray at a time by the single-ray block test.
//! A measured kernel for the `traversal` benchmark (issue #35's packet rung), not used by
//! the renderer: on incoherent rays it costs more than eight single-ray queries, on
//! coherent camera rays about 10 % less (figures in `bench/RESULTS.md`, `## traversal`).
//! The renderer's camera packets are [`super::coherent`]'s (trees of one node, leaves
//! tested eight rays at a time).

use std::cell::Cell;

use super::{Accel, Hit};
use crate::geometry::{Ray, TriangleHit};

/// How [`Accel::occluded8`] and [`Accel::intersect8`] take a packet through a node.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PacketMode {
    /// Each child box against the eight rays in lanes (true), or each ray against the
    /// node's eight boxes with the single-ray test (false).
    pub box_against_rays: bool,
    /// A subtree that this many rays or fewer reach is finished by each alone.
    pub single_below: u32,
}

impl Accel {
    /// Whether each of eight rays is blocked within (0, `t_max[i]`) (bit `i`), as eight
    /// [`Accel::occluded`] calls answer. With AVX2 kernels, full nodes and inline
    /// leaves, the rays go through the tree together as `mode` says; otherwise eight
    /// single queries.
    pub fn occluded8(
        &self,
        rays: &[Ray; 8],
        t_max: &[f32; 8],
        mode: PacketMode,
        filter: impl Fn(u32, &TriangleHit) -> bool,
    ) -> u32 {
        #[cfg(target_arch = "x86_64")]
        if let (super::Simd::Avx2, super::Tree::Full(tree), super::Leaves::Inline(blocks)) =
            (self.simd, &self.tree, &self.leaves)
        {
            // SAFETY: `finish` checked that the CPU supports AVX2 (and with it BMI1, BMI2
            // and LZCNT, which `Simd::best` asks for).
            return unsafe {
                if self.plain {
                    x86::occluded8::<true>(tree, blocks, rays, t_max, mode, &filter)
                } else {
                    x86::occluded8::<false>(tree, blocks, rays, t_max, mode, &filter)
                }
            };
        }
        let _ = mode;
        (0..8).fold(0, |m, i| {
            m | (self.occluded(&rays[i], t_max[i], &filter) as u32) << i
        })
    }

    /// The nearest hit of each of eight rays within (0, `t_max[i]`), as eight
    /// [`Accel::intersect`] calls find it (where two primitives are hit at the same
    /// distance, either may be reported: the order of the visits differs). Packet or
    /// single queries as for [`Accel::occluded8`].
    pub fn intersect8(
        &self,
        rays: &[Ray; 8],
        t_max: &[f32; 8],
        mode: PacketMode,
        filter: impl Fn(u32, &TriangleHit) -> bool,
    ) -> [Option<Hit>; 8] {
        #[cfg(target_arch = "x86_64")]
        if let (super::Simd::Avx2, super::Tree::Full(tree), super::Leaves::Inline(blocks)) =
            (self.simd, &self.tree, &self.leaves)
        {
            // SAFETY: as in `occluded8`.
            return unsafe {
                if self.plain {
                    x86::intersect8::<true>(tree, blocks, rays, t_max, mode, &filter)
                } else {
                    x86::intersect8::<false>(tree, blocks, rays, t_max, mode, &filter)
                }
            };
        }
        let _ = mode;
        std::array::from_fn(|i| self.intersect(&rays[i], t_max[i], &filter))
    }
}

/// The hit of a block test as the query reports it.
fn hit_of(h: &super::block::LaneHit) -> Hit {
    Hit {
        prim: h.id,
        t: h.hit.t,
        b1: h.hit.b1,
        b2: h.hit.b2,
    }
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::*;
    use crate::accel::block::{Block, AVX2};
    use crate::bvh::{
        Avx2Boxes, BoxAgainstRays, Node8, PacketTest, Ray8, RaysAgainstBoxes, WideBvh,
    };
    use crate::geometry::WatertightRay;

    /// # Safety
    /// The CPU must have AVX2, BMI1, BMI2 and LZCNT.
    #[target_feature(enable = "avx2,bmi1,bmi2,lzcnt")]
    pub unsafe fn occluded8<const PLAIN: bool>(
        tree: &WideBvh<Node8>,
        blocks: &[Block],
        rays: &[Ray; 8],
        t_max: &[f32; 8],
        mode: PacketMode,
        filter: &impl Fn(u32, &TriangleHit) -> bool,
    ) -> u32 {
        let r8: [Ray8; 8] = std::array::from_fn(|i| Ray8::new(&rays[i]));
        if mode.box_against_rays {
            occluded8_with::<PLAIN>(
                tree,
                blocks,
                rays,
                &r8,
                &BoxAgainstRays::new(&r8),
                t_max,
                mode,
                filter,
            )
        } else {
            occluded8_with::<PLAIN>(
                tree,
                blocks,
                rays,
                &r8,
                &RaysAgainstBoxes::new(&r8),
                t_max,
                mode,
                filter,
            )
        }
    }

    /// (Compiled for AVX2 itself, so that the closures in it are too.)
    #[inline]
    #[target_feature(enable = "avx2,bmi1,bmi2,lzcnt")]
    #[allow(clippy::too_many_arguments)]
    unsafe fn occluded8_with<const PLAIN: bool>(
        tree: &WideBvh<Node8>,
        blocks: &[Block],
        rays: &[Ray; 8],
        r8: &[Ray8; 8],
        packet: &impl PacketTest,
        t_max: &[f32; 8],
        mode: PacketMode,
        filter: &impl Fn(u32, &TriangleHit) -> bool,
    ) -> u32 {
        let w: [WatertightRay; 8] =
            std::array::from_fn(|i| WatertightRay::from_recip(&rays[i], r8[i].inv_d));
        // One ray against one leaf block (as `occluded_tree` tests it).
        let test = |lane: usize, leaf: u32, count: u32| {
            let wray = std::hint::black_box(&w[lane]);
            blocks[leaf as usize]
                .intersect::<AVX2, true, PLAIN>(&rays[lane], wray, count, t_max[lane], filter)
                .is_some()
        };
        tree.occluded8(
            packet,
            t_max,
            0xff,
            mode.single_below,
            test,
            |lane, node| {
                tree.occluded_from::<Avx2Boxes>(node, &r8[lane], t_max[lane], |leaf, count, _| {
                    test(lane, leaf, count)
                })
            },
        )
    }

    /// # Safety
    /// As for [`occluded8`].
    #[target_feature(enable = "avx2,bmi1,bmi2,lzcnt")]
    pub unsafe fn intersect8<const PLAIN: bool>(
        tree: &WideBvh<Node8>,
        blocks: &[Block],
        rays: &[Ray; 8],
        t_max: &[f32; 8],
        mode: PacketMode,
        filter: &impl Fn(u32, &TriangleHit) -> bool,
    ) -> [Option<Hit>; 8] {
        let r8: [Ray8; 8] = std::array::from_fn(|i| Ray8::new(&rays[i]));
        if mode.box_against_rays {
            intersect8_with::<PLAIN>(
                tree,
                blocks,
                rays,
                &r8,
                &BoxAgainstRays::new(&r8),
                t_max,
                mode,
                filter,
            )
        } else {
            intersect8_with::<PLAIN>(
                tree,
                blocks,
                rays,
                &r8,
                &RaysAgainstBoxes::new(&r8),
                t_max,
                mode,
                filter,
            )
        }
    }

    /// (Compiled for AVX2 itself, so that the closures in it are too.)
    #[inline]
    #[target_feature(enable = "avx2,bmi1,bmi2,lzcnt")]
    #[allow(clippy::too_many_arguments)]
    unsafe fn intersect8_with<const PLAIN: bool>(
        tree: &WideBvh<Node8>,
        blocks: &[Block],
        rays: &[Ray; 8],
        r8: &[Ray8; 8],
        packet: &impl PacketTest,
        t_max: &[f32; 8],
        mode: PacketMode,
        filter: &impl Fn(u32, &TriangleHit) -> bool,
    ) -> [Option<Hit>; 8] {
        let w: [WatertightRay; 8] =
            std::array::from_fn(|i| WatertightRay::from_recip(&rays[i], r8[i].inv_d));
        let best: [Cell<Option<Hit>>; 8] = Default::default();
        // One ray against one leaf block within `t_max` (as `intersect_tree` tests it).
        let test = |lane: usize, leaf: u32, count: u32, t_max: f32| {
            let wray = std::hint::black_box(&w[lane]);
            match blocks[leaf as usize].intersect::<AVX2, false, PLAIN>(
                &rays[lane],
                wray,
                count,
                t_max,
                filter,
            ) {
                Some(h) => {
                    best[lane].set(Some(hit_of(&h)));
                    h.hit.t
                }
                None => t_max,
            }
        };
        let mut t = *t_max;
        tree.intersect8(
            packet,
            &mut t,
            0xff,
            mode.single_below,
            test,
            |lane, node, t_max| {
                let mut t = t_max;
                tree.intersect_from::<Avx2Boxes>(
                    node,
                    &r8[lane],
                    t_max,
                    |leaf, count, t_max| {
                        t = test(lane, leaf, count, t_max);
                        t
                    },
                    |leaf| {
                        let at = blocks.as_ptr().wrapping_add(leaf as usize);
                        crate::bvh::prefetch(at as *const u8, size_of::<Block>() / 64)
                    },
                );
                t
            },
        );
        best.map(Cell::into_inner)
    }
}
