//! Scene files for loader tests: written into a fresh temporary folder (removed when the
//! returned [`TempDir`] is dropped) and loaded as a user's would be.

use std::path::Path;

use candela_scene::{load_scene_with, LoadError, LoadOptions, LoadedScene};
use tempfile::TempDir;

/// Writes `files` (name, contents) into a fresh folder; a name may hold sub-folders.
pub fn write_files(files: &[(&str, &[u8])]) -> TempDir {
    let dir = tempfile::tempdir().unwrap();
    for (name, bytes) in files {
        let path = dir.path().join(name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, bytes).unwrap();
    }
    dir
}

/// Writes `files` into a fresh folder and loads the first with `options`; the folder
/// comes back with the result, so that what the scene refers to stays on disk.
pub fn load_files(
    files: &[(&str, &[u8])],
    options: &LoadOptions,
) -> (TempDir, Result<LoadedScene, LoadError>) {
    let dir = write_files(files);
    let r = load_scene_with(&dir.path().join(files[0].0), options);
    (dir, r)
}

/// Load options with these `-D name=value` parameters, strict or lenient.
pub fn options(defines: &[(&str, &str)], lenient: bool) -> LoadOptions {
    LoadOptions {
        defines: defines
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect(),
        lenient,
        ..LoadOptions::default()
    }
}

/// `message` with the folder `dir` taken off the file names in it, so that a test can
/// compare it with a fixed text.
pub fn without_dir(dir: &Path, message: &str) -> String {
    message.replace(&format!("{}/", dir.display()), "")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn files_land_in_their_folders_and_the_folder_comes_off_messages() {
        let dir = write_files(&[("a.txt", b"x"), ("sub/b.txt", b"yz")]);
        assert_eq!(std::fs::read(dir.path().join("sub/b.txt")).unwrap(), b"yz");
        let message = format!("{}/sub/b.txt:1:2: bad", dir.path().display());
        assert_eq!(without_dir(dir.path(), &message), "sub/b.txt:1:2: bad");
        let o = options(&[("spp", "3")], true);
        assert_eq!(o.defines, vec![("spp".to_string(), "3".to_string())]);
        assert!(o.lenient && o.scene.is_none());
    }
}
