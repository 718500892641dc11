//! How the acceleration structure lays out its nodes and leaves. Every layout finds the
//! same hits, bit for bit; they trade memory for speed.

use crate::desc::AccelStorage;

/// How the wide BVH's nodes store their child boxes. Both find the same hits (the
/// quantized boxes contain the exact ones, and the primitive tests decide).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum NodeLayout {
    /// Full f32 planes ([`crate::bvh::Node8`], 256 bytes a node): the default, the
    /// faster one measured (bench/README.md, "Compressed nodes").
    #[default]
    Full,
    /// Child boxes in bytes against a per-node frame ([`crate::bvh::QNode8`], 128 bytes
    /// a node).
    Quantized,
}

/// How a leaf's primitives are stored.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LeafLayout {
    /// One block of eight lanes a leaf with the vertices copied in (320 bytes, ready for
    /// the vector test): about 86 bytes a triangle on a height field, the fastest.
    #[default]
    Inline,
    /// Per primitive three indices into one shared vertex array and the id (16 bytes,
    /// and the vertices once, 12 bytes each), gathered into a block when a ray reaches
    /// the leaf: about a quarter of the memory, for some speed.
    Indexed,
}

/// Both layout choices.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AccelLayout {
    pub nodes: NodeLayout,
    pub leaves: LeafLayout,
}

impl From<NodeLayout> for AccelLayout {
    fn from(nodes: NodeLayout) -> AccelLayout {
        AccelLayout {
            nodes,
            leaves: LeafLayout::Inline,
        }
    }
}

/// Primitives from which [`LeafLayout::auto`] stores leaves indexed: 2²² (4.2 million),
/// where inline blocks would take about 360 MB. Below it a scene's memory is small next
/// to the machine's and the faster layout is kept; above it the peak memory of load and
/// build grows by the blocks' 86 bytes a triangle against the indexed leaves' 22, the
/// larger share of a scene's footprint (bench/RESULTS.md, bigscene).
pub const INDEXED_FROM: usize = 1 << 22;

impl LeafLayout {
    /// The layout `storage` asks for over `primitives`.
    pub fn choose(storage: AccelStorage, primitives: usize) -> LeafLayout {
        match storage {
            AccelStorage::Auto => LeafLayout::auto(primitives),
            AccelStorage::Inline => LeafLayout::Inline,
            AccelStorage::Compact => LeafLayout::Indexed,
        }
    }

    /// The layout for a structure over `primitives`: [`LeafLayout::Indexed`] from
    /// [`INDEXED_FROM`] on, else [`LeafLayout::Inline`].
    pub fn auto(primitives: usize) -> LeafLayout {
        if primitives >= INDEXED_FROM {
            LeafLayout::Indexed
        } else {
            LeafLayout::Inline
        }
    }
}
