//! RRT-Connect in random cluttered scenes, the exact check of returned paths, shortcutting,
//! determinism.

use agrisim_manip::checker::{Checker, Context};
use agrisim_manip::exact::{exact_check, EXACT_RESOLUTION};
use agrisim_manip::planner::{PlanError, Planner};
use agrisim_manip::scene::{Obstacle, ObstacleKind, Scene};
use agrisim_manip::shortcut::{path_length, shortcut};
use agrisim_manip::{ArmModel, Rng, Side};
use agrisim_robot::Shape;
use nalgebra::Isometry3;

const READY: [f64; 7] = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785];

/// Vertical stems and boxes in front of and beside the left arm.
fn clutter(rng: &mut Rng) -> Scene {
    let mut v = Vec::new();
    for i in 0..8 {
        let p = Isometry3::translation(0.55 + 0.4 * rng.uniform(), -0.6 + 1.4 * rng.uniform(), 1.2);
        v.push(Obstacle::new(
            format!("stem{i}"),
            Shape::Cylinder { radius: 0.015, length: 2.4 },
            p,
            ObstacleKind::Solid,
        ));
    }
    for i in 0..4 {
        let p =
            Isometry3::translation(0.5 + 0.4 * rng.uniform(), -0.5 + 1.3 * rng.uniform(), 0.7 + 0.9 * rng.uniform());
        v.push(Obstacle::new(format!("box{i}"), Shape::Box { size: [0.1, 0.1, 0.1] }, p, ObstacleKind::Solid));
    }
    Scene::new(v)
}

/// A random valid configuration of `checker`'s arm with its TCP in front of the robot.
fn random_goal(arm: &ArmModel, checker: &Checker, rng: &mut Rng) -> [f64; 7] {
    loop {
        let q = arm.random_q(rng);
        let p = arm.fk_iso(0.3, &q).translation.vector;
        if p.x > 0.45 && checker.is_valid(&q) {
            return q;
        }
    }
}

#[test]
fn rrt_connect_finds_exactly_valid_paths_in_cluttered_scenes() {
    let left = ArmModel::new(Side::Left);
    let right = ArmModel::new(Side::Right);
    let planner = Planner::default();
    let mut rng = Rng::new(100);
    let (mut ok, mut rrt_used, mut n) = (0, 0, 0);
    while n < 60 {
        let scene = clutter(&mut rng);
        let ctx = Context::new(&left, 0.3, &scene).with_other(&right, READY, 0.04);
        let checker = Checker::new(ctx);
        if !checker.is_valid(&READY) {
            continue;
        }
        n += 1;
        let goals: Vec<[f64; 7]> = (0..3).map(|_| random_goal(&left, &checker, &mut rng)).collect();
        match planner.plan(&ctx, &READY, &goals, &mut rng) {
            Ok(p) => {
                ok += 1;
                if p.stats.iterations > 0 {
                    rrt_used += 1;
                }
                assert_eq!(p.waypoints[0], READY);
                assert_eq!(*p.waypoints.last().unwrap(), goals[p.goal_index]);
                // Every returned path passes the exact check (planner did it; do it again
                // independently at a finer resolution) and the sphere check at every waypoint.
                exact_check(&ctx, &p.waypoints, EXACT_RESOLUTION * 0.5).expect("exact check");
                assert!(p.waypoints.iter().all(|q| checker.is_valid(q)));
                assert!(p.stats.length <= p.stats.raw_length + 1e-9);
            }
            Err(e) => println!("failed: {e}"),
        }
    }
    println!("{ok}/{n} planned, {rrt_used} needed RRT-Connect");
    assert!(ok >= n * 95 / 100, "{ok}/{n}");
    assert!(rrt_used >= 10, "scenes should not all be trivially direct ({rrt_used})");
}

#[test]
fn shortcutting_never_lengthens_nor_collides() {
    let left = ArmModel::new(Side::Left);
    let mut rng = Rng::new(7);
    for _ in 0..30 {
        let scene = clutter(&mut rng);
        let ctx = Context::new(&left, 0.3, &scene);
        let checker = Checker::new(ctx);
        // A valid zig-zag path: random valid waypoints joined by valid edges.
        let mut path = vec![READY];
        if !checker.is_valid(&READY) {
            continue;
        }
        while path.len() < 8 {
            let last = *path.last().unwrap();
            let q: [f64; 7] = std::array::from_fn(|i| {
                (last[i] + 0.6 * (rng.uniform() - 0.5)).clamp(left.lower()[i], left.upper()[i])
            });
            if checker.is_valid(&q) && checker.edge_valid(&last, &q, 0.02) {
                path.push(q);
            }
        }
        let before = path_length(&path);
        let (first, last) = (path[0], *path.last().unwrap());
        shortcut(&mut path, &checker, 0.02, 100, &mut rng);
        assert!(path_length(&path) <= before + 1e-12);
        assert_eq!((path[0], *path.last().unwrap()), (first, last));
        for w in path.windows(2) {
            assert!(checker.edge_valid(&w[0], &w[1], 0.02), "shortcut introduced a colliding edge");
        }
    }
}

#[test]
fn same_seed_same_plan() {
    let left = ArmModel::new(Side::Left);
    let right = ArmModel::new(Side::Right);
    let mut rng = Rng::new(55);
    let scene = clutter(&mut rng);
    let ctx = Context::new(&left, 0.3, &scene).with_other(&right, READY, 0.04);
    let checker = Checker::new(ctx);
    let goals: Vec<[f64; 7]> = (0..3).map(|_| random_goal(&left, &checker, &mut rng)).collect();
    let plan = |seed| {
        Planner::default()
            .plan(&ctx, &READY, &goals, &mut Rng::new(seed))
            .map(|p| (p.waypoints, p.goal_index, p.stats.iterations))
    };
    let a = plan(9).expect("plans");
    assert_eq!(a, plan(9).unwrap());
    let _ = plan(10); // another seed may differ; only the same one must repeat.
}

#[test]
fn errors_are_reported() {
    let left = ArmModel::new(Side::Left);
    let scene = Scene::empty();
    let ctx = Context::new(&left, 0.3, &scene);
    let mut rng = Rng::new(1);
    let p = Planner::default();
    assert_eq!(p.plan(&ctx, &[0.0; 7], &[READY], &mut rng).unwrap_err(), PlanError::StartOutOfLimits);
    assert_eq!(p.plan(&ctx, &READY, &[], &mut rng).unwrap_err(), PlanError::NoValidGoal);
    // A goal inside a box is invalid.
    let tcp = left.fk_iso(0.3, &READY);
    let boxed = Scene::new(vec![Obstacle::new("wall", Shape::Box { size: [0.3, 0.3, 0.3] }, tcp, ObstacleKind::Solid)]);
    let ctx2 = Context::new(&left, 0.3, &boxed);
    let start = [0.0, -0.3, 0.0, -1.0, 0.0, 1.0, 0.785];
    assert!(matches!(p.plan(&ctx2, &READY, &[start], &mut rng), Err(PlanError::StartInCollision(_))));
    assert_eq!(p.plan(&ctx2, &start, &[READY], &mut rng).unwrap_err(), PlanError::NoValidGoal);
}

#[test]
fn cartesian_approach_is_a_straight_line_and_stops_at_obstacles() {
    use agrisim_manip::cartesian_path;
    use nalgebra::Vector3;
    let left = ArmModel::new(Side::Left);
    let scene = Scene::empty();
    let checker = Checker::new(Context::new(&left, 0.3, &scene));
    let p0 = left.fk_iso(0.3, &READY);
    // 10 cm forward along x from the ready pose.
    let forward = |checker: &Checker| cartesian_path(checker, &READY, Vector3::new(0.1, 0.0, 0.0), 0.005, 0.2, 0.02);
    let path = forward(&checker).expect("free line");
    assert_eq!(path.len(), 21);
    for (k, q) in path.iter().enumerate() {
        let p = left.fk_iso(0.3, q);
        let want = p0.translation.vector + Vector3::new(0.1 * k as f64 / 20.0, 0.0, 0.0);
        assert!((p.translation.vector - want).norm() < 1.5e-3, "step {k}");
        assert!((p.rotation.inverse() * p0.rotation).angle() < 0.011);
    }
    // A wall 5 cm ahead stops it part way.
    let wall = Scene::new(vec![Obstacle::new(
        "wall",
        Shape::Box { size: [0.02, 1.0, 1.0] },
        Isometry3::translation(p0.translation.x + 0.1, 0.0, 1.0),
        ObstacleKind::Solid,
    )]);
    let checker = Checker::new(Context::new(&left, 0.3, &wall));
    let e = forward(&checker).unwrap_err();
    assert!(e.fraction > 0.2 && e.fraction < 0.9, "{e}");
    assert!(e.partial.iter().all(|q| checker.is_valid(q)));
}

/// A start whose fingers touch a small object (a hand that ended against a leaf) is refused
/// by `plan`; `plan_out_of_contact` moves out of the contact and plans on: the path starts
/// at the start, leaves the contact within the first third of its first segment, and is
/// valid from there on. A start clear of everything gets `plan`'s own answer.
#[test]
fn a_start_in_contact_is_planned_out_of() {
    // The harvest's home pose (READY's elbow meets the lift rails at low lift heights).
    const HOME: [f64; 7] = [0.0, -0.3, 0.0, -2.356, 0.0, 1.571, 0.785];
    let arm = ArmModel::new(Side::Left);
    assert!(Checker::new(Context::new(&arm, 0.3, &Scene::new(vec![]))).is_valid(&HOME));
    let planner = Planner::default();
    let tcp = arm.fk_iso(0.3, &HOME);
    // A 1 cm leaf beside the hand, as far out as it still touches (within the padding).
    let leaf_at = |d: f64| {
        let c = tcp * nalgebra::Point3::new(0.0, d, -0.05);
        Scene::new(vec![Obstacle::new(
            "leaf",
            Shape::Sphere { radius: 0.01 },
            Isometry3::translation(c.x, c.y, c.z),
            ObstacleKind::Solid,
        )])
    };
    let d = (0..300)
        .map(|k| 0.3 - 0.001 * k as f64)
        .find(|&d| !Checker::new(Context::new(&arm, 0.3, &leaf_at(d))).is_valid(&HOME))
        .expect("a leaf beside the hand");
    let scene = leaf_at(d);
    let ctx = Context::new(&arm, 0.3, &scene);
    let checker = Checker::new(ctx);
    assert!(!checker.is_valid(&HOME), "the start touches the leaf");
    let goal = [0.8, -0.8, 0.5, -0.5]
        .iter()
        .map(|dq| {
            let mut g = HOME;
            g[0] += dq;
            g
        })
        .find(|g| checker.is_valid(g))
        .expect("a valid goal");
    let mut rng = Rng::new(4);
    assert!(matches!(planner.plan(&ctx, &HOME, &[goal], &mut rng.clone()), Err(PlanError::StartInCollision(_))));
    let p = planner.plan_out_of_contact(&ctx, &HOME, &[goal], &mut rng).expect("out of the contact");
    assert_eq!(p.waypoints[0], HOME);
    assert_eq!(*p.waypoints.last().unwrap(), goal);
    let (a, b) = (p.waypoints[0], p.waypoints[1]);
    let n = agrisim_manip::checker::steps(&a, &b, 0.02);
    for k in n / 3..=n {
        assert!(checker.is_valid(&agrisim_manip::checker::lerp(&a, &b, k as f64 / n as f64)), "step {k} of {n}");
    }
    assert!(p.waypoints[1..].iter().all(|q| checker.is_valid(q)));
    for w in p.waypoints[1..].windows(2) {
        assert!(checker.edge_valid(&w[0], &w[1], 0.02));
    }
    // Clear of everything: the same as plan.
    let free = Scene::new(vec![]);
    let ctx = Context::new(&arm, 0.3, &free);
    let a = planner.plan(&ctx, &HOME, &[goal], &mut Rng::new(9)).unwrap().waypoints;
    let b = planner.plan_out_of_contact(&ctx, &HOME, &[goal], &mut Rng::new(9)).unwrap().waypoints;
    assert_eq!(a, b);
}
