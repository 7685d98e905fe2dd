//! One sounding object of a scene: its engine, the events that sound it, and the two paths from
//! it to the listener's ears.

use std::sync::Arc;

use super::listener::{HeadShadow, Placement};
use crate::engine::{Controls, Engine, NoteEvent, PreparedBank};
use crate::render::TimedEvent;

/// Longest delay between an object's sound and an ear beyond the events' own shift, in samples:
/// the interaural difference (0.66 ms: 127 samples at 192 kHz) and a sample of rounding.
const EAR_DELAY_CAPACITY: usize = 256;

/// A fractional delay of at most [`EAR_DELAY_CAPACITY`] samples, by linear interpolation.
#[derive(Debug, Clone)]
struct FracDelay {
    /// The last samples, a ring.
    ring: Box<[f32; EAR_DELAY_CAPACITY]>,
    /// Where the next sample goes.
    head: usize,
    /// Whole samples of delay.
    whole: usize,
    /// Fraction of a sample more, 0 to 1.
    frac: f32,
}

impl FracDelay {
    fn new(delay_samples: f64) -> Self {
        let d = delay_samples.clamp(0.0, (EAR_DELAY_CAPACITY - 2) as f64);
        Self {
            ring: Box::new([0.0; EAR_DELAY_CAPACITY]),
            head: 0,
            whole: d.floor() as usize,
            frac: (d - d.floor()) as f32,
        }
    }

    #[inline]
    fn tick(&mut self, x: f32) -> f32 {
        let mask = EAR_DELAY_CAPACITY - 1;
        self.ring[self.head] = x;
        let a = self.ring[(self.head + EAR_DELAY_CAPACITY - self.whole) & mask];
        let b = self.ring[(self.head + EAR_DELAY_CAPACITY - self.whole - 1) & mask];
        self.head = (self.head + 1) & mask;
        a + self.frac * (b - a)
    }

    /// Whether what it holds has all come out (or is silent).
    fn is_empty(&self) -> bool {
        self.ring.iter().all(|&v| v == 0.0)
    }
}

/// One ear's path from an object: the delay left after the events' shift, the head shadow, the
/// gain.
#[derive(Debug, Clone)]
struct EarPath {
    delay: FracDelay,
    shadow: HeadShadow,
    gain: f32,
}

/// One way an object is sounded (struck, or scraped, rolled or rubbed): an engine of its own
/// with the exciter for it, and its events.
struct Part {
    /// The engine, playing the object's bank (the air's absorption over its distance applied to
    /// the modes).
    engine: Engine,
    /// Its events, at the samples the listener hears them begin: when they happen plus the
    /// time sound takes to arrive, whole samples.
    events: Vec<TimedEvent>,
    /// The next event not yet played.
    next: usize,
    /// Gain of its output.
    gain: f32,
}

/// An object as it sounds at the listener.
pub(super) struct SoundingObject {
    /// Its strikes, and its contacts: each an engine with its events.
    parts: Vec<Part>,
    /// Left ear, right ear.
    ears: [EarPath; 2],
    /// Events of the block in hand.
    block_events: Vec<NoteEvent>,
    /// The object's sound in the block in hand: its parts' left outputs summed (width 0: the
    /// right is the same).
    left: Vec<f32>,
    /// An engine's right output, unused.
    right: Vec<f32>,
    /// An engine's left output.
    scratch: Vec<f32>,
    /// Whether it has played and fallen silent, delays included.
    done: bool,
}

impl SoundingObject {
    /// An object playing `bank`, each of `parts` with its controls, its events timed where
    /// they happen (shifted here by the travel time) and its gain, heard as `placement` says
    /// through `gain`. `max_block` is at least 1.
    pub fn new(
        bank: &Arc<PreparedBank>,
        parts: Vec<(Controls, Vec<TimedEvent>, f64)>,
        placement: &Placement,
        gain: f64,
        sample_rate_hz: f64,
        max_block: usize,
    ) -> Self {
        let delays = placement.ears.map(|e| e.delay_s * sample_rate_hz);
        let shift = delays[0].min(delays[1]).floor().max(0.0) as u64;
        let parts: Vec<Part> = parts
            .into_iter()
            .map(|(controls, mut events, part_gain)| {
                let mut engine = Engine::new(Arc::clone(bank));
                engine.set_controls(&controls);
                engine.reserve_voices(controls.polyphony);
                engine.prepare(sample_rate_hz as f32, max_block);
                for e in &mut events {
                    e.sample += shift;
                }
                Part {
                    engine,
                    events,
                    next: 0,
                    gain: part_gain as f32,
                }
            })
            .collect();
        let most_in_a_block = parts_most_in_a_block(&parts, max_block);
        let shift = shift as f64;
        let ears = [0, 1].map(|k| {
            let ear = &placement.ears[k];
            EarPath {
                delay: FracDelay::new(delays[k] - shift),
                // Alpha 1 (stereo) passes every sample unchanged.
                shadow: HeadShadow::new(ear.shadow_alpha, sample_rate_hz),
                gain: (gain * ear.gain) as f32,
            }
        });
        Self {
            parts,
            ears,
            block_events: Vec::with_capacity(most_in_a_block),
            left: vec![0.0; max_block],
            right: vec![0.0; max_block],
            scratch: vec![0.0; max_block],
            done: false,
        }
    }

    /// Adds its next `left.len()` samples at the listener to `left` and `right`, the block
    /// starting at sample `start`. Never allocates: the events of a block fit the storage
    /// sized for the fullest block.
    pub fn add_to(&mut self, start: u64, left: &mut [f32], right: &mut [f32]) {
        if self.done {
            return;
        }
        let len = left.len();
        let end = start + len as u64;
        let (l, r) = (&mut self.left[..len], &mut self.right[..len]);
        l.fill(0.0);
        let mut silent = true;
        let mut sounded = false;
        for part in &mut self.parts {
            let waiting = part.events.get(part.next).is_some_and(|e| e.sample >= end);
            if (waiting || part.next == part.events.len()) && part.engine.is_silent() {
                silent &= !waiting;
                continue;
            }
            sounded = true;
            self.block_events.clear();
            while part.next < part.events.len() && part.events[part.next].sample < end {
                let e = &part.events[part.next];
                self.block_events
                    .push(e.event.at((e.sample - start) as u32));
                part.next += 1;
            }
            // Engines write their output; each part's is added to the object's.
            let (pl, pr) = (&mut self.scratch[..len], &mut r[..]);
            pl.fill(0.0);
            pr.fill(0.0);
            part.engine.process(&self.block_events, None, pl, pr);
            for (o, &x) in l.iter_mut().zip(pl.iter()) {
                *o += part.gain * x;
            }
            silent &= part.next == part.events.len() && part.engine.is_silent();
        }
        if !sounded && self.ears.iter().all(|e| e.delay.is_empty()) {
            self.done = silent;
            return;
        }
        for (k, out) in [left, right].into_iter().enumerate() {
            let ear = &mut self.ears[k];
            for (o, &x) in out.iter_mut().zip(self.left.iter()) {
                *o += ear.gain * ear.shadow.tick(ear.delay.tick(x));
            }
        }
        self.done = silent && self.ears.iter().all(|e| e.delay.is_empty());
    }

    /// Whether it has played every event and fallen silent.
    pub fn is_done(&self) -> bool {
        self.done
    }

    /// The sample at the listener of its last event, if it has any.
    pub fn last_event_sample(&self) -> Option<u64> {
        self.parts
            .iter()
            .filter_map(|p| p.events.last())
            .map(|e| e.sample)
            .max()
    }
}

/// The most events of any one part that fall within `max_block` samples of each other: what a
/// block can hold, so that playing never allocates.
fn parts_most_in_a_block(parts: &[Part], max_block: usize) -> usize {
    parts
        .iter()
        .map(|p| {
            let mut first = 0;
            let mut most = 0;
            for (last, e) in p.events.iter().enumerate() {
                while e.sample - p.events[first].sample >= max_block as u64 {
                    first += 1;
                }
                most = most.max(last + 1 - first);
            }
            most
        })
        .max()
        .unwrap_or(0)
}
