//! Textbook frequency ratios and absolute frequencies of every object, against closed forms and
//! published tables.

use super::*;

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
    let modes = Shape::StiffString(StiffString(wire))
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
    let modes = Shape::IdealString(IdealString(piano_wire()))
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
fn clamped_free_bar_ratios_match_the_textbook() {
    let modes = kalimba_tine()
        .modes(steel(), &on_line(&[1.0]), &ModeLimits::default())
        .unwrap();
    // (b_n L / b_1 L)^2 with b_n L = 1.8751, 4.6941, 7.8548, 10.9955 (Blevins table 8-1).
    assert_ratios(
        "clamped-free bar",
        &freqs(&modes),
        &[1.0, 6.267, 17.55, 34.39],
        1e-3,
    );
}

#[test]
fn steel_bars_match_the_euler_bernoulli_formula() {
    // f = (b L)^2 / (2 pi L^2) sqrt(E I / (rho A)), I = w h^3 / 12, A = w h, for steel
    // (E = 200 GPa, rho = 7850 kg/m^3): a 300 x 30 x 10 mm bar free at both ends, and a
    // 60 x 4 x 1.2 mm tine clamped at one end.
    let euler_bernoulli = |beta_l: f64, length: f64, width: f64, thickness: f64| {
        let second_moment = width * thickness.powi(3) / 12.0;
        let area = width * thickness;
        beta_l * beta_l / (TAU * length * length) * (200e9 * second_moment / (7850.0 * area)).sqrt()
    };
    let cases = [
        (
            glockenspiel_bar(),
            [4.730_040_7, 7.853_204_6],
            (0.3, 0.03, 0.01),
        ),
        (
            kalimba_tine(),
            [1.875_104_07, 4.694_091_13],
            (0.06, 0.004, 1.2e-3),
        ),
    ];
    for (shape, beta_ls, (length, width, thickness)) in cases {
        let modes = shape
            .modes(steel(), &on_line(&[1.0]), &ModeLimits::default())
            .unwrap();
        for (mode, beta_l) in modes.iter().zip(beta_ls) {
            let want = euler_bernoulli(beta_l, length, width, thickness);
            assert!(
                (mode.freq_hz / want - 1.0).abs() < 1e-7,
                "{}: {} Hz vs {want} Hz",
                shape.kind(),
                mode.freq_hz
            );
        }
    }
    // By hand for the tine: sqrt(E I / (rho A)) = h sqrt(E / (12 rho)) = 1.7485 m^2/s,
    // (1.8751)^2 / (2 pi 0.06^2) = 155.45 / m^2: f1 = 271.8 Hz.
    let f1 = kalimba_tine().root_hz(steel());
    assert!((f1 - 271.8).abs() < 0.1, "tine f1 = {f1}");
}

#[test]
fn rectangular_membrane_follows_the_formula() {
    let mylar = &materials::MYLAR;
    let modes = frame_drum()
        .modes(mylar, &on_plane(&[[0.31, 0.23]]), &ModeLimits::default())
        .unwrap();
    // f_mn = (c / 2) sqrt((m / Lx)^2 + (n / Ly)^2), c = sqrt(T / (rho h)) (seed 000 section 3.1):
    // every (m, n) up to 60, sorted, against the lowest modes of the bank.
    let c = (2000.0f64 / (1390.0 * 0.2e-3)).sqrt();
    let mut want: Vec<(f64, usize, usize)> = Vec::new();
    for m in 1..=60 {
        for n in 1..=60 {
            let f = 0.5 * c * ((m as f64 / 0.4).powi(2) + (n as f64 / 0.3).powi(2)).sqrt();
            want.push((f, m, n));
        }
    }
    want.sort_by(|a, b| a.0.total_cmp(&b.0));
    assert_eq!(modes.len(), DEFAULT_MAX_MODES);
    let first = modes[0].gains[0];
    let f11 = want[0].0;
    for (i, (mode, &(f, m, n))) in modes.iter().zip(&want).enumerate() {
        assert!(
            (mode.freq_hz / f - 1.0).abs() < 1e-12,
            "mode {i}: {} Hz vs {f} Hz",
            mode.freq_hz
        );
        // seed 000 eq. 3.11: Psi_mn(p) / omega_mn, relative to mode (1, 1).
        let psi = |m: usize, n: usize| {
            (m as f64 * std::f64::consts::PI * 0.31).sin()
                * (n as f64 * std::f64::consts::PI * 0.23).sin()
        };
        let gain = psi(m, n) / f / (psi(1, 1) / f11);
        assert!(
            (mode.gains[0] / first - gain).abs() < 1e-9,
            "mode {i} ({m}, {n}): gain {} vs {gain}",
            mode.gains[0] / first
        );
    }
    // A square membrane sounds sqrt((m^2 + n^2) / 2): 1, 1.581 (twice), 2, 2.236 (twice) ...
    let square = Shape::RectangularMembrane(RectangularMembrane {
        length_x_m: 0.3,
        length_y_m: 0.3,
        thickness_m: 0.2e-3,
        tension_n_per_m: 2000.0,
    });
    let modes = square
        .modes(mylar, &on_plane(&[[0.31, 0.23]]), &ModeLimits::default())
        .unwrap();
    assert_ratios(
        "square membrane",
        &freqs(&modes),
        &[
            1.0, 1.5811, 1.5811, 2.0, 2.2361, 2.2361, 2.5495, 2.5495, 2.9155, 2.9155, 3.0,
        ],
        1e-4,
    );
}

#[test]
fn circular_plates_match_leissa() {
    // Clamped: lambda^2 = 10.2158, 21.260, 34.877, 39.771, 51.030, 60.829 (Leissa, Vibration of
    // Plates, table 2.1), whatever the material. Positions on the x axis: one mode per root.
    let clamped = disc(PlateEdge::Clamped)
        .modes(steel(), &on_plane(&[[0.3, 0.0]]), &ModeLimits::default())
        .unwrap();
    let table = [10.2158, 21.260, 34.877, 39.771, 51.030, 60.829];
    let ratios: Vec<f64> = table.iter().map(|l2| l2 / table[0]).collect();
    assert_ratios("clamped disc", &freqs(&clamped), &ratios, 1e-4);
    // Absolute: f = lambda^2 / (2 pi a^2) sqrt(D / (rho h)), D = E h^3 / (12 (1 - nu^2)), for a
    // steel disc 100 mm in radius and 2 mm thick.
    let rigidity: f64 = 200e9 * 8e-9 / (12.0 * (1.0 - 0.09));
    let f00 = 10.2158 / (TAU * 0.01) * (rigidity / (7850.0 * 2e-3)).sqrt();
    assert!(
        (clamped[0].freq_hz / f00 - 1.0).abs() < 1e-5,
        "clamped disc f00 = {} Hz vs {f00} Hz",
        clamped[0].freq_hz
    );
    // Free, in aluminium (nu = 0.33 as in Leissa's table 2.3): 5.253, 9.084, 12.23, 20.52,
    // 21.6, 33.1, 35.25, 38.55 to within the table's 0.4%.
    let aluminium = &materials::ALUMINIUM;
    assert_eq!(aluminium.poisson_ratio, 0.33);
    let free = disc(PlateEdge::Free)
        .modes(aluminium, &on_plane(&[[0.3, 0.0]]), &ModeLimits::default())
        .unwrap();
    let table = [5.253, 9.084, 12.23, 20.52, 21.6, 33.1, 35.25, 38.55];
    let ratios: Vec<f64> = table.iter().map(|l2| l2 / table[0]).collect();
    assert_ratios("free disc", &freqs(&free), &ratios, 6e-3);
    // Off the axis, modes with nodal diameters come in pairs at one frequency.
    let off_axis = disc(PlateEdge::Free)
        .modes(aluminium, &on_plane(&[[0.3, 0.2]]), &ModeLimits::default())
        .unwrap();
    assert_eq!(off_axis[0].freq_hz, off_axis[1].freq_hz);
    assert!(off_axis[2].freq_hz > off_axis[1].freq_hz);
}
