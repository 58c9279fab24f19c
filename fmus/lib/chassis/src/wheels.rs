//! Four independently steered and driven wheels: inverse kinematics (twist -> per-wheel
//! steering angle and speed) and forward kinematics (actual wheel states -> twist).

use crate::se2::Twist2;
use agrisim_math::wrap_angle_euclid;
use std::f64::consts::PI;

/// Wheel order used everywhere (ports, arrays): front-left, front-right, rear-left, rear-right.
pub const WHEEL_NAMES: [&str; 4] = ["fl", "fr", "rl", "rr"];

/// Where the four wheels sit in the base frame and how large they are.
#[derive(Clone, Copy, Debug, serde::Serialize, serde::Deserialize)]
pub struct WheelLayout {
    /// Wheel contact points (x, y) in base_link [m].
    pub pos: [(f64, f64); 4],
    pub radius: f64,
}

/// State of one wheel: steering angle [rad] and spin rate [rad/s].
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WheelState {
    pub steer: f64,
    pub spin: f64,
}

impl WheelLayout {
    /// A rectangular layout: `wheel_base` between axles, `track` between left and right wheels.
    pub fn rectangular(wheel_base: f64, track: f64, radius: f64) -> WheelLayout {
        let (a, b) = (wheel_base / 2.0, track / 2.0);
        WheelLayout { pos: [(a, b), (a, -b), (-a, b), (-a, -b)], radius }
    }

    /// Velocity of each wheel's contact point when the base moves with `t`.
    pub fn contact_velocities(&self, t: Twist2) -> [(f64, f64); 4] {
        self.pos.map(|(x, y)| (t.vx - t.wz * y, t.vy + t.wz * x))
    }

    /// Steering and spin targets for twist `t`, given the current steering angles.
    ///
    /// Each wheel takes whichever of the two equivalent solutions (angle, +speed) and
    /// (angle ± π, -speed) lies within `steer_max` and closest to its current angle, so a
    /// wheel never turns more than 90° to follow a reversal. A wheel with no speed to make
    /// keeps its angle (no pointless steering at standstill).
    pub fn inverse(&self, t: Twist2, current: &[WheelState; 4], steer_max: f64) -> [WheelState; 4] {
        let v = self.contact_velocities(t);
        std::array::from_fn(|i| {
            let (vx, vy) = v[i];
            let speed = vx.hypot(vy) / self.radius;
            if speed < 1e-12 {
                return WheelState { steer: current[i].steer, spin: 0.0 };
            }
            let a = vy.atan2(vx);
            let candidates = [(a, speed), (wrap_angle_euclid(a + PI), -speed), (wrap_angle_euclid(a - PI), -speed)];
            candidates
                .into_iter()
                .filter(|(s, _)| s.abs() <= steer_max + 1e-12)
                .min_by(|p, q| {
                    let dp = (p.0 - current[i].steer).abs();
                    let dq = (q.0 - current[i].steer).abs();
                    dp.total_cmp(&dq)
                })
                .map(|(steer, spin)| WheelState { steer, spin })
                .unwrap_or(WheelState { steer: a.clamp(-steer_max, steer_max), spin: speed })
        })
    }

    /// Least-squares base twist from the wheels' contact velocities (each wheel contributes two
    /// equations; solved through the 3x3 normal equations, valid for any layout).
    pub fn forward_from_velocities(&self, v: &[(f64, f64); 4]) -> Twist2 {
        // Unknowns (vx, vy, wz); rows: [1 0 -y_i] · u = v_ix, [0 1 x_i] · u = v_iy.
        let (mut sx, mut sy, mut sr2) = (0.0, 0.0, 0.0);
        let (mut bx, mut by, mut bw) = (0.0, 0.0, 0.0);
        for (i, &(x, y)) in self.pos.iter().enumerate() {
            sx += x;
            sy += y;
            sr2 += x * x + y * y;
            bx += v[i].0;
            by += v[i].1;
            bw += -y * v[i].0 + x * v[i].1;
        }
        let n = 4.0;
        let a = [[n, 0.0, -sy], [0.0, n, sx], [-sy, sx, sr2]];
        let [vx, vy, wz] = solve3(a, [bx, by, bw]);
        Twist2 { vx, vy, wz }
    }

    /// Contact velocity of each wheel from its steering angle and spin.
    pub fn wheel_velocities(&self, w: &[WheelState; 4]) -> [(f64, f64); 4] {
        w.map(|s| {
            let v = s.spin * self.radius;
            (v * s.steer.cos(), v * s.steer.sin())
        })
    }

    pub fn forward(&self, w: &[WheelState; 4]) -> Twist2 {
        self.forward_from_velocities(&self.wheel_velocities(w))
    }
}

/// Solves a 3x3 linear system by Cramer's rule (the matrix here is symmetric positive definite).
fn solve3(a: [[f64; 3]; 3], b: [f64; 3]) -> [f64; 3] {
    let det = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(a);
    std::array::from_fn(|k| {
        let mut m = a;
        for r in 0..3 {
            m[r][k] = b[r];
        }
        det(m) / d
    })
}

/// Moves `x` toward `target` by at most `max_delta`.
pub fn approach(x: f64, target: f64, max_delta: f64) -> f64 {
    x + (target - x).clamp(-max_delta, max_delta)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn layout() -> WheelLayout {
        WheelLayout::rectangular(1.0, 0.8, 0.1)
    }

    /// IK followed by FK returns the commanded twist, over many random twists.
    #[test]
    fn inverse_then_forward_is_identity() {
        let l = layout();
        let mut rng = agrisim_math::Rng::new(3);
        for _ in 0..10_000 {
            let t = Twist2 { vx: rng.normal(), vy: rng.normal(), wz: rng.normal() };
            let cur: [WheelState; 4] =
                std::array::from_fn(|_| WheelState { steer: (rng.uniform() - 0.5) * PI, spin: 0.0 });
            let w = l.inverse(t, &cur, PI / 2.0);
            for s in &w {
                assert!(s.steer.abs() <= PI / 2.0 + 1e-9);
            }
            let back = l.forward(&w);
            assert!(
                (back.vx - t.vx).abs() < 1e-9 && (back.vy - t.vy).abs() < 1e-9 && (back.wz - t.wz).abs() < 1e-9,
                "{t:?} -> {back:?}"
            );
        }
    }

    #[test]
    fn pure_rotation_steers_wheels_tangentially() {
        let l = layout();
        let w = l.inverse(Twist2 { vx: 0.0, vy: 0.0, wz: 1.0 }, &[WheelState::default(); 4], PI / 2.0);
        // front-left wheel at (0.5, 0.4): tangent direction is (-0.4, 0.5)
        let (vx, vy) = l.wheel_velocities(&w)[0];
        assert!((vx + 0.4).abs() < 1e-12 && (vy - 0.5).abs() < 1e-12);
    }
}
