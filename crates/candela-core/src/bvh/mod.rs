//! Bounding volume hierarchies over primitive boxes.
//!
//! [`Bvh`] is the binary tree of the binned SAH build (Wald 2007); it is also kept as the
//! reference traversal the tests compare against. [`WideBvh`] is that tree collapsed to
//! eight children per node with the children's boxes stored side by side, so that one
//! SIMD slab test checks all eight at once (Wald et al. 2008, "Getting Rid of Packets";
//! Dammertz et al. 2008, "Shallow Bounding Volume Hierarchies"; Embree's BVH8). That is
//! what the scene traces rays through, with the box kernel [`Simd::best`] picks. Its
//! nodes keep full f32 planes ([`Node8`]) or, after [`WideBvh::quantize`], child boxes
//! in bytes against a per-node frame ([`QNode8`], half the size; Ylitie et al. 2017),
//! which contain the exact boxes, so both find the same hits.
//!
//! Neither knows of triangles or spheres: traversal calls a closure with the leaf-order
//! range of each leaf whose box the ray enters, so any primitive type can sit in them
//! (the scene's [`crate::accel`] lays its primitives out in that order).

mod binary;
mod box8;
mod extents;
mod packet;
mod quant8;
mod wide;

pub use binary::{Bvh, BvhNode, SahCost};
pub(crate) use box8::{finite, FAR_SCALE};
pub use box8::{hit8_scalar, BoxTest, Planes8, Ray8, ScalarBoxes, Simd, T_MAX_SCALE};
#[cfg(target_arch = "x86_64")]
pub use box8::{Avx2Boxes, SseBoxes};
#[cfg(target_arch = "x86_64")]
pub use packet::{BoxAgainstRays, Children, PacketTest, RaysAgainstBoxes};
pub use quant8::QBoxes8;
pub use wide::{prefetch, Node8, QNode8, WideBvh, WideNode};
