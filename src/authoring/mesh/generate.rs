//! Closed surfaces made by code: boxes, solids of revolution (discs, cups, bells) and extruded
//! outlines (tuning forks, brackets), for tests and for the factory's meshed banks.

use super::surface::Surface;

/// A surface behind a meshed factory bank: its file and the code that makes it.
pub struct FactoryMesh {
    /// File name in `presets/meshes/`.
    pub file: &'static str,
    /// The generator.
    pub surface: fn() -> Surface,
}

/// The surfaces behind the meshed factory banks (`tests/mesh_presets.rs` checks each file
/// against its generator).
pub const FACTORY_MESHES: [FactoryMesh; 3] = [
    FactoryMesh {
        file: "cup.obj",
        surface: cup,
    },
    FactoryMesh {
        file: "tuning-fork.obj",
        surface: tuning_fork,
    },
    FactoryMesh {
        file: "bell.obj",
        surface: bell,
    },
];

/// A box from the origin to `size_m`, faces outward.
pub fn cuboid(size_m: [f64; 3]) -> Surface {
    let [x, y, z] = size_m;
    let vertices = (0..8)
        .map(|c| {
            [
                if c & 1 == 1 { x } else { 0.0 },
                if c & 2 == 2 { y } else { 0.0 },
                if c & 4 == 4 { z } else { 0.0 },
            ]
        })
        .collect();
    // Each face as a quad, counter-clockwise seen from outside.
    let quads = [
        [0, 2, 3, 1], // z = 0
        [4, 5, 7, 6], // z = top
        [0, 1, 5, 4], // y = 0
        [2, 6, 7, 3], // y = top
        [0, 4, 6, 2], // x = 0
        [1, 3, 7, 5], // x = top
    ];
    let triangles = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    Surface {
        vertices,
        triangles,
    }
}

/// The solid swept by revolving the closed outline `profile` (points `(r, z)`, `r >= 0`, the
/// first and last on the axis `r = 0`, in either turning sense) about the z axis, in `segments`
/// steps around.
pub fn revolve(profile: &[[f64; 2]], segments: usize) -> Surface {
    let n = profile.len();
    assert!(n >= 3 && segments >= 3, "a profile of 3 points, 3 segments");
    assert!(
        profile[0][0] == 0.0 && profile[n - 1][0] == 0.0,
        "ends on the axis"
    );
    let mut vertices = Vec::new();
    // Index of each profile point's ring (one vertex for points on the axis).
    let mut ring = Vec::with_capacity(n);
    for p in profile {
        ring.push(vertices.len() as u32);
        if p[0] == 0.0 {
            vertices.push([0.0, 0.0, p[1]]);
        } else {
            for s in 0..segments {
                let angle = std::f64::consts::TAU * s as f64 / segments as f64;
                vertices.push([p[0] * angle.cos(), p[0] * angle.sin(), p[1]]);
            }
        }
    }
    let at = |i: usize, s: usize| {
        if profile[i][0] == 0.0 {
            ring[i]
        } else {
            ring[i] + (s % segments) as u32
        }
    };
    let mut triangles = Vec::new();
    for i in 0..n - 1 {
        for s in 0..segments {
            let (a, b) = (at(i, s), at(i, s + 1));
            let (c, d) = (at(i + 1, s + 1), at(i + 1, s));
            if profile[i][0] != 0.0 {
                triangles.push([a, d, b]);
            }
            if profile[i + 1][0] != 0.0 {
                triangles.push([b, d, c]);
            }
        }
    }
    outward(Surface {
        vertices,
        triangles,
    })
}

/// The prism of the simple polygon `outline` (points `(x, z)`, in either turning sense) from
/// `y = 0` to `y = depth_m`.
pub fn extrude(outline: &[[f64; 2]], depth_m: f64) -> Surface {
    let n = outline.len();
    let mut vertices = Vec::with_capacity(2 * n);
    for y in [0.0, depth_m] {
        for p in outline {
            vertices.push([p[0], y, p[1]]);
        }
    }
    let mut triangles = Vec::new();
    for [a, b, c] in ear_clip(outline) {
        triangles.push([a, b, c]);
        triangles.push([a + n as u32, c + n as u32, b + n as u32]);
    }
    for i in 0..n {
        let j = (i + 1) % n;
        // The bottom cap runs i -> j, so this side runs j -> i.
        let (i0, j0, i1, j1) = (i as u32, j as u32, (i + n) as u32, (j + n) as u32);
        triangles.push([j0, i0, i1]);
        triangles.push([j0, i1, j1]);
    }
    outward(Surface {
        vertices,
        triangles,
    })
}

/// Points `(r, z)` in millimetres as metres.
fn mm(points: &[[f64; 2]]) -> Vec<[f64; 2]> {
    points.iter().map(|p| [p[0] * 1e-3, p[1] * 1e-3]).collect()
}

/// A cup without a handle: 80 mm across and 90 mm tall, walls 4 mm thick on a 6 mm base
/// (a porcelain mug's proportions), open at the top, standing on z = 0.
pub fn cup() -> Surface {
    revolve(
        &mm(&[
            [0.0, 0.0],
            [38.0, 0.0],
            [40.0, 2.0],
            [40.0, 90.0],
            [36.0, 90.0],
            [36.0, 6.0],
            [0.0, 6.0],
        ]),
        96,
    )
}

/// A tuning fork 6 mm thick (along y): two prongs 6 mm wide and 80 mm long, 8 mm apart, on a
/// 6 mm bridge and a 40 mm stem 8 mm wide, in the x-z plane with the stem along -z.
pub fn tuning_fork() -> Surface {
    let outline = mm(&[
        [-4.0, -40.0],
        [4.0, -40.0],
        [4.0, 0.0],
        [10.0, 0.0],
        [10.0, 86.0],
        [4.0, 86.0],
        [4.0, 6.0],
        [-4.0, 6.0],
        [-4.0, 86.0],
        [-10.0, 86.0],
        [-10.0, 0.0],
        [-4.0, 0.0],
    ]);
    extrude(&outline, 6e-3)
}

/// A small bell 120 mm across the mouth and 100 mm tall, its wall thickening from 5 mm at the
/// waist to 8 mm at the sound bow (the lip), crown closed, mouth down on z = 0.
pub fn bell() -> Surface {
    revolve(
        &mm(&[
            [0.0, 100.0],
            [24.0, 100.0],
            [30.0, 96.0],
            [32.0, 85.0],
            [33.0, 70.0],
            [36.0, 50.0],
            [42.0, 30.0],
            [50.0, 14.0],
            [58.0, 4.0],
            [60.0, 0.0],
            [54.0, 0.0],
            [47.0, 10.0],
            [37.0, 27.0],
            [31.0, 48.0],
            [28.0, 68.0],
            [27.0, 84.0],
            [23.0, 92.0],
            [0.0, 92.0],
        ]),
        96,
    )
}

/// `surface` with its triangles flipped if they face inward.
fn outward(mut surface: Surface) -> Surface {
    if surface.signed_volume_m3() < 0.0 {
        for t in &mut surface.triangles {
            t.swap(1, 2);
        }
    }
    surface
}

/// Triangles of a simple polygon by ear clipping, all turning the polygon's own way.
fn ear_clip(outline: &[[f64; 2]]) -> Vec<[u32; 3]> {
    let area2: f64 = (0..outline.len())
        .map(|i| {
            let (p, q) = (outline[i], outline[(i + 1) % outline.len()]);
            p[0] * q[1] - q[0] * p[1]
        })
        .sum();
    let sense = area2.signum();
    let turn = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| {
        ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])) * sense
    };
    let mut left: Vec<usize> = (0..outline.len()).collect();
    let mut triangles = Vec::new();
    while left.len() > 3 {
        let m = left.len();
        let ear = (0..m).find(|&k| {
            let (a, b, c) = (left[(k + m - 1) % m], left[k], left[(k + 1) % m]);
            let (pa, pb, pc) = (outline[a], outline[b], outline[c]);
            turn(pa, pb, pc) > 0.0
                && left.iter().all(|&o| {
                    o == a
                        || o == b
                        || o == c
                        || turn(pa, pb, outline[o]) < 0.0
                        || turn(pb, pc, outline[o]) < 0.0
                        || turn(pc, pa, outline[o]) < 0.0
                })
        });
        let k = ear.expect("a simple polygon always has an ear");
        let (a, b, c) = (left[(k + m - 1) % m], left[k], left[(k + 1) % m]);
        triangles.push([a as u32, b as u32, c as u32]);
        left.remove(k);
    }
    triangles.push([left[0] as u32, left[1] as u32, left[2] as u32]);
    triangles
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn generated_solids_are_closed_with_the_right_volume() {
        let bar = cuboid([0.3, 0.03, 0.01]);
        bar.check().unwrap();
        assert!((bar.signed_volume_m3() / 9e-5 - 1.0).abs() < 1e-12);

        let disc = revolve(&[[0.0, 0.0], [0.1, 0.0], [0.1, 0.002], [0.0, 0.002]], 64);
        disc.check().unwrap();
        // A 64-gon's area is (64/2) sin(2 pi/64) r^2.
        let expected = 32.0 * (std::f64::consts::TAU / 64.0).sin() * 0.01 * 0.002;
        assert!((disc.signed_volume_m3() / expected - 1.0).abs() < 1e-9);

        let u = extrude(
            &[
                [0.0, 0.0],
                [0.03, 0.0],
                [0.03, 0.05],
                [0.02, 0.05],
                [0.02, 0.01],
                [0.01, 0.01],
                [0.01, 0.05],
                [0.0, 0.05],
            ],
            0.005,
        );
        u.check().unwrap();
        for (name, s) in [
            ("cup", cup()),
            ("tuning fork", tuning_fork()),
            ("bell", bell()),
        ] {
            s.check().unwrap_or_else(|e| panic!("{name}: {e}"));
        }
        let area = 0.03 * 0.05 - 0.01 * 0.04;
        assert!((u.signed_volume_m3() / (area * 0.005) - 1.0).abs() < 1e-9);
    }
}
