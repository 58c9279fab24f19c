//! IK property tests over many random reachable targets (FK of random configurations).

use agrisim_manip::{ik, kdl, ArmModel, Ik, Rng, Side, Target};

fn cases(arm: &ArmModel, lift: f64, n: usize, seed: u64) -> Vec<(Target, [f64; 7])> {
    let mut rng = Rng::new(seed);
    (0..n).map(|_| (Target::pose(arm.fk_iso(lift, &arm.random_q(&mut rng))), arm.random_q(&mut rng))).collect()
}

fn check(arm: &ArmModel, lift: f64, t: &Target, q: &[f64; 7]) {
    assert!(arm.within_limits(q), "solution outside limits: {q:?}");
    let e = t.error(&arm.fk_iso(lift, q));
    assert!(e.fixed_rows::<3>(0).norm() <= 1e-3 && e.fixed_rows::<3>(3).norm() <= 1e-2, "residual {e:?}");
}

#[test]
fn ours_solves_at_least_99_percent_of_reachable_6d_targets_and_beats_kdl() {
    let arm = ArmModel::new(Side::Left);
    let lift = 0.3;
    let ik = Ik::new(&arm, lift);
    let cs = cases(&arm, lift, 1000, 42);
    let mut rng = Rng::new(7);
    let (mut ours, mut kdl_ok) = (0, 0);
    for (t, seed) in &cs {
        if let Some(q) = ik.solve(t, seed, &mut rng, ik::DEFAULT_BUDGET) {
            check(&arm, lift, t, &q);
            ours += 1;
        }
        if let Some(q) = kdl::kdl_nr_jl(&arm, lift, t, seed) {
            check(&arm, lift, t, &q);
            kdl_ok += 1;
        }
    }
    println!("IK success on {} reachable 6-D targets: ours {ours}, KDL NR_JL {kdl_ok}", cs.len());
    assert!(ours >= 990, "ours solved only {ours}/1000");
    assert!(ours > kdl_ok + 300, "ours {ours} should be far above KDL {kdl_ok}");
}

#[test]
fn free_roll_targets_are_solved_and_keep_the_approach_axis() {
    let arm = ArmModel::new(Side::Right);
    let lift = 0.6;
    let ik = Ik::new(&arm, lift);
    let mut rng = Rng::new(9);
    let mut ok = 0;
    let cs = cases(&arm, lift, 500, 43);
    for (t, seed) in &cs {
        // Rotate the target about its own z: any roll must be acceptable.
        let roll = nalgebra::UnitQuaternion::from_axis_angle(&nalgebra::Vector3::z_axis(), 6.0 * rng.uniform());
        let mut t = Target::free_roll(t.pose);
        t.pose.rotation *= roll;
        if let Some(q) = ik.solve(&t, seed, &mut rng, ik::DEFAULT_BUDGET) {
            let f = arm.fk_iso(lift, &q);
            assert!((f.translation.vector - t.pose.translation.vector).norm() <= 1e-3);
            let zc = f.rotation * nalgebra::Vector3::z();
            let zt = t.pose.rotation * nalgebra::Vector3::z();
            assert!(zc.angle(&zt) <= 1e-2);
            ok += 1;
        }
    }
    assert!(ok >= 495, "free roll solved {ok}/500");
}

#[test]
fn free_lift_solves_targets_at_another_lift_height() {
    let arm = ArmModel::new(Side::Left);
    let mut rng = Rng::new(4);
    let mut solved = 0;
    for _ in 0..50 {
        // Reachable at lift 0.7, asked with the lift starting at 0.
        let q = arm.random_q(&mut rng);
        let t = Target::pose(arm.fk_iso(0.7, &q));
        let ik = Ik::with_free_lift(&arm, 0.0);
        if let Some((lift, q)) = ik.solve_lift(&t, &arm.random_q(&mut rng), &mut rng, ik::DEFAULT_BUDGET) {
            assert!((0.0..=0.8).contains(&lift));
            check(&arm, lift, &t, &q);
            solved += 1;
        }
    }
    assert!(solved >= 48, "{solved}/50");
}

#[test]
fn unreachable_target_fails_within_budget() {
    let arm = ArmModel::new(Side::Left);
    let ik = Ik::new(&arm, 0.3);
    let t = Target::pose(nalgebra::Isometry3::translation(3.0, 0.0, 1.0));
    let mut rng = Rng::new(1);
    assert!(ik.solve(&t, &[0.0, 0.0, 0.0, -1.5, 0.0, 1.5, 0.0], &mut rng, 500).is_none());
}

#[test]
fn goal_set_returns_distinct_valid_solutions_deterministically() {
    let arm = ArmModel::new(Side::Left);
    let lift = 0.3;
    let ik = Ik::new(&arm, lift);
    let (t, seed) = cases(&arm, lift, 1, 77)[0];
    let t = Target::free_roll(t.pose);
    let run = || {
        let mut rng = Rng::new(5);
        ik.goal_set(&t, &seed, &mut rng, 8, 0.3, 20_000, |q| q[0] > -2.0)
    };
    let a = run();
    assert!(a.len() >= 4, "only {} goals", a.len());
    for (i, q) in a.iter().enumerate() {
        check(&arm, lift, &t, q);
        assert!(q[0] > -2.0, "validity predicate ignored");
        for p in &a[..i] {
            assert!(ik::dist(p, q) >= 0.3);
        }
    }
    assert_eq!(a, run());
}

#[test]
fn kdl_baseline_converges_from_a_nearby_seed() {
    // Semantics check: Newton-Raphson converges quadratically close to a solution.
    let arm = ArmModel::new(Side::Left);
    let mut rng = Rng::new(2);
    for _ in 0..100 {
        let q = arm.random_q(&mut rng);
        let t = Target::pose(arm.fk_iso(0.3, &q));
        let seed: [f64; 7] =
            std::array::from_fn(|i| (q[i] + 0.02 * (rng.uniform() - 0.5)).clamp(arm.lower()[i], arm.upper()[i]));
        let s = kdl::kdl_nr_jl(&arm, 0.3, &t, &seed).expect("converges from 0.01 rad away");
        let e = t.error(&arm.fk_iso(0.3, &s));
        assert!(e.amax() < kdl::KDL_EPS);
    }
}
