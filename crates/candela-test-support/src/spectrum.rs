//! How blue an image's error is: its power spectrum, radially averaged. White noise (the
//! error of pixels estimated independently) has the same expected power at every spatial
//! frequency; blue noise has little at low frequencies, which is what the eye, HDR-FLIP and
//! a denoiser forgive (Ahmed and Wonka 2020; Heitz and Belcour 2019).

use std::f64::consts::TAU;

/// |DFT|² of an `n` × `n` image (row major), by a separable O(n³) transform (test sizes
/// only), divided by n² so that white noise of variance σ² has expected power σ² at
/// every frequency.
pub fn power_spectrum(img: &[f64], n: usize) -> Vec<f64> {
    assert_eq!(img.len(), n * n);
    let twiddle: Vec<(f64, f64)> = (0..n)
        .map(|k| {
            let a = -TAU * k as f64 / n as f64;
            (a.cos(), a.sin())
        })
        .collect();
    let dft_row = |re: &[f64], im: &[f64], out_re: &mut [f64], out_im: &mut [f64]| {
        for k in 0..n {
            let (mut sr, mut si) = (0.0, 0.0);
            for j in 0..n {
                let (c, s) = twiddle[(j * k) % n];
                sr += re[j] * c - im[j] * s;
                si += re[j] * s + im[j] * c;
            }
            (out_re[k], out_im[k]) = (sr, si);
        }
    };
    // Rows, then columns.
    let (mut re, mut im) = (vec![0.0; n * n], vec![0.0; n * n]);
    let zeros = vec![0.0; n];
    for y in 0..n {
        let (r, i) = (&mut re[y * n..(y + 1) * n], &mut im[y * n..(y + 1) * n]);
        dft_row(&img[y * n..(y + 1) * n], &zeros, r, i);
    }
    let mut power = vec![0.0; n * n];
    let (mut col_re, mut col_im) = (vec![0.0; n], vec![0.0; n]);
    let (mut out_re, mut out_im) = (vec![0.0; n], vec![0.0; n]);
    for x in 0..n {
        for y in 0..n {
            (col_re[y], col_im[y]) = (re[y * n + x], im[y * n + x]);
        }
        dft_row(&col_re, &col_im, &mut out_re, &mut out_im);
        for y in 0..n {
            power[y * n + x] = (out_re[y].powi(2) + out_im[y].powi(2)) / (n * n) as f64;
        }
    }
    power
}

/// The mean power of `img`'s spectrum at frequencies 0 < |f| ≤ `cutoff` (in cycles per
/// pixel, at most 0.5) divided by its mean power at every frequency but 0: about 1 for
/// white noise, well below 1 for blue noise.
pub fn low_frequency_power_ratio(img: &[f64], n: usize, cutoff: f64) -> f64 {
    let power = power_spectrum(img, n);
    let signed = |k: usize| {
        if k <= n / 2 {
            k as f64
        } else {
            k as f64 - n as f64
        }
    };
    let (mut low, mut low_count, mut all) = (0.0, 0usize, 0.0);
    for y in 0..n {
        for x in 0..n {
            if x == 0 && y == 0 {
                continue;
            }
            let f = (signed(x).powi(2) + signed(y).powi(2)).sqrt() / n as f64;
            if f <= cutoff {
                low += power[y * n + x];
                low_count += 1;
            }
            all += power[y * n + x];
        }
    }
    (low / low_count as f64) / (all / (n * n - 1) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use candela_core::sampler::Pcg32;

    #[test]
    fn a_sine_puts_its_power_at_its_frequency() {
        let n = 16;
        let img: Vec<f64> = (0..n * n)
            .map(|i| (TAU * 3.0 * (i % n) as f64 / n as f64).cos())
            .collect();
        let p = power_spectrum(&img, n);
        // With the 1/n² normalization the powers sum to Σ img² (Parseval), all of it at
        // the frequencies (±3, 0).
        let total: f64 = p.iter().sum();
        let energy: f64 = img.iter().map(|v| v * v).sum();
        assert!((total - energy).abs() < 1e-9 * energy, "Parseval");
        assert!((p[3] + p[13] - energy).abs() < 1e-9 * energy, "all at ±3");
    }

    #[test]
    fn white_noise_has_a_flat_spectrum_and_a_smoothed_one_does_not() {
        // White noise: ratio 1 ± 0.1 (about 100 independent exponential powers below the
        // cutoff 1/8 on 64²: relative spread 0.1; the bound is 3.5 of those). Its
        // difference with a neighbour (a high-pass, blue) is far below; its box-blur
        // (low-pass, red) far above.
        let n = 64;
        let mut rng = Pcg32::new(1, 2);
        let white: Vec<f64> = (0..n * n).map(|_| rng.uniform_f32() as f64 - 0.5).collect();
        let r = low_frequency_power_ratio(&white, n, 0.125);
        assert!((r - 1.0).abs() < 0.35, "white {r}");
        let at = |x: usize, y: usize| white[(y % n) * n + x % n];
        let blue: Vec<f64> = (0..n * n)
            .map(|i| at(i % n, i / n) - at(i % n + 1, i / n))
            .collect();
        let r = low_frequency_power_ratio(&blue, n, 0.125);
        assert!(r < 0.2, "high-passed {r}");
        let red: Vec<f64> = (0..n * n)
            .map(|i| at(i % n, i / n) + at(i % n + 1, i / n))
            .collect();
        let r = low_frequency_power_ratio(&red, n, 0.125);
        assert!(r > 1.5, "low-passed {r}");
    }
}
