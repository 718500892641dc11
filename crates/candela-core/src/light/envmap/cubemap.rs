//! The cube map: six square faces, looked up by direction alone.
//!
//! Face convention (the OpenGL / Direct3D table, so that files named `+x … −z` for those
//! APIs load as they are). For direction d the face is the axis of largest |component|
//! (ties go to x, then y); with `m` that component's magnitude, the face image is read at
//! column `s = (sc/m + 1)/2` (left to right) and row `t = (tc/m + 1)/2` (top to bottom):
//!
//! | index | face | sc  | tc  |
//! |-------|------|-----|-----|
//! | 0     | +x   | −z  | −y  |
//! | 1     | −x   | +z  | −y  |
//! | 2     | +y   | +x  | +z  |
//! | 3     | −y   | +x  | −z  |
//! | 4     | +z   | +x  | −y  |
//! | 5     | −z   | −x  | −y  |
//!
//! This table comes from a left-handed world, so in Candela's right-handed frame each
//! face appears mirrored left-right when seen from the cube's centre; the faces still
//! meet seamlessly. Bilinear filtering clamps at face edges (no filtering across faces).
//!
//! Sampling works on the faces directly: face `f` is chosen in proportion to its share
//! of the importance, then a point of it by a bilinear density through its texel centres
//! and edges ([`Bilinear2D`]), weighted by the luminance above half the map's mean
//! (`compensated`) times the solid angle, dω = 4 (1 + a² + b²)^(−3/2) ds dt with
//! a = 2s − 1, b = 2t − 1.

use glam::{Vec2, Vec3};

use super::bilinear::{Bilinear2D, GridAxis};
use super::{compensated, Image, MapSample};
use crate::math::luminance;
use crate::sampling::Distribution1D;

/// Six equal square faces in the order +x, −x, +y, −y, +z, −z.
#[derive(Clone, Debug)]
pub struct Cubemap {
    pub faces: Box<[Image; 6]>,
    /// Per face, boxed to keep [`crate::light::Light`] small.
    distributions: Box<[Bilinear2D; 6]>,
    face_distribution: Distribution1D,
}

/// dω / (ds dt) at face coordinates `st ∈ [0,1]²`.
fn solid_angle_jacobian(st: Vec2) -> f32 {
    let ab = 2.0 * st - Vec2::ONE;
    4.0 * (1.0 + ab.length_squared()).powf(-1.5)
}

/// The face index and face coordinates `st ∈ [0,1]²` of a non-zero direction.
pub fn direction_to_face(d: Vec3) -> (usize, Vec2) {
    let a = d.abs();
    let (face, m, sc, tc) = if a.x >= a.y && a.x >= a.z {
        if d.x > 0.0 {
            (0, a.x, -d.z, -d.y)
        } else {
            (1, a.x, d.z, -d.y)
        }
    } else if a.y >= a.z {
        if d.y > 0.0 {
            (2, a.y, d.x, d.z)
        } else {
            (3, a.y, d.x, -d.z)
        }
    } else if d.z > 0.0 {
        (4, a.z, d.x, -d.y)
    } else {
        (5, a.z, -d.x, -d.y)
    };
    let st = (Vec2::new(sc, tc) / m + Vec2::ONE) * 0.5;
    (face, st.clamp(Vec2::ZERO, Vec2::ONE))
}

/// The unit direction through face coordinates `st` of face `face`; inverse of
/// [`direction_to_face`].
pub fn face_to_direction(face: usize, st: Vec2) -> Vec3 {
    let a = 2.0 * st.x - 1.0;
    let b = 2.0 * st.y - 1.0;
    let d = match face {
        0 => Vec3::new(1.0, -b, -a),
        1 => Vec3::new(-1.0, -b, a),
        2 => Vec3::new(a, 1.0, b),
        3 => Vec3::new(a, -1.0, -b),
        4 => Vec3::new(a, -b, 1.0),
        _ => Vec3::new(-a, -b, -1.0),
    };
    d.normalize()
}

impl Cubemap {
    /// The faces must be square and of equal size (the build checks).
    pub fn new(faces: Box<[Image; 6]>) -> Cubemap {
        let n = faces[0].width;
        let axis = GridAxis::Centred(n);
        // The mean luminance over the sphere, texels weighted by their solid angle.
        let (mut light, mut area) = (0.0f64, 0.0f64);
        for img in faces.iter() {
            for (i, &l) in img.pixels.iter().enumerate() {
                let st = Vec2::new(
                    ((i % n) as f32 + 0.5) / n as f32,
                    ((i / n) as f32 + 0.5) / n as f32,
                );
                let a = solid_angle_jacobian(st) as f64;
                light += luminance(l).max(0.0) as f64 * a;
                area += a;
            }
        }
        let mean = (light / area) as f32;
        let distributions = Box::new(faces.each_ref().map(|img| {
            let texel = |k: usize| k.saturating_sub(1).min(n - 1);
            let mut values = Vec::with_capacity(axis.vertices() * axis.vertices());
            for j in 0..axis.vertices() {
                for k in 0..axis.vertices() {
                    let st = Vec2::new(axis.position(k), axis.position(j));
                    let l = luminance(img.pixels[texel(j) * n + texel(k)]);
                    values.push(compensated(l, mean) * solid_angle_jacobian(st));
                }
            }
            Bilinear2D::new(values, axis, axis)
        }));
        let weights = distributions.each_ref().map(|d| d.integral());
        Cubemap {
            faces,
            distributions,
            face_distribution: Distribution1D::new(&weights),
        }
    }

    /// Bilinearly filtered radiance towards direction `d`.
    pub fn eval(&self, d: Vec3) -> Vec3 {
        let (f, st) = direction_to_face(d);
        self.faces[f].bilinear(st, false)
    }

    /// A direction drawn in proportion to the importance, with its solid-angle density.
    pub fn sample(&self, u: Vec2) -> Option<MapSample> {
        let (x, pdf_face, face) = self.face_distribution.sample_continuous(u.x);
        // Reuse the remainder of u.x within the chosen face's cell.
        let ux = (x * 6.0 - face as f32).clamp(0.0, crate::sampling::ONE_MINUS_EPSILON);
        let (st, pdf_st) = self.distributions[face].sample(Vec2::new(ux, u.y))?;
        let pdf = pdf_face / 6.0 * pdf_st / solid_angle_jacobian(st);
        (pdf > 0.0).then(|| MapSample {
            dir: face_to_direction(face, st),
            pdf,
            radiance: self.faces[face].bilinear(st, false),
        })
    }

    /// Solid-angle density of [`Self::sample`] towards direction `d`.
    pub fn pdf(&self, d: Vec3) -> f32 {
        let (f, st) = direction_to_face(d);
        self.pdf_on_face(f, st)
    }

    /// The radiance towards direction `d` and the solid-angle density with which
    /// [`Self::sample`] draws `d`: [`Self::eval`] and [`Self::pdf`] from one face lookup.
    pub fn eval_pdf(&self, d: Vec3) -> (Vec3, f32) {
        let (f, st) = direction_to_face(d);
        (self.faces[f].bilinear(st, false), self.pdf_on_face(f, st))
    }

    /// Solid-angle density of [`Self::sample`] at coordinates `st` of face `f`.
    fn pdf_on_face(&self, f: usize, st: Vec2) -> f32 {
        let pmf = self.face_distribution.pdf((f as f32 + 0.5) / 6.0) / 6.0;
        pmf * self.distributions[f].pdf(st) / solid_angle_jacobian(st)
    }

    /// Each texel's direction (its centre), luminance × solid angle, and solid angle.
    pub fn luminance_patches(&self) -> impl Iterator<Item = (Vec3, f32, f32)> + Clone + '_ {
        self.faces.iter().enumerate().flat_map(|(f, img)| {
            let n = img.width;
            img.pixels.iter().enumerate().map(move |(i, &l)| {
                let st = Vec2::new(
                    ((i % n) as f32 + 0.5) / n as f32,
                    ((i / n) as f32 + 0.5) / n as f32,
                );
                let area = solid_angle_jacobian(st) / (n * n) as f32;
                (face_to_direction(f, st), luminance(l).max(0.0) * area, area)
            })
        })
    }

    /// ∫ luminance(L) dω, by the midpoint rule over the texels.
    pub fn luminance_integral(&self) -> f32 {
        self.luminance_patches()
            .map(|(_, w, _)| w as f64)
            .sum::<f64>() as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn face_table_round_trips_and_axes_land_on_face_centres() {
        let axes = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
        for (f, axis) in axes.iter().enumerate() {
            let (face, st) = direction_to_face(*axis);
            assert_eq!(face, f);
            assert!((st - Vec2::splat(0.5)).length() < 1e-6);
            for i in 0..20 {
                let st = Vec2::new((i as f32 * 0.618).fract(), (i as f32 * 0.414).fract());
                let st = 0.02 + 0.96 * st; // away from the edges, where faces tie
                let (face2, st2) = direction_to_face(face_to_direction(f, st));
                assert_eq!(face2, f);
                assert!((st2 - st).length() < 1e-5);
            }
        }
        // The top row of the side faces looks up (+y), the top row of +y looks to −z.
        assert!(face_to_direction(0, Vec2::new(0.5, 0.0)).y > 0.7);
        assert!(face_to_direction(2, Vec2::new(0.5, 0.0)).z < -0.7);
        // +z face: column s grows with +x; −z face: with −x; +x face: with −z.
        assert!(face_to_direction(4, Vec2::new(1.0, 0.5)).x > 0.7);
        assert!(face_to_direction(5, Vec2::new(1.0, 0.5)).x < -0.7);
        assert!(face_to_direction(0, Vec2::new(1.0, 0.5)).z < -0.7);
    }
}
