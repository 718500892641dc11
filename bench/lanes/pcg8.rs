//! Cost of drawing one number from each of eight PCG32 streams (the independent
//! sampler's generator, `crates/candela-core/src/sampler/mod.rs`): eight scalar steps
//! against one AVX2 step over the eight streams, whose 64-bit multiply AVX2 lacks and
//! which is put together from three `vpmuludq` (32×32→64) per four lanes. Checks first
//! that both give the same floats bit for bit, then runs one of them N times, for
//! callgrind to count (`pcg8.sh`). Standalone: `rustc -C opt-level=3 pcg8.rs`.
//! Usage: pcg8 N scalar|avx2

use std::arch::x86_64::*;

const MULT: u64 = 0x5851_f42d_4c95_7f2d;

#[derive(Clone, Copy)]
struct Pcg32 {
    state: u64,
    inc: u64,
}

/// `Pcg32::next_u32` of the sampler, unchanged.
#[inline(always)]
fn next_u32(r: &mut Pcg32) -> u32 {
    let old = r.state;
    r.state = old.wrapping_mul(MULT).wrapping_add(r.inc);
    let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
    xorshifted.rotate_right((old >> 59) as u32)
}

/// `uniform_f32` of each stream, one after the other.
#[inline(never)]
fn scalar8(r: &mut [Pcg32; 8], out: &mut [f32; 8]) {
    for i in 0..8 {
        out[i] = (next_u32(&mut r[i]) >> 8) as f32 * (1.0 / (1u32 << 24) as f32);
    }
}

/// Four 64-bit lanes times `MULT`, modulo 2⁶⁴: lo·lo + ((lo·hi + hi·lo) << 32).
#[inline(always)]
unsafe fn mul_mult(a: __m256i) -> __m256i {
    let m_lo = _mm256_set1_epi64x((MULT & 0xffff_ffff) as i64);
    let m_hi = _mm256_set1_epi64x((MULT >> 32) as i64);
    let lo_lo = _mm256_mul_epu32(a, m_lo);
    let cross = _mm256_add_epi64(
        _mm256_mul_epu32(a, m_hi),
        _mm256_mul_epu32(_mm256_srli_epi64(a, 32), m_lo),
    );
    _mm256_add_epi64(lo_lo, _mm256_slli_epi64(cross, 32))
}

/// The same eight draws, streams 0–3 in `state[0]` and 4–7 in `state[1]`.
#[target_feature(enable = "avx2")]
#[inline(never)]
unsafe fn avx2x8(state: &mut [__m256i; 2], inc: &[__m256i; 2], out: &mut [f32; 8]) {
    let mut words = [_mm256_setzero_si256(); 2];
    for h in 0..2 {
        let old = state[h];
        state[h] = _mm256_add_epi64(mul_mult(old), inc[h]);
        let x = _mm256_srli_epi64(_mm256_xor_si256(_mm256_srli_epi64(old, 18), old), 27);
        let x = _mm256_and_si256(x, _mm256_set1_epi64x(0xffff_ffff));
        let rot = _mm256_srli_epi64(old, 59);
        // The 32-bit rotation, in the low word of each 64-bit lane.
        let back = _mm256_sub_epi64(_mm256_set1_epi64x(32), rot);
        words[h] = _mm256_or_si256(_mm256_srlv_epi64(x, rot), _mm256_sllv_epi64(x, back));
    }
    // The low words of both halves into eight u32, streams in order.
    let low = _mm256_setr_epi32(0, 2, 4, 6, 0, 2, 4, 6);
    let u = _mm256_blend_epi32::<0b1111_0000>(
        _mm256_permutevar8x32_epi32(words[0], low),
        _mm256_permutevar8x32_epi32(words[1], low),
    );
    let scale = _mm256_set1_ps(1.0 / (1u32 << 24) as f32);
    let f = _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_srli_epi32(u, 8)), scale);
    _mm256_storeu_ps(out.as_mut_ptr(), f);
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args[1].parse().expect("N");
    assert!(is_x86_feature_detected!("avx2"), "needs AVX2");
    let streams: [Pcg32; 8] = std::array::from_fn(|i| Pcg32 {
        state: 0x1234_5678_9abc_def0 ^ (i as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15),
        inc: ((i as u64) << 1) | 1,
    });
    let pack = |f: fn(&Pcg32) -> u64, h: usize| {
        let v: [u64; 4] = std::array::from_fn(|i| f(&streams[4 * h + i]));
        unsafe { _mm256_loadu_si256(v.as_ptr().cast()) }
    };
    let mut state = [pack(|p| p.state, 0), pack(|p| p.state, 1)];
    let inc = [pack(|p| p.inc, 0), pack(|p| p.inc, 1)];
    let mut scalar = streams;
    let (mut a, mut b) = ([0.0f32; 8], [0.0f32; 8]);
    for _ in 0..10_000 {
        scalar8(&mut scalar, &mut a);
        unsafe { avx2x8(&mut state, &inc, &mut b) };
        assert_eq!(a.map(f32::to_bits), b.map(f32::to_bits), "AVX2 differs");
    }
    let mut sum = 0.0f32;
    for _ in 0..n {
        match args[2].as_str() {
            "scalar" => scalar8(&mut scalar, &mut a),
            _ => unsafe { avx2x8(&mut state, &inc, &mut a) },
        }
        sum += a[3];
    }
    println!("{sum}");
}
