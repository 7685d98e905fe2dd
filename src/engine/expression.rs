//! The player's channel-wide controllers (pitch bend, mod wheel, channel pressure) and what they
//! move: the engine keeps where each is and plays its controls as they move them, from the sample
//! each change arrives on, in the plugins and in the renderer alike.

use super::controls::{Controls, ExpressionTarget, CONTACT_SPEED_MAX_M_PER_S};

/// A channel-wide controller moving, from its sample on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ControlChange {
    /// Pitch bend, -1 to 1.
    Bend(f32),
    /// Mod wheel, 0 to 1.
    ModWheel(f32),
    /// Channel pressure, 0 to 1.
    Pressure(f32),
}

/// Where the channel-wide controllers are.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Controllers {
    /// Pitch bend, -1 to 1.
    pub bend: f32,
    /// Mod wheel, 0 to 1.
    pub mod_wheel: f32,
    /// Channel pressure, 0 to 1.
    pub pressure: f32,
}

impl Controllers {
    /// Moves one controller (non-finite values are ignored; the others are clamped to range).
    pub fn apply(&mut self, change: ControlChange) {
        let (slot, value, lowest) = match change {
            ControlChange::Bend(v) => (&mut self.bend, v, -1.0),
            ControlChange::ModWheel(v) => (&mut self.mod_wheel, v, 0.0),
            ControlChange::Pressure(v) => (&mut self.pressure, v, 0.0),
        };
        if value.is_finite() {
            *slot = value.clamp(lowest, 1.0);
        }
    }
}

impl Controls {
    /// These controls as the controllers move them: the bend adds its share of the bend range
    /// to the pitch bend, and the mod wheel and pressure each move their target (the strike
    /// position towards the far end, damping, or a contact's speed or force). Pressure routed to
    /// damping does not damp a contact: it is the contact notes' own force
    /// ([`super::MidiInput`]).
    pub fn expressed(&self, c: &Controllers) -> Controls {
        let mut out = self.clone();
        out.pitch_bend_semitones += c.bend * self.bend_range_semitones;
        let pressure_target = match self.pressure_target {
            ExpressionTarget::Damping if self.exciter.is_contact() => ExpressionTarget::None,
            target => target,
        };
        for (target, amount) in [
            (self.mod_wheel_target, c.mod_wheel),
            (pressure_target, c.pressure),
        ] {
            match target {
                ExpressionTarget::None => {}
                ExpressionTarget::Position => out.strike_x += amount * (1.0 - out.strike_x),
                ExpressionTarget::Damping => out.extra_damping += amount,
                ExpressionTarget::Speed => {
                    out.contact_speed_m_per_s = amount * CONTACT_SPEED_MAX_M_PER_S
                }
                ExpressionTarget::Force => out.contact_force = amount,
            }
        }
        out.extra_damping = out.extra_damping.min(1.0);
        out
    }
}
