//! How often the harvest node's pre-grasp plan succeeds on the benchmark's targets, without
//! running the co-simulation: the base exactly at the stand-off, the lift at its set-point,
//! both arms home, the planning scene built from the scene's objects as the world FMU lists
//! them. Success and the first failure reason are tallied by visibility class, so changes to
//! the grasp candidates can be compared in seconds.
//!
//! `cargo run --release -p agrisim-bench --example pregrasp_reach -- --n 200 --scenes 5 --seed 1`
//! (`CANDIDATES="yaw,tilt;yaw,tilt;..."` tries other approach directions than
//! `geometry::APPROACHES`; `VERBOSE=1` prints every failure.)

use agrisim_bench::harvest::targets::eligible;
use agrisim_harvest::geometry as geo;
use agrisim_harvest::motion::{Arm, Motion, HOME};
use agrisim_math::{Pose2, Rng};
use agrisim_msgs::agrisim::{CollisionObject, PlanningScene};
use agrisim_msgs::geometry_msgs::{Point, Pose, Quaternion};
use agrisim_msgs::shape_msgs::SolidPrimitive;
use agrisim_scene::{generate, GreenhouseConfig, Kind, Shape};
use std::collections::BTreeMap;

fn arg(name: &str, default: u64) -> u64 {
    let args: Vec<String> = std::env::args().collect();
    args.iter().position(|a| a == name).and_then(|i| args.get(i + 1)).map_or(default, |v| v.parse().expect("a number"))
}

fn kind_label(k: Kind) -> &'static str {
    match k {
        Kind::Stem => "stem",
        Kind::Leaf => "leaf",
        Kind::Truss => "truss",
        Kind::Fruit { .. } => "fruit",
        Kind::Floor => "floor",
        _ => "structure",
    }
}

/// The scene objects within `radius` (horizontally, centre distance plus size) of `c`.
fn scene_near(g: &agrisim_scene::Greenhouse, c: [f64; 2], radius: f64) -> PlanningScene {
    let objects = g
        .objects
        .iter()
        .filter_map(|o| {
            let p = o.placement.translation;
            let (primitive, size) = match o.shape {
                Shape::Box { half } => (
                    SolidPrimitive::new_box(2.0 * half[0], 2.0 * half[1], 2.0 * half[2]),
                    half.iter().map(|h| h * h).sum::<f64>().sqrt(),
                ),
                Shape::Sphere { radius } => (SolidPrimitive::sphere(radius), radius),
                Shape::Cylinder { radius, half_height } => {
                    (SolidPrimitive::cylinder(2.0 * half_height, radius), radius.max(half_height))
                }
            };
            if ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2)).sqrt() > radius + size {
                return None;
            }
            let q = o.placement.rotation;
            Some(CollisionObject {
                id: o.id.to_string(),
                kind: kind_label(o.kind).into(),
                primitive,
                pose: Pose {
                    position: Point { x: p[0], y: p[1], z: p[2] },
                    orientation: Quaternion { x: q[0], y: q[1], z: q[2], w: q[3] },
                },
            })
        })
        .collect();
    PlanningScene { objects, ..Default::default() }
}

/// The reason's family: what the message says first, without coordinates.
fn family(e: &str) -> String {
    let e = e.split(" at (").next().unwrap_or(e);
    e.chars().take(60).collect()
}

/// Experimental candidates: "yaw,tilt;yaw,tilt;..." in radians (yaw > 0 points the approach
/// forward along base x, tilt > 0 upward).
fn candidates(c: [f64; 3], side: f64, list: &str) -> Vec<geo::TcpGoal> {
    list.split(';')
        .map(|p| {
            let v: Vec<f64> = p.split(',').map(|x| x.trim().parse().expect("yaw,tilt")).collect();
            let (yaw, tilt) = (v[0], v[1]);
            let h = tilt.cos();
            geo::TcpGoal { position: c, approach: [h * yaw.sin(), side * h * yaw.cos(), tilt.sin()], x_axis: None }
        })
        .collect()
}

fn main() {
    let (n, scenes, seed) = (arg("--n", 100), arg("--scenes", 3), arg("--seed", 1));
    // The greenhouse of models/scenarios/harvest.toml.
    let cfg = GreenhouseConfig::from_toml_str("active_rows = 6\naisle_width = 2.0").expect("config");
    let mut tally: BTreeMap<&str, [usize; 2]> = BTreeMap::new();
    let mut reasons: BTreeMap<String, usize> = BTreeMap::new();
    let mut blockers: BTreeMap<String, usize> = BTreeMap::new();
    let mut which: BTreeMap<usize, usize> = BTreeMap::new();
    let mut rng = Rng::new(seed);
    for scene in 0..scenes {
        let g = generate(&cfg, cfg.seed.wrapping_add(scene));
        let targets = eligible(&g.objects, &g.layout);
        for _ in 0..n / scenes {
            let t = &targets[((rng.uniform() * targets.len() as f64) as usize).min(targets.len() - 1)];
            let heading = if rng.uniform() < 0.5 { 0.0 } else { std::f64::consts::PI };
            let side = if heading == 0.0 { t.side } else { -t.side };
            let [x, y, yaw] = geo::standoff_facing(t.center, side, heading);
            let base = Pose2 { x, y, yaw };
            let lift = geo::lift_for(t.center[2]);
            let mut m = Motion::new(seed ^ t.fruit_index as u64);
            m.set_target(t.center);
            m.set_scene(&scene_near(&g, [x, y], 2.5), base);
            m.ignore_target(false);
            let (s, c) = yaw.sin_cos();
            let (dx, dy) = (t.center[0] - x, t.center[1] - y);
            let cb = [c * dx + s * dy, -s * dx + c * dy, t.center[2]];
            let arm = if side > 0.0 { Arm::Left } else { Arm::Right };
            let candidates = match std::env::var("CANDIDATES").ok().as_deref() {
                None | Some("current") => geo::grasp_candidates(cb, side),
                Some(list) => candidates(cb, side, list),
            };
            let r = m.plan_pregrasp_any(arm, lift, HOME, &candidates, geo::PRE_GRASP, HOME);
            let class = t.visibility.name();
            let e = tally.entry(class).or_default();
            e[1] += 1;
            match r {
                Ok((i, _)) => {
                    e[0] += 1;
                    *which.entry(i).or_default() += 1;
                }
                Err(err) => {
                    *reasons.entry(family(&err)).or_default() += 1;
                    // What blocks: the kinds of the scene objects the failure names.
                    let mut kinds: Vec<&str> = err
                        .split("object \"")
                        .skip(1)
                        .filter_map(|r| r.split('"').next()?.parse::<u32>().ok())
                        .filter_map(|id| g.objects.iter().find(|o| o.id == id))
                        .map(|o| kind_label(o.kind))
                        .collect();
                    kinds.sort_unstable();
                    kinds.dedup();
                    *blockers.entry(format!("{class}: {}", kinds.join("+"))).or_default() += 1;
                    if std::env::var("VERBOSE").is_ok() {
                        eprintln!("{class} fruit {}: {err}", t.fruit_index);
                    }
                }
            }
        }
    }
    for (class, [ok, all]) in &tally {
        println!("{class}: {ok}/{all}");
    }
    println!("candidate used: {which:?}");
    for (b, k) in &blockers {
        println!("{k:4}  blocked by {b}");
    }
    for (r, k) in &reasons {
        println!("{k:4}  {r}");
    }
}
