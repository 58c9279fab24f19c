//! Command-line handling and the synthetic tomato-row scene shared by the benchmark
//! examples (`mod common;` in each).

use agrisim_manip::scene::{Obstacle, ObstacleKind};
use agrisim_manip::Rng;
use agrisim_robot::Shape;
use nalgebra::{Isometry3, Vector3};

/// The integer after `name` on the command line (`--n 200`), `default` when it is missing
/// or not a number.
pub fn arg(name: &str, default: u64) -> u64 {
    let a: Vec<String> = std::env::args().collect();
    a.iter().position(|x| x == name).and_then(|i| a.get(i + 1)).and_then(|v| v.parse().ok()).unwrap_or(default)
}

/// Tomato row at x = 0.8 m plus random boxes.
#[allow(dead_code)] // not every example plans
pub fn tomato_row(rng: &mut Rng) -> Vec<Obstacle> {
    let mut v = Vec::new();
    for k in 0..9 {
        let y = -1.0 + 0.25 * k as f64 + 0.05 * (rng.uniform() - 0.5);
        v.push(Obstacle::new(
            format!("stem_{k}"),
            Shape::Cylinder { radius: 0.012, length: 2.5 },
            Isometry3::translation(0.8, y, 1.25),
            ObstacleKind::Solid,
        ));
    }
    let along_y = Isometry3::rotation(Vector3::x() * std::f64::consts::FRAC_PI_2);
    v.push(Obstacle::new(
        "wire",
        Shape::Box { size: [0.01, 3.0, 0.01] },
        Isometry3::translation(0.8, 0.0, 1.9),
        ObstacleKind::Solid,
    ));
    for (i, x) in [0.6, 0.95].iter().enumerate() {
        v.push(Obstacle::new(
            format!("pipe_{i}"),
            Shape::Cylinder { radius: 0.03, length: 3.0 },
            Isometry3::translation(*x, 0.0, 0.15) * along_y,
            ObstacleKind::Solid,
        ));
    }
    for i in 0..3 {
        let s = [0.05 + 0.1 * rng.uniform(), 0.05 + 0.1 * rng.uniform(), 0.05 + 0.1 * rng.uniform()];
        let p =
            Isometry3::translation(0.75 + 0.2 * rng.uniform(), -0.9 + 1.8 * rng.uniform(), 0.6 + 0.9 * rng.uniform());
        v.push(Obstacle::new(format!("box_{i}"), Shape::Box { size: s }, p, ObstacleKind::Solid));
    }
    // Leaves: soft, ignored by the planner.
    for i in 0..6 {
        let p =
            Isometry3::translation(0.7 + 0.1 * rng.uniform(), -0.9 + 1.8 * rng.uniform(), 0.6 + 0.9 * rng.uniform());
        v.push(Obstacle::new(format!("leaf_{i}"), Shape::Box { size: [0.15, 0.15, 0.005] }, p, ObstacleKind::Soft));
    }
    v
}
