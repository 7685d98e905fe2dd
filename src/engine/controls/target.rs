//! What a channel-wide controller (the mod wheel, channel pressure) is set to move: a value of
//! the controls, read by the expression that moves them.

/// What the mod wheel or channel pressure moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExpressionTarget {
    /// Nothing.
    None,
    /// The strike position, towards the far end.
    Position,
    /// Damping of every mode, as a hand pressing on the object.
    Damping,
    /// The speed of a contact (scrape, roll, rub), from still to the fastest.
    Speed,
    /// The force of a contact.
    Force,
}

impl ExpressionTarget {
    /// Every target.
    pub const ALL: [ExpressionTarget; 5] = [
        ExpressionTarget::None,
        ExpressionTarget::Position,
        ExpressionTarget::Damping,
        ExpressionTarget::Speed,
        ExpressionTarget::Force,
    ];

    /// Lowercase name.
    pub fn name(self) -> &'static str {
        match self {
            ExpressionTarget::None => "none",
            ExpressionTarget::Position => "position",
            ExpressionTarget::Damping => "damping",
            ExpressionTarget::Speed => "speed",
            ExpressionTarget::Force => "force",
        }
    }

    /// The target with this lowercase name.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|t| t.name() == name)
    }
}
