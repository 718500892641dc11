//! `[[shape]]` entries of the TOML scene format and their `transform` lists.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use candela_core::desc::{GeometryDesc, MeshDesc, ShapeDesc, Span, TextureDesc};
use candela_core::photometry::GoniometricTable;
use glam::{Mat4, Vec3, Vec4};
use serde::de::IgnoredAny;
use serde::Deserialize;
use toml::Spanned;

use crate::toml::material::{texture, Slot, TexValue};
use crate::toml::values::{Num, NumArray, Splat3, V2, V3};
use crate::toml::{deserialize, item_type, Item};
use crate::{load_mesh, LoadError, Source};

/// One step of a `transform` list: a one-key inline table such as `{ translate = [...] }`.
#[derive(Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub(crate) enum TransformOp {
    Translate(V3),
    /// Right-handed rotation about `axis` by `angle` degrees.
    Rotate {
        axis: V3,
        angle: Num,
    },
    Scale(Splat3),
    /// 16 numbers, row-major.
    Matrix(NumArray<16>),
    /// Mitsuba's `lookat`: +z to `target - origin`, +y towards `up`, origin to `origin`.
    LookAt {
        origin: V3,
        target: V3,
        up: Option<V3>,
    },
}

fn op_matrix(src: &Source, op: Spanned<TransformOp>) -> Result<Mat4, LoadError> {
    let at = op.span().start;
    Ok(match op.into_inner() {
        TransformOp::Translate(t) => Mat4::from_translation(t.vec3()),
        TransformOp::Rotate { axis, angle } => {
            let axis = axis.vec3().normalize_or_zero();
            if axis == Vec3::ZERO {
                return Err(src.error(at, "rotation axis must not be zero"));
            }
            Mat4::from_axis_angle(axis, angle.0.to_radians())
        }
        TransformOp::Scale(s) => Mat4::from_scale(s.0),
        TransformOp::Matrix(m) => Mat4::from_cols_array(&m.0).transpose(),
        TransformOp::LookAt { origin, target, up } => {
            look_at(origin.vec3(), target.vec3(), up.map_or(Vec3::Y, V3::vec3)).ok_or_else(
                || {
                    src.error(
                        at,
                        "look_at needs target != origin and an `up` not parallel to \
                         target - origin",
                    )
                },
            )?
        }
    })
}

/// Mitsuba's `lookat` transform: maps +z to the unit direction from `origin` to `target`,
/// +y to the part of `up` orthogonal to it, +x to `up × dir`, and moves the origin to
/// `origin`. A rotation (determinant +1) followed by a translation.
pub(crate) fn look_at(origin: Vec3, target: Vec3, up: Vec3) -> Option<Mat4> {
    let dir = (target - origin).normalize_or_zero();
    let left = up.cross(dir).normalize_or_zero();
    if dir == Vec3::ZERO || left == Vec3::ZERO {
        return None;
    }
    let new_up = dir.cross(left);
    Some(Mat4::from_cols(
        left.extend(0.0),
        new_up.extend(0.0),
        dir.extend(0.0),
        Vec4::from((origin, 1.0)),
    ))
}

/// Composes a `transform` list; the first item is applied to the object first.
pub(crate) fn compose(src: &Source, ops: Vec<Spanned<TransformOp>>) -> Result<Mat4, LoadError> {
    let mut m = Mat4::IDENTITY;
    for op in ops {
        m = op_matrix(src, op)? * m;
    }
    Ok(m)
}

/// Keys every shape takes; repeated in each entry type because serde's `flatten` does not
/// combine with `deny_unknown_fields`.
struct Common {
    material: String,
    emission: Option<Spanned<TexValue>>,
    ies: Option<Spanned<String>>,
    flip_normals: Option<bool>,
    transform: Option<Vec<Spanned<TransformOp>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MeshEntry {
    #[serde(rename = "type")]
    _kind: IgnoredAny,
    file: Option<Spanned<String>>,
    positions: Option<Spanned<Vec<V3>>>,
    indices: Option<Spanned<Vec<[u32; 3]>>>,
    normals: Option<Spanned<Vec<V3>>>,
    uvs: Option<Spanned<Vec<V2>>>,
    material: String,
    emission: Option<Spanned<TexValue>>,
    ies: Option<Spanned<String>>,
    flip_normals: Option<bool>,
    transform: Option<Vec<Spanned<TransformOp>>>,
    /// Placements of the one mesh: each a transform list applied after `transform`.
    instances: Option<Spanned<Vec<Vec<Spanned<TransformOp>>>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SphereEntry {
    #[serde(rename = "type")]
    _kind: IgnoredAny,
    center: Option<V3>,
    radius: Option<Num>,
    material: String,
    emission: Option<Spanned<TexValue>>,
    ies: Option<Spanned<String>>,
    flip_normals: Option<bool>,
    transform: Option<Vec<Spanned<TransformOp>>>,
}

/// `rectangle`, `disk` and `cube`: unit primitives placed by their transform.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PrimitiveEntry {
    #[serde(rename = "type")]
    _kind: IgnoredAny,
    material: String,
    emission: Option<Spanned<TexValue>>,
    ies: Option<Spanned<String>>,
    flip_normals: Option<bool>,
    transform: Option<Vec<Spanned<TransformOp>>>,
}

const SHAPE_TYPES: &[&str] = &["mesh", "sphere", "rectangle", "disk", "cube"];

/// An IES profile attached to an emitting shape, and where it was named.
pub(crate) type ShapeProfile = (Arc<GoniometricTable>, Span);

/// Meshes loaded from files so far, by path: `[[shape]]` entries naming the same file
/// share one `Arc`, which the build instances.
pub(crate) type MeshFiles = HashMap<PathBuf, Arc<MeshDesc>>;

/// Parses one `[[shape]]` entry and its IES profile, if any; files resolve against
/// `base`. A mesh with `instances` gives one shape per instance, all holding one mesh.
pub(crate) fn parse_shape(
    src: &Source,
    base: &Path,
    item: Item,
    files: &mut MeshFiles,
) -> Result<(Vec<ShapeDesc>, Option<ShapeProfile>), LoadError> {
    let at = item.span().start;
    let kind = item_type(src, "shape", &item, SHAPE_TYPES)?;
    check_transform_steps(src, &item)?;
    let mut instances = None;
    let (geometry, common) = match kind {
        "mesh" => {
            let e: MeshEntry = deserialize(src, item)?;
            let common = Common {
                material: e.material,
                emission: e.emission,
                ies: e.ies,
                flip_normals: e.flip_normals,
                transform: e.transform,
            };
            if let Some(list) = e.instances {
                if list.get_ref().is_empty() {
                    return Err(src.error(list.span().start, "`instances` is empty"));
                }
                instances = Some(list.into_inner());
            }
            let mesh = match (e.file, e.positions, e.indices) {
                (Some(file), None, None) if e.normals.is_none() && e.uvs.is_none() => {
                    mesh_file(src, base, file, files)?
                }
                (Some(file), ..) => {
                    return Err(src.error(
                        file.span().start,
                        "`file` and inline mesh data (`positions`, `indices`, `normals`, \
                         `uvs`) exclude each other",
                    ))
                }
                (None, Some(positions), Some(indices)) => {
                    Arc::new(inline_mesh(src, positions, indices, e.normals, e.uvs)?)
                }
                _ => {
                    return Err(src.error(
                        at,
                        "a mesh needs either `file` or both `positions` and `indices`",
                    ))
                }
            };
            (GeometryDesc::Mesh(mesh), common)
        }
        "sphere" => {
            let e: SphereEntry = deserialize(src, item)?;
            let geometry = GeometryDesc::Sphere {
                center: e.center.map_or(Vec3::ZERO, V3::vec3),
                radius: e.radius.map_or(1.0, |r| r.0),
            };
            let common = Common {
                material: e.material,
                emission: e.emission,
                ies: e.ies,
                flip_normals: e.flip_normals,
                transform: e.transform,
            };
            (geometry, common)
        }
        primitive => {
            let e: PrimitiveEntry = deserialize(src, item)?;
            let geometry = match primitive {
                "rectangle" => GeometryDesc::Rectangle,
                "disk" => GeometryDesc::Disk,
                _ => GeometryDesc::Cube,
            };
            let common = Common {
                material: e.material,
                emission: e.emission,
                ies: e.ies,
                flip_normals: e.flip_normals,
                transform: e.transform,
            };
            (geometry, common)
        }
    };
    let profile = match &common.ies {
        None => None,
        Some(file) if common.emission.is_none() => {
            return Err(src.error(
                file.span().start,
                "`ies` shapes an emitter's radiance; the shape needs an `emission`",
            ))
        }
        Some(file) if matches!(geometry, GeometryDesc::Sphere { .. }) => {
            return Err(src.error(file.span().start, "`ies` is not supported on spheres"))
        }
        Some(file) => Some((
            crate::toml::light::load_ies_table(src, base, file)?,
            src.span(file.span().start),
        )),
    };
    // A constant emission is the radiance; a texture multiplies a radiance of one.
    let (emission, emission_texture) = match common.emission {
        None => (None, None),
        Some(v) => match texture(src, base, v, Slot::Color)? {
            TextureDesc::Constant(c) => (Some(c), None),
            t => (Some(Vec3::ONE), Some(t)),
        },
    };
    let shape = ShapeDesc {
        geometry,
        material: common.material,
        emission,
        emission_texture,
        transform: compose(src, common.transform.unwrap_or_default())?,
        flip_normals: common.flip_normals.unwrap_or(false),
        span: src.span(at),
    };
    let Some(instances) = instances else {
        return Ok((vec![shape], profile));
    };
    let shapes = instances
        .into_iter()
        .map(|steps| {
            Ok(ShapeDesc {
                transform: compose(src, steps)? * shape.transform,
                ..shape.clone()
            })
        })
        .collect::<Result<_, LoadError>>()?;
    Ok((shapes, profile))
}

/// Gives a step with several keys a clearer error than serde's enum message.
pub(crate) fn check_transform_steps(src: &Source, item: &Item) -> Result<(), LoadError> {
    let steps = item.get_ref().as_table().and_then(|t| t.get("transform"));
    let Some(steps) = steps.and_then(|s| s.get_ref().as_array()) else {
        return Ok(()); // absent, or a wrong type that serde reports
    };
    for step in steps.iter() {
        match step.get_ref().as_table() {
            Some(t) if t.len() != 1 => {
                return Err(src.error(
                    step.span().start,
                    format!(
                        "a transform step must have exactly one key (`translate`, `rotate`, \
                         `scale`, `matrix` or `look_at`), found {}",
                        t.len()
                    ),
                ))
            }
            _ => {}
        }
    }
    Ok(())
}

fn mesh_file(
    src: &Source,
    base: &Path,
    file: Spanned<String>,
    files: &mut MeshFiles,
) -> Result<Arc<MeshDesc>, LoadError> {
    let at = file.span().start;
    let path = base.join(file.get_ref());
    if !path.is_file() {
        return Err(src.error(at, format!("mesh file {} does not exist", path.display())));
    }
    let key = std::fs::canonicalize(&path).unwrap_or(path);
    if let Some(m) = files.get(&key) {
        return Ok(m.clone());
    }
    let mesh = Arc::new(load_mesh(&key).map_err(|e| src.error(at, e.to_string()))?);
    files.insert(key, mesh.clone());
    Ok(mesh)
}

fn inline_mesh(
    src: &Source,
    positions: Spanned<Vec<V3>>,
    indices: Spanned<Vec<[u32; 3]>>,
    normals: Option<Spanned<Vec<V3>>>,
    uvs: Option<Spanned<Vec<V2>>>,
) -> Result<MeshDesc, LoadError> {
    let n = positions.get_ref().len();
    if indices.get_ref().is_empty() {
        return Err(src.error(indices.span().start, "mesh has no triangles"));
    }
    if let Some(i) = indices
        .get_ref()
        .iter()
        .flatten()
        .find(|&&i| i as usize >= n)
    {
        return Err(src.error(
            indices.span().start,
            format!("index {i} is out of range ({n} positions)"),
        ));
    }
    let check_len = |what: &str, at: usize, len: usize| {
        if len == n {
            Ok(())
        } else {
            Err(src.error(at, format!("{len} {what} for {n} positions")))
        }
    };
    if let Some(normals) = &normals {
        check_len("normals", normals.span().start, normals.get_ref().len())?;
    }
    if let Some(uvs) = &uvs {
        check_len("uvs", uvs.span().start, uvs.get_ref().len())?;
    }
    Ok(MeshDesc {
        positions: positions.into_inner().into_iter().map(V3::vec3).collect(),
        normals: normals.map_or_else(Vec::new, |v| {
            v.into_inner().into_iter().map(V3::vec3).collect()
        }),
        uvs: uvs.map_or_else(Vec::new, |v| {
            v.into_inner().into_iter().map(V2::vec2).collect()
        }),
        indices: indices.into_inner(),
        colors: Vec::new(),
        tangents: Vec::new(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn look_at_maps_z_to_the_view_direction_and_y_towards_up() {
        let m = look_at(Vec3::new(1.0, 2.0, 3.0), Vec3::new(1.0, 2.0, -7.0), Vec3::Y).unwrap();
        assert!(m
            .transform_point3(Vec3::ZERO)
            .abs_diff_eq(Vec3::new(1.0, 2.0, 3.0), 1e-6));
        assert!(m.transform_vector3(Vec3::Z).abs_diff_eq(-Vec3::Z, 1e-6));
        assert!(m.transform_vector3(Vec3::Y).abs_diff_eq(Vec3::Y, 1e-6));
        // Right-handed: +x = y × z, so it goes to up × dir = y × (-z) = -x.
        assert!(m.transform_vector3(Vec3::X).abs_diff_eq(-Vec3::X, 1e-6));
        assert!((m.determinant() - 1.0).abs() < 1e-5);

        // A tilted up keeps only its part orthogonal to the view direction.
        let m = look_at(Vec3::ZERO, Vec3::X, Vec3::new(0.3, 1.0, 0.0)).unwrap();
        assert!(m.transform_vector3(Vec3::Z).abs_diff_eq(Vec3::X, 1e-6));
        assert!(m.transform_vector3(Vec3::Y).abs_diff_eq(Vec3::Y, 1e-6));
    }

    #[test]
    fn look_at_rejects_degenerate_input() {
        assert!(look_at(Vec3::ONE, Vec3::ONE, Vec3::Y).is_none());
        assert!(look_at(Vec3::ZERO, Vec3::Y * 2.0, Vec3::Y).is_none());
    }
}
