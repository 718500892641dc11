//! `candela render`: load, build, render in parallel with a progress bar, write.
//!
//! Ctrl-C (or SIGTERM) stops the render at the next work item and writes the image
//! accumulated so far, each pixel divided by its own sample count; a second Ctrl-C exits
//! at once.

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::Instant;

use candela_core::desc::{
    AccelStorage, ApertureSizeDesc, EnvironmentDesc, EnvironmentMapDesc, FilterSampling, FocusDesc,
    IntegratorKind, Isa, LampSampling, LensDesc, LightSamplerKind, MisMode, SamplerKind, SceneDesc,
    Span,
};
use candela_core::integrator;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use signal_hook::consts::{SIGINT, SIGTERM};
use signal_hook::flag;

use crate::output::ImageFormat;
use crate::part::{write_part, PartInfo};
use crate::tonemap::{DisplayTransform, Tonemap};
use crate::UserError;

/// How a scene file is read: parameters and strictness.
#[derive(Args)]
pub struct LoadArgs {
    /// Sets a scene parameter (Mitsuba's `$name`), overriding the file's default.
    #[arg(short = 'D', value_name = "NAME=VALUE", value_parser = parse_define)]
    define: Vec<(String, String)>,
    /// Warn about and skip what Candela does not support instead of failing.
    #[arg(long)]
    lenient: bool,
    /// Which scene of a glTF file to load (default: its default scene, else the first).
    #[arg(long = "scene", value_name = "N")]
    gltf_scene: Option<usize>,
}

fn parse_define(s: &str) -> Result<(String, String), String> {
    match s.split_once('=') {
        Some((k, v)) if !k.trim().is_empty() => Ok((k.trim().to_string(), v.to_string())),
        _ => Err(format!("expected NAME=VALUE, got \"{s}\"")),
    }
}

impl LoadArgs {
    /// Loads the scene, printing each warning to stderr.
    pub fn load(&self, path: &std::path::Path) -> Result<SceneDesc, UserError> {
        let options = candela_scene::LoadOptions {
            defines: self.define.clone(),
            lenient: self.lenient,
            scene: self.gltf_scene,
        };
        let loaded = candela_scene::load_scene_with(path, &options)?;
        for w in &loaded.warnings {
            eprintln!("candela: warning: {w}");
        }
        Ok(loaded.desc)
    }
}

#[derive(Args)]
pub struct RenderArgs {
    /// Scene file (.toml, Mitsuba 3 .xml, glTF 2.0 .gltf or .glb).
    scene: PathBuf,
    #[command(flatten)]
    load: LoadArgs,
    /// Light the scene with this latitude-longitude environment map (.hdr, .exr, or an
    /// sRGB image), replacing the scene's own environment.
    #[arg(long)]
    env: Option<PathBuf>,
    /// Scales the environment's radiance (the scene's own, or --env's).
    #[arg(long)]
    env_strength: Option<f32>,
    /// Output image: .exr, .pfm (linear) or .png (sRGB).
    #[arg(short, long)]
    output: PathBuf,
    /// Samples per pixel.
    #[arg(long)]
    spp: Option<u32>,
    /// Seed of the sample streams; the same seed gives the same image.
    #[arg(long)]
    seed: Option<u64>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Maximum scattering events per path (0: emitters only, 1: direct light).
    #[arg(long)]
    max_depth: Option<u32>,
    /// Scattering events before Russian roulette may end a path (default 5, as Mitsuba).
    #[arg(long)]
    rr_depth: Option<u32>,
    /// Resolution as WIDTHxHEIGHT.
    #[arg(long, value_parser = parse_resolution)]
    res: Option<(u32, u32)>,
    #[command(flatten)]
    display: DisplayArgs,
    /// Render only these sample indices of every pixel (START..END, within 0..spp) and
    /// write an .exr film part that `candela merge` combines exactly with other parts.
    #[arg(long, value_name = "START..END", value_parser = crate::part::parse_range)]
    samples: Option<std::ops::Range<u32>>,
    /// MIS heuristic between light and BSDF sampling: balance, power, none (light
    /// sampling only) or bsdf (BSDF sampling only).
    #[arg(long, value_parser = parse_name::<MisMode>)]
    mis: Option<MisMode>,
    /// Which integrator follows the paths: path (the default: one path at a time) or
    /// lanes (eight paths at a time in SIMD lanes; scenes with media fall back to path).
    #[arg(long, value_parser = parse_name::<IntegratorKind>)]
    integrator: Option<IntegratorKind>,
    /// How next event estimation picks a light: uniform, power, array, ris, bvh (the
    /// default) or ris-bvh.
    #[arg(long, value_parser = parse_name::<LightSamplerKind>)]
    light_sampler: Option<LightSamplerKind>,
    /// How next event estimation draws points on flat lamps: area (uniformly by area, the
    /// default) or solid-angle (near lamps uniformly in the solid angle they cover).
    #[arg(long, value_parser = parse_name::<LampSampling>)]
    lamp_sampling: Option<LampSampling>,
    /// Candidates per pick of the `ris` and `ris-bvh` light samplers.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    ris_candidates: Option<u32>,
    /// Sample generator: independent (uniform random numbers), sobol (Owen-scrambled
    /// Sobol' points, stratified within each pixel), sobol-cmj (the default: sobol, but
    /// the first bounce's BSDF direction from a correlated multi-jittered pattern) or
    /// zsobol (one Sobol' sequence over the image in scrambled Morton order: the error is
    /// blue noise in screen space, fine-grained at low spp; ≈ 40 % more instructions).
    #[arg(long, value_parser = parse_name::<SamplerKind>)]
    sampler: Option<SamplerKind>,
    /// How a pixel filter wider than a pixel (a Mitsuba scene's tent or Gaussian) reaches
    /// the image: splat (the default: each sample weighted into every pixel under the
    /// filter, as Mitsuba) or importance (each sample's offset drawn from the filter, into
    /// its own pixel).
    #[arg(long, value_parser = parse_name::<FilterSampling>)]
    filter_sampling: Option<FilterSampling>,
    /// Which compiled copy of the render loop runs: auto (the fastest the CPU has),
    /// baseline (any x86-64) or v3 (x86-64-v3: AVX2, FMA, BMI2). Same pixels with each.
    #[arg(long, value_parser = parse_name::<Isa>)]
    isa: Option<Isa>,
    /// How the ray-tracing structure stores its triangles: auto (the default: inline
    /// below 4.2 million primitives, compact from there), inline (each leaf's vertices
    /// copied in, the fastest) or compact (indices into the meshes' vertices, about a
    /// quarter of the memory). Same pixels with each.
    #[arg(long, value_parser = parse_name::<AccelStorage>)]
    accel: Option<AccelStorage>,
    /// Focus distance of a thin lens, in scene units along the view axis (a pinhole
    /// scene also needs --f-number to blur).
    #[arg(long, allow_negative_numbers = true)]
    focus_distance: Option<f32>,
    /// f-number of a thin lens (aperture radius = focal length / 2N, scene units taken as
    /// metres); turns a pinhole into a thin lens with a disc aperture, focused on look_at
    /// unless --focus-distance says otherwise.
    #[arg(long, allow_negative_numbers = true)]
    f_number: Option<f32>,
    #[command(flatten)]
    passes: crate::passes::PassArgs,
}

/// How a linear image becomes PNG pixels.
#[derive(Args)]
pub struct DisplayArgs {
    /// Exposure in stops, applied before PNG encoding.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    exposure: f32,
    /// Tone curve applied before PNG encoding (EXR/PFM stay linear).
    #[arg(long, value_enum, default_value_t = Tonemap::None)]
    tonemap: Tonemap,
    /// Encode PNG with a pure power law 1/γ instead of the sRGB curve, e.g. 2.2.
    #[arg(long, value_parser = parse_gamma)]
    gamma: Option<f32>,
}

impl DisplayArgs {
    pub fn transform(&self) -> DisplayTransform {
        DisplayTransform {
            exposure: self.exposure,
            tonemap: self.tonemap,
            gamma: self.gamma,
        }
    }
}

/// Parses a setting's name as scene files spell it, so the two cannot drift apart.
fn parse_name<T: serde::de::DeserializeOwned>(s: &str) -> Result<T, String> {
    use serde::de::IntoDeserializer;
    T::deserialize(s.into_deserializer()).map_err(|e: serde::de::value::Error| e.to_string())
}

fn parse_gamma(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(g) if g.is_finite() && g > 0.0 => Ok(g),
        _ => Err(format!("expected a positive number, got \"{s}\"")),
    }
}

fn parse_resolution(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected WIDTHxHEIGHT, got \"{s}\""))?;
    let parse = |v: &str| v.trim().parse::<u32>().ok().filter(|&v| v > 0);
    match (parse(w), parse(h)) {
        (Some(w), Some(h)) => candela_core::build::check_resolution(w, h).map(|()| (w, h)),
        _ => Err(format!(
            "expected WIDTHxHEIGHT with positive integers, got \"{s}\""
        )),
    }
}

impl RenderArgs {
    fn apply_overrides(&self, desc: &mut SceneDesc) {
        let r = &mut desc.render;
        if let Some(spp) = self.spp {
            r.spp = spp;
        }
        if let Some(seed) = self.seed {
            r.seed = seed;
        }
        if let Some(d) = self.max_depth {
            r.max_depth = d;
        }
        r.rr_depth = self.rr_depth.unwrap_or(r.rr_depth);
        if let Some((w, h)) = self.res {
            (r.width, r.height) = (w, h);
        }
        r.mis = self.mis.unwrap_or(r.mis);
        r.integrator = self.integrator.unwrap_or(r.integrator);
        r.light_sampler = self.light_sampler.unwrap_or(r.light_sampler);
        r.lamp_sampling = self.lamp_sampling.unwrap_or(r.lamp_sampling);
        if let Some(n) = self.ris_candidates {
            r.ris_candidates = n;
        }
        r.sampler = self.sampler.unwrap_or(r.sampler);
        r.filter_sampling = self.filter_sampling.unwrap_or(r.filter_sampling);
        r.isa = self.isa.unwrap_or(r.isa);
        r.accel = self.accel.unwrap_or(r.accel);
        self.passes.apply(r, self.filter_sampling.is_some());
        if self.focus_distance.is_some() || self.f_number.is_some() {
            let lens = desc.camera.lens.get_or_insert_with(LensDesc::default);
            if let Some(d) = self.focus_distance {
                lens.focus = FocusDesc::Distance(d);
            }
            if let Some(n) = self.f_number {
                lens.size = ApertureSizeDesc::FNumber(n);
            }
        }
    }
}

impl RenderArgs {
    /// `--env` and `--env-strength`.
    fn apply_environment(&self, desc: &mut SceneDesc) -> Result<(), UserError> {
        if let Some(path) = &self.env {
            let img = candela_scene::envmap::load_linear_image(path)
                .map_err(|e| UserError(format!("{}: {e}", path.display())))?;
            desc.environment = Some(EnvironmentDesc {
                map: EnvironmentMapDesc::Equirect(img),
                span: Span::new(path.display().to_string(), 0, 0),
                ..EnvironmentDesc::default()
            });
        }
        if let Some(s) = self.env_strength {
            match &mut desc.environment {
                Some(env) => env.strength = s,
                None => {
                    return Err(UserError(
                        "--env-strength needs an environment (the scene's or --env)".into(),
                    ))
                }
            }
        }
        Ok(())
    }
}

/// What the interrupt handlers share with the render: whether to stop, and which signal
/// asked for it.
struct Interrupt {
    cancel: Arc<AtomicBool>,
    signal: Arc<AtomicUsize>,
}

impl Interrupt {
    /// Ctrl-C (SIGINT) or SIGTERM: the first stops the render at its next work item, so
    /// that what it has is written; a second exits at once, writing nothing. Either way
    /// the exit status is the shell's for that signal, 128 + its number (130, 143).
    fn install() -> Result<Interrupt, UserError> {
        let cancel = Arc::new(AtomicBool::new(false));
        let signal = Arc::new(AtomicUsize::new(0));
        let register = |sig: i32| -> std::io::Result<()> {
            // Handlers run in the order they were registered: the conditional exit sees
            // `cancel` before this signal sets it, so only a second signal exits.
            flag::register_conditional_shutdown(sig, 128 + sig, Arc::clone(&cancel))?;
            flag::register(sig, Arc::clone(&cancel))?;
            flag::register_usize(sig, Arc::clone(&signal), sig as usize)?;
            Ok(())
        };
        for sig in [SIGINT, SIGTERM] {
            register(sig).map_err(|e| UserError(format!("cannot handle signal {sig}: {e}")))?;
        }
        Ok(Interrupt { cancel, signal })
    }

    /// The exit status of a render that the signal stopped.
    fn exit_code(&self) -> ExitCode {
        let sig = self.signal.load(Ordering::SeqCst);
        ExitCode::from(u8::try_from(128 + sig).unwrap_or(130))
    }
}

/// What a `--samples` part holds; the range must lie within the render's spp.
fn part_info(desc: &SceneDesc, range: &std::ops::Range<u32>) -> Result<PartInfo, UserError> {
    let spp = desc.render.spp;
    if range.end > spp {
        return Err(UserError(format!(
            "--samples {}..{} lies beyond the render's {spp} spp (--spp sets the whole render's count)",
            range.start, range.end
        )));
    }
    Ok(PartInfo {
        fingerprint: candela_core::fingerprint::fingerprint(desc),
        seed: desc.render.seed,
        spp,
        samples: vec![range.clone()],
    })
}

pub fn run(args: RenderArgs) -> Result<ExitCode, UserError> {
    // Fail on a bad output name before spending any time rendering.
    let format = ImageFormat::from_path(&args.output)?;
    if args.samples.is_some() && format != ImageFormat::Exr {
        return Err(UserError(format!(
            "{}: --samples writes a film part, which needs an .exr output",
            args.output.display()
        )));
    }
    if args.samples.is_some() && args.passes.requested() {
        return Err(UserError(
            "--aov and --denoise apply to a whole render, not to a --samples part \
             (merge the parts first)"
                .into(),
        ));
    }
    let loaded = Instant::now();
    let mut desc = args.load.load(&args.scene)?;
    let load_s = loaded.elapsed().as_secs_f64();
    let load_peak = crate::footprint::peak_resident_bytes();
    args.apply_overrides(&mut desc);
    if !desc.render.isa.is_supported() {
        // Auto and baseline run anywhere: only v3 can be refused.
        return Err(UserError(
            "--isa v3: this CPU lacks x86-64-v3 (AVX2, FMA, BMI1/2, LZCNT, MOVBE, F16C)".into(),
        ));
    }
    args.apply_environment(&mut desc)?;
    let denoiser = args.passes.load_denoiser()?;
    let part = args
        .samples
        .as_ref()
        .map(|r| part_info(&desc, r))
        .transpose()?;
    let built = Instant::now();
    let scene = candela_core::build::build_owned(desc)?;
    let build_s = built.elapsed().as_secs_f64();
    let build_peak = crate::footprint::peak_resident_bytes();
    let s = &scene.settings;
    if let Some(why) = integrator::lanes_fallback(&scene) {
        eprintln!("candela: --integrator lanes: {why}; rendering with the path integrator");
    }

    let threads = args.threads.unwrap_or(0);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| UserError(format!("cannot start {threads} threads: {e}")))?;
    let interrupt = Interrupt::install()?;

    let range = args.samples.clone().unwrap_or(0..s.spp);
    let total = s.width as u64 * s.height as u64 * range.len() as u64;
    let bar = ProgressBar::new(total);
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {wide_bar} {percent:>3}% ETA {eta}",
        )
        .expect("valid progress template"),
    );
    let start = Instant::now();
    let result = pool
        .install(|| integrator::render(&scene, range.clone(), &interrupt.cancel, &|n| bar.inc(n)));
    let elapsed = start.elapsed().as_secs_f64();
    bar.finish_and_clear();

    let mut passes_summary = None;
    match &part {
        Some(info) if !result.cancelled => write_part(&args.output, &result.film, info)?,
        Some(_) => {
            eprintln!("candela: interrupted: no part written (a part holds its whole range)");
            return Ok(interrupt.exit_code());
        }
        None => {
            let pixels = result.film.resolve();
            let passes = pool.install(|| {
                let (d, cancel) = (denoiser.as_ref(), &interrupt.cancel);
                crate::passes::finish(&args.passes, d, &scene, pixels, cancel, threads)
            })?;
            passes_summary = passes.summary.clone();
            passes.write(&args.output, &args.display.transform())?;
        }
    }

    let st = result.stats;
    println!(
        "{}x{}, {} spp, {:.2} s, {:.2} M paths/s, {:.2} M rays/s -> {}",
        s.width,
        s.height,
        s.spp,
        elapsed,
        st.paths as f64 / elapsed / 1e6,
        st.rays as f64 / elapsed / 1e6,
        args.output.display()
    );
    if let Some(line) = passes_summary {
        println!("{line}");
    }
    if !scene.instances.is_empty() {
        println!(
            "{} instances of {}: {} triangles stored, {} rendered; built in {:.2} s",
            scene.instances.instances.len(),
            crate::info::shared_meshes(scene.instances.meshes.len()),
            scene.stored_triangle_count(),
            scene.triangle_count(),
            build_s
        );
    }
    println!(
        "load {load_s:.2} s, build {build_s:.2} s, render {elapsed:.2} s; scene {}; peak memory {}",
        crate::footprint::describe(&scene),
        crate::footprint::peaks(load_peak, build_peak)
    );
    let rejected = result.film.rejected_samples();
    if rejected > 0 {
        println!("{rejected} non-finite samples were dropped");
    }
    if result.cancelled {
        let done = result.film.total_samples() as f64 / total as f64;
        eprintln!(
            "candela: interrupted: wrote the partial image ({:.1}% of samples) to {}",
            100.0 * done,
            args.output.display()
        );
        return Ok(interrupt.exit_code());
    }
    Ok(ExitCode::SUCCESS)
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        render: RenderArgs,
    }

    fn overridden(args: &[&str]) -> SceneDesc {
        let cli = Cli::try_parse_from([&["candela", "s.toml", "-o", "x.png"], args].concat())
            .expect("flags parse");
        let mut desc = SceneDesc::default();
        cli.render.apply_overrides(&mut desc);
        desc
    }

    #[test]
    fn isa_flag_sets_the_render_loop_copy() {
        assert_eq!(overridden(&[]).render.isa, Isa::Auto);
        assert_eq!(overridden(&["--isa", "baseline"]).render.isa, Isa::Baseline);
        assert_eq!(overridden(&["--isa", "v3"]).render.isa, Isa::V3);
        let cli = Cli::try_parse_from(["candela", "s.toml", "-o", "x.png", "--isa", "v4"]);
        assert!(cli.is_err(), "an unknown copy is refused");
    }

    #[test]
    fn lens_flags_turn_a_pinhole_into_a_thin_lens() {
        assert!(overridden(&[]).camera.lens.is_none());
        let lens = overridden(&["--f-number", "2.8"]).camera.lens.unwrap();
        assert_eq!(lens.size, ApertureSizeDesc::FNumber(2.8));
        assert_eq!(lens.focus, FocusDesc::LookAt);
        let lens = overridden(&["--focus-distance", "3.5", "--f-number", "4"])
            .camera
            .lens
            .unwrap();
        assert_eq!(lens.focus, FocusDesc::Distance(3.5));
        assert_eq!(lens.size, ApertureSizeDesc::FNumber(4.0));
    }
}
