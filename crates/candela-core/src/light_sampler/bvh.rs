//! A light BVH (Conty Estevez & Kulla 2018; pbrt-v4 §12.6.3): lights grouped into a
//! binary tree whose nodes carry [`LightBounds`]; sampling descends from the root,
//! choosing each child in proportion to its importance at the shading point, in
//! O(log N). The pick probability is the product of the choices along the way, which
//! [`LightBvh::pmf`] retraces from a per-light bit trail.
//!
//! Lights without bounds (infinite lights) are kept apart and picked uniformly with
//! probability n_inf / (n_inf + 1), the tree counting as one more "light" (as pbrt does).

use rayon::join;

use crate::light::{cone_measure, Light, LightBounds, ShadingCtx};
use crate::sampling::ONE_MINUS_EPSILON;

/// Buckets per split candidate of the build.
const BUCKETS: usize = 12;
/// Subtrees with more lights than this are built in parallel.
const PARALLEL_MIN: usize = 4096;
/// Beyond this depth splits fall back to the median, so that trails fit in 64 bits.
const MAX_SAOH_DEPTH: u32 = 40;

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
    nodes: Vec<Node>,
    infinite: Vec<u32>,
    /// Per light: the branch taken at each level (bit d = level d, 1 = second child),
    /// with a leading 1 marking the depth; 0 where the light is not in the tree.
    trails: Vec<u64>,
}

/// A node under construction.
enum Tree {
    Leaf(LightBounds, u32),
    Interior(LightBounds, Box<Tree>, Box<Tree>),
}

struct Item {
    bounds: LightBounds,
    centroid: glam::Vec3,
    light: u32,
}

impl LightBvh {
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
        let mut bvh = LightBvh {
            nodes: Vec::with_capacity(2 * items.len()),
            infinite,
            trails: vec![0; lights.len()],
        };
        if !items.is_empty() {
            let tree = build(&mut items, 0);
            bvh.flatten(tree, 1);
        }
        Some(bvh)
    }

    fn flatten(&mut self, tree: Tree, trail: u64) {
        match tree {
            Tree::Leaf(bounds, light) => {
                self.trails[light as usize] = trail;
                self.nodes.push(Node {
                    bounds,
                    index: light,
                    is_leaf: true,
                });
            }
            Tree::Interior(bounds, a, b) => {
                let at = self.nodes.len();
                self.nodes.push(Node {
                    bounds,
                    index: 0,
                    is_leaf: false,
                });
                // Move the depth marker one bit up; the bit it leaves is the branch.
                let depth = 63 - trail.leading_zeros();
                let child = (trail & !(1 << depth)) | (1 << (depth + 1));
                self.flatten(*a, child);
                self.nodes[at].index = self.nodes.len() as u32;
                self.flatten(*b, child | (1 << depth));
            }
        }
    }

    /// Probability of picking the tree rather than an infinite light.
    fn p_tree(&self) -> f32 {
        if self.nodes.is_empty() {
            0.0
        } else {
            1.0 / (self.infinite.len() as f32 + 1.0)
        }
    }

    /// A light and its probability at `ctx`; `None` where no light in the tree can reach
    /// the point (and there are no infinite lights).
    pub fn sample(&self, ctx: &ShadingCtx, mut u: f32) -> Option<(u32, f32)> {
        let p_tree = self.p_tree();
        let p_inf = 1.0 - p_tree;
        if u < p_inf {
            let n = self.infinite.len();
            let i = ((u / p_inf * n as f32) as usize).min(n - 1);
            return Some((self.infinite[i], p_inf / n as f32));
        }
        u = ((u - p_inf) / p_tree).min(ONE_MINUS_EPSILON);
        let mut pmf = p_tree;
        let mut at = 0usize;
        loop {
            let node = &self.nodes[at];
            if node.is_leaf {
                // A single light whose bounds say it cannot reach the point.
                return (at > 0 || node.bounds.importance(ctx) > 0.0).then_some((node.index, pmf));
            }
            let (a, b) = (at + 1, node.index as usize);
            let ia = self.nodes[a].bounds.importance(ctx);
            let ib = self.nodes[b].bounds.importance(ctx);
            if !(ia + ib > 0.0) {
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

    /// Probability that [`Self::sample`] picks `light` at `ctx`.
    pub fn pmf(&self, ctx: &ShadingCtx, light: u32) -> f32 {
        let trail = self.trails[light as usize];
        if trail == 0 {
            return match self.infinite.contains(&light) {
                true => (1.0 - self.p_tree()) / self.infinite.len() as f32,
                false => 0.0,
            };
        }
        let depth = 63 - trail.leading_zeros();
        let mut pmf = self.p_tree();
        let mut at = 0usize;
        for level in 0..depth {
            let node = &self.nodes[at];
            let (a, b) = (at + 1, node.index as usize);
            let ia = self.nodes[a].bounds.importance(ctx);
            let ib = self.nodes[b].bounds.importance(ctx);
            if !(ia + ib > 0.0) {
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
        if depth == 0 && self.nodes[0].bounds.importance(ctx) <= 0.0 {
            return 0.0;
        }
        pmf
    }

    /// Bytes held, for the benchmark's memory note.
    pub fn memory_bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<Node>() + 8 * self.trails.len()
    }

    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }
}

/// SAOH cost of a cluster (pbrt-v4's `EvaluateCost`): intensity × orientation measure
/// × surface area, with a regularizer against thin slabs along the split axis.
fn cost(b: &LightBounds, kr: f32) -> f32 {
    b.intensity * cone_measure(b.cos_theta_o, b.cos_theta_e) * b.aabb.surface_area() * kr
}

fn build(items: &mut [Item], depth: u32) -> Tree {
    if items.len() == 1 {
        return Tree::Leaf(items[0].bounds, items[0].light);
    }
    let mid = split(items, depth);
    let (left, right) = items.split_at_mut(mid);
    let (a, b) = if left.len() + right.len() > PARALLEL_MIN {
        join(|| build(left, depth + 1), || build(right, depth + 1))
    } else {
        (build(left, depth + 1), build(right, depth + 1))
    };
    let bounds = LightBounds::union(bounds_of(&a), bounds_of(&b));
    Tree::Interior(bounds, Box::new(a), Box::new(b))
}

fn bounds_of(t: &Tree) -> &LightBounds {
    match t {
        Tree::Leaf(b, _) | Tree::Interior(b, _, _) => b,
    }
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
    if ext[axis] <= 0.0 || depth >= MAX_SAOH_DEPTH || n <= 2 {
        return median(items, axis);
    }
    let bucket_of = |c: glam::Vec3| {
        (((c[axis] - lo[axis]) / ext[axis] * BUCKETS as f32) as usize).min(BUCKETS - 1)
    };
    let mut buckets: [Option<LightBounds>; BUCKETS] = [None; BUCKETS];
    for it in items.iter() {
        let b = &mut buckets[bucket_of(it.centroid)];
        *b = Some(match b {
            Some(acc) => LightBounds::union(acc, &it.bounds),
            None => it.bounds,
        });
    }
    let whole = buckets
        .iter()
        .flatten()
        .copied()
        .reduce(|a, b| LightBounds::union(&a, &b))
        .expect("at least one light");
    let diag = whole.aabb.extent();
    let kr = diag.max_element() / diag[axis].max(f32::MIN_POSITIVE);
    let merge = |bs: &[Option<LightBounds>]| {
        bs.iter()
            .flatten()
            .copied()
            .reduce(|a, b| LightBounds::union(&a, &b))
    };
    let mut best = (f32::INFINITY, 0usize);
    for cut in 1..BUCKETS {
        let (Some(a), Some(b)) = (merge(&buckets[..cut]), merge(&buckets[cut..])) else {
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
        assert_eq!(bvh.node_count(), 2 * lights.len() - 1);
        for (i, &trail) in bvh.trails.iter().enumerate() {
            let depth = 63 - trail.leading_zeros();
            let mut at = 0usize;
            for level in 0..depth {
                let node = &bvh.nodes[at];
                assert!(!node.is_leaf);
                at = if trail & (1 << level) == 0 {
                    at + 1
                } else {
                    node.index as usize
                };
            }
            assert!(bvh.nodes[at].is_leaf);
            assert_eq!(bvh.nodes[at].index, i as u32);
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
