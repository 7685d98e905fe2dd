//! The scene of seed 001 section 6, hail on a picnic: roof panes, plates, a table and a can,
//! each a rectangular plate of its material (seed 000 section 3.1), struck by a Poisson rain of
//! impacts whose energies follow a 1/E law.

use modal_resonator::authoring::materials::{self, Material};
use modal_resonator::authoring::shapes::{ModeLimits, RectangularPlate, Shape, MAX_AUDIBLE_HZ};
use modal_resonator::bank::{Bank, Mode, Position};
use modal_resonator::rng::Rng;

use crate::RATE_HZ;

/// Mean impacts per second over the whole scene.
const IMPACTS_PER_S: f64 = 30.0;

/// Span of impact energies: the 1/E law runs over this ratio (40 dB).
pub const ENERGY_RANGE: f64 = 1e4;
/// MIDI key of the first object; object `k` plays on `FIRST_KEY + k`.
pub const FIRST_KEY: u8 = 48;

/// One object of the scene.
pub struct Object {
    /// What it is.
    pub name: &'static str,
    /// Its shape: every object is a rectangular plate (the can as its unrolled wall).
    pub plate: RectangularPlate,
    /// What it is made of (decays from the material's loss factor).
    pub material: &'static Material,
    /// How many of its lowest modes it keeps.
    pub modes: usize,
    /// Level of the object's loudest mode relative to the others', in dB.
    pub level_db: f64,
    /// Relative chance of being hit.
    pub exposure: f64,
}

/// The nine objects: four roof panes, three plates, a table and a can (two of over a thousand
/// modes, 3,300 in all).
pub fn objects() -> Vec<Object> {
    let plate = |x: f64, y: f64, h: f64| RectangularPlate {
        length_x_m: x,
        length_y_m: y,
        thickness_m: h,
    };
    vec![
        Object {
            name: "roof pane 1",
            plate: plate(0.9, 0.6, 2.0e-3),
            material: &materials::ALUMINIUM,
            modes: 100,
            level_db: -6.0,
            exposure: 3.0,
        },
        Object {
            name: "roof pane 2",
            plate: plate(1.1, 0.7, 2.5e-3),
            material: &materials::ALUMINIUM,
            modes: 150,
            level_db: -6.0,
            exposure: 3.0,
        },
        Object {
            name: "roof pane 3",
            plate: plate(1.2, 0.8, 3.0e-3),
            material: &materials::STEEL,
            modes: 200,
            level_db: -4.0,
            exposure: 3.0,
        },
        Object {
            name: "roof pane 4",
            plate: plate(1.5, 1.0, 1.5e-3),
            material: &materials::STEEL,
            modes: 1050,
            level_db: -3.0,
            exposure: 3.0,
        },
        Object {
            name: "plate 1",
            plate: plate(0.25, 0.25, 1.2e-3),
            material: &materials::STEEL,
            modes: 200,
            level_db: -10.0,
            exposure: 1.0,
        },
        Object {
            name: "plate 2",
            plate: plate(0.3, 0.3, 1.5e-3),
            material: &materials::STEEL,
            modes: 200,
            level_db: -10.0,
            exposure: 1.0,
        },
        Object {
            name: "plate 3",
            plate: plate(0.35, 0.35, 1.8e-3),
            material: &materials::BRASS,
            modes: 200,
            level_db: -10.0,
            exposure: 1.0,
        },
        Object {
            name: "table",
            plate: plate(1.6, 0.8, 30e-3),
            material: &materials::SPRUCE,
            modes: 100,
            level_db: -2.0,
            exposure: 2.0,
        },
        Object {
            name: "can",
            plate: plate(1.2, 0.5, 0.8e-3),
            material: &materials::STEEL,
            modes: 1100,
            level_db: 0.0,
            exposure: 1.5,
        },
    ]
}

/// Modes of the scene's objects start here: what lies below hearing is left out of a model.
const LOWEST_HZ: f64 = 20.0;

/// The lowest `o.modes` audible modes of object `o` struck at `strike`.
pub fn object_modes(o: &Object, strike: &[Position]) -> Vec<Mode> {
    let limits = ModeLimits {
        max_freq_hz: MAX_AUDIBLE_HZ,
        max_modes: o.modes + 32,
    };
    let mut modes = Shape::RectangularPlate(o.plate.clone())
        .modes(o.material, strike, &limits)
        .unwrap_or_else(|e| panic!("{}: {e}", o.name));
    modes.retain(|m| m.freq_hz >= LOWEST_HZ);
    assert!(modes.len() >= o.modes, "{} has too few modes", o.name);
    modes.truncate(o.modes);
    modes
}

/// The scene as one bank: position `k` is object `k`, struck off-centre.
pub fn scene_bank(objects: &[Object]) -> Bank {
    let positions: Vec<Position> = (0..objects.len())
        .map(|k| Position {
            name: objects[k].name.into(),
            coords: vec![k as f64],
        })
        .collect();
    let mut bank = Bank::new("hail on a picnic", positions);
    let strike = [Position {
        name: "off-centre".into(),
        coords: vec![0.38, 0.42],
    }];
    for (k, o) in objects.iter().enumerate() {
        let modes = object_modes(o, &strike);
        let scale = 10f64.powf(o.level_db / 20.0);
        for m in modes {
            let mut gains = vec![0.0; objects.len()];
            gains[k] = m.gains[0] * scale;
            bank.modes.push(Mode { gains, ..m });
        }
    }
    bank
}

/// Uniform numbers in `0..1`, seeded.
fn uniform(seed: u32) -> impl FnMut() -> f64 {
    let mut rng = Rng::new(seed);
    move || rng.uniform()
}

/// One impact: sample, object, velocity.
pub type Impact = (usize, usize, f32);

/// A Poisson rain of impacts on objects chosen by exposure, energies drawn from a 1/E law
/// (log-uniform over `ENERGY_RANGE`), seeded.
pub fn hail(objects: &[Object], seconds: f64, seed: u32) -> Vec<Impact> {
    let mut uniform = uniform(seed);
    let total: f64 = objects.iter().map(|o| o.exposure).sum();
    let mut t = 0.0;
    let mut out = Vec::new();
    loop {
        t += -(1.0 - uniform()).ln() / IMPACTS_PER_S;
        if t >= seconds {
            break;
        }
        let mut pick = uniform() * total;
        let object = objects
            .iter()
            .position(|o| {
                pick -= o.exposure;
                pick < 0.0
            })
            .unwrap_or(objects.len() - 1);
        // Energy E / E_max = range^-u: density proportional to 1/E. Velocity is the amplitude.
        let energy = ENERGY_RANGE.powf(-uniform());
        out.push(((t * RATE_HZ) as usize, object, energy.sqrt() as f32));
    }
    out
}

/// One strike of a scene: sample, key, velocity and strike position.
#[derive(Debug, Clone, Copy)]
pub struct Hit {
    /// Sample it lands on.
    pub at: usize,
    /// MIDI key.
    pub key: u8,
    /// Velocity 0 to 1.
    pub velocity: f32,
    /// Strike position (the engine's `strike_x`).
    pub strike_x: f32,
}

/// The hail as strikes: object `k` on key `FIRST_KEY + k`, struck at its own position.
pub fn hail_hits(impacts: &[Impact], objects: usize) -> Vec<Hit> {
    impacts
        .iter()
        .map(|&(at, object, velocity)| Hit {
            at,
            key: FIRST_KEY + object as u8,
            velocity,
            strike_x: object as f32 / (objects - 1) as f32,
        })
        .collect()
}

/// Modes of the dense scene's plate.
pub const DENSE_MODES: usize = 2_200;

/// Voices of the dense scene.
pub const DENSE_VOICES: usize = 16;

/// The dense scene's object: a steel sheet of [`DENSE_MODES`] modes up to about 16 kHz, struck
/// off-centre, its root at middle C.
pub fn dense_bank() -> Bank {
    let sheet = Object {
        name: "steel sheet",
        plate: RectangularPlate {
            length_x_m: 1.0,
            length_y_m: 0.65,
            thickness_m: 1.5e-3,
        },
        material: &materials::STEEL,
        modes: DENSE_MODES,
        level_db: 0.0,
        exposure: 1.0,
    };
    let strike = [Position {
        name: "off-centre".into(),
        coords: vec![0.38, 0.42],
    }];
    let mut bank = Bank::new("steel sheet", strike.to_vec());
    bank.modes = object_modes(&sheet, &strike);
    bank
}

/// Keys the dense scene plays: a minor pentatonic over two octaves below the root, so every
/// pitch keeps its modes under the audible limit.
const DENSE_KEYS: [u8; 11] = [36, 39, 41, 43, 46, 48, 51, 53, 55, 58, 60];

/// Chords and rolls on the sheet, seeded: a chord of four keys every 0.75 s, and between two
/// chords a roll of six strikes ten a second on one key, softer.
pub fn chords_and_rolls(seconds: f64, seed: u32) -> Vec<Hit> {
    let mut uniform = uniform(seed);
    let key =
        |u: f64| DENSE_KEYS[((u * DENSE_KEYS.len() as f64) as usize).min(DENSE_KEYS.len() - 1)];
    let mut hits = Vec::new();
    let mut t = 0.0;
    while t < seconds {
        for _ in 0..4 {
            hits.push(Hit {
                at: (t * RATE_HZ) as usize,
                key: key(uniform()),
                velocity: (0.4 + 0.6 * uniform()) as f32,
                strike_x: 0.38,
            });
        }
        let roll = key(uniform());
        for k in 0..6 {
            let at = t + 0.15 + 0.1 * k as f64;
            if at < seconds {
                hits.push(Hit {
                    at: (at * RATE_HZ) as usize,
                    key: roll,
                    velocity: (0.3 + 0.4 * uniform()) as f32,
                    strike_x: 0.38,
                });
            }
        }
        t += 0.75;
    }
    hits.sort_by_key(|h| h.at);
    hits
}
