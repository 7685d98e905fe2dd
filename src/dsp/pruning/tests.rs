//! The masking pass against the seed's pairwise algorithm, and its verdicts at chosen points.

use super::*;
use crate::dsp::masking::{masking_curve_db, masking_threshold_db};
use crate::rng::Rng;

/// The seed's pseudo-code, literally: every pair, `O(N^2)`.
fn reference(level: &[f32], bark: &[f32], threshold: &[f32], av: f32) -> Vec<bool> {
    let n = level.len();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| level[b].total_cmp(&level[a]));
    let mut on = vec![false; n];
    let mut masker = vec![false; n];
    for (rank, &i) in order.iter().enumerate() {
        on[i] = rank == 0 || level[i] > threshold[i];
        masker[i] = on[i];
    }
    for a in 0..n {
        let i = order[a];
        if !masker[i] {
            continue;
        }
        for &k in &order[a + 1..] {
            if !on[k] {
                continue;
            }
            let th = masking_threshold_db(bark[i], level[i], av, bark[k], threshold[k]);
            if level[k] < th {
                on[k] = false;
                masker[k] = false;
            } else if level[k] < th + av {
                masker[k] = false;
            }
        }
    }
    on
}

fn random_scene(n: usize, seed: u32) -> (Vec<f32>, Vec<f32>, Vec<f32>) {
    let mut rng = Rng::new(seed);
    let mut rnd = move || rng.next_u32() as f32 / u32::MAX as f32;
    let level: Vec<f32> = (0..n).map(|_| 90.0 * rnd()).collect();
    let bark: Vec<f32> = (0..n).map(|_| 24.0 * rnd()).collect();
    let threshold: Vec<f32> = (0..n).map(|_| 10.0 * rnd()).collect();
    (level, bark, threshold)
}

#[test]
fn the_pass_agrees_with_the_seeds_pairwise_algorithm() {
    for (n, seed, av) in [(50, 1, 5.0), (700, 2, 2.5), (2000, 3, 10.0), (300, 4, 0.0)] {
        let (level, bark, threshold) = random_scene(n, seed);
        let mut pass = MaskingPass::with_capacity(n);
        let mut verdicts = vec![Verdict::Inaudible; n];
        pass.run(&level, &bark, &threshold, av, &mut verdicts);
        let want = reference(&level, &bark, &threshold, av);
        for i in 0..n {
            assert_eq!(
                verdicts[i].is_audible(),
                want[i],
                "n {n}, a_v {av}: candidate {i} ({} dB at {} Bark): {:?}",
                level[i],
                bark[i],
                verdicts[i]
            );
        }
        // Roughly 2 sqrt(N) maskers (seed 001, footnote 1): far fewer than N.
        assert!(pass.num_maskers() < n / 2, "{} maskers", pass.num_maskers());
    }
}

#[test]
fn a_loud_mode_masks_a_quiet_neighbour_and_not_a_distant_one() {
    // 70 dB at 10 Bark (upper slope 22 - 70 / 5 = 8 dB per Bark); 40 dB at 10.5 Bark (curve
    // 65 - 8 * 0.5 = 61 dB there: masked);
    // 40 dB at 16 Bark (curve 65 - 8 * 6 = 17 dB: heard).
    let level = [70.0, 40.0, 40.0];
    let bark = [10.0, 10.5, 16.0];
    let threshold = [3.0; 3];
    let mut pass = MaskingPass::with_capacity(3);
    let mut v = [Verdict::Inaudible; 3];
    pass.run(&level, &bark, &threshold, 5.0, &mut v);
    assert_eq!(v[0], Verdict::Audible { masker: true });
    assert_eq!(v[1], Verdict::Masked { by: 0 });
    assert!(v[2].is_audible(), "{:?}", v[2]);
    assert!(masking_curve_db(10.0, 70.0, 5.0, 10.5) > 40.0);
}

#[test]
fn a_quiet_isolated_mode_above_the_threshold_is_kept_and_one_below_is_not() {
    let level = [20.0, 8.0, 2.0];
    let bark = [5.0, 20.0, 22.0];
    let threshold = [5.0, 6.0, 9.0];
    let mut pass = MaskingPass::with_capacity(3);
    let mut v = [Verdict::Inaudible; 3];
    pass.run(&level, &bark, &threshold, 5.0, &mut v);
    assert!(v[0].is_audible() && v[1].is_audible());
    assert_eq!(v[2], Verdict::Inaudible);
}

#[test]
fn the_loudest_mode_is_never_removed() {
    // Even below the threshold of hearing.
    let mut pass = MaskingPass::with_capacity(4);
    let mut v = [Verdict::Inaudible; 3];
    pass.run(
        &[-10.0, -20.0, -30.0],
        &[1.0, 2.0, 3.0],
        &[20.0; 3],
        5.0,
        &mut v,
    );
    assert_eq!(v[0], Verdict::Audible { masker: true });
    assert_eq!(&v[1..], &[Verdict::Inaudible; 2]);
    // And among random scenes at every offset.
    for seed in 1..20 {
        let (level, bark, threshold) = random_scene(200, seed);
        let loudest = (0..200)
            .max_by(|&a, &b| level[a].total_cmp(&level[b]))
            .unwrap();
        let mut verdicts = vec![Verdict::Inaudible; 200];
        let mut pass = MaskingPass::with_capacity(200);
        pass.run(&level, &bark, &threshold, 0.0, &mut verdicts);
        assert!(verdicts[loudest].is_audible(), "seed {seed}");
    }
}

#[test]
fn a_larger_offset_prunes_less() {
    let (level, bark, threshold) = random_scene(1000, 9);
    let mut pass = MaskingPass::with_capacity(1000);
    let mut verdicts = vec![Verdict::Inaudible; 1000];
    let mut kept = Vec::new();
    for av in [0.0, 2.5, 5.0, 10.0, 20.0] {
        pass.run(&level, &bark, &threshold, av, &mut verdicts);
        kept.push(verdicts.iter().filter(|v| v.is_audible()).count());
    }
    assert!(kept.windows(2).all(|w| w[0] <= w[1]), "{kept:?}");
}

#[test]
fn the_budget_keeps_the_most_energetic() {
    let mut ranked: Vec<(f32, u32)> = (0..100)
        .map(|i| (((i * 37) % 100) as f32, i as u32))
        .collect();
    keep_most_energetic(&mut ranked, 10);
    let mut top: Vec<f32> = ranked[..10].iter().map(|r| r.0).collect();
    top.sort_by(f32::total_cmp);
    assert_eq!(top, (90..100).map(|e| e as f32).collect::<Vec<_>>());
}

#[test]
fn a_masked_mode_names_the_loudest_masker_whose_curve_covers_it() {
    // Twenty maskers, 2 Bark apart from 1 Bark, falling 1 dB each from 80 dB: more than two
    // chunks of eight lanes. Probes at 30 dB, far below every curve within reach and beside one masker
    // each: the masker named is the loudest whose curve lies above the probe, which the
    // pairwise check finds too, whatever lane it sits in.
    let n_maskers = 20;
    let mut level: Vec<f32> = (0..n_maskers).map(|j| 80.0 - j as f32).collect();
    let mut bark: Vec<f32> = (0..n_maskers).map(|j| 1.0 + 2.0 * j as f32).collect();
    let probes = [0usize, 7, 8, 9, 15, 19];
    for &j in &probes {
        level.push(30.0);
        bark.push(bark[j] + 0.3);
    }
    let n = level.len();
    let threshold = vec![0.0; n];
    let mut pass = MaskingPass::with_capacity(n);
    let mut v = vec![Verdict::Inaudible; n];
    let av = 5.0;
    pass.run(&level, &bark, &threshold, av, &mut v);
    for (p, &j) in probes.iter().enumerate() {
        let i = n_maskers + p;
        let expected = (0..n_maskers)
            .find(|&k| masking_curve_db(bark[k], level[k], av, bark[i]) > level[i])
            .unwrap();
        assert_eq!(
            v[i],
            Verdict::Masked {
                by: expected as u32
            },
            "probe beside {j}"
        );
    }
}

/// The portable pass, and the AVX2 one where the CPU has it.
fn both_paths(capacity: usize) -> Vec<MaskingPass> {
    let mut portable = MaskingPass::with_capacity(capacity);
    portable.avx2 = false;
    let native = MaskingPass::with_capacity(capacity);
    let mut passes = vec![portable];
    if native.avx2 {
        passes.push(native);
    }
    passes
}

#[test]
fn maskers_of_an_earlier_pass_mask_nothing_in_the_next() {
    // Eight 90 dB maskers, 2 Bark apart from 1 to 15 Bark, fill a whole group of lanes.
    let loud_bark: Vec<f32> = (0..8).map(|k| 1.0 + 2.0 * k as f32).collect();
    // Then a 70 dB mode at 22 Bark and a 40 dB one at 5.2 Bark, which the old masker at 5 Bark
    // would cover (85 - 4 * 0.2 dB) and the new one does not (it is 16.8 Bark above it).
    let (level, bark) = ([70.0, 40.0], [22.0, 5.2]);
    for mut pass in both_paths(16) {
        let mut v = vec![Verdict::Inaudible; 8];
        pass.run(&[90.0; 8], &loud_bark, &[3.0; 8], 5.0, &mut v);
        assert_eq!(pass.num_maskers(), 8, "{v:?}");
        let mut v = [Verdict::Inaudible; 2];
        pass.run(&level, &bark, &[3.0; 2], 5.0, &mut v);
        assert_eq!(
            v,
            [Verdict::Audible { masker: true }; 2],
            "avx2 {}",
            pass.avx2
        );
    }
}

#[test]
fn a_masker_or_a_mode_that_is_not_a_number_changes_no_other_verdict() {
    // The neighbours of `a_loud_mode_masks_a_quiet_neighbour_and_not_a_distant_one`, with prior
    // maskers of no level and of no critical-band rate, and a candidate of no level.
    let level = [70.0, 40.0, 40.0, f32::NAN];
    let bark = [10.0, 10.5, 16.0, 16.1];
    for mut pass in both_paths(8) {
        let mut v = [Verdict::Inaudible; 4];
        pass.run_after(
            &[16.0, f32::NAN],
            &[f32::NAN, 90.0],
            &level,
            &bark,
            &[3.0; 4],
            5.0,
            &mut v,
            None,
        );
        let avx2 = pass.avx2;
        assert_eq!(v[0], Verdict::Audible { masker: true }, "avx2 {avx2}");
        assert_eq!(v[1], Verdict::Masked { by: 0 }, "avx2 {avx2}");
        assert!(v[2].is_audible(), "avx2 {avx2}: {:?}", v[2]);
        assert_eq!(v[3], Verdict::Inaudible, "avx2 {avx2}");
        // Nor does a prior masker of no critical-band rate take the loudest candidate's place:
        // the loudest mode is kept even below the threshold of hearing.
        let mut v = [Verdict::Inaudible; 1];
        let (prior_bark, prior_level) = ([f32::NAN], [90.0]);
        let (quiet_level, quiet_bark, threshold) = ([1.0], [10.0], [3.0]);
        pass.run_after(
            &prior_bark,
            &prior_level,
            &quiet_level,
            &quiet_bark,
            &threshold,
            5.0,
            &mut v,
            None,
        );
        assert_eq!(v[0], Verdict::Audible { masker: true }, "avx2 {avx2}");
    }
}

#[test]
fn both_paths_give_the_same_verdicts_maskers_and_envelopes() {
    // Three hundred modes spread over the Bark scale at scattered levels, after forty prior
    // maskers: many maskers per lane group, so a masked mode's masker is often past the first.
    let n = 300;
    let mut rng = Rng::new(0x2545_f491);
    let mut next = move || rng.next_u32() as f32 / u32::MAX as f32;
    let prior_bark: Vec<f32> = (0..40).map(|_| 24.0 * next()).collect();
    let prior_level: Vec<f32> = (0..40).map(|_| 30.0 + 60.0 * next()).collect();
    let bark: Vec<f32> = (0..n).map(|_| 24.0 * next()).collect();
    let level: Vec<f32> = (0..n).map(|_| 100.0 * next()).collect();
    let threshold = vec![10.0; n];
    let mut results = Vec::new();
    for mut pass in both_paths(n + 40) {
        let mut v = vec![Verdict::Inaudible; n];
        let mut envelope = vec![0.0; n];
        pass.run_after(
            &prior_bark,
            &prior_level,
            &level,
            &bark,
            &threshold,
            5.0,
            &mut v,
            Some(&mut envelope),
        );
        let masked = v
            .iter()
            .filter(|x| matches!(x, Verdict::Masked { .. }))
            .count();
        assert!(masked > n / 4, "{masked} masked");
        let by_later = v
            .iter()
            .filter(|x| matches!(x, Verdict::Masked { by } if by & !PRIOR >= 8))
            .count();
        assert!(by_later > 10, "{by_later} masked past the first lane group");
        results.push((v, envelope));
    }
    match &results[..] {
        [portable, native] => {
            assert_eq!(portable.0, native.0);
            // The envelope is written for every mode above the threshold of hearing.
            for i in 0..n {
                if portable.0[i] != Verdict::Inaudible {
                    assert_eq!(
                        portable.1[i].to_bits(),
                        native.1[i].to_bits(),
                        "envelope at {i}"
                    );
                }
            }
        }
        _ => eprintln!("no AVX2 on this CPU: only the portable path ran"),
    }
}
