//! Strike points on a disc (drum heads, circular plates) and the angular part of its modes.
//!
//! A mode of a disc with `m` nodal diameters is `R(r) cos(m theta)`, and for `m > 0` it has a
//! twin `R(r) sin(m theta)` at the same frequency. Angles are measured from the x axis, so with
//! every position on it (`y = 0`) the sine twins are silent everywhere and are left out; they are
//! added, for the orders that need them, when some position is off the axis.

use super::ShapedMode;

/// Below this `|sin(m theta)|` a position is taken to be on a nodal diameter of the sine twin.
const ON_AXIS_EPS: f64 = 1e-9;

/// The factor that gives `R(r) cos(m theta)` unit mean square over the unit disc, from
/// `integral = int_0^1 R(r)^2 r dr`: the mean square is `2 integral` for `m = 0` and `integral`
/// otherwise (the mean of `cos^2` is a half).
pub(super) fn unit_mean_square_scale(m: usize, integral: f64) -> f64 {
    if m == 0 {
        1.0 / (2.0 * integral).sqrt()
    } else {
        1.0 / integral.sqrt()
    }
}

/// Strike positions on a disc, in polar form.
pub(super) struct DiscPoints {
    /// `(r, theta)` of each position: `r` in fractions of the radius, `theta` in radians.
    polar: Vec<(f64, f64)>,
}

impl DiscPoints {
    /// The positions at `coords`, `(x, y)` in fractions of the radius from the centre.
    pub fn new(coords: &[[f64; 2]]) -> Self {
        Self {
            polar: coords
                .iter()
                .map(|&[x, y]| (x.hypot(y), y.atan2(x)))
                .collect(),
        }
    }

    /// Whether some position is off every nodal diameter of the sine twin of order `m`.
    pub fn needs_sine(&self, m: usize) -> bool {
        m > 0
            && self
                .polar
                .iter()
                .any(|&(_, angle)| (m as f64 * angle).sin().abs() > ON_AXIS_EPS)
    }

    /// How many modes order `m` contributes per radial solution: 2 with a sine twin, else 1.
    pub fn modes_per_root(&self, m: usize) -> usize {
        if self.needs_sine(m) {
            2
        } else {
            1
        }
    }

    /// Pushes onto `modes` the mode of order `m` at `freq_hz` whose radial part is `radial`,
    /// scaled so that `radial(r) cos(m theta)` has unit mean square over the disc (see
    /// [`unit_mean_square_scale`]). Adds the sine twin when a position needs it.
    pub fn push_modes(
        &self,
        modes: &mut Vec<ShapedMode>,
        freq_hz: f64,
        m: usize,
        radial: impl Fn(f64) -> f64,
    ) {
        let values: Vec<f64> = self.polar.iter().map(|&(r, _)| radial(r)).collect();
        let angular = |f: fn(f64) -> f64| -> Vec<f64> {
            values
                .iter()
                .zip(&self.polar)
                .map(|(value, &(_, angle))| value * f(m as f64 * angle))
                .collect()
        };
        modes.push(ShapedMode {
            freq_hz,
            shape: angular(f64::cos),
        });
        if self.needs_sine(m) {
            modes.push(ShapedMode {
                freq_hz,
                shape: angular(f64::sin),
            });
        }
    }
}
