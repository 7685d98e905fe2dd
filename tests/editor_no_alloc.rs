//! What the audio thread does for the editor never allocates: measuring blocks and publishing
//! meters and mode energies, taking strike-pad requests and turning them into notes. A counting
//! global allocator watches it while a struck bank rings.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::Arc;
use std::time::Duration;

use modal_resonator::bank::factory::factory_bank;
use modal_resonator::editor::{Audition, EditorShared};
use modal_resonator::engine::{Controls, Engine, NoteEvent, PreparedBank};

struct Counting;

thread_local! {
    /// Allocations and frees made on this thread while `WATCHING` is set.
    static COUNT: Cell<usize> = const { Cell::new(0) };
    static WATCHING: Cell<bool> = const { Cell::new(false) };
}

fn count() {
    if WATCHING.with(|w| w.get()) {
        COUNT.with(|c| c.set(c.get() + 1));
    }
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        count();
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Runs `f` and returns how many allocations and frees it made on this thread.
fn allocations_in(f: impl FnOnce()) -> usize {
    COUNT.with(|c| c.set(0));
    WATCHING.with(|w| w.set(true));
    f();
    WATCHING.with(|w| w.set(false));
    COUNT.with(|c| c.get())
}

#[test]
fn metering_and_auditions_never_allocate_on_the_audio_thread() {
    let bank = factory_bank("steel-plate").unwrap();
    let mut engine = Engine::new(Arc::new(PreparedBank::new(&bank)));
    engine.prepare(48_000.0, 512);
    // Pruning on, so the meters publish switched-off modes too.
    let mut c = Controls::for_bank(&bank);
    c.pruning = true;
    engine.set_controls(&c);
    let shared = EditorShared::new();
    let block = 128;
    let (mut l, mut r) = (vec![0.0f32; block], vec![0.0f32; block]);
    let mut events = Vec::with_capacity(16);
    // Requests the GUI queued, taken by the audio thread while watched.
    for x in [0.1, 0.5, 0.9] {
        assert!(shared.request(Audition::Strike {
            x,
            y: 0.4,
            velocity: 0.9
        }));
        assert!(shared.request(Audition::Release));
    }
    let allocations = allocations_in(|| {
        for b in 0..400 {
            events.clear();
            if b % 50 == 0 {
                events.push(NoteEvent::on(0, 60 + (b / 50) as u8, 1.0));
            }
            while let Some(audition) = shared.next_audition() {
                events.extend(audition.events(64));
            }
            engine.process(&events, None, &mut l, &mut r);
            let channels: [&mut [f32]; 2] = [&mut l, &mut r];
            shared.measure_block(
                Some(&engine),
                3,
                &channels,
                Duration::from_micros(300),
                48_000.0,
            );
        }
    });
    assert_eq!(allocations, 0, "allocations or frees on the audio thread");
    assert!(shared.serial() > 10, "meters were published");
    let (mut energies, mut pruned) = (Vec::new(), Vec::new());
    assert!(shared.read_energies(3, &mut energies, &mut pruned));
    assert!(energies.iter().any(Option::is_some), "modes sound");
    assert_eq!(pruned.len(), energies.len());
}
