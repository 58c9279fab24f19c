//! Sphere model vs exact parry shapes, broad phase vs brute force, ACM, other arm, object kinds.

use agrisim_manip::checker::{Checker, Context, Hit};
use agrisim_manip::exact::exact_contact;
use agrisim_manip::scene::{Obstacle, ObstacleKind, Scene};
use agrisim_manip::{ArmModel, Rng, Side};
use agrisim_robot::Shape;
use nalgebra::{Isometry3, UnitQuaternion, Vector3};

const READY: [f64; 7] = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785];

fn random_obstacle(rng: &mut Rng, i: usize) -> Obstacle {
    let shape = match i % 4 {
        0 => Shape::Box { size: [0.02 + 0.2 * rng.uniform(), 0.02 + 0.2 * rng.uniform(), 0.02 + 0.2 * rng.uniform()] },
        1 => Shape::Sphere { radius: 0.01 + 0.08 * rng.uniform() },
        2 => Shape::Cylinder { radius: 0.005 + 0.05 * rng.uniform(), length: 0.05 + 0.5 * rng.uniform() },
        _ => Shape::Capsule { radius: 0.005 + 0.05 * rng.uniform(), length: 0.05 + 0.4 * rng.uniform() },
    };
    let rot = UnitQuaternion::from_euler_angles(6.0 * rng.uniform(), 6.0 * rng.uniform(), 6.0 * rng.uniform());
    let p = Vector3::new(-0.2 + 1.2 * rng.uniform(), -0.9 + 1.8 * rng.uniform(), 0.5 + 1.3 * rng.uniform());
    Obstacle::new(format!("o{i}"), shape, Isometry3::from_parts(p.into(), rot), ObstacleKind::Solid)
}

#[test]
fn sphere_model_is_conservative_against_exact_shapes() {
    let left = ArmModel::new(Side::Left);
    let right = ArmModel::new(Side::Right);
    let mut rng = Rng::new(21);
    let (mut exact_hits, mut sphere_hits) = (0, 0);
    for trial in 0..300 {
        let scene = Scene::new((0..12).map(|i| random_obstacle(&mut rng, i)).collect());
        let mut ctx = Context::new(&left, 0.8 * rng.uniform(), &scene).with_other(
            &right,
            right.random_q(&mut rng),
            0.04 * rng.uniform(),
        );
        ctx.padding = 0.0;
        ctx.finger = 0.04 * rng.uniform();
        if trial % 3 == 1 {
            ctx = ctx.holding(0.02 + 0.03 * rng.uniform());
        }
        if trial % 4 == 2 {
            ctx = ctx.other_holding(0.02 + 0.03 * rng.uniform());
        }
        let checker = Checker::new(ctx);
        for _ in 0..20 {
            let q = left.random_q(&mut rng);
            let e = exact_contact(&ctx, &q);
            let s = checker.contact(&q);
            if e.is_some() {
                exact_hits += 1;
                assert!(
                    s.is_some(),
                    "trial {trial}: exact contact {:?} missed by spheres at {q:?}",
                    e.map(|c| c.describe(&ctx))
                );
            }
            if s.is_some() {
                sphere_hits += 1;
            }
        }
    }
    println!("exact contacts {exact_hits}, sphere contacts {sphere_hits} of 6000 configurations");
    assert!(exact_hits > 500, "test must exercise contacts ({exact_hits})");
    // Not absurdly conservative either.
    assert!(sphere_hits < exact_hits * 2, "{sphere_hits} vs {exact_hits}");
}

#[test]
fn every_object_kind_is_detected_by_grid_and_by_brute_force_alike() {
    // The grid must not lose an object: compare with a one-object scene per object.
    let arm = ArmModel::new(Side::Left);
    let mut rng = Rng::new(8);
    for _ in 0..100 {
        let objs: Vec<Obstacle> = (0..30).map(|i| random_obstacle(&mut rng, i)).collect();
        let scene = Scene::new(objs.clone());
        let singles: Vec<Scene> = objs.iter().map(|o| Scene::new(vec![o.clone()])).collect();
        let q = arm.random_q(&mut rng);
        let c = Checker::new(Context::new(&arm, 0.3, &scene));
        let grid_env = match c.contact(&q) {
            Some(k) => matches!(k.hit, Hit::Object(_)),
            None => false,
        };
        let self_or_body = Checker::new(Context::new(&arm, 0.3, &Scene::empty())).contact(&q).is_some();
        let brute = singles.iter().any(|s| {
            matches!(Checker::new(Context::new(&arm, 0.3, s)).contact(&q).map(|k| k.hit), Some(Hit::Object(_)))
        });
        if !self_or_body {
            assert_eq!(grid_env, brute);
        }
    }
}

#[test]
fn ready_pose_is_free_and_allowed_collision_matrix_is_sensible() {
    let arm = ArmModel::new(Side::Left);
    let right = ArmModel::new(Side::Right);
    let scene = Scene::empty();
    let ctx = Context::new(&arm, 0.3, &scene).with_other(&right, READY, 0.04);
    assert_eq!(Checker::new(ctx).contact(&READY), None);
    assert_eq!(exact_contact(&ctx, &READY), None);
    let acm = &arm.acm;
    for b in 0..7 {
        assert!(!acm.pair[b][b + 1], "adjacent links {b},{} must be disabled", b + 1);
    }
    assert!(acm.pair[1][8], "link1 vs hand can collide and must be checked");
    assert!(!acm.pair[9][10], "fingers are driven together");
    let n = acm.enabled_pairs();
    assert!((5..45).contains(&n), "{n} enabled pairs");
    // The hand can reach the harvest crate: must be checked.
    let crate_part = arm.body.iter().position(|p| p.link == "harvest_box_link").unwrap();
    assert!(acm.body[crate_part][8]);
}

#[test]
fn self_other_arm_body_and_object_kinds() {
    let left = ArmModel::new(Side::Left);
    let right = ArmModel::new(Side::Right);
    let scene = Scene::empty();
    // Left arm reaching right across to where the right arm's hand is.
    let p_right_hand = right.fk_iso(0.3, &READY);
    let ik = agrisim_manip::Ik::new(&left, 0.3);
    let mut rng = Rng::new(3);
    let q = ik.solve(&agrisim_manip::Target::free_roll(p_right_hand), &READY, &mut rng, 5000).expect("reachable");
    let ctx = Context::new(&left, 0.3, &scene).with_other(&right, READY, 0.04);
    let c = Checker::new(ctx).contact(&q).expect("arms collide");
    assert!(matches!(c.hit, Hit::OtherArm(_) | Hit::SelfBody(_)), "{c:?}");
    assert!(exact_contact(&ctx, &q).is_some());

    // A fruit at the TCP, wider than the open fingers: forbidden as Solid, allowed as Target (hand may touch), ignored as Soft.
    let tcp = left.fk_iso(0.3, &READY);
    for (kind, allowed) in [(ObstacleKind::Solid, false), (ObstacleKind::Target, true), (ObstacleKind::Soft, true)] {
        let s = Scene::new(vec![Obstacle::new("fruit", Shape::Sphere { radius: 0.045 }, tcp, kind)]);
        let ctx = Context::new(&left, 0.3, &s);
        assert_eq!(Checker::new(ctx).contact(&READY).is_none(), allowed, "{kind:?}");
        assert_eq!(exact_contact(&ctx, &READY).is_none(), allowed, "{kind:?} exact");
    }
    // A Target object hit by the forearm is still a collision.
    let fr = left.frames(0.3, &READY, 0.04);
    let s =
        Scene::new(vec![Obstacle::new("fruit", Shape::Sphere { radius: 0.03 }, fr.bodies[4], ObstacleKind::Target)]);
    assert!(Checker::new(Context::new(&left, 0.3, &s)).contact(&READY).is_some());

    // Fixed body: some random configurations hit the robot's structure, and the exact check
    // sees a contact there too whenever the shapes truly touch.
    let ctx = Context { padding: 0.0, ..Context::new(&left, 0.0, &scene) };
    let c = Checker::new(ctx);
    let mut body_hits = 0;
    for _ in 0..5000 {
        let q = left.random_q(&mut rng);
        if let Some(k) = c.contact(&q) {
            if let Hit::RobotBody(_) = k.hit {
                body_hits += 1;
            }
        }
    }
    assert!(body_hits > 50, "{body_hits} configurations touch the fixed body");
}

#[test]
fn checks_cost_microseconds() {
    let arm = ArmModel::new(Side::Left);
    let right = ArmModel::new(Side::Right);
    let mut rng = Rng::new(1);
    let scene = Scene::new((0..40).map(|i| random_obstacle(&mut rng, i)).collect());
    let c = Checker::new(Context::new(&arm, 0.3, &scene).with_other(&right, READY, 0.04));
    let qs: Vec<[f64; 7]> = (0..20000).map(|_| arm.random_q(&mut rng)).collect();
    let t = std::time::Instant::now();
    let n = qs.iter().filter(|q| c.contact(q).is_some()).count();
    let us = t.elapsed().as_secs_f64() * 1e6 / qs.len() as f64;
    println!("sphere check: {us:.2} us per configuration ({n} in contact), {} spheres per arm", arm.spheres.count());
}

#[test]
fn a_held_fruit_collides_where_the_empty_gripper_does_not() {
    let left = ArmModel::new(Side::Left);
    let right = ArmModel::new(Side::Right);
    let tcp = left.fk_iso(0.3, &READY);
    // 5 cm beyond the TCP along the approach axis: past the fingertips (5 mm beyond the TCP).
    let p = tcp * Isometry3::translation(0.0, 0.0, 0.05);
    let scene = Scene::new(vec![Obstacle::new("twig", Shape::Sphere { radius: 0.012 }, p, ObstacleKind::Solid)]);
    let empty = Context { padding: 0.0, ..Context::new(&left, 0.3, &scene) };
    assert_eq!(Checker::new(empty).contact(&READY), None);
    assert_eq!(exact_contact(&empty, &READY), None);
    let holding = empty.holding(0.04);
    let c = Checker::new(holding).contact(&READY).expect("held fruit touches");
    assert_eq!(c.body, agrisim_manip::checker::HELD);
    assert!(c.describe(&holding).contains("held_object"));
    assert_eq!(exact_contact(&holding, &READY).map(|c| c.body), Some(agrisim_manip::checker::HELD));

    // The other arm's held fruit is an obstacle for this arm's links but not its hand.
    let q_right = READY;
    let fruit_at = right.fk_iso(0.3, &q_right);
    let ik = agrisim_manip::Ik::new(&left, 0.3);
    let mut rng = Rng::new(2);
    // Left hand grasping the right arm's fruit (handover): allowed.
    let mut t = agrisim_manip::Target::free_roll(fruit_at);
    t.pose.rotation = fruit_at.rotation * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI);
    let s0 = Scene::empty();
    let ctx =
        Context { padding: 0.0, ..Context::new(&left, 0.3, &s0) }.with_other(&right, q_right, 0.02).other_holding(0.03);
    let goals = ik.goal_set(&t, &READY, &mut rng, 20, 0.1, 50_000, |_| true);
    assert!(!goals.is_empty());
    for q in &goals {
        if let Some(c) = Checker::new(ctx).contact(q) {
            // Whatever touches, it is not this hand/fingers against the held fruit.
            assert!(
                !(c.body >= agrisim_manip::layout::HAND && c.hit == Hit::OtherArm(agrisim_manip::checker::HELD)),
                "{c:?}"
            );
        }
    }
}

/// `arms_contact` is the two-arm part of `contact`: over random configurations, held
/// fruit and obstacles, it finds a contact whenever the full check's first contact is with
/// the other arm (or its fruit), any contact it finds fails the full check too, and it finds
/// one only where the arms alone meet (the same check with the other arm moved far away
/// and nothing held finds none there).
#[test]
fn arms_contact_is_the_two_arm_part_of_the_full_check() {
    let left = ArmModel::new(Side::Left);
    let right = ArmModel::new(Side::Right);
    let mut rng = Rng::new(5);
    let (mut arm_hits, mut other_first) = (0, 0);
    for trial in 0..300 {
        let scene = Scene::new((0..6).map(|i| random_obstacle(&mut rng, i)).collect());
        let empty = Scene::new(vec![]);
        let lift = 0.8 * rng.uniform();
        let q_other = right.random_q(&mut rng);
        let held = (trial % 3 == 1).then(|| 0.02 + 0.03 * rng.uniform());
        let other_held = (trial % 4 == 2).then(|| 0.02 + 0.03 * rng.uniform());
        let build = |scene, other: bool| {
            let mut ctx = Context::new(&left, lift, scene);
            if other {
                ctx = ctx.with_other(&right, q_other, 0.04);
            }
            if let Some(r) = held {
                ctx = ctx.holding(r);
            }
            if let Some(r) = other_held {
                ctx = ctx.other_holding(r);
            }
            Checker::new(ctx)
        };
        let (full, alone) = (build(&scene, true), build(&empty, false));
        for _ in 0..20 {
            let q = left.random_q(&mut rng);
            let a = full.arms_contact(&q);
            assert!(alone.arms_contact(&q).is_none(), "trial {trial}: no other arm, no contact between arms");
            if let Some(c) = full.contact(&q) {
                if matches!(c.hit, Hit::OtherArm(_)) {
                    other_first += 1;
                    assert!(a.is_some(), "trial {trial}: the full check met the other arm at {q:?}");
                }
            }
            if let Some(c) = a {
                arm_hits += 1;
                assert!(matches!(c.hit, Hit::OtherArm(_)), "trial {trial}: {c:?}");
                assert!(!full.is_valid(&q), "trial {trial}: the full check passes {q:?}");
            }
        }
    }
    assert!(other_first > 50 && arm_hits >= other_first, "too few arm contacts drawn: {other_first}, {arm_hits}");
}
