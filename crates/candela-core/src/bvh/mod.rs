//! Bounding volume hierarchies over primitive boxes.
//!
//! [`Bvh`] is the binary tree of the binned SAH build (Wald 2007); it is also kept as the
//! reference traversal the tests compare against. [`WideBvh`] is that tree collapsed to
//! four children per node with the children's boxes stored side by side, so that one
//! SIMD slab test checks all four at once (Wald et al. 2008, "Getting Rid of Packets";
//! Dammertz et al. 2008, "Shallow Bounding Volume Hierarchies"). That is what the scene
//! traces rays through.
//!
//! Neither knows of triangles or spheres: traversal calls a closure with the leaf-order
//! range of each leaf whose box the ray enters, so any primitive type can sit in them
//! (the scene's [`crate::accel`] lays its primitives out in that order).

mod binary;
mod box4;
mod extents;
mod wide;

pub use binary::{Bvh, BvhNode};
pub use box4::{hit4_scalar, Ray4, T_MAX_SCALE};
pub use wide::{Node4, WideBvh};
