//! Time-optimal motion of a point mass under velocity and acceleration limits, from any
//! state (p0, v0) to rest at a target: a sequence of constant-acceleration segments that is
//! evaluated in closed form, so the lift's trajectory is exact at every communication point.

/// A constant-acceleration segment.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
struct Segment {
    duration: f64,
    accel: f64,
}

/// A planned motion starting at time `t0`.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Profile {
    t0: f64,
    p0: f64,
    v0: f64,
    segments: Vec<Segment>,
}

impl Profile {
    /// At rest at `p` from `t0` on.
    pub fn hold(t0: f64, p: f64) -> Profile {
        Profile { t0, p0: p, v0: 0.0, segments: vec![] }
    }

    /// Plans from (p0, v0) at t0 to rest at `target`, with |v| <= vmax (vmax >= |v0|) and |a| <= amax.
    ///
    /// If the mass moves away from the target or cannot stop before it, it first brakes to
    /// rest (the time-optimal choice for the away case; for overshoot it is within one
    /// braking phase of optimal and keeps the profile simple), then makes a rest-to-target move.
    pub fn plan(t0: f64, p0: f64, v0: f64, target: f64, vmax: f64, amax: f64) -> Profile {
        let mut segments = vec![];
        let (mut p, mut v) = (p0, v0);
        let d = target - p;
        let stop_dist = v * v / (2.0 * amax);
        if v != 0.0 && (v * d < 0.0 || stop_dist > d.abs()) {
            let tb = v.abs() / amax;
            let a = -v.signum() * amax;
            segments.push(Segment { duration: tb, accel: a });
            p += v * tb + 0.5 * a * tb * tb;
            v = 0.0;
        }
        let d = target - p;
        let (s, dist, v0s) = (d.signum(), d.abs(), v.abs());
        if dist > 0.0 {
            // Peak speed: accelerate from v0s, decelerate to 0 within dist.
            let v_peak = (amax * dist + 0.5 * v0s * v0s).sqrt().min(vmax);
            let t_acc = (v_peak - v0s) / amax;
            let t_dec = v_peak / amax;
            let d_acc = (v_peak * v_peak - v0s * v0s) / (2.0 * amax);
            let d_dec = v_peak * v_peak / (2.0 * amax);
            let t_cruise = ((dist - d_acc - d_dec) / v_peak).max(0.0);
            for (duration, accel) in [(t_acc, s * amax), (t_cruise, 0.0), (t_dec, -s * amax)] {
                if duration > 0.0 {
                    segments.push(Segment { duration, accel });
                }
            }
        }
        Profile { t0, p0, v0, segments }
    }

    /// Position and velocity at time `t`.
    pub fn eval(&self, t: f64) -> (f64, f64) {
        let (mut p, mut v) = (self.p0, self.v0);
        let mut remaining = (t - self.t0).max(0.0);
        for s in &self.segments {
            let dt = remaining.min(s.duration);
            p += v * dt + 0.5 * s.accel * dt * dt;
            v += s.accel * dt;
            remaining -= dt;
            if remaining <= 0.0 {
                return (p, v);
            }
        }
        // Past the end: at rest (v is 0 up to rounding; report exactly 0).
        (p, if self.segments.is_empty() { v } else { 0.0 })
    }

    /// Time at which the motion ends.
    pub fn end_time(&self) -> f64 {
        self.t0 + self.segments.iter().map(|s| s.duration).sum::<f64>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trapezoid_from_rest() {
        // 1 m with vmax 0.2, amax 0.5: accel 0.4 s (0.04 m), cruise 4.6 s, decel 0.4 s.
        let p = Profile::plan(0.0, 0.0, 0.0, 1.0, 0.2, 0.5);
        assert!((p.end_time() - 5.4).abs() < 1e-12);
        let (x, v) = p.eval(0.4);
        assert!((x - 0.04).abs() < 1e-12 && (v - 0.2).abs() < 1e-12);
        let (x, v) = p.eval(10.0);
        assert!((x - 1.0).abs() < 1e-12 && v == 0.0);
    }

    /// Randomized: limits hold at every sample, and the motion ends at rest on the target.
    #[test]
    fn random_plans_respect_limits_and_arrive() {
        let mut state = 12345u64;
        let mut uni = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..5000 {
            let (vmax, amax) = (0.05 + uni(), 0.05 + 2.0 * uni());
            let (p0, target) = (uni() * 2.0 - 1.0, uni() * 2.0 - 1.0);
            let v0 = (uni() * 2.0 - 1.0) * vmax;
            let prof = Profile::plan(0.0, p0, v0, target, vmax, amax);
            let (pe, ve) = prof.eval(prof.end_time() + 1.0);
            assert!((pe - target).abs() < 1e-9 && ve == 0.0, "{p0} {v0} -> {target}: {pe} {ve}");
            let n = 400;
            let mut prev = prof.eval(0.0).1;
            for k in 1..=n {
                let t = prof.end_time() * k as f64 / n as f64;
                let (_, v) = prof.eval(t);
                assert!(v.abs() <= vmax + 1e-9);
                let a = (v - prev) / (prof.end_time() / n as f64);
                assert!(a.abs() <= amax * (1.0 + 1e-6) + 1e-9, "a {a} > {amax}");
                prev = v;
            }
        }
    }
}
