//! RRT-Connect (Kuffner & LaValle, ICRA 2000) in the 7-D joint space, from one start to a
//! set of goal configurations: the goal tree has one root per goal, so the planner reaches
//! whichever IK solution is easiest instead of committing to one beforehand.
//! Seeded and bounded by an iteration count; edges are checked at a fixed joint resolution.

use crate::checker::{lerp, Checker};
use crate::layout::DOF;
use agrisim_math::Rng;

type Q = [f64; DOF];

#[derive(Debug, Clone, Copy)]
pub struct RrtConfig {
    /// Maximum extend/connect rounds.
    pub max_iterations: usize,
    /// Largest joint-space step (Euclidean, rad) of one extension.
    pub step: f64,
    /// Max joint motion (rad) between collision-checked samples of an edge.
    pub resolution: f64,
}

impl Default for RrtConfig {
    fn default() -> Self {
        RrtConfig { max_iterations: 20_000, step: 0.4, resolution: 0.02 }
    }
}

struct Tree {
    nodes: Vec<Q>,
    /// Parent index; `usize::MAX` for a root.
    parent: Vec<usize>,
    /// Root index (goal number for the goal tree).
    root: Vec<usize>,
}

impl Tree {
    fn new(roots: &[Q]) -> Tree {
        Tree { nodes: roots.to_vec(), parent: vec![usize::MAX; roots.len()], root: (0..roots.len()).collect() }
    }
    fn nearest(&self, q: &Q) -> usize {
        let mut best = (f64::INFINITY, 0);
        for (i, n) in self.nodes.iter().enumerate() {
            let d: f64 = n.iter().zip(q).map(|(a, b)| (a - b) * (a - b)).sum();
            if d < best.0 {
                best = (d, i);
            }
        }
        best.1
    }
    fn add(&mut self, q: Q, parent: usize) -> usize {
        self.nodes.push(q);
        self.parent.push(parent);
        self.root.push(self.root[parent]);
        self.nodes.len() - 1
    }
    /// Node `i` back to its root.
    fn branch(&self, mut i: usize) -> Vec<Q> {
        let mut out = vec![self.nodes[i]];
        while self.parent[i] != usize::MAX {
            i = self.parent[i];
            out.push(self.nodes[i]);
        }
        out
    }
}

enum Step {
    Trapped,
    Advanced(usize),
    Reached(usize),
}

/// Result of a successful search.
#[derive(Debug, Clone)]
pub struct RrtPath {
    pub waypoints: Vec<Q>,
    /// Which goal was reached.
    pub goal: usize,
    pub iterations: usize,
    pub nodes: usize,
}

fn extend(tree: &mut Tree, q: &Q, cfg: &RrtConfig, checker: &Checker) -> Step {
    let near = tree.nearest(q);
    let from = tree.nodes[near];
    let d = from.iter().zip(q).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt();
    let (to, reached) = if d <= cfg.step { (*q, true) } else { (lerp(&from, q, cfg.step / d), false) };
    if !checker.edge_valid(&from, &to, cfg.resolution) {
        return Step::Trapped;
    }
    let i = tree.add(to, near);
    if reached {
        Step::Reached(i)
    } else {
        Step::Advanced(i)
    }
}

fn connect(tree: &mut Tree, q: &Q, cfg: &RrtConfig, checker: &Checker) -> Step {
    loop {
        match extend(tree, q, cfg, checker) {
            Step::Advanced(_) => continue,
            s => return s,
        }
    }
}

/// Searches a path from `start` to any of `goals` (all assumed valid). `None` when the
/// iteration budget runs out.
pub fn rrt_connect(checker: &Checker, start: &Q, goals: &[Q], cfg: &RrtConfig, rng: &mut Rng) -> Option<RrtPath> {
    if goals.is_empty() {
        return None;
    }
    let mut a = Tree::new(&[*start]);
    let mut b = Tree::new(goals);
    // `a_is_start` tracks which tree is which after swaps.
    let mut a_is_start = true;
    let arm = checker.ctx.arm;
    for it in 0..cfg.max_iterations {
        let q_rand = arm.random_q(rng);
        if let Step::Advanced(i) | Step::Reached(i) = extend(&mut a, &q_rand, cfg, checker) {
            let q_new = a.nodes[i];
            if let Step::Reached(j) = connect(&mut b, &q_new, cfg, checker) {
                let (s, g, si, gi) = if a_is_start { (&a, &b, i, j) } else { (&b, &a, j, i) };
                let mut path = s.branch(si);
                path.reverse();
                let to_goal = g.branch(gi);
                // Both branches contain the meeting configuration: keep it once.
                path.extend_from_slice(&to_goal[1..]);
                return Some(RrtPath {
                    waypoints: path,
                    goal: g.root[gi],
                    iterations: it + 1,
                    nodes: a.nodes.len() + b.nodes.len(),
                });
            }
        }
        std::mem::swap(&mut a, &mut b);
        a_is_start = !a_is_start;
    }
    None
}
