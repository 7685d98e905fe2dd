//! The engines of one plugin instance: the one playing, the one fading out after a bank swap, and
//! those on their way in from the background thread and back to it to be dropped. The audio
//! thread never builds or drops an engine.

use crossbeam_channel::{Receiver, Sender};

use super::bank_loader::LoadedEngine;
use crate::engine::{BankCrossfade, Engine, Note, MAX_POLYPHONY};

/// Engines handed to the background thread at once, before one waits for room.
const TRASH_CAPACITY: usize = 8;

/// Engines kept on the audio thread while the trash is full.
const WAITING_SLOTS: usize = 4;

/// Built engines waiting for the audio thread.
const LOADED_CAPACITY: usize = 4;

/// Blocks without the requested bank before it is asked for again (a request or a built engine
/// can be lost when a queue is full).
const RETRY_BLOCKS: u32 = 256;

/// The background thread's ends of the channels.
pub struct BackgroundEnds {
    /// Where built engines go.
    pub loaded_tx: Sender<LoadedEngine>,
    /// Where old engines come from, to be dropped.
    pub trash_rx: Receiver<Box<Engine>>,
}

/// The audio thread's engines.
pub struct Engines {
    /// The engine playing; `None` until activated.
    pub current: Option<Box<Engine>>,
    /// The engine that played before the last swap, while it fades out.
    pub outgoing: BankCrossfade,
    /// Engines built by the background thread.
    loaded_rx: Receiver<LoadedEngine>,
    /// Engines to drop, for the background thread.
    trash_tx: Sender<Box<Engine>>,
    /// Old engines waiting for room in the trash.
    waiting: [Option<Box<Engine>>; WAITING_SLOTS],
    /// The bank generation last asked for.
    pub requested_generation: u64,
    /// The bank generation of the engine playing.
    pub playing_generation: u64,
    /// The polyphony the last request was made at.
    requested_polyphony: usize,
    /// Incremented on every activation: engines built for an earlier one are not used.
    pub epoch: u64,
    /// Blocks since the requested bank was last asked for.
    blocks_waiting: u32,
}

impl Engines {
    /// No engines yet, and the channels to the background thread; the outgoing engine takes up
    /// to `max_events` events per segment.
    pub fn new(max_events: usize) -> (Self, BackgroundEnds) {
        let (loaded_tx, loaded_rx) = crossbeam_channel::bounded(LOADED_CAPACITY);
        let (trash_tx, trash_rx) = crossbeam_channel::bounded(TRASH_CAPACITY);
        let engines = Self {
            current: None,
            outgoing: BankCrossfade::new(max_events),
            loaded_rx,
            trash_tx,
            waiting: Default::default(),
            requested_generation: 0,
            playing_generation: 0,
            requested_polyphony: 0,
            epoch: 0,
            blocks_waiting: 0,
        };
        (
            engines,
            BackgroundEnds {
                loaded_tx,
                trash_rx,
            },
        )
    }

    /// Starts over with `engine` for bank `generation` (on activation, off the audio thread):
    /// anything built for an earlier activation is ignored.
    pub fn activate(&mut self, engine: Box<Engine>, generation: u64) {
        self.current = Some(engine);
        drop(self.outgoing.take());
        self.epoch += 1;
        self.requested_generation = generation;
        self.playing_generation = generation;
        self.requested_polyphony = 0;
        while self.loaded_rx.try_recv().is_ok() {}
    }

    /// The bank generation to ask the background thread for, if any: a new one, one asked for
    /// long ago that has not arrived (and did not fail to load, per `failed_generation`), or the
    /// one playing again when `polyphony` outgrows its voices (the background thread builds
    /// engines with voices for the polyphony set then). Call once per block.
    pub fn request(
        &mut self,
        generation: u64,
        failed_generation: u64,
        polyphony: usize,
    ) -> Option<u64> {
        if generation != self.requested_generation {
            self.requested_generation = generation;
            self.requested_polyphony = polyphony;
            self.blocks_waiting = 0;
            return Some(generation);
        }
        let outgrown = self
            .current
            .as_ref()
            .is_some_and(|e| e.voice_capacity() < polyphony.min(MAX_POLYPHONY));
        if outgrown && self.requested_polyphony < polyphony {
            self.requested_polyphony = polyphony;
            self.blocks_waiting = 0;
            return Some(generation);
        }
        // A bank that failed to load is not asked for again, unless the one playing still
        // lacks the voices asked for (a rebuild for them lost to that failed bank): the failed
        // generation then holds the playing bank again.
        let settled = self.playing_generation == generation || failed_generation == generation;
        if settled && !outgrown {
            return None;
        }
        self.blocks_waiting += 1;
        if self.blocks_waiting >= RETRY_BLOCKS {
            self.blocks_waiting = 0;
            return Some(generation);
        }
        None
    }

    /// Swaps in an engine the background thread built for the current request, if one has
    /// arrived; the one playing fades out. `sample_rate_hz` is the rate now. Each note of the
    /// engine leaving goes to `ended` (the host can forget them: they take no more events).
    /// Returns whether any engine went to the trash.
    pub fn take_loaded(
        &mut self,
        sample_rate_hz: f32,
        last_key: Option<u8>,
        mut ended: impl FnMut(Note),
    ) -> bool {
        let mut trashed = self.flush_waiting();
        while let Ok(loaded) = self.loaded_rx.try_recv() {
            // Superseded by a newer request, or built for an earlier activation or another
            // sample rate: discard it. Otherwise swap it in and let the old one fade out.
            let wanted = loaded.generation == self.requested_generation
                && loaded.epoch == self.epoch
                && loaded.engine.sample_rate_hz() == sample_rate_hz;
            let old = if wanted {
                let mut engine = loaded.engine;
                engine.set_last_key(last_key);
                // The wheels are where the player left them.
                if let Some(current) = self.current.as_ref() {
                    engine.set_controllers(current.controllers());
                }
                self.playing_generation = loaded.generation;
                match self.current.replace(engine) {
                    Some(old) if !old.is_silent() => {
                        old.notes().for_each(&mut ended);
                        // A fade already under way is cut short by the newer swap.
                        self.outgoing.start(old)
                    }
                    old => old,
                }
            } else {
                Some(loaded.engine)
            };
            if let Some(old) = old {
                trashed |= self.discard(old);
            }
        }
        trashed
    }

    /// Ends the outgoing engine's fade at once (on a reset).
    pub fn drop_outgoing(&mut self) -> bool {
        match self.outgoing.take() {
            Some(engine) => self.discard(engine),
            None => false,
        }
    }

    /// Hands `engine` to the background thread to be dropped there, or keeps it until there is
    /// room. Returns whether it went to the background thread. Never drops it here: with every
    /// slot taken (the background thread stalled for many swaps) it is leaked instead, which
    /// costs memory but never the audio thread's time.
    pub fn discard(&mut self, engine: Box<Engine>) -> bool {
        match self.trash_tx.try_send(engine) {
            Ok(()) => true,
            Err(e) => {
                let engine = e.into_inner();
                match self.waiting.iter_mut().find(|w| w.is_none()) {
                    Some(slot) => *slot = Some(engine),
                    None => std::mem::forget(engine),
                }
                false
            }
        }
    }

    /// Retries the engines waiting for room in the trash. Returns whether any went.
    fn flush_waiting(&mut self) -> bool {
        let mut sent = false;
        for slot in self.waiting.iter_mut() {
            if let Some(engine) = slot.take() {
                match self.trash_tx.try_send(engine) {
                    Ok(()) => sent = true,
                    Err(e) => {
                        *slot = Some(e.into_inner());
                        break;
                    }
                }
            }
        }
        sent
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::bank::{Bank, Mode, Position};
    use crate::engine::PreparedBank;

    /// An engine playing a bank of `modes` modes, with voices reserved for `polyphony`.
    fn engine(modes: usize, polyphony: usize) -> Box<Engine> {
        let mut bank = Bank::new(
            "large",
            vec![Position {
                name: "a".into(),
                coords: vec![0.0],
            }],
        );
        bank.modes = (0..modes)
            .map(|i| Mode {
                freq_hz: 100.0 + i as f64,
                decay_per_s: 3.0,
                gains: vec![1.0],
            })
            .collect();
        let mut e = Box::new(Engine::new(Arc::new(PreparedBank::new(&bank))));
        e.reserve_voices(polyphony);
        e.prepare(48_000.0, 64);
        e
    }

    #[test]
    fn the_bank_playing_is_asked_for_again_when_the_polyphony_outgrows_its_voices() {
        let (mut engines, _background) = Engines::new(16);
        engines.activate(engine(20_000, 2), 1);
        let capacity = engines.current.as_ref().unwrap().voice_capacity();
        assert!(capacity < MAX_POLYPHONY, "{capacity}");
        // Within the voices: nothing to ask.
        assert_eq!(engines.request(1, 0, capacity), None);
        // Beyond them: the same bank once, not on every block while it is built.
        assert_eq!(engines.request(1, 0, capacity + 1), Some(1));
        assert_eq!(engines.request(1, 0, capacity + 1), None);
        // Higher still: asked again, for the new polyphony.
        assert_eq!(engines.request(1, 0, MAX_POLYPHONY), Some(1));
        // A lost request is repeated.
        let repeats = (0..RETRY_BLOCKS).filter_map(|_| engines.request(1, 0, MAX_POLYPHONY));
        assert_eq!(repeats.count(), 1);
        // A new bank supersedes the rebuild, then fails to load: the bank playing still lacks
        // the voices, and the failed generation (which holds it again) is asked for.
        assert_eq!(engines.request(2, 0, MAX_POLYPHONY), Some(2));
        let repeats = (0..RETRY_BLOCKS).filter_map(|_| engines.request(2, 2, MAX_POLYPHONY));
        assert_eq!(repeats.collect::<Vec<_>>(), [2]);

        // A small bank has every voice: no polyphony needs a rebuild.
        let (mut engines, _background) = Engines::new(16);
        engines.activate(engine(100, 2), 1);
        for polyphony in [1, 16, MAX_POLYPHONY, 1_000] {
            assert_eq!(engines.request(1, 0, polyphony), None, "{polyphony}");
        }
    }
}
