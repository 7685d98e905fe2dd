//! Flush denormals to zero while audio is processed.
//!
//! Resonator tails decay towards zero; on x86 a denormal operand costs a hundred cycles or more.
//! Truncation normally removes a mode long before that, but an input-driven voice or a threshold
//! of -140 dB must not stall either.

/// Sets the FTZ and DAZ bits of the SSE control register for its lifetime, restoring the previous
/// value on drop.
pub struct FlushDenormals {
    /// The control register value to restore.
    #[cfg(target_arch = "x86_64")]
    previous: u32,
}

#[cfg(target_arch = "x86_64")]
impl FlushDenormals {
    /// Flush-to-zero (bit 15) and denormals-are-zero (bit 6) of MXCSR.
    const FTZ_DAZ: u32 = (1 << 15) | (1 << 6);

    /// Enables flushing until the guard is dropped.
    #[inline]
    pub fn new() -> Self {
        let mut previous: u32 = 0;
        // SAFETY: stmxcsr/ldmxcsr read and write the SSE control register of this thread only;
        // x86_64 always has SSE.
        unsafe {
            std::arch::asm!("stmxcsr [{}]", in(reg) &mut previous, options(nostack, preserves_flags));
            let wanted = previous | Self::FTZ_DAZ;
            std::arch::asm!("ldmxcsr [{}]", in(reg) &wanted, options(nostack, preserves_flags));
        }
        Self { previous }
    }
}

#[cfg(target_arch = "x86_64")]
impl Drop for FlushDenormals {
    fn drop(&mut self) {
        // SAFETY: restores the value read in `new`.
        unsafe {
            std::arch::asm!("ldmxcsr [{}]", in(reg) &self.previous, options(nostack, preserves_flags));
        }
    }
}

#[cfg(not(target_arch = "x86_64"))]
impl FlushDenormals {
    /// Other architectures: no-op (aarch64 flushes by FPCR, left at its default).
    #[inline]
    pub fn new() -> Self {
        Self {}
    }
}

impl Default for FlushDenormals {
    fn default() -> Self {
        Self::new()
    }
}

/// Sets every subnormal sample of `x` to zero. The engine flushes its own arithmetic, but a
/// plugin's output must hold none whatever the host feeds it: the plugins after it may not
/// flush, and a dry path copies its input.
pub fn flush_subnormals(x: &mut [f32]) {
    for v in x {
        // Branch-free, so it vectorises; zero, normal, infinite and not-a-number samples stay.
        *v = if v.abs() < f32::MIN_POSITIVE { 0.0 } else { *v };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn subnormal_samples_become_zero_and_the_rest_stay() {
        let tiny = f32::MIN_POSITIVE;
        let mut x = [
            tiny / 2.0,
            -tiny / 3.0,
            f32::from_bits(1),
            tiny,
            -tiny,
            0.5,
            -0.0,
            f32::INFINITY,
        ];
        flush_subnormals(&mut x);
        assert_eq!(&x[..3], &[0.0, 0.0, 0.0]);
        assert_eq!(&x[3..6], &[tiny, -tiny, 0.5]);
        assert_eq!(x[7], f32::INFINITY);
        assert!(x.iter().all(|v| !v.is_subnormal()));
    }
}
