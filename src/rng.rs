//! Seeded randomness every layer may use, so that a render, a mesh's modes or a test's noise
//! repeats bit for bit: a generator of numbers in sequence ([`Rng`]), and a hash for numbers
//! drawn by position rather than in order ([`hash`], the lattice of a value noise).

/// xorshift32 (Marsaglia, "Xorshift RNGs", 2003, shifts 13, 17, 5): fast, deterministic, good
/// enough for strike variation, noise bursts, start vectors and test signals.
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
        bipolar(self.next_u32())
    }

    /// Uniform in (0, 1), in steps of 2^-32: never 0, so its logarithm is finite.
    #[inline]
    pub fn uniform(&mut self) -> f64 {
        (f64::from(self.next_u32()) + 0.5) / 4_294_967_296.0
    }
}

/// 32 random bits mapped onto [-1, 1): the top 24, exact in f32.
#[inline]
pub fn bipolar(bits: u32) -> f32 {
    (bits >> 8) as f32 * (2.0 / 16_777_216.0) - 1.0
}

/// A 32-bit hash of the point `(a, b)` of a lattice under `seed`: random bits drawn by position,
/// the same wherever and however often they are asked for.
#[inline]
pub fn hash(seed: u32, a: u32, b: u32) -> u32 {
    // A multiply-xorshift finaliser (the constants of Chris Wellons' "lowbias32").
    let mut h = seed ^ a.wrapping_mul(0x9E37_79B9) ^ b.wrapping_mul(0x85EB_CA6B);
    h ^= h >> 16;
    h = h.wrapping_mul(0x7FEB_352D);
    h ^= h >> 15;
    h = h.wrapping_mul(0x846C_A68B);
    h ^ (h >> 16)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_numbers_stay_inside_the_open_interval_and_average_a_half() {
        let mut rng = Rng::new(1);
        let draws: Vec<f64> = (0..100_000).map(|_| rng.uniform()).collect();
        assert!(draws.iter().all(|&u| u > 0.0 && u < 1.0));
        let mean = draws.iter().sum::<f64>() / draws.len() as f64;
        assert!((mean - 0.5).abs() < 0.01, "{mean}");
    }

    #[test]
    fn a_seed_repeats_its_sequence_and_zero_is_a_seed_too() {
        let (mut a, mut b) = (Rng::new(0), Rng::new(0));
        for _ in 0..100 {
            assert_eq!(a.next_u32(), b.next_u32());
        }
        assert!((0..100).any(|_| a.next_u32() != 0));
    }

    #[test]
    fn bipolar_numbers_span_minus_one_to_one() {
        assert_eq!(bipolar(0), -1.0);
        assert!(bipolar(u32::MAX) < 1.0 && bipolar(u32::MAX) > 0.9999);
        assert_eq!(bipolar(1 << 31), 0.0);
    }
}
