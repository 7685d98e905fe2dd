//! Helpers shared by the integration tests: banks built in code and small signal measurements.
#![allow(dead_code)]

pub mod clap;
pub mod corpus;
pub mod decode;
pub mod fit_score;
pub mod recordings;
pub mod sf2;

use std::sync::Arc;

use modal_resonator::bank::{Bank, Mode, Position};
use modal_resonator::engine::{Engine, NoteEvent, PreparedBank};
use modal_resonator::rng::Rng;

/// A 1-D bank of `modes` given as `(freq_hz, decay_per_s, gain)`, with a single position.
pub fn simple_bank(modes: &[(f64, f64, f64)]) -> Bank {
    let mut bank = Bank::new(
        "test",
        vec![Position {
            name: "a".into(),
            coords: vec![0.0],
        }],
    );
    bank.modes = modes
        .iter()
        .map(|&(f, d, g)| Mode {
            freq_hz: f,
            decay_per_s: d,
            gains: vec![g],
        })
        .collect();
    bank
}

/// Two strike positions on a line: `a` at 0 and `b` at 1.
#[allow(dead_code)] // not every test file uses it
pub fn two_ends() -> Vec<Position> {
    vec![
        Position {
            name: "a".into(),
            coords: vec![0.0],
        },
        Position {
            name: "b".into(),
            coords: vec![1.0],
        },
    ]
}

/// A bank of `n` inharmonic modes from `f0` with two positions, deterministic.
pub fn dense_bank(n: usize, f0: f64) -> Bank {
    let positions = vec![
        Position {
            name: "end".into(),
            coords: vec![0.0],
        },
        Position {
            name: "middle".into(),
            coords: vec![0.5],
        },
    ];
    let mut bank = Bank::new("dense", positions);
    let mut rng = Rng::new(12345);
    let mut rnd = || f64::from(rng.next_u32()) / f64::from(u32::MAX);
    bank.modes = (0..n)
        .map(|i| {
            let f = f0 * (1.0 + i as f64 * (0.7 + 0.6 * rnd()));
            Mode {
                freq_hz: f,
                decay_per_s: 1.0 + f / 400.0,
                gains: vec![
                    (1.0 / (1.0 + i as f64 * 0.1)) * (rnd() - 0.3),
                    0.5 * (rnd() - 0.5),
                ],
            }
        })
        .collect();
    bank.root_hz = Some(f0);
    bank
}

/// An engine playing `bank`, prepared at `rate`.
pub fn engine(bank: &Bank, rate: f32) -> Engine {
    let mut e = Engine::new(Arc::new(PreparedBank::new(bank)));
    e.prepare(rate, 512);
    e
}

/// Renders `seconds` of stereo from `engine` in blocks of `block`, with `events` given in absolute
/// sample times.
pub fn render(
    engine: &mut Engine,
    events: &[NoteEvent],
    seconds: f64,
    block: usize,
) -> (Vec<f32>, Vec<f32>) {
    let total = (seconds * engine.sample_rate_hz() as f64) as usize;
    let mut l = vec![0.0; total];
    let mut r = vec![0.0; total];
    let mut start = 0;
    let mut block_events = Vec::new();
    while start < total {
        let end = (start + block).min(total);
        block_events.clear();
        for e in events {
            let t = e.time() as usize;
            if t >= start && t < end {
                block_events.push(shift(*e, start as u32));
            }
        }
        engine.process(&block_events, None, &mut l[start..end], &mut r[start..end]);
        start = end;
    }
    (l, r)
}

/// `event` with its time made relative to `offset`.
pub fn shift(event: NoteEvent, offset: u32) -> NoteEvent {
    event.at(event.time() - offset)
}

/// A note-on at absolute sample `time`.
pub fn on(time: u32, key: u8, velocity: f32) -> NoteEvent {
    NoteEvent::on(time, key, velocity)
}

/// Largest absolute sample.
pub fn peak(x: &[f32]) -> f32 {
    x.iter().fold(0.0, |a, v| a.max(v.abs()))
}

/// Largest absolute difference between consecutive samples in `x`.
pub fn max_step(x: &[f32]) -> f32 {
    x.windows(2).fold(0.0, |a, w| a.max((w[1] - w[0]).abs()))
}

/// Fundamental frequency of `x` by autocorrelation peak picking with parabolic refinement,
/// searching `lo_hz..hi_hz`.
pub fn pitch_hz(x: &[f32], rate: f64, lo_hz: f64, hi_hz: f64) -> f64 {
    let n = x.len().min((rate * 0.5) as usize);
    let x = &x[..n];
    let ac = |lag: usize| -> f64 {
        x[..n - lag]
            .iter()
            .zip(&x[lag..])
            .map(|(a, b)| (*a as f64) * (*b as f64))
            .sum()
    };
    let (min_lag, max_lag) = ((rate / hi_hz) as usize, (rate / lo_hz) as usize);
    let mut best = (min_lag, f64::MIN);
    for lag in min_lag..=max_lag.min(n / 2) {
        let v = ac(lag);
        if v > best.1 {
            best = (lag, v);
        }
    }
    let l = best.0;
    let (a, b, c) = (ac(l - 1), ac(l), ac(l + 1));
    let shift = 0.5 * (a - c) / (a - 2.0 * b + c);
    rate / (l as f64 + shift)
}

/// Frequency of the strongest spectral peak of `x` between `lo_hz` and `hi_hz`, to about
/// 0.01 Hz: for mixtures, where autocorrelation picks the wrong period.
pub fn spectral_peak_hz(x: &[f32], rate: f64, lo_hz: f64, hi_hz: f64) -> f64 {
    let strongest = |from: f64, to: f64, step: f64| {
        let mut best = (from, f64::MIN);
        let mut f = from;
        while f <= to {
            let m = magnitude_at(x, rate, f);
            if m > best.1 {
                best = (f, m);
            }
            f += step;
        }
        best.0
    };
    let coarse = strongest(lo_hz, hi_hz, 1.0);
    let fine = strongest(coarse - 1.0, coarse + 1.0, 0.05);
    strongest(fine - 0.05, fine + 0.05, 0.005)
}

/// Magnitude of the spectrum of `x` at `freq_hz` (a single DFT bin at any frequency).
pub fn magnitude_at(x: &[f32], rate: f64, freq_hz: f64) -> f64 {
    let w = std::f64::consts::TAU * freq_hz / rate;
    let (mut re, mut im) = (0.0, 0.0);
    for (n, &v) in x.iter().enumerate() {
        let hann = 0.5 - 0.5 * (std::f64::consts::TAU * n as f64 / x.len() as f64).cos();
        re += hann * v as f64 * (w * n as f64).cos();
        im -= hann * v as f64 * (w * n as f64).sin();
    }
    (re * re + im * im).sqrt()
}

/// The benchmarks' bank: 256 modes ringing for about a minute, so every mode stays live for
/// the whole run.
pub fn bench_bank() -> modal_resonator::bank::Bank {
    let mut bank = modal_resonator::bank::Bank::new(
        "bench",
        vec![modal_resonator::bank::Position {
            name: "a".into(),
            coords: vec![0.0],
        }],
    );
    bank.modes = (0..256)
        .map(|i| modal_resonator::bank::Mode {
            freq_hz: 60.0 * (1.0 + i as f64 * 0.37),
            decay_per_s: 0.2,
            gains: vec![1.0 / (1.0 + i as f64)],
        })
        .collect();
    bank.root_hz = Some(60.0);
    bank
}
