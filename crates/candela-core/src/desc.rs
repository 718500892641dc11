//! The scene description: plain data that loaders produce and [`crate::build`] turns into
//! a render-time [`crate::Scene`].
//!
//! Everything here is owned, plain and cloneable, so a program can also write a scene in
//! code. Every item remembers where it came from ([`Span`]) so that build errors can point
//! at the file, line and column that caused them. Units: radiance in W·sr⁻¹·m⁻², linear
//! Rec.709 primaries; lengths in scene units; angles in degrees where a field says so.
//!
//! The description is the bottom layer: loaders produce it, [`crate::build`] reads it,
//! and it imports nothing from the renderer. Its only imports inside the crate are the
//! option enums it shares with the renderer ([`crate::options`]) and the sampling math
//! ([`crate::sampling`], itself free of crate imports) that a [`photometry`] table, the
//! canonical form loaders make of a measured profile, samples with
//! (`tests/layering.rs` checks this). Besides the records, it holds the named conductors
//! every loader's presets read ([`CONDUCTORS`]) and builders for writing a scene in code.

use std::fmt;
use std::sync::Arc;

use glam::{Affine2, Mat3, Mat4, Vec2, Vec3, Vec4};

use crate::options::AovSet;

mod builders;
mod conductors;
mod media;
pub mod photometry;

pub use crate::options::{
    AccelStorage, FilterSampling, IntegratorKind, Isa, LampSampling, LightSamplerKind, MisMode,
    SamplerKind,
};
pub use conductors::{conductor, metal_preset, CONDUCTORS, METAL_PRESETS};
pub use media::*;

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
    /// The sky: what escaped rays see and what lights the scene from infinitely far.
    pub environment: Option<EnvironmentDesc>,
    pub render: RenderSettings,
    /// Goniometric profiles attached to emitting shapes (IES-shaped area lights).
    pub emission_profiles: Vec<EmissionProfileDesc>,
    /// Participating media and the shapes that bound them.
    pub media: MediaDesc,
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
    /// An orthographic camera's view height in world units (its width follows the
    /// image's aspect): parallel rays along the view direction from the camera's plane,
    /// and no field of view. `None` for a perspective camera.
    pub ortho_height: Option<f32>,
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
            ortho_height: None,
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

/// The scattering model of a material. Roughnesses are the α of the microfacet
/// `distribution` (for GGX, α = perceptual roughness²); α below 10⁻³ makes a smooth
/// (delta) interface. `eta` is the relative index of refraction, inside over outside.
#[derive(Clone, Debug)]
pub enum BsdfDesc {
    /// Lambertian reflection with the given albedo.
    Diffuse { albedo: TextureDesc },
    /// No surface at all: rays pass straight through. Only a medium's boundary (Mitsuba's
    /// `null` BSDF).
    Null,
    /// A metal with complex index η + ik per channel (see [`CONDUCTORS`] for named
    /// metals); α along the tangent and bitangent.
    Conductor {
        eta: Vec3,
        k: Vec3,
        /// Multiplies the Fresnel reflectance (Mitsuba's `specular_reflectance`); one for
        /// a plain metal.
        specular: Vec3,
        alpha_u: f32,
        alpha_v: f32,
        distribution: MicrofacetDesc,
    },
    /// Glass-like interface; `thin` makes a thin sheet (no net refraction, smooth only).
    Dielectric {
        eta: f32,
        alpha_u: f32,
        alpha_v: f32,
        distribution: MicrofacetDesc,
        thin: bool,
        /// Multiplies transmission only (glTF's base colour under KHR_materials_transmission);
        /// constant one for clear glass. Not for thin sheets.
        tint: TextureDesc,
    },
    /// A diffuse base under a dielectric coat of index `eta`, smooth (`alpha` 0) or rough
    /// (isotropic microfacets of roughness `alpha`); see [`crate::bsdf::Plastic`].
    Plastic {
        albedo: TextureDesc,
        eta: f32,
        alpha: f32,
        distribution: MicrofacetDesc,
        /// The base term ρ/(1 − F_dr) (Mitsuba's default) instead of Candela's
        /// ρ/(1 − ρ F_dr), which saturates colours by the light the coat keeps inside.
        linear: bool,
        /// Tints the coat's reflection (Mitsuba's `specular_reflectance`); one for a
        /// clear coat.
        specular: Vec3,
    },
    /// glTF 2.0 metallic-roughness: metallic and roughness read the texture's first
    /// channel (or the one an image texture selects) and lie in [0, 1].
    MetalRough {
        base_color: TextureDesc,
        metallic: TextureDesc,
        roughness: TextureDesc,
    },
    /// The same BSDF on both sides. Candela's reflective BSDFs already are two-sided, so
    /// this records the intent of imported scenes (Mitsuba `twosided`, glTF
    /// `doubleSided`) and builds the inner BSDF.
    TwoSided(Box<BsdfDesc>),
    /// Bends the shading normal by a tangent-space normal map (glTF convention: RGB =
    /// (x, y, z)·0.5 + 0.5, x along +u, y along +v, linear data).
    NormalMap {
        map: TextureDesc,
        inner: Box<BsdfDesc>,
    },
    /// The inner BSDF on the front (the side the shading normal points to) and black
    /// from the back, as Mitsuba's reflective BSDFs are unless wrapped in `twosided`.
    OneSided(Box<BsdfDesc>),
    /// The inner BSDF on a surface that is cut out (`Mask`) or see-through (`Blend`) by
    /// α, glTF's alpha modes. Meshes only; see [`crate::alpha`].
    Alpha {
        alpha: AlphaDesc,
        inner: Box<BsdfDesc>,
    },
    /// `a` where the weight is 0, `b` where it is 1, and (1 − w)·a + w·b between: the
    /// weight is the texture's first channel, clamped to [0, 1]. Rendered by choosing one
    /// of the two at each shading point (see [`crate::material::Material::Mix`]).
    Mix {
        weight: TextureDesc,
        a: Box<BsdfDesc>,
        b: Box<BsdfDesc>,
    },
}

/// The microfacet distribution of a rough conductor or dielectric (ignored when smooth).
/// α means what it does in Walter et al. 2007, pbrt and Mitsuba; at equal α, Beckmann's
/// highlight has the shorter tails.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MicrofacetDesc {
    /// Trowbridge–Reitz: Candela's TOML and glTF default.
    #[default]
    Ggx,
    /// Beckmann: Mitsuba's default.
    Beckmann,
}

/// How a mesh's α hides it (see [`crate::alpha`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AlphaMode {
    /// Present where α ≥ `cutoff`.
    Mask { cutoff: f32 },
    /// Present with probability α.
    Blend,
}

/// A surface's coverage α = `factor` × the texture's first channel (1 without one).
#[derive(Clone, Debug)]
pub struct AlphaDesc {
    pub mode: AlphaMode,
    pub factor: f32,
    pub texture: Option<TextureDesc>,
}

/// A colour (or, read through one channel, a scalar) that may vary over a surface.
/// Values are linear.
#[derive(Clone, Debug)]
pub enum TextureDesc {
    Constant(Vec3),
    Image(ImageTextureDesc),
    /// Alternating squares of `a` and `b`, one per unit of the transformed uv.
    Checker {
        a: Vec3,
        b: Vec3,
        uv_transform: Affine2,
    },
}

/// A decoded image: linear values, rows from the top, `width·height` pixels. Loaders do
/// the decoding (sRGB EOTF for colour images, none for data images).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ImageDesc {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<Vec3>,
}

/// How texture coordinates outside [0, 1] are brought back.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum WrapMode {
    #[default]
    Repeat,
    Clamp,
    Mirror,
}

/// An image placed on a surface. The uv (0, 0) is the image's bottom-left corner
/// (OpenGL, pbrt and Mitsuba; glTF loaders flip v). Filtering is bilinear.
#[derive(Clone, Debug)]
pub struct ImageTextureDesc {
    pub image: Arc<ImageDesc>,
    pub wrap: WrapMode,
    /// Applied to the uv before the lookup.
    pub uv_transform: Affine2,
    /// Multiplies the looked-up value (glTF's factors).
    pub scale: Vec3,
    /// Reads one channel (0, 1, 2) into all three, e.g. glTF roughness (1) and metallic
    /// (2) from one packed image.
    pub channel: Option<u8>,
}

impl ImageTextureDesc {
    /// An image with repeat wrapping, no transform, no scale, all channels.
    pub fn new(image: Arc<ImageDesc>) -> ImageTextureDesc {
        ImageTextureDesc {
            image,
            wrap: WrapMode::Repeat,
            uv_transform: Affine2::IDENTITY,
            scale: Vec3::ONE,
            channel: None,
        }
    }
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
    /// Multiplies `emission` at each point, looked up at the surface's uvs (a screen, a
    /// stained-glass window, glTF's emissive texture). Meshes and the unit primitives
    /// take one; spheres do not.
    pub emission_texture: Option<TextureDesc>,
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
    /// A triangle mesh, shared: shapes that hold the same `Arc` are instances of one mesh
    /// (a glTF mesh used by several nodes, a Mitsuba `shapegroup`).
    Mesh(Arc<MeshDesc>),
    /// A sphere; the transform may translate, rotate and scale it uniformly.
    Sphere { center: Vec3, radius: f32 },
    /// The square [-1, 1]² in the z = 0 plane, normal +z.
    Rectangle,
    /// The unit disk in the z = 0 plane, normal +z.
    Disk,
    /// The cube [-1, 1]³, normals outwards.
    Cube,
}

/// An indexed triangle mesh. `normals`, `uvs` and `colors` are either empty or one per
/// position.
#[derive(Clone, Debug, Default)]
pub struct MeshDesc {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub uvs: Vec<Vec2>,
    pub indices: Vec<[u32; 3]>,
    /// Linear RGB vertex colours (glTF COLOR_0), multiplying the material's base colour
    /// (diffuse and plastic albedo, metal_rough base colour) where given.
    pub colors: Vec<Vec3>,
    /// Tangents (glTF TANGENT): xyz along +u, w = ±1 the handedness, so the bitangent of
    /// a normal map is w·(n × t). Where empty, normal maps use ∂p/∂u of the uvs.
    pub tangents: Vec<Vec4>,
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
    /// A point light with stated units and colour, optionally shaped by a profile.
    ShapedPoint(ShapedPointDesc),
    /// A spotlight: a point light whose intensity falls off outside a cone.
    Spot(SpotLightDesc),
    /// Parallel light from infinitely far away.
    Directional(DirectionalLightDesc),
    /// A point light that projects an image through a rectangular frustum.
    Projector(ProjectorLightDesc),
}

// --- Lights with units, profiles and shapes (issue 6) ---------------------------------

/// A light's colour: linear Rec.709, or a blackbody temperature in kelvin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightColorDesc {
    Rgb(Vec3),
    Temperature(f32),
}

impl Default for LightColorDesc {
    fn default() -> Self {
        LightColorDesc::Rgb(Vec3::ONE)
    }
}

/// How strong a light is, in the unit the user stated. The build converts photometric
/// units at 683 lm/W and normalizes powers by the light's solid angle (see
/// [`crate::build`]). Radiometric amounts scale the RGB colour per channel; photometric
/// amounts scale the colour normalized to unit luminance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightAmountDesc {
    /// Peak radiant intensity, W/sr (the intensity along the axis / profile peak).
    WattsPerSr(f32),
    /// Peak luminous intensity, cd.
    Candela(f32),
    /// Total emitted power, W.
    Watts(f32),
    /// Total luminous flux, lm.
    Lumens(f32),
    /// The absolute candela values of the attached profile (IES files are absolute).
    ProfileCandela,
}

/// A goniometric profile placed in the world: the table's nadir (+z of the table frame)
/// along `nadir`, its C0 plane towards `c0` (made orthogonal to `nadir`).
#[derive(Clone, Debug)]
pub struct ProfileDesc {
    pub table: Arc<photometry::GoniometricTable>,
    pub nadir: Vec3,
    pub c0: Vec3,
    pub span: Span,
}

/// See [`LightKindDesc::ShapedPoint`].
#[derive(Clone, Debug)]
pub struct ShapedPointDesc {
    pub position: Vec3,
    pub color: LightColorDesc,
    pub amount: LightAmountDesc,
    pub profile: Option<ProfileDesc>,
}

/// The angular falloff of a spotlight between its inner and outer cone.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SpotFalloff {
    /// pbrt-v4: smoothstep in cos θ.
    #[default]
    Smoothstep,
    /// Mitsuba 3: linear in the angle θ.
    Mitsuba,
    /// glTF KHR_lights_punctual: the square of a linear ramp in cos θ.
    Gltf,
}

/// See [`LightKindDesc::Spot`]. A profile, if any, is aimed along `direction` and
/// multiplies the cone's falloff.
#[derive(Clone, Debug)]
pub struct SpotLightDesc {
    pub position: Vec3,
    pub direction: Vec3,
    pub inner_angle_deg: f32,
    pub outer_angle_deg: f32,
    pub falloff: SpotFalloff,
    pub color: LightColorDesc,
    pub amount: LightAmountDesc,
    pub profile: Option<ProfileDesc>,
}

/// See [`LightKindDesc::Directional`]. `direction` is the way the light travels.
/// Amounts: `WattsPerSr`/`Candela` are read as irradiance (W/m²) / illuminance (lux) on a
/// surface facing the light; `Watts`/`Lumens` are not accepted.
#[derive(Clone, Debug)]
pub struct DirectionalLightDesc {
    pub direction: Vec3,
    pub color: LightColorDesc,
    pub amount: LightAmountDesc,
}

/// See [`LightKindDesc::Projector`]. The image spans the frustum `fov_x_deg` ×
/// `fov_y_deg` around `direction`, its top edge towards `up`. The intensity towards a
/// direction is the pixel's linear value times the scale the amount gives (the amount
/// refers to a pixel value of 1).
#[derive(Clone, Debug)]
pub struct ProjectorLightDesc {
    pub position: Vec3,
    pub direction: Vec3,
    pub up: Vec3,
    pub fov_x_deg: f32,
    pub fov_y_deg: f32,
    pub image: Arc<ImageDesc>,
    pub color: LightColorDesc,
    pub amount: LightAmountDesc,
    pub projection: ProjectionDesc,
}

/// How a projector's image gives its intensity.
#[derive(Clone, Debug, Default)]
pub enum ProjectionDesc {
    /// I(ω) = scale × the pixel ω passes through, looked up nearest.
    #[default]
    PixelIntensity,
    /// Mitsuba's `projector`: the texture (at uv from (0, 0) at the frustum's bottom-left
    /// to (1, 1) at its top-right) is an irradiance E on the plane at distance 1, and
    /// I(ω) = π · scale · E / cos³θ, θ from the axis.
    PlaneIrradiance(TextureDesc),
}

/// A profile attached to the emitting shape `shape` (index into [`SceneDesc::shapes`]):
/// its radiance towards ω is scaled by I(ω)/I_max, the table's nadir along the surface
/// normal and its C0 plane along the shape's transformed local +x.
#[derive(Clone, Debug)]
pub struct EmissionProfileDesc {
    pub shape: usize,
    pub table: Arc<photometry::GoniometricTable>,
    pub span: Span,
}

/// An environment light: radiance arriving from infinitely far away, by direction.
#[derive(Clone, Debug)]
pub struct EnvironmentDesc {
    pub map: EnvironmentMapDesc,
    /// Scales the map's radiance.
    pub strength: f32,
    /// World from map: a rotation applied to the map's native directions.
    pub rotation: Mat3,
    /// Whether camera rays see the map; when `false` they see `background` instead, while
    /// the map still lights the scene.
    pub visible: bool,
    /// What camera rays see when the map is not visible (linear radiance).
    pub background: Vec3,
    pub span: Span,
}

impl Default for EnvironmentDesc {
    fn default() -> Self {
        EnvironmentDesc {
            map: EnvironmentMapDesc::Constant(Vec3::ONE),
            strength: 1.0,
            rotation: Mat3::IDENTITY,
            visible: true,
            background: Vec3::ZERO,
            span: Span::code(),
        }
    }
}

/// The radiance of an environment by direction. Images are decoded to linear RGB by the
/// loaders; the mappings are documented in `light::envmap`.
#[derive(Clone, Debug)]
pub enum EnvironmentMapDesc {
    /// The same radiance from every direction.
    Constant(Vec3),
    /// A latitude-longitude panorama, 2:1 or any aspect.
    Equirect(ImageDesc),
    /// Six square faces of equal size in the order +x, −x, +y, −y, +z, −z.
    Cubemap(Box<[ImageDesc; 6]>),
}

/// Default number of RIS candidates, chosen by `bench/many_lights`.
pub const DEFAULT_RIS_CANDIDATES: u32 = 2;

/// Default of [`RenderSettings::rr_depth`]: Mitsuba's, and the most efficient start of
/// the roulette measured on Candela's example scenes (bench/RESULTS.md, rr_depth).
pub const DEFAULT_RR_DEPTH: u32 = 5;

/// Render settings a scene carries; the command line may override them.
#[derive(Clone, Debug)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    /// Maximum number of scattering events along a path: 0 shows emitters only, 1 gives
    /// direct light, and so on.
    pub max_depth: u32,
    /// Russian roulette may end a path once it has scattered this many times (Mitsuba's
    /// `rr_depth`, counted the same way; its default, 5). Before that every path goes on.
    pub rr_depth: u32,
    pub seed: u64,
    pub mis: MisMode,
    /// Which integrator follows the paths (see [`IntegratorKind`]).
    pub integrator: IntegratorKind,
    pub light_sampler: LightSamplerKind,
    /// How next event estimation draws points on flat lamps.
    pub lamp_sampling: LampSampling,
    /// Candidates per pick of the RIS light samplers.
    pub ris_candidates: u32,
    pub sampler: SamplerKind,
    /// Camera rays that hit an emitter or escape to the environment return nothing at
    /// all, as with Mitsuba's `hide_emitters` (the emitters still light the scene).
    pub hide_emitters: bool,
    pub filter: PixelFilterDesc,
    /// How samples reach the pixels under a filter wider than a pixel.
    pub filter_sampling: FilterSampling,
    /// Which compiled copy of the render loop runs; it must be supported by the CPU
    /// ([`Isa::is_supported`]).
    pub isa: Isa,
    /// How the acceleration structure stores its leaves.
    pub accel: AccelStorage,
    /// Passes rendered beside the beauty image (see [`crate::aov`]).
    pub aovs: AovSet,
}

/// The pixel reconstruction filter (see [`crate::filter`]); radii in pixels.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum PixelFilterDesc {
    /// Each pixel averages its own square.
    #[default]
    Box,
    Tent {
        radius: f32,
    },
    /// Truncated at `radius` (Mitsuba: σ = 0.5, radius 4σ).
    Gaussian {
        stddev: f32,
        radius: f32,
    },
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            width: 512,
            height: 512,
            spp: 64,
            max_depth: 8,
            rr_depth: DEFAULT_RR_DEPTH,
            seed: 0,
            mis: MisMode::default(),
            integrator: IntegratorKind::default(),
            light_sampler: LightSamplerKind::default(),
            lamp_sampling: LampSampling::default(),
            ris_candidates: DEFAULT_RIS_CANDIDATES,
            sampler: SamplerKind::default(),
            hide_emitters: false,
            filter: PixelFilterDesc::Box,
            filter_sampling: FilterSampling::default(),
            isa: Isa::Auto,
            accel: AccelStorage::Auto,
            aovs: AovSet::NONE,
        }
    }
}
