//! `--normalize`: the gain that brings a render's peak to a level, found by rendering it.

use std::convert::Infallible;
use std::sync::Arc;

use super::{render_to, RenderSettings, Score};
use crate::engine::{control_range, PreparedBank};
use crate::units::gain_to_db;

/// The gain that brings the peak of `score`'s render to `peak_dbfs`, measured by rendering it
/// (renders are reproducible, so a second, scaled render has the same samples), calling
/// `progress` with the fraction done (0 to 1).
///
/// Modes stop at the truncation threshold before the scaling: a render to be raised stops them
/// as far lower in `settings` (down to the lowest threshold), or its tail would end in an
/// audible cut; its peak is then measured again with that threshold, since more modes start
/// under it. A silent render gets a gain of 1.
pub fn normalizing_scale(
    bank: &Arc<PreparedBank>,
    score: Score,
    settings: &mut RenderSettings,
    peak_dbfs: f32,
    mut progress: impl FnMut(f64),
) -> f32 {
    let target = 10f32.powf(peak_dbfs / 20.0);
    let mut peak_of = |settings: &RenderSettings, from: f64| {
        let quiet = |_: &[f32], _: &[f32]| Ok::<(), Infallible>(());
        let Ok(pass) = render_to(
            bank,
            score,
            settings,
            1.0,
            |d| progress(from + 0.5 * d),
            quiet,
        );
        pass.peak
    };
    let mut peak = peak_of(settings, 0.0);
    if peak > 0.0 && target > peak {
        let lowest = control_range("truncation_db").0;
        let lowered = (settings.controls.truncation_db - gain_to_db(target / peak)).max(lowest);
        if lowered < settings.controls.truncation_db {
            settings.controls.truncation_db = lowered;
            peak = peak_of(settings, 0.5);
        }
    }
    if peak > 0.0 {
        target / peak
    } else {
        1.0
    }
}
