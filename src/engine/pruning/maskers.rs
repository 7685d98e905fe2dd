//! Maskers carried from one analysis to the next, so that most frames need not look at every mode.

/// Maskers, their levels as of `at`, structure-of-arrays.
#[derive(Debug, Clone, Default)]
pub(super) struct Maskers {
    /// Critical-band rate.
    pub bark: Vec<f32>,
    /// Level in dB SPL at `at`.
    pub level_db: Vec<f32>,
    /// Fall of the level, dB per sample.
    pub fall_db: Vec<f32>,
    /// `voice << 24 | mode`.
    pub who: Vec<u32>,
    /// The voice's generation when the masker was found.
    pub generation: Vec<u32>,
    /// Engine clock of `level_db`.
    pub at: Vec<u64>,
    /// Number in use.
    pub len: usize,
}

impl Maskers {
    /// Room for `n`. Allocates.
    pub fn with_capacity(n: usize) -> Self {
        Self {
            bark: vec![0.0; n],
            level_db: vec![0.0; n],
            fall_db: vec![0.0; n],
            who: vec![0; n],
            generation: vec![0; n],
            at: vec![0; n],
            len: 0,
        }
    }

    /// The level of masker `j` at engine clock `now`: levels fall linearly in dB.
    pub fn level_at(&self, j: usize, now: u64) -> f32 {
        self.level_db[j] - self.fall_db[j] * now.saturating_sub(self.at[j]) as f32
    }

    /// Copies masker `from` to `to`.
    pub fn move_entry(&mut self, from: usize, to: usize) {
        self.bark[to] = self.bark[from];
        self.level_db[to] = self.level_db[from];
        self.fall_db[to] = self.fall_db[from];
        self.who[to] = self.who[from];
        self.generation[to] = self.generation[from];
        self.at[to] = self.at[from];
    }

    /// Appends a masker.
    pub fn push(
        &mut self,
        bark: f32,
        level_db: f32,
        fall_db: f32,
        who: u32,
        generation: u32,
        at: u64,
    ) {
        let j = self.len;
        self.bark[j] = bark;
        self.level_db[j] = level_db;
        self.fall_db[j] = fall_db;
        self.who[j] = who;
        self.generation[j] = generation;
        self.at[j] = at;
        self.len += 1;
    }
}
