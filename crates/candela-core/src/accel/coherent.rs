//! Closest hits of eight coherent rays (a packet of camera rays) traced together, each
//! ray's answer that of [`Accel::intersect`] bit for bit: distance, barycentrics,
//! primitive, and the choice among equal distances; and whether each of eight rays
//! (shadow rays of eight paths) is blocked, each ray's answer that of
//! [`Accel::occluded`].
//!
//! Covered: trees of one node ([`super::small`]) with inline blocks and the AVX2
//! kernels. Each block is tested against the rays that visit it at once
//! ([`Block::intersect_rays8`]: a primitive against eight rays in lanes). The rays go
//! through the one node as each alone would: every ray's next block is its own (nearest
//! entry first, the cut past its nearest hit so far), and a block is tested against
//! the rays whose next block it is, each with the `t_max` it would have there. Coherent
//! rays visit the same blocks in the same order, so a packet tests each block once.
//! Whether a ray is blocked does not depend on the order its blocks are tested in (each
//! primitive's test is the single query's), so the any-hit query tests each block the
//! rays enter once, in lane order as the single query does, against the rays that enter
//! it and are not yet blocked, coherent or not.
//!
//! Not covered, and answered by eight single queries ([`Accel::packs_rays`] says which):
//! trees of more than one node (the packet traversal of [`super::packet`] visits nodes in
//! an order of its own, so ties and the scaled `t_max` test could differ), indexed
//! leaves, the quantized layout's node, and CPUs without AVX2 (SSE and scalar kernels).
//! Spheres and filtered (alpha-masked) triangles inside a covered block are tested ray by
//! ray by the single-ray scalar test, as the single-ray block test does; instances are
//! not in this structure (the scene traces those rays singly).

use super::{Accel, Hit};
use crate::geometry::{Ray, TriangleHit};

impl Accel {
    /// Whether [`Accel::intersect_coherent8`] traces packets here (else it makes eight
    /// single queries, and a caller gains nothing by grouping rays).
    pub fn packs_rays(&self) -> bool {
        #[cfg(target_arch = "x86_64")]
        {
            self.simd == super::Simd::Avx2
                && matches!(self.leaves, super::Leaves::Inline(_))
                && (self.small.leaf.is_some() || self.small.root.is_some())
        }
        #[cfg(not(target_arch = "x86_64"))]
        false
    }

    /// The blocks the packet queries test, where they trace packets
    /// ([`Accel::packs_rays`]).
    #[cfg(target_arch = "x86_64")]
    fn packed_blocks(&self) -> Option<&[super::Block]> {
        match &self.leaves {
            super::Leaves::Inline(blocks) if self.packs_rays() => Some(blocks),
            _ => None,
        }
    }

    /// The nearest hit of each ray `i` of `rays` that `active` names (bit `i`) within
    /// (0, `t_max[i]`), hits on flagged triangles counting only where
    /// `filter(i, prim, hit)` accepts them: what [`Accel::intersect`] finds for each, bit
    /// for bit. Rays not in `active` get `None`.
    pub fn intersect_coherent8(
        &self,
        rays: &[Ray; 8],
        active: u32,
        t_max: &[f32; 8],
        filter: impl Fn(usize, u32, &TriangleHit) -> bool,
    ) -> [Option<Hit>; 8] {
        #[cfg(target_arch = "x86_64")]
        if let Some(blocks) = self.packed_blocks() {
            // SAFETY: `finish` checked that the CPU supports AVX2 (and with it BMI1,
            // BMI2 and LZCNT, which `Simd::best` asks for).
            return unsafe {
                if self.plain {
                    x86::intersect8::<true>(&self.small, blocks, rays, active, t_max, &filter)
                } else {
                    x86::intersect8::<false>(&self.small, blocks, rays, active, t_max, &filter)
                }
            };
        }
        std::array::from_fn(|i| {
            if active & (1 << i) == 0 {
                return None;
            }
            self.intersect(&rays[i], t_max[i], |prim, hit| filter(i, prim, hit))
        })
    }

    /// Which rays `i` of `rays` that `active` names (bit `i`) are blocked within
    /// (0, `t_max[i]`), hits on flagged triangles counting only where
    /// `filter(i, prim, hit)` accepts them: bit `i` set where [`Accel::occluded`] says
    /// ray `i` is. Packed or single queries as for [`Accel::intersect_coherent8`].
    pub fn occluded_coherent8(
        &self,
        rays: &[Ray; 8],
        active: u32,
        t_max: &[f32; 8],
        filter: impl Fn(usize, u32, &TriangleHit) -> bool,
    ) -> u32 {
        #[cfg(target_arch = "x86_64")]
        if let Some(blocks) = self.packed_blocks() {
            // SAFETY: as in `intersect_coherent8`.
            return unsafe {
                if self.plain {
                    x86::occluded8::<true>(&self.small, blocks, rays, active, t_max, &filter)
                } else {
                    x86::occluded8::<false>(&self.small, blocks, rays, active, t_max, &filter)
                }
            };
        }
        (0..8).filter(|&i| active & (1 << i) != 0).fold(0, |m, i| {
            let blocked = self.occluded(&rays[i], t_max[i], |prim, hit| filter(i, prim, hit));
            m | (blocked as u32) << i
        })
    }
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::*;
    use crate::accel::block::{Best8, Block, Rays8};
    use crate::accel::small::{nearest, SmallRoot, SmallTree};
    use crate::bvh::{Avx2Boxes, BoxTest, Node8, Ray8, T_MAX_SCALE};
    use std::arch::x86_64::*;

    /// The packet query of a tree of one node.
    ///
    /// # Safety
    /// The CPU must have AVX2, BMI1, BMI2 and LZCNT.
    #[target_feature(enable = "avx2,bmi1,bmi2,lzcnt")]
    pub unsafe fn intersect8<const PLAIN: bool>(
        small: &SmallTree,
        blocks: &[Block],
        rays: &[Ray; 8],
        active: u32,
        t_max: &[f32; 8],
        filter: &impl Fn(usize, u32, &TriangleHit) -> bool,
    ) -> [Option<Hit>; 8] {
        let (packet, finite) = Rays8::new(rays);
        // Rays that are not finite find nothing, as in the single query.
        let active = active & finite;
        let mut best = Best8::new(*t_max);
        if let Some(sole) = &small.leaf {
            if active != 0 {
                blocks[sole.leaf as usize].intersect_rays8::<PLAIN, false>(
                    &packet, active, sole.count, &mut best, filter,
                );
            }
        } else if let Some(root) = &small.root {
            let mut boxes = RootBoxes::new(root, rays, active, t_max);
            root8::<PLAIN>(
                blocks, &root.node, &packet, &mut boxes, active, &mut best, filter,
            );
        }
        std::array::from_fn(|i| {
            (best.found & (1 << i) != 0).then(|| Hit {
                prim: best.id[i],
                t: best.t[i],
                b1: best.b1[i],
                b2: best.b2[i],
            })
        })
    }

    /// The packet any-hit query of a tree of one node: which rays are blocked.
    ///
    /// # Safety
    /// The CPU must have AVX2, BMI1, BMI2 and LZCNT.
    #[target_feature(enable = "avx2,bmi1,bmi2,lzcnt")]
    pub unsafe fn occluded8<const PLAIN: bool>(
        small: &SmallTree,
        blocks: &[Block],
        rays: &[Ray; 8],
        active: u32,
        t_max: &[f32; 8],
        filter: &impl Fn(usize, u32, &TriangleHit) -> bool,
    ) -> u32 {
        let (packet, finite) = Rays8::new(rays);
        // Rays that are not finite meet nothing, as in the single query.
        let active = active & finite;
        let mut best = Best8::new(*t_max);
        if active == 0 {
            return 0;
        }
        if let Some(sole) = &small.leaf {
            blocks[sole.leaf as usize]
                .intersect_rays8::<PLAIN, true>(&packet, active, sole.count, &mut best, filter);
        } else if let Some(root) = &small.root {
            // The leaves in lane order, as `root_query` takes them for any hit; each
            // against the rays that enter it and are not blocked yet.
            let entering = RootBoxes::new(root, rays, active, t_max).by_child(active);
            for (lane, &rays) in entering.iter().enumerate() {
                let group = rays & !best.found;
                if group != 0 {
                    let count = root.node.count[lane] as u32;
                    blocks[root.node.child[lane] as usize]
                        .intersect_rays8::<PLAIN, true>(&packet, group, count, &mut best, filter);
                }
            }
        }
        best.found
    }

    /// One node over leaves, each ray as [`crate::accel::small`]'s `root_query` takes
    /// it (closest hit): its box test, then the blocks of the children it enters,
    /// nearest entry first (the higher lane among equals), until the next one is entered
    /// beyond its nearest hit so far (widened by [`T_MAX_SCALE`]). Each round tests the
    /// next block of the first ray still going, against every ray whose next block it
    /// is.
    ///
    /// # Safety
    /// As for [`intersect8`].
    #[inline]
    #[target_feature(enable = "avx2,bmi1,bmi2,lzcnt")]
    #[allow(clippy::too_many_arguments)]
    unsafe fn root8<const PLAIN: bool>(
        blocks: &[Block],
        root: &Node8,
        packet: &Rays8<'_>,
        boxes: &mut RootBoxes,
        active: u32,
        best: &mut Best8,
        filter: &impl Fn(usize, u32, &TriangleHit) -> bool,
    ) {
        let RootBoxes { mask, t_near } = boxes;
        // Each going ray's next block (lane of the root), in lanes for the grouping.
        let mut next = [-1i32; 8];
        let mut going = 0u32;
        let mut rest = active;
        while rest != 0 {
            let r = rest.trailing_zeros() as usize;
            rest &= rest - 1;
            if let Some(lane) = step(mask[r], &t_near[r], best.t[r]) {
                next[r] = lane as i32;
                going |= 1 << r;
            }
        }
        while going != 0 {
            let lane = next[going.trailing_zeros() as usize];
            let same = _mm256_cmpeq_epi32(
                _mm256_loadu_si256(next.as_ptr() as *const __m256i),
                _mm256_set1_epi32(lane),
            );
            let group = _mm256_movemask_ps(_mm256_castsi256_ps(same)) as u32 & going;
            let lane = lane as usize;
            let count = root.count[lane] as u32;
            blocks[root.child[lane] as usize]
                .intersect_rays8::<PLAIN, false>(packet, group, count, best, filter);
            let mut rest = group;
            while rest != 0 {
                let r = rest.trailing_zeros() as usize;
                rest &= rest - 1;
                mask[r] &= !(1 << lane);
                match step(mask[r], &t_near[r], best.t[r]) {
                    Some(lane) => next[r] = lane as i32,
                    None => going &= !(1 << r),
                }
            }
        }
    }

    /// Each ray's box test of the root: the children it enters (bits) and where.
    struct RootBoxes {
        mask: [u32; 8],
        t_near: [[f32; 8]; 8],
    }

    impl RootBoxes {
        /// The box tests of the rays `active` names, each within its `t_max` widened by
        /// [`T_MAX_SCALE`], as `root_query` makes them; the leaves' lanes only (the others
        /// hold spheres' boxes, which the packet's block tests do not use).
        ///
        /// # Safety
        /// As for [`intersect8`].
        #[inline]
        #[target_feature(enable = "avx2,bmi1,bmi2,lzcnt")]
        unsafe fn new(root: &SmallRoot, rays: &[Ray; 8], active: u32, t_max: &[f32; 8]) -> Self {
            let mut boxes = RootBoxes {
                mask: [0; 8],
                t_near: [[0.0; 8]; 8],
            };
            let mut rest = active;
            while rest != 0 {
                let i = rest.trailing_zeros() as usize;
                rest &= rest - 1;
                let prepared = Avx2Boxes::prepare(&Ray8::new(&rays[i]));
                let t_box = t_max[i] * T_MAX_SCALE;
                let (hits, t_near) = Avx2Boxes::hit8(&prepared, &root.node.planes, t_box);
                (boxes.mask[i], boxes.t_near[i]) = (hits & root.leaves, t_near);
            }
            boxes
        }

        /// By child lane of the root, the rays of `active` that enter it (bits).
        #[inline(always)]
        fn by_child(&self, active: u32) -> [u32; 8] {
            let mut entering = [0; 8];
            let mut rest = active;
            while rest != 0 {
                let i = rest.trailing_zeros() as usize;
                rest &= rest - 1;
                let mut lanes = self.mask[i];
                while lanes != 0 {
                    entering[lanes.trailing_zeros() as usize] |= 1 << i;
                    lanes &= lanes - 1;
                }
            }
            entering
        }
    }

    /// A ray's next block: the lane of `mask` it enters first (`t_near`), unless that is
    /// entered beyond its nearest hit so far `t_max` widened by [`T_MAX_SCALE`], or none
    /// is left.
    #[inline(always)]
    fn step(mask: u32, t_near: &[f32; 8], t_max: f32) -> Option<usize> {
        if mask == 0 {
            return None;
        }
        let lane = nearest(mask, t_near);
        (t_near[lane] <= t_max * T_MAX_SCALE).then_some(lane)
    }
}
