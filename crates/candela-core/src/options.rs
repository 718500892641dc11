//! The choices a render takes, by name: how to weigh light against BSDF sampling, which
//! light sampler, sampler and compiled copy of the render loop, how filters reach the
//! pixels, which passes to render beside the beauty; and [`RenderOptions`], the part of
//! a scene's render settings that the render code reads.
//!
//! Plain enums that scene files and the command line name and the renderer acts on, so
//! that the description ([`crate::desc`], which re-exports them) and the render code
//! share them without either importing the other.

/// How to weigh next event estimation against BSDF sampling. Its names in scene files and
/// on the command line are `balance`, `power`, `none` and `bsdf`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MisMode {
    /// Balance heuristic (Veach 1997, §9.2.2); the default, as in the course notes.
    #[default]
    Balance,
    /// Power heuristic with β = 2.
    Power,
    /// Next event estimation only for direct light; emitters hit by BSDF-sampled rays
    /// count only after specular bounces.
    #[serde(rename = "none")]
    NeeOnly,
    /// BSDF sampling only: no shadow rays. For testing estimators against each other.
    #[serde(rename = "bsdf")]
    BsdfOnly,
}

/// Which integrator follows the camera paths of a scene without media. Its names in scene
/// files and on the command line are `path` and `lanes`. Both estimate the same image
/// (the per-tile Welch tests of `crates/candela-scene/tests/lanes_consistency.rs`); scenes
/// with media use the volumetric path tracer whichever is chosen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum IntegratorKind {
    /// One path at a time ([`crate::integrator::li`]): the default, since the lanes
    /// integrator takes more instructions per path on every bench scene
    /// (bench/RESULTS.md, lanes_integrator).
    #[default]
    Path,
    /// Eight paths at a time in SIMD lanes, each lane refilled with the band's next pixel
    /// sample when its path ends (see `crate::integrator::lanes`).
    Lanes,
}

/// How to pick the one light that next event estimation samples. Its names in scene files
/// and on the command line are the variants' names in kebab case (`ris-bvh`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LightSamplerKind {
    Uniform,
    /// Proportional to emitted power, through an alias table.
    Power,
    /// Proportional to power through the course notes' slot array.
    Array,
    /// Resampled importance sampling over candidates from the array.
    Ris,
    /// Light BVH with orientation cones (Conty Estevez & Kulla 2018): the default, since
    /// at equal spp it is never worse than `Uniform` or `Power` beyond noise on 22 scenes
    /// and 0.08–0.79× their variance where the choice of light matters, for 1.0–1.6× the
    /// instructions per path (one light: the same pick and cost) (`bench/light_sampler.sh`,
    /// bench/RESULTS.md, light_sampler; issue 36).
    #[default]
    Bvh,
    /// Resampled importance sampling over candidates from the light BVH.
    RisBvh,
}

/// How next event estimation draws a point on a flat lamp (an emitting triangle or
/// rectangle without an emission texture). Its names in scene files and on the command
/// line are `area` and `solid-angle`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LampSampling {
    /// Uniformly by area, everywhere: the default, the cheaper per sample, and the more
    /// efficient where most of the noise is indirect light (the Cornell box and a softbox
    /// scene measured 0.93× and 0.92× as efficient with `SolidAngle`: bench/RESULTS.md,
    /// lamp_sampling).
    #[default]
    Area,
    /// Where a lamp is wider than its centre is far from the shading point, uniformly in
    /// the solid angle it covers, warped by the receiver's cosine (Arvo's spherical
    /// triangles, Ureña et al.'s spherical rectangles); elsewhere by area. Less noise
    /// from large, close lamps for more time a sample (about 250 ns against 20 ns by
    /// area): 1.66× as efficient on `scenes/plastics.toml`.
    SolidAngle,
}

/// Where the integrator's uniform numbers come from (see [`crate::sampler`]). Its names in
/// scene files and on the command line are `independent`, `sobol`, `sobol-cmj` and `zsobol`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SamplerKind {
    /// Independent uniform numbers (PCG32).
    Independent,
    /// Owen-scrambled Sobol' points, stratified within each pixel: `bench/sampler.sh`
    /// measured 1.56× lower relMSE than independent samples at 64 spp on the 512² Cornell
    /// box and 1.68× on the depth-of-field scene for 5–10 % more time (bench/JOURNAL.md,
    /// "Samplers — `bench/sampler.sh`, noisy machine").
    Sobol,
    /// [`SamplerKind::Sobol`] except for the first bounce's BSDF direction, which comes
    /// from a correlated multi-jittered pattern of the planned spp
    /// ([`crate::sampler::SobolCmjSampler`]); the default, since it measured 1.135× lower
    /// relMSE than `Sobol` on the Cornell box at 64 spp (1.025× at 16), level or better
    /// on five other scenes, for ≈ 2.5 % more instructions in the render loop
    /// (bench/RESULTS.md, sampler).
    #[default]
    SobolCmj,
    /// One Owen-scrambled Sobol' sequence over the whole image in a scrambled Morton order
    /// of the pixels ([`crate::sampler::ZSobolSampler`], pbrt-v4's `ZSobolSampler`): each
    /// pixel as stratified as with [`SamplerKind::Sobol`], and neighbouring pixels
    /// stratified together, so the error is blue noise in screen space: fine-grained
    /// rather than blotchy at low spp (bench/RESULTS.md, denoise: it did not lower
    /// HDR-FLIP after denoising).
    Zsobol,
}

/// Which compiled copy of the render loop runs (see [`crate::isa`]). Its names on the
/// command line are `auto`, `baseline` and `v3`. Every choice renders the same pixels,
/// bit for bit; only the speed differs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Isa {
    /// The fastest copy the CPU runs: [`Isa::V3`] where it has x86-64-v3, else
    /// [`Isa::Baseline`].
    #[default]
    Auto,
    /// The copy compiled for the build's target (on x86-64, any x86-64 CPU).
    Baseline,
    /// The copy compiled for x86-64-v3 (AVX2, FMA, BMI1/2, LZCNT, MOVBE, F16C); only
    /// on x86-64 CPUs that have them.
    V3,
}

/// How a pixel filter wider than a pixel (tent, Gaussian) reaches the image (see
/// [`crate::splat`]). Its names in scene files and on the command line are `splat` and
/// `importance`. The box filter renders the same either way.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FilterSampling {
    /// Each sample, uniform in its pixel, adds to every pixel under the filter, weighted by
    /// it; each pixel divides by its weights' sum (Mitsuba's way). A pixel then averages
    /// about as many samples as the filter covers pixels, so at equal spp its noise is
    /// lower: the default.
    #[default]
    Splat,
    /// Each sample's offset is drawn from the filter and the sample goes to its own pixel
    /// only (filter importance sampling, Ernst et al. 2006): the same expected image, with
    /// no sample crossing a pixel.
    Importance,
}

/// How the acceleration structure stores its leaves' primitives (see
/// [`crate::accel::LeafLayout`]). Its names in scene files and on the command line are
/// `auto`, `inline` and `compact`. Every choice renders the same pixels, bit for bit;
/// only speed and memory differ.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AccelStorage {
    /// Inline below [`crate::accel::INDEXED_FROM`] primitives, compact from there on.
    #[default]
    Auto,
    /// Each leaf a block with its vertices copied in: the fastest.
    Inline,
    /// Each primitive as indices into a shared vertex array: about a quarter of the
    /// memory.
    Compact,
}

/// One pass. Its name in scene files and on the command line is its lowercase name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum AovKind {
    Albedo,
    Normal,
    Depth,
}

impl AovKind {
    /// Every pass, in the order files list them.
    pub const ALL: [AovKind; 3] = [AovKind::Albedo, AovKind::Normal, AovKind::Depth];

    /// The EXR layer of the pass and its channels (`albedo.R`, `normal.X`, `depth.Z`):
    /// the `layer.channel` naming of OpenEXR's multi-part convention, which Nuke, Blender
    /// and OIDN's own tools read.
    pub fn layer(self) -> (&'static str, &'static [&'static str]) {
        match self {
            AovKind::Albedo => ("albedo", &["R", "G", "B"]),
            AovKind::Normal => ("normal", &["X", "Y", "Z"]),
            AovKind::Depth => ("depth", &["Z"]),
        }
    }

    /// The pass's name, as scene files and the command line spell it.
    pub fn name(self) -> &'static str {
        self.layer().0
    }

    /// The pass named `name`, if any.
    pub fn from_name(name: &str) -> Option<AovKind> {
        AovKind::ALL.into_iter().find(|k| k.name() == name)
    }
}

/// A set of passes (none by default).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AovSet(u8);

impl AovSet {
    pub const NONE: AovSet = AovSet(0);

    pub fn with(self, kind: AovKind) -> AovSet {
        AovSet(self.0 | 1 << kind as u8)
    }

    pub fn union(self, o: AovSet) -> AovSet {
        AovSet(self.0 | o.0)
    }

    pub fn contains(self, kind: AovKind) -> bool {
        self.0 & 1 << kind as u8 != 0
    }

    pub fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// The passes in the set, in [`AovKind::ALL`]'s order.
    pub fn iter(self) -> impl Iterator<Item = AovKind> {
        AovKind::ALL.into_iter().filter(move |&k| self.contains(k))
    }

    /// Parses a comma-separated list such as `albedo,normal,depth`.
    pub fn parse_list(s: &str) -> Result<AovSet, String> {
        s.split(',')
            .map(str::trim)
            .filter(|n| !n.is_empty())
            .try_fold(AovSet::NONE, |set, n| match AovKind::from_name(n) {
                Some(k) => Ok(set.with(k)),
                None => Err(format!(
                    "unknown AOV `{n}`, expected albedo, normal or depth"
                )),
            })
    }
}

impl FromIterator<AovKind> for AovSet {
    fn from_iter<I: IntoIterator<Item = AovKind>>(iter: I) -> AovSet {
        iter.into_iter().fold(AovSet::NONE, AovSet::with)
    }
}

/// What the render code reads of a scene's render settings, copied from the
/// description's [`crate::desc::RenderSettings`] by [`crate::build`]: the image, the
/// sample streams, the path loop's limits and choices, the compiled copy and the passes.
/// The light sampler, lamp sampling and pixel filter are built into the scene's own
/// objects ([`crate::Scene::light_sampler`], its lights, [`crate::Scene::filter`]) and
/// not kept here.
#[derive(Clone, Debug)]
pub struct RenderOptions {
    pub width: u32,
    pub height: u32,
    /// The planned samples per pixel (the CMJ sampler's pattern size; a render may take
    /// any sample range).
    pub spp: u32,
    /// Maximum number of scattering events along a path.
    pub max_depth: u32,
    /// Scattering events before Russian roulette may end a path.
    pub rr_depth: u32,
    pub seed: u64,
    pub mis: MisMode,
    pub integrator: IntegratorKind,
    pub sampler: SamplerKind,
    /// Camera rays that hit an emitter or escape return nothing.
    pub hide_emitters: bool,
    pub filter_sampling: FilterSampling,
    /// Which compiled copy of the render loop runs; the CPU must support it.
    pub isa: Isa,
    /// Passes rendered beside the beauty image (see [`crate::aov`]).
    pub aovs: AovSet,
}
