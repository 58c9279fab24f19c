//! Joint-space polyline with parabolic corner blends.
//!
//! The planner collision-checks straight joint-space segments between its waypoints; a cubic
//! spline through the same waypoints can swing far from them. This path follows the polyline
//! exactly except within `radius` (joint-space distance) of each interior corner, where a
//! quadratic Bézier through the corner's control point replaces it; the deviation from the
//! corner is at most radius / 2. s is the polyline's arc length: a blend spans 2ℓ of s where
//! ℓ = min(radius, half of either adjacent segment), with dq/ds going linearly from the
//! incoming to the outgoing unit direction, so d²q/ds² = (d_out − d_in) / 2ℓ is constant there.
//! The piece boundaries are reported as breakpoints so the TOPP-RA grid contains them.

use crate::path::{JointPath, PathError};

#[derive(Debug, Clone)]
struct Piece {
    s0: f64,
    len: f64,
    /// Start point, incoming and outgoing unit directions (equal on straight pieces).
    p0: Vec<f64>,
    d_in: Vec<f64>,
    d_out: Vec<f64>,
}

/// Polyline through waypoints with parabolic blends at the interior corners.
#[derive(Debug, Clone)]
pub struct BlendedPolylinePath {
    dof: usize,
    pieces: Vec<Piece>,
    breakpoints: Vec<f64>,
}

impl BlendedPolylinePath {
    /// Path through `waypoints` with corner blends of at most `radius` (> 0) on each side.
    /// Consecutive identical waypoints are dropped.
    pub fn new(waypoints: &[Vec<f64>], radius: f64) -> Result<Self, PathError> {
        if !(radius > 0.0 && radius.is_finite()) {
            return Err(PathError::BadParameters(format!("blend radius {radius} must be positive")));
        }
        let dof = waypoints.first().map_or(0, |w| w.len());
        if dof == 0 {
            return Err(PathError::BadWaypoints("no waypoints or zero joints".into()));
        }
        let mut pts: Vec<&Vec<f64>> = Vec::new();
        for (k, w) in waypoints.iter().enumerate() {
            if w.len() != dof || w.iter().any(|v| !v.is_finite()) {
                return Err(PathError::BadWaypoints(format!("waypoint {k} has wrong length or is not finite")));
            }
            if pts.last().is_none_or(|p| *p != w) {
                pts.push(w);
            }
        }
        if pts.len() < 2 {
            return Err(PathError::BadWaypoints("need at least 2 distinct waypoints".into()));
        }
        let seg_len: Vec<f64> = pts.windows(2).map(|w| dist(w[0], w[1])).collect();
        let dirs: Vec<Vec<f64>> = pts
            .windows(2)
            .zip(&seg_len)
            .map(|(w, l)| w[1].iter().zip(w[0]).map(|(b, a)| (b - a) / l).collect())
            .collect();
        // Blend half-length at each interior corner.
        let m = pts.len();
        let ell: Vec<f64> = (0..m)
            .map(|k| if k == 0 || k == m - 1 { 0.0 } else { radius.min(0.5 * seg_len[k - 1]).min(0.5 * seg_len[k]) })
            .collect();
        let mut pieces = Vec::new();
        let mut s = 0.0;
        for k in 0..m - 1 {
            // Straight part of segment k, then the blend at corner k+1.
            let start: Vec<f64> = pts[k].iter().zip(&dirs[k]).map(|(p, d)| p + ell[k] * d).collect();
            let straight = seg_len[k] - ell[k] - ell[k + 1];
            if straight > 0.0 {
                pieces.push(Piece { s0: s, len: straight, p0: start, d_in: dirs[k].clone(), d_out: dirs[k].clone() });
                s += straight;
            }
            if k + 1 < m - 1 && ell[k + 1] > 0.0 {
                let a: Vec<f64> = pts[k + 1].iter().zip(&dirs[k]).map(|(p, d)| p - ell[k + 1] * d).collect();
                pieces.push(Piece {
                    s0: s,
                    len: 2.0 * ell[k + 1],
                    p0: a,
                    d_in: dirs[k].clone(),
                    d_out: dirs[k + 1].clone(),
                });
                s += 2.0 * ell[k + 1];
            }
        }
        let breakpoints = pieces.iter().skip(1).map(|p| p.s0).collect();
        Ok(BlendedPolylinePath { dof, pieces, breakpoints })
    }
}

fn dist(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (y - x) * (y - x)).sum::<f64>().sqrt()
}

impl JointPath for BlendedPolylinePath {
    fn dof(&self) -> usize {
        self.dof
    }

    fn interval(&self) -> (f64, f64) {
        let last = &self.pieces[self.pieces.len() - 1];
        (0.0, last.s0 + last.len)
    }

    fn eval(&self, s: f64, q: &mut [f64], dq: &mut [f64], ddq: &mut [f64]) {
        let (s0, s1) = self.interval();
        let s = s.clamp(s0, s1);
        let k = self.pieces[1..].partition_point(|p| p.s0 <= s);
        let p = &self.pieces[k];
        let x = (s - p.s0).clamp(0.0, p.len);
        let tau = x / p.len;
        for j in 0..self.dof {
            // dq/ds = (1 - τ) d_in + τ d_out, integrated from p0.
            let (di, dout) = (p.d_in[j], p.d_out[j]);
            q[j] = p.p0[j] + x * di + 0.5 * x * tau * (dout - di);
            dq[j] = di + tau * (dout - di);
            ddq[j] = (dout - di) / p.len;
        }
    }

    fn breakpoints(&self) -> Vec<f64> {
        self.breakpoints.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(p: &BlendedPolylinePath, s: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let (mut q, mut dq, mut ddq) = (vec![0.0; 2], vec![0.0; 2], vec![0.0; 2]);
        p.eval(s, &mut q, &mut dq, &mut ddq);
        (q, dq, ddq)
    }

    #[test]
    fn follows_the_polyline_and_rounds_corners_within_half_radius() {
        let w = vec![vec![0.0, 0.0], vec![1.0, 0.0], vec![1.0, 2.0]];
        let p = BlendedPolylinePath::new(&w, 0.2).unwrap();
        assert!(p.interval().0 == 0.0 && (p.interval().1 - 3.0).abs() < 1e-12);
        assert!(
            (JointPath::breakpoints(&p)[0] - 0.8).abs() < 1e-12 && (JointPath::breakpoints(&p)[1] - 1.2).abs() < 1e-12
        );
        assert_eq!(JointPath::breakpoints(&p).len(), 2);
        // Ends and straight parts exact, unit speed there.
        assert_eq!(at(&p, 0.0).0, vec![0.0, 0.0]);
        let (q, dq, _) = at(&p, 3.0);
        assert!((q[0] - 1.0).abs() < 1e-12 && (q[1] - 2.0).abs() < 1e-12 && (dq[1] - 1.0).abs() < 1e-12);
        let (q, _, _) = at(&p, 0.5);
        assert!((q[0] - 0.5).abs() < 1e-12 && q[1] == 0.0);
        // Continuous position and velocity across the blend ends; corner deviation radius/2·|Δd|/2.
        for b in JointPath::breakpoints(&p) {
            let (qa, da, _) = at(&p, b - 1e-12);
            let (qb, db, _) = at(&p, b + 1e-12);
            assert!(dist(&qa, &qb) < 1e-9 && dist(&da, &db) < 1e-9);
        }
        let (q, _, ddq) = at(&p, 1.0);
        let dev = dist(&q, &[1.0, 0.0]);
        assert!((dev - 0.2 * 2f64.sqrt() / 4.0).abs() < 1e-12 && dev <= 0.1);
        assert!((ddq[0] + 2.5).abs() < 1e-12 && (ddq[1] - 2.5).abs() < 1e-12);
    }
}
