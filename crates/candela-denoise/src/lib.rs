//! Denoising with Intel Open Image Denoise 2.x (OIDN), loaded at run time.
//!
//! OIDN is not linked: [`Denoiser::load`] finds `libOpenImageDenoise.so.2` through
//! `OIDN_DIR` or a `pyoidn` installation (see [`locate`]) and resolves the dozen C
//! functions Candela calls, so Candela builds and runs without it and only `--denoise`
//! (and the Python package's `candela.denoise`) needs it. The filter is OIDN's `RT`
//! (ray-traced images) on the CPU device at high quality, in HDR mode by default; with
//! albedo (and normal) passes it by default first denoises each of them with the same
//! filter and then tells the beauty's filter they are clean (`cleanAux`), the
//! prefiltering OIDN's documentation prescribes for the highest quality.

mod api;
pub mod locate;

use std::ffi::{c_int, c_void, CStr};
use std::path::Path;

use glam::Vec3;
use libloading::Library;

use api::{Api, Device, Filter};
pub use locate::INSTALL_HINT;

/// The albedo and normal passes that guide the filter (OIDN takes a normal pass only
/// beside an albedo pass).
#[derive(Clone, Copy, Debug)]
pub struct Guides<'a> {
    /// Albedo in [0, 1], row-major.
    pub albedo: &'a [Vec3],
    /// World- or camera-space normals in [−1, 1], row-major.
    pub normal: Option<&'a [Vec3]>,
}

/// How the filter reads its inputs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Options {
    /// The beauty is linear HDR radiance (any non-negative value); `false`: a display
    /// image in [0, 1].
    pub hdr: bool,
    /// Denoise the guides first and tell the beauty's filter they are clean
    /// (`cleanAux`), OIDN's high-quality recipe for guides rendered with the beauty's
    /// noise (antialiasing, depth of field, rough reflections); `false`: pass them as they
    /// are, for noise-free guides or a faster filter.
    pub prefilter: bool,
}

impl Default for Options {
    /// HDR, prefiltered guides: what `candela render --denoise` uses.
    fn default() -> Options {
        Options {
            hdr: true,
            prefilter: true,
        }
    }
}

/// What to denoise: a linear HDR image and, optionally, its guides.
#[derive(Clone, Copy, Debug)]
pub struct Images<'a> {
    pub width: u32,
    pub height: u32,
    /// The noisy beauty, linear radiance, row-major.
    pub color: &'a [Vec3],
    pub guides: Option<Guides<'a>>,
}

/// A loaded OIDN library.
pub struct Denoiser {
    api: Api,
    /// Where it was loaded from.
    pub source: String,
    // Dropped after `api`, whose function pointers point into it.
    _lib: Library,
}

impl Denoiser {
    /// Finds and loads the library. The error is one line; when the library is absent it
    /// says how to install it ([`INSTALL_HINT`]).
    pub fn load() -> Result<Denoiser, String> {
        Denoiser::load_with(None)
    }

    /// [`Denoiser::load`], trying the `pyoidn` package folder `pyoidn` (e.g. the one the
    /// running Python interpreter imports) right after `OIDN_DIR`.
    pub fn load_with(pyoidn: Option<&Path>) -> Result<Denoiser, String> {
        let (lib, source) = match locate::locate_with(pyoidn)? {
            locate::Location::File(path) => {
                // SAFETY: loading runs the library's initializers; this is OIDN's library,
                // found where OIDN installs it.
                let lib = unsafe { Library::new(&path) }
                    .map_err(|e| format!("cannot load {}: {e}", path.display()))?;
                (lib, path.display().to_string())
            }
            locate::Location::System(name) => {
                // SAFETY: as above, by the name OIDN's library has.
                let lib = unsafe { Library::new(name) }.map_err(|_| {
                    format!("Intel Open Image Denoise 2.x was not found: {INSTALL_HINT}")
                })?;
                (lib, name.to_string())
            }
        };
        // SAFETY: the library is OIDN's, whose C API has the signatures `Api` declares.
        let api = unsafe { Api::resolve(&lib) }
            .map_err(|e| format!("{source} is not Open Image Denoise 2.x ({e})"))?;
        Ok(Denoiser {
            api,
            source,
            _lib: lib,
        })
    }

    /// Denoises `images` with OIDN's `RT` filter on the CPU, `threads` of them (0: all),
    /// with the default [`Options`] (HDR, guides prefiltered). Returns the denoised
    /// beauty, row-major.
    pub fn denoise(&self, images: &Images, threads: usize) -> Result<Vec<Vec3>, String> {
        self.denoise_with(images, Options::default(), threads)
    }

    /// [`Denoiser::denoise`] with the given [`Options`].
    pub fn denoise_with(
        &self,
        images: &Images,
        options: Options,
        threads: usize,
    ) -> Result<Vec<Vec3>, String> {
        let n = images.width as usize * images.height as usize;
        assert_eq!(images.color.len(), n, "the beauty has one value a pixel");
        let device = DeviceGuard::new(&self.api, threads)?;
        let version = device.int(c"version");
        if version < 20000 {
            return Err(format!(
                "{} is Open Image Denoise {version}, Candela needs 2.x",
                self.source
            ));
        }
        let size = (images.width as usize, images.height as usize);
        let mut color = flatten(images.color);
        let mut output = vec![0.0f32; 3 * n];
        let Some(guides) = images.guides else {
            device.run(
                size,
                &mut [(c"color", &mut color), (c"output", &mut output)],
                options.hdr,
                false,
            )?;
            return Ok(unflatten(&output));
        };
        assert_eq!(guides.albedo.len(), n, "the albedo has one value a pixel");
        let mut albedo = flatten(guides.albedo);
        let mut normal = guides.normal.map(|normal| {
            assert_eq!(normal.len(), n, "the normal pass has one value a pixel");
            flatten(normal)
        });
        if options.prefilter {
            // Denoise each guide in place, then tell the beauty's filter they are clean.
            device.prefilter(size, c"albedo", &mut albedo)?;
            if let Some(normal) = &mut normal {
                device.prefilter(size, c"normal", normal)?;
            }
        }
        let mut inputs = vec![(c"color", &mut color), (c"albedo", &mut albedo)];
        if let Some(normal) = &mut normal {
            inputs.push((c"normal", normal));
        }
        inputs.push((c"output", &mut output));
        device.run(size, &mut inputs, options.hdr, options.prefilter)?;
        Ok(unflatten(&output))
    }
}

fn flatten(v: &[Vec3]) -> Vec<f32> {
    v.iter().flat_map(|p| p.to_array()).collect()
}

fn unflatten(v: &[f32]) -> Vec<Vec3> {
    v.chunks_exact(3).map(Vec3::from_slice).collect()
}

/// A committed CPU device, released on drop.
struct DeviceGuard<'a> {
    api: &'a Api,
    device: Device,
}

impl<'a> DeviceGuard<'a> {
    fn new(api: &'a Api, threads: usize) -> Result<DeviceGuard<'a>, String> {
        // SAFETY: plain calls into the C API with a device it returned.
        unsafe {
            let device = (api.new_device)(api::DEVICE_TYPE_CPU);
            if device.is_null() {
                return Err("Open Image Denoise could not create a CPU device".into());
            }
            let guard = DeviceGuard { api, device };
            if threads > 0 {
                let t = c_int::try_from(threads).unwrap_or(c_int::MAX);
                (api.set_device_int)(device, c"numThreads".as_ptr(), t);
            }
            (api.commit_device)(device);
            match api.error(device) {
                Some(e) => Err(e),
                None => Ok(guard),
            }
        }
    }

    fn int(&self, name: &CStr) -> c_int {
        // SAFETY: a live device and a NUL-terminated name.
        unsafe { (self.api.get_device_int)(self.device, name.as_ptr()) }
    }

    /// Denoises one guide in place (its own `RT` filter: the guide as input and output).
    fn prefilter(
        &self,
        size: (usize, usize),
        name: &CStr,
        image: &mut [f32],
    ) -> Result<(), String> {
        let ptr = image.as_mut_ptr() as *mut c_void;
        self.execute(size, &[(name, ptr), (c"output", ptr)], |_| {})
    }

    /// Runs the beauty's `RT` filter over `images` (`output` among them).
    fn run(
        &self,
        size: (usize, usize),
        images: &mut [(&CStr, &mut Vec<f32>)],
        hdr: bool,
        clean_aux: bool,
    ) -> Result<(), String> {
        let ptrs: Vec<(&CStr, *mut c_void)> = images
            .iter_mut()
            .map(|(name, v)| (*name, v.as_mut_ptr() as *mut c_void))
            .collect();
        self.execute(size, &ptrs, |filter| {
            // SAFETY: a live filter and NUL-terminated names.
            unsafe {
                (self.api.set_filter_bool)(filter, c"hdr".as_ptr(), hdr);
                (self.api.set_filter_bool)(filter, c"cleanAux".as_ptr(), clean_aux);
            }
        })
    }

    /// Creates an `RT` filter at high quality over `images` (each `3 · width · height`
    /// floats, RGB or XYZ per pixel, tightly packed), lets `configure` set more, then
    /// commits, executes and releases it.
    fn execute(
        &self,
        (width, height): (usize, usize),
        images: &[(&CStr, *mut c_void)],
        configure: impl FnOnce(Filter),
    ) -> Result<(), String> {
        let api = self.api;
        // SAFETY: the buffers outlive the filter, which is released before returning;
        // each holds width·height FLOAT3 pixels (the callers' vectors are that long).
        unsafe {
            let filter = (api.new_filter)(self.device, c"RT".as_ptr());
            if filter.is_null() {
                return Err(api
                    .error(self.device)
                    .unwrap_or_else(|| "Open Image Denoise has no RT filter".into()));
            }
            for &(name, ptr) in images {
                (api.set_shared_filter_image)(
                    filter,
                    name.as_ptr(),
                    ptr,
                    api::FORMAT_FLOAT3,
                    width,
                    height,
                    0,
                    0,
                    0,
                );
            }
            (api.set_filter_int)(filter, c"quality".as_ptr(), api::QUALITY_HIGH);
            configure(filter);
            (api.commit_filter)(filter);
            (api.execute_filter)(filter);
            let error = api.error(self.device);
            (api.release_filter)(filter);
            error.map_or(Ok(()), Err)
        }
    }
}

impl Drop for DeviceGuard<'_> {
    fn drop(&mut self) {
        // SAFETY: the device was created by this library and is released once.
        unsafe { (self.api.release_device)(self.device) }
    }
}
