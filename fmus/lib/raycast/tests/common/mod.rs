//! Helpers shared by the ray-casting tests.

use agrisim_math::Rng;
use agrisim_scene::{Kind, Object, Placement, Shape};

pub fn unit(v: [f64; 3]) -> [f64; 3] {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    [v[0] / n, v[1] / n, v[2] / n]
}

/// Random solids with random rotations (tilted cylinders, rotated boxes) in a 10 m cube.
pub fn random_solids(rng: &mut Rng, n: usize) -> Vec<Object> {
    (0..n)
        .map(|i| {
            let shape = match i % 3 {
                0 => Shape::Sphere { radius: rng.range(0.02, 0.6) },
                1 => Shape::Box { half: [rng.range(0.01, 0.8), rng.range(0.01, 0.8), rng.range(0.01, 0.8)] },
                _ => Shape::Cylinder { radius: rng.range(0.005, 0.4), half_height: rng.range(0.02, 1.5) },
            };
            let axis = unit([rng.scene_normal(), rng.scene_normal(), rng.scene_normal()]);
            // A third stay axis-aligned (the specialised code paths).
            let angle = if i % 7 < 2 {
                0.0
            } else if i % 7 == 2 {
                std::f64::consts::FRAC_PI_2
            } else {
                rng.range(-3.2, 3.2)
            };
            let axis = if i % 7 == 2 { [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]][i % 3] } else { axis };
            let t = [rng.range(0.0, 10.0), rng.range(0.0, 10.0), rng.range(0.0, 10.0)];
            Object {
                id: i as u32,
                name: format!("s{i}"),
                kind: Kind::Obstacle,
                shape,
                placement: Placement::axis_angle(t, axis, angle),
            }
        })
        .collect()
}
