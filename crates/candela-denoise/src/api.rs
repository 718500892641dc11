//! The few entry points of Open Image Denoise's C API (`OpenImageDenoise/oidn.h`, 2.x)
//! that Candela calls, resolved from the loaded library.

use std::ffi::{c_char, c_int, c_void, CStr};

use libloading::Library;

/// `OIDNDevice`, `OIDNFilter`: opaque handles.
pub type Device = *mut c_void;
pub type Filter = *mut c_void;

/// `OIDN_DEVICE_TYPE_CPU`.
pub const DEVICE_TYPE_CPU: c_int = 1;
/// `OIDN_FORMAT_FLOAT3`.
pub const FORMAT_FLOAT3: c_int = 3;
/// `OIDN_QUALITY_HIGH`: the quality for final frames.
pub const QUALITY_HIGH: c_int = 6;
/// `OIDN_ERROR_NONE`.
pub const ERROR_NONE: c_int = 0;

/// The functions, copied out of the library (which must outlive them: [`crate::Denoiser`]
/// keeps both).
pub struct Api {
    pub new_device: unsafe extern "C" fn(c_int) -> Device,
    pub commit_device: unsafe extern "C" fn(Device),
    pub release_device: unsafe extern "C" fn(Device),
    pub get_device_int: unsafe extern "C" fn(Device, *const c_char) -> c_int,
    pub set_device_int: unsafe extern "C" fn(Device, *const c_char, c_int),
    pub get_device_error: unsafe extern "C" fn(Device, *mut *const c_char) -> c_int,
    pub new_filter: unsafe extern "C" fn(Device, *const c_char) -> Filter,
    #[allow(clippy::type_complexity)]
    pub set_shared_filter_image: unsafe extern "C" fn(
        Filter,
        *const c_char,
        *mut c_void,
        c_int,
        usize,
        usize,
        usize,
        usize,
        usize,
    ),
    pub set_filter_bool: unsafe extern "C" fn(Filter, *const c_char, bool),
    pub set_filter_int: unsafe extern "C" fn(Filter, *const c_char, c_int),
    pub commit_filter: unsafe extern "C" fn(Filter),
    pub execute_filter: unsafe extern "C" fn(Filter),
    pub release_filter: unsafe extern "C" fn(Filter),
}

impl Api {
    /// Resolves every function, or names the first one missing.
    ///
    /// # Safety
    /// `lib` must be Open Image Denoise 2.x, whose functions have these signatures.
    pub unsafe fn resolve(lib: &Library) -> Result<Api, String> {
        macro_rules! get {
            ($name:literal) => {
                *lib.get(concat!($name, "\0").as_bytes())
                    .map_err(|e| format!("{}: {e}", $name))?
            };
        }
        Ok(Api {
            new_device: get!("oidnNewDevice"),
            commit_device: get!("oidnCommitDevice"),
            release_device: get!("oidnReleaseDevice"),
            get_device_int: get!("oidnGetDeviceInt"),
            set_device_int: get!("oidnSetDeviceInt"),
            get_device_error: get!("oidnGetDeviceError"),
            new_filter: get!("oidnNewFilter"),
            set_shared_filter_image: get!("oidnSetSharedFilterImage"),
            set_filter_bool: get!("oidnSetFilterBool"),
            set_filter_int: get!("oidnSetFilterInt"),
            commit_filter: get!("oidnCommitFilter"),
            execute_filter: get!("oidnExecuteFilter"),
            release_filter: get!("oidnReleaseFilter"),
        })
    }

    /// The device's pending error, if any, as a message.
    ///
    /// # Safety
    /// `device` must be a live device of this library.
    pub unsafe fn error(&self, device: Device) -> Option<String> {
        let mut message: *const c_char = std::ptr::null();
        let code = (self.get_device_error)(device, &mut message);
        if code == ERROR_NONE {
            return None;
        }
        let text = if message.is_null() {
            String::from("no message")
        } else {
            CStr::from_ptr(message).to_string_lossy().into_owned()
        };
        Some(format!("Open Image Denoise error {code}: {text}"))
    }
}
