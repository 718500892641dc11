//! The environment light: its description checked and made into the canonical,
//! sampleable form (a constant, an equirectangular map or a cube map).

use glam::Mat3;

use crate::desc::{EnvironmentDesc, EnvironmentMapDesc};
use crate::light::envmap::{Cubemap, Equirect, Image};
use crate::light::{EnvironmentLight, EnvironmentMap};

use super::validate::{check_color, check_finite, check_image, err, BuildError};

/// Validates an environment and makes its canonical, sampleable form.
pub(super) fn build_environment(
    env: &EnvironmentDesc,
    radius: f32,
) -> Result<EnvironmentLight, BuildError> {
    let span = &env.span;
    check_finite(span, "environment strength", &[env.strength])?;
    if env.strength < 0.0 {
        return err(span, "environment strength must not be negative");
    }
    check_color(span, "environment background", env.background)?;
    let r = env.rotation;
    check_finite(span, "environment rotation", &r.to_cols_array())?;
    let off = (r.transpose() * r - Mat3::IDENTITY).abs().to_cols_array();
    if off.iter().any(|&e| e > 1e-3) || r.determinant() < 0.0 {
        return err(
            span,
            "environment rotation must be a rotation (orthonormal, det +1)",
        );
    }
    let map = match &env.map {
        EnvironmentMapDesc::Constant(c) => {
            check_color(span, "environment constant", *c)?;
            EnvironmentMap::Constant(*c)
        }
        EnvironmentMapDesc::Equirect(img) => {
            check_image(span, "environment map", img)?;
            EnvironmentMap::Equirect(Equirect::new(Image::from_desc(img)))
        }
        EnvironmentMapDesc::Cubemap(faces) => {
            let n = faces[0].width;
            for (f, name) in faces.iter().zip(["+x", "-x", "+y", "-y", "+z", "-z"]) {
                let what = format!("cube map face {name}");
                check_image(span, &what, f)?;
                if f.width != n || f.height != n {
                    return err(
                        span,
                        format!(
                            "{what} is {}x{}; faces must be square and all {n}x{n}",
                            f.width, f.height
                        ),
                    );
                }
            }
            EnvironmentMap::Cubemap(Cubemap::new(Box::new(
                faces.each_ref().map(Image::from_desc),
            )))
        }
    };
    let mut light = EnvironmentLight::new(map, env.strength, r, radius);
    light.visible = env.visible;
    light.background = env.background;
    Ok(light)
}
