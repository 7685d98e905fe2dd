//! A bank made ready for the audio thread: modes sorted by frequency, tables in the units the
//! voices use, and the level that meets the loudness contract.

use std::f64::consts::TAU;

use super::controls::Controls;
use super::pitch_level::PitchLevel;
use super::position::{PositionMap, PositionWeights};
use super::stereo::{balanced_pans, lane_weights, COLUMN_PAN};
use crate::bank::format::MIN_DECAY_PER_S;
use crate::bank::Bank;
use crate::dsp::coeffs::ModeCoeffs;
use crate::dsp::{Exciter, Kernel, ResonatorBank, StrikeKind, COLUMNS};
use crate::units::hz_to_midi_key;

/// Peak of a full-velocity strike with the bank's default controls (its default strike
/// position included): -6 dBFS.
pub const TARGET_PEAK: f32 = 0.5;

/// Sample rate of the loudness measurement; level does not depend on the rate.
const MEASURE_RATE_HZ: f64 = 48_000.0;

/// Length of a default strike over which the columns' pans are chosen to balance it: the
/// part of a note a listener places it by.
const BALANCE_S: f64 = 2.0;

/// Most mode-samples spent measuring the balance (about a tenth of a second of work): a bank
/// of thousands of modes is measured over less than [`BALANCE_S`], and is balanced by its
/// density anyway.
const BALANCE_MODE_SAMPLES: f64 = 1e8;

/// A bank prepared for playing. Built off the audio thread; shared read-only by voices.
#[derive(Debug, Clone)]
pub struct PreparedBank {
    /// The bank as loaded, for display and saving.
    pub source: Bank,
    /// Mode frequencies in Hz, ascending.
    pub freq_hz: Vec<f64>,
    /// Mode decay rates in 1/s, at least `MIN_DECAY_PER_S`.
    pub decay_per_s: Vec<f64>,
    /// `ln(f / f_lowest)` of each mode, for the damping tilt.
    pub ln_freq_ratio: Vec<f64>,
    /// Gains, mode-major: `gains[m * num_positions + k]`, scaled by the loudness normalisation.
    /// Read-only once prepared: `gains_by_position` holds them too.
    pub gains: Vec<f32>,
    /// The same gains position-major, `[k * num_modes + m]`: a strike reads a position's column
    /// of every mode at once.
    gains_by_position: Vec<f32>,
    /// Number of strike positions.
    pub num_positions: usize,
    /// The positions, normalised.
    pub positions: PositionMap,
    /// The MIDI key that plays the bank at its own pitch: the one nearest its root pitch.
    pub root_key: f64,
    /// The bank's own quality factor: median of `pi f / d` (with `d` at least
    /// `MIN_DECAY_PER_S`). Material Q scales decays relative to it.
    pub reference_q: f64,
    /// Gain applied to the bank's gains so a default strike peaks at `TARGET_PEAK`.
    pub normalization: f32,
    /// Gain of a strike under the root, so a default strike peaks at `TARGET_PEAK` there too.
    pub pitch_level: PitchLevel,
    /// Pan of each accumulator column at full width: the default spread dealt so that a default
    /// strike sounds centred.
    pub column_pan: [f32; COLUMNS],
}

/// A default strike's modes after [`PreparedBank::render_default_strike`], to render further.
struct Ringing {
    bank: ResonatorBank,
    kernel: Kernel,
    /// Mode-samples computed so far.
    spent: usize,
}

/// Samples the default strike is rendered in at a time.
const RUN: usize = 256;

/// Most mode-samples spent following a default strike for its peak: 10 s of 200 modes, or
/// 0.2 s of 10,000.
const PEAK_MODE_SAMPLES: f64 = 1e8;

impl PreparedBank {
    /// Prepares `bank` (which should have passed validation). Allocates and renders a short
    /// strike to measure the level.
    pub fn new(bank: &Bank) -> Self {
        let k = bank.positions.len().max(1);
        let mut order: Vec<usize> = (0..bank.modes.len()).collect();
        order.sort_by(|&a, &b| bank.modes[a].freq_hz.total_cmp(&bank.modes[b].freq_hz));
        let freq_hz: Vec<f64> = order.iter().map(|&m| bank.modes[m].freq_hz).collect();
        let lowest = freq_hz.first().copied().unwrap_or(1.0).max(1e-9);
        let mut gains = Vec::with_capacity(order.len() * k);
        for &m in &order {
            let g = &bank.modes[m].gains;
            gains.extend((0..k).map(|i| g.get(i).copied().unwrap_or(0.0) as f32));
        }
        let coords: Vec<Vec<f64>> = bank.positions.iter().map(|p| p.coords.clone()).collect();
        let decay_per_s: Vec<f64> = order
            .iter()
            .map(|&m| bank.modes[m].decay_per_s.max(MIN_DECAY_PER_S))
            .collect();
        let reference_q = bank.reference_q().unwrap_or(1.0);
        let mut prepared = Self {
            source: bank.clone(),
            decay_per_s,
            ln_freq_ratio: freq_hz.iter().map(|f| (f / lowest).ln()).collect(),
            freq_hz,
            gains,
            gains_by_position: Vec::new(),
            num_positions: k,
            positions: PositionMap::new(&coords),
            // The key nearest the root plays the bank as authored, off the equal-tempered grid
            // or not: a fitted cowbell sounds on its root key as it was recorded.
            root_key: hz_to_midi_key(bank.effective_root_hz()).round(),
            reference_q,
            normalization: 1.0,
            pitch_level: PitchLevel::default(),
            column_pan: COLUMN_PAN,
        };
        let (frames, mut ringing) = prepared.render_default_strike(None);
        let mut cov = [[0.0f64; COLUMNS]; COLUMNS];
        for frame in &frames {
            for (row, &x) in cov.iter_mut().zip(frame) {
                for (c, &y) in row.iter_mut().zip(frame) {
                    *c += x as f64 * y as f64;
                }
            }
        }
        prepared.column_pan = balanced_pans(&cov);
        let peak = prepared.default_peak(&frames, &mut ringing);
        prepared.pitch_level = prepared.measure_pitch_level(peak);
        if peak > 0.0 && peak.is_finite() {
            prepared.normalization = TARGET_PEAK / peak;
            for g in &mut prepared.gains {
                *g *= prepared.normalization;
            }
        }
        let n = prepared.num_modes();
        prepared.gains_by_position = (0..k * n)
            .map(|i| prepared.gains[(i % n) * k + i / n])
            .collect();
        prepared
    }

    /// This bank with each mode's gains, at every position, multiplied by `gain(freq_hz)`, the
    /// loudness normalisation kept: a filter on the object's modes, such as the air's absorption
    /// over a distance (a scene's listener hears each object through one).
    pub fn with_mode_gains(&self, gain: impl Fn(f64) -> f32) -> Self {
        let mut out = self.clone();
        let (n, k) = (self.num_modes(), self.num_positions);
        for m in 0..n {
            let g = gain(self.freq_hz[m]);
            for p in 0..k {
                out.gains[m * k + p] *= g;
                out.gains_by_position[p * n + m] *= g;
            }
        }
        out
    }

    /// The order in which a prepared bank holds `bank`'s modes: `frequency_order(bank)[m]` is the
    /// index in `bank.modes` of prepared mode `m` (ascending frequency, ties in bank order).
    pub fn frequency_order(bank: &Bank) -> Vec<usize> {
        let mut order: Vec<usize> = (0..bank.modes.len()).collect();
        order.sort_by(|&a, &b| bank.modes[a].freq_hz.total_cmp(&bank.modes[b].freq_hz));
        order
    }

    /// Number of modes.
    pub fn num_modes(&self) -> usize {
        self.freq_hz.len()
    }

    /// Every mode's gain at strike point `w` into `out` (one per mode, as [`Self::gain_at`] gives
    /// them), a position at a time.
    pub fn gains_at(&self, w: &PositionWeights, out: &mut [f32]) {
        let n = self.num_modes();
        let out = &mut out[..n];
        let column = |i: usize| &self.gains_by_position[w.index[i] * n..(w.index[i] + 1) * n];
        if w.count == 0 {
            out.fill(0.0);
            return;
        }
        let weight = w.weight[0];
        for (o, &g) in out.iter_mut().zip(column(0)) {
            *o = weight * g;
        }
        for i in 1..w.count {
            let weight = w.weight[i];
            for (o, &g) in out.iter_mut().zip(column(i)) {
                *o += weight * g;
            }
        }
    }

    /// Gain of mode `m` for a strike blended by `w`.
    #[inline]
    pub fn gain_at(&self, m: usize, w: &PositionWeights) -> f32 {
        let row = &self.gains[m * self.num_positions..(m + 1) * self.num_positions];
        (0..w.count).map(|i| w.weight[i] * row[w.index[i]]).sum()
    }

    /// Natural log of the decay multiplier `Q_ref / Q` for `material_q` (0 when authored).
    pub fn log_damping(&self, material_q: Option<f32>) -> f64 {
        material_q.map_or(0.0, |q| (self.reference_q / q as f64).ln())
    }

    /// Decay rate of mode `m` before pitch scaling, for a decay multiplier `exp(log_damping)`
    /// and a damping tilt: `d Q_ref / Q (f / f_lowest) ^ tilt`.
    #[inline]
    pub fn damped_decay(&self, m: usize, log_damping: f64, damping_tilt: f64) -> f64 {
        (self.decay_per_s[m] * (log_damping + damping_tilt * self.ln_freq_ratio[m]).exp())
            .max(MIN_DECAY_PER_S)
    }

    /// Each column's output of a full-velocity strike with the bank's default controls (strike
    /// position, material, exciter, hardness) at the root pitch, before
    /// normalisation, at `MEASURE_RATE_HZ`: `BALANCE_S` of it, or less for a bank of so many
    /// modes that this would cost more than `BALANCE_MODE_SAMPLES`, but never less than
    /// the first 0.2 to 1 s (more for low modes, to let their beating build up); and the modes
    /// still ringing at its end.
    ///
    /// `kind` replaces the bank's default exciter when given.
    fn render_default_strike(&self, kind: Option<StrikeKind>) -> (Vec<[f32; COLUMNS]>, Ringing) {
        let controls = Controls::for_bank(&self.source);
        let n = self.num_modes();
        let mut bank = ResonatorBank::new(n);
        let w = self.positions.weights(controls.strike_x, controls.strike_y);
        let theta_max = TAU * crate::bank::format::MAX_FREQ_RATIO;
        let log_damping = self.log_damping(controls.material_q);
        for m in 0..n {
            let theta = TAU * self.freq_hz[m] / MEASURE_RATE_HZ;
            if theta < theta_max {
                let delta = self.damped_decay(m, log_damping, controls.damping_tilt as f64)
                    / MEASURE_RATE_HZ;
                bank.activate(
                    m,
                    ModeCoeffs::from_angle_radius(theta, delta),
                    self.gain_at(m, &w),
                );
            }
        }
        let mut exciter = Exciter::new(1);
        let contact = (controls.hardness_ms as f64 * 1e-3 * MEASURE_RATE_HZ).round() as u32;
        // A bank played by a contact is set to the level of a mallet strike, which a contact at
        // its defaults matches.
        let kind = kind.unwrap_or(controls.exciter.knock());
        exciter.strike(kind, 1.0, contact);
        // Long enough for the slowest beating of the lowest modes to build up.
        let lowest = self.freq_hz.first().copied().unwrap_or(100.0).max(1.0);
        let peak_s = (4.0 / lowest).clamp(0.2, 1.0);
        let affordable_s = BALANCE_MODE_SAMPLES / (n.max(1) as f64 * MEASURE_RATE_HZ);
        let seconds = affordable_s.min(BALANCE_S).max(peak_s);
        let total = (seconds * MEASURE_RATE_HZ) as usize;
        let mut frames = vec![[0.0f32; COLUMNS]; total.div_ceil(RUN) * RUN];
        let mut input = vec![0.0f32; RUN];
        let kernel = Kernel::from_env_or_detect();
        for run in frames.chunks_mut(RUN) {
            let driven = exciter.render(&mut input);
            bank.process(kernel, driven.then_some(&input[..]), run);
        }
        let spent = frames.len() * bank.num_active();
        (
            frames,
            Ringing {
                bank,
                kernel,
                spent,
            },
        )
    }

    /// The gain of strikes under the root for a bank whose default strike is a mallet's (or a
    /// contact's, levelled as a mallet's), `root_peak` the default strike's peak: an impulse's
    /// peak is measured the same way, and [`PitchLevel`] goes between them.
    fn measure_pitch_level(&self, root_peak: f32) -> PitchLevel {
        let controls = Controls::for_bank(&self.source);
        if controls.exciter.knock() != StrikeKind::Mallet {
            return PitchLevel::default();
        }
        let (frames, mut ringing) = self.render_default_strike(Some(StrikeKind::Impulse));
        let impulse_peak = self.default_peak(&frames, &mut ringing);
        let w = self.positions.weights(controls.strike_x, controls.strike_y);
        let gains: Vec<f32> = (0..self.num_modes()).map(|m| self.gain_at(m, &w)).collect();
        PitchLevel::new(
            &self.freq_hz,
            &gains,
            controls.hardness_ms as f64 * 1e-3,
            root_peak,
            impulse_peak,
        )
    }

    /// Peak of either channel of a default strike at the bank's default width with its column
    /// pans: of `frames` ([`Self::render_default_strike`]), and of the rest of the strike while
    /// the modes still `ringing` could sum to more than that (modes that cancel at first and
    /// drift into phase later), as long as `PEAK_MODE_SAMPLES` allow.
    fn default_peak(&self, frames: &[[f32; COLUMNS]], ringing: &mut Ringing) -> f32 {
        let width = Controls::for_bank(&self.source).width;
        let (wl, wr) = lane_weights(width, &self.column_pan);
        let peak_of = |frames: &[[f32; COLUMNS]]| {
            let mut peak = 0.0f32;
            for a in frames {
                let l: f32 = a.iter().zip(&wl).map(|(x, w)| x * w).sum();
                let r: f32 = a.iter().zip(&wr).map(|(x, w)| x * w).sum();
                peak = peak.max(l.abs()).max(r.abs());
            }
            peak
        };
        let mut peak = peak_of(frames);
        let step = (0.1 * MEASURE_RATE_HZ) as usize / RUN * RUN;
        let cost = step * ringing.bank.num_active();
        let mut run = vec![[0.0f32; COLUMNS]; RUN];
        loop {
            let a = ringing.bank.column_amplitudes();
            let dot = |w: &[f32; COLUMNS]| a.iter().zip(w).map(|(x, w)| x * w).sum::<f32>();
            let bound = dot(&wl).max(dot(&wr));
            if bound <= peak || bound.is_nan() || (ringing.spent + cost) as f64 > PEAK_MODE_SAMPLES
            {
                return peak;
            }
            for _ in 0..step / RUN {
                run.fill([0.0; COLUMNS]);
                ringing.bank.process(ringing.kernel, None, &mut run);
                peak = peak.max(peak_of(&run));
            }
            ringing.spent += cost;
        }
    }
}
