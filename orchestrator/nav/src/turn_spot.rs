//! Where to turn when the goal's heading cannot be reached in place: a 1.2 x 0.9 m base at a
//! goal beside an obstacle (a box next to the target in an aisle) sweeps its corners into it
//! while turning. The omnidirectional base shifts to a nearby spot where the turn is clear,
//! turns there, and shifts back to the goal at the goal's heading (blocked-aisles trial 100
//! stood at its goal unable to turn until it was declared stuck). Where the goal pose itself
//! is closer to the obstacle than the collision margin, it ends at the nearest point within
//! [`END_RADIUS`] of the goal that keeps the margin (inside the goal tolerance).

use agrisim_math::pose2::{wrap_angle, Pose2};

/// How far from the goal a spot may be [m], and the spacing of the spots tried [m].
pub const RADIUS: f64 = 2.0;
pub const STEP: f64 = 0.05;
/// How far from the goal the turn may end [m] (well inside Nav2's 0.25 m goal tolerance).
pub const END_RADIUS: f64 = 0.15;
/// Heading increment of the turn check [rad].
const TURN_STEP: f64 = 0.05;

/// Is the footprint at least `margin` clear while turning in place at (x, y) from yaw `from`
/// to yaw `to` (the shorter way)? `clearance` gives the footprint's clearance at a pose.
pub fn turn_clear(x: f64, y: f64, from: f64, to: f64, margin: f64, clearance: &impl Fn(&Pose2) -> f64) -> bool {
    let err = wrap_angle(to - from);
    let steps = ((err.abs() / TURN_STEP).ceil() as usize).max(1);
    (0..=steps).all(|k| clearance(&Pose2::new(x, y, from + err * k as f64 / steps as f64)) >= margin)
}

/// Is the footprint at least `margin` clear along the straight shift from `a` to `b` at
/// heading `yaw`?
pub fn shift_clear(a: (f64, f64), b: (f64, f64), yaw: f64, margin: f64, clearance: &impl Fn(&Pose2) -> f64) -> bool {
    let n = ((b.0 - a.0).hypot(b.1 - a.1) / STEP).ceil().max(1.0) as usize;
    (0..=n).all(|k| {
        let t = k as f64 / n as f64;
        clearance(&Pose2::new(a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1), yaw)) >= margin
    })
}

/// Grid offsets (squared length, i, j) in steps within [`RADIUS`], nearest first (ties in
/// grid order): sorted once, since the executor searches every exchange it cannot turn.
fn offsets() -> &'static [(i64, i64, i64)] {
    static OFFSETS: std::sync::OnceLock<Vec<(i64, i64, i64)>> = std::sync::OnceLock::new();
    OFFSETS.get_or_init(|| {
        let n = (RADIUS / STEP).round() as i64;
        let mut v: Vec<(i64, i64, i64)> = Vec::new();
        for i in -n..=n {
            for j in -n..=n {
                if i * i + j * j <= n * n {
                    v.push((i * i + j * j, i, j));
                }
            }
        }
        v.sort_unstable();
        v
    })
}

/// Points on a [`STEP`] grid about `c` within `radius` (at most [`RADIUS`]), nearest first
/// (ties in grid order).
fn around(c: (f64, f64), radius: f64) -> impl Iterator<Item = (f64, f64)> {
    let n = (radius / STEP).round() as i64;
    offsets()
        .iter()
        .take_while(move |&&(d2, _, _)| d2 <= n * n)
        .map(move |&(_, i, j)| (c.0 + i as f64 * STEP, c.1 + j as f64 * STEP))
}

/// The spot nearest `goal` (within [`RADIUS`]) that the robot at `pose` reaches by a straight
/// shift at its heading and where it can turn to the goal's heading, with the point where it
/// then ends: the nearest to the goal (within [`END_RADIUS`]) whose footprint at the goal's
/// heading keeps `margin`, reached from the spot by a straight shift at that heading.
pub fn find(
    pose: &Pose2,
    goal: &Pose2,
    margin: f64,
    clearance: impl Fn(&Pose2) -> f64,
) -> Option<((f64, f64), (f64, f64))> {
    let end = around((goal.x, goal.y), END_RADIUS).find(|e| clearance(&Pose2::new(e.0, e.1, goal.yaw)) >= margin)?;
    let spot = around((goal.x, goal.y), RADIUS).find(|&s| {
        shift_clear((pose.x, pose.y), s, pose.yaw, margin, &clearance)
            && shift_clear(s, end, goal.yaw, margin, &clearance)
            && turn_clear(s.0, s.1, pose.yaw, goal.yaw, margin, &clearance)
    })?;
    Some((spot, end))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::footprint::Footprint;

    /// An aisle 2 m wide (y 0..2) with a box reaching 0.35 m into it from y = 0 at x 0..0.55:
    /// at the aisle's centre line beside the box a 1.2 x 0.9 m base cannot turn, but it can
    /// after shifting away from the box, and it comes back at the new heading.
    #[test]
    fn finds_a_spot_away_from_a_box_beside_the_goal() {
        let outline = Footprint::default().outline(0.05);
        let clearance = |p: &Pose2| {
            Footprint::clearance(&outline, p, |x, y| {
                let walls = y.min(2.0 - y);
                let dx = (x - 0.55).max(0.0 - x).max(0.0);
                let dy = (y - 0.35).max(0.0);
                walls.min(dx.hypot(dy)).max(0.0)
            })
        };
        let (pose, goal) = (Pose2::new(0.45, 1.0, 0.0), Pose2::new(0.45, 1.0, 2.9));
        assert!(!turn_clear(goal.x, goal.y, pose.yaw, goal.yaw, 0.06, &clearance));
        let (s, end) = find(&pose, &goal, 0.06, clearance).expect("a spot");
        assert!((end.0 - goal.x).hypot(end.1 - goal.y) <= END_RADIUS + 1e-9);
        assert!(s.1 > goal.y, "away from the box: {s:?}");
        assert!(turn_clear(s.0, s.1, pose.yaw, goal.yaw, 0.06, &clearance));
        assert!((s.0 - goal.x).hypot(s.1 - goal.y) <= RADIUS + 1e-9);
        // Nowhere to turn in a 1.2 m corridor.
        let narrow = |p: &Pose2| Footprint::clearance(&outline, p, |_, y| (y - 0.4).min(1.6 - y).max(0.0));
        assert!(find(&pose, &goal, 0.06, narrow).is_none());
    }
}
