//! The anisotropic Trowbridge–Reitz (GGX) microfacet distribution with Smith's
//! height-correlated masking-shadowing, sampled through its visible normals.
//!
//! Walter et al. 2007, "Microfacet Models for Refraction through Rough Surfaces"; Heitz
//! 2014, "Understanding the Masking-Shadowing Function in Microfacet-Based BRDFs";
//! Heitz 2018, "Sampling the GGX Distribution of Visible Normals". Same layout as
//! pbrt-v4's `TrowbridgeReitzDistribution` (§9.6).

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

/// GGX with roughness `alpha_x` along the local x axis (the shading frame's tangent) and
/// `alpha_y` along y. Directions are in the local frame (normal +z).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrowbridgeReitz {
    pub alpha_x: f32,
    pub alpha_y: f32,
}

impl TrowbridgeReitz {
    /// Below this α the distribution is treated as a perfect mirror (delta): f32 cannot
    /// resolve the lobe any more.
    pub const SMOOTH_ALPHA: f32 = 1e-3;

    pub fn new(alpha_x: f32, alpha_y: f32) -> Self {
        TrowbridgeReitz { alpha_x, alpha_y }
    }

    /// α from a perceptual roughness r ∈ [0, 1]: α = r² (Burley 2012; glTF 2.0).
    pub fn roughness_to_alpha(r: f32) -> f32 {
        r * r
    }

    pub fn effectively_smooth(&self) -> bool {
        self.alpha_x.max(self.alpha_y) < Self::SMOOTH_ALPHA
    }

    /// Microfacet normal density D(ωm), normalized so ∫D(ωm) cos θm dωm = 1.
    pub fn d(&self, wm: Vec3) -> f32 {
        let (ax, ay) = (self.alpha_x, self.alpha_y);
        let e = (wm.x / ax).powi(2) + (wm.y / ay).powi(2) + wm.z * wm.z;
        if wm.z <= 0.0 || e == 0.0 {
            return 0.0;
        }
        1.0 / (PI * ax * ay * e * e)
    }

    /// Smith's auxiliary function Λ(ω).
    pub fn lambda(&self, w: Vec3) -> f32 {
        if w.z == 0.0 {
            return f32::INFINITY;
        }
        let a2tan2 = ((self.alpha_x * w.x).powi(2) + (self.alpha_y * w.y).powi(2)) / (w.z * w.z);
        0.5 * ((1.0 + a2tan2).sqrt() - 1.0)
    }

    /// Masking of one direction, G₁(ω) = 1/(1 + Λ(ω)).
    pub fn g1(&self, w: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(w))
    }

    /// Height-correlated masking-shadowing G(ωo, ωi) = 1/(1 + Λ(ωo) + Λ(ωi)).
    pub fn g(&self, wo: Vec3, wi: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(wo) + self.lambda(wi))
    }

    /// Density of visible normals from `w`: G₁(ω)/|cos θ| · D(ωm) · |ω·ωm| (Heitz 2014,
    /// eq. 38); back-facing normals are invisible. From below (`w.z < 0`) the surface is
    /// seen mirrored, as [`Self::sample_wm`] samples it: the density is that seen from
    /// −`w`, so a normal is visible where ω·ωm has the sign of cos θ. Integrates to 1
    /// over ωm from either side.
    pub fn d_visible(&self, w: Vec3, wm: Vec3) -> f32 {
        if w.z == 0.0 {
            return 0.0;
        }
        let cos_m = w.dot(wm) * w.z.signum();
        self.g1(w) / w.z.abs() * self.d(wm) * cos_m.max(0.0)
    }

    /// Samples a visible normal seen from `w` (either hemisphere: `w` is mirrored to the
    /// upper one) with density [`Self::d_visible`] (Heitz 2018, listing 1).
    pub fn sample_wm(&self, w: Vec3, u: Vec2) -> Vec3 {
        let mut wh = Vec3::new(self.alpha_x * w.x, self.alpha_y * w.y, w.z).normalize();
        if wh.z < 0.0 {
            wh = -wh;
        }
        let t1 = if wh.z < 0.99999 {
            Vec3::Z.cross(wh).normalize()
        } else {
            Vec3::X
        };
        let t2 = wh.cross(t1);
        let r = u.x.sqrt();
        let phi = 2.0 * PI * u.y;
        let (mut px, mut py) = (r * phi.cos(), r * phi.sin());
        let h = (1.0 - px * px).max(0.0).sqrt();
        let s = 0.5 * (1.0 + wh.z);
        py = (1.0 - s) * h + s * py;
        let pz = (1.0 - px * px - py * py).max(0.0).sqrt();
        px = px.clamp(-1.0, 1.0);
        let nh = px * t1 + py * t2 + pz * wh;
        Vec3::new(self.alpha_x * nh.x, self.alpha_y * nh.y, nh.z.max(1e-6)).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ∫ D(ωm) cos θm dωm = 1 and ∫ D_ω(ωm) dωm = 1, by a midpoint rule in (θ, φ).
    #[test]
    fn distribution_and_visible_normals_are_normalized() {
        for (ax, ay) in [(0.5, 0.5), (0.2, 0.6), (0.05, 0.05)] {
            let m = TrowbridgeReitz::new(ax, ay);
            // From above, and from below (the mirrored view that `sample_wm` samples).
            let (w, w_below) = (
                Vec3::new(0.5, 0.2, 0.6).normalize(),
                Vec3::new(0.5, 0.2, -0.6).normalize(),
            );
            let (nt, np) = (4000, 256);
            let (mut proj, mut vis, mut vis_below) = (0.0f64, 0.0f64, 0.0f64);
            for i in 0..nt {
                let th = (i as f32 + 0.5) / nt as f32 * PI / 2.0;
                for j in 0..np {
                    let ph = (j as f32 + 0.5) / np as f32 * 2.0 * PI;
                    let wm = Vec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos());
                    let dw = (th.sin() * (PI / 2.0 / nt as f32) * (2.0 * PI / np as f32)) as f64;
                    proj += (m.d(wm) * wm.z) as f64 * dw;
                    vis += m.d_visible(w, wm) as f64 * dw;
                    vis_below += m.d_visible(w_below, wm) as f64 * dw;
                }
            }
            assert!((proj - 1.0).abs() < 5e-3, "α=({ax},{ay}): ∫D cos = {proj}");
            assert!((vis - 1.0).abs() < 5e-3, "α=({ax},{ay}): ∫D_ω = {vis}");
            assert!(
                (vis_below - 1.0).abs() < 5e-3,
                "α=({ax},{ay}): ∫D_ω from below = {vis_below}"
            );
        }
    }
}
