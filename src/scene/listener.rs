//! How the listener hears an object at a place: the distance gain, the air's absorption, the
//! propagation delay, and the direction (equal-power stereo, or a spherical head's two ears).

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

use super::format::{Listener, Output};

/// Speed of sound in air at 20 °C, m/s.
pub const SPEED_OF_SOUND_M_PER_S: f64 = 343.0;

/// Distance under which the distance gain stops growing, in metres: a point source's `1/r` has
/// no meaning inside the object (+12 dB over its level at 1 m at most).
pub const NEAR_M: f64 = 0.25;

/// Radius of the spherical head, in metres (Brown and Duda 1998: 8.75 cm).
pub const HEAD_RADIUS_M: f64 = 0.0875;

/// Brown and Duda's head shadow: its gain at high frequencies falls to this where the source is
/// farthest from the ear...
const SHADOW_ALPHA_MIN: f64 = 0.1;

/// ... at this angle from the ear's axis, in radians (150°).
const SHADOW_THETA_MIN: f64 = 150.0 * PI / 180.0;

/// The air's absorption in dB per metre at `freq_hz` (ISO 9613-1:1993, eqs. 3-5), at 20 °C, 50 %
/// relative humidity and 101.325 kPa. About 4.7 dB per km at 1 kHz and 100 dB per km at 8 kHz.
pub fn air_absorption_db_per_m(freq_hz: f64) -> f64 {
    const T: f64 = 293.15; // K
    const T0: f64 = 293.15; // reference air temperature, K
    const T01: f64 = 273.16; // triple-point isotherm temperature, K
    const RELATIVE_HUMIDITY_PCT: f64 = 50.0;
    // Molar concentration of water vapour, % (pressure at the reference, p_a = p_r).
    let p_sat = 10f64.powf(-6.8346 * (T01 / T).powf(1.261) + 4.6151);
    let h = RELATIVE_HUMIDITY_PCT * p_sat;
    // Relaxation frequencies of oxygen and nitrogen, Hz.
    let fr_o = 24.0 + 4.04e4 * h * (0.02 + h) / (0.391 + h);
    let fr_n = (T / T0).powf(-0.5)
        * (9.0 + 280.0 * h * (-4.170 * ((T / T0).powf(-1.0 / 3.0) - 1.0)).exp());
    let f2 = freq_hz * freq_hz;
    8.686
        * f2
        * (1.84e-11 * (T / T0).sqrt()
            + (T / T0).powf(-2.5)
                * (0.01275 * (-2239.1 / T).exp() / (fr_o + f2 / fr_o)
                    + 0.1068 * (-3352.0 / T).exp() / (fr_n + f2 / fr_n)))
}

/// How one ear (or loudspeaker channel) hears an object that does not move.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ear {
    /// Gain: the distance gain and, in stereo, the pan.
    pub gain: f64,
    /// Delay from the object's sound to this ear, in seconds: the distance at the speed of
    /// sound, and the head's part in binaural.
    pub delay_s: f64,
    /// Brown and Duda's `alpha` for the head shadow, the filter's gain at high frequencies
    /// (1 for no shadow).
    pub shadow_alpha: f64,
}

/// How the listener hears an object at a place: the left ear, then the right.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placement {
    /// Distance from the head's centre, metres.
    pub distance_m: f64,
    /// Left, right.
    pub ears: [Ear; 2],
}

/// The listener's frame: unit vectors to the right and ahead, horizontal.
fn frame(l: &Listener) -> ([f64; 3], [f64; 3]) {
    let f = l.forward;
    let norm = (f[0] * f[0] + f[2] * f[2]).sqrt().max(1e-300);
    let ahead = [f[0] / norm, 0.0, f[2] / norm];
    // ahead x up, with up = +y.
    let right = [-ahead[2], 0.0, ahead[0]];
    (right, ahead)
}

/// How `listener` hears an object at `at`.
pub fn place(listener: &Listener, at: [f64; 3]) -> Placement {
    let v: Vec<f64> = (0..3).map(|i| at[i] - listener.position[i]).collect();
    let r = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let gain = 1.0 / r.max(NEAR_M);
    let (right, _) = frame(listener);
    // The source's share along the ears' axis, -1 (left) to 1 (right); ahead when at the head.
    let lateral = if r > 0.0 {
        ((v[0] * right[0] + v[2] * right[2]) / r).clamp(-1.0, 1.0)
    } else {
        0.0
    };
    let travel_s = r / SPEED_OF_SOUND_M_PER_S;
    let ears = match listener.output {
        Output::Stereo => {
            // Equal power, the pan linear in the azimuth (folded to the front): the pan angle
            // runs from 0 (left, -90°) to pi/2 (right, 90°).
            let azimuth = lateral.asin();
            let angle = (azimuth / FRAC_PI_2 + 1.0) * FRAC_PI_4;
            [angle.cos(), angle.sin()].map(|pan| Ear {
                gain: gain * pan,
                delay_s: travel_s,
                shadow_alpha: 1.0,
            })
        }
        Output::Binaural => [-1.0, 1.0].map(|side: f64| {
            // Angle between the ear's axis and the source.
            let theta = (side * lateral).clamp(-1.0, 1.0).acos();
            Ear {
                gain,
                delay_s: (travel_s + ear_delay_s(theta)).max(0.0),
                shadow_alpha: shadow_alpha(theta),
            }
        }),
    };
    Placement {
        distance_m: r,
        ears,
    }
}

/// Brown and Duda's delay of an ear for a source `theta` radians off its axis, relative to the
/// head's centre: `-(a/c) cos(theta)` on the ear's side, `(a/c)(theta - pi/2)` in its shadow (the
/// way round the sphere). A source on one side reaches the far ear `(a/c)(1 + pi/2)` = 0.66 ms
/// after the near one.
fn ear_delay_s(theta: f64) -> f64 {
    let a_over_c = HEAD_RADIUS_M / SPEED_OF_SOUND_M_PER_S;
    if theta < FRAC_PI_2 {
        -a_over_c * theta.cos()
    } else {
        a_over_c * (theta - FRAC_PI_2)
    }
}

/// Brown and Duda's head shadow gain at high frequencies for a source `theta` radians off the
/// ear's axis: 2 (+6 dB) facing it, 0.1 (-20 dB) at 150°.
fn shadow_alpha(theta: f64) -> f64 {
    (1.0 + 0.5 * SHADOW_ALPHA_MIN)
        + (1.0 - 0.5 * SHADOW_ALPHA_MIN) * (theta / SHADOW_THETA_MIN * PI).cos()
}

/// Brown and Duda's head shadow as a digital filter: the one-pole, one-zero
/// `H(s) = (alpha s + beta) / (s + beta)`, `beta = 2 c / a`, through the bilinear transform. Unity
/// at low frequencies, `alpha` at high ones.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadShadow {
    b0: f32,
    b1: f32,
    a1: f32,
    /// Last input.
    x1: f32,
    /// Last output.
    y1: f32,
}

impl HeadShadow {
    /// The filter for `alpha` at `sample_rate_hz`.
    pub fn new(alpha: f64, sample_rate_hz: f64) -> Self {
        let beta = 2.0 * SPEED_OF_SOUND_M_PER_S / HEAD_RADIUS_M;
        let k = 2.0 * sample_rate_hz;
        let norm = k + beta;
        Self {
            b0: ((alpha * k + beta) / norm) as f32,
            b1: ((beta - alpha * k) / norm) as f32,
            a1: ((beta - k) / norm) as f32,
            x1: 0.0,
            y1: 0.0,
        }
    }

    /// Filters one sample.
    #[inline]
    pub fn tick(&mut self, x: f32) -> f32 {
        let y = self.b0 * x + self.b1 * self.x1 - self.a1 * self.y1;
        self.x1 = x;
        // Flushed to zero well above the subnormals.
        self.y1 = if y.abs() < 1e-30 { 0.0 } else { y };
        self.y1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn air_absorption_matches_the_standard_table() {
        // ISO 9613-1 table 1, 20 °C, 50 %: dB/km.
        for (f, db_per_km) in [
            (125.0, 0.445),
            (1000.0, 4.66),
            (4000.0, 29.4),
            (8000.0, 104.0),
        ] {
            let got = 1000.0 * air_absorption_db_per_m(f);
            assert!(
                (got / db_per_km - 1.0).abs() < 0.05,
                "{f} Hz: {got:.3} dB/km, the table gives {db_per_km}"
            );
        }
    }

    #[test]
    fn a_source_at_the_left_reaches_the_left_ear_first() {
        let listener = Listener {
            output: Output::Binaural,
            ..Listener::default()
        };
        let p = place(&listener, [-2.0, 0.0, 0.0]);
        let itd_ms = 1e3 * (p.ears[1].delay_s - p.ears[0].delay_s);
        assert!((0.6..=0.7).contains(&itd_ms), "ITD {itd_ms} ms");
        assert!(p.ears[0].shadow_alpha > 1.9 && p.ears[1].shadow_alpha < 0.5);
        // Ahead, both ears alike.
        let p = place(&listener, [0.0, 0.0, -2.0]);
        assert!((p.ears[0].delay_s - p.ears[1].delay_s).abs() < 1e-12);
    }

    #[test]
    fn stereo_pans_with_equal_power_and_falls_with_distance() {
        let listener = Listener::default();
        for at in [
            [-1.0, 0.0, 0.0],
            [1.0, 0.0, -1.0],
            [0.0, 0.0, -1.0],
            [0.3, 0.0, 2.0],
        ] {
            let p = place(&listener, at);
            let power: f64 = p.ears.iter().map(|e| (e.gain * p.distance_m).powi(2)).sum();
            assert!((power - 1.0).abs() < 1e-9, "{at:?}: power {power}");
        }
        let left = place(&listener, [-1.0, 0.0, 0.0]);
        assert!(left.ears[0].gain > 0.99 && left.ears[1].gain < 1e-9);
        let near = place(&listener, [0.0, 0.0, -2.0]).ears[0].gain;
        let far = place(&listener, [0.0, 0.0, -4.0]).ears[0].gain;
        assert!((near / far - 2.0).abs() < 1e-12);
    }

    #[test]
    fn the_head_shadow_passes_lows_and_scales_highs_by_alpha() {
        let rate = 48_000.0;
        for alpha in [0.1, 1.0, 2.0] {
            let gain_at = |f: f64| {
                let mut h = HeadShadow::new(alpha, rate);
                let w = std::f64::consts::TAU * f / rate;
                let mut peak = 0.0f32;
                for n in 0..48_000 {
                    let y = h.tick((w * n as f64).sin() as f32);
                    if n > 24_000 {
                        peak = peak.max(y.abs());
                    }
                }
                peak as f64
            };
            assert!((gain_at(50.0) - 1.0).abs() < 0.01, "alpha {alpha}");
            assert!(
                (gain_at(20_000.0) / alpha - 1.0).abs() < 0.1,
                "alpha {alpha}"
            );
        }
    }
}
