//! From a TCP goal to a trajectory_msgs/JointTrajectory the arm FMU accepts.
//!
//! Free motions: IK goal set (collision-free configurations, several IK branches) ->
//! RRT-Connect from the current joints to that set -> shortcutting -> exact parry check
//! (agrisim-manip) -> TOPP-RA on a blended path -> samples at the send period checked
//! against velocity, acceleration and jerk limits (agrisim-trajectory). Short Cartesian moves
//! (approach, retreat, handover): IK seeded at the current joints, jerk-limited ruckig motion,
//! accepted only if the TCP stays within a few millimetres of the straight line and the path
//! passes the collision checks. Every step is deterministic (seeded sampler, iteration
//! budgets); wall time is measured by the caller for statistics only.

use super::geometry::{TcpGoal, NEIGHBOUR_GAP};
use agrisim_manip::cartesian::cartesian_path;
use agrisim_manip::prim::Prim;
use agrisim_manip::{
    exact_check, ArmModel, Checker, Context, Ik, Meter, Obstacle, ObstacleKind, Planner, Rng, Scene, Shape, Side,
    Target, Work, DOF,
};
use agrisim_math::vec3::{cross, normalize};
use agrisim_math::Pose2;
use agrisim_msgs::agrisim::PlanningScene;
use agrisim_msgs::builtin_interfaces::Duration;
use agrisim_msgs::shape_msgs::SolidPrimitive;
use agrisim_msgs::trajectory_msgs::{JointTrajectory, JointTrajectoryPoint};
use agrisim_trajectory::{
    time_state_to_state, time_waypoints, JointState, PathParam, PathShape, Sampled, TimingConfig,
};
use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion, Vector3};

/// Where both arms start and end (the harvest system's `q_init` of both Arm FMUs): Franka's
/// "ready" pose with the upper arm 0.3 rad instead of 0.785 rad back, because on this robot
/// the ready pose's elbow touches the lift rails at low lift heights.
pub const HOME: [f64; DOF] = [0.0, -0.3, 0.0, -2.356, 0.0, 1.571, 0.785];
/// Period of the JointTrajectory points sent to the arms [s].
pub const SEND_DT: f64 = 0.04;
/// A Cartesian move may leave the straight TCP line by this much [m].
const LINE_TOLERANCE: f64 = 0.005;
/// TCP step between the IK waypoints of a Cartesian move [m].
const CARTESIAN_STEP: f64 = 0.01;
/// How far from the grasped fruit's centre the hand reaches as it rolls about its own axis
/// [m]: the Franka Hand is about 0.2 m across the fingers (Franka Emika, FR3 product
/// manual: hand dimensions) and its palm lies about 0.09 m behind the fingertip centre, so its
/// corners sweep a sphere of about sqrt(0.1^2 + 0.09^2) = 0.135 m about the grasp point.
const ROLL_SWEEP: f64 = 0.14;
/// Truss parts (rachis, pedicels) this near the target's centre, beyond its surface, are
/// kept clear while the hand comes in, where a grasp allows it ([`Motion::guard_trusses`])
/// [m]: with compliant trusses, a hand that presses the target's truss swings the target
/// away. About a truss's reach around its fruit.
const TRUSS_GUARD: f64 = 0.08;
/// A truss part this near the target's surface is its own pedicel (it joins the fruit's
/// top): never guarded [m].
const OWN_PEDICEL: f64 = 0.01;
/// Rolls about the approach axis tried for a grasp.
const ROLLS: usize = 12;
/// Distinct IK solutions asked for per free goal, and their minimum joint-space spread [rad].
const GOAL_SET: (usize, f64) = (6, 0.3);
/// IK iterations for a goal set / for one seeded Cartesian goal.
const IK_BUDGET: (usize, usize) = (12_000, 3_000);

/// Which arm (the FMU instance), with its ROS names.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Arm {
    Left,
    Right,
}

impl Arm {
    pub fn index(self) -> usize {
        self as usize
    }
    pub fn other(self) -> Arm {
        match self {
            Arm::Left => Arm::Right,
            Arm::Right => Arm::Left,
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            Arm::Left => "left",
            Arm::Right => "right",
        }
    }
    fn side(self) -> Side {
        match self {
            Arm::Left => Side::Left,
            Arm::Right => Side::Right,
        }
    }
    pub fn joint_names(self) -> [String; DOF] {
        std::array::from_fn(|i| format!("{}_joint{}", self.name(), i + 1))
    }
    /// `/left_arm/<suffix>`.
    pub fn topic(self, suffix: &str) -> String {
        format!("/{}_arm/{suffix}", self.name())
    }
    /// `/left_gripper/<suffix>`.
    pub fn gripper_topic(self, suffix: &str) -> String {
        format!("/{}_gripper/{suffix}", self.name())
    }
}

/// A motion ready to send.
#[derive(Debug, Clone)]
pub struct Planned {
    pub msg: JointTrajectory,
    pub duration: f64,
    pub goal_q: [f64; DOF],
}

impl Planned {
    /// The configuration `t` s after the start (linear between samples; the last after the end).
    pub fn at(&self, t: f64) -> [f64; DOF] {
        let pts = &self.msg.points;
        let time = |k: usize| pts[k].time_from_start.to_nanos() as f64 * 1e-9;
        let q = |k: usize| -> [f64; DOF] { std::array::from_fn(|i| pts[k].positions.get(i).copied().unwrap_or(0.0)) };
        let Some(k) = (0..pts.len()).position(|k| time(k) > t) else {
            return if pts.is_empty() { [0.0; DOF] } else { q(pts.len() - 1) };
        };
        if k == 0 {
            return q(0);
        }
        let (t0, t1) = (time(k - 1), time(k));
        let s = if t1 > t0 { (t - t0) / (t1 - t0) } else { 1.0 };
        agrisim_manip::checker::lerp(&q(k - 1), &q(k), s)
    }
}

/// How far apart in time two trajectories sent together are checked against each other [s]:
/// both arms start them at the same stamp and track within a millimetre, so this covers a
/// step of lag either way and more.
pub const TIMING_SLACK: f64 = 0.1;

pub struct Motion {
    arms: [ArmModel; 2],
    rng: Rng,
    planner: Planner,
    timing: TimingConfig,
    /// The planning scene in base_link; the target fruit's index into it.
    obstacles: Vec<Obstacle>,
    scene: Scene,
    target: Option<usize>,
    target_map: Option<[f64; 3]>,
    ignore_target: bool,
    /// Radius of the fruit each arm holds (it moves with the hand in collision checks).
    held: [Option<f64>; 2],
    /// Indices into `obstacles` of the truss parts (soft, but see [`TRUSS_GUARD`]).
    trusses: Vec<usize>,
    /// Whether truss parts near the target are obstacles ([`Motion::guard_trusses`]), and
    /// how many the scene has.
    guard: bool,
    guarded: usize,
    /// Scene ids of the fruit this node has held (in the box, or dropped: one that fell on
    /// the robot would otherwise block its arm for good): loose, pushed aside, never
    /// planned around.
    loose: Vec<String>,
    /// The grasp point of a wrist roll being planned: fruit within the hand's sweep of it are
    /// pushed aside, not planned around (see [`Motion::plan_roll`]).
    roll_centre: Option<[f64; 3]>,
    /// Safety margin of the sphere checks [m] (the exact check has none).
    padding: f64,
    /// The straight approach (joint path, pre-grasp first) checked by the last pre-grasp plan.
    approach: Option<(Arm, Vec<[f64; DOF]>)>,
    /// Every check, IK iteration and time parameterization of every plan, counted.
    meter: Meter,
}

impl Motion {
    pub fn new(seed: u64) -> Motion {
        Motion {
            arms: [ArmModel::new(Arm::Left.side()), ArmModel::new(Arm::Right.side())],
            rng: Rng::new(seed ^ 0x0048_4152_5645_5354), // "HARVEST"
            planner: Planner::default(),
            timing: TimingConfig::panda(SEND_DT),
            obstacles: vec![],
            trusses: vec![],
            guard: false,
            guarded: 0,
            scene: Scene::new(vec![]),
            target: None,
            target_map: None,
            ignore_target: false,
            held: [None, None],
            loose: vec![],
            roll_centre: None,
            padding: agrisim_manip::checker::DEFAULT_PADDING,
            approach: None,
            meter: Meter::default(),
        }
    }

    /// The planning work done so far (differences give one plan's work).
    pub fn work(&self) -> Work {
        self.meter.work()
    }

    fn ik(&self, arm: Arm, lift: f64) -> Ik<'_> {
        Ik::new(self.model(arm), lift).metered(Some(&self.meter))
    }

    pub fn model(&self, arm: Arm) -> &ArmModel {
        &self.arms[arm.index()]
    }

    /// The target fruit (map frame): its scene object is the one the hand may touch.
    pub fn set_target(&mut self, center_map: [f64; 3]) {
        self.target_map = Some(center_map);
    }

    /// Whether the truss parts near the target (its truss's rachis, its neighbours' pedicels:
    /// [`TRUSS_GUARD`]) are obstacles until the fruit is in the hand. The pre-grasp plans with
    /// them first and falls back to pressing them aside (as leaves) where no grasp keeps clear.
    pub fn guard_trusses(&mut self, guard: bool) {
        if self.guard != guard {
            self.guard = guard;
            self.rebuild();
        }
    }

    /// Truss parts the guard makes obstacles in the current scene (0: guarding changes nothing).
    pub fn guarded_trusses(&self) -> usize {
        self.guarded
    }

    /// Once the fruit is in the hand (or about to be), nothing of it is an obstacle.
    pub fn ignore_target(&mut self, ignore: bool) {
        self.ignore_target = ignore;
        self.rebuild();
    }

    /// The world's planning scene (map frame) seen from the localized base pose. Leaves are
    /// soft (pushed aside, never planned around); the floor is left to the fixed body.
    pub fn set_scene(&mut self, scene: &PlanningScene, base: Pose2) {
        let (s, c) = base.yaw.sin_cos();
        let to_base = |p: [f64; 3]| -> [f64; 3] {
            let (dx, dy) = (p[0] - base.x, p[1] - base.y);
            [c * dx + s * dy, -s * dx + c * dy, p[2]]
        };
        let yaw_inv = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), -base.yaw);
        self.obstacles.clear();
        self.trusses.clear();
        self.target = None;
        let mut best = f64::INFINITY;
        for o in &scene.objects {
            let Some(shape) = shape_of(&o.primitive) else { continue };
            let kind = match o.kind.as_str() {
                // Leaves and trusses bend out of the way (the world counts the contacts).
                "leaf" | "truss" => ObstacleKind::Soft,
                // Sensed space by the target the fingers push aside (harvest by sight).
                crate::sight::PUSHED_KIND => ObstacleKind::Soft,
                "floor" => continue,
                // A fruit in a hand is the hand's (`set_held` models it); the world's copy of
                // it is no obstacle. As Solid, a fruit held from an earlier task (the
                // recovery carrying it to the box) put the hand's start in collision.
                "fruit_held" => ObstacleKind::Soft,
                _ => ObstacleKind::Solid,
            };
            let p = &o.pose.position;
            let q = &o.pose.orientation;
            let rot = yaw_inv * UnitQuaternion::from_quaternion(Quaternion::new(q.w, q.x, q.y, q.z));
            let t = to_base([p.x, p.y, p.z]);
            let pose = Isometry3::from_parts(Translation3::new(t[0], t[1], t[2]), rot);
            if let (Some(tm), Shape::Sphere { .. }) = (self.target_map, shape) {
                let d = ((p.x - tm[0]).powi(2) + (p.y - tm[1]).powi(2) + (p.z - tm[2]).powi(2)).sqrt();
                if d < 0.01 && d < best {
                    best = d;
                    self.target = Some(self.obstacles.len());
                }
            }
            if o.kind == "truss" {
                self.trusses.push(self.obstacles.len());
            }
            self.obstacles.push(Obstacle::new(o.id.clone(), shape, pose, kind));
        }
        self.rebuild();
    }

    fn rebuild(&mut self) {
        let mut objs = self.obstacles.clone();
        self.guarded = 0;
        for o in objs.iter_mut().filter(|o| self.loose.contains(&o.name)) {
            o.kind = ObstacleKind::Soft;
        }
        if let Some(c) = self.roll_centre {
            let c = Vector3::from(c);
            for o in objs.iter_mut() {
                if let Shape::Sphere { radius } = o.shape {
                    if (o.pose.translation.vector - c).norm() < ROLL_SWEEP + radius {
                        o.kind = ObstacleKind::Soft;
                    }
                }
            }
        }
        if let Some(i) = self.target {
            objs[i].kind = if self.ignore_target { ObstacleKind::Soft } else { ObstacleKind::Target };
            // Tomatoes touching the target are pushed aside by the fingers and brushed when
            // it is pulled out (plant contacts in the world), so they are no obstacles.
            let c = objs[i].pose.translation.vector;
            let rt = match objs[i].shape {
                Shape::Sphere { radius } => radius,
                _ => 0.0,
            };
            for (j, o) in objs.iter_mut().enumerate() {
                if let Shape::Sphere { radius } = o.shape {
                    if j != i && (o.pose.translation.vector - c).norm() < rt + radius + NEIGHBOUR_GAP {
                        o.kind = ObstacleKind::Soft;
                    }
                }
            }
            if self.guard && !self.ignore_target {
                for &j in &self.trusses {
                    let gap = Prim::new(objs[j].shape, objs[j].pose).point_distance(&Point3::from(c)) - rt;
                    if gap > OWN_PEDICEL && gap < TRUSS_GUARD {
                        objs[j].kind = ObstacleKind::Solid;
                        self.guarded += 1;
                    }
                }
            }
        }
        self.scene = Scene::new(objs);
    }

    /// The target fruit's radius from the planning scene (None before a scene showed it).
    pub fn target_radius(&self) -> Option<f64> {
        match self.obstacles.get(self.target?)?.shape {
            Shape::Sphere { radius } => Some(radius),
            _ => None,
        }
    }

    /// Sphere-check margin: the default, or a small one for the handover, where the two
    /// hands meet by design and the exact check decides.
    pub fn set_padding(&mut self, padding: f64) {
        self.padding = padding;
    }

    /// `arm` now holds a fruit of `radius` (None: empty hand).
    pub fn set_held(&mut self, arm: Arm, radius: Option<f64>) {
        self.held[arm.index()] = radius;
        if let (Some(_), Some(i)) = (radius, self.target) {
            let id = &self.obstacles[i].name;
            if !self.loose.contains(id) {
                self.loose.push(id.clone());
            }
        }
    }

    fn context<'a>(&'a self, arm: Arm, lift: f64, other_q: [f64; DOF]) -> Context<'a> {
        let o = self.model(arm.other());
        let mut ctx = Context::new(self.model(arm), lift, &self.scene).with_other(o, other_q, o.finger_limits.upper);
        ctx.padding = self.padding;
        ctx.meter = Some(&self.meter);
        if let Some(r) = self.held[arm.index()] {
            ctx = ctx.holding(r);
        }
        if let Some(r) = self.held[arm.other().index()] {
            ctx = ctx.other_holding(r);
        }
        ctx
    }

    /// Whether both arms, frozen at `q` (left, right), stay collision-free while the lift
    /// moves from `from` to `to` (checked every centimetre).
    pub fn lift_sweep_clear(&self, q: [[f64; DOF]; 2], from: f64, to: f64) -> bool {
        let n = ((to - from).abs() / 0.01).ceil().max(1.0) as usize;
        (0..=n).all(|i| {
            let lift = from + (to - from) * i as f64 / n as f64;
            [Arm::Left, Arm::Right]
                .iter()
                .all(|&a| Checker::new(self.context(a, lift, q[a.other().index()])).is_valid(&q[a.index()]))
        })
    }

    /// Whether `arm` may follow `mine` while the other arm follows `theirs`, both sent to
    /// start at the same instant: each configuration of `mine` keeps the arms apart (with
    /// what each holds) from every configuration the other arm passes through within
    /// [`TIMING_SLACK`] of the same time, both sampled every 10 ms (an arm at rest at its
    /// end after it). Each trajectory was checked against the scene and the robot when it
    /// was planned; this adds only what moving both at once adds
    /// ([`Checker::arms_contact`]).
    pub fn trajectories_clear(&self, arm: Arm, lift: f64, mine: &Planned, theirs: &Planned) -> bool {
        const DT: f64 = 0.01;
        let n = (mine.duration.max(theirs.duration) / DT).ceil() as usize + 1;
        let w = (TIMING_SLACK / DT).round() as usize;
        let qs: Vec<[f64; DOF]> = (0..n).map(|i| mine.at(i as f64 * DT)).collect();
        (0..n).all(|j| {
            let checker = Checker::new(self.context(arm, lift, theirs.at(j as f64 * DT)));
            qs[j.saturating_sub(w)..(j + w + 1).min(n)].iter().all(|q| checker.arms_contact(q).is_none())
        })
    }

    /// Free-space motion to a TCP goal through the IK goal set.
    pub fn plan_free(
        &mut self,
        arm: Arm,
        lift: f64,
        start: [f64; DOF],
        goal: &TcpGoal,
        other: [f64; DOF],
    ) -> Result<Planned, String> {
        let target = target_of(goal);
        let goals = {
            let ctx = self.context(arm, lift, other);
            let checker = Checker::new(ctx);
            let ik = self.ik(arm, lift);
            let mut rng = self.rng.clone();
            let g =
                ik.goal_set(&target, &start, &mut rng, GOAL_SET.0, GOAL_SET.1, IK_BUDGET.0, |q| checker.is_valid(q));
            self.rng = rng;
            g
        };
        if goals.is_empty() {
            return Err(format!(
                "no collision-free IK solution for the TCP at ({:.3}, {:.3}, {:.3}) in base_link",
                goal.position[0], goal.position[1], goal.position[2]
            ));
        }
        self.plan_to_configs(arm, lift, start, &goals, other)
    }

    /// Free-space motion to a stand-off `standoff` m before a grasp: the goal set holds
    /// pre-grasp configurations whose grasp configuration (same orientation, reached by the
    /// straight approach) is valid too, over rolls every 30 degrees when the roll is free
    /// (so fingers that would hit a neighbour are never chosen), else the given roll and its
    /// opposite.
    pub fn plan_pregrasp(
        &mut self,
        arm: Arm,
        lift: f64,
        start: [f64; DOF],
        grasp: &TcpGoal,
        standoff: f64,
        other: [f64; DOF],
    ) -> Result<Planned, String> {
        let mut rng = std::mem::replace(&mut self.rng, Rng::new(0));
        let goals = {
            let ctx = self.context(arm, lift, other);
            let checker = Checker::new(ctx);
            let ik = self.ik(arm, lift);
            let z = normalize(grasp.approach);
            let up = if z[2].abs() < 0.9 { [0.0, 0.0, 1.0] } else { [1.0, 0.0, 0.0] };
            let x0 = normalize(cross(cross(z, up), z));
            let y0 = cross(z, x0);
            // Rolls to try: every 30 degrees when free; a given roll and its opposite (the
            // same finger line) otherwise.
            let rolls: Vec<(u32, [f64; 3])> = match grasp.x_axis {
                Some(x) => vec![(0, x), (180, [-x[0], -x[1], -x[2]])],
                None => (0..ROLLS)
                    .map(|k| {
                        let (sa, ca) = (k as f64 * std::f64::consts::TAU / ROLLS as f64).sin_cos();
                        (
                            (k * 360 / ROLLS) as u32,
                            [ca * x0[0] + sa * y0[0], ca * x0[1] + sa * y0[1], ca * x0[2] + sa * y0[2]],
                        )
                    })
                    .collect(),
            };
            let mut goals: Vec<[f64; DOF]> = vec![];
            let mut backout: Vec<String> = vec![];
            let mut approaches: Vec<Vec<[f64; DOF]>> = vec![];
            for &(deg, x) in &rolls {
                let g = TcpGoal { x_axis: Some(x), ..*grasp };
                let at_grasp = ik.goal_set(&target_of(&g), &start, &mut rng, 2, GOAL_SET.1, 2 * IK_BUDGET.1, |q| {
                    checker.is_valid(q)
                });
                for qg in at_grasp {
                    // Back out along the approach: the reverse of the approach move, so the
                    // pre-grasp and grasp configurations are joined by a valid straight line.
                    let back = Vector3::new(-standoff * z[0], -standoff * z[1], -standoff * z[2]);
                    match cartesian_path(&checker, &qg, back, CARTESIAN_STEP, 0.3, 0.02) {
                        Ok(mut path) => {
                            let qp = *path.last().expect("start at least");
                            if goals.iter().all(|o| agrisim_manip::ik::dist(o, &qp) > 1e-3) {
                                goals.push(qp);
                                path.reverse();
                                approaches.push(path);
                            }
                        }
                        Err(e) => backout.push(format!("roll {deg}: {e}")),
                    }
                }
            }
            // Say why when nothing worked: what the grasp configuration touches.
            let why = if goals.is_empty() {
                let mut why = Vec::new();
                for &(deg, x) in &rolls {
                    let g = TcpGoal { x_axis: Some(x), ..*grasp };
                    match ik.solve(&target_of(&g), &start, &mut rng, IK_BUDGET.1) {
                        None => why.push(format!("roll {deg}: no IK")),
                        Some(q) => why.push(format!(
                            "roll {deg}: {}",
                            checker.contact(&q).map(|c| c.describe(&ctx)).unwrap_or_else(|| "free?".into())
                        )),
                    }
                }
                why.extend(backout);
                why.join("; ")
            } else {
                String::new()
            };
            (goals, why, approaches)
        };
        let (goals, why, approaches) = goals;
        self.rng = rng;
        if goals.is_empty() {
            return Err(format!(
                "no collision-free IK solution for a grasp at ({:.3}, {:.3}, {:.3}) in base_link with any roll ({why})",
                grasp.position[0], grasp.position[1], grasp.position[2]
            ));
        }
        // Nearest goals first: the planner tries the direct edge to them in order. The
        // approach from the goal reached is kept for plan_linear.
        let mut order: Vec<usize> = (0..goals.len()).collect();
        order.sort_by(|&a, &b| {
            agrisim_manip::ik::dist(&goals[a], &start).total_cmp(&agrisim_manip::ik::dist(&goals[b], &start))
        });
        let sorted: Vec<[f64; DOF]> = order.iter().map(|&i| goals[i]).collect();
        let planned = self.plan_to_configs(arm, lift, start, &sorted, other)?;
        let reached = order.iter().copied().find(|&i| goals[i] == planned.goal_q);
        self.approach = reached.map(|i| (arm, approaches[i].clone()));
        Ok(planned)
    }

    /// The first of `goals` [`Self::plan_free`] reaches, with its index.
    pub fn plan_free_any(
        &mut self,
        arm: Arm,
        lift: f64,
        start: [f64; DOF],
        goals: &[TcpGoal],
        other: [f64; DOF],
    ) -> Result<(usize, Planned), String> {
        first_ok(goals, "goal", |g| self.plan_free(arm, lift, start, g, other))
    }

    /// [`Self::plan_pregrasp_any`] clear of the target's truss ([`Self::guard_trusses`]) where
    /// a grasp allows it, else pressing the truss aside. The second try starts from the same
    /// random state as the first, so it plans exactly as if the guard had never been tried:
    /// guarding can cost planning time, never a grasp found without it. The guard stays as
    /// the plan found it (on, or off after the fallback) for the approach that follows.
    pub fn plan_pregrasp_guarded(
        &mut self,
        arm: Arm,
        lift: f64,
        start: [f64; DOF],
        grasps: &[TcpGoal],
        standoff: f64,
        other: [f64; DOF],
    ) -> Result<(usize, Planned), String> {
        self.guard_trusses(true);
        let rng = self.rng.clone();
        let r = self.plan_pregrasp_any(arm, lift, start, grasps, standoff, other);
        if r.is_ok() || self.guarded == 0 {
            return r;
        }
        self.rng = rng;
        self.guard_trusses(false);
        self.plan_pregrasp_any(arm, lift, start, grasps, standoff, other)
    }

    /// The first of `grasps` [`Self::plan_pregrasp`] reaches, with its index.
    pub fn plan_pregrasp_any(
        &mut self,
        arm: Arm,
        lift: f64,
        start: [f64; DOF],
        grasps: &[TcpGoal],
        standoff: f64,
        other: [f64; DOF],
    ) -> Result<(usize, Planned), String> {
        first_ok(grasps, "approach", |g| self.plan_pregrasp(arm, lift, start, g, standoff, other))
    }

    /// The first of `goals` [`Self::plan_linear`] reaches, with its index.
    pub fn plan_linear_any(
        &mut self,
        arm: Arm,
        lift: f64,
        start: [f64; DOF],
        goals: &[TcpGoal],
        other: [f64; DOF],
    ) -> Result<(usize, Planned), String> {
        first_ok(goals, "goal", |g| self.plan_linear(arm, lift, start, g, other))
    }

    /// Free-space motion to any of the joint configurations `goals`.
    pub fn plan_joints(
        &mut self,
        arm: Arm,
        lift: f64,
        start: [f64; DOF],
        goals: &[[f64; DOF]],
        other: [f64; DOF],
    ) -> Result<Planned, String> {
        self.plan_to_configs(arm, lift, start, goals, other)
    }

    /// Why `arm` at `q` is no valid configuration (out of limits, or its first contact), or
    /// None when it is valid: for the reports of a plan without a valid goal.
    pub fn invalid_reason(&self, arm: Arm, lift: f64, q: &[f64; DOF], other: [f64; DOF]) -> Option<String> {
        let ctx = self.context(arm, lift, other);
        if !ctx.arm.within_limits(q) {
            return Some("out of the joint limits".into());
        }
        Checker::new(ctx).contact(q).map(|c| c.describe(&ctx))
    }

    /// Joint motion of a wrist roll with the grasped fruit at `centre` (base_link): the fruit
    /// hanging within the hand's sweep of it are pushed aside on their pedicels, as the
    /// fingers push the target's neighbours at the grasp (the world counts the touches), so
    /// they are no obstacles. Without this, a truss neighbour beside the palm blocks every
    /// roll of an arm that grasped from that side. After a planned roll they stay pushed aside
    /// (the hand rests against them) until [`Motion::end_roll`]; a failed plan leaves the
    /// scene as it was.
    pub fn plan_roll(
        &mut self,
        arm: Arm,
        lift: f64,
        start: [f64; DOF],
        goals: &[[f64; DOF]],
        other: [f64; DOF],
        centre: [f64; 3],
    ) -> Result<Planned, String> {
        self.roll_centre = Some(centre);
        self.rebuild();
        let r = self.plan_to_configs(arm, lift, start, goals, other);
        let reason =
            r.as_ref().err().and_then(|_| goals.first()).and_then(|g| self.invalid_reason(arm, lift, g, other));
        if r.is_err() {
            self.end_roll();
        }
        r.map_err(|e| match reason {
            Some(why) => format!("{e}; first roll: {why}"),
            None => e,
        })
    }

    /// The hand has left the fruit a roll pushed aside: they are obstacles again.
    pub fn end_roll(&mut self) {
        if self.roll_centre.take().is_some() {
            self.rebuild();
        }
    }

    /// Free-space motion back to [`HOME`].
    pub fn plan_home(&mut self, arm: Arm, lift: f64, start: [f64; DOF], other: [f64; DOF]) -> Result<Planned, String> {
        self.plan_to_configs(arm, lift, start, &[HOME], other)
    }

    fn plan_to_configs(
        &mut self,
        arm: Arm,
        lift: f64,
        start: [f64; DOF],
        goals: &[[f64; DOF]],
        other: [f64; DOF],
    ) -> Result<Planned, String> {
        let plan = {
            let ctx = self.context(arm, lift, other);
            let mut rng = self.rng.clone();
            let p = self.planner.plan_out_of_contact(&ctx, &start, goals, &mut rng);
            self.rng = rng;
            p.map_err(|e| format!("motion planning: {e}"))?
        };
        let wps: Vec<Vec<f64>> = plan.waypoints.iter().map(|q| q.to_vec()).collect();
        let samples = if wps.len() < 2 || plan.waypoints[0] == plan.waypoints[wps.len() - 1] {
            hold(&start)
        } else {
            self.meter.add_timing();
            time_waypoints(&wps, &self.timing).map_err(|e| format!("time parameterization: {e}"))?
        };
        Ok(self.to_msg(arm, &samples, *plan.waypoints.last().expect("start at least")))
    }

    /// Straight-line TCP move (approach, retreat, handover), orientation kept: joint
    /// waypoints along the line (IK every centimetre, agrisim-manip's Cartesian path), timed
    /// by ruckig as one jerk-limited motion when that stays on the line, else by TOPP-RA on a
    /// spline through the waypoints; then the line, collision and exact checks.
    pub fn plan_linear(
        &mut self,
        arm: Arm,
        lift: f64,
        start: [f64; DOF],
        goal: &TcpGoal,
        other: [f64; DOF],
    ) -> Result<Planned, String> {
        // The approach the pre-grasp plan checked, if this is it: the same joint path.
        if let Some((a, path)) = &self.approach {
            let same_start = path.first().is_some_and(|p| agrisim_manip::ik::dist(p, &start) < 1e-6);
            let end = path.last().map(|q| self.model(arm).fk(lift, q).trans);
            let same_end = end.is_some_and(|e| (0..3).all(|i| (e[i] - goal.position[i]).abs() < 5e-3));
            if *a == arm && same_start && same_end {
                let wps = path.clone();
                return self.time_line(arm, lift, start, wps, goal.position, other);
            }
        }
        let model = &self.arms[arm.index()];
        let from = model.fk(lift, &start).trans;
        let to = goal.position;
        let ctx = self.context(arm, lift, other);
        let checker = Checker::new(ctx);
        let offset = Vector3::new(to[0] - from[0], to[1] - from[1], to[2] - from[2]);
        let wps = match cartesian_path(&checker, &start, offset, CARTESIAN_STEP, 0.3, 0.02) {
            Ok(w) => w,
            Err(e) => {
                // Name what the blocked configuration touches.
                let last = *e.partial.last().unwrap_or(&start);
                let what = self
                    .ik(arm, lift)
                    .solve(
                        &target_of(&TcpGoal { x_axis: Some(current_x(model, lift, &start)), ..*goal }),
                        &last,
                        &mut Rng::new(7),
                        IK_BUDGET.1,
                    )
                    .and_then(|q| checker.contact(&q))
                    .map(|c| format!(" (at the goal: {})", c.describe(&ctx)))
                    .unwrap_or_default();
                return Err(format!("Cartesian move: {e}{what}"));
            }
        };
        self.time_line(arm, lift, start, wps, to, other)
    }

    /// Times joint waypoints that move the TCP along a straight line to `to` (ruckig when
    /// that stays on the line, else TOPP-RA), then the line, collision and exact checks.
    fn time_line(
        &self,
        arm: Arm,
        lift: f64,
        start: [f64; DOF],
        wps: Vec<[f64; DOF]>,
        to: [f64; 3],
        other: [f64; DOF],
    ) -> Result<Planned, String> {
        let model = self.model(arm);
        let from = model.fk(lift, &start).trans;
        let ctx = self.context(arm, lift, other);
        let checker = Checker::new(ctx);
        let end = *wps.last().expect("start at least");
        let on_line = |samples: &Sampled| -> Result<Vec<[f64; DOF]>, String> {
            let path: Vec<[f64; DOF]> = samples.q.iter().map(|v| std::array::from_fn(|i| v[i])).collect();
            let worst = path.iter().map(|q| distance_to_segment(model.fk(lift, q).trans, from, to)).fold(0.0, f64::max);
            if worst > LINE_TOLERANCE {
                return Err(format!("Cartesian move leaves the straight line by {:.1} mm", worst * 1e3));
            }
            Ok(path)
        };
        // Checked in full: on the line, collision-free, exact. The jerk-limited motion first;
        // where it leaves the line or clips a neighbour, a spline through the dense waypoints
        // (or, where that overshoots a limit, the polyline with small corner blends), which
        // follows the checked segments.
        let checked = |samples: Sampled| -> Result<Sampled, String> {
            let path = on_line(&samples)?;
            if let Some(qs) = path.iter().find(|q| !checker.is_valid(q)) {
                let what = checker.contact(qs).map(|c| c.describe(&ctx)).unwrap_or_default();
                return Err(format!("Cartesian move in collision: {what}"));
            }
            exact_check(&ctx, &path, agrisim_manip::exact::EXACT_RESOLUTION)
                .map_err(|c| format!("Cartesian move fails the exact check: {}", c.description))?;
            Ok(samples)
        };
        self.meter.add_timing();
        let jerk_limited =
            time_state_to_state(&JointState::at_rest(start.to_vec()), &JointState::at_rest(end.to_vec()), &self.timing)
                .map_err(|e| format!("jerk-limited motion: {e}"))?;
        let samples = match checked(jerk_limited) {
            Ok(s) => s,
            Err(_) => {
                self.meter.add_timing();
                let wv: Vec<Vec<f64>> = wps.iter().map(|q| q.to_vec()).collect();
                let spline = TimingConfig { shape: PathShape::Spline(PathParam::ChordLength), ..self.timing.clone() };
                let blended = TimingConfig { shape: PathShape::Blended { radius: 0.01 }, ..self.timing.clone() };
                let s = time_waypoints(&wv, &spline)
                    .or_else(|_| time_waypoints(&wv, &blended))
                    .map_err(|e| format!("time parameterization of the Cartesian path: {e}"))?;
                checked(s)?
            }
        };
        Ok(self.to_msg(arm, &samples, end))
    }

    fn to_msg(&self, arm: Arm, s: &Sampled, goal_q: [f64; DOF]) -> Planned {
        let model = self.model(arm);
        let points = (0..s.t.len())
            .map(|k| JointTrajectoryPoint {
                // Samples on a joint limit can be a rounding error beyond it; the arm's
                // validator is strict.
                positions: s.q[k].iter().zip(&model.limits).map(|(q, l)| q.clamp(l.lower, l.upper)).collect(),
                velocities: s.qd[k].clone(),
                accelerations: s.qdd[k].clone(),
                effort: vec![],
                time_from_start: Duration::from_nanos((s.t[k] * 1e9).round() as i64),
            })
            .collect();
        let msg = JointTrajectory { joint_names: arm.joint_names().to_vec(), points, ..Default::default() };
        Planned { msg, duration: s.t.last().copied().unwrap_or(0.0), goal_q }
    }
}

/// The first item `plan` succeeds on, with its index; else every item's error, labelled.
fn first_ok(
    items: &[TcpGoal],
    label: &str,
    mut plan: impl FnMut(&TcpGoal) -> Result<Planned, String>,
) -> Result<(usize, Planned), String> {
    let mut errors = vec![];
    for (i, g) in items.iter().enumerate() {
        match plan(g) {
            Ok(p) => return Ok((i, p)),
            Err(e) => errors.push(format!("{label} {i}: {e}")),
        }
    }
    Err(errors.join("; "))
}

/// A one-point "stay here" trajectory.
fn hold(q: &[f64; DOF]) -> Sampled {
    Sampled { t: vec![0.0], q: vec![q.to_vec()], qd: vec![vec![0.0; DOF]], qdd: vec![vec![0.0; DOF]] }
}

/// The TCP's x axis (the roll) at `q`.
fn current_x(model: &ArmModel, lift: f64, q: &[f64; DOF]) -> [f64; 3] {
    let p = model.fk(lift, q);
    [p.rot[0][0], p.rot[1][0], p.rot[2][0]]
}

fn target_of(goal: &TcpGoal) -> Target {
    let hint = goal.x_axis.unwrap_or_else(|| {
        // Any vector not parallel to the approach; the roll is free anyway.
        if goal.approach[2].abs() < 0.9 {
            [0.0, 0.0, 1.0]
        } else {
            [1.0, 0.0, 0.0]
        }
    });
    let p = goal.pose_with_x(hint);
    Target::from_pose(&p, goal.x_axis.is_none())
}

fn shape_of(p: &SolidPrimitive) -> Option<Shape> {
    let d = &p.dimensions;
    match p.r#type {
        SolidPrimitive::BOX if d.len() >= 3 => Some(Shape::Box { size: [d[0], d[1], d[2]] }),
        SolidPrimitive::SPHERE if !d.is_empty() => Some(Shape::Sphere { radius: d[0] }),
        SolidPrimitive::CYLINDER if d.len() >= 2 => Some(Shape::Cylinder {
            radius: d[SolidPrimitive::CYLINDER_RADIUS],
            length: d[SolidPrimitive::CYLINDER_HEIGHT],
        }),
        _ => None,
    }
}

fn distance_to_segment(p: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let ap = [p[0] - a[0], p[1] - a[1], p[2] - a[2]];
    let l2 = ab.iter().map(|x| x * x).sum::<f64>();
    let t = if l2 > 0.0 { (ab.iter().zip(&ap).map(|(x, y)| x * y).sum::<f64>() / l2).clamp(0.0, 1.0) } else { 0.0 };
    (0..3).map(|i| (ap[i] - t * ab[i]).powi(2)).sum::<f64>().sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Either arm, holding a fruit at the transfer lift, reaches every place pose of the
    /// first round from over the box by the straight way down, the hand clear of the walls
    /// (the planner's body model has the box; the exact check decides).
    #[test]
    fn every_place_pose_is_reached_straight_down() {
        use crate::geometry::{place_goals, DROP_SPOTS, GRASP_DEPTH, LIFT_TRANSFER, PLACE_DESCENT};
        for arm in [Arm::Left, Arm::Right] {
            let mut m = Motion::new(1);
            m.set_held(arm, Some(0.035));
            for (i, g) in place_goals(0.035, GRASP_DEPTH, &[]).iter().take(DROP_SPOTS).enumerate() {
                let p = m.plan_pregrasp(arm, LIFT_TRANSFER, HOME, g, PLACE_DESCENT, HOME);
                let p = p.unwrap_or_else(|e| panic!("{arm:?}, spot {i}: {e}"));
                let down = m.plan_linear(arm, LIFT_TRANSFER, p.goal_q, g, HOME);
                assert!(down.is_ok(), "{arm:?}, spot {i}: {:?}", down.err());
            }
        }
    }

    /// Two trajectories sent together are checked against each other in time: arms that
    /// would meet at the same moment are refused; the same ways, one starting after the
    /// other has left, pass. The configurations are drawn until the arms meet in them but
    /// each way passes the other arm at home.
    #[test]
    fn trajectories_sent_together_are_checked_in_time() {
        let m = Motion::new(1);
        let (l, r) = (m.model(Arm::Left), m.model(Arm::Right));
        let empty = Scene::new(vec![]);
        let lift = 0.3;
        let meet = |ql: &[f64; DOF], qr: &[f64; DOF]| {
            Checker::new(Context::new(l, lift, &empty).with_other(r, *qr, r.finger_limits.upper))
                .arms_contact(ql)
                .is_some()
        };
        let way = |a: &[f64; DOF], b: &[f64; DOF]| -> Vec<[f64; DOF]> {
            (0..=50).map(|k| agrisim_manip::checker::lerp(a, b, k as f64 / 50.0)).collect()
        };
        let mut rng = Rng::new(3);
        let (ql, qr) = (0..20_000)
            .map(|_| (l.random_q(&mut rng), r.random_q(&mut rng)))
            .find(|(ql, qr)| {
                meet(ql, qr)
                    && way(&HOME, ql).iter().all(|q| !meet(q, &HOME))
                    && way(&HOME, qr).iter().all(|q| !meet(&HOME, q))
            })
            .expect("a pair of configurations where the arms meet");
        let timed = |points: &[(f64, [f64; DOF])]| {
            let pts = points
                .iter()
                .map(|(t, q)| JointTrajectoryPoint {
                    positions: q.to_vec(),
                    time_from_start: Duration::from_nanos((t * 1e9) as i64),
                    ..Default::default()
                })
                .collect();
            let (t, q) = *points.last().expect("points");
            Planned { msg: JointTrajectory { points: pts, ..Default::default() }, duration: t, goal_q: q }
        };
        // Out to ql and back home in 2 s; the right arm out to qr at once, or after 3 s.
        let left = timed(&[(0.0, HOME), (1.0, ql), (2.0, HOME)]);
        let together = timed(&[(0.0, HOME), (1.0, qr)]);
        let after = timed(&[(0.0, HOME), (3.0, HOME), (4.0, qr)]);
        assert!(!m.trajectories_clear(Arm::Left, lift, &left, &together));
        assert!(!m.trajectories_clear(Arm::Right, lift, &together, &left));
        assert!(m.trajectories_clear(Arm::Left, lift, &left, &after));
        assert!(m.trajectories_clear(Arm::Right, lift, &after, &left));
        // The left arm at ql for 1 s, home by 1.5 s; the right arm jumps to qr within the
        // slack of the left's leaving (refused), or well after it is home (passes).
        let stay = timed(&[(0.0, ql), (1.0, ql), (1.5, HOME)]);
        let soon = timed(&[(0.0, HOME), (1.0 + 0.5 * TIMING_SLACK, HOME), (1.01 + 0.5 * TIMING_SLACK, qr)]);
        let later = timed(&[(0.0, HOME), (1.5 + 3.0 * TIMING_SLACK, HOME), (1.51 + 3.0 * TIMING_SLACK, qr)]);
        assert!(!m.trajectories_clear(Arm::Left, lift, &stay, &soon));
        assert!(m.trajectories_clear(Arm::Left, lift, &stay, &later));
    }

    #[test]
    fn line_distance() {
        assert!((distance_to_segment([0.5, 1.0, 0.0], [0.0; 3], [1.0, 0.0, 0.0]) - 1.0).abs() < 1e-12);
        assert!((distance_to_segment([2.0, 0.0, 0.0], [0.0; 3], [1.0, 0.0, 0.0]) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn home_is_collision_free_over_the_lift_range() {
        let m = Motion::new(1);
        for lift in [0.0, 0.3, 0.8] {
            for arm in [Arm::Left, Arm::Right] {
                let ctx = m.context(arm, lift, HOME);
                assert!(Checker::new(ctx).is_valid(&HOME), "{arm:?} at lift {lift}");
            }
        }
    }

    /// A point in the left arm's reach at `lift`, 0.85 m aside (where a fruit hangs).
    fn reach_centre(lift: f64) -> [f64; 3] {
        [
            0.4,
            0.85,
            crate::geometry::ARM_Z0 + lift + crate::geometry::SHOULDER_UP - crate::geometry::REACH_BELOW_SHOULDER,
        ]
    }

    /// A planning-scene object at `p`, unrotated.
    fn object(
        id: String,
        kind: &str,
        primitive: SolidPrimitive,
        p: [f64; 3],
    ) -> agrisim_msgs::agrisim::CollisionObject {
        use agrisim_msgs::geometry_msgs::{Point, Pose, Quaternion};
        agrisim_msgs::agrisim::CollisionObject {
            id,
            kind: kind.into(),
            primitive,
            pose: Pose { position: Point { x: p[0], y: p[1], z: p[2] }, orientation: Quaternion::IDENTITY },
        }
    }

    /// A tomato hanging right in front of the target (toward the aisle, 2.5 cm apart: not a
    /// touching neighbour) blocks the wrist of every straight-in and tilted approach; an
    /// approach turned along the row reaches round it.
    #[test]
    fn a_fruit_in_front_is_reached_round_from_the_side() {
        let (r, lift) = (0.035, 0.3);
        let c = reach_centre(lift);
        let fruit = |id: &str, y: f64| object(id.into(), "fruit", SolidPrimitive::sphere(r), [c[0], y, c[2]]);
        let scene =
            PlanningScene { objects: vec![fruit("1", c[1]), fruit("2", c[1] - 2.0 * r - 0.025)], ..Default::default() };
        let plan = |candidates: &[TcpGoal]| {
            let mut m = Motion::new(1);
            m.set_target(c);
            m.set_scene(&scene, Pose2 { x: 0.0, y: 0.0, yaw: 0.0 });
            m.ignore_target(false);
            m.plan_pregrasp_any(Arm::Left, lift, HOME, candidates, crate::geometry::PRE_GRASP, HOME).map(|(i, _)| i)
        };
        let all = crate::geometry::grasp_candidates(c, 1.0);
        assert!(plan(&all[..3]).is_err(), "straight in and tilted must be blocked by the fruit in front");
        let i = plan(&all).expect("an approach along the row reaches it");
        assert!(i >= 3 && crate::geometry::APPROACHES[i].0 != 0.0, "approach {i}");
    }

    /// Where the guarded truss blocks every grasp, the fallback plans from the random state
    /// the guarded try started with: the same trajectory as a node that never guarded.
    #[test]
    fn the_guard_fallback_plans_as_if_unguarded() {
        let (r, lift) = (0.035, 0.3);
        let c = reach_centre(lift);
        // A closed cage of six truss slabs 3 cm off the fruit's surface: guarded, it walls the
        // fruit in; pressed aside, it is no obstacle.
        let mut objects = vec![object("target".into(), "fruit", SolidPrimitive::sphere(r), c)];
        let (off, thick) = (r + 0.03 + 0.005, 0.01);
        for axis in 0..3 {
            for sign in [-1.0, 1.0] {
                let mut size = [0.3; 3];
                size[axis] = thick;
                let mut p = c;
                p[axis] += sign * off;
                objects.push(object(
                    format!("slab{axis}{sign}"),
                    "truss",
                    SolidPrimitive::new_box(size[0], size[1], size[2]),
                    p,
                ));
            }
        }
        let scene = PlanningScene { objects, ..Default::default() };
        let grasps = crate::geometry::grasp_candidates(c, 1.0);
        let fresh = || {
            let mut m = Motion::new(1);
            m.set_target(c);
            m.set_scene(&scene, Pose2 { x: 0.0, y: 0.0, yaw: 0.0 });
            m
        };
        let mut walled = fresh();
        walled.guard_trusses(true);
        assert_eq!(walled.guarded_trusses(), 6);
        let blocked = walled.plan_pregrasp_any(Arm::Left, lift, HOME, &grasps, crate::geometry::PRE_GRASP, HOME);
        assert!(blocked.is_err(), "the guarded cage must block every grasp");
        let mut guarded = fresh();
        let (i, a) = guarded
            .plan_pregrasp_guarded(Arm::Left, lift, HOME, &grasps, crate::geometry::PRE_GRASP, HOME)
            .expect("the fallback presses the cage aside");
        assert_eq!(guarded.guarded_trusses(), 0, "the guard is off after the fallback");
        let mut unguarded = fresh();
        let (j, b) = unguarded
            .plan_pregrasp_any(Arm::Left, lift, HOME, &grasps, crate::geometry::PRE_GRASP, HOME)
            .expect("unguarded, the cage is soft");
        assert_eq!(i, j);
        assert_eq!(a.goal_q, b.goal_q);
        assert_eq!(a.msg.points, b.msg.points);
        // And the random stream goes on the same, for every plan after this one.
        assert_eq!(format!("{:?}", guarded.rng), format!("{:?}", unguarded.rng));
    }

    /// A fruit this node once held is loose: lying against the hand afterwards (dropped on
    /// the robot), it blocks nothing; the same fruit never held does.
    #[test]
    fn a_fruit_once_held_is_loose() {
        use agrisim_msgs::agrisim::CollisionObject;
        use agrisim_msgs::geometry_msgs::{Point, Pose, Quaternion};
        let lift = 0.3;
        let fruit = |id: &str, p: [f64; 3]| CollisionObject {
            id: id.into(),
            kind: "fruit".into(),
            primitive: SolidPrimitive::sphere(0.03),
            pose: Pose {
                position: Point { x: p[0], y: p[1], z: p[2] },
                orientation: Quaternion { x: 0.0, y: 0.0, z: 0.0, w: 1.0 },
            },
        };
        let base = Pose2 { x: 0.0, y: 0.0, yaw: 0.0 };
        let (picked, next) = ([0.4, 0.85, 1.1], [0.4, -0.85, 1.1]);
        let at_hand = Motion::new(1).model(Arm::Left).fk(lift, &HOME).trans;
        let later = PlanningScene { objects: vec![fruit("5", at_hand), fruit("6", next)], ..Default::default() };
        let home_free = |m: &Motion| Checker::new(m.context(Arm::Left, lift, HOME)).is_valid(&HOME);
        let mut m = Motion::new(1);
        m.set_target(picked);
        m.set_scene(&PlanningScene { objects: vec![fruit("5", picked)], ..Default::default() }, base);
        m.set_held(Arm::Left, Some(0.03));
        m.set_held(Arm::Left, None);
        m.set_target(next);
        m.set_scene(&later, base);
        assert!(home_free(&m), "the once-held fruit at the hand must not block");
        let mut fresh = Motion::new(1);
        fresh.set_target(next);
        fresh.set_scene(&later, base);
        assert!(!home_free(&fresh), "a fruit never held at the hand blocks it");
        // The world's "fruit_held" (a fruit in a hand, of an earlier task: the recovery
        // carries it to the box) is the hand's, never an obstacle to it.
        let mut held = later.clone();
        held.objects[0].kind = "fruit_held".into();
        let mut rescue = Motion::new(1);
        rescue.set_target(next);
        rescue.set_scene(&held, base);
        assert!(home_free(&rescue), "the world's held fruit must not block the hand holding it");
    }

    #[test]
    fn free_goal_in_open_space_is_planned_and_timed() {
        let mut m = Motion::new(1);
        let goal = TcpGoal { position: [0.6, 0.5, 1.0], approach: [0.0, 1.0, 0.0], x_axis: None };
        let p = m.plan_free(Arm::Left, 0.2, HOME, &goal, HOME).expect("reachable in open space");
        assert!(p.duration > 0.1 && p.msg.points.len() > 2);
        let tcp = m.model(Arm::Left).fk(0.2, &p.goal_q).trans;
        assert!((0..3).all(|i| (tcp[i] - goal.position[i]).abs() < 2e-3), "{tcp:?}");
        // Approach 0.1 m along the axis from there: a straight, jerk-limited move.
        let l = m.plan_linear(Arm::Left, 0.2, p.goal_q, &goal.along(0.1), HOME).expect("short line");
        let tcp = m.model(Arm::Left).fk(0.2, &l.goal_q).trans;
        assert!((tcp[1] - 0.6).abs() < 2e-3);
    }

    /// With the guard on, the truss parts near the target (a neighbour's pedicel, the
    /// rachis above) are obstacles; the target's own pedicel (touching it) and a far truss
    /// are not; nor is anything once the fruit is in the hand, or with the guard off.
    #[test]
    fn the_target_truss_is_guarded_but_not_its_own_pedicel() {
        use agrisim_msgs::agrisim::CollisionObject;
        use agrisim_msgs::geometry_msgs::{Point, Pose, Quaternion};
        let (c, r) = ([0.4, 0.85, 1.2], 0.03);
        let object = |id: &str, kind: &str, primitive: SolidPrimitive, p: [f64; 3]| CollisionObject {
            id: id.into(),
            kind: kind.into(),
            primitive,
            pose: Pose { position: Point { x: p[0], y: p[1], z: p[2] }, orientation: Quaternion::IDENTITY },
        };
        // Vertical rods of 4 cm: the own pedicel on the fruit's top, a neighbour's 5 cm
        // aside, one 30 cm away; a rachis (horizontal: turned about x) 3 cm above the top.
        let rod = || SolidPrimitive::cylinder(0.04, 0.002);
        let along_y =
            Quaternion { x: std::f64::consts::FRAC_1_SQRT_2, y: 0.0, z: 0.0, w: std::f64::consts::FRAC_1_SQRT_2 };
        let mut rachis = object("rachis", "truss", SolidPrimitive::cylinder(0.3, 0.004), [c[0], c[1], c[2] + r + 0.03]);
        rachis.pose.orientation = along_y;
        let scene = PlanningScene {
            objects: vec![
                object("target", "fruit", SolidPrimitive::sphere(r), c),
                object("own", "truss", rod(), [c[0], c[1], c[2] + r + 0.02]),
                object("neighbour", "truss", rod(), [c[0] + 0.05, c[1], c[2] + r]),
                object("far", "truss", rod(), [c[0] + 0.3, c[1], c[2]]),
                rachis,
            ],
            ..Default::default()
        };
        let mut m = Motion::new(1);
        m.set_target(c);
        m.set_scene(&scene, Pose2 { x: 0.0, y: 0.0, yaw: 0.0 });
        assert_eq!(m.guarded_trusses(), 0, "off by default");
        m.guard_trusses(true);
        assert_eq!(m.guarded_trusses(), 2, "the neighbour's pedicel and the rachis");
        let solid: Vec<&str> =
            m.scene.objects().iter().filter(|o| o.kind == ObstacleKind::Solid).map(|o| o.name.as_str()).collect();
        assert_eq!(solid, ["neighbour", "rachis"]);
        m.ignore_target(true);
        assert_eq!(m.guarded_trusses(), 0, "the fruit in the hand: trusses pressed aside again");
        m.ignore_target(false);
        m.guard_trusses(false);
        assert_eq!(m.guarded_trusses(), 0);
    }
}
