//! Planning benchmark: `cargo run --release -p agrisim-manip --example plan_bench -- --n 200 --seed 1`.
//!
//! Each trial builds a synthetic tomato-row-like scene in front of the robot (vertical stem
//! cylinders every 0.25 m, a horizontal support wire, heating pipes, a few random boxes),
//! draws a reachable target in front of the robot (FK of a random collision-free joint
//! configuration whose TCP is in the picking zone and points forward), solves a goal set with
//! the IK (free roll about the approach axis) and plans the left arm from its ready pose with
//! the right arm at its ready pose as an obstacle. Reports success rate and time percentiles.

use agrisim_manip::checker::{Checker, Context};
use agrisim_manip::planner::Planner;
use agrisim_manip::scene::Scene;
use agrisim_manip::{ik, ArmModel, Ik, Rng, Side, Target};
use nalgebra::Vector3;
use std::time::Instant;

mod common;
use common::{arg, tomato_row};

const READY: [f64; 7] = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785];

fn pct(v: &[f64], p: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v[((v.len() - 1) as f64 * p).round() as usize]
}

fn main() {
    let n = arg("--n", 200) as usize;
    let seed = arg("--seed", 1);
    let left = ArmModel::new(Side::Left);
    let right = ArmModel::new(Side::Right);
    let lift = 0.3;
    let planner = Planner::default();
    let mut rng = Rng::new(seed);
    let (mut ok, mut no_goal) = (0, 0);
    let mut fails: Vec<String> = Vec::new();
    let (mut times, mut ik_times, mut exact_times) = (Vec::new(), Vec::new(), Vec::new());
    let mut goals_total = 0;
    for trial in 0..n {
        let scene = Scene::new(tomato_row(&mut rng));
        let ctx = Context::new(&left, lift, &scene).with_other(&right, READY, 0.04);
        let checker = Checker::new(ctx);
        // Reachable target in the picking zone (rejection sampling of joint configurations).
        let target = loop {
            let q = left.random_q(&mut rng);
            let t = left.fk_iso(lift, &q);
            let p = t.translation.vector;
            let z = t.rotation * Vector3::z();
            if (0.45..0.75).contains(&p.x)
                && p.y.abs() < 0.7
                && (0.7..1.6).contains(&p.z)
                && z.x > 0.5
                && checker.is_valid(&q)
            {
                break Target::free_roll(t);
            }
        };
        let t0 = Instant::now();
        let ikr = Ik::new(&left, lift);
        let goals = ikr.goal_set(&target, &READY, &mut rng, 6, 0.3, 6 * ik::DEFAULT_BUDGET, |q| checker.is_valid(q));
        ik_times.push(t0.elapsed().as_secs_f64() * 1e3);
        goals_total += goals.len();
        if goals.is_empty() {
            no_goal += 1;
            fails.push(format!("trial {trial}: IK found no collision-free goal"));
            continue;
        }
        match planner.plan(&ctx, &READY, &goals, &mut rng) {
            Ok(p) => {
                ok += 1;
                times.push(p.stats.planning_time_s * 1e3);
                exact_times.push(p.stats.exact_time_s * 1e3);
            }
            Err(e) => fails.push(format!("trial {trial}: {e}")),
        }
    }
    times.sort_by(f64::total_cmp);
    ik_times.sort_by(f64::total_cmp);
    exact_times.sort_by(f64::total_cmp);
    println!("planning benchmark: {n} trials, seed {seed}, left arm, lift {lift} m, tomato-row scenes");
    println!(
        "planning success   {ok}/{n} = {:.1} %  (IK found no valid goal in {no_goal})",
        100.0 * ok as f64 / n as f64
    );
    println!("goals per target   {:.2} (mean)", goals_total as f64 / n as f64);
    println!(
        "plan time ms       p50 {:.2}  p95 {:.2}  max {:.2}  (incl. exact check p50 {:.2})",
        pct(&times, 0.5),
        pct(&times, 0.95),
        times.last().copied().unwrap_or(f64::NAN),
        pct(&exact_times, 0.5)
    );
    println!(
        "goal-set IK ms     p50 {:.2}  p95 {:.2}  max {:.2}",
        pct(&ik_times, 0.5),
        pct(&ik_times, 0.95),
        ik_times.last().copied().unwrap_or(f64::NAN)
    );
    for f in fails.iter().take(20) {
        println!("  {f}");
    }
}
