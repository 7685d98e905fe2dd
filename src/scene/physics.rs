//! The objects' rigid bodies, moved by rapier; their impacts become events.
//!
//! Every step the solver resolves the contacts; a pair of bodies that touches (its manifolds
//! carry an impulse) and did not touch the step before has struck, at the relative normal speed
//! its bodies had at the contact point before the step. A pair that stays in touch strikes
//! again only when it closes at [`RESTRIKE_M_PER_S`] or faster (a box rocking onto its other
//! edge), so resting contact, whose solver corrections are far slower, never chatters. Impacts
//! slower than [`MIN_IMPACT_M_PER_S`] are not heard (40 dB under one at 1 m/s) and are left out.

use std::collections::HashSet;

use rapier3d::math::{Pose, Vector};
use rapier3d::parry::query;
use rapier3d::prelude::{
    ColliderBuilder, ColliderHandle, PairContacts, PhysicsWorld, QueryFilter, Ray,
    RigidBodyBuilder, RigidBodyHandle, SharedShape,
};

use super::format::{Body, Collider, DropKind, Emitter, Impact, SceneEvent, SceneFile, MAX_EVENTS};
use crate::bank::validate::Problem;
use crate::rng::Rng;

/// Slowest impact struck, m/s: 40 dB under an impact at 1 m/s.
pub const MIN_IMPACT_M_PER_S: f64 = 0.01;

/// Closing speed at which a pair already in touch strikes again, m/s.
pub const RESTRIKE_M_PER_S: f64 = 0.1;

/// Deepest overlap of two bodies at the start allowed, m: touching is fine, one inside another
/// is an error.
const MAX_OVERLAP_M: f64 = 1e-3;

/// What the simulation found.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Simulated {
    /// Impacts on sounding objects, in time order.
    pub events: Vec<SceneEvent>,
    /// Steps taken.
    pub steps: usize,
    /// Whether more impacts were found than a scene may hold ([`MAX_EVENTS`]); the later ones
    /// are left out.
    pub capped: bool,
}

fn vector(v: [f64; 3]) -> Vector {
    Vector::new(v[0] as f32, v[1] as f32, v[2] as f32)
}

fn shape(c: &Collider) -> SharedShape {
    match *c {
        Collider::Ball { radius_m } => SharedShape::ball(radius_m as f32),
        Collider::Cuboid { half_extents_m: h } => {
            SharedShape::cuboid(h[0] as f32, h[1] as f32, h[2] as f32)
        }
        Collider::Cylinder {
            half_height_m,
            radius_m,
        } => SharedShape::cylinder(half_height_m as f32, radius_m as f32),
    }
}

/// Problems of the bodies' places: one inside another, the listener inside one.
pub fn check_places(scene: &SceneFile) -> Vec<Problem> {
    let bodies: Vec<(usize, Pose, SharedShape, f64)> = scene
        .objects
        .iter()
        .enumerate()
        .filter_map(|(i, o)| {
            let b = o.body.as_ref()?;
            let s = shape(&b.collider);
            let radius = s.compute_local_bounding_sphere().radius() as f64;
            Some((i, Pose::from_translation(vector(o.position)), s, radius))
        })
        .collect();
    let mut problems = Vec::new();
    let listener = vector(scene.listener.position);
    for (i, pose, s, _) in &bodies {
        if s.contains_point(pose, listener) {
            problems.push(Problem {
                path: "listener.position".into(),
                message: format!(
                    "inside \"{}\" (objects[{i}]): the listener must stand outside every body",
                    scene.objects[*i].name
                ),
            });
        }
    }
    for (a, (i, pi, si, ri)) in bodies.iter().enumerate() {
        for (j, pj, sj, rj) in &bodies[a + 1..] {
            let far = (pi.translation - pj.translation).length() as f64 > ri + rj;
            if far {
                continue;
            }
            if let Ok(Some(c)) = query::contact(pi, si.as_ref(), pj, sj.as_ref(), 0.0) {
                if (c.dist as f64) < -MAX_OVERLAP_M {
                    problems.push(Problem {
                        path: format!("objects[{j}].position"),
                        message: format!(
                            "\"{}\" overlaps \"{}\" (objects[{i}]) by {:.1} mm at the start",
                            scene.objects[*j].name,
                            scene.objects[*i].name,
                            -1e3 * c.dist
                        ),
                    });
                }
            }
        }
        if problems.len() >= 20 {
            break;
        }
    }
    problems
}

/// Builds the world: one rigid body per object with a `body`, its index in `user_data`.
fn build(scene: &SceneFile) -> (PhysicsWorld, Vec<(usize, RigidBodyHandle)>) {
    let mut world = PhysicsWorld::default();
    if let Some(physics) = scene.physics {
        world.gravity = vector(physics.gravity_m_per_s2);
        world.integration_parameters.dt = physics.step_s as f32;
    }
    let mut handles = Vec::new();
    for (i, o) in scene.objects.iter().enumerate() {
        let Some(b) = &o.body else { continue };
        let body = if b.dynamic {
            RigidBodyBuilder::dynamic()
                .linvel(vector(b.linear_velocity_m_per_s))
                .angvel(vector(b.angular_velocity_rad_per_s))
                .ccd_enabled(true)
        } else {
            RigidBodyBuilder::fixed()
        }
        .translation(vector(o.position))
        .user_data(i as u128);
        let collider = collider(b);
        let (h, _) = world.insert(body, collider);
        handles.push((i, h));
    }
    (world, handles)
}

fn collider(b: &Body) -> ColliderBuilder {
    let c = ColliderBuilder::new(shape(&b.collider))
        .restitution(b.restitution as f32)
        .friction(b.friction as f32);
    match b.mass_kg {
        Some(m) => c.mass(m as f32),
        None => c.density(b.density_kg_per_m3 as f32),
    }
}

/// A body's velocity before a step: linear, angular, centre of mass.
#[derive(Debug, Clone, Copy)]
struct Motion {
    linvel: Vector,
    angvel: Vector,
    com: Vector,
}

impl Motion {
    fn at(&self, p: Vector) -> Vector {
        self.linvel + self.angvel.cross(p - self.com)
    }
}

/// Runs the scene's physics for its duration, and its emitters' drops, and returns the impacts
/// on objects that sound.
pub fn simulate(scene: &SceneFile) -> Simulated {
    if scene.physics.is_none() && scene.emitters.is_empty() {
        return Simulated::default();
    }
    let drops = drops(&scene.emitters);
    let Some(physics) = scene.physics else {
        // Nothing moves: every drop is cast against the bodies where they stand.
        let (mut world, _) = build(scene);
        world.detect_collisions(&(), &());
        let mut events = Vec::new();
        for d in &drops {
            cast(&world, scene, d, &mut events);
        }
        events.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
        let capped = cap(&mut events, scene.events.len());
        return Simulated {
            events,
            steps: 0,
            capped,
        };
    };
    let (mut world, handles) = build(scene);
    let steps = (physics.duration_s / physics.step_s).round() as usize;
    let mut motions: Vec<Option<Motion>> = vec![None; scene.objects.len()];
    let mut touching: HashSet<(ColliderHandle, ColliderHandle)> = HashSet::new();
    let mut now_touching = HashSet::new();
    let mut events = Vec::new();
    let mut next_drop = 0;
    for step in 0..steps {
        if events.len() > MAX_EVENTS {
            break;
        }
        // Drops let go before this step ends fall on the bodies where they stand now.
        let step_end_s = (step + 1) as f64 * physics.step_s;
        while next_drop < drops.len() && drops[next_drop].time_s < step_end_s {
            cast(&world, scene, &drops[next_drop], &mut events);
            next_drop += 1;
        }
        for &(i, h) in &handles {
            let b = &world.bodies[h];
            motions[i] = Some(Motion {
                linvel: b.linvel(),
                angvel: b.angvel(),
                com: b.center_of_mass(),
            });
        }
        world.step();
        let step_start_s = step as f64 * physics.step_s;
        let step_s = physics.step_s;
        let after = Step {
            start_s: step_start_s,
            step_s,
            motions: &motions,
            touching: &touching,
        };
        now_touching.clear();
        strikes_of_step(&world, scene, &after, &mut now_touching, &mut events);
        std::mem::swap(&mut touching, &mut now_touching);
    }
    events.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
    let capped = cap(&mut events, scene.events.len());
    Simulated {
        events,
        steps,
        capped,
    }
}

/// A step just taken: when it began, how long it was, the bodies' motions before it, and the
/// pairs that touched the step before.
struct Step<'a> {
    start_s: f64,
    step_s: f64,
    motions: &'a [Option<Motion>],
    touching: &'a HashSet<(ColliderHandle, ColliderHandle)>,
}

/// The strikes of the step `after` describes: every pair whose manifolds took an impulse is
/// noted in `now_touching`; a pair that touches anew closing at [`MIN_IMPACT_M_PER_S`] or more,
/// or one in touch closing at [`RESTRIKE_M_PER_S`], strikes each of its bodies that sounds.
fn strikes_of_step(
    world: &PhysicsWorld,
    scene: &SceneFile,
    after: &Step,
    now_touching: &mut HashSet<(ColliderHandle, ColliderHandle)>,
    events: &mut Vec<SceneEvent>,
) {
    for pair in world.narrow_phase.contact_pairs() {
        let PairContacts::Rigid(contacts) = &pair.contacts else {
            continue;
        };
        // The point that took the largest impulse, its manifold's normal, and the gap there
        // when the step began.
        let mut hit: Option<(Vector, Vector, f32)> = None;
        let mut most = 0.0f32;
        for m in contacts.solver_manifolds() {
            for p in &m.points {
                if p.data.impulse > most {
                    most = p.data.impulse;
                    let c1 = &world.colliders[pair.collider1];
                    let at = c1.position().transform_point(p.local_p1);
                    hit = Some((at, m.data.normal, p.dist));
                }
            }
        }
        let Some((point, normal, gap)) = hit else {
            continue;
        };
        let key = (pair.collider1, pair.collider2);
        now_touching.insert(key);
        let object = |c: ColliderHandle| {
            let parent = world.colliders[c].parent()?;
            Some(world.bodies[parent].user_data as usize)
        };
        let (Some(o1), Some(o2)) = (object(pair.collider1), object(pair.collider2)) else {
            continue;
        };
        let velocity = |o: usize| after.motions[o].map_or(Vector::ZERO, |m| m.at(point));
        let closing = ((velocity(o1) - velocity(o2)).dot(normal)) as f64;
        let threshold = if after.touching.contains(&key) {
            RESTRIKE_M_PER_S
        } else {
            MIN_IMPACT_M_PER_S
        };
        if closing < threshold {
            continue;
        }
        // When the gap closed: the contacts are found at the start of the step, the gap
        // then negative if the bodies already overlapped (they moved through it in the
        // step before) or positive if they meet within this one.
        let time_s = (after.start_s + gap as f64 / closing)
            .clamp(after.start_s - after.step_s, after.start_s + after.step_s)
            .max(0.0);
        for o in [o1, o2] {
            if scene.objects[o].bank.is_some() {
                events.push(SceneEvent {
                    time_s,
                    object: scene.objects[o].name.clone(),
                    impact: Some(Impact {
                        speed_m_per_s: closing.min(super::format::MAX_SPEED_M_PER_S),
                        gain_db: 0.0,
                    }),
                    contact: None,
                });
            }
        }
    }
}

/// Keeps the earliest of `events` that fit beside `given` events within [`MAX_EVENTS`];
/// returns whether any were left out.
fn cap(events: &mut Vec<SceneEvent>, given: usize) -> bool {
    let room = MAX_EVENTS.saturating_sub(given);
    let capped = events.len() > room;
    events.truncate(room);
    capped
}

/// Drag coefficient of a hailstone, a rough sphere (the drag equation's `C_d`).
const HAIL_DRAG: f64 = 0.6;

/// Density of hail (ice with air in it) and of air, kg/m³.
const HAIL_DENSITY: f64 = 900.0;
const AIR_DENSITY: f64 = 1.2;

/// Terminal speed of a drop, m/s: for hail the drag equation, `v = sqrt(4 g d rho_ice /
/// (3 C_d rho_air))` (13 m/s for 1 cm); for rain Atlas, Srivastava and Sekhon (1973),
/// `v = 9.65 - 10.3 exp(-0.6 d)` with `d` in mm (6.5 m/s for 2 mm).
pub fn terminal_speed_m_per_s(kind: DropKind, diameter_m: f64) -> f64 {
    match kind {
        DropKind::Hail => {
            (4.0 * 9.81 * diameter_m * HAIL_DENSITY / (3.0 * HAIL_DRAG * AIR_DENSITY)).sqrt()
        }
        DropKind::Rain => (9.65 - 10.3 * (-0.6 * diameter_m * 1e3).exp()).max(0.1),
    }
}

/// One drop: when it is let go, where, how large, how fast.
#[derive(Debug, Clone, Copy)]
struct Drop {
    time_s: f64,
    at: [f64; 3],
    speed_m_per_s: f64,
    /// Its level against the largest drop its emitter can let go: its mass, the cube of its
    /// diameter, at the same speed (the impulse).
    gain_db: f64,
}

/// Every emitter's drops, in time order: Poisson arrivals at the rate, points uniform over the
/// rectangle, diameters uniform on a log scale.
fn drops(emitters: &[Emitter]) -> Vec<Drop> {
    let mut drops = Vec::new();
    for e in emitters {
        let mut rng = Rng::new(e.seed);
        let [lo, hi] = e.diameter_mm.unwrap_or(e.kind.default_diameter_mm());
        let mut t = e.start_s;
        loop {
            // 1 - u lies in (0, 1]: its logarithm is finite.
            t += -(1.0 - rng.uniform()).ln() / e.rate_per_s;
            if t >= e.start_s + e.duration_s {
                break;
            }
            let x = e.centre[0] + e.half_extents_m[0] * (2.0 * rng.uniform() - 1.0);
            let z = e.centre[2] + e.half_extents_m[1] * (2.0 * rng.uniform() - 1.0);
            let d_mm = lo * (hi / lo).powf(rng.uniform());
            drops.push(Drop {
                time_s: t,
                at: [x, e.centre[1], z],
                speed_m_per_s: terminal_speed_m_per_s(e.kind, d_mm * 1e-3),
                gain_db: 60.0 * (d_mm / hi).log10(),
            });
        }
    }
    drops.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
    drops
}

/// Casts a drop straight down; if it lands on an object that sounds, strikes it there at the
/// drop's speed along the surface's normal.
fn cast(world: &PhysicsWorld, scene: &SceneFile, d: &Drop, events: &mut Vec<SceneEvent>) {
    let ray = Ray::new(vector(d.at), Vector::new(0.0, -1.0, 0.0));
    let hit = world.cast_ray_and_get_normal(&ray, 1e6, true, QueryFilter::default());
    let Some((collider, hit)) = hit else { return };
    let Some(parent) = world.colliders[collider].parent() else {
        return;
    };
    let object = &scene.objects[world.bodies[parent].user_data as usize];
    let speed = d.speed_m_per_s * hit.normal.y.abs() as f64;
    if object.bank.is_none() || speed < MIN_IMPACT_M_PER_S {
        return;
    }
    events.push(SceneEvent {
        time_s: d.time_s + hit.time_of_impact as f64 / d.speed_m_per_s,
        object: object.name.clone(),
        impact: Some(Impact {
            speed_m_per_s: speed,
            gain_db: d.gain_db,
        }),
        contact: None,
    });
}
