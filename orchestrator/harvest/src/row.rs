//! The whole-row harvest: one [`HarvestNode`] taken through a row segment, moving the base
//! between picks. After each pick, successful or not, the node lets go of anything it holds
//! and brings both arms home before it selects the next ([`Stage::Recover`]). Every pick's
//! stages and outcome go to `/harvest/status`, as in the single-fruit task, so one judge
//! reads both.
//!
//! Two ways to be told the work:
//! * [`RowNode::new`]: the fruit to pick, in order (the world's fruit-list indices, as the
//!   paper hands over a target); their poses the node learns one at a time from
//!   `/target_fruit` (ground truth, for isolating manipulation);
//! * [`RowNode::by_sight`]: the segment as 1 m regions of row, and nothing else. In each
//!   region the node picks ripe fruit it finds itself ([`Task::Region`]) until its scan finds
//!   none left untried, or [`MAX_FAILURES_PER_REGION`] picks in a row fail there; then it
//!   drives on to the next region. When the last region is done it reports the outcome
//!   [`FINISHED`].

use super::node::{topics, HarvestNode, Task};
use super::sight::Region;
use super::stage::{Failure, Stage};
use agrisim_bus::{Bus, Node};
use agrisim_error::Result;
use agrisim_msgs::agrisim::HarvestStatus;
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::std_msgs::Header;

/// By sight: consecutive failed picks in one region after which the node moves on (each
/// failure's fruit is tried no more, but a region whose fruit all fail would otherwise take
/// the segment's whole time).
pub const MAX_FAILURES_PER_REGION: u32 = 3;
/// By sight: picks tried in one region at most (a region of a dense truss crop holds about
/// ten ripe fruit within reach).
pub const MAX_PICKS_PER_REGION: u32 = 16;
/// `/harvest/status` outcome of a row by sight once every region is done.
pub const FINISHED: &str = "finished";

/// The work of a row node.
enum Plan {
    /// Fruit-list indices, in order, and the index of the current one.
    Fruit { targets: Vec<usize>, current: usize },
    /// Regions in order, the current one, and the picks and consecutive failures in it.
    Regions { regions: Vec<Region>, current: usize, picks: u32, failures: u32, finished: bool },
}

pub struct RowNode {
    plan: Plan,
    inner: HarvestNode,
}

impl RowNode {
    /// Harvests `targets` (fruit-list indices) in this order; `seed` drives the planners.
    pub fn new(targets: Vec<usize>, seed: u64) -> RowNode {
        let first = targets.first().copied().unwrap_or(0);
        RowNode { plan: Plan::Fruit { targets, current: 0 }, inner: HarvestNode::new(first, seed) }
    }

    /// Harvests the ripe fruit it finds in `regions`, one region after the other.
    pub fn by_sight(regions: Vec<Region>, seed: u64) -> RowNode {
        let first = regions.first().copied().unwrap_or(Region { x: [0.0; 2], y: [0.0; 2], z: [0.0; 2] });
        RowNode {
            plan: Plan::Regions { regions, current: 0, picks: 1, failures: 0, finished: false },
            inner: HarvestNode::by_sight(first, seed).with_region_margin(super::sight::ROW_MARGIN),
        }
    }

    /// By sight, after a pick ended: the region to work in next, if any.
    fn next_region(&mut self) -> Option<Region> {
        let failure = self.inner.failure();
        let Plan::Regions { regions, current, picks, failures, .. } = &mut self.plan else { return None };
        *failures = if failure.is_some() { *failures + 1 } else { 0 };
        // Nothing left to pick there: none ripe, or none the hand opens round.
        let exhausted = matches!(failure, Some(Failure::NotDetected | Failure::TooWide));
        if exhausted || *failures >= MAX_FAILURES_PER_REGION || *picks >= MAX_PICKS_PER_REGION {
            *current += 1;
            (*picks, *failures) = (0, 0);
        }
        *picks += 1;
        regions.get(*current).copied()
    }
}

impl Node for RowNode {
    fn name(&self) -> &str {
        "harvest"
    }

    fn step(&mut self, t_ns: i64, bus: &mut Bus) -> Result<()> {
        let ended = matches!(self.inner.stage(), Stage::Done | Stage::Failed);
        match &mut self.plan {
            Plan::Fruit { targets, .. } if targets.is_empty() => return Ok(()),
            Plan::Fruit { targets, current } => {
                if ended && *current + 1 < targets.len() {
                    *current += 1;
                    let next = targets[*current];
                    self.inner.next_target(next, t_ns, bus);
                }
            }
            Plan::Regions { finished: true, .. } => return Ok(()),
            Plan::Regions { .. } if ended => match self.next_region() {
                Some(r) => self.inner.next_task(Task::Region(r), t_ns, bus),
                None => {
                    if let Plan::Regions { finished, regions, .. } = &mut self.plan {
                        *finished = true;
                        let msg = HarvestStatus {
                            header: Header { stamp: Time::from_nanos(t_ns), frame_id: "map".into() },
                            stage: Stage::Done.name().into(),
                            target_id: -1,
                            target_name: "row".into(),
                            outcome: FINISHED.into(),
                            failure_category: String::new(),
                            detail: format!("every one of the {} regions done", regions.len()),
                            plans: 0,
                        };
                        bus.publish(topics::STATUS, t_ns, &msg);
                    }
                    return Ok(());
                }
            },
            Plan::Regions { .. } => {}
        }
        self.inner.step(t_ns, bus)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry as geo;

    fn region(x: f64) -> Region {
        Region { x: [x, x + 1.0], y: [0.0, 1.0], z: [0.55, 1.75] }
    }

    /// A fruit-map entry: ripe (class "red"), 6 cm across, track `id` at `c`.
    fn ripe(id: &str, c: [f64; 3]) -> agrisim_msgs::vision_msgs::Detection3D {
        use agrisim_msgs::geometry_msgs::{Point, Pose, Quaternion, Vector3};
        use agrisim_msgs::vision_msgs::{BoundingBox3D, Detection3D, ObjectHypothesis, ObjectHypothesisWithPose};
        Detection3D {
            results: vec![ObjectHypothesisWithPose {
                hypothesis: ObjectHypothesis { class_id: "red".into(), score: 1.0 },
                ..Default::default()
            }],
            bbox: BoundingBox3D {
                center: Pose { position: Point { x: c[0], y: c[1], z: c[2] }, orientation: Quaternion::IDENTITY },
                size: Vector3 { x: 0.06, y: 0.06, z: 0.06 },
            },
            id: id.into(),
            ..Default::default()
        }
    }

    /// Regression (row by sight, 2026-11-29): after a pick the next region's task starts
    /// with the recovery (arms home, grippers open), as a next fruit's does; it used to go
    /// straight to SelectTarget, leaving the placing arm over the box.
    #[test]
    fn the_next_task_starts_with_the_recovery() {
        for by_sight in [true, false] {
            let mut row = if by_sight {
                RowNode::by_sight(vec![region(0.0), region(1.0)], 1)
            } else {
                RowNode::new(vec![3, 4], 1)
            };
            let mut bus = Bus::default();
            row.step(0, &mut bus).unwrap();
            assert_eq!(row.inner.stage(), Stage::SelectTarget);
            row.inner.stage = Stage::Done;
            row.step(100_000_000, &mut bus).unwrap();
            assert_eq!(row.inner.stage(), Stage::Recover, "by sight {by_sight}");
            row.step(200_000_000, &mut bus).unwrap();
            assert_eq!(row.inner.stage(), Stage::Recover, "by sight {by_sight}: the grippers open first");
        }
    }

    /// The recovery waits half a second for the grippers to open only when they were not
    /// both open already (told to open, and reading so): after a placed fruit both are, and
    /// the arms at home go straight on to the next fruit.
    #[test]
    fn the_recovery_waits_for_grippers_only_when_they_were_not_open() {
        use crate::motion::{Arm, HOME};
        use agrisim_msgs::agrisim::GripperState;
        use agrisim_msgs::sensor_msgs::JointState;
        // Steps (100 ms each) from a pick's end to the next fruit's selection, with the
        // grippers reading `width` wide throughout.
        let steps_to_select = |width: f64, rounds: usize| -> Vec<usize> {
            let mut row = RowNode::new(vec![3, 4, 5], 1);
            let mut bus = Bus::default();
            for arm in [Arm::Left, Arm::Right] {
                let js = JointState { name: arm.joint_names().to_vec(), position: HOME.to_vec(), ..Default::default() };
                bus.publish(&arm.topic("joint_states"), 0, &js);
                let g = GripperState { position: width, ..Default::default() };
                bus.publish(&arm.gripper_topic("state"), 0, &g);
            }
            row.step(0, &mut bus).unwrap();
            let mut t = 0;
            (0..rounds)
                .map(|_| {
                    row.inner.stage = Stage::Done;
                    let mut n = 0;
                    while row.inner.stage() != Stage::SelectTarget {
                        t += 100_000_000;
                        n += 1;
                        row.step(t, &mut bus).unwrap();
                        assert!(n < 50, "stuck in {:?}", row.inner.stage());
                    }
                    n
                })
                .collect()
        };
        // Not told to open before the first recovery: it waits; the second does not.
        let open = steps_to_select(geo::OPEN_WIDTH, 2);
        assert!(open[0] >= 6 && open[1] <= 2, "{open:?}");
        // Reading half closed: every recovery waits.
        let half = steps_to_select(0.03, 2);
        assert!(half.iter().all(|&n| n >= 6), "{half:?}");
    }

    /// Regression (row by sight, 2026-11-29): a fruit still in a gripper when the next task
    /// starts (its handover failed) is not let go where the arm is: the holder, as the
    /// taker, carries it into the box first; the other gripper opens as usual.
    #[test]
    fn the_recovery_puts_a_held_fruit_in_the_box_first() {
        use agrisim_bus::Reader;
        use agrisim_msgs::agrisim::GripperState;
        use agrisim_msgs::control_msgs::GripperCommand;
        for holder in ["left", "right"] {
            let mut row = RowNode::by_sight(vec![region(0.0), region(1.0)], 1);
            let mut bus = Bus::default();
            let mut commands = ["left", "right"].map(|a| Reader::new(&format!("/{a}_gripper/command")));
            row.step(0, &mut bus).unwrap();
            let held = GripperState { position: 0.05, effort: 20.0, stalled: true, ..Default::default() };
            bus.publish(&format!("/{holder}_gripper/state"), 50_000_000, &held);
            row.inner.stage = Stage::Done;
            row.step(100_000_000, &mut bus).unwrap();
            assert_eq!(row.inner.stage(), Stage::Transfer, "{holder} holds a fruit");
            let opened: Vec<usize> = (0..2)
                .filter(|&i| commands[i].take::<GripperCommand>(&mut bus).unwrap().iter().any(|c| c.position > 0.07))
                .collect();
            let other = if holder == "left" { 1 } else { 0 };
            assert_eq!(opened, vec![other], "only the free gripper opens ({holder} holds)");
            // The carry cannot be planned: the fruit is let go and the task goes on with its
            // recovery (it was failed before, and every later task tried the same rescue).
            row.inner.fail(Failure::Planning, 200_000_000, &mut bus, "start configuration in collision".into());
            assert_eq!((row.inner.stage(), row.inner.failure()), (Stage::Recover, None), "{holder}");
            row.step(300_000_000, &mut bus).unwrap();
            let opened: Vec<usize> = (0..2)
                .filter(|&i| commands[i].take::<GripperCommand>(&mut bus).unwrap().iter().any(|c| c.position > 0.07))
                .collect();
            assert_eq!(opened, vec![0, 1], "both grippers open after the failed rescue ({holder} held)");
            assert_eq!(row.inner.stage(), Stage::Recover, "{holder}");
        }
    }

    /// A row's later task takes a ripe fruit the fruit map already holds in its region from
    /// where the robot stands (-> position_base in the first step), where a run's first task
    /// scans; with none untried in the map, a later task scans too.
    #[test]
    fn a_later_task_takes_a_fruit_the_map_holds_without_a_scan() {
        use crate::motion::Arm;
        use crate::sight::topics::FRUIT_MAP;
        use agrisim_msgs::geometry_msgs::{Pose, PoseStamped};
        use agrisim_msgs::sensor_msgs::JointState;
        use agrisim_msgs::vision_msgs::Detection3DArray;
        // The stage after one step at SelectTarget, for a run's first task or a later one,
        // with a ripe fruit in the region's map at `fruit`.
        let first_step = |later: bool, fruit: [f64; 3]| -> Stage {
            let mut row = RowNode::by_sight(vec![region(0.0), region(1.0)], 1);
            let mut bus = Bus::default();
            let header = Header { frame_id: "map".into(), ..Default::default() };
            let map = Detection3DArray { header: header.clone(), detections: vec![ripe("7", fruit)] };
            bus.publish(FRUIT_MAP, 0, &map);
            bus.publish(topics::POSE, 0, &PoseStamped { header, pose: Pose::default() });
            for arm in [Arm::Left, Arm::Right] {
                let js = JointState { name: arm.joint_names().to_vec(), position: vec![0.0; 7], ..Default::default() };
                bus.publish(&arm.topic("joint_states"), 0, &js);
            }
            if later {
                row.inner.next_task(Task::Region(region(0.0)), 0, &mut bus);
                row.inner.stage = Stage::SelectTarget;
            }
            row.inner.step(100_000_000, &mut bus).unwrap();
            row.inner.stage()
        };
        let inside = [0.5, 0.5, 1.0];
        assert_eq!(first_step(false, inside), Stage::SelectTarget, "the first task scans");
        assert_eq!(first_step(true, inside), Stage::PositionBase, "a later task takes the fruit it knows");
        // Outside the region (along the row): the later task scans.
        assert_eq!(first_step(true, [1.5, 0.5, 1.0]), Stage::SelectTarget);
        // On the boundary with the next stretch, either side of it within the perception's
        // error: the row's margin takes it (an inward margin left it to neither stretch).
        assert_eq!(first_step(true, [0.995, 0.5, 1.0]), Stage::PositionBase);
        assert_eq!(first_step(true, [1.005, 0.5, 1.0]), Stage::PositionBase);
    }

    /// A target whose track the perception node drops (frames saw through it) while the base
    /// positions is chosen again from the map as it stands: the node aims at the fruit the
    /// map now holds, not at the dropped track's last estimate. A track that merely moves, or
    /// one that took the dropped one's place within its radius, is followed as before.
    #[test]
    fn a_dropped_target_track_is_chosen_again() {
        use crate::motion::Arm;
        use crate::sight::topics::{ALLOWED, FRUIT_MAP};
        use agrisim_bus::Reader;
        use agrisim_msgs::geometry_msgs::{Pose, PoseStamped};
        use agrisim_msgs::sensor_msgs::JointState;
        use agrisim_msgs::vision_msgs::{Detection3D, Detection3DArray};
        let header = Header { frame_id: "map".into(), ..Default::default() };
        let map = |d: Vec<Detection3D>| Detection3DArray { header: header.clone(), detections: d };
        // Where the node aims after the second map, the first holding fruit "7" at `a`.
        let aim_after = |second: Detection3DArray| -> [f64; 3] {
            let mut row = RowNode::by_sight(vec![region(0.0), region(1.0)], 1);
            let mut bus = Bus::default();
            let mut allowed = Reader::new(ALLOWED);
            bus.publish(FRUIT_MAP, 0, &map(vec![ripe("7", [0.5, 0.5, 1.0])]));
            bus.publish(topics::POSE, 0, &PoseStamped { header: header.clone(), pose: Pose::default() });
            for arm in [Arm::Left, Arm::Right] {
                let js = JointState { name: arm.joint_names().to_vec(), position: vec![0.0; 7], ..Default::default() };
                bus.publish(&arm.topic("joint_states"), 0, &js);
            }
            row.inner.next_task(Task::Region(region(0.0)), 0, &mut bus);
            row.inner.stage = Stage::SelectTarget;
            row.inner.step(100_000_000, &mut bus).unwrap();
            assert_eq!(row.inner.stage(), Stage::PositionBase);
            bus.publish(FRUIT_MAP, 150_000_000, &second);
            row.inner.step(200_000_000, &mut bus).unwrap();
            assert_eq!(row.inner.stage(), Stage::PositionBase);
            let sent = allowed.take::<Detection3DArray>(&mut bus).unwrap();
            let p = &sent.last().expect("an aim").detections[0].bbox.center.position;
            [p.x, p.y, p.z]
        };
        let near = |a: [f64; 3], b: [f64; 3]| (0..3).all(|i| (a[i] - b[i]).abs() < 1e-9);
        // Track 7 moved: followed.
        assert!(near(aim_after(map(vec![ripe("7", [0.51, 0.5, 1.0])])), [0.51, 0.5, 1.0]));
        // Dropped, another track within its radius: that one (the merge rule).
        assert!(near(aim_after(map(vec![ripe("8", [0.52, 0.5, 1.0])])), [0.52, 0.5, 1.0]));
        // Dropped, the region's fruit elsewhere: chosen again.
        assert!(near(aim_after(map(vec![ripe("9", [0.2, 0.5, 1.3])])), [0.2, 0.5, 1.3]));
        // Dropped, nothing in the region: the last estimate stays (nothing better is known).
        assert!(near(aim_after(map(vec![ripe("9", [1.7, 0.5, 1.3])])), [0.5, 0.5, 1.0]));
    }

    /// The region rule: stay while picks succeed, move on when the scan finds nothing, after
    /// MAX_FAILURES_PER_REGION failures in a row, or after MAX_PICKS_PER_REGION picks.
    #[test]
    fn regions_advance_on_nothing_found_repeated_failures_or_the_pick_cap() {
        let mut row = RowNode::by_sight(vec![region(0.0), region(1.0), region(2.0)], 1);
        let next = |row: &mut RowNode, f: Option<Failure>| {
            row.inner.failure = f;
            row.next_region().map(|r| r.x[0])
        };
        assert_eq!(next(&mut row, None), Some(0.0));
        assert_eq!(next(&mut row, Some(Failure::Planning)), Some(0.0));
        assert_eq!(next(&mut row, None), Some(0.0)); // a success resets the failure count
        assert_eq!(next(&mut row, Some(Failure::NotDetected)), Some(1.0));
        for _ in 1..MAX_FAILURES_PER_REGION {
            assert_eq!(next(&mut row, Some(Failure::Grasp)), Some(1.0));
        }
        assert_eq!(next(&mut row, Some(Failure::Grasp)), Some(2.0));
        for _ in 1..MAX_PICKS_PER_REGION {
            assert_eq!(next(&mut row, None), Some(2.0));
        }
        assert_eq!(next(&mut row, None), None);
    }
}
