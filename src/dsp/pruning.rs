//! The masking pass of perceptual mode pruning (seed 001 section 4, steps 5 to 7 of its
//! pseudo-code), and the selection of the modes a computation budget keeps (seed 000 sections 5.5
//! and 6.4).
//!
//! The pass takes candidate modes as plain slices (level in dB SPL, critical-band rate in Bark,
//! threshold in quiet in dB SPL), sorts them by level, drops those below the threshold of hearing,
//! and walks them loudest first against the upper envelope of the masking curves of the modes
//! kept so far: a mode under the envelope is masked; a mode within the masking offset above it
//! is kept but masks nothing. Sorting first keeps the cost near `O(N log N + N M)` with `M` the
//! number of maskers (about `2 sqrt(N)`, seed 001), instead of `O(N^2)` pairs; the sort here is a
//! radix sort on quantised levels, linear in `N`. The envelope at a
//! mode is evaluated against all maskers at once, eight lanes at a time.
//!
//! Storage is sized by [`MaskingPass::with_capacity`]; [`MaskingPass::run`] never allocates.

use std::cmp::{Ordering, Reverse};

use super::masking::{upper_slope_db_per_bark, LOWER_SLOPE_DB_PER_BARK};

/// What the pass decided for one candidate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// Heard: compute it. With `masker`, it may mask quieter modes.
    Audible {
        /// Whether its masking curve joins the envelope.
        masker: bool,
    },
    /// Below the threshold of hearing.
    Inaudible,
    /// Under the masking curve of candidate `by`.
    Masked {
        /// Index of the first (loudest) masker whose curve lies above this one.
        by: u32,
    },
}

impl Verdict {
    /// Whether the mode is to be computed.
    pub fn is_audible(self) -> bool {
        matches!(self, Verdict::Audible { .. })
    }
}

/// Set in [`Verdict::Masked`]'s `by` when the masker is a prior one
/// ([`MaskingPass::run_after`]).
pub const PRIOR: u32 = 1 << 31;

/// Levels are sorted as whole multiples of this, in dB: finer than any decision the curves make.
const SORT_STEP_DB: f32 = 1.0 / 128.0;

/// Highest level the sort keys distinguish, in dB SPL; anything louder sorts first. With 16-bit
/// keys the range below it is 512 dB.
const SORT_CEILING_DB: f32 = 300.0;

/// Turns counts into the start of each bucket.
fn prefix_sums(counts: &mut [u32; 256]) {
    let mut sum = 0;
    for c in counts.iter_mut() {
        let n = *c;
        *c = sum;
        sum += n;
    }
}

/// Lanes of the envelope evaluation.
const LANES: usize = 8;

/// Scratch storage for the masking pass.
#[derive(Debug, Clone)]
pub struct MaskingPass {
    /// Sort key of each candidate: its level quantised, loudest first.
    keys: Vec<u16>,
    /// Candidate indices in level order (loudest first) once sorted.
    order: Vec<u32>,
    /// Scratch for the radix sort.
    scratch: Vec<u32>,
    /// Bark of each masker, padded to a whole number of lanes.
    masker_bark: Vec<f32>,
    /// `L - a_v` of each masker: its curve's peak.
    masker_peak: Vec<f32>,
    /// Upper slope of each masker's curve, dB per Bark.
    masker_upper_slope: Vec<f32>,
    /// Candidate index of each masker.
    masker_index: Vec<u32>,
    /// Number of maskers found by the last run.
    num_maskers: usize,
    /// Whether the CPU runs AVX2 and FMA (the envelope is evaluated eight lanes wide).
    avx2: bool,
}

impl Default for MaskingPass {
    fn default() -> Self {
        Self::with_capacity(0)
    }
}

impl MaskingPass {
    /// Storage for passes over up to `capacity` candidates and maskers. Allocates.
    pub fn with_capacity(capacity: usize) -> Self {
        let padded = capacity.div_ceil(LANES) * LANES;
        Self {
            keys: vec![0; capacity],
            order: vec![0; capacity],
            scratch: vec![0; capacity],
            masker_bark: vec![0.0; padded],
            masker_peak: vec![f32::NEG_INFINITY; padded],
            masker_upper_slope: vec![0.0; padded],
            masker_index: vec![0; capacity],
            num_maskers: 0,
            avx2: crate::dsp::Kernel::Avx2.is_supported(),
        }
    }

    /// Most candidates one run takes.
    pub fn capacity(&self) -> usize {
        self.masker_index.len()
    }

    /// Maskers found by the last run.
    pub fn num_maskers(&self) -> usize {
        self.num_maskers
    }

    /// The maskers of the last run, loudest first: candidate indices, or prior maskers' with
    /// [`PRIOR`] set.
    pub fn maskers(&self) -> &[u32] {
        &self.masker_index[..self.num_maskers]
    }

    /// Classifies every candidate `i` with level `level_db[i]` at `bark[i]` and threshold in quiet
    /// `threshold_db[i]` into `verdicts[i]`, with masking offset `offset_db` (`a_v`, seed 001).
    /// The loudest candidate is always audible. Candidates beyond the capacity are an error.
    pub fn run(
        &mut self,
        level_db: &[f32],
        bark: &[f32],
        threshold_db: &[f32],
        offset_db: f32,
        verdicts: &mut [Verdict],
    ) {
        self.run_after(
            &[],
            &[],
            level_db,
            bark,
            threshold_db,
            offset_db,
            verdicts,
            None,
        );
    }

    /// As [`MaskingPass::run`], with maskers already known: prior masker `j` at `prior_bark[j]`
    /// and `prior_level_db[j]` masks from the start, and a candidate it masks gets
    /// `Masked { by: PRIOR | j }`. A candidate is only sure to be kept when it is louder than every
    /// prior masker too. With `envelope_db`, the envelope of the masking curves (or the threshold
    /// in quiet, if higher) at each audible candidate is written there, so the caller can tell
    /// how far it is from being masked.
    #[allow(clippy::too_many_arguments)] // two sets of parallel slices and the outputs
    pub fn run_after(
        &mut self,
        prior_bark: &[f32],
        prior_level_db: &[f32],
        level_db: &[f32],
        bark: &[f32],
        threshold_db: &[f32],
        offset_db: f32,
        verdicts: &mut [Verdict],
        mut envelope_db: Option<&mut [f32]>,
    ) {
        let n = level_db.len();
        assert!(
            bark.len() == n && threshold_db.len() == n && verdicts.len() == n,
            "candidate slices differ in length"
        );
        assert_eq!(prior_bark.len(), prior_level_db.len(), "prior maskers");
        assert!(
            n + prior_bark.len() <= self.capacity(),
            "{n} candidates and {} maskers, capacity {}",
            prior_bark.len(),
            self.capacity()
        );
        self.num_maskers = 0;
        let mut loudest_prior = f32::NEG_INFINITY;
        for (j, (&b, &l)) in prior_bark.iter().zip(prior_level_db).enumerate() {
            self.push_masker(PRIOR as usize | j, b, l, offset_db);
            // A masker nowhere on the Bark scale masks nothing, and outranks nothing either.
            if b.is_finite() {
                loudest_prior = loudest_prior.max(l);
            }
        }
        // Step 5: sort by level, loudest first.
        self.sort(level_db);
        for rank in 0..n {
            let i = self.order[rank] as usize;
            let (l, b) = (level_db[i], bark[i]);
            let loudest = rank == 0 && l >= loudest_prior;
            // Step 6: below the threshold of hearing (the loudest mode is always kept, so
            // pruning never silences a sounding object).
            if !loudest && l.partial_cmp(&threshold_db[i]) != Some(Ordering::Greater) {
                verdicts[i] = Verdict::Inaudible;
                continue;
            }
            // Step 7, against the envelope of every masker so far at once (and the first
            // masker above the mode, named if it is masked).
            let (envelope, first_above) = self.envelope_at(b, l);
            if let Some(out) = envelope_db.as_deref_mut() {
                out[i] = envelope.max(threshold_db[i]);
            }
            verdicts[i] = if l < envelope {
                Verdict::Masked {
                    by: self.masker_index[first_above.unwrap_or(0)],
                }
            } else if !loudest && l < envelope.max(threshold_db[i]) + offset_db {
                // Close to a masker's curve, or to the threshold in quiet (the seed's curve
                // includes it, eq. 4): heard, but too faint to mask.
                Verdict::Audible { masker: false }
            } else {
                self.push_masker(i, b, l, offset_db);
                Verdict::Audible { masker: true }
            };
        }
        // Leave the padding inert for the next run.
        let used = self.num_maskers.div_ceil(LANES) * LANES;
        self.masker_peak[..used].fill(f32::NEG_INFINITY);
    }

    /// Sorts the candidates by level, loudest first, into `order`: a stable radix sort on the
    /// levels quantised to [`SORT_STEP_DB`] (two passes of eight bits, linear in the count).
    fn sort(&mut self, level_db: &[f32]) {
        let n = level_db.len();
        for (k, &l) in self.keys.iter_mut().zip(level_db) {
            // Loudest first; NaN sorts last (and is below any threshold).
            let steps = ((SORT_CEILING_DB - l) / SORT_STEP_DB).clamp(0.0, u16::MAX as f32);
            *k = if l.is_nan() { u16::MAX } else { steps as u16 };
        }
        let mut counts = [0u32; 256];
        for &k in &self.keys[..n] {
            counts[(k & 0xff) as usize] += 1;
        }
        prefix_sums(&mut counts);
        for i in 0..n {
            let b = (self.keys[i] & 0xff) as usize;
            self.scratch[counts[b] as usize] = i as u32;
            counts[b] += 1;
        }
        let mut counts = [0u32; 256];
        for &k in &self.keys[..n] {
            counts[(k >> 8) as usize] += 1;
        }
        prefix_sums(&mut counts);
        for j in 0..n {
            let i = self.scratch[j];
            let b = (self.keys[i as usize] >> 8) as usize;
            self.order[counts[b] as usize] = i;
            counts[b] += 1;
        }
    }

    /// Upper envelope of the maskers' curves at `bark` (seed 001 eq. 4 without the threshold in
    /// quiet, which the caller has already applied), and the first masker (loudest first) whose
    /// curve there lies above `level_db`: every masker at once, eight lanes at a time, in one
    /// pass with AVX2 when the CPU has it.
    #[inline]
    fn envelope_at(&self, bark: f32, level_db: f32) -> (f32, Option<usize>) {
        let (mb, peak, su) = self.masker_lanes();
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` is only set when the CPU supports AVX2 and FMA.
            return unsafe { envelope_and_first_above_avx2(mb, peak, su, bark, level_db) };
        }
        let envelope = envelope(mb, peak, su, bark);
        // Only a mode under the envelope has a masker above it.
        let first = if level_db < envelope {
            first_above(mb, peak, su, bark, level_db)
        } else {
            None
        };
        (envelope, first)
    }

    /// The maskers' bark, peak and upper slope, padded to a whole number of lanes.
    fn masker_lanes(&self) -> (&[f32], &[f32], &[f32]) {
        let used = self.num_maskers.div_ceil(LANES) * LANES;
        (
            &self.masker_bark[..used],
            &self.masker_peak[..used],
            &self.masker_upper_slope[..used],
        )
    }

    fn push_masker(&mut self, index: usize, bark: f32, level_db: f32, offset_db: f32) {
        let j = self.num_maskers;
        self.masker_bark[j] = bark;
        self.masker_peak[j] = level_db - offset_db;
        self.masker_upper_slope[j] = upper_slope_db_per_bark(level_db);
        self.masker_index[j] = index as u32;
        self.num_maskers += 1;
    }
}

/// The envelope of masking curves given as parallel lanes (a whole number of [`LANES`]): bark,
/// peak `L - a_v` and upper slope of each masker.
#[inline(always)]
fn envelope(masker_bark: &[f32], peak: &[f32], upper_slope: &[f32], bark: f32) -> f32 {
    let mut best = [f32::NEG_INFINITY; LANES];
    for ((mb, pk), su) in masker_bark
        .chunks_exact(LANES)
        .zip(peak.chunks_exact(LANES))
        .zip(upper_slope.chunks_exact(LANES))
    {
        for l in 0..LANES {
            let below = LOWER_SLOPE_DB_PER_BARK * (mb[l] - bark);
            let above = su[l] * (bark - mb[l]);
            let curve = pk[l] - if below > above { below } else { above };
            best[l] = if curve > best[l] { curve } else { best[l] };
        }
    }
    best.into_iter().fold(f32::NEG_INFINITY, f32::max)
}

/// [`envelope`] and [`first_above`] in one pass, with AVX2 and FMA intrinsics: the same
/// comparisons in the same order, so the same results.
///
/// # Safety
/// The CPU must support AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn envelope_and_first_above_avx2(
    masker_bark: &[f32],
    peak: &[f32],
    upper_slope: &[f32],
    bark: f32,
    level_db: f32,
) -> (f32, Option<usize>) {
    use std::arch::x86_64::*;
    const _: () = assert!(LANES == 8);
    let n = masker_bark.len();
    assert!(peak.len() == n && upper_slope.len() == n && n.is_multiple_of(LANES));
    let b = _mm256_set1_ps(bark);
    let level = _mm256_set1_ps(level_db);
    let lower = _mm256_set1_ps(LOWER_SLOPE_DB_PER_BARK);
    let mut best = _mm256_set1_ps(f32::NEG_INFINITY);
    let mut first = None;
    for k in (0..n).step_by(LANES) {
        // SAFETY: `k + LANES <= n`, the length of all three slices (checked above).
        let (mb, pk, su) = unsafe {
            (
                _mm256_loadu_ps(masker_bark.as_ptr().add(k)),
                _mm256_loadu_ps(peak.as_ptr().add(k)),
                _mm256_loadu_ps(upper_slope.as_ptr().add(k)),
            )
        };
        let below = _mm256_mul_ps(lower, _mm256_sub_ps(mb, b));
        let above = _mm256_mul_ps(su, _mm256_sub_ps(b, mb));
        // `max_ps(x, y)` is `if x > y { x } else { y }`, as in `envelope`.
        let curve = _mm256_sub_ps(pk, _mm256_max_ps(below, above));
        best = _mm256_max_ps(curve, best);
        if first.is_none() {
            let above_level = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_GT_OQ>(curve, level));
            if above_level != 0 {
                first = Some(k + above_level.trailing_zeros() as usize);
            }
        }
    }
    let mut lanes = [0.0f32; LANES];
    // SAFETY: `lanes` holds eight floats.
    unsafe { _mm256_storeu_ps(lanes.as_mut_ptr(), best) };
    (lanes.into_iter().fold(f32::NEG_INFINITY, f32::max), first)
}

/// The first masker, given as parallel lanes as for [`envelope`], whose curve at `bark` lies above
/// `level_db` (the padding, at a peak of minus infinity, never does).
#[inline(always)]
fn first_above(
    masker_bark: &[f32],
    peak: &[f32],
    upper_slope: &[f32],
    bark: f32,
    level_db: f32,
) -> Option<usize> {
    for (k, ((mb, pk), su)) in masker_bark
        .chunks_exact(LANES)
        .zip(peak.chunks_exact(LANES))
        .zip(upper_slope.chunks_exact(LANES))
        .enumerate()
    {
        let mut above_level = 0u32;
        for l in 0..LANES {
            let below = LOWER_SLOPE_DB_PER_BARK * (mb[l] - bark);
            let above = su[l] * (bark - mb[l]);
            let curve = pk[l] - if below > above { below } else { above };
            above_level |= ((curve > level_db) as u32) << l;
        }
        if above_level != 0 {
            return Some(k * LANES + above_level.trailing_zeros() as usize);
        }
    }
    None
}

/// Reorders `ranked` so that its first `keep` entries are those with the most energy (the first
/// value of each pair, seed 000 eq. 5.15), in no particular order. Does not allocate.
pub fn keep_most_energetic(ranked: &mut [(f32, u32)], keep: usize) {
    if keep == 0 || keep >= ranked.len() {
        return;
    }
    ranked.select_nth_unstable_by_key(keep - 1, |&(e, i)| (Reverse(OrderedEnergy(e)), i));
}

/// Energies ordered totally (NaN as the least).
#[derive(Debug, Clone, Copy, PartialEq)]
struct OrderedEnergy(f32);

impl Eq for OrderedEnergy {}

impl PartialOrd for OrderedEnergy {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for OrderedEnergy {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        let key = |e: f32| if e.is_nan() { f32::NEG_INFINITY } else { e };
        key(self.0).total_cmp(&key(other.0))
    }
}

#[cfg(test)]
mod tests;
