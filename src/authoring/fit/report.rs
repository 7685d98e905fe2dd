//! What a fit tells the designer: per mode how well it was measured, per recording how close the
//! bank comes to it, and every warning.

use std::fmt;
use std::path::Path;

use serde::Serialize;

use crate::bank::staged::StagedFile;
use crate::bank::summary::note_name;

/// The report of a fit, printed by the command line and saved as text or JSON.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FitReport {
    /// One entry per recording, in the order of the bank's positions.
    pub recordings: Vec<RecordingReport>,
    /// One entry per mode of the bank, by frequency.
    pub modes: Vec<ModeReport>,
    /// Frequency range searched, in Hz.
    pub range_hz: (f64, f64),
    /// Most modes asked for.
    pub max_modes: usize,
    /// Modes found before the limit on their number was applied.
    pub modes_found: usize,
}

/// How one recording was read and how close the bank comes to it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RecordingReport {
    /// Position name.
    pub name: String,
    /// Sample rate in Hz.
    pub sample_rate_hz: u32,
    /// Time of the strike in the file, in seconds.
    pub onset_s: f64,
    /// Length of the sound analysed after the onset, in seconds.
    pub sound_s: f64,
    /// Analysis window in samples.
    pub window_samples: usize,
    /// Level of the strike over the noise, in dB.
    pub snr_db: f64,
    /// Noise floor as the amplitude of a mode level with the noise, in dBFS (median over the
    /// frequency range).
    pub noise_floor_dbfs: f64,
    /// Modes found in this recording alone.
    pub modes_found: usize,
    /// Log-spectral distance between the recording and the bank re-synthesised at its position,
    /// in dB (0 is identical).
    pub lsd_db: f64,
    /// Energy of the re-synthesis over the recording's, in dB.
    pub level_db: f64,
    /// Energy of what the bank's modes leave of the recording, relative to the recording, in dB
    /// (phases fitted): how much of the sound is not modal ringing.
    pub residual_db: f64,
    /// Problems with the recording.
    pub warnings: Vec<String>,
}

/// How one mode was measured.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModeReport {
    /// Frequency in Hz.
    pub freq_hz: f64,
    /// Decay rate in 1/s.
    pub decay_per_s: f64,
    /// Time to fall 60 dB, in seconds.
    pub t60_s: f64,
    /// Gain at each position in dB relative to the bank's largest gain; `None` where the mode
    /// was not excited (below that recording's noise floor).
    pub gains_db: Vec<Option<f64>>,
    /// The recording the frequency and decay are best measured in.
    pub measured_in: String,
    /// Frames of that recording the decay regression used.
    pub fit_frames: usize,
    /// RMS distance of those frames' levels from the fitted exponential, in dB.
    pub fit_error_db: f64,
    /// Level of the mode's first frame over the noise, in dB.
    pub snr_db: f64,
    /// Findings in the recordings combined into this mode: one per recording it was found in,
    /// more when modes closer than the difference limen were merged.
    pub findings: usize,
}

impl fmt::Display for FitReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "{} modes ({} found, at most {}), {:.0} Hz to {:.0} Hz",
            self.modes.len(),
            self.modes_found,
            self.max_modes,
            self.range_hz.0,
            self.range_hz.1
        )?;
        writeln!(f, "recordings:")?;
        for r in &self.recordings {
            writeln!(
                f,
                "  {}: {} Hz, strike at {:.3} s, {:.2} s analysed, window {}, SNR {:.1} dB, \
                 noise floor {:.1} dBFS, {} modes",
                r.name,
                r.sample_rate_hz,
                r.onset_s,
                r.sound_s,
                r.window_samples,
                r.snr_db,
                r.noise_floor_dbfs,
                r.modes_found
            )?;
            writeln!(
                f,
                "    fidelity: log-spectral distance {:.2} dB, level {:+.2} dB, residual {:.1} dB",
                r.lsd_db, r.level_db, r.residual_db
            )?;
            for w in &r.warnings {
                writeln!(f, "    warning: {w}")?;
            }
        }
        writeln!(f, "modes:")?;
        let names: Vec<&str> = self.recordings.iter().map(|r| r.name.as_str()).collect();
        writeln!(
            f,
            "  {:>10} {:<10} {:>9} {:>8}  {:<24} {:>6} {:>8} {:>7}  gains dB ({})",
            "Hz",
            "note",
            "decay/s",
            "T60 s",
            "measured in",
            "frames",
            "err dB",
            "SNR dB",
            names.join(", ")
        )?;
        for m in &self.modes {
            let gains: Vec<String> = m
                .gains_db
                .iter()
                .map(|g| match g {
                    Some(db) => format!("{db:.1}"),
                    None => "-".to_string(),
                })
                .collect();
            let findings = if m.findings > 1 {
                format!("  ({} findings)", m.findings)
            } else {
                String::new()
            };
            writeln!(
                f,
                "  {:>10.2} {:<10} {:>9.3} {:>8.3}  {:<24} {:>6} {:>8.2} {:>7.1}  {}{findings}",
                m.freq_hz,
                note_name(m.freq_hz),
                m.decay_per_s,
                m.t60_s,
                m.measured_in,
                m.fit_frames,
                m.fit_error_db,
                m.snr_db,
                gains.join(" ")
            )?;
        }
        Ok(())
    }
}

/// Writes `report` to `path`: JSON when the name ends in `.json`, else the text the command line
/// prints. The file is replaced atomically.
pub fn save_report_file(report: &FitReport, path: &Path) -> std::io::Result<()> {
    stage_report_file(report, path)?.commit()
}

/// Writes `report` as [`save_report_file`] does to a temporary file beside `path`, to replace
/// `path` when committed.
pub fn stage_report_file(report: &FitReport, path: &Path) -> std::io::Result<StagedFile> {
    let text = if path.extension().is_some_and(|e| e == "json") {
        // Serializing plain numbers and strings cannot fail; an infinite T60 becomes null.
        let mut json = serde_json::to_string_pretty(report).expect("a report serializes");
        json.push('\n');
        json
    } else {
        report.to_string()
    };
    StagedFile::write(path, "modal-report", text.as_bytes())
}
