//! The host parameters of perceptual pruning (seed 001) and the mode budget (seed 000 sections
//! 5.5 and 6.4), in their own group.

use std::sync::Arc;

use nice_plug::prelude::*;

use super::{decibels, RoundedSteps};
use crate::engine::{
    Controls, ANALYSIS_FRAME_RANGE_MS, MASKING_OFFSET_RANGE_DB, MAX_MODE_BUDGET,
    MAX_TARGET_LOAD_PCT, PLAYBACK_LEVEL_RANGE_DB_SPL,
};

/// Pruning and budget parameters. Their ids are stable, like every other parameter's.
#[derive(Params)]
pub struct PruningParams {
    /// Perceptual pruning (seed 001): modes below the threshold of hearing or masked by louder
    /// ones are not computed.
    #[id = "prune"]
    pub pruning: BoolParam,
    /// Masking offset `a_v` in dB: larger prunes less.
    #[id = "maskav"]
    pub masking_offset: FloatParam,
    /// Playback level: dB SPL of a full-scale sine, calibrating the pruning.
    #[id = "spl"]
    pub playback_level: FloatParam,
    /// How often pruning looks at the modes, in ms.
    #[id = "prfrm"]
    pub analysis_frame: FloatParam,
    /// Most modes computed at once, the most energetic kept; 0 = no cap.
    #[id = "budget"]
    pub mode_budget: IntParam,
    /// Automatic budget: share of real time the synthesis may take, from the engine's measured
    /// cost; 0 = off.
    #[id = "load"]
    pub target_load: FloatParam,
}

impl PruningParams {
    /// The parameters with the defaults of `controls`.
    pub fn new(controls: &Controls) -> Self {
        Self {
            pruning: BoolParam::new("Pruning", controls.pruning),
            masking_offset: decibels(
                "Masking offset",
                controls.masking_offset_db,
                MASKING_OFFSET_RANGE_DB,
            ),
            playback_level: decibels(
                "Playback level",
                controls.playback_level_db_spl,
                PLAYBACK_LEVEL_RANGE_DB_SPL,
            )
            .with_unit(" dB SPL"),
            analysis_frame: FloatParam::new(
                "Pruning frame",
                controls.analysis_frame_ms,
                FloatRange::Linear {
                    min: ANALYSIS_FRAME_RANGE_MS.0,
                    max: ANALYSIS_FRAME_RANGE_MS.1,
                },
            )
            .with_unit(" ms")
            .with_rounded_steps(1.0),
            mode_budget: IntParam::new(
                "Mode budget",
                controls.mode_budget as i32,
                IntRange::Linear {
                    min: 0,
                    max: MAX_MODE_BUDGET as i32,
                },
            )
            .with_value_to_string(Arc::new(|v| off_when_zero(v as f32, "")))
            .with_string_to_value(Arc::new(|s| parse_off_or(s).map(|v| v as i32))),
            target_load: FloatParam::new(
                "Target load",
                controls.target_load_pct,
                FloatRange::Linear {
                    min: 0.0,
                    max: MAX_TARGET_LOAD_PCT,
                },
            )
            .with_step_size(1.0)
            .with_value_to_string(Arc::new(|v| off_when_zero(v, " %")))
            .with_string_to_value(Arc::new(parse_off_or)),
        }
    }

    /// `controls` with the pruning and budget settings of these parameters.
    pub fn apply(&self, controls: Controls) -> Controls {
        Controls {
            pruning: self.pruning.value(),
            masking_offset_db: self.masking_offset.value(),
            playback_level_db_spl: self.playback_level.value(),
            analysis_frame_ms: self.analysis_frame.value(),
            mode_budget: self.mode_budget.value().max(0) as usize,
            target_load_pct: self.target_load.value(),
            ..controls
        }
    }
}

/// A value with its unit, or "off" at zero (budgets that are not in force).
fn off_when_zero(v: f32, unit: &str) -> String {
    if v <= 0.0 {
        "off".to_string()
    } else {
        format!("{v:.0}{unit}")
    }
}

/// Parses "off" as zero, else a number (a trailing unit is ignored).
fn parse_off_or(s: &str) -> Option<f32> {
    let s = s.trim();
    if s.eq_ignore_ascii_case("off") {
        return Some(0.0);
    }
    s.trim_end_matches(|c: char| !c.is_ascii_digit() && c != '.')
        .trim()
        .parse()
        .ok()
}
