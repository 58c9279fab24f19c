//! IK benchmark, ours vs the KDL NR_JL baseline:
//! `cargo run --release -p agrisim-manip --example ik_bench -- --n 10000 --seed 1`.
//! Targets are the FK of uniform random joint configurations (so all are reachable); each
//! solver gets one random seed configuration per target (the same for both).

use agrisim_manip::{ik, kdl, ArmModel, Ik, Rng, Side, Target};
use std::time::Instant;

mod common;
use common::arg;

/// One IK solver under test: target and seed configuration -> solution.
type Solver<'a> = dyn FnMut(&Target, &[f64; 7]) -> Option<[f64; 7]> + 'a;

fn stats(t: &mut [f64]) -> (f64, f64) {
    t.sort_by(f64::total_cmp);
    let mean = t.iter().sum::<f64>() / t.len().max(1) as f64;
    (mean, t.get(t.len() / 2).copied().unwrap_or(0.0))
}

fn main() {
    let n = arg("--n", 10000) as usize;
    let seed = arg("--seed", 1);
    let arm = ArmModel::new(Side::Left);
    let lift = 0.3;
    let mut rng = Rng::new(seed);
    let cases: Vec<(Target, [f64; 7])> = (0..n)
        .map(|_| {
            let q = arm.random_q(&mut rng);
            (Target::pose(arm.fk_iso(lift, &q)), arm.random_q(&mut rng))
        })
        .collect();
    let free: Vec<(Target, [f64; 7])> = cases.iter().map(|(t, s)| (Target { free_roll: true, ..*t }, *s)).collect();
    let ik = Ik::new(&arm, lift);
    let report = |name: &str, f: &mut Solver, cases: &[(Target, [f64; 7])]| {
        let mut ok = 0;
        let mut times = Vec::with_capacity(n);
        for (t, s) in cases {
            let t0 = Instant::now();
            let r = f(t, s);
            times.push(t0.elapsed().as_secs_f64() * 1e6);
            if let Some(q) = r {
                assert!(arm.within_limits(&q));
                let e = t.error(&arm.fk_iso(lift, &q));
                if t.reached(&e) {
                    ok += 1;
                }
            }
        }
        let (mean, med) = stats(&mut times);
        println!(
            "{name:<28} success {ok:>6}/{n} = {:6.2} %   mean {mean:8.1} us   median {med:8.1} us",
            100.0 * ok as f64 / n as f64
        );
    };
    println!("IK benchmark: {n} reachable random targets, seed {seed}, lift {lift} m, left arm");
    let mut r2 = Rng::new(seed ^ 0xABCD);
    report("ours (6-D)", &mut |t, s| ik.solve(t, s, &mut r2, ik::DEFAULT_BUDGET), &cases);
    report("KDL NR_JL (6-D)", &mut |t, s| kdl::kdl_nr_jl(&arm, lift, t, s), &cases);
    // Like for like, both ways: KDL with our tolerance (1 mm, 0.01 rad) and our budget of
    // iterations spent on random restarts; ours with KDL's tolerance (1e-5) and budget (100).
    let mut r4 = Rng::new(seed ^ 0x5678);
    report(
        "KDL NR_JL, our tol+budget",
        &mut |t, s| kdl::kdl_nr_jl_restarts(&arm, lift, t, s, &mut r4, ik::DEFAULT_BUDGET),
        &cases,
    );
    let strict: Vec<(Target, [f64; 7])> =
        cases.iter().map(|(t, s)| (Target { pos_tol: kdl::KDL_EPS, rot_tol: kdl::KDL_EPS, ..*t }, *s)).collect();
    let mut r5 = Rng::new(seed ^ 0x9ABC);
    report("ours, KDL tol+budget", &mut |t, s| ik.solve(t, s, &mut r5, kdl::KDL_MAX_ITER), &strict);
    let mut r3 = Rng::new(seed ^ 0x1234);
    report("ours (free roll, 5-D)", &mut |t, s| ik.solve(t, s, &mut r3, ik::DEFAULT_BUDGET), &free);
}
