//! The `Greenhouse` model: builds the scene at initialization, then each step moves the robot
//! base to its input pose and reports contacts, clearance and ground truth.

use crate::base_box::BaseBox;
use crate::clearance::min_clearance;
use crate::collision_report::collision_state;
use crate::contacts::{robot_contacts, ContactTracker};
use crate::ground_truth::{fruit_poses, Target};
use crate::ports::*;
use crate::scene_world::SceneWorld;
use agrisim_fmi::{Log, Model, Store, Var};
use agrisim_fmu_util::{to_ns, Schedule};
use agrisim_greenhouse::config::GreenhouseConfig;
use agrisim_msgs::Message;
use rapier3d::prelude::Pose;

/// Everything that exists once the scene is built.
#[derive(Clone)]
struct Running {
    world: SceneWorld,
    tracker: ContactTracker,
    band: [f64; 2],
    clearance_cap: f64,
    collision_schedule: Schedule,
    fruit_schedule: Schedule,
    collision_seq: i64,
    fruit_seq: i64,
    target_seq: i64,
    /// `target_fruit` at the last target publication (a change publishes at once).
    published_target: Option<i32>,
}

/// The Greenhouse world model (the FMU's `Model`).
#[derive(Clone, Default)]
pub struct GreenhouseWorld {
    /// Boxed: a cheap `new()` and a small FMU-state handle until the scene exists.
    run: Option<Box<Running>>,
}

impl GreenhouseWorld {
    /// The scene world (None before initialization): for tests and tools.
    pub fn scene(&self) -> Option<&SceneWorld> {
        self.run.as_ref().map(|r| &r.world)
    }
}

/// The generator's configuration and seed from the `scene` and `seed` parameters. A negative
/// seed keeps the configuration's own `seed`, which every other scene consumer (LiDAR,
/// navigation map) uses too.
pub fn scene_config(io: &Store) -> Result<(GreenhouseConfig, u64), String> {
    let cfg = GreenhouseConfig::from_toml_str(io.string(SCENE)).map_err(|e| format!("parameter scene: {e}"))?;
    let seed = match io.i32(SEED) {
        s if s < 0 => cfg.seed,
        s => s as u64,
    };
    Ok((cfg, seed))
}

fn robot_pose(io: &Store, base: &BaseBox) -> Result<Pose, String> {
    let (x, y, yaw) = (io.f64(BASE_X), io.f64(BASE_Y), io.f64(BASE_YAW));
    if [x, y, yaw].iter().all(|v| v.is_finite() && v.abs() < 1e6) {
        Ok(base.pose(x, y, yaw))
    } else {
        Err(format!("robot pose input (base_x, base_y, base_yaw) = ({x}, {y}, {yaw}) is not finite or beyond 1e6"))
    }
}

/// Publication instants at multiples of 1/rate on simulation time.
fn schedule(io: &Store, i: usize, start_time: f64) -> Result<Schedule, String> {
    Schedule::new(io.f64(i), start_time).map_err(|e| format!("parameter {}: {e}", VARIABLES[i].name))
}

impl Running {
    /// Contacts, clearance, ground truth and due messages for time `t`.
    fn report(&mut self, io: &mut Store, t: f64) {
        self.report_contacts(io, t);
        self.report_ground_truth(io, t);
    }

    fn report_contacts(&mut self, io: &mut Store, t: f64) {
        let contacts = robot_contacts(&self.world);
        let changed = self.tracker.update(&contacts);
        io.set_bool(COLLISION, !contacts.is_empty());
        io.set_i32(COLLISION_COUNT, self.tracker.onsets().min(i32::MAX as u64) as i32);
        // Anything touching the box lies in its band: clearance 0, whatever f32 rounding in
        // the distance query says (it can differ from the contact query by ~1e-5 m).
        let clearance = if contacts.is_empty() { min_clearance(&self.world, self.band, self.clearance_cap) } else { 0.0 };
        io.set_f64(MIN_CLEARANCE, clearance);
        let due = self.collision_schedule.due(t);
        if changed || due.is_some() {
            let stamp = if changed { to_ns(t) } else { due.unwrap_or(to_ns(t)) };
            self.collision_seq += 1;
            io.set_binary(COLLISION_STATE, &collision_state(&self.world, &contacts, stamp).to_cdr());
            io.set_i64(COLLISION_STATE_SEQ, self.collision_seq);
        }
    }

    fn report_ground_truth(&mut self, io: &mut Store, t: f64) {
        let fruit_due = self.fruit_schedule.due(t);
        if let Some(stamp) = fruit_due {
            self.fruit_seq += 1;
            io.set_binary(FRUIT_POSES, &fruit_poses(&self.world, stamp).to_cdr());
            io.set_i64(FRUIT_POSES_SEQ, self.fruit_seq);
        }
        let index = io.i32(TARGET_FRUIT);
        let target = Target::select(&self.world, index);
        io.set_bool(TARGET_VALID, target.is_some());
        io.set_i32(TARGET_ID, target.map_or(-1, |t| t.id as i32));
        let p = target.map_or(rapier3d::prelude::Vector::ZERO, |t| t.pose.translation);
        io.set_f64(TARGET_X, p.x as f64);
        io.set_f64(TARGET_Y, p.y as f64);
        io.set_f64(TARGET_Z, p.z as f64);
        let reselected = self.published_target != Some(index);
        if let Some(target) = target.filter(|_| fruit_due.is_some() || reselected) {
            let stamp = if reselected { to_ns(t) } else { fruit_due.unwrap_or(to_ns(t)) };
            self.target_seq += 1;
            io.set_binary(TARGET, &target.message(stamp).to_cdr());
            io.set_i64(TARGET_SEQ, self.target_seq);
        }
        self.published_target = Some(index);
    }
}

impl Model for GreenhouseWorld {
    const NAME: &'static str = "Greenhouse";
    const TOKEN: &'static str = "{9b7d2e41-5c3a-4f18-a6e2-agrisim-greenhouse-world-1}";
    const DESCRIPTION: &'static str =
        "Tomato greenhouse world: the scene in a rapier world, robot-scene contacts and clearance, ground-truth fruit poses";
    const VARIABLES: &'static [Var] = VARIABLES;

    fn new() -> Self {
        Self::default()
    }

    fn initialize(&mut self, io: &mut Store, start_time: f64, log: &mut dyn Log) -> Result<(), String> {
        self.run = None;
        let base = BaseBox::from_params(io)?;
        let cap = io.f64(CLEARANCE_CAP);
        if !(cap.is_finite() && cap > 0.0) {
            return Err(format!("parameter clearance_cap must be positive and finite, got {cap}"));
        }
        let collision_schedule = schedule(io, COLLISION_RATE, start_time)?;
        let fruit_schedule = schedule(io, FRUIT_RATE, start_time)?;
        let pose = robot_pose(io, &base)?;
        let (cfg, seed) = scene_config(io)?;
        let greenhouse = agrisim_greenhouse::generate(&cfg, seed);
        let world = SceneWorld::build(&greenhouse.objects, base, pose)?;
        log.info(&format!(
            "greenhouse: {} rows, {} objects, {} fruit (seed {seed})",
            cfg.rows,
            world.objects.len(),
            world.fruit.len()
        ));
        io.set_i32(FRUIT_COUNT, world.fruit.len().min(i32::MAX as usize) as i32);
        let mut run = Box::new(Running {
            world,
            tracker: ContactTracker::default(),
            band: base.band(),
            clearance_cap: cap,
            collision_schedule,
            fruit_schedule,
            collision_seq: 0,
            fruit_seq: 0,
            target_seq: 0,
            published_target: None,
        });
        run.report(io, start_time);
        self.run = Some(run);
        Ok(())
    }

    fn do_step(&mut self, io: &mut Store, t: f64, h: f64, _log: &mut dyn Log) -> Result<(), String> {
        if !(h.is_finite() && h > 0.0) {
            return Err(format!("communication step {h} s must be positive and finite"));
        }
        let run = self.run.as_mut().ok_or("do_step before initialization")?;
        let pose = robot_pose(io, &run.world.robot.base)?;
        run.world.move_robot(pose);
        run.report(io, t + h);
        Ok(())
    }
}
