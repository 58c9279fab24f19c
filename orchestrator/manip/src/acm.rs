//! Allowed-collision matrix, computed the way MoveIt's setup assistant does: a pair of bodies
//! is not checked when it is adjacent in the kinematic tree, in contact in every sampled
//! configuration ("always"), or in none of them ("never", e.g. link1 and link4, which the
//! kinematics keep apart). Sampling uses the sphere model, a fixed seed and many
//! configurations (random joints, lift and finger opening), so the matrix is deterministic.
//! Pairs with the other arm are never disabled.

use crate::body::BodyPart;
use crate::layout::{HAND, NBODIES};
use crate::spheres::bodies_touch;
use agrisim_math::Rng;
use nalgebra::Point3;

/// Samples used to build the matrix.
pub const ACM_SAMPLES: usize = 20_000;
const ACM_SEED: u64 = 0x5EED_AC0F;

/// `true` = checked.
#[derive(Debug, Clone, Default)]
pub struct Acm {
    /// Arm body pairs (symmetric).
    pub pair: [[bool; NBODIES]; NBODIES],
    /// Fixed-body part i vs arm body b: `body[i][b]`.
    pub body: Vec<[bool; NBODIES]>,
}

impl Acm {
    /// Samples `n` configurations of an arm against the fixed-body `parts`. `pose` draws one
    /// configuration (joints, lift, finger opening) from the generator it is given, writes the
    /// arm's spheres there into the buffer (body after body, `offsets` being the sphere
    /// model's per-body ranges) and returns the lift; the arm's kinematics and sphere model
    /// must be set ([`ArmModel::from_robot`](crate::chain::ArmModel::from_robot) passes them).
    #[allow(clippy::needless_range_loop)] // body pairs (a, b) index the hit matrix and the sphere ranges
    pub fn sample(
        parts: &[BodyPart],
        n: usize,
        offsets: [usize; NBODIES + 1],
        mut pose: impl FnMut(&mut Rng, &mut Vec<(Point3<f64>, f64)>) -> f64,
    ) -> Acm {
        let mut rng = Rng::new(ACM_SEED);
        let mut pair_hits = [[0usize; NBODIES]; NBODIES];
        let mut body_hits = vec![[0usize; NBODIES]; parts.len()];
        let mut buf = Vec::new();
        let off = offsets;
        let r = |b: usize| off[b]..off[b + 1];
        for _ in 0..n {
            let lift = pose(&mut rng, &mut buf);
            for a in 0..NBODIES {
                for b in a + 1..NBODIES {
                    if bodies_touch(&buf, r(a), &buf, r(b), 0.0) {
                        pair_hits[a][b] += 1;
                    }
                }
            }
            for (i, p) in parts.iter().enumerate() {
                let prim = p.prim(lift);
                for b in 0..NBODIES {
                    if buf[r(b)].iter().any(|(c, rad)| prim.overlaps_sphere(c, *rad)) {
                        body_hits[i][b] += 1;
                    }
                }
            }
        }
        let mut pair = [[false; NBODIES]; NBODIES];
        for a in 0..NBODIES {
            for b in a + 1..NBODIES {
                let h = pair_hits[a][b];
                // Adjacent: consecutive links, link7-hand, hand-finger; the two fingers are
                // driven together by the gripper, not by the planner.
                let adjacent = b == a + 1 && b <= HAND || (a == HAND && b > HAND) || (a == HAND + 1 && b == HAND + 2);
                let on = !adjacent && h != 0 && h != n;
                pair[a][b] = on;
                pair[b][a] = on;
            }
        }
        // The arm's own link0 sits on the carriage (lift_link): adjacent in the tree.
        let body = body_hits
            .iter()
            .zip(parts)
            .map(|(hits, p)| {
                std::array::from_fn(|b| !(b == 0 && p.link == "lift_link") && hits[b] != 0 && hits[b] != n)
            })
            .collect();
        Acm { pair, body }
    }

    /// Number of checked arm-arm body pairs (for reports).
    pub fn enabled_pairs(&self) -> usize {
        (0..NBODIES).map(|a| (a + 1..NBODIES).filter(|&b| self.pair[a][b]).count()).sum()
    }
}
