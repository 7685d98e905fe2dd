//! One sounding object: its resonators, the strikes under way, and its pitch.

use std::f64::consts::TAU;

use super::mode_fade::fade_samples;
use super::prepared::PreparedBank;
use super::{NoteExpression, VoiceModulation, CONTACT_SPEED_MAX_M_PER_S, MAX_EXPRESSION_SEMITONES};
use crate::bank::format::MAX_FREQ_RATIO;
use crate::dsp::coeffs::ModeCoeffs;
use crate::dsp::{Exciter, ExciterKind, ResonatorBank};
use crate::units::t60_to_decay;

/// Pole angle (radians per sample) above which a mode is not started, and at which a sounding
/// mode pushed higher is held while it fades out.
const THETA_MAX: f64 = TAU * MAX_FREQ_RATIO;

/// T60 in seconds of a mode pushed above `THETA_MAX` by a pitch change: gone before it is heard
/// aliasing, without a click.
const ABOVE_RANGE_T60_S: f64 = 0.005;

/// What a voice is doing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VoiceState {
    /// Silent and available.
    Free,
    /// Struck, key still down.
    Held,
    /// Struck, key released: rings on (or damps, with release damping).
    Released,
    /// Stolen: fading out over a few milliseconds before it is freed.
    Fading,
}

/// Controls a voice holds in place of the engine's (CLAP polyphonic modulation); `None` follows
/// the engine.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct VoiceOverrides {
    /// Fine tune in cents.
    pub fine_tune_cents: Option<f32>,
    /// Size ratio.
    pub size_ratio: Option<f32>,
    /// Strike position, first axis.
    pub strike_x: Option<f32>,
    /// Strike position, second axis.
    pub strike_y: Option<f32>,
    /// Mallet contact time in milliseconds.
    pub hardness_ms: Option<f32>,
    /// Contact speed in m/s.
    pub contact_speed_m_per_s: Option<f32>,
    /// Contact force at full velocity.
    pub contact_force: Option<f32>,
}

/// A strike waiting for the other events at its sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PendingStrike {
    /// Velocity, 0 to 1.
    pub velocity: f32,
    /// Whether the voice was free: its pitch starts at its target instead of gliding there.
    pub fresh: bool,
}

/// The parameters a voice's coefficients were last computed with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tuning {
    /// Natural log of the pitch ratio.
    pub log_pitch: f64,
    /// Version of the engine's decay table.
    pub damping_version: u64,
    /// Lowest decay rate imposed by release damping, in 1/s (0 = none).
    pub release_decay_per_s: f64,
    /// Decay rate a held contact adds to every mode, in 1/s (a scraper's hand damping the object).
    pub contact_decay_per_s: f64,
    /// Natural log of this voice's own decay multiplier (per-note pressure).
    pub log_damping: f64,
}

/// One voice.
#[derive(Debug, Clone)]
pub struct Voice {
    /// What the voice is doing.
    pub state: VoiceState,
    /// MIDI key that struck it.
    pub key: u8,
    /// MIDI channel of the note.
    pub channel: u8,
    /// The host's id for the note, if it gave one.
    pub id: Option<i32>,
    /// Controls this voice holds in place of the engine's.
    pub overrides: VoiceOverrides,
    /// Velocity of a strike to make once every event at the current sample is in (so
    /// modulation sent with the note-on shapes the strike).
    pub pending_strike: Option<PendingStrike>,
    /// Order of allocation, to break ties when stealing.
    pub age: u64,
    /// The resonators.
    pub modes: ResonatorBank,
    /// Strikes under way.
    pub exciter: Exciter,
    /// Natural log of the current (smoothed) pitch ratio.
    pub log_pitch: f64,
    /// The tuning the coefficients hold, or `None` when they must be recomputed.
    pub applied: Option<Tuning>,
    /// Gain while fading after being stolen, 1 down to 0.
    pub fade_gain: f32,
    /// Per-note tuning offset in semitones (note expression).
    pub tuning_semitones: f32,
    /// The last strike's random change of pitch, in semitones (strike variation).
    pub variation_semitones: f32,
    /// The last strike's random change of decay, as a natural log of its multiplier.
    pub variation_log_damping: f32,
    /// Per-note pressure 0 to 1 (note expression): the contact's force on a contact note, else
    /// damping the object like a hand on it.
    pub pressure: f32,
    /// Whether the note plays a contact (scrape, roll, rub) rather than a strike.
    pub contact: bool,
    /// A contact note's force from its velocity, until pressure takes over (0 to 1).
    pub contact_velocity: f32,
    /// Whether the note's pressure has been above 0 since it started: it then sets a contact's
    /// force.
    pub pressed: bool,
    /// The note's own contact speed in m/s, from its slide (note expression, MPE's CC 74) or a
    /// rendered note's speed curve, if one came.
    pub speed_m_per_s: Option<f32>,
}

impl Voice {
    /// A free voice for banks of up to `num_modes` modes. Allocates.
    pub fn new(num_modes: usize, seed: u32) -> Self {
        Self {
            state: VoiceState::Free,
            key: 0,
            channel: 0,
            id: None,
            overrides: VoiceOverrides::default(),
            pending_strike: None,
            age: 0,
            modes: ResonatorBank::new(num_modes),
            exciter: Exciter::new(seed),
            log_pitch: 0.0,
            applied: None,
            fade_gain: 1.0,
            tuning_semitones: 0.0,
            variation_semitones: 0.0,
            variation_log_damping: 0.0,
            pressure: 0.0,
            contact: false,
            contact_velocity: 0.0,
            pressed: false,
            speed_m_per_s: None,
        }
    }

    /// Whether the voice counts against polyphony.
    pub fn is_sounding(&self) -> bool {
        matches!(self.state, VoiceState::Held | VoiceState::Released)
    }

    /// Silences the voice and makes it available.
    pub fn free(&mut self) {
        self.state = VoiceState::Free;
        self.modes.clear();
        self.exciter.reset();
        self.applied = None;
        self.fade_gain = 1.0;
        self.tuning_semitones = 0.0;
        self.variation_semitones = 0.0;
        self.variation_log_damping = 0.0;
        self.pressure = 0.0;
        self.contact = false;
        self.pressed = false;
        self.speed_m_per_s = None;
        self.id = None;
        self.overrides = VoiceOverrides::default();
        self.pending_strike = None;
    }

    /// Applies a per-note expression (non-finite values are ignored).
    pub fn express(&mut self, expression: NoteExpression) {
        match expression {
            NoteExpression::Tuning(semitones) if semitones.is_finite() => {
                self.tuning_semitones =
                    semitones.clamp(-MAX_EXPRESSION_SEMITONES, MAX_EXPRESSION_SEMITONES)
            }
            NoteExpression::Pressure(p) if p.is_finite() => {
                self.pressure = p.clamp(0.0, 1.0);
                // A note's pressure takes over a contact's force once it presses at all (MPE
                // sends the channel's resting pressure, 0, with each note).
                self.pressed |= self.pressure > 0.0;
            }
            NoteExpression::Slide(s) if s.is_finite() => {
                self.speed_m_per_s = Some(s.clamp(0.0, 1.0) * CONTACT_SPEED_MAX_M_PER_S)
            }
            // Sanitised where the contact takes it ([`crate::dsp::contact::Contact::set_speed`]).
            NoteExpression::ContactSpeed(v) => self.speed_m_per_s = Some(v),
            _ => {}
        }
    }

    /// Holds a control of its own in place of the engine's (already sanitised).
    pub fn modulate(&mut self, modulation: VoiceModulation) {
        let o = &mut self.overrides;
        match modulation {
            VoiceModulation::FineTuneCents(v) => o.fine_tune_cents = Some(v),
            VoiceModulation::SizeRatio(v) => o.size_ratio = Some(v),
            VoiceModulation::StrikeX(v) => o.strike_x = Some(v),
            VoiceModulation::StrikeY(v) => o.strike_y = Some(v),
            VoiceModulation::HardnessMs(v) => o.hardness_ms = Some(v),
            VoiceModulation::ContactSpeed(v) => o.contact_speed_m_per_s = Some(v),
            VoiceModulation::ContactForce(v) => o.contact_force = Some(v),
        }
    }

    /// Recomputes the coefficients of every live mode for `tuning`: angles scale with pitch,
    /// decays follow frequency (constant Q) plus a held contact's damping, with the release decay
    /// as a floor, and a mode pushed above `THETA_MAX` is held there and fades out.
    pub fn retune(
        &mut self,
        bank: &PreparedBank,
        decay: &[f64],
        sample_rate_hz: f64,
        tuning: Tuning,
    ) {
        let pitch = tuning.log_pitch.exp();
        let damping = pitch * tuning.log_damping.exp();
        let theta_per_hz = TAU * pitch / sample_rate_hz;
        let inv_rate = 1.0 / sample_rate_hz;
        let release = tuning.release_decay_per_s;
        let contact = tuning.contact_decay_per_s;
        let fade = t60_to_decay(ABOVE_RANGE_T60_S);
        self.modes.set_poles_with(|m| {
            let theta = bank.freq_hz[m] * theta_per_hz;
            let decay_per_s = (decay[m] * damping + contact).max(release);
            if theta < THETA_MAX {
                (theta, decay_per_s * inv_rate)
            } else {
                (THETA_MAX, decay_per_s.max(fade) * inv_rate)
            }
        });
        self.applied = Some(tuning);
    }

    /// Strikes the voice: restarts modes that have died (unless the strike cannot lift them above
    /// `threshold`), sets every computed mode's gain to `gains` (the bank's at the strike point;
    /// dormant ones take theirs with the pulse, in `settle_strike`), tunes the voice to `tuning`
    /// and starts the pulse. With `start_dormant` (pruning on, a pulse known in advance) the
    /// modes restarted are not computed until the pruner hears them: they start dormant, for
    /// [`crate::engine::Engine`]'s `settle_strike` to judge at once.
    #[allow(clippy::too_many_arguments)] // two call sites; the values are all distinct and plain
    pub fn strike(
        &mut self,
        bank: &PreparedBank,
        decay: &[f64],
        sample_rate_hz: f64,
        tuning: Tuning,
        gains: &[f32],
        kind: ExciterKind,
        amplitude: f32,
        len_samples: u32,
        threshold: f32,
        start_dormant: bool,
    ) {
        let pitch = tuning.log_pitch.exp();
        let knock = kind.knock();
        let bound = amplitude * knock.peak_bound(len_samples);
        let threshold = start_threshold(threshold, bank.num_modes());
        let heard = |gain: f32| gain.abs() * bound >= threshold;
        // A strike point reaches some of a bank's modes only (one object of a scene): runs of
        // modes it cannot lift are passed over `RUN` at a time, without a branch for each.
        const RUN: usize = 8;
        for (c, chunk) in gains[..bank.num_modes()].chunks(RUN).enumerate() {
            if !chunk.iter().fold(false, |any, &g| any | heard(g)) {
                continue;
            }
            for (k, &gain) in chunk.iter().enumerate() {
                let m = RUN * c + k;
                if heard(gain) && !self.modes.is_live(m) {
                    self.start_mode(bank, sample_rate_hz, pitch, m, gain, start_dormant);
                }
            }
        }
        self.modes.set_gains_with(|m| gains[m]);
        self.retune(bank, decay, sample_rate_hz, tuning);
        // A contact is started by the engine, which knows its controls. A key struck again while
        // its contact goes on knocks the object (a mallet strike), and the contact goes on.
        if !kind.is_contact() || self.exciter.holds_contact() {
            self.exciter.strike(knock, amplitude, len_samples);
        }
    }

    /// Starts mode `m`, struck with `gain`, at `pitch`: dormant with `start_dormant`, else
    /// computed (its coefficients follow with the retune after the strike); not at all if the
    /// pitch takes it out of range.
    fn start_mode(
        &mut self,
        bank: &PreparedBank,
        sample_rate_hz: f64,
        pitch: f64,
        m: usize,
        gain: f32,
        start_dormant: bool,
    ) {
        let theta = TAU * bank.freq_hz[m] * pitch / sample_rate_hz;
        if theta < THETA_MAX && start_dormant {
            let fade = fade_samples(theta as f32, sample_rate_hz);
            self.modes.start_dormant(m, fade);
        } else if theta < THETA_MAX {
            // Coefficients follow with the retune, for all modes at once.
            self.modes.activate(
                m,
                ModeCoeffs {
                    q_re: 0.0,
                    q_im: 0.0,
                },
                gain,
            );
        }
    }
}

/// What a strike must add to a mode of a bank of `num_modes` to start it, for truncation
/// threshold `threshold` (as an amplitude): modes left out share the threshold's energy, like
/// modes retired later.
pub fn start_threshold(threshold: f32, num_modes: usize) -> f32 {
    threshold / (num_modes.max(1) as f32).sqrt()
}
