//! The set-point signal of an accepted trajectory, on simulation time: from the set-point
//! in force when it starts to point 0, then point to point; per segment linear when its end
//! point has positions only, cubic Hermite when it has velocities (the start velocity is the
//! previous point's, or the running set-point's for the first segment, 0 when not given).
//! After the last point the set-point holds it.

use crate::ports::N;

/// One waypoint, in output order.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Waypoint {
    /// Time from the trajectory's start [ns].
    pub t_ns: i64,
    pub q: [f64; N],
    pub qd: Option<[f64; N]>,
}

/// Position and velocity set-points.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Setpoint {
    pub q: [f64; N],
    pub qd: [f64; N],
}

/// A trajectory starting at `start_ns` from `from`; `before` runs until it starts.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Reference {
    start_ns: i64,
    from: Setpoint,
    points: Vec<Waypoint>,
    before: Option<Box<Reference>>,
}

/// Cubic Hermite between (p0, v0) and (p1, v1) over `t` seconds, at `s`: position, velocity.
fn hermite(p0: f64, v0: f64, p1: f64, v1: f64, t: f64, s: f64) -> (f64, f64) {
    let t2 = t * t;
    let c2 = (3.0 * (p1 - p0) - (2.0 * v0 + v1) * t) / t2;
    let c3 = (2.0 * (p0 - p1) + (v0 + v1) * t) / (t2 * t);
    (p0 + s * (v0 + s * (c2 + s * c3)), v0 + s * (2.0 * c2 + 3.0 * s * c3))
}

impl Reference {
    /// Holds `q` from the beginning of time.
    pub fn hold(q: [f64; N]) -> Reference {
        Reference { start_ns: i64::MIN, from: Setpoint { q, qd: [0.0; N] }, points: vec![], before: None }
    }

    /// `points` (validated: times >= 0 and strictly increasing) from `start_ns`; this
    /// reference (the one in force) runs until then.
    pub fn replaced_by(self, start_ns: i64, points: Vec<Waypoint>, now_ns: i64) -> Reference {
        let from = self.sample(start_ns);
        let before = (start_ns > now_ns).then(|| Box::new(self));
        Reference { start_ns, from, points, before }
    }

    /// Forgets what ran before `now_ns`.
    pub fn prune(&mut self, now_ns: i64) {
        if self.start_ns <= now_ns {
            self.before = None;
        } else if let Some(b) = &mut self.before {
            b.prune(now_ns);
        }
    }

    /// Whether the trajectory still moves the set-point after `t_ns`.
    pub fn executing(&self, t_ns: i64) -> bool {
        match (&self.before, self.points.last()) {
            (Some(_), _) if t_ns < self.start_ns => true,
            (_, Some(last)) => t_ns < self.start_ns.saturating_add(last.t_ns),
            _ => false,
        }
    }

    /// The set-point at absolute time `t_ns`.
    pub fn sample(&self, t_ns: i64) -> Setpoint {
        if t_ns < self.start_ns {
            return self.before.as_ref().map_or(self.from, |b| b.sample(t_ns));
        }
        let rel = t_ns - self.start_ns;
        let i = self.points.partition_point(|p| p.t_ns <= rel);
        let Some(end) = self.points.get(i) else {
            let q = self.points.last().map_or(self.from.q, |p| p.q);
            return Setpoint { q, qd: [0.0; N] };
        };
        let (t0, q0, v0) = match i.checked_sub(1).map(|k| &self.points[k]) {
            Some(p) => (p.t_ns, p.q, p.qd.unwrap_or([0.0; N])),
            None => (0, self.from.q, self.from.qd),
        };
        let t = (end.t_ns - t0) as f64 * 1e-9;
        let s = (rel - t0) as f64 * 1e-9;
        let mut out = Setpoint::default();
        for j in 0..N {
            (out.q[j], out.qd[j]) = match end.qd {
                Some(v1) => hermite(q0[j], v0[j], end.q[j], v1[j], t, s),
                None => {
                    let v = (end.q[j] - q0[j]) / t;
                    (q0[j] + v * s, v)
                }
            };
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hermite_meets_its_ends() {
        let (p, v) = hermite(0.2, -0.1, 1.0, 0.5, 2.0, 0.0);
        assert_eq!((p, v), (0.2, -0.1));
        let (p, v) = hermite(0.2, -0.1, 1.0, 0.5, 2.0, 2.0);
        assert!((p - 1.0).abs() < 1e-12 && (v - 0.5).abs() < 1e-12);
    }
}
