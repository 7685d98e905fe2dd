//! Packing: modes keep their columns and states however the bank is re-packed.

use super::*;

fn coeffs(mode: usize) -> ModeCoeffs {
    ModeCoeffs::from_freq_decay(48_000.0, 100.0 + 37.0 * mode as f64, 3.0 + mode as f64)
}

/// A bank of `n` modes, all sounding with gain 1.
fn sounding(n: usize) -> ResonatorBank {
    let mut bank = ResonatorBank::new(n);
    for m in 0..n {
        bank.activate(m, coeffs(m), 1.0);
    }
    bank
}

#[test]
fn repacking_keeps_each_mode_with_its_state() {
    let mut bank = ResonatorBank::new(100);
    for m in 0..100 {
        bank.activate(m, coeffs(m), 1.0 + m as f32);
    }
    let mut acc = vec![[0.0; COLUMNS]; 32];
    let input: Vec<f32> = (0..32).map(|n| if n == 0 { 1.0 } else { 0.0 }).collect();
    bank.process(Kernel::Scalar, Some(&input), &mut acc);
    let before: Vec<_> = (0..100).map(|m| bank.state(m).unwrap()).collect();
    // Silence every third mode, then retire the silent ones.
    let mut kept = bank.clone();
    for m in (0..100).filter(|m| m % 3 == 0) {
        let slot = kept.slot_of_mode[m] as usize;
        kept.re[slot] = 0.0;
        kept.im[slot] = 0.0;
    }
    kept.retire_below(1e-10);
    for (m, state) in before.iter().enumerate() {
        if m % 3 == 0 {
            assert!(!kept.is_live(m), "mode {m} should be retired");
        } else {
            assert_eq!(kept.state(m), Some(*state), "mode {m} lost its state");
            assert_eq!(
                kept.slot_of_mode[m] as usize % COLUMNS,
                m % COLUMNS,
                "mode {m} changed column"
            );
        }
    }
    assert_eq!(kept.num_live(), 100 - 34);
}

#[test]
fn retiring_finds_quiet_and_broken_modes_among_padding() {
    // 20 modes: columns 0-3 hold three, columns 4-7 two, so the rows the kernels run over hold
    // 4 empty slots (12 for a kernel taking two rows at once).
    let mut bank = sounding(20);
    let mut acc = vec![[0.0; COLUMNS]; 16];
    let input: Vec<f32> = (0..16).map(|n| if n == 0 { 1.0 } else { 0.0 }).collect();
    bank.process(Kernel::Scalar, Some(&input), &mut acc);
    assert_eq!(bank.rows_active * COLUMNS - bank.num_slots, 4);
    let set = |bank: &mut ResonatorBank, m: usize, value: f32| {
        let slot = bank.slot_of_mode[m] as usize;
        (bank.re[slot], bank.im[slot]) = (value, 0.0);
    };
    // Nothing is below: nothing goes.
    assert_eq!(bank.retire_below(1e-6), 0);
    assert_eq!(bank.num_live(), 20);
    // A state that is not a number, alone.
    set(&mut bank, 8, f32::NAN);
    assert_eq!(bank.retire_below(1e-6), 1);
    assert!(!bank.is_live(8));
    // A quiet mode in a short column (4), with column 0 one mode shorter after re-packing.
    let short = 12;
    assert_eq!(bank.slot_of_mode[short] as usize % COLUMNS, 4);
    set(&mut bank, short, 1e-9);
    assert_eq!(bank.retire_below(1e-6), 1);
    assert!(!bank.is_live(short));
    // Exactly at the threshold stays.
    set(&mut bank, 5, 1e-6);
    assert_eq!(bank.retire_below(1e-6), 0);
    assert_eq!(bank.num_live(), 18);
    // Computing keeps the empty slots silent (checked in debug builds).
    bank.process(Kernel::Scalar, None, &mut acc);
    assert_eq!(bank.retire_below(1e-7), 0);
}

#[test]
fn skipped_modes_do_not_leave_lanes_empty() {
    // Only even modes sound, as when a string is struck at its middle.
    let mut bank = ResonatorBank::new(256);
    for m in (0..256).step_by(2) {
        bank.activate(m, coeffs(m), 1.0);
    }
    assert_eq!(bank.live, [16; COLUMNS]);
    assert_eq!(bank.num_computed(Kernel::Scalar), 128);
}

#[test]
fn kernels_compute_the_rows_the_fullest_column_needs_in_their_row_blocks() {
    // 20 modes fill three rows.
    let mut bank = sounding(20);
    let mut acc = vec![[0.0; COLUMNS]; 16];
    for kernel in Kernel::ALL.into_iter().filter(|k| k.is_supported()) {
        let before = bank.computed_mode_samples();
        bank.process(kernel, None, &mut acc);
        let rows = if kernel.row_block() == 1 { 3 } else { 4 };
        assert_eq!(
            bank.num_computed(kernel),
            rows * COLUMNS,
            "{}",
            kernel.name()
        );
        assert_eq!(
            bank.computed_mode_samples() - before,
            (rows * COLUMNS * 16) as u64,
            "{}",
            kernel.name()
        );
    }
}

mod dormant {
    use super::super::FADE_DEPTH_NEPERS;
    use super::*;
    use std::f64::consts::TAU;

    const RATE: f64 = 48_000.0;

    fn pole(m: usize, pitch: f64) -> (f64, f64) {
        let f = pitch * (100.0 + 173.0 * m as f64);
        (TAU * f / RATE, (2.0 + m as f64) / RATE)
    }

    /// A bank of `n` modes ringing after an impulse.
    fn ringing(n: usize) -> ResonatorBank {
        let mut bank = ResonatorBank::new(n);
        for m in 0..n {
            bank.activate(m, coeffs(m), 0.0);
        }
        bank.set_poles_with(|m| pole(m, 1.0));
        bank.set_gains_with(|m| 1.0 / (1.0 + m as f32));
        let mut acc = vec![[0.0; COLUMNS]; 64];
        let mut x = vec![0.0; 64];
        x[0] = 1.0;
        bank.process(Kernel::Scalar, Some(&x), &mut acc);
        bank
    }

    /// Runs `samples` (whole control periods) without input, ending fades on the way; returns
    /// the summed output.
    fn run(bank: &mut ResonatorBank, samples: usize, input: Option<&[f32]>) -> Vec<f32> {
        let mut out = Vec::new();
        for block in 0..samples / 64 {
            let mut acc = vec![[0.0; COLUMNS]; 64];
            bank.process(Kernel::Scalar, input.filter(|_| block == 0), &mut acc);
            bank.finish_fades();
            out.extend(acc.iter().map(|a| a.iter().sum::<f32>()));
        }
        out
    }

    fn assert_same_states(a: &ResonatorBank, b: &ResonatorBank, n: usize) {
        for m in 0..n {
            let (x, y) = (a.state(m).unwrap(), b.state(m).unwrap());
            let scale = y.0.hypot(y.1);
            assert!(
                (x.0 - y.0).abs() < 1e-4 * scale && (x.1 - y.1).abs() < 1e-4 * scale,
                "mode {m}: {x:?} vs {y:?}"
            );
        }
    }

    #[test]
    fn a_mode_switched_off_and_on_returns_in_phase() {
        let mut pruned = ringing(20);
        let mut reference = pruned.clone();
        for m in [3, 7, 11] {
            pruned.switch_off(m, 256, 0, 0);
        }
        assert_eq!(pruned.num_fading(), 3);
        run(&mut pruned, 512, None);
        run(&mut reference, 512, None);
        assert_eq!(pruned.num_dormant(), 3);
        assert_eq!(pruned.num_active(), 17);
        assert_eq!(pruned.num_live(), 20);
        // Dormant, the mode's level follows its decay.
        pruned.for_each_dormant(u64::MAX, |d| {
            let (re, im) = reference.state(d.mode).unwrap();
            let want = 10.0 * (re * re + im * im).log10();
            assert!(
                (d.level_db - want).abs() < 0.01,
                "mode {}: {} dB, expected {want}",
                d.mode,
                d.level_db
            );
        });
        for m in [3, 7, 11] {
            pruned.switch_on(m, 256);
        }
        run(&mut pruned, 5 * 64, None);
        run(&mut reference, 5 * 64, None);
        assert_eq!(pruned.num_fading(), 0);
        assert_same_states(&pruned, &reference, 20);
    }

    #[test]
    fn fades_are_smooth_envelopes() {
        let mut pruned = ringing(1);
        let mut reference = pruned.clone();
        pruned.switch_off(0, 256, 0, 0);
        let (x, y) = (run(&mut pruned, 512, None), run(&mut reference, 512, None));
        // The reference under an exponential envelope 60 dB deep over 256 samples.
        for n in 0..256 {
            let env = (-FADE_DEPTH_NEPERS * (n + 1) as f64 / 256.0).exp() as f32;
            assert!(
                (x[n] - env * y[n]).abs() < 1e-5,
                "sample {n}: {} vs {}",
                x[n],
                env * y[n]
            );
        }
        assert!(x[256..].iter().all(|&v| v == 0.0));
        assert_eq!(pruned.num_active(), 0);
        assert_eq!(pruned.num_live(), 1);
    }

    #[test]
    fn a_strike_on_woken_modes_sounds_as_if_they_had_never_slept() {
        let n = 30;
        let mut pruned = ringing(n);
        let mut reference = pruned.clone();
        for m in (0..n).step_by(2) {
            pruned.switch_off(m, 128, 0, 0);
        }
        run(&mut pruned, 640, None);
        run(&mut reference, 640, None);
        // A pitch change while dormant.
        pruned.set_poles_with(|m| pole(m, 1.05));
        reference.set_poles_with(|m| pole(m, 1.05));
        run(&mut pruned, 640, None);
        run(&mut reference, 640, None);
        // One mode fading back in, one fading out, the rest dormant, when the strike comes.
        pruned.switch_on(4, 256);
        pruned.switch_off(5, 256, 0, 0);
        let mut before: Vec<f32> = run(&mut pruned, 64, None)
            .iter()
            .zip(run(&mut reference, 64, None))
            .map(|(a, b)| a - b)
            .collect();
        // The strike comes between control periods: fades started there end between them.
        let (mut a, mut b) = ([[0.0; COLUMNS]; 23], [[0.0; COLUMNS]; 23]);
        pruned.process(Kernel::Scalar, None, &mut a);
        reference.process(Kernel::Scalar, None, &mut b);
        before.extend(
            a.iter()
                .zip(&b)
                .map(|(a, b)| a.iter().sum::<f32>() - b.iter().sum::<f32>()),
        );
        pruned.wake_all(NextTick::EVERY_SAMPLE);
        assert_eq!(pruned.num_dormant(), 0);
        assert_eq!(pruned.num_active(), n);
        assert_eq!(pruned.num_woken(), n as u64 / 2 + 1);
        let mut strike = vec![0.0; 64];
        strike[0] = 0.7;
        strike[1] = -0.2;
        // Back onto the control grid, which fades started by the strike do not keep to.
        let first = |bank: &mut ResonatorBank| {
            let mut acc = [[0.0; COLUMNS]; 41];
            bank.process(Kernel::Scalar, Some(&strike[..41]), &mut acc);
            bank.finish_fades();
            let mut out: Vec<f32> = acc.iter().map(|a| a.iter().sum::<f32>()).collect();
            out.extend(run(bank, 1024, None));
            out
        };
        let x = first(&mut pruned);
        let y = first(&mut reference);
        // Ghosts have joined their modes: the states are the reference's.
        assert_eq!(pruned.num_fading(), 0);
        assert_same_states(&pruned, &reference, n);
        // The woken modes took the strike at full gain from its first sample (it cancels in
        // the difference), and their old ringing comes back without a step: across the wake the
        // difference moves no more than it does from sample to sample before it.
        let after: Vec<f32> = x.iter().zip(&y).map(|(a, b)| a - b).collect();
        let typical = before
            .windows(2)
            .fold(0.0f32, |a, w| a.max((w[1] - w[0]).abs()));
        let across = (after[0] - before[before.len() - 1]).abs();
        assert!(
            across <= 1.5 * typical,
            "the difference steps by {across} at the wake, by at most {typical} before"
        );
        assert!(after[1000..].iter().all(|d| d.abs() < 1e-4));
    }
}

mod strike {
    use super::super::{Pulse, PulseShape};
    use super::*;
    use crate::dsp::masking::power_to_db;
    use crate::dsp::{Exciter, StrikeKind};
    use std::f64::consts::TAU;

    const RATE: f64 = 48_000.0;

    fn ringing(n: usize) -> ResonatorBank {
        let mut bank = ResonatorBank::new(n);
        for m in 0..n {
            bank.activate(m, coeffs(m), 0.0);
        }
        // Slow and fast decays, low and high modes (one near the pulse's own frequency).
        bank.set_poles_with(|m| {
            let f = 40.0 + 397.0 * m as f64;
            (TAU * f / RATE, (1.0 + 40.0 * (m % 3) as f64) / RATE)
        });
        bank.set_gains_with(|m| 0.5 / (1.0 + m as f32));
        let mut acc = vec![[0.0; COLUMNS]; 64];
        let mut x = vec![0.0; 64];
        x[0] = 1.0;
        bank.process(Kernel::Scalar, Some(&x), &mut acc);
        bank
    }

    fn gain(m: usize) -> f32 {
        0.8 - 0.03 * m as f32
    }

    /// A [`ringing`] bank of `n` modes with its odd modes switched off and faded out, and the same
    /// bank with every mode computed.
    fn half_dormant(n: usize) -> (ResonatorBank, ResonatorBank) {
        let mut pruned = ringing(n);
        let mut reference = pruned.clone();
        for m in (1..n).step_by(2) {
            pruned.switch_off(m, 64, 0, 0);
        }
        for bank in [&mut pruned, &mut reference] {
            let mut acc = vec![[0.0; COLUMNS]; 128];
            bank.process(Kernel::Scalar, None, &mut acc);
            bank.finish_fades();
        }
        assert_eq!(pruned.num_dormant(), n / 2);
        (pruned, reference)
    }

    /// Strikes both banks with `kind` over `len` samples, the pruned one with its odd modes
    /// dormant (taking the strike analytically), wakes everything `wake_after` samples into the
    /// pulse, and compares the states once the ghosts have joined.
    fn check(kind: StrikeKind, len: u32, wake_after: usize) {
        let n = 24;
        let (mut pruned, mut reference) = half_dormant(n);
        let mut exciter = Exciter::new(3);
        exciter.strike(kind, 0.7, len);
        let mut x = vec![0.0; 2048];
        exciter.render(&mut x);
        let shape = kind.pulse_shape().expect("a pulse known in advance");
        reference.set_gains_with(gain);
        pruned.set_gains_with(gain);
        pruned.absorb_strike(
            Pulse {
                shape,
                amplitude: 0.7,
                len,
            },
            true,
            NextTick::EVERY_SAMPLE,
            gain,
        );
        let mut pos = 0;
        for bank in [&mut pruned, &mut reference] {
            let mut acc = vec![[0.0; COLUMNS]; wake_after];
            bank.process(Kernel::Scalar, Some(&x[..wake_after]), &mut acc);
        }
        pos += wake_after;
        pruned.wake_all(NextTick::EVERY_SAMPLE);
        // On in control periods, ending fades as the engine does.
        for bank in [&mut pruned, &mut reference] {
            for chunk in x[pos..].chunks(64) {
                let mut acc = vec![[0.0; COLUMNS]; chunk.len()];
                bank.process(Kernel::Scalar, Some(chunk), &mut acc);
                bank.finish_fades();
            }
        }
        let what = format!("{kind:?} over {len}, woken after {wake_after}");
        assert_woken_as_computed(&pruned, &reference, n, &what);
    }

    /// Every one of the `n` modes of `pruned`, woken and with its ghost joined, is where
    /// `reference` (computed throughout) leaves it.
    fn assert_woken_as_computed(
        pruned: &ResonatorBank,
        reference: &ResonatorBank,
        n: usize,
        what: &str,
    ) {
        assert_eq!(pruned.num_fading(), 0, "{what}: still fading");
        for m in 0..n {
            let (a, b) = (pruned.state(m).unwrap(), reference.state(m).unwrap());
            let scale = b.0.hypot(b.1).max(1e-3);
            assert!(
                (a.0 - b.0).abs() < 2e-4 * scale && (a.1 - b.1).abs() < 2e-4 * scale,
                "{what}: mode {m}: {a:?} vs {b:?}"
            );
        }
    }

    #[test]
    fn dormant_modes_take_an_impulse_analytically() {
        check(StrikeKind::Impulse, 1, 64);
    }

    #[test]
    fn dormant_modes_take_a_mallet_analytically() {
        for len in [2, 15, 121, 600] {
            check(StrikeKind::Mallet, len, 700);
        }
    }

    #[test]
    fn a_mode_woken_during_a_pulse_it_took_gets_only_what_was_played() {
        for (len, after) in [(15, 7), (600, 64), (600, 599)] {
            check(StrikeKind::Mallet, len, after);
        }
    }

    /// A dormant mode takes a pulse with its own pole's response, whatever it took before: struck,
    /// retuned and struck with the same mallet again (the response kept from the first strike no
    /// longer holds), then struck once more at the new pitch (it does), its state is where
    /// computing it all along leaves it.
    #[test]
    fn a_retuned_dormant_mode_takes_the_next_strike_with_its_new_pole() {
        let (n, len) = (24, 15);
        let (mut pruned, mut reference) = half_dormant(n);
        for bank in [&mut pruned, &mut reference] {
            bank.set_gains_with(gain);
        }
        let mut exciter = Exciter::new(3);
        for pitch in [1.0, 1.5, 1.5] {
            for bank in [&mut pruned, &mut reference] {
                bank.set_poles_with(|m| {
                    let f = pitch * (40.0 + 397.0 * m as f64);
                    (TAU * f / RATE, (1.0 + 40.0 * (m % 3) as f64) / RATE)
                });
            }
            pruned.absorb_strike(mallet(0.7, len), true, NextTick::EVERY_SAMPLE, gain);
            exciter.strike(StrikeKind::Mallet, 0.7, len);
            let mut x = vec![0.0; 320];
            exciter.render(&mut x);
            for bank in [&mut pruned, &mut reference] {
                let mut acc = vec![[0.0; COLUMNS]; x.len()];
                bank.process(Kernel::Scalar, Some(&x), &mut acc);
            }
        }
        assert_eq!(pruned.num_dormant(), n / 2);
        pruned.wake_all(NextTick::EVERY_SAMPLE);
        for bank in [&mut pruned, &mut reference] {
            for _ in 0..32 {
                let mut acc = vec![[0.0; COLUMNS]; 64];
                bank.process(Kernel::Scalar, None, &mut acc);
                bank.finish_fades();
            }
        }
        assert_woken_as_computed(&pruned, &reference, n, "after the retune");
    }

    /// A pulse of `len` samples of amplitude `amplitude`, as the exciter's mallet.
    fn mallet(amplitude: f32, len: u32) -> Pulse {
        Pulse {
            shape: PulseShape::Mallet,
            amplitude,
            len,
        }
    }

    /// A second strike `t2` samples into a first, with gains of its own (the computed modes'
    /// change at once, for what is left of the first pulse too), starting a mode from rest: the
    /// dormant modes and the one started dormant are where computing them all along leaves them
    /// as their ghosts join them, whether woken during both pulses or after. Every fourth mode
    /// decays by 36 nepers over the first pulse, too fast to take it analytically.
    fn check_overlap(t2: usize, wake_at: usize) {
        let n = 24;
        let pole = |m: usize| {
            let f = 40.0 + 397.0 * m as f64;
            let delta = if m % 4 == 3 {
                0.06
            } else {
                (1.0 + 40.0 * (m % 3) as f64) / RATE
            };
            (TAU * f / RATE, delta)
        };
        let gain2 = |m: usize| 0.3 + 0.05 * (m % 5) as f32;
        // Mode `n` is dead until the second strike starts it.
        let mut reference = ResonatorBank::new(n + 1);
        for m in 0..n {
            reference.activate(m, coeffs(m), 0.0);
        }
        reference.set_poles_with(pole);
        reference.set_gains_with(gain);
        let mut pruned = reference.clone();
        for m in (1..n).step_by(2) {
            pruned.switch_off(m, 64, 0, 0);
        }
        for bank in [&mut pruned, &mut reference] {
            let mut acc = vec![[0.0; COLUMNS]; 128];
            bank.process(Kernel::Scalar, None, &mut acc);
            bank.finish_fades();
        }
        assert_eq!(pruned.num_dormant(), n / 2);
        let (first, second) = (mallet(0.7, 600), mallet(0.4, 300));
        pruned.absorb_strike(first, true, NextTick::EVERY_SAMPLE, gain);
        let mut exciter = Exciter::new(3);
        exciter.strike(StrikeKind::Mallet, first.amplitude, first.len);
        let mut x = vec![0.0; 2048];
        exciter.render(&mut x[..t2]);
        exciter.strike(StrikeKind::Mallet, second.amplitude, second.len);
        exciter.render(&mut x[t2..]);
        let mut pos = 0;
        let go = |bank: &mut ResonatorBank, from: usize, to: usize| {
            for chunk in x[from..to].chunks(64) {
                let mut acc = vec![[0.0; COLUMNS]; chunk.len()];
                bank.process(Kernel::Scalar, Some(chunk), &mut acc);
                bank.finish_fades();
            }
        };
        for bank in [&mut pruned, &mut reference] {
            go(bank, pos, t2);
        }
        pos = t2;
        reference.activate(n, coeffs(n), 0.0);
        pruned.start_dormant(n, 64);
        for bank in [&mut pruned, &mut reference] {
            bank.set_gains_with(gain2);
            bank.set_poles_with(pole);
        }
        pruned.absorb_strike(second, true, NextTick::EVERY_SAMPLE, gain2);
        for bank in [&mut pruned, &mut reference] {
            go(bank, pos, wake_at);
        }
        pos = wake_at;
        pruned.wake_all(NextTick::EVERY_SAMPLE);
        while pruned.num_fading() > 0 {
            for bank in [&mut pruned, &mut reference] {
                go(bank, pos, pos + 64);
            }
            pos += 64;
        }
        for m in 0..=n {
            let (a, b) = (pruned.state(m).unwrap(), reference.state(m).unwrap());
            let scale = b.0.hypot(b.1).max(1e-3);
            assert!(
                (a.0 - b.0).abs() < 2e-4 * scale && (a.1 - b.1).abs() < 2e-4 * scale,
                "second strike at {t2}, woken at {wake_at}, joined at {pos}: mode {m}: {a:?} vs \
                 {b:?}"
            );
        }
    }

    #[test]
    fn a_mode_still_fading_out_is_left_to_its_fade_by_strikes_and_scans() {
        let mut bank = sounding(4);
        let mut x = vec![0.0; 64];
        x[0] = 0.1;
        bank.process(Kernel::Scalar, Some(&x), &mut vec![[0.0; COLUMNS]; 64]);
        // Mode 0's fade is over after 128 samples; mode 1's is not.
        bank.switch_off(0, 64, 0, 0);
        bank.switch_off(1, 1024, 0, 0);
        bank.process(Kernel::Scalar, None, &mut vec![[0.0; COLUMNS]; 128]);
        bank.finish_fades();
        let mut listed = Vec::new();
        bank.for_each_dormant(u64::MAX, |d| listed.push(d.mode));
        assert_eq!(listed, [0], "only mode 0 is dormant");
        // The engine wakes fading modes before a strike; if one is not, it is still left alone.
        let pulse = Pulse {
            shape: PulseShape::Impulse,
            amplitude: 0.1,
            len: 1,
        };
        assert_eq!(
            bank.absorb_strike(pulse, true, NextTick::EVERY_SAMPLE, |_| 1.0),
            1,
            "absorbed"
        );
    }

    #[test]
    fn overlapping_strikes_with_new_gains_leave_dormant_modes_where_computing_would() {
        // Woken during both pulses, during the first's end, and after both.
        for (t2, wake_at) in [(200, 300), (200, 580), (100, 1200)] {
            check_overlap(t2, wake_at);
        }
    }

    #[test]
    fn a_dormant_mode_reads_no_louder_than_a_pulse_under_way_can_make_it() {
        // Mode 0, at 30 Hz, decays 5 nepers over the 12.5 ms mallet: referred back to the strike,
        // the pulse is some 25 dB louder than anything it can make the mode. Until the pulse
        // ends it reads its amplitude before plus the pulse's; from then on, its true level.
        let pole = |m: usize| (TAU * [30.0, 900.0][m] / RATE, [5.0 / 600.0, 1e-4][m]);
        let mut reference = ResonatorBank::new(2);
        for m in 0..2 {
            reference.activate(m, coeffs(m), 0.0);
        }
        reference.set_poles_with(pole);
        reference.set_gains_with(|_| 0.5);
        let mut x = vec![0.0; 64];
        x[0] = 0.01;
        let mut acc = vec![[0.0; COLUMNS]; 64];
        reference.process(Kernel::Scalar, Some(&x), &mut acc);
        let mut pruned = reference.clone();
        for m in 0..2 {
            pruned.switch_off(m, 64, 0, 0);
        }
        for bank in [&mut pruned, &mut reference] {
            let mut acc = vec![[0.0; COLUMNS]; 128];
            bank.process(Kernel::Scalar, None, &mut acc);
            bank.finish_fades();
        }
        let level = |bank: &mut ResonatorBank| {
            let mut level = f32::NAN;
            bank.for_each_dormant(u64::MAX, |d| {
                if d.mode == 0 {
                    level = d.level_db;
                }
            });
            level
        };
        let before = reference.state(0).unwrap();
        let pulse = mallet(0.7, 600);
        assert_eq!(
            pruned.absorb_strike(pulse, true, NextTick::EVERY_SAMPLE, |_| 0.5),
            2
        );
        let bound = before.0.hypot(before.1) + 0.5 * pulse.amplitude;
        let read = level(&mut pruned);
        assert!(
            read <= power_to_db(bound * bound) + 0.01,
            "{read} dB over the bound {} dB",
            power_to_db(bound * bound)
        );
        let mut exciter = Exciter::new(3);
        exciter.strike(StrikeKind::Mallet, pulse.amplitude, pulse.len);
        let mut x = vec![0.0; 640];
        exciter.render(&mut x);
        for bank in [&mut pruned, &mut reference] {
            bank.set_gains_with(|_| 0.5);
            for chunk in x.chunks(64) {
                let mut acc = vec![[0.0; COLUMNS]; chunk.len()];
                bank.process(Kernel::Scalar, Some(chunk), &mut acc);
            }
        }
        let (re, im) = reference.state(0).unwrap();
        let truth = power_to_db(re * re + im * im);
        let read = level(&mut pruned);
        assert!((read - truth).abs() < 0.05, "{read} dB against {truth} dB");
    }

    #[test]
    fn through_overlapping_pulses_a_dormant_mode_reads_no_quieter_than_it_is() {
        // The 30 Hz mode rings loud, then takes two 600-sample mallets 300 samples apart, the
        // second at the opposite gain: what is left of the first then works against its
        // ringing. Until the pulses end it reads at least its true level, and the pruner looks
        // at it again when they end, whatever time it asks for.
        let pole = |_| (TAU * 30.0 / RATE, 5.0 / 600.0);
        let mut reference = ResonatorBank::new(1);
        reference.activate(0, coeffs(0), 0.0);
        reference.set_poles_with(pole);
        reference.set_gains_with(|_| 1.0);
        let mut x = vec![0.0; 64];
        x[0] = 0.5;
        let mut acc = vec![[0.0; COLUMNS]; 64];
        reference.process(Kernel::Scalar, Some(&x), &mut acc);
        let mut pruned = reference.clone();
        pruned.switch_off(0, 64, 0, 0);
        let mut exciter = Exciter::new(3);
        let mut x = vec![0.0; 1024];
        let (first, second) = (mallet(0.7, 600), mallet(0.7, 600));
        let mut at = 0;
        for bank in [&mut pruned, &mut reference] {
            let mut acc = vec![[0.0; COLUMNS]; 64];
            bank.process(Kernel::Scalar, None, &mut acc);
            bank.finish_fades();
        }
        let mut lowest_margin = f32::INFINITY;
        for step in 0..16 {
            if step == 0 || step == 5 {
                let (pulse, gain) = if step == 0 {
                    (first, 0.5)
                } else {
                    (second, -0.5)
                };
                exciter.strike(StrikeKind::Mallet, pulse.amplitude, pulse.len);
                reference.set_gains_with(|_| gain);
                assert_eq!(
                    pruned.absorb_strike(pulse, true, NextTick::EVERY_SAMPLE, |_| gain),
                    1
                );
                pruned.set_recheck(0, u64::MAX / 2, 0);
                let mut due = false;
                pruned.for_each_dormant(pruned.clock() + 900, |_| due = true);
                assert!(due, "not looked at when its pulses end");
            }
            let (mut read, mut acc) = (f32::NAN, vec![[0.0; COLUMNS]; 60]);
            pruned.for_each_dormant(u64::MAX, |d| read = d.level_db);
            let (re, im) = reference.state(0).unwrap();
            lowest_margin = lowest_margin.min(read - power_to_db(re * re + im * im));
            exciter.render(&mut x[at..at + 60]);
            reference.process(Kernel::Scalar, Some(&x[at..at + 60]), &mut acc);
            pruned.process(Kernel::Scalar, None, &mut acc);
            at += 60;
        }
        assert!(
            lowest_margin > -0.01,
            "reads {lowest_margin} dB under the truth"
        );
    }
}

#[test]
fn fades_started_between_ticks_are_lengthened_to_end_on_one() {
    let tick = NextTick {
        in_samples: 10,
        period: 64,
    };
    assert_eq!(tick.fade_len(256), 266);
    assert_eq!(tick.fade_len(250), 266);
    assert_eq!(tick.fade_len(266), 266);
    assert_eq!(tick.fade_len(267), 330);
    let on_a_tick = NextTick {
        in_samples: 0,
        period: 64,
    };
    assert_eq!(on_a_tick.fade_len(256), 256);
    assert_eq!(NextTick::EVERY_SAMPLE.fade_len(37), 37);
}
