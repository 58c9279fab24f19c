//! The harvest node's stages, one function each; [`HarvestNode::run_stage`] dispatches to
//! them, and each moves on by [`HarvestNode::enter`]ing the next stage or ends the harvest.

use super::{topics, HarvestNode};
use crate::geometry::{self as geo, TcpGoal};
use crate::motion::{Arm, Planned};
use crate::sight::{self, Region};
use crate::stage::{Failure, Stage};
use agrisim_bus::Bus;
use agrisim_msgs::geometry_msgs::{Twist, Vector3};

/// Gripper force for tomatoes [N] (well below bruising; the Franka Hand holds 70 N).
const GRASP_FORCE: f64 = 20.0;
/// Time the released fruit gets to fall and settle before the box is checked [s].
const SETTLE: f64 = 1.5;
/// Where the later grasp attempts aim, from the first: (across the finger pads, deeper along
/// the approach) [m]. A miss means the fruit is not where the localized base put it: the
/// pads tolerate least across them, and a base that stands off a little too far (lateral
/// localization error) leaves the fruit beyond the pads' tips.
const REGRASP_SHIFTS: [(f64, f64); 3] = [(0.012, 0.0), (-0.012, 0.0), (0.0, 0.015)];
/// Sphere-check margin of the taker's final approach [m]: the hands meet by design there.
const HANDOVER_PADDING: f64 = 0.002;
/// How far the giver backs off along its approach after letting go [m].
const GIVER_BACKOFF: f64 = 0.1;
/// Motions the recovery may send before it gives up (two per arm: back-off and home).
const RECOVERY_MOTIONS: u32 = 4;
/// Wrist roll (joint 7) that bends the grasped fruit off its plant [rad]. The roll turns the
/// fruit about the approach axis through its centre, so its calyx swings sideways under the
/// pedicel: bending, which detaches tomato with less force than pulling (Li et al., Trans.
/// CSAE 24(12), 2008). About 50 deg: above the bend the world's default pedicel needs
/// (its mean 0.15 N m at 0.3 N m/rad, plus the sideways pull on the pedicel).
const DETACH_ROLL: f64 = 0.9;
/// A joint torque this much above its value right after the grasp means the fruit still
/// pulls on the hand: still on its plant [N m]. (A few newtons at the arm's ~0.6 m reach;
/// well above the joints' Coulomb friction, 0.15-0.64 N m, that the holding torque may hide.)
const DETACH_LOAD_TORQUE: f64 = 2.5;
/// Time the joint torques get to settle after the roll before they are read [s].
const DETACH_SETTLE: f64 = 0.2;

impl HarvestNode {
    /// Between two fruit: open both grippers and stop the base, then send home each arm that
    /// is not, the one that reached furthest first. -> select_target once both are home.
    /// An arm that still holds a fruit (the last pick's handover failed) is not opened: it
    /// carries the fruit into the box first, as the taker of a handover does. -> transfer.
    pub(super) fn run_recover(&mut self, t_ns: i64, bus: &mut Bus) {
        match self.phase_now() {
            0 if !self.rescuing && !self.rescue_failed => {
                if let Some(arm) = [Arm::Left, Arm::Right].into_iter().find(|&a| self.holding(a)) {
                    // The holder becomes the taker; the fruit sits GRASP_DEPTH short of its
                    // TCP, where a giver holds it, as a taker's first attempt holds it
                    // (`handover_offset` with no attempt made).
                    self.side = if arm == Arm::Right { 1.0 } else { -1.0 };
                    let r = 0.5 * self.view(arm).gripper.as_ref().map_or(0.06, |g| g.position);
                    self.motion.set_held(arm, Some(r));
                    self.gripper(arm.other(), geo::OPEN_WIDTH, GRASP_FORCE, t_ns, bus);
                    self.stop_base(t_ns, bus);
                    self.rescuing = true;
                    self.enter(
                        Stage::Transfer,
                        t_ns,
                        bus,
                        &format!("{} arm still holds a fruit: into the box first", arm.name()),
                    );
                    return;
                }
                self.open_grippers(t_ns, bus);
            }
            0 => {
                // Back from putting a held fruit into the box, or from failing to: the
                // grippers as usual.
                self.rescuing = false;
                self.open_grippers(t_ns, bus);
            }
            // The grippers open (half a second, unless both were open already), then each
            // arm that is not home goes home, the one that reached furthest first (it may
            // stand in the other's way).
            1 if self.step_in_stage > 5 || self.grippers_were_open => {
                let far = |a: Arm| agrisim_manip::ik::dist(&self.q(a), &crate::motion::HOME);
                let arm = if far(Arm::Left) >= far(Arm::Right) { Arm::Left } else { Arm::Right };
                if far(arm) < 1e-3 {
                    self.attempts = 0;
                    self.approach_from = None;
                    self.enter(Stage::SelectTarget, t_ns, bus, "both arms home");
                } else if self.attempts >= RECOVERY_MOTIONS {
                    self.fail(
                        Failure::Planning,
                        t_ns,
                        bus,
                        format!("recover: the arms are not home after {RECOVERY_MOTIONS} motions"),
                    );
                } else if self.go_home(arm, t_ns, bus) {
                    self.attempts += 1;
                    self.phase = 2;
                }
            }
            2 if [Arm::Left, Arm::Right].iter().all(|&a| self.arm_done(a, t_ns, bus) == Some(true)) => self.phase = 1,
            _ => {}
        }
    }

    /// Recovery's start: both grippers told to open (noting whether both already were, told
    /// so and reading so: then nothing waits for them), the base stopped.
    fn open_grippers(&mut self, t_ns: i64, bus: &mut Bus) {
        self.grippers_were_open = [Arm::Left, Arm::Right].iter().all(|&a| self.gripper_open(a));
        for arm in [Arm::Left, Arm::Right] {
            self.gripper(arm, geo::OPEN_WIDTH, GRASP_FORCE, t_ns, bus);
        }
        self.stop_base(t_ns, bus);
        self.phase = 1;
    }

    /// Waits for the target, the localized pose and both arms' joints, then chooses the side
    /// of the row, the grasp, the base's stand-off and the lift height. -> position_base.
    pub(super) fn run_select_target(&mut self, t_ns: i64, bus: &mut Bus) {
        if let Some(region) = self.region() {
            return self.run_scan(region, t_ns, bus);
        }
        bus.set_scalar(topics::TARGET_ID, self.fruit_index as f64);
        if self.target_map.is_some() && self.pose.is_some() && self.arms.iter().all(|a| a.q.is_some()) {
            self.aim(t_ns, bus);
        }
    }

    /// With the target known: the side of the row, the grasp, the base's stand-off and the
    /// lift height. -> position_base.
    pub(super) fn aim(&mut self, t_ns: i64, bus: &mut Bus) {
        {
            let t = self.target_map.expect("checked");
            // The base harvests facing along the aisle the way it already faces (+x or
            // -x: no turning round in the aisle); the row is on the side of that
            // heading where the fruit is.
            let pose = self.pose.expect("checked");
            let heading = if pose.yaw.cos() >= 0.0 { 0.0 } else { std::f64::consts::PI };
            let (s, c) = f64::sin_cos(heading);
            self.side = if -s * (t[0] - pose.x) + c * (t[1] - pose.y) >= 0.0 { 1.0 } else { -1.0 };
            self.grasp = geo::grasp([0.0; 3], self.side);
            self.base_goal = geo::standoff_facing(t, self.side, heading);
            self.lift_target = geo::lift_for(t[2]);
            let name = match &self.track {
                Some(id) if self.region().is_some() => format!("track {id}"),
                _ => format!("fruit {}", self.fruit_index),
            };
            self.enter(Stage::PositionBase, t_ns, bus, &format!("{name} at ({:.3}, {:.3}, {:.3})", t[0], t[1], t[2]));
        }
    }

    /// By sight: a row's later task first takes an untried ripe fruit of the region its
    /// fruit map already holds; otherwise it drives to the middle of the region along the
    /// aisle line the base stands on, and stops the lift at each of [`sight::SCAN_LIFTS`] while the cameras look into the
    /// row; after each stop's dwell, the ripe fruit of the fruit map in the region nearest the
    /// aisle is the target (-> position_base); none after the last stop: not detected.
    fn run_scan(&mut self, region: Region, t_ns: i64, bus: &mut Bus) {
        let Some(pose) = self.pose else { return };
        if !self.arms.iter().all(|a| a.q.is_some()) {
            return;
        }
        if self.phase == 0 {
            let heading = if pose.yaw.cos() >= 0.0 { 0.0 } else { std::f64::consts::PI };
            // The region reaches from its row's plant line to the aisle's centre line: the
            // bound nearer the base (a row harvest's base may stand off it after a pick).
            let [a, b] = region.y;
            self.aisle_y = if (a - pose.y).abs() <= (b - pose.y).abs() { a } else { b };
            self.base_goal = [region.centre()[0], self.aisle_y, heading];
            self.base_ctl = crate::base::BaseController::default();
            (self.scan, self.dwell_from, self.in_place_ticks) = (0, None, 0);
            self.phase = 1;
            // A row's later task: a ripe fruit the map already holds is taken from where the
            // robot stands (the cameras looked on through the last pick); none: scan.
            if self.look_first {
                if let Some(f) = sight::choose(&self.fruit_map, &region, self.region_margin, self.aisle_y, &self.tried)
                {
                    self.target_seen(&f);
                    return self.aim(t_ns, bus);
                }
            }
        }
        let lift = sight::SCAN_LIFTS[self.scan];
        bus.set_scalar(topics::LIFT_SETPOINT, lift);
        if !(self.drive(pose, t_ns, bus) && self.lift_at(lift)) {
            return;
        }
        let since = *self.dwell_from.get_or_insert(t_ns);
        if ((t_ns - since) as f64) < sight::SCAN_DWELL * 1e9 {
            return;
        }
        if let Some(f) = sight::choose(&self.fruit_map, &region, self.region_margin, self.aisle_y, &self.tried) {
            self.target_seen(&f);
            return self.aim(t_ns, bus);
        }
        self.dwell_from = None;
        self.scan += 1;
        if self.scan == sight::SCAN_LIFTS.len() {
            let n = self.fruit_map.iter().filter(|f| region.contains(f.center)).count();
            let wide = sight::too_wide(&self.fruit_map, &region, self.region_margin, &self.tried);
            if wide.is_empty() {
                let why = format!("no ripe fruit in the region after the scan ({n} fruit of the map in it, none ripe)");
                self.fail(Failure::NotDetected, t_ns, bus, why);
            } else {
                let mm: Vec<String> = wide.iter().map(|r| format!("{:.1}", r * 1e3)).collect();
                let why = format!(
                    "no ripe fruit in the region the hand opens round after the scan ({n} fruit of the map in it; \
                     ripe, perceived radius over {:.0} mm: {} mm)",
                    sight::GRASPABLE_RADIUS * 1e3,
                    mm.join(", ")
                );
                self.fail(Failure::TooWide, t_ns, bus, why);
            }
        }
    }

    /// One exchange of driving the base to `base_goal`; whether it has stood there for five.
    fn drive(&mut self, pose: agrisim_math::Pose2, t_ns: i64, bus: &mut Bus) -> bool {
        let ctl = &mut self.base_ctl;
        if ctl.in_place(pose, self.base_goal) {
            self.in_place_ticks += 1;
            self.stop_base(t_ns, bus);
        } else {
            self.in_place_ticks = 0;
            let [vx, vy, wz] = ctl.command(pose, self.base_goal);
            bus.publish(
                topics::CMD_VEL,
                t_ns,
                &Twist { linear: Vector3 { x: vx, y: vy, z: 0.0 }, angular: Vector3 { x: 0.0, y: 0.0, z: wz } },
            );
        }
        self.in_place_ticks >= 5
    }

    /// Drives the base to its stand-off and the lift to the fruit's height.
    /// -> pre_grasp once both are in place.
    pub(super) fn run_position_base(&mut self, first: bool, t_ns: i64, bus: &mut Bus) {
        bus.set_scalar(topics::LIFT_SETPOINT, self.lift_target);
        let pose = self.pose.expect("known since SelectTarget");
        if first {
            self.base_ctl = crate::base::BaseController::default();
            self.in_place_ticks = 0;
        }
        if self.drive(pose, t_ns, bus) && self.lift_at(self.lift_target) {
            self.enter(Stage::PreGrasp, t_ns, bus, "base and lift in place");
        }
    }

    /// Opens the giver's gripper and plans it to the stand-off of the first reachable grasp,
    /// on a planning scene sent after the base stopped. -> approach once it is there.
    pub(super) fn run_pre_grasp(&mut self, first: bool, t_ns: i64, bus: &mut Bus) {
        let giver = self.giver();
        if first {
            self.gripper(giver, geo::OPEN_WIDTH, GRASP_FORCE, t_ns, bus);
        }
        if !self.planned {
            // Plan on a scene sent after the base stopped, the target through TF.
            if !self.fresh_scene(self.stage_start_ns) {
                return;
            }
            self.motion.set_target(self.target_map.expect("known since SelectTarget"));
            self.update_scene();
            let Some(c) = self.target_base() else { return };
            self.motion.ignore_target(false);
            self.planned = true;
            let candidates = geo::grasp_candidates(c, self.side);
            if let Some(i) = self.move_pregrasp(giver, &candidates, t_ns, bus) {
                self.grasp = candidates[i];
            }
        } else if self.arm_done(giver, t_ns, bus) == Some(true) {
            self.enter(Stage::Approach, t_ns, bus, "");
        }
    }

    /// Straight in to the grasp (a later attempt: to the next aim of [`REGRASP_SHIFTS`]).
    /// -> grasp.
    pub(super) fn run_approach(&mut self, first: bool, t_ns: i64, bus: &mut Bus) {
        let giver = self.giver();
        if first {
            let Some(c) = self.target_base() else { return };
            // A later attempt whose aim cannot be reached goes on to the next aim.
            let [x, z] = self.regrasp_axes;
            let shifts =
                if self.attempts == 0 { &[(0.0, 0.0)][..] } else { &REGRASP_SHIFTS[self.attempts as usize - 1..] };
            let mut goals: Vec<TcpGoal> = shifts
                .iter()
                .map(|&(a, d)| {
                    TcpGoal { position: std::array::from_fn(|i| c[i] + a * x[i] + d * z[i]), ..self.grasp }
                        .along(geo::GRASP_DEPTH)
                })
                .collect();
            // The target as the localized base sees it now may have moved a few
            // millimetres since the pre-grasp plan; where the straight line to it is
            // blocked, the line the pre-grasp plan checked.
            if self.attempts == 0 && (0..3).any(|i| (goals[0].position[i] - self.grasp.position[i]).abs() > 1e-3) {
                goals.push(self.grasp);
            }
            self.approach_from = Some((giver, self.q(giver)));
            if let Some(i) = self.plan_and_send(giver, "linear", t_ns, bus, |m, lift, start, other| {
                m.plan_linear_any(giver, lift, start, &goals, other)
            }) {
                if self.attempts > 0 {
                    self.attempts += i as u32;
                }
                self.grasp_point = goals[i].position;
            }
        } else if self.arm_done(giver, t_ns, bus) == Some(true) {
            self.enter(Stage::Grasp, t_ns, bus, "");
        }
    }

    /// Closes the giver's gripper. -> retreat holding the fruit; -> regrasp when it closed on
    /// nothing (failed after the last aim).
    pub(super) fn run_grasp(&mut self, first: bool, t_ns: i64, bus: &mut Bus) {
        let giver = self.giver();
        if first {
            self.gripper(giver, 0.0, GRASP_FORCE, t_ns, bus);
        } else if self.holding(giver) && self.step_in_stage > 3 {
            let r = self
                .motion
                .target_radius()
                .unwrap_or(0.5 * self.view(giver).gripper.as_ref().map_or(0.06, |g| g.position));
            self.motion.set_held(giver, Some(r));
            self.detach_baseline = self.view(giver).effort;
            self.enter(Stage::Detach, t_ns, bus, "fruit held");
        } else if self.view(giver).gripper.as_ref().is_some_and(|g| g.reached_goal && g.position < 0.005) {
            if self.attempts as usize >= REGRASP_SHIFTS.len() {
                self.fail(
                    Failure::Grasp,
                    t_ns,
                    bus,
                    format!("the gripper closed on nothing ({} attempts)", self.attempts + 1),
                );
            } else {
                self.enter(Stage::Regrasp, t_ns, bus, "the gripper closed on nothing");
            }
        }
    }

    /// The fruit is not where the TCP went (localization error): open, back off to the
    /// pre-grasp and come in again at the next aim of [`REGRASP_SHIFTS`]. -> approach.
    pub(super) fn run_regrasp(&mut self, t_ns: i64, bus: &mut Bus) {
        let giver = self.giver();
        match self.phase_now() {
            0 => {
                self.gripper(giver, geo::OPEN_WIDTH, GRASP_FORCE, t_ns, bus);
                self.phase = 1;
            }
            1 if self.view(giver).gripper.as_ref().is_some_and(|g| g.position > geo::OPEN_WIDTH - 0.005) => {
                let goal = TcpGoal { position: self.grasp_point, ..self.grasp }.along(-geo::PRE_GRASP);
                if self.move_arm(giver, &goal, true, t_ns, bus) {
                    self.phase = 2;
                }
            }
            2 if self.arm_done(giver, t_ns, bus) == Some(true) => {
                if self.attempts == 0 {
                    let tcp = self.motion.model(giver).fk(self.lift, &self.q(giver));
                    self.regrasp_axes = [0, 2].map(|k| [tcp.rot[0][k], tcp.rot[1][k], tcp.rot[2][k]]);
                }
                self.attempts += 1;
                self.enter(Stage::Approach, t_ns, bus, &format!("attempt {}", self.attempts + 1));
            }
            _ => {}
        }
    }

    /// Rolls the wrist by [`DETACH_ROLL`] (either way; half of it where there is no room for
    /// more), waits for the joint
    /// torques to settle and compares them with those right after the grasp: within
    /// [`DETACH_LOAD_TORQUE`] the fruit came off (bent off); beyond, it still hangs on its
    /// plant: roll back and let the retreat pull it off (the fallback). Where no roll can be
    /// planned, the retreat pulls at once. -> retreat.
    pub(super) fn run_detach(&mut self, t_ns: i64, bus: &mut Bus) {
        let giver = self.giver();
        match self.phase_now() {
            0 => {
                // The fruit is in the hand: no obstacle to the roll.
                self.motion.ignore_target(true);
                let (start, other) = (self.q(giver), self.q(giver.other()));
                let l = self.motion.model(giver).limits[6];
                // Either way, the full roll first; half a roll where the hand has no room for
                // more (a roll too short to bend the fruit off ends in the pull).
                let goals: Vec<[f64; 7]> = [DETACH_ROLL, -DETACH_ROLL, 0.5 * DETACH_ROLL, -0.5 * DETACH_ROLL]
                    .iter()
                    .map(|&roll| {
                        let mut g = start;
                        g[6] += roll;
                        g
                    })
                    .filter(|g| g[6] > l.lower + 0.05 && g[6] < l.upper - 0.05)
                    .collect();
                let r = if goals.is_empty() {
                    Err(format!("joint 7 at {:.2} rad has no room to roll", start[6]))
                } else {
                    self.motion.plan_roll(giver, self.lift, start, &goals, other, self.grasp_point)
                };
                self.record(giver, "detach", &r, true, t_ns, bus);
                match r {
                    Ok(p) => {
                        self.grasp_q = start;
                        self.send(giver, p, t_ns, bus);
                        self.phase = 1;
                    }
                    Err(e) => {
                        self.detach_motion = "pull";
                        self.enter(Stage::Retreat, t_ns, bus, &format!("no bend ({e}): pulling"));
                    }
                }
            }
            1 if self.arm_done(giver, t_ns, bus) == Some(true) => {
                self.release_ns = t_ns;
                self.phase = 2;
            }
            2 if (t_ns - self.release_ns) as f64 * 1e-9 >= DETACH_SETTLE => {
                let load = match (self.detach_baseline, self.view(giver).effort) {
                    (Some(b), Some(e)) => (0..7).map(|i| (e[i] - b[i]).abs()).fold(0.0, f64::max),
                    // No torques measured: assume it still hangs (the pull is the safe side).
                    _ => f64::INFINITY,
                };
                if load <= DETACH_LOAD_TORQUE {
                    self.detach_motion = "bend";
                    self.enter(Stage::Retreat, t_ns, bus, &format!("bent off (load {load:.2} N m)"));
                } else {
                    let goal = self.grasp_q;
                    let (start, other) = (self.q(giver), self.q(giver.other()));
                    let r = self.motion.plan_roll(giver, self.lift, start, &[goal], other, self.grasp_point);
                    self.record(giver, "detach", &r, true, t_ns, bus);
                    self.detach_motion = "pull";
                    match r {
                        Ok(p) => {
                            self.send(giver, p, t_ns, bus);
                            self.phase = 3;
                        }
                        Err(e) => self.enter(
                            Stage::Retreat,
                            t_ns,
                            bus,
                            &format!("still on (load {load:.2} N m), no roll back ({e}): pulling"),
                        ),
                    }
                }
            }
            3 if self.arm_done(giver, t_ns, bus) == Some(true) => {
                self.enter(Stage::Retreat, t_ns, bus, "still on after the bend: pulling");
            }
            _ => {}
        }
    }

    /// Backs the held fruit out of the plant. -> handover_pose (failed if it slipped out).
    pub(super) fn run_retreat(&mut self, first: bool, t_ns: i64, bus: &mut Bus) {
        let giver = self.giver();
        if first {
            // The fruit now belongs to the hand: it is no obstacle. Back out along the
            // approach and a little up; where the held fruit would catch on a
            // neighbour that way, straight back, then a shorter way.
            self.motion.ignore_target(true);
            let grasp = TcpGoal { position: self.grasp_point, ..self.grasp };
            let goals = geo::RETREATS.map(|[back, up]| {
                let g = grasp.along(-back);
                TcpGoal { position: [g.position[0], g.position[1], g.position[2] + up], ..g }
            });
            // No straight line out (a bend or twist turned the hand, and a post or a
            // neighbour stands where it would back into): a free motion back to where the
            // approach began, the way the hand came in.
            let back = self.approach_from;
            self.plan_and_send(giver, "linear", t_ns, bus, |m, lift, start, other| {
                m.plan_linear_any(giver, lift, start, &goals, other).or_else(|e| match back {
                    Some((_, q)) => m
                        .plan_joints(giver, lift, start, &[q], other)
                        .map(|p| (goals.len(), p))
                        .map_err(|f| format!("{e}; back to the approach's start: {f}")),
                    None => Err(e),
                })
            });
        } else if self.arm_done(giver, t_ns, bus) == Some(true) {
            if !self.holding(giver) {
                self.fail(Failure::Grasp, t_ns, bus, "the fruit slipped out during the retreat".into());
                return;
            }
            self.enter(Stage::HandoverPose, t_ns, bus, "");
        }
    }

    /// Lifts to the transfer height, the giver presents the fruit, then the taker comes to
    /// its pre-handover pose: one arm moves at a time, so each plans against the other's actual
    /// configuration. -> handover.
    pub(super) fn run_handover_pose(&mut self, t_ns: i64, bus: &mut Bus) {
        let (giver, taker) = (self.giver(), self.taker());
        match self.phase_now() {
            0 => {
                // Lift to the transfer height unless an arm would meet the robot on the way.
                let q = [self.q(Arm::Left), self.q(Arm::Right)];
                if self.motion.lift_sweep_clear(q, self.lift, geo::LIFT_TRANSFER) {
                    self.lift_target = geo::LIFT_TRANSFER;
                }
                bus.set_scalar(topics::LIFT_SETPOINT, self.lift_target);
                self.gripper(taker, geo::OPEN_WIDTH, GRASP_FORCE, t_ns, bus);
                self.phase = 1;
            }
            1 if self.lift_at(self.lift_target) => {
                let (g, _) = geo::handover_goals(geo::handover_point(self.lift), self.side);
                if self.move_arm(giver, &g, false, t_ns, bus) {
                    self.phase = 2;
                }
            }
            2 if self.arm_done(giver, t_ns, bus) == Some(true) => {
                // The taker's stand-off is chosen so its straight approach to the
                // fruit is valid too; the hands meet by design, the exact check decides.
                let (_, t) = geo::handover_goals(geo::handover_point(self.lift), self.side);
                self.motion.set_padding(HANDOVER_PADDING);
                let ok = self.move_pregrasp(taker, &[t.along(geo::HANDOVER_DEPTHS[0])], t_ns, bus).is_some();
                self.motion.set_padding(agrisim_manip::checker::DEFAULT_PADDING);
                if ok {
                    self.phase = 3;
                }
            }
            3 if self.arm_done(taker, t_ns, bus) == Some(true) => self.enter(Stage::Handover, t_ns, bus, ""),
            _ => {}
        }
    }

    /// The taker closes on the fruit in the giver's hand and the giver lets go and backs
    /// off; where the taker closed on nothing, it tries again deeper ([`geo::HANDOVER_DEPTHS`]).
    /// -> transfer.
    // A phase's guard says when it may act; the motion request inside is the action, kept out
    // of the guard so no arm's condition has side effects.
    #[allow(clippy::collapsible_match)]
    pub(super) fn run_handover(&mut self, t_ns: i64, bus: &mut Bus) {
        let (giver, taker) = (self.giver(), self.taker());
        let (_, t) = geo::handover_goals(geo::handover_point(self.lift), self.side);
        match self.phase_now() {
            0 => {
                self.motion.set_padding(HANDOVER_PADDING);
                let ok =
                    self.move_arm(taker, &TcpGoal { x_axis: None, ..t.along(self.handover_offset()) }, true, t_ns, bus);
                self.motion.set_padding(agrisim_manip::checker::DEFAULT_PADDING);
                if ok {
                    self.phase = 1;
                }
            }
            1 if self.arm_done(taker, t_ns, bus) == Some(true) => {
                self.gripper(taker, 0.0, GRASP_FORCE, t_ns, bus);
                self.phase = 2;
            }
            2 if self.holding(taker) => {
                let r = self.motion.target_radius();
                self.motion.set_held(taker, r);
                self.motion.set_held(giver, None);
                self.gripper(giver, geo::OPEN_WIDTH, GRASP_FORCE, t_ns, bus);
                self.release_ns = t_ns;
                self.phase = 3;
            }
            2 if self.view(taker).gripper.as_ref().is_some_and(|g| g.reached_goal && g.position < 0.005) => {
                // Where the fruit sits between the giver's pads (along the approach)
                // is not known: open, back off and try deeper.
                if self.handover_attempts as usize + 1 >= geo::HANDOVER_DEPTHS.len() {
                    self.fail(
                        Failure::Handover,
                        t_ns,
                        bus,
                        format!("the taking gripper closed on nothing ({} attempts)", self.handover_attempts + 1),
                    );
                } else {
                    self.gripper(taker, geo::OPEN_WIDTH, GRASP_FORCE, t_ns, bus);
                    self.phase = 4;
                }
            }
            3 => {
                let opened = self.view(giver).gripper.as_ref().is_some_and(|g| g.position > geo::OPEN_WIDTH - 0.005);
                if opened && t_ns - self.release_ns > 500_000_000 {
                    if !self.holding(taker) {
                        self.fail(Failure::Handover, t_ns, bus, "the fruit fell during the exchange".into());
                        return;
                    }
                    // The giver backs off if a straight line allows it; otherwise
                    // its plan home (next stage) starts right here. The hands met by
                    // design, so the line is checked with the taker's approach's margin.
                    let (g, _) = geo::handover_goals(geo::handover_point(self.lift), self.side);
                    let goal = TcpGoal { x_axis: None, ..g.along(-GIVER_BACKOFF) };
                    let (start, other) = (self.q(giver), self.q(taker));
                    self.motion.set_padding(HANDOVER_PADDING);
                    let r = self.motion.plan_linear(giver, self.lift, start, &goal, other);
                    self.motion.set_padding(agrisim_manip::checker::DEFAULT_PADDING);
                    self.record(giver, "linear", &r, true, t_ns, bus);
                    if let Ok(p) = r {
                        self.send(giver, p, t_ns, bus);
                    }
                    self.enter(Stage::Transfer, t_ns, bus, "fruit handed over");
                }
            }
            4 if self.view(taker).gripper.as_ref().is_some_and(|g| g.position > geo::OPEN_WIDTH - 0.005) => {
                if self.move_arm(taker, &TcpGoal { x_axis: None, ..t.along(-0.04) }, true, t_ns, bus) {
                    self.phase = 5;
                }
            }
            5 if self.arm_done(taker, t_ns, bus) == Some(true) => {
                self.handover_attempts += 1;
                self.publish_status(
                    t_ns,
                    bus,
                    "running",
                    "",
                    &format!("handover attempt {}", self.handover_attempts + 1),
                );
                self.phase = 0;
            }
            _ => {}
        }
    }

    /// The giver, whose back-off was sent on entering, goes home, the lift goes to the
    /// transfer height, then the taker carries the fruit over the box and lowers it straight
    /// down into it, to just above the floor or the fruit already there
    /// ([`geo::place_goals`]). With the lift already there, the taker sets off for the box
    /// as the giver sets off home, where the two trajectories keep the arms apart
    /// ([`Motion::trajectories_clear`](crate::motion::Motion::trajectories_clear)); the way
    /// down waits for both. -> release.
    // A phase's guard says when it may act; the motion request inside is the action, kept out
    // of the guard so no arm's condition has side effects.
    #[allow(clippy::collapsible_match)]
    pub(super) fn run_transfer(&mut self, t_ns: i64, bus: &mut Bus) {
        let (giver, taker) = (self.giver(), self.taker());
        match self.phase_now() {
            0 if self.arm_done(giver, t_ns, bus) == Some(true) => {
                if self.lift_at(geo::LIFT_TRANSFER) {
                    match self.plan_transfer_together(t_ns, bus) {
                        (Ok(h), Some(p)) => {
                            self.send(giver, h, t_ns, bus);
                            self.send(taker, p, t_ns, bus);
                            self.phase = 2;
                        }
                        (Ok(h), None) => {
                            self.send(giver, h, t_ns, bus);
                            self.phase = 1;
                        }
                        (Err(e), _) => {
                            let why = format!("{} arm, {}: {e}", giver.name(), self.stage.name());
                            self.fail(Failure::Planning, t_ns, bus, why);
                        }
                    }
                    return;
                }
                if self.move_home(giver, t_ns, bus) {
                    self.phase = 1;
                }
            }
            1 if self.arm_done(giver, t_ns, bus) == Some(true) => {
                // Down (or up) to the transfer height, where the hand reaches into the box
                // (from the top of the lift it cannot), unless an arm would meet the robot
                // on the way (the handover stage lifts only where it can, with the giver
                // still out at the plant).
                let q = [self.q(Arm::Left), self.q(Arm::Right)];
                if !self.lift_at(geo::LIFT_TRANSFER) && self.motion.lift_sweep_clear(q, self.lift, geo::LIFT_TRANSFER) {
                    self.lift_target = geo::LIFT_TRANSFER;
                    bus.set_scalar(topics::LIFT_SETPOINT, self.lift_target);
                }
                self.phase = 5;
            }
            5 if self.lift_at(self.lift_target) => {
                let goals = self.place_goals();
                // Over the place pose first, with a roll whose straight way down is free.
                let (start, other) = (self.q(taker), self.q(giver));
                let r = self
                    .motion
                    .plan_pregrasp_any(taker, self.lift, start, &goals, geo::PLACE_DESCENT, other)
                    .map(|(_, p)| p);
                self.record(taker, "pregrasp", &r, true, t_ns, bus);
                match r {
                    Ok(p) => {
                        self.send(taker, p, t_ns, bus);
                        self.phase = 2;
                    }
                    // No way down into the box: over it, and let go from there (a drop that
                    // may bruise the fruit, but puts it in the box).
                    Err(_) => {
                        let over: Vec<TcpGoal> = goals.iter().map(|g| g.along(-geo::PLACE_DESCENT)).collect();
                        if self.move_any(taker, &over, t_ns, bus) {
                            self.phase = 4;
                        }
                    }
                }
            }
            2 if [taker, giver].iter().all(|&a| self.arm_done(a, t_ns, bus) == Some(true)) => {
                if !self.holding(taker) {
                    self.fail(Failure::Handover, t_ns, bus, "the fruit was lost on the way to the box".into());
                    return;
                }
                // Straight down from where the hand is (the stand-off of the place pose).
                let tcp = self.motion.model(taker).fk(self.lift, &self.q(taker)).trans;
                let goal =
                    TcpGoal { position: tcp, approach: [0.0, 0.0, -1.0], x_axis: None }.along(geo::PLACE_DESCENT);
                if self.move_arm(taker, &goal, true, t_ns, bus) {
                    self.phase = 3;
                }
            }
            3 | 4 if self.arm_done(taker, t_ns, bus) == Some(true) => {
                if !self.holding(taker) {
                    self.fail(Failure::Handover, t_ns, bus, "the fruit was lost on the way into the box".into());
                    return;
                }
                let how = if self.phase == 3 { "" } else { "no way down into the box: dropped from over it" };
                self.enter(Stage::Release, t_ns, bus, how);
            }
            _ => {}
        }
    }

    /// Where the taker may put the fruit down: successive fruit of a row go to successive
    /// spots in the box, so they spread instead of heaping up under one. The fruit sits in
    /// the taker's pads where the giver held it (GRASP_DEPTH short of its TCP), shifted by
    /// the handover attempt's offset.
    fn place_goals(&self) -> Vec<TcpGoal> {
        let radius = self
            .motion
            .target_radius()
            .unwrap_or(0.5 * self.view(self.taker()).gripper.as_ref().map_or(0.06, |g| g.position));
        let below_tcp = geo::GRASP_DEPTH - self.handover_offset();
        let mut goals = geo::place_goals(radius, below_tcp, &self.box_heap());
        let spot = self.boxed as usize % geo::DROP_SPOTS;
        goals[..geo::DROP_SPOTS].rotate_left(spot);
        goals[geo::DROP_SPOTS..].rotate_left(spot);
        goals
    }

    /// The giver's way home and, where it can set off at once, the taker's way to the stand-off
    /// over the box: planned with the giver home, and checked against the giver's way in
    /// time. Both reported (the taker's as optional: it has the sequential way as fallback).
    fn plan_transfer_together(&mut self, t_ns: i64, bus: &mut Bus) -> (Result<Planned, String>, Option<Planned>) {
        let (giver, taker) = (self.giver(), self.taker());
        let (g0, t0) = (self.q(giver), self.q(taker));
        let home = self.motion.plan_home(giver, self.lift, g0, t0);
        self.record(giver, "home", &home, false, t_ns, bus);
        let Ok(home) = home else { return (home, None) };
        let goals = self.place_goals();
        let place = self
            .motion
            .plan_pregrasp_any(taker, self.lift, t0, &goals, geo::PLACE_DESCENT, home.goal_q)
            .map(|(_, p)| p)
            .and_then(|p| {
                if self.motion.trajectories_clear(taker, self.lift, &p, &home) {
                    Ok(p)
                } else {
                    Err("the way to the box meets the giver's way home".into())
                }
            });
        self.record(taker, "pregrasp", &place, true, t_ns, bus);
        (Ok(home), place.ok())
    }

    /// What lies in the harvest box by the planning scene (base frame): every sphere (centre,
    /// radius) and box (centre, half diagonal) centred inside it, the fruit in a hand aside.
    fn box_heap(&self) -> Vec<([f64; 3], f64)> {
        use agrisim_msgs::shape_msgs::SolidPrimitive;
        let (Some(scene), Some(p)) = (&self.scene, self.pose) else { return vec![] };
        let (s, c) = p.yaw.sin_cos();
        scene
            .objects
            .iter()
            .filter(|o| o.kind != "fruit_held")
            .filter_map(|o| {
                let d = &o.primitive.dimensions;
                let r = match o.primitive.r#type {
                    SolidPrimitive::SPHERE if !d.is_empty() => d[0],
                    SolidPrimitive::BOX if d.len() >= 3 => 0.5 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt(),
                    _ => return None,
                };
                let (dx, dy) = (o.pose.position.x - p.x, o.pose.position.y - p.y);
                let b = [c * dx + s * dy, -s * dx + c * dy, o.pose.position.z];
                geo::in_box(b).then_some((b, r))
            })
            .collect()
    }

    /// Opens the taker in the box, backs the open hand straight up out of it (where that can
    /// be planned; else the way home starts in the box) and judges where the fruit settled,
    /// on a target message sent after it did. -> done, or failed (placement).
    pub(super) fn run_release(&mut self, first: bool, t_ns: i64, bus: &mut Bus) {
        let taker = self.taker();
        if first {
            self.gripper(taker, geo::OPEN_WIDTH, GRASP_FORCE, t_ns, bus);
            self.motion.set_held(taker, None);
            self.release_ns = t_ns;
            return;
        }
        match self.phase_now() {
            0 if self.view(taker).gripper.as_ref().is_some_and(|g| g.position > geo::OPEN_WIDTH - 0.005) => {
                let tcp = self.motion.model(taker).fk(self.lift, &self.q(taker)).trans;
                let goal = TcpGoal { position: tcp, approach: [0.0, 0.0, 1.0], x_axis: None }.along(geo::PLACE_DESCENT);
                let (start, other) = (self.q(taker), self.q(taker.other()));
                let r = self.motion.plan_linear(taker, self.lift, start, &goal, other);
                self.record(taker, "linear", &r, true, t_ns, bus);
                self.phase = match r {
                    Ok(p) => {
                        self.send(taker, p, t_ns, bus);
                        1
                    }
                    Err(_) => 2,
                };
            }
            1 if self.arm_done(taker, t_ns, bus) == Some(true) => self.phase = 2,
            _ => {}
        }
        // Judge, once the hand is out of the box, on a target message sent after the fruit
        // settled.
        let settled_ns = self.release_ns + (SETTLE * 1e9) as i64;
        // A fruit the recovery put in the box is not this task's: on with the recovery.
        if self.rescuing && self.phase == 2 && t_ns >= settled_ns {
            self.boxed += 1;
            return self.enter(Stage::Recover, t_ns, bus, "the held fruit released into the box");
        }
        // By sight no camera looks into the box: the node takes the release as done (the
        // judge checks the box on ground truth).
        if self.region().is_some() && self.phase == 2 && t_ns >= settled_ns {
            return self.succeed(t_ns, bus, "fruit released into the box");
        }
        if self.phase == 2 && t_ns >= settled_ns && self.target_stamp_ns >= settled_ns {
            match self.target_base() {
                Some(p) if geo::in_box(p) => self.succeed(t_ns, bus, "fruit in the box"),
                Some(p) => self.fail(
                    Failure::Placement,
                    t_ns,
                    bus,
                    format!("fruit at ({:.3}, {:.3}, {:.3}) in base_link, not in the box", p[0], p[1], p[2]),
                ),
                None => {}
            }
        }
    }
}
