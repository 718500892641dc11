//! `candela._candela`: the native half of the Python package. The Python half
//! (`python/candela/__init__.py`) turns pixels into NumPy arrays and draws the progress
//! bar; this half loads scenes, renders with the GIL released, writes images, reads,
//! writes and merges film parts, and denoises images ([`denoise`]).

mod denoise;

use std::ops::Range;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Duration;

use candela_cli::merge::{merge_parts, NamedPart};
use candela_cli::output::{write_image, LinearImage};
use candela_cli::part::{read_part, write_part, PartInfo};
use candela_cli::tonemap::{DisplayTransform, Tonemap};
use candela_core::desc::{FilterSampling, SceneDesc};
use candela_core::film::Film as CoreFilm;
use candela_core::integrator;
use clap::ValueEnum;
use glam::Vec3;
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};

create_exception!(
    _candela,
    SceneError,
    PyException,
    "A scene that cannot be loaded or built; the message is `file:line:col: what is wrong`."
);
create_exception!(
    _candela,
    MergeError,
    PyException,
    "Films that cannot be merged: other scene, resolution, seed or spp, or overlapping ranges."
);

/// How often the waiting thread looks at Python's signals and the progress counter.
const POLL: Duration = Duration::from_millis(50);

/// A loaded scene description (not yet built).
#[pyclass(module = "candela._candela", frozen)]
struct Scene {
    desc: SceneDesc,
    path: String,
    #[pyo3(get)]
    warnings: Vec<String>,
}

#[pymethods]
impl Scene {
    /// The file the scene was loaded from.
    #[getter]
    fn path(&self) -> &str {
        &self.path
    }

    /// (width, height) in pixels.
    #[getter]
    fn resolution(&self) -> (u32, u32) {
        (self.desc.render.width, self.desc.render.height)
    }

    /// The scene's own samples per pixel.
    #[getter]
    fn spp(&self) -> u32 {
        self.desc.render.spp
    }

    /// The scene's own seed.
    #[getter]
    fn seed(&self) -> u64 {
        self.desc.render.seed
    }

    fn __repr__(&self) -> String {
        let r = &self.desc.render;
        format!(
            "<candela.Scene {} {}x{} {} spp>",
            self.path, r.width, r.height, r.spp
        )
    }
}

impl Scene {
    /// The description with the render's own spp and seed overrides.
    fn with_overrides(&self, spp: Option<u32>, seed: Option<u64>) -> SceneDesc {
        let mut desc = self.desc.clone();
        if let Some(spp) = spp {
            desc.render.spp = spp;
        }
        if let Some(seed) = seed {
            desc.render.seed = seed;
        }
        desc
    }
}

/// A pool of `threads` workers (default: one a core).
fn thread_pool(threads: Option<usize>) -> PyResult<rayon::ThreadPool> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map_err(|e| PyValueError::new_err(format!("cannot start threads: {e}")))
}

/// The film of a range of sample indices: exact per-pixel sums that merge bit for bit.
#[pyclass(module = "candela._candela", frozen)]
struct Film {
    film: CoreFilm,
    info: PartInfo,
}

#[pymethods]
impl Film {
    #[getter]
    fn width(&self) -> u32 {
        self.film.width
    }

    #[getter]
    fn height(&self) -> u32 {
        self.film.height
    }

    /// The sample-index ranges held, as (start, end) pairs.
    #[getter]
    fn samples(&self) -> Vec<(u32, u32)> {
        self.info.samples.iter().map(|r| (r.start, r.end)).collect()
    }

    /// Samples per pixel of the whole render this film is part of.
    #[getter]
    fn spp(&self) -> u32 {
        self.info.spp
    }

    #[getter]
    fn seed(&self) -> u64 {
        self.info.seed
    }

    /// The scene-and-settings fingerprint, as 16 hex digits.
    #[getter]
    fn fingerprint(&self) -> String {
        format!("{:016x}", self.info.fingerprint)
    }

    /// Whether the film holds every sample 0..spp.
    #[getter]
    fn complete(&self) -> bool {
        self.info.is_complete()
    }

    /// Samples dropped for being non-finite or out of range.
    #[getter]
    fn rejected(&self) -> u64 {
        self.film.rejected_samples()
    }

    /// The resolved image: a float32 NumPy array (height, width, 3) of linear radiance,
    /// each pixel its samples' weighted mean.
    fn image(&self, py: Python<'_>) -> PyResult<PyObject> {
        let bytes = PyBytes::new(py, &pixel_bytes(&self.film.resolve()));
        let shape = (self.film.height as usize, self.film.width as usize, 3usize);
        let np = py.import("numpy")?;
        let flat = np.call_method1("frombuffer", (bytes, "<f4"))?;
        let image = flat.call_method1("reshape", (shape,))?;
        Ok(image.call_method1("astype", ("float32",))?.unbind())
    }

    /// Writes the film as an OpenEXR part file that `candela merge` reads.
    fn save(&self, path: PathBuf) -> PyResult<()> {
        write_part(&path, &self.film, &self.info).map_err(|e| PyValueError::new_err(e.0))
    }

    /// The film as part-file bytes (how films travel between processes).
    fn __getstate__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let bytes = candela_cli::part::encode_part(&self.film, &self.info)
            .map_err(PyValueError::new_err)?;
        Ok(PyBytes::new(py, &bytes))
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(PyObject, (Bound<'py, PyBytes>,))> {
        let py = slf.py();
        let ctor = py.import("candela._candela")?.getattr("_film_from_bytes")?;
        Ok((ctor.unbind(), (slf.get().__getstate__(py)?,)))
    }

    fn __repr__(&self) -> String {
        let ranges: Vec<String> = self
            .info
            .samples
            .iter()
            .map(|r| format!("{}..{}", r.start, r.end))
            .collect();
        format!(
            "<candela.Film {}x{} samples {} of {} spp>",
            self.film.width,
            self.film.height,
            ranges.join(","),
            self.info.spp
        )
    }
}

/// Pixels as little-endian float32 RGB bytes, how images cross into Python.
fn pixel_bytes(pixels: &[Vec3]) -> Vec<u8> {
    pixels
        .iter()
        .flat_map(|p| p.to_array())
        .flat_map(f32::to_le_bytes)
        .collect()
}

/// [`pixel_bytes`] back into `n` pixels, or an error naming the image (`what`) when the
/// length is not 12·`n` bytes.
fn rgb_pixels(bytes: &[u8], n: usize, what: &str) -> PyResult<Vec<Vec3>> {
    if bytes.len() != 12 * n {
        return Err(PyValueError::new_err(format!(
            "{what}: expected {n} RGB float32 pixels ({} bytes), got {} bytes",
            12 * n,
            bytes.len()
        )));
    }
    Ok(bytes
        .chunks_exact(12)
        .map(|p| {
            let f = |i: usize| f32::from_le_bytes(p[4 * i..4 * i + 4].try_into().unwrap());
            Vec3::new(f(0), f(1), f(2))
        })
        .collect())
}

/// Loads a scene (.toml, Mitsuba .xml, .gltf/.glb) with `NAME=VALUE` parameters.
#[pyfunction]
#[pyo3(signature = (path, defines, lenient=false, gltf_scene=None))]
fn load(
    py: Python<'_>,
    path: PathBuf,
    defines: Vec<(String, String)>,
    lenient: bool,
    gltf_scene: Option<usize>,
) -> PyResult<Scene> {
    let options = candela_scene::LoadOptions {
        defines,
        lenient,
        scene: gltf_scene,
    };
    let loaded = py
        .allow_threads(|| candela_scene::load_scene_with(&path, &options))
        .map_err(|e| SceneError::new_err(e.to_string()))?;
    Ok(Scene {
        desc: loaded.desc,
        path: path.display().to_string(),
        warnings: loaded.warnings,
    })
}

/// Renders `samples` (default 0..spp) of the scene with optional spp and seed overrides.
/// `progress(done, total)` is called from the waiting thread (with the GIL) every 50 ms.
/// `filter_sampling`: "splat" or "importance" over the scene's own.
#[pyfunction]
#[pyo3(signature = (scene, spp=None, seed=None, samples=None, threads=None, progress=None,
                    filter_sampling=None))]
#[allow(clippy::too_many_arguments)]
fn render_film(
    py: Python<'_>,
    scene: &Scene,
    spp: Option<u32>,
    seed: Option<u64>,
    samples: Option<(u32, u32)>,
    threads: Option<usize>,
    progress: Option<PyObject>,
    filter_sampling: Option<&str>,
) -> PyResult<Film> {
    let mut desc = scene.with_overrides(spp, seed);
    match filter_sampling {
        None => {}
        Some("splat") => desc.render.filter_sampling = FilterSampling::Splat,
        Some("importance") => desc.render.filter_sampling = FilterSampling::Importance,
        Some(other) => {
            return Err(PyValueError::new_err(format!(
                "filter_sampling must be \"splat\" or \"importance\", got {other:?}"
            )))
        }
    }
    let total_spp = desc.render.spp;
    let range: Range<u32> = match samples {
        None => 0..total_spp,
        Some((a, b)) if a < b && b <= total_spp => a..b,
        Some((a, b)) => {
            return Err(PyValueError::new_err(format!(
                "samples range({a}, {b}) must be non-empty and within 0..{total_spp} (spp)"
            )))
        }
    };
    let built = py
        .allow_threads(|| candela_core::build::build(&desc))
        .map_err(|e| SceneError::new_err(e.to_string()))?;
    let pool = thread_pool(threads)?;
    let (w, h) = (built.settings.width as u64, built.settings.height as u64);
    let total = w * h * range.len() as u64;
    let cancel = AtomicBool::new(false);
    let done = AtomicU64::new(0);
    let mut interrupted = None;
    let result = std::thread::scope(|s| {
        let worker = s.spawn(|| {
            pool.install(|| {
                integrator::render(&built, range.clone(), &cancel, &|n| {
                    done.fetch_add(n, Ordering::Relaxed);
                })
            })
        });
        // This thread waits with the GIL released, and takes it briefly every POLL to
        // run signal handlers (Ctrl-C raises KeyboardInterrupt here) and the bar.
        while !worker.is_finished() {
            py.allow_threads(|| std::thread::sleep(POLL));
            if interrupted.is_none() {
                if let Err(e) = py.check_signals() {
                    cancel.store(true, Ordering::Relaxed);
                    interrupted = Some(e);
                }
            }
            if let Some(cb) = &progress {
                if let Err(e) = cb.call1(py, (done.load(Ordering::Relaxed), total)) {
                    cancel.store(true, Ordering::Relaxed);
                    interrupted.get_or_insert(e);
                }
            }
        }
        py.allow_threads(|| worker.join())
    });
    let result = result.map_err(|_| PyException::new_err("the render thread panicked"))?;
    if let Some(e) = interrupted {
        return Err(e);
    }
    if let Some(cb) = &progress {
        cb.call1(py, (total, total))?;
    }
    Ok(Film {
        film: result.film,
        info: PartInfo {
            fingerprint: candela_core::fingerprint::fingerprint(&desc),
            seed: desc.render.seed,
            spp: total_spp,
            samples: vec![range],
        },
    })
}

/// Merges films of disjoint sample ranges of one render, exactly.
#[pyfunction]
fn merge(films: Vec<Bound<'_, Film>>) -> PyResult<Film> {
    let parts: Vec<NamedPart> = films
        .iter()
        .enumerate()
        .map(|(i, f)| {
            let f = f.get();
            NamedPart {
                name: format!("film {i}"),
                film: f.film.clone(),
                info: f.info.clone(),
            }
        })
        .collect();
    let (film, info) = merge_parts(&parts).map_err(|e| MergeError::new_err(e.0))?;
    Ok(Film { film, info })
}

/// Reads a film part file (.exr from `render --samples`, `merge` or `Film.save`).
#[pyfunction]
fn read_film(path: PathBuf) -> PyResult<Film> {
    let (film, info) = read_part(&path).map_err(|e| PyValueError::new_err(e.0))?;
    Ok(Film { film, info })
}

#[pyfunction]
fn _film_from_bytes(bytes: &[u8]) -> PyResult<Film> {
    let (film, info) = candela_cli::part::decode_part(bytes).map_err(PyValueError::new_err)?;
    Ok(Film { film, info })
}

/// Writes linear f32 RGB bytes (row-major, top row first) as .exr, .pfm or .png.
#[pyfunction]
#[pyo3(signature = (path, pixels, width, height, exposure=0.0, tonemap="none", gamma=None))]
#[allow(clippy::too_many_arguments)]
fn write_pixels(
    py: Python<'_>,
    path: PathBuf,
    pixels: &[u8],
    width: u32,
    height: u32,
    exposure: f32,
    tonemap: &str,
    gamma: Option<f32>,
) -> PyResult<()> {
    let n = width as usize * height as usize;
    let rgb = rgb_pixels(pixels, n, "pixels")?;
    let tonemap = Tonemap::from_str(tonemap, true).map_err(PyValueError::new_err)?;
    if gamma.is_some_and(|g| !(g.is_finite() && g > 0.0)) {
        return Err(PyValueError::new_err("gamma must be a positive number"));
    }
    let display = DisplayTransform {
        exposure,
        tonemap,
        gamma,
    };
    py.allow_threads(|| {
        let image = LinearImage {
            width,
            height,
            pixels: &rgb,
        };
        write_image(&path, &image, &display)
    })
    .map_err(|e| PyValueError::new_err(e.0))
}

/// What the built scene contains, like `candela info`.
#[pyfunction]
fn info<'py>(py: Python<'py>, scene: &Scene) -> PyResult<Bound<'py, PyDict>> {
    let built = py
        .allow_threads(|| candela_core::build::build(&scene.desc))
        .map_err(|e| SceneError::new_err(e.to_string()))?;
    let d = PyDict::new(py);
    let s = &built.settings;
    d.set_item("path", &scene.path)?;
    d.set_item("resolution", (s.width, s.height))?;
    d.set_item("spp", s.spp)?;
    d.set_item("seed", s.seed)?;
    d.set_item("max_depth", s.max_depth)?;
    d.set_item("shapes", scene.desc.shapes.len())?;
    d.set_item("triangles", built.triangle_count())?;
    d.set_item("stored_triangles", built.stored_triangle_count())?;
    d.set_item("instances", built.instances.instances.len())?;
    d.set_item("lights", built.lights.len())?;
    let power: f32 = built.lights.iter().map(|l| l.power()).sum();
    d.set_item("light_power_w", power)?;
    let names: Vec<&str> = scene
        .desc
        .materials
        .iter()
        .map(|m| m.name.as_str())
        .collect();
    d.set_item("materials", names)?;
    let b = built.bounds();
    d.set_item("bounds", (b.min.to_array(), b.max.to_array()))?;
    d.set_item(
        "fingerprint",
        format!(
            "{:016x}",
            candela_core::fingerprint::fingerprint(&scene.desc)
        ),
    )?;
    Ok(d)
}

#[pymodule]
fn _candela(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Scene>()?;
    m.add_class::<Film>()?;
    m.add("SceneError", m.py().get_type::<SceneError>())?;
    m.add("MergeError", m.py().get_type::<MergeError>())?;
    m.add("DenoiseError", m.py().get_type::<denoise::DenoiseError>())?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(render_film, m)?)?;
    m.add_function(wrap_pyfunction!(merge, m)?)?;
    m.add_function(wrap_pyfunction!(read_film, m)?)?;
    m.add_function(wrap_pyfunction!(_film_from_bytes, m)?)?;
    m.add_function(wrap_pyfunction!(write_pixels, m)?)?;
    m.add_function(wrap_pyfunction!(info, m)?)?;
    m.add_function(wrap_pyfunction!(denoise::denoise, m)?)?;
    m.add_function(wrap_pyfunction!(denoise::render_aovs, m)?)?;
    Ok(())
}
