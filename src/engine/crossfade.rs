//! The engine that played before a bank swap, fading out under the new one: it keeps sounding
//! the notes it had, follows the channel-wide controllers (the wheels move both engines), and
//! takes no new notes.

use super::mix::FadeOut;
use super::{Controls, Engine, NoteEvent};

/// The outgoing engine after a bank swap, and the buffers it is rendered into; sized by
/// [`BankCrossfade::prepare`], so rendering it never allocates.
pub struct BankCrossfade {
    /// The engine fading out, if any.
    engine: Option<Box<Engine>>,
    /// Its fade to silence.
    fade: FadeOut,
    /// Scratch: the channel-wide controller events of the part of the block being rendered.
    events: Vec<NoteEvent>,
    /// Scratch: its output, before it is faded into the mix.
    out: [Vec<f32>; 2],
}

impl BankCrossfade {
    /// No engine fading out; room for `max_events` controller events per segment.
    pub fn new(max_events: usize) -> Self {
        Self {
            engine: None,
            fade: FadeOut::new(),
            events: Vec::with_capacity(max_events),
            out: [Vec::new(), Vec::new()],
        }
    }

    /// Sizes the output buffers for segments of up to `max_block` samples (may allocate).
    pub fn prepare(&mut self, max_block: usize) {
        self.out = [vec![0.0; max_block], vec![0.0; max_block]];
    }

    /// Whether an engine is fading out.
    pub fn is_active(&self) -> bool {
        self.engine.is_some()
    }

    /// Starts fading `engine` out from full gain. Returns the engine whose fade it cuts short,
    /// if one was under way, to be dropped off the audio thread.
    pub fn start(&mut self, engine: Box<Engine>) -> Option<Box<Engine>> {
        self.fade = FadeOut::new();
        self.engine.replace(engine)
    }

    /// Ends the fade at once. Returns the engine that was fading, to be dropped off the audio
    /// thread.
    pub fn take(&mut self) -> Option<Box<Engine>> {
        self.engine.take()
    }

    /// Renders the outgoing engine for one segment with `controls`, the controller events among
    /// `events` and `drive` (the direct input, if any), and adds it, faded, to `out`. Returns
    /// the engine when its fade has ended (or it fell silent), its voices ended, to be dropped
    /// off the audio thread. At most [`Self::prepare`]'s `max_block` samples.
    pub fn add_to(
        &mut self,
        out: [&mut [f32]; 2],
        controls: &Controls,
        events: &[NoteEvent],
        drive: Option<&[f32]>,
    ) -> Option<Box<Engine>> {
        let engine = self.engine.as_mut()?;
        let n = out[0].len();
        let [ol, or] = &mut self.out;
        let (ol, or) = (&mut ol[..n], &mut or[..n]);
        engine.set_controls(controls);
        self.events.clear();
        self.events.extend(
            events
                .iter()
                .filter(|e| matches!(e, NoteEvent::Controller { .. })),
        );
        engine.process(&self.events, drive, ol, or);
        let rate = engine.sample_rate_hz();
        self.fade.add(out, [ol, or], rate);
        // Nothing to tell the host: its notes were reported ended at the swap.
        let _ = engine.take_ended_voices().count();
        if !(self.fade.is_done() || engine.is_silent()) {
            return None;
        }
        let mut done = self.engine.take()?;
        done.end_all_voices();
        let _ = done.take_ended_voices().count();
        Some(done)
    }
}
