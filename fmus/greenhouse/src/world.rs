//! The `Greenhouse` model: builds the scene and the robot at initialization, then each step
//! moves the robot base and links to their input pose (FK of lift, arm joints and fingers),
//! applies the harvest rules (grasp, carry, release, fall, place), and reports contacts,
//! clearance, harvest counters and ground truth.

use crate::base_box::BaseBox;
use crate::clearance::min_clearance;
use crate::collision_report::collision_state;
use crate::contacts::{robot_contacts, Category, ContactTracker, Press, RobotContact, Toucher};
use crate::foliage::{Foliage, FoliageParams, FoliageTable, Part, Spring};
use crate::ground_truth::{fruit_poses, Target};
use crate::harvest::{DamageParams, FruitState, Harvest, HarvestParams};
use crate::moved_objects::{grown_fruit_poses, moved_objects};
use crate::pedicel::{PedicelGeometry, PedicelParams};
use crate::planning_scene::planning_scene;
use crate::ports::*;
use crate::robot_links::{base_pose, to_rapier};
use crate::robot_model::{Coords, RobotModel, Side};
use crate::scene_world::SceneWorld;
use crate::stems::{stem_loads, StemGeometry, StemParams};
use agrisim_fmi::{Log, Model, OutPort, Store, Var};
use agrisim_msgs::agrisim::PlantDamage;
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::std_msgs::Header;
use agrisim_msgs::Message;
use agrisim_robot::Pose as RPose;
use agrisim_scene::config::GreenhouseConfig;
use agrisim_schedule::{to_ns, Schedule};
use rapier3d::prelude::{Pose, RigidBodyHandle};
use std::sync::Arc;

const LEFT_Q: [usize; 7] = [LEFT_Q1, LEFT_Q2, LEFT_Q3, LEFT_Q4, LEFT_Q5, LEFT_Q6, LEFT_Q7];
const RIGHT_Q: [usize; 7] = [RIGHT_Q1, RIGHT_Q2, RIGHT_Q3, RIGHT_Q4, RIGHT_Q5, RIGHT_Q6, RIGHT_Q7];

/// The robot's kinematic state as last applied to the world.
#[derive(Clone)]
struct RobotState {
    model: Arc<RobotModel>,
    coords: Coords,
    /// (x, y, yaw) of base_link in the map frame.
    planar: [f64; 3],
    /// Every link in base_link (FK of `coords`).
    link_in_base: Vec<RPose>,
    hand_links: [usize; 2],
    /// left_link0 and right_link0: the frames of the load outputs.
    arm_bases: [usize; 2],
    box_link: usize,
    /// harvest_box_link in the map frame at the end of the last step.
    box_pose: RPose,
    physics_dt: f64,
}

impl RobotState {
    fn hands(&self, base: &RPose) -> [RPose; 2] {
        self.hand_links.map(|i| base.mul(&self.link_in_base[i]))
    }
}

/// Everything that exists once the scene is built.
#[derive(Clone)]
struct Running {
    world: SceneWorld,
    robot: RobotState,
    harvest: Harvest,
    /// Each fruit's pedicel (by fruit index), from the scene: rebuilt, not serialized.
    pedicels: Arc<Vec<PedicelGeometry>>,
    /// The main stems (sorted by object index), from the scene: rebuilt, not serialized.
    stems: Arc<Vec<StemGeometry>>,
    /// The compound leaves and trusses and their grown poses, from the scene: rebuilt, not
    /// serialized.
    foliage_table: Arc<FoliageTable>,
    foliage_params: FoliageParams,
    /// The leaves and trusses the robot moved.
    foliage: Foliage,
    /// Each fruit body's pose as built, from the scene: rebuilt, not serialized.
    grown_fruit: Arc<Vec<Pose>>,
    /// The last step's length [s] (0 before the first step).
    last_h: f64,
    /// Kinematic moves of one step (kept to reuse its allocation).
    moves: Vec<(RigidBodyHandle, Pose)>,
    /// Kinematic fruit to keep awake while something falls (reused allocation).
    awake: Vec<RigidBodyHandle>,
    tracker: ContactTracker,
    band: [f64; 2],
    clearance_cap: f64,
    collision_schedule: Schedule,
    fruit_schedule: Schedule,
    scene_schedule: Schedule,
    scene_radius: f64,
    ports: Ports,
    window_ns: i64,
    /// `target_fruit` at the last target publication (a change publishes at once).
    published_target: Option<i32>,
}

/// A serialized [`Running`] (see `save_state`).
type SavedRun = (
    SceneWorld,
    (Coords, [f64; 3], Vec<RPose>, RPose),
    (Harvest, Foliage, f64),
    ContactTracker,
    (Schedule, Schedule, Schedule),
    Ports,
    Option<i32>,
);

/// The world's message ports.
#[derive(Clone, serde::Serialize, serde::Deserialize)]
struct Ports {
    scene: OutPort,
    collision: OutPort,
    fruit: OutPort,
    target: OutPort,
    damage: OutPort,
    /// CDR of the last published PlantDamage with a zero header (a change publishes).
    damage_published: Vec<u8>,
    moved: OutPort,
    /// CDR of the last published MovedObjects with a zero header (a change publishes).
    moved_published: Option<Vec<u8>>,
}

impl Ports {
    fn new() -> Ports {
        Ports {
            scene: OutPort::new(PLANNING_SCENE, PLANNING_SCENE_SEQ),
            collision: OutPort::new(COLLISION_STATE, COLLISION_STATE_SEQ),
            fruit: OutPort::new(FRUIT_POSES, FRUIT_POSES_SEQ),
            target: OutPort::new(TARGET, TARGET_SEQ),
            damage: OutPort::new(PLANT_DAMAGE, PLANT_DAMAGE_SEQ),
            damage_published: Vec::new(),
            moved: OutPort::new(MOVED_OBJECTS, MOVED_OBJECTS_SEQ),
            moved_published: None,
        }
    }

    fn sync(&mut self, io: &mut Store, now_ns: i64, window_ns: i64) {
        for p in
            [&mut self.scene, &mut self.collision, &mut self.fruit, &mut self.target, &mut self.damage, &mut self.moved]
        {
            p.sync(io, now_ns, window_ns);
        }
    }
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

fn planar_input(io: &Store) -> Result<[f64; 3], String> {
    let (x, y, yaw) = (io.f64(BASE_X), io.f64(BASE_Y), io.f64(BASE_YAW));
    if [x, y, yaw].iter().all(|v| v.is_finite() && v.abs() < 1e6) {
        Ok([x, y, yaw])
    } else {
        Err(format!("robot pose input (base_x, base_y, base_yaw) = ({x}, {y}, {yaw}) is not finite or beyond 1e6"))
    }
}

/// Lift, arm joints and finger gaps from the inputs. Non-finite values are errors; finite
/// ones are clamped to the URDF limits by FK, the gaps here to the fingers' travel.
fn coords_input(io: &Store, model: &RobotModel) -> Result<Coords, String> {
    let mut c = Coords { lift: io.f64(LIFT_POSITION), ..Coords::default() };
    for (side, vrs) in [(Side::Left, LEFT_Q), (Side::Right, RIGHT_Q)] {
        for (i, &vr) in vrs.iter().enumerate() {
            c.arms[side as usize][i] = io.f64(vr);
        }
    }
    c.widths = [io.f64(LEFT_FINGER_WIDTH), io.f64(RIGHT_FINGER_WIDTH)];
    let all = std::iter::once(c.lift).chain(c.arms.iter().flatten().copied()).chain(c.widths);
    if let Some(bad) = all.zip(0..).find(|(v, _)| !v.is_finite()) {
        return Err(format!(
            "robot joint input #{} (lift, left_q1..7, right_q1..7, widths) is not finite: {}",
            bad.1, bad.0
        ));
    }
    for side in Side::BOTH {
        let s = side as usize;
        c.widths[s] = c.widths[s].clamp(0.0, model.pads[s].max_width());
    }
    Ok(c)
}

fn positive_param(io: &Store, i: usize, max: f64) -> Result<f64, String> {
    let v = io.f64(i);
    if v.is_finite() && v >= 0.0 && v <= max {
        Ok(v)
    } else {
        Err(format!("parameter {} must be in [0, {max}], got {v}", VARIABLES[i].name))
    }
}

/// The `pedicel_*` parameters.
fn pedicel_params(io: &Store) -> Result<PedicelParams, String> {
    let mean = |i: usize, max: f64| {
        let v = positive_param(io, i, max)?;
        if v > 0.0 {
            Ok(v)
        } else {
            Err(format!("parameter {} must be positive, got {v}", VARIABLES[i].name))
        }
    };
    Ok(PedicelParams {
        enabled: io.bool(PEDICEL_ENABLED),
        pull_mean: mean(PEDICEL_PULL_MEAN, 1000.0)?,
        pull_sd: positive_param(io, PEDICEL_PULL_SD, 1000.0)?,
        bend_mean: mean(PEDICEL_BEND_MEAN, 100.0)?,
        bend_sd: positive_param(io, PEDICEL_BEND_SD, 100.0)?,
        twist_mean: mean(PEDICEL_TWIST_MEAN, 100.0)?,
        twist_sd: positive_param(io, PEDICEL_TWIST_SD, 100.0)?,
        stiffness: mean(PEDICEL_STIFFNESS, 1e6)?,
        damping: positive_param(io, PEDICEL_DAMPING, 1e4)?,
        bend_stiffness: mean(PEDICEL_BEND_STIFFNESS, 1e4)?,
        twist_stiffness: mean(PEDICEL_TWIST_STIFFNESS, 1e4)?,
        rot_damping: positive_param(io, PEDICEL_ROT_DAMPING, 100.0)?,
    })
}

/// The `stem_*` parameters: both positive.
fn stem_params(io: &Store) -> Result<StemParams, String> {
    let p = StemParams { modulus: io.f64(STEM_MODULUS), strength: io.f64(STEM_STRENGTH) };
    for (v, i) in [(p.modulus, STEM_MODULUS), (p.strength, STEM_STRENGTH)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(format!("parameter {} must be positive and finite, got {v}", VARIABLES[i].name));
        }
    }
    Ok(p)
}

/// The `leaf_*` and `truss_*` parameters.
fn foliage_params(io: &Store) -> Result<FoliageParams, String> {
    let spring = |[enabled, stiffness, frequency, damping_ratio]: [usize; 4]| -> Result<Spring, String> {
        let s = Spring {
            enabled: io.bool(enabled),
            stiffness: io.f64(stiffness),
            frequency: io.f64(frequency),
            damping_ratio: io.f64(damping_ratio),
        };
        for (v, i) in [(s.stiffness, stiffness), (s.frequency, frequency)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("parameter {} must be positive and finite, got {v}", VARIABLES[i].name));
            }
        }
        if !(s.damping_ratio.is_finite() && s.damping_ratio >= 0.0) {
            return Err(format!(
                "parameter {} must be finite and not negative, got {}",
                VARIABLES[damping_ratio].name, s.damping_ratio
            ));
        }
        Ok(s)
    };
    let truss = spring([TRUSS_COMPLIANT, TRUSS_STIFFNESS, TRUSS_FREQUENCY, TRUSS_DAMPING_RATIO])?;
    // A pedicel bends on its own stiffness (that of the pedicel model, checked there).
    let pedicel =
        Spring { stiffness: io.f64(PEDICEL_BEND_STIFFNESS), frequency: crate::foliage::PEDICEL_FREQUENCY, ..truss };
    Ok(FoliageParams {
        leaf: spring([LEAF_COMPLIANT, LEAF_STIFFNESS, LEAF_FREQUENCY, LEAF_DAMPING_RATIO])?,
        truss,
        pedicel,
    })
}

/// Each fruit's pedicel from the scene's objects: `.../pedicel{t}_{f}` belongs to
/// `.../fruit{t}_{f}`, a rod whose local z runs from the fruit's top up to the truss.
/// `fruit` lists the fruit's indices into `objects` in fruit order.
pub fn pedicel_geometry(objects: &[agrisim_scene::scene::Object], fruit: &[usize]) -> Vec<PedicelGeometry> {
    use agrisim_scene::Shape;
    let by_name: std::collections::BTreeMap<&str, usize> =
        objects.iter().enumerate().map(|(i, o)| (o.name.as_str(), i)).collect();
    fruit
        .iter()
        .map(|&f| {
            let name = objects[f].name.replace("/fruit", "/pedicel");
            let Some(o) = by_name.get(name.as_str()).map(|&i| &objects[i]) else { return PedicelGeometry::VERTICAL };
            let Shape::Cylinder { half_height, .. } = o.shape else { return PedicelGeometry::VERTICAL };
            let [x, y, z, w] = o.placement.rotation;
            // The quaternion's image of local z.
            let mut axis = [2.0 * (x * z + w * y), 2.0 * (y * z - w * x), 1.0 - 2.0 * (x * x + y * y)];
            let n = agrisim_math::vec3::norm(axis);
            if !(n > 1e-9) {
                return PedicelGeometry::VERTICAL;
            }
            axis = axis.map(|c| c / n);
            if axis[2] < 0.0 {
                axis = axis.map(|c| -c);
            }
            PedicelGeometry { axis, length: 2.0 * half_height }
        })
        .collect()
}

/// Publication instants at multiples of 1/rate on simulation time.
fn schedule(io: &Store, i: usize, start_time: f64) -> Result<Schedule, String> {
    Schedule::new(io.f64(i), start_time).map_err(|e| format!("parameter {}: {e}", VARIABLES[i].name))
}

impl Running {
    /// Contacts, clearance, ground truth and due messages for time `t`.
    fn report(&mut self, io: &mut Store, t: f64) {
        self.report_contacts(io, t);
        self.report_harvest(io, t);
        self.report_ground_truth(io, t);
        self.report_moved(t);
        if let Some(stamp) = self.scene_schedule.due(t) {
            let [x, y, _] = self.robot.planar;
            self.ports
                .scene
                .publish(stamp, planning_scene(&self.world, &self.harvest, [x, y], self.scene_radius, stamp).to_cdr());
        }
        self.ports.sync(io, to_ns(t), self.window_ns);
    }

    /// The moved objects, at the start and whenever one moves (each step while a leaf swings
    /// or a fruit is carried; nothing while the robot only drives).
    fn report_moved(&mut self, t: f64) {
        let mut msg = moved_objects(&self.world, &self.grown_fruit, &self.foliage_table, &self.foliage);
        let key = msg.to_cdr();
        if self.ports.moved_published.as_ref() != Some(&key) {
            let stamp = to_ns(t);
            msg.header = Header::new(Time::from_nanos(stamp), "map");
            self.ports.moved.publish(stamp, msg.to_cdr());
            self.ports.moved_published = Some(key);
        }
    }

    fn report_harvest(&mut self, io: &mut Store, t: f64) {
        let (w, h) = (&self.world, &self.harvest);
        let id = |f: Option<usize>| f.map_or(-1, |f| w.objects[w.fruit[f].object].id.min(i32::MAX as u32) as i32);
        io.set_f64(LEFT_GRASP_WIDTH, h.grasp_width(w, Side::Left));
        io.set_f64(RIGHT_GRASP_WIDTH, h.grasp_width(w, Side::Right));
        io.set_i32(LEFT_HELD_ID, id(h.grippers[Side::Left as usize].held));
        io.set_i32(RIGHT_HELD_ID, id(h.grippers[Side::Right as usize].held));
        let count = |n: u32| n.min(i32::MAX as u32) as i32;
        io.set_i32(PICKED_COUNT, count(h.picked));
        io.set_i32(PLACED_COUNT, count(h.placed));
        io.set_i32(DROPPED_COUNT, count(h.dropped));
        io.set_i32(LAST_PLACED_ID, id(h.last_placed));
        // The pedicel loads on the hands, in each arm's link0 (about its origin).
        let r = &self.robot;
        let base = base_pose(r.planar[0], r.planar[1], r.planar[2]);
        let outs = [
            (LEFT_LOAD_FX, [LEFT_PEDICEL_PULL, LEFT_PEDICEL_BEND, LEFT_PEDICEL_TWIST]),
            (RIGHT_LOAD_FX, [RIGHT_PEDICEL_PULL, RIGHT_PEDICEL_BEND, RIGHT_PEDICEL_TWIST]),
        ];
        for (s, (first, az)) in outs.into_iter().enumerate() {
            let (mut wrench, mut at_az) = ([0.0; 6], [0.0; 3]);
            if let Some(load) = &h.loads[s] {
                let link0 = base.mul(&r.link_in_base[r.arm_bases[s]]);
                let inv = link0.inverse();
                let f = inv.rotate(load.force);
                let m = inv.rotate(load.moment_about(link0.trans));
                wrench = [f[0], f[1], f[2], m[0], m[1], m[2]];
                at_az = [load.pull, load.bend, load.twist];
            }
            // LEFT_LOAD_FX..MZ (and the right's) are consecutive.
            for (k, v) in wrench.into_iter().enumerate() {
                io.set_f64(first + k, v);
            }
            for (vr, v) in az.into_iter().zip(at_az) {
                io.set_f64(vr, v);
            }
        }
        io.set_i32(DETACHED_PULL_COUNT, count(h.detached_by[0]));
        io.set_i32(DETACHED_BEND_COUNT, count(h.detached_by[1]));
        io.set_i32(DETACHED_TWIST_COUNT, count(h.detached_by[2]));
        let last = h.last_detachment.as_ref();
        io.set_i32(LAST_DETACH_MODE, last.map_or(0, |d| d.mode.code()));
        io.set_f64(LAST_DETACH_FORCE, last.map_or(0.0, |d| agrisim_math::vec3::norm(d.load.force)));
        io.set_f64(LAST_DETACH_MOMENT, last.map_or(0.0, |d| d.load.bend.max(d.load.twist)));
        let n = |k: usize| k.min(i32::MAX as usize) as i32;
        io.set_i32(BRUISED_COUNT, n(h.damage.bruised()));
        io.set_i32(GRIP_BRUISED_COUNT, n(h.damage.grip_bruised.len()));
        io.set_i32(IMPACT_BRUISED_COUNT, n(h.damage.impact_bruised.len()));
        io.set_i32(UNRIPE_DETACHED_COUNT, n(h.damage.unripe_detached.len()));
        io.set_i32(STEMS_BROKEN_COUNT, n(h.damage.stems_broken.len()));
        io.set_f64(PEAK_STEM_LOAD, h.damage.peak_stem_ratio);
        io.set_f64(PEAK_STEM_FORCE, h.damage.peak_stem_force);
        let u = |k: usize| k.min(u32::MAX as usize) as u32;
        let mut msg = PlantDamage {
            header: Header::default(),
            bruised_by_grip: u(h.damage.grip_bruised.len()),
            bruised_by_impact: u(h.damage.impact_bruised.len()),
            unripe_detached: u(h.damage.unripe_detached.len()),
            stems_broken: u(h.damage.stems_broken.len()),
            detached_by_pull: h.detached_by[0],
            detached_by_bend: h.detached_by[1],
            detached_by_twist: h.detached_by[2],
            last_detach_mode: last.map_or("", |d| d.mode.label()).to_string(),
            last_detach_force: last.map_or(0.0, |d| agrisim_math::vec3::norm(d.load.force)),
            last_detach_moment: last.map_or(0.0, |d| d.load.bend.max(d.load.twist)),
            leaf_pushes: self.foliage.pushes.min(u32::MAX as u64) as u32,
            // Rounded: a peak rises step by step while a press goes on, and every change is
            // a message.
            peak_leaf_force: (10.0 * self.foliage.peak_force).round() / 10.0,
            peak_stem_load: (100.0 * h.damage.peak_stem_ratio).round() / 100.0,
        };
        let key = msg.to_cdr();
        if key != self.ports.damage_published {
            let stamp = to_ns(t);
            msg.header = Header::new(Time::from_nanos(stamp), "map");
            self.ports.damage.publish(stamp, msg.to_cdr());
            self.ports.damage_published = key;
        }
    }

    /// One step of `h` seconds with the robot inputs in `io`: kinematics, harvest rules,
    /// physics, settling.
    fn advance(&mut self, io: &Store, h: f64) -> Result<(), String> {
        let planar = planar_input(io)?;
        let coords = coords_input(io, &self.robot.model)?;
        let r = &mut self.robot;
        let (base_moved, joints_moved) = (planar != r.planar, coords != r.coords);
        if joints_moved {
            r.model.fk(&coords, &mut r.link_in_base);
            r.coords = coords;
        }
        r.planar = planar;
        let base = base_pose(planar[0], planar[1], planar[2]);
        let hands = r.hands(&base);
        let box_pose = base.mul(&r.link_in_base[r.box_link]);
        self.harvest.grip(&mut self.world, &r.model.pads, &self.pedicels, &hands, coords.widths, h);
        let grip_forces = [io.f64(LEFT_GRIP_FORCE), io.f64(RIGHT_GRIP_FORCE)];
        if grip_forces.iter().any(|f| !f.is_finite()) {
            return Err(format!(
                "grip force inputs (left_grip_force, right_grip_force) = {grip_forces:?} are not finite"
            ));
        }
        self.harvest.pull(&self.world, &hands, grip_forces, h);
        self.moves.clear();
        if base_moved {
            let body = self.world.robot.base.pose(planar[0], planar[1], planar[2]);
            self.moves.push((self.world.robot.body, body));
        }
        if base_moved || joints_moved {
            for link in &mut self.world.links {
                let pose = to_rapier(&base.mul(&r.link_in_base[link.link]));
                if pose != link.pose {
                    link.pose = pose;
                    self.moves.push((link.body, pose));
                }
            }
        }
        self.harvest.fruit_moves(&self.world, &hands, &box_pose, &mut self.moves);
        let dynamic = self.harvest.any_falling();
        if dynamic {
            self.harvest.kinematic_fruit(&self.world, &mut self.awake);
        }
        self.world.advance(&self.moves, &self.awake, h, dynamic, r.physics_dt);
        self.last_h = h;
        let box_vel: [f64; 3] = std::array::from_fn(|i| (box_pose.trans[i] - r.box_pose.trans[i]) / h);
        self.harvest.settle(&mut self.world, &r.model.box_interior, &box_pose, box_vel, h);
        r.box_pose = box_pose;
        Ok(())
    }

    fn report_contacts(&mut self, io: &mut Store, t: f64) {
        let contacts = robot_contacts(&self.world, &self.harvest);
        let presses: Vec<Press> = contacts.iter().filter_map(RobotContact::press).collect();
        let stem_presses = presses.iter().map(|p| (p.object, p.point, p.depth));
        let loads = stem_loads(&self.stems, stem_presses, &self.harvest.params.damage.stem);
        self.harvest.damage.press_stems(&loads);
        let harvest = &self.harvest;
        let hangs = |f: usize| harvest.state(f) == FruitState::OnPlant;
        if self.last_h > 0.0
            && self.foliage.step(
                &self.foliage_table,
                &mut self.world,
                &presses,
                &self.foliage_params,
                self.last_h,
                hangs,
            )
        {
            self.world.refresh();
        }
        let (foliage, table) = (&self.foliage, &*self.foliage_table);
        let count = |n: u64| n.min(i32::MAX as u64) as i32;
        io.set_i32(LEAF_PUSHES, count(foliage.pushes));
        io.set_i32(MOVING_LEAVES, count(foliage.moving_of(table, Part::Leaf) as u64));
        io.set_f64(PEAK_LEAF_FORCE, foliage.peak_force);
        io.set_i32(TRUSS_PUSHES, count(foliage.truss_pushes));
        io.set_i32(
            MOVING_TRUSSES,
            count((foliage.moving_of(table, Part::Truss) + foliage.moving_of(table, Part::Pedicel)) as u64),
        );
        io.set_f64(PEAK_TRUSS_FORCE, foliage.peak_truss_force);
        let changed = self.tracker.update(&contacts);
        io.set_bool(COLLISION, !contacts.is_empty());
        io.set_i32(COLLISION_COUNT, count(self.tracker.onsets()));
        io.set_i32(CONTACT_ROBOT_PLANT, count(self.tracker.onsets_in(Category::Plant)));
        io.set_i32(CONTACT_ROBOT_STRUCTURE, count(self.tracker.onsets_in(Category::Structure)));
        io.set_i32(CONTACT_ARM_ARM, count(self.tracker.onsets_in(Category::ArmArm)));
        io.set_i32(CONTACT_CARRIED_STRUCTURE, count(self.tracker.onsets_in(Category::CarriedStructure)));
        // Anything touching the box lies in its band: clearance 0, whatever f32 rounding in
        // the distance query says (it can differ from the contact query by ~1e-5 m). Only
        // part 0, the base box: what a carried fruit touches says nothing of the band.
        let base_touches = contacts.iter().any(|c| c.toucher == Toucher::Part(0));
        let clearance = if !base_touches { min_clearance(&self.world, self.band, self.clearance_cap) } else { 0.0 };
        io.set_f64(MIN_CLEARANCE, clearance);
        let due = self.collision_schedule.due(t);
        if changed || due.is_some() {
            let stamp = if changed { to_ns(t) } else { due.unwrap_or(to_ns(t)) };
            self.ports.collision.publish(stamp, collision_state(&self.world, &contacts, stamp).to_cdr());
        }
    }

    fn report_ground_truth(&mut self, io: &mut Store, t: f64) {
        let fruit_due = self.fruit_schedule.due(t);
        if let Some(stamp) = fruit_due {
            self.ports.fruit.publish(stamp, fruit_poses(&self.world, stamp).to_cdr());
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
            self.ports.target.publish(stamp, target.message(stamp).to_cdr());
        }
        self.published_target = Some(index);
    }
}

impl Model for GreenhouseWorld {
    const NAME: &'static str = "Greenhouse";
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
        let (cfg, seed) = scene_config(io)?;
        let params = HarvestParams {
            grasp_tolerance: positive_param(io, GRASP_TOLERANCE, 0.05)?,
            release_margin: positive_param(io, RELEASE_MARGIN, 0.05)?,
            pedicel: pedicel_params(io)?,
            seed,
            damage: DamageParams {
                bruise_grip_force: positive_param(io, BRUISE_GRIP_FORCE, 1000.0)?,
                bruise_impact_speed: positive_param(io, BRUISE_IMPACT_SPEED, 100.0)?,
                stem: stem_params(io)?,
                ripe_stage: match io.i32(RIPE_STAGE) {
                    s @ 1..=7 => s as u8,
                    s => {
                        return Err(format!(
                            "parameter ripe_stage must be a USDA stage 1..6 (7: none is ripe), got {s}"
                        ))
                    }
                },
            },
        };
        let physics_dt = positive_param(io, PHYSICS_DT, 0.1)?;
        let scene_schedule = schedule(io, PLANNING_SCENE_RATE, start_time)?;
        let scene_radius = positive_param(io, PLANNING_SCENE_RADIUS, 1000.0)?;
        if physics_dt < 1e-4 {
            return Err(format!("parameter physics_dt must be at least 1e-4 s, got {physics_dt}"));
        }
        let planar = planar_input(io)?;
        let model = Arc::new(RobotModel::load()?);
        let coords = coords_input(io, &model)?;
        let mut link_in_base = Vec::new();
        model.fk(&coords, &mut link_in_base);
        let link = |name: &str| model.link_index(name).ok_or(format!("robot URDF: no link {name}"));
        let hand_links = [link("left_hand")?, link("right_hand")?];
        let arm_bases = [link("left_link0")?, link("right_link0")?];
        let box_link = link("harvest_box_link")?;
        let greenhouse = agrisim_scene::generate(&cfg, seed);
        let mut world = SceneWorld::build(&greenhouse.objects, base, base.pose(planar[0], planar[1], planar[2]))?;
        let base_link = base_pose(planar[0], planar[1], planar[2]);
        world.add_robot_links(&model, &base_link, &link_in_base)?;
        let robot = RobotState {
            box_pose: base_link.mul(&link_in_base[box_link]),
            model,
            coords,
            planar,
            link_in_base,
            hand_links,
            arm_bases,
            box_link,
            physics_dt,
        };
        let harvest = Harvest::new(params, coords.widths, robot.hands(&base_link));
        let stems = Arc::new(StemGeometry::all(&greenhouse.objects));
        let foliage_table = Arc::new(FoliageTable::new(&greenhouse.objects, &world));
        let foliage_params = foliage_params(io)?;
        let grown_fruit = Arc::new(grown_fruit_poses(&world));
        let pedicels =
            Arc::new(pedicel_geometry(&greenhouse.objects, &world.fruit.iter().map(|f| f.object).collect::<Vec<_>>()));
        log.info(format_args!(
            "greenhouse: {} rows, {} objects, {} fruit (seed {seed})",
            cfg.rows,
            world.objects.len(),
            world.fruit.len()
        ));
        io.set_i32(FRUIT_COUNT, world.fruit.len().min(i32::MAX as usize) as i32);
        let mut run = Box::new(Running {
            world,
            robot,
            harvest,
            pedicels,
            stems,
            foliage_table,
            foliage_params,
            foliage: Foliage::default(),
            grown_fruit,
            last_h: 0.0,
            moves: Vec::new(),
            awake: Vec::new(),
            tracker: ContactTracker::default(),
            band: base.band(),
            clearance_cap: cap,
            collision_schedule,
            fruit_schedule,
            scene_schedule,
            scene_radius,
            ports: Ports::new(),
            window_ns: agrisim_fmi::port::window_ns(io, PORT_WINDOW)?,
            published_target: None,
        });
        run.report(io, start_time);
        self.run = Some(run);
        Ok(())
    }

    /// The physics world, the robot's applied pose, harvest, contacts, schedules and ports;
    /// the rest of [`Running`] follows from the parameters.
    fn save_state(&self, out: &mut Vec<u8>) -> Result<(), String> {
        let r = self.run.as_ref().ok_or("the world is not initialized")?;
        let robot = (&r.robot.coords, &r.robot.planar, &r.robot.link_in_base, &r.robot.box_pose);
        let schedules = (&r.collision_schedule, &r.fruit_schedule, &r.scene_schedule);
        agrisim_fmi::serial::write(
            &(&r.world, robot, (&r.harvest, &r.foliage, r.last_h), &r.tracker, schedules, &r.ports, r.published_target),
            out,
        )
    }

    fn load_state(&mut self, bytes: &[u8]) -> Result<(), String> {
        let r = self.run.as_mut().ok_or("the world is not initialized")?;
        let saved: SavedRun = agrisim_fmi::serial::read(bytes)?;
        let (
            world,
            (coords, planar, link_in_base, box_pose),
            (harvest, foliage, last_h),
            tracker,
            schedules,
            ports,
            published_target,
        ) = saved;
        if world.fruit.len() != r.world.fruit.len() || link_in_base.len() != r.robot.link_in_base.len() {
            return Err("the saved world is of another scene or robot".into());
        }
        r.world.adopt(world);
        (r.robot.coords, r.robot.planar, r.robot.link_in_base, r.robot.box_pose) =
            (coords, planar, link_in_base, box_pose);
        (r.harvest, r.tracker, r.ports, r.published_target) = (harvest, tracker, ports, published_target);
        (r.foliage, r.last_h) = (foliage, last_h);
        (r.collision_schedule, r.fruit_schedule, r.scene_schedule) = schedules;
        Ok(())
    }

    fn do_step(&mut self, io: &mut Store, t: f64, h: f64, _log: &mut dyn Log) -> Result<(), String> {
        if !(h.is_finite() && h > 0.0) {
            return Err(format!("communication step {h} s must be positive and finite"));
        }
        let run = self.run.as_mut().ok_or("do_step before initialization")?;
        run.advance(io, h)?;
        run.report(io, t + h);
        Ok(())
    }
}
