//! The standalone opens its editor in a real window: under a virtual X server (Xvfb) the window is
//! captured (xwd) and checked to be the editor, at its configured size and not blank. A click on
//! its strike pad (xdotool) then strikes the object: the audio thread plays it and the mode view
//! draws the modes ringing. Needs the packages `.ci/run` installs: xvfb, x11-apps, xdotool and
//! Mesa's OpenGL.
//!
//! The captures are written to `target/tmp/`; with `MODAL_RESONATOR_UPDATE_SCREENSHOT=1` the one
//! after the strike also replaces `docs/editor.png`, the README's screenshot.

#[path = "common/editor.rs"]
mod harness;

use std::fs::File;
use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::thread::sleep;
use std::time::{Duration, Instant};

use egui::Rect;
use harness::{at, Harness};
use modal_resonator::editor::EDITOR_SIZE;

/// The window's title: the instrument's name.
const WINDOW_NAME: &str = "Modal Resonator";
/// Longest wait for the window to show the editor.
const OPEN_TIMEOUT: Duration = Duration::from_secs(90);
/// Longest wait for a strike to show in the mode view.
const STRIKE_TIMEOUT: Duration = Duration::from_secs(15);
/// The virtual screen: large enough that the pointer, which starts at its centre, is off the
/// window and shows no tooltip.
const SCREEN: &str = "2560x1600x24";
/// Fewest distinct colours in a capture of the editor (a blank or black window has one or two).
const MIN_COLOURS: usize = 64;
/// Fewest live-level pixels the mode view gains when the object is struck.
const MIN_LIVE_PIXELS: usize = 100;

/// A child process, killed when dropped.
struct Process(Child);

impl Drop for Process {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// A captured window, 8-bit RGB.
struct Image {
    width: usize,
    height: usize,
    rgb: Vec<[u8; 3]>,
}

impl Image {
    /// Decodes an XWD dump of a 24-bit TrueColor window (32 bits per pixel).
    fn from_xwd(data: &[u8]) -> Result<Self, String> {
        let field = |i: usize| -> Result<usize, String> {
            let b = data.get(4 * i..4 * i + 4).ok_or("XWD header cut short")?;
            Ok(u32::from_be_bytes([b[0], b[1], b[2], b[3]]) as usize)
        };
        let (header_size, width, height) = (field(0)?, field(4)?, field(5)?);
        let (lsb_first, bits_per_pixel, bytes_per_line) = (field(7)? == 0, field(11)?, field(12)?);
        let colours = field(19)?;
        if bits_per_pixel != 32 {
            return Err(format!("{bits_per_pixel} bits per pixel, expected 32"));
        }
        let start = header_size + 12 * colours;
        let pixels = data
            .get(start..start + bytes_per_line * height)
            .ok_or("XWD pixels cut short")?;
        let mut rgb = Vec::with_capacity(width * height);
        for row in pixels.chunks(bytes_per_line) {
            for p in row[..4 * width].chunks(4) {
                rgb.push(if lsb_first {
                    [p[2], p[1], p[0]]
                } else {
                    [p[1], p[2], p[3]]
                });
            }
        }
        Ok(Self { width, height, rgb })
    }

    /// Number of distinct colours.
    fn colours(&self) -> usize {
        let mut seen: Vec<[u8; 3]> = self.rgb.clone();
        seen.sort_unstable();
        seen.dedup();
        seen.len()
    }

    /// Standard deviation of the luminance, 0 to 255.
    fn luminance_spread(&self) -> f64 {
        let lum: Vec<f64> = self
            .rgb
            .iter()
            .map(|p| 0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64)
            .collect();
        let mean = lum.iter().sum::<f64>() / lum.len() as f64;
        (lum.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / lum.len() as f64).sqrt()
    }

    /// Pixels inside `rect` coloured like the live level (cyan: green and blue well above red).
    fn live_pixels(&self, rect: Rect) -> usize {
        let (x0, x1) = (
            rect.left() as usize,
            (rect.right() as usize).min(self.width),
        );
        let (y0, y1) = (
            rect.top() as usize,
            (rect.bottom() as usize).min(self.height),
        );
        (y0..y1)
            .flat_map(|y| (x0..x1).map(move |x| (x, y)))
            .filter(|&(x, y)| {
                let [r, g, b] = self.rgb[y * self.width + x];
                g as i32 > r as i32 + 50 && b as i32 > r as i32 + 50
            })
            .count()
    }

    fn write_png(&self, path: &Path) {
        let file = File::create(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let mut encoder = png::Encoder::new(file, self.width as u32, self.height as u32);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().unwrap();
        writer.write_image_data(self.rgb.as_flattened()).unwrap();
    }
}

/// Runs `program` with `args` on `display`, failing with a hint when it is not installed.
fn run(program: &str, args: &[&str], display: &str) -> std::process::Output {
    Command::new(program)
        .args(args)
        .env("DISPLAY", display)
        .stdin(Stdio::null())
        .output()
        .unwrap_or_else(|e| {
            panic!("cannot run {program} ({e}): install xvfb, x11-apps and xdotool (see README)")
        })
}

/// The editor window's contents, once it can be captured.
fn capture(display: &str) -> Option<Image> {
    let out = run("xwd", &["-silent", "-name", WINDOW_NAME], display);
    if !out.status.success() {
        return None;
    }
    Image::from_xwd(&out.stdout).ok()
}

/// A virtual X server.
struct Xvfb {
    /// The server, stopped when dropped.
    _process: Process,
    /// Its standard output, kept open: closing it would kill the server with SIGPIPE when it
    /// writes there.
    _stdout: BufReader<std::process::ChildStdout>,
    /// The display's name, ":N".
    display: String,
}

/// Starts Xvfb on a free display.
fn start_xvfb() -> Xvfb {
    let mut child = Command::new("Xvfb")
        .args([
            "-displayfd",
            "1",
            "-screen",
            "0",
            SCREEN,
            "-nolisten",
            "tcp",
        ])
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap_or_else(|e| panic!("cannot start Xvfb ({e}): install xvfb (see README)"));
    // Xvfb writes the display number once it accepts connections.
    let mut line = String::new();
    let mut stdout = BufReader::new(child.stdout.take().expect("piped"));
    stdout.read_line(&mut line).expect("Xvfb's display number");
    assert!(!line.trim().is_empty(), "Xvfb did not start");
    Xvfb {
        _process: Process(child),
        _stdout: stdout,
        display: format!(":{}", line.trim()),
    }
}

#[test]
fn the_standalone_shows_the_editor_and_its_strike_pad_plays() {
    let xvfb = start_xvfb();
    let display = xvfb.display.clone();
    let dir = tempfile::tempdir().unwrap();
    let log_path = dir.path().join("standalone.log");
    let log = File::create(&log_path).unwrap();
    let app = Command::new(env!("CARGO_BIN_EXE_modal-resonator"))
        .args(["play", "--backend", "dummy"])
        .env("DISPLAY", &display)
        // User banks go to a temporary folder, not the home directory.
        .env("XDG_DATA_HOME", dir.path())
        .stdin(Stdio::null())
        .stdout(log.try_clone().unwrap())
        .stderr(log)
        .spawn()
        .expect("the standalone starts");
    let mut app = Process(app);

    // Wait until the window shows something other than a blank frame.
    let started = Instant::now();
    let before = loop {
        if let Some(status) = app.0.try_wait().unwrap() {
            let log = std::fs::read_to_string(&log_path).unwrap_or_default();
            panic!("the standalone exited with {status} before showing its editor:\n{log}");
        }
        match capture(&display) {
            Some(image) if image.colours() >= MIN_COLOURS => break image,
            _ if started.elapsed() > OPEN_TIMEOUT => {
                let log = std::fs::read_to_string(&log_path).unwrap_or_default();
                panic!("no editor window within {OPEN_TIMEOUT:?}:\n{log}");
            }
            _ => sleep(Duration::from_millis(250)),
        }
    };
    let out_dir = Path::new(env!("CARGO_TARGET_TMPDIR"));
    before.write_png(&out_dir.join("editor-opened.png"));
    assert_eq!(
        (before.width, before.height),
        (EDITOR_SIZE.0 as usize, EDITOR_SIZE.1 as usize),
        "the window has the editor's configured size"
    );
    let spread = before.luminance_spread();
    assert!(
        spread > 10.0,
        "the window is nearly uniform: spread {spread}"
    );

    // The window lays out as the headless editor does at the same size: strike its pad there.
    let layout = Harness::new(None).app.layout();
    let before_live = before.live_pixels(layout.mode_view);
    let target = at(layout.strike_area, 0.5, 0.5);
    let (x, y) = (target.x.round().to_string(), target.y.round().to_string());
    let clicked = run(
        "xdotool",
        &[
            "mousemove",
            "--sync",
            &x,
            &y,
            "click",
            "1",
            "mousemove",
            "1",
            "1",
        ],
        &display,
    );
    assert!(clicked.status.success(), "xdotool: {clicked:?}");

    let started = Instant::now();
    let after = loop {
        sleep(Duration::from_millis(100));
        let image = capture(&display).expect("the window is still there");
        let live = image.live_pixels(layout.mode_view);
        if live >= before_live + MIN_LIVE_PIXELS {
            break image;
        }
        if started.elapsed() > STRIKE_TIMEOUT {
            image.write_png(&out_dir.join("editor-struck.png"));
            panic!(
                "the mode view shows no live levels after the strike ({live} pixels, {before_live} \
                 before; see {})",
                out_dir.join("editor-struck.png").display()
            );
        }
    };
    after.write_png(&out_dir.join("editor-struck.png"));
    if std::env::var_os("MODAL_RESONATOR_UPDATE_SCREENSHOT").is_some() {
        after.write_png(&Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/editor.png"));
    }
    assert!(
        app.0.try_wait().unwrap().is_none(),
        "the standalone is still running"
    );
}
