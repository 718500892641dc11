//! Display transforms for PNG output: exposure, a tone curve, then the sRGB OETF (or a
//! pure power law). EXR and PFM are written linear and never pass through here.

use candela_core::color::{gamma_encode, srgb_encode, to_u8};
use clap::ValueEnum;
use glam::{Mat3, Vec3};

/// The tone curve that maps scene-referred linear radiance into [0, 1].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum Tonemap {
    /// Clip at 1.
    #[default]
    None,
    /// c/(1 + c) per channel (Reinhard et al. 2002, eq. 3).
    Reinhard,
    /// Narkowicz's 2015 fit of the ACES reference rendering transform.
    Aces,
    /// Sobotka's AgX, in its minimal analytic form (inset matrix, log2 encoding over
    /// [−12.47, 4.03] EV, 6th-order contrast polynomial, outset matrix, γ 2.2 back to
    /// linear), as published with Blender 4's AgX.
    Agx,
}

/// How linear pixels become 8-bit PNG values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DisplayTransform {
    /// Stops; the radiance is multiplied by 2^exposure first.
    pub exposure: f32,
    pub tonemap: Tonemap,
    /// A pure power law 1/γ instead of the sRGB OETF.
    pub gamma: Option<f32>,
}

impl Default for DisplayTransform {
    fn default() -> Self {
        DisplayTransform {
            exposure: 0.0,
            tonemap: Tonemap::None,
            gamma: None,
        }
    }
}

impl DisplayTransform {
    /// The 8-bit encoding of one linear pixel.
    pub fn encode(&self, c: Vec3) -> [u8; 3] {
        let c = c * self.exposure.exp2();
        let c = if c.is_finite() {
            c.max(Vec3::ZERO)
        } else {
            Vec3::ZERO
        };
        let t = match self.tonemap {
            Tonemap::None => c,
            Tonemap::Reinhard => c / (Vec3::ONE + c),
            Tonemap::Aces => aces(c),
            Tonemap::Agx => agx(c),
        };
        t.to_array().map(|v| {
            to_u8(match self.gamma {
                Some(g) => gamma_encode(v, g),
                None => srgb_encode(v),
            })
        })
    }
}

fn aces(x: Vec3) -> Vec3 {
    let (a, b, c, d, e) = (2.51, 0.03, 2.43, 0.59, 0.14);
    ((x * (a * x + b)) / (x * (c * x + d) + e)).clamp(Vec3::ZERO, Vec3::ONE)
}

fn agx(c: Vec3) -> Vec3 {
    const MIN_EV: f32 = -12.473_93;
    const MAX_EV: f32 = 4.026_069;
    let inset = Mat3::from_cols_array(&[
        0.842_479_06,
        0.042_328_24,
        0.042_375_655,
        0.078_433_6,
        0.878_468_6,
        0.078_433_6,
        0.079_223_745,
        0.079_166_13,
        0.879_143,
    ]);
    let outset = Mat3::from_cols_array(&[
        1.196_879,
        -0.052_896_85,
        -0.052_971_635,
        -0.098_020_88,
        1.151_903_1,
        -0.098_043_45,
        -0.099_029_74,
        -0.098_961_18,
        1.151_073_7,
    ]);
    let v = inset * c;
    let v = v.max(Vec3::splat(1e-10)).to_array().map(|x| {
        let x = (x.log2().clamp(MIN_EV, MAX_EV) - MIN_EV) / (MAX_EV - MIN_EV);
        let (x2, x4) = (x * x, x * x * x * x);
        15.5 * x4 * x2 - 40.14 * x4 * x + 31.96 * x4 - 6.868 * x2 * x + 0.4298 * x2 + 0.1191 * x
            - 0.00232
    });
    (outset * Vec3::from_array(v))
        .clamp(Vec3::ZERO, Vec3::ONE)
        .powf(2.2)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn t(tonemap: Tonemap) -> DisplayTransform {
        DisplayTransform {
            tonemap,
            ..Default::default()
        }
    }

    #[test]
    fn linear_half_writes_as_188_and_gamma_2_2_as_186() {
        assert_eq!(t(Tonemap::None).encode(Vec3::splat(0.5)), [188; 3]);
        let g = DisplayTransform {
            gamma: Some(2.2),
            ..Default::default()
        };
        assert_eq!(g.encode(Vec3::splat(0.5)), [186; 3]);
        // One stop of exposure doubles the radiance: 0.25 → 0.5 → 188.
        let e = DisplayTransform {
            exposure: 1.0,
            ..Default::default()
        };
        assert_eq!(e.encode(Vec3::splat(0.25)), [188; 3]);
    }

    #[test]
    fn reinhard_maps_one_to_one_half() {
        assert_eq!(t(Tonemap::Reinhard).encode(Vec3::ONE), [188; 3]);
    }

    #[test]
    fn curves_are_monotone_bounded_and_safe() {
        for tm in [
            Tonemap::None,
            Tonemap::Reinhard,
            Tonemap::Aces,
            Tonemap::Agx,
        ] {
            let tr = t(tm);
            let mut last = 0u8;
            for i in 0..200 {
                let x = 1e-4 * 1.08f32.powi(i);
                let v = tr.encode(Vec3::splat(x))[0];
                assert!(v >= last, "{tm:?} not monotone at {x}");
                last = v;
            }
            assert!(
                tr.encode(Vec3::splat(1e6))[0] >= 250,
                "{tm:?}: bright goes white"
            );
            assert!(tr.encode(Vec3::ZERO)[0] <= 3, "{tm:?}: black stays black");
            assert_eq!(tr.encode(Vec3::NAN), tr.encode(Vec3::ZERO));
            assert_eq!(tr.encode(-Vec3::ONE), tr.encode(Vec3::ZERO));
        }
        // AgX keeps middle grey in the middle.
        let mid = t(Tonemap::Agx).encode(Vec3::splat(0.18))[0];
        assert!((90..170).contains(&mid), "{mid}");
    }
}
