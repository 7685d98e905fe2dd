//! The resonator bank against closed forms, and every kernel against the scalar oracle.

use modal_resonator::dsp::coeffs::ModeCoeffs;
use modal_resonator::dsp::{Kernel, ResonatorBank, COLUMNS};
use modal_resonator::units::{decay_to_t60_s, t60_to_decay};

fn kernels() -> Vec<Kernel> {
    Kernel::ALL
        .into_iter()
        .filter(|k| k.is_supported())
        .collect()
}

/// Output (sum over columns) of `bank` driven by `input`, in runs of `block` samples.
fn run(bank: &mut ResonatorBank, kernel: Kernel, input: &[f32], block: usize) -> Vec<f64> {
    let mut out = Vec::with_capacity(input.len());
    let mut acc = vec![[0.0f32; COLUMNS]; block];
    for chunk in input.chunks(block) {
        let acc = &mut acc[..chunk.len()];
        acc.fill([0.0; COLUMNS]);
        let driven = chunk.iter().any(|&x| x != 0.0);
        bank.process(kernel, driven.then_some(chunk), acc);
        out.extend(acc.iter().map(|a| a.iter().map(|&v| v as f64).sum::<f64>()));
    }
    out
}

/// Frequency (Hz) of a damped sinusoid from its upward zero crossings, which fall exactly one
/// period apart whatever the decay; linear interpolation between samples.
fn measure_freq_hz(y: &[f64], rate: f64) -> f64 {
    let crossings: Vec<f64> = y
        .windows(2)
        .enumerate()
        .filter(|(_, w)| w[0] < 0.0 && w[1] >= 0.0)
        .map(|(n, w)| n as f64 + w[0] / (w[0] - w[1]))
        .collect();
    let (first, last) = (crossings[0], crossings[crossings.len() - 1]);
    (crossings.len() - 1) as f64 * rate / (last - first)
}

/// Decay rate (1/s) of a damped sinusoid: least-squares slope of the log of its half-cycle peaks
/// (parabolically interpolated), which all sit at the same phase.
fn measure_decay_per_s(y: &[f64], rate: f64) -> f64 {
    let mut points = Vec::new();
    for n in 1..y.len() - 1 {
        let (a, b, c) = (y[n - 1].abs(), y[n].abs(), y[n + 1].abs());
        if b > a && b >= c && b > 0.0 {
            let shift = 0.5 * (a - c) / (a - 2.0 * b + c);
            let height = b - 0.25 * (a - c) * shift;
            points.push(((n as f64 + shift) / rate, height.ln()));
        }
    }
    let k = points.len() as f64;
    let (st, sl) = points
        .iter()
        .fold((0.0, 0.0), |(st, sl), (t, l)| (st + t, sl + l));
    let (mt, ml) = (st / k, sl / k);
    let (num, den) = points.iter().fold((0.0, 0.0), |(n, d), (t, l)| {
        (n + (t - mt) * (l - ml), d + (t - mt).powi(2))
    });
    -num / den
}

#[test]
fn impulse_response_has_the_requested_frequency_and_t60() {
    let rates = [44_100.0, 48_000.0, 96_000.0, 192_000.0];
    let cases = [
        (27.5, 8.0),
        (440.0, 1.0),
        (2_000.0, 3.0),
        (9_000.0, 0.2),
        (19_000.0, 0.5),
    ];
    for kernel in kernels() {
        for &rate in &rates {
            for &(freq_hz, t60_s) in &cases {
                let decay = t60_to_decay(t60_s);
                let mut bank = ResonatorBank::new(1);
                bank.activate(0, ModeCoeffs::from_freq_decay(rate, freq_hz, decay), 0.8);
                // Long enough to see the decay (at least 0.4 s), short enough to stay far above
                // f32 rounding.
                let len = (rate * (t60_s * 0.5).clamp(0.4, 2.0)) as usize;
                let mut input = vec![0.0f32; len];
                input[0] = 1.0;
                let y = run(&mut bank, kernel, &input, 256);
                let got_hz = measure_freq_hz(&y, rate);
                let got_t60 = decay_to_t60_s(measure_decay_per_s(&y, rate));
                let k = kernel.name();
                assert!(
                    (got_hz / freq_hz - 1.0).abs() < 1e-4,
                    "{k} at {rate} Hz: asked {freq_hz} Hz, got {got_hz} Hz"
                );
                assert!(
                    (got_t60 / t60_s - 1.0).abs() < 0.01,
                    "{k} at {rate} Hz, {freq_hz} Hz: asked T60 {t60_s} s, got {got_t60} s"
                );
                // And the waveform is the model's, gain * exp(-d t) * sin(2 pi f t), over the
                // first 50 ms (later, f32 rounding of the pole shifts the phase by a few 1e-4 rad).
                let peak = y.iter().fold(0.0f64, |a, v| a.max(v.abs()));
                for (n, &v) in y.iter().enumerate().take((0.05 * rate) as usize).step_by(7) {
                    let want = ModeCoeffs::impulse_response(rate, freq_hz, decay, 0.8, n);
                    assert!(
                        (v - want).abs() <= 1e-4 * peak,
                        "{k} at {rate} Hz, {freq_hz} Hz, sample {n}: {v} vs closed form {want}"
                    );
                }
            }
        }
    }
}

/// Coefficients and gain of mode `m` of an assorted bank at 48 kHz.
fn assorted_mode(m: usize) -> (ModeCoeffs, f32) {
    let f = 40.0 + (m as f64 * 131.7) % 21_000.0;
    let d = 0.5 + (m % 17) as f64 * 3.0;
    let g = if m.is_multiple_of(3) { -1.0 } else { 1.0 } / (1.0 + m as f32 * 0.05);
    (ModeCoeffs::from_freq_decay(48_000.0, f, d), g)
}

/// A bank of `n` modes with assorted frequencies, decays and gains.
fn assorted(n: usize) -> ResonatorBank {
    let mut bank = ResonatorBank::new(n);
    for m in 0..n {
        let (c, g) = assorted_mode(m);
        bank.activate(m, c, g);
    }
    bank
}

/// A mallet-like pulse at the start, then silence, then a second strike.
fn strike_input(len: usize) -> Vec<f32> {
    let mut x = vec![0.0f32; len];
    for (n, v) in x.iter_mut().take(24).enumerate() {
        *v = (1.0 - (std::f32::consts::TAU * (n as f32 + 0.5) / 24.0).cos()) / 24.0;
    }
    x[len / 2] = 0.7;
    x
}

#[test]
fn every_kernel_matches_the_scalar_oracle() {
    // Mode counts that leave every size of group over after the whole ones (one to three rows,
    // or row pairs).
    for &n in &[1usize, 7, 14, 24, 30, 56, 64, 96, 200, 420, 1000] {
        let input = strike_input(24_000);
        let oracle = run(&mut assorted(n), Kernel::Scalar, &input, 64);
        let peak = oracle.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        for kernel in kernels() {
            let got = run(&mut assorted(n), kernel, &input, 64);
            for (i, (a, b)) in oracle.iter().zip(&got).enumerate() {
                assert!(
                    (a - b).abs() <= 1e-5 * peak,
                    "{} with {n} modes, sample {i}: scalar {a}, got {b} (peak {peak})",
                    kernel.name()
                );
            }
        }
    }
}

#[test]
fn block_size_does_not_change_the_output() {
    let input = strike_input(12_000);
    for kernel in kernels() {
        let whole = run(&mut assorted(300), kernel, &input, 4096);
        for block in [1, 3, 64, 1000] {
            let split = run(&mut assorted(300), kernel, &input, block);
            assert_eq!(
                whole,
                split,
                "{}: block {block} differs from block 4096",
                kernel.name()
            );
        }
    }
}

#[test]
fn clearing_reproduces_the_output_exactly() {
    let input = strike_input(6_000);
    for kernel in kernels() {
        let mut bank = assorted(100);
        let first = run(&mut bank, kernel, &input, 64);
        bank.clear();
        for m in 0..100 {
            let (c, g) = assorted_mode(m);
            bank.activate(m, c, g);
        }
        let second = run(&mut bank, kernel, &input, 64);
        assert_eq!(first, second, "{}", kernel.name());
    }
}

#[test]
fn retired_modes_leave_the_rest_untouched() {
    // The upper half of the modes decays fast; after retiring them the survivors must sound
    // exactly as in a bank that never held the fast ones.
    for kernel in kernels() {
        let n = 203;
        let fast = |m: usize| m >= n / 2;
        let coeffs = |m: usize| {
            let fast = fast(m);
            ModeCoeffs::from_freq_decay(
                48_000.0,
                100.0 + 53.0 * m as f64,
                if fast { 2_000.0 } else { 1.0 },
            )
        };
        let mut both = ResonatorBank::new(n);
        let mut slow_only = ResonatorBank::new(n);
        for m in 0..n {
            both.activate(m, coeffs(m), 1.0);
            if !fast(m) {
                slow_only.activate(m, coeffs(m), 1.0);
            }
        }
        let mut input = vec![0.0f32; 4_800];
        input[0] = 1.0;
        run(&mut both, kernel, &input, 64);
        run(&mut slow_only, kernel, &input, 64);
        let computed_before = both.num_computed(kernel);
        both.retire_below(1e-6);
        assert_eq!(both.num_live(), slow_only.num_live(), "{}", kernel.name());
        assert!(
            both.num_computed(kernel) < computed_before,
            "re-packing must shrink the work: {} modes computed before, {} after",
            computed_before,
            both.num_computed(kernel)
        );
        let silence = vec![0.0f32; 4_800];
        let a = run(&mut both, kernel, &silence, 64);
        let b = run(&mut slow_only, kernel, &silence, 64);
        let peak = b.iter().fold(0.0f64, |x, v| x.max(v.abs()));
        for (i, (x, y)) in a.iter().zip(&b).enumerate() {
            assert!(
                (x - y).abs() <= 1e-6 * peak,
                "{} sample {i}: {x} vs {y}",
                kernel.name()
            );
        }
    }
}
