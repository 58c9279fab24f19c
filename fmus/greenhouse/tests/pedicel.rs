//! Detachment in isolation, against the configured (literature-based) distributions: every
//! fruit of a scene, on its own pedicel (the scene's geometry, the FMU's per-fruit
//! thresholds), is pulled straight off, bent off and twisted off in small steps by the joint
//! model the world FMU runs. Reported: the force and moment at detachment. Checked: each fruit
//! comes off at its own drawn threshold, the means and spreads match the configured
//! distributions within their sampling error, each motion breaks the pedicel in its own mode,
//! and bending detaches at a lower force at the gripper than pulling.

use agrisim_fmu_greenhouse::pedicel::{Attachment, Mode, PedicelParams, AZ_OFFSET};
use agrisim_fmu_greenhouse::world::pedicel_geometry;
use agrisim_math::vec3::{add, cross, norm, normalize, scale, sub};
use agrisim_robot::Pose as RPose;
use agrisim_scene::{Kind, Shape};

const H: f64 = 0.02;

/// Mean and standard deviation.
fn stats(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    (m, (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt())
}

/// The pose `p` rotated by `angle` about `axis` through point `c`.
fn rotated_about(p: &RPose, axis: [f64; 3], angle: f64, c: [f64; 3]) -> RPose {
    let r = RPose::from_axis_angle(axis, angle);
    let about = RPose::from_translation(c).mul(&r).mul(&RPose::from_translation(scale(c, -1.0)));
    about.mul(p)
}

/// Steps `motion(k)` (the fruit's pose after step k) until the pedicel breaks; the mode, the
/// force at the gripper |F| and the moments (bend, twist) at that step.
fn detach(a: &mut Attachment, p: &PedicelParams, motion: impl Fn(usize) -> RPose) -> (Mode, f64, f64, f64) {
    for k in 1..100_000 {
        let load = a.load(p, &motion(k), H);
        if let Some(mode) = load.breaks(&a.thresholds) {
            return (mode, norm(load.force), load.bend, load.twist);
        }
    }
    panic!("the pedicel never broke");
}

#[test]
fn pull_bend_and_twist_detach_at_the_configured_loads() {
    let cfg = agrisim_scene::config::GreenhouseConfig::from_toml_str(
        "rows = 2\nactive_rows = 2\nwidth = 12.0\nlength = 20.0\nrow_length = 8.0",
    )
    .unwrap();
    let seed = cfg.seed;
    let gh = agrisim_scene::generate(&cfg, seed);
    let fruit: Vec<usize> =
        gh.objects.iter().enumerate().filter(|(_, o)| matches!(o.kind, Kind::Fruit { .. })).map(|(i, _)| i).collect();
    let geoms = pedicel_geometry(&gh.objects, &fruit);
    let p = PedicelParams::default();
    let n = fruit.len().min(300);
    assert!(n >= 200, "{n} fruit");
    let (mut pull_f, mut bend_m, mut bend_f, mut twist_m) = (vec![], vec![], vec![], vec![]);
    for (i, (&o, geom)) in fruit.iter().zip(&geoms).take(n).enumerate() {
        let obj = &gh.objects[o];
        let Shape::Sphere { radius } = obj.shape else { panic!("a fruit is a sphere") };
        let rest = RPose::from_translation(obj.placement.translation);
        let t = p.thresholds(seed, i);
        let new = || Attachment::new(rest, radius, *geom, t);
        let az = new().anchor;
        let a = geom.axis;
        // Straight pull: away from the truss along the pedicel at 5 mm/s.
        let mut att = new();
        let (mode, f, _, _) =
            detach(&mut att, &p, |k| RPose::from_translation(sub(rest.trans, scale(a, 1e-4 * k as f64))));
        assert_eq!(mode, Mode::Pull, "fruit {i}");
        // Each fruit comes off at its own drawn threshold, within one step of the ramp.
        let within = |load: f64, threshold: f64, step: f64| load >= threshold && load < threshold + step + 1e-9;
        assert!(within(f, t.pull, p.stiffness * 1e-4), "fruit {i}: pulled off at {f} N, threshold {}", t.pull);
        pull_f.push(f);
        // Bend: the fruit swung about the abscission zone, sideways to the pedicel, at 0.05 rad/s.
        let side = normalize(cross(a, if a[2].abs() < 0.9 { [0.0, 0.0, 1.0] } else { [1.0, 0.0, 0.0] }));
        let mut att = new();
        let (mode, _, m, _) = detach(&mut att, &p, |k| rotated_about(&rest, side, 1e-3 * k as f64, az));
        assert_eq!(mode, Mode::Bend, "fruit {i}");
        assert!(within(m, t.bend, p.bend_stiffness * 1e-3), "fruit {i}: bent off at {m} N m, threshold {}", t.bend);
        bend_m.push(m);
        // The gripper holds the fruit at its centre: the force there that makes this moment.
        bend_f.push(m / norm(sub(rest.trans, az)));
        // Twist: about the pedicel axis.
        let mut att = new();
        let (mode, _, _, m) = detach(&mut att, &p, |k| rotated_about(&rest, a, 2e-3 * k as f64, az));
        assert_eq!(mode, Mode::Twist, "fruit {i}");
        assert!(
            within(m, t.twist, p.twist_stiffness * 2e-3),
            "fruit {i}: twisted off at {m} N m, threshold {}",
            t.twist
        );
        twist_m.push(m);
        assert!(norm(sub(add(rest.trans, [0.0, 0.0, radius]), az)) <= AZ_OFFSET + 1e-9);
    }
    let report = [
        ("pull force [N]", stats(&pull_f), (p.pull_mean, p.pull_sd), p.stiffness * 1e-4),
        ("bend moment [N m]", stats(&bend_m), (p.bend_mean, p.bend_sd), p.bend_stiffness * 1e-3),
        ("twist moment [N m]", stats(&twist_m), (p.twist_mean, p.twist_sd), p.twist_stiffness * 2e-3),
    ];
    let bend_force = stats(&bend_f);
    println!("detachment over {n} fruit (mean, SD) vs configured (mean, SD):");
    for (what, (m, s), (cm, cs), step) in report {
        println!("  {what}: {m:.4}, {s:.4} vs {cm}, {cs}");
        // The sample mean lies within 4 standard errors of the configured mean (one step of
        // the ramp overshoots by at most `step`); the SD within 25 %.
        let tol = 4.0 * cs / (n as f64).sqrt() + step;
        assert!((m - cm).abs() <= tol, "{what}: mean {m} vs {cm} (tolerance {tol})");
        assert!((s - cs).abs() <= 0.25 * cs + step, "{what}: SD {s} vs {cs}");
    }
    println!("  bend force at the gripper [N]: {:.3}, {:.3}", bend_force.0, bend_force.1);
    let pull = stats(&pull_f).0;
    assert!(bend_force.0 < 0.5 * pull, "bending detaches at {} N at the gripper, pulling at {pull} N", bend_force.0);
}
