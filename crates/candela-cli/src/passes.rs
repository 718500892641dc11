//! `--aov` and `--denoise`: the AOV pass beside the beauty, Open Image Denoise, and the
//! image they make (a layered EXR, or the beauty alone in PFM and PNG).

use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use candela_core::aov::{render_aovs, AovKind, AovSet};
use candela_core::desc::{FilterSampling, RenderSettings};
use candela_core::Scene;
use candela_denoise::{Denoiser, Guides, Images};
use clap::{Args, ValueEnum};
use glam::Vec3;

use crate::layers::{encode_layered_exr, Channel};
use crate::output::{write_atomically, write_image, ImageFormat, LinearImage};
use crate::tonemap::DisplayTransform;
use crate::UserError;

/// What `--denoise` guides the filter with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum DenoiseMode {
    /// The albedo and normal passes, prefiltered (OIDN's high-quality mode).
    Guided,
    /// The beauty alone.
    Color,
}

#[derive(Args)]
pub struct PassArgs {
    /// Extra passes, written as EXR layers: a comma-separated list of albedo, normal and
    /// depth (albedo.R/G/B, normal.X/Y/Z, depth.Z). PFM and PNG ignore them.
    #[arg(long, value_name = "LIST", value_parser = AovSet::parse_list)]
    aov: Option<AovSet>,
    /// Denoise the beauty with Intel Open Image Denoise 2.x (`pip install pyoidn`, or
    /// OIDN_DIR): `--denoise` guides it with the albedo and normal passes, prefiltered;
    /// `--denoise=color` uses the beauty alone. An EXR keeps the noisy beauty as the
    /// `noisy` layer. A filter wider than a pixel is importance-sampled, not splatted
    /// (OIDN cannot denoise splatted noise), unless --filter-sampling is given.
    #[arg(long, value_name = "GUIDES", num_args = 0..=1, require_equals = true,
          default_missing_value = "guided")]
    denoise: Option<DenoiseMode>,
}

impl PassArgs {
    /// Whether `--aov` or `--denoise` was given.
    pub fn requested(&self) -> bool {
        self.aov.is_some() || self.denoise.is_some()
    }

    /// `--aov` over the scene's own `aov` list; with `--denoise`, filter importance
    /// sampling unless `filter_sampling` was chosen on the command line (`explicit`).
    ///
    /// Open Image Denoise cannot denoise a splatted image: a sample weighted into every
    /// pixel under a filter wider than a pixel correlates neighbouring pixels' noise,
    /// which its `RT` filter then keeps ("not supported", OIDN's API documentation). Filter
    /// importance sampling converges to the same image with each sample in one pixel, at
    /// the AOV pass's own sample positions. The box filter renders the same either way.
    pub fn apply(&self, r: &mut RenderSettings, explicit_filter_sampling: bool) {
        if let Some(set) = self.aov {
            r.aovs = set;
        }
        if self.denoise.is_some() && !explicit_filter_sampling {
            r.filter_sampling = FilterSampling::Importance;
        }
    }

    /// Loads OIDN if `--denoise` asks for it: before the render, so that a missing
    /// library costs no render time.
    pub fn load_denoiser(&self) -> Result<Option<Denoiser>, UserError> {
        match self.denoise {
            None => Ok(None),
            Some(_) => Denoiser::load()
                .map(Some)
                .map_err(|e| UserError(format!("--denoise: {e}"))),
        }
    }

    /// The passes to render: the scene's (after `--aov`), and albedo and normal when a
    /// guided `--denoise` needs them.
    fn needed(&self, scene: &Scene) -> AovSet {
        let guides = match self.denoise {
            Some(DenoiseMode::Guided) => AovSet::NONE.with(AovKind::Albedo).with(AovKind::Normal),
            _ => AovSet::NONE,
        };
        scene.settings.aovs.union(guides)
    }
}

/// The finished image: the beauty (denoised or not) and the layers beside it.
pub struct Passes {
    width: u32,
    height: u32,
    beauty: Vec<Vec3>,
    layers: Vec<Channel>,
    /// What the passes cost and did, for the summary line.
    pub summary: Option<String>,
}

/// Renders the passes `args` and the scene ask for over the beauty's samples, denoises
/// the beauty if asked, and gathers the layers. `cancel` set (an interrupted render)
/// skips both: the beauty is written as it is.
pub fn finish(
    args: &PassArgs,
    denoiser: Option<&Denoiser>,
    scene: &Scene,
    beauty: Vec<Vec3>,
    cancel: &AtomicBool,
    threads: usize,
) -> Result<Passes, UserError> {
    let s = &scene.settings;
    let mut passes = Passes {
        width: s.width,
        height: s.height,
        beauty,
        layers: Vec::new(),
        summary: None,
    };
    let needed = args.needed(scene);
    if cancel.load(std::sync::atomic::Ordering::Relaxed) {
        return Ok(passes);
    }
    let mut summary = Vec::new();
    let mut guides = None;
    if !needed.is_empty() {
        let start = Instant::now();
        let film = render_aovs(scene, 0..s.spp, cancel);
        let names: Vec<&str> = needed.iter().map(AovKind::name).collect();
        let secs = start.elapsed().as_secs_f64();
        summary.push(format!("passes {} in {secs:.2} s", names.join(", ")));
        for kind in needed.iter() {
            let (layer, names) = kind.layer();
            for (name, values) in names.iter().zip(film.channels(kind)) {
                passes.layers.push(Channel {
                    name: format!("{layer}.{name}"),
                    values,
                });
            }
        }
        guides = Some((film.albedo(), film.normal()));
    }
    if let (Some(mode), Some(denoiser)) = (args.denoise, denoiser) {
        let start = Instant::now();
        let images = Images {
            width: s.width,
            height: s.height,
            color: &passes.beauty,
            guides: guides.as_ref().filter(|_| mode == DenoiseMode::Guided).map(
                |(albedo, normal)| Guides {
                    albedo,
                    normal: Some(normal),
                },
            ),
        };
        let denoised = denoiser
            .denoise(&images, threads)
            .map_err(|e| UserError(format!("--denoise: {e}")))?;
        let noisy = std::mem::replace(&mut passes.beauty, denoised);
        passes.layers.extend(rgb_channels("noisy.", &noisy));
        let how = match mode {
            DenoiseMode::Guided => "guided by albedo and normal, prefiltered",
            DenoiseMode::Color => "beauty alone",
        };
        let secs = start.elapsed().as_secs_f64();
        summary.push(format!("denoised ({how}) in {secs:.2} s"));
    }
    passes.summary = (!summary.is_empty()).then(|| summary.join("; "));
    Ok(passes)
}

impl Passes {
    /// Writes the image: every layer into an EXR; the beauty alone into PFM or PNG, with
    /// a note on stderr that the layers were left out.
    pub fn write(self, path: &Path, display: &DisplayTransform) -> Result<(), UserError> {
        if self.layers.is_empty() || ImageFormat::from_path(path)? != ImageFormat::Exr {
            if !self.layers.is_empty() {
                eprintln!(
                    "candela: note: {} holds one image: the AOV and noisy layers are \
                     written to .exr only",
                    path.display()
                );
            }
            let image = LinearImage {
                width: self.width,
                height: self.height,
                pixels: &self.beauty,
            };
            return write_image(path, &image, display);
        }
        let mut channels = rgb_channels("", &self.beauty);
        channels.extend(self.layers);
        let bytes = encode_layered_exr(self.width, self.height, channels)
            .map_err(|e| UserError(format!("{}: cannot encode image: {e}", path.display())))?;
        write_atomically(path, &bytes)
    }
}

/// `pixels` as three channels named `{prefix}R`, `{prefix}G`, `{prefix}B`.
fn rgb_channels(prefix: &str, pixels: &[Vec3]) -> Vec<Channel> {
    ["R", "G", "B"]
        .into_iter()
        .enumerate()
        .map(|(c, name)| Channel {
            name: format!("{prefix}{name}"),
            values: pixels.iter().map(|p| p[c]).collect(),
        })
        .collect()
}
