//! The `[environment]` section of the TOML scene format: an equirect panorama, a cube map
//! (six files or one cross) or a constant colour, with strength, rotation and camera
//! visibility. Image paths resolve against the scene file's folder.

use std::fmt;
use std::path::{Path, PathBuf};

use candela_core::desc::{EnvironmentDesc, EnvironmentMapDesc, ImageDesc};
use glam::{Mat3, Vec3};
use serde::de::{self, Deserializer, MapAccess, Visitor};
use serde::Deserialize;
use toml::Spanned;

use crate::envmap::{flip_vertical, load_cube_faces, load_linear_image, split_cross};
use crate::toml::shape::{compose, TransformOp};
use crate::toml::values::{Num, Splat3};
use crate::toml::{deserialize, Item};
use crate::{LoadError, Source};

/// `cubemap = "cross.hdr"` or `cubemap = { px = …, nx = …, py = …, ny = …, pz = …, nz = … }`.
enum CubemapSpec {
    Cross(String),
    Faces(Box<[String; 6]>),
}

const FACE_KEYS: [&str; 6] = ["px", "nx", "py", "ny", "pz", "nz"];

struct CubemapVisitor;

impl<'de> Visitor<'de> for CubemapVisitor {
    type Value = CubemapSpec;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a cross image file or a table of six face files px, nx, py, ny, pz, nz")
    }
    fn visit_str<E: de::Error>(self, v: &str) -> Result<CubemapSpec, E> {
        Ok(CubemapSpec::Cross(v.to_owned()))
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<CubemapSpec, A::Error> {
        let mut faces: [Option<String>; 6] = Default::default();
        while let Some(key) = map.next_key::<String>()? {
            let Some(i) = FACE_KEYS.iter().position(|k| *k == key) else {
                return Err(de::Error::unknown_field(&key, &FACE_KEYS));
            };
            if faces[i].is_some() {
                return Err(de::Error::duplicate_field(FACE_KEYS[i]));
            }
            faces[i] = Some(map.next_value()?);
        }
        let mut out: [String; 6] = Default::default();
        for (i, f) in faces.into_iter().enumerate() {
            out[i] = f.ok_or_else(|| de::Error::missing_field(FACE_KEYS[i]))?;
        }
        Ok(CubemapSpec::Faces(Box::new(out)))
    }
}

impl<'de> Deserialize<'de> for CubemapSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(CubemapVisitor)
    }
}

fn flip_faces(faces: [ImageDesc; 6], flip: bool) -> [ImageDesc; 6] {
    if flip {
        faces.map(|f| flip_vertical(&f))
    } else {
        faces
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct EnvironmentSection {
    equirect: Option<Spanned<String>>,
    cubemap: Option<Spanned<CubemapSpec>>,
    flip_faces: Option<Spanned<bool>>,
    constant: Option<Spanned<Splat3>>,
    strength: Option<Num>,
    rotation: Option<Spanned<Num>>,
    transform: Option<Spanned<Vec<Spanned<TransformOp>>>>,
    visible: Option<bool>,
    background: Option<Splat3>,
}

/// Parses `[environment]`; `key_at` is the offset of the section's key, where build
/// errors will point.
pub(crate) fn parse_environment(
    src: &Source,
    base: &Path,
    key_at: usize,
    value: Item,
) -> Result<EnvironmentDesc, LoadError> {
    let e: EnvironmentSection = deserialize(src, value)?;
    let sources = [
        e.equirect.as_ref().map(|s| s.span().start),
        e.cubemap.as_ref().map(|s| s.span().start),
        e.constant.as_ref().map(|s| s.span().start),
    ];
    let mut given: Vec<usize> = sources.iter().flatten().copied().collect();
    given.sort_unstable(); // point at the second one in the file
    if given.len() != 1 {
        return Err(src.error(
            given.get(1).copied().unwrap_or(key_at),
            "`[environment]` needs exactly one of `equirect`, `cubemap`, `constant`",
        ));
    }
    if let (Some(f), None) = (&e.flip_faces, &e.cubemap) {
        return Err(src.error(f.span().start, "`flip_faces` applies only to a `cubemap`"));
    }
    let flip = e.flip_faces.is_some_and(|f| f.into_inner());
    let resolve = |p: &str| -> PathBuf { base.join(p) };
    let map = if let Some(file) = e.equirect {
        let at = file.span().start;
        // Load errors name the file already.
        let img = load_linear_image(&resolve(file.get_ref())).map_err(|m| src.error(at, m))?;
        EnvironmentMapDesc::Equirect(img)
    } else if let Some(cube) = e.cubemap {
        let at = cube.span().start;
        match cube.into_inner() {
            CubemapSpec::Cross(file) => {
                let img = load_linear_image(&resolve(&file)).map_err(|m| src.error(at, m))?;
                let img = split_cross(&img).map_err(|m| src.error(at, format!("{file}: {m}")))?;
                EnvironmentMapDesc::Cubemap(Box::new(flip_faces(img, flip)))
            }
            CubemapSpec::Faces(files) => {
                let paths: Vec<PathBuf> = files.iter().map(|f| resolve(f)).collect();
                let refs: [&Path; 6] = std::array::from_fn(|i| paths[i].as_path());
                let faces = load_cube_faces(&refs).map_err(|(i, m)| {
                    src.error(at, format!("face {} ({}): {m}", FACE_KEYS[i], files[i]))
                })?;
                EnvironmentMapDesc::Cubemap(Box::new(flip_faces(faces, flip)))
            }
        }
    } else {
        let c = e.constant.expect("one source is given");
        EnvironmentMapDesc::Constant(c.into_inner().0)
    };
    let rotation = match (e.rotation, e.transform) {
        (Some(_), Some(t)) => {
            return Err(src.error(
                t.span().start,
                "give either `rotation` (degrees about y) or `transform`, not both",
            ))
        }
        (Some(deg), None) => Mat3::from_rotation_y(deg.get_ref().0.to_radians()),
        (None, Some(t)) => {
            let at = t.span().start;
            let m = compose(src, t.into_inner())?;
            if m.w_axis.truncate() != Vec3::ZERO {
                return Err(src.error(at, "an environment `transform` cannot translate"));
            }
            Mat3::from_mat4(m)
        }
        (None, None) => Mat3::IDENTITY,
    };
    let d = EnvironmentDesc::default();
    Ok(EnvironmentDesc {
        map,
        strength: e.strength.map_or(d.strength, |n| n.0),
        rotation,
        visible: e.visible.unwrap_or(d.visible),
        background: e.background.map_or(d.background, |c| c.0),
        span: src.span(key_at),
    })
}
