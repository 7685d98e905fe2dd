//! Continuous contact: the force of an object scraped or rolled along a rough surface, or rubbed
//! by a finger or a stick, computed per sample from a few slowly varying inputs (contact speed and
//! normal force).
//!
//! Both read a *surface profile* at the contact point as it moves (seed 000 section 4.3, after van
//! den Doel, Kry and Pai's FoleyAutomatic): the height of the surface along the path, fractal noise
//! whose power falls as `k^-beta` with spatial frequency `k` (the roughness sets `beta`). Read at
//! speed `v`, a spatial frequency `k` sounds at `k v`: a faster scrape is brighter, the whole
//! spectrum sliding up with speed. The profile is a sum of octaves of smooth value noise (a
//! lattice of random heights per octave, eased between lattice points), each leaving the sum as
//! its frequency at the current speed nears the Nyquist frequency (eased value noise has some
//! energy above its lattice rate, which the contact's low-pass and the object's modes mostly
//! leave unheard).
//!
//! - **Scrape**: the profile seen through the contact (a low-pass whose corner is the speed over
//!   the width of the contact: a hard, sharp scraper feels finer detail), its rate of change
//!   driving the object: the contact point's vertical velocity, `v dh/dx`, scaled by the normal
//!   force. Faster is louder as well as brighter. The hand pressing the scraper on the object also
//!   damps it ([`ContactKind::damping_per_s`]): without that, a held scrape on a long-ringing
//!   object would fill its slowest modes over many seconds and wander with them, as narrow-band
//!   noise does.
//! - **Roll** (seed 004 section 5.3): the same ground profile low-passed by the contact patch of a
//!   rolling object of radius `r` (a wider patch, `sqrt(2 r d)` for an indentation `d`, smooths
//!   more, so a large ball rolls duller), plus the object's own bumps: eight per revolution, at a
//!   rate of speed over circumference, whose height and irregularity is the roughness: a perfect
//!   ball has none, an irregular one a pattern that repeats once a revolution.
//!
//! - **Rub**: stick-slip friction driving the object through its own motion, as a bow drives a
//!   bar (bowed-bar style, after McIntyre, Schumacher and Woodhouse's friction-driven
//!   oscillators): the force is the normal force times a friction coefficient that depends on
//!   the *relative* velocity `dv` of rubber and object at the contact point,
//!   `mu(dv) = tanh(dv / v_s) (mu_s - c ln(1 + |dv| / v0))`: the object sticks while `dv` is
//!   within `v_s` and slides with friction falling with the logarithm of `dv`, the velocity
//!   weakening of Dieterich and Ruina's rate-and-state friction, from `mu_s` to `mu_d` at the
//!   fastest rub ([`rub_friction`]). Where it slides, that falling friction feeds energy into the
//!   modes moving with the rubber (negative damping); a mode whose loss is smaller than that gain
//!   grows until it sticks and slips once a cycle, and then sings steadily at its own frequency,
//!   its contact point swinging at about the rubbing speed: a wine glass or a singing bowl, louder
//!   the faster it is rubbed. Below a force threshold no mode gains more than it loses, and the
//!   object stays silent. The friction's slope falls as `1 / dv` (a hyperbolic curve's falls as
//!   `1 / dv^2`), so the force a song needs rises about in proportion to its speed, as
//!   Schelleng's minimum bow force does: a firm touch sings across the whole speed range.
//!
//!   The rubber's speed changes at most [`RUB_MAX_ACCELERATION_M_PER_S2`], as a hand's does: a
//!   song catches only where the friction falls steeply, while the stroke is slow, and once caught
//!   it rides up with the speed (a bow's attack needs its acceleration bounded by its force too:
//!   Guettler, *On the creation of the Helmholtz motion in bowed strings*, Acta Acustica 2002).
//!   Brought up to speed within 5 ms, as the other contacts are, the factory glass never caught
//!   above 0.45 m/s.
//!
//!   The object's velocity at the contact point is the sum of its modes' velocities (see
//!   [`crate::dsp::resonator_bank::ResonatorBank::process_rubbed`]), one sample old, so the
//!   friction is computed explicitly; the sticking branch is made wide enough that this
//!   one-sample loop gains at most [`RUB_LOOP_GAIN`] per sample whatever the bank. The force is
//!   high-passed at [`RUB_DC_HZ`], so the steady drag does not push the object off its rest
//!   position.
//!
//! Speed and force are smoothed over [`SMOOTHING_S`], and the force starts from zero, so a contact
//! starts, stops and moves without a click.

use std::f64::consts::TAU;

use crate::rng::{bipolar, hash};

/// Time constant of the speed and force smoothing, in seconds.
pub const SMOOTHING_S: f64 = 0.005;

/// Spatial frequency of the profile's lowest octave, cycles per metre (features of 5 mm).
const LOWEST_CYCLES_PER_M: f64 = 200.0;

/// Octaves of the profile: up to 200 * 2^13 = 1.6 million cycles per metre (0.6 um features).
const OCTAVES: usize = 14;

/// Lattice cells of the lowest octave before the profile repeats (and the position wraps): 2^20
/// cells of 5 mm, 5 km of surface. Every octave's lattice repeats there too, so the wrap is
/// seamless.
const PERIOD_CELLS: f64 = (1u64 << PERIOD_BITS) as f64;

/// `log2` of [`PERIOD_CELLS`].
const PERIOD_BITS: u32 = 20;

/// How deep a rolling object sinks into the ground, in metres: its contact patch is `sqrt(2 r d)`.
const INDENTATION_M: f64 = 1e-5;

/// Bumps per revolution of a rolling object (seed 004 section 5.3: eight impulses of different
/// heights).
const BUMPS: usize = 8;

/// Width of a bump, as a share of the spacing between bumps.
const BUMP_WIDTH: f64 = 0.25;

/// Gain of a rolling object's ground noise, a fortieth of its bumps' (seed 004 section 5.3
/// turns the ground down too): the bumps carry the roll's rhythm.
const GROUND_GAIN: f32 = 0.4;

/// Force of a rolling object's tallest bump, relative: held, the factory table rolled on at
/// 0.6 m/s peaks at -11.4 dBFS over seconds 2 to 4, the factory steel sheet scraped at 0.4 m/s at
/// -8.5 dBFS (`tests/factory_presets.rs`).
const BUMP_GAIN: f32 = 16.0;

/// Decay rate a held scrape adds to every mode of the object, 1/s. The scraper is held by a
/// hand, a lossy mass coupled to the object through a stiff contact: a resistance `R` at a point
/// adds `R phi^2 / (2 M)` to the decay of a mode of modal mass `M` and shape `phi` there
/// (Rayleigh's dissipation function), and about 10 N s/m for a hand-held tool against the half
/// kilogram a mode of a 0.5 x 0.35 m, 1.5 mm steel sheet moves (`rho h S / 4`) gives several per
/// second. How hard the scraper presses changes the contact's stiffness, not the hand's loss, so
/// the level stays in proportion to the force. Without it the factory steel sheet's lowest mode
/// (0.28 /s, T60 25 s) took nearly all of a held scrape and filled over seconds: -6.1 dBFS after
/// 1 s, +1.3 after 10 s, +3.8 after 300 s.
const SCRAPE_DAMPING_PER_S: f64 = 3.0;

/// The vertical velocity is in units of the profile's RMS per lowest-octave cell crossed at this
/// speed, metres per second.
const REFERENCE_SPEED_M_PER_S: f64 = 1.0;

/// Static friction coefficient of a rub (at the edge of sticking).
const RUB_STATIC: f32 = 1.0;

/// Sliding friction coefficient of a rub at the fastest rub's speed, [`RUB_MAX_SPEED_M_PER_S`].
const RUB_DYNAMIC: f32 = 0.4;

/// Relative velocity at which a rub's friction starts to fall with its logarithm, m/s.
const RUB_FALL_M_PER_S: f32 = 0.05;

/// Least friction coefficient, reached only at relative velocities far beyond any rub's (the
/// logarithm would otherwise turn the friction round).
const RUB_LEAST: f32 = 0.1;

/// Width of a rub's sticking branch, m/s: within it the friction holds the rubber and the
/// contact point together.
const RUB_STICK_M_PER_S: f32 = 0.02;

/// How much the contact point's velocity may answer a change of friction force within one sample,
/// relative: the rub's sticking branch is never steeper than this share of the explicit loop's
/// stability limit (1).
pub const RUB_LOOP_GAIN: f32 = 0.5;

/// Acceleration of the contact point under full friction at full force, m/s^2 (the friction
/// force over the mass the contact point moves): enough for the factory glass, the lossiest
/// rubbed bank (2.3 /s), to sing up to the fastest rub at its default force (0.7); at 300 it
/// broke away above 1 m/s. More would flatten low modes pressed hard at slow speeds further.
const RUB_ACCELERATION: f64 = 400.0;

/// Fastest rub, m/s (the fastest contact the engine plays): a rub's level follows its speed.
const RUB_MAX_SPEED_M_PER_S: f64 = 3.0;

/// Fastest change of a rub's speed, m/s^2: a hand circling a rim takes a second to reach 1 m/s.
/// Measured on the factory glass at force 0.7, rubbed from rest: at 2 m/s^2 it no longer catches
/// at 2 and 3 m/s; at 1 m/s^2 it sings at every speed from 0.1 to 3 m/s.
const RUB_MAX_ACCELERATION_M_PER_S2: f64 = 1.0;

/// Corner of the high-pass on a rub's force, Hz.
pub const RUB_DC_HZ: f64 = 5.0;

/// The object's velocity at the contact point, m/s, per unit of the modes' summed velocity
/// (the state the resonators hold for a unit impulse): a rub's steady oscillation swings the
/// contact point at about the rubbing speed, so this sets its level: the factory glass and bowl
/// rubbed at the fastest speed, 3 m/s, peak near -2.5 dBFS, at 0.1 m/s near -33 dBFS.
const RUB_M_PER_S_PER_UNIT: f32 = 4.0;

/// The motion of a contact held with a note, as a player chooses it; [`ContactKind`] is the
/// contact it plays, with its size.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ContactMotion {
    /// Sliding along the surface ([`ContactKind::Scrape`]).
    Scrape,
    /// Rolling on it ([`ContactKind::Roll`]).
    Roll,
    /// Rubbing it ([`ContactKind::Rub`]).
    Rub,
}

/// How an object touches the surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ContactKind {
    /// Sliding along it, through a contact `width_m` wide.
    Scrape {
        /// Width of the contact, metres.
        width_m: f64,
    },
    /// Rolling on it: a round object of radius `radius_m`.
    Roll {
        /// Radius, metres.
        radius_m: f64,
    },
    /// Rubbing it: stick-slip friction (its force from [`Contact::rub`], not [`Contact::render`]).
    Rub,
}

impl ContactKind {
    /// Decay rate, 1/s, this contact adds to every mode of the object it touches while held: a
    /// scraper's hand damps the object ([`SCRAPE_DAMPING_PER_S`]). A rolling ball is held on by
    /// its weight alone, through a contact close to elastic (Hertz), and a rub's loss is its
    /// friction's own.
    pub fn damping_per_s(self) -> f64 {
        match self {
            ContactKind::Scrape { .. } => SCRAPE_DAMPING_PER_S,
            ContactKind::Roll { .. } | ContactKind::Rub => 0.0,
        }
    }
}

/// The contact force of one object on one surface.
#[derive(Debug, Clone)]
pub struct Contact {
    /// Scrape or roll, and its size.
    kind: ContactKind,
    /// Roughness, 0 (smooth) to 1 (rough).
    roughness: f32,
    /// Amplitude of each profile octave, normalised so the whole profile has unit RMS.
    octave_gain: [f32; OCTAVES],
    /// Seed of the profile's lattice.
    seed: u32,
    /// Position along the surface, in lattice cells of the lowest octave (wraps).
    position_cells: f64,
    /// Each bump's height, relative.
    bump_height: [f32; BUMPS],
    /// Each bump's place within its slot, in revolutions.
    bump_place: [f64; BUMPS],
    /// Phase of the rolling object, in revolutions `[0, 1)`.
    revolution: f64,
    /// Where the speed is going, metres per second: finite and not negative.
    target_speed: f64,
    /// Smoothed speed, metres per second.
    speed: f64,
    /// Smoothed normal force, relative.
    force: f32,
    /// State of the contact low-pass.
    low_pass: f32,
    /// The low-pass's output one sample earlier.
    last: f32,
    /// Each octave's last lattice cell and the heights either side of it.
    lattice: [(u64, (f32, f32)); OCTAVES],
    /// The low-pass coefficient, and the speed it is for.
    pole: f32,
    /// See `pole`.
    pole_speed: f64,
    /// A rub's force before its high-pass, one sample earlier.
    rub_last: f32,
    /// A rub's force after its high-pass.
    rub_out: f32,
    /// The high-pass's pole.
    rub_pole: f32,
    /// Sample rate, Hz.
    sample_rate_hz: f64,
    /// Smoothing coefficient per sample.
    smoothing: f64,
    /// Largest change of a rub's speed in one sample, m/s.
    rub_speed_step: f64,
}

impl Contact {
    /// A contact of `kind` at `roughness` (0 to 1), its surface drawn from `seed`, at rest.
    pub fn new(kind: ContactKind, roughness: f32, seed: u32, sample_rate_hz: f64) -> Self {
        let roughness = if roughness.is_finite() {
            roughness.clamp(0.0, 1.0)
        } else {
            0.5
        };
        // beta from 2.5 (smooth: fine detail weak) down to 1 (rough: detail as strong, per
        // octave of bandwidth, as coarse features). An octave's band holds power
        // `k^-beta * k`, so its amplitude goes as `k^((1 - beta) / 2)`.
        let beta = 2.5 - 1.5 * roughness as f64;
        let mut octave_gain: [f32; OCTAVES] =
            std::array::from_fn(|k| (2f64.powf(k as f64 * (1.0 - beta) / 2.0)) as f32);
        let norm = octave_gain.iter().map(|g| g * g).sum::<f32>().sqrt();
        octave_gain
            .iter_mut()
            .for_each(|g| *g /= norm * VALUE_NOISE_RMS);
        let mut bump_height = [1.0f32; BUMPS];
        let mut bump_place = [0.0f64; BUMPS];
        for j in 0..BUMPS {
            let (a, b) = (
                bipolar(hash(seed ^ 0xB0B, j as u32, 1)),
                bipolar(hash(seed ^ 0xB0B, j as u32, 2)),
            );
            bump_height[j] = roughness * (1.0 + 0.5 * a);
            bump_place[j] = (j as f64 + 0.5 * roughness as f64 * b as f64) / BUMPS as f64;
        }
        Self {
            kind,
            roughness,
            octave_gain,
            seed,
            position_cells: 0.0,
            bump_height,
            bump_place,
            revolution: 0.0,
            target_speed: 0.0,
            speed: 0.0,
            force: 0.0,
            low_pass: 0.0,
            last: 0.0,
            lattice: [(u64::MAX, (0.0, 0.0)); OCTAVES],
            pole: 0.0,
            pole_speed: 0.0,
            rub_last: 0.0,
            rub_out: 0.0,
            rub_pole: (-std::f64::consts::TAU * RUB_DC_HZ / sample_rate_hz).exp() as f32,
            sample_rate_hz,
            smoothing: 1.0 - (-1.0 / (SMOOTHING_S * sample_rate_hz)).exp(),
            rub_speed_step: RUB_MAX_ACCELERATION_M_PER_S2 / sample_rate_hz,
        }
    }

    /// Roughness, 0 to 1.
    pub fn roughness(&self) -> f32 {
        self.roughness
    }

    /// Moves the contact point to `cells` lattice cells of the lowest octave along the surface
    /// (wrapped to the surface's length), without smoothing: for a contact starting afresh.
    pub fn move_to(&mut self, cells: u32) {
        self.position_cells = cells as f64 % PERIOD_CELLS;
    }

    /// Scrape or roll, and its size.
    pub fn kind(&self) -> ContactKind {
        self.kind
    }

    /// Changes the size of the contact (scrape width, rolling radius) from the next sample; the
    /// kind stays what it was.
    pub fn set_kind(&mut self, kind: ContactKind) {
        if std::mem::discriminant(&kind) == std::mem::discriminant(&self.kind) {
            self.kind = kind;
            // The low-pass's corner moves with the width.
            self.pole_speed = f64::NAN;
        }
    }

    /// Moves the contact towards `speed_m_per_s` from the next sample, smoothly; non-finite or
    /// negative speeds count as zero. Every speed a contact plays comes through here.
    pub fn set_speed(&mut self, speed_m_per_s: f32) {
        self.target_speed = if speed_m_per_s.is_finite() {
            speed_m_per_s.max(0.0) as f64
        } else {
            0.0
        };
    }

    /// Lets the contact go at once: force and speed back to zero, the low-pass emptied.
    pub fn reset(&mut self) {
        self.target_speed = 0.0;
        self.speed = 0.0;
        self.force = 0.0;
        self.low_pass = 0.0;
        self.last = 0.0;
        self.rub_last = 0.0;
        self.rub_out = 0.0;
    }

    /// Whether the smoothed force has died away (the contact has ended).
    pub fn is_silent(&self) -> bool {
        self.force.abs() < 1e-6
    }

    /// Adds the contact force for the next `out.len()` samples into `out`, as speed moves
    /// towards [`Contact::set_speed`]'s and force towards `force` (relative, 1 is a firm touch;
    /// non-finite or negative counts as zero). A rub adds nothing here: its force answers the
    /// object's motion, sample by sample ([`Contact::rub`]).
    pub fn render(&mut self, force: f32, out: &mut [f32]) {
        let (target_speed, target_force) = (self.target_speed, sanitized_force(force));
        let k = self.smoothing;
        let dt = 1.0 / self.sample_rate_hz;
        let width_m = match self.kind {
            ContactKind::Scrape { width_m } => width_m.max(1e-6),
            ContactKind::Roll { radius_m } => (2.0 * radius_m.max(1e-4) * INDENTATION_M).sqrt(),
            ContactKind::Rub => return,
        };
        let reference_cells = REFERENCE_SPEED_M_PER_S * dt * LOWEST_CYCLES_PER_M;
        let slope_scale = (1.0 / reference_cells) as f32;
        for y in out.iter_mut() {
            self.speed += (target_speed - self.speed) * k;
            if (target_speed - self.speed).abs() < 1e-9 {
                self.speed = target_speed;
            }
            self.force += (target_force - self.force) * k as f32;
            let cells = self.speed * dt * LOWEST_CYCLES_PER_M;
            self.position_cells += cells;
            if self.position_cells >= PERIOD_CELLS {
                self.position_cells -= PERIOD_CELLS;
            }
            let height = self.profile();
            // The contact's low-pass: corner at speed over width (recomputed only as the speed
            // moves).
            if self.speed != self.pole_speed {
                self.pole_speed = self.speed;
                self.pole = 1.0 - (-TAU * self.speed / width_m * dt).exp() as f32;
            }
            let a = self.pole;
            self.low_pass += (height - self.low_pass) * a;
            // Vertical velocity: the change of height per sample, in profile RMS per lattice
            // cell of the reference speed.
            let slope = (self.low_pass - self.last) * slope_scale;
            self.last = self.low_pass;
            *y += self.force
                * match self.kind {
                    ContactKind::Scrape { .. } => slope,
                    ContactKind::Roll { radius_m } => {
                        let turn = self.speed * dt / (TAU * radius_m.max(1e-4));
                        self.revolution = (self.revolution + turn).fract();
                        GROUND_GAIN * slope + BUMP_GAIN * self.bumps()
                    }
                    ContactKind::Rub => 0.0,
                };
        }
    }

    /// A rub's force on the object for the next sample, as speed moves towards
    /// [`Contact::set_speed`]'s and force towards `force` (relative, 1 is a firm touch;
    /// non-finite or negative counts as zero), given the object's velocity at the contact point now: `velocity`, the sum of its
    /// modes' velocities with the sign of their gains, and `gain_sum`, the sum of their gains'
    /// magnitudes (how far that velocity moves for a unit force in one sample).
    #[inline]
    pub fn rub(&mut self, force: f32, velocity: f32, gain_sum: f32) -> f32 {
        let target_speed = self.target_speed.min(RUB_MAX_SPEED_M_PER_S);
        let target_force = sanitized_force(force);
        let k = self.smoothing;
        // The speed moves as a hand does, at a bounded acceleration.
        let step = self.rub_speed_step;
        self.speed += ((target_speed - self.speed) * k).clamp(-step, step);
        self.force += (target_force - self.force) * k as f32;
        // Settled values snap to their targets (no subnormal tail on the way to zero).
        if (target_speed - self.speed).abs() < 1e-9 {
            self.speed = target_speed;
        }
        if (target_force - self.force).abs() < 1e-9 {
            self.force = target_force;
        }
        let relative_m_per_s = self.speed as f32 - RUB_M_PER_S_PER_UNIT * velocity;
        // A unit force moves the contact point `RUB_M_PER_S_PER_UNIT * gain_sum` in one sample:
        // full friction at full force accelerates it at `RUB_ACCELERATION`.
        let per_sample = (RUB_ACCELERATION / self.sample_rate_hz) as f32;
        let scale = per_sample / (RUB_M_PER_S_PER_UNIT * gain_sum.max(1e-12));
        // The sticking branch as narrow as asked, or as the one-sample loop allows at this force.
        let stick_m_per_s =
            RUB_STICK_M_PER_S.max(per_sample * RUB_STATIC * self.force / RUB_LOOP_GAIN);
        let friction = rub_friction(relative_m_per_s, stick_m_per_s);
        let drag = self.force * scale * friction;
        let drag = if drag.is_finite() { drag } else { 0.0 };
        // One-pole high-pass: y = p (y + x - x_prev).
        self.rub_out = self.rub_pole * (self.rub_out + drag - self.rub_last);
        self.rub_last = drag;
        self.rub_out
    }

    /// The surface's height at the contact point: the sum of the octaves still under the
    /// Nyquist frequency at the current speed.
    fn profile(&mut self) -> f32 {
        // An octave's weight falls from 1 at half the Nyquist frequency to 0 at it.
        let per_hz = 4.0 / self.sample_rate_hz;
        let mut sum = 0.0f32;
        let mut freq_hz = self.speed * LOWEST_CYCLES_PER_M;
        let mut scale = 1.0;
        for k in 0..OCTAVES {
            // Full weight up to half the Nyquist frequency, none from it on.
            let weight = (2.0 - freq_hz * per_hz).clamp(0.0, 1.0) as f32;
            if weight == 0.0 {
                break;
            }
            let x = self.position_cells * scale;
            let cell = x.floor();
            let t = (x - cell) as f32;
            // The lattice heights either side, hashed again only when the cell changes (most
            // samples stay in one).
            let cached = &mut self.lattice[k];
            let i = cell as u64 & ((1u64 << (PERIOD_BITS + k as u32)) - 1);
            if cached.0 != i {
                *cached = (i, lattice_heights(self.seed, k as u32, i));
            }
            let (a, b) = cached.1;
            let s = t * t * (3.0 - 2.0 * t);
            sum += weight * self.octave_gain[k] * (a + (b - a) * s);
            freq_hz *= 2.0;
            scale *= 2.0;
        }
        sum
    }

    /// The rolling object's bumps at its current phase: raised-cosine pulses, one per slot.
    fn bumps(&self) -> f32 {
        let slot = 1.0 / BUMPS as f64;
        let half = 0.5 * BUMP_WIDTH * slot;
        let mut sum = 0.0f32;
        for j in 0..BUMPS {
            let mut d = self.revolution - self.bump_place[j];
            d -= d.round();
            if d.abs() < half {
                let shape = 0.5 + 0.5 * (std::f64::consts::PI * d / half).cos();
                sum += self.bump_height[j] * shape as f32;
            }
        }
        sum
    }
}

/// A rub's friction coefficient at relative velocity `dv_m_per_s` of rubber and object, with a
/// sticking branch `stick_m_per_s` wide: `tanh(dv / v_s) (mu_s - c ln(1 + |dv| / v0))`, falling
/// from [`RUB_STATIC`] to [`RUB_DYNAMIC`] at the fastest rub. Steady sliding friction falling with
/// the logarithm of the sliding speed is the velocity weakening of rate-and-state friction
/// (Dieterich 1979; Ruina, *Slip instability and state variable friction laws*, JGR 1983).
#[inline]
fn rub_friction(dv_m_per_s: f32, stick_m_per_s: f32) -> f32 {
    // The fall over the whole range, per unit of the logarithm.
    let per_log =
        (RUB_STATIC - RUB_DYNAMIC) / (1.0 + RUB_MAX_SPEED_M_PER_S as f32 / RUB_FALL_M_PER_S).ln();
    let sliding = RUB_STATIC - per_log * (1.0 + dv_m_per_s.abs() / RUB_FALL_M_PER_S).ln();
    (dv_m_per_s / stick_m_per_s).tanh() * sliding.max(RUB_LEAST)
}

/// A force target with non-finite or negative values taken as zero.
fn sanitized_force(force: f32) -> f32 {
    if force.is_finite() {
        force.max(0.0)
    } else {
        0.0
    }
}

/// RMS of the eased lattice heights over a long path (lattice values uniform in [-1, 1], eased):
/// measured, to normalise the profile.
const VALUE_NOISE_RMS: f32 = 0.48;

/// The random heights in [-1, 1) of `octave`'s lattice at cell `i` and the next: the profile
/// eases between them (smoothstep), so it has no kinks. The lattice repeats every
/// `PERIOD_CELLS << octave` cells.
#[inline]
fn lattice_heights(seed: u32, octave: u32, i: u64) -> (f32, f32) {
    let mask = (1u64 << (PERIOD_BITS + octave)) - 1;
    // Hashed on the low 32 bits and the octave: distinct within a period of up to 2^32 cells.
    (
        bipolar(hash(seed, octave, i as u32)),
        bipolar(hash(seed, octave, ((i + 1) & mask) as u32)),
    )
}

#[cfg(test)]
mod tests;
