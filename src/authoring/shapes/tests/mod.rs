//! Checks of the analytic shapes: textbook frequency ratios and absolute frequencies
//! (`textbook.rs`), nodes, and the invariants every generated bank keeps (here).

mod textbook;

use super::positions::position;
use super::*;
use crate::authoring::materials::{self, Material, MATERIALS};

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
        (Shape::IdealString(IdealString(piano_wire())), steel()),
        (Shape::StiffString(StiffString(piano_wire())), steel()),
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
        (kalimba_tine(), steel()),
        (frame_drum(), &materials::MYLAR),
        (disc(PlateEdge::Free), &materials::BRASS),
        (disc(PlateEdge::Clamped), steel()),
    ]
}

fn kalimba_tine() -> Shape {
    Shape::ClampedFreeBar(Cantilever(Bar {
        length_m: 0.06,
        width_m: 0.004,
        thickness_m: 1.2e-3,
    }))
}

fn frame_drum() -> Shape {
    Shape::RectangularMembrane(RectangularMembrane {
        length_x_m: 0.4,
        length_y_m: 0.3,
        thickness_m: 0.2e-3,
        tension_n_per_m: 2000.0,
    })
}

fn disc(edge: PlateEdge) -> Shape {
    Shape::CircularPlate(CircularPlate {
        radius_m: 0.1,
        thickness_m: 2e-3,
        edge,
    })
}

#[test]
fn striking_a_node_silences_the_mode() {
    // A string struck at its middle has no even harmonics.
    let modes = Shape::IdealString(IdealString(piano_wire()))
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
                                            // A free disc struck at its centre: only the modes without nodal diameters sound, so the
                                            // lowest, (2, 0), is silent and (0, 1), the second, is not.
    let modes = disc(PlateEdge::Free)
        .modes(
            &materials::BRASS,
            &on_plane(&[[0.0, 0.0]]),
            &ModeLimits::default(),
        )
        .unwrap();
    assert_eq!(modes[0].gains[0], 0.0);
    assert!(modes[1].gains[0].abs() > 0.0);
    // A tine struck at its clamp does not move at all.
    let modes = kalimba_tine()
        .modes(steel(), &on_line(&[0.0, 1.0]), &ModeLimits::default())
        .unwrap();
    assert!(modes.iter().all(|m| m.gains[0] == 0.0 && m.gains[1] != 0.0));
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
    let stubborn = Shape::StiffString(StiffString(StretchedString {
        length_m: 0.05,
        diameter_m: 3e-3,
        tension_n: 100.0,
    }));
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
