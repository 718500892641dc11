//! Constructors and builder methods for writing a description in code (tests, examples,
//! benchmarks, programs that make scenes): each item starts from the plain defaults a
//! loader would give it (no emission, placed by the identity, made in code), and builder
//! methods change one thing each.
//!
//! ```
//! use candela_core::desc::*;
//! use glam::{Mat4, Vec3};
//!
//! let lamp = ShapeDesc::new(GeometryDesc::Rectangle, "black")
//!     .transformed(Mat4::from_translation(Vec3::Y))
//!     .emitting(Vec3::splat(5.0));
//! assert_eq!(lamp.emission, Some(Vec3::splat(5.0)));
//! assert!(!lamp.flip_normals);
//! let white = MaterialDesc::diffuse("white", Vec3::splat(0.8));
//! assert_eq!(white.name, "white");
//! ```

use std::sync::Arc;

use glam::{Mat4, Vec3};

use super::{
    BsdfDesc, CameraDesc, GeometryDesc, LightDesc, LightKindDesc, MaterialDesc, MeshDesc,
    ShapeDesc, Span, TextureDesc,
};

impl ShapeDesc {
    /// `geometry` of the material named `material`: not emitting, placed by the identity,
    /// normals as the geometry has them, made in code.
    pub fn new(geometry: GeometryDesc, material: impl Into<String>) -> ShapeDesc {
        ShapeDesc {
            geometry,
            material: material.into(),
            emission: None,
            emission_texture: None,
            transform: Mat4::IDENTITY,
            flip_normals: false,
            span: Span::code(),
        }
    }

    /// A sphere of `radius` around `center` (see [`ShapeDesc::new`]).
    pub fn sphere(center: Vec3, radius: f32, material: impl Into<String>) -> ShapeDesc {
        ShapeDesc::new(GeometryDesc::Sphere { center, radius }, material)
    }

    /// A triangle mesh (see [`ShapeDesc::new`]); shapes given the same `Arc` share it.
    pub fn mesh(mesh: impl Into<Arc<MeshDesc>>, material: impl Into<String>) -> ShapeDesc {
        ShapeDesc::new(GeometryDesc::Mesh(mesh.into()), material)
    }

    /// This shape placed by `transform` (object to world), in place of its transform.
    pub fn transformed(self, transform: Mat4) -> ShapeDesc {
        ShapeDesc { transform, ..self }
    }

    /// This shape emitting `radiance` (W·sr⁻¹·m⁻²) from its front side.
    pub fn emitting(self, radiance: Vec3) -> ShapeDesc {
        self.with_emission(Some(radiance))
    }

    /// This shape with `emission` in place of its own (`None`: not emitting).
    pub fn with_emission(self, emission: Option<Vec3>) -> ShapeDesc {
        ShapeDesc { emission, ..self }
    }

    /// This shape's emission multiplied by `texture` at each point.
    pub fn with_emission_texture(self, texture: TextureDesc) -> ShapeDesc {
        ShapeDesc {
            emission_texture: Some(texture),
            ..self
        }
    }

    /// This shape with its normals (and the side it emits from) turned around where
    /// `flip` is set.
    pub fn with_flipped_normals(self, flip: bool) -> ShapeDesc {
        ShapeDesc {
            flip_normals: flip,
            ..self
        }
    }
}

impl MaterialDesc {
    /// A material named `name`, made in code.
    pub fn new(name: impl Into<String>, bsdf: BsdfDesc) -> MaterialDesc {
        MaterialDesc {
            name: name.into(),
            bsdf,
            span: Span::code(),
        }
    }

    /// A Lambertian material of constant `albedo`.
    pub fn diffuse(name: impl Into<String>, albedo: Vec3) -> MaterialDesc {
        MaterialDesc::new(name, BsdfDesc::diffuse(albedo))
    }
}

impl BsdfDesc {
    /// Lambertian reflection of constant `albedo`.
    pub fn diffuse(albedo: Vec3) -> BsdfDesc {
        BsdfDesc::Diffuse {
            albedo: TextureDesc::Constant(albedo),
        }
    }
}

impl LightDesc {
    /// A light of `kind`, made in code.
    pub fn new(kind: LightKindDesc) -> LightDesc {
        LightDesc {
            kind,
            span: Span::code(),
        }
    }

    /// An isotropic point light of radiant intensity `intensity` (W/sr per channel).
    pub fn point(position: Vec3, intensity: Vec3) -> LightDesc {
        LightDesc::new(LightKindDesc::Point {
            position,
            intensity,
        })
    }
}

impl CameraDesc {
    /// A pinhole at `position` looking at `look_at`, up +y, `fov_y_deg` degrees
    /// vertically; the rest as [`CameraDesc::default`].
    pub fn looking_at(position: Vec3, look_at: Vec3, fov_y_deg: f32) -> CameraDesc {
        CameraDesc {
            position,
            look_at,
            fov_y_deg,
            ..CameraDesc::default()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builders_start_from_the_plain_defaults() {
        let s = ShapeDesc::sphere(Vec3::X, 2.0, "m");
        assert!(matches!(s.geometry, GeometryDesc::Sphere { center, radius }
            if center == Vec3::X && radius == 2.0));
        assert_eq!(
            (s.material.as_str(), s.emission, s.transform, s.flip_normals),
            ("m", None, Mat4::IDENTITY, false)
        );
        assert!(s.emission_texture.is_none() && s.span == Span::code());
        let t = Mat4::from_scale(Vec3::splat(3.0));
        let s = s
            .transformed(t)
            .emitting(Vec3::ONE)
            .with_flipped_normals(true)
            .with_emission_texture(TextureDesc::Constant(Vec3::Y));
        assert_eq!(
            (s.emission, s.transform, s.flip_normals),
            (Some(Vec3::ONE), t, true)
        );
        assert!(matches!(s.emission_texture, Some(TextureDesc::Constant(c)) if c == Vec3::Y));
        assert_eq!(s.with_emission(None).emission, None);

        let mesh = Arc::new(MeshDesc::default());
        let a = ShapeDesc::mesh(mesh.clone(), "m");
        assert!(matches!(&a.geometry, GeometryDesc::Mesh(m) if Arc::ptr_eq(m, &mesh)));

        let m = MaterialDesc::diffuse("white", Vec3::splat(0.5));
        assert!(
            matches!(m.bsdf, BsdfDesc::Diffuse { albedo: TextureDesc::Constant(c) }
            if c == Vec3::splat(0.5))
        );
        let l = LightDesc::point(Vec3::Y, Vec3::ONE);
        assert!(
            matches!(l.kind, LightKindDesc::Point { position, intensity }
            if position == Vec3::Y && intensity == Vec3::ONE)
        );
        let c = CameraDesc::looking_at(Vec3::Z, Vec3::ZERO, 30.0);
        assert_eq!(
            (c.position, c.look_at, c.up, c.fov_y_deg),
            (Vec3::Z, Vec3::ZERO, Vec3::Y, 30.0)
        );
        assert!(c.lens.is_none() && c.ortho_height.is_none());
    }
}
