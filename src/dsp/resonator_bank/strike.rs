//! A strike on a bank whose modes are partly dormant.
//!
//! The kernels cannot drive a dormant mode, but an impulse or a mallet pulse is known in advance
//! and the phasor is linear: a pulse `x_0 .. x_(L-1)` starting just after bank clock `t` leaves
//! the state `p^L z(t) + g sum_j x_j p^(L-1-j)` when it ends, whatever `z(t)` was. So a dormant
//! mode the strike leaves masked takes it analytically: its record is brought to `t` and the
//! pulse's contribution referred to that instant, `g sum_j x_j p^-(j+1)`, is added (in closed form
//! for the raised cosine, seed 000 eq. 4.5). Until the pulse has ended the record runs ahead of
//! the truth by the part not yet played, so a mode woken then has that part taken back.
//!
//! A record thus holds the truth on the understanding that what is left of the pulses under way
//! reaches it with its own gain. A computed mode takes the rest of an earlier pulse with the
//! gain of the latest strike, so a strike that changes a record's gain also gives it the rest of
//! the earlier pulses at the difference; a mode started from rest has a gain of zero until then.
//! Referred back to the strike, a pulse grows as `e^(delta L)`: modes that decay more than
//! [`MAX_ABSORB_NEPERS`] within what is left of the pulses are woken before it instead, and
//! computed through it (they soon die away).

use super::dormant::Dormant;
use super::{NextTick, ResonatorBank};
use crate::dsp::masking::power_to_db;
use crate::dsp::prefetch::{self, prefetch};
use realfft::num_complex::Complex64;

/// Most pulses kept track of at once: as many as one exciter overlaps.
pub(super) use crate::dsp::exciter::MAX_PULSES;

/// Below this distance from 1 a geometric ratio is summed term by term rather than in closed
/// form (the closed form divides by it).
const NEAR_ONE: f64 = 1e-3;

/// Least decay, in nepers, over what is left of the pulses under way for a dormant mode to read
/// a bound until they end (3 dB): short of it, the record reads within about that much of the
/// truth while they play.
const BOUND_NEPERS: f64 = 0.35;

/// Most decay, in nepers, over what is left of the pulses under way for a dormant mode to take
/// a strike analytically: referred back to the strike the pulse grows by as much, and taking its
/// unplayed part back loses that many nepers of an `f32` state's precision (`e^6` of `2^-24`,
/// about -92 dB).
pub(super) const MAX_ABSORB_NEPERS: f64 = 6.0;

pub use crate::dsp::exciter::PulseShape;

/// A pulse: its shape, its area and its length in samples.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pulse {
    /// Shape.
    pub shape: PulseShape,
    /// Area (sum of the samples).
    pub amplitude: f32,
    /// Length in samples (1 for an impulse).
    pub len: u32,
}

impl Pulse {
    /// A pulse of nothing.
    pub const NONE: Self = Self {
        shape: PulseShape::Impulse,
        amplitude: 0.0,
        len: 1,
    };

    /// Samples it lasts.
    fn samples(&self) -> u32 {
        match self.shape {
            PulseShape::Impulse => 1,
            PulseShape::Mallet => self.len.max(1),
        }
    }

    /// The constants of its response, worked out once per strike.
    fn prepared(&self) -> Prepared {
        let len = self.samples();
        let w0 = std::f64::consts::TAU / len as f64;
        Prepared {
            amplitude: self.amplitude as f64,
            len,
            rot: Complex64::cis(w0),
            half_back: Complex64::cis(-0.5 * w0),
        }
    }
}

/// A pulse's response constants.
#[derive(Debug, Clone, Copy)]
pub(super) struct Prepared {
    /// Area.
    amplitude: f64,
    /// Samples.
    len: u32,
    /// `e^(i w0)`, `w0 = 2 pi / L`.
    rot: Complex64,
    /// `e^(-i w0 / 2)`.
    half_back: Complex64,
}

impl Prepared {
    /// Constants of no pulse.
    const NONE: Self = Self {
        amplitude: 0.0,
        len: 1,
        rot: Complex64::ONE,
        half_back: Complex64::ONE,
    };

    /// `sum_(j = a)^(b - 1) x_j w^(j + 1)` with `w = 1 / p`: the part of the pulse from sample `a`
    /// to `b`, referred to the sample before it starts, for a mode of pole `p`.
    fn response(&self, p: Complex64, a: u32, b: u32) -> Complex64 {
        let w = Complex64::ONE / p;
        let b = b.min(self.len);
        if a >= b {
            return Complex64::ZERO;
        }
        if self.len == 1 {
            return w.scale(self.amplitude);
        }
        // Raised cosine: 1 - (e^(i w0 (j + 1/2)) + e^(-i w0 (j + 1/2))) / 2, and
        // e^(+-i w0 (j + 1/2)) w^(j + 1) = e^(-+i w0 / 2) (w e^(+-i w0))^(j + 1). The three
        // ratios' powers differ only by whole turns of e^(+-i w0): worked out once.
        let (first, span) = (powi(w, a + 1), powi(w, b - a));
        let (ra, rs) = (powi(self.rot, a + 1), powi(self.rot, b - a));
        let up = geometric(w * self.rot, first * ra, span * rs, a, b);
        let down = geometric(
            w * self.rot.conj(),
            first * ra.conj(),
            span * rs.conj(),
            a,
            b,
        );
        let sum = geometric(w, first, span, a, b)
            - (self.half_back * up).scale(0.5)
            - (self.half_back.conj() * down).scale(0.5);
        sum.scale(self.amplitude / self.len as f64)
    }
}

/// `sum_(j = a)^(b - 1) u^(j + 1)`, given `u^(a + 1)` and `u^(b - a)`.
fn geometric(u: Complex64, first: Complex64, span: Complex64, a: u32, b: u32) -> Complex64 {
    let one_minus = Complex64::ONE - u;
    if one_minus.norm_sqr() < NEAR_ONE * NEAR_ONE {
        let mut term = first;
        let mut sum = Complex64::ZERO;
        for _ in a..b {
            sum += term;
            term *= u;
        }
        return sum;
    }
    first * (Complex64::ONE - span) / one_minus
}

impl ResonatorBank {
    /// Every dormant mode (none may be fading: see [`ResonatorBank::wake_fading`]) takes `pulse`,
    /// starting at the next sample, with input gain `gain_of(mode)`, without being computed. With
    /// `due`, each is due for another look by the pruner now; otherwise its recheck time stands
    /// until the pruner sets another from the strike's outcome. A mode the pruner then wakes
    /// ([`ResonatorBank::wake`]) computes the strike from its first sample. Modes decaying too
    /// fast to take it analytically are woken at once. Returns how many took it. Call it for
    /// every pulse within which modes may start dormant, dormant modes or not: those started
    /// later take the rest of the pulses still playing
    /// ([`ResonatorBank::num_pulses_under_way`]). Fades started now end on `tick`'s ticks.
    pub fn absorb_strike(
        &mut self,
        pulse: Pulse,
        due: bool,
        tick: NextTick,
        mut gain_of: impl FnMut(usize) -> f32,
    ) -> usize {
        let under_way = self.note_pulse(pulse);
        // Noted even with no dormant modes: a mode this pulse is still playing into when a later
        // strike starts it dormant takes the rest of it.
        if self.num_dormant == 0 {
            return 0;
        }
        let (n, num_waking) = self.refer_to_records(pulse, &under_way, due, &mut gain_of);
        let scratch = &mut self.absorb;
        scratch.run(n);
        for k in 0..n {
            let d = &mut self.dormant[scratch.record[k] as usize];
            d.re = scratch.out_re[k];
            d.im = scratch.out_im[k];
            d.snap_db = scratch.out_db[k];
        }
        if due {
            self.earliest_recheck = self.earliest_recheck.min(self.clock);
        }
        // Woken as though before this pulse (their old ringing, less what it has not played of
        // the earlier pulses, fades back in), with this strike's gain; last first, so the
        // records moved into the places of those woken have been passed already.
        self.num_pulses = under_way.kept;
        for k in (0..num_waking).rev() {
            let r = self.absorb.waking[k] as usize;
            let mode = self.dormant[r].mode as usize;
            self.wake_record(r, tick);
            let slot = self.slot_of_mode[mode] as usize;
            self.gain[slot] = gain_of(mode);
        }
        self.num_pulses = under_way.kept + 1;
        n
    }

    /// Notes `pulse`, starting now, among the pulses under way, forgetting those that have
    /// ended (and the oldest, if there are too many); returns what is left of the earlier ones.
    fn note_pulse(&mut self, pulse: Pulse) -> UnderWay {
        let now = self.clock;
        let mut u = UnderWay {
            kept: 0,
            span: pulse.samples() as u64,
            reach: pulse.amplitude.abs(),
            earlier: [(0, Prepared::NONE); MAX_PULSES],
        };
        for k in 0..self.num_pulses {
            let (start, old) = self.pulses[k];
            let end = start + old.samples() as u64;
            if end > now {
                self.pulses[u.kept] = self.pulses[k];
                u.earlier[u.kept] = ((now - start) as u32, old.prepared());
                u.span = u.span.max(end - now);
                u.reach += old.amplitude.abs();
                u.kept += 1;
            }
        }
        if u.kept == MAX_PULSES {
            self.pulses.rotate_left(1);
            u.earlier.rotate_left(1);
            u.kept -= 1;
        }
        self.pulses[u.kept] = (now, pulse);
        self.num_pulses = u.kept + 1;
        u
    }

    /// Brings each dormant record to now and works out its share of `pulse` (and, at a change
    /// of gain, of the pulses `under_way`) into the scratch, for its arithmetic to run over all
    /// of them at once. Records of modes too damped to refer the pulses back to now are listed
    /// to be woken instead. Returns how many records took it and how many are to be woken.
    fn refer_to_records(
        &mut self,
        pulse: Pulse,
        under_way: &UnderWay,
        due: bool,
        gain_of: &mut impl FnMut(usize) -> f32,
    ) -> (usize, usize) {
        let now = self.clock;
        let unit = Pulse {
            amplitude: 1.0,
            ..pulse
        };
        let prepared = unit.prepared();
        let key = (pulse.shape, unit.samples());
        let span = under_way.span;
        let earlier = &under_way.earlier[..under_way.kept];
        let too_damped = MAX_ABSORB_NEPERS / span as f64;
        let (mut n, mut num_waking) = (0, 0);
        for r in 0..self.num_dormant {
            // The records are in no order of mode: ask early for a later one's response.
            if let Some(ahead) = self.dormant[..self.num_dormant].get(r + prefetch::AHEAD) {
                prefetch(&self.responses, ahead.mode as usize);
            }
            if self.still_fading_out(self.dormant[r].mode as usize) {
                continue;
            }
            let (d, scratch) = (&mut self.dormant[r], &mut self.absorb);
            if d.delta > too_damped {
                scratch.waking[num_waking] = r as u32;
                num_waking += 1;
                continue;
            }
            d.advance_to(now);
            let gain = gain_of(d.mode as usize);
            let p = Complex64::new(d.p_re, d.p_im);
            let response = self.responses[d.mode as usize].get(p, key, &prepared);
            let change = gain as f64 - d.gain as f64;
            let bounded = d.pulse_left > 0 || d.delta * span as f64 > BOUND_NEPERS;
            let rest = if change != 0.0 || bounded {
                still_to_play(p, earlier)
            } else {
                Complex64::ZERO
            };
            // What the earlier pulses have still to play now comes with this strike's gain.
            let added = response.scale(pulse.amplitude as f64 * gain as f64) + rest.scale(change);
            scratch.phase[n] = d.phase;
            scratch.log_gain[n] = d.log_gain;
            scratch.re[n] = d.re;
            scratch.im[n] = d.im;
            scratch.add_re[n] = added.re;
            scratch.add_im[n] = added.im;
            scratch.record[n] = r as u32;
            n += 1;
            // Referred back, the pulses make the record read up to `delta * span` nepers off the
            // truth: beyond 3 dB it reads a bound until they end instead, its true
            // amplitude now (the record less what the earlier pulses have still to play, at its
            // gain so far) and all the pulses can add.
            if bounded {
                let (re, im) = d.state();
                let truth = Complex64::new(re as f64, im as f64) - rest.scale(d.gain as f64);
                let peak = truth.norm_sqr().sqrt() as f32 + gain.abs() * under_way.reach;
                d.pulse_peak_db = power_to_db(peak * peak);
                d.pulse_left = span as u32;
            }
            d.phase = 0.0;
            d.log_gain = 0.0;
            d.gain = gain;
            if due {
                self.recheck[r] = now;
            }
        }
        (n, num_waking)
    }

    /// How many of the pulses given to [`ResonatorBank::absorb_strike`] are still playing.
    pub fn num_pulses_under_way(&self) -> usize {
        self.pulses[..self.num_pulses]
            .iter()
            .filter(|(start, pulse)| start + pulse.samples() as u64 > self.clock)
            .count()
    }

    /// The state of record `d` (brought to now) with the unplayed part of any pulse it took
    /// taken back.
    pub(super) fn undo_pending_pulses(&self, d: &Dormant, state: (f32, f32)) -> (f32, f32) {
        let now = self.clock;
        let mut z = Complex64::new(state.0 as f64, state.1 as f64);
        let p = Complex64::new(d.p_re, d.p_im);
        for &(start, pulse) in &self.pulses[..self.num_pulses] {
            let played = now.saturating_sub(start);
            if played >= pulse.samples() as u64 {
                continue;
            }
            // The record holds p^k (z + g sum_all); the truth is p^k (z + g sum_(j<k)).
            let ahead = pulse.prepared().response(p, played as u32, u32::MAX);
            z -= (powi(p, played as u32) * ahead).scale(d.gain as f64);
        }
        let (re, im) = (z.re as f32, z.im as f32);
        // A pulse too big to refer back (`absorb_strike` left the mode silent): nothing to undo.
        if (re * re + im * im).is_finite() {
            (re, im)
        } else {
            (0.0, 0.0)
        }
    }
}

/// A pole's response to a unit pulse, referred to the sample before the pulse: kept for each
/// mode, whichever record holds it, since strikes on an object usually repeat their mallet and a
/// mode restarted from rest at the same pitch has the same pole.
#[derive(Debug, Clone, Copy)]
pub(super) struct CachedResponse {
    /// The pole it was worked out for.
    pole: Complex64,
    /// The pulse's shape and length in samples; a length of 0 in an empty entry, which no pulse
    /// matches.
    key: (PulseShape, u32),
    /// The response.
    response: Complex64,
}

impl CachedResponse {
    /// Nothing cached.
    pub const EMPTY: Self = Self {
        pole: Complex64::ZERO,
        key: (PulseShape::Impulse, 0),
        response: Complex64::ZERO,
    };

    /// The response of pole `p` to the unit pulse `prepared` of `key` (shape and length), from
    /// the cache or worked out and kept.
    fn get(&mut self, p: Complex64, key: (PulseShape, u32), prepared: &Prepared) -> Complex64 {
        if (self.pole, self.key) != (p, key) {
            *self = Self {
                pole: p,
                key,
                response: prepared.response(p, 0, u32::MAX),
            };
        }
        self.response
    }
}

/// The pulses under way when a new one comes.
struct UnderWay {
    /// How many earlier pulses are still playing.
    kept: usize,
    /// Samples from now until the last of them, the new one included, ends.
    span: u64,
    /// Sum of their amplitudes' magnitudes, the new one's included.
    reach: f32,
    /// Each earlier pulse still playing (the first `kept`): samples it has played, and its
    /// response constants.
    earlier: [(u32, Prepared); MAX_PULSES],
}

/// What the `earlier` pulses (samples played, response constants) have still to play, at unit
/// gain, referred back to now, for a mode of pole `p`.
fn still_to_play(p: Complex64, earlier: &[(u32, Prepared)]) -> Complex64 {
    let mut rest = Complex64::ZERO;
    for &(played, old) in earlier {
        rest += powi(p, played) * old.response(p, played, u32::MAX);
    }
    rest
}

/// `z^n` by repeated squaring, from one upward by the bits of `n`.
fn powi(z: Complex64, mut n: u32) -> Complex64 {
    let (mut base, mut acc) = (z, Complex64::ONE);
    while n > 0 {
        if n & 1 == 1 {
            acc *= base;
        }
        base = base * base;
        n >>= 1;
    }
    acc
}
