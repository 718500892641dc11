//! The binary BVH, built with the binned surface area heuristic (Wald 2007, "On fast
//! Construction of SAH-based Bounding Volume Hierarchies"). Rendering traces the
//! [`super::WideBvh`] collapsed from it; its own traversal, one box at a time, is the
//! reference the tests compare against.

use glam::Vec3A;
use std::sync::Mutex;

use rayon::prelude::*;

use super::extents::{Box3A, Extents, PrimInfo};

use super::box8::T_MAX_SCALE;
use crate::geometry::{Aabb, Ray};

const BINS: usize = 16;
/// Subtrees larger than this are built in parallel.
const PARALLEL_THRESHOLD: usize = 4096;
/// From this depth on, splits fall back to the median, so that no tree is deeper than
/// about `MAX_SAH_DEPTH + log2(n)` and the traversal stacks cannot overflow.
const MAX_SAH_DEPTH: usize = 48;

/// A node of the flattened tree. An interior node's first child follows it directly and
/// `offset` is its second child; a leaf holds `count` primitives from `offset` on.
#[derive(Clone, Copy, Debug)]
pub struct BvhNode {
    pub bounds: Aabb,
    pub offset: u32,
    pub count: u16,
    pub axis: u8,
}

impl BvhNode {
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }
}

/// How the SAH sizes leaves. Nodes of more than `max_leaf` primitives are always split,
/// by the usual cost (primitives × box area on each side). A smaller node is tested as
/// one block whatever its count (the accelerator's [`crate::accel`] blocks hold up to
/// `max_leaf`), so it is split only where two blocks, each weighted by its box area, and
/// `node` more (a binary node, in block tests) cost less than one.
#[derive(Clone, Copy, Debug)]
pub struct SahCost {
    pub max_leaf: usize,
    /// From 1 on (two children cost at least as much as one block) no split of a small
    /// node pays, and their SAH sweep is skipped.
    pub node: f32,
}

impl SahCost {
    /// Leaves of up to four, never split: the binary tree's own traversal (its tests,
    /// and the instance TLAS, whose leaves are instances).
    pub const PRIMS: SahCost = SahCost {
        max_leaf: 4,
        node: 1.0,
    };

    /// Eight-lane blocks (the scene's [`crate::accel::Accel`]). A node costs nothing
    /// here: the collapse to eight-wide nodes absorbs binary nodes. Measured with the
    /// first eight-lane kernel (callgrind instructions per closest-hit ray,
    /// bench/traversal.sh's rays): a node cost of 0
    /// gave 674 on the Cornell box, 0.5 gave 781, the 590k room 1606 and 1598; pricing
    /// large nodes by blocks (⌈n / 8⌉ × area) instead of primitives gave 756 at 0.
    pub const BLOCKS: SahCost = SahCost {
        max_leaf: 8,
        node: 0.0,
    };
}

#[derive(Clone, Debug, Default)]
pub struct Bvh {
    pub nodes: Vec<BvhNode>,
    /// Primitive indices in leaf order.
    pub prims: Vec<u32>,
}

/// The top of a build, over nodes of more than [`PARALLEL_THRESHOLD`] primitives, whose
/// halves are built in parallel; below it, each subtree is built by one thread, laid out
/// depth first, and appended whole to the build's node store ([`Chunk`]). Only these few
/// top nodes are allocated one by one, so the build holds no allocation per node (which
/// left a freed heap of about 29 bytes a triangle resident after the build: 8M-triangle
/// height field, 1515 MB peak before).
enum Top {
    Interior {
        bounds: Aabb,
        axis: u8,
        children: Box<[Top; 2]>,
    },
    Chunk(Chunk),
}

/// A subtree in the node store: `len` nodes from `at` on, depth first, with interior
/// nodes' `offset` counted from `at` (leaves' from the start of the primitives).
struct Chunk {
    at: usize,
    len: usize,
}

impl Top {
    fn node_count(&self) -> usize {
        match self {
            Top::Interior { children, .. } => {
                1 + children[0].node_count() + children[1].node_count()
            }
            Top::Chunk(c) => c.len,
        }
    }
}

impl Bvh {
    /// Builds a BVH over primitives with the given boxes, leaves sized for
    /// [`SahCost::PRIMS`]. Primitives with empty or non-finite boxes are left out: no ray
    /// can hit them.
    pub fn build(boxes: &[Aabb]) -> Bvh {
        Bvh::build_with(boxes, SahCost::PRIMS)
    }

    /// [`Bvh::build`] with the given cost model.
    pub fn build_with(boxes: &[Aabb], cost: SahCost) -> Bvh {
        Bvh::build_from(boxes.len(), |i| boxes[i], cost)
    }

    /// [`Bvh::build_with`] over `count` primitives whose boxes `box_of` gives, so that
    /// no array of boxes need be kept beside the build's own.
    ///
    /// # Panics
    /// With 2³⁰ primitives or more.
    pub fn build_from(count: usize, box_of: impl Fn(usize) -> Aabb, cost: SahCost) -> Bvh {
        assert!(
            count <= PrimInfo::MAX_INDEX as usize + 1,
            "at most 2^30 primitives in a BVH"
        );
        let mut infos = Vec::with_capacity(count);
        infos.extend(
            (0..count)
                .map(|i| (i, box_of(i)))
                .filter(|(_, b)| !b.is_empty() && b.min.is_finite() && b.max.is_finite())
                .map(|(i, b)| PrimInfo::new(b.min.into(), b.max.into(), i as u32)),
        );
        if infos.is_empty() {
            return Bvh::default();
        }
        let extents = Extents::of(&infos);
        let store = Mutex::new(Vec::new());
        let top = build_top(&mut infos, 0, 0, extents, &cost, &store);
        // The primitive order out of the build's records before the nodes are laid out,
        // so that the two are not held together.
        let prims = infos.iter().map(PrimInfo::index).collect();
        drop(infos);
        let store = store.into_inner().expect("no build thread panicked");
        let mut bvh = Bvh {
            nodes: Vec::with_capacity(top.node_count()),
            prims,
        };
        bvh.flatten(top, &store);
        bvh
    }

    /// Lays the tree out depth first: an interior node's first child follows it, its
    /// second is at `offset`.
    fn flatten(&mut self, node: Top, store: &[BvhNode]) {
        match node {
            Top::Chunk(Chunk { at, len }) => {
                let base = self.nodes.len() as u32;
                self.nodes
                    .extend(store[at..at + len].iter().map(|n| BvhNode {
                        offset: if n.is_leaf() {
                            n.offset
                        } else {
                            n.offset + base
                        },
                        ..*n
                    }));
            }
            Top::Interior {
                bounds,
                axis,
                children,
            } => {
                let at = self.nodes.len();
                self.nodes.push(BvhNode {
                    bounds,
                    offset: 0,
                    count: 0,
                    axis,
                });
                let [left, right] = *children;
                self.flatten(left, store);
                self.nodes[at].offset = self.nodes.len() as u32;
                self.flatten(right, store);
            }
        }
    }

    pub fn bounds(&self) -> Aabb {
        self.nodes.first().map_or(Aabb::EMPTY, |n| n.bounds)
    }

    /// Finds the nearest hit. `hit(prim, t_max)` tests primitive `prim` and returns its
    /// distance if it is hit before `t_max`; the search then narrows to that distance.
    /// Returns the nearest primitive and its distance.
    #[inline]
    pub fn intersect(
        &self,
        ray: &Ray,
        t_max: f32,
        mut hit: impl FnMut(u32, f32) -> Option<f32>,
    ) -> Option<(u32, f32)> {
        let mut best = None;
        self.traverse(
            ray,
            |prim, t_max| match hit(prim, t_max) {
                Some(t) if t < t_max => {
                    best = Some((prim, t));
                    (t, false)
                }
                _ => (t_max, false),
            },
            t_max,
        );
        best
    }

    /// Whether any primitive blocks the ray before `t_max`; stops at the first one found.
    #[inline]
    pub fn occluded(
        &self,
        ray: &Ray,
        t_max: f32,
        mut blocks: impl FnMut(u32, f32) -> bool,
    ) -> bool {
        let mut found = false;
        self.traverse(
            ray,
            |prim, t| {
                found = blocks(prim, t);
                (t, found)
            },
            t_max,
        );
        found
    }

    /// Visits leaves front to back (the near child first, by the ray's direction on the
    /// node's split axis); `visit(prim, t_max)` returns the new `t_max` and whether to stop.
    /// Boxes are tested against a `t_max` widened by [`T_MAX_SCALE`], so a leaf a little
    /// beyond it may be visited: `visit` must apply its own `t_max`.
    #[inline]
    pub fn traverse(
        &self,
        ray: &Ray,
        mut visit: impl FnMut(u32, f32) -> (f32, bool),
        mut t_max: f32,
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let inv_d = ray.d.recip();
        let neg = [inv_d.x < 0.0, inv_d.y < 0.0, inv_d.z < 0.0];
        let mut stack = [0u32; 128];
        let mut sp = 0usize;
        let mut current = 0usize;
        loop {
            let node = &self.nodes[current];
            // Widened like the wide BVH's (see `T_MAX_SCALE`) so that both find the same hits.
            if node.bounds.hit(ray.o, inv_d, t_max * T_MAX_SCALE).is_some() {
                if node.is_leaf() {
                    let first = node.offset as usize;
                    for &prim in &self.prims[first..first + node.count as usize] {
                        let (t, stop) = visit(prim, t_max);
                        if stop {
                            return;
                        }
                        t_max = t;
                    }
                } else {
                    // Visit the child on the ray's near side first.
                    let (near, far) = if neg[node.axis as usize] {
                        (node.offset as usize, current + 1)
                    } else {
                        (current + 1, node.offset as usize)
                    };
                    stack[sp] = far as u32;
                    sp += 1;
                    current = near;
                    continue;
                }
            }
            if sp == 0 {
                return;
            }
            sp -= 1;
            current = stack[sp] as usize;
        }
    }
}

/// How a node is built: a leaf, or two children, the primitives partitioned at `mid`,
/// with the children's extents.
enum Split {
    Leaf,
    At {
        axis: usize,
        mid: usize,
        extents: (Extents, Extents),
    },
}

/// Builds the subtree over `prims` (primitives `first..` of the leaf order): in parallel
/// halves above [`PARALLEL_THRESHOLD`], below it by [`build_serial`] into a chunk of
/// `store`.
fn build_top(
    prims: &mut [PrimInfo],
    first: usize,
    depth: usize,
    ext: Extents,
    cost: &SahCost,
    store: &Mutex<Vec<BvhNode>>,
) -> Top {
    let n = prims.len();
    if n > PARALLEL_THRESHOLD {
        if let Split::At { axis, mid, extents } = choose_split(prims, depth, &ext, cost) {
            let (left, right) = prims.split_at_mut(mid);
            let (el, er) = extents;
            let (a, b) = rayon::join(
                || build_top(left, first, depth + 1, el, cost, store),
                || build_top(right, first + mid, depth + 1, er, cost, store),
            );
            return Top::Interior {
                bounds: ext.bounds.aabb(),
                axis: axis as u8,
                children: Box::new([a, b]),
            };
        }
    }
    // At most 2n - 1 nodes: one allocation, reused in place of one per node.
    let mut nodes = Vec::with_capacity(2 * n - 1);
    build_serial(prims, first, depth, ext, cost, &mut nodes);
    let mut store = store.lock().expect("no build thread panicked");
    let at = store.len();
    store.extend_from_slice(&nodes);
    Top::Chunk(Chunk {
        at,
        len: nodes.len(),
    })
}

/// Builds the subtree over `prims` depth first onto `out`, interior offsets counted from
/// the start of `out`.
fn build_serial(
    prims: &mut [PrimInfo],
    first: usize,
    depth: usize,
    ext: Extents,
    cost: &SahCost,
    out: &mut Vec<BvhNode>,
) {
    let bounds = ext.bounds.aabb();
    match choose_split(prims, depth, &ext, cost) {
        Split::Leaf => out.push(BvhNode {
            bounds,
            offset: first as u32,
            count: prims.len() as u16,
            axis: 0,
        }),
        Split::At { axis, mid, extents } => {
            let at = out.len();
            out.push(BvhNode {
                bounds,
                offset: 0,
                count: 0,
                axis: axis as u8,
            });
            let (left, right) = prims.split_at_mut(mid);
            build_serial(left, first, depth + 1, extents.0, cost, out);
            out[at].offset = out.len() as u32;
            build_serial(right, first + mid, depth + 1, extents.1, cost, out);
        }
    }
}

/// Chooses how to build the node over `prims` (extents `ext`), and partitions them so.
fn choose_split(prims: &mut [PrimInfo], depth: usize, ext: &Extents, cost: &SahCost) -> Split {
    let n = prims.len();
    // A split of a one-block leaf saves at most one block test and costs a node: with
    // `cost.node` ≥ 1 it never pays (with four-lane blocks, always making leaves of four
    // measured 15–20 % more closest-hit rays/s on the 590k room than splitting down to
    // single triangles).
    let small = n <= cost.max_leaf;
    if small && (n == 1 || cost.node >= 1.0) {
        return Split::Leaf;
    }
    let cmin = ext.centroids.min;
    let extent = (ext.centroids.max - cmin).max(Vec3A::ZERO);
    let axis = extent.max_position();
    if extent[axis] <= 0.0 || depth >= MAX_SAH_DEPTH {
        // All centroids coincide (no split separates them), or the tree is deep enough.
        if small {
            return Split::Leaf;
        }
        return split_middle(prims, axis);
    }

    // Bin centroids along the widest axis and sweep for the cheapest SAH split.
    // Small nodes get fewer bins: for a handful of primitives, sixteen bins cost more
    // to clear and sweep than they gain, and there are half a million such nodes per
    // million triangles.
    let nb = n.clamp(2, BINS);
    let scale = nb as f32 / extent[axis];
    let (c0, cmin_axis, last) = (axis, cmin[axis], nb as i32 - 1);
    let bin_of = move |p: &PrimInfo| {
        // Through i32: a plain truncating conversion (`as usize` checks for NaN).
        (((p.centroid2()[c0] - cmin_axis) * scale) as i32).clamp(0, last) as usize
    };
    let (bins, bin_counts) = bin_prims(prims, bin_of);
    let area = |b: &Box3A| b.aabb().surface_area();
    let mut right_area = [0.0f32; BINS];
    let mut right_count = [0usize; BINS];
    let (mut acc, mut count) = (Box3A::EMPTY, 0);
    for i in (1..nb).rev() {
        acc.union(bins[i].bounds.min, bins[i].bounds.max);
        count += bin_counts[i];
        right_area[i] = area(&acc);
        right_count[i] = count;
    }
    let (mut best_cost, mut best_split) = (f32::INFINITY, 0);
    let (mut acc, mut count) = (Box3A::EMPTY, 0);
    for i in 0..nb - 1 {
        acc.union(bins[i].bounds.min, bins[i].bounds.max);
        count += bin_counts[i];
        if count == 0 || right_count[i + 1] == 0 {
            continue;
        }
        let split = if small {
            area(&acc) + right_area[i + 1]
        } else {
            count as f32 * area(&acc) + right_count[i + 1] as f32 * right_area[i + 1]
        };
        if split < best_cost {
            best_cost = split;
            best_split = i;
        }
    }
    if small && best_cost + cost.node * area(&ext.bounds) >= area(&ext.bounds) {
        // One block costs no more than the node and the children's blocks.
        return Split::Leaf;
    }
    if !best_cost.is_finite() {
        return split_middle(prims, axis);
    }
    let mid = partition(prims, |p| bin_of(p) <= best_split);
    let (mut left, mut right) = (bins[0], bins[best_split + 1]);
    for b in &bins[1..=best_split] {
        left.merge(b);
    }
    for b in &bins[best_split + 2..nb] {
        right.merge(b);
    }
    Split::At {
        axis,
        mid,
        extents: (left, right),
    }
}

/// Nodes of more primitives than this are binned by both threads (or all), in chunks
/// of a quarter of it: the top of the tree is where one thread would otherwise work
/// alone on millions of primitives.
const PARALLEL_BINNING: usize = 1 << 16;

/// Each bin's extents and primitive count. Unions and counts do not depend on the
/// order they are taken in, so the chunked parallel pass gives the serial one's bins
/// exactly (and the same tree).
fn bin_prims(
    prims: &[PrimInfo],
    bin_of: impl Fn(&PrimInfo) -> usize + Sync,
) -> ([Extents; BINS], [usize; BINS]) {
    const EMPTY: Extents = Extents {
        bounds: Box3A::EMPTY,
        centroids: Box3A::EMPTY,
    };
    let serial = |chunk: &[PrimInfo]| {
        let (mut bins, mut counts) = ([EMPTY; BINS], [0usize; BINS]);
        for p in chunk {
            let b = bin_of(p);
            counts[b] += 1;
            bins[b].add(p);
        }
        (bins, counts)
    };
    if prims.len() <= PARALLEL_BINNING {
        return serial(prims);
    }
    prims.par_chunks(PARALLEL_BINNING / 4).map(serial).reduce(
        || ([EMPTY; BINS], [0; BINS]),
        |(mut bins, mut counts), (b, c)| {
            for i in 0..BINS {
                bins[i].merge(&b[i]);
                counts[i] += c[i];
            }
            (bins, counts)
        },
    )
}

/// The median split on `axis`, for when binning finds no split or the tree is deep.
fn split_middle(prims: &mut [PrimInfo], axis: usize) -> Split {
    let mid = prims.len() / 2;
    prims.select_nth_unstable_by(mid, |a, b| {
        a.centroid2()[axis].total_cmp(&b.centroid2()[axis])
    });
    let (left, right) = prims.split_at(mid);
    Split::At {
        axis,
        mid,
        extents: (Extents::of(left), Extents::of(right)),
    }
}

fn partition(prims: &mut [PrimInfo], pred: impl Fn(&PrimInfo) -> bool) -> usize {
    let mut i = 0;
    for j in 0..prims.len() {
        if pred(&prims[j]) {
            prims.swap(i, j);
            i += 1;
        }
    }
    i
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::Pcg32;
    use glam::Vec3;

    fn random_boxes(n: usize, rng: &mut Pcg32) -> Vec<Aabb> {
        (0..n)
            .map(|_| {
                let c = Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32()) * 10.0;
                let e = Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32()) * 0.3;
                Aabb {
                    min: c - e,
                    max: c + e,
                }
            })
            .collect()
    }

    #[test]
    fn finds_the_same_nearest_box_as_brute_force() {
        let mut rng = Pcg32::new(11, 0);
        let boxes = random_boxes(5000, &mut rng);
        let bvh = Bvh::build(&boxes);
        let mut seen: Vec<u32> = bvh.prims.clone();
        seen.sort();
        assert_eq!(
            seen,
            (0..5000).collect::<Vec<_>>(),
            "every primitive sits in one leaf"
        );
        for _ in 0..2000 {
            let o = Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32()) * 12.0 - 1.0;
            let d = (Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32()) - 0.5)
                .normalize();
            let ray = Ray::new(o, d);
            let inv = d.recip();
            let box_t = |i: u32, t_max: f32| boxes[i as usize].hit(o, inv, t_max);
            let brute = (0..boxes.len() as u32)
                .filter_map(|i| box_t(i, f32::INFINITY).map(|t| (i, t)))
                .min_by(|a, b| a.1.total_cmp(&b.1));
            let found = bvh.intersect(&ray, f32::INFINITY, box_t);
            assert_eq!(found.map(|f| f.1), brute.map(|b| b.1));
            assert_eq!(
                bvh.occluded(&ray, f32::INFINITY, |i, t| box_t(i, t).is_some()),
                brute.is_some()
            );
        }
    }

    #[test]
    fn degenerate_input_builds() {
        assert!(Bvh::build(&[]).nodes.is_empty());
        let same = vec![
            Aabb {
                min: Vec3::ZERO,
                max: Vec3::ONE
            };
            100
        ];
        let bvh = Bvh::build(&same);
        assert_eq!(bvh.prims.len(), 100);
        let bad = [
            Aabb::EMPTY,
            Aabb {
                min: Vec3::splat(f32::NAN),
                max: Vec3::ONE,
            },
            Aabb {
                min: Vec3::ZERO,
                max: Vec3::ZERO,
            },
        ];
        assert_eq!(
            Bvh::build(&bad).prims,
            vec![2],
            "empty and NaN boxes are left out; a flat box stays"
        );
    }
}
