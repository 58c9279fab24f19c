//! Path shortening after RRT-Connect: random shortcutting between points on two random
//! segments (Geraerts & Overmars 2007, "partial" shortcuts anywhere on the path, not only at
//! waypoints), then removal of waypoints whose neighbours see each other. A replacement edge
//! is taken only if the checker validates it at the planner's resolution, and a straight
//! joint-space segment is never longer than the polyline it replaces, so the path never
//! gets longer and never gains a collision the checker can see.

use crate::checker::{lerp, Checker};
use crate::layout::DOF;
use agrisim_math::Rng;

type Q = [f64; DOF];

/// Joint-space (Euclidean) length of a polyline.
pub fn path_length(p: &[Q]) -> f64 {
    p.windows(2).map(|w| crate::ik::dist(&w[0], &w[1])).sum()
}

/// Random shortcutting: `iterations` attempts, each between a random point of segment i and
/// one of segment j > i.
pub fn shortcut(path: &mut Vec<Q>, checker: &Checker, resolution: f64, iterations: usize, rng: &mut Rng) {
    for _ in 0..iterations {
        let n = path.len();
        if n < 3 {
            break;
        }
        let segs = n - 1;
        let i = (rng.next_u64() % segs as u64) as usize;
        let j = (rng.next_u64() % segs as u64) as usize;
        let (i, j) = (i.min(j), i.max(j));
        if i == j {
            continue;
        }
        let a = lerp(&path[i], &path[i + 1], rng.uniform());
        let b = lerp(&path[j], &path[j + 1], rng.uniform());
        if !checker.is_valid(&a) || !checker.edge_valid(&a, &b, resolution) {
            continue;
        }
        // path[..=i] + a + b + path[j+1..]
        let mut out = Vec::with_capacity(n);
        out.extend_from_slice(&path[..=i]);
        out.push(a);
        out.push(b);
        out.extend_from_slice(&path[j + 1..]);
        if path_length(&out) < path_length(path) {
            *path = out;
        }
    }
    remove_redundant(path, checker, resolution);
}

/// Drops every waypoint whose predecessor can reach its successor directly (greedy, one pass
/// from the start; repeated until nothing changes).
pub fn remove_redundant(path: &mut Vec<Q>, checker: &Checker, resolution: f64) {
    loop {
        let mut changed = false;
        let mut k = 1;
        while k + 1 < path.len() {
            if checker.edge_valid(&path[k - 1], &path[k + 1], resolution) {
                path.remove(k);
                changed = true;
            } else {
                k += 1;
            }
        }
        // Also merge near-duplicate points left by partial shortcuts.
        path.dedup_by(|b, a| crate::ik::dist(a, b) < 1e-9);
        if !changed {
            break;
        }
    }
}
