//! The `modal-resonator` command line, run as a user would.

mod common;

use std::path::Path;
use std::process::{Command, Output};

use midly::num::{u15, u28, u4, u7};
use midly::{Format, Header, MetaMessage, MidiMessage, Smf, Timing, TrackEvent, TrackEventKind};

/// Runs the binary in `dir` with `args`.
fn run(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_modal-resonator"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("the binary runs")
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The output of `child` once it ends; if it runs on past `seconds`, it is killed and the test
/// fails with `failure`.
fn wait_within(mut child: std::process::Child, seconds: u64, failure: &str) -> Output {
    let started = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if started.elapsed().as_secs() > seconds {
            let _ = child.kill();
            panic!("{failure}");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

/// A temporary directory holding `bank.json`: two quickly decaying modes rooted at 440 Hz.
fn dir_with_bank() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let mut bank = common::simple_bank(&[(440.0, 8.0, 1.0), (1210.0, 15.0, 0.4)]);
    bank.root_hz = Some(440.0);
    std::fs::write(
        dir.path().join("bank.json"),
        serde_json::to_string_pretty(&bank).unwrap(),
    )
    .unwrap();
    dir
}

/// Names in `dir`, sorted.
fn entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// Asserts that `out` failed with a message containing each of `expected` on stderr, and that
/// `dir` holds only `bank.json` (and `extra`): no output and no temporary file.
fn assert_failed_cleanly(out: &Output, expected: &[&str], dir: &Path, extra: &[&str]) {
    assert!(
        !out.status.success(),
        "should fail; stdout: {}",
        stdout(out)
    );
    let err = stderr(out);
    for e in expected {
        assert!(err.contains(e), "stderr should mention {e:?}: {err}");
    }
    let mut allowed: Vec<String> = ["bank.json"]
        .iter()
        .chain(extra)
        .map(|s| s.to_string())
        .collect();
    allowed.sort();
    assert_eq!(entries(dir), allowed, "files left in the directory");
}

#[test]
fn renders_a_bank_file_to_a_wav() {
    let dir = dir_with_bank();
    let out = run(
        dir.path(),
        &[
            "render",
            "bank.json",
            "--notes",
            "69:1@0, 72:0.5@0.2+0.3",
            "-o",
            "out.wav",
            "--bits",
            "16",
            "--rate",
            "44100",
            "--set",
            "material=wood",
            "--set",
            "width=0.8",
        ],
    );
    assert!(out.status.success(), "stderr: {}", stderr(&out));
    let summary = stdout(&out);
    assert!(
        summary.contains("out.wav") && summary.contains("dBFS"),
        "summary: {summary}"
    );
    assert_eq!(entries(dir.path()), ["bank.json", "out.wav"]);

    let mut reader = hound::WavReader::open(dir.path().join("out.wav")).unwrap();
    let spec = reader.spec();
    assert_eq!(
        (spec.channels, spec.sample_rate, spec.bits_per_sample),
        (2, 44_100, 16)
    );
    assert_eq!(spec.sample_format, hound::SampleFormat::Int);
    let samples: Vec<i16> = reader.samples::<i16>().map(Result::unwrap).collect();
    assert!(samples.len() > 2 * 44_100 / 5, "{} samples", samples.len());
    let peak = samples.iter().map(|s| s.unsigned_abs()).max().unwrap();
    assert!(peak > 3000, "peak {peak} of 32768: should be audible");
}

#[test]
fn renders_a_midi_file() {
    let dir = dir_with_bank();
    let on = |delta: u32, vel: u8| TrackEvent {
        delta: u28::new(delta),
        kind: TrackEventKind::Midi {
            channel: u4::new(0),
            message: MidiMessage::NoteOn {
                key: u7::new(69),
                vel: u7::new(vel),
            },
        },
    };
    let smf = Smf {
        header: Header::new(Format::SingleTrack, Timing::Metrical(u15::new(96))),
        tracks: vec![vec![
            on(0, 100),
            on(48, 0),
            TrackEvent {
                delta: u28::new(0),
                kind: TrackEventKind::Meta(MetaMessage::EndOfTrack),
            },
        ]],
    };
    smf.save(dir.path().join("song.mid")).unwrap();
    let out = run(
        dir.path(),
        &[
            "render",
            "bank.json",
            "--midi",
            "song.mid",
            "-o",
            "song.wav",
            "--bits",
            "32",
        ],
    );
    assert!(out.status.success(), "stderr: {}", stderr(&out));
    let mut reader = hound::WavReader::open(dir.path().join("song.wav")).unwrap();
    assert_eq!(reader.spec().sample_format, hound::SampleFormat::Float);
    let peak = reader
        .samples::<f32>()
        .map(Result::unwrap)
        .fold(0.0f32, |a, s| a.max(s.abs()));
    assert!(peak > 0.1, "peak {peak}");
}

#[test]
fn identical_runs_write_identical_files() {
    let dir = dir_with_bank();
    let args = |out: &'static str| {
        [
            "render",
            "bank.json",
            "--notes",
            "60:1@0, 67:0.7@0.1, 64:0.4@0.15+0.1",
            "-o",
            out,
            "--set",
            "position_variation=0.4",
            // Pruning and a fixed budget repeat exactly too; only the measured Target load
            // may not.
            "--set",
            "pruning=on",
            "--set",
            "mode_budget=3",
        ]
    };
    for name in ["a.wav", "b.wav"] {
        let out = run(dir.path(), &args(name));
        assert!(out.status.success(), "stderr: {}", stderr(&out));
    }
    let a = std::fs::read(dir.path().join("a.wav")).unwrap();
    let b = std::fs::read(dir.path().join("b.wav")).unwrap();
    assert!(a.len() > 1000);
    assert!(
        a == b,
        "two runs with the same arguments wrote different files"
    );
}

#[test]
fn a_bad_bank_file_fails_and_writes_nothing() {
    let dir = dir_with_bank();
    std::fs::write(
        dir.path().join("broken.json"),
        "{ \"format\": \"modal-bank\", ",
    )
    .unwrap();
    let out = run(
        dir.path(),
        &[
            "render",
            "broken.json",
            "--notes",
            "60:1@0",
            "-o",
            "out.wav",
        ],
    );
    assert_failed_cleanly(
        &out,
        &["broken.json:1:", "truncated"],
        dir.path(),
        &["broken.json"],
    );

    std::fs::write(dir.path().join("wrong.json"), "{ \"modes\": 3 }").unwrap();
    let out = run(
        dir.path(),
        &["render", "wrong.json", "--notes", "60:1@0", "-o", "out.wav"],
    );
    assert_failed_cleanly(
        &out,
        &["wrong.json"],
        dir.path(),
        &["broken.json", "wrong.json"],
    );

    let out = run(
        dir.path(),
        &[
            "render",
            "no-such-bank",
            "--notes",
            "60:1@0",
            "-o",
            "out.wav",
        ],
    );
    assert_failed_cleanly(
        &out,
        &[
            "no factory bank named \"no-such-bank\" and no file",
            "modal-resonator list",
        ],
        dir.path(),
        &["broken.json", "wrong.json"],
    );
}

#[test]
fn bad_notes_fail_and_write_nothing() {
    let dir = dir_with_bank();
    let out = run(
        dir.path(),
        &[
            "render",
            "bank.json",
            "--notes",
            "60:1@0, 61:1.5@0.1",
            "-o",
            "out.wav",
        ],
    );
    assert_failed_cleanly(&out, &["--notes", "note 2", "velocity"], dir.path(), &[]);
    let out = run(
        dir.path(),
        &["render", "bank.json", "--notes", "200:1@0", "-o", "out.wav"],
    );
    assert_failed_cleanly(&out, &["key", "0 to 127"], dir.path(), &[]);
    let out = run(
        dir.path(),
        &[
            "render",
            "bank.json",
            "--midi",
            "missing.mid",
            "-o",
            "out.wav",
        ],
    );
    assert_failed_cleanly(&out, &["missing.mid"], dir.path(), &[]);
    let out = run(
        dir.path(),
        &[
            "render",
            "bank.json",
            "--notes",
            "60:1@0, 62:1@100",
            "-o",
            "out.wav",
        ],
    );
    assert_failed_cleanly(
        &out,
        &["note 2 starts at 100 s", "--max-seconds 30"],
        dir.path(),
        &[],
    );
    let before = std::fs::read(dir.path().join("bank.json")).unwrap();
    let out = run(
        dir.path(),
        &[
            "render",
            "bank.json",
            "--notes",
            "60:1@0",
            "-o",
            "./bank.json",
        ],
    );
    assert_failed_cleanly(&out, &["would overwrite an input"], dir.path(), &[]);
    assert_eq!(std::fs::read(dir.path().join("bank.json")).unwrap(), before);
    let out = run(
        dir.path(),
        &[
            "render",
            "bank.json",
            "--notes",
            "60:1@0",
            "--set",
            "polyphony=2.5",
            "-o",
            "out.wav",
        ],
    );
    assert_failed_cleanly(&out, &["polyphony", "whole number"], dir.path(), &[]);
    // Neither notes nor a MIDI file.
    let out = run(dir.path(), &["render", "bank.json", "-o", "out.wav"]);
    assert_failed_cleanly(&out, &["--notes", "--midi"], dir.path(), &[]);
}

#[test]
fn bad_controls_fail_and_write_nothing() {
    let dir = dir_with_bank();
    let render_with = |set: &str| {
        run(
            dir.path(),
            &[
                "render",
                "bank.json",
                "--notes",
                "60:1@0",
                "-o",
                "out.wav",
                "--set",
                set,
            ],
        )
    };
    let out = render_with("sise_ratio=2");
    assert_failed_cleanly(&out, &["sise_ratio", "unknown control"], dir.path(), &[]);
    let out = render_with("size_ratio=9");
    assert_failed_cleanly(&out, &["size_ratio", "0.25 to 4"], dir.path(), &[]);
    let out = render_with("material=cheese");
    assert_failed_cleanly(&out, &["material", "cheese"], dir.path(), &[]);
    let out = render_with("size_ratio");
    assert_failed_cleanly(&out, &["NAME=VALUE"], dir.path(), &[]);
    let out = run(
        dir.path(),
        &[
            "render",
            "bank.json",
            "--notes",
            "60:1@0",
            "-o",
            "out.wav",
            "--bits",
            "20",
        ],
    );
    assert_failed_cleanly(&out, &["--bits", "16, 24 or 32"], dir.path(), &[]);
}

#[test]
fn an_unwritable_output_fails_and_leaves_nothing() {
    let dir = dir_with_bank();
    let out = run(
        dir.path(),
        &[
            "render",
            "bank.json",
            "--notes",
            "60:1@0",
            "-o",
            "missing/out.wav",
        ],
    );
    assert_failed_cleanly(
        &out,
        &["missing/out.wav", "does not exist"],
        dir.path(),
        &[],
    );

    std::fs::create_dir(dir.path().join("sub")).unwrap();
    let out = run(
        dir.path(),
        &["render", "bank.json", "--notes", "60:1@0", "-o", "sub"],
    );
    assert_failed_cleanly(&out, &["sub", "is a directory"], dir.path(), &["sub"]);
    assert!(entries(&dir.path().join("sub")).is_empty());

    // Passes the early checks; fails when the finished file is renamed into place.
    let out = run(
        dir.path(),
        &[
            "render",
            "bank.json",
            "--notes",
            "60:1@0",
            "-o",
            "late.wav/",
        ],
    );
    assert_failed_cleanly(&out, &["late.wav"], dir.path(), &["sub"]);
}

#[test]
fn help_lists_the_subcommands() {
    let dir = tempfile::tempdir().unwrap();
    let out = run(dir.path(), &["--help"]);
    assert!(out.status.success(), "stderr: {}", stderr(&out));
    let help = stdout(&out);
    for sub in [
        "play", "render", "fit", "shape", "mesh", "compress", "validate", "info", "list", "schema",
    ] {
        assert!(help.contains(sub), "help lacks {sub}: {help}");
    }
}

#[cfg(unix)]
#[test]
fn the_standalone_runs_headless_with_the_dummy_backend() {
    // The standalone runs until stopped: start it, let it process for a while, then stop it as
    // Ctrl-C does. Its options work after `play` and with no subcommand at all.
    let options = [
        "--backend",
        "dummy",
        "--sample-rate",
        "48000",
        "--period-size",
        "256",
    ];
    for play in [&["play"][..], &[]] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_modal-resonator"))
            .args(play.iter().chain(&options))
            .env_remove("DISPLAY")
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("the binary runs");
        std::thread::sleep(std::time::Duration::from_secs(2));
        let still_running = child.try_wait().unwrap().is_none();
        // SAFETY: sends a signal to the child this test started and has not reaped.
        assert_eq!(unsafe { libc::kill(child.id() as i32, libc::SIGINT) }, 0);
        let out = wait_within(
            child,
            20,
            &format!("{play:?}: Ctrl-C did not stop the standalone"),
        );
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            still_running,
            "{play:?}: the standalone stopped by itself: {stderr}"
        );
        assert!(
            out.status.success() && !stderr.to_lowercase().contains("error"),
            "{play:?}: Ctrl-C ended the standalone with {}: {stderr}",
            out.status
        );
    }
}

#[test]
fn a_clipping_render_warns_and_normalize_sets_the_peak() {
    let dir = dir_with_bank();
    // Eight full-velocity notes struck together.
    let chord = "57:1@0, 60:1@0, 64:1@0, 67:1@0, 69:1@0, 72:1@0, 76:1@0, 79:1@0";
    let args = |extra: &[&'static str]| {
        let mut a = vec!["render", "bank.json", "--notes", chord, "--bits", "16"];
        a.extend_from_slice(extra);
        a
    };
    let out = run(dir.path(), &args(&["-o", "loud.wav"]));
    assert!(out.status.success(), "{}", stderr(&out));
    let warning = stderr(&out);
    assert!(
        warning.contains("warning: the render peaks at +")
            && warning.contains("clipped")
            && warning.contains("--normalize"),
        "stderr: {warning}"
    );
    for target in [-1.0f64, -12.0] {
        let level = format!("{target}");
        let out = run(
            dir.path(),
            &[
                "render",
                "bank.json",
                "--notes",
                chord,
                "--bits",
                "16",
                "--normalize",
                &level,
                "-o",
                "normal.wav",
            ],
        );
        assert!(out.status.success(), "{}", stderr(&out));
        assert!(!stderr(&out).contains("warning"), "{}", stderr(&out));
        let mut reader = hound::WavReader::open(dir.path().join("normal.wav")).unwrap();
        let peak = reader
            .samples::<i16>()
            .map(|s| s.unwrap().unsigned_abs())
            .max()
            .unwrap();
        let peak_dbfs = 20.0 * (peak as f64 / 32_768.0).log10();
        assert!(
            (peak_dbfs - target).abs() < 0.05,
            "--normalize {target}: peak {peak_dbfs:.3} dBFS"
        );
    }
    // A note near the quietest a 16-bit file holds is lifted before it is written.
    let out = run(
        dir.path(),
        &[
            "render",
            "bank.json",
            "--notes",
            "69:0.003@0",
            "--bits",
            "16",
            "--normalize",
            "-6",
            "-o",
            "soft.wav",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let mut reader = hound::WavReader::open(dir.path().join("soft.wav")).unwrap();
    let peak = reader
        .samples::<i16>()
        .map(|s| s.unwrap().unsigned_abs())
        .max()
        .unwrap();
    assert!(
        (20.0 * (peak as f64 / 32_768.0).log10() + 6.0).abs() < 0.05,
        "soft note normalised to a peak of {peak}"
    );
    let out = run(dir.path(), &args(&["--normalize", "3", "-o", "bad.wav"]));
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("from -100 to 0"), "{}", stderr(&out));
}

#[test]
fn a_silent_render_warns_and_exits_with_its_own_status() {
    let dir = tempfile::tempdir().unwrap();
    // A bank whose only mode lies above what 8 kHz can play, and one with no gain anywhere.
    for (name, mode) in [
        ("high.json", (6_000.0, 5.0, 1.0)),
        ("mute.json", (440.0, 5.0, 0.0)),
    ] {
        let mut bank = common::simple_bank(&[mode]);
        bank.root_hz = Some(440.0);
        std::fs::write(dir.path().join(name), serde_json::to_string(&bank).unwrap()).unwrap();
        let out = run(
            dir.path(),
            &[
                "render", name, "--notes", "69:1@0", "--rate", "8000", "-o", "out.wav",
            ],
        );
        assert_eq!(out.status.code(), Some(3), "{name}: {}", stderr(&out));
        assert!(
            stderr(&out).contains("warning: the render is silent"),
            "{name}: {}",
            stderr(&out)
        );
        assert!(dir.path().join("out.wav").is_file(), "{name}: no file");
    }
    // A MIDI file of a tempo alone: the warning says there is nothing to play.
    let mut midi = b"MThd\x00\x00\x00\x06\x00\x00\x00\x01\x01\xe0MTrk\x00\x00\x00\x0b".to_vec();
    midi.extend_from_slice(b"\x00\xff\x51\x03\x07\xa1\x20\x00\xff\x2f\x00");
    std::fs::write(dir.path().join("tempo.mid"), midi).unwrap();
    let out = run(
        dir.path(),
        &[
            "render",
            "rosewood-marimba-bar",
            "--midi",
            "tempo.mid",
            "-o",
            "out.wav",
        ],
    );
    assert_eq!(out.status.code(), Some(3), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("no notes to play"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn the_standalone_with_no_display_and_no_backend_named_says_so_and_exits() {
    for play in [&["play"][..], &[]] {
        let child = Command::new(env!("CARGO_BIN_EXE_modal-resonator"))
            .args(play)
            .env_remove("DISPLAY")
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("the binary runs");
        let out = wait_within(
            child,
            20,
            &format!("{play:?}: the standalone blocked with nothing to play on"),
        );
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{play:?}: {stderr}");
        assert!(
            stderr.contains("no display") && stderr.contains("--backend"),
            "{play:?}: {stderr}"
        );
    }
}

#[test]
fn play_help_lists_the_standalone_options() {
    let out = Command::new(env!("CARGO_BIN_EXE_modal-resonator"))
        .args(["play", "--help"])
        .env_remove("DISPLAY")
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for option in [
        "--backend",
        "--sample-rate",
        "--period-size",
        "--input-device",
    ] {
        assert!(
            text.contains(option),
            "`play --help` lacks {option}:\n{text}"
        );
    }
}

/// The broken banks of the format tests, each with the JSON path (or position) its error names.
const BROKEN: &[(&str, &str)] = &[
    ("coords-4d.json", "positions[0].coords"),
    ("duplicate-position-names.json", "positions[2].name"),
    ("huge-number-1e300.json", "modes[0].freq_hz"),
    ("huge-number-1e400.json", "out of range"),
    ("nan-literal.json", "NaN"),
    ("negative-frequency.json", "modes[1].freq_hz"),
    ("no-modes.json", "modes: found 0 modes"),
    ("ragged-gains.json", "modes[3].gains"),
    ("truncated.json", "truncated"),
    ("unknown-field.json", "did you mean \"freq_hz\""),
    ("version-2.json", "newer version"),
    ("wrong-types.json", "expected a string"),
];

#[test]
fn every_broken_bank_fails_to_render_and_writes_nothing() {
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/bad");
    for (file, expected) in BROKEN {
        let dir = dir_with_bank();
        std::fs::copy(fixtures.join(file), dir.path().join(file)).unwrap();
        let out = run(
            dir.path(),
            &["render", file, "--notes", "60:1@0", "-o", "out.wav"],
        );
        assert_failed_cleanly(&out, &[file, expected], dir.path(), &[file]);
    }
}

#[test]
fn validate_reports_every_problem_and_fails_on_any() {
    let dir = dir_with_bank();
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/bad");
    std::fs::copy(
        fixtures.join("many-problems.json"),
        dir.path().join("many.json"),
    )
    .unwrap();
    let good = run(dir.path(), &["validate", "bank.json"]);
    assert!(good.status.success(), "{}", stderr(&good));
    assert!(
        stdout(&good).contains("bank.json: ok (2 modes, 1 positions)"),
        "{}",
        stdout(&good)
    );
    let bad = run(dir.path(), &["validate", "bank.json", "many.json"]);
    assert!(!bad.status.success());
    let text = stdout(&bad);
    for path in [
        "root_hz",
        "positions[1].weight",
        "modes[0].decay_per_s",
        "modes[1].gains",
        "defaults.hardness_ms",
    ] {
        assert!(
            text.contains(&format!("many.json: {path}")),
            "missing {path}: {text}"
        );
    }
    assert!(stderr(&bad).contains("1 of 2 files have problems"));
}

#[test]
fn factory_presets_render_and_describe_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let out = run(
        dir.path(),
        &[
            "render",
            "steel-free-free-bar",
            "--notes",
            "84:0.9@0",
            "-o",
            "bar.wav",
            "--max-seconds",
            "2",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let reader = hound::WavReader::open(dir.path().join("bar.wav")).unwrap();
    assert_eq!(reader.spec().channels, 2);
    let info = run(dir.path(), &["info", "Bronze bell"]);
    assert!(info.status.success(), "{}", stderr(&info));
    let text = stdout(&info);
    assert!(
        text.contains("root: 440.00 Hz (A4)") && text.contains("modes: 11"),
        "{text}"
    );
    let list = run(dir.path(), &["list"]);
    assert!(stdout(&list).lines().count() >= 6);
    let schema = run(dir.path(), &["schema"]);
    let parsed: serde_json::Value = serde_json::from_slice(&schema.stdout).unwrap();
    assert!(parsed.get("properties").is_some());
}

/// Writes a WAV file of `channels` channels at 48 kHz: a lead-in, then a strike of two modes
/// (440 Hz and 1234.5 Hz) in every channel, over faint deterministic noise.
fn write_strike_wav(path: &Path, channels: u16) {
    let spec = hound::WavSpec {
        channels,
        sample_rate: 48_000,
        bits_per_sample: 16,
        sample_format: hound::SampleFormat::Int,
    };
    let mut writer = hound::WavWriter::create(path, spec).unwrap();
    let mut seed = 1u32;
    for n in 0..(1.5 * 48_000.0) as usize {
        let t = n as f64 / 48_000.0 - 0.05;
        let tau = std::f64::consts::TAU;
        let ring = if t >= 0.0 {
            0.5 * (-3.0 * t).exp() * (tau * 440.0 * t).sin()
                + 0.2 * (-9.0 * t).exp() * (tau * 1234.5 * t).sin()
        } else {
            0.0
        };
        for _ in 0..channels {
            seed ^= seed << 13;
            seed ^= seed >> 17;
            seed ^= seed << 5;
            let noise = 1e-4 * (seed as f64 / u32::MAX as f64 - 0.5);
            writer
                .write_sample(((ring + noise) * 32767.0).round() as i16)
                .unwrap();
        }
    }
    writer.finalize().unwrap();
}

#[test]
fn banks_go_to_standard_output_for_a_dash() {
    let dir = dir_with_bank();
    write_strike_wav(&dir.path().join("strike.wav"), 1);
    for args in [
        &["shape", "free-free-bar", "-o", "-"][..],
        &["compress", "bank.json", "-o", "-"][..],
        &["fit", "strike.wav", "--modes", "4", "-o", "-"][..],
    ] {
        let out = run(dir.path(), args);
        assert!(out.status.success(), "{args:?}: {}", stderr(&out));
        // Standard output holds the bank alone; the summary goes to standard error.
        let bank = modal_resonator::bank::parse_bank_str(&stdout(&out), "stdout")
            .unwrap_or_else(|e| panic!("{args:?}: {e}"));
        assert!(!bank.modes.is_empty(), "{args:?}");
        assert!(
            stderr(&out).contains("standard output:"),
            "{args:?}: {}",
            stderr(&out)
        );
        assert_eq!(entries(dir.path()), ["bank.json", "strike.wav"], "{args:?}");
    }
}

#[test]
fn fit_writes_a_bank_and_a_report_from_recordings() {
    let dir = dir_with_bank();
    write_strike_wav(&dir.path().join("edge.wav"), 1);
    write_strike_wav(&dir.path().join("middle.wav"), 2);
    let out = run(
        dir.path(),
        &[
            "fit",
            "edge.wav",
            "middle.wav=centre",
            "-o",
            "fitted.json",
            "--modes",
            "8",
            "--report",
            "report.json",
            "--license",
            "CC0-1.0",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(text.contains("log-spectral distance"), "{text}");
    assert!(text.contains(" modes, 2 positions"), "{text}");
    // The stereo file was mixed to mono, and says so.
    assert!(stderr(&out).contains("centre: stereo"), "{}", stderr(&out));

    let bank = modal_resonator::bank::load_bank_file(&dir.path().join("fitted.json")).unwrap();
    assert_eq!(bank.name, "fitted");
    assert_eq!(bank.license, "CC0-1.0");
    let names: Vec<&str> = bank.positions.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["edge", "centre"]);
    // The two modes struck, and nothing else within 60 dB of them: the rest fits the 16-bit
    // rounding, and no listener hears it.
    let loudest =
        |m: &modal_resonator::bank::Mode| m.gains.iter().fold(0.0f64, |a, g| a.max(g.abs()));
    let mut modes: Vec<_> = bank.modes.iter().collect();
    modes.sort_by(|a, b| loudest(b).total_cmp(&loudest(a)));
    let mut strongest: Vec<f64> = modes[..2].iter().map(|m| m.freq_hz).collect();
    strongest.sort_by(f64::total_cmp);
    for (got, f) in strongest.iter().zip([440.0, 1234.5]) {
        assert!((got / f - 1.0).abs() < 1e-4, "{got} Hz vs {f} Hz");
    }
    for m in &modes[2..] {
        assert!(
            loudest(m) < 1e-3 * loudest(modes[0]),
            "{} Hz: gain {} beside {}",
            m.freq_hz,
            loudest(m),
            loudest(modes[0])
        );
    }
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("report.json")).unwrap())
            .unwrap();
    assert_eq!(report["recordings"][1]["name"], "centre");
    assert!(
        report["recordings"][0]["lsd_db"].as_f64().unwrap() < 3.0,
        "{report}"
    );
    assert_eq!(report["modes"].as_array().unwrap().len(), bank.modes.len());
}

#[test]
fn fit_rejects_bad_recordings_and_writes_nothing() {
    let dir = dir_with_bank();
    std::fs::write(dir.path().join("notes.wav"), "these are words, not sound").unwrap();
    let out = run(dir.path(), &["fit", "notes.wav", "-o", "out.json"]);
    assert_failed_cleanly(
        &out,
        &["notes.wav", "not a WAV file"],
        dir.path(),
        &["notes.wav"],
    );

    write_strike_wav(&dir.path().join("surround.wav"), 3);
    let out = run(dir.path(), &["fit", "surround.wav", "-o", "out.json"]);
    assert_failed_cleanly(
        &out,
        &["surround.wav", "3 channels", "mono or stereo"],
        dir.path(),
        &["notes.wav", "surround.wav"],
    );

    let out = run(dir.path(), &["fit", "missing.wav", "-o", "out.json"]);
    assert_failed_cleanly(
        &out,
        &["missing.wav", "cannot read"],
        dir.path(),
        &["notes.wav", "surround.wav"],
    );

    // Silence: a valid WAV file with nothing in it.
    let spec = hound::WavSpec {
        channels: 1,
        sample_rate: 44_100,
        bits_per_sample: 16,
        sample_format: hound::SampleFormat::Int,
    };
    let mut writer = hound::WavWriter::create(dir.path().join("silence.wav"), spec).unwrap();
    for _ in 0..44_100 {
        writer.write_sample(0i16).unwrap();
    }
    writer.finalize().unwrap();
    let out = run(dir.path(), &["fit", "silence.wav=top", "-o", "out.json"]);
    assert_failed_cleanly(
        &out,
        &["silence.wav (top): no strike", "every sample is zero"],
        dir.path(),
        &["notes.wav", "silence.wav", "surround.wav"],
    );

    let out = run(
        dir.path(),
        &[
            "fit",
            "silence.wav",
            "-o",
            "out.json",
            "--noise-floor-db",
            "6",
        ],
    );
    assert_failed_cleanly(
        &out,
        &["--noise-floor-db 6"],
        dir.path(),
        &["notes.wav", "silence.wav", "surround.wav"],
    );
}

#[test]
fn fit_never_overwrites_a_recording_and_a_late_failure_writes_nothing() {
    let dir = dir_with_bank();
    write_strike_wav(&dir.path().join("edge.wav"), 1);
    let original = std::fs::read(dir.path().join("edge.wav")).unwrap();
    for (args, expected) in [
        (
            &[
                "fit",
                "edge.wav",
                "-o",
                "out.json",
                "--report",
                "./edge.wav",
            ][..],
            &[
                "--report ./edge.wav",
                "would overwrite an input, the recording edge.wav",
            ][..],
        ),
        (
            &["fit", "edge.wav", "-o", "edge.wav"][..],
            &[
                "-o edge.wav",
                "would overwrite an input, the recording edge.wav",
            ][..],
        ),
        (
            &[
                "fit",
                "edge.wav",
                "-o",
                "out.json",
                "--report",
                "./out.json",
            ][..],
            &["out.json", "the report and the bank would be the same file"][..],
        ),
        // The report cannot be put in place: the bank, staged first, is not written either.
        (
            &["fit", "edge.wav", "-o", "out.json", "--report", "late.txt/"][..],
            &["late.txt", "cannot write"][..],
        ),
    ] {
        let out = run(dir.path(), args);
        assert_failed_cleanly(&out, expected, dir.path(), &["edge.wav"]);
        assert_eq!(
            std::fs::read(dir.path().join("edge.wav")).unwrap(),
            original,
            "{args:?} changed the recording"
        );
    }
}

#[test]
fn shape_builds_a_stated_steel_bar_and_prints_its_summary() {
    let dir = dir_with_bank();
    let out = run(
        dir.path(),
        &[
            "shape",
            "free-free-bar",
            "--material",
            "steel",
            "--length",
            "0.3",
            "--width",
            "0.03",
            "--thickness",
            "0.01",
            "-o",
            "bar.json",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    // f1 = (4.730^2 / (2 pi 0.3^2)) 0.01 sqrt(200e9 / (12 * 7850)) = 576.50 Hz.
    assert!(text.contains("root 576.50 Hz"), "{text}");
    // Modes below 20 kHz: b_n L up to (2 * 8 + 1) pi / 2, at 18.37 kHz.
    assert!(text.contains("bar.json: 8 modes, 4 positions"), "{text}");
    let bank = modal_resonator::bank::load_bank_file(&dir.path().join("bar.json")).unwrap();
    assert_eq!(bank.modes.len(), 8);
    assert_eq!(bank.license, "CC0-1.0");
    let ratio = bank.modes[1].freq_hz / bank.modes[0].freq_hz;
    assert!((ratio - 2.756).abs() < 1e-3, "ratio {ratio}");
}

#[test]
fn shape_tunes_takes_positions_and_limits() {
    let dir = dir_with_bank();
    let out = run(
        dir.path(),
        &[
            "shape",
            "circular-plate",
            "--edge",
            "clamped",
            "--material",
            "ceramic",
            "--root-note",
            "A4",
            "--positions",
            "centre=0,0; rim side=0.8,0.3",
            "--modes",
            "20",
            "--name",
            "Test disc",
            "-o",
            "disc.json",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let bank = modal_resonator::bank::load_bank_file(&dir.path().join("disc.json")).unwrap();
    assert_eq!(bank.name, "Test disc");
    assert!((bank.root_hz.unwrap() - 440.0).abs() < 1e-9);
    assert_eq!(bank.modes.len(), 20);
    assert_eq!(bank.positions.len(), 2);
    let source = bank.source.unwrap();
    assert_eq!(
        (source["material"].as_str(), source["edge"].as_str()),
        (Some("porcelain"), Some("clamped"))
    );
    let tuned = run(
        dir.path(),
        &[
            "shape",
            "stiff-string",
            "--tune-hz",
            "110",
            "-o",
            "string.json",
        ],
    );
    assert!(tuned.status.success(), "{}", stderr(&tuned));
    assert!(
        stdout(&tuned).contains("root 110.00 Hz (A2)"),
        "{}",
        stdout(&tuned)
    );
}

#[test]
fn shape_refuses_bad_names_and_dimensions_cleanly() {
    let dir = dir_with_bank();
    let out = run(dir.path(), &["shape", "kazoo", "-o", "x.json"]);
    assert_failed_cleanly(
        &out,
        &[
            "unknown object \"kazoo\"",
            "expected one of ideal-string",
            "circular-plate",
        ],
        dir.path(),
        &[],
    );
    let out = run(
        dir.path(),
        &["shape", "bell", "--material", "cheese", "-o", "x.json"],
    );
    assert_failed_cleanly(
        &out,
        &[
            "unknown material \"cheese\"",
            "steel",
            "porcelain (ceramic)",
        ],
        dir.path(),
        &[],
    );
    let out = run(
        dir.path(),
        &["shape", "free-free-bar", "--radius", "0.1", "-o", "x.json"],
    );
    assert_failed_cleanly(
        &out,
        &["free-free-bar does not take it", "--length"],
        dir.path(),
        &[],
    );
    let out = run(
        dir.path(),
        &[
            "shape",
            "free-free-bar",
            "--thickness",
            "-1",
            "-o",
            "x.json",
        ],
    );
    assert_failed_cleanly(&out, &["expected a number above 0"], dir.path(), &[]);
    let out = run(
        dir.path(),
        &[
            "shape",
            "ideal-string",
            "--positions",
            "1.5",
            "-o",
            "x.json",
        ],
    );
    assert_failed_cleanly(&out, &["positions[0]", "[0, 1]"], dir.path(), &[]);
    // Objects the theory cannot make: a bar thicker than long, a bar wider than long, a bar so
    // long and a bell so large that their lowest modes fall below the 1 Hz floor of a bank.
    for (args, expected) in [
        (
            &["free-free-bar", "--length", "0.01", "--thickness", "0.5"][..],
            &["thickness_m = 0.5", "a fifth of the length"][..],
        ),
        (
            &["free-free-bar", "--length", "0.1", "--width", "0.5"][..],
            &["width_m = 0.5", "a plate"][..],
        ),
        (
            &["free-free-bar", "--length", "30"][..],
            &["lowest mode would be at", "below the 1 Hz", "--tune-hz"][..],
        ),
        (
            &["bell", "--diameter", "40"][..],
            &["lowest mode would be at", "below the 1 Hz"][..],
        ),
        // Checked as tuned: a marimba bar tuned to 12 kHz is shorter than it is wide.
        (
            &["tuned-bar", "--tune-hz", "12000"][..],
            &["width_m", "(0.0572 m): that is a plate"][..],
        ),
    ] {
        let mut command = vec!["shape"];
        command.extend(args);
        command.extend(["-o", "x.json"]);
        let out = run(dir.path(), &command);
        assert_failed_cleanly(&out, expected, dir.path(), &[]);
    }
    // Proportions hold for the object as tuned: a 7 cm thick bar is slender once tuned down to
    // 200 Hz (1.3 m long).
    let out = run(
        dir.path(),
        &[
            "shape",
            "free-free-bar",
            "--thickness",
            "0.07",
            "--tune-hz",
            "200",
            "-o",
            "tuned.json",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    std::fs::remove_file(dir.path().join("tuned.json")).unwrap();
    let help = run(dir.path(), &["shape", "--help"]);
    let text = stdout(&help);
    for word in [
        "clamped-free-bar",
        "rectangular-membrane",
        "acrylic",
        "hardwood",
    ] {
        assert!(text.contains(word), "shape --help lacks {word}: {text}");
    }
}

#[test]
fn compress_merges_and_drops_and_reports() {
    let dir = tempfile::tempdir().unwrap();
    // 2000 and 2002 Hz are within the 5 Hz limen; the 3 kHz mode is 100 dB down.
    let mut bank = common::simple_bank(&[
        (2000.0, 4.0, 1.0),
        (2002.0, 4.0, 0.5),
        (2500.0, 5.0, 0.3),
        (3000.0, 6.0, 1e-5),
    ]);
    bank.root_hz = Some(2000.0);
    modal_resonator::bank::save_bank_file(&bank, &dir.path().join("bank.json")).unwrap();
    let out = run(dir.path(), &["compress", "bank.json", "-o", "small.json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stdout(&out).contains("4 modes -> 2 modes (merged 1, dropped 1)"),
        "{}",
        stdout(&out)
    );
    let small = modal_resonator::bank::load_bank_file(&dir.path().join("small.json")).unwrap();
    assert_eq!(small.modes.len(), 2);
    assert!((small.modes[0].gains[0] - 1.5).abs() < 1e-12);
    let kept = run(
        dir.path(),
        &[
            "compress",
            "bank.json",
            "-o",
            "kept.json",
            "--keep-weak",
            "--limen-scale",
            "0",
        ],
    );
    assert!(
        stdout(&kept).contains("4 modes -> 4 modes (merged 0, dropped 0)"),
        "{}",
        stdout(&kept)
    );
    // Factory banks by name; the input is never overwritten.
    let plate = run(dir.path(), &["compress", "steel-plate", "-o", "plate.json"]);
    assert!(plate.status.success(), "{}", stderr(&plate));
    assert!(
        stdout(&plate).starts_with("300 modes -> "),
        "{}",
        stdout(&plate)
    );
    let same = run(dir.path(), &["compress", "bank.json", "-o", "bank.json"]);
    assert!(!same.status.success());
    assert!(stderr(&same).contains("overwrite"), "{}", stderr(&same));
    let bad = run(
        dir.path(),
        &[
            "compress",
            "bank.json",
            "-o",
            "x.json",
            "--drop-below-db",
            "6",
        ],
    );
    assert!(!bad.status.success());
    assert!(
        stderr(&bad).contains("--drop-below-db 6: expected"),
        "{}",
        stderr(&bad)
    );
    assert!(!dir.path().join("x.json").exists());
}

/// The notes of the output-path tests: one short strike.
const ONE_NOTE: &str = "69:0.8@0+0.1";

#[cfg(unix)]
#[test]
fn outputs_follow_links_keep_permissions_and_refuse_what_is_no_file() {
    use std::os::unix::fs::{MetadataExt, PermissionsExt};
    let dir = dir_with_bank();
    let d = dir.path();
    let render_to = |output: &str| {
        run(
            d,
            &["render", "bank.json", "--notes", ONE_NOTE, "-o", output],
        )
    };
    let is_wav = |path: &Path| std::fs::read(path).unwrap().starts_with(b"RIFF");

    // A symbolic link is followed: its target gets the WAV, the link stays a link.
    std::fs::write(d.join("target.wav"), b"old").unwrap();
    std::os::unix::fs::symlink("target.wav", d.join("link.wav")).unwrap();
    let out = render_to("link.wav");
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(std::fs::symlink_metadata(d.join("link.wav"))
        .unwrap()
        .file_type()
        .is_symlink());
    assert!(is_wav(&d.join("target.wav")));

    // A dangling link makes the file it names.
    std::os::unix::fs::symlink("new.wav", d.join("dangling.wav")).unwrap();
    let out = render_to("dangling.wav");
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(is_wav(&d.join("new.wav")));

    // An existing file keeps its permissions.
    std::fs::write(d.join("private.wav"), b"old").unwrap();
    std::fs::set_permissions(
        d.join("private.wav"),
        std::fs::Permissions::from_mode(0o600),
    )
    .unwrap();
    let out = render_to("private.wav");
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(is_wav(&d.join("private.wav")));
    let mode = std::fs::metadata(d.join("private.wav")).unwrap().mode() & 0o777;
    assert_eq!(mode, 0o600);

    // And its owner, where the writer may give it away (as root, as CI runs).
    // SAFETY: geteuid has no preconditions.
    if unsafe { libc::geteuid() } == 0 {
        std::fs::write(d.join("theirs.wav"), b"old").unwrap();
        std::os::unix::fs::chown(d.join("theirs.wav"), Some(65_534), Some(65_534)).unwrap();
        let out = render_to("theirs.wav");
        assert!(out.status.success(), "{}", stderr(&out));
        let meta = std::fs::metadata(d.join("theirs.wav")).unwrap();
        assert!(is_wav(&d.join("theirs.wav")));
        assert_eq!((meta.uid(), meta.gid()), (65_534, 65_534));
        std::fs::remove_file(d.join("theirs.wav")).unwrap();
    } else {
        eprintln!("not root: the owner of a file replaced is not checked");
    }

    // A named pipe, a device and a directory are refused, named, and left as they were.
    let fifo = d.join("pipe.wav");
    let c_path = std::ffi::CString::new(fifo.as_os_str().as_encoded_bytes()).unwrap();
    // SAFETY: a valid NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c_path.as_ptr(), 0o644) }, 0);
    std::fs::create_dir(d.join("folder")).unwrap();
    for (output, kind) in [
        ("pipe.wav", "named pipe"),
        ("/dev/null", "device"),
        ("folder", "directory"),
    ] {
        let out = render_to(output);
        assert!(!out.status.success(), "{output} was written");
        let err = stderr(&out);
        assert!(
            err.contains(output) && err.contains(kind) && err.contains("not a regular file"),
            "{output}: {err}"
        );
    }
    assert!(std::os::unix::fs::FileTypeExt::is_fifo(
        &std::fs::symlink_metadata(&fifo).unwrap().file_type()
    ));
    // Nothing else was left behind.
    let mut names = entries(d);
    names.sort();
    assert_eq!(
        names,
        [
            "bank.json",
            "dangling.wav",
            "folder",
            "link.wav",
            "new.wav",
            "pipe.wav",
            "private.wav",
            "target.wav"
        ]
    );
}

#[cfg(unix)]
#[test]
fn an_input_is_known_by_its_identity_not_its_name() {
    let dir = dir_with_bank();
    let d = dir.path();
    std::fs::hard_link(d.join("bank.json"), d.join("alias.wav")).unwrap();
    std::os::unix::fs::symlink("bank.json", d.join("link.wav")).unwrap();
    let before = std::fs::read(d.join("bank.json")).unwrap();
    for output in ["alias.wav", "link.wav"] {
        let out = run(
            d,
            &["render", "bank.json", "--notes", ONE_NOTE, "-o", output],
        );
        assert!(!out.status.success(), "{output} overwrote the bank");
        assert!(
            stderr(&out).contains("would overwrite an input"),
            "{output}: {}",
            stderr(&out)
        );
        let out = run(d, &["compress", "bank.json", "-o", output]);
        assert!(!out.status.success(), "{output} overwrote the bank");
        assert!(
            stderr(&out).contains("would overwrite an input, the bank bank.json"),
            "{output}: {}",
            stderr(&out)
        );
    }
    assert_eq!(std::fs::read(d.join("bank.json")).unwrap(), before);
}

#[test]
fn no_command_writes_over_what_it_reads() {
    let dir = dir_with_bank();
    let d = dir.path();
    write_box_stl(&d.join("box.stl"), [0.1, 0.02, 0.01]);
    write_strike_wav(&d.join("rec.wav"), 1);
    std::fs::hard_link(d.join("box.stl"), d.join("alias.json")).unwrap();
    let kept = ["alias.json", "box.stl", "rec.wav"];
    let originals: Vec<Vec<u8>> = ["bank.json", "box.stl", "rec.wav"]
        .iter()
        .map(|f| std::fs::read(d.join(f)).unwrap())
        .collect();
    let mesh = ["mesh", "box.stl", "--elements", "500", "--modes", "8"];
    let cases: Vec<(Vec<&str>, &str)> = vec![
        ([&mesh[..], &["-o", "box.stl"]].concat(), "the mesh box.stl"),
        (
            [&mesh[..], &["-o", "./alias.json"]].concat(),
            "the mesh box.stl",
        ),
        (
            [
                &mesh[..],
                &["--positions", "2", "--match", "rec.wav=p1", "-o", "rec.wav"],
            ]
            .concat(),
            "the recording rec.wav",
        ),
        (
            vec!["fit", "rec.wav", "-o", "rec.wav"],
            "the recording rec.wav",
        ),
        (
            vec!["compress", "bank.json", "-o", "bank.json"],
            "the bank bank.json",
        ),
        (
            vec![
                "render",
                "bank.json",
                "--notes",
                ONE_NOTE,
                "-o",
                "bank.json",
            ],
            "the bank bank.json",
        ),
    ];
    for (args, input) in cases {
        let out = run(d, &args);
        assert_failed_cleanly(&out, &["would overwrite an input", input], d, &kept);
    }
    for (file, original) in ["bank.json", "box.stl", "rec.wav"].iter().zip(&originals) {
        assert_eq!(
            &std::fs::read(d.join(file)).unwrap(),
            original,
            "{file} changed"
        );
    }
}

#[cfg(target_os = "linux")]
#[test]
fn an_output_that_cannot_be_written_is_refused_before_any_work() {
    // Nobody, root included, may make a file in /sys.
    let dir = dir_with_bank();
    let d = dir.path();
    write_box_stl(&d.join("box.stl"), [0.1, 0.02, 0.01]);
    write_strike_wav(&d.join("rec.wav"), 1);
    let out_path = "/sys/modal-resonator-out.json";
    for args in [
        vec![
            "mesh",
            "box.stl",
            "--elements",
            "500",
            "--modes",
            "8",
            "-o",
            out_path,
        ],
        vec!["fit", "rec.wav", "-o", out_path],
        vec!["shape", "free-free-bar", "-o", out_path],
        vec!["compress", "bank.json", "-o", out_path],
        vec!["render", "bank.json", "--notes", ONE_NOTE, "-o", out_path],
        vec!["fit", "rec.wav", "-o", "fit.json", "--report", out_path],
    ] {
        let out = run(d, &args);
        let err = stderr(&out);
        assert!(!out.status.success(), "{args:?} succeeded");
        assert!(
            err.contains(out_path) && err.contains("cannot write in directory /sys"),
            "{args:?}: {err}"
        );
        assert!(
            !err.contains(".tmp"),
            "{args:?} names a temporary file: {err}"
        );
        // Nothing was solved, fitted or rendered first.
        assert!(stdout(&out).is_empty(), "{args:?}: {}", stdout(&out));
        assert_eq!(entries(d), ["bank.json", "box.stl", "rec.wav"], "{args:?}");
    }
}

#[test]
fn factory_names_are_not_hidden_and_missing_files_are_named() {
    let dir = dir_with_bank();
    let d = dir.path();
    // A factory bank written under its own name is not "the input".
    let out = run(
        d,
        &["compress", "bronze-flat-gong", "-o", "bronze-flat-gong"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    // A render then names the output after the bank: the name still means the factory bank.
    std::fs::write(d.join("bronze-bell"), b"RIFF not a bank").unwrap();
    let out = run(d, &["info", "bronze-bell"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stdout(&out).contains("Bronze bell"), "{}", stdout(&out));
    assert!(
        stderr(&out).contains("write ./bronze-bell for the file"),
        "{}",
        stderr(&out)
    );
    let out = run(d, &["info", "./bronze-bell"]);
    assert!(!out.status.success());
    // A missing file is called missing, where it was looked for.
    let out = run(
        d,
        &["render", "my-bank.json", "--notes", ONE_NOTE, "-o", "x.wav"],
    );
    let err = stderr(&out);
    let looked = d.canonicalize().unwrap().join("my-bank.json");
    assert!(
        err.contains("my-bank.json: no such bank file") && err.contains(&*looked.to_string_lossy()),
        "{err}"
    );
    assert!(!err.contains("celesta"), "lists every factory bank: {err}");
    let out = run(d, &["info", "bronze-bel"]);
    assert!(
        stderr(&out).contains("did you mean bronze-bell"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn list_keeps_its_columns_and_the_docs_count_the_banks_it_lists() {
    let out = run(Path::new("."), &["list"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    let lines: Vec<&str> = text.lines().collect();
    // The modes column ends at the same place on every line, the longest slug's included.
    let ends: Vec<usize> = lines.iter().map(|l| l.find(" modes").unwrap()).collect();
    assert!(ends.iter().all(|&e| e == ends[0]), "{text}");
    let count = lines.len();
    assert_eq!(count, modal_resonator::bank::factory::factory_banks().len());
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    assert!(
        readme.contains(&format!("{count} banks are built in")),
        "README.md"
    );
    let presets = std::fs::read_to_string(root.join("presets/README.md")).unwrap();
    assert!(
        presets.contains(&format!("ships {count} factory banks")),
        "presets/README.md"
    );
}

#[test]
fn every_control_is_documented_for_render_set() {
    let readme =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md")).unwrap();
    let start = readme
        .find("- `--set name=value` sets any control")
        .unwrap();
    let list = &readme[start..start + readme[start..].find("\n- ").unwrap()];
    for spec in modal_resonator::engine::NUMERIC_CONTROLS {
        assert!(
            list.contains(&format!("`{}`", spec.name)),
            "{} is not documented",
            spec.name
        );
    }
}

#[test]
fn quiet_mistakes_are_refused_or_said() {
    let dir = dir_with_bank();
    let d = dir.path();
    write_box_stl(&d.join("box.stl"), [0.1, 0.02, 0.01]);
    let kept = ["box.stl"];
    // A negative value reaches the option's own check, not clap's advice to write `-- -1`.
    for (args, expected) in [
        (
            vec!["mesh", "box.stl", "--scale", "-1", "-o", "o.json"],
            "expected a number above 0",
        ),
        (
            vec!["render", "bank.json", "--notes", "-5:1@0", "-o", "o.wav"],
            "expected a whole number from 0 to 127, found \"-5\"",
        ),
        (
            vec![
                "render",
                "bank.json",
                "--notes",
                "69:1@0 speed=1",
                "-o",
                "o.wav",
            ],
            "speed= and force= drive a contact",
        ),
        (
            vec!["mesh", "box.stl", "--loss-factor", "10", "-o", "o.json"],
            "expected a loss factor above 0 and at most 0.5",
        ),
        (
            vec![
                "compress",
                "bank.json",
                "--limen-scale",
                "1e9",
                "-o",
                "o.json",
            ],
            "--limen-scale 1000000000: expected a number from 0 to 10",
        ),
    ] {
        let out = run(d, &args);
        assert_failed_cleanly(&out, &[expected], d, &kept);
        assert!(!stderr(&out).contains("tip:"), "{args:?}: {}", stderr(&out));
    }
    // A float render over full scale is written, and said to be.
    let out = run(
        d,
        &[
            "render",
            "bank.json",
            "--notes",
            ONE_NOTE,
            "--bits",
            "32",
            "--set",
            "output_gain_db=12",
            "-o",
            "loud.wav",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("over full scale"), "{}", stderr(&out));
    // A note too soft to ring on still counts as the voice it played.
    let out = run(
        d,
        &[
            "render",
            "bank.json",
            "--notes",
            "69:0.001@0",
            "-o",
            "soft.wav",
        ],
    );
    assert!(stdout(&out).contains("up to 1 voice,"), "{}", stdout(&out));
}

#[test]
fn a_normalised_quiet_note_fades_out_instead_of_stopping() {
    // Raised 48 dB by --normalize, a soft note's tail would stop where its modes fell under the
    // truncation threshold before the scaling: at -57 dBFS, a cut.
    let dir = dir_with_bank();
    let out = run(
        dir.path(),
        &[
            "render",
            "rosewood-marimba-bar",
            "--notes",
            "60:0.05@0",
            "--normalize",
            "-1",
            "-o",
            "n.wav",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let samples: Vec<f64> = hound::WavReader::open(dir.path().join("n.wav"))
        .unwrap()
        .samples::<i32>()
        .step_by(2)
        .map(|v| v.unwrap() as f64 / 8_388_608.0)
        .collect();
    let last = samples.iter().rposition(|v| *v != 0.0).unwrap();
    let before = &samples[last.saturating_sub(480)..=last];
    let level = before.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(
        20.0 * level.log10() < -80.0,
        "the 10 ms before the render falls silent peak at {:.1} dBFS",
        20.0 * level.log10()
    );
}

#[test]
fn a_render_to_dash_goes_to_standard_output() {
    let dir = dir_with_bank();
    let d = dir.path();
    let out = run(d, &["render", "bank.json", "--notes", ONE_NOTE, "-o", "-"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(entries(d), ["bank.json"], "a file was written");
    let reader = hound::WavReader::new(std::io::Cursor::new(out.stdout.clone())).unwrap();
    assert_eq!(reader.spec().channels, 2);
    assert!(reader.len() > 0);
    // The summary goes to standard error, out of the WAV's way.
    assert!(stderr(&out).contains("standard output"), "{}", stderr(&out));
    // The same render to a file holds the same bytes.
    let file = run(
        d,
        &["render", "bank.json", "--notes", ONE_NOTE, "-o", "x.wav"],
    );
    assert!(file.status.success());
    let again = run(d, &["render", "bank.json", "--notes", ONE_NOTE, "-o", "-"]);
    assert_eq!(std::fs::read(d.join("x.wav")).unwrap(), again.stdout);
}

#[cfg(unix)]
#[test]
fn listing_commands_end_quietly_when_their_pipe_closes() {
    use std::io::Read;
    use std::process::Stdio;
    let dir = tempfile::tempdir().unwrap();
    for args in [
        &["schema"][..],
        &["info", "ideal-string"],
        &["list"],
        &["validate", "ideal-string"],
    ] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_modal-resonator"))
            .current_dir(dir.path())
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // Close the pipe before reading anything, as `| true` does: the first line printed
        // meets a closed pipe.
        drop(child.stdout.take());
        let mut err = String::new();
        child
            .stderr
            .take()
            .unwrap()
            .read_to_string(&mut err)
            .unwrap();
        child.wait().unwrap();
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert!(err.is_empty(), "{args:?}: {err}");
    }
}

#[test]
fn validate_takes_factory_preset_names() {
    let dir = tempfile::tempdir().unwrap();
    let out = run(dir.path(), &["validate", "ideal-string"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stdout(&out).contains("ok (factory preset"),
        "{}",
        stdout(&out)
    );
    let out = run(dir.path(), &["validate", "no-such-bank"]);
    assert!(!out.status.success());
}

#[test]
fn an_interrupted_render_leaves_nothing_behind() {
    for signal in [libc::SIGINT, libc::SIGTERM] {
        let dir = tempfile::tempdir().unwrap();
        // A mode that barely decays rings to the end: 600 s of 32-bit stereo, a 230 MB file.
        let mut bank = common::simple_bank(&[(440.0, 0.01, 1.0)]);
        bank.root_hz = Some(440.0);
        std::fs::write(
            dir.path().join("bank.json"),
            serde_json::to_string(&bank).unwrap(),
        )
        .unwrap();
        let mut child = Command::new(env!("CARGO_BIN_EXE_modal-resonator"))
            .current_dir(dir.path())
            .args([
                "render",
                "bank.json",
                "--notes",
                "69:1@0+600",
                "--max-seconds",
                "600",
                "--bits",
                "32",
                "-o",
                "out.wav",
            ])
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        // Interrupt it while its temporary file is being written.
        let started = std::time::Instant::now();
        loop {
            if entries(dir.path())
                .iter()
                .any(|n| n.starts_with(".modal-resonator-"))
            {
                break;
            }
            if let Some(status) = child.try_wait().unwrap() {
                panic!("signal {signal}: the render ended ({status}) before it was interrupted");
            }
            assert!(
                started.elapsed().as_secs() < 120,
                "no temporary file appeared"
            );
            std::thread::sleep(std::time::Duration::from_millis(1));
        }
        // SAFETY: sends a signal to the child this test started and has not reaped.
        assert_eq!(unsafe { libc::kill(child.id() as i32, signal) }, 0);
        let status = child.wait().unwrap();
        assert_eq!(status.code(), Some(130), "signal {signal}: {status}");
        assert_eq!(
            entries(dir.path()),
            ["bank.json"],
            "signal {signal} left files behind"
        );
    }
}

/// The exit status and peak resident memory, in bytes, of `child` once it ends.
fn wait_with_peak_memory(child: std::process::Child) -> (std::process::ExitStatus, u64) {
    use std::os::unix::process::ExitStatusExt;
    let mut status = 0;
    // SAFETY: an all-zero rusage is a valid value for wait4 to fill.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: waits for the child this test started and has not reaped, with valid pointers.
    let pid = unsafe { libc::wait4(child.id() as i32, &mut status, 0, &mut usage) };
    assert_eq!(pid, child.id() as i32, "wait4 failed");
    // ru_maxrss is in kilobytes on Linux.
    (
        std::process::ExitStatus::from_raw(status),
        usage.ru_maxrss as u64 * 1024,
    )
}

#[test]
fn a_long_render_streams_to_disk_in_bounded_memory() {
    let dir = tempfile::tempdir().unwrap();
    // A mode that barely decays rings to the end: 300 s of 32-bit stereo, a 115 MB file, which
    // a render held in memory would need as much again to hold.
    let mut bank = common::simple_bank(&[(440.0, 0.01, 1.0)]);
    bank.root_hz = Some(440.0);
    std::fs::write(
        dir.path().join("bank.json"),
        serde_json::to_string(&bank).unwrap(),
    )
    .unwrap();
    let render = |seconds: u32, output: &str| {
        let notes = format!("69:1@0+{seconds}");
        let seconds = seconds.to_string();
        let child = Command::new(env!("CARGO_BIN_EXE_modal-resonator"))
            .current_dir(dir.path())
            .args([
                "render",
                "bank.json",
                "--notes",
                &notes,
                "--max-seconds",
                &seconds,
                "--bits",
                "32",
                "-o",
                output,
            ])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        let (status, peak_bytes) = wait_with_peak_memory(child);
        assert!(status.success(), "{status}");
        peak_bytes
    };
    // The process's own footprint (code, libraries, the bank), measured on a 1 s render.
    let short_bytes = render(1, "short.wav");
    let peak_bytes = render(300, "out.wav");
    let file_bytes = std::fs::metadata(dir.path().join("out.wav")).unwrap().len();
    println!(
        "a {file_bytes}-byte render in {peak_bytes} bytes of memory at most, a 1 s one in \
         {short_bytes}"
    );
    assert!(file_bytes > 115_000_000, "{file_bytes}");
    assert!(
        peak_bytes < short_bytes + file_bytes / 16,
        "the render took {peak_bytes} bytes of memory for a {file_bytes}-byte file, a 1 s one \
         {short_bytes}"
    );
    // The file is whole: its header gives every sample, and the end is faded out.
    let mut reader = hound::WavReader::open(dir.path().join("out.wav")).unwrap();
    assert_eq!(reader.duration(), 300 * 48_000);
    let samples: Vec<f32> = reader.samples::<f32>().map(Result::unwrap).collect();
    let tail = &samples[samples.len() - 2..];
    assert!(tail.iter().all(|x| x.abs() < 1e-3), "{tail:?}");
    assert!(samples[samples.len() / 2..].iter().any(|x| x.abs() > 0.1));
}

#[test]
fn a_bank_of_the_most_modes_renders_one_voice_in_bounded_memory() {
    let dir = tempfile::tempdir().unwrap();
    // 65,536 modes from 100 Hz to 19.8 kHz: every voice of it takes about 19 MB, all 73 of
    // them (polyphony, fade slots and the input voice) 1.4 GB.
    let modes: Vec<(f64, f64, f64)> = (0..65_536)
        .map(|i| (100.0 + 0.3 * i as f64, 5.0, 1.0))
        .collect();
    let mut bank = common::simple_bank(&modes);
    bank.root_hz = Some(100.0);
    std::fs::write(
        dir.path().join("bank.json"),
        serde_json::to_string(&bank).unwrap(),
    )
    .unwrap();
    let child = Command::new(env!("CARGO_BIN_EXE_modal-resonator"))
        .current_dir(dir.path())
        .args([
            "render",
            "bank.json",
            "--notes",
            "43:1@0",
            "--set",
            "polyphony=1",
            "--max-seconds",
            "0.05",
            "-o",
            "out.wav",
        ])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let (status, peak_bytes) = wait_with_peak_memory(child);
    assert!(status.success(), "{status}");
    println!("a 65,536-mode bank at polyphony 1 rendered in {peak_bytes} bytes of memory at most");
    assert!(
        peak_bytes < 400_000_000,
        "one voice of a 65,536-mode bank took {peak_bytes} bytes of memory"
    );
    let mut reader = hound::WavReader::open(dir.path().join("out.wav")).unwrap();
    let samples: Vec<f32> = reader.samples::<i32>().map(|s| s.unwrap() as f32).collect();
    assert!(samples.iter().any(|&x| x != 0.0), "the note is silent");
}

#[test]
fn a_strike_setting_along_an_axis_the_bank_lacks_is_reported() {
    let dir = tempfile::tempdir().unwrap();
    let render = |set: &str| {
        run(
            dir.path(),
            &[
                "render",
                "rosewood-marimba-bar",
                "--notes",
                "60:1@0",
                "--set",
                set,
                "--max-seconds",
                "0.2",
                "-o",
                "out.wav",
            ],
        )
    };
    // The bar's positions lie on a line: y changes nothing, and the user hears why.
    let out = render("strike_y=0.3");
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out)
            .contains("warning: --set strike_y: every position of this bank lies at the same y"),
        "{}",
        stderr(&out)
    );
    let out = render("strike_x=0.5");
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!stderr(&out).contains("warning"), "{}", stderr(&out));
}

/// A binary STL of a box `size` (in the file's units) from the origin.
fn write_box_stl(path: &Path, size: [f64; 3]) {
    let surface = modal_resonator::authoring::mesh::generate::cuboid(size);
    let mut bytes = vec![0u8; 80];
    bytes.extend((surface.triangles.len() as u32).to_le_bytes());
    for t in 0..surface.triangles.len() {
        bytes.extend([0u8; 12]);
        for corner in surface.corners(t) {
            for x in corner {
                bytes.extend((x as f32).to_le_bytes());
            }
        }
        bytes.extend([0u8; 2]);
    }
    std::fs::write(path, bytes).unwrap();
}

#[test]
fn mesh_makes_a_bank_from_an_stl_in_millimetres() {
    let dir = dir_with_bank();
    write_box_stl(&dir.path().join("bar.stl"), [300.0, 30.0, 10.0]);
    let out = run(
        dir.path(),
        &[
            "mesh",
            "bar.stl",
            "--scale",
            "0.001",
            "--elements",
            "2000",
            "--modes",
            "12",
            "--positions",
            "end=0,15,10; middle=150,15,10",
            "-o",
            "bar-mesh.json",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(text.contains("6 rigid motions left out"), "{text}");
    // The first bending mode within 1 % of Euler-Bernoulli's 576.50 Hz.
    let bank = modal_resonator::bank::load_bank_file(&dir.path().join("bar-mesh.json")).unwrap();
    let root = bank.root_hz.unwrap();
    assert!((root / 576.5 - 1.0).abs() < 0.01, "root {root}: {text}");
    assert_eq!(bank.positions[1].name, "middle");
    assert_eq!(bank.positions[1].coords, vec![0.15, 0.015, 0.01]);
    let source = bank.source.as_ref().unwrap();
    assert_eq!(source["kind"], "mesh");
    assert_eq!(source["mesh"], "bar.stl");
    assert_eq!(source["mesh_sha256"].as_str().unwrap().len(), 64);
    assert_eq!(source["material"], "steel");

    // Clamped at one end it is a cantilever: no rigid motion, and 1.875^2 / 4.730^2 of the free
    // bar's first mode (90.6 Hz).
    let out = run(
        dir.path(),
        &[
            "mesh",
            "bar.stl",
            "--scale",
            "0.001",
            "--elements",
            "2000",
            "--modes",
            "4",
            "--fix",
            "x<0",
            "--positions",
            "2",
            "-o",
            "tine.json",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stdout(&out).contains(" 0 rigid motions left out"),
        "{}",
        stdout(&out)
    );
    let tine = modal_resonator::bank::load_bank_file(&dir.path().join("tine.json")).unwrap();
    let lowest = tine.modes[0].freq_hz;
    assert!((lowest / 90.6 - 1.0).abs() < 0.03, "cantilever {lowest} Hz");

    // Matched to a recording struck at its end: the recording's 440 Hz is the bank's lowest mode.
    write_strike_wav(&dir.path().join("strike.wav"), 1);
    let out = run(
        dir.path(),
        &[
            "mesh",
            "bar.stl",
            "--scale",
            "0.001",
            "--elements",
            "2000",
            "--modes",
            "12",
            "--positions",
            "end=0,15,10; middle=150,15,10",
            "--match",
            "strike.wav=end",
            "-o",
            "matched.json",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let matched = modal_resonator::bank::load_bank_file(&dir.path().join("matched.json")).unwrap();
    let at_440 = matched
        .modes
        .iter()
        .find(|m| (m.freq_hz - 440.0).abs() < 0.5)
        .unwrap_or_else(|| panic!("no 440 Hz mode: {:?}", matched.modes));
    // Paired with the mesh's first bending mode: quieter at the middle than at the end.
    assert!(at_440.gains[1].abs() < at_440.gains[0].abs(), "{at_440:?}");
    let record = &matched.source.as_ref().unwrap()["matched_recording"];
    assert_eq!(record["position"], "end");
    assert!(record["paired_modes"].as_u64().unwrap() >= 1, "{record}");
}

#[test]
fn mesh_seeks_modes_up_to_a_frequency_limit() {
    let dir = dir_with_bank();
    write_box_stl(&dir.path().join("bar.stl"), [0.3, 0.03, 0.01]);
    // Asked for every mode below 1 MHz, the solve doubles its count until the cap of 500.
    let out = run(
        dir.path(),
        &[
            "mesh",
            "bar.stl",
            "--elements",
            "300",
            "--max-hz",
            "1000000",
            "-o",
            "all.json",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("all 500 modes found lie below --max-hz"),
        "{}",
        stderr(&out)
    );
    let bank = modal_resonator::bank::load_bank_file(&dir.path().join("all.json")).unwrap();
    // Those the strike points excite (the rest have no gain anywhere).
    assert!(bank.modes.len() > 100, "{} modes", bank.modes.len());
    // With a limit the first 100 reach, one solve: every mode kept lies below it.
    let out = run(
        dir.path(),
        &[
            "mesh",
            "bar.stl",
            "--elements",
            "300",
            "--max-hz",
            "3000",
            "-o",
            "low.json",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let low = modal_resonator::bank::load_bank_file(&dir.path().join("low.json")).unwrap();
    assert!(
        low.modes.iter().all(|m| m.freq_hz < 3000.0),
        "{:?}",
        low.modes
    );
    assert!(low.modes.len() >= 2, "{:?}", low.modes);
}

#[test]
fn mesh_refuses_bad_meshes_and_options_cleanly() {
    let dir = dir_with_bank();
    let open = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\n";
    std::fs::write(dir.path().join("open.obj"), open).unwrap();
    let out = run(dir.path(), &["mesh", "open.obj", "-o", "out.json"]);
    assert_failed_cleanly(
        &out,
        &["open.obj", "not closed", "edge"],
        dir.path(),
        &["open.obj"],
    );

    write_box_stl(&dir.path().join("box.stl"), [0.1, 0.1, 0.1]);
    let extra = ["box.stl", "open.obj"];
    for (args, expected) in [
        (vec!["--fix", "w<3"], "--fix \"w<3\""),
        (vec!["--fix", "vertices=99"], "vertex 99 does not exist"),
        (vec!["--positions", "rim=1,2"], "expected NAME=X,Y,Z"),
        (vec!["--positions", "0"], "expected 1 to 64 points"),
        (
            vec!["--match", "missing.wav=nowhere"],
            "neither a strike point",
        ),
        (
            vec!["--positions", "2", "--match", "missing.wav=p1"],
            "missing.wav",
        ),
        (vec!["--elements", "2"], "elements: expected at least 8"),
        (
            vec!["--modes", "100000"],
            "expected a whole number from 1 to 500",
        ),
        (
            vec!["--positions", "a=0,0,0; a=1,1,1"],
            "\"a\" is named twice",
        ),
    ] {
        let mut all = vec!["mesh", "box.stl"];
        all.extend(args.iter().copied());
        all.extend(["-o", "out.json"]);
        let out = run(dir.path(), &all);
        assert_failed_cleanly(&out, &[expected], dir.path(), &extra);
    }
}

#[test]
fn mesh_says_a_binary_stl_is_truncated() {
    let dir = dir_with_bank();
    write_box_stl(&dir.path().join("box.stl"), [0.1, 0.1, 0.1]);
    let bytes = std::fs::read(dir.path().join("box.stl")).unwrap();
    std::fs::write(dir.path().join("cut.stl"), &bytes[..bytes.len() / 2]).unwrap();
    let out = run(dir.path(), &["mesh", "cut.stl", "-o", "out.json"]);
    assert_failed_cleanly(
        &out,
        &[
            "cut.stl: a binary STL whose header gives 12 triangles",
            "truncated",
        ],
        dir.path(),
        &["box.stl", "cut.stl"],
    );
}

#[test]
fn mesh_refuses_too_many_elements_before_reading_the_mesh() {
    let dir = dir_with_bank();
    let out = run(
        dir.path(),
        &[
            "mesh",
            "missing.stl",
            "--elements",
            "200001",
            "-o",
            "out.json",
        ],
    );
    assert_failed_cleanly(
        &out,
        &["--elements: too large: 200001 elements, at most 200000"],
        dir.path(),
        &[],
    );
    assert!(!stderr(&out).contains("missing.stl"), "{}", stderr(&out));
}

#[test]
fn mesh_in_millimetres_read_as_metres_is_refused_naming_scale() {
    let dir = dir_with_bank();
    write_box_stl(&dir.path().join("bar.stl"), [300.0, 30.0, 10.0]);
    let out = run(
        dir.path(),
        &[
            "mesh",
            "bar.stl",
            "--elements",
            "1000",
            "--modes",
            "4",
            "-o",
            "bar.json",
        ],
    );
    // The 300 m bar's first bending mode, 576.5 Hz / 1000, is found and refused, not dropped
    // as a seventh rigid motion.
    assert_failed_cleanly(
        &out,
        &[
            "warning: bar.stl: at --scale 1: the object is 300 m across",
            "lowest mode 0.57",
            "under the 1 Hz floor",
            "try --scale 0.001",
        ],
        dir.path(),
        &["bar.stl"],
    );
    // Scaled a thousand times too small, every mode lies far above 20 kHz: said so, with the
    // lowest and the size.
    let out = run(
        dir.path(),
        &[
            "mesh",
            "bar.stl",
            "--scale",
            "1e-6",
            "--elements",
            "1000",
            "-o",
            "bar.json",
        ],
    );
    assert_failed_cleanly(
        &out,
        &[
            "no mode below 20000 Hz: the lowest is 57",
            "the object is 0.3 mm across: is --scale right?",
        ],
        dir.path(),
        &["bar.stl"],
    );
    assert!(
        !stderr(&out).contains("positive definite"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn mesh_default_strike_points_sound_a_bar_s_fundamental() {
    let dir = dir_with_bank();
    write_box_stl(&dir.path().join("bar.stl"), [300.0, 30.0, 10.0]);
    let out = run(
        dir.path(),
        &[
            "mesh",
            "bar.stl",
            "--scale",
            "0.001",
            "--elements",
            "2000",
            "--modes",
            "12",
            "-o",
            "bar.json",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!stderr(&out).contains("warning"), "{}", stderr(&out));
    let bank = modal_resonator::bank::load_bank_file(&dir.path().join("bar.json")).unwrap();
    assert_eq!(bank.positions.len(), 6);
    // The first bending mode (Euler-Bernoulli 576.50 Hz), not the width-bending 1,671 Hz.
    let root = bank.root_hz.unwrap();
    assert!(
        (root / 576.5 - 1.0).abs() < 0.01,
        "root {root}: {}",
        stdout(&out)
    );
    let first = &bank.modes[0];
    assert_eq!(first.freq_hz, root);
    let peak_at_default = bank
        .modes
        .iter()
        .map(|m| m.gains[0].abs())
        .fold(0.0, f64::max);
    assert_eq!(first.gains[0].abs(), peak_at_default, "{:?}", bank.modes);
}

#[test]
fn shape_builds_a_triangle_at_the_requested_root() {
    let dir = dir_with_bank();
    let out = run(
        dir.path(),
        &[
            "shape",
            "triangle",
            "--root-note",
            "A5",
            "-o",
            "triangle.json",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stdout(&out).contains("root 880.00 Hz (A5)"),
        "{}",
        stdout(&out)
    );
    let bank = modal_resonator::bank::load_bank_file(&dir.path().join("triangle.json")).unwrap();
    assert!(modal_resonator::bank::validate::validate_bank(&bank).is_empty());
    assert!((bank.root_hz.unwrap() / 880.0 - 1.0).abs() < 1e-12);
    assert_eq!(bank.modes[0].freq_hz, bank.root_hz.unwrap());
    // The free-free rod's partials, 1 : 2.756 : 5.404.
    for (k, ratio) in [(1, 2.756), (2, 5.404)] {
        let got = bank.modes[k].freq_hz / bank.modes[0].freq_hz;
        assert!((got / ratio - 1.0).abs() < 1e-3, "mode {k}: {got}");
    }
    let source = bank.source.unwrap();
    assert_eq!(source["shape"], "triangle");
    assert_eq!(source["material"], "steel");
    let help = stdout(&run(dir.path(), &["shape", "--help"]));
    assert!(help.contains("triangle"), "{help}");
}
