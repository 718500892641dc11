//! The light BVH's stochastic descent two levels at a time. Each step of the descent
//! weighs the two children of a node by their importance at the shading point and takes
//! one; the scalar form evaluated the two bounds of every level one after the other,
//! ~125 instructions each. Here every other level's node holds a block: its two children
//! and the children of those that are interior, two to six nodes whose bounds one 8-lane
//! evaluation weighs, serving two levels' choices.
//!
//! A block stores only the lanes it uses, in rows of its own width: 40 bytes of bounds
//! and a 4-byte link per node, each node in exactly one block, so 44 B × (2N − 2) for N
//! lights. sin θ_o is recomputed from cos θ_o (as [`ImportanceBounds::new`] computes it)
//! and the two-sided flag rides in the sign bit of the intensity, which is never
//! negative.
//!
//! The lanes give the scalar importances' bits and the choices below repeat the scalar
//! descent's arithmetic in the same order, so picks and probabilities are the same bits as
//! a descent node by node (`tests` compares both on random trees).

#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::*;

#[cfg(target_arch = "x86_64")]
use crate::light::LoadedLanes;
use crate::light::{ImportanceBounds, ShadingCtx, LANES};
use crate::sampling::ONE_MINUS_EPSILON;

/// A node of the light BVH's depth-first array, without its bounds.
#[derive(Clone, Copy, Debug)]
pub(super) struct TreeNode {
    /// Leaf: the light. Interior: the second child (the first follows the node).
    pub index: u32,
    pub is_leaf: bool,
}

/// The rows of a block, one f32 per lane each: the bounding sphere's center (3 rows) and
/// radius, the cone's axis (3 rows), the intensity (its sign bit set where two-sided),
/// cos θ_o and cos θ_e; the links' row follows them.
const CENTER: usize = 0;
const RADIUS: usize = 3;
const AXIS: usize = 4;
const INTENSITY: usize = 7;
const COS_THETA_O: usize = 8;
const COS_THETA_E: usize = 9;
const ROWS: usize = 10;

/// The sign bit of an f32: in the intensity row, two-sided bounds.
const SIGN: u32 = 1 << 31;

/// Words from the start of a block of `k` lanes that its evaluation reads: its rows, of
/// which an 8-lane load takes 8 words whatever `k` (the lanes past `k` are ignored), and
/// 8 words from its links' row (past the block, the next one's or the padding).
const fn span(k: usize) -> usize {
    ROWS * k + LANES
}

/// A link to a leaf: this bit, and its light below it.
const LEAF: u32 = 1 << 31;
/// A link to a block: its width (lanes ÷ 2: 1, 2 or 3) from this bit, its first word
/// below it.
const WIDTH_SHIFT: u32 = 29;
const OFFSET_MASK: u32 = (1 << WIDTH_SHIFT) - 1;

/// The blocks of a light BVH of at least two lights.
///
/// A block of an interior node is `k` ∈ {2, 4, 6} lanes: its children in lanes 0 and 1,
/// then the two children of each interior child (of the first before the second);
/// [`ROWS`] rows of `k` f32 bits (row r of lane i at word r·k + i), then one link per
/// lane: `LEAF | light` for a leaf; for an interior child, the lane of its first child
/// (2 or 4); for an interior grandchild, the link to its own block.
#[derive(Clone, Debug)]
pub(super) struct Descent {
    /// The blocks one after another, depth first, then [`LANES`] words of padding that the
    /// last block's loads may read.
    words: Vec<u32>,
    /// The link to the root's block.
    root: u32,
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

/// The bounds of lane `lane` of a block of `k` lanes, as the builder was given them.
fn lane_bounds(block: &[u32], k: usize, lane: usize) -> ImportanceBounds {
    let row = |r: usize| f32::from_bits(block[r * k + lane]);
    let vec3 = |r: usize| glam::Vec3::new(row(r), row(r + 1), row(r + 2));
    let cos_theta_o = row(COS_THETA_O);
    ImportanceBounds {
        center: vec3(CENTER),
        radius: row(RADIUS),
        w: vec3(AXIS),
        intensity: row(INTENSITY).abs(),
        cos_theta_o,
        // As `ImportanceBounds::new` computes it.
        sin_theta_o: (1.0 - cos_theta_o * cos_theta_o).max(0.0).sqrt(),
        cos_theta_e: row(COS_THETA_E),
        two_sided: row(INTENSITY).is_sign_negative(),
    }
}

/// The importances at `ctx` of the `K` lanes of `block` (at least [`span`]`(K)` words;
/// the lanes past `K` are to be ignored), lane by lane by the scalar code.
fn weigh_scalar<const K: usize>(block: &[u32], ctx: &ShadingCtx) -> [f32; LANES] {
    let mut out = [0.0; LANES];
    for (lane, out) in out.iter_mut().enumerate().take(K) {
        *out = lane_bounds(block, K, lane).importance(ctx);
    }
    out
}

/// [`weigh_scalar`] in AVX2, the same bits; inlined into the AVX2 descent.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx,avx2")]
#[inline]
fn weigh_avx2<const K: usize>(block: &[u32], ctx: &ShadingCtx) -> [f32; LANES] {
    assert!(block.len() >= span(K));
    // SAFETY: row r < ROWS reads words r·K .. r·K + LANES, within span(K).
    let row = |r: usize| unsafe { _mm256_loadu_ps(block.as_ptr().add(r * K).cast()) };
    let zero = _mm256_setzero_ps();
    let cos_theta_o = row(COS_THETA_O);
    let signed_intensity = row(INTENSITY);
    let one_minus_sq = _mm256_sub_ps(_mm256_set1_ps(1.0), _mm256_mul_ps(cos_theta_o, cos_theta_o));
    LoadedLanes {
        center: [row(CENTER), row(CENTER + 1), row(CENTER + 2)],
        radius: row(RADIUS),
        w: [row(AXIS), row(AXIS + 1), row(AXIS + 2)],
        intensity: _mm256_andnot_ps(_mm256_set1_ps(-0.0), signed_intensity),
        cos_theta_o,
        // As `lane_bounds`: maxps gives 0 for a NaN, as `f32::max`.
        sin_theta_o: _mm256_sqrt_ps(_mm256_max_ps(one_minus_sq, zero)),
        cos_theta_e: row(COS_THETA_E),
        two_sided: signed_intensity,
    }
    .importance(ctx)
}

impl Descent {
    /// The blocks of the tree `nodes` (depth-first, the root first and interior, at
    /// least two lights), whose node `i` has the bounds `bounds[i]` (of intensity ≥ 0).
    pub fn new(nodes: &[TreeNode], bounds: &[ImportanceBounds]) -> Descent {
        assert!(nodes.len() >= 3 && !nodes[0].is_leaf && bounds.len() == nodes.len());
        // Each node but the root in one lane of 11 words.
        let mut descent = Descent {
            words: Vec::with_capacity((ROWS + 1) * (nodes.len() - 1) + LANES),
            root: 0,
        };
        descent.root = descent.add_block(nodes, bounds, 0);
        descent.words.extend([0; LANES]);
        descent
    }

    /// Adds the block of interior node `at` and those below it; the link to it.
    fn add_block(&mut self, nodes: &[TreeNode], bounds: &[ImportanceBounds], at: usize) -> u32 {
        let mut lane_nodes = [at + 1, nodes[at].index as usize, 0, 0, 0, 0];
        let mut links = [0u32; 6];
        let mut k = 2;
        for lane in 0..2 {
            let child = &nodes[lane_nodes[lane]];
            if child.is_leaf {
                links[lane] = LEAF | child.index;
            } else {
                links[lane] = k as u32;
                lane_nodes[k] = lane_nodes[lane] + 1;
                lane_nodes[k + 1] = child.index as usize;
                k += 2;
            }
        }
        let start = self.words.len();
        assert!(
            start + (ROWS + 1) * k <= OFFSET_MASK as usize,
            "light BVH too large for 32-bit links"
        );
        self.words.resize(start + (ROWS + 1) * k, 0);
        for (lane, &n) in lane_nodes[..k].iter().enumerate() {
            let b = &bounds[n];
            assert!(
                b.intensity >= 0.0,
                "negative light intensity {}",
                b.intensity
            );
            let sign = if b.two_sided { SIGN } else { 0 };
            let rows = [
                b.center.x,
                b.center.y,
                b.center.z,
                b.radius,
                b.w.x,
                b.w.y,
                b.w.z,
                f32::from_bits(b.intensity.to_bits() | sign),
                b.cos_theta_o,
                b.cos_theta_e,
            ];
            for (r, v) in rows.iter().enumerate() {
                self.words[start + r * k + lane] = v.to_bits();
            }
        }
        for lane in 2..k {
            let node = &nodes[lane_nodes[lane]];
            links[lane] = if node.is_leaf {
                LEAF | node.index
            } else {
                self.add_block(nodes, bounds, lane_nodes[lane])
            };
        }
        self.words[start + ROWS * k..start + (ROWS + 1) * k].copy_from_slice(&links[..k]);
        ((k / 2) as u32) << WIDTH_SHIFT | start as u32
    }

    /// The block that `link` leads to: its lanes' importances at `ctx` (of the lanes it
    /// has) and the 8 words from its links (of the lanes it has).
    #[inline(always)]
    fn weigh<const AVX2: bool>(
        &self,
        link: u32,
        ctx: &ShadingCtx,
    ) -> ([f32; LANES], &[u32; LANES]) {
        let at = (link & OFFSET_MASK) as usize;
        match link >> WIDTH_SHIFT {
            1 => self.weigh_block::<2, AVX2>(at, ctx),
            2 => self.weigh_block::<4, AVX2>(at, ctx),
            _ => self.weigh_block::<6, AVX2>(at, ctx),
        }
    }

    /// [`Self::weigh`] for a block of `K` lanes at word `at`.
    #[inline(always)]
    fn weigh_block<const K: usize, const AVX2: bool>(
        &self,
        at: usize,
        ctx: &ShadingCtx,
    ) -> ([f32; LANES], &[u32; LANES]) {
        let block = &self.words[at..at + span(K)];
        let links: &[u32; LANES] = block[ROWS * K..].try_into().expect("span(K) − ROWS·K");
        #[cfg(target_arch = "x86_64")]
        if AVX2 {
            // SAFETY: AVX2 is only requested where the CPU has it.
            return (unsafe { weigh_avx2::<K>(block, ctx) }, links);
        }
        (weigh_scalar::<K>(block, ctx), links)
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
        self.sample_by::<false>(ctx, u, pmf)
    }

    /// [`Self::sample`] in AVX2 code, the lanes' evaluation inlined (the point's splats
    /// and the test of its normal then come once a descent rather than once a block).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2")]
    fn sample_avx2(&self, ctx: &ShadingCtx, u: f32, pmf: f32) -> Option<(u32, f32)> {
        self.sample_by::<true>(ctx, u, pmf)
    }

    /// The descent of [`Self::sample`], the blocks weighed in AVX2 where `AVX2`.
    #[inline(always)]
    fn sample_by<const AVX2: bool>(
        &self,
        ctx: &ShadingCtx,
        mut u: f32,
        mut pmf: f32,
    ) -> Option<(u32, f32)> {
        let mut link = self.root;
        loop {
            let (w, links) = self.weigh::<AVX2>(link, ctx);
            let first = choose(w[0], w[1], &mut u, &mut pmf)?;
            let child = links[first];
            if let Some(light) = leaf(child) {
                return Some((light, pmf));
            }
            // The lane of the child's first child: 2 or 4 (the mask spares bound checks).
            let lane = child as usize & 6;
            let second = choose(w[lane], w[lane + 1], &mut u, &mut pmf)?;
            link = links[lane + second];
            if let Some(light) = leaf(link) {
                return Some((light, pmf));
            }
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
        self.pmf_by::<false>(ctx, trail, pmf)
    }

    /// [`Self::pmf`] in AVX2 code, as [`Self::sample_avx2`].
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2")]
    fn pmf_avx2(&self, ctx: &ShadingCtx, trail: u64, pmf: f32) -> f32 {
        self.pmf_by::<true>(ctx, trail, pmf)
    }

    /// The retrace of [`Self::pmf`], the blocks weighed in AVX2 where `AVX2`.
    #[inline(always)]
    fn pmf_by<const AVX2: bool>(&self, ctx: &ShadingCtx, trail: u64, mut pmf: f32) -> f32 {
        let depth = 63 - trail.leading_zeros();
        let branch = |level: u32| ((trail >> level) & 1) as usize;
        let taken = |p: f32, branch: usize| if branch == 0 { p } else { 1.0 - p };
        let mut link = self.root;
        let mut level = 0;
        loop {
            let (w, links) = self.weigh::<AVX2>(link, ctx);
            let first = branch(level);
            let Some(pa) = first_probability(w[0], w[1]) else {
                return 0.0;
            };
            pmf *= taken(pa, first);
            if level + 1 == depth {
                return pmf;
            }
            let lane = links[first] as usize & 6;
            let second = branch(level + 1);
            let Some(pb) = first_probability(w[lane], w[lane + 1]) else {
                return 0.0;
            };
            pmf *= taken(pb, second);
            if level + 2 == depth {
                return pmf;
            }
            level += 2;
            link = links[lane + second];
        }
    }

    /// The light at the end of `trail` (as [`Self::pmf`] takes it), by the blocks' links;
    /// `None` where the trail ends at an interior node or runs past a leaf.
    #[cfg(test)]
    pub fn light_at(&self, trail: u64) -> Option<u32> {
        let depth = 63 - trail.leading_zeros();
        let branch = |level: u32| ((trail >> level) & 1) as usize;
        let mut link = self.root;
        let mut level = 0;
        loop {
            let k = 2 * (link >> WIDTH_SHIFT) as usize;
            let at = (link & OFFSET_MASK) as usize;
            let links = &self.words[at + ROWS * k..at + (ROWS + 1) * k];
            let child = links[branch(level)];
            if let Some(light) = leaf(child) {
                return (level + 1 == depth).then_some(light);
            }
            if level + 1 >= depth {
                return None;
            }
            link = links[child as usize + branch(level + 1)];
            if let Some(light) = leaf(link) {
                return (level + 2 == depth).then_some(light);
            }
            if level + 2 >= depth {
                return None;
            }
            level += 2;
        }
    }

    /// Bytes held.
    pub fn memory_bytes(&self) -> usize {
        self.words.len() * size_of::<u32>()
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
            // Each node but the root in one lane of 11 words, and the padding.
            assert_eq!(
                descent.memory_bytes(),
                4 * (11 * (2 * n as usize - 2) + LANES)
            );
            for (light, &trail) in trails.iter().enumerate() {
                assert_eq!(descent.light_at(trail), Some(light as u32), "round {round}");
                // A trail cut short ends at an interior node.
                let depth = 63 - trail.leading_zeros();
                let short = (trail & ((1 << (depth - 1)) - 1)) | (1 << (depth - 1));
                assert_eq!(descent.light_at(short), None, "round {round}");
            }
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
                let scalar = descent.sample_by::<false>(&ctx, u, p0);
                assert_eq!(bits(scalar), bits(want), "round {round}, point {k}");
                match got {
                    Some((light, p)) => {
                        picks += 1;
                        let back = descent.pmf(&ctx, trails[light as usize], p0);
                        assert_eq!(back.to_bits(), p.to_bits(), "round {round}, point {k}");
                        let scalar = descent.pmf_by::<false>(&ctx, trails[light as usize], p0);
                        assert_eq!(scalar.to_bits(), p.to_bits(), "round {round}, point {k}");
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
