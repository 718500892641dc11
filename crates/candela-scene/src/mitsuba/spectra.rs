//! Spectra given as wavelength:value pairs, reduced to linear Rec. 709 RGB exactly as
//! Mitsuba 3's RGB variants reduce them (`spectrum_list_to_srgb` in its `spectrum.cpp`):
//! the piecewise-linear spectrum, zero outside the wavelengths given, times the CIE 1931
//! colour-matching functions (and, for anything but an emitter's colour, the D65
//! illuminant), summed at 1000 points from 360 to 830 nm, scaled by the width of a step
//! and Mitsuba's 1/∫ȳ, then taken from XYZ to Rec. 709 by Mitsuba's matrix. A
//! reflectance-like colour is clamped to [0, 1], any other to ≥ 0.
//!
//! The tables are Mitsuba 3.9.1's own (its `cie1931_xyz` and `cie_d65` at their 5 nm
//! knots, which it interpolates linearly), so the RGB agrees with Mitsuba's to f32
//! round-off (`tests/mitsuba_materials.rs` quotes Mitsuba's numbers).

use glam::{DVec3, Vec3};

/// The first and last wavelength of the tables, and their spacing, in nm.
const CIE_MIN: f64 = 360.0;
const CIE_MAX: f64 = 830.0;
const CIE_STEP: f64 = 5.0;

/// Mitsuba's `MI_CIE_Y_NORMALIZATION`, 1/∫ȳ(λ) dλ over its table.
const CIE_Y_NORMALIZATION: f64 = 0.009_367_658_735_689_113;

/// x̄, ȳ, z̄ and D65 (relative spectral power, 1 at 560 nm) from 360 to 830 nm by 5 nm.
const CIE_XYZ_D65: [[f32; 4]; 95] = [
    [0.0001299, 3.917e-06, 0.0006061, 0.47110626],
    [0.0002321, 6.965e-06, 0.001086, 0.49863625],
    [0.0004149, 1.239e-05, 0.001946, 0.52616626],
    [0.0007416, 2.202e-05, 0.003486, 0.51549125],
    [0.001368, 3.9e-05, 0.006450001, 0.5048162],
    [0.002236, 6.4e-05, 0.01054999, 0.5284158],
    [0.004243, 0.00012, 0.02005001, 0.55201644],
    [0.00765, 0.000217, 0.03621, 0.69397265],
    [0.01431, 0.000396, 0.06785001, 0.8359299],
    [0.02319, 0.00064, 0.1102, 0.880027],
    [0.04351, 0.00121, 0.2074, 0.92412513],
    [0.07763, 0.00218, 0.3713, 0.9339526],
    [0.13438, 0.004, 0.6456, 0.9437802],
    [0.21477, 0.0073, 1.0390501, 0.9096904],
    [0.2839, 0.0116, 1.3856, 0.8756016],
    [0.3285, 0.01684, 1.62296, 0.9674353],
    [0.34828, 0.023, 1.74706, 1.05927],
    [0.34806, 0.0298, 1.7826, 1.1205949],
    [0.3362, 0.038, 1.77211, 1.1819298],
    [0.3187, 0.048, 1.7441, 1.1859906],
    [0.2908, 0.06, 1.6692, 1.1900512],
    [0.2511, 0.0739, 1.5281, 1.1751418],
    [0.19536, 0.09098, 1.28764, 1.1602424],
    [0.1421, 0.1126, 1.0419, 1.1656061],
    [0.09564, 0.13902, 0.8129501, 1.17097],
    [0.05795001, 0.1693, 0.6162, 1.1350498],
    [0.03201, 0.20802, 0.46518, 1.0991297],
    [0.0147, 0.2586, 0.3533, 1.1018672],
    [0.0049, 0.323, 0.272, 1.1046146],
    [0.0024, 0.4073, 0.2123, 1.0967761],
    [0.0093, 0.503, 0.1582, 1.0889375],
    [0.0291, 0.6082, 0.1117, 1.073725],
    [0.06327, 0.71, 0.07824999, 1.0585124],
    [0.1096, 0.7932, 0.05725001, 1.0731492],
    [0.1655, 0.862, 0.04216, 1.0877961],
    [0.2257499, 0.9148501, 0.02984, 1.0712098],
    [0.2904, 0.954, 0.0203, 1.0546235],
    [0.3597, 0.9803, 0.0134, 1.0528052],
    [0.4334499, 0.9949501, 0.008749999, 1.0509971],
    [0.5120501, 1.0, 0.005749999, 1.0305623],
    [0.5945, 0.995, 0.0039, 1.0101273],
    [0.6784, 0.9786, 0.002749999, 0.99161273],
    [0.7621, 0.952, 0.0021, 0.9730981],
    [0.8425, 0.9154, 0.0018, 0.9703394],
    [0.9163, 0.87, 0.001650001, 0.9675808],
    [0.9786, 0.8163, 0.0014, 0.9317092],
    [1.0263, 0.757, 0.0011, 0.89583755],
    [1.0567, 0.6949, 0.001, 0.9025074],
    [1.0622, 0.631, 0.0008, 0.9091773],
    [1.0456, 0.5668, 0.0006, 0.9071206],
    [1.0026, 0.503, 0.00034, 0.905065],
    [0.9384, 0.4412, 0.00024, 0.8954668],
    [0.8544499, 0.381, 0.00019, 0.88586855],
    [0.7514, 0.321, 1.0e-04, 0.86359423],
    [0.6424, 0.265, 4.999999e-05, 0.84132093],
    [0.5419, 0.217, 3.0e-05, 0.8433947],
    [0.4479, 0.175, 2.0e-05, 0.8454686],
    [0.3608, 0.1382, 1.0e-05, 0.82692057],
    [0.2835, 0.107, 0.0, 0.8083726],
    [0.2187, 0.0816, 0.0, 0.8093211],
    [0.1649, 0.061, 0.0, 0.8102696],
    [0.1212, 0.04458, 0.0, 0.8206901],
    [0.0874, 0.032, 0.0, 0.8311106],
    [0.0636, 0.0232, 0.0, 0.8109403],
    [0.04677, 0.017, 0.0, 0.7907702],
    [0.0329, 0.01192, 0.0, 0.7475215],
    [0.0227, 0.00821, 0.0, 0.70427394],
    [0.01584, 0.005723, 0.0, 0.71380854],
    [0.01135916, 0.004102, 0.0, 0.72334313],
    [0.008110916, 0.002929, 0.0, 0.7371808],
    [0.005790346, 0.002091, 0.0, 0.7510196],
    [0.004109457, 0.001484, 0.0, 0.68664926],
    [0.002899327, 0.001047, 0.0, 0.62227887],
    [0.00204919, 0.00074, 0.0, 0.6641062],
    [0.001439971, 0.00052, 0.0, 0.7059336],
    [0.0009999493, 0.0003611, 0.0, 0.7322039],
    [0.0006900786, 0.0002492, 0.0, 0.7584743],
    [0.0004760213, 0.0001719, 0.0, 0.70042026],
    [0.0003323011, 0.00012, 0.0, 0.6423673],
    [0.0002348261, 8.48e-05, 0.0, 0.5556246],
    [0.0001661505, 6.0e-05, 0.0, 0.46888295],
    [0.000117413, 4.24e-05, 0.0, 0.5718513],
    [8.307527e-05, 3.0e-05, 0.0, 0.6748196],
    [5.870652e-05, 2.12e-05, 0.0, 0.65753335],
    [4.150994e-05, 1.499e-05, 0.0, 0.64024705],
    [2.935326e-05, 1.06e-05, 0.0, 0.64489967],
    [2.067383e-05, 7.4657e-06, 0.0, 0.6495523],
    [1.455977e-05, 5.2578e-06, 0.0, 0.6250456],
    [1.025398e-05, 3.7029e-06, 0.0, 0.6005399],
    [7.221456e-06, 2.6078e-06, 0.0, 0.5626955],
    [5.085868e-06, 1.8366e-06, 0.0, 0.5248521],
    [3.581652e-06, 1.2934e-06, 0.0, 0.5525376],
    [2.522525e-06, 9.1093e-07, 0.0, 0.58022326],
    [1.776509e-06, 6.4153e-07, 0.0, 0.59472764],
    [1.251141e-06, 4.5181e-07, 0.0, 0.6092331],
];

/// Mitsuba's XYZ to linear Rec. 709 matrix (its `xyz_to_srgb`), by rows.
const XYZ_TO_REC709: [[f64; 3]; 3] = [
    [3.240479, -1.53715, -0.498535],
    [-0.969256, 1.875991, 0.041556],
    [0.055648, -0.204043, 1.057311],
];

/// How a colour is read, which decides Mitsuba's weighting and clamping.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum SpectrumUse {
    /// A reflectance or transmittance: under D65, clamped to [0, 1].
    Reflectance,
    /// A BSDF parameter with no upper bound (a conductor's η or k): under D65, ≥ 0.
    Unbounded,
    /// An emitter's radiance, intensity or irradiance: no illuminant, ≥ 0.
    Emission,
}

/// (x̄, ȳ, z̄) and D65 at `nm`, linear between the table's knots.
fn cie_at(nm: f64) -> (DVec3, f64) {
    let at = |i: usize| {
        let [x, y, z, d] = CIE_XYZ_D65[i];
        (DVec3::new(x as f64, y as f64, z as f64), d as f64)
    };
    let f = ((nm - CIE_MIN) / CIE_STEP).clamp(0.0, (CIE_XYZ_D65.len() - 1) as f64);
    let i = (f as usize).min(CIE_XYZ_D65.len() - 2);
    let t = f - i as f64;
    let ((x0, d0), (x1, d1)) = (at(i), at(i + 1));
    (x0 * (1.0 - t) + x1 * t, d0 * (1.0 - t) + d1 * t)
}

/// The RGB of the piecewise-linear spectrum through `(wavelength, value)` pairs, whose
/// wavelengths rise strictly (at least two pairs).
pub(crate) fn spectrum_to_rgb(pairs: &[(f64, f64)], use_: SpectrumUse) -> Vec3 {
    debug_assert!(pairs.len() >= 2 && pairs.windows(2).all(|w| w[0].0 < w[1].0));
    const STEPS: usize = 1000;
    let (first, last) = (pairs[0].0, pairs[pairs.len() - 1].0);
    let mut xyz = DVec3::ZERO;
    for i in 0..STEPS {
        let nm = CIE_MIN + i as f64 / (STEPS - 1) as f64 * (CIE_MAX - CIE_MIN);
        if nm < first || nm > last {
            continue;
        }
        let j = pairs
            .partition_point(|p| p.0 <= nm)
            .clamp(1, pairs.len() - 1)
            - 1;
        let ((x0, y0), (x1, y1)) = (pairs[j], pairs[j + 1]);
        let value = y0 + (y1 - y0) * (nm - x0) / (x1 - x0);
        let (cmf, d65) = cie_at(nm);
        let weight = if use_ == SpectrumUse::Emission {
            1.0
        } else {
            d65
        };
        xyz += cmf * weight * value;
    }
    xyz *= (CIE_MAX - CIE_MIN) / STEPS as f64 * CIE_Y_NORMALIZATION;
    let m = XYZ_TO_REC709;
    let rgb = DVec3::new(
        m[0][0] * xyz.x + m[0][1] * xyz.y + m[0][2] * xyz.z,
        m[1][0] * xyz.x + m[1][1] * xyz.y + m[1][2] * xyz.z,
        m[2][0] * xyz.x + m[2][1] * xyz.y + m[2][2] * xyz.z,
    )
    .max(DVec3::ZERO);
    let rgb = match use_ {
        SpectrumUse::Reflectance => rgb.min(DVec3::ONE),
        SpectrumUse::Unbounded | SpectrumUse::Emission => rgb,
    };
    rgb.as_vec3()
}
