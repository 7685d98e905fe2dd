//! The audio-thread half of the engine: events, control ticks and rendering.

use super::mode_fade::next_tick;
use super::*;
use crate::dsp::contact::{ContactKind, ContactMotion};
use crate::dsp::masking::DB_PER_NEPER;
use crate::dsp::ExciterKind;

impl Engine {
    /// Renders `out_l.len()` samples into `out_l` and `out_r` (overwritten), applying `events`
    /// (sorted by time; times past the block act at its last sample) and driving the input voice
    /// with `input` when given (same length; non-finite samples count as silence).
    ///
    /// Never allocates, locks, logs or does I/O.
    pub fn process(
        &mut self,
        events: &[NoteEvent],
        input: Option<&[f32]>,
        out_l: &mut [f32],
        out_r: &mut [f32],
    ) {
        assert_eq!(out_l.len(), out_r.len(), "output channels differ in length");
        if let Some(x) = input {
            assert_eq!(x.len(), out_l.len(), "input and output lengths differ");
        }
        assert!(
            !self.voices.is_empty(),
            "Engine::prepare must be called before process"
        );
        let _ftz = FlushDenormals::new();
        let len = out_l.len();
        let mut next_event = 0;
        let mut pos = 0;
        while pos < len {
            self.block_pos = pos as u32;
            if self.clock.is_multiple_of(CONTROL_PERIOD as u64) {
                self.control_tick();
            }
            let first_event = next_event;
            while next_event < events.len()
                && (events[next_event].time() as usize).min(len - 1) <= pos
            {
                self.apply_event(events[next_event]);
                next_event += 1;
            }
            if next_event > first_event {
                self.make_pending_strikes();
            }
            let to_tick = CONTROL_PERIOD - (self.clock % CONTROL_PERIOD as u64) as usize;
            let to_event = events
                .get(next_event)
                .map_or(len, |e| (e.time() as usize).min(len - 1));
            let run = to_tick.min(to_event.max(pos + 1) - pos).min(len - pos);
            self.render_run(
                input.map(|x| &x[pos..pos + run]),
                &mut out_l[pos..pos + run],
                &mut out_r[pos..pos + run],
            );
            self.clock += run as u64;
            pos += run;
        }
        // Voices ended outside `process` (bank swaps) end at the start of the next block.
        self.block_pos = 0;
    }

    /// Natural logs of the decay multiplier and the tilt the controls ask for.
    pub(super) fn damping_targets(&self) -> (f64, f64) {
        let extra = self.expressed.extra_damping as f64 * MAX_EXTRA_DAMPING.ln();
        (
            self.bank.log_damping(self.expressed.material_q) + extra,
            self.expressed.damping_tilt as f64,
        )
    }

    /// Sets every smoothed value to its target at once.
    fn snap_smoothing(&mut self) {
        let (log_damping, tilt) = self.damping_targets();
        let s = &mut self.smoothed;
        if s.tilt != tilt {
            self.decay_stale = Stale::Tilt;
        } else if s.log_damping != log_damping {
            self.decay_stale = self.decay_stale.max(Stale::Damping);
        }
        s.log_damping = log_damping;
        s.tilt = tilt;
        s.gain = db_to_gain(self.expressed.output_gain_db);
        s.input_gain = db_to_gain(self.expressed.input_gain_db);
        s.weights = lane_weights(self.expressed.width, &self.bank.column_pan);
        s.weight_target = s.weights;
        s.weight_ramp_left = 0;
    }

    /// Brings the decay table up to the smoothed material: a tilt change costs an `exp` per
    /// mode, a Q change only a multiply.
    pub(super) fn rebuild_decay_table(&mut self) {
        let (log_damping, tilt) = (self.smoothed.log_damping, self.smoothed.tilt);
        if self.decay_stale == Stale::Tilt {
            for (m, d) in self.tilted_decay.iter_mut().enumerate() {
                *d = self.bank.damped_decay(m, 0.0, tilt);
            }
        }
        let scale = log_damping.exp();
        for (d, t) in self.decay.iter_mut().zip(&self.tilted_decay) {
            *d = (t * scale).max(MIN_DECAY_PER_S);
        }
        self.decay_stale = Stale::Fresh;
        self.damping_version += 1;
    }

    /// One-pole smoothing coefficient per control tick for a time constant.
    fn tick_coefficient(&self, time_constant_s: f64) -> f64 {
        1.0 - (-(CONTROL_PERIOD as f64) / (time_constant_s * self.sample_rate_hz)).exp()
    }

    /// Lowest decay rate of a released voice, in 1/s: release damping 1 gives a 50 ms T60,
    /// smaller values longer ones (200x longer towards 0), 0 none.
    fn release_decay(&self) -> f64 {
        let r = self.expressed.release_damping as f64;
        if r <= 0.0 {
            0.0
        } else {
            t60_to_decay(0.05 * 200f64.powf(1.0 - r))
        }
    }

    /// Smoothing steps, truncation, freeing and coefficient updates, every `CONTROL_PERIOD`.
    fn control_tick(&mut self) {
        self.smooth_damping();
        self.ramp_width();
        let input_heard = std::mem::take(&mut self.input_heard);
        self.tick_voices(input_heard);
        // Polyphony lowered: fade the quietest voices beyond the limit.
        let polyphony = self.expressed.polyphony.min(self.capacity);
        while self.voices.iter().filter(|v| v.is_sounding()).count() > polyphony {
            let victim = self.quietest_sounding();
            self.voices[victim].state = VoiceState::Fading;
        }
        self.prune_tick(input_heard);
    }

    /// Steps the damping and its tilt towards their targets (jumps, when nothing sounds), and
    /// brings the decay table up to date for the voices sounding.
    fn smooth_damping(&mut self) {
        if self.is_silent() {
            // Nothing sounds, so nothing can zipper: jump to the targets.
            self.snap_smoothing();
            return;
        }
        let (target_damping, target_tilt) = self.damping_targets();
        let k = self.tick_coefficient(DAMPING_SMOOTHING_S);
        let s = &mut self.smoothed;
        if s.log_damping != target_damping || s.tilt != target_tilt {
            let tilt_moved = s.tilt != target_tilt;
            s.log_damping = step_towards(s.log_damping, target_damping, k, 1e-4);
            s.tilt = step_towards(s.tilt, target_tilt, k, 1e-4);
            let stale = if tilt_moved {
                Stale::Tilt
            } else {
                Stale::Damping
            };
            self.decay_stale = self.decay_stale.max(stale);
        }
        // Only sounding voices need the table now; a note-on brings it up to date otherwise.
        if self.decay_stale != Stale::Fresh {
            self.rebuild_decay_table();
        }
    }

    /// Stereo width: ramps the column weights over the next period to the width's.
    fn ramp_width(&mut self) {
        let target = lane_weights(self.expressed.width, &self.bank.column_pan);
        if target != self.smoothed.weights && self.smoothed.weight_ramp_left == 0 {
            let inv = 1.0 / CONTROL_PERIOD as f32;
            for j in 0..COLUMNS {
                self.smoothed.weight_step.0[j] = (target.0[j] - self.smoothed.weights.0[j]) * inv;
                self.smoothed.weight_step.1[j] = (target.1[j] - self.smoothed.weights.1[j]) * inv;
            }
            self.smoothed.weight_target = target;
            self.smoothed.weight_ramp_left = CONTROL_PERIOD;
        }
    }

    /// Each sounding voice (and the input voice, heard this period if `input_heard`): fades
    /// finished, modes under the truncation threshold retired (the voice ended when none is
    /// left), its contact following its targets, its pitch stepped and its modes retuned.
    fn tick_voices(&mut self, input_heard: bool) {
        let threshold = db_to_gain(self.expressed.truncation_db);
        let pitch_k = self.tick_coefficient(PITCH_SMOOTHING_S);
        let input_key = self
            .last_key
            .unwrap_or(self.bank.root_key.round().clamp(0.0, 127.0) as u8);
        let release = self.release_decay();
        let version = self.damping_version;
        let num_voices = self.voices.len();
        let no_overrides = VoiceOverrides::default();
        let (controls, bank, decay, rate, ended, time) = (
            &self.expressed,
            &self.bank,
            &self.decay,
            self.sample_rate_hz,
            &mut self.ended,
            self.block_pos,
        );
        for (i, v) in self
            .voices
            .iter_mut()
            .chain(self.input_voice.as_mut())
            .enumerate()
        {
            let is_input = i == num_voices;
            if v.state == VoiceState::Free && v.modes.num_live() == 0 {
                continue;
            }
            v.modes.finish_fades();
            if v.exciter.is_idle() && !(is_input && input_heard) {
                // Each mode started gets an equal share of the threshold's energy, so all a
                // voice ever drops adds up to less than the threshold. (Seed 000 section 5.4.2
                // applies the threshold to each mode alone, which lets hundreds of dropped modes
                // add up to far more.)
                let live = v.modes.num_live();
                let share = (v.modes.num_started().max(1) as f32).sqrt();
                v.modes.retire_below(threshold / share);
                if is_input && v.modes.num_live() < live {
                    self.input_dormant = true;
                }
                if v.modes.num_live() == 0 {
                    end_voice(v, ended, time);
                    continue;
                }
            }
            let (key, overrides) = if is_input {
                (input_key, &no_overrides)
            } else {
                (v.key, &v.overrides)
            };
            if v.contact && v.state == VoiceState::Held {
                let (speed, force) = contact_targets(controls, v);
                v.exciter.set_contact(speed, force);
            }
            let target =
                target_log_pitch(controls, bank.root_key, key, overrides) + expression_log_pitch(v);
            v.log_pitch = step_towards(v.log_pitch, target, pitch_k, 1e-6);
            let tuning = tuning_of(v, version, release);
            if v.applied != Some(tuning) {
                v.retune(bank, decay, rate, tuning);
            }
        }
    }

    fn apply_event(&mut self, event: NoteEvent) {
        match event {
            NoteEvent::On { note, velocity, .. } if velocity > 0.0 && velocity.is_finite() => {
                self.note_on(note, velocity.min(1.0))
            }
            NoteEvent::On { note, .. } | NoteEvent::Off { note, .. } => {
                for i in 0..self.voices.len() {
                    if self.voices[i].state == VoiceState::Held && note.names(&self.voices[i]) {
                        self.release(i);
                    }
                }
            }
            NoteEvent::AllNotesOff { .. } => {
                for i in 0..self.voices.len() {
                    if self.voices[i].state == VoiceState::Held {
                        self.release(i);
                    }
                }
            }
            NoteEvent::Expression {
                note, expression, ..
            } => {
                for v in self
                    .voices
                    .iter_mut()
                    .filter(|v| v.is_sounding() && note.names(v))
                {
                    v.express(expression);
                }
            }
            NoteEvent::ChannelExpression {
                channel,
                expression,
                ..
            } => {
                for v in self
                    .voices
                    .iter_mut()
                    .filter(|v| v.is_sounding() && v.channel == channel)
                {
                    v.express(expression);
                }
            }
            NoteEvent::Modulate { id, modulation, .. } => {
                let Some(modulation) = modulation.sanitized() else {
                    return;
                };
                for v in self
                    .voices
                    .iter_mut()
                    .filter(|v| v.is_sounding() && v.id == Some(id))
                {
                    v.modulate(modulation);
                }
            }
            NoteEvent::Choke { note, .. } => {
                let time = self.block_pos;
                for v in self
                    .voices
                    .iter_mut()
                    .filter(|v| v.is_sounding() && note.names(v))
                {
                    end_voice(v, &mut self.ended, time);
                }
            }
            NoteEvent::AllSoundOff { .. } => self.end_all_voices(),
            NoteEvent::Controller { change, .. } => {
                self.controllers.apply(change);
                self.expressed = self.controls.expressed(&self.controllers).sanitized();
            }
        }
    }

    fn release(&mut self, i: usize) {
        self.voices[i].state = VoiceState::Released;
        self.voices[i].exciter.release_contact();
        let tuning = tuning_of(&self.voices[i], self.damping_version, self.release_decay());
        if self.voices[i].applied != Some(tuning) {
            self.voices[i].retune(&self.bank, &self.decay, self.sample_rate_hz, tuning);
        }
    }

    fn quietest_sounding(&self) -> usize {
        // Energy now, not at the last tick: a voice struck since then must not look silent.
        let loudness = |v: &Voice| {
            if v.exciter.is_idle() {
                v.modes.energy()
            } else {
                f32::INFINITY
            }
        };
        (0..self.voices.len())
            .filter(|&i| self.voices[i].is_sounding())
            .min_by(|&a, &b| {
                let (va, vb) = (&self.voices[a], &self.voices[b]);
                loudness(va)
                    .total_cmp(&loudness(vb))
                    .then(va.age.cmp(&vb.age))
            })
            .expect("a sounding voice")
    }

    /// The voice `note` plays: the one still ringing on its key and channel, a free one, or one
    /// freed by stealing the quietest.
    fn voice_for(&mut self, note: Note) -> usize {
        if let Some(i) = self
            .voices
            .iter()
            .position(|v| v.is_sounding() && v.key == note.key && v.channel == note.channel)
        {
            return i;
        }
        let polyphony = self.expressed.polyphony.min(self.capacity);
        if self.voices.iter().filter(|v| v.is_sounding()).count() >= polyphony {
            let victim = self.quietest_sounding();
            self.voices[victim].state = VoiceState::Fading;
        }
        if let Some(i) = self.voices.iter().position(|v| v.state == VoiceState::Free) {
            return i;
        }
        // Every other slot is fading: reuse the fading one closest to silence.
        let i = (0..self.voices.len())
            .filter(|&i| self.voices[i].state == VoiceState::Fading)
            .min_by(|&a, &b| {
                self.voices[a]
                    .fade_gain
                    .total_cmp(&self.voices[b].fade_gain)
            })
            .unwrap_or_else(|| self.quietest_sounding());
        end_voice(&mut self.voices[i], &mut self.ended, self.block_pos);
        i
    }

    /// Starts `note` on a voice; the strike itself waits for the other events at this sample.
    fn note_on(&mut self, note: Note, velocity: f32) {
        let i = self.voice_for(note);
        let v = &mut self.voices[i];
        let fresh = v.state == VoiceState::Free;
        if fresh {
            self.allocations += 1;
            v.key = note.key;
            v.channel = note.channel;
            v.age = self.allocations;
            v.id = note.id;
        } else if v.id != note.id {
            // The new note takes over the ringing voice: the old one has ended for the host.
            if v.id.is_some() && self.ended.len() < self.ended.capacity() {
                self.ended.push(EndedVoice {
                    time: self.block_pos,
                    note: Note {
                        key: v.key,
                        channel: v.channel,
                        id: v.id,
                    },
                });
            }
            v.id = note.id;
        }
        // A new note starts without the last one's per-note expression and modulation (its
        // pitch glides back).
        v.tuning_semitones = 0.0;
        v.pressure = 0.0;
        v.pressed = false;
        v.speed_m_per_s = None;
        v.overrides = VoiceOverrides::default();
        v.state = VoiceState::Held;
        v.pending_strike = Some(PendingStrike { velocity, fresh });
        self.last_key = Some(note.key);
    }

    /// Makes the strikes of the notes started at this sample.
    fn make_pending_strikes(&mut self) {
        for i in 0..self.voices.len() {
            if let Some(p) = self.voices[i].pending_strike.take() {
                self.strike(i, p);
            }
        }
        let sounding = self.voices.iter().filter(|v| v.is_sounding()).count();
        self.peak_voices = self.peak_voices.max(sounding);
    }

    /// Strikes voice `i` with the engine's controls and the voice's own.
    fn strike(&mut self, i: usize, pending: PendingStrike) {
        if self.decay_stale != Stale::Fresh {
            self.rebuild_decay_table();
        }
        let release = self.release_decay();
        let c = &self.expressed;
        let v = &mut self.voices[i];
        let o = v.overrides;
        // On a contact note pressure is the contact's force, not a hand damping the object.
        v.contact = c.exciter.is_contact();
        let variation = c.strike_variation;
        (v.variation_semitones, v.variation_log_damping) = draw_variation(variation, &mut self.rng);
        if pending.fresh {
            v.log_pitch =
                target_log_pitch(c, self.bank.root_key, v.key, &o) + expression_log_pitch(v);
        }
        let tuning = tuning_of(v, self.damping_version, release);

        let c = &self.expressed;
        let vary = c.position_variation;
        let (mut x, mut y) = (
            o.strike_x.unwrap_or(c.strike_x),
            o.strike_y.unwrap_or(c.strike_y),
        );
        if vary > 0.0 {
            x += vary * self.rng.bipolar();
            y += vary * self.rng.bipolar();
        }
        let weights = self.bank.positions.weights(x, y);
        self.bank.gains_at(&weights, &mut self.strike_gains);
        vary_gains(variation, &mut self.rng, &mut self.strike_gains);
        // Force: velocity^(2 s); contact: up to 4x longer for soft notes.
        let velocity = pending.velocity;
        let amplitude = velocity.powf(2.0 * c.velocity_sensitivity);
        let hardness_ms = o.hardness_ms.unwrap_or(c.hardness_ms);
        let contact_ms = (hardness_ms * 4f32.powf(c.velocity_to_hardness * (1.0 - velocity)))
            .clamp(HARDNESS_RANGE_MS.0, HARDNESS_RANGE_MS.1);
        let len = (contact_ms as f64 * 1e-3 * self.sample_rate_hz)
            .round()
            .max(1.0) as u32;
        let threshold = db_to_gain(c.truncation_db);
        let kind = c.exciter;
        // A pulse under the root is held to the root's level (see `PitchLevel`); a contact's
        // force is its own.
        let amplitude = if kind.is_contact() {
            amplitude
        } else {
            amplitude * self.bank.pitch_level.at(self.voices[i].log_pitch)
        };
        // With pruning, modes the strike restarts are judged before they are computed. Started
        // dormant, they take only the pulses their bank knows of: while a strike it does not know
        // still plays (a noise burst, or one struck with pruning off), they are computed.
        let v = &self.voices[i];
        let start_dormant = c.pruning
            && kind.pulse_shape().is_some()
            && v.exciter.num_under_way() == v.modes.num_pulses_under_way();
        self.prepare_strike(i, kind);
        self.voices[i].strike(
            &self.bank,
            &self.decay,
            self.sample_rate_hz,
            tuning,
            &self.strike_gains,
            kind,
            amplitude,
            len,
            threshold,
            start_dormant,
        );
        // Pulses are noted whenever modes may start dormant, so those a later strike starts
        // within one take the rest of it.
        if start_dormant || self.voices[i].modes.num_dormant() > 0 {
            self.settle_strike(i, kind, amplitude, len);
        }
        if let Some(motion) = kind.contact() {
            self.start_contact(i, motion, amplitude, hardness_ms);
        }
    }

    /// Starts voice `i`'s contact moving as `motion` at velocity-derived force `amplitude`, its
    /// width from `hardness_ms`. A note released at the sample it started (a click on the
    /// strike pad, a note of no length) lets go of it at once.
    fn start_contact(&mut self, i: usize, motion: ContactMotion, amplitude: f32, hardness_ms: f32) {
        let c = &self.expressed;
        let v = &mut self.voices[i];
        v.contact_velocity = amplitude;
        let (speed, force) = contact_targets(c, v);
        let shape = contact_shape(c, motion, hardness_ms);
        v.exciter
            .start_contact(shape, c.roughness, self.sample_rate_hz, speed, force);
        if v.state != VoiceState::Held {
            v.exciter.release_contact();
        }
    }

    /// Renders a run of samples within one control period and with no events inside.
    fn render_run(&mut self, input: Option<&[f32]>, out_l: &mut [f32], out_r: &mut [f32]) {
        let n = out_l.len();
        let acc = &mut self.acc[..n];
        acc.fill([0.0; COLUMNS]);
        let x = &mut self.excitation[..n];
        let fade_step = (1.0 / (STEAL_FADE_S * self.sample_rate_hz)) as f32;
        for v in self.voices.iter_mut() {
            if v.state == VoiceState::Free && v.modes.num_live() == 0 {
                continue;
            }
            let driven = v.exciter.render(x);
            if v.state == VoiceState::Fading {
                let fade = &mut self.fade_acc[..n];
                fade.fill([0.0; COLUMNS]);
                drive_voice(v, self.kernel, driven, x, fade);
                for (a, f) in acc.iter_mut().zip(fade.iter()) {
                    v.fade_gain = (v.fade_gain - fade_step).max(0.0);
                    for j in 0..COLUMNS {
                        a[j] += v.fade_gain * f[j];
                    }
                }
                if v.fade_gain <= 0.0 {
                    end_voice(v, &mut self.ended, self.block_pos);
                }
            } else {
                drive_voice(v, self.kernel, driven, x, acc);
            }
        }
        self.drive_input_voice(input, n);

        let s = &mut self.smoothed;
        let target_gain = db_to_gain(self.expressed.output_gain_db);
        let gain_k = (1.0 - (-1.0 / (GAIN_SMOOTHING_S * self.sample_rate_hz)).exp()) as f32;
        // Pairwise sums: independent adds, not a chain of eight (one per column).
        const _: () = assert!(COLUMNS == 8);
        let mix = |a: &[f32; COLUMNS], w: &[f32; COLUMNS]| {
            let p: [f32; COLUMNS] = std::array::from_fn(|j| a[j] * w[j]);
            ((p[0] + p[1]) + (p[2] + p[3])) + ((p[4] + p[5]) + (p[6] + p[7]))
        };
        let acc = &self.acc[..n];
        if s.weight_ramp_left == 0 && s.gain + (target_gain - s.gain) * gain_k == s.gain {
            // Weights and gain settled: the same sums without the per-sample smoothing.
            let (weights, gain) = (s.weights, s.gain);
            for ((a, l), r) in acc.iter().zip(out_l.iter_mut()).zip(out_r.iter_mut()) {
                *l = mix(a, &weights.0) * gain;
                *r = mix(a, &weights.1) * gain;
            }
            return;
        }
        for ((a, l), r) in acc.iter().zip(out_l.iter_mut()).zip(out_r.iter_mut()) {
            if s.weight_ramp_left > 0 {
                s.weight_ramp_left -= 1;
                for j in 0..COLUMNS {
                    s.weights.0[j] += s.weight_step.0[j];
                    s.weights.1[j] += s.weight_step.1[j];
                }
                if s.weight_ramp_left == 0 {
                    s.weights = s.weight_target;
                }
            }
            s.gain += (target_gain - s.gain) * gain_k;
            let (sl, sr) = (mix(a, &s.weights.0), mix(a, &s.weights.1));
            *l = sl * s.gain;
            *r = sr * s.gain;
        }
    }

    /// Adds the input voice's output for the current run to `self.acc`, driven by `input`
    /// (non-finite samples count as silence). Input after truncation has retired modes starts
    /// every mode again, from where it is.
    fn drive_input_voice(&mut self, input: Option<&[f32]>, n: usize) {
        let Some(input) = input else {
            if let Some(v) = self.input_voice.as_mut().filter(|v| v.modes.num_live() > 0) {
                v.modes.process(self.kernel, None, &mut self.acc[..n]);
            }
            return;
        };
        // Smoothed per sample, so automation of the input gain does not zipper.
        let target_gain = db_to_gain(self.expressed.input_gain_db);
        let gain_k = (1.0 - (-1.0 / (INPUT_GAIN_SMOOTHING_S * self.sample_rate_hz)).exp()) as f32;
        let gain = &mut self.smoothed.input_gain;
        let x = &mut self.excitation[..n];
        let mut heard = false;
        for (xi, &s) in x.iter_mut().zip(input) {
            *gain += (target_gain - *gain) * gain_k;
            *xi = if s.is_finite() { *gain * s } else { 0.0 };
            heard |= *xi != 0.0;
        }
        if heard {
            self.input_heard = true;
            if self.input_dormant {
                self.input_dormant = false;
                if self.decay_stale != Stale::Fresh {
                    self.rebuild_decay_table();
                }
                let key = self
                    .last_key
                    .unwrap_or(self.bank.root_key.round().clamp(0.0, 127.0) as u8);
                let target = target_log_pitch(
                    &self.expressed,
                    self.bank.root_key,
                    key,
                    &VoiceOverrides::default(),
                );
                let weights = self
                    .bank
                    .positions
                    .weights(self.expressed.strike_x, self.expressed.strike_y);
                self.bank.gains_at(&weights, &mut self.strike_gains);
                let Some(v) = self.input_voice.as_mut() else {
                    return;
                };
                if v.modes.num_live() == 0 {
                    v.log_pitch = target;
                }
                let tuning = tuning_of(v, self.damping_version, 0.0);
                // Every mode in range; the strike itself adds nothing (amplitude 0).
                v.strike(
                    &self.bank,
                    &self.decay,
                    self.sample_rate_hz,
                    tuning,
                    &self.strike_gains,
                    ExciterKind::Impulse,
                    0.0,
                    1,
                    0.0,
                    false,
                );
                v.exciter.reset();
            }
        }
        let Some(v) = self.input_voice.as_mut() else {
            return;
        };
        let acc = &mut self.acc[..n];
        if heard {
            // Dormant modes cannot take input: compute them all again, in phase.
            if v.modes.num_dormant() + v.modes.num_fading() > 0 {
                v.modes.wake_all(next_tick(self.clock));
                self.pruner.note_input();
            }
            v.modes
                .process(self.kernel, Some(&self.excitation[..n]), acc);
        } else if v.modes.num_live() > 0 {
            v.modes.process(self.kernel, None, acc);
        }
    }
}

/// Advances voice `v`'s modes over a run, driven by `x` when `driven` (its exciter's strikes and
/// scrape or roll), and by its rub's friction sample by sample while it is rubbed.
fn drive_voice(v: &mut Voice, kernel: Kernel, driven: bool, x: &[f32], out: &mut [[f32; COLUMNS]]) {
    if v.exciter.is_rubbing() {
        let exciter = &mut v.exciter;
        v.modes.process_rubbed(
            kernel,
            x,
            |velocity, gain_sum| exciter.rub_force(velocity, gain_sum),
            out,
        );
    } else {
        v.modes.process(kernel, driven.then_some(x), out);
    }
}

/// One smoothing step from `current` towards `target` by fraction `k`, snapping to the target
/// once within `snap`.
fn step_towards(current: f64, target: f64, k: f64, snap: f64) -> f64 {
    let next = current + (target - current) * k;
    if (target - next).abs() <= snap || !next.is_finite() {
        target
    } else {
        next
    }
}

/// The pitch (natural log of the frequency ratio) a voice on `key` with `overrides` is heading
/// for, before per-note expression.
fn target_log_pitch(c: &Controls, root_key: f64, key: u8, overrides: &VoiceOverrides) -> f64 {
    let fine_tune_cents = overrides.fine_tune_cents.unwrap_or(c.fine_tune_cents);
    let size_ratio = overrides.size_ratio.unwrap_or(c.size_ratio);
    let semitones = c.key_tracking as f64 * (key as f64 - root_key)
        + fine_tune_cents as f64 / 100.0
        + c.pitch_bend_semitones as f64;
    semitones * std::f64::consts::LN_2 / 12.0 - (size_ratio as f64).ln()
}

/// A strike's random change of pitch (semitones) and decay (natural log of its multiplier) at
/// strike variation `variation`: none at 0.
fn draw_variation(variation: f32, rng: &mut Rng) -> (f32, f32) {
    if variation <= 0.0 {
        return (0.0, 0.0);
    }
    (
        variation * VARIATION_CENTS / 100.0 * rng.bipolar(),
        (1.0 + variation * VARIATION_DECAY * rng.bipolar()).ln(),
    )
}

/// Each mode's gain in `gains` moved at random within the variation's dB either way.
fn vary_gains(variation: f32, rng: &mut Rng, gains: &mut [f32]) {
    if variation > 0.0 {
        let spread = variation * VARIATION_GAIN_DB / DB_PER_NEPER;
        for g in gains {
            *g *= (spread * rng.bipolar()).exp();
        }
    }
}

/// Width of a scrape's contact per ms of hardness, in metres: the default 0.25 ms scrapes through
/// a quarter of a millimetre (a corner at 2 kHz at 0.5 m/s), a soft 5 ms through 5 mm.
const SCRAPE_WIDTH_M_PER_MS: f64 = 1e-3;

/// The contact a note held with `motion` plays, at hardness `hardness_ms`.
fn contact_shape(c: &Controls, motion: ContactMotion, hardness_ms: f32) -> ContactKind {
    match motion {
        ContactMotion::Scrape => ContactKind::Scrape {
            width_m: hardness_ms as f64 * SCRAPE_WIDTH_M_PER_MS,
        },
        ContactMotion::Roll => ContactKind::Roll {
            radius_m: c.rolling_radius_mm as f64 * 1e-3,
        },
        ContactMotion::Rub => ContactKind::Rub,
    }
}

/// Where a contact note's speed (m/s) and force are going: the note's own speed (its slide),
/// else its own contact speed (polyphonic modulation), else the contact speed; the note's own pressure once it
/// has pressed, else its own or the engine's contact force (which the channel's pressure or mod
/// wheel may set) times its velocity.
fn contact_targets(c: &Controls, v: &Voice) -> (f32, f32) {
    let o = &v.overrides;
    let speed = v
        .speed_m_per_s
        .unwrap_or(o.contact_speed_m_per_s.unwrap_or(c.contact_speed_m_per_s));
    let force = if v.pressed {
        v.pressure
    } else {
        o.contact_force.unwrap_or(c.contact_force) * v.contact_velocity
    };
    (speed, force)
}

/// The pitch offset of a voice's per-note tuning and its strike's variation, as a natural log of
/// the frequency ratio.
fn expression_log_pitch(v: &Voice) -> f64 {
    (v.tuning_semitones + v.variation_semitones) as f64 * std::f64::consts::LN_2 / 12.0
}

/// The tuning voice `v` should have, given the engine's decay table version and the release decay.
fn tuning_of(v: &Voice, damping_version: u64, release_decay_per_s: f64) -> Tuning {
    Tuning {
        log_pitch: v.log_pitch,
        damping_version,
        release_decay_per_s: if v.state == VoiceState::Released {
            release_decay_per_s
        } else {
            0.0
        },
        contact_decay_per_s: v.exciter.contact_damping_per_s(),
        // On a contact note pressure is the contact's force, not a hand damping the object.
        log_damping: v.variation_log_damping as f64
            + if v.contact {
                0.0
            } else {
                v.pressure as f64 * MAX_EXTRA_DAMPING.ln()
            },
    }
}
