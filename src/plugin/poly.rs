//! The host's polyphonic modulation offsets, per note id, so a change of a parameter's own value
//! (mono automation) can move every modulated note with it.

use crate::params::poly_id;

/// One modulated note.
#[derive(Debug, Clone, Copy)]
struct Entry {
    /// The host's note id.
    id: i32,
    /// Normalised offset of each parameter, by polyphonic modulation id.
    offsets: [Option<f32>; poly_id::COUNT],
}

/// Offsets of the notes the host modulates. Fixed capacity: never allocates after `new`.
#[derive(Debug)]
pub struct PolyTable {
    /// The notes, in no order.
    entries: Vec<Entry>,
}

impl PolyTable {
    /// Room for `capacity` notes; more are not tracked (their modulation still applies, but no
    /// longer follows mono automation).
    pub fn new(capacity: usize) -> Self {
        Self {
            entries: Vec::with_capacity(capacity),
        }
    }

    /// Records `offset` for parameter `poly_id` of note `id`.
    pub fn set(&mut self, id: i32, poly_id: u32, offset: f32) {
        let slot = poly_id as usize;
        if slot >= poly_id::COUNT {
            return;
        }
        let entry = match self.entries.iter().position(|e| e.id == id) {
            Some(i) => &mut self.entries[i],
            None if self.entries.len() < self.entries.capacity() => {
                self.entries.push(Entry {
                    id,
                    offsets: [None; poly_id::COUNT],
                });
                self.entries.last_mut().expect("just pushed")
            }
            None => return,
        };
        entry.offsets[slot] = Some(offset);
    }

    /// The notes with an offset for parameter `poly_id`, and the offset.
    pub fn offsets(&self, poly_id: u32) -> impl Iterator<Item = (i32, f32)> + '_ {
        self.entries.iter().filter_map(move |e| {
            e.offsets
                .get(poly_id as usize)
                .copied()
                .flatten()
                .map(|o| (e.id, o))
        })
    }

    /// Forgets note `id` (it has ended).
    pub fn remove(&mut self, id: i32) {
        if let Some(i) = self.entries.iter().position(|e| e.id == id) {
            self.entries.swap_remove(i);
        }
    }

    /// Keeps only the notes for which `keep` holds.
    pub fn retain(&mut self, mut keep: impl FnMut(i32) -> bool) {
        self.entries.retain(|e| keep(e.id));
    }

    /// Forgets every note.
    pub fn clear(&mut self) {
        self.entries.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offsets_follow_their_notes_until_removed() {
        let mut t = PolyTable::new(2);
        t.set(7, poly_id::SIZE, 0.1);
        t.set(9, poly_id::SIZE, -0.2);
        t.set(9, poly_id::FINE_TUNE, 0.3);
        // Full: a third note is not tracked.
        t.set(11, poly_id::SIZE, 0.5);
        let mut sizes: Vec<_> = t.offsets(poly_id::SIZE).collect();
        sizes.sort_by_key(|e| e.0);
        assert_eq!(sizes, vec![(7, 0.1), (9, -0.2)]);
        assert_eq!(
            t.offsets(poly_id::FINE_TUNE).collect::<Vec<_>>(),
            vec![(9, 0.3)]
        );
        t.remove(9);
        assert_eq!(t.offsets(poly_id::FINE_TUNE).count(), 0);
        t.set(11, poly_id::STRIKE_X, 0.5);
        assert_eq!(
            t.offsets(poly_id::STRIKE_X).collect::<Vec<_>>(),
            vec![(11, 0.5)]
        );
        // Unknown ids are ignored.
        t.set(11, 99, 1.0);
        assert_eq!(t.offsets(99).count(), 0);
    }
}
