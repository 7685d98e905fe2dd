//! A small seeded random number generator, so renders repeat bit for bit.

/// xorshift32: fast, deterministic, good enough for strike variation and noise bursts.
#[derive(Debug, Clone)]
pub struct Rng {
    /// Generator state; never zero.
    state: u32,
}

impl Rng {
    /// A generator started from `seed` (0 is replaced by a fixed non-zero seed).
    pub fn new(seed: u32) -> Self {
        Self {
            state: if seed == 0 { 0x9E37_79B9 } else { seed },
        }
    }

    /// The next 32 random bits.
    #[inline]
    pub fn next_u32(&mut self) -> u32 {
        let mut x = self.state;
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        self.state = x;
        x
    }

    /// Uniform in [-1, 1).
    #[inline]
    pub fn bipolar(&mut self) -> f32 {
        // 24 random bits mapped onto [-1, 1): exact in f32.
        (self.next_u32() >> 8) as f32 * (2.0 / 16_777_216.0) - 1.0
    }
}
