//! The energies of the modes the budget kept at its last ranking, to one dB, so that a strike can
//! tell at once how many of the modes it excites the budget would keep: those it wakes and plays
//! from their first sample, and the next control tick ranks everything again.

/// Energy buckets, one dB each, from [`LOWEST_DB`] up (anything outside goes to the end buckets).
const BUCKETS: usize = 320;

/// Lower edge of the first bucket, dB (energies are in dB re a unit amplitude, per-sample units).
const LOWEST_DB: f32 = -220.0;

/// How many kept modes had at least a given energy. Fixed size; nothing allocates.
#[derive(Debug, Clone)]
pub(super) struct KeptEnergies {
    /// Number of kept modes whose energy falls in bucket `b` or a higher one.
    at_or_above: [u32; BUCKETS],
}

impl KeptEnergies {
    /// Nothing kept.
    pub const fn new() -> Self {
        Self {
            at_or_above: [0; BUCKETS],
        }
    }

    /// The bucket of `energy_db` (NaN in the lowest).
    fn bucket(energy_db: f32) -> usize {
        let above = (energy_db - LOWEST_DB).max(0.0);
        (above as usize).min(BUCKETS - 1)
    }

    /// Forgets what was kept and notes `energies_db` instead.
    pub fn record(&mut self, energies_db: impl Iterator<Item = f32>) {
        self.at_or_above = [0; BUCKETS];
        for e in energies_db {
            self.at_or_above[Self::bucket(e)] += 1;
        }
        for b in (0..BUCKETS - 1).rev() {
            self.at_or_above[b] += self.at_or_above[b + 1];
        }
    }

    /// Kept modes with an energy of about `energy_db` or more (ties to within a dB count as
    /// more).
    pub fn at_or_above(&self, energy_db: f32) -> usize {
        self.at_or_above[Self::bucket(energy_db)] as usize
    }

    /// How many of `lifted` (energies in dB, loudest first) rank among the first `room` of them
    /// and the kept modes together.
    pub fn how_many_fit(&self, lifted: impl Iterator<Item = f32>, room: usize) -> usize {
        lifted
            .enumerate()
            .take_while(|&(j, e)| j + self.at_or_above(e) < room)
            .count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lifted_modes_fit_where_they_outrank_what_was_kept() {
        let mut kept = KeptEnergies::new();
        kept.record([10.0, 20.0, 30.0, 40.0].into_iter());
        assert_eq!(kept.at_or_above(25.0), 2);
        assert_eq!(kept.at_or_above(-500.0), 4);
        assert_eq!(kept.at_or_above(500.0), 0);
        // 50 and 35 rank first and third of all; 15 ranks sixth.
        assert_eq!(kept.how_many_fit([50.0, 35.0, 15.0].into_iter(), 6), 3);
        assert_eq!(kept.how_many_fit([50.0, 35.0, 15.0].into_iter(), 5), 2);
        assert_eq!(kept.how_many_fit([50.0, 35.0, 15.0].into_iter(), 3), 2);
        assert_eq!(kept.how_many_fit([50.0, 35.0, 15.0].into_iter(), 2), 1);
        // No room, or nothing lifted.
        assert_eq!(kept.how_many_fit([50.0].into_iter(), 0), 0);
        assert_eq!(kept.how_many_fit(std::iter::empty(), 10), 0);
        // Nothing kept: as many as there is room for.
        kept.record(std::iter::empty());
        assert_eq!(kept.how_many_fit([1.0, 2.0, 3.0].into_iter(), 2), 2);
    }
}
