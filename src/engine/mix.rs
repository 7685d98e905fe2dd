//! What is mixed around an engine: its audio input taken to mono, strikes at the input's onsets,
//! the fade of an outgoing engine after a bank swap, and the output stage: the dry/wet mix, the
//! bypass fade and the flush of subnormals. Each keeps its own state between blocks, so a change
//! of setting ramps instead of clicking, and none allocates.

use super::NoteEvent;
use crate::dsp::denormal::flush_subnormals;
use crate::dsp::onset::OnsetDetector;

/// How long the engine playing before a bank swap fades out, in seconds.
pub const BANK_CROSSFADE_S: f32 = 0.05;

/// How long the bypass takes to fade in or out, in seconds.
pub const BYPASS_FADE_S: f32 = 0.01;

/// `out = (left + right) / 2`.
pub fn mix_to_mono(left: &[f32], right: &[f32], out: &mut [f32]) {
    for ((o, l), r) in out.iter_mut().zip(left).zip(right) {
        *o = 0.5 * (l + r);
    }
}

/// Strikes at the onsets of an audio input (the trigger input mode).
#[derive(Debug, Clone)]
pub struct OnsetTrigger {
    /// Finds the onsets.
    detector: OnsetDetector,
}

impl OnsetTrigger {
    /// A trigger at `sample_rate_hz`, at rest.
    pub fn new(sample_rate_hz: f32) -> Self {
        Self {
            detector: OnsetDetector::new(sample_rate_hz),
        }
    }

    /// Forgets the input heard so far.
    pub fn reset(&mut self) {
        self.detector.reset();
    }

    /// Adds a strike of `key` at each onset of `input` louder than `threshold` (linear), at most
    /// one per `retrigger_s`, to `events` (timed from the start of `input`), keeping them in time
    /// order, after events at the same time; `events` never grows past `max_events` nor its
    /// capacity, so this never allocates.
    pub fn add_strikes(
        &mut self,
        input: &[f32],
        threshold: f32,
        retrigger_s: f32,
        key: u8,
        events: &mut Vec<NoteEvent>,
        max_events: usize,
    ) {
        let max_events = max_events.min(events.capacity());
        self.detector
            .process(input, threshold, retrigger_s, |onset| {
                if events.len() < max_events {
                    let at = events.partition_point(|e| e.time() <= onset.time);
                    events.insert(at, NoteEvent::on(onset.time, key, onset.strength));
                }
            });
    }
}

/// An engine's output fading out over [`BANK_CROSSFADE_S`] after a bank swap.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FadeOut {
    /// The gain now, 1 down to 0.
    gain: f32,
}

impl Default for FadeOut {
    fn default() -> Self {
        Self::new()
    }
}

impl FadeOut {
    /// At full gain.
    pub const fn new() -> Self {
        Self { gain: 1.0 }
    }

    /// Adds `from` to `out`, channel by channel, at a gain falling linearly to zero over
    /// [`BANK_CROSSFADE_S`] at `sample_rate_hz`.
    pub fn add(&mut self, out: [&mut [f32]; 2], from: [&[f32]; 2], sample_rate_hz: f32) {
        let step = 1.0 / (BANK_CROSSFADE_S * sample_rate_hz).max(1.0);
        let [out_l, out_r] = out;
        let [from_l, from_r] = from;
        for ((l, r), (a, b)) in out_l
            .iter_mut()
            .zip(out_r.iter_mut())
            .zip(from_l.iter().zip(from_r))
        {
            self.gain = (self.gain - step).max(0.0);
            *l += self.gain * a;
            *r += self.gain * b;
        }
    }

    /// Whether the fade has reached silence.
    pub fn is_done(&self) -> bool {
        self.gain <= 0.0
    }
}

/// The dry/wet mix of an input with the engine's output, ramped from one block's setting to the
/// next so automation does not zipper.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct DryWet {
    /// The wet share at the end of the last block; `None` after a reset (no ramp needed).
    wet: Option<f32>,
}

impl DryWet {
    /// Forgets the last setting: the next block starts at its own.
    pub fn reset(&mut self) {
        self.wet = None;
    }

    /// Mixes each channel of `out` (wet) with the same channel of `dry`, at a wet share ramping
    /// from the last block's to `wet` (0 dry, 1 wet) over the block.
    pub fn mix(&mut self, out: [&mut [f32]; 2], dry: [&[f32]; 2], wet: f32) {
        let to = wet.clamp(0.0, 1.0);
        let from = self.wet.unwrap_or(to);
        for (channel, dry) in out.into_iter().zip(dry) {
            let step = (to - from) / channel.len().max(1) as f32;
            for (i, (o, d)) in channel.iter_mut().zip(dry).enumerate() {
                let wet = from + step * (i + 1) as f32;
                *o = wet * *o + (1.0 - wet) * d;
            }
        }
        self.wet = Some(to);
    }
}

/// The host's bypass: a fade over [`BYPASS_FADE_S`] from the output to the dry input (an
/// effect's) or to silence (an instrument's).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Bypass {
    /// Share bypassed at the end of the last block (0 playing, 1 bypassed); `None` after a
    /// reset (no fade needed).
    share: Option<f32>,
}

impl Bypass {
    /// Forgets the last state: the next block starts at its own.
    pub fn reset(&mut self) {
        self.share = None;
    }

    /// Fades each channel of `out` toward the same channel of `dry` (silence where `dry` is
    /// `None`) while `bypassed`, back while not, at `sample_rate_hz`.
    pub fn apply(
        &mut self,
        out: [&mut [f32]; 2],
        dry: Option<[&[f32]; 2]>,
        bypassed: bool,
        sample_rate_hz: f32,
    ) {
        let to = if bypassed { 1.0 } else { 0.0 };
        let from = self.share.unwrap_or(to);
        self.share = Some(to);
        if from == 0.0 && to == 0.0 {
            return;
        }
        let step = 1.0 / (BYPASS_FADE_S * sample_rate_hz).max(1.0);
        for (c, channel) in out.into_iter().enumerate() {
            let mut share = from;
            for (i, o) in channel.iter_mut().enumerate() {
                share = if to > share {
                    (share + step).min(to)
                } else {
                    (share - step).max(to)
                };
                let d = dry.map_or(0.0, |dry| dry[c].get(i).copied().unwrap_or(0.0));
                *o = (1.0 - share) * *o + share * d;
            }
            self.share = Some(share);
        }
    }
}

/// The last stage before the host: the dry/wet mix with the input, the host's bypass, and no
/// subnormal sample out (a dry path copies what the host sends, and the plugins after this one
/// may not flush).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct OutputStage {
    /// The dry/wet mix, ramped from segment to segment.
    dry_wet: DryWet,
    /// The host's bypass, faded.
    bypass: Bypass,
}

impl OutputStage {
    /// Forgets the last settings: the next block starts at its own.
    pub fn reset(&mut self) {
        self.dry_wet.reset();
        self.bypass.reset();
    }

    /// Finishes `out`, the engine's output: mixed with `input` (the effect's input, or the
    /// instrument's exciter input, if any) at `wet`, then faded toward the input while
    /// `bypassed` when `bypass_to_input` (an effect), else toward silence, at `sample_rate_hz`.
    pub fn apply(
        &mut self,
        out: [&mut [f32]; 2],
        input: Option<[&[f32]; 2]>,
        wet: f32,
        bypassed: bool,
        bypass_to_input: bool,
        sample_rate_hz: f32,
    ) {
        let [out_l, out_r] = out;
        if let Some(dry) = input {
            self.dry_wet.mix([&mut *out_l, &mut *out_r], dry, wet);
        }
        let dry = input.filter(|_| bypass_to_input);
        self.bypass
            .apply([&mut *out_l, &mut *out_r], dry, bypassed, sample_rate_hz);
        flush_subnormals(out_l);
        flush_subnormals(out_r);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const RATE: f32 = 48_000.0;

    fn steps(x: &[f32]) -> f32 {
        x.windows(2)
            .map(|w| (w[1] - w[0]).abs())
            .fold(0.0, f32::max)
    }

    #[test]
    fn the_outgoing_engine_fades_to_silence_in_the_crossfade_time() {
        let mut fade = FadeOut::new();
        let block = 64;
        let from = vec![1.0f32; block];
        let mut heard = Vec::new();
        while !fade.is_done() {
            let (mut l, mut r) = (vec![0.0f32; block], vec![0.0f32; block]);
            fade.add([&mut l, &mut r], [&from, &from], RATE);
            assert_eq!(l, r);
            heard.extend(l);
            assert!(heard.len() < 10 * RATE as usize, "never done");
        }
        let len_s = heard.iter().position(|&v| v == 0.0).unwrap() as f32 / RATE;
        assert!((len_s - BANK_CROSSFADE_S).abs() < 2.0 / RATE, "{len_s} s");
        assert!(heard.windows(2).all(|w| w[1] <= w[0]));
        assert!(steps(&heard) <= 1.01 / (BANK_CROSSFADE_S * RATE));
    }

    #[test]
    fn dry_wet_ramps_over_a_block_and_holds_after() {
        let mut mix = DryWet::default();
        let (dry, n) = (vec![1.0f32; 100], 100);
        // First block: at its setting at once (no ramp from nothing).
        let (mut l, mut r) = (vec![0.0f32; n], vec![0.0f32; n]);
        mix.mix([&mut l, &mut r], [&dry, &dry], 1.0);
        assert!(l.iter().all(|&v| v == 0.0));
        // Turned fully dry: a straight ramp over the next block, ending dry.
        let (mut l, mut r) = (vec![0.0f32; n], vec![0.0f32; n]);
        mix.mix([&mut l, &mut r], [&dry, &dry], 0.0);
        assert!(
            (l[n - 1] - 1.0).abs() < 1e-6 && (l[0] - 0.01).abs() < 1e-6,
            "{l:?}"
        );
        assert!(steps(&l) < 0.0101 && l == r);
        // Held: the next block is dry throughout.
        let (mut l, mut r) = (vec![0.0f32; n], vec![0.0f32; n]);
        mix.mix([&mut l, &mut r], [&dry, &dry], 0.0);
        assert!(l.iter().all(|&v| (v - 1.0).abs() < 1e-6));
        // Out-of-range settings are held to 0..1.
        let (mut l, mut r) = (vec![0.5f32; n], vec![0.5f32; n]);
        mix.reset();
        mix.mix([&mut l, &mut r], [&dry, &dry], 7.0);
        assert!(l.iter().all(|&v| v == 0.5));
    }

    #[test]
    fn bypass_fades_to_the_dry_input_or_silence_without_a_click() {
        for dry_in in [true, false] {
            let mut bypass = Bypass::default();
            let dry = vec![0.25f32; 2048];
            let dry_pair = dry_in.then_some([dry.as_slice(), dry.as_slice()]);
            // Playing: untouched.
            let (mut l, mut r) = (vec![1.0f32; 256], vec![1.0f32; 256]);
            bypass.apply([&mut l, &mut r], dry_pair, false, RATE);
            assert!(l.iter().chain(&r).all(|&v| v == 1.0));
            // Bypassed: a fade over 10 ms to the dry input, in steps no larger than the fade's.
            let (mut l, mut r) = (vec![1.0f32; 2048], vec![1.0f32; 2048]);
            bypass.apply([&mut l, &mut r], dry_pair, true, RATE);
            let target = if dry_in { 0.25 } else { 0.0 };
            let fade = (BYPASS_FADE_S * RATE) as usize;
            assert!(
                (l[fade + 1] - target).abs() < 1e-6 && l == r,
                "{}",
                l[fade + 1]
            );
            assert!(l[fade / 2] > target + 0.3);
            assert!(steps(&l) <= 1.01 / fade as f32);
            // And back.
            let (mut l, mut r) = (vec![1.0f32; 2048], vec![1.0f32; 2048]);
            bypass.apply([&mut l, &mut r], dry_pair, false, RATE);
            assert!((l[0] - target).abs() < 0.01 && l[fade + 1] == 1.0);
        }
    }

    #[test]
    fn the_output_stage_lets_no_subnormal_out() {
        let mut stage = OutputStage::default();
        let tiny = f32::MIN_POSITIVE / 4.0;
        let (mut l, mut r) = (vec![tiny; 64], vec![-tiny; 64]);
        let dry = vec![tiny; 64];
        stage.apply([&mut l, &mut r], Some([&dry, &dry]), 0.5, false, true, RATE);
        assert!(l.iter().chain(&r).all(|&v| v == 0.0), "{l:?} {r:?}");
    }

    #[test]
    fn strikes_land_at_the_inputs_onsets_in_time_order() {
        let mut trigger = OnsetTrigger::new(RATE);
        // Quiet, then a tap at sample 1000 and another half a second later.
        let mut input = vec![0.0f32; 30_000];
        for at in [1000, 25_000] {
            for (k, v) in input[at..at + 200].iter_mut().enumerate() {
                *v = 0.8 * (-(k as f32) / 40.0).exp() * if k % 2 == 0 { 1.0 } else { -1.0 };
            }
        }
        let mut events = Vec::with_capacity(16);
        events.extend([NoteEvent::off(0, 60), NoteEvent::on(2000, 64, 0.5)]);
        trigger.add_strikes(&input, 0.05, 0.05, 67, &mut events, 16);
        let times: Vec<u32> = events.iter().map(|e| e.time()).collect();
        assert_eq!(events.len(), 4, "{events:?}");
        assert!(times.windows(2).all(|w| w[0] <= w[1]), "{times:?}");
        let strikes: Vec<&NoteEvent> = events
            .iter()
            .filter(|e| matches!(e, NoteEvent::On { note, .. } if note.key == 67))
            .collect();
        assert_eq!(strikes.len(), 2);
        for (strike, at) in strikes.iter().zip([1000, 25_000]) {
            assert!((at..at + 48).contains(&strike.time()), "{strike:?}");
        }
        // Never past the limit, nor the room the events have.
        let mut full = vec![NoteEvent::off(0, 60); 16];
        trigger.reset();
        trigger.add_strikes(&input, 0.05, 0.05, 67, &mut full, 16);
        assert_eq!(full.len(), 16);
        let mut no_room = Vec::with_capacity(1);
        no_room.push(NoteEvent::off(0, 60));
        trigger.reset();
        trigger.add_strikes(&input, 0.05, 0.05, 67, &mut no_room, 16);
        assert_eq!((no_room.len(), no_room.capacity()), (1, 1));
    }

    #[test]
    fn mono_is_the_mean_of_the_channels() {
        let mut out = [0.0f32; 3];
        mix_to_mono(&[1.0, 0.0, -1.0], &[0.0, 1.0, 1.0], &mut out);
        assert_eq!(out, [0.5, 0.5, 0.0]);
    }
}
