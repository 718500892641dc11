//! `<transform>`: a sequence of steps, each applied after (left-multiplied onto) the ones
//! before it, as in Mitsuba.

use candela_core::math::Frame;
use glam::{Mat3, Mat4, Vec3};

use super::parse::Node;
use crate::LoadError;

/// The matrix of a `<transform>` element.
pub(crate) fn transform(node: &Node) -> Result<Mat4, LoadError> {
    let mut m = Mat4::IDENTITY;
    for step in &node.children {
        m = step_matrix(step)? * m;
    }
    Ok(m)
}

fn step_matrix(s: &Node) -> Result<Mat4, LoadError> {
    Ok(match s.tag.as_str() {
        "translate" => Mat4::from_translation(s.xyz(0.0)?),
        "scale" => {
            let v = match s.attr("value") {
                Some(v) => s.parse_vec3(v, true)?,
                None => s.xyz(1.0)?,
            };
            Mat4::from_scale(v)
        }
        "rotate" => {
            let axis = s.xyz(0.0)?;
            let angle = s.parse_f32(s.req("angle")?)?;
            if axis.length_squared() == 0.0 {
                return Err(s.error("rotation axis is zero"));
            }
            Mat4::from_mat3(rotation(axis, angle.to_radians()))
        }
        "matrix" => {
            let v = s.parse_list(s.req("value")?)?;
            // Row-major in the file.
            match v.len() {
                16 => Mat4::from_cols_array(&v.try_into().expect("16 values")).transpose(),
                9 => Mat4::from_mat3(
                    Mat3::from_cols_array(&v.try_into().expect("9 values")).transpose(),
                ),
                n => return Err(s.error(format!("a matrix needs 16 (or 9) values, not {n}"))),
            }
        }
        "lookat" => {
            let vec = |a: &str| s.parse_vec3(s.req(a)?, false);
            let (origin, target) = (vec("origin")?, vec("target")?);
            // Without `up`, Mitsuba's parser takes the first axis of its
            // `coordinate_system` around the view direction (Duff et al. 2017), which is
            // `Frame::from_z`'s `s`; a lookat without `up` then rolls the camera.
            let up = match s.attr("up") {
                Some(u) => s.parse_vec3(u, false)?,
                None => Frame::from_z((target - origin).normalize_or_zero()).s,
            };
            look_at(origin, target, up).ok_or_else(|| {
                s.error("lookat: origin and target coincide, or up is parallel to the view")
            })?
        }
        other => {
            return Err(s.error(format!(
                "unknown transform step <{other}> (translate, rotate, scale, matrix, lookat)"
            )))
        }
    })
}

/// Rodrigues' formula c·I + s·[k]× + (1 − c)·k·kᵀ exactly as Mitsuba evaluates it: with
/// the axis as given, **not** normalized (so an axis of length ≠ 1 also scales and
/// shears, and Candela puts the shape where Mitsuba does).
fn rotation(k: Vec3, angle: f32) -> Mat3 {
    let (s, c) = angle.sin_cos();
    let cross = Mat3::from_cols(
        Vec3::new(0.0, k.z, -k.y),
        Vec3::new(-k.z, 0.0, k.x),
        Vec3::new(k.y, -k.x, 0.0),
    );
    let outer = Mat3::from_cols(k * k.x, k * k.y, k * k.z);
    Mat3::IDENTITY * c + cross * s + outer * (1.0 - c)
}

/// Mitsuba's `Transform4f::look_at` is the TOML format's `look_at` step: the frame's +z
/// looks at the target, +y is up and +x is up × forward (the image's left, as Mitsuba's
/// cameras see it).
pub(crate) use crate::toml::shape::look_at;
