//! The scene description: plain data that loaders produce and [`crate::build`] turns into
//! a render-time [`crate::Scene`].
//!
//! Everything here is owned, plain and cloneable, so a program can also write a scene in
//! code. Every item remembers where it came from ([`Span`]) so that build errors can point
//! at the file, line and column that caused them. Units: radiance in W·sr⁻¹·m⁻², linear
//! Rec.709 primaries; lengths in scene units; angles in degrees where a field says so.

use std::fmt;
use std::sync::Arc;

use glam::{Mat4, Vec2, Vec3};

/// Where an item of a description came from: `file:line:col` (1-based). Items made in code
/// have an empty file name and line 0.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Span {
    pub file: Arc<str>,
    pub line: u32,
    pub col: u32,
}

impl Span {
    pub fn new(file: impl Into<Arc<str>>, line: u32, col: u32) -> Span {
        Span {
            file: file.into(),
            line,
            col,
        }
    }

    /// A span for items built in code rather than loaded from a file.
    pub fn code() -> Span {
        Span::default()
    }
}

impl fmt::Display for Span {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match (self.file.is_empty(), self.line) {
            (true, _) => write!(f, "<code>"),
            (false, 0) => write!(f, "{}", self.file),
            (false, _) if self.col == 0 => write!(f, "{}:{}", self.file, self.line),
            (false, _) => write!(f, "{}:{}:{}", self.file, self.line, self.col),
        }
    }
}

/// A complete scene: what to render and how.
#[derive(Clone, Debug, Default)]
pub struct SceneDesc {
    pub camera: CameraDesc,
    pub materials: Vec<MaterialDesc>,
    pub shapes: Vec<ShapeDesc>,
    pub lights: Vec<LightDesc>,
    pub render: RenderSettings,
}

/// A camera placed by position, target and up vector.
#[derive(Clone, Debug)]
pub struct CameraDesc {
    pub position: Vec3,
    pub look_at: Vec3,
    pub up: Vec3,
    /// Vertical field of view in degrees; ignored when `focal_length_mm` is set.
    pub fov_y_deg: f32,
    /// Focal length in millimetres: with `sensor_mm`, the alternative to `fov_y_deg`.
    pub focal_length_mm: Option<f32>,
    /// Sensor size in millimetres (width, height); its height spans the image's height.
    /// Default 36×24 mm (full frame).
    pub sensor_mm: Vec2,
    /// A thin lens for depth of field; `None` is a pinhole.
    pub lens: Option<LensDesc>,
    pub span: Span,
}

impl Default for CameraDesc {
    fn default() -> Self {
        CameraDesc {
            position: Vec3::new(0.0, 0.0, 5.0),
            look_at: Vec3::ZERO,
            up: Vec3::Y,
            fov_y_deg: 40.0,
            focal_length_mm: None,
            sensor_mm: Vec2::new(36.0, 24.0),
            lens: None,
            span: Span::code(),
        }
    }
}

/// A thin lens: where it focuses, how wide it opens and the shape of its aperture.
#[derive(Clone, Debug, Default)]
pub struct LensDesc {
    pub focus: FocusDesc,
    pub size: ApertureSizeDesc,
    pub aperture: ApertureDesc,
}

/// Where a thin lens focuses.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum FocusDesc {
    /// On the camera's `look_at` point.
    #[default]
    LookAt,
    /// At this distance along the view axis, in scene units.
    Distance(f32),
    /// On the plane through this point, perpendicular to the view axis.
    Point(Vec3),
}

/// How wide a thin lens opens.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ApertureSizeDesc {
    /// Radius in scene units (the circumradius of a polygonal aperture).
    Radius(f32),
    /// f-number N: radius = focal length / (2N), with scene units taken as metres.
    FNumber(f32),
}

impl Default for ApertureSizeDesc {
    fn default() -> Self {
        ApertureSizeDesc::Radius(0.0)
    }
}

/// The shape of a thin lens's aperture.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum ApertureDesc {
    #[default]
    Disc,
    /// A regular polygon of `blades` corners on the aperture circle; corner 0 points up
    /// at rotation 0, and `rotation_deg` turns it counter-clockwise.
    Polygon { blades: u32, rotation_deg: f32 },
    /// An image mask: decoded linear luminance, `width`×`height`, row-major from the top
    /// row. Fitted into the aperture circle's bounding square, longer side to diameter.
    Image {
        width: u32,
        height: u32,
        luminance: Vec<f32>,
    },
}

/// A named material. Shapes refer to materials by name; the build resolves the names.
#[derive(Clone, Debug)]
pub struct MaterialDesc {
    pub name: String,
    pub bsdf: BsdfDesc,
    pub span: Span,
}

/// The scattering model of a material.
#[derive(Clone, Debug)]
pub enum BsdfDesc {
    /// Lambertian reflection with the given albedo.
    Diffuse { albedo: TextureDesc },
    /// The inner BSDF on the front (the side the shading normal points to) and black
    /// from the back, as Mitsuba's reflective BSDFs are unless wrapped in `twosided`.
    OneSided(Box<BsdfDesc>),
}

/// A colour that may vary over a surface. Values are linear.
#[derive(Clone, Debug)]
pub enum TextureDesc {
    Constant(Vec3),
}

/// A shape, its material, its emission and its placement.
#[derive(Clone, Debug)]
pub struct ShapeDesc {
    pub geometry: GeometryDesc,
    /// Name of a [`MaterialDesc`].
    pub material: String,
    /// Emitted radiance (W·sr⁻¹·m⁻²) on the side the surface normal points to; this makes
    /// the shape an area light.
    pub emission: Option<Vec3>,
    /// Object to world.
    pub transform: Mat4,
    /// Turns the surface's normals (and so the side an area light emits from) around.
    pub flip_normals: bool,
    pub span: Span,
}

/// Geometry in object space. The primitive shapes follow Mitsuba's conventions so that
/// imported scenes land where Mitsuba puts them.
#[derive(Clone, Debug)]
pub enum GeometryDesc {
    Mesh(MeshDesc),
    /// A sphere; the transform may translate, rotate and scale it uniformly.
    Sphere {
        center: Vec3,
        radius: f32,
    },
    /// The square [-1, 1]² in the z = 0 plane, normal +z.
    Rectangle,
    /// The unit disk in the z = 0 plane, normal +z.
    Disk,
    /// The cube [-1, 1]³, normals outwards.
    Cube,
}

/// An indexed triangle mesh. `normals` and `uvs` are either empty or one per position.
#[derive(Clone, Debug, Default)]
pub struct MeshDesc {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub uvs: Vec<Vec2>,
    pub indices: Vec<[u32; 3]>,
}

/// A light that is not a shape.
#[derive(Clone, Debug)]
pub struct LightDesc {
    pub kind: LightKindDesc,
    pub span: Span,
}

#[derive(Clone, Debug)]
pub enum LightKindDesc {
    /// An isotropic point light of the given radiant intensity (W/sr per channel).
    Point { position: Vec3, intensity: Vec3 },
}

/// How to weigh next event estimation against BSDF sampling.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MisMode {
    /// Balance heuristic (Veach 1997, §9.2.2); the default, as in the course notes.
    #[default]
    Balance,
    /// Power heuristic with β = 2.
    Power,
    /// Next event estimation only for direct light; emitters hit by BSDF-sampled rays
    /// count only after specular bounces.
    NeeOnly,
    /// BSDF sampling only: no shadow rays. For testing estimators against each other.
    BsdfOnly,
}

/// How to pick the one light that next event estimation samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LightSamplerKind {
    Uniform,
    /// Proportional to emitted power, through an alias table.
    #[default]
    Power,
    /// Proportional to power through the course notes' slot array.
    Array,
    /// Resampled importance sampling over candidates from the array.
    Ris,
    /// Light BVH with orientation cones (Conty Estevez & Kulla 2018).
    Bvh,
    /// Resampled importance sampling over candidates from the light BVH.
    RisBvh,
}

/// Default number of RIS candidates, chosen by `bench/many_lights`.
pub const DEFAULT_RIS_CANDIDATES: u32 = 2;

/// Render settings a scene carries; the command line may override them.
#[derive(Clone, Debug)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    /// Maximum number of scattering events along a path: 0 shows emitters only, 1 gives
    /// direct light, and so on.
    pub max_depth: u32,
    pub seed: u64,
    pub mis: MisMode,
    pub light_sampler: LightSamplerKind,
    /// Candidates per pick of the RIS light samplers.
    pub ris_candidates: u32,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            width: 512,
            height: 512,
            spp: 64,
            max_depth: 8,
            seed: 0,
            mis: MisMode::default(),
            light_sampler: LightSamplerKind::default(),
            ris_candidates: DEFAULT_RIS_CANDIDATES,
        }
    }
}
