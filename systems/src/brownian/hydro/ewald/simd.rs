//! The widest vector instruction set of the processor for the multiversioned kernels
//! (spreading and gathering in `wave`): each kernel body is compiled once per level from the
//! same source, with no contraction to FMA unless written as `mul_add`, so every level gives
//! bitwise the same result.

/// Vector instruction set level, detected at run time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Simd {
    /// baseline (SSE2 on x86-64)
    Plain,
    /// AVX2 and FMA
    Avx2,
    /// AVX-512 F, DQ and VL (with AVX2 and FMA)
    Avx512,
}

impl Simd {
    /// The widest level this processor supports.
    pub fn detect() -> Self {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::is_x86_feature_detected as has;
            if has!("avx2") && has!("fma") {
                if has!("avx512f") && has!("avx512dq") && has!("avx512vl") {
                    return Self::Avx512;
                }
                return Self::Avx2;
            }
        }
        Self::Plain
    }
}
