//! Path discretization (gridpoints) for TOPP-RA.
//!
//! [`GridSpec::Auto`] reproduces `toppra.interpolator.propose_gridpoints` with the defaults
//! `toppra.algorithm.TOPPRA` uses when no gridpoints are given (max_err_threshold 1e-3,
//! max_seg_length 0.05, min_nb_points 100, max_iteration 100): segments are halved while longer
//! than 0.05 in s or while the interpolation error estimate 0.5·max|q''|·Δs² exceeds the
//! threshold, then all are halved until there are at least 100 points. A path's breakpoints
//! (where d²q/ds² jumps; none for splines, so toppra's grid is reproduced) start the grid.

use crate::path::JointPath;

/// How TOPP-RA discretizes the path parameter.
#[derive(Debug, Clone, PartialEq)]
pub enum GridSpec {
    /// toppra's default automatic proposal (see module doc).
    Auto,
    /// `n` equally spaced points (n >= 2) over the path interval, ends included.
    Uniform(usize),
    /// Explicit strictly increasing points; first and last must equal the path interval ends.
    Points(Vec<f64>),
}

/// Resolves a [`GridSpec`] for `path` into gridpoints.
pub fn gridpoints<P: JointPath + ?Sized>(path: &P, spec: &GridSpec) -> Result<Vec<f64>, String> {
    let (s0, s1) = path.interval();
    if s1.partial_cmp(&s0) != Some(std::cmp::Ordering::Greater) {
        return Err(format!("path interval [{s0}, {s1}] is empty"));
    }
    let pts = match spec {
        GridSpec::Auto => propose(path, 1e-3, 100, 0.05, 100)?,
        GridSpec::Uniform(n) => {
            if *n < 2 {
                return Err(format!("uniform grid needs at least 2 points, got {n}"));
            }
            let mut v: Vec<f64> = (0..*n).map(|k| s0 + (s1 - s0) * k as f64 / (*n - 1) as f64).collect();
            v[*n - 1] = s1;
            v
        }
        GridSpec::Points(v) => {
            if v.len() < 2 || v[0] != s0 || v[v.len() - 1] != s1 {
                return Err("explicit gridpoints must start and end at the path interval ends".into());
            }
            v.clone()
        }
    };
    if pts.iter().any(|s| !s.is_finite()) || pts.windows(2).any(|w| w[1] <= w[0]) {
        return Err("gridpoints must be finite and strictly increasing".into());
    }
    Ok(pts)
}

fn propose<P: JointPath + ?Sized>(
    path: &P,
    max_err: f64,
    max_iteration: usize,
    max_seg_length: f64,
    min_points: usize,
) -> Result<Vec<f64>, String> {
    let (s0, s1) = path.interval();
    let dof = path.dof();
    let (mut q, mut dq, mut ddq) = (vec![0.0; dof], vec![0.0; dof], vec![0.0; dof]);
    let mut grid = vec![s0];
    grid.extend(path.breakpoints().into_iter().filter(|&b| b > s0 && b < s1));
    grid.push(s1);
    let mut converged = false;
    for _ in 0..max_iteration {
        let mut added = Vec::new();
        for w in grid.windows(2) {
            let (a, b) = (w[0], w[1]);
            let mid = 0.5 * (a + b);
            let len = b - a;
            if len > max_seg_length {
                added.push(mid);
                continue;
            }
            path.eval(mid, &mut q, &mut dq, &mut ddq);
            let err = ddq.iter().fold(0.0_f64, |m, v| m.max((0.5 * v * len * len).abs()));
            if err > max_err {
                added.push(mid);
            }
        }
        if added.is_empty() {
            converged = true;
            break;
        }
        grid.extend(added);
        grid.sort_by(f64::total_cmp);
    }
    if !converged {
        return Err(format!("no adequate grid after {max_iteration} refinement passes"));
    }
    while grid.len() < min_points {
        let mids: Vec<f64> = grid.windows(2).map(|w| 0.5 * (w[0] + w[1])).collect();
        grid.extend(mids);
        grid.sort_by(f64::total_cmp);
    }
    Ok(grid)
}
