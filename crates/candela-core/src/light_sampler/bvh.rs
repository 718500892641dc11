//! A light BVH (Conty Estevez & Kulla 2018; pbrt-v4 §12.6.3): lights grouped into a
//! binary tree whose nodes carry [`LightBounds`]; sampling descends from the root,
//! choosing each child in proportion to its importance at the shading point, in
//! O(log N). The pick probability is the product of the choices along the way, which
//! [`LightBvh::pmf`] retraces from a per-light bit trail. The descent weighs two levels
//! (a node's children and grandchildren) in one 8-lane evaluation ([`Descent`]). A tree
//! of at most [`FLAT_MAX`] lights is not descended: each light is picked by its own
//! bounds' importance, for the cost of one level's evaluation (on
//! `scenes/ies-room.toml`, six lights, 0.74× the descent's variance at equal spp:
//! bench/RESULTS.md, light_sampler).
//!
//! Lights without bounds (infinite lights) are kept apart and picked with probability
//! n_inf / (n_inf + 1), the tree counting as one more "light" (as pbrt does); among
//! themselves by their importance at the point ([`InfiniteImportance`]: a sun is picked
//! over a sky where it gives more light), where pbrt picks them uniformly.

use rayon::join;

use super::descent::{Descent, TreeNode};
use super::flat::{positive_finite, FlatLights};
use crate::light::{
    cone_measure, ImportanceBounds, InfiniteImportance, Light, LightBounds, ShadingCtx, LANES,
};
use crate::sampling::ONE_MINUS_EPSILON;

/// Buckets per split candidate of the build.
const BUCKETS: usize = 12;
/// Subtrees with more lights than this are built in parallel.
const PARALLEL_MIN: usize = 4096;
/// Nodes of at most this many lights split at the median of the longest axis: the SAOH
/// evaluation per node costs ~50 transcendental calls, and most nodes are small.
const MEDIAN_MAX: usize = 8;
/// Beyond this depth splits fall back to the median, so that trails fit in 64 bits.
const MAX_SAOH_DEPTH: u32 = 40;
/// Trees of at most this many lights are sampled flat: every light by its own importance
/// at the point, in one pass over the leaves, instead of a descent through clusters whose
/// bounds blur their members' (see [`LightBvh::sample`]).
pub const FLAT_MAX: usize = LANES;
/// At most this many infinite lights are picked by their importance at the point (see
/// [`LightBvh::new`]).
const INFINITE_MAX: usize = 8;

#[derive(Clone, Copy, Debug)]
struct Node {
    bounds: LightBounds,
    /// Leaf: the light. Interior: the second child (the first follows the node).
    index: u32,
    is_leaf: bool,
}

/// A light BVH over the bounded lights, plus the unbounded ones.
#[derive(Clone, Debug, Default)]
pub struct LightBvh {
    /// The shape of a flat tree (see `flat`, which holds its bounds); empty where the
    /// tree is descended (its shape is in `descent`'s links).
    nodes: Vec<TreeNode>,
    /// See [`Self::tree_probability`].
    p_tree: f32,
    infinite: Vec<u32>,
    /// Per infinite light, what weighs it at a point; empty where some infinite light
    /// has no such measure, or there are fewer than 2 or more than [`INFINITE_MAX`]
    /// (then they are picked uniformly).
    infinite_importance: Vec<InfiniteImportance>,
    /// Per light: the branch taken at each level (bit d = level d, 1 = second child),
    /// with a leading 1 marking the depth; 0 where the light is not in the tree.
    trails: Vec<u64>,
    /// Where the tree has at most [`FLAT_MAX`] lights: its leaves, which sampling weighs
    /// directly.
    flat: Option<FlatLights>,
    /// Where the tree has more than [`FLAT_MAX`] lights: its nodes' bounds in the blocks
    /// that the descent evaluates two levels at a time.
    descent: Option<Descent>,
}

struct Item {
    bounds: LightBounds,
    centroid: glam::Vec3,
    light: u32,
}

impl LightBvh {
    /// The probability of picking the tree rather than one of `infinite` infinite lights
    /// (1/(n + 1), the tree counting as one more light; 0 without a tree).
    fn tree_probability(has_tree: bool, infinite: usize) -> f32 {
        if has_tree {
            1.0 / (infinite as f32 + 1.0)
        } else {
            0.0
        }
    }

    /// The tree over `lights`; `None` where no light emits.
    pub fn new(lights: &[Light]) -> Option<LightBvh> {
        let mut items = Vec::new();
        let mut infinite = Vec::new();
        for (i, l) in lights.iter().enumerate() {
            match l.bounds() {
                // Lights that emit nothing are never worth a shadow ray.
                Some(b) if b.intensity > 0.0 && b.intensity.is_finite() => items.push(Item {
                    centroid: b.centroid(),
                    bounds: b,
                    light: i as u32,
                }),
                Some(_) => {}
                None => infinite.push(i as u32),
            }
        }
        if items.is_empty() && infinite.is_empty() {
            return None;
        }
        // Weighed picks among 2 to INFINITE_MAX infinite lights (more are unheard of and
        // picked uniformly, which keeps the weights on the stack).
        let infinite_importance = if (2..=INFINITE_MAX).contains(&infinite.len()) {
            infinite
                .iter()
                .map(|&i| lights[i as usize].infinite_importance())
                .collect::<Option<Vec<_>>>()
                .unwrap_or_default()
        } else {
            Vec::new()
        };
        let mut bvh = LightBvh {
            p_tree: Self::tree_probability(!items.is_empty(), infinite.len()),
            nodes: Vec::new(),
            infinite,
            infinite_importance,
            trails: vec![0; lights.len()],
            flat: None,
            descent: None,
        };
        if !items.is_empty() {
            // A subtree over n lights has exactly 2n − 1 nodes, so every subtree's place in
            // the depth-first array is known before it is built: the build writes into
            // disjoint slices in parallel, without an intermediate tree.
            let dummy = Node {
                bounds: items[0].bounds,
                index: 0,
                is_leaf: true,
            };
            let mut nodes = vec![dummy; 2 * items.len() - 1];
            build(&mut items, 0, &mut nodes, 0);
            drop(items);
            let bounds: Vec<ImportanceBounds> = nodes
                .iter()
                .map(|n| ImportanceBounds::new(&n.bounds))
                .collect();
            bvh.nodes = nodes
                .iter()
                .map(|n| TreeNode {
                    index: n.index,
                    is_leaf: n.is_leaf,
                })
                .collect();
            bvh.set_trails();
            // A tree of n lights has 2n − 1 nodes.
            if bvh.nodes.len() < 2 * FLAT_MAX {
                let leaves: Vec<usize> = (0..bvh.nodes.len())
                    .filter(|&i| bvh.nodes[i].is_leaf)
                    .collect();
                let ids: Vec<u32> = leaves.iter().map(|&i| bvh.nodes[i].index).collect();
                let leaf_bounds: Vec<ImportanceBounds> =
                    leaves.iter().map(|&i| bounds[i]).collect();
                bvh.flat = Some(FlatLights::new(&ids, &leaf_bounds));
            } else {
                bvh.descent = Some(Descent::new(&bvh.nodes, &bounds));
                bvh.nodes = Vec::new();
            }
        }
        Some(bvh)
    }

    /// Records, for every light in the tree, the branches from the root to its leaf.
    fn set_trails(&mut self) {
        let mut stack = vec![(0usize, 1u64)];
        while let Some((at, trail)) = stack.pop() {
            let node = &self.nodes[at];
            if node.is_leaf {
                self.trails[node.index as usize] = trail;
                continue;
            }
            // Move the depth marker one bit up; the bit it leaves is the branch.
            let depth = 63 - trail.leading_zeros();
            let child = (trail & !(1 << depth)) | (1 << (depth + 1));
            stack.push((at + 1, child));
            stack.push((node.index as usize, child | (1 << depth)));
        }
    }

    /// Probability of picking the tree rather than an infinite light.
    #[inline]
    fn p_tree(&self) -> f32 {
        self.p_tree
    }

    /// A light and its probability at `ctx`; `None` where no light in the tree can reach
    /// the point (and there are no infinite lights).
    ///
    /// A flat tree without infinite lights, most scenes' few lamps, is sampled here, inlined
    /// into the caller (the render loop's AVX2 copy, which then inlines the lanes'
    /// evaluation too); the rest out of line. There the tree is picked with probability 1
    /// and `u` passes unchanged: the same numbers as `Self::sample_general`'s
    /// `(u − 0) / 1` and `1 · p`.
    #[inline]
    pub fn sample(&self, ctx: &ShadingCtx, u: f32) -> Option<(u32, f32)> {
        match &self.flat {
            Some(flat) if self.infinite.is_empty() => flat.sample(ctx, u.min(ONE_MINUS_EPSILON)),
            _ => self.sample_general(ctx, u),
        }
    }

    /// [`Self::sample`] in general: an infinite light or the tree, then within the tree.
    #[inline(never)]
    fn sample_general(&self, ctx: &ShadingCtx, mut u: f32) -> Option<(u32, f32)> {
        let p_tree = self.p_tree();
        let p_inf = 1.0 - p_tree;
        if u < p_inf {
            let (i, p) = self.pick_infinite(ctx, (u / p_inf).min(ONE_MINUS_EPSILON));
            return Some((self.infinite[i], p_inf * p));
        }
        u = ((u - p_inf) / p_tree).min(ONE_MINUS_EPSILON);
        if let Some(flat) = &self.flat {
            return flat.sample(ctx, u).map(|(i, p)| (i, p_tree * p));
        }
        self.descent.as_ref()?.sample(ctx, u, p_tree)
    }

    /// Probability that [`Self::sample`] picks `light` at `ctx`; inlined for a flat tree
    /// without infinite lights, as [`Self::sample`] (a light outside the tree gets 0 there
    /// too: the flat pick does not hold it).
    #[inline]
    pub fn pmf(&self, ctx: &ShadingCtx, light: u32) -> f32 {
        match &self.flat {
            Some(flat) if self.infinite.is_empty() => flat.pmf(ctx, light),
            _ => self.pmf_general(ctx, light),
        }
    }

    /// [`Self::pmf`] in general.
    #[inline(never)]
    fn pmf_general(&self, ctx: &ShadingCtx, light: u32) -> f32 {
        let trail = self.trails[light as usize];
        if trail == 0 {
            return match self.infinite.iter().position(|&l| l == light) {
                Some(i) => (1.0 - self.p_tree()) * self.infinite_pmf(ctx, i),
                None => 0.0,
            };
        }
        if let Some(flat) = &self.flat {
            return self.p_tree() * flat.pmf(ctx, light);
        }
        match &self.descent {
            Some(d) => d.pmf(ctx, trail, self.p_tree()),
            None => 0.0,
        }
    }

    /// The importances of the infinite lights at `ctx` (the first `infinite.len()`
    /// entries) and their sum, or `None` where they are to be picked uniformly (no
    /// measures, or nothing positive).
    #[inline(always)]
    fn infinite_weights(&self, ctx: &ShadingCtx) -> Option<([f32; INFINITE_MAX], f32)> {
        if self.infinite_importance.is_empty() {
            return None;
        }
        let mut w = [0.0f32; INFINITE_MAX];
        let mut total = 0.0f32;
        for (w, m) in w.iter_mut().zip(&self.infinite_importance) {
            *w = m.at(ctx).max(0.0);
            total += *w;
        }
        positive_finite(total).then_some((w, total))
    }

    /// One of the infinite lights (its index in `infinite`) and its probability among
    /// them, from `u ∈ [0, 1)`.
    fn pick_infinite(&self, ctx: &ShadingCtx, u: f32) -> (usize, f32) {
        let n = self.infinite.len();
        let Some((weights, total)) = self.infinite_weights(ctx) else {
            return (((u * n as f32) as usize).min(n - 1), 1.0 / n as f32);
        };
        let target = u * total;
        let mut acc = 0.0;
        let mut last = (0, 0.0);
        for (i, &w) in weights[..n].iter().enumerate() {
            if w > 0.0 {
                last = (i, w / total);
                acc += w;
                if target < acc {
                    break;
                }
            }
        }
        last
    }

    /// Probability that [`Self::pick_infinite`] picks infinite light `i` at `ctx`.
    fn infinite_pmf(&self, ctx: &ShadingCtx, i: usize) -> f32 {
        match self.infinite_weights(ctx) {
            Some((weights, total)) => weights.get(i).map_or(0.0, |w| w / total),
            None => 1.0 / self.infinite.len() as f32,
        }
    }

    /// Bytes held, for the benchmark's memory note.
    pub fn memory_bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<TreeNode>()
            + 8 * self.trails.len()
            + self.flat.as_ref().map_or(0, FlatLights::memory_bytes)
            + self.descent.as_ref().map_or(0, Descent::memory_bytes)
    }
}

/// SAOH cost of a cluster (pbrt-v4's `EvaluateCost`): intensity × orientation measure
/// × surface area, with a regularizer against thin slabs along the split axis.
fn cost(b: &LightBounds, kr: f32) -> f32 {
    b.intensity * cone_measure(b.cos_theta_o, b.cos_theta_e) * b.aabb.surface_area() * kr
}

/// Builds the subtree over `items` into `nodes` (exactly 2·len − 1 of them), whose first
/// node has index `base` in the whole array.
fn build(items: &mut [Item], depth: u32, nodes: &mut [Node], base: u32) {
    if items.len() == 1 {
        nodes[0] = Node {
            bounds: items[0].bounds,
            index: items[0].light,
            is_leaf: true,
        };
        return;
    }
    let mid = split(items, depth);
    let (left, right) = items.split_at_mut(mid);
    let (head, rest) = nodes.split_at_mut(1);
    let (left_nodes, right_nodes) = rest.split_at_mut(2 * mid - 1);
    let right_base = base + 2 * mid as u32;
    if left.len() + right.len() > PARALLEL_MIN {
        join(
            || build(left, depth + 1, left_nodes, base + 1),
            || build(right, depth + 1, right_nodes, right_base),
        );
    } else {
        build(left, depth + 1, left_nodes, base + 1);
        build(right, depth + 1, right_nodes, right_base);
    }
    head[0] = Node {
        bounds: LightBounds::union(&left_nodes[0].bounds, &right_nodes[0].bounds),
        index: right_base,
        is_leaf: false,
    };
}

/// cos of the half-angle of the smallest cone about `axis` that holds the cone (`w`,
/// `cos_t`): cos(∠(axis, w) + θ), or −1 past π; widened by a hair against round-off.
fn cos_containing(axis: glam::Vec3, w: glam::Vec3, cos_t: f32) -> f32 {
    let c = axis.dot(w).clamp(-1.0, 1.0);
    if cos_t < -c {
        return -1.0;
    }
    let s = (1.0 - c * c).max(0.0).sqrt();
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    (c * cos_t - s * sin_t - 1e-5).max(-1.0)
}

/// Reorders `items` and returns the split point: the cheapest bucket boundary by SAOH
/// along the longest axis of the centroids, or the median where that fails.
fn split(items: &mut [Item], depth: u32) -> usize {
    let n = items.len();
    let median = |items: &mut [Item], axis: usize| {
        items.select_nth_unstable_by(n / 2, |a, b| a.centroid[axis].total_cmp(&b.centroid[axis]));
        n / 2
    };
    let (lo, hi) = items.iter().fold(
        (glam::Vec3::INFINITY, glam::Vec3::NEG_INFINITY),
        |(lo, hi), it| (lo.min(it.centroid), hi.max(it.centroid)),
    );
    let ext = hi - lo;
    let axis = if ext.x >= ext.y && ext.x >= ext.z {
        0
    } else if ext.y >= ext.z {
        1
    } else {
        2
    };
    if ext[axis] <= 0.0 || depth >= MAX_SAOH_DEPTH || n <= MEDIAN_MAX {
        return median(items, axis);
    }
    let bucket_of = |c: glam::Vec3| {
        (((c[axis] - lo[axis]) / ext[axis] * BUCKETS as f32) as usize).min(BUCKETS - 1)
    };
    // Bucket bounds in two passes without trigonometry (the pairwise cone union costs
    // three arccosines, and this loop runs N times per tree level): first boxes, sums and
    // the mean normal direction, then each bucket's cone about that mean, wide enough to
    // hold every member's cone.
    let mut buckets: [Option<LightBounds>; BUCKETS] = [None; BUCKETS];
    let mut axis_sum = [glam::Vec3::ZERO; BUCKETS];
    for it in items.iter() {
        let k = bucket_of(it.centroid);
        axis_sum[k] += it.bounds.w;
        let b = &mut buckets[k];
        *b = Some(match b {
            Some(acc) => LightBounds {
                aabb: acc.aabb.union(it.bounds.aabb),
                intensity: acc.intensity + it.bounds.intensity,
                cos_theta_e: acc.cos_theta_e.min(it.bounds.cos_theta_e),
                two_sided: acc.two_sided || it.bounds.two_sided,
                ..*acc
            },
            None => LightBounds {
                cos_theta_o: 1.0,
                ..it.bounds
            },
        });
    }
    for (b, sum) in buckets.iter_mut().zip(axis_sum) {
        if let Some(b) = b {
            b.w = sum.try_normalize().unwrap_or(glam::Vec3::Z);
        }
    }
    for it in items.iter() {
        let b = buckets[bucket_of(it.centroid)]
            .as_mut()
            .expect("filled above");
        b.cos_theta_o = b
            .cos_theta_o
            .min(cos_containing(b.w, it.bounds.w, it.bounds.cos_theta_o));
    }
    let whole = buckets
        .iter()
        .flatten()
        .fold(crate::geometry::Aabb::EMPTY, |acc, b| acc.union(b.aabb));
    let diag = whole.extent();
    let kr = diag.max_element() / diag[axis].max(f32::MIN_POSITIVE);
    // Bounds of buckets [0, cut) from a forward sweep, of [cut, BUCKETS) from a backward
    // one: 2·BUCKETS unions per node.
    let sweep = |order: &mut dyn Iterator<Item = usize>| {
        let mut acc: Option<LightBounds> = None;
        let mut out = [None; BUCKETS];
        for b in order {
            if let Some(x) = &buckets[b] {
                acc = Some(acc.map_or(*x, |a| LightBounds::union(&a, x)));
            }
            out[b] = acc;
        }
        out
    };
    let below = sweep(&mut (0..BUCKETS));
    let above = sweep(&mut (0..BUCKETS).rev());
    let mut best = (f32::INFINITY, 0usize);
    for cut in 1..BUCKETS {
        let (Some(a), Some(b)) = (below[cut - 1], above[cut]) else {
            continue;
        };
        let c = cost(&a, kr) + cost(&b, kr);
        if c < best.0 {
            best = (c, cut);
        }
    }
    if !best.0.is_finite() {
        return median(items, axis);
    }
    // Partition in place: lights of buckets below the cut first.
    let mut i = 0;
    for j in 0..n {
        if bucket_of(items[j].centroid) < best.1 {
            items.swap(i, j);
            i += 1;
        }
    }
    if i == 0 || i == n {
        median(items, axis)
    } else {
        i
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::{PointLight, TriangleLight};
    use glam::Vec3;

    #[test]
    fn trails_lead_back_to_their_leaves() {
        let lights: Vec<Light> = (0..37)
            .map(|i| {
                Light::Point(PointLight {
                    position: Vec3::new(i as f32, (i * 7 % 5) as f32, 0.0),
                    intensity: Vec3::splat(1.0 + i as f32),
                })
            })
            .collect();
        let bvh = LightBvh::new(&lights).unwrap();
        let descent = bvh.descent.as_ref().expect("more lights than FLAT_MAX");
        for (i, &trail) in bvh.trails.iter().enumerate() {
            assert_eq!(descent.light_at(trail), Some(i as u32));
        }
    }

    #[test]
    fn lights_behind_the_point_get_zero_only_when_they_cannot_reach_it() {
        // Two one-sided triangles facing +y at y = 0 and a point below them: zero.
        let tri = |x: f32| {
            Light::Triangle(TriangleLight::new(
                [
                    Vec3::new(x, 0.0, 0.0),
                    Vec3::new(x + 1.0, 0.0, 1.0),
                    Vec3::new(x + 1.0, 0.0, 0.0),
                ],
                Vec3::Y,
                Vec3::ONE,
            ))
        };
        let bvh = LightBvh::new(&[tri(0.0), tri(3.0)]).unwrap();
        let below = ShadingCtx {
            p: Vec3::new(1.0, -1.0, 0.5),
            n: Vec3::ZERO,
        };
        assert!(bvh.sample(&below, 0.3).is_none());
        let above = ShadingCtx {
            p: Vec3::new(1.0, 1.0, 0.5),
            n: Vec3::ZERO,
        };
        let total = bvh.pmf(&above, 0) + bvh.pmf(&above, 1);
        assert!((total - 1.0).abs() < 1e-6);
        assert!(bvh.pmf(&above, 0) > bvh.pmf(&above, 1));
    }
}
