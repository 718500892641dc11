//! The layers of the core, checked on its source: the description (`src/desc.rs`,
//! `src/desc/`) and the option enums it shares with the renderer (`src/options.rs`)
//! import nothing from the renderer, and the math they use (`src/sampling.rs`,
//! `src/math.rs`) imports nothing from the crate outside its tests. So loaders →
//! description → build → scene → integrator stays the only direction.

use std::path::{Path, PathBuf};

/// The first path segment after `crate::` of every `crate::` path in `text`, outside
/// comments and `#[cfg(test)]` modules, with its line number.
fn crate_imports(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let code = line.split("//").next().unwrap_or("");
        if line.trim_start().starts_with("#[cfg(test)]") {
            break; // unit tests sit at the end of a file and may use anything
        }
        let mut rest = code;
        while let Some(at) = rest.find("crate::") {
            let after = &rest[at + "crate::".len()..];
            let name: String = after
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            out.push((i + 1, name));
            rest = after;
        }
    }
    out
}

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

/// Every `.rs` file of `dir`, recursively.
fn files_under(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            out.extend(files_under(&path));
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
    out
}

/// Asserts that `files` reach into the crate only through `allowed` modules.
fn check(files: &[PathBuf], allowed: &[&str]) {
    let mut bad = Vec::new();
    for f in files {
        let text = std::fs::read_to_string(f).unwrap();
        for (line, name) in crate_imports(&text) {
            if !allowed.contains(&name.as_str()) {
                bad.push(format!("{}:{line}: crate::{name}", f.display()));
            }
        }
    }
    assert!(
        bad.is_empty(),
        "imports across the layers:\n{}",
        bad.join("\n")
    );
}

#[test]
fn the_description_imports_nothing_from_the_renderer() {
    let mut files = files_under(&src().join("desc"));
    files.push(src().join("desc.rs"));
    files.push(src().join("options.rs"));
    assert!(files.len() >= 6, "{files:?}");
    check(&files, &["desc", "options", "sampling"]);
}

#[test]
fn the_math_the_description_uses_imports_nothing() {
    check(&[src().join("sampling.rs"), src().join("math.rs")], &[]);
}

#[test]
fn the_check_sees_imports_and_skips_comments_and_unit_tests() {
    let text = "use crate::scene::Scene;\n// crate::light in a comment\nlet x = crate::bsdf::f(); // crate::z\n#[cfg(test)]\nmod tests { use crate::integrator; }\n";
    let found: Vec<String> = crate_imports(text).into_iter().map(|(_, n)| n).collect();
    assert_eq!(found, ["scene", "bsdf"]);
}
