//! Factory banks of membranes, plates, discs, bells and bowls.

use super::{key, Contact, FactoryObject, Tweaks};
use crate::authoring::materials;
use crate::authoring::shapes::{
    Bowl, CircularMembrane, CircularPlate, PlateEdge, RectangularMembrane, RectangularPlate, Shape,
    TunedBell,
};

/// Contact time in ms of a padded gong beater: a long, soft contact that brings out the low
/// modes and leaves the highs to build up.
const GONG_BEATER_MS: f64 = 3.0;

/// The membranes, plates, discs and bells, in display order.
pub(super) fn objects() -> Vec<FactoryObject> {
    vec![
        FactoryObject {
            name: "Circular membrane",
            description: "A 13-inch polyester drum head tuned by its tension: the dense, \
                          inharmonic Bessel-zero spectrum of a tom, short and thuddy. Struck at \
                          the centre only the axisymmetric modes sound. Air loading, which pulls \
                          a real drum's modes closer together, is not modelled.",
            shape: Shape::CircularMembrane(CircularMembrane {
                radius_m: 0.165,
                thickness_m: 0.25e-3,
                tension_n_per_m: 1400.0,
            }),
            material: &materials::MYLAR,
            root_key: key::D3,
            tweaks: Tweaks::NONE,
        },
        FactoryObject {
            name: "Steel plate",
            description: "A thin rectangular steel plate with hinged edges, like a thunder \
                          sheet or a plate reverb: hundreds of closely spaced modes ringing for \
                          many seconds, a metallic wash.",
            shape: Shape::RectangularPlate(RectangularPlate {
                length_x_m: 0.4,
                length_y_m: 0.3,
                thickness_m: 2e-3,
            }),
            material: &materials::STEEL,
            root_key: key::E2,
            tweaks: Tweaks::NONE,
        },
        FactoryObject {
            name: "Glass plate",
            description: "A small pane of glass held at its edges and tapped: a dense, glassy \
                          ring that fades within a few seconds.",
            shape: Shape::RectangularPlate(RectangularPlate {
                length_x_m: 0.2,
                length_y_m: 0.15,
                thickness_m: 4e-3,
            }),
            material: &materials::GLASS,
            root_key: key::F5,
            tweaks: Tweaks::NONE,
        },
        FactoryObject {
            name: "Rectangular frame drum",
            description: "A polyester head on a rectangular frame, struck with the hand or a \
                          soft stick: a low, dense, quickly damped thud whose partials follow \
                          the rectangle's sqrt((m/Lx)^2 + (n/Ly)^2), the textbook object of \
                          seed 000 section 3.1. Air loading and the frame are not modelled.",
            shape: Shape::RectangularMembrane(RectangularMembrane {
                length_x_m: 0.45,
                length_y_m: 0.35,
                thickness_m: 0.2e-3,
                tension_n_per_m: 1000.0,
            }),
            material: &materials::MYLAR,
            root_key: key::A2,
            tweaks: Tweaks::NONE,
        },
        FactoryObject {
            name: "Acrylic plate",
            description: "A sheet of acrylic with hinged edges, tapped: a dull plastic knock \
                          with a brief, boxy resonance, since the polymer's internal friction \
                          (Q about 33) kills every mode within a fraction of a second.",
            shape: Shape::RectangularPlate(RectangularPlate {
                length_x_m: 0.3,
                length_y_m: 0.2,
                thickness_m: 0.005,
            }),
            material: &materials::ACRYLIC,
            root_key: key::D3,
            tweaks: Tweaks::NONE,
        },
        FactoryObject {
            name: "Spruce panel",
            description: "A thin spruce panel, like a soundboard without its ribs, knocked \
                          with a knuckle: a warm, woody thud over a dense cluster of quickly \
                          fading modes. Spruce is far stiffer along the grain than across it; \
                          the plate here is isotropic, with the stiffness along the grain.",
            shape: Shape::RectangularPlate(RectangularPlate {
                length_x_m: 0.5,
                length_y_m: 0.35,
                thickness_m: 0.003,
            }),
            material: &materials::SPRUCE,
            root_key: key::F2,
            tweaks: Tweaks::NONE,
        },
        FactoryObject {
            name: "Scraped steel sheet",
            description: "A thin steel sheet scraped with a metal edge for as long as a key is \
                          held: a rasping, ringing screech that brightens as the scrape speeds \
                          up (pressure sets the force, slide the speed) and \
                          rings on when it stops.",
            shape: Shape::RectangularPlate(RectangularPlate {
                length_x_m: 0.5,
                length_y_m: 0.35,
                thickness_m: 1.5e-3,
            }),
            material: &materials::STEEL,
            root_key: key::E2,
            tweaks: Tweaks {
                // A sharp edge: a quarter of a millimetre of contact.
                hardness_ms: Some(0.25),
                contact: Some(Contact {
                    exciter: "scrape",
                    roughness: 0.6,
                    rolling_radius_mm: None,
                    speed_m_per_s: 0.4,
                    force: 0.8,
                }),
                ..Tweaks::NONE
            },
        },
        FactoryObject {
            name: "Spruce table top (rolled ball)",
            description: "A spruce table top with a wooden ball of 25 mm radius rolled across it \
                          for as long as a key is held: a low rumble, the ball's own bumps \
                          repeating once a revolution, faster as it rolls faster.",
            shape: Shape::RectangularPlate(RectangularPlate {
                length_x_m: 0.8,
                length_y_m: 0.5,
                thickness_m: 0.012,
            }),
            material: &materials::SPRUCE,
            root_key: key::A2,
            tweaks: Tweaks {
                contact: Some(Contact {
                    exciter: "roll",
                    roughness: 0.5,
                    rolling_radius_mm: Some(25.0),
                    speed_m_per_s: 0.6,
                    force: 0.8,
                }),
                ..Tweaks::NONE
            },
        },
        FactoryObject {
            name: "Rubbed wine glass",
            description: "A thin wine glass rubbed round its rim with a wet finger for as long \
                          as a key is held: a pure tone on the glass's lowest mode that swells \
                          from nothing within a second as the finger gets up to speed, louder \
                          the faster it goes. Press too lightly for the speed and it will not \
                          sing; it rings on when let go. Velocity and pressure set how hard the \
                          finger presses, slide its speed. The glass's stem is not modelled.",
            shape: Shape::Bowl(Bowl {
                diameter_m: 0.075,
                thickness_m: 0.0012,
            }),
            material: &materials::GLASS,
            root_key: key::E5,
            tweaks: Tweaks {
                contact: Some(Contact {
                    exciter: "rub",
                    roughness: 0.5,
                    rolling_radius_mm: None,
                    speed_m_per_s: 0.7,
                    force: 0.7,
                }),
                ..Tweaks::NONE
            },
        },
        FactoryObject {
            name: "Singing bowl (circled with a stick)",
            description: "A bronze singing bowl circled at its rim with a wooden stick for as \
                          long as a key is held: a low hum that swells within a second, as the \
                          stick gets up to speed, and holds, and rings on for many seconds when \
                          the stick leaves it, beating slowly as each pair of the bowl's modes \
                          drifts in and out of step.",
            shape: Shape::Bowl(Bowl {
                diameter_m: 0.2,
                thickness_m: 0.004,
            }),
            material: &materials::BRONZE,
            root_key: key::A3,
            tweaks: Tweaks {
                contact: Some(Contact {
                    exciter: "rub",
                    roughness: 0.5,
                    rolling_radius_mm: None,
                    speed_m_per_s: 0.8,
                    force: 0.7,
                }),
                ..Tweaks::NONE
            },
        },
        FactoryObject {
            name: "Brass disc (cymbal-like)",
            description: "A thin flat brass disc free at its rim and struck on its bow with a \
                          stick: a bright, splashy wash of hundreds of inharmonic modes over a \
                          low hum. A real cymbal's curvature and bell shift these modes; the \
                          flat free disc is its starting point.",
            shape: Shape::CircularPlate(CircularPlate {
                radius_m: 0.13,
                thickness_m: 0.001,
                edge: PlateEdge::Free,
            }),
            material: &materials::BRASS,
            root_key: key::A1,
            tweaks: Tweaks::NONE,
        },
        FactoryObject {
            name: "Bronze flat gong",
            description: "A flat bronze disc hung free and struck near its centre with a \
                          padded beater: a deep, dark, long-ringing gong tone. A real gong's \
                          turned rim and hammered dome are not modelled.",
            shape: Shape::CircularPlate(CircularPlate {
                radius_m: 0.19,
                thickness_m: 0.0025,
                edge: PlateEdge::Free,
            }),
            material: &materials::BRONZE,
            root_key: key::C2,
            tweaks: Tweaks {
                hardness_ms: Some(GONG_BEATER_MS),
                strike_at: Some("third radius"),
                contact: None,
            },
        },
        FactoryObject {
            name: "Porcelain saucer",
            description: "A porcelain saucer tapped with a spoon: a high, glassy clink that \
                          rings for a second or two. Modelled as a flat free disc; the raised \
                          rim and the foot of a real saucer are left out.",
            shape: Shape::CircularPlate(CircularPlate {
                radius_m: 0.07,
                thickness_m: 0.004,
                edge: PlateEdge::Free,
            }),
            material: &materials::PORCELAIN,
            root_key: key::D6,
            tweaks: Tweaks::NONE,
        },
        FactoryObject {
            name: "Bronze bell",
            description: "A tuned church bell in bell bronze: hum an octave below the strike \
                          note, minor-third tierce, fifth and nominal octave, the hum lingering \
                          after the rest. Partial ratios are those of a tuned bell; gains along \
                          the profile are a heuristic.",
            shape: Shape::Bell(TunedBell {
                diameter_m: 0.6,
                thickness_m: 0.046,
            }),
            material: &materials::BRONZE,
            root_key: key::A4,
            tweaks: Tweaks::NONE,
        },
        FactoryObject {
            name: "Small brass bell",
            description: "A small bell of the church-bell profile cast in brass, like a desk or \
                          ship's bell: the tuned bell's minor-third tierce and octave hum, \
                          brighter and shorter than bronze. Partial ratios are those of a tuned \
                          bell; gains along the profile are a heuristic.",
            shape: Shape::Bell(TunedBell {
                diameter_m: 0.15,
                thickness_m: 0.0115,
            }),
            material: &materials::BRASS,
            root_key: key::E5,
            tweaks: Tweaks::NONE,
        },
        FactoryObject {
            name: "Porcelain bell",
            description: "A small porcelain bell of the church-bell profile: a delicate, high, \
                          glassy ring with the tuned bell's partials. Partial ratios are those \
                          of a tuned bell; gains along the profile are a heuristic.",
            shape: Shape::Bell(TunedBell {
                diameter_m: 0.08,
                thickness_m: 0.006,
            }),
            material: &materials::PORCELAIN,
            root_key: key::G6,
            tweaks: Tweaks::NONE,
        },
    ]
}
