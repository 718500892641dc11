//! The light BVH's stochastic descent two levels at a time. Each step of the descent
//! weighs the two children of a node by their importance at the shading point and takes
//! one; the scalar form evaluated the two bounds of every level one after the other,
//! ~125 instructions each. Here every other level's node holds a [`Block`]: its two
//! children and four grandchildren in the lanes of one [`ImportanceLanes`], so that one
//! 8-lane evaluation serves two levels' choices.
//!
//! The lanes give the scalar importances' bits and the choices below repeat the scalar
//! descent's arithmetic in the same order, so picks and probabilities are the same bits as
//! a descent node by node (`tests` compares both on random trees).

use crate::light::{ImportanceBounds, ImportanceLanes, ShadingCtx};
use crate::sampling::ONE_MINUS_EPSILON;

/// A node of the light BVH's depth-first array, without its bounds.
#[derive(Clone, Copy, Debug)]
pub(super) struct TreeNode {
    /// Leaf: the light. Interior: the second child (the first follows the node).
    pub index: u32,
    pub is_leaf: bool,
}

/// Marks a leaf in [`Block::next`]; the other bits are its light.
const LEAF: u32 = 1 << 31;

/// An interior node's children (lanes 0 and 1) and grandchildren (lanes 2 and 3 below
/// the first child, 4 and 5 below the second; where a child is a leaf, its two lanes
/// repeat lane 0 and are never read).
#[derive(Clone, Debug)]
struct Block {
    lanes: ImportanceLanes,
    /// Per lane, where the descent goes on: `LEAF | light` for a leaf; for an interior
    /// grandchild (lanes 2–5) the index of its own block; 0 otherwise (an interior child
    /// goes on in the same block).
    next: [u32; 6],
}

/// The blocks of a light BVH of at least two lights, the root's first.
#[derive(Clone, Debug)]
pub(super) struct Descent {
    blocks: Vec<Block>,
}

/// Where the descent goes on after a choice: a light, or the node's own block.
#[inline(always)]
fn leaf(next: u32) -> Option<u32> {
    (next & LEAF != 0).then_some(next & !LEAF)
}

/// The probability of taking the first of two children whose importances are `ia` and
/// `ib`; `None` where neither can reach the point.
#[inline(always)]
fn first_probability(ia: f32, ib: f32) -> Option<f32> {
    if ia + ib <= 0.0 || (ia + ib).is_nan() {
        return None;
    }
    Some(ia / (ia + ib))
}

/// One choice between two children by `u`, which is rescaled to the chosen child's
/// interval, and `pmf` multiplied by its probability: the child (0 or 1).
#[inline(always)]
fn choose(ia: f32, ib: f32, u: &mut f32, pmf: &mut f32) -> Option<usize> {
    let pa = first_probability(ia, ib)?;
    if *u < pa {
        *u = (*u / pa).min(ONE_MINUS_EPSILON);
        *pmf *= pa;
        Some(0)
    } else {
        *u = ((*u - pa) / (1.0 - pa)).min(ONE_MINUS_EPSILON);
        *pmf *= 1.0 - pa;
        Some(1)
    }
}

impl Descent {
    /// The blocks of the tree `nodes` (depth-first, the root first and interior, at
    /// least two lights), whose node `i` has the bounds `bounds[i]`.
    pub fn new(nodes: &[TreeNode], bounds: &[ImportanceBounds]) -> Descent {
        assert!(nodes.len() >= 3 && !nodes[0].is_leaf && bounds.len() == nodes.len());
        let mut descent = Descent { blocks: Vec::new() };
        descent.add_block(nodes, bounds, 0);
        descent
    }

    /// Adds the block of interior node `at` and those below it; its index.
    fn add_block(&mut self, nodes: &[TreeNode], bounds: &[ImportanceBounds], at: usize) -> u32 {
        let children = [at + 1, nodes[at].index as usize];
        let mut lane_nodes = [children[0]; 6];
        lane_nodes[1] = children[1];
        for (k, &c) in children.iter().enumerate() {
            if !nodes[c].is_leaf {
                lane_nodes[2 + 2 * k] = c + 1;
                lane_nodes[3 + 2 * k] = nodes[c].index as usize;
            }
        }
        let id = self.blocks.len();
        self.blocks.push(Block {
            lanes: ImportanceLanes::new(&lane_nodes.map(|n| bounds[n])),
            next: [0; 6],
        });
        let mut next = [0; 6];
        for (lane, &n) in lane_nodes.iter().enumerate() {
            let grandchild = lane >= 2;
            if grandchild && nodes[children[(lane - 2) / 2]].is_leaf {
                continue;
            }
            next[lane] = if nodes[n].is_leaf {
                LEAF | nodes[n].index
            } else if grandchild {
                self.add_block(nodes, bounds, n)
            } else {
                0
            };
        }
        self.blocks[id].next = next;
        id as u32
    }

    /// A light by descent from the root with `u ∈ [0, 1)`, and `pmf` times its
    /// probability; `None` where no light can reach the point.
    #[inline]
    pub fn sample(&self, ctx: &ShadingCtx, u: f32, pmf: f32) -> Option<(u32, f32)> {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2.
            return unsafe { self.sample_avx2(ctx, u, pmf) };
        }
        self.sample_by(|lanes| lanes.importance_scalar(ctx), u, pmf)
    }

    /// [`Self::sample`] in AVX2 code, the lanes' evaluation inlined (the point's splats
    /// and the test of its normal then come once a descent rather than once a block).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2")]
    fn sample_avx2(&self, ctx: &ShadingCtx, u: f32, pmf: f32) -> Option<(u32, f32)> {
        self.sample_by(|lanes| lanes.importance_avx2(ctx), u, pmf)
    }

    /// The descent of [`Self::sample`], each block's lanes weighed by `weigh`.
    #[inline(always)]
    fn sample_by(
        &self,
        weigh: impl Fn(&ImportanceLanes) -> [f32; 8],
        mut u: f32,
        mut pmf: f32,
    ) -> Option<(u32, f32)> {
        let mut block = &self.blocks[0];
        loop {
            let w = weigh(&block.lanes);
            let first = choose(w[0], w[1], &mut u, &mut pmf)?;
            if let Some(light) = leaf(block.next[first]) {
                return Some((light, pmf));
            }
            let second = choose(w[2 + 2 * first], w[3 + 2 * first], &mut u, &mut pmf)?;
            let next = block.next[2 + 2 * first + second];
            if let Some(light) = leaf(next) {
                return Some((light, pmf));
            }
            block = &self.blocks[next as usize];
        }
    }

    /// `pmf` times the probability that [`Self::sample`] reaches the leaf at the end of
    /// `trail` (bit d: the branch at level d, under a leading 1 that marks the depth).
    #[inline]
    pub fn pmf(&self, ctx: &ShadingCtx, trail: u64, pmf: f32) -> f32 {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2.
            return unsafe { self.pmf_avx2(ctx, trail, pmf) };
        }
        self.pmf_by(|lanes| lanes.importance_scalar(ctx), trail, pmf)
    }

    /// [`Self::pmf`] in AVX2 code, as [`Self::sample_avx2`].
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2")]
    fn pmf_avx2(&self, ctx: &ShadingCtx, trail: u64, pmf: f32) -> f32 {
        self.pmf_by(|lanes| lanes.importance_avx2(ctx), trail, pmf)
    }

    /// The retrace of [`Self::pmf`], each block's lanes weighed by `weigh`.
    #[inline(always)]
    fn pmf_by(
        &self,
        weigh: impl Fn(&ImportanceLanes) -> [f32; 8],
        trail: u64,
        mut pmf: f32,
    ) -> f32 {
        let depth = 63 - trail.leading_zeros();
        let branch = |level: u32| ((trail >> level) & 1) as usize;
        let taken = |p: f32, branch: usize| if branch == 0 { p } else { 1.0 - p };
        let mut block = &self.blocks[0];
        let mut level = 0;
        loop {
            let w = weigh(&block.lanes);
            let first = branch(level);
            let Some(pa) = first_probability(w[0], w[1]) else {
                return 0.0;
            };
            pmf *= taken(pa, first);
            if level + 1 == depth {
                return pmf;
            }
            let second = branch(level + 1);
            let Some(pb) = first_probability(w[2 + 2 * first], w[3 + 2 * first]) else {
                return 0.0;
            };
            pmf *= taken(pb, second);
            if level + 2 == depth {
                return pmf;
            }
            level += 2;
            block = &self.blocks[block.next[2 + 2 * first + second] as usize];
        }
    }

    /// Bytes held.
    pub fn memory_bytes(&self) -> usize {
        self.blocks.len() * std::mem::size_of::<Block>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Aabb;
    use crate::light::LightBounds;
    use glam::Vec3;

    /// A depth-first tree over lights `first..first + n` split at random points, into
    /// `nodes`.
    fn random_tree(n: u32, first: u32, nodes: &mut Vec<TreeNode>, r: &mut impl FnMut() -> f32) {
        let at = nodes.len();
        nodes.push(TreeNode {
            index: first,
            is_leaf: n == 1,
        });
        if n == 1 {
            return;
        }
        let left = 1 + ((r() * (n - 1) as f32) as u32).min(n - 2);
        random_tree(left, first, nodes, r);
        nodes[at].index = nodes.len() as u32;
        random_tree(n - left, first + left, nodes, r);
    }

    /// The scalar descent node by node, as the light BVH sampled before the blocks.
    fn sample_by_node(
        nodes: &[TreeNode],
        bounds: &[ImportanceBounds],
        ctx: &ShadingCtx,
        mut u: f32,
        mut pmf: f32,
    ) -> Option<(u32, f32)> {
        let mut at = 0;
        loop {
            if nodes[at].is_leaf {
                return Some((nodes[at].index, pmf));
            }
            let (a, b) = (at + 1, nodes[at].index as usize);
            let ia = bounds[a].importance(ctx);
            let ib = bounds[b].importance(ctx);
            if ia + ib <= 0.0 || (ia + ib).is_nan() {
                return None;
            }
            let pa = ia / (ia + ib);
            if u < pa {
                u = (u / pa).min(ONE_MINUS_EPSILON);
                pmf *= pa;
                at = a;
            } else {
                u = ((u - pa) / (1.0 - pa)).min(ONE_MINUS_EPSILON);
                pmf *= 1.0 - pa;
                at = b;
            }
        }
    }

    /// The scalar pmf node by node along `trail`, as the light BVH retraced it before.
    fn pmf_by_node(
        nodes: &[TreeNode],
        bounds: &[ImportanceBounds],
        ctx: &ShadingCtx,
        trail: u64,
        mut pmf: f32,
    ) -> f32 {
        let mut at = 0;
        for level in 0..63 - trail.leading_zeros() {
            let (a, b) = (at + 1, nodes[at].index as usize);
            let ia = bounds[a].importance(ctx);
            let ib = bounds[b].importance(ctx);
            if ia + ib <= 0.0 || (ia + ib).is_nan() {
                return 0.0;
            }
            let pa = ia / (ia + ib);
            if trail & (1 << level) == 0 {
                pmf *= pa;
                at = a;
            } else {
                pmf *= 1.0 - pa;
                at = b;
            }
        }
        pmf
    }

    /// Per light, its trail (as the light BVH records them).
    fn trails(nodes: &[TreeNode], n: usize) -> Vec<u64> {
        let mut out = vec![0; n];
        let mut stack = vec![(0usize, 1u64)];
        while let Some((at, trail)) = stack.pop() {
            if nodes[at].is_leaf {
                out[nodes[at].index as usize] = trail;
                continue;
            }
            let depth = 63 - trail.leading_zeros();
            let child = (trail & !(1 << depth)) | (1 << (depth + 1));
            stack.push((at + 1, child));
            stack.push((nodes[at].index as usize, child | (1 << depth)));
        }
        out
    }

    /// Random trees (balanced and lopsided, odd and even depths) with random bounds, some
    /// of which cannot reach the point: the blocks pick the same lights with the same
    /// probability bits as the descent node by node, and their pmf retraces the same bits.
    #[test]
    fn blocks_give_the_scalar_descents_bits() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut uniform = move || {
            state = crate::sampler::mix64(state);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let (mut picks, mut refusals) = (0, 0);
        for round in 0..300 {
            let n = 2 + (uniform() * 70.0) as u32;
            let mut nodes = Vec::new();
            random_tree(n, 0, &mut nodes, &mut uniform);
            assert_eq!(nodes.len(), 2 * n as usize - 1);
            let mut r = |lo: f32, hi: f32| lo + (hi - lo) * uniform();
            let bounds: Vec<ImportanceBounds> = nodes
                .iter()
                .map(|_| {
                    let c = Vec3::new(r(-4.0, 4.0), r(-4.0, 4.0), r(-4.0, 4.0));
                    let e = Vec3::new(r(0.0, 1.0), r(0.0, 1.0), r(0.0, 1.0));
                    let w = Vec3::new(r(-1.0, 1.0), r(-1.0, 1.0), r(-1.0, 1.0));
                    ImportanceBounds::new(&LightBounds {
                        aabb: Aabb {
                            min: c - e,
                            max: c + e,
                        },
                        w: w.try_normalize().unwrap_or(Vec3::Y),
                        intensity: r(0.0, 50.0),
                        cos_theta_o: r(-0.2, 1.0),
                        cos_theta_e: if r(0.0, 1.0) < 0.7 { 0.0 } else { r(0.5, 1.0) },
                        two_sided: r(0.0, 1.0) < 0.3,
                    })
                })
                .collect();
            let descent = Descent::new(&nodes, &bounds);
            let trails = trails(&nodes, n as usize);
            for k in 0..40 {
                let ctx = ShadingCtx {
                    p: Vec3::new(r(-5.0, 5.0), r(-5.0, 5.0), r(-5.0, 5.0)),
                    n: if k % 4 == 0 {
                        Vec3::ZERO
                    } else {
                        Vec3::new(r(-1.0, 1.0), r(-1.0, 1.0), r(-1.0, 1.0)).normalize()
                    },
                };
                let u = if k == 1 {
                    ONE_MINUS_EPSILON
                } else {
                    r(0.0, 1.0)
                };
                let p0 = r(0.25, 1.0);
                let want = sample_by_node(&nodes, &bounds, &ctx, u, p0);
                let got = descent.sample(&ctx, u, p0);
                let bits = |s: Option<(u32, f32)>| s.map(|(i, p)| (i, p.to_bits()));
                assert_eq!(bits(got), bits(want), "round {round}, point {k}");
                // The fallback of CPUs without AVX2 too.
                let scalar = descent.sample_by(|l| l.importance_scalar(&ctx), u, p0);
                assert_eq!(bits(scalar), bits(want), "round {round}, point {k}");
                match got {
                    Some((light, p)) => {
                        picks += 1;
                        let back = descent.pmf(&ctx, trails[light as usize], p0);
                        assert_eq!(back.to_bits(), p.to_bits(), "round {round}, point {k}");
                    }
                    None => refusals += 1,
                }
                // Any light, reachable or not.
                let j = ((r(0.0, 1.0) * n as f32) as usize).min(n as usize - 1);
                let want = pmf_by_node(&nodes, &bounds, &ctx, trails[j], p0);
                let got = descent.pmf(&ctx, trails[j], p0);
                assert_eq!(
                    got.to_bits(),
                    want.to_bits(),
                    "round {round}, point {k}, light {j}"
                );
            }
        }
        // Both outcomes are exercised (a test of refusals alone would prove little).
        assert!(
            picks > 8000 && refusals > 10,
            "{picks} picks, {refusals} refusals"
        );
    }
}
