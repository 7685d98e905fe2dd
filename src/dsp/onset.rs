//! Onsets in an audio signal, so taps on a table into a microphone can strike the object.
//!
//! Two envelope followers on the rectified signal: a fast one (1 ms attack, 15 ms release) tracks
//! transients, a slow one (200 ms) the background. An onset fires when the fast envelope rises
//! above the threshold and above the background by a fixed margin, at most once per retrigger
//! time. Its strength is how far the fast envelope is above the threshold.

/// Attack time of the fast envelope, in seconds.
const FAST_ATTACK_S: f32 = 0.001;
/// Release time of the fast envelope, in seconds.
const FAST_RELEASE_S: f32 = 0.015;
/// Time constant of the background envelope, in seconds.
const SLOW_S: f32 = 0.2;
/// How far above the background a transient must rise: 3 dB.
const MARGIN: f32 = 1.4;
/// Span of levels mapped onto strength 0..1 above the threshold, in dB.
const STRENGTH_RANGE_DB: f32 = 36.0;

/// An onset found in a block.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Onset {
    /// Sample offset within the block.
    pub time: u32,
    /// Strength 0 to 1, for velocity.
    pub strength: f32,
}

/// Onset detector state.
#[derive(Debug, Clone)]
pub struct OnsetDetector {
    /// Fast envelope.
    fast: f32,
    /// Background envelope.
    slow: f32,
    /// Samples until another onset may fire.
    holdoff: u32,
    /// Whether the fast envelope is above the trigger level (an onset fires on the way up).
    armed: bool,
    /// Per-sample coefficients: fast attack, fast release, slow.
    k_attack: f32,
    k_release: f32,
    k_slow: f32,
    /// Sample rate in Hz.
    sample_rate_hz: f32,
}

impl OnsetDetector {
    /// A detector at `sample_rate_hz`, at rest.
    pub fn new(sample_rate_hz: f32) -> Self {
        let k = |t: f32| 1.0 - (-1.0 / (t * sample_rate_hz)).exp();
        Self {
            fast: 0.0,
            slow: 0.0,
            holdoff: 0,
            armed: true,
            k_attack: k(FAST_ATTACK_S),
            k_release: k(FAST_RELEASE_S),
            k_slow: k(SLOW_S),
            sample_rate_hz,
        }
    }

    /// Back to rest.
    pub fn reset(&mut self) {
        self.fast = 0.0;
        self.slow = 0.0;
        self.holdoff = 0;
        self.armed = true;
    }

    /// Scans `input`, calling `on_onset` for each onset, with threshold `threshold` (linear
    /// amplitude) and at least `retrigger_s` seconds between onsets. Non-finite samples count as
    /// silence.
    pub fn process(
        &mut self,
        input: &[f32],
        threshold: f32,
        retrigger_s: f32,
        mut on_onset: impl FnMut(Onset),
    ) {
        let holdoff = (retrigger_s.max(0.0) * self.sample_rate_hz) as u32;
        for (n, &x) in input.iter().enumerate() {
            let level = if x.is_finite() { x.abs() } else { 0.0 };
            let k = if level > self.fast {
                self.k_attack
            } else {
                self.k_release
            };
            self.fast += (level - self.fast) * k;
            self.slow += (level - self.slow) * self.k_slow;
            self.holdoff = self.holdoff.saturating_sub(1);
            let above = self.fast > threshold && self.fast > MARGIN * self.slow;
            if above && self.armed && self.holdoff == 0 {
                let db = 20.0 * (self.fast / threshold.max(1e-9)).log10();
                on_onset(Onset {
                    time: n as u32,
                    strength: (0.25 + db / STRENGTH_RANGE_DB).clamp(0.05, 1.0),
                });
                self.holdoff = holdoff;
                self.armed = false;
            } else if self.fast < 0.5 * threshold {
                self.armed = true;
            }
        }
        // Keep the envelopes out of the denormal range between sounds.
        if self.fast < 1e-20 {
            self.fast = 0.0;
        }
        if self.slow < 1e-20 {
            self.slow = 0.0;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A decaying click every `period` samples, at amplitude `a`.
    fn taps(len: usize, period: usize, a: f32) -> Vec<f32> {
        (0..len)
            .map(|n| {
                let t = n % period;
                a * (-(t as f32) / 200.0).exp() * if t.is_multiple_of(2) { 1.0 } else { -0.8 }
            })
            .collect()
    }

    fn onsets(x: &[f32], threshold: f32, retrigger_s: f32) -> Vec<Onset> {
        let mut d = OnsetDetector::new(48_000.0);
        let mut found = Vec::new();
        for block in x.chunks(256) {
            d.process(block, threshold, retrigger_s, |o| found.push(o));
        }
        found
    }

    #[test]
    fn taps_fire_once_each_above_the_threshold() {
        let x = taps(48_000, 9_600, 0.5);
        assert_eq!(onsets(&x, 0.05, 0.05).len(), 5);
        // Too quiet for the threshold.
        let quiet = taps(48_000, 9_600, 0.01);
        assert!(onsets(&quiet, 0.05, 0.05).is_empty());
        // Retrigger time longer than the spacing halves the count.
        assert_eq!(onsets(&x, 0.05, 0.3).len(), 3);
    }

    #[test]
    fn louder_taps_are_stronger() {
        let soft = onsets(&taps(9_600, 9_600, 0.1), 0.02, 0.05)[0].strength;
        let loud = onsets(&taps(9_600, 9_600, 0.8), 0.02, 0.05)[0].strength;
        assert!(loud > soft, "{loud} vs {soft}");
    }

    #[test]
    fn steady_noise_does_not_retrigger() {
        let mut seed = 1u32;
        let noise: Vec<f32> = (0..96_000)
            .map(|_| {
                seed ^= seed << 13;
                seed ^= seed >> 17;
                seed ^= seed << 5;
                (seed as f32 / u32::MAX as f32 - 0.5) * 0.2
            })
            .collect();
        // The noise starts once (an onset) and then stays: no more onsets.
        assert!(onsets(&noise, 0.02, 0.05).len() <= 1);
    }
}
