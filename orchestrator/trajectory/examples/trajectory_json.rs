//! JSON bridge for the Python cross-checks (python/test_toppra_crosscheck.py,
//! python/test_ruckig_crosscheck.py, python/bench_toppra.py).
//!
//! Reads one JSON object on stdin: `{"op": "toppra" | "ruckig" | "check", "problems": [...]}`
//! and writes `{"results": [...]}` (one result per problem, same order) on stdout.
//! Wall times are measured for the benchmark report only.

use std::io::Read;
use std::time::Instant;

use agrisim_trajectory::jerk_limited::{self, JointState, KinematicLimits};
use agrisim_trajectory::toppra::{parameterize, parameterize_within_limits, Discretization, ToppraProblem};
use agrisim_trajectory::{check, sample, CheckError, CubicSplinePath, GridSpec, JointLimits, SplineEnd, Trajectory};
use serde::Deserialize;
use serde_json::{json, Value};

#[derive(Deserialize)]
struct Request {
    op: String,
    problems: Vec<Value>,
}

#[derive(Deserialize)]
struct ToppraIn {
    ss: Vec<f64>,
    waypoints: Vec<Vec<f64>>,
    #[serde(default)]
    bc: Option<String>,
    vmax: Vec<f64>,
    amax: Vec<f64>,
    /// Explicit gridpoints; absent = toppra's automatic proposal.
    #[serde(default)]
    gridpoints: Option<Vec<f64>>,
    #[serde(default)]
    collocation: bool,
    /// Sample period for the limit check (absent: no check).
    #[serde(default)]
    sample_dt: Option<f64>,
    #[serde(default)]
    rel_tol: f64,
    /// Solve this many times to time it (the first result is returned).
    #[serde(default)]
    repeat: Option<usize>,
    #[serde(default)]
    return_grid: bool,
    /// Use `parameterize_within_limits` at `sample_dt` / `rel_tol` (8 rounds).
    #[serde(default)]
    verify: bool,
}

#[derive(Deserialize)]
struct RuckigIn {
    q0: Vec<f64>,
    v0: Vec<f64>,
    a0: Vec<f64>,
    q1: Vec<f64>,
    v1: Vec<f64>,
    a1: Vec<f64>,
    vmax: Vec<f64>,
    amax: Vec<f64>,
    jmax: Vec<f64>,
    #[serde(default)]
    sample_dt: Option<f64>,
    #[serde(default)]
    rel_tol: f64,
    #[serde(default)]
    probe_times: Vec<f64>,
}

#[derive(Deserialize)]
struct CheckIn {
    t: Vec<f64>,
    /// JSON has no NaN: `null` samples stand for NaN.
    q: Vec<Vec<Option<f64>>>,
    qd: Vec<Vec<Option<f64>>>,
    qdd: Vec<Vec<Option<f64>>>,
    #[serde(default)]
    position: Vec<(f64, f64)>,
    #[serde(default)]
    velocity: Vec<f64>,
    #[serde(default)]
    acceleration: Vec<f64>,
    #[serde(default)]
    jerk: Vec<f64>,
    #[serde(default)]
    rel_tol: f64,
}

fn check_json(r: Result<(), CheckError>) -> Value {
    match r {
        Ok(()) => json!({"ok": true}),
        Err(CheckError::Malformed(m)) => json!({"ok": false, "malformed": m}),
        Err(e @ CheckError::Violation(_)) => {
            let CheckError::Violation(v) = &e else { unreachable!() };
            json!({"ok": false, "joint": v.joint, "time": v.time, "quantity": v.quantity.to_string(),
                   "value": v.value, "limit": v.limit, "message": e.to_string()})
        }
    }
}

fn toppra_one(p: ToppraIn) -> Value {
    let end = match p.bc.as_deref() {
        None | Some("not-a-knot") => SplineEnd::NotAKnot,
        Some("clamped") => SplineEnd::Clamped,
        Some("natural") => SplineEnd::Natural,
        Some(other) => return json!({"error": format!("unknown bc {other}")}),
    };
    let grid = p.gridpoints.clone().map_or(GridSpec::Auto, GridSpec::Points);
    let problem = ToppraProblem {
        max_velocity: p.vmax.clone(),
        max_acceleration: p.amax.clone(),
        grid,
        discretization: if p.collocation { Discretization::Collocation } else { Discretization::Interpolation },
    };
    let solve = || -> Result<_, String> {
        let path = CubicSplinePath::new(&p.ss, &p.waypoints, end).map_err(|e| e.to_string())?;
        match (p.verify, p.sample_dt) {
            (true, Some(dt)) => parameterize_within_limits(path, &problem, dt, p.rel_tol, 8),
            _ => parameterize(path, &problem),
        }
        .map_err(|e| e.to_string())
    };
    let repeat = p.repeat.unwrap_or(1).max(1);
    let t0 = Instant::now();
    let mut first = None;
    for _ in 0..repeat {
        let r = solve();
        if first.is_none() {
            first = Some(r);
        }
    }
    let seconds = t0.elapsed().as_secs_f64() / repeat as f64;
    let traj = match first.unwrap() {
        Ok(t) => t,
        Err(e) => return json!({"error": e, "seconds": seconds}),
    };
    let mut out = json!({"duration": traj.duration(), "n_grid": traj.gridpoints().len(), "seconds": seconds});
    if p.return_grid {
        out["gridpoints"] = json!(traj.gridpoints());
        out["sd_squared"] = json!(traj.sd_squared());
    }
    if let Some(dt) = p.sample_dt {
        let s = sample(&traj, dt);
        let lim =
            JointLimits { position: vec![], velocity: p.vmax.clone(), acceleration: p.amax.clone(), jerk: vec![] };
        out["check"] = check_json(check(&s, &lim, p.rel_tol));
        // Largest |qd|/vmax and |qdd|/amax seen in the samples.
        let mut vr = 0.0_f64;
        let mut ar = 0.0_f64;
        for k in 0..s.len() {
            for j in 0..p.vmax.len() {
                vr = vr.max(s.qd[k][j].abs() / p.vmax[j]);
                ar = ar.max(s.qdd[k][j].abs() / p.amax[j]);
            }
        }
        out["max_velocity_ratio"] = json!(vr);
        out["max_acceleration_ratio"] = json!(ar);
        out["end_q"] = json!(s.q.last());
    }
    out
}

fn ruckig_one(p: RuckigIn) -> Value {
    let start = JointState { q: p.q0, qd: p.v0, qdd: p.a0 };
    let goal = JointState { q: p.q1, qd: p.v1, qdd: p.a1 };
    let lim = KinematicLimits { velocity: p.vmax.clone(), acceleration: p.amax.clone(), jerk: p.jmax.clone() };
    let t0 = Instant::now();
    let motion = match jerk_limited::plan(&start, &goal, &lim) {
        Ok(m) => m,
        Err(e) => return json!({"error": e.to_string()}),
    };
    let seconds = t0.elapsed().as_secs_f64();
    let dof = motion.dof();
    let mut out = json!({"duration": motion.duration(), "seconds": seconds});
    let probes: Vec<Value> = p
        .probe_times
        .iter()
        .map(|&t| {
            let (mut q, mut qd, mut qdd) = (vec![0.0; dof], vec![0.0; dof], vec![0.0; dof]);
            motion.state_at(t, &mut q, &mut qd, &mut qdd);
            json!({"t": t, "q": q, "qd": qd, "qdd": qdd})
        })
        .collect();
    out["probes"] = json!(probes);
    if let Some(dt) = p.sample_dt {
        let s = sample(&motion, dt);
        let jl = JointLimits { position: vec![], velocity: p.vmax, acceleration: p.amax, jerk: p.jmax };
        out["check"] = check_json(check(&s, &jl, p.rel_tol));
    }
    out
}

fn check_one(p: CheckIn) -> Value {
    let nan = |m: Vec<Vec<Option<f64>>>| -> Vec<Vec<f64>> {
        m.into_iter().map(|r| r.into_iter().map(|v| v.unwrap_or(f64::NAN)).collect()).collect()
    };
    let s = agrisim_trajectory::Sampled { t: p.t, q: nan(p.q), qd: nan(p.qd), qdd: nan(p.qdd) };
    let lim = JointLimits { position: p.position, velocity: p.velocity, acceleration: p.acceleration, jerk: p.jerk };
    check_json(check(&s, &lim, p.rel_tol))
}

fn main() {
    let mut text = String::new();
    std::io::stdin().read_to_string(&mut text).expect("read stdin");
    let req: Request = serde_json::from_str(&text).expect("request JSON");
    let results: Vec<Value> = req
        .problems
        .into_iter()
        .map(|v| {
            let parsed = match req.op.as_str() {
                "toppra" => serde_json::from_value(v).map(toppra_one),
                "ruckig" => serde_json::from_value(v).map(ruckig_one),
                "check" => serde_json::from_value(v).map(check_one),
                other => Ok(json!({"error": format!("unknown op {other}")})),
            };
            parsed.unwrap_or_else(|e| json!({"error": format!("bad problem: {e}")}))
        })
        .collect();
    println!("{}", json!({ "results": results }));
}
