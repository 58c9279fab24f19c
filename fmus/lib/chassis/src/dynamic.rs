//! Dynamic drive: rigid base with mass and yaw inertia, wheel spin inertia, torque-limited
//! speed controllers, and tyre forces from slip velocity saturated on the friction circle
//! (a brush-like linear tyre: F = -k v_slip, |F| <= mu N). Loads shift with acceleration and
//! the payload's height. Integrated with semi-implicit Euler substeps of at most 0.5 ms.

use crate::chassis::{Drive, StepInput, StepOutput};
use crate::ports::*;
use crate::se2::Twist2;
use crate::wheels::WheelState;
use agrisim_fmi::Store;

const G: f64 = 9.80665;
const MAX_SUBSTEP: f64 = 5e-4;
/// Radius of gyration assumed for the payload about the base's vertical axis [m].
const PAYLOAD_GYRATION: f64 = 0.25;

#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct DynamicDrive {
    mass: f64,
    inertia_z: f64,
    cg_height: f64,
    wheel_inertia: f64,
    torque_max: f64,
    gain: f64,
    mu: f64,
    stiffness: f64,
    wheel_base: f64,
    track: f64,
    /// Body-frame acceleration of the last substep, for load transfer.
    accel: (f64, f64),
}

fn finite_positive(io: &Store, i: usize) -> Result<f64, String> {
    let v = io.f64(i);
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(format!("parameter {} must be positive and finite, got {v}", VARIABLES[i].name))
    }
}

impl Drive for DynamicDrive {
    const NAME: &'static str = "ChassisDynamic";
    const DESCRIPTION: &'static str = "4-wheel-steering omnidirectional base, dynamic model: mass/inertia, torque-limited wheel motors, tyre slip and friction, load transfer; wheel odometry";

    /// 10 s is 20,000 substeps: longer steps would stall the importer, so they are refused.
    const MAX_STEP: f64 = 10.0;

    fn initialize(&mut self, io: &Store) -> Result<(), String> {
        *self = DynamicDrive {
            mass: finite_positive(io, MASS)?,
            inertia_z: finite_positive(io, INERTIA_Z)?,
            cg_height: io.f64(CG_HEIGHT),
            wheel_inertia: finite_positive(io, WHEEL_INERTIA)?,
            torque_max: finite_positive(io, TORQUE_MAX)?,
            gain: finite_positive(io, SPEED_GAIN)?,
            mu: finite_positive(io, MU)?,
            stiffness: finite_positive(io, SLIP_STIFFNESS)?,
            wheel_base: io.f64(WHEEL_BASE),
            track: io.f64(TRACK),
            accel: (0.0, 0.0),
        };
        Ok(())
    }

    fn step(&mut self, wheels: &mut [WheelState; 4], base: Twist2, input: StepInput<'_>) -> StepOutput {
        let (payload, payload_h) = (input.io.f64(PAYLOAD_MASS).max(0.0), input.io.f64(PAYLOAD_HEIGHT));
        let m = self.mass + payload;
        let iz = self.inertia_z + payload * PAYLOAD_GYRATION * PAYLOAD_GYRATION;
        let h_cg = (self.mass * self.cg_height + payload * payload_h) / m;
        let r = input.layout.radius;
        let n = (input.h / MAX_SUBSTEP).ceil().max(1.0) as usize;
        let dt = input.h / n as f64;
        let start = *wheels;
        let mut v = base;
        let mut sum = Twist2::default();
        let mut travel = [(0.0, 0.0); 4];
        for k in 1..=n {
            let f = k as f64 / n as f64;
            // Longitudinal and lateral load transfer (front wheels are 0,1; left wheels 0,2).
            let dn_long = m * self.accel.0 * h_cg / self.wheel_base / 2.0;
            let dn_lat = m * self.accel.1 * h_cg / self.track / 2.0;
            let (mut fx, mut fy, mut mz) = (0.0, 0.0, 0.0);
            for i in 0..4 {
                let w = &mut wheels[i];
                w.steer = start[i].steer + (input.reference[i].steer - start[i].steer) * f;
                // Set-points arrive once per step and are held (zero-order hold, like a real drive bus).
                let spin_ref = input.reference[i].spin;
                let (x, y) = input.layout.pos[i];
                let front = if i < 2 { -1.0 } else { 1.0 };
                let left = if i % 2 == 0 { -1.0 } else { 1.0 };
                let load = (m * G / 4.0 + front * dn_long + left * dn_lat).max(0.0);
                let (s, c) = w.steer.sin_cos();
                let (cx, cy) = (v.vx - v.wz * y, v.vy + v.wz * x);
                let (vl, vt) = (cx * c + cy * s, -cx * s + cy * c);
                let (mut fl, mut ft) = (-self.stiffness * (vl - r * w.spin), -self.stiffness * vt);
                let mag = fl.hypot(ft);
                let limit = self.mu * load;
                if mag > limit {
                    fl *= limit / mag;
                    ft *= limit / mag;
                }
                let torque = (self.gain * (spin_ref - w.spin)).clamp(-self.torque_max, self.torque_max);
                // The floor pushes the base with +fl and the tyre's contact patch with -fl.
                w.spin += dt * (torque - r * fl) / self.wheel_inertia;
                let (ws, wc) = w.steer.sin_cos();
                travel[i].0 += r * w.spin * wc;
                travel[i].1 += r * w.spin * ws;
                let (bx, by) = (fl * c - ft * s, fl * s + ft * c);
                fx += bx;
                fy += by;
                mz += x * by - y * bx;
            }
            self.accel = (fx / m, fy / m);
            let (vx, vy) = (v.vx, v.vy);
            v.vx += dt * (fx / m + v.wz * vy);
            v.vy += dt * (fy / m - v.wz * vx);
            v.wz += dt * mz / iz;
            sum.vx += v.vx;
            sum.vy += v.vy;
            sum.wz += v.wz;
        }
        let k = n as f64;
        StepOutput {
            mean: Twist2 { vx: sum.vx / k, vy: sum.vy / k, wz: sum.wz / k },
            end: v,
            wheel_travel: travel.map(|(x, y)| (x / k, y / k)),
        }
    }
}

/// The dynamic chassis model (FMU `ChassisDynamic`).
pub type ChassisDynamic = crate::chassis::Chassis<DynamicDrive>;
