//! Joint-level dynamics: each joint is a rigid body on its axis driven by a PD + feedforward
//! torque controller at 1 kHz (Franka's control rate), torque saturated at the URDF effort
//! limit, with viscous and Coulomb friction and hard stops at the position limits.
//!
//! Plant, per joint: `M(q) qdd = tau - b qd - f_c sign(qd)` with M from [`crate::inertia`]
//! (decoupled, gravity compensated). The controller uses a deliberately mismatched model
//! (`ModelMismatch`), as a real one would:
//! `tau = sat(M^ qdd_d + b^ qd_d + f_c^ sign(qd_d) + Kp (q_d - q) + Kd (qd_d - qd))`.
//!
//! Integration: semi-implicit Euler per 1 ms substep with the torque held (zero-order hold,
//! like a sampled controller) and Coulomb friction as a velocity-level impulse bounded by what
//! stops the joint, so a joint at rest under a torque below `f_c` stays at rest exactly.

use crate::description::N;
use crate::reference::Setpoint;

/// Coulomb friction [N m]: half the span of the sigmoid friction model identified by Gaz,
/// Cognetti, Oliva, Robuffo Giordano, De Luca, "Dynamic Identification of the Franka Emika
/// Panda Robot With Retrieval of Feasible Parameters Using Penalty-Based Optimization",
/// IEEE RA-L 4(4), 2019 (amplitudes phi_1 = 0.54615, 0.87224, 0.64068, 1.2794, 0.83904,
/// 0.30301, 0.56489 N m; the sigmoid spans phi_1 from full reverse to full forward motion).
pub const COULOMB: [f64; N] = [0.273075, 0.43612, 0.32034, 0.6397, 0.41952, 0.151505, 0.282445];

/// Viscous friction [N m s/rad]: estimate (not published for the Panda; of the order of the
/// sigmoid's slope in the identified model at a few rad/s).
pub const VISCOUS: [f64; N] = [0.2, 0.2, 0.2, 0.2, 0.1, 0.1, 0.1];

/// Default joint stiffness/damping: libfranka's joint impedance example gains
/// (examples/joint_impedance_control.cpp: k = 600, 600, 600, 600, 250, 150, 50;
/// d = 50, 50, 50, 50, 30, 25, 15).
pub const DEFAULT_KP: [f64; N] = [600.0, 600.0, 600.0, 600.0, 250.0, 150.0, 50.0];
pub const DEFAULT_KD: [f64; N] = [50.0, 50.0, 50.0, 50.0, 30.0, 25.0, 15.0];

/// Control period [ns] (1 kHz).
pub const CONTROL_PERIOD_NS: i64 = 1_000_000;

/// How the controller's model differs from the plant: factors applied to the plant's inertia,
/// Coulomb and viscous friction. Defaults: inertia under-estimated by 10 %, Coulomb friction
/// over-estimated by 20 %, viscous friction under-estimated by 30 % (typical identification
/// errors of the order Gaz et al. report between models; chosen, not measured).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ModelMismatch {
    pub inertia: f64,
    pub coulomb: f64,
    pub viscous: f64,
}

impl Default for ModelMismatch {
    fn default() -> Self {
        ModelMismatch { inertia: 0.9, coulomb: 1.2, viscous: 0.7 }
    }
}

/// Per-joint constants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointParams {
    pub lower: f64,
    pub upper: f64,
    pub effort: f64,
    pub kp: f64,
    pub kd: f64,
    pub coulomb: f64,
    pub viscous: f64,
}

/// Actual joint state and the last torque applied.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct JointState {
    pub q: [f64; N],
    pub qd: [f64; N],
    pub tau: [f64; N],
}

fn sign(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// Controller torque for one joint (saturated).
/// `actual` = (q, qd); `desired` = (q_d, qd_d, qdd_d).
pub fn control_torque(
    p: &JointParams,
    mm: &ModelMismatch,
    inertia: f64,
    actual: (f64, f64),
    desired: (f64, f64, f64),
) -> f64 {
    let ((q, qd), (q_d, qd_d, qdd_d)) = (actual, desired);
    let ff = mm.inertia * inertia * qdd_d + mm.viscous * p.viscous * qd_d + mm.coulomb * p.coulomb * sign(qd_d);
    let tau = ff + p.kp * (q_d - q) + p.kd * (qd_d - qd);
    tau.clamp(-p.effort, p.effort)
}

/// Advances one joint by `dt` under torque `tau` (plant).
pub fn integrate(p: &JointParams, inertia: f64, q: f64, qd: f64, tau: f64, dt: f64) -> (f64, f64) {
    let v_free = qd + dt * (tau - p.viscous * qd) / inertia;
    let dv_fric = dt * p.coulomb / inertia;
    let mut v = if v_free.abs() <= dv_fric { 0.0 } else { v_free - sign(v_free) * dv_fric };
    let mut q_new = q + dt * v;
    if q_new > p.upper {
        q_new = p.upper;
        v = v.min(0.0);
    } else if q_new < p.lower {
        q_new = p.lower;
        v = v.max(0.0);
    }
    (q_new, v)
}

/// One control period for all joints: torque from the setpoint and the state, then the plant
/// under that torque plus the external torque `ext` (a held load, not known to the controller).
pub fn step(
    params: &[JointParams; N],
    mm: &ModelMismatch,
    inertia: &[f64; N],
    s: &mut JointState,
    sp: &Setpoint,
    ext: &[f64; N],
    dt: f64,
) {
    for i in 0..N {
        let tau = control_torque(&params[i], mm, inertia[i], (s.q[i], s.qd[i]), (sp.q[i], sp.qd[i], sp.qdd[i]));
        let (q, v) = integrate(&params[i], inertia[i], s.q[i], s.qd[i], tau + ext[i], dt);
        s.q[i] = q;
        s.qd[i] = v;
        s.tau[i] = tau;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params() -> JointParams {
        JointParams { lower: -3.0, upper: 3.0, effort: 87.0, kp: 600.0, kd: 50.0, coulomb: 0.5, viscous: 0.2 }
    }

    #[test]
    fn stiction_holds_below_coulomb_and_moves_above() {
        let p = params();
        assert_eq!(integrate(&p, 1.0, 0.25, 0.0, 0.49, 1e-3), (0.25, 0.0));
        let (_, v) = integrate(&p, 1.0, 0.25, 0.0, 1.5, 1e-3);
        assert!((v - 1e-3).abs() < 1e-15);
    }

    /// Without friction and torque limits, a step response of the PD loop matches the analytic
    /// second-order response to within the discretization error.
    #[test]
    fn pd_step_response_matches_analytic() {
        let p = JointParams { coulomb: 0.0, viscous: 0.0, effort: 1e9, kp: 100.0, kd: 10.0, ..params() };
        let mm = ModelMismatch { inertia: 1.0, coulomb: 1.0, viscous: 1.0 };
        let (m, dt) = (1.0, 1e-4);
        let (mut q, mut v) = (0.0, 0.0);
        // q'' = 100 (1 - q) - 10 q' : wn = 10, zeta = 0.5.
        let (wn, z): (f64, f64) = (10.0, 0.5);
        let wd = wn * (1.0 - z * z).sqrt();
        for k in 1..=10_000 {
            let tau = control_torque(&p, &mm, m, (q, v), (1.0, 0.0, 0.0));
            (q, v) = integrate(&p, m, q, v, tau, dt);
            let t = k as f64 * dt;
            let exact = 1.0 - (-z * wn * t).exp() * ((wd * t).cos() + z * wn / wd * (wd * t).sin());
            assert!((q - exact).abs() < 2e-3, "t={t}: {q} vs {exact}");
        }
    }

    #[test]
    fn hard_stop_and_saturation() {
        let p = JointParams { effort: 5.0, ..params() };
        let mm = ModelMismatch::default();
        assert_eq!(control_torque(&p, &mm, 1.0, (0.0, 0.0), (10.0, 0.0, 0.0)), 5.0);
        let (q, v) = integrate(&p, 0.01, 2.999, 5.0, 0.0, 1e-3);
        assert_eq!((q, v), (3.0, 0.0));
    }
}
