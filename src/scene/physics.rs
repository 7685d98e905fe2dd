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
    ColliderBuilder, ColliderHandle, PairContacts, PhysicsWorld, RigidBodyBuilder, RigidBodyHandle,
    SharedShape,
};

use super::format::{Body, Collider, Impact, SceneEvent, SceneFile};
use crate::bank::validate::Problem;

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
    let physics = scene
        .physics
        .expect("only scenes with physics are simulated");
    world.gravity = vector(physics.gravity_m_per_s2);
    world.integration_parameters.dt = physics.step_s as f32;
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

/// Runs the scene's physics for its duration and returns the impacts on objects that sound.
pub fn simulate(scene: &SceneFile) -> Simulated {
    let Some(physics) = scene.physics else {
        return Simulated::default();
    };
    let (mut world, handles) = build(scene);
    let steps = (physics.duration_s / physics.step_s).round() as usize;
    let mut motions: Vec<Option<Motion>> = vec![None; scene.objects.len()];
    let mut touching: HashSet<(ColliderHandle, ColliderHandle)> = HashSet::new();
    let mut now_touching = HashSet::new();
    let mut events = Vec::new();
    for step in 0..steps {
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
        now_touching.clear();
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
            let velocity = |o: usize| motions[o].map_or(Vector::ZERO, |m| m.at(point));
            let closing = ((velocity(o1) - velocity(o2)).dot(normal)) as f64;
            let threshold = if touching.contains(&key) {
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
            let time_s = (step_start_s + gap as f64 / closing)
                .clamp(step_start_s - physics.step_s, step_start_s + physics.step_s)
                .max(0.0);
            for o in [o1, o2] {
                if scene.objects[o].bank.is_some() {
                    events.push(SceneEvent {
                        time_s,
                        object: scene.objects[o].name.clone(),
                        impact: Some(Impact {
                            speed_m_per_s: closing.min(super::format::MAX_SPEED_M_PER_S),
                        }),
                        contact: None,
                    });
                }
            }
        }
        std::mem::swap(&mut touching, &mut now_touching);
    }
    Simulated { events, steps }
}
