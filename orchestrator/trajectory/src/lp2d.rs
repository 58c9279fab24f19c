//! Linear programs in two variables (u, x) — the per-stage problem of TOPP-RA.
//!
//! Seidel's incremental algorithm with a fixed constraint order: keep the optimum of the
//! constraints seen so far; when a new constraint is violated, the new optimum lies on its
//! boundary line, found by a one-dimensional LP over the earlier constraints. With the few dozen
//! rows of a 7-DoF stage this is O(m²) worst case, O(m) typical, and allocation-free.

/// Feasibility slack: a row counts as satisfied when `a·u + b·x - g < EPS`.
const EPS: f64 = 1e-10;
/// Parallel rows are declared inconsistent only beyond this violation.
const PARALLEL_EPS: f64 = 1e-8;
/// Range of the line parameter in the 1-D subproblem (never active with the box present).
const T_INF: f64 = 1e12;

/// One half-plane `a·u + b·x <= g`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Row {
    pub a: f64,
    pub b: f64,
    pub g: f64,
}

/// Maximize `c[0]·u + c[1]·x` subject to `rows` and the box `lo <= (u, x) <= hi`.
/// Returns the optimal `(u, x)`, or `None` when infeasible.
pub(crate) fn maximize(c: [f64; 2], rows: &[Row], lo: [f64; 2], hi: [f64; 2]) -> Option<[f64; 2]> {
    if lo[0] > hi[0] || lo[1] > hi[1] {
        return None;
    }
    let mut v = [0.0; 2];
    for i in 0..2 {
        v[i] = if c[i] > 0.0 { hi[i] } else { lo[i] };
    }
    for k in 0..rows.len() {
        let r = rows[k];
        if r.a * v[0] + r.b * v[1] - r.g < EPS {
            continue;
        }
        let nn = r.a * r.a + r.b * r.b;
        if nn == 0.0 {
            return None; // 0 <= g with g < 0
        }
        // Line a·u + b·x = g: p(t) = p0 + t·d, p0 the point closest to the origin, d along it.
        let p0 = [r.a * r.g / nn, r.b * r.g / nn];
        let d = [-r.b, r.a];
        let (mut tmin, mut tmax) = (-T_INF, T_INF);
        let mut bound = |a: f64, b: f64, g: f64| -> bool {
            let alpha = a * d[0] + b * d[1];
            let beta = g - (a * p0[0] + b * p0[1]);
            if alpha > EPS {
                tmax = tmax.min(beta / alpha);
            } else if alpha < -EPS {
                tmin = tmin.max(beta / alpha);
            } else if beta < -PARALLEL_EPS {
                return false;
            }
            true
        };
        let box_rows = [(-1.0, 0.0, -lo[0]), (1.0, 0.0, hi[0]), (0.0, -1.0, -lo[1]), (0.0, 1.0, hi[1])];
        for &(a, b, g) in &box_rows {
            if !bound(a, b, g) {
                return None;
            }
        }
        for q in &rows[..k] {
            if !bound(q.a, q.b, q.g) {
                return None;
            }
        }
        if tmin > tmax {
            return None;
        }
        let t = if c[0] * d[0] + c[1] * d[1] > 0.0 { tmax } else { tmin };
        v = [p0[0] + t * d[0], p0[1] + t * d[1]];
    }
    Some(v)
}

/// Largest `u` in `[lo, hi]` with `a·u <= g - b·x` for every row, at fixed `x`.
pub(crate) fn max_u_at_x(x: f64, rows: &[Row], lo: f64, hi: f64) -> Option<f64> {
    let (mut ulo, mut uhi) = (lo, hi);
    for r in rows {
        let rhs = r.g - r.b * x;
        if r.a > EPS {
            uhi = uhi.min(rhs / r.a);
        } else if r.a < -EPS {
            ulo = ulo.max(rhs / r.a);
        } else if rhs < -EPS {
            return None;
        }
    }
    if ulo > uhi {
        None
    } else {
        Some(uhi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute force: best feasible vertex among all pairwise intersections (box included).
    fn brute(c: [f64; 2], rows: &[Row], lo: [f64; 2], hi: [f64; 2]) -> Option<f64> {
        let mut all: Vec<Row> = rows.to_vec();
        all.push(Row { a: -1.0, b: 0.0, g: -lo[0] });
        all.push(Row { a: 1.0, b: 0.0, g: hi[0] });
        all.push(Row { a: 0.0, b: -1.0, g: -lo[1] });
        all.push(Row { a: 0.0, b: 1.0, g: hi[1] });
        let mut best: Option<f64> = None;
        for i in 0..all.len() {
            for j in i + 1..all.len() {
                let det = all[i].a * all[j].b - all[i].b * all[j].a;
                if det.abs() < 1e-12 {
                    continue;
                }
                let u = (all[i].g * all[j].b - all[i].b * all[j].g) / det;
                let x = (all[i].a * all[j].g - all[i].g * all[j].a) / det;
                if all.iter().all(|r| r.a * u + r.b * x - r.g < 1e-7) {
                    let val = c[0] * u + c[1] * x;
                    best = Some(best.map_or(val, |b: f64| b.max(val)));
                }
            }
        }
        best
    }

    #[test]
    fn matches_vertex_enumeration_on_random_problems() {
        let mut state = 0x1234_5678_u64;
        let mut rnd = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        let (mut feasible, mut infeasible) = (0, 0);
        for _ in 0..3000 {
            let m = 2 + (rnd().abs() * 12.0) as usize;
            let rows: Vec<Row> = (0..m).map(|_| Row { a: rnd(), b: rnd(), g: rnd() + 0.3 }).collect();
            let c = [rnd(), rnd()];
            let (lo, hi) = ([-5.0, -5.0], [5.0, 5.0]);
            let got = maximize(c, &rows, lo, hi);
            let want = brute(c, &rows, lo, hi);
            match (got, want) {
                (Some(v), Some(w)) => {
                    feasible += 1;
                    assert!((c[0] * v[0] + c[1] * v[1] - w).abs() < 1e-7, "{v:?} vs {w}");
                    assert!(rows.iter().all(|r| r.a * v[0] + r.b * v[1] - r.g < 1e-7));
                }
                (None, None) => infeasible += 1,
                (g, w) => panic!("disagree: {g:?} vs {w:?}"),
            }
        }
        assert!(feasible > 1000 && infeasible > 50, "{feasible} {infeasible}");
    }
}
