//! The bank the editor shows and edits: the bank as loaded or edited, the modes muted or soloed,
//! and undo and redo of both. The plugin plays [`BankSession::played_bank`], "Save as" writes
//! [`BankSession::saved_bank`]. No drawing here.

use serde_json::Value;

use crate::bank::validate::{validate_bank, DECAY_PER_S, FREQ_HZ, GAIN};
use crate::bank::Bank;
use crate::engine::{PositionMap, PositionWeights, PreparedBank};

/// Most values (gains, frequencies and decays) the undo history keeps; the oldest steps go
/// first. 8 M values is 64 MB: hundreds of steps of a large bank.
const UNDO_BUDGET_VALUES: usize = 8_000_000;

/// Lowest frequency an edit sets, in Hz: the lowest the format allows.
const MIN_EDIT_FREQ_HZ: f64 = crate::bank::validate::MODE_FREQ_HZ.min;

/// The state one undo step restores.
#[derive(Debug, Clone, PartialEq)]
struct Snapshot {
    /// The bank, all modes.
    bank: Bank,
    /// Muted modes, by index in `bank.modes`.
    muted: Vec<bool>,
    /// Soloed modes, by index in `bank.modes`.
    soloed: Vec<bool>,
}

impl Snapshot {
    /// Values held, for the undo budget.
    fn cost(&self) -> usize {
        self.bank.modes.len() * (self.bank.positions.len() + 2)
    }
}

/// The bank in the editor, with its edits.
#[derive(Debug, Clone)]
pub struct BankSession {
    /// The bank, the muted and the soloed modes.
    now: Snapshot,
    /// Where the bank came from, for display: a factory name, a file, "plugin state".
    origin: String,
    /// Index in `bank.modes` of each mode of the prepared bank (ascending frequency).
    order: Vec<usize>,
    /// The positions, normalised as the engine does.
    positions: PositionMap,
    /// Whether any mode is soloed (kept, as every mode asks on every frame).
    any_soloed: bool,
    /// Earlier states, oldest first.
    undo: Vec<Snapshot>,
    /// States undone, most recent last.
    redo: Vec<Snapshot>,
    /// Whether an edit gesture (a drag, a typed value) is under way; it makes one undo step.
    gesture_open: bool,
    /// Whether the plugin plays an older version than this.
    needs_push: bool,
    /// Whether the bank was edited since it was loaded.
    edited: bool,
    /// The version of the plugin's saved bank (its generation) this session matches.
    generation: u64,
    /// Incremented on every change, so views can cache what they derive.
    version: u64,
}

impl BankSession {
    /// A session on `bank` from `origin`, matching the plugin's bank `generation`.
    pub fn new(bank: Bank, origin: impl Into<String>, generation: u64) -> Self {
        let n = bank.modes.len();
        let mut session = Self {
            now: Snapshot {
                bank,
                muted: vec![false; n],
                soloed: vec![false; n],
            },
            origin: origin.into(),
            order: Vec::new(),
            positions: PositionMap::new(&[]),
            any_soloed: false,
            undo: Vec::new(),
            redo: Vec::new(),
            gesture_open: false,
            needs_push: false,
            edited: false,
            generation,
            version: 0,
        };
        session.derive();
        session
    }

    /// The bank, every mode (muted ones too).
    pub fn bank(&self) -> &Bank {
        &self.now.bank
    }

    /// Where the bank came from.
    pub fn origin(&self) -> &str {
        &self.origin
    }

    /// Number of modes.
    pub fn num_modes(&self) -> usize {
        self.now.bank.modes.len()
    }

    /// Index in `bank().modes` of each mode of the prepared bank (the engine's numbering).
    pub fn order(&self) -> &[usize] {
        &self.order
    }

    /// The bank's positions, normalised as the engine does.
    pub fn positions(&self) -> &PositionMap {
        &self.positions
    }

    /// The plugin's bank generation this session matches.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// Records that the plugin's bank is now at `generation`, matching this session.
    pub fn set_generation(&mut self, generation: u64) {
        self.generation = generation;
    }

    /// Changes whenever anything in the session does.
    pub fn version(&self) -> u64 {
        self.version
    }

    /// Whether the bank was edited since it was loaded.
    pub fn is_edited(&self) -> bool {
        self.edited
    }

    /// Whether mode `i` is muted.
    pub fn is_muted(&self, i: usize) -> bool {
        self.now.muted.get(i).copied().unwrap_or(false)
    }

    /// Whether mode `i` is soloed.
    pub fn is_soloed(&self, i: usize) -> bool {
        self.now.soloed.get(i).copied().unwrap_or(false)
    }

    /// Whether mode `i` is heard: soloed when any mode is, else not muted.
    pub fn is_audible(&self, i: usize) -> bool {
        if self.any_soloed {
            self.is_soloed(i)
        } else {
            !self.is_muted(i)
        }
    }

    /// Whether any mode is muted or soloed.
    pub fn has_mutes(&self) -> bool {
        self.now.muted.iter().chain(&self.now.soloed).any(|&m| m)
    }

    /// Gain of mode `i` for a strike blended by `weights`.
    pub fn gain_at(&self, i: usize, weights: &PositionWeights) -> f64 {
        let gains = &self.now.bank.modes[i].gains;
        (0..weights.count)
            .map(|k| weights.weight[k] as f64 * gains.get(weights.index[k]).copied().unwrap_or(0.0))
            .sum()
    }

    /// Sets the frequency of mode `i` (kept within the format's range).
    pub fn set_freq_hz(&mut self, i: usize, freq_hz: f64) {
        if !freq_hz.is_finite() {
            return;
        }
        self.touch();
        self.now.bank.modes[i].freq_hz = freq_hz.clamp(MIN_EDIT_FREQ_HZ, FREQ_HZ.max);
        self.changed();
    }

    /// Sets the decay rate of mode `i` in 1/s (kept within the format's range).
    pub fn set_decay_per_s(&mut self, i: usize, decay_per_s: f64) {
        if decay_per_s.is_nan() {
            return;
        }
        self.touch();
        self.now.bank.modes[i].decay_per_s = decay_per_s.clamp(DECAY_PER_S.min, DECAY_PER_S.max);
        self.changed();
    }

    /// Makes the gain of mode `i` for a strike blended by `weights` equal `gain`: the columns
    /// blended are scaled together (or set, when they blend to zero).
    pub fn set_gain_at(&mut self, i: usize, weights: &PositionWeights, gain: f64) {
        if !gain.is_finite() {
            return;
        }
        let gain = gain.clamp(GAIN.min, GAIN.max);
        let old = self.gain_at(i, weights);
        self.touch();
        let gains = &mut self.now.bank.modes[i].gains;
        for k in 0..weights.count {
            if let Some(g) = gains.get_mut(weights.index[k]) {
                *g = if old.abs() > 1e-12 {
                    (*g * gain / old).clamp(GAIN.min, GAIN.max)
                } else {
                    gain
                };
            }
        }
        self.changed();
    }

    /// Mutes or unmutes mode `i`: one undo step.
    pub fn toggle_mute(&mut self, i: usize) {
        self.step(|s| s.muted[i] = !s.muted[i]);
    }

    /// Solos or unsolos mode `i`: one undo step.
    pub fn toggle_solo(&mut self, i: usize) {
        self.step(|s| s.soloed[i] = !s.soloed[i]);
    }

    /// Clears every mute and solo: one undo step.
    pub fn clear_mutes(&mut self) {
        if self.has_mutes() {
            self.step(|s| {
                s.muted.fill(false);
                s.soloed.fill(false);
            });
        }
    }

    /// Ends the edit gesture under way: the next edit starts a new undo step.
    pub fn end_gesture(&mut self) {
        self.gesture_open = false;
    }

    /// Whether an edit gesture is under way.
    pub fn gesture_open(&self) -> bool {
        self.gesture_open
    }

    /// Whether there is a step to undo.
    pub fn can_undo(&self) -> bool {
        !self.undo.is_empty()
    }

    /// Whether there is a step to redo.
    pub fn can_redo(&self) -> bool {
        !self.redo.is_empty()
    }

    /// Restores the state before the last step.
    pub fn undo(&mut self) {
        self.gesture_open = false;
        if let Some(previous) = self.undo.pop() {
            self.redo.push(std::mem::replace(&mut self.now, previous));
            self.changed();
        }
    }

    /// Restores the last state undone.
    pub fn redo(&mut self) {
        self.gesture_open = false;
        if let Some(next) = self.redo.pop() {
            self.undo.push(std::mem::replace(&mut self.now, next));
            self.changed();
        }
    }

    /// The bank the plugin should play, once no gesture is under way and it changed since last
    /// asked: every mode, those not heard with zero gains (so modes keep their numbers).
    pub fn take_push(&mut self) -> Option<Bank> {
        if !self.needs_push || self.gesture_open {
            return None;
        }
        self.needs_push = false;
        Some(self.played_bank())
    }

    /// The bank as heard: modes muted (or not soloed) have zero gains.
    pub fn played_bank(&self) -> Bank {
        let mut bank = self.now.bank.clone();
        for (i, mode) in bank.modes.iter_mut().enumerate() {
            if !self.is_audible(i) {
                mode.gains.fill(0.0);
            }
        }
        bank
    }

    /// The bank to save under `name`: the modes heard (muted ones left out), marked as edited
    /// from the bank it started as, and checked against the format.
    pub fn saved_bank(&self, name: &str) -> Result<Bank, String> {
        let mut bank = self.now.bank.clone();
        let original = bank.name.clone();
        bank.name = name.trim().to_string();
        bank.modes = (0..self.num_modes())
            .filter(|&i| self.is_audible(i))
            .map(|i| self.now.bank.modes[i].clone())
            .collect();
        if self.edited || self.has_mutes() {
            let source = bank.source.get_or_insert_with(Default::default);
            source.insert("kind".into(), Value::from("edited"));
            source.insert("edited_from".into(), Value::from(original));
        }
        let problems = validate_bank(&bank);
        if problems.is_empty() {
            Ok(bank)
        } else {
            let lines: Vec<String> = problems.iter().map(|p| p.to_string()).collect();
            Err(lines.join("\n"))
        }
    }

    /// Starts an undo step unless a gesture already has.
    fn touch(&mut self) {
        if !self.gesture_open {
            self.gesture_open = true;
            self.push_undo();
        }
        self.edited = true;
    }

    /// One whole undo step.
    fn step(&mut self, change: impl FnOnce(&mut Snapshot)) {
        self.gesture_open = false;
        self.push_undo();
        change(&mut self.now);
        self.changed();
    }

    fn push_undo(&mut self) {
        self.undo.push(self.now.clone());
        self.redo.clear();
        let mut total: usize = self.undo.iter().map(Snapshot::cost).sum();
        while total > UNDO_BUDGET_VALUES && self.undo.len() > 1 {
            total -= self.undo.remove(0).cost();
        }
    }

    fn changed(&mut self) {
        self.needs_push = true;
        self.derive();
    }

    /// Recomputes what follows from the bank.
    fn derive(&mut self) {
        self.order = PreparedBank::frequency_order(&self.now.bank);
        let coords: Vec<Vec<f64>> = self
            .now
            .bank
            .positions
            .iter()
            .map(|p| p.coords.clone())
            .collect();
        self.positions = PositionMap::new(&coords);
        self.any_soloed = self.now.soloed.iter().any(|&s| s);
        self.version += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bank::factory::factory_bank;

    fn session() -> BankSession {
        BankSession::new(factory_bank("steel-plate").unwrap(), "test", 1)
    }

    #[test]
    fn a_gesture_is_one_undo_step_and_undo_restores_the_bank() {
        let mut s = session();
        let before = s.bank().clone();
        s.set_freq_hz(3, 1000.0);
        s.set_freq_hz(3, 1100.0);
        s.set_decay_per_s(3, 2.0);
        assert!(s.take_push().is_none(), "nothing is pushed mid-gesture");
        s.end_gesture();
        assert_eq!(s.take_push().unwrap().modes[3].freq_hz, 1100.0);
        s.undo();
        assert_eq!(s.bank(), &before);
        assert!(!s.can_undo());
        s.redo();
        assert_eq!(s.bank().modes[3].decay_per_s, 2.0);
    }

    #[test]
    fn gain_edits_at_a_blend_scale_the_blended_columns() {
        let mut s = session();
        let w = s.positions().weights(0.3, 0.6);
        assert!(w.count > 1);
        let old = s.gain_at(5, &w);
        s.set_gain_at(5, &w, old * 0.5);
        assert!((s.gain_at(5, &w) - old * 0.5).abs() < 1e-12);
    }

    #[test]
    fn mutes_zero_the_played_gains_and_leave_saved_modes_out() {
        let mut s = session();
        let n = s.num_modes();
        s.toggle_mute(0);
        let played = s.played_bank();
        assert_eq!(played.modes.len(), n);
        assert!(played.modes[0].gains.iter().all(|&g| g == 0.0));
        assert_eq!(s.saved_bank("x").unwrap().modes.len(), n - 1);
        s.toggle_solo(4);
        let played = s.played_bank();
        let heard: Vec<usize> = (0..n)
            .filter(|&i| played.modes[i].gains.iter().any(|&g| g != 0.0))
            .collect();
        assert_eq!(heard, vec![4]);
        s.undo();
        s.undo();
        assert!(!s.has_mutes());
    }
}
