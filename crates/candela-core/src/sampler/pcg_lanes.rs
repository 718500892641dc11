//! PCG32 for eight streams at once in AVX2: the independent sampler's batched draw
//! ([`super::Sampler::draw_bounce_lanes`]). AVX2 has no 64-bit multiply; the LCG step's
//! product modulo 2⁶⁴ is put together from three 32×32→64 multiplies (`vpmuludq`) per four
//! streams. Each stream gives bit for bit what [`super::Pcg32::uniform_f32`] gives
//! (`bench/lanes/pcg8.sh`: 60 instructions for one number of eight streams, against 146
//! for eight scalar steps).

use std::arch::x86_64::*;

use super::{IndependentSampler, Pcg32, LANES};

/// The next `N` numbers of each of eight streams: `out[k][i]` is the `k`-th of stream `i`,
/// what its `uniform_f32` gives on the `k`-th call from here; the streams move on by `N`.
/// Besides, each stream's state before its step `keep` (a deferred request's, see
/// [`super::Pcg32::step`]).
///
/// # Safety
/// The CPU must have AVX2.
#[target_feature(enable = "avx2")]
pub(super) unsafe fn uniform_lanes<const N: usize>(
    streams: &mut [IndependentSampler; LANES],
    keep: usize,
) -> ([[f32; LANES]; N], [u64; LANES]) {
    let mut state = [
        gather(streams, 0, |r| r.state),
        gather(streams, 4, |r| r.state),
    ];
    let inc = [gather(streams, 0, |r| r.inc), gather(streams, 4, |r| r.inc)];
    let mut out = [[0.0; LANES]; N];
    let mut kept = [0u64; LANES];
    for (k, numbers) in out.iter_mut().enumerate() {
        if k == keep {
            _mm256_storeu_si256(kept.as_mut_ptr().cast(), state[0]);
            _mm256_storeu_si256(kept[4..].as_mut_ptr().cast(), state[1]);
        }
        let words = [step(&mut state[0], inc[0]), step(&mut state[1], inc[1])];
        *numbers = to_uniform(words);
    }
    for (h, lanes) in state.iter().enumerate() {
        let mut s = [0u64; 4];
        _mm256_storeu_si256(s.as_mut_ptr().cast(), *lanes);
        for (i, s) in s.into_iter().enumerate() {
            streams[4 * h + i].rng.state = s;
        }
    }
    (out, kept)
}

/// One field of streams `first..first + 4`, one stream a 64-bit lane.
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn gather(
    streams: &[IndependentSampler; LANES],
    first: usize,
    field: fn(&Pcg32) -> u64,
) -> __m256i {
    let v: [u64; 4] = std::array::from_fn(|i| field(&streams[first + i].rng));
    _mm256_loadu_si256(v.as_ptr().cast())
}

/// `Pcg32::next_u32` of four streams: advances `state` and returns the outputs in the low
/// word of each 64-bit lane.
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn step(state: &mut __m256i, inc: __m256i) -> __m256i {
    let old = *state;
    *state = _mm256_add_epi64(mul_mult(old), inc);
    let x = _mm256_srli_epi64::<27>(_mm256_xor_si256(_mm256_srli_epi64::<18>(old), old));
    let x = _mm256_and_si256(x, _mm256_set1_epi64x(0xffff_ffff));
    let rot = _mm256_srli_epi64::<59>(old);
    // The 32-bit rotation right by `rot`, in the low word of each 64-bit lane.
    let back = _mm256_sub_epi64(_mm256_set1_epi64x(32), rot);
    _mm256_or_si256(_mm256_srlv_epi64(x, rot), _mm256_sllv_epi64(x, back))
}

/// Four 64-bit lanes times `Pcg32::MULT`, modulo 2⁶⁴: lo·lo + ((lo·hi + hi·lo) << 32).
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn mul_mult(a: __m256i) -> __m256i {
    let m_lo = _mm256_set1_epi64x((Pcg32::MULT & 0xffff_ffff) as i64);
    let m_hi = _mm256_set1_epi64x((Pcg32::MULT >> 32) as i64);
    let lo_lo = _mm256_mul_epu32(a, m_lo);
    let cross = _mm256_add_epi64(
        _mm256_mul_epu32(a, m_hi),
        _mm256_mul_epu32(_mm256_srli_epi64::<32>(a), m_lo),
    );
    _mm256_add_epi64(lo_lo, _mm256_slli_epi64::<32>(cross))
}

/// `uniform_f32` of the outputs of streams 0–3 (`words[0]`) and 4–7 (`words[1]`).
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn to_uniform(words: [__m256i; 2]) -> [f32; LANES] {
    let low = _mm256_setr_epi32(0, 2, 4, 6, 0, 2, 4, 6);
    let u = _mm256_blend_epi32::<0b1111_0000>(
        _mm256_permutevar8x32_epi32(words[0], low),
        _mm256_permutevar8x32_epi32(words[1], low),
    );
    let scale = _mm256_set1_ps(1.0 / (1u32 << 24) as f32);
    let f = _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_srli_epi32::<8>(u)), scale);
    let mut out = [0.0; LANES];
    _mm256_storeu_ps(out.as_mut_ptr(), f);
    out
}

#[cfg(test)]
mod tests {
    use glam::UVec2;

    use super::*;
    use crate::sampler::Sampler;

    /// Every stream's numbers equal its scalar draws bit for bit, over streams started at
    /// different pixels and samples (different states and increments) and many steps.
    #[test]
    fn lanes_equal_the_scalar_streams() {
        if !is_x86_feature_detected!("avx2") {
            return;
        }
        let mut lanes: [IndependentSampler; LANES] =
            std::array::from_fn(|_| IndependentSampler::new(11));
        for (i, s) in lanes.iter_mut().enumerate() {
            s.start_pixel_sample(UVec2::new(3 * i as u32, 7), i as u32 * 5);
        }
        let mut scalar = lanes.clone();
        for _ in 0..500 {
            // SAFETY: AVX2 checked above.
            let (got, kept) = unsafe { uniform_lanes::<7>(&mut lanes, 3) };
            for (k, numbers) in got.iter().enumerate() {
                for (i, stream) in scalar.iter_mut().enumerate() {
                    if k == 3 {
                        assert_eq!(stream.rng.state, kept[i], "kept state, stream {i}");
                    }
                    let want = stream.get_1d();
                    assert_eq!(
                        numbers[i].to_bits(),
                        want.to_bits(),
                        "number {k}, stream {i}"
                    );
                }
            }
        }
        assert_eq!(lanes[5].get_1d(), scalar[5].get_1d());
    }
}
