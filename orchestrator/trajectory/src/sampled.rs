//! Time-sampled joint trajectories: the common output of every time parameterization, and what
//! becomes `trajectory_msgs/JointTrajectory` points (t → time_from_start, q → positions,
//! qd → velocities, qdd → accelerations).

/// A trajectory that can be evaluated at any time in `[0, duration]`.
pub trait Trajectory {
    /// Number of joints.
    fn dof(&self) -> usize;
    /// Total duration in seconds (starts at t = 0).
    fn duration(&self) -> f64;
    /// Writes position, velocity and acceleration at time `t` (clamped to `[0, duration]`).
    fn state_at(&self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]);
}

/// Samples of a trajectory; DoF-generic (one `Vec<f64>` per sample), strictly increasing `t`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Sampled {
    pub t: Vec<f64>,
    pub q: Vec<Vec<f64>>,
    pub qd: Vec<Vec<f64>>,
    pub qdd: Vec<Vec<f64>>,
}

impl Sampled {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// True without samples.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// Resamples at a fixed step (see [`sample`]); between samples the state is the quintic
    /// Hermite interpolant of (q, qd, qdd) at both ends, so a fine sampling resamples faithfully.
    pub fn resample(&self, dt: f64) -> Sampled {
        sample(self, dt)
    }
}

impl Trajectory for Sampled {
    fn dof(&self) -> usize {
        self.q.first().map_or(0, |q| q.len())
    }

    fn duration(&self) -> f64 {
        match (self.t.first(), self.t.last()) {
            (Some(a), Some(b)) => b - a,
            _ => 0.0,
        }
    }

    fn state_at(&self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]) {
        let n = self.t.len();
        if n == 0 {
            return;
        }
        if n == 1 {
            q.copy_from_slice(&self.q[0]);
            qd.copy_from_slice(&self.qd[0]);
            qdd.copy_from_slice(&self.qdd[0]);
            return;
        }
        let t = (t + self.t[0]).clamp(self.t[0], self.t[n - 1]);
        let k = self.t[1..n - 1].partition_point(|&x| x <= t);
        let h = self.t[k + 1] - self.t[k];
        let x = ((t - self.t[k]) / h).clamp(0.0, 1.0);
        for j in 0..q.len() {
            let (p0, v0, a0) = (self.q[k][j], self.qd[k][j] * h, self.qdd[k][j] * h * h);
            let (p1, v1, a1) = (self.q[k + 1][j], self.qd[k + 1][j] * h, self.qdd[k + 1][j] * h * h);
            let (p, v, a) = quintic_hermite(x, p0, v0, a0, p1, v1, a1);
            q[j] = p;
            qd[j] = v / h;
            qdd[j] = a / (h * h);
        }
    }
}

/// Quintic Hermite on the unit interval: value, first and second derivative at `x`.
fn quintic_hermite(x: f64, p0: f64, v0: f64, a0: f64, p1: f64, v1: f64, a1: f64) -> (f64, f64, f64) {
    let c3 = 10.0 * (p1 - p0) - 6.0 * v0 - 4.0 * v1 - 1.5 * a0 + 0.5 * a1;
    let c4 = -15.0 * (p1 - p0) + 8.0 * v0 + 7.0 * v1 + 1.5 * a0 - a1;
    let c5 = 6.0 * (p1 - p0) - 3.0 * (v0 + v1) - 0.5 * a0 + 0.5 * a1;
    let c2 = 0.5 * a0;
    let p = p0 + x * (v0 + x * (c2 + x * (c3 + x * (c4 + x * c5))));
    let v = v0 + x * (2.0 * c2 + x * (3.0 * c3 + x * (4.0 * c4 + x * 5.0 * c5)));
    let a = 2.0 * c2 + x * (6.0 * c3 + x * (12.0 * c4 + x * 20.0 * c5));
    (p, v, a)
}

/// Samples `traj` at t = 0, dt, 2·dt, … and always at its exact end time (a last step shorter
/// than 1e-9 s is merged into the end sample, so times stay strictly increasing).
/// `dt` must be positive and finite; a non-positive `dt` gives just the two end samples.
pub fn sample<T: Trajectory + ?Sized>(traj: &T, dt: f64) -> Sampled {
    let dof = traj.dof();
    let duration = traj.duration().max(0.0);
    let mut times: Vec<f64> = Vec::new();
    if dt > 0.0 && dt.is_finite() {
        let steps = (duration / dt).floor() as usize;
        times.extend((0..=steps).map(|k| k as f64 * dt).filter(|&t| t < duration - 1e-9));
    }
    times.push(duration);
    if times[0] != 0.0 {
        times.insert(0, 0.0);
    }
    let mut out = Sampled { t: times, ..Default::default() };
    for &t in &out.t {
        let (mut q, mut qd, mut qdd) = (vec![0.0; dof], vec![0.0; dof], vec![0.0; dof]);
        traj.state_at(t, &mut q, &mut qd, &mut qdd);
        out.q.push(q);
        out.qd.push(qd);
        out.qdd.push(qdd);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// q = t³ on [0, 2] for one joint.
    struct Cubic;
    impl Trajectory for Cubic {
        fn dof(&self) -> usize {
            1
        }
        fn duration(&self) -> f64 {
            2.0
        }
        fn state_at(&self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]) {
            let t = t.clamp(0.0, 2.0);
            q[0] = t * t * t;
            qd[0] = 3.0 * t * t;
            qdd[0] = 6.0 * t;
        }
    }

    #[test]
    fn sampling_hits_end_exactly_and_resampling_is_exact_for_polynomials() {
        let s = sample(&Cubic, 0.3);
        assert_eq!(s.t.len(), 8); // 0, 0.3, ..., 1.8, 2.0
        assert_eq!(*s.t.last().unwrap(), 2.0);
        assert!(s.t.windows(2).all(|w| w[1] > w[0]));
        let s2 = sample(&Cubic, 0.5);
        assert_eq!(s2.t, vec![0.0, 0.5, 1.0, 1.5, 2.0]);
        // Quintic Hermite reproduces a cubic exactly.
        let r = s.resample(0.05);
        for (k, &t) in r.t.iter().enumerate() {
            assert!((r.q[k][0] - t * t * t).abs() < 1e-12);
            assert!((r.qd[k][0] - 3.0 * t * t).abs() < 1e-11);
            assert!((r.qdd[k][0] - 6.0 * t).abs() < 1e-10);
        }
    }
}
