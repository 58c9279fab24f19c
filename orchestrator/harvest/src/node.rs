//! The harvest node: the dual-arm harvest of one tomato as a state machine, speaking only
//! ROS 2 messages (and the lift's scalar set-point), like a MoveIt-based task node would.
//!
//! In: `/target_fruit` (PoseStamped, map: the ground-truth target as in the paper),
//! `/localization/pose` (map -> base_link from the localizer: the TF the target goes
//! through into the planning frame), `/planning_scene`, `/{left,right}_arm/joint_states`,
//! `/{left,right}_arm/trajectory_status`, `/{left,right}_gripper/state`, `/lift/position`.
//! Out: `/cmd_vel`, `/lift/setpoint`, `/harvest/target_id`, `/{side}_arm/joint_trajectory`,
//! `/{side}_gripper/command`, `/harvest/status` (every stage entered, and the outcome),
//! `/harvest/plans` (every motion plan asked for and its result).
//!
//! The node is told which fruit to harvest (its index in the world's fruit list, as the paper
//! hands the target over); everything else (where the fruit is, on which side of the robot)
//! it learns from its messages. Whoever runs it judges it by those messages alone.
//!
//! The arm on the row's side grasps, hands the fruit over in front of the robot, and the
//! other arm places it in the box at the rear. Planning happens inside one exchange step
//! but is charged in simulated time: the node prices the work each plan did (configuration
//! checks, IK iterations, exact checks, time parameterizations) with a calibrated
//! [`CostModel`], reports it as `planning_time` on `/harvest/plans`, and stamps the
//! trajectory to start only after the step's plans so far would have been computed. The node
//! never reads a clock, so results stay deterministic.

use super::geometry::{self as geo, TcpGoal};
use super::motion::{Arm, Motion, Planned};
use super::sight::{self, Region, Seen};
use super::stage::{Failure, Stage};
use agrisim_bus::Bus;
use agrisim_bus::Node;
use agrisim_error::Result;
use agrisim_manip::{CostModel, Work};
use agrisim_math::Pose2;
use agrisim_msgs::agrisim::{GripperState, HarvestStatus, PlanResult, PlanningScene, TrajectoryStatus};
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::control_msgs::GripperCommand;
use agrisim_msgs::geometry_msgs::{PoseStamped, Twist};
use agrisim_msgs::sensor_msgs::JointState;
use agrisim_msgs::std_msgs::Header;
use agrisim_msgs::vision_msgs::Detection3DArray;

mod stages;

pub mod topics {
    pub const TARGET: &str = "/target_fruit";
    pub const TARGET_ID: &str = "/harvest/target_id";
    pub const POSE: &str = "/localization/pose";
    pub const SCENE: &str = "/planning_scene";
    pub const CMD_VEL: &str = "/cmd_vel";
    pub const LIFT_SETPOINT: &str = "/lift/setpoint";
    pub const LIFT_POSITION: &str = "/lift/position";
    pub const STATUS: &str = "/harvest/status";
    /// agrisim_msgs/PlanResult, one per motion plan.
    pub const PLANS: &str = "/harvest/plans";
}

/// Per-stage limit of simulated time [s] (a stuck stage is a timeout, not a hang).
const STAGE_TIMEOUT: f64 = 25.0;
/// How far an arm backs off along its approach axis when it cannot plan home from where it
/// is (a row harvest's recovery) [m].
const RECOVERY_BACKOFF: f64 = 0.12;

/// What the node is asked to harvest.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Task {
    /// Fruit `index` of the world's fruit list: its pose from `/target_fruit` and the
    /// collision scene from `/planning_scene`, both the world's ground truth (as the paper
    /// hands the target over). For isolating manipulation from perception.
    Fruit(usize),
    /// A ripe fruit the node finds itself in this box of the map frame, by sight: the
    /// perception node's fruit map and the mapping node's sensed scene ([`crate::sight`]).
    Region(Region),
}

/// What the node knows of one arm, from its messages.
#[derive(Debug, Clone, Default)]
struct ArmView {
    q: Option<[f64; 7]>,
    /// Measured joint torques (joint_states effort).
    effort: Option<[f64; 7]>,
    status: TrajectoryStatus,
    gripper: Option<GripperState>,
    seen: [u64; 3],
    /// Accepted-trajectory count that means "the last one I sent", and when it should end.
    pending: Option<(u64, i64, [f64; 7])>,
    /// The last trajectory's final point: where the arm's controller holds it. Plans start
    /// here, not at the measured joints (which lag by the tracking error, and the arm
    /// refuses a first point away from its commanded position).
    commanded: Option<[f64; 7]>,
    /// The opening last commanded to the gripper: its state reads true of that command
    /// only once it no longer moves.
    gripper_commanded: Option<f64>,
}

pub struct HarvestNode {
    task: Task,
    fruit_index: usize,
    side: f64,
    motion: Motion,
    pub(crate) stage: Stage,
    stage_start_ns: i64,
    step_in_stage: u64,
    arms: [ArmView; 2],
    target_map: Option<[f64; 3]>,
    target_stamp_ns: i64,
    /// Target messages stamped at or before this are of an earlier fruit.
    target_after_ns: i64,
    target_seen: u64,
    pose: Option<Pose2>,
    pose_seen: u64,
    scene: Option<PlanningScene>,
    scene_seen: u64,
    scene_at_ns: i64,
    lift: f64,
    lift_target: f64,
    base_goal: [f64; 3],
    in_place_ticks: u32,
    /// The base positioning controller (it keeps its crab/drive mode between exchanges).
    base_ctl: super::base::BaseController,
    /// The current stage has sent its plan.
    planned: bool,
    /// By sight: the target was chosen again while the base positioned or the pre-grasp was
    /// being planned (its track was dropped): aim anew.
    reaim: bool,
    /// Sub-step of multi-motion stages.
    phase: u8,
    /// Grasp attempts after the first, the hand's axes (across the pads, approach) at the
    /// first miss, and where the current attempt aimed.
    attempts: u32,
    regrasp_axes: [[f64; 3]; 2],
    grasp_point: [f64; 3],
    /// The giver and its joints where its approach to the fruit began (the pre-grasp): the
    /// way back out of the plant when no straight line is free (retreat, recovery).
    approach_from: Option<(Arm, [f64; 7])>,
    /// The approach the pre-grasp plan chose (position: the target as first seen).
    grasp: TcpGoal,
    /// Joint torques of the giver right after the grasp (the fruit still hanging unloaded):
    /// what the detach check compares with.
    detach_baseline: Option<[f64; 7]>,
    /// The giver's joints at the grasp (where a roll that did not detach goes back to).
    grasp_q: [f64; 7],
    /// How the fruit came off: "bend" (the wrist roll) or "pull" (the retreat).
    pub detach_motion: &'static str,
    handover_attempts: u32,
    release_ns: i64,
    target_name: String,
    /// Motions planned so far (reported in the status).
    plans: u32,
    /// Fruit this node has put in the box (a row harvest's earlier fruit included).
    boxed: u32,
    /// The recovery is putting a fruit an arm still held (a failed handover of the last
    /// pick) into the box: its release goes back to the recovery instead of ending the task.
    rescuing: bool,
    /// That rescue failed (its plan could not be made): the recovery lets the fruit go.
    rescue_failed: bool,
    /// Recovery: both grippers were open when it began (see `open_grippers`).
    grippers_were_open: bool,
    /// Prices planning work in simulated seconds.
    cost: CostModel,
    /// Planning work counted up to the last plan reported.
    work_mark: Work,
    /// Simulated planning time of this exchange step so far [s]: a trajectory planned now
    /// starts this long after the step.
    step_thinking: f64,
    /// By sight: the fruit map as last published, the chosen track and its radius, the scan
    /// stop and when its dwell began, the aisle line the scan stands on, and the allowed
    /// sphere last sent to the mapper.
    fruit_map: Vec<Seen>,
    fruit_map_seen: u64,
    track: Option<String>,
    target_r: f64,
    scan: usize,
    dwell_from: Option<i64>,
    aisle_y: f64,
    allowed_sent: Option<([f64; 3], f64)>,
    /// By sight: where earlier tasks of a row aimed (picked there, or failed on), so the
    /// next task does not choose the same fruit again ([`sight::choose`]).
    tried: Vec<[f64; 3]>,
    /// By sight: fruit of this task declined for want of a grasp ([`sight::MAX_DECLINED`]).
    declined: usize,
    /// By sight: whether the task first looks in the fruit map it already has and takes an
    /// untried ripe fruit found there without scanning (a row's later tasks: the cameras
    /// kept looking through the last pick). The first task of a run has an empty map.
    look_first: bool,
    /// By sight: how far inside (or, negative, outside) the region's faces a fruit's
    /// estimate must lie to be chosen ([`sight::TASK_MARGIN`], a row's [`sight::ROW_MARGIN`]).
    region_margin: [f64; 3],
    /// Why the task failed, once it has.
    pub(crate) failure: Option<Failure>,
}

impl HarvestNode {
    /// Harvests fruit `fruit_index` (the world's fruit list); `seed` drives the planners'
    /// sampling. The side of the robot the fruit is on is learned from the target's pose.
    pub fn new(fruit_index: usize, seed: u64) -> HarvestNode {
        HarvestNode::with_task(Task::Fruit(fruit_index), seed)
    }

    /// Harvests a ripe fruit it finds in `region` (map frame) by sight.
    pub fn by_sight(region: Region, seed: u64) -> HarvestNode {
        HarvestNode::with_task(Task::Region(region), seed)
    }

    pub fn with_task(task: Task, seed: u64) -> HarvestNode {
        let side = 1.0;
        let fruit_index = match task {
            Task::Fruit(i) => i,
            Task::Region(_) => 0,
        };
        HarvestNode {
            task,
            fruit_index,
            side,
            motion: Motion::new(seed),
            stage: Stage::SelectTarget,
            stage_start_ns: 0,
            step_in_stage: 0,
            arms: [ArmView::default(), ArmView::default()],
            target_map: None,
            target_stamp_ns: i64::MIN,
            target_after_ns: i64::MIN,
            target_seen: 0,
            pose: None,
            pose_seen: 0,
            scene: None,
            scene_seen: 0,
            scene_at_ns: i64::MIN,
            lift: 0.0,
            lift_target: 0.0,
            base_goal: [0.0; 3],
            in_place_ticks: 0,
            base_ctl: super::base::BaseController::default(),
            planned: false,
            reaim: false,
            phase: 0,
            attempts: 0,
            regrasp_axes: [[0.0; 3]; 2],
            grasp_point: [0.0; 3],
            approach_from: None,
            grasp: geo::grasp([0.0; 3], side),
            detach_baseline: None,
            grasp_q: [0.0; 7],
            detach_motion: "",
            handover_attempts: 0,
            release_ns: 0,
            target_name: String::new(),
            plans: 0,
            boxed: 0,
            rescuing: false,
            rescue_failed: false,
            grippers_were_open: false,
            cost: CostModel::CALIBRATED,
            work_mark: Work::default(),
            step_thinking: 0.0,
            fruit_map: vec![],
            fruit_map_seen: 0,
            track: None,
            target_r: 0.0,
            scan: 0,
            dwell_from: None,
            aisle_y: 0.0,
            allowed_sent: None,
            tried: vec![],
            declined: 0,
            look_first: false,
            region_margin: sight::TASK_MARGIN,
            failure: None,
        }
    }

    /// The region of a harvest by sight.
    fn region(&self) -> Option<Region> {
        match self.task {
            Task::Region(r) => Some(r),
            Task::Fruit(_) => None,
        }
    }

    /// `target_id` of the status: the world's fruit index, -1 for a fruit found by sight.
    fn target_id(&self) -> i32 {
        match self.task {
            Task::Fruit(i) => i as i32,
            Task::Region(_) => -1,
        }
    }

    fn scene_topic(&self) -> &'static str {
        match self.task {
            Task::Fruit(_) => topics::SCENE,
            Task::Region(_) => sight::topics::SENSED_SCENE,
        }
    }

    /// Charges planning with `cost` instead of [`CostModel::CALIBRATED`] (e.g. a slower
    /// computer, or [`CostModel::FREE`]).
    pub fn with_cost(mut self, cost: CostModel) -> HarvestNode {
        self.cost = cost;
        self
    }

    /// By sight: chooses fruit with `margin` at the region's faces ([`sight::choose`]).
    pub fn with_region_margin(mut self, margin: [f64; 3]) -> HarvestNode {
        self.region_margin = margin;
        self
    }

    pub fn stage(&self) -> Stage {
        self.stage
    }

    /// Why the task failed (`None` while it runs or after a success).
    pub fn failure(&self) -> Option<Failure> {
        self.failure
    }

    /// Goes on to fruit `fruit_index` (a row harvest handed its fruit): see [`Self::next_task`].
    pub fn next_target(&mut self, fruit_index: usize, t_ns: i64, bus: &mut Bus) {
        self.next_task(Task::Fruit(fruit_index), t_ns, bus)
    }

    /// Goes on to `task` (a row harvest): what the node knows of the robot and, by sight, of
    /// the crop (the fruit map, the places already tried), its planner's random stream and
    /// its work count carry over; the task starts afresh with [`Stage::Recover`] (let go,
    /// arms home), then selects the new target. Target messages sent before `t_ns` are of
    /// the old fruit.
    pub fn next_task(&mut self, task: Task, t_ns: i64, bus: &mut Bus) {
        let mut fresh = HarvestNode::with_task(task, 0).with_cost(self.cost).with_region_margin(self.region_margin);
        std::mem::swap(&mut fresh.motion, &mut self.motion);
        fresh.motion.set_held(Arm::Left, None);
        fresh.motion.set_held(Arm::Right, None);
        fresh.motion.ignore_target(false);
        // The old target's truss is no obstacle for the recovery and the next choice.
        fresh.motion.guard_trusses(false);
        fresh.arms = std::mem::take(&mut self.arms);
        fresh.arms.iter_mut().for_each(|a| a.pending = None);
        (fresh.pose, fresh.pose_seen) = (self.pose, self.pose_seen);
        (fresh.scene, fresh.scene_seen, fresh.scene_at_ns) = (self.scene.take(), self.scene_seen, self.scene_at_ns);
        (fresh.lift, fresh.lift_target, fresh.target_seen) = (self.lift, self.lift, self.target_seen);
        fresh.target_after_ns = t_ns;
        (fresh.work_mark, fresh.boxed) = (self.work_mark, self.boxed);
        fresh.approach_from = self.approach_from;
        (fresh.fruit_map, fresh.fruit_map_seen) = (std::mem::take(&mut self.fruit_map), self.fruit_map_seen);
        fresh.tried = std::mem::take(&mut self.tried);
        if let (Task::Region(_), Some(aim)) = (self.task, self.target_map) {
            fresh.tried.push(aim);
        }
        fresh.look_first = matches!(task, Task::Region(_));
        // The old target is no longer to be left out of the sensed scene.
        if self.allowed_sent.is_some() {
            bus.publish(sight::topics::ALLOWED, t_ns, &sight::allowed(Time::from_nanos(t_ns), None));
        }
        let why = match task {
            Task::Fruit(i) => {
                fresh.target_name = format!("fruit[{i}]");
                // The world answers with the new fruit's pose from the next exchange on.
                bus.set_scalar(topics::TARGET_ID, i as f64);
                format!("next: fruit {i} of the world's list")
            }
            Task::Region(r) => {
                // Named, so the first step does not take the node for a new one and skip
                // the recovery (arms home, grippers open) for SelectTarget: the arm that
                // placed the last fruit stayed over the box, and the next handover could
                // not be planned from there.
                fresh.target_name = "by sight".into();
                format!("next: a ripe fruit in x {:.2}..{:.2}, y {:.2}..{:.2}", r.x[0], r.x[1], r.y[0], r.y[1])
            }
        };
        *self = fresh;
        self.enter(Stage::Recover, t_ns, bus, &why);
    }

    fn giver(&self) -> Arm {
        if self.side > 0.0 {
            Arm::Left
        } else {
            Arm::Right
        }
    }

    fn taker(&self) -> Arm {
        self.giver().other()
    }

    /// How far the TCP of the hand that takes the fruit to the box is past the giver's TCP at
    /// the handover ([`geo::HANDOVER_DEPTHS`], by attempt): the fruit's centre sits this
    /// minus GRASP_DEPTH short of that TCP. A fruit carried to the box by the arm that
    /// picked it (a rescue, no handover tried) sits as at a first attempt.
    fn handover_offset(&self) -> f64 {
        geo::HANDOVER_DEPTHS[self.handover_attempts as usize]
    }

    fn view(&self, arm: Arm) -> &ArmView {
        &self.arms[arm.index()]
    }

    fn q(&self, arm: Arm) -> [f64; 7] {
        let v = self.view(arm);
        v.commanded.or(v.q).unwrap_or(super::motion::HOME)
    }

    fn read(&mut self, bus: &mut Bus) -> Result<()> {
        if self.region().is_none() {
            if let Some(p) = bus.take_new::<PoseStamped>(topics::TARGET, &mut self.target_seen)? {
                if p.header.stamp.to_nanos() > self.target_after_ns {
                    self.target_map = Some([p.pose.position.x, p.pose.position.y, p.pose.position.z]);
                    self.target_stamp_ns = p.header.stamp.to_nanos();
                }
            }
        } else if let Some(m) = bus.take_new::<Detection3DArray>(sight::topics::FRUIT_MAP, &mut self.fruit_map_seen)? {
            self.fruit_map = sight::fruit_of(&m, "map");
            // The chosen fruit's estimate improves as the base comes closer: follow it until
            // the pre-grasp is planned.
            let following = self.stage == Stage::PositionBase || (self.stage == Stage::PreGrasp && !self.planned);
            if let (Some(id), Some(at), true) = (&self.track, self.target_map, following) {
                match sight::follow(&self.fruit_map, id, at, self.target_r).cloned() {
                    Some(f) => self.target_seen(&f),
                    // The track is gone and none took its place: the perception node dropped
                    // it (frames saw through where it was), so its estimate is stale. Choose
                    // again from the map as it stands, before any arm has moved toward it.
                    None => {
                        let again = self.region().and_then(|region| {
                            sight::choose(&self.fruit_map, &region, self.region_margin, self.aisle_y, &self.tried)
                        });
                        if let Some(f) = again {
                            self.target_seen(&f);
                            self.reaim = true;
                        }
                    }
                }
            }
        }
        if let Some(p) = bus.take_new::<PoseStamped>(topics::POSE, &mut self.pose_seen)? {
            self.pose = Some(Pose2::from(&p.pose));
        }
        let mut seen = self.scene_seen;
        if let Some(s) = bus.take_new::<PlanningScene>(self.scene_topic(), &mut seen)? {
            self.scene_at_ns = s.header.stamp.to_nanos();
            self.scene = Some(s);
        }
        self.scene_seen = seen;
        if let Some(x) = bus.scalar(topics::LIFT_POSITION) {
            self.lift = x;
        }
        for arm in [Arm::Left, Arm::Right] {
            let names = arm.joint_names();
            let v = &mut self.arms[arm.index()];
            let mut seen = v.seen;
            if let Some(js) = bus.take_new::<JointState>(&arm.topic("joint_states"), &mut seen[0])? {
                let mut q = [0.0; 7];
                let mut tau = [0.0; 7];
                let (mut found, mut efforts) = (0, 0);
                for (i, n) in names.iter().enumerate() {
                    if let Some(k) = js.name.iter().position(|m| m == n) {
                        if let Some(&x) = js.position.get(k) {
                            q[i] = x;
                            found += 1;
                        }
                        if let Some(&e) = js.effort.get(k) {
                            tau[i] = e;
                            efforts += 1;
                        }
                    }
                }
                if found == 7 {
                    v.q = Some(q);
                }
                if efforts == 7 {
                    v.effort = Some(tau);
                }
            }
            if let Some(st) = bus.take_new::<TrajectoryStatus>(&arm.topic("trajectory_status"), &mut seen[1])? {
                v.status = st;
            }
            if let Some(g) = bus.take_new::<GripperState>(&arm.gripper_topic("state"), &mut seen[2])? {
                v.gripper = Some(g);
            }
            v.seen = seen;
        }
        Ok(())
    }

    fn enter(&mut self, stage: Stage, t_ns: i64, bus: &mut Bus, detail: &str) {
        // The fruit a wrist roll pushed aside stay so while the hand backs out of the plant.
        if !matches!(stage, Stage::Detach | Stage::Retreat) {
            self.motion.end_roll();
        }
        self.stage = stage;
        self.stage_start_ns = t_ns;
        self.step_in_stage = 0;
        self.planned = false;
        self.phase = 0;
        self.publish_status(t_ns, bus, "running", "", detail);
    }

    fn publish_status(&self, t_ns: i64, bus: &mut Bus, outcome: &str, category: &str, detail: &str) {
        let msg = HarvestStatus {
            header: Header { stamp: Time::from_nanos(t_ns), frame_id: "map".into() },
            stage: self.stage.name().into(),
            target_id: self.target_id(),
            target_name: self.target_name.clone(),
            outcome: outcome.into(),
            failure_category: category.into(),
            detail: detail.into(),
            plans: self.plans,
        };
        bus.publish(topics::STATUS, t_ns, &msg);
    }

    pub(crate) fn fail(&mut self, f: Failure, t_ns: i64, bus: &mut Bus, detail: String) {
        if self.rescuing {
            // Carrying the last pick's fruit into the box failed: let it go where the arm is
            // (as before the rescue existed) and go on with this task's recovery. Failing the
            // task would fail a fruit not tried yet, and the next task would try the same
            // rescue from the same place (a whole row segment lost that way).
            self.rescuing = false;
            self.rescue_failed = true;
            self.motion.set_held(Arm::Left, None);
            self.motion.set_held(Arm::Right, None);
            return self.enter(
                Stage::Recover,
                t_ns,
                bus,
                &format!("the held fruit cannot go into the box, let go: {detail}"),
            );
        }
        self.failure = Some(f);
        self.publish_status(t_ns, bus, "failure", f.name(), &detail);
        self.motion.end_roll();
        self.stage = Stage::Failed;
        self.stop_base(t_ns, bus);
    }

    fn succeed(&mut self, t_ns: i64, bus: &mut Bus, detail: &str) {
        self.stage = Stage::Done;
        self.boxed += 1;
        self.publish_status(t_ns, bus, "success", "", detail);
    }

    fn stop_base(&self, t_ns: i64, bus: &mut Bus) {
        bus.publish(topics::CMD_VEL, t_ns, &Twist::default());
    }

    /// Target in base_link through the localized pose (map -> base_link).
    fn target_base(&self) -> Option<[f64; 3]> {
        let (t, p) = (self.target_map?, self.pose?);
        let (dx, dy) = (t[0] - p.x, t[1] - p.y);
        let (s, c) = p.yaw.sin_cos();
        Some([c * dx + s * dy, -s * dx + c * dy, t[2]])
    }

    /// Reports one plan on /harvest/plans; `optional`: its failure has a fallback (it does
    /// not fail the harvest).
    fn record<T>(
        &mut self,
        arm: Arm,
        kind: &str,
        r: &std::result::Result<T, String>,
        optional: bool,
        t_ns: i64,
        bus: &mut Bus,
    ) {
        self.plans += 1;
        let work = self.motion.work();
        let planning_time = self.cost.seconds(&(work - self.work_mark));
        self.work_mark = work;
        self.step_thinking += planning_time;
        let msg = PlanResult {
            header: Header { stamp: Time::from_nanos(t_ns), frame_id: "map".into() },
            stage: self.stage.name().into(),
            arm: arm.name().into(),
            kind: kind.into(),
            ok: r.is_ok(),
            optional,
            detail: r.as_ref().err().cloned().unwrap_or_default(),
            planning_time,
        };
        bus.publish(topics::PLANS, t_ns, &msg);
    }

    /// Plans one motion of `arm` with `plan` (given the motion planner, lift, start and the
    /// other arm's joints), reports it, and sends it; a planning failure ends the
    /// harvest. Returns the index of the goal reached (for planners with several).
    fn plan_and_send(
        &mut self,
        arm: Arm,
        kind: &'static str,
        t_ns: i64,
        bus: &mut Bus,
        plan: impl FnOnce(&mut Motion, f64, [f64; 7], [f64; 7]) -> std::result::Result<(usize, Planned), String>,
    ) -> Option<usize> {
        let (start, other) = (self.q(arm), self.q(arm.other()));
        let r = plan(&mut self.motion, self.lift, start, other);
        let chosen = r.as_ref().ok().map(|(i, _)| *i);
        let r = r.map(|(_, p)| p);
        self.record(arm, kind, &r, false, t_ns, bus);
        match r {
            Ok(p) => {
                self.send(arm, p, t_ns, bus);
                chosen
            }
            Err(e) => {
                self.fail(Failure::Planning, t_ns, bus, format!("{} arm, {}: {e}", arm.name(), self.stage.name()));
                None
            }
        }
    }

    /// A free (RRT-Connect) or straight-line motion to `goal`.
    fn move_arm(&mut self, arm: Arm, goal: &TcpGoal, linear: bool, t_ns: i64, bus: &mut Bus) -> bool {
        let kind = if linear { "linear" } else { "free" };
        self.plan_and_send(arm, kind, t_ns, bus, |m, lift, start, other| {
            if linear {
                m.plan_linear(arm, lift, start, goal, other)
            } else {
                m.plan_free(arm, lift, start, goal, other)
            }
            .map(|p| (0, p))
        })
        .is_some()
    }

    /// Plans to the stand-off (pre-grasp) of the first reachable grasp of `grasps`; returns
    /// its index. By sight, a fruit
    /// with no collision-free pre-grasp is declined while another ripe fruit of the region
    /// is in the fruit map (at most [`sight::MAX_DECLINED`] per task): nothing has moved
    /// toward it yet, and a harvester chooses the fruit it can reach. The failed plan is
    /// reported as optional (it had a fallback); the judge's report counts them.
    fn move_pregrasp(&mut self, arm: Arm, grasps: &[TcpGoal], t_ns: i64, bus: &mut Bus) -> Option<usize> {
        let (start, other) = (self.q(arm), self.q(arm.other()));
        // Clear of the target's truss where a grasp allows it (a pressed truss swings the
        // target away); failing that, pressing it aside.
        let r = self.motion.plan_pregrasp_guarded(arm, self.lift, start, grasps, geo::PRE_GRASP, other);
        let next = if r.is_err() { self.next_choice() } else { None };
        let chosen = r.as_ref().ok().map(|(i, _)| *i);
        let r = r.map(|(_, p)| p);
        self.record(arm, "pregrasp", &r, next.is_some(), t_ns, bus);
        match (r, next) {
            (Ok(p), _) => {
                self.send(arm, p, t_ns, bus);
                chosen
            }
            (Err(e), Some(f)) => {
                let was = self.track.clone().unwrap_or_default();
                self.tried.extend(self.target_map);
                self.declined += 1;
                self.target_seen(&f);
                let detail = format!("declined track {was}: {} arm, {}: {e}", arm.name(), self.stage.name());
                self.publish_status(t_ns, bus, "running", "", &detail);
                self.aim(t_ns, bus);
                None
            }
            (Err(e), None) => {
                self.fail(Failure::Planning, t_ns, bus, format!("{} arm, {}: {e}", arm.name(), self.stage.name()));
                None
            }
        }
    }

    /// By sight: `f` of the fruit map is the target (its estimate, radius and track).
    fn target_seen(&mut self, f: &Seen) {
        (self.target_map, self.target_r, self.track) = (Some(f.center), f.radius, Some(f.id.clone()));
    }

    /// By sight: the fruit to take if the current one is declined (None when it may not be,
    /// or no other is left).
    fn next_choice(&self) -> Option<Seen> {
        let region = self.region()?;
        if self.declined >= sight::MAX_DECLINED {
            return None;
        }
        let mut tried = self.tried.clone();
        tried.extend(self.target_map);
        sight::choose(&self.fruit_map, &region, self.region_margin, self.aisle_y, &tried)
    }

    /// Plans to the first reachable goal of `goals`.
    fn move_any(&mut self, arm: Arm, goals: &[TcpGoal], t_ns: i64, bus: &mut Bus) -> bool {
        self.plan_and_send(arm, "free", t_ns, bus, |m, lift, start, other| {
            m.plan_free_any(arm, lift, start, goals, other)
        })
        .is_some()
    }

    fn move_home(&mut self, arm: Arm, t_ns: i64, bus: &mut Bus) -> bool {
        self.plan_and_send(arm, "home", t_ns, bus, |m, lift, start, other| {
            m.plan_home(arm, lift, start, other).map(|p| (0, p))
        })
        .is_some()
    }

    /// Sends a planned trajectory, stamped to start once this step's planning is done.
    fn send(&mut self, arm: Arm, p: Planned, t_ns: i64, bus: &mut Bus) {
        let mut msg = p.msg;
        let start_ns = t_ns + (self.step_thinking * 1e9).ceil() as i64;
        msg.header.stamp = Time::from_nanos(start_ns);
        bus.publish(&arm.topic("joint_trajectory"), t_ns, &msg);
        let v = &mut self.arms[arm.index()];
        let expect = v.status.trajectory_count + 1;
        v.pending = Some((expect, start_ns + (p.duration * 1e9) as i64, p.goal_q));
        v.commanded = Some(p.goal_q);
    }

    fn gripper(&mut self, arm: Arm, width: f64, effort: f64, t_ns: i64, bus: &mut Bus) {
        bus.publish(&arm.gripper_topic("command"), t_ns, &GripperCommand { position: width, max_effort: effort });
        self.arms[arm.index()].gripper_commanded = Some(width);
    }

    /// Whether the arm's gripper was told to open and reads open, holding nothing.
    pub(super) fn gripper_open(&self, arm: Arm) -> bool {
        let v = self.view(arm);
        v.gripper_commanded == Some(geo::OPEN_WIDTH)
            && v.gripper.as_ref().is_some_and(|g| !g.stalled && g.position > geo::OPEN_WIDTH - 0.005)
    }

    /// Whether the arm finished its last trajectory. A rejected trajectory is a planning
    /// failure (the arm's validator found something the planner's checks missed).
    fn arm_done(&mut self, arm: Arm, t_ns: i64, bus: &mut Bus) -> Option<bool> {
        let v = &self.arms[arm.index()];
        let Some((expect, t_end, goal)) = v.pending else { return Some(true) };
        if v.status.rejected_count > 0
            && v.status.trajectory_count < expect
            && v.status.state == TrajectoryStatus::REJECTED
        {
            let reason = v.status.reason.clone();
            self.fail(Failure::Planning, t_ns, bus, format!("{} arm rejected the trajectory: {reason}", arm.name()));
            return None;
        }
        let accepted_done = v.status.trajectory_count >= expect && v.status.state == TrajectoryStatus::SUCCEEDED;
        let settled =
            t_ns >= t_end + 200_000_000 && v.q.is_some_and(|q| q.iter().zip(goal).all(|(a, b)| (a - b).abs() < 0.01));
        if accepted_done || settled {
            self.arms[arm.index()].pending = None;
            Some(true)
        } else {
            Some(false)
        }
    }

    /// The sub-step, copied out so match guards may call `&mut self` methods.
    fn phase_now(&self) -> u8 {
        self.phase
    }

    fn holding(&self, arm: Arm) -> bool {
        self.view(arm).gripper.as_ref().is_some_and(|g| g.stalled && g.position > 0.01)
    }

    fn lift_at(&self, target: f64) -> bool {
        (self.lift - target).abs() < 0.003
    }

    fn fresh_scene(&self, since_ns: i64) -> bool {
        self.scene.is_some() && self.scene_at_ns >= since_ns
    }

    /// The planner's scene: the world's, or by sight the sensed one with the perceived target
    /// in it (the mapper left its voxels out).
    fn update_scene(&mut self) {
        if let (Some(scene), Some(pose)) = (&self.scene, self.pose) {
            match (self.region(), self.target_map) {
                (Some(_), Some(c)) => {
                    self.motion.set_scene(&sight::with_target(scene, c, self.target_r, &self.fruit_map), pose)
                }
                _ => self.motion.set_scene(scene, pose),
            }
        }
    }

    /// By sight: tells the mapper which fruit to leave out of the sensed scene (the target,
    /// from choosing it until it is in the box), when that changes.
    fn publish_allowed(&mut self, t_ns: i64, bus: &mut Bus) {
        if self.region().is_none() {
            return;
        }
        let active = !matches!(self.stage, Stage::Recover | Stage::SelectTarget | Stage::Done | Stage::Failed);
        let want = self.target_map.filter(|_| active).map(|c| (c, self.target_r));
        if want != self.allowed_sent {
            bus.publish(sight::topics::ALLOWED, t_ns, &sight::allowed(Time::from_nanos(t_ns), want));
            self.allowed_sent = want;
        }
    }

    /// Plans `arm` home; from a cramped spot (the plan fails) first straight back along the
    /// hand's approach axis. Both plans are optional: a failure is reported, and only when
    /// neither works does the recovery fail. Returns whether a motion was sent.
    fn go_home(&mut self, arm: Arm, t_ns: i64, bus: &mut Bus) -> bool {
        let (start, other) = (self.q(arm), self.q(arm.other()));
        let r = self.motion.plan_home(arm, self.lift, start, other);
        self.record(arm, "home", &r, true, t_ns, bus);
        if let Ok(p) = r {
            self.send(arm, p, t_ns, bus);
            return true;
        }
        let tcp = self.motion.model(arm).fk(self.lift, &start);
        let column = |k: usize| [tcp.rot[0][k], tcp.rot[1][k], tcp.rot[2][k]];
        let back =
            TcpGoal { position: tcp.trans, approach: column(2), x_axis: Some(column(0)) }.along(-RECOVERY_BACKOFF);
        let r = self.motion.plan_linear(arm, self.lift, start, &back, other);
        self.record(arm, "linear", &r, false, t_ns, bus);
        // Still in the plant (the last retreat failed): the free way back to where its
        // approach began, then home from there.
        let r = match (r, self.approach_from) {
            (Err(e), Some((a, q))) if a == arm => {
                let back = self.motion.plan_joints(arm, self.lift, start, &[q], other);
                self.record(arm, "free", &back, false, t_ns, bus);
                back.map_err(|f| format!("{e}; back to the approach's start: {f}"))
            }
            (r, _) => r,
        };
        match r {
            Ok(p) => {
                self.send(arm, p, t_ns, bus);
                true
            }
            Err(e) => {
                self.fail(Failure::Planning, t_ns, bus, format!("{} arm, recover: no way home ({e})", arm.name()));
                false
            }
        }
    }

    /// One exchange of the state machine: the current stage's step (each stage is one
    /// function in [`stages`]), unless the stage has run out of time.
    ///
    /// ```text
    /// recover -> select_target -> position_base -> pre_grasp -> approach -> grasp -> detach -> retreat
    ///                                                               ^          |
    ///                                                               +- regrasp +  (closed on nothing)
    /// retreat -> handover_pose -> handover -> transfer -> release -> done
    /// any stage -> failed (timeout, planning, grasp, handover, placement)
    /// ```
    fn run_stage(&mut self, t_ns: i64, bus: &mut Bus) {
        let first = self.step_in_stage == 0;
        self.step_in_stage += 1;
        let elapsed = (t_ns - self.stage_start_ns) as f64 * 1e-9;
        if elapsed > STAGE_TIMEOUT && !matches!(self.stage, Stage::Done | Stage::Failed) {
            self.fail(Failure::Timeout, t_ns, bus, format!("stage {} took over {STAGE_TIMEOUT} s", self.stage.name()));
            return;
        }
        if std::mem::take(&mut self.reaim) && matches!(self.stage, Stage::PositionBase | Stage::PreGrasp) {
            return self.aim(t_ns, bus);
        }
        match self.stage {
            Stage::Recover => self.run_recover(t_ns, bus),
            Stage::SelectTarget => self.run_select_target(t_ns, bus),
            Stage::PositionBase => self.run_position_base(first, t_ns, bus),
            Stage::PreGrasp => self.run_pre_grasp(first, t_ns, bus),
            Stage::Approach => self.run_approach(first, t_ns, bus),
            Stage::Grasp => self.run_grasp(first, t_ns, bus),
            Stage::Regrasp => self.run_regrasp(t_ns, bus),
            Stage::Detach => self.run_detach(t_ns, bus),
            Stage::Retreat => self.run_retreat(first, t_ns, bus),
            Stage::HandoverPose => self.run_handover_pose(t_ns, bus),
            Stage::Handover => self.run_handover(t_ns, bus),
            Stage::Transfer => self.run_transfer(t_ns, bus),
            Stage::Release => self.run_release(first, t_ns, bus),
            Stage::Done | Stage::Failed => {}
        }
    }
}

impl Node for HarvestNode {
    fn name(&self) -> &str {
        "harvest"
    }

    fn step(&mut self, t_ns: i64, bus: &mut Bus) -> Result<()> {
        self.read(bus)?;
        // Work outside a reported plan (e.g. the lift's sweep check) is not charged.
        self.work_mark = self.motion.work();
        self.step_thinking = 0.0;
        if self.target_name.is_empty() {
            // First exchange: report the first stage like every later one.
            let detail = match self.task {
                Task::Fruit(i) => {
                    self.target_name = format!("fruit[{i}]");
                    format!("fruit {i} of the world's list")
                }
                Task::Region(r) => {
                    self.target_name = "by sight".into();
                    format!(
                        "a ripe fruit in x {:.2}..{:.2}, y {:.2}..{:.2}, z {:.2}..{:.2} m (map)",
                        r.x[0], r.x[1], r.y[0], r.y[1], r.z[0], r.z[1]
                    )
                }
            };
            self.enter(Stage::SelectTarget, t_ns, bus, &detail);
        }
        self.run_stage(t_ns, bus);
        self.publish_allowed(t_ns, bus);
        Ok(())
    }
}
