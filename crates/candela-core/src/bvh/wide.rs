//! The eight-wide BVH: the binary SAH tree collapsed so that each node holds up to eight
//! children, their boxes side by side for one [`BoxTest`] of all eight.
//!
//! Memory order: the interior children of a node are stored next to each other, the
//! groups in depth-first order, so a subtree's nodes are close together and a node's
//! children share pages and cache-line prefetches.

use std::mem::MaybeUninit;

use super::binary::{Bvh, BvhNode};
use super::box8::{BoxTest, Planes8, Ray8, T_MAX_SCALE};
use super::quant8::QBoxes8;
use crate::geometry::Aabb;

const WIDTH: usize = 8;

/// A node of eight children. Child `i` is a leaf of `count[i]` primitives from
/// `child[i]` on in leaf order when `count[i] > 0`, otherwise the interior node
/// `child[i]`; an unused slot has an empty box, which no ray enters. `leaves` has bit
/// `i` set when child `i` is a leaf. Four cache lines.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct Node8 {
    pub planes: Planes8,
    pub child: [u32; WIDTH],
    pub count: [u8; WIDTH],
    pub leaves: u8,
}

impl Node8 {
    const UNUSED: Node8 = Node8 {
        planes: [
            [f32::INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
            [f32::INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
            [f32::INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
        ],
        child: [u32::MAX; WIDTH],
        count: [0; WIDTH],
        leaves: 0,
    };

    fn set_box(&mut self, lane: usize, b: Aabb) {
        for axis in 0..3 {
            self.planes[2 * axis][lane] = b.min[axis];
            self.planes[2 * axis + 1][lane] = b.max[axis];
        }
    }

    /// The box of child `lane` (empty for an unused slot).
    pub fn child_bounds(&self, lane: usize) -> Aabb {
        let p = &self.planes;
        Aabb {
            min: glam::Vec3::new(p[0][lane], p[2][lane], p[4][lane]),
            max: glam::Vec3::new(p[1][lane], p[3][lane], p[5][lane]),
        }
    }
}

/// What the traversal asks of a node: which children a ray enters, and the links.
pub trait WideNode: Copy {
    /// The box test of the eight children (bit `i` for child `i`, entry distances).
    ///
    /// # Safety
    /// The CPU must support kernel `K`.
    unsafe fn hit<K: BoxTest>(&self, ray: &K::Prepared, t_max: f32) -> (u32, [f32; 8]);
    /// `child`, `count` and `leaves`, as in [`Node8`].
    fn links(&self) -> (&[u32; WIDTH], &[u8; WIDTH], u8);
}

impl WideNode for Node8 {
    #[inline(always)]
    unsafe fn hit<K: BoxTest>(&self, ray: &K::Prepared, t_max: f32) -> (u32, [f32; 8]) {
        K::hit8(ray, &self.planes, t_max)
    }
    #[inline(always)]
    fn links(&self) -> (&[u32; WIDTH], &[u8; WIDTH], u8) {
        (&self.child, &self.count, self.leaves)
    }
}

/// [`Node8`] with its child boxes quantized to bytes ([`QBoxes8`]): 128 bytes (two
/// cache lines) instead of 256. `used` has bit `i` set for each child slot in use; the
/// others' bytes mean nothing and their hits are masked off.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct QNode8 {
    pub boxes: QBoxes8,
    pub child: [u32; WIDTH],
    pub count: [u8; WIDTH],
    pub leaves: u8,
    pub used: u8,
}

const _: () = assert!(size_of::<QNode8>() == 128);

impl QNode8 {
    /// Quantizes `node`'s boxes (each dequantized box contains the exact one).
    pub fn new(node: &Node8) -> QNode8 {
        let used = (0..WIDTH)
            .filter(|&l| !node.child_bounds(l).is_empty())
            .fold(0u8, |m, l| m | 1 << l);
        let bounds = (0..WIDTH)
            .map(|l| node.child_bounds(l))
            .fold(Aabb::EMPTY, Aabb::union);
        QNode8 {
            boxes: QBoxes8::new(&node.planes, bounds, used),
            child: node.child,
            count: node.count,
            leaves: node.leaves,
            used,
        }
    }

    /// The dequantized box of child `lane` (empty for an unused slot).
    pub fn child_bounds(&self, lane: usize) -> Aabb {
        if self.used & (1 << lane) == 0 {
            return Aabb::EMPTY;
        }
        let p = self.boxes.planes();
        Aabb {
            min: glam::Vec3::new(p[0][lane], p[2][lane], p[4][lane]),
            max: glam::Vec3::new(p[1][lane], p[3][lane], p[5][lane]),
        }
    }
}

impl WideNode for QNode8 {
    #[inline(always)]
    unsafe fn hit<K: BoxTest>(&self, ray: &K::Prepared, t_max: f32) -> (u32, [f32; 8]) {
        let (mask, t) = K::hit8q(ray, &self.boxes, t_max);
        (mask & self.used as u32, t)
    }
    #[inline(always)]
    fn links(&self) -> (&[u32; WIDTH], &[u8; WIDTH], u8) {
        (&self.child, &self.count, self.leaves)
    }
}

/// An eight-wide BVH; node 0 is the root. Leaves index the same leaf order as the
/// binary tree it was made from. Nodes are [`Node8`] as collapsed, or [`QNode8`] after
/// [`WideBvh::quantize`].
#[derive(Clone, Debug)]
pub struct WideBvh<N = Node8> {
    pub nodes: Vec<N>,
    bounds: Aabb,
}

impl<N> Default for WideBvh<N> {
    fn default() -> Self {
        WideBvh {
            nodes: Vec::new(),
            bounds: Aabb::EMPTY,
        }
    }
}

/// One pending subtree: a node or a leaf, and where the ray enters its box.
#[derive(Clone, Copy)]
struct Entry {
    child: u32,
    count: u32,
    t: f32,
}

/// Entries a traversal stack holds: at most seven pending siblings per level, and the
/// build keeps the binary tree, and so the wide one, under about 80 levels
/// (`MAX_SAH_DEPTH` + log2 n). Indexing is checked: a deeper tree would panic, not
/// overrun.
const STACK: usize = 7 * 84;

/// Asks for the `lines` cache lines from `p` on to be loaded (a hint; never faults).
#[inline(always)]
pub fn prefetch(p: *const u8, lines: usize) {
    #[cfg(target_arch = "x86_64")]
    for k in 0..lines {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        // SAFETY: prefetching is a hint that never faults, whatever the address.
        unsafe { _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(64 * k) as *const i8) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (p, lines);
}

/// Set bits of an eight-bit mask, from a table: fewer instructions than `count_ones`
/// without `popcnt` (the SSE traversal's; callgrind, room closest-hit instructions a
/// ray: 2141 with the insertion, 2267 with `count_ones` ranks, 2188 with this), and
/// with AVX2 as few as two `popcnt`s (1497 -> 1476).
#[inline(always)]
fn ones8(bits: u32) -> u32 {
    const ONES: [u8; 256] = {
        let mut t = [0u8; 256];
        let mut i = 0;
        while i < 256 {
            t[i] = (i as u32).count_ones() as u8;
            i += 1;
        }
        t
    };
    ONES[bits as usize & 255] as u32
}

impl WideBvh<Node8> {
    /// Collapses a binary tree: each wide node takes the binary node's two children and
    /// keeps opening its largest interior child (by surface area) until it has eight,
    /// which keeps the SAH tree's cuts. (Opening first the subtrees whose leaves all fit
    /// makes fuller nodes, 5.5 children on average instead of 3.3 on random boxes, but
    /// costs 4 % more instructions a ray on the Cornell box and gains nothing measurable
    /// on the 590k-triangle room.)
    pub fn collapse(bvh: &Bvh) -> WideBvh {
        let mut wide = WideBvh {
            nodes: Vec::with_capacity(bvh.nodes.len() / 4 + 1),
            bounds: bvh.bounds(),
        };
        if !bvh.nodes.is_empty() {
            wide.nodes.push(Node8::UNUSED);
            wide.fill(bvh, 0, 0);
        }
        wide
    }

    /// Fills wide node `at` from binary node `node`: first its slots, then (so that the
    /// interior children are adjacent) each interior child's subtree.
    fn fill(&mut self, bvh: &Bvh, node: usize, at: usize) {
        let children_of = |i: usize| [i + 1, bvh.nodes[i].offset as usize];
        let mut kids: Vec<usize> = if bvh.nodes[node].is_leaf() {
            vec![node]
        } else {
            children_of(node).to_vec()
        };
        while kids.len() < WIDTH {
            let area = |k: usize| bvh.nodes[k].bounds.surface_area();
            let Some(i) = kids
                .iter()
                .enumerate()
                .filter(|(_, &k)| !bvh.nodes[k].is_leaf())
                .max_by(|a, b| area(*a.1).total_cmp(&area(*b.1)))
                .map(|(i, _)| i)
            else {
                break;
            };
            // In place, so that the lanes keep the tree's left-to-right order.
            let k = kids.remove(i);
            kids.splice(i..i, children_of(k));
        }
        // Interior children by decreasing box area, then the leaves in tree order: the
        // any-hit traversal descends into the first interior child it enters, and a big
        // box is the likeliest to hold a blocker (room any-hit: 547 -> 457 instructions
        // a ray; the closest-hit order is by distance and does not change).
        kids.sort_by(|&a, &b| {
            let key = |k: usize| {
                let n = &bvh.nodes[k];
                if n.is_leaf() {
                    0.0
                } else {
                    -n.bounds.surface_area()
                }
            };
            key(a).total_cmp(&key(b))
        });
        let mut interior = Vec::new();
        let first = self.nodes.len();
        for (lane, &k) in kids.iter().enumerate() {
            let BvhNode {
                bounds,
                offset,
                count,
                ..
            } = bvh.nodes[k];
            let n = &mut self.nodes[at];
            n.set_box(lane, bounds);
            if count > 0 {
                n.child[lane] = offset;
                n.count[lane] = count as u8;
                n.leaves |= 1 << lane;
            } else {
                n.child[lane] = (first + interior.len()) as u32;
                interior.push(k);
            }
        }
        self.nodes
            .extend(std::iter::repeat_n(Node8::UNUSED, interior.len()));
        for (j, k) in interior.into_iter().enumerate() {
            self.fill(bvh, k, first + j);
        }
    }

    /// The same tree with quantized child boxes, node for node.
    pub fn quantize(&self) -> WideBvh<QNode8> {
        WideBvh {
            nodes: self.nodes.iter().map(QNode8::new).collect(),
            bounds: self.bounds,
        }
    }
}

impl<N: WideNode> WideBvh<N> {
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The leaf (as its lane names it, and its primitive count) when the tree is one
    /// node over one leaf: every primitive fits one leaf, and a traversal needs no box
    /// test (which only culls) to find that leaf's hits.
    pub fn sole_leaf(&self) -> Option<(u32, u32)> {
        let [root] = &self.nodes[..] else {
            return None;
        };
        let (child, count, leaves) = root.links();
        (leaves.count_ones() == 1).then(|| {
            let lane = leaves.trailing_zeros() as usize;
            (child[lane], count[lane] as u32)
        })
    }

    /// The root when the tree is one node: every child is a leaf (there is no other node
    /// to be an interior child), and a query needs no stack.
    pub fn sole_node(&self) -> Option<&N> {
        match &self.nodes[..] {
            [root] => Some(root),
            _ => None,
        }
    }

    /// Finds the nearest hit. `leaf(first, count, t_max)` tests the leaf's primitives
    /// and returns the distance of the nearest one hit before `t_max` (or `t_max`);
    /// `prefetch_leaf(first)` is called when a leaf is put off for later, so that the
    /// caller can prefetch its primitives (see [`prefetch`]).
    /// Children are visited nearest entry first, and subtrees the ray enters beyond
    /// the nearest hit so far are skipped.
    ///
    /// # Safety
    /// The CPU must support kernel `K` (see [`super::Simd::is_supported`]).
    #[inline(always)]
    pub unsafe fn intersect<K: BoxTest>(
        &self,
        ray: &Ray8,
        t_max: f32,
        leaf: impl FnMut(u32, u32, f32) -> f32,
        prefetch_leaf: impl Fn(u32),
    ) {
        self.intersect_from::<K>(0, ray, t_max, leaf, prefetch_leaf)
    }

    /// [`WideBvh::intersect`] in the subtree under node `start` (the packet traversal's
    /// single rays finish subtrees with it).
    ///
    /// # Safety
    /// As for [`WideBvh::intersect`]; `start` must be a node of this tree.
    #[inline(always)]
    pub unsafe fn intersect_from<K: BoxTest>(
        &self,
        start: u32,
        ray: &Ray8,
        mut t_max: f32,
        mut leaf: impl FnMut(u32, u32, f32) -> f32,
        prefetch_leaf: impl Fn(u32),
    ) {
        if self.nodes.is_empty() || !ray.finite {
            return;
        }
        let node_lines = size_of::<N>() / 64;
        let r = K::prepare(ray);
        // The box tests' widened `t_max`, made again only when a leaf has been tested, not
        // at every node and pop (callgrind, closest-hit instructions a query: Cornell
        // render 569.5 -> 559.3, bench/traversal.sh's room rays 1346.7 -> 1301.3).
        let mut t_box = t_max * T_MAX_SCALE;
        let mut leaf = |first, count, t_max| {
            let t: f32 = leaf(first, count, t_max);
            (t, t * T_MAX_SCALE)
        };
        // Left uninitialised: zeroing it would cost as much as a shallow traversal.
        let mut stack = [const { MaybeUninit::<Entry>::uninit() }; STACK];
        let mut sp = 0;
        let mut current = start as usize;
        // A subtree put off for later: have its memory on the way meanwhile (measured:
        // about 10 % more closest-hit rays/s on the room).
        let wait = |e: &Entry| {
            if e.count == 0 {
                prefetch(
                    self.nodes.as_ptr().wrapping_add(e.child as usize) as *const u8,
                    node_lines,
                );
            } else {
                prefetch_leaf(e.child);
            }
        };
        loop {
            let node = &self.nodes[current];
            let (mut mask, t_near) = node.hit::<K>(&r, t_box);
            let (child, count, _) = node.links();
            // Child `lane` as a pending subtree.
            let entry = |lane: usize| Entry {
                child: child[lane],
                count: count[lane] as u32,
                t: t_near[lane],
            };
            if mask & mask.wrapping_sub(1) == 0 {
                // One child or none: no sorting, and an interior child is next.
                if mask != 0 {
                    let lane = mask.trailing_zeros() as usize;
                    let prims = count[lane] as u32;
                    if prims == 0 {
                        current = child[lane] as usize;
                        continue;
                    }
                    (t_max, t_box) = leaf(child[lane], prims, t_max);
                }
            } else if (mask & (mask - 1)).count_ones() == 1 {
                // Two children (the commonest case after one): the nearer is next, the
                // farther waits. The order is the insertion's below (the higher lane
                // first among equals), without its data-dependent branches and without
                // the nearer's round trip through the stack (which, entered no farther
                // than t_max, would pass the pop's test).
                let (a, b) = (
                    mask.trailing_zeros() as usize,
                    31 - mask.leading_zeros() as usize,
                );
                let a_first = t_near[a] < t_near[b];
                let (near, far) = if a_first { (a, b) } else { (b, a) };
                let far = entry(far);
                wait(&far);
                stack[sp].write(far);
                sp += 1;
                let prims = count[near] as u32;
                if prims == 0 {
                    current = child[near] as usize;
                    continue;
                }
                (t_max, t_box) = leaf(child[near], prims, t_max);
            } else {
                // Three or more: each goes straight to its place, farthest lowest, from its
                // rank among them (how many are farther, or as far and in a lower lane:
                // the order an insertion in lane order makes), with no data-dependent
                // branches (the insertion's compare mispredicted 0.5 times a closest-hit
                // query on the Cornell render, callgrind's branch model).
                let hits = mask;
                while mask != 0 {
                    let lane = mask.trailing_zeros() as usize;
                    let below = hits & ((1 << lane) - 1);
                    mask &= mask - 1;
                    let t = t_near[lane];
                    let (farther, level) = K::order(&t_near, t);
                    let rank = ones8(farther & hits | level & below);
                    let entry = entry(lane);
                    wait(&entry);
                    stack[sp + rank as usize].write(entry);
                }
                sp += ones8(hits) as usize;
            }
            // Pop the nearest pending subtree still in front of the nearest hit.
            loop {
                if sp == 0 {
                    return;
                }
                sp -= 1;
                // SAFETY: every slot below the old `sp` has been written.
                let e = stack[sp].assume_init();
                if e.t > t_box {
                    continue;
                }
                if e.count > 0 {
                    (t_max, t_box) = leaf(e.child, e.count, t_max);
                    continue;
                }
                current = e.child as usize;
                break;
            }
        }
    }

    /// Whether any leaf reports a blocker: `leaf(first, count, t_max)` returns true to
    /// stop. An any-hit query needs no order: a node's leaves are tested at once, then
    /// the first interior child is next and the others wait on the stack.
    ///
    /// # Safety
    /// The CPU must support kernel `K` (see [`super::Simd::is_supported`]).
    #[inline(always)]
    pub unsafe fn occluded<K: BoxTest>(
        &self,
        ray: &Ray8,
        t_max: f32,
        leaf: impl FnMut(u32, u32, f32) -> bool,
    ) -> bool {
        self.occluded_from::<K>(0, ray, t_max, leaf)
    }

    /// [`WideBvh::occluded`] in the subtree under node `start`.
    ///
    /// # Safety
    /// As for [`WideBvh::occluded`]; `start` must be a node of this tree.
    #[inline(always)]
    pub unsafe fn occluded_from<K: BoxTest>(
        &self,
        start: u32,
        ray: &Ray8,
        t_max: f32,
        mut leaf: impl FnMut(u32, u32, f32) -> bool,
    ) -> bool {
        if self.nodes.is_empty() || !ray.finite {
            return false;
        }
        let node_lines = size_of::<N>() / 64;
        let r = K::prepare(ray);
        let t_box = t_max * T_MAX_SCALE;
        let mut stack = [const { MaybeUninit::<u32>::uninit() }; STACK];
        let mut sp = 0;
        let mut current = start as usize;
        loop {
            let node = &self.nodes[current];
            let (mask, _) = node.hit::<K>(&r, t_box);
            let (child, count, leaves) = node.links();
            let leaves = leaves as u32;
            let mut hit_leaves = mask & leaves;
            while hit_leaves != 0 {
                let lane = hit_leaves.trailing_zeros() as usize;
                hit_leaves &= hit_leaves - 1;
                if leaf(child[lane], count[lane] as u32, t_max) {
                    return true;
                }
            }
            let mut inner = mask & !leaves;
            if inner != 0 {
                current = child[inner.trailing_zeros() as usize] as usize;
                inner &= inner - 1;
                while inner != 0 {
                    let next = child[inner.trailing_zeros() as usize];
                    prefetch(
                        self.nodes.as_ptr().wrapping_add(next as usize) as *const u8,
                        node_lines,
                    );
                    stack[sp].write(next);
                    sp += 1;
                    inner &= inner - 1;
                }
                continue;
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            // SAFETY: every slot below the old `sp` has been written.
            current = stack[sp].assume_init() as usize;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Ray;
    use crate::sampler::Pcg32;
    use glam::Vec3;

    /// Every primitive sits in exactly one leaf, each child box holds what is below, a
    /// node's interior children are adjacent, and `leaves` matches `count`.
    #[test]
    fn collapse_keeps_every_primitive_once() {
        let mut rng = Pcg32::new(1, 2);
        let boxes: Vec<Aabb> = (0..3000)
            .map(|_| {
                let c = Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32());
                Aabb {
                    min: c,
                    max: c + 0.01,
                }
            })
            .collect();
        let binary = Bvh::build(&boxes);
        let wide = WideBvh::collapse(&binary);
        assert!(wide.nodes.len() * 4 < binary.nodes.len());
        let mut seen = vec![0u32; boxes.len()];
        let mut stack = vec![0usize];
        let mut visited = 0;
        while let Some(n) = stack.pop() {
            visited += 1;
            let node = &wide.nodes[n];
            let mut inner = Vec::new();
            for lane in 0..WIDTH {
                let b = node.child_bounds(lane);
                assert_eq!(node.leaves & (1 << lane) != 0, node.count[lane] > 0);
                if node.count[lane] > 0 {
                    let first = node.child[lane] as usize;
                    for &p in &binary.prims[first..first + node.count[lane] as usize] {
                        seen[p as usize] += 1;
                        assert_eq!(b.union(boxes[p as usize]), b, "leaf box holds its prims");
                    }
                } else if node.child[lane] != u32::MAX {
                    let c = node.child[lane] as usize;
                    assert_eq!(
                        wide.nodes[c].bounds_union(),
                        b,
                        "child box is its children's"
                    );
                    inner.push(c);
                    stack.push(c);
                } else {
                    assert!(b.is_empty(), "unused slots are empty");
                }
            }
            for pair in inner.windows(2) {
                assert_eq!(pair[1], pair[0] + 1, "interior children are adjacent");
            }
        }
        assert_eq!(visited, wide.nodes.len(), "every node is reached once");
        assert!(seen.iter().all(|&c| c == 1));
    }

    /// The quantized tree finds what the full one finds, on boxes as primitives (hit at
    /// their entry distance by the slab test): the same nearest distance, bit for bit, as
    /// brute force, and the same any-hit answers, with every kernel. Rays start inside
    /// boxes, on their planes and outside, some along axes or with ±0 components, some
    /// with a finite t_max. Each quantized child box also contains its exact box.
    #[test]
    fn quantized_nodes_find_the_same_hits() {
        let mut rng = Pcg32::new(8, 21);
        let mut u = || rng.uniform_f32();
        let boxes: Vec<Aabb> = (0..2000)
            .map(|k| {
                let c = Vec3::new(u(), u(), u()) * 10.0;
                let mut e = Vec3::new(u(), u(), u()) * 0.4;
                if k % 9 == 0 {
                    e.z = 0.0; // flat
                }
                Aabb { min: c, max: c + e }
            })
            .collect();
        let binary = Bvh::build(&boxes);
        let full = WideBvh::collapse(&binary);
        let quantized = full.quantize();
        for (f, q) in full.nodes.iter().zip(&quantized.nodes) {
            for lane in 0..WIDTH {
                let (a, b) = (f.child_bounds(lane), q.child_bounds(lane));
                assert!(a.is_empty() || a.union(b) == b, "{a:?} not inside {b:?}");
            }
        }
        let leaf_order: Vec<Aabb> = binary.prims.iter().map(|&p| boxes[p as usize]).collect();
        let mut hits = 0;
        for k in 0..20000 {
            let target = boxes[k % boxes.len()];
            let o = match k % 4 {
                0 => (target.min + target.max) * 0.5,
                1 => target.min,
                2 => Vec3::new(u(), u(), u()) * 14.0 - 2.0,
                _ => Vec3::new(target.min.x, u() * 10.0, target.max.z),
            };
            let mut d = Vec3::new(u(), u(), u()) - 0.5;
            match k % 5 {
                0 => d = [Vec3::X, -Vec3::Y, Vec3::Z][k / 5 % 3],
                1 => d.x = -0.0,
                2 => d.y = 0.0,
                _ => {}
            }
            let ray = Ray::new(o, d.normalize_or(Vec3::Y));
            let t_max = if k % 3 == 0 { u() * 3.0 } else { f32::INFINITY };
            let brute = boxes
                .iter()
                .filter_map(|b| box_prim(b, &ray, t_max))
                .min_by(f32::total_cmp);
            hits += brute.is_some() as usize;
            for simd in crate::bvh::Simd::available() {
                let args = (&ray, t_max, &leaf_order[..]);
                // SAFETY: `available` lists only kernels this CPU supports.
                let found = unsafe {
                    match simd {
                        #[cfg(target_arch = "x86_64")]
                        crate::bvh::Simd::Sse => {
                            use super::super::box8::SseBoxes as K;
                            [
                                box_queries::<K, _>(&full, args),
                                box_queries::<K, _>(&quantized, args),
                            ]
                        }
                        #[cfg(target_arch = "x86_64")]
                        crate::bvh::Simd::Avx2 => {
                            use super::super::box8::Avx2Boxes as K;
                            [
                                box_queries::<K, _>(&full, args),
                                box_queries::<K, _>(&quantized, args),
                            ]
                        }
                        _ => {
                            use super::super::box8::ScalarBoxes as K;
                            [
                                box_queries::<K, _>(&full, args),
                                box_queries::<K, _>(&quantized, args),
                            ]
                        }
                    }
                };
                for (layout, (t, blocked)) in ["full", "quantized"].iter().zip(found) {
                    assert_eq!(
                        t.map(f32::to_bits),
                        brute.map(f32::to_bits),
                        "{simd:?} {layout}: ray {k} {ray:?}"
                    );
                    assert_eq!(
                        blocked,
                        brute.is_some(),
                        "{simd:?} {layout}: any-hit, ray {k}"
                    );
                }
            }
        }
        assert!(hits > 5000, "only {hits} rays hit");
    }

    /// A box as a primitive: hit at the scalar slab test's entry distance. (Not
    /// `Aabb::hit`: where a plane's distance is NaN its result depends on glam's
    /// `min_element` order, so it can report a hit the slab test rightly rejects.)
    fn box_prim(b: &Aabb, ray: &Ray, t_max: f32) -> Option<f32> {
        let mut planes = Node8::UNUSED.planes;
        for axis in 0..3 {
            planes[2 * axis][0] = b.min[axis];
            planes[2 * axis + 1][0] = b.max[axis];
        }
        let (mask, t) = super::super::box8::hit8_scalar(&Ray8::new(ray), &planes, t_max);
        (mask & 1 != 0).then_some(t[0])
    }

    /// Nearest-hit distance and any-hit answer of `bvh` on boxes as primitives (given in
    /// leaf order, hit as [`box_prim`] says).
    ///
    /// # Safety
    /// The CPU must support `K`.
    unsafe fn box_queries<K: BoxTest, N: WideNode>(
        bvh: &WideBvh<N>,
        (ray, t_max, leaf_order): (&Ray, f32, &[Aabb]),
    ) -> (Option<f32>, bool) {
        let prims = |first: u32, count: u32| &leaf_order[first as usize..(first + count) as usize];
        let mut best = None;
        let r8 = Ray8::new(ray);
        bvh.intersect::<K>(
            &r8,
            t_max,
            |first, count, mut t_max| {
                for b in prims(first, count) {
                    if let Some(t) = box_prim(b, ray, t_max) {
                        t_max = t;
                        best = Some(t);
                    }
                }
                t_max
            },
            |_| (),
        );
        let blocked = bvh.occluded::<K>(&r8, t_max, |first, count, t_max| {
            prims(first, count)
                .iter()
                .any(|b| box_prim(b, ray, t_max).is_some())
        });
        (best, blocked)
    }

    impl Node8 {
        fn bounds_union(&self) -> Aabb {
            (0..WIDTH)
                .map(|l| self.child_bounds(l))
                .fold(Aabb::EMPTY, Aabb::union)
        }
    }
}
