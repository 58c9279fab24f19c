//! The oscillator's exact solution, for checking importers and integrators against.
//!
//! Between kicks the motion is the free response of x'' + 2 zeta omega x' + omega^2 x = 0;
//! at the kick the velocity jumps by `kick_dv` and the free response starts again from there.

/// The FMU's parameters (defaults = its start values).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Params {
    /// Undamped natural frequency [rad/s], > 0.
    pub omega: f64,
    /// Damping ratio [1], >= 0 (< 1 under-, = 1 critically, > 1 over-damped).
    pub zeta: f64,
    /// Position at the start time [m].
    pub x0: f64,
    /// Velocity at the start time [m/s].
    pub v0: f64,
    /// Time of the velocity kick [s]; see [`kick_applies`].
    pub kick_time: f64,
    /// Velocity added at `kick_time` [m/s].
    pub kick_dv: f64,
}

impl Default for Params {
    fn default() -> Self {
        Params { omega: 2.0, zeta: 0.1, x0: 1.0, v0: 0.0, kick_time: 1.0, kick_dv: 0.5 }
    }
}

/// Whether the kick happens in a run starting at `t0`: `kick_time` is positive and not
/// before the start (a kick at exactly `t0` is applied in the initial event iteration).
pub fn kick_applies(p: &Params, t0: f64) -> bool {
    p.kick_time > 0.0 && p.kick_time >= t0 && p.kick_time.is_finite()
}

/// `(e^{-a t} c(t), e^{-a t} s(t))` with a = zeta omega, where c and s solve the undamped
/// part: c = cos, s = sin(w t)/w (w = omega sqrt(1 - zeta^2)) below critical damping,
/// c = 1, s = t at it, cosh / sinh above. Written so that neither near-critical damping
/// (w -> 0) nor strong over-damping (e^{-at} cosh overflowing) loses accuracy.
fn basis(omega: f64, zeta: f64, t: f64) -> (f64, f64) {
    let a = zeta * omega;
    if zeta < 1.0 {
        let w = omega * ((1.0 - zeta) * (1.0 + zeta)).sqrt();
        let y = w * t;
        let sinc = if y == 0.0 { 1.0 } else { y.sin() / y };
        let e = (-a * t).exp();
        (e * y.cos(), e * t * sinc)
    } else if zeta == 1.0 {
        let e = (-a * t).exp();
        (e, e * t)
    } else {
        let mu = omega * ((zeta - 1.0) * (zeta + 1.0)).sqrt();
        let y = mu * t;
        if y < 1.0 {
            let e = (-a * t).exp();
            let sinhc = if y == 0.0 { 1.0 } else { y.sinh() / y };
            (e * y.cosh(), e * t * sinhc)
        } else {
            // mu - a = -omega / (zeta + sqrt(zeta^2 - 1)), without cancellation.
            let slow = (-omega / (zeta + ((zeta - 1.0) * (zeta + 1.0)).sqrt()) * t).exp();
            let fast = (-(mu + a) * t).exp();
            ((slow + fast) / 2.0, (slow - fast) / (2.0 * mu))
        }
    }
}

/// Free response: position and velocity a time `dt` >= 0 after (x0, v0), no kick.
pub fn free_response(omega: f64, zeta: f64, x0: f64, v0: f64, dt: f64) -> (f64, f64) {
    let a = zeta * omega;
    let (c, s) = basis(omega, zeta, dt);
    (x0 * c + (v0 + a * x0) * s, v0 * c - (omega * omega * x0 + a * v0) * s)
}

/// Position and velocity at time `t` >= `t0` of a run started at `t0` with `p`.
/// Right-continuous at the kick: at `t == kick_time` the kick has happened.
pub fn solution(p: &Params, t0: f64, t: f64) -> (f64, f64) {
    if kick_applies(p, t0) && t >= p.kick_time {
        let (xk, vk) = free_response(p.omega, p.zeta, p.x0, p.v0, p.kick_time - t0);
        free_response(p.omega, p.zeta, xk, vk + p.kick_dv, t - p.kick_time)
    } else {
        free_response(p.omega, p.zeta, p.x0, p.v0, t - t0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Residual of the ODE by central differences, relative to the solution's scale.
    fn residual(omega: f64, zeta: f64, t: f64) -> f64 {
        let h = 1e-4;
        let x = |t| free_response(omega, zeta, 0.7, -1.3, t).0;
        let v = |t| free_response(omega, zeta, 0.7, -1.3, t).1;
        let acc = (x(t + h) - 2.0 * x(t) + x(t - h)) / (h * h);
        let vel = (x(t + h) - x(t - h)) / (2.0 * h);
        let scale = 1.0 + omega * omega;
        let ode = (acc + 2.0 * zeta * omega * v(t) + omega * omega * x(t)).abs() / scale;
        ode.max((vel - v(t)).abs() / scale)
    }

    #[test]
    fn free_response_solves_the_ode_in_every_damping_regime() {
        for &zeta in &[0.0, 0.1, 0.5, 1.0 - 1e-9, 1.0, 1.0 + 1e-9, 1.5, 20.0] {
            for &t in &[0.3, 1.0, 2.5] {
                let r = residual(2.0, zeta, t);
                assert!(r < 1e-6, "zeta {zeta} t {t}: residual {r}");
            }
            assert_eq!(free_response(2.0, zeta, 0.7, -1.3, 0.0), (0.7, -1.3));
        }
    }

    #[test]
    fn regimes_meet_continuously_at_critical_damping() {
        let at = free_response(3.0, 1.0, 1.0, 0.5, 0.8);
        for zeta in [1.0 - 1e-12, 1.0 + 1e-12] {
            let (x, v) = free_response(3.0, zeta, 1.0, 0.5, 0.8);
            assert!((x - at.0).abs() < 1e-10 && (v - at.1).abs() < 1e-10, "{zeta}: {x} {v} vs {at:?}");
        }
    }

    #[test]
    fn undamped_motion_is_a_cosine_and_strong_damping_does_not_overflow() {
        let (x, v) = free_response(2.0, 0.0, 1.0, 0.0, 1.7);
        assert!((x - (3.4f64).cos()).abs() < 1e-15 && (v + 2.0 * (3.4f64).sin()).abs() < 1e-14);
        let (x, v) = free_response(1.0, 1e6, 1.0, 0.0, 1e3);
        assert!(x.is_finite() && v.is_finite() && x > 0.99 && x < 1.0, "{x} {v}");
    }

    #[test]
    fn the_kick_adds_velocity_at_kick_time_only() {
        let p = Params::default();
        let before = solution(&p, 0.0, p.kick_time - 1e-12);
        let after = solution(&p, 0.0, p.kick_time);
        assert!((after.0 - before.0).abs() < 1e-9);
        assert!((after.1 - before.1 - p.kick_dv).abs() < 1e-9);
        let off = Params { kick_time: 0.0, ..p };
        assert_eq!(solution(&off, 0.0, 2.0), free_response(p.omega, p.zeta, p.x0, p.v0, 2.0));
        // A kick before the start never happens; one at the start does.
        assert!(!kick_applies(&p, 1.5));
        assert_eq!(solution(&p, 1.0, 1.0), (p.x0, p.v0 + p.kick_dv));
    }
}
