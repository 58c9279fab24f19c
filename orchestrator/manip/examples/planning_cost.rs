//! Calibrates the planning cost model (`agrisim_manip::CostModel`): wall time of real
//! planning problems against the work they did, fitted by least squares.
//!
//! `cargo run --release -p agrisim-manip --example planning_cost -- --n 400 --seed 1`
//!
//! Each problem is one harvest-like plan in a synthetic tomato-row scene (as `plan_bench`):
//! an IK goal set for a reachable target (free roll), RRT-Connect from the ready pose to it
//! with shortcutting and the exact check, and a 0.1 m Cartesian back-out from the goal. The
//! fit has no intercept (an empty plan costs nothing) and is repeated on the problems'
//! halves to show how stable the coefficients are. Wall time is measured here only: the
//! model it yields is a constant in the code.

use agrisim_manip::checker::{Checker, Context};
use agrisim_manip::planner::Planner;
use agrisim_manip::scene::Scene;
use agrisim_manip::{cartesian_path, ArmModel, Ik, Meter, Rng, Side, Target, Work};
use nalgebra::{DMatrix, DVector, Vector3};
use std::time::Instant;

mod common;
use common::{arg, tomato_row};

const READY: [f64; 7] = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785];

/// Least squares without intercept: seconds ~ checks, IK iterations, exact checks.
fn fit(samples: &[(Work, f64)]) -> Option<[f64; 3]> {
    let a = DMatrix::from_fn(samples.len(), 3, |r, c| {
        let w = &samples[r].0;
        [w.checks, w.ik_iterations, w.exact_checks][c] as f64
    });
    let b = DVector::from_iterator(samples.len(), samples.iter().map(|s| s.1));
    let x = a.clone().svd(true, true).solve(&b, 1e-12).ok()?;
    Some([x[0], x[1], x[2]])
}

fn main() {
    let n = arg("--n", 400) as usize;
    let seed = arg("--seed", 1);
    let (left, right) = (ArmModel::new(Side::Left), ArmModel::new(Side::Right));
    let lift = 0.3;
    let planner = Planner::default();
    let mut rng = Rng::new(seed);
    let mut samples: Vec<(Work, f64)> = Vec::new();
    for _ in 0..n {
        let scene = Scene::new(tomato_row(&mut rng));
        let target = {
            let checker = Checker::new(Context::new(&left, lift, &scene).with_other(&right, READY, 0.04));
            loop {
                let q = left.random_q(&mut rng);
                let t = left.fk_iso(lift, &q);
                let (p, z) = (t.translation.vector, t.rotation * Vector3::z());
                if (0.45..0.75).contains(&p.x)
                    && p.y.abs() < 0.7
                    && (0.7..1.6).contains(&p.z)
                    && z.x > 0.5
                    && checker.is_valid(&q)
                {
                    break Target::free_roll(t);
                }
            }
        };
        let meter = Meter::default();
        let mut ctx = Context::new(&left, lift, &scene).with_other(&right, READY, 0.04);
        ctx.meter = Some(&meter);
        let t0 = Instant::now();
        let checker = Checker::new(ctx);
        let ik = Ik::new(&left, lift).metered(Some(&meter));
        let goals = ik.goal_set(&target, &READY, &mut rng, 6, 0.3, 12_000, |q| checker.is_valid(q));
        if let Ok(p) = planner.plan(&ctx, &READY, &goals, &mut rng) {
            let end = *p.waypoints.last().expect("start at least");
            let z = left.fk_iso(lift, &end).rotation * Vector3::z();
            let _ = cartesian_path(&checker, &end, -0.1 * z, 0.01, 0.3, 0.02);
        }
        samples.push((meter.work(), t0.elapsed().as_secs_f64()));
    }
    let total: f64 = samples.iter().map(|s| s.1).sum();
    println!("planning cost calibration: {n} problems, seed {seed}, {:.3} s of planning measured", total);
    let show = |name: &str, c: Option<[f64; 3]>| match c {
        Some(c) => println!(
            "{name:<12} per check {:.3e} s, per IK iteration {:.3e} s, per exact check {:.3e} s",
            c[0], c[1], c[2]
        ),
        None => println!("{name:<12} fit failed"),
    };
    let all = fit(&samples);
    show("all", all);
    show("first half", fit(&samples[..n / 2]));
    show("second half", fit(&samples[n / 2..]));
    if let Some(c) = all {
        let predicted: Vec<f64> = samples
            .iter()
            .map(|(w, _)| w.checks as f64 * c[0] + w.ik_iterations as f64 * c[1] + w.exact_checks as f64 * c[2])
            .collect();
        let mut rel: Vec<f64> =
            samples.iter().zip(&predicted).filter(|(s, _)| s.1 > 1e-4).map(|(s, p)| (p - s.1) / s.1).collect();
        rel.sort_by(f64::total_cmp);
        let at = |q: f64| rel.get(((rel.len().max(1) - 1) as f64 * q).round() as usize).copied().unwrap_or(f64::NAN);
        println!("prediction error (model - measured) / measured: p5 {:+.0} %, p50 {:+.0} %, p95 {:+.0} %; total {:.3} s predicted vs {:.3} s measured", 100.0 * at(0.05), 100.0 * at(0.5), 100.0 * at(0.95), predicted.iter().sum::<f64>(), total);
    }
}
