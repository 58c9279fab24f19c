//! The reference (desired) joint motion from a validated trajectory, as ROS 2
//! joint_trajectory_controller interpolates it: per segment, linear when the end point has
//! positions only, cubic Hermite when it has velocities, quintic when it has accelerations
//! too; the segment before point 0 starts at the commanded state when the trajectory arrived.
//! After the last point the reference holds its position with zero velocity.

use crate::description::N;
use crate::validate::Waypoint;

/// Desired position, velocity, acceleration of every joint.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Setpoint {
    pub q: [f64; N],
    pub qd: [f64; N],
    pub qdd: [f64; N],
}

impl Setpoint {
    pub fn hold(q: [f64; N]) -> Setpoint {
        Setpoint { q, qd: [0.0; N], qdd: [0.0; N] }
    }
}

/// Polynomial segment per joint: `q(s) = sum c[k] s^k`, s in [0, T] seconds.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
struct Segment {
    t0_ns: i64,
    t1_ns: i64,
    c: [[f64; 6]; N],
}

#[derive(Clone, Copy, PartialEq)]
enum Degree {
    Linear,
    Cubic,
    Quintic,
}

fn coefficients(deg: Degree, a: (f64, f64, f64), b: (f64, f64, f64), t: f64) -> [f64; 6] {
    let (p0, v0, a0) = a;
    let (p1, v1, a1) = b;
    match deg {
        Degree::Linear => [p0, (p1 - p0) / t, 0.0, 0.0, 0.0, 0.0],
        Degree::Cubic => {
            let (t2, t3) = (t * t, t * t * t);
            [p0, v0, (3.0 * (p1 - p0) - (2.0 * v0 + v1) * t) / t2, (2.0 * (p0 - p1) + (v0 + v1) * t) / t3, 0.0, 0.0]
        }
        Degree::Quintic => {
            let (t2, t3, t4, t5) = (t * t, t.powi(3), t.powi(4), t.powi(5));
            let h = p1 - p0;
            [
                p0,
                v0,
                0.5 * a0,
                (20.0 * h - (8.0 * v1 + 12.0 * v0) * t - (3.0 * a0 - a1) * t2) / (2.0 * t3),
                (-30.0 * h + (14.0 * v1 + 16.0 * v0) * t + (3.0 * a0 - 2.0 * a1) * t2) / (2.0 * t4),
                (12.0 * h - 6.0 * (v1 + v0) * t - (a0 - a1) * t2) / (2.0 * t5),
            ]
        }
    }
}

fn eval(c: &[f64; 6], s: f64) -> (f64, f64, f64) {
    let q = c[0] + s * (c[1] + s * (c[2] + s * (c[3] + s * (c[4] + s * c[5]))));
    let qd = c[1] + s * (2.0 * c[2] + s * (3.0 * c[3] + s * (4.0 * c[4] + s * 5.0 * c[5])));
    let qdd = 2.0 * c[2] + s * (6.0 * c[3] + s * (12.0 * c[4] + s * 20.0 * c[5]));
    (q, qd, qdd)
}

/// A trajectory being executed: starts at `start_ns` (absolute simulation time). Before
/// that (a trajectory stamped to start later, as ros2_control's joint_trajectory_controller
/// allows) the one it replaced goes on: `before`.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Reference {
    start_ns: i64,
    segments: Vec<Segment>,
    last: [f64; N],
    before: Option<Box<Reference>>,
}

impl Reference {
    /// Holds `q` forever.
    pub fn hold(q: [f64; N]) -> Reference {
        Reference { start_ns: 0, segments: vec![], last: q, before: None }
    }

    /// Builds the segments of `points` (validated, times strictly increasing), starting at
    /// `start_ns` from the commanded state `from`.
    pub fn new(start_ns: i64, from: &Setpoint, points: &[Waypoint]) -> Reference {
        let mut segments = Vec::with_capacity(points.len());
        let mut prev_t = 0i64;
        let mut prev: [(f64, f64, f64); N] = std::array::from_fn(|i| (from.q[i], from.qd[i], from.qdd[i]));
        for w in points {
            let deg = match (w.qd, w.qdd) {
                (Some(_), Some(_)) => Degree::Quintic,
                (Some(_), None) => Degree::Cubic,
                _ => Degree::Linear,
            };
            let end: [(f64, f64, f64); N] =
                std::array::from_fn(|i| (w.q[i], w.qd.map_or(0.0, |v| v[i]), w.qdd.map_or(0.0, |a| a[i])));
            if w.t_ns > prev_t {
                let t = (w.t_ns - prev_t) as f64 * 1e-9;
                let c = std::array::from_fn(|i| coefficients(deg, prev[i], end[i], t));
                segments.push(Segment { t0_ns: prev_t, t1_ns: w.t_ns, c });
            }
            prev_t = w.t_ns;
            prev = end;
        }
        let last = points.last().map_or(from.q, |w| w.q);
        Reference { start_ns, segments, last, before: None }
    }

    /// This trajectory, with `old` running until it starts (dropped when it starts now).
    pub fn after(mut self, old: Reference, now_ns: i64) -> Reference {
        if self.start_ns > now_ns {
            self.before = Some(Box::new(old));
        }
        self
    }

    /// Forgets what ran before `now_ns` (keeps the chain short).
    pub fn prune(&mut self, now_ns: i64) {
        if self.start_ns <= now_ns {
            self.before = None;
        } else if let Some(b) = &mut self.before {
            b.prune(now_ns);
        }
    }

    /// Absolute end time [ns] (the start for a hold).
    pub fn end_ns(&self) -> i64 {
        self.start_ns + self.segments.last().map_or(0, |s| s.t1_ns)
    }

    /// Desired state at absolute time `t_ns`.
    pub fn sample(&self, t_ns: i64) -> Setpoint {
        if let Some(b) = self.before.as_ref().filter(|_| t_ns < self.start_ns) {
            return b.sample(t_ns);
        }
        let rel = t_ns - self.start_ns;
        // Segments are sorted and contiguous: the first one ending after `rel`.
        let Some(seg) = self.segments.get(self.segments.partition_point(|s| s.t1_ns <= rel)) else {
            return Setpoint::hold(self.last);
        };
        let s = ((rel - seg.t0_ns).max(0)) as f64 * 1e-9;
        let mut out = Setpoint::default();
        for i in 0..N {
            let (q, qd, qdd) = eval(&seg.c[i], s);
            out.q[i] = q;
            out.qd[i] = qd;
            out.qdd[i] = qdd;
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wp(t_ns: i64, q: f64, qd: Option<f64>, qdd: Option<f64>) -> Waypoint {
        Waypoint { t_ns, q: [q; N], qd: qd.map(|v| [v; N]), qdd: qdd.map(|a| [a; N]) }
    }

    /// Each degree meets its boundary conditions at both ends of a segment.
    #[test]
    fn boundary_conditions() {
        let from = Setpoint { q: [0.1; N], qd: [0.2; N], qdd: [-0.3; N] };
        for (qd, qdd) in [(None, None), (Some(0.5), None), (Some(0.5), Some(1.5))] {
            let r = Reference::new(1_000, &from, &[wp(2_000_000_000, 1.0, qd, qdd)]);
            let s0 = r.sample(1_000);
            let s1 = r.sample(1_000 + 2_000_000_000 - 1);
            assert!((s0.q[0] - 0.1).abs() < 1e-12);
            assert!((s1.q[0] - 1.0).abs() < 1e-8, "{:?}", s1.q[0]);
            if qd.is_some() {
                assert!((s0.qd[0] - 0.2).abs() < 1e-12 && (s1.qd[0] - 0.5).abs() < 1e-8);
            } else {
                assert!((s0.qd[0] - 0.45).abs() < 1e-12); // linear: 0.9 rad / 2 s
            }
            if qdd.is_some() {
                assert!((s0.qdd[0] + 0.3).abs() < 1e-12 && (s1.qdd[0] - 1.5).abs() < 1e-6);
            }
            // Past the end: hold.
            assert_eq!(r.sample(r.end_ns() + 5), Setpoint::hold([1.0; N]));
        }
    }

    /// A trajectory that starts later leaves the running one in charge until then, and the
    /// old one is forgotten once the new one has started.
    #[test]
    fn a_later_start_keeps_the_old_trajectory_until_then() {
        let old = Reference::new(0, &Setpoint::hold([0.0; N]), &[wp(1_000_000_000, 1.0, Some(0.0), Some(0.0))]);
        let at = old.sample(1_500_000_000);
        let mut new = Reference::new(2_000_000_000, &at, &[wp(1_000_000_000, 2.0, Some(0.0), Some(0.0))])
            .after(old.clone(), 500_000_000);
        assert_eq!(new.sample(600_000_000), old.sample(600_000_000), "the old one still runs");
        assert_eq!(new.sample(1_900_000_000), Setpoint::hold([1.0; N]), "then holds its end");
        assert!((new.sample(2_000_000_000).q[0] - 1.0).abs() < 1e-12);
        assert!((new.sample(3_000_000_000).q[0] - 2.0).abs() < 1e-9);
        assert_eq!(new.end_ns(), 3_000_000_000);
        new.prune(1_000_000_000);
        assert!(new.before.is_some(), "not started yet");
        new.prune(2_000_000_000);
        assert!(new.before.is_none());
        // Starting now: nothing kept.
        let now = Reference::new(500, &at, &[wp(10, 1.0, None, None)]).after(old, 500);
        assert!(now.before.is_none());
    }

    /// Velocity is the derivative of position (central differences), for a 3-point quintic.
    #[test]
    fn derivatives_are_consistent() {
        let from = Setpoint::hold([0.0; N]);
        let r = Reference::new(
            0,
            &from,
            &[wp(500_000_000, 0.3, Some(0.4), Some(0.0)), wp(1_500_000_000, -0.2, Some(0.0), Some(0.0))],
        );
        for k in 1..1400 {
            let t = k * 1_000_000;
            let (a, b, m) = (r.sample(t - 1000), r.sample(t + 1000), r.sample(t));
            let v = (b.q[3] - a.q[3]) / 2e-6;
            let acc = (b.qd[3] - a.qd[3]) / 2e-6;
            // Skip the knot where the segment changes.
            if (t - 500_000_000).abs() > 2000 {
                assert!((v - m.qd[3]).abs() < 1e-5, "t={t}: {v} vs {}", m.qd[3]);
                assert!((acc - m.qdd[3]).abs() < 1e-3, "t={t}: {acc} vs {}", m.qdd[3]);
            }
        }
    }
}
