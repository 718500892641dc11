//! `candela.denoise` and `candela.render_aovs`: Intel Open Image Denoise on NumPy images,
//! through [`candela_denoise::Denoiser`] (the library `candela render --denoise` loads),
//! and the albedo, normal and depth passes that guide it.
//!
//! The Python half (`candela/__init__.py`) checks the arrays and hands over their bytes
//! (float32, row-major RGB) with the `pyoidn` package folder its interpreter would import;
//! this half loads OIDN once per process and filters with the GIL released.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::{Arc, Mutex};

use candela_core::aov::AovKind;
use candela_denoise::{Denoiser, Guides, Images, Options};
use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};

use crate::{pixel_bytes, rgb_pixels, Scene, SceneError};

create_exception!(
    _candela,
    DenoiseError,
    PyRuntimeError,
    "Open Image Denoise is absent (the message says how to install it) or failed."
);

/// The library, loaded by the first call that finds it and kept for the process (a
/// failed load is retried by the next call).
static LOADED: Mutex<Option<Arc<Denoiser>>> = Mutex::new(None);

fn denoiser(pyoidn: Option<PathBuf>) -> PyResult<Arc<Denoiser>> {
    let mut loaded = LOADED.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(d) = loaded.as_ref() {
        return Ok(d.clone());
    }
    let d = Arc::new(Denoiser::load_with(pyoidn.as_deref()).map_err(DenoiseError::new_err)?);
    *loaded = Some(d.clone());
    Ok(d)
}

/// Denoises `color` (width·height float32 RGB pixels, row-major) with OIDN's `RT` filter,
/// guided by `albedo` and `normal` if given; returns the denoised pixels as bytes.
/// `pyoidn`: the package folder of `pyoidn` to load the library from after `OIDN_DIR`.
#[pyfunction]
#[pyo3(signature = (color, width, height, albedo=None, normal=None, prefilter=true, hdr=true,
                    threads=None, pyoidn=None))]
#[allow(clippy::too_many_arguments)]
pub fn denoise<'py>(
    py: Python<'py>,
    color: &[u8],
    width: u32,
    height: u32,
    albedo: Option<&[u8]>,
    normal: Option<&[u8]>,
    prefilter: bool,
    hdr: bool,
    threads: Option<usize>,
    pyoidn: Option<PathBuf>,
) -> PyResult<Bound<'py, PyBytes>> {
    let n = width as usize * height as usize;
    let color = rgb_pixels(color, n, "img")?;
    let albedo = albedo.map(|a| rgb_pixels(a, n, "albedo")).transpose()?;
    let normal = normal.map(|a| rgb_pixels(a, n, "normal")).transpose()?;
    if normal.is_some() && albedo.is_none() {
        return Err(PyValueError::new_err(
            "normal needs albedo too (Open Image Denoise takes a normal pass only beside an albedo pass)",
        ));
    }
    let denoiser = denoiser(pyoidn)?;
    let images = Images {
        width,
        height,
        color: &color,
        guides: albedo.as_deref().map(|albedo| Guides {
            albedo,
            normal: normal.as_deref(),
        }),
    };
    let options = Options { hdr, prefilter };
    let out = py
        .allow_threads(|| denoiser.denoise_with(&images, options, threads.unwrap_or(0)))
        .map_err(DenoiseError::new_err)?;
    Ok(PyBytes::new(py, &pixel_bytes(&out)))
}

/// Renders the albedo, normal and depth passes over the sample positions of the render
/// of the same spp and seed (see [`candela_core::aov`]), with the GIL released: a dict of
/// pass name to little-endian float32 bytes, row-major (3 values a pixel, depth 1).
#[pyfunction]
#[pyo3(signature = (scene, spp=None, seed=None, threads=None))]
pub fn render_aovs<'py>(
    py: Python<'py>,
    scene: &Scene,
    spp: Option<u32>,
    seed: Option<u64>,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    let desc = scene.with_overrides(spp, seed);
    let built = py
        .allow_threads(|| candela_core::build::build(&desc))
        .map_err(|e| SceneError::new_err(e.to_string()))?;
    let pool = crate::thread_pool(threads)?;
    let never = AtomicBool::new(false);
    let spp = built.settings.spp;
    let film = py
        .allow_threads(|| pool.install(|| candela_core::aov::render_aovs(&built, 0..spp, &never)));
    let d = PyDict::new(py);
    let albedo = pixel_bytes(&film.albedo());
    d.set_item(AovKind::Albedo.name(), PyBytes::new(py, &albedo))?;
    let normal = pixel_bytes(&film.normal());
    d.set_item(AovKind::Normal.name(), PyBytes::new(py, &normal))?;
    let depth: Vec<u8> = film
        .depth()
        .into_iter()
        .flat_map(f32::to_le_bytes)
        .collect();
    d.set_item(AovKind::Depth.name(), PyBytes::new(py, &depth))?;
    Ok(d)
}
