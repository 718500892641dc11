//! Colour encodings. Candela computes in linear light; images are encoded only on the way
//! out (and decoded once on the way in).

/// The sRGB opto-electronic transfer function (IEC 61966-2-1): linear → encoded, in [0, 1].
pub fn srgb_encode(linear: f32) -> f32 {
    if linear <= 0.003_130_8 {
        12.92 * linear.max(0.0)
    } else {
        1.055 * linear.min(1.0).powf(1.0 / 2.4) - 0.055
    }
}

/// The inverse of [`srgb_encode`]: encoded → linear.
pub fn srgb_decode(encoded: f32) -> f32 {
    if encoded <= 0.040_45 {
        encoded / 12.92
    } else {
        ((encoded + 0.055) / 1.055).powf(2.4)
    }
}

/// A pure power-law encoding, e.g. γ = 2.2.
pub fn gamma_encode(linear: f32, gamma: f32) -> f32 {
    linear.clamp(0.0, 1.0).powf(1.0 / gamma)
}

/// Quantizes an encoded value in [0, 1] to 8 bits, rounding to nearest.
pub fn to_u8(encoded: f32) -> u8 {
    (encoded.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_values() {
        // 8-bit 128 is 0.2158 linear; linear 0.5 encodes to 188.
        assert!((srgb_decode(128.0 / 255.0) - 0.2158).abs() < 1e-4);
        assert_eq!(to_u8(srgb_encode(0.5)), 188);
        assert_eq!(to_u8(srgb_encode(0.0)), 0);
        assert_eq!(to_u8(srgb_encode(1.0)), 255);
        assert_eq!(to_u8(srgb_encode(7.0)), 255);
    }

    #[test]
    fn round_trip_of_all_8_bit_values_is_exact() {
        for v in 0..=255u8 {
            assert_eq!(to_u8(srgb_encode(srgb_decode(v as f32 / 255.0))), v);
        }
    }
}
