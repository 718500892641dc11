//! Which compiled copy of the render loop runs: the target's baseline (on x86-64, any
//! x86-64: SSE2) or a second copy compiled for x86-64-v3 (AVX2, FMA, BMI1/2, LZCNT,
//! MOVBE, F16C; Haswell and Zen 1 onwards), chosen once per render by what the CPU has.
//!
//! The v3 copy is the same source compiled under `#[target_feature]`, so only what is
//! inlined into it gets the features; the integrator's hot callees are marked
//! `#[inline]` for that reason. Both copies compute the same numbers bit for bit: Rust
//! never contracts `a * b + c` into an FMA by itself, and neither Candela nor glam calls
//! `mul_add` on the render path, so the features change instruction encodings (VEX,
//! three-operand forms) and integer bit operations, not the arithmetic
//! (`tests/isa.rs` compares the films of both).

use crate::options::Isa;

/// The features of x86-64-v3 beyond the x86-64 baseline, as `#[target_feature]` and
/// `is_x86_feature_detected!` spell them (rustc's `--print cfg -C
/// target-cpu=x86-64-v3`). [`crate::integrator`]'s `#[target_feature]` list is the same.
#[cfg(target_arch = "x86_64")]
macro_rules! v3_detected {
    () => {
        std::arch::is_x86_feature_detected!("avx")
            && std::arch::is_x86_feature_detected!("avx2")
            && std::arch::is_x86_feature_detected!("bmi1")
            && std::arch::is_x86_feature_detected!("bmi2")
            && std::arch::is_x86_feature_detected!("cmpxchg16b")
            && std::arch::is_x86_feature_detected!("f16c")
            && std::arch::is_x86_feature_detected!("fma")
            && std::arch::is_x86_feature_detected!("lzcnt")
            && std::arch::is_x86_feature_detected!("movbe")
            && std::arch::is_x86_feature_detected!("popcnt")
            && std::arch::is_x86_feature_detected!("sse3")
            && std::arch::is_x86_feature_detected!("sse4.1")
            && std::arch::is_x86_feature_detected!("sse4.2")
            && std::arch::is_x86_feature_detected!("ssse3")
            && std::arch::is_x86_feature_detected!("xsave")
    };
}

impl Isa {
    /// The fastest copy this CPU runs (`is_x86_feature_detected!` caches its answers;
    /// this is asked once per render).
    pub fn best() -> Isa {
        if Isa::V3.is_supported() {
            Isa::V3
        } else {
            Isa::Baseline
        }
    }

    /// What `self` means on this CPU: [`Isa::Auto`] becomes [`Isa::best`], the others
    /// stay.
    pub fn resolve(self) -> Isa {
        match self {
            Isa::Auto => Isa::best(),
            isa => isa,
        }
    }

    /// Whether this CPU can run `self`.
    pub fn is_supported(self) -> bool {
        match self {
            Isa::Auto | Isa::Baseline => true,
            #[cfg(target_arch = "x86_64")]
            Isa::V3 => v3_detected!(),
            #[cfg(not(target_arch = "x86_64"))]
            Isa::V3 => false,
        }
    }

    /// Every copy this CPU can run, baseline first.
    pub fn available() -> Vec<Isa> {
        [Isa::Baseline, Isa::V3]
            .into_iter()
            .filter(|i| i.is_supported())
            .collect()
    }
}
