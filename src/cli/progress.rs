//! A progress bar on standard error for long work: it appears only on a terminal, and only once
//! the work has taken a second, so quick runs print nothing but their summary.

use std::io::IsTerminal;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Work after which the bar appears.
const PROGRESS_DELAY: Duration = Duration::from_secs(1);

/// Steps of the bar.
const PROGRESS_STEPS: u64 = 1000;

/// A bar for one piece of work.
pub(super) struct Progress {
    /// The bar, hidden until it is shown.
    bar: ProgressBar,
    /// When the work started.
    started: Instant,
    /// Whether the bar is still to be shown (standard error is a terminal and it is hidden).
    pending: bool,
}

impl Progress {
    /// A hidden bar labelled `verb` ("rendering", "fitting").
    pub(super) fn new(verb: &str) -> Self {
        let bar = ProgressBar::with_draw_target(Some(PROGRESS_STEPS), ProgressDrawTarget::hidden());
        bar.set_style(
            ProgressStyle::with_template(&format!("{verb} {{bar:40}} {{percent:>3}}% {{elapsed}}"))
                .expect("a valid template"),
        );
        Self {
            bar,
            started: Instant::now(),
            pending: std::io::stderr().is_terminal(),
        }
    }

    /// The share of the work done, 0 to 1.
    pub(super) fn set(&mut self, done: f64) {
        if self.pending && self.started.elapsed() >= PROGRESS_DELAY {
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
            self.pending = false;
        }
        self.bar
            .set_position((done.clamp(0.0, 1.0) * PROGRESS_STEPS as f64) as u64);
    }

    /// Clears the bar; returns the time since the work started.
    pub(super) fn finish(self) -> Duration {
        self.bar.finish_and_clear();
        self.started.elapsed()
    }
}
