//! The state of eight paths in lanes, structure of arrays: what the lane stages read and
//! write as vectors (throughput, η scale) in [`F32x8`] form, what the per-lane scalar code
//! reads (rays, hits, radiance, previous vertex) as arrays of records, and each lane's
//! sampler and pixel sample.

use glam::{UVec2, Vec2, Vec3};

use super::simd::{Lanes32, Vec3Lanes, LANES};
use crate::geometry::Ray;
use crate::integrator::path::PrevVertex;
use crate::light::ShadingCtx;
use crate::scene::SurfaceInteraction;

/// Eight paths, one a lane. A lane is *busy* while it holds a pixel sample (`slot` is
/// `Some`); a busy lane whose path ends hands its radiance back and takes the band's next
/// pixel sample, if any is left.
pub(super) struct PathLanes<S> {
    /// Each lane's sample stream, positioned in its current pixel sample.
    pub samplers: [S; LANES],
    /// The pixel sample a lane follows: its index among the band's samples (pixel-major,
    /// then sample index), its pixel and its film position.
    pub slot: [Option<usize>; LANES],
    pub pixel: [UVec2; LANES],
    pub film_pos: [Vec2; LANES],
    /// The ray to trace next.
    pub ray: [Ray; LANES],
    /// Where the last ray hit (written by the trace, read when the next ray is spawned).
    pub hit: [Option<SurfaceInteraction>; LANES],
    /// Radiance gathered so far.
    pub l: [Vec3; LANES],
    /// Path throughput.
    pub beta: Vec3Lanes,
    /// The product of η′² over the refractions so far (see `Bsdf::eta_crossed_sq`).
    pub eta_scale: Lanes32,
    /// Scattering events so far.
    pub depth: [u32; LANES],
    /// Whether the last bounce was a delta lobe (or the path just left the camera).
    pub specular: [bool; LANES],
    /// The previous scattering vertex, for MIS of emission the next ray finds.
    pub prev: [PrevVertex; LANES],
}

impl<S: Clone> PathLanes<S> {
    /// Eight idle lanes, each with a copy of `sampler`.
    pub fn new(sampler: &S) -> PathLanes<S> {
        let ray = Ray::new(Vec3::ZERO, Vec3::Z);
        PathLanes {
            samplers: std::array::from_fn(|_| sampler.clone()),
            slot: [None; LANES],
            pixel: [UVec2::ZERO; LANES],
            film_pos: [Vec2::ZERO; LANES],
            ray: [ray; LANES],
            hit: [None; LANES],
            l: [Vec3::ZERO; LANES],
            beta: Vec3Lanes::splat(Vec3::ONE),
            eta_scale: [1.0; LANES],
            depth: [0; LANES],
            specular: [true; LANES],
            prev: [PrevVertex {
                ctx: ShadingCtx {
                    p: Vec3::ZERO,
                    n: Vec3::ZERO,
                },
                bsdf_pdf: 0.0,
            }; LANES],
        }
    }

    /// The busy lanes (bit `i` for lane `i`).
    #[inline(always)]
    pub fn busy(&self) -> u32 {
        (0..LANES).fold(0, |m, i| m | (self.slot[i].is_some() as u32) << i)
    }

    /// Starts lane `i` on pixel sample `slot`, of pixel `pixel`, whose camera ray through
    /// `film_pos` is `ray` (its sampler already positioned there): the state a path starts
    /// with.
    #[inline(always)]
    pub fn start(&mut self, i: usize, slot: usize, pixel: UVec2, film_pos: Vec2, ray: Ray) {
        self.slot[i] = Some(slot);
        self.pixel[i] = pixel;
        self.film_pos[i] = film_pos;
        self.ray[i] = ray;
        self.l[i] = Vec3::ZERO;
        self.beta.set_lane(i, Vec3::ONE);
        self.eta_scale[i] = 1.0;
        self.depth[i] = 0;
        self.specular[i] = true;
        self.prev[i] = PrevVertex {
            ctx: ShadingCtx {
                p: ray.o,
                n: Vec3::ZERO,
            },
            bsdf_pdf: 0.0,
        };
    }
}
