//! Candela's render-time core: sampling, geometry, the BVH, cameras, BSDFs, lights and
//! light selection, the path tracer and the film. It does no file I/O: loaders produce a
//! [`desc::SceneDesc`] and [`build::build`] turns it into a [`Scene`].
//!
//! ```
//! use candela_core::desc::*;
//! use glam::Vec3;
//! use std::sync::atomic::AtomicBool;
//!
//! let mut desc = SceneDesc::default();
//! desc.render = RenderSettings { width: 8, height: 8, spp: 4, ..Default::default() };
//! desc.materials.push(MaterialDesc::diffuse("white", Vec3::splat(0.8)));
//! desc.shapes.push(ShapeDesc::sphere(Vec3::ZERO, 1.0, "white").emitting(Vec3::ONE));
//! let scene = candela_core::build::build(&desc).unwrap();
//! let result = candela_core::integrator::render(&scene, 0..4, &AtomicBool::new(false), &|_| {});
//! assert_eq!(result.film.resolve()[4 * 8 + 4], Vec3::ONE); // the centre pixel sees the sphere
//! ```

pub mod accel;
pub mod alpha;
pub mod aov;
pub mod bsdf;
pub mod build;
pub mod bvh;
pub mod camera;
pub mod chi2;
pub mod color;
pub mod desc;
pub mod exact_sum;
pub mod film;
pub mod filter;
pub mod fingerprint;
pub mod geometry;
pub mod instance;
pub mod integrator;
pub mod isa;
pub mod lane_expf;
pub mod light;
pub mod light_sampler;
pub mod limb_sums;
pub mod material;
pub mod math;
pub mod medium;
pub mod options;
pub mod sampler;
pub mod sampling;
pub mod scene;
pub mod splat;
pub mod texture;

pub use desc::photometry;
pub use scene::Scene;
