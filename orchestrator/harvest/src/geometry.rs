//! Where the harvest puts the base, the lift and the grippers, in base_link (REP 105: x
//! forward, y left, z up). Figures are the robot's (models/robot/generate_urdf.py); the test
//! below checks them against the URDF so the two cannot drift apart.

use agrisim_math::vec3::{cross, dot, normalize};
use agrisim_robot::Pose;

/// Where the base stands to reach a fruit (shared with the benchmarks that lay out its task).
pub use agrisim_robot::reach::{standoff, standoff_facing, ARM_Y, REACH_AHEAD, REACH_LATERAL, SHOULDER_X};
/// Arm base height at lift 0 [m].
pub const ARM_Z0: f64 = 0.475;
/// Panda shoulder (joint 2) above the arm base [m] (DH d1).
pub const SHOULDER_UP: f64 = 0.333;
/// Lift range [m].
pub const LIFT_MAX: f64 = 0.8;
/// Where the fruit is below the grasping arm's shoulder when the lift is in place [m] (its
/// place sideways and ahead: [`agrisim_robot::reach`]).
pub const REACH_BELOW_SHOULDER: f64 = 0.1;
/// Pre-grasp stand-off along the approach axis [m].
pub const PRE_GRASP: f64 = 0.1;
/// How far past the fruit centre the TCP goes along the approach [m]. The TCP sits 5 mm
/// short of the pads' tips (hand z 0.1034, pads 0.0584..0.1084 in the URDF), so a fruit
/// centre a localization error beyond the aim (8 mm with the world's 3 mm grasp
/// tolerance) was outside the pads: in 200 benchmark trials four harvests failed after such
/// a first grasp closed on nothing (trial 101: 7.2 mm beyond) and every regrasp aim was
/// blocked. 10 mm deeper puts the centre 18 mm inside that limit, and a fruit of 30 mm
/// radius still clears the palm (hand z 0.0575) unless it is 6 mm nearer than believed.
pub const GRASP_DEPTH: f64 = 0.01;
/// How far the taker's TCP goes past the giver's along its approach, attempt by attempt [m].
/// The giver holds the fruit [`GRASP_DEPTH`] short of its TCP, so at twice that the taker
/// holds it as the giver did: its centre 15 mm inside the pad tips and 35 mm from the pads'
/// inner end (the world attaches a fruit whose centre lies between the pads, give or take
/// 3 mm). The first attempt used to stop at the giver's TCP, which left the fruit 2 mm
/// beyond the world's limit whenever the giver held it where it aimed: the first attempt
/// closed on nothing in 34 of 51 handovers of two row segments by sight and in 4 of 6
/// ground-truth harvests, 2.5 s lost each. The second attempt goes 15 mm deeper, for a
/// fruit held nearer the giver's palm (the test below: together they take every fruit the
/// giver can hold, but one within 5 mm of its palm).
pub const HANDOVER_DEPTHS: [f64; 2] = [2.0 * GRASP_DEPTH, 2.0 * GRASP_DEPTH + 0.015];
/// Retreats after the grasp, tried in order: back along the approach, and up [m].
pub const RETREATS: [[f64; 2]; 3] = [[0.14, 0.02], [0.14, 0.0], [0.08, 0.0]];
/// Lift height during handover and placement [m].
pub const LIFT_TRANSFER: f64 = 0.3;
/// Handover point relative to the arm bases' midpoint (x forward, z above the arm bases) [m].
pub const HANDOVER: [f64; 2] = [0.42, 0.30];
/// Harvest box: centre of its opening on base_link [m] (rear enclosure at x -0.35, crate
/// 0.4 x 0.6 x 0.25 on a 0.72 m deck).
pub const BOX_TOP: [f64; 3] = [-0.35, 0.0, 0.97];
/// The box's inside: floor height on base_link and half sizes of the opening (x, y) [m]
/// (walls and bottom 0.01 m thick in the URDF; checked below).
pub const BOX_FLOOR: f64 = 0.73;
pub const BOX_INNER_HALF: [f64; 2] = [0.19, 0.29];
/// How far the released fruit falls [m]: its bottom this far above the box floor, or above
/// the fruit already under it. A free fall of 3 cm lands at 0.77 m/s; the fruit may sit
/// 15 mm either way along the pads from where the node believes (the handover attempts'
/// offsets), so at worst 4.5 cm, 0.94 m/s, well under the world's 2.0 m/s bruise speed (a
/// 0.2 m drop, Sargent et al. 1992). Dropped from 0.13 m above the rim (0.35 m, 2.6 m/s)
/// every fruit was impact-bruised.
pub const PLACE_GAP: f64 = 0.03;
/// The hand comes over the box this far above the place pose, pointing down, then goes
/// straight down to it [m] (the fruit then 4 cm above the rim over an empty box).
pub const PLACE_DESCENT: f64 = 0.25;
/// Height added to every place pose for the second round of goals, where none of the first
/// could be reached [m] (a fall of at most 7.5 cm then, 1.2 m/s).
pub const PLACE_HIGHER: f64 = 0.03;
/// Fruit closer than this to the picked one (surface to surface) may be brushed: the
/// fingers push them aside on the way in [m].
pub const NEIGHBOUR_GAP: f64 = 0.02;
/// Gripper opening for approach [m] (Franka Hand maximum).
pub const OPEN_WIDTH: f64 = 0.08;

/// Lift height that brings the shoulder level with a fruit at height `z` [m].
pub fn lift_for(z: f64) -> f64 {
    (z - ARM_Z0 - SHOULDER_UP + REACH_BELOW_SHOULDER).clamp(0.0, LIFT_MAX)
}

/// A TCP goal: position plus the approach axis (tool z). `x_axis` fixes the roll (finger
/// closing direction is tool y); `None` leaves the roll about the approach axis free.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TcpGoal {
    pub position: [f64; 3],
    pub approach: [f64; 3],
    pub x_axis: Option<[f64; 3]>,
}

impl TcpGoal {
    /// The goal shifted along its approach axis by `d` (negative = back off).
    pub fn along(&self, d: f64) -> TcpGoal {
        let p = self.position;
        let a = self.approach;
        TcpGoal { position: [p[0] + d * a[0], p[1] + d * a[1], p[2] + d * a[2]], ..*self }
    }

    /// A full pose with the given roll vector (x axis, made orthogonal to the approach).
    pub fn pose_with_x(&self, x_hint: [f64; 3]) -> Pose {
        let z = normalize(self.approach);
        let d = dot(x_hint, z);
        let x = normalize([x_hint[0] - d * z[0], x_hint[1] - d * z[1], x_hint[2] - d * z[2]]);
        let y = cross(z, x);
        Pose { rot: [[x[0], y[0], z[0]], [x[1], y[1], z[1]], [x[2], y[2], z[2]]], trans: self.position }
    }
}

/// Grasp of a fruit at `c` (base frame) from the aisle by the arm on `side`: horizontal
/// approach into the row, roll free (the planner picks fingers that miss the truss).
pub fn grasp(c: [f64; 3], side: f64) -> TcpGoal {
    TcpGoal { position: c, approach: [0.0, side, 0.0], x_axis: None }
}

/// Approach directions tried in order, as (yaw, tilt) [rad] of the approach axis against the
/// horizontal line into the row: yaw > 0 turns it toward base +x (the hand comes from behind
/// the fruit), tilt > 0 points it upward (the hand comes from below). Straight in first, then
/// from below and above (a fruit hanging just above or below the target blocks the palm),
/// then ever more along the row (a fruit occluded by its neighbours is mostly open from the
/// side), then turned and tilted at once. Chosen with `examples/pregrasp_reach.rs`
/// (agrisim-bench) on 600 benchmark targets (3 seeds x 200, 5 scenes each): straight in and
/// tilted alone reach 98/104 free and 36/96 partly occluded fruit of the first 200 (the
/// blockers were all neighbouring fruit in front); the first nine 321/321 free and 272/279
/// partly occluded of the 600, all 21 321/321 and 278/279.
pub const APPROACHES: [(f64, f64); 21] = [
    (0.0, 0.0),
    (0.0, 0.44),
    (0.0, -0.44),
    (0.5, 0.0),
    (-0.5, 0.0),
    (0.9, 0.0),
    (-0.9, 0.0),
    (1.25, 0.0),
    (-1.25, 0.0),
    (0.5, 0.44),
    (-0.5, 0.44),
    (0.5, -0.44),
    (-0.5, -0.44),
    (0.9, 0.44),
    (-0.9, 0.44),
    (0.9, -0.44),
    (-0.9, -0.44),
    (1.25, 0.44),
    (-1.25, 0.44),
    (1.25, -0.44),
    (-1.25, -0.44),
];

/// Grasps of a fruit at `c` (base frame) by the arm on `side`, roll free, one per
/// [`APPROACHES`] entry in its order, each [`GRASP_DEPTH`] past the centre.
pub fn grasp_candidates(c: [f64; 3], side: f64) -> Vec<TcpGoal> {
    APPROACHES
        .iter()
        .map(|&(yaw, tilt)| {
            let h = tilt.cos();
            TcpGoal { position: c, approach: [h * yaw.sin(), side * h * yaw.cos(), tilt.sin()], x_axis: None }
                .along(GRASP_DEPTH)
        })
        .collect()
}

/// Handover point (base frame) at lift `lift`.
pub fn handover_point(lift: f64) -> [f64; 3] {
    [SHOULDER_X + HANDOVER[0], 0.0, ARM_Z0 + lift + HANDOVER[1]]
}

/// The giving arm (on `side`) presents the fruit with its approach axis toward the other
/// arm and the fingers closing vertically; the taking arm comes from the other side with
/// fingers closing horizontally, so the two hands' fingers never meet.
pub fn handover_goals(point: [f64; 3], giver_side: f64) -> (TcpGoal, TcpGoal) {
    // Giver: tool z = -side y; tool y (fingers) = z up, so tool x = y cross z.
    let zg = [0.0, -giver_side, 0.0];
    let xg = cross([0.0, 0.0, 1.0], zg);
    let giver = TcpGoal { position: point, approach: zg, x_axis: Some(xg) };
    // Taker: tool z = +side y; tool y (fingers) = x forward.
    let zt = [0.0, giver_side, 0.0];
    let xt = cross([1.0, 0.0, 0.0], zt);
    let taker = TcpGoal { position: point, approach: zt, x_axis: Some(xt) };
    (giver, taker)
}

/// Spots in the box a fruit is put down at (x, y from the centre of its opening) [m]: a 3 x 3
/// grid, the centre first, used in turn, so the fruit spread over the floor of the box. (With
/// the centre and four spots toward the corners, the five heaps reached the rim after about
/// 96 fruit of a 10 m row segment and every later fruit rolled off: 82 placement failures.)
/// The hand goes down into the box to put the fruit down, so the grid keeps the arm off the
/// walls: a scan of the place poses every 3 cm (the test below checks the grid) found both
/// arms reach them straight down at -0.09..+0.06 m across (toward the arms, the forearm
/// meets the front wall) and -0.16..+0.16 m along the box.
pub const PLACE_SPOTS: [(f64, f64); 9] = [
    (0.0, 0.0),
    (0.06, 0.15),
    (-0.08, -0.15),
    (0.06, -0.15),
    (-0.08, 0.15),
    (0.0, 0.15),
    (0.0, -0.15),
    (0.06, 0.0),
    (-0.08, 0.0),
];
pub const DROP_SPOTS: usize = PLACE_SPOTS.len();

/// Height of the centre of a fruit of `radius` put down at (x, y) (base frame) when it comes to
/// rest on the floor of the box or on the highest of the fruit already in it, `heap`
/// (centre, radius; base frame), that it would touch on the way down.
pub fn rest_height(x: f64, y: f64, radius: f64, heap: &[([f64; 3], f64)]) -> f64 {
    heap.iter().fold(BOX_FLOOR + radius, |z, &(c, r)| {
        let (d2, reach) = ((c[0] - x).powi(2) + (c[1] - y).powi(2), radius + r);
        if d2 < reach * reach {
            z.max(c[2] + (reach * reach - d2).sqrt())
        } else {
            z
        }
    })
}

/// Place poses in the harvest box, pointing down, roll free: for a held fruit of `radius`
/// whose centre is `below_tcp` below the TCP, the TCP where the fruit's bottom is
/// [`PLACE_GAP`] above where it would come to rest (the floor, or the fruit of `heap` under
/// it) at every spot of [`PLACE_SPOTS`], then the same [`PLACE_HIGHER`] higher. The hand comes
/// in [`PLACE_DESCENT`] above each (as a pre-grasp stand-off) and goes straight down.
pub fn place_goals(radius: f64, below_tcp: f64, heap: &[([f64; 3], f64)]) -> Vec<TcpGoal> {
    let mut v = vec![];
    for dz in [0.0, PLACE_HIGHER] {
        for (dx, dy) in PLACE_SPOTS {
            let (x, y) = (BOX_TOP[0] + dx, BOX_TOP[1] + dy);
            let z = rest_height(x, y, radius, heap) + PLACE_GAP + below_tcp + dz;
            v.push(TcpGoal { position: [x, y, z], approach: [0.0, 0.0, -1.0], x_axis: None });
        }
    }
    v
}

/// Whether a point (base frame) lies inside the harvest box's opening footprint, below its rim.
pub fn in_box(p: [f64; 3]) -> bool {
    (p[0] - BOX_TOP[0]).abs() < BOX_INNER_HALF[0]
        && (p[1] - BOX_TOP[1]).abs() < BOX_INNER_HALF[1]
        && p[2] < BOX_TOP[2]
        && p[2] > BOX_TOP[2] - 0.26
}

#[cfg(test)]
mod tests {
    use super::*;
    use agrisim_robot::Robot;
    use std::collections::BTreeMap;

    #[test]
    fn figures_match_the_urdf() {
        let robot = Robot::from_urdf_str(include_str!("../../../models/robot/agrisim_robot.urdf")).unwrap();
        let fk = robot.fk(&BTreeMap::new()).unwrap();
        let l0 = fk["left_link0"].trans;
        assert!(
            (l0[0] - SHOULDER_X).abs() < 1e-9 && (l0[1] - ARM_Y).abs() < 1e-9 && (l0[2] - ARM_Z0).abs() < 1e-9,
            "{l0:?}"
        );
        let r0 = fk["right_link0"].trans;
        assert!((r0[1] + ARM_Y).abs() < 1e-9);
        let b = fk["harvest_box_link"].trans;
        assert!(
            (b[0] - BOX_TOP[0]).abs() < 1e-9
                && (b[1] - BOX_TOP[1]).abs() < 1e-9
                && (b[2] + 0.25 - BOX_TOP[2]).abs() < 1e-9,
            "{b:?}"
        );
    }

    /// The box's inside as the URDF has it: the top of its bottom and the inner faces of its
    /// walls.
    #[test]
    fn box_inside_matches_the_urdf() {
        let robot = Robot::from_urdf_str(include_str!("../../../models/robot/agrisim_robot.urdf")).unwrap();
        let b = robot.fk(&BTreeMap::new()).unwrap()["harvest_box_link"].trans;
        let (mut floor, mut half) = (f64::NEG_INFINITY, [f64::INFINITY; 2]);
        for c in robot.colliders("harvest_box_link").unwrap() {
            let agrisim_robot::Shape::Box { size } = c.shape else { panic!("the box is made of boxes") };
            let o = c.origin.trans;
            if size[2] < size[0].min(size[1]) {
                floor = floor.max(b[2] + o[2] + 0.5 * size[2]);
            }
            for i in 0..2 {
                if size[i] < size[2].min(size[1 - i]) {
                    half[i] = half[i].min(o[i].abs() - 0.5 * size[i]);
                }
            }
        }
        assert!((floor - BOX_FLOOR).abs() < 1e-9, "floor {floor}");
        assert!((0..2).all(|i| (half[i] - BOX_INNER_HALF[i]).abs() < 1e-9), "inside half sizes {half:?}");
    }

    /// The taker's attempts ([`HANDOVER_DEPTHS`]) close on a fruit wherever the giver can
    /// hold it, from its pad tips to 5 mm short of the inner end of its pads; the first
    /// attempt, where the giver aimed to hold it, with 10 mm to spare either way. Pads and
    /// TCP from the URDF, as the world's grasp rule takes them, with its default 3 mm
    /// tolerance.
    #[test]
    fn the_taker_closes_where_the_giver_holds_the_fruit() {
        let robot = Robot::from_urdf_str(include_str!("../../../models/robot/agrisim_robot.urdf")).unwrap();
        let fk = robot.fk(&BTreeMap::new()).unwrap();
        let tcp_z = fk["left_hand"].inverse().transform_point(fk["left_hand_tcp"].trans)[2];
        let pads = agrisim_robot::model::RobotModel::load().unwrap().pads[0].z;
        let tol = 0.003;
        // The fruit centre's place along a hand's approach axis, from its TCP (+: beyond it),
        // where that hand's pads close on it.
        let window = [pads[0] - tol - tcp_z, pads[1] + tol - tcp_z];
        // Held by the giver at `s` from its TCP, the fruit is -s - depth from the taker's.
        let takes = |s: f64, depth: f64| {
            let u = -s - depth;
            u >= window[0] && u <= window[1]
        };
        let aim = -GRASP_DEPTH;
        let first = HANDOVER_DEPTHS[0];
        assert!(takes(aim - 0.01, first) && takes(aim + 0.01, first), "window {window:?}");
        let mut s = window[0] + 0.005;
        while s <= window[1] {
            assert!(HANDOVER_DEPTHS.iter().any(|&d| takes(s, d)), "no attempt takes a fruit held at {s:.3} m");
            s += 0.0005;
        }
    }

    /// Onto the empty floor the released fruit falls [`PLACE_GAP`]; wherever it sits along
    /// the pads (15 mm either way of the belief) and in either round of goals, it falls at
    /// most 8 cm, under 1.3 m/s (the world bruises above 2.0 m/s), and it is inside the box,
    /// clear of the floor, before it is let go.
    #[test]
    fn the_fruit_is_put_down_gently() {
        for r in [0.025, 0.04] {
            for below in HANDOVER_DEPTHS.map(|d| GRASP_DEPTH - d) {
                let goals = place_goals(r, below, &[]);
                assert_eq!(goals.len(), 2 * DROP_SPOTS);
                for (i, g) in goals.iter().enumerate() {
                    let fall = g.position[2] - below - r - BOX_FLOOR;
                    if i < DROP_SPOTS {
                        assert!((fall - PLACE_GAP).abs() < 1e-12, "goal {i}: {fall}");
                    }
                    for actual in [below - 0.015, below + 0.015] {
                        let fall = g.position[2] - actual - r - BOX_FLOOR;
                        assert!(fall > 0.0 && fall <= 0.08, "goal {i}, r {r}: falls {fall} m");
                        assert!((2.0 * 9.81 * fall).sqrt() < 1.3);
                        assert!(in_box([g.position[0], g.position[1], g.position[2] - actual]), "goal {i}");
                    }
                    let over = g.position[2] + PLACE_DESCENT - below - 0.015 - r - BOX_TOP[2];
                    assert!(over > 0.02, "goal {i}: the fruit comes in {over} m over the rim");
                }
            }
        }
    }

    /// A fruit already under a spot raises its place pose by what the new fruit rests on;
    /// one beside it, out of the new fruit's way down, does not.
    #[test]
    fn the_fruit_is_put_down_on_the_fruit_already_there() {
        let r = 0.03;
        let empty = place_goals(r, 0.01, &[]);
        let under = [BOX_TOP[0], BOX_TOP[1], BOX_FLOOR + r];
        let on_one = place_goals(r, 0.01, &[(under, r)]);
        assert!((on_one[0].position[2] - empty[0].position[2] - 2.0 * r).abs() < 1e-12);
        assert!((1..2 * DROP_SPOTS).filter(|&i| i != DROP_SPOTS).all(|i| on_one[i] == empty[i]));
        // Half a radius aside: it rests on its flank, lower than on its top.
        let aside = [under[0] + 0.5 * r, under[1], under[2]];
        let z = rest_height(BOX_TOP[0], BOX_TOP[1], r, &[(aside, r)]);
        assert!(z > BOX_FLOOR + r + 0.05 && z < under[2] + 2.0 * r, "{z}");
        // Two radii aside: out of the way.
        let beside = [under[0] + 2.0 * r + 1e-3, under[1], under[2]];
        assert_eq!(rest_height(BOX_TOP[0], BOX_TOP[1], r, &[(beside, r)]), BOX_FLOOR + r);
    }

    /// Every grasp candidate is a unit approach into the row (toward the fruit's side), and
    /// no two are alike.
    #[test]
    fn grasp_candidates_point_into_the_row() {
        for side in [1.0, -1.0] {
            let g = grasp_candidates([0.4, 0.85 * side, 1.0], side);
            assert_eq!(g.len(), APPROACHES.len());
            assert_eq!(g[0].approach, [0.0, side, 0.0], "straight in first");
            for (i, a) in g.iter().enumerate() {
                assert!((dot(a.approach, a.approach) - 1.0).abs() < 1e-12);
                assert!(a.approach[1] * side > 0.25, "candidate {i} points out of the row");
                for b in &g[..i] {
                    assert!(dot(a.approach, b.approach) < 0.99, "candidate {i} repeats another");
                }
            }
        }
    }

    #[test]
    fn handover_fingers_are_crossed() {
        let (g, t) = handover_goals([0.6, 0.0, 1.2], 1.0);
        let pg = g.pose_with_x(g.x_axis.unwrap());
        let pt = t.pose_with_x(t.x_axis.unwrap());
        // Finger directions (tool y) orthogonal; approach axes opposite.
        let yg = [pg.rot[0][1], pg.rot[1][1], pg.rot[2][1]];
        let yt = [pt.rot[0][1], pt.rot[1][1], pt.rot[2][1]];
        assert!(dot(yg, yt).abs() < 1e-12);
        assert!((dot(g.approach, t.approach) + 1.0).abs() < 1e-12);
        assert!((yg[2] - 1.0).abs() < 1e-12, "giver fingers close vertically");
    }
}
