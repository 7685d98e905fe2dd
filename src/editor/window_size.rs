//! The window's size, saved with the project: each time the window opens it asks the host for
//! the size it was left at, and from then on records every size the player gives it.

use std::sync::RwLock;

use egui::{vec2, Ui, Vec2, ViewportCommand};

use super::EDITOR_MIN_SIZE;

/// Frames to wait for the host to apply the size asked for before recording sizes again (a host
/// may refuse, or take a while).
const RESTORE_FRAMES: u32 = 30;

/// Sizes closer than this, in points, are the same.
const SAME_SIZE_PT: f32 = 1.0;

/// Where the restoring of the saved size stands.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Restore {
    /// The window has just opened: the saved size is still to be asked for.
    Pending,
    /// Asked for `size`; frames left to wait for it.
    Requested { size: Vec2, frames_left: u32 },
    /// Restored (or nothing to restore): the size is recorded as it changes.
    Done,
}

/// Keeps the window's size and the size saved in the plugin state in step.
#[derive(Debug, Clone)]
pub struct WindowSize {
    /// Where the restoring stands.
    restore: Restore,
}

impl Default for WindowSize {
    fn default() -> Self {
        Self::new()
    }
}

impl WindowSize {
    /// For a window about to open.
    pub fn new() -> Self {
        Self {
            restore: Restore::Pending,
        }
    }

    /// The window opened again: restore the saved size first.
    pub fn reopen(&mut self) {
        self.restore = Restore::Pending;
    }

    /// Once a frame: asks for the size in `saved` after the window opens, then records the
    /// window's size in `saved` whenever it changes. `saved` holds logical points.
    pub fn update(&mut self, ui: &Ui, saved: &RwLock<Option<(f32, f32)>>) {
        let current = ui.ctx().content_rect().size();
        let read = || *saved.read().unwrap_or_else(|e| e.into_inner());
        let same = |a: Vec2, b: Vec2| (a - b).length() <= SAME_SIZE_PT;
        self.restore = match self.restore {
            Restore::Pending => match read() {
                Some((w, h)) => {
                    let size = vec2(w, h).max(vec2(EDITOR_MIN_SIZE.0, EDITOR_MIN_SIZE.1));
                    if same(size, current) {
                        Restore::Done
                    } else {
                        ui.send_viewport_cmd(ViewportCommand::InnerSize(size));
                        Restore::Requested {
                            size,
                            frames_left: RESTORE_FRAMES,
                        }
                    }
                }
                None => Restore::Done,
            },
            Restore::Requested { size, frames_left } => {
                if same(size, current) || frames_left == 0 {
                    Restore::Done
                } else {
                    Restore::Requested {
                        size,
                        frames_left: frames_left - 1,
                    }
                }
            }
            Restore::Done => Restore::Done,
        };
        if self.restore == Restore::Done && read().is_none_or(|(w, h)| !same(vec2(w, h), current)) {
            *saved.write().unwrap_or_else(|e| e.into_inner()) = Some((current.x, current.y));
        }
    }
}
