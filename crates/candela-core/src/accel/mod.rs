//! The ray-tracing acceleration structure: a [`WideBvh`] (eight children a node) over the
//! scene's primitives, each leaf's primitives copied into one [`block::Block`] of eight
//! lanes with the vertices inline (no index → mesh → position chase), tested eight at a
//! time. The build sizes leaves knowing that a leaf of up to eight triangles costs one
//! block test ([`SahCost::BLOCKS`]).
//!
//! Triangles keep the watertight test (Woop et al. 2013) on the same vertex values as
//! the meshes, so a hit's distance is the same bits as the mesh's own test gives. Each
//! primitive carries flag bits: a sphere, or a triangle whose hits must pass a filter
//! (alpha masks). Blocks without flags never call the filter; a flagged triangle calls
//! it after its barycentrics are known, and traversal goes on past it when the filter
//! rejects.
//!
//! The SIMD kernels ([`Simd`]) are chosen once, at build: AVX2 box and triangle tests
//! where the CPU has them, else SSE; [`Accel::build_for`] forces one (the tests run each the CPU has
//! against the scalar one). Every kernel finds the same hits, bit for bit.
//!
//! [`NodeLayout`] picks the wide nodes: full planes (the default) or quantized boxes
//! (half the node memory; [`Accel::build_layout`]).

mod block;
mod lanes;
mod sphere;

use glam::Vec3;

#[cfg(target_arch = "x86_64")]
use crate::bvh::{Avx2Boxes, SseBoxes};
use crate::bvh::{BoxTest, Bvh, Node8, QNode8, Ray8, SahCost, ScalarBoxes, WideBvh, WideNode};
use crate::geometry::{Aabb, Ray, TriangleHit, WatertightRay};
use block::{Block, FILTERED, ID_MASK, LANES, SPHERE};

pub use crate::bvh::Simd;

// Every leaf of the build fits one block.
const _: () = assert!(SahCost::BLOCKS.max_leaf == LANES);

/// A primitive handed to [`Accel::build`].
#[derive(Clone, Copy, Debug)]
pub enum Shape {
    Triangle([Vec3; 3]),
    Sphere { center: Vec3, radius: f32 },
}

impl Shape {
    pub fn bounds(&self) -> Aabb {
        match *self {
            Shape::Triangle(v) => Aabb::from_points(&v),
            Shape::Sphere { center, radius } => Aabb {
                min: center - Vec3::splat(radius),
                max: center + Vec3::splat(radius),
            },
        }
    }
}

/// What a ray hit: the primitive's index in the list given to [`Accel::build`], the
/// distance, and for a triangle the barycentrics of its vertices 1 and 2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub prim: u32,
    pub t: f32,
    pub b1: f32,
    pub b2: f32,
}

/// Accepts every hit: the filter of scenes without alpha masks.
pub fn accept_all(_: u32, _: &TriangleHit) -> bool {
    true
}

/// How the wide BVH's nodes store their child boxes. Both find the same hits (the
/// quantized boxes contain the exact ones, and the primitive tests decide).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum NodeLayout {
    /// Full f32 planes ([`Node8`], 256 bytes a node): the default, the faster one
    /// measured (bench/README.md, "Compressed nodes").
    #[default]
    Full,
    /// Child boxes in bytes against a per-node frame ([`QNode8`], 128 bytes a node).
    Quantized,
}

#[derive(Clone, Debug)]
enum Tree {
    Full(WideBvh<Node8>),
    Quantized(WideBvh<QNode8>),
}

impl Default for Tree {
    fn default() -> Self {
        Tree::Full(WideBvh::default())
    }
}

#[derive(Clone, Debug, Default)]
pub struct Accel {
    tree: Tree,
    blocks: Vec<Block>,
    simd: Simd,
    /// Whether every primitive is an unfiltered triangle: the AVX2 traversal then runs
    /// a copy whose block tests skip the check for spheres and filters.
    plain: bool,
}

impl Accel {
    /// Builds over `shapes`; `filtered(i)` says whether hits on triangle `i` must pass
    /// the filter. Primitives with empty or non-finite boxes are left out.
    pub fn build(shapes: &[Shape], filtered: impl Fn(u32) -> bool) -> Accel {
        Accel::build_for(shapes, filtered, Simd::best())
    }

    /// [`Accel::build`] with the given kernels, which must be supported by this CPU
    /// ([`Simd::available`]); for tests and benchmarks.
    pub fn build_for(shapes: &[Shape], filtered: impl Fn(u32) -> bool, simd: Simd) -> Accel {
        Accel::build_layout(shapes, filtered, simd, NodeLayout::Full)
    }

    /// [`Accel::build_for`] with the given node layout.
    pub fn build_layout(
        shapes: &[Shape],
        filtered: impl Fn(u32) -> bool,
        simd: Simd,
        layout: NodeLayout,
    ) -> Accel {
        Accel::build_indexed(shapes.len(), |i| shapes[i as usize], filtered, simd, layout)
    }

    /// [`Accel::build_layout`] over `count` primitives that `shape(i)` gives, so that a
    /// big scene need not hold an array of shapes beside its meshes while it builds.
    pub fn build_indexed(
        count: usize,
        shape: impl Fn(u32) -> Shape,
        filtered: impl Fn(u32) -> bool,
        simd: Simd,
        layout: NodeLayout,
    ) -> Accel {
        assert!(
            simd.is_supported(),
            "{simd:?} kernels on a CPU without them"
        );
        assert!(
            count < ID_MASK as usize,
            "at most 2^30 primitives per scene"
        );
        let binary = Bvh::build_from(count, |i| shape(i as u32).bounds(), SahCost::BLOCKS);
        let record = |i: u32| match shape(i) {
            Shape::Triangle(v) => (v, i | if filtered(i) { FILTERED } else { 0 }),
            Shape::Sphere { center, radius } => (
                [center, Vec3::new(radius, 0.0, 0.0), Vec3::ZERO],
                i | SPHERE,
            ),
        };
        // The wide tree first, so that the binary nodes are gone before the blocks take
        // their memory; then one block per wide leaf lane, in the wide nodes' order, its
        // lane pointing at the block rather than the primitive range.
        let mut bvh = WideBvh::collapse(&binary);
        let prims = binary.prims;
        drop(binary.nodes);
        let leaves = bvh
            .nodes
            .iter()
            .flat_map(|n| n.count)
            .filter(|&c| c > 0)
            .count();
        let mut blocks = Vec::with_capacity(leaves);
        let mut lanes = [([Vec3::ZERO; 3], 0u32); LANES];
        for node in &mut bvh.nodes {
            for lane in 0..node.child.len() {
                let count = node.count[lane] as usize;
                if count > 0 {
                    let first = node.child[lane] as usize;
                    for (slot, &i) in lanes.iter_mut().zip(&prims[first..first + count]) {
                        *slot = record(i);
                    }
                    node.child[lane] = blocks.len() as u32;
                    blocks.push(Block::new(&lanes[..count]));
                }
            }
        }
        let tree = match layout {
            NodeLayout::Full => Tree::Full(bvh),
            NodeLayout::Quantized => Tree::Quantized(bvh.quantize()),
        };
        let plain = blocks.iter().all(Block::is_plain);
        Accel {
            tree,
            blocks,
            simd,
            plain,
        }
    }

    pub fn bounds(&self) -> Aabb {
        match &self.tree {
            Tree::Full(t) => t.bounds(),
            Tree::Quantized(t) => t.bounds(),
        }
    }

    pub fn layout(&self) -> NodeLayout {
        match self.tree {
            Tree::Full(_) => NodeLayout::Full,
            Tree::Quantized(_) => NodeLayout::Quantized,
        }
    }

    /// Bytes of the wide BVH's nodes and of the primitive blocks.
    pub fn memory(&self) -> (usize, usize) {
        let nodes = match &self.tree {
            Tree::Full(t) => size_of_val(&t.nodes[..]),
            Tree::Quantized(t) => size_of_val(&t.nodes[..]),
        };
        (nodes, size_of_val(&self.blocks[..]))
    }

    /// The kernels this structure traces with.
    pub fn simd(&self) -> Simd {
        self.simd
    }

    /// The nearest hit within (0, t_max); hits on flagged triangles count only where
    /// `filter` accepts them.
    #[inline]
    pub fn intersect(
        &self,
        ray: &Ray,
        t_max: f32,
        filter: impl Fn(u32, &TriangleHit) -> bool,
    ) -> Option<Hit> {
        // SAFETY: `build_for` checked that the CPU supports `self.simd`.
        unsafe {
            match self.simd {
                #[cfg(target_arch = "x86_64")]
                Simd::Avx2 if self.plain => self.intersect_avx2::<true, _>(ray, t_max, &filter),
                #[cfg(target_arch = "x86_64")]
                Simd::Avx2 => self.intersect_avx2::<false, _>(ray, t_max, &filter),
                #[cfg(target_arch = "x86_64")]
                Simd::Sse => {
                    self.intersect_with::<SseBoxes, { block::SSE }, false>(ray, t_max, &filter)
                }
                _ => self
                    .intersect_with::<ScalarBoxes, { block::SCALAR }, false>(ray, t_max, &filter),
            }
        }
    }

    /// Whether anything accepted by `filter` lies on the ray within (0, t_max); stops
    /// at the first blocker found.
    #[inline]
    pub fn occluded(
        &self,
        ray: &Ray,
        t_max: f32,
        filter: impl Fn(u32, &TriangleHit) -> bool,
    ) -> bool {
        // SAFETY: `build_for` checked that the CPU supports `self.simd`.
        unsafe {
            match self.simd {
                #[cfg(target_arch = "x86_64")]
                Simd::Avx2 if self.plain => self.occluded_avx2::<true, _>(ray, t_max, &filter),
                #[cfg(target_arch = "x86_64")]
                Simd::Avx2 => self.occluded_avx2::<false, _>(ray, t_max, &filter),
                #[cfg(target_arch = "x86_64")]
                Simd::Sse => {
                    self.occluded_with::<SseBoxes, { block::SSE }, false>(ray, t_max, &filter)
                }
                _ => {
                    self.occluded_with::<ScalarBoxes, { block::SCALAR }, false>(ray, t_max, &filter)
                }
            }
        }
    }

    /// The traversal compiled with AVX2 enabled, so that its box and triangle kernels
    /// inline, and with the bit-manipulation sets every AVX2 CPU has ([`Simd::best`]
    /// checks them): `blsr`/`tzcnt`/`lzcnt` for the child masks, `shlx` for shifts.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,bmi1,bmi2,lzcnt")]
    unsafe fn intersect_avx2<const PLAIN: bool, F: Fn(u32, &TriangleHit) -> bool>(
        &self,
        ray: &Ray,
        t_max: f32,
        filter: &F,
    ) -> Option<Hit> {
        self.intersect_with::<Avx2Boxes, { block::AVX2 }, PLAIN>(ray, t_max, filter)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,bmi1,bmi2,lzcnt")]
    unsafe fn occluded_avx2<const PLAIN: bool, F: Fn(u32, &TriangleHit) -> bool>(
        &self,
        ray: &Ray,
        t_max: f32,
        filter: &F,
    ) -> bool {
        self.occluded_with::<Avx2Boxes, { block::AVX2 }, PLAIN>(ray, t_max, filter)
    }

    /// # Safety
    /// The CPU must support `K` and `LEAF`.
    #[inline(always)]
    unsafe fn intersect_with<K: BoxTest, const LEAF: u8, const PLAIN: bool>(
        &self,
        ray: &Ray,
        t_max: f32,
        filter: &impl Fn(u32, &TriangleHit) -> bool,
    ) -> Option<Hit> {
        match &self.tree {
            Tree::Full(t) => self.intersect_tree::<K, LEAF, PLAIN, _>(t, ray, t_max, filter),
            Tree::Quantized(t) => self.intersect_tree::<K, LEAF, PLAIN, _>(t, ray, t_max, filter),
        }
    }

    /// # Safety
    /// The CPU must support `K` and `LEAF`.
    #[inline(always)]
    unsafe fn intersect_tree<K: BoxTest, const LEAF: u8, const PLAIN: bool, N: WideNode>(
        &self,
        tree: &WideBvh<N>,
        ray: &Ray,
        t_max: f32,
        filter: &impl Fn(u32, &TriangleHit) -> bool,
    ) -> Option<Hit> {
        let r8 = Ray8::new(ray);
        let wray = WatertightRay::from_recip(ray, r8.inv_d);
        let mut best: Option<Hit> = None;
        tree.intersect::<K>(
            &r8,
            t_max,
            #[inline(always)]
            |block, count, t_max| {
                let block = &self.blocks[block as usize];
                // Opaque to the optimizer, so that the block test's broadcasts of the
                // watertight ray are made where a block is tested: otherwise they are
                // hoisted into the query's setup and spilled, paid by every query though
                // a shadow ray tests 0.64 blocks on average (callgrind, Cornell render
                // 128², 1 spp: closest 559.3 -> 545.4 instructions a query, shadow
                // 366.1 -> 347.1). A hint: it changes no result.
                let wray = std::hint::black_box(&wray);
                match block.intersect::<LEAF, false, PLAIN>(ray, wray, count, t_max, filter) {
                    Some(h) => {
                        best = Some(Hit {
                            prim: h.id,
                            t: h.hit.t,
                            b1: h.hit.b1,
                            b2: h.hit.b2,
                        });
                        h.hit.t
                    }
                    None => t_max,
                }
            },
            #[inline(always)]
            |block| {
                let at = self.blocks.as_ptr().wrapping_add(block as usize);
                crate::bvh::prefetch(at as *const u8, size_of::<Block>() / 64)
            },
        );
        best
    }

    /// # Safety
    /// The CPU must support `K` and `LEAF`.
    #[inline(always)]
    unsafe fn occluded_with<K: BoxTest, const LEAF: u8, const PLAIN: bool>(
        &self,
        ray: &Ray,
        t_max: f32,
        filter: &impl Fn(u32, &TriangleHit) -> bool,
    ) -> bool {
        match &self.tree {
            Tree::Full(t) => self.occluded_tree::<K, LEAF, PLAIN, _>(t, ray, t_max, filter),
            Tree::Quantized(t) => self.occluded_tree::<K, LEAF, PLAIN, _>(t, ray, t_max, filter),
        }
    }

    /// # Safety
    /// The CPU must support `K` and `LEAF`.
    #[inline(always)]
    unsafe fn occluded_tree<K: BoxTest, const LEAF: u8, const PLAIN: bool, N: WideNode>(
        &self,
        tree: &WideBvh<N>,
        ray: &Ray,
        t_max: f32,
        filter: &impl Fn(u32, &TriangleHit) -> bool,
    ) -> bool {
        let r8 = Ray8::new(ray);
        let wray = WatertightRay::from_recip(ray, r8.inv_d);
        tree.occluded::<K>(
            &r8,
            t_max,
            #[inline(always)]
            |block, count, t_max| {
                // As in `intersect_tree`: the broadcasts where a block is tested.
                let wray = std::hint::black_box(&wray);
                self.blocks[block as usize]
                    .intersect::<LEAF, true, PLAIN>(ray, wray, count, t_max, filter)
                    .is_some()
            },
        )
    }
}
