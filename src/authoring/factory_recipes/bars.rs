//! Factory banks of strings, bars and tines.

use super::{key, FactoryObject, Tweaks};
use crate::authoring::materials;
use crate::authoring::shapes::triangle::Triangle;
use crate::authoring::shapes::{
    Bar, Cantilever, IdealString, Shape, StiffString, StretchedString, TunedBar, MARIMBA_RATIOS,
    VIBRAPHONE_RATIOS, XYLOPHONE_RATIOS,
};

/// Contact time in ms of one clave struck against the other: hardwood on hardwood, as short as
/// a metal mallet's.
const CLAVE_ON_CLAVE_MS: f64 = 0.3;

/// Contact time in ms of a tuning fork struck on a rubber block or a knee: soft enough that the
/// clang partial is faint.
const FORK_ON_RUBBER_MS: f64 = 0.6;

/// The strings, bars and tines, in display order.
pub(super) fn objects() -> Vec<FactoryObject> {
    vec![
        FactoryObject {
            name: "Ideal string",
            description: "A string with no stiffness, struck by a point hammer: a pure harmonic \
                          series whose spectrum falls as 1/n, with the harmonics at the strike \
                          point's nodes missing. The textbook reference for every other bank.",
            shape: Shape::IdealString(IdealString(StretchedString {
                length_m: 0.65,
                diameter_m: 0.9e-3,
                tension_n: 100.0,
            })),
            material: &materials::STEEL,
            root_key: key::A2,
            tweaks: Tweaks::NONE,
        },
        FactoryObject {
            name: "Piano-like stiff string",
            description: "A plain steel piano wire at middle C, struck near one end like a \
                          piano hammer: the wire's stiffness stretches the upper partials sharp \
                          (inharmonicity B about 4e-4), the shimmer of a real piano tone.",
            shape: Shape::StiffString(StiffString(StretchedString {
                length_m: 0.62,
                diameter_m: 1.0e-3,
                tension_n: 650.0,
            })),
            material: &materials::STEEL,
            root_key: key::C4,
            tweaks: Tweaks::NONE,
        },
        FactoryObject {
            name: "Steel free-free bar",
            description: "A uniform steel bar free at both ends, like a glockenspiel bar: a \
                          bright, long-ringing bell tone with the inharmonic overtones \
                          1 : 2.76 : 5.40 : 8.93.",
            shape: Shape::FreeFreeBar(Bar {
                length_m: 0.2,
                width_m: 0.025,
                thickness_m: 0.008,
            }),
            material: &materials::STEEL,
            root_key: key::C6,
            tweaks: Tweaks::NONE,
        },
        FactoryObject {
            name: "Rosewood marimba bar",
            description: "A rosewood marimba bar undercut to the classic 1 : 4 : 10 tuning: a \
                          warm, woody note that rings for a second or two, its upper partials \
                          gone within a fraction of a second. Dimensions are those of an \
                          equivalent uniform bar.",
            shape: Shape::TunedBar(TunedBar {
                bar: Bar {
                    length_m: 0.38,
                    width_m: 0.06,
                    thickness_m: 0.009,
                },
                tuned_ratios: MARIMBA_RATIOS.to_vec(),
            }),
            material: &materials::ROSEWOOD,
            root_key: key::C4,
            tweaks: Tweaks::NONE,
        },
        FactoryObject {
            name: "Aluminium vibraphone bar",
            description: "An aluminium bar undercut so its first overtone sits two octaves up, \
                          like a vibraphone bar with the motor off: a pure, very long sustain. \
                          Dimensions are those of an equivalent uniform bar.",
            shape: Shape::TunedBar(TunedBar {
                bar: Bar {
                    length_m: 0.38,
                    width_m: 0.057,
                    thickness_m: 0.006,
                },
                tuned_ratios: VIBRAPHONE_RATIOS.to_vec(),
            }),
            material: &materials::ALUMINIUM,
            root_key: key::F3,
            tweaks: Tweaks::NONE,
        },
        FactoryObject {
            name: "Rosewood claves",
            description: "A rosewood clave struck against its partner: a sharp, high, woody \
                          click with a short ring, its overtones at the free-free bar's \
                          1 : 2.76 : 5.40. The round rod is modelled as a bar of equivalent \
                          section.",
            shape: Shape::FreeFreeBar(Bar {
                length_m: 0.2,
                width_m: 0.022,
                thickness_m: 0.022,
            }),
            material: &materials::ROSEWOOD,
            root_key: key::D7,
            tweaks: Tweaks {
                hardness_ms: Some(CLAVE_ON_CLAVE_MS),
                ..Tweaks::NONE
            },
        },
        FactoryObject {
            name: "Spruce xylophone bar",
            description: "A soft-wood bar undercut to the xylophone's 1 : 3 tuning (a twelfth): \
                          lighter and duller than rosewood, with a short, hollow knock and \
                          highs that are gone almost at once. Dimensions are those of an \
                          equivalent uniform bar.",
            shape: Shape::TunedBar(TunedBar {
                bar: Bar {
                    length_m: 0.3,
                    width_m: 0.04,
                    thickness_m: 0.02,
                },
                tuned_ratios: XYLOPHONE_RATIOS.to_vec(),
            }),
            material: &materials::SPRUCE,
            root_key: key::G4,
            tweaks: Tweaks::NONE,
        },
        FactoryObject {
            name: "Glass chime bar",
            description: "A bar of glass free at both ends, like a crystallophone key: a clear, \
                          cool bell tone that rings for a few seconds, its overtones fading \
                          faster than a metal bar's.",
            shape: Shape::FreeFreeBar(Bar {
                length_m: 0.2,
                width_m: 0.03,
                thickness_m: 0.008,
            }),
            material: &materials::GLASS,
            root_key: key::A5,
            tweaks: Tweaks::NONE,
        },
        FactoryObject {
            name: "Aluminium chime bar",
            description: "A plain aluminium bar free at both ends, like a bell lyra or a \
                          metallophone key: untuned inharmonic overtones over a very long, \
                          pure sustain.",
            shape: Shape::FreeFreeBar(Bar {
                length_m: 0.25,
                width_m: 0.03,
                thickness_m: 0.01,
            }),
            material: &materials::ALUMINIUM,
            root_key: key::E5,
            tweaks: Tweaks::NONE,
        },
        FactoryObject {
            name: "Kalimba tine",
            description: "A spring-steel tine clamped over a bridge and struck at its tip, like \
                          a kalimba or mbira key: a round fundamental with the bright clang \
                          partial 6.27 times higher (the clamped-free bar's 1 : 6.27 : 17.5). \
                          The resonating box is not modelled.",
            shape: Shape::ClampedFreeBar(Cantilever(Bar {
                length_m: 0.06,
                width_m: 0.004,
                thickness_m: 0.0012,
            })),
            material: &materials::STEEL,
            root_key: key::C5,
            tweaks: Tweaks::NONE,
        },
        FactoryObject {
            name: "Steel tuning fork",
            description: "One prong of a steel tuning fork at A440, clamped at the stem and \
                          struck on a rubber block: an almost pure tone that rings for tens of \
                          seconds, with a faint clang partial 6.27 times higher that dies \
                          first.",
            shape: Shape::ClampedFreeBar(Cantilever(Bar {
                length_m: 0.086,
                width_m: 0.005,
                thickness_m: 0.004,
            })),
            material: &materials::STEEL,
            root_key: key::A4,
            tweaks: Tweaks {
                hardness_ms: Some(FORK_ON_RUBBER_MS),
                ..Tweaks::NONE
            },
        },
        FactoryObject {
            name: "Steel triangle",
            description: "An orchestral triangle: a 10 mm steel rod bent into three sides, hung \
                          from a corner and struck on its bottom side with a steel beater: a \
                          bright, long ring whose inharmonic partials (1 : 2.76 : 5.40) blur \
                          its pitch.",
            shape: Shape::Triangle(Triangle {
                length_m: 0.54,
                diameter_m: 0.01,
            }),
            material: &materials::STEEL,
            root_key: key::D3,
            tweaks: Tweaks::NONE,
        },
    ]
}
