//! Closed-form checks of the analytic shapes: textbook frequency ratios, absolute frequencies,
//! nodes, and the invariants every generated bank keeps.

use super::positions::position;
use super::*;
use crate::model::materials::{self, Material, MATERIALS};

fn steel() -> &'static Material {
    &materials::STEEL
}

fn on_line(xs: &[f64]) -> Vec<Position> {
    xs.iter()
        .map(|&x| position(&format!("x = {x}"), &[x]))
        .collect()
}

fn on_plane(points: &[[f64; 2]]) -> Vec<Position> {
    points
        .iter()
        .map(|p| position(&format!("{p:?}"), p))
        .collect()
}

fn freqs(modes: &[Mode]) -> Vec<f64> {
    modes.iter().map(|mode| mode.freq_hz).collect()
}

/// Asserts `got[i] / got[0]` against `want[i]` within `rel_tol`.
fn assert_ratios(what: &str, got: &[f64], want: &[f64], rel_tol: f64) {
    assert!(got.len() >= want.len(), "{what}: only {} modes", got.len());
    for (i, &ratio) in want.iter().enumerate() {
        let found = got[i] / got[0];
        assert!(
            (found / ratio - 1.0).abs() < rel_tol,
            "{what}: mode {i} ratio {found}, expected {ratio}"
        );
    }
}

fn glockenspiel_bar() -> Shape {
    Shape::FreeFreeBar(Bar {
        length_m: 0.3,
        width_m: 0.03,
        thickness_m: 0.01,
    })
}

fn membrane() -> Shape {
    Shape::CircularMembrane(CircularMembrane {
        radius_m: 0.15,
        thickness_m: 0.25e-3,
        tension_n_per_m: 1500.0,
    })
}

fn square_plate() -> Shape {
    Shape::RectangularPlate(RectangularPlate {
        length_x_m: 0.3,
        length_y_m: 0.3,
        thickness_m: 2e-3,
    })
}

fn piano_wire() -> StretchedString {
    StretchedString {
        length_m: 0.62,
        diameter_m: 1.0e-3,
        tension_n: 650.0,
    }
}

/// One of each kind of shape, with a material that suits it.
fn every_shape() -> Vec<(Shape, &'static Material)> {
    vec![
        (Shape::IdealString(piano_wire()), steel()),
        (Shape::StiffString(piano_wire()), steel()),
        (glockenspiel_bar(), steel()),
        (
            Shape::TunedBar(TunedBar {
                bar: Bar {
                    length_m: 0.38,
                    width_m: 0.06,
                    thickness_m: 0.009,
                },
                tuned_ratios: MARIMBA_RATIOS.to_vec(),
            }),
            &materials::ROSEWOOD,
        ),
        (membrane(), &materials::MYLAR),
        (square_plate(), steel()),
        (
            Shape::Bell(TunedBell {
                diameter_m: 0.6,
                thickness_m: 0.046,
            }),
            &materials::BRONZE,
        ),
    ]
}

#[test]
fn free_free_bar_ratios_match_the_textbook() {
    let modes = glockenspiel_bar()
        .modes(steel(), &on_line(&[0.1]), &ModeLimits::default())
        .unwrap();
    assert_ratios(
        "free-free bar",
        &freqs(&modes),
        &[1.0, 2.756, 5.404, 8.933],
        1e-3,
    );
}

#[test]
fn steel_bar_fundamental_matches_a_hand_calculation() {
    // Steel, E = 200 GPa, rho = 7850 kg/m^3; L = 0.3 m, h = 0.01 m.
    // sqrt(E / (12 rho)) = sqrt(200e9 / 94200) = 1457.10 m/s; times h: 14.5710 m/s.
    // (b1 L)^2 = 4.730041^2 = 22.37329; over 2 pi L^2 = 0.5654867 m^2: 39.56466 1/m^2.
    // f1 = 39.56466 * 14.5710 = 576.497 Hz.
    let modes = glockenspiel_bar()
        .modes(steel(), &on_line(&[0.0]), &ModeLimits::default())
        .unwrap();
    let f1 = modes[0].freq_hz;
    assert!((f1 - 576.497).abs() < 0.01, "f1 = {f1}");
    assert_eq!(glockenspiel_bar().root_hz(steel()), f1);
}

#[test]
fn circular_membrane_ratios_are_bessel_zero_ratios() {
    let modes = membrane()
        .modes(
            &materials::MYLAR,
            &on_line_2d(&[[0.5, 0.0]]),
            &ModeLimits::default(),
        )
        .unwrap();
    // j01, j11, j21, j02, j31, j12 over j01.
    assert_ratios(
        "membrane",
        &freqs(&modes),
        &[1.0, 1.594, 2.136, 2.296, 2.653, 2.918],
        1e-3,
    );
    assert_eq!(modes.len(), DEFAULT_MAX_MODES);
    // Absolute: f01 = j01 sqrt(T / (rho h)) / (2 pi a).
    let c = (1500.0f64 / (1390.0 * 0.25e-3)).sqrt();
    let f01 = 2.404_825_557_695_773 * c / (TAU * 0.15);
    assert!((modes[0].freq_hz / f01 - 1.0).abs() < 1e-12);
}

fn on_line_2d(points: &[[f64; 2]]) -> Vec<Position> {
    on_plane(points)
}

#[test]
fn membrane_adds_sine_twins_only_off_axis() {
    let limits = ModeLimits {
        max_freq_hz: MAX_AUDIBLE_HZ,
        max_modes: 40,
    };
    let on_axis = membrane()
        .modes(&materials::MYLAR, &on_plane(&[[0.5, 0.0]]), &limits)
        .unwrap();
    let off_axis = membrane()
        .modes(&materials::MYLAR, &on_plane(&[[0.3, 0.4]]), &limits)
        .unwrap();
    // Off the axis, (1,1) appears twice: f01, f11, f11, f21, f21, ...
    let f = freqs(&off_axis);
    assert_eq!(f[1], f[2]);
    assert_eq!(f[3], f[4]);
    assert!(f[0] < f[1] && f[2] < f[3]);
    assert_eq!(freqs(&on_axis)[1], f[1]);
    // The twins split the energy of the cos mode at that radius: cos^2 + sin^2 = 1.
    let on = membrane()
        .modes(
            &materials::MYLAR,
            &on_plane(&[[0.5, 0.0], [0.3, 0.4]]),
            &limits,
        )
        .unwrap();
    let (cos_twin, sin_twin) = (&on[1], &on[2]);
    let split = cos_twin.gains[1].hypot(sin_twin.gains[1]);
    assert!((split - cos_twin.gains[0].abs()).abs() < 1e-12);
}

#[test]
fn stiff_string_follows_the_inharmonicity_formula() {
    let wire = piano_wire();
    // By hand: mu = 7850 pi (0.5e-3)^2 = 6.1654e-3 kg/m, f0 = sqrt(650 / mu) / 1.24 = 261.85 Hz,
    // B = pi^3 200e9 (1e-3)^4 / (64 * 650 * 0.62^2) = 3.878e-4.
    let mu = 7850.0 * std::f64::consts::PI * 0.25e-6;
    let f0 = (650.0 / mu).sqrt() / (2.0 * 0.62);
    let b = std::f64::consts::PI.powi(3) * 200e9 * 1e-12 / (64.0 * 650.0 * 0.62 * 0.62);
    assert!((f0 - 261.85).abs() < 0.01, "f0 = {f0}");
    assert!((b - 3.878e-4).abs() < 1e-6, "B = {b}");
    let modes = Shape::StiffString(wire)
        .modes(steel(), &on_line(&[0.125]), &ModeLimits::default())
        .unwrap();
    for (i, mode) in modes.iter().enumerate() {
        let n = (i + 1) as f64;
        let want = n * f0 * (1.0 + b * n * n).sqrt();
        assert!(
            (mode.freq_hz / want - 1.0).abs() < 1e-12,
            "mode {n}: {} vs {want}",
            mode.freq_hz
        );
    }
    // Partials are stretched: the 20th is more than 7% sharp of 20 f1.
    assert!(modes[19].freq_hz / (20.0 * modes[0].freq_hz) > 1.07);
    // The last mode kept is the last below 20 kHz.
    let n_next = modes.len() as f64 + 1.0;
    assert!(n_next * f0 * (1.0 + b * n_next * n_next).sqrt() >= MAX_AUDIBLE_HZ);
}

#[test]
fn ideal_string_is_harmonic_with_struck_string_gains() {
    let x_p = 0.125;
    let modes = Shape::IdealString(piano_wire())
        .modes(steel(), &on_line(&[x_p]), &ModeLimits::default())
        .unwrap();
    let f1 = modes[0].freq_hz;
    let first = (std::f64::consts::PI * x_p).sin();
    for (i, mode) in modes.iter().enumerate() {
        let n = (i + 1) as f64;
        assert!((mode.freq_hz / (n * f1) - 1.0).abs() < 1e-12);
        // seed 000 eq. 3.11: Psi_n(p) / omega_n, relative to mode 1.
        let want = (n * std::f64::consts::PI * x_p).sin() / n / first;
        assert!(
            (mode.gains[0] - want).abs() < 1e-12,
            "mode {n}: {}",
            mode.gains[0]
        );
    }
}

#[test]
fn square_plate_ratios() {
    let modes = square_plate()
        .modes(steel(), &on_plane(&[[0.31, 0.23]]), &ModeLimits::default())
        .unwrap();
    // (m^2 + n^2) / 2: (1,1) 1, (1,2) (2,1) 2.5, (2,2) 4, (1,3) (3,1) 5, (2,3) (3,2) 6.5,
    // (1,4) (4,1) 8.5, (3,3) 9.
    assert_ratios(
        "square plate",
        &freqs(&modes),
        &[1.0, 2.5, 2.5, 4.0, 5.0, 5.0, 6.5, 6.5, 8.5, 8.5, 9.0],
        1e-12,
    );
    // Absolute: f11 = (pi / 2) sqrt(D / (rho h)) * 2 / a^2.
    let d: f64 = 200e9 * 8e-9 / (12.0 * (1.0 - 0.09));
    let f11 = std::f64::consts::FRAC_PI_2 * (d / (7850.0 * 2e-3)).sqrt() * 2.0 / 0.09;
    assert!((modes[0].freq_hz / f11 - 1.0).abs() < 1e-12);
}

#[test]
fn tuned_bar_keeps_its_tuning() {
    let (shape, rosewood) = &every_shape()[3];
    let modes = shape
        .modes(rosewood, &on_line(&[0.1]), &ModeLimits::default())
        .unwrap();
    let f = freqs(&modes);
    assert_ratios("marimba bar", &f, &MARIMBA_RATIOS, 1e-12);
    let b3 = bar::free_free_beta_l(3);
    let b4 = bar::free_free_beta_l(4);
    assert!((f[3] / f[0] - 10.0 * (b4 / b3).powi(2)).abs() < 1e-9);
}

#[test]
fn bell_partials_follow_the_table() {
    let (shape, bronze) = &every_shape()[6];
    let modes = shape
        .modes(bronze, &shape.default_positions(), &ModeLimits::default())
        .unwrap();
    let prime = shape.root_hz(bronze);
    assert_eq!(modes.len(), TUNED_BELL_PARTIALS.len());
    for (mode, partial) in modes.iter().zip(&TUNED_BELL_PARTIALS) {
        assert!(
            (mode.freq_hz / prime - partial.ratio).abs() < 1e-12,
            "{}",
            partial.name
        );
    }
    // Struck on the sound bow, the quint is silent (its nodal circle is there).
    let sound_bow = shape
        .default_positions()
        .iter()
        .position(|p| p.name == "sound bow")
        .unwrap();
    let quint = TUNED_BELL_PARTIALS
        .iter()
        .position(|p| p.name == "quint")
        .unwrap();
    assert_eq!(modes[quint].gains[sound_bow], 0.0);
    // The hum is an octave below the prime.
    assert!((modes[0].freq_hz * 2.0 / prime - 1.0).abs() < 1e-12);
}

#[test]
fn striking_a_node_silences_the_mode() {
    // A string struck at its middle has no even harmonics.
    let modes = Shape::IdealString(piano_wire())
        .modes(steel(), &on_line(&[0.5]), &ModeLimits::default())
        .unwrap();
    for (i, mode) in modes.iter().enumerate() {
        let n = i + 1;
        if n % 2 == 0 {
            assert_eq!(mode.gains[0], 0.0, "harmonic {n}");
        } else {
            assert!(mode.gains[0].abs() > 0.0, "harmonic {n}");
        }
    }
    // A free-free bar struck at its centre: the antisymmetric modes (2, 4, ...) are silent;
    // struck on the fundamental's node (0.2242 L), the fundamental nearly is.
    let modes = glockenspiel_bar()
        .modes(
            steel(),
            &on_line(&[0.5, 0.224_2, 0.0]),
            &ModeLimits::default(),
        )
        .unwrap();
    assert_eq!(modes[1].gains[0], 0.0);
    assert_eq!(modes[3].gains[0], 0.0);
    assert!(modes[0].gains[1].abs() < 2e-3 * modes[0].gains[2].abs());
    // A drum struck at its centre sounds only the axisymmetric modes: 1, 4 (j02), 9 (j03) ...
    let modes = membrane()
        .modes(
            &materials::MYLAR,
            &on_plane(&[[0.0, 0.0]]),
            &ModeLimits::default(),
        )
        .unwrap();
    assert!(modes[0].gains[0] > 0.0);
    assert_eq!(modes[1].gains[0], 0.0);
    assert_eq!(modes[2].gains[0], 0.0);
    assert!(modes[3].gains[0].abs() > 0.0);
    // A plate struck at its centre: every mode with an even index is silent.
    let modes = square_plate()
        .modes(steel(), &on_plane(&[[0.5, 0.5]]), &ModeLimits::default())
        .unwrap();
    assert!(modes[0].gains[0] > 0.0);
    assert_eq!(modes[1].gains[0], 0.0);
    assert_eq!(modes[2].gains[0], 0.0);
    assert_eq!(modes[3].gains[0], 0.0);
    assert!(modes[4].gains[0].abs() > 0.0); // (1,3)
}

#[test]
fn every_shape_gives_a_sane_bank() {
    for (shape, material) in every_shape() {
        let positions = shape.default_positions();
        assert!(positions.len() >= 3, "{}", shape.kind());
        assert!(positions
            .iter()
            .all(|p| p.coords.len() == shape.num_coords()));
        let bank = build_bank(
            "test",
            "",
            &shape,
            material,
            &positions,
            &ModeLimits::default(),
        )
        .unwrap_or_else(|e| panic!("{}: {e}", shape.kind()));
        let what = shape.kind();
        assert!(!bank.modes.is_empty() && bank.modes.len() <= DEFAULT_MAX_MODES);
        assert!(bank
            .description
            .contains(material.display_name.to_lowercase().as_str()));
        let mut peak = 0.0f64;
        for (i, mode) in bank.modes.iter().enumerate() {
            assert!(
                mode.freq_hz.is_finite() && mode.freq_hz > 0.0,
                "{what} mode {i}"
            );
            assert!(
                mode.freq_hz < MAX_AUDIBLE_HZ,
                "{what} mode {i}: {}",
                mode.freq_hz
            );
            assert!(mode.decay_per_s.is_finite() && mode.decay_per_s > 0.0);
            let want_decay = std::f64::consts::PI * mode.freq_hz * material.loss_factor
                + materials::AIR_DAMPING_PER_S;
            assert!((mode.decay_per_s - want_decay).abs() < 1e-12);
            assert_eq!(mode.gains.len(), positions.len());
            for gain in &mode.gains {
                assert!(gain.is_finite(), "{what} mode {i}");
                peak = peak.max(gain.abs());
            }
            if i > 0 {
                assert!(
                    mode.freq_hz >= bank.modes[i - 1].freq_hz,
                    "{what}: not ascending at {i}"
                );
            }
        }
        assert!((peak - 1.0).abs() < 1e-12, "{what}: peak gain {peak}");
        assert_eq!(bank.root_hz, Some(shape.root_hz(material)));
        let source = bank.source.as_ref().unwrap();
        assert_eq!(source["kind"], "analytic");
        assert_eq!(source["shape"], shape.kind());
        assert_eq!(source["material"], material.name);
        let defaults = bank.defaults.as_ref().unwrap();
        // Played at the first position by default: the one nearest the typical strike.
        assert_eq!(defaults.strike_position, None);
        let typical = shape.typical_strike();
        let distance = |p: &Position| -> f64 {
            p.coords
                .iter()
                .zip(&typical)
                .map(|(a, b)| (a - b).powi(2))
                .sum()
        };
        let first = distance(&bank.positions[0]);
        assert!(
            bank.positions.iter().all(|p| distance(p) >= first),
            "{what}: first position is not the typical strike"
        );
        assert!(defaults.hardness_ms.unwrap() > 0.0);
        assert_eq!(defaults.material_q, None);
    }
}

#[test]
fn tuning_hits_the_requested_pitch() {
    for (shape, material) in every_shape() {
        for target_hz in [98.0, 261.625_565_300_598_6, 1046.5] {
            let tuned = shape.tuned_to(material, target_hz).unwrap();
            let got = tuned.root_hz(material);
            assert!(
                (got / target_hz - 1.0).abs() < 1e-12,
                "{}: {got} Hz for {target_hz} Hz",
                shape.kind()
            );
            assert_eq!(tuned.kind(), shape.kind());
        }
    }
    // A wire too stiff for its pitch cannot be tuned by tension.
    let stubborn = Shape::StiffString(StretchedString {
        length_m: 0.05,
        diameter_m: 3e-3,
        tension_n: 100.0,
    });
    assert!(matches!(
        stubborn.tuned_to(steel(), 50.0),
        Err(ShapeError::CannotTune { .. })
    ));
}

#[test]
fn limits_cap_frequency_and_count() {
    let limits = ModeLimits {
        max_freq_hz: 5000.0,
        max_modes: 12,
    };
    for (shape, material) in every_shape() {
        let modes = shape
            .modes(material, &shape.default_positions(), &limits)
            .unwrap();
        assert!(modes.len() <= 12, "{}", shape.kind());
        assert!(modes.iter().all(|m| m.freq_hz < 5000.0), "{}", shape.kind());
    }
    // The lowest modes are the ones kept: the first 12 of the full list.
    let all = square_plate()
        .modes(steel(), &on_plane(&[[0.3, 0.2]]), &ModeLimits::default())
        .unwrap();
    let few = square_plate()
        .modes(
            steel(),
            &on_plane(&[[0.3, 0.2]]),
            &ModeLimits {
                max_freq_hz: MAX_AUDIBLE_HZ,
                max_modes: 12,
            },
        )
        .unwrap();
    assert_eq!(freqs(&few), freqs(&all)[..12]);
    let too_low = ModeLimits {
        max_freq_hz: 10.0,
        max_modes: 10,
    };
    assert!(matches!(
        glockenspiel_bar().modes(steel(), &on_line(&[0.1]), &too_low),
        Err(ShapeError::NoModes { .. })
    ));
}

#[test]
fn bad_input_is_reported() {
    let bar = glockenspiel_bar();
    let err = bar
        .modes(steel(), &on_plane(&[[0.1, 0.2]]), &ModeLimits::default())
        .unwrap_err();
    assert!(
        matches!(err, ShapeError::BadPosition { index: 0, .. }),
        "{err}"
    );
    let err = bar
        .modes(steel(), &on_line(&[0.2, 1.5]), &ModeLimits::default())
        .unwrap_err();
    assert!(err.to_string().starts_with("positions[1]"), "{err}");
    let err = membrane()
        .modes(
            &materials::MYLAR,
            &on_plane(&[[0.8, 0.8]]),
            &ModeLimits::default(),
        )
        .unwrap_err();
    assert!(matches!(err, ShapeError::BadPosition { .. }), "{err}");
    let flat = Shape::FreeFreeBar(Bar {
        length_m: 0.3,
        width_m: 0.03,
        thickness_m: 0.0,
    });
    let err = flat
        .modes(steel(), &on_line(&[0.1]), &ModeLimits::default())
        .unwrap_err();
    assert_eq!(
        err.to_string(),
        "thickness_m = 0: expected a positive finite number"
    );
    let detuned = Shape::TunedBar(TunedBar {
        bar: Bar {
            length_m: 0.3,
            width_m: 0.03,
            thickness_m: 0.01,
        },
        tuned_ratios: vec![1.0, 4.0, 3.0],
    });
    assert!(detuned.validate().is_err());
}

#[test]
fn every_material_works_with_every_shape() {
    for material in MATERIALS {
        for (shape, _) in every_shape() {
            let modes = shape
                .modes(material, &shape.default_positions(), &ModeLimits::default())
                .unwrap();
            assert!(modes
                .iter()
                .all(|m| m.decay_per_s > 0.0 && m.freq_hz.is_finite()));
        }
    }
}
