//! The ray-tracing acceleration structure: a [`WideBvh`] (eight children a node) over the
//! scene's primitives, each leaf's primitives copied into one `block::Block` of eight
//! lanes with the vertices inline (no index → mesh → position chase), tested eight at a
//! time. The build sizes leaves knowing that a leaf of up to eight triangles costs one
//! block test ([`SahCost::BLOCKS`]). A tree of one node (a scene whose primitives fit
//! eight blocks) is queried without the traversal (`small`): one leaf by its block
//! test alone, several by the root's box test and their blocks near to far.
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
//! Camera rays are traced eight at a time where the tree is one node (`coherent`:
//! each block against the eight rays in lanes, every ray's hit that of
//! [`Accel::intersect`] bit for bit); `packet` is the measured packet traversal of
//! deeper trees, which the renderer does not use.
//!
//! [`AccelLayout`] picks the wide nodes, full planes (the default) or quantized boxes
//! (half the node memory), and the leaves: inline blocks (the default) or indexed
//! records gathered into a block when a ray reaches them (a quarter of the memory;
//! [`LeafLayout::auto`] chooses them for big scenes). Every layout finds the same hits.

mod block;
mod coherent;
mod geometry;
mod indexed;
mod lanes;
mod layout;
mod packet;
mod small;
mod sphere;

use glam::Vec3;

#[cfg(target_arch = "x86_64")]
use crate::bvh::{Avx2Boxes, SseBoxes};
use crate::bvh::{BoxTest, Bvh, Node8, QNode8, Ray8, SahCost, ScalarBoxes, WideBvh, WideNode};
use crate::geometry::{Aabb, Ray, TriangleHit, WatertightRay};
use block::{Block, FILTERED, ID_MASK, LANES, SPHERE};
use indexed::IndexedLeaves;
use small::{SmallRoot, SmallTree, SoleLeaf};

pub use crate::bvh::Simd;
pub use geometry::{Geometry, Located, TriangleMesh};
pub use layout::{AccelLayout, LeafLayout, NodeLayout, INDEXED_FROM};
pub use packet::PacketMode;

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

/// The primitives of the leaves, in the layout [`LeafLayout`] names.
#[derive(Clone, Debug)]
enum Leaves {
    /// One block a leaf; a wide node's leaf lane names its block.
    Inline(Vec<Block>),
    /// A wide node's leaf lane names its first record.
    Indexed(IndexedLeaves),
}

impl Default for Leaves {
    fn default() -> Self {
        Leaves::Inline(Vec::new())
    }
}

#[derive(Clone, Debug, Default)]
pub struct Accel {
    tree: Tree,
    leaves: Leaves,
    simd: Simd,
    /// Whether every primitive is an unfiltered triangle: the AVX2 traversal then runs
    /// a copy whose block tests skip the check for spheres and filters.
    plain: bool,
    /// A tree of one node, which queries walk without the traversal ([`SmallTree`]).
    small: SmallTree,
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

    /// [`Accel::build_for`] with the given layout.
    pub fn build_layout(
        shapes: &[Shape],
        filtered: impl Fn(u32) -> bool,
        simd: Simd,
        layout: impl Into<AccelLayout>,
    ) -> Accel {
        let layout = layout.into();
        let shape = |i: u32| shapes[i as usize];
        let flags = |i: u32| flags_of(&shape(i), filtered(i));
        let (bvh, order) = Accel::tree(shapes.len(), |i| shape(i).bounds());
        Accel::finish(bvh, &order, layout, shape, flags, simd, |order| {
            IndexedLeaves::from_shapes(order, shape, flags)
        })
    }

    /// Builds over a scene's primitives by reference to its meshes' arrays (see
    /// [`Geometry`]: hits report ids in its order), with the given kernels and layout.
    pub fn build_geometry(geometry: &Geometry, simd: Simd, layout: AccelLayout) -> Accel {
        let shape = |i: u32| geometry.shape(i);
        let flags = |i: u32| flags_of(&shape(i), geometry.filtered(i));
        let (bvh, order) = Accel::tree(geometry.len(), |i| shape(i).bounds());
        Accel::finish(bvh, &order, layout, shape, flags, simd, |order| {
            IndexedLeaves::from_geometry(geometry, order, flags)
        })
    }

    /// The wide tree over `count` primitives whose boxes `bounds(i)` gives, and its leaf
    /// order. Primitives with empty or non-finite boxes are left out.
    fn tree(count: usize, bounds: impl Fn(u32) -> Aabb) -> (WideBvh<Node8>, Vec<u32>) {
        assert!(
            count < ID_MASK as usize,
            "at most 2^30 primitives per scene"
        );
        let binary = Bvh::build_from(count, |i| bounds(i as u32), SahCost::BLOCKS);
        // The binary nodes are gone (at the end of this scope) before the leaves take
        // their memory.
        let bvh = WideBvh::collapse(&binary);
        (bvh, binary.prims)
    }

    /// The structure with leaves in `layout` over the tree's leaf `order`: inline blocks
    /// of `shape(i)` and `flags(i)`, or the records `indexed(order)` makes.
    fn finish(
        mut bvh: WideBvh<Node8>,
        order: &[u32],
        layout: AccelLayout,
        shape: impl Fn(u32) -> Shape,
        flags: impl Fn(u32) -> u32,
        simd: Simd,
        indexed: impl FnOnce(&[u32]) -> IndexedLeaves,
    ) -> Accel {
        assert!(
            simd.is_supported(),
            "{simd:?} kernels on a CPU without them"
        );
        let leaves = match layout.leaves {
            LeafLayout::Inline => Leaves::Inline(inline_blocks(&mut bvh, order, |i| {
                let v = match shape(i) {
                    Shape::Triangle(v) => v,
                    Shape::Sphere { center, radius } => {
                        [center, Vec3::new(radius, 0.0, 0.0), Vec3::ZERO]
                    }
                };
                (v, i | flags(i))
            })),
            // The wide nodes' leaf lanes already name their first primitive in leaf order.
            LeafLayout::Indexed => Leaves::Indexed(indexed(order)),
        };
        let plain = match &leaves {
            Leaves::Inline(blocks) => blocks.iter().all(Block::is_plain),
            Leaves::Indexed(x) => x.is_plain(),
        };
        let blocks = match &leaves {
            Leaves::Inline(blocks) => Some(&blocks[..]),
            Leaves::Indexed(_) => None,
        };
        let small = SmallTree::of(&bvh, layout.nodes, blocks);
        let tree = match layout.nodes {
            NodeLayout::Full => Tree::Full(bvh),
            NodeLayout::Quantized => Tree::Quantized(bvh.quantize()),
        };
        Accel {
            tree,
            leaves,
            simd,
            plain,
            small,
        }
    }

    pub fn bounds(&self) -> Aabb {
        match &self.tree {
            Tree::Full(t) => t.bounds(),
            Tree::Quantized(t) => t.bounds(),
        }
    }

    pub fn layout(&self) -> AccelLayout {
        AccelLayout {
            nodes: match self.tree {
                Tree::Full(_) => NodeLayout::Full,
                Tree::Quantized(_) => NodeLayout::Quantized,
            },
            leaves: match self.leaves {
                Leaves::Inline(_) => LeafLayout::Inline,
                Leaves::Indexed(_) => LeafLayout::Indexed,
            },
        }
    }

    /// The same structure queried by the traversal even where the tree is one node
    /// ([`SmallTree`]): for tests that the shortcut finds the traversal's hits.
    #[doc(hidden)]
    pub fn without_shortcut(mut self) -> Accel {
        self.small = SmallTree::default();
        self
    }

    /// Bytes of the wide BVH's nodes and of the leaves (blocks, or records and
    /// vertices).
    pub fn memory(&self) -> (usize, usize) {
        let nodes = match &self.tree {
            Tree::Full(t) => size_of_val(&t.nodes[..]),
            Tree::Quantized(t) => size_of_val(&t.nodes[..]),
        };
        let leaves = match &self.leaves {
            Leaves::Inline(blocks) => size_of_val(&blocks[..]),
            Leaves::Indexed(x) => x.memory(),
        };
        (nodes, leaves)
    }

    /// The kernels this structure traces with.
    pub fn simd(&self) -> Simd {
        self.simd
    }

    /// The nearest hit within (0, t_max); hits on flagged triangles count only where
    /// `filter` accepts them. (Always inlined: a dispatch and one call.)
    #[inline(always)]
    pub fn intersect(
        &self,
        ray: &Ray,
        t_max: f32,
        filter: impl Fn(u32, &TriangleHit) -> bool,
    ) -> Option<Hit> {
        let hit = |h: block::LaneHit| Hit {
            prim: h.id,
            t: h.hit.t,
            b1: h.hit.b1,
            b2: h.hit.b2,
        };
        if let Some(sole) = &self.small.leaf {
            return self
                .small_hit::<SoleLeaf, false, _>(sole, ray, t_max, &filter)
                .map(hit);
        }
        if let Some(root) = &self.small.root {
            return self
                .small_hit::<SmallRoot, false, _>(root, ray, t_max, &filter)
                .map(hit);
        }
        // The leaf layout first, so that each kernel's traversal is compiled once per
        // layout, and the indexed one out of line, so that what callers inline is the
        // inline layout's traversal alone (callgrind, instructions a path against main
        // before indexed leaves: both layouts in one function +1.8 % on cornell.toml,
        // both inlined +2.4 % on instances.toml, this +1.1 % and +0.9 %).
        match &self.leaves {
            Leaves::Inline(blocks) => self.intersect_in(&blocks[..], ray, t_max, &filter),
            Leaves::Indexed(x) => self.intersect_indexed(x, ray, t_max, &filter),
        }
    }

    #[inline(never)]
    fn intersect_indexed(
        &self,
        leaves: &IndexedLeaves,
        ray: &Ray,
        t_max: f32,
        filter: &impl Fn(u32, &TriangleHit) -> bool,
    ) -> Option<Hit> {
        self.intersect_in(leaves, ray, t_max, filter)
    }

    /// Whether anything accepted by `filter` lies on the ray within (0, t_max); stops
    /// at the first blocker found. (Always inlined: a dispatch and one call.)
    #[inline(always)]
    pub fn occluded(
        &self,
        ray: &Ray,
        t_max: f32,
        filter: impl Fn(u32, &TriangleHit) -> bool,
    ) -> bool {
        if let Some(sole) = &self.small.leaf {
            return self
                .small_hit::<SoleLeaf, true, _>(sole, ray, t_max, &filter)
                .is_some();
        }
        if let Some(root) = &self.small.root {
            return self
                .small_hit::<SmallRoot, true, _>(root, ray, t_max, &filter)
                .is_some();
        }
        match &self.leaves {
            Leaves::Inline(blocks) => self.occluded_in(&blocks[..], ray, t_max, &filter),
            Leaves::Indexed(x) => self.occluded_indexed(x, ray, t_max, &filter),
        }
    }

    #[inline(never)]
    fn occluded_indexed(
        &self,
        leaves: &IndexedLeaves,
        ray: &Ray,
        t_max: f32,
        filter: &impl Fn(u32, &TriangleHit) -> bool,
    ) -> bool {
        self.occluded_in(leaves, ray, t_max, filter)
    }

    #[inline(always)]
    fn intersect_in<L: LeafBlocks + ?Sized>(
        &self,
        leaves: &L,
        ray: &Ray,
        t_max: f32,
        filter: &impl Fn(u32, &TriangleHit) -> bool,
    ) -> Option<Hit> {
        // SAFETY: `finish` checked that the CPU supports `self.simd`.
        unsafe {
            match self.simd {
                #[cfg(target_arch = "x86_64")]
                Simd::Avx2 if self.plain => {
                    self.intersect_avx2::<true, _, _>(leaves, ray, t_max, filter)
                }
                #[cfg(target_arch = "x86_64")]
                Simd::Avx2 => self.intersect_avx2::<false, _, _>(leaves, ray, t_max, filter),
                #[cfg(target_arch = "x86_64")]
                Simd::Sse => self.intersect_out_of_line::<SseBoxes, { block::SSE }, _, _>(
                    leaves, ray, t_max, filter,
                ),
                _ => self.intersect_out_of_line::<ScalarBoxes, { block::SCALAR }, _, _>(
                    leaves, ray, t_max, filter,
                ),
            }
        }
    }

    #[inline(always)]
    fn occluded_in<L: LeafBlocks + ?Sized>(
        &self,
        leaves: &L,
        ray: &Ray,
        t_max: f32,
        filter: &impl Fn(u32, &TriangleHit) -> bool,
    ) -> bool {
        // SAFETY: `finish` checked that the CPU supports `self.simd`.
        unsafe {
            match self.simd {
                #[cfg(target_arch = "x86_64")]
                Simd::Avx2 if self.plain => {
                    self.occluded_avx2::<true, _, _>(leaves, ray, t_max, filter)
                }
                #[cfg(target_arch = "x86_64")]
                Simd::Avx2 => self.occluded_avx2::<false, _, _>(leaves, ray, t_max, filter),
                #[cfg(target_arch = "x86_64")]
                Simd::Sse => self.occluded_out_of_line::<SseBoxes, { block::SSE }, _, _>(
                    leaves, ray, t_max, filter,
                ),
                _ => self.occluded_out_of_line::<ScalarBoxes, { block::SCALAR }, _, _>(
                    leaves, ray, t_max, filter,
                ),
            }
        }
    }

    // The SSE and scalar traversals out of line, like the AVX2 ones (whose target
    // features keep them there): the dispatch above is then a few instructions that
    // inline into `Scene::intersect` and `Scene::occluded`, with one call to the chosen
    // traversal, instead of an out-of-line function with an 8 KiB stack frame (two
    // stack probes) around that call (callgrind: about 40 instructions a query).

    /// [`Accel::intersect_with`] out of line.
    ///
    /// # Safety
    /// The CPU must support `K` and `LEAF`.
    #[inline(never)]
    unsafe fn intersect_out_of_line<K: BoxTest, const LEAF: u8, L, F>(
        &self,
        leaves: &L,
        ray: &Ray,
        t_max: f32,
        filter: &F,
    ) -> Option<Hit>
    where
        L: LeafBlocks + ?Sized,
        F: Fn(u32, &TriangleHit) -> bool,
    {
        self.intersect_with::<K, LEAF, false, _>(leaves, ray, t_max, filter)
    }

    /// [`Accel::occluded_with`] out of line.
    ///
    /// # Safety
    /// The CPU must support `K` and `LEAF`.
    #[inline(never)]
    unsafe fn occluded_out_of_line<K: BoxTest, const LEAF: u8, L, F>(
        &self,
        leaves: &L,
        ray: &Ray,
        t_max: f32,
        filter: &F,
    ) -> bool
    where
        L: LeafBlocks + ?Sized,
        F: Fn(u32, &TriangleHit) -> bool,
    {
        self.occluded_with::<K, LEAF, false, _>(leaves, ray, t_max, filter)
    }

    /// The traversal compiled with AVX2 enabled, so that its box and triangle kernels
    /// inline, and with the bit-manipulation sets every AVX2 CPU has ([`Simd::best`]
    /// checks them): `blsr`/`tzcnt`/`lzcnt` for the child masks, `shlx` for shifts.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,bmi1,bmi2,lzcnt")]
    unsafe fn intersect_avx2<
        const PLAIN: bool,
        L: LeafBlocks + ?Sized,
        F: Fn(u32, &TriangleHit) -> bool,
    >(
        &self,
        leaves: &L,
        ray: &Ray,
        t_max: f32,
        filter: &F,
    ) -> Option<Hit> {
        self.intersect_with::<Avx2Boxes, { block::AVX2 }, PLAIN, _>(leaves, ray, t_max, filter)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,bmi1,bmi2,lzcnt")]
    unsafe fn occluded_avx2<
        const PLAIN: bool,
        L: LeafBlocks + ?Sized,
        F: Fn(u32, &TriangleHit) -> bool,
    >(
        &self,
        leaves: &L,
        ray: &Ray,
        t_max: f32,
        filter: &F,
    ) -> bool {
        self.occluded_with::<Avx2Boxes, { block::AVX2 }, PLAIN, _>(leaves, ray, t_max, filter)
    }

    /// # Safety
    /// The CPU must support `K` and `LEAF`.
    #[inline(always)]
    unsafe fn intersect_with<K: BoxTest, const LEAF: u8, const PLAIN: bool, L>(
        &self,
        leaves: &L,
        ray: &Ray,
        t_max: f32,
        filter: &impl Fn(u32, &TriangleHit) -> bool,
    ) -> Option<Hit>
    where
        L: LeafBlocks + ?Sized,
    {
        match &self.tree {
            Tree::Full(t) => intersect_tree::<K, LEAF, PLAIN, _, _>(t, leaves, ray, t_max, filter),
            Tree::Quantized(t) => {
                intersect_tree::<K, LEAF, PLAIN, _, _>(t, leaves, ray, t_max, filter)
            }
        }
    }

    /// # Safety
    /// The CPU must support `K` and `LEAF`.
    #[inline(always)]
    unsafe fn occluded_with<K: BoxTest, const LEAF: u8, const PLAIN: bool, L>(
        &self,
        leaves: &L,
        ray: &Ray,
        t_max: f32,
        filter: &impl Fn(u32, &TriangleHit) -> bool,
    ) -> bool
    where
        L: LeafBlocks + ?Sized,
    {
        match &self.tree {
            Tree::Full(t) => occluded_tree::<K, LEAF, PLAIN, _, _>(t, leaves, ray, t_max, filter),
            Tree::Quantized(t) => {
                occluded_tree::<K, LEAF, PLAIN, _, _>(t, leaves, ray, t_max, filter)
            }
        }
    }
}

/// The watertight constants of `ray`, whose reciprocal direction is `inv_d`: under the
/// AVX2 kernel made in registers (`small::setup`), the same bits with no stack round trip
/// to index the axes (callgrind, INLINE split: many-lights 1121 -> 1107 traversal
/// instructions a path, glossy-plates 1805 -> 1802, hdr-sky-sun 749 -> 741).
///
/// # Safety
/// The CPU must support `LEAF`.
#[inline(always)]
unsafe fn watertight<const LEAF: u8>(ray: &Ray, inv_d: glam::Vec3) -> WatertightRay {
    #[cfg(target_arch = "x86_64")]
    if LEAF == block::AVX2 {
        return small::setup::watertight_from_recip(ray, inv_d);
    }
    WatertightRay::from_recip(ray, inv_d)
}

/// # Safety
/// The CPU must support `K` and `LEAF`.
#[inline(always)]
unsafe fn intersect_tree<
    K: BoxTest,
    const LEAF: u8,
    const PLAIN: bool,
    N: WideNode,
    L: LeafBlocks + ?Sized,
>(
    tree: &WideBvh<N>,
    leaves: &L,
    ray: &Ray,
    t_max: f32,
    filter: &impl Fn(u32, &TriangleHit) -> bool,
) -> Option<Hit> {
    let r8 = Ray8::new(ray);
    let wray = watertight::<LEAF>(ray, r8.inv_d);
    let mut best: Option<Hit> = None;
    tree.intersect::<K>(
        &r8,
        t_max,
        #[inline(always)]
        |leaf, count, t_max| {
            // Opaque to the optimizer, so that the block test's broadcasts of the
            // watertight ray are made where a block is tested: otherwise they are
            // hoisted into the query's setup and spilled, paid by every query though
            // a shadow ray tests 0.64 blocks on average (callgrind, Cornell render
            // 128², 1 spp: closest 559.3 -> 545.4 instructions a query, shadow
            // 366.1 -> 347.1). A hint: it changes no result.
            let wray = std::hint::black_box(&wray);
            let hit = leaves.with_block(
                leaf,
                count,
                // Inlined, so that the block test is compiled for the caller's kernels
                // (a closure left out of line gets none: twice the instructions a path).
                #[inline(always)]
                |block| block.intersect::<LEAF, false, PLAIN>(ray, wray, count, t_max, filter),
            );
            match hit {
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
        |leaf| leaves.prefetch(leaf),
    );
    best
}

/// # Safety
/// The CPU must support `K` and `LEAF`.
#[inline(always)]
unsafe fn occluded_tree<
    K: BoxTest,
    const LEAF: u8,
    const PLAIN: bool,
    N: WideNode,
    L: LeafBlocks + ?Sized,
>(
    tree: &WideBvh<N>,
    leaves: &L,
    ray: &Ray,
    t_max: f32,
    filter: &impl Fn(u32, &TriangleHit) -> bool,
) -> bool {
    let r8 = Ray8::new(ray);
    let wray = watertight::<LEAF>(ray, r8.inv_d);
    tree.occluded::<K>(
        &r8,
        t_max,
        #[inline(always)]
        |leaf, count, t_max| {
            // As in `intersect_tree`: the broadcasts where a block is tested.
            let wray = std::hint::black_box(&wray);
            leaves.with_block(
                leaf,
                count,
                // Inlined, so that the block test is compiled for the caller's kernels
                // (a closure left out of line gets none: twice the instructions a path).
                #[inline(always)]
                |block| {
                    block
                        .intersect::<LEAF, true, PLAIN>(ray, wray, count, t_max, filter)
                        .is_some()
                },
            )
        },
    )
}

/// Where the traversal finds a leaf's block: the inline blocks hold it, an indexed leaf
/// gathers it.
trait LeafBlocks {
    /// `test` on the block of leaf lane `leaf` (`count` primitives).
    fn with_block<R>(&self, leaf: u32, count: u32, test: impl FnOnce(&Block) -> R) -> R;
    /// Asks for leaf `leaf`'s memory to be loaded (see [`crate::bvh::prefetch`]).
    fn prefetch(&self, leaf: u32);
}

impl LeafBlocks for [Block] {
    #[inline(always)]
    fn with_block<R>(&self, leaf: u32, _: u32, test: impl FnOnce(&Block) -> R) -> R {
        test(&self[leaf as usize])
    }

    #[inline(always)]
    fn prefetch(&self, leaf: u32) {
        let at = self.as_ptr().wrapping_add(leaf as usize);
        crate::bvh::prefetch(at as *const u8, size_of::<Block>() / 64)
    }
}

impl LeafBlocks for IndexedLeaves {
    #[inline(always)]
    fn with_block<R>(&self, leaf: u32, count: u32, test: impl FnOnce(&Block) -> R) -> R {
        test(&self.block(leaf, count))
    }

    #[inline(always)]
    fn prefetch(&self, leaf: u32) {
        // The records (the vertices they name are known only once these are loaded).
        crate::bvh::prefetch(self.record_at(leaf), 1)
    }
}

/// The flag bits of a primitive's id.
fn flags_of(shape: &Shape, filtered: bool) -> u32 {
    match shape {
        Shape::Sphere { .. } => SPHERE,
        Shape::Triangle(_) if filtered => FILTERED,
        Shape::Triangle(_) => 0,
    }
}

/// One block a leaf lane of `bvh`, in its nodes' order, each lane then naming its block
/// rather than its first primitive of `order`; `record(i)` gives primitive `i`'s block
/// lane (vertices, id with flags).
fn inline_blocks(
    bvh: &mut WideBvh<Node8>,
    order: &[u32],
    record: impl Fn(u32) -> ([Vec3; 3], u32),
) -> Vec<Block> {
    let leaves = bvh
        .nodes
        .iter()
        .flat_map(|n| n.count)
        .filter(|&c| c > 0)
        .count();
    let mut blocks = Vec::with_capacity(leaves);
    for node in &mut bvh.nodes {
        for lane in 0..node.child.len() {
            let count = node.count[lane] as usize;
            if count > 0 {
                let first = node.child[lane] as usize;
                let prims = &order[first..first + count];
                node.child[lane] = blocks.len() as u32;
                blocks.push(Block::gather(prims.iter().map(|&i| record(i))));
            }
        }
    }
    blocks
}
