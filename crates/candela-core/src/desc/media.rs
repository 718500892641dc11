//! The description of participating media: named media, the shapes that bound them and
//! the medium the camera sits in (see [`crate::medium`] for how they render).

use std::sync::Arc;

use glam::{Mat4, Vec3};

use super::Span;

/// The scene's media. Empty by default: a scene without media (and without
/// [`super::BsdfDesc::Null`] surfaces) renders with the plain path tracer.
#[derive(Clone, Debug, Default)]
pub struct MediaDesc {
    pub media: Vec<MediumDesc>,
    /// Media on either side of shapes, by index into [`super::SceneDesc::shapes`].
    pub shapes: Vec<ShapeMediaDesc>,
    /// The medium around the camera, by name: with no shape around it, a scene-wide fog.
    pub camera: Option<String>,
    pub camera_span: Span,
}

/// A named medium.
#[derive(Clone, Debug)]
pub struct MediumDesc {
    pub name: String,
    pub kind: MediumKindDesc,
    pub phase: PhaseDesc,
    pub span: Span,
}

/// What a medium is made of. Coefficients are per scene unit; the single-scattering
/// albedo σs/σt is in [0, 1] per channel.
#[derive(Clone, Debug)]
pub enum MediumKindDesc {
    /// The same extinction σt and albedo everywhere.
    Homogeneous { sigma_t: Vec3, albedo: Vec3 },
    /// σt = `scale` × a grid (trilinear), in the unit cube that `to_world` places.
    Grid {
        sigma_t: Arc<GridDesc>,
        albedo: VolumeDesc,
        scale: f32,
        to_world: Mat4,
    },
}

/// A quantity over a medium's volume.
#[derive(Clone, Debug)]
pub enum VolumeDesc {
    Constant(Vec3),
    Grid(Arc<GridDesc>),
}

/// Voxel values: `res` cells, x fastest, then y, then z; `channels` (1 or 3) per cell.
#[derive(Clone, Debug, PartialEq)]
pub struct GridDesc {
    pub res: [u32; 3],
    pub channels: u32,
    pub data: Vec<f32>,
}

/// A phase function.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum PhaseDesc {
    #[default]
    Isotropic,
    /// Henyey–Greenstein with mean cosine `g` ∈ (−1, 1).
    HenyeyGreenstein { g: f32 },
}

/// The media inside (against the normals) and outside a shape, by name; `None` is
/// vacuum. A shape with no entry leaves a crossing ray in the medium it was in.
#[derive(Clone, Debug)]
pub struct ShapeMediaDesc {
    pub shape: usize,
    pub interior: Option<String>,
    pub exterior: Option<String>,
    pub span: Span,
}
