//! What excites the resonators: strikes (impulses, mallet force pulses and noise bursts) and
//! the contact held with a note (scrape, roll, rub: [`super::contact`]).
//!
//! Each strike becomes a short input signal of unit area (impulse, mallet) or unit energy (noise)
//! times its amplitude, so a mode's response to it has the mode's own amplitude for an impulse.
//! Several strikes may overlap on one voice; their pulses add.

use std::f32::consts::TAU;

use super::contact::{Contact, ContactKind, ContactMotion};
use crate::rng::Rng;

/// Level of a contact's force against a strike's: a scrape at 0.5 m/s and the default force
/// (0.7), held, drives a bank to about the level of the first half second of a mallet strike at
/// full velocity (2.3 dB below it on a bank of 200 modes from 110 Hz in `tests/contact.rs`, the
/// scraper's hand damping the modes).
const CONTACT_GAIN: f32 = 3.7e-4;

/// How many overlapping strikes one voice keeps; a further strike replaces the oldest.
pub const MAX_PULSES: usize = 4;

/// How a note excites the object: one of three strikes, or one of three contacts held with the
/// note. The exciter control, the plugin's exciter parameter and a bank's `defaults.exciter`
/// name it ([`ExciterKind::name`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ExciterKind {
    /// A single sample ([`StrikeKind::Impulse`]).
    Impulse,
    /// A mallet's force pulse ([`StrikeKind::Mallet`]).
    #[default]
    Mallet,
    /// A noise burst: a brush ([`StrikeKind::Noise`]).
    Noise,
    /// Scraping for as long as the note is held ([`ContactMotion::Scrape`]).
    Scrape,
    /// Rolling for as long as the note is held ([`ContactMotion::Roll`]).
    Roll,
    /// Rubbing for as long as the note is held ([`ContactMotion::Rub`]).
    Rub,
}

impl ExciterKind {
    /// Every kind, for parameter lists.
    pub const ALL: [ExciterKind; 6] = [
        ExciterKind::Impulse,
        ExciterKind::Mallet,
        ExciterKind::Noise,
        ExciterKind::Scrape,
        ExciterKind::Roll,
        ExciterKind::Rub,
    ];

    /// Lowercase name.
    pub fn name(self) -> &'static str {
        match self {
            ExciterKind::Impulse => "impulse",
            ExciterKind::Mallet => "mallet",
            ExciterKind::Noise => "noise",
            ExciterKind::Scrape => "scrape",
            ExciterKind::Roll => "roll",
            ExciterKind::Rub => "rub",
        }
    }

    /// The kind with this lowercase name.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }

    /// What a note of this kind does: strike the object, or hold a contact on it.
    pub fn excitation(self) -> Excitation {
        match self {
            ExciterKind::Impulse => Excitation::Strike(StrikeKind::Impulse),
            ExciterKind::Mallet => Excitation::Strike(StrikeKind::Mallet),
            ExciterKind::Noise => Excitation::Strike(StrikeKind::Noise),
            ExciterKind::Scrape => Excitation::Contact(ContactMotion::Scrape),
            ExciterKind::Roll => Excitation::Contact(ContactMotion::Roll),
            ExciterKind::Rub => Excitation::Contact(ContactMotion::Rub),
        }
    }

    /// The contact held with the note, if the note holds one (scrape, roll, rub).
    pub fn contact(self) -> Option<ContactMotion> {
        match self.excitation() {
            Excitation::Strike(_) => None,
            Excitation::Contact(motion) => Some(motion),
        }
    }

    /// Whether the note holds a contact (scrape, roll, rub) rather than striking.
    pub fn is_contact(self) -> bool {
        self.contact().is_some()
    }

    /// The strike a note of this kind gives when its key is struck: its own, or for a contact
    /// note a knock of a mallet (a key struck again while its contact goes on).
    pub fn knock(self) -> StrikeKind {
        match self.excitation() {
            Excitation::Strike(kind) => kind,
            Excitation::Contact(_) => StrikeKind::Mallet,
        }
    }

    /// The strike's shape when it is known in full in advance (impulse, mallet); `None` for
    /// noise and contact, whose samples are not. This alone decides what pruning may take
    /// analytically.
    pub fn pulse_shape(self) -> Option<PulseShape> {
        match self.excitation() {
            Excitation::Strike(kind) => kind.pulse_shape(),
            Excitation::Contact(_) => None,
        }
    }

    /// Bound on a mode's amplitude after this kind's strike ([`ExciterKind::knock`]) of unit
    /// amplitude over `len_samples`, relative to its gain ([`StrikeKind::peak_bound`]); a
    /// contact's own force is not bounded in advance.
    pub fn peak_bound(self, len_samples: u32) -> f32 {
        self.knock().peak_bound(len_samples)
    }
}

/// What a note does to the object.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Excitation {
    /// Strikes it once, when the key is struck.
    Strike(StrikeKind),
    /// Holds a contact on it for as long as the note is held.
    Contact(ContactMotion),
}

/// The shape of a strike: a short input signal of unit area (impulse, mallet) or unit energy
/// (noise) times its amplitude.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StrikeKind {
    /// A single sample: every mode at its full amplitude.
    Impulse,
    /// Raised-cosine force pulse `1 - cos(2 pi t / T)` over the contact time T (van den Doel,
    /// seed 000 eq. 4.5): short T is a hard, bright mallet, long T a soft, dull one.
    Mallet,
    /// White noise under a linearly falling envelope over the contact time: a brush.
    Noise,
}

impl StrikeKind {
    /// The strike's shape when it is known in full in advance (impulse, mallet); `None` for
    /// noise, whose samples are not.
    pub fn pulse_shape(self) -> Option<PulseShape> {
        match self {
            StrikeKind::Impulse => Some(PulseShape::Impulse),
            StrikeKind::Mallet => Some(PulseShape::Mallet),
            StrikeKind::Noise => None,
        }
    }

    /// Bound on a mode's amplitude after a strike of unit amplitude, relative to its gain: 1 for
    /// unit-area pulses; for noise of `len` samples and unit energy, `sqrt(len)` (Cauchy-Schwarz).
    pub fn peak_bound(self, len_samples: u32) -> f32 {
        match self {
            StrikeKind::Impulse | StrikeKind::Mallet => 1.0,
            StrikeKind::Noise => (len_samples.max(1) as f32).sqrt(),
        }
    }
}

/// The shape of a strike known in full when it comes: what a dormant mode can take without
/// being computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PulseShape {
    /// A single sample.
    Impulse,
    /// A raised cosine `(A / L) (1 - cos(2 pi (j + 1/2) / L))` over `L` samples (the mallet).
    Mallet,
}

/// One strike in progress.
#[derive(Debug, Clone, Copy)]
struct StrikeUnderWay {
    /// Shape of the pulse.
    kind: StrikeKind,
    /// Scale of the pulse: its area (impulse, mallet) or the square root of its energy (noise).
    amplitude: f32,
    /// Length in samples.
    len: u32,
    /// Samples already emitted.
    pos: u32,
    /// Noise scale making the burst's energy `amplitude^2`.
    noise_scale: f32,
}

/// The strikes under way on one voice, and its contact.
#[derive(Debug, Clone)]
pub struct Exciter {
    /// Active pulses; the first `count` are in use.
    pulses: [StrikeUnderWay; MAX_PULSES],
    /// Number of active pulses.
    count: usize,
    /// The contact held with the note (scrape, roll, rub), while `in_contact`.
    contact: Contact,
    /// Whether a contact is under way: held, or dying away after its release.
    in_contact: bool,
    /// Whether the contact under way has been let go: it ends once its force has died away. A
    /// contact held at no force carries on (a player may press again).
    contact_released: bool,
    /// Where the contact's normal force is going, 0 to 1.
    contact_force: f32,
    /// Noise source, reseeded on reset so output repeats.
    rng: Rng,
    /// Seed restored by `reset`.
    seed: u32,
}

impl Exciter {
    /// An idle exciter whose noise starts from `seed`.
    pub fn new(seed: u32) -> Self {
        let idle = StrikeUnderWay {
            kind: StrikeKind::Impulse,
            amplitude: 0.0,
            len: 0,
            pos: 0,
            noise_scale: 0.0,
        };
        Self {
            pulses: [idle; MAX_PULSES],
            count: 0,
            contact: Contact::new(ContactKind::Scrape { width_m: 1e-3 }, 0.5, seed, 48_000.0),
            in_contact: false,
            contact_released: false,
            contact_force: 0.0,
            rng: Rng::new(seed),
            seed,
        }
    }

    /// Drops every pulse and restarts the noise sequence.
    pub fn reset(&mut self) {
        self.count = 0;
        self.in_contact = false;
        self.contact_released = false;
        self.contact.reset();
        self.rng = Rng::new(self.seed);
    }

    /// Whether no strike or contact is under way.
    pub fn is_idle(&self) -> bool {
        self.count == 0 && !self.in_contact
    }

    /// Starts a contact of `kind` at `roughness` moving towards `speed_m_per_s` and `force`
    /// from the next sample (from no force, so without a click); a contact of the same kind
    /// under way carries on towards them.
    pub fn start_contact(
        &mut self,
        kind: ContactKind,
        roughness: f32,
        sample_rate_hz: f64,
        speed_m_per_s: f32,
        force: f32,
    ) {
        let same = self.in_contact
            && std::mem::discriminant(&self.contact.kind()) == std::mem::discriminant(&kind)
            && self.contact.roughness() == roughness;
        if !same {
            self.contact = Contact::new(kind, roughness, self.seed, sample_rate_hz);
            // Each contact starts somewhere else on the surface.
            self.contact.move_to(self.rng.next_u32());
        } else {
            self.contact.set_kind(kind);
        }
        self.in_contact = true;
        self.contact_released = false;
        self.contact.set_speed(speed_m_per_s);
        self.contact_force = force;
    }

    /// Moves the contact under way towards `speed_m_per_s` and `force`, unless it has been let
    /// go.
    pub fn set_contact(&mut self, speed_m_per_s: f32, force: f32) {
        if !self.contact_released {
            self.contact.set_speed(speed_m_per_s);
            self.contact_force = force;
        }
    }

    /// Lets the contact go: its force falls to nothing, and it ends.
    pub fn release_contact(&mut self) {
        self.contact_released = true;
        self.contact_force = 0.0;
    }

    /// Whether a contact is held (under way and not let go).
    pub fn holds_contact(&self) -> bool {
        self.in_contact && !self.contact_released
    }

    /// Decay rate the contact held adds to every mode of the object, 1/s
    /// ([`ContactKind::damping_per_s`]); none once it has been let go.
    pub fn contact_damping_per_s(&self) -> f64 {
        if self.holds_contact() {
            self.contact.kind().damping_per_s()
        } else {
            0.0
        }
    }

    /// Whether a rub is under way: its force comes sample by sample from [`Exciter::rub_force`]
    /// rather than from [`Exciter::render`].
    pub fn is_rubbing(&self) -> bool {
        self.in_contact && self.contact.kind() == ContactKind::Rub
    }

    /// The rub's force for the next sample, given the object's velocity at the contact point
    /// and the sum of its gains' magnitudes ([`Contact::rub`]). Zero when no rub is under way.
    #[inline]
    pub fn rub_force(&mut self, velocity: f32, gain_sum: f32) -> f32 {
        if !self.is_rubbing() {
            return 0.0;
        }
        self.contact.rub(self.contact_force, velocity, gain_sum)
    }

    /// How many strikes are under way.
    pub fn num_under_way(&self) -> usize {
        self.count
    }

    /// Bound on how much the strikes still under way can add to a mode's amplitude, relative to
    /// its gain: the sum of their whole pulses' bounds ([`StrikeKind::peak_bound`]).
    pub fn pending_bound(&self) -> f32 {
        self.pulses[..self.count]
            .iter()
            .map(|p| p.amplitude.abs() * p.kind.peak_bound(p.len))
            .sum()
    }

    /// Starts a strike of `amplitude` lasting `len_samples` (at least 1) from the next sample
    /// rendered (contacts start with [`Exciter::start_contact`]).
    pub fn strike(&mut self, kind: StrikeKind, amplitude: f32, len_samples: u32) {
        let len = if kind == StrikeKind::Impulse {
            1
        } else {
            len_samples.max(1)
        };
        // Linear envelope (1 - n/len) for n = 0..len: its squares sum to (len + 1)(2 len + 1) /
        // (6 len). Uniform noise has variance 1/3.
        let l = len as f32;
        let env_energy = (l + 1.0) * (2.0 * l + 1.0) / (6.0 * l);
        let noise_scale = (3.0 / env_energy.max(1e-9)).sqrt();
        let pulse = StrikeUnderWay {
            kind,
            amplitude,
            len,
            pos: 0,
            noise_scale,
        };
        if self.count < MAX_PULSES {
            self.pulses[self.count] = pulse;
            self.count += 1;
        } else {
            self.pulses.rotate_left(1);
            self.pulses[MAX_PULSES - 1] = pulse;
        }
    }

    /// Writes the excitation for the next `out.len()` samples into `out` (overwriting it).
    /// Returns whether any pulse contributed.
    pub fn render(&mut self, out: &mut [f32]) -> bool {
        if self.count == 0 && !self.in_contact {
            return false;
        }
        out.fill(0.0);
        if self.in_contact {
            self.contact.render(CONTACT_GAIN * self.contact_force, out);
            if self.contact_released && self.contact.is_silent() {
                self.in_contact = false;
            }
        }
        let mut i = 0;
        while i < self.count {
            let p = &mut self.pulses[i];
            let n = ((p.len - p.pos) as usize).min(out.len());
            match p.kind {
                StrikeKind::Impulse => {
                    if n > 0 {
                        out[0] += p.amplitude;
                    }
                }
                StrikeKind::Mallet => {
                    if p.len == 1 {
                        out[0] += p.amplitude;
                    } else {
                        // Raised cosine sampled at cell centres: sums to exactly `len`.
                        let scale = p.amplitude / p.len as f32;
                        let step = TAU / p.len as f32;
                        for (k, x) in out[..n].iter_mut().enumerate() {
                            let phase = (p.pos as usize + k) as f32 + 0.5;
                            *x += scale * (1.0 - (step * phase).cos());
                        }
                    }
                }
                StrikeKind::Noise => {
                    let inv_len = 1.0 / p.len as f32;
                    for (k, x) in out[..n].iter_mut().enumerate() {
                        let env = 1.0 - (p.pos as usize + k) as f32 * inv_len;
                        *x += p.amplitude * p.noise_scale * env * self.rng.bipolar();
                    }
                }
            }
            p.pos += n as u32;
            if p.pos >= p.len {
                self.pulses.copy_within(i + 1..self.count, i);
                self.count -= 1;
            } else {
                i += 1;
            }
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn total(kind: StrikeKind, len: u32, block: usize) -> (f32, f32) {
        let mut e = Exciter::new(7);
        e.strike(kind, 0.5, len);
        let mut sum = 0.0;
        let mut energy = 0.0;
        let mut buf = vec![0.0; block];
        while e.render(&mut buf) {
            sum += buf.iter().sum::<f32>();
            energy += buf.iter().map(|x| x * x).sum::<f32>();
        }
        (sum, energy)
    }

    #[test]
    fn each_kind_strikes_or_holds_a_contact_under_its_own_name() {
        let names = ExciterKind::ALL.map(|k| k.name());
        assert_eq!(
            names,
            ["impulse", "mallet", "noise", "scrape", "roll", "rub"]
        );
        for kind in ExciterKind::ALL {
            assert_eq!(ExciterKind::from_name(kind.name()), Some(kind));
            let contact = matches!(kind.excitation(), Excitation::Contact(_));
            assert_eq!(kind.is_contact(), contact, "{kind:?}");
            assert_eq!(kind.contact().is_some(), contact, "{kind:?}");
            // A contact note's key knocks as a mallet.
            if let Excitation::Strike(strike) = kind.excitation() {
                assert_eq!(kind.knock(), strike);
            } else {
                assert_eq!(kind.knock(), StrikeKind::Mallet);
            }
        }
    }

    #[test]
    fn a_contact_let_go_is_no_longer_held_while_it_dies_away() {
        let mut e = Exciter::new(7);
        assert!(!e.holds_contact());
        e.start_contact(
            ContactKind::Scrape { width_m: 1e-3 },
            0.5,
            48_000.0,
            0.5,
            0.7,
        );
        let mut buf = [0.0f32; 480];
        assert!(e.render(&mut buf) && e.holds_contact());
        e.release_contact();
        // Still sounding (its force falls over a few ms), but not held: a key struck now does
        // not knock.
        assert!(e.render(&mut buf[..8]) && !e.is_idle());
        assert!(!e.holds_contact());
    }

    #[test]
    fn pulses_have_unit_area_or_energy_whatever_the_block() {
        for block in [1, 7, 64] {
            let (area, _) = total(StrikeKind::Impulse, 10, block);
            assert!((area - 0.5).abs() < 1e-6, "impulse area {area}");
            for len in [1, 2, 48, 960] {
                let (area, _) = total(StrikeKind::Mallet, len, block);
                assert!(
                    (area - 0.5).abs() < 1e-4,
                    "mallet len {len} block {block}: area {area}"
                );
            }
            let (_, energy) = total(StrikeKind::Noise, 4800, block);
            assert!((energy / 0.25 - 1.0).abs() < 0.1, "noise energy {energy}");
        }
    }
}
