//! Cubic spline joint path through waypoints.
//!
//! Built exactly like `toppra.SplineInterpolator(ss, waypoints)`, which wraps
//! `scipy.interpolate.CubicSpline(ss, waypoints, bc_type="not-a-knot")` (read from toppra 0.6.10):
//! an interpolating C² cubic per joint, with the not-a-knot end condition (third derivative
//! continuous at the second and second-to-last knots); for 3 knots that is the parabola through
//! them, for 2 knots the straight line — scipy's special cases. The path parameter values `ss`
//! are chosen by the caller (toppra takes them as given); [`PathParam`] offers the two usual
//! choices. Using the same construction lets the cross-check time-parameterize the identical path.

use crate::path::{JointPath, PathError};

/// End conditions of the spline.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SplineEnd {
    /// scipy/toppra default: third derivative continuous across the second and second-to-last knot.
    NotAKnot,
    /// dq/ds = 0 at both ends (scipy `bc_type="clamped"`).
    Clamped,
    /// d²q/ds² = 0 at both ends (scipy `bc_type="natural"`).
    Natural,
}

/// How path parameter values are assigned to waypoints.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PathParam {
    /// s_k = k / (n - 1), i.e. `np.linspace(0, 1, n)` (toppra's examples).
    Uniform,
    /// s_k = cumulative Euclidean joint-space distance (chord length); keeps |dq/ds| near 1 so
    /// grid spacing means the same on long and short paths.
    ChordLength,
}

/// Per-joint piecewise cubic q_j(s) on knots `s`.
#[derive(Debug, Clone)]
pub struct CubicSplinePath {
    knots: Vec<f64>,
    dof: usize,
    /// `coeffs[k * dof + j] = [c0, c1, c2, c3]`: q_j(s) = Σ c_m (s - s_k)^m on segment k.
    coeffs: Vec<[f64; 4]>,
}

impl CubicSplinePath {
    /// Spline through `waypoints[k]` at path parameter `ss[k]` (strictly increasing).
    pub fn new(ss: &[f64], waypoints: &[Vec<f64>], end: SplineEnd) -> Result<Self, PathError> {
        let n = waypoints.len();
        if n < 2 {
            return Err(PathError::BadWaypoints(format!("need at least 2 waypoints, got {n}")));
        }
        if ss.len() != n {
            return Err(PathError::BadParameters(format!("{} path parameters for {n} waypoints", ss.len())));
        }
        let dof = waypoints[0].len();
        if dof == 0 {
            return Err(PathError::BadWaypoints("waypoints have zero joints".into()));
        }
        for (k, w) in waypoints.iter().enumerate() {
            if w.len() != dof {
                return Err(PathError::BadWaypoints(format!("waypoint {k} has {} joints, expected {dof}", w.len())));
            }
            if w.iter().any(|v| !v.is_finite()) {
                return Err(PathError::BadWaypoints(format!("waypoint {k} is not finite")));
            }
        }
        if ss.iter().any(|v| !v.is_finite()) || ss.windows(2).any(|w| w[1] <= w[0]) {
            return Err(PathError::BadParameters("path parameters must be finite and strictly increasing".into()));
        }
        let h: Vec<f64> = ss.windows(2).map(|w| w[1] - w[0]).collect();
        let mut coeffs = vec![[0.0; 4]; (n - 1) * dof];
        let mut y = vec![0.0; n];
        for j in 0..dof {
            for k in 0..n {
                y[k] = waypoints[k][j];
            }
            let m = second_derivatives(&h, &y, end);
            for k in 0..n - 1 {
                let d = (y[k + 1] - y[k]) / h[k];
                coeffs[k * dof + j] =
                    [y[k], d - h[k] * (2.0 * m[k] + m[k + 1]) / 6.0, 0.5 * m[k], (m[k + 1] - m[k]) / (6.0 * h[k])];
            }
        }
        Ok(CubicSplinePath { knots: ss.to_vec(), dof, coeffs })
    }

    /// Spline through planner waypoints with the given parameterization and not-a-knot ends.
    /// Consecutive identical waypoints are dropped first (they would give zero chord length).
    pub fn through_waypoints(waypoints: &[Vec<f64>], param: PathParam) -> Result<Self, PathError> {
        let mut kept: Vec<Vec<f64>> = Vec::with_capacity(waypoints.len());
        for w in waypoints {
            if kept.last().is_none_or(|p| p != w) {
                kept.push(w.clone());
            }
        }
        if kept.len() < 2 {
            return Err(PathError::BadWaypoints("need at least 2 distinct waypoints".into()));
        }
        let ss = path_parameters(&kept, param);
        Self::new(&ss, &kept, SplineEnd::NotAKnot)
    }

    /// Knot positions (the waypoints' path parameters).
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }

    fn segment(&self, s: f64) -> (usize, f64) {
        let n = self.knots.len();
        let s = s.clamp(self.knots[0], self.knots[n - 1]);
        // Number of interior knots <= s: the segment to the right of a knot, as scipy's PPoly.
        let k = self.knots[1..n - 1].partition_point(|&x| x <= s);
        (k, s - self.knots[k])
    }
}

/// Path parameters for `waypoints` (assumed to have no consecutive duplicates for chord length).
pub fn path_parameters(waypoints: &[Vec<f64>], param: PathParam) -> Vec<f64> {
    let n = waypoints.len();
    match param {
        PathParam::Uniform => (0..n).map(|k| if n > 1 { k as f64 / (n - 1) as f64 } else { 0.0 }).collect(),
        PathParam::ChordLength => {
            let mut ss = Vec::with_capacity(n);
            let mut acc = 0.0;
            ss.push(0.0);
            for w in waypoints.windows(2) {
                acc += w[0].iter().zip(&w[1]).map(|(a, b)| (b - a) * (b - a)).sum::<f64>().sqrt();
                ss.push(acc);
            }
            ss
        }
    }
}

/// Second derivatives M_k at the knots of the interpolating cubic (standard moment equations
/// h_{k-1} M_{k-1} + 2 (h_{k-1} + h_k) M_k + h_k M_{k+1} = 6 (d_k - d_{k-1}) plus end rows).
fn second_derivatives(h: &[f64], y: &[f64], end: SplineEnd) -> Vec<f64> {
    let n = y.len();
    let d: Vec<f64> = (0..n - 1).map(|k| (y[k + 1] - y[k]) / h[k]).collect();
    let mut m = vec![0.0; n];
    let mut t = Tridiagonal::default();
    match end {
        SplineEnd::NotAKnot if n == 2 => {}
        SplineEnd::NotAKnot if n == 3 => {
            // scipy: the parabola through the three points.
            m.fill(2.0 * (d[1] - d[0]) / (h[0] + h[1]));
        }
        SplineEnd::NotAKnot => {
            // Unknowns M_1..M_{n-2}; M_0 and M_{n-1} eliminated with the not-a-knot conditions
            // M_0 = ((h0 + h1) M_1 - h0 M_2) / h1 and the mirror image at the end.
            t.push_interior(h, &d);
            let u = n - 2;
            let (h0, h1) = (h[0], h[1]);
            t.dia[0] += h0 * (h0 + h1) / h1;
            t.sup[0] -= h0 * h0 / h1;
            let (ha, hb) = (h[n - 3], h[n - 2]);
            t.dia[u - 1] += hb * (ha + hb) / ha;
            t.sub[u - 1] -= hb * hb / ha;
            m[1..n - 1].copy_from_slice(&t.solve());
            m[0] = ((h0 + h1) * m[1] - h0 * m[2]) / h1;
            m[n - 1] = ((ha + hb) * m[n - 2] - hb * m[n - 3]) / ha;
        }
        SplineEnd::Clamped => {
            t.push(0.0, 2.0 * h[0], h[0], 6.0 * d[0]);
            t.push_interior(h, &d);
            t.push(h[n - 2], 2.0 * h[n - 2], 0.0, -6.0 * d[n - 2]);
            m = t.solve();
        }
        SplineEnd::Natural => {
            if n > 2 {
                t.push_interior(h, &d);
                m[1..n - 1].copy_from_slice(&t.solve());
            }
        }
    }
    m
}

/// A tridiagonal system, one row per unknown: `sub[i] x[i-1] + dia[i] x[i] + sup[i] x[i+1]
/// = rhs[i]` (`sub[0]` and the last `sup` are unused).
#[derive(Default)]
struct Tridiagonal {
    sub: Vec<f64>,
    dia: Vec<f64>,
    sup: Vec<f64>,
    rhs: Vec<f64>,
}

impl Tridiagonal {
    fn push(&mut self, sub: f64, dia: f64, sup: f64, rhs: f64) {
        self.sub.push(sub);
        self.dia.push(dia);
        self.sup.push(sup);
        self.rhs.push(rhs);
    }

    /// The moment equations of the interior knots k = 1..n-2 (`h`, `d`: interval lengths
    /// and slopes, n - 1 each); every end condition shares them.
    fn push_interior(&mut self, h: &[f64], d: &[f64]) {
        for k in 1..h.len() {
            self.push(h[k - 1], 2.0 * (h[k - 1] + h[k]), h[k], 6.0 * (d[k] - d[k - 1]));
        }
    }

    /// Thomas algorithm; the systems above are diagonally dominant, so no pivoting is needed.
    fn solve(&self) -> Vec<f64> {
        let (sub, dia, sup, rhs) = (&self.sub, &self.dia, &self.sup, &self.rhs);
        let n = dia.len();
        let mut c = vec![0.0; n];
        let mut x = vec![0.0; n];
        let mut beta = dia[0];
        c[0] = sup[0] / beta;
        x[0] = rhs[0] / beta;
        for i in 1..n {
            beta = dia[i] - sub[i] * c[i - 1];
            c[i] = sup[i] / beta;
            x[i] = (rhs[i] - sub[i] * x[i - 1]) / beta;
        }
        for i in (0..n - 1).rev() {
            x[i] -= c[i] * x[i + 1];
        }
        x
    }
}

impl JointPath for CubicSplinePath {
    fn dof(&self) -> usize {
        self.dof
    }

    fn interval(&self) -> (f64, f64) {
        (self.knots[0], self.knots[self.knots.len() - 1])
    }

    fn eval(&self, s: f64, q: &mut [f64], dq: &mut [f64], ddq: &mut [f64]) {
        let (k, x) = self.segment(s);
        let row = &self.coeffs[k * self.dof..(k + 1) * self.dof];
        for (j, c) in row.iter().enumerate() {
            q[j] = c[0] + x * (c[1] + x * (c[2] + x * c[3]));
            dq[j] = c[1] + x * (2.0 * c[2] + x * 3.0 * c[3]);
            ddq[j] = 2.0 * c[2] + 6.0 * c[3] * x;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn eval1(p: &CubicSplinePath, s: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let d = p.dof();
        let (mut q, mut dq, mut ddq) = (vec![0.0; d], vec![0.0; d], vec![0.0; d]);
        p.eval(s, &mut q, &mut dq, &mut ddq);
        (q, dq, ddq)
    }

    #[test]
    fn not_a_knot_reproduces_a_cubic_exactly() {
        // A not-a-knot spline reproduces any cubic polynomial (its defining property).
        let f = |s: f64| 0.3 - 1.2 * s + 0.7 * s * s - 0.4 * s * s * s;
        let ss = [0.0, 0.3, 0.45, 1.1, 1.7, 2.0];
        let w: Vec<Vec<f64>> = ss.iter().map(|&s| vec![f(s)]).collect();
        let p = CubicSplinePath::new(&ss, &w, SplineEnd::NotAKnot).unwrap();
        for i in 0..=40 {
            let s = 2.0 * i as f64 / 40.0;
            let (q, dq, ddq) = eval1(&p, s);
            assert!((q[0] - f(s)).abs() < 1e-12);
            assert!((dq[0] - (-1.2 + 1.4 * s - 1.2 * s * s)).abs() < 1e-11);
            assert!((ddq[0] - (1.4 - 2.4 * s)).abs() < 1e-10);
        }
    }

    #[test]
    fn special_cases_and_continuity() {
        // Three points: the parabola; two points: the line.
        let p =
            CubicSplinePath::new(&[0.0, 1.0, 3.0], &[vec![0.0], vec![1.0], vec![9.0]], SplineEnd::NotAKnot).unwrap();
        let (q, _, ddq) = eval1(&p, 2.0);
        assert!((q[0] - 4.0).abs() < 1e-12 && (ddq[0] - 2.0).abs() < 1e-12);
        let p = CubicSplinePath::new(&[0.0, 2.0], &[vec![1.0], vec![3.0]], SplineEnd::NotAKnot).unwrap();
        let (q, dq, _) = eval1(&p, 0.5);
        assert!((q[0] - 1.5).abs() < 1e-12 && (dq[0] - 1.0).abs() < 1e-12);
        // C² at interior knots for all end conditions; clamped has zero end slope.
        let ss = [0.0, 0.2, 0.9, 1.0, 1.6];
        let w: Vec<Vec<f64>> = [0.1, -0.4, 0.8, 0.3, 1.0].iter().map(|&v| vec![v, 2.0 * v]).collect();
        for end in [SplineEnd::NotAKnot, SplineEnd::Clamped, SplineEnd::Natural] {
            let p = CubicSplinePath::new(&ss, &w, end).unwrap();
            for &k in &ss[1..4] {
                let (a, da, dda) = eval1(&p, k - 1e-12);
                let (b, db, ddb) = eval1(&p, k + 1e-12);
                assert!((a[1] - b[1]).abs() < 1e-7 && (da[1] - db[1]).abs() < 1e-6 && (dda[1] - ddb[1]).abs() < 1e-6);
            }
            let (q, dq, ddq) = eval1(&p, ss[0]);
            assert!((q[0] - 0.1).abs() < 1e-12);
            if end == SplineEnd::Clamped {
                assert!(dq[0].abs() < 1e-12);
            }
            if end == SplineEnd::Natural {
                assert!(ddq[0].abs() < 1e-12);
            }
        }
    }

    #[test]
    fn chord_length_and_rejections() {
        let w = vec![vec![0.0, 0.0], vec![3.0, 4.0], vec![3.0, 4.0], vec![3.0, 5.0]];
        let p = CubicSplinePath::through_waypoints(&w, PathParam::ChordLength).unwrap();
        assert_eq!(p.knots(), &[0.0, 5.0, 6.0]);
        assert!(CubicSplinePath::through_waypoints(&[vec![1.0], vec![1.0]], PathParam::Uniform).is_err());
        assert!(CubicSplinePath::new(&[0.0, 0.0], &[vec![1.0], vec![2.0]], SplineEnd::NotAKnot).is_err());
        assert!(CubicSplinePath::new(&[0.0, 1.0], &[vec![1.0], vec![2.0, 3.0]], SplineEnd::NotAKnot).is_err());
    }
}
