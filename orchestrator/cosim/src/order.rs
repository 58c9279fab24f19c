//! The order in which the master steps and initializes the components of a system.
//!
//! Gauss-Seidel: a component steps after the components it takes values from, and reads
//! their values at the end of the step it is about to take, so the world sees the base where
//! it is now, not one step ago. Where connections form a loop (the grippers and the world:
//! joint angles go to the world, grasp widths come back), no order can serve every
//! connection; the order chosen delays the fewest connections (those read before their source
//! steps, one step late) and keeps the system file's order among equals. The same order drives
//! initialization: a component's inputs are all set before its outputs are read, so no model
//! computes its initial state twice unless a loop needs it; loops are iterated to a fixed point.
//!
//! The FMUs' declared initial dependencies (ModelStructure `InitialUnknown`) tell which
//! delayed connections matter at initialization: one whose destination has no initial
//! output depending on it needs no iteration.

use crate::system::{Port, System};

/// Above this many components the exact search gives way to a greedy topological order.
const EXACT_LIMIT: usize = 16;

/// How the master orders a system.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Order {
    /// Component indices in stepping (and initialization) order.
    pub step: Vec<usize>,
    /// FMU-to-FMU routes whose destination steps before their source: read one step late.
    pub delayed: Vec<usize>,
    /// Delayed routes some initial output of the destination depends on: initialization
    /// iterates through them until nothing changes.
    pub init_loops: Vec<usize>,
}

/// `(source component, destination component)` of an FMU-to-FMU route.
pub fn fmu_link(system: &System, r: usize) -> Option<(usize, usize)> {
    match (&system.routes[r].from, &system.routes[r].to) {
        (Port::Fmu { comp: a, .. }, Port::Fmu { comp: b, .. }) => Some((*a, *b)),
        _ => None,
    }
}

/// The stepping order of `system`.
pub fn plan(system: &System) -> Order {
    let n = system.components.len();
    // weight[a][b]: routes from component a to component b.
    let mut weight = vec![vec![0u32; n]; n];
    for r in 0..system.routes.len() {
        if let Some((a, b)) = fmu_link(system, r) {
            if a != b {
                weight[a][b] += 1;
            }
        }
    }
    let step = if n <= EXACT_LIMIT { exact_order(&weight) } else { greedy_order(&weight) };
    let mut position = vec![0; n];
    for (i, &c) in step.iter().enumerate() {
        position[c] = i;
    }
    let delayed: Vec<usize> = (0..system.routes.len())
        .filter(|&r| fmu_link(system, r).is_some_and(|(a, b)| position[a] >= position[b]))
        .collect();
    let init_loops = delayed.iter().copied().filter(|&r| matters_at_init(system, r)).collect();
    Order { step, delayed, init_loops }
}

/// Whether some initial output of route `r`'s destination depends on its input.
fn matters_at_init(system: &System, r: usize) -> bool {
    let Port::Fmu { comp, var, .. } = &system.routes[r].to else { return false };
    let md = &system.components[*comp].archive.md;
    md.variables
        .iter()
        .filter(|v| v.causality == crate::model_description::Causality::Output)
        .any(|v| md.initial_depends(v.value_reference, var.value_reference))
}

/// The order with the fewest delayed routes (ties: the earliest in the system file's order,
/// lexicographically), by dynamic programming over subsets: placing `v` after the set `S`
/// delays the routes from `v` into `S`.
fn exact_order(weight: &[Vec<u32>]) -> Vec<usize> {
    let n = weight.len();
    let full = (1usize << n) - 1;
    // best[S]: (cost, sequence) of the best arrangement of S as the first |S| components.
    let mut best: Vec<Option<(u32, Vec<usize>)>> = vec![None; full + 1];
    best[0] = Some((0, vec![]));
    for mask in 0..=full {
        let Some((cost, seq)) = best[mask].clone() else { continue };
        for v in (0..n).filter(|v| mask & (1 << v) == 0) {
            let added: u32 = (0..n).filter(|u| mask & (1 << u) != 0).map(|u| weight[v][u]).sum();
            let next = mask | (1 << v);
            let mut cand = seq.clone();
            cand.push(v);
            let better = match &best[next] {
                None => true,
                Some((c, s)) => cost + added < *c || (cost + added == *c && cand < *s),
            };
            if better {
                best[next] = Some((cost + added, cand));
            }
        }
    }
    best[full].take().map(|(_, s)| s).unwrap_or_default()
}

/// Kahn's topological order, earliest component first; in a loop, the earliest remaining
/// component goes next.
fn greedy_order(weight: &[Vec<u32>]) -> Vec<usize> {
    let n = weight.len();
    let mut placed = vec![false; n];
    let mut order = Vec::with_capacity(n);
    while order.len() < n {
        let ready = (0..n).find(|&v| !placed[v] && (0..n).all(|u| placed[u] || u == v || weight[u][v] == 0));
        let v = ready.unwrap_or_else(|| (0..n).find(|&v| !placed[v]).expect("some component remains"));
        placed[v] = true;
        order.push(v);
    }
    order
}

/// The plan in words, for `agrisim run --explain`.
pub fn explain(system: &System, order: &Order) -> String {
    let name = |c: usize| system.components[c].name.as_str();
    let labels =
        |routes: &[usize]| routes.iter().map(|&r| format!("  {}\n", system.routes[r].label)).collect::<String>();
    let mut out = String::new();
    let names: Vec<&str> = order.step.iter().map(|&c| name(c)).collect();
    out.push_str(&format!(
        "Step order (Gauss-Seidel; each component reads the values its sources have after this step): {}\n",
        names.join(" -> ")
    ));
    if order.delayed.is_empty() {
        out.push_str("Delayed connections: none (no loop)\n");
    } else {
        out.push_str("Delayed connections (read before their source steps, one step late; they close a loop):\n");
        out.push_str(&labels(&order.delayed));
    }
    out.push_str(
        "Initialization: one pass in the step order (every input of a component set before its outputs are read)",
    );
    if order.init_loops.is_empty() {
        out.push_str("; no loop needs iteration\n");
    } else {
        out.push_str(", then fixed-point passes until nothing changes through:\n");
        out.push_str(&labels(&order.init_loops));
    }
    out.push_str("Exchange periods:\n");
    for r in &system.routes {
        out.push_str(&format!("  {} every {} step(s)\n", r.label, r.period_ticks));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn w(n: usize, edges: &[(usize, usize, u32)]) -> Vec<Vec<u32>> {
        let mut m = vec![vec![0; n]; n];
        for &(a, b, k) in edges {
            m[a][b] += k;
        }
        m
    }

    #[test]
    fn chains_are_topological_and_loops_cut_at_the_lightest_link() {
        // File order: world(0), chassis(1), lift(2), arm(3); lift -> chassis -> world,
        // arm -> world (8 routes), world -> arm (1 route).
        let m = w(4, &[(2, 1, 2), (1, 0, 3), (3, 0, 8), (0, 3, 1)]);
        assert_eq!(exact_order(&m), vec![2, 1, 3, 0]);
        assert_eq!(greedy_order(&w(3, &[(2, 1, 1), (1, 0, 1)])), vec![2, 1, 0]);
        // No connections: the file's order.
        assert_eq!(exact_order(&w(3, &[])), vec![0, 1, 2]);
    }

    #[test]
    fn exact_and_greedy_agree_on_acyclic_graphs() {
        let mut rng = agrisim_math::Rng::new(7);
        for _ in 0..200 {
            let n = 1 + rng.below(7) as usize;
            // Random DAG over a random permutation.
            let mut perm: Vec<usize> = (0..n).collect();
            for i in (1..n).rev() {
                perm.swap(i, rng.below(i as u64 + 1) as usize);
            }
            let mut edges = vec![];
            for i in 0..n {
                for j in i + 1..n {
                    if rng.below(3) == 0 {
                        edges.push((perm[i], perm[j], 1 + rng.below(3) as u32));
                    }
                }
            }
            let m = w(n, &edges);
            for order in [exact_order(&m), greedy_order(&m)] {
                let pos: Vec<usize> = (0..n).map(|c| order.iter().position(|&x| x == c).unwrap()).collect();
                assert!(edges.iter().all(|&(a, b, _)| pos[a] < pos[b]), "{edges:?} -> {order:?}");
            }
        }
    }
}
