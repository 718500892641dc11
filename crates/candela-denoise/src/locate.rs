//! Where Open Image Denoise's library is: `OIDN_DIR`, else a `pyoidn` installation (the
//! PyPI wheel ships `pyoidn/oidn/lib/libOpenImageDenoise.so.2` with its CPU device), else
//! the system's library path.

use std::env;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The library's file name on this platform (the 2.x ABI).
#[cfg(target_os = "linux")]
pub const LIBRARY: &str = "libOpenImageDenoise.so.2";
#[cfg(target_os = "macos")]
pub const LIBRARY: &str = "libOpenImageDenoise.2.dylib";
#[cfg(windows)]
pub const LIBRARY: &str = "OpenImageDenoise.dll";
#[cfg(not(any(target_os = "linux", target_os = "macos", windows)))]
pub const LIBRARY: &str = "libOpenImageDenoise.so.2";

/// How to install the library, in one line.
pub const INSTALL_HINT: &str = "install it with `pip install pyoidn` (Candela finds the wheel's \
     library through python3 or $VIRTUAL_ENV), or set OIDN_DIR to a folder holding \
     lib/libOpenImageDenoise.so.2";

/// Where the library was found, or why not.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Location {
    /// A file to load.
    File(PathBuf),
    /// A bare name for the system's loader to look up (its library path).
    System(&'static str),
}

/// The files to try under a folder: the folder itself, its `lib`, `lib64` and `bin`, and
/// a `pyoidn` package's `oidn/lib`.
fn candidates(dir: &Path) -> Vec<PathBuf> {
    ["", "lib", "lib64", "bin", "oidn/lib", "pyoidn/oidn/lib"]
        .iter()
        .map(|sub| dir.join(sub).join(LIBRARY))
        .collect()
}

fn first_file(dir: &Path) -> Option<PathBuf> {
    candidates(dir).into_iter().find(|p| p.is_file())
}

/// Finds the library. `OIDN_DIR`, when set, must hold it (a folder or the file itself);
/// otherwise the active virtual environment's `pyoidn`, then the `pyoidn` that `python3`
/// imports, then the system's loader.
pub fn locate() -> Result<Location, String> {
    locate_with(None)
}

/// [`locate`], trying the `pyoidn` package folder `pyoidn` right after `OIDN_DIR` (the
/// Python package passes the one its own interpreter imports, which `python3` on the
/// path may not see).
pub fn locate_with(pyoidn: Option<&Path>) -> Result<Location, String> {
    if let Some(dir) = env::var_os("OIDN_DIR").filter(|d| !d.is_empty()) {
        let dir = PathBuf::from(dir);
        if dir.is_file() {
            return Ok(Location::File(dir));
        }
        return first_file(&dir).map(Location::File).ok_or_else(|| {
            format!(
                "OIDN_DIR={} holds no {LIBRARY} (nor lib/{LIBRARY}): {INSTALL_HINT}",
                dir.display()
            )
        });
    }
    if let Some(found) = pyoidn.and_then(first_file) {
        return Ok(Location::File(found));
    }
    if let Some(found) = virtual_env_pyoidn().or_else(python_pyoidn) {
        return Ok(Location::File(found));
    }
    Ok(Location::System(LIBRARY))
}

/// `$VIRTUAL_ENV/lib/python3.*/site-packages/pyoidn/oidn/lib`.
fn virtual_env_pyoidn() -> Option<PathBuf> {
    let venv = PathBuf::from(env::var_os("VIRTUAL_ENV")?);
    let lib = std::fs::read_dir(venv.join("lib")).ok()?;
    lib.flatten()
        .filter(|e| e.file_name().to_string_lossy().starts_with("python"))
        .find_map(|e| first_file(&e.path().join("site-packages")))
}

/// The `pyoidn` package of `python3` (without importing it: `find_spec` reads no code of
/// the package), e.g. a `pip install --user pyoidn`.
fn python_pyoidn() -> Option<PathBuf> {
    let script = "import importlib.util as u\n\
                  s = u.find_spec('pyoidn')\n\
                  print(s.submodule_search_locations[0] if s and s.submodule_search_locations else '')";
    let out = Command::new("python3").args(["-c", script]).output().ok()?;
    if !out.status.success() {
        return None;
    }
    let dir = String::from_utf8(out.stdout).ok()?;
    let dir = dir.trim();
    (!dir.is_empty())
        .then(|| first_file(Path::new(dir)))
        .flatten()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_folder_is_searched_in_its_lib_and_pyoidn_layouts() {
        let dir = std::env::temp_dir().join(format!("candela-oidn-{}", std::process::id()));
        let lib = dir.join("pyoidn/oidn/lib");
        std::fs::create_dir_all(&lib).unwrap();
        assert_eq!(first_file(&dir), None);
        std::fs::write(lib.join(LIBRARY), b"").unwrap();
        assert_eq!(first_file(&dir), Some(lib.join(LIBRARY)));
        std::fs::create_dir_all(dir.join("lib")).unwrap();
        std::fs::write(dir.join("lib").join(LIBRARY), b"").unwrap();
        assert_eq!(first_file(&dir), Some(dir.join("lib").join(LIBRARY)));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
