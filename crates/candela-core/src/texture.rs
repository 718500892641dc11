//! Textures as render-time data: constants, bilinearly filtered images with wrap modes
//! and a uv transform, and a procedural checker. Images arrive decoded to linear values
//! (the loaders decode sRGB once), so a lookup is pure arithmetic.

use std::sync::Arc;

use glam::{Affine2, Vec2, Vec3};

use crate::desc::{ImageDesc, WrapMode};

/// A value that may vary over a surface (linear).
#[derive(Clone, Debug)]
pub enum Texture {
    Constant(Vec3),
    Image(ImageTexture),
    /// Squares of `a` where ⌊u⌋ + ⌊v⌋ is even, `b` elsewhere, after the transform.
    Checker {
        a: Vec3,
        b: Vec3,
        uv_transform: Affine2,
    },
}

impl Texture {
    #[inline]
    pub fn eval(&self, uv: Vec2) -> Vec3 {
        match self {
            Texture::Constant(c) => *c,
            Texture::Image(t) => t.eval(uv),
            Texture::Checker { a, b, uv_transform } => {
                let p = uv_transform.transform_point2(uv).floor();
                if (p.x + p.y).rem_euclid(2.0) == 0.0 {
                    *a
                } else {
                    *b
                }
            }
        }
    }

    /// The first channel, for scalar parameters (roughness, metallic).
    pub fn eval_scalar(&self, uv: Vec2) -> f32 {
        self.eval(uv).x
    }

    /// The mean over one period of uv: an image's mean texel (its channel and scale
    /// applied), the mean of a checker's two colours.
    pub fn mean(&self) -> Vec3 {
        match self {
            Texture::Constant(c) => *c,
            Texture::Image(t) => {
                let img = &t.image;
                let sum = img
                    .pixels
                    .iter()
                    .fold(glam::DVec3::ZERO, |s, p| s + p.as_dvec3());
                let v = (sum / img.pixels.len().max(1) as f64).as_vec3();
                let v = match t.channel {
                    Some(c) => Vec3::splat(v[c.min(2) as usize]),
                    None => v,
                };
                v * t.scale
            }
            Texture::Checker { a, b, .. } => 0.5 * (*a + *b),
        }
    }

    /// How many lookups a unit of uv area needs to see what the texture holds: an
    /// image's texels, four a checker square, none for a constant (both after the uv
    /// transform's change of area).
    pub fn detail(&self) -> f32 {
        match self {
            Texture::Constant(_) => 0.0,
            Texture::Image(t) => {
                let texels = t.image.width as f32 * t.image.height as f32;
                texels * t.uv_transform.matrix2.determinant().abs()
            }
            Texture::Checker { uv_transform, .. } => 4.0 * uv_transform.matrix2.determinant().abs(),
        }
    }
}

/// An image lookup with bilinear filtering. Texel (i, j) (row j from the top) has its
/// centre at uv ((i + ½)/w, 1 − (j + ½)/h).
#[derive(Clone, Debug)]
pub struct ImageTexture {
    pub image: Arc<ImageDesc>,
    pub wrap: WrapMode,
    pub uv_transform: Affine2,
    pub scale: Vec3,
    pub channel: Option<u8>,
}

/// Brings an integer texel coordinate into [0, n) by the wrap mode.
fn wrap_index(i: i64, n: u32, mode: WrapMode) -> usize {
    let n = n as i64;
    (match mode {
        WrapMode::Repeat => i.rem_euclid(n),
        WrapMode::Clamp => i.clamp(0, n - 1),
        WrapMode::Mirror => {
            let m = i.rem_euclid(2 * n);
            if m < n {
                m
            } else {
                2 * n - 1 - m
            }
        }
    }) as usize
}

impl ImageTexture {
    fn texel(&self, x: i64, y: i64) -> Vec3 {
        let img = &self.image;
        let (i, j) = (
            wrap_index(x, img.width, self.wrap),
            wrap_index(y, img.height, self.wrap),
        );
        img.pixels[j * img.width as usize + i]
    }

    pub fn eval(&self, uv: Vec2) -> Vec3 {
        let img = &self.image;
        if img.width == 0 || img.height == 0 {
            return Vec3::ZERO;
        }
        let uv = self.uv_transform.transform_point2(uv);
        if !uv.is_finite() {
            return Vec3::ZERO;
        }
        let x = uv.x * img.width as f32 - 0.5;
        let y = (1.0 - uv.y) * img.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let top = self.texel(x0, y0).lerp(self.texel(x0 + 1, y0), fx);
        let bottom = self.texel(x0, y0 + 1).lerp(self.texel(x0 + 1, y0 + 1), fx);
        let v = top.lerp(bottom, fy);
        let v = match self.channel {
            Some(c) => Vec3::splat(v[c.min(2) as usize]),
            None => v,
        };
        v * self.scale
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image_2x1() -> ImageTexture {
        ImageTexture {
            image: Arc::new(ImageDesc {
                width: 2,
                height: 1,
                pixels: vec![Vec3::ZERO, Vec3::ONE],
            }),
            wrap: WrapMode::Clamp,
            uv_transform: Affine2::IDENTITY,
            scale: Vec3::ONE,
            channel: None,
        }
    }

    #[test]
    fn bilinear_interpolates_between_texel_centres() {
        let t = image_2x1();
        assert_eq!(t.eval(Vec2::new(0.25, 0.5)), Vec3::ZERO);
        assert_eq!(t.eval(Vec2::new(0.75, 0.5)), Vec3::ONE);
        assert!((t.eval(Vec2::new(0.5, 0.5)).x - 0.5).abs() < 1e-6);
        assert!((t.eval(Vec2::new(0.375, 0.5)).x - 0.25).abs() < 1e-6);
        // Clamp holds the edge texel beyond the image.
        assert_eq!(t.eval(Vec2::new(-3.0, 0.5)), Vec3::ZERO);
        assert_eq!(t.eval(Vec2::new(7.0, 0.5)), Vec3::ONE);
    }

    #[test]
    fn wrap_modes() {
        assert_eq!(wrap_index(-1, 4, WrapMode::Repeat), 3);
        assert_eq!(wrap_index(5, 4, WrapMode::Repeat), 1);
        assert_eq!(wrap_index(-1, 4, WrapMode::Clamp), 0);
        assert_eq!(wrap_index(9, 4, WrapMode::Clamp), 3);
        assert_eq!(wrap_index(-1, 4, WrapMode::Mirror), 0);
        assert_eq!(wrap_index(4, 4, WrapMode::Mirror), 3);
        assert_eq!(wrap_index(5, 4, WrapMode::Mirror), 2);
        assert_eq!(wrap_index(8, 4, WrapMode::Mirror), 0);
        let mut t = image_2x1();
        t.wrap = WrapMode::Repeat;
        // Halfway between the last and (wrapped) first texel centres.
        assert!((t.eval(Vec2::new(1.0, 0.5)).x - 0.5).abs() < 1e-6);
        assert_eq!(t.eval(Vec2::new(1.25, 0.5)), t.eval(Vec2::new(0.25, 0.5)));
    }

    #[test]
    fn transform_scale_and_channel() {
        let mut t = image_2x1();
        t.uv_transform = Affine2::from_translation(Vec2::new(0.5, 0.0));
        assert_eq!(t.eval(Vec2::new(0.25, 0.5)), Vec3::ONE);
        t.scale = Vec3::new(2.0, 3.0, 4.0);
        t.channel = Some(1);
        assert_eq!(t.eval(Vec2::new(0.25, 0.5)), Vec3::new(2.0, 3.0, 4.0));
        let c = Texture::Checker {
            a: Vec3::ZERO,
            b: Vec3::ONE,
            uv_transform: Affine2::from_scale(Vec2::splat(4.0)),
        };
        assert_eq!(c.eval(Vec2::new(0.1, 0.1)), Vec3::ZERO);
        assert_eq!(c.eval(Vec2::new(0.3, 0.1)), Vec3::ONE);
        assert_eq!(c.eval(Vec2::new(0.3, 0.3)), Vec3::ZERO);
        assert_eq!(c.eval(Vec2::new(-0.1, 0.1)), Vec3::ONE);
    }
}
