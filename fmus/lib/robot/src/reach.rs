//! Where the base stands for an arm to reach a point: the pose the harvest node drives to and
//! the one a benchmark's task is laid out from (trial start poses, row segments), kept here
//! so the node and the benchmarks that judge it agree without either reaching into the
//! other. Figures in base_link (REP 105: x forward, y left, z up); the arm mounting is the
//! URDF's (the harvest node's test checks it against the URDF).

/// Arm base (link0) x on base_link [m] (lift carriage centre).
pub const SHOULDER_X: f64 = 0.2;
/// Arm bases left/right of the carriage centre [m].
pub const ARM_Y: f64 = 0.25;
/// Where the fruit is relative to the grasping arm's base when the base is in place [m]:
/// sideways (a horizontal approach still works 0.1 m closer, at the pre-grasp), ahead of the
/// arm (straight sideways at shoulder height the Panda's wrist meets its own shoulder and IK
/// fails).
pub const REACH_LATERAL: f64 = 0.6;
pub const REACH_AHEAD: f64 = 0.2;

/// Base pose (x, y, yaw) in the map frame that puts a fruit at `fruit` (map) within reach
/// of the arm on `side` (+1 left, -1 right): facing +x along the aisle.
pub fn standoff(fruit: [f64; 3], side: f64) -> [f64; 3] {
    standoff_facing(fruit, side, 0.0)
}

/// The base pose (x, y, yaw = `heading`) from which the arm on `side` (of the base: +1 left)
/// reaches `fruit`: the fruit sits at the same place in base_link whichever way the base
/// faces, so a base that starts facing down the aisle harvests without turning round.
pub fn standoff_facing(fruit: [f64; 3], side: f64, heading: f64) -> [f64; 3] {
    let (ax, ay) = (SHOULDER_X + REACH_AHEAD, side * (ARM_Y + REACH_LATERAL));
    let (s, c) = heading.sin_cos();
    [fruit[0] - (c * ax - s * ay), fruit[1] - (s * ax + c * ay), heading]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Facing +x or -x, the fruit is at the same place in base_link: ahead of the shoulder,
    /// on the grasping arm's side.
    #[test]
    fn the_fruit_sits_alike_in_base_link_for_either_heading() {
        let fruit = [5.0, 2.0, 1.2];
        for (heading, side) in [(0.0, 1.0), (0.0, -1.0), (std::f64::consts::PI, 1.0), (std::f64::consts::PI, -1.0)] {
            let [x, y, yaw] = standoff_facing(fruit, side, heading);
            let (s, c) = yaw.sin_cos();
            let (dx, dy) = (fruit[0] - x, fruit[1] - y);
            let (bx, by) = (c * dx + s * dy, -s * dx + c * dy);
            assert!(
                (bx - (SHOULDER_X + REACH_AHEAD)).abs() < 1e-12 && (by - side * (ARM_Y + REACH_LATERAL)).abs() < 1e-12,
                "{heading} {side}: ({bx}, {by})"
            );
        }
        assert_eq!(standoff(fruit, 1.0), standoff_facing(fruit, 1.0, 0.0));
    }
}
