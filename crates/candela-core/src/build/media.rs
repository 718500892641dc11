//! Media from their description: validated coefficients and grids, each shape's boundary
//! turned into a material of its own that carries the [`MediumInterface`], null surfaces
//! marked, and the camera's medium.

use std::collections::HashMap;

use glam::{Affine3A, Vec3};

use super::{check_finite, err, BuildError};
use crate::alpha::AlphaMask;
use crate::desc::{BsdfDesc, GridDesc, MediumKindDesc, PhaseDesc, SceneDesc, Span, VolumeDesc};
use crate::material::{Material, MaterialId};
use crate::medium::grid::Albedo;
use crate::medium::{
    GridMedium, HenyeyGreenstein, Homogeneous, Medium, MediumId, MediumInterface, SceneMedia,
    SurfaceMedia, VoxelGrid,
};

/// Media being built alongside the shapes.
pub(super) struct MediaBuilder<'a> {
    desc: &'a SceneDesc,
    ids: HashMap<&'a str, MediumId>,
    media: Vec<Medium>,
    /// Interface of each shape that has one, by shape index.
    shapes: HashMap<usize, MediumInterface>,
    /// The materials made for bounded shapes: the copy, its original, the interface.
    interfaces: Vec<(MaterialId, MaterialId, MediumInterface)>,
}

impl<'a> MediaBuilder<'a> {
    /// Validates and builds every medium and resolves the shapes' and camera's names.
    pub(super) fn new(desc: &'a SceneDesc) -> Result<Self, BuildError> {
        let mut ids = HashMap::new();
        let mut media = Vec::new();
        for m in &desc.media.media {
            if ids
                .insert(m.name.as_str(), MediumId(media.len() as u32))
                .is_some()
            {
                return err(&m.span, format!("medium \"{}\" is defined twice", m.name));
            }
            let phase = build_phase(m.phase, &m.span)?;
            media.push(build_medium(&m.kind, phase, &m.span)?);
        }
        let resolve = |name: &Option<String>, span: &Span| match name {
            None => Ok(None),
            Some(n) => match ids.get(n.as_str()) {
                Some(&id) => Ok(Some(id)),
                None => err(span, format!("unknown medium \"{n}\"")),
            },
        };
        let mut shapes = HashMap::new();
        for s in &desc.media.shapes {
            if s.shape >= desc.shapes.len() {
                return err(&s.span, format!("no shape {} to bound a medium", s.shape));
            }
            let iface = MediumInterface {
                interior: resolve(&s.interior, &s.span)?,
                exterior: resolve(&s.exterior, &s.span)?,
            };
            shapes.insert(s.shape, iface);
        }
        resolve(&desc.media.camera, &desc.media.camera_span)?;
        Ok(MediaBuilder {
            desc,
            ids,
            media,
            shapes,
            interfaces: Vec::new(),
        })
    }

    /// The material shape `shape` renders with: `material` itself, or where the shape
    /// bounds media a copy of it (appended to `materials` and `alphas`) that carries the
    /// interface.
    pub(super) fn shape_material(
        &mut self,
        shape: usize,
        material: MaterialId,
        materials: &mut Vec<Material>,
        alphas: &mut Vec<Option<AlphaMask>>,
    ) -> MaterialId {
        let Some(&iface) = self.shapes.get(&shape) else {
            return material;
        };
        let id = MaterialId(materials.len() as u32);
        materials.push(materials[material.0 as usize].clone());
        alphas.push(alphas[material.0 as usize].clone());
        self.interfaces.push((id, material, iface));
        id
    }

    /// The scene's media, or `None` where it has neither media nor null surfaces (then
    /// the plain path tracer renders it, exactly as before media existed).
    pub(super) fn finish(self, material_count: usize) -> Option<Box<SceneMedia>> {
        let desc = self.desc;
        let null: Vec<bool> = desc
            .materials
            .iter()
            .map(|m| matches!(m.bsdf, BsdfDesc::Null))
            .collect();
        if self.media.is_empty() && !null.contains(&true) {
            return None;
        }
        let mut surfaces = vec![SurfaceMedia::default(); material_count];
        for (s, &n) in surfaces.iter_mut().zip(&null) {
            s.null = n;
        }
        for &(copy, original, iface) in &self.interfaces {
            surfaces[copy.0 as usize] = SurfaceMedia {
                null: null.get(original.0 as usize).copied().unwrap_or(false),
                interface: Some(iface),
            };
        }
        let camera = desc
            .media
            .camera
            .as_deref()
            .and_then(|n| self.ids.get(n).copied());
        Some(Box::new(SceneMedia {
            media: self.media,
            surfaces,
            camera,
        }))
    }
}

fn build_phase(p: PhaseDesc, span: &Span) -> Result<HenyeyGreenstein, BuildError> {
    match p {
        PhaseDesc::Isotropic => Ok(HenyeyGreenstein::ISOTROPIC),
        PhaseDesc::HenyeyGreenstein { g } => {
            if !(g.is_finite() && g.abs() < 1.0) {
                return err(span, format!("phase g {g} must lie in (-1, 1)"));
            }
            Ok(HenyeyGreenstein::new(g))
        }
    }
}

fn check_coefficient(span: &Span, what: &str, v: Vec3) -> Result<(), BuildError> {
    check_finite(span, what, &v.to_array())?;
    if v.min_element() < 0.0 {
        return err(span, format!("{what} must not be negative"));
    }
    Ok(())
}

fn check_albedo(span: &Span, a: Vec3) -> Result<(), BuildError> {
    check_coefficient(span, "albedo", a)?;
    if a.max_element() > 1.0 {
        return err(span, "albedo must lie in [0, 1]");
    }
    Ok(())
}

fn build_grid(g: &GridDesc, span: &Span) -> Result<VoxelGrid, BuildError> {
    VoxelGrid::new(g.res, g.channels, g.data.clone()).or_else(|m| err(span, m))
}

fn build_medium(
    kind: &MediumKindDesc,
    phase: HenyeyGreenstein,
    span: &Span,
) -> Result<Medium, BuildError> {
    Ok(match kind {
        MediumKindDesc::Homogeneous { sigma_t, albedo } => {
            check_coefficient(span, "sigma_t", *sigma_t)?;
            check_albedo(span, *albedo)?;
            Medium::Homogeneous(Homogeneous::from_albedo(*sigma_t, *albedo, phase))
        }
        MediumKindDesc::Grid {
            sigma_t,
            albedo,
            scale,
            to_world,
        } => {
            check_finite(span, "scale", &[*scale])?;
            if *scale < 0.0 {
                return err(span, "scale must not be negative");
            }
            check_finite(span, "to_world", &to_world.to_cols_array())?;
            if to_world.determinant() == 0.0 {
                return err(span, "to_world is singular");
            }
            let albedo = match albedo {
                VolumeDesc::Constant(a) => {
                    check_albedo(span, *a)?;
                    Albedo::Constant(*a)
                }
                VolumeDesc::Grid(g) => Albedo::Grid(build_grid(g, span)?),
            };
            let world_to_local = Affine3A::from_mat4(to_world.inverse());
            Medium::Grid(GridMedium::new(
                build_grid(sigma_t, span)?,
                albedo,
                *scale,
                world_to_local,
                phase,
            ))
        }
    })
}
