//! The local planner's commands respect the velocity and acceleration limits from any state
//! (property test over random poses, velocities, plans and obstacle fields).

use agrisim_nav::controller::{Request, Velocity};
use agrisim_nav::dwa::{dwa, rotate_in_place, ControllerConfig, ESCAPE_SLACK};
use agrisim_nav::footprint::Footprint;
use agrisim_nav::Pose2;
use proptest::prelude::*;

fn within_limits(c: &ControllerConfig, v: &Velocity) -> bool {
    v.vx.abs() <= c.max_vx + 1e-9
        && v.vy.abs() <= c.max_vy + 1e-9
        && v.wz.abs() <= c.max_wz + 1e-9
        && v.vx.hypot(v.vy) <= c.max_speed_xy + 1e-9
}

fn within_window(c: &ControllerConfig, from: &Velocity, to: &Velocity) -> bool {
    (to.vx - from.vx).abs() <= c.acc_xy * c.period + 1e-9
        && (to.vy - from.vy).abs() <= c.acc_xy * c.period + 1e-9
        && (to.wz - from.wz).abs() <= c.acc_wz * c.period + 1e-9
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, .. ProptestConfig::default() })]

    #[test]
    fn dwa_respects_limits(
        x in -5.0..5.0f64, y in -5.0..5.0f64, yaw in -3.2..3.2f64,
        vx in -0.5..0.5f64, vy in -0.5..0.5f64, wz in -0.8..0.8f64,
        cx in -4.0..4.0f64, cy in -4.0..4.0f64, dyaw in -3.2..3.2f64,
        obstacles in proptest::collection::vec((-6.0..6.0f64, -6.0..6.0f64, 0.1..1.0f64), 0..6),
        max_v in 0.2..0.8f64, acc in 0.3..2.0f64,
    ) {
        let cfg = ControllerConfig { max_vx: max_v, max_vy: 0.8 * max_v, max_speed_xy: max_v, acc_xy: acc, ..ControllerConfig::default() };
        // A current velocity inside the limits (scale the random one into them).
        let mut cur = Velocity { vx: vx * max_v / 0.5, vy: vy * 0.8 * max_v / 0.5, wz };
        let s = cur.vx.hypot(cur.vy);
        if s > cfg.max_speed_xy { cur.vx *= cfg.max_speed_xy / s; cur.vy *= cfg.max_speed_xy / s; }
        let path: Vec<(f64, f64)> = (0..40).map(|i| (x + (cx - x) * i as f64 / 39.0, y + (cy - y) * i as f64 / 39.0)).collect();
        let req = Request { pose: Pose2::new(x, y, yaw), current: cur, path: &path, carrot: (cx, cy), desired_yaw: dyaw };
        let outline = Footprint::default().outline(0.05);
        let field = |px: f64, py: f64| obstacles.iter().map(|&(ox, oy, r)| ((px - ox).hypot(py - oy) - r).max(0.0)).fold(10.0, f64::min);
        let d = dwa(&cfg, &req, &outline, field);
        prop_assert!(within_limits(&cfg, &d.cmd), "{:?}", d.cmd);
        prop_assert!(within_window(&cfg, &cur, &d.cmd), "{:?} -> {:?}", cur, d.cmd);
        // A valid command keeps the margin, or, from inside it, never comes closer than
        // the robot is now (less the escape slack).
        let now = Footprint::clearance(&outline, &req.pose, field);
        if d.valid {
            prop_assert!(d.clearance >= cfg.collision_margin.min((now - ESCAPE_SLACK).max(0.0)), "{} from {}", d.clearance, now);
        }
        let r = rotate_in_place(&cfg, cur, dyaw);
        prop_assert!(within_limits(&cfg, &r) && within_window(&cfg, &cur, &r));
    }

    #[test]
    fn dwa_output_is_within_limits_even_from_out_of_limit_states(
        vx in -3.0..3.0f64, vy in -3.0..3.0f64, wz in -3.0..3.0f64,
    ) {
        let cfg = ControllerConfig::default();
        let path = [(0.0, 0.0), (1.0, 0.0)];
        let req = Request { pose: Pose2::default(), current: Velocity { vx, vy, wz }, path: &path, carrot: (1.0, 0.0), desired_yaw: 0.0 };
        let d = dwa(&cfg, &req, &Footprint::default().outline(0.05), |_, _| 10.0);
        prop_assert!(within_limits(&cfg, &d.cmd), "{:?}", d.cmd);
    }
}
