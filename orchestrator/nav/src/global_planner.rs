//! The global planner seam (Nav2's `nav2_core::GlobalPlanner`): a path from the robot to the
//! goal on the global costmap, so another planner can replace A* without touching the
//! executor. Also what every planner's output shares: where the robot centre may go, the
//! spacing of the published poses, and the nav_msgs/Path it is published as.

use super::costmap::{GlobalCostmap, INSCRIBED};
use agrisim_math::pose2::Pose2;
use agrisim_msgs::geometry_msgs::PoseStamped;
use agrisim_msgs::nav_msgs::Path;
use agrisim_msgs::std_msgs::Header;

/// Why no path came out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlanError {
    StartOutside,
    GoalOutside,
    /// The goal cell is an obstacle or within the inscribed radius of one.
    GoalBlocked,
    /// The start is boxed in beyond the escape radius.
    StartBlocked,
    /// Search exhausted.
    Unreachable,
    /// The straight line to the goal crosses an obstacle or its inscribed zone (a planner
    /// that draws only straight lines).
    LineBlocked,
}

/// A global planner behind the executor.
pub trait GlobalPlanner: Send {
    /// Map-frame waypoints from `start` to `goal` on `costmap`: the first point is the start
    /// position and the last the goal position, exactly; consecutive points at most the
    /// planner's spacing apart (the controller's carrot and path distance read them).
    fn plan(&mut self, costmap: &GlobalCostmap, start: &Pose2, goal: &Pose2) -> Result<Vec<(f64, f64)>, PlanError>;
}

/// May the robot centre be in a cell of cost `c`? Not at or above the inscribed cost, where
/// the footprint would touch an obstacle.
pub fn traversable(c: u8) -> bool {
    c < INSCRIBED
}

/// Points along the polyline at most `spacing` apart, the vertices kept.
pub fn densify(pts: &[(f64, f64)], spacing: f64) -> Vec<(f64, f64)> {
    let mut out = vec![pts[0]];
    for k in 1..pts.len() {
        let (a, b) = (pts[k - 1], pts[k]);
        let n = (((b.0 - a.0).hypot(b.1 - a.1)) / spacing).ceil().max(1.0) as usize;
        for i in 1..=n {
            let t = i as f64 / n as f64;
            out.push((a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1)));
        }
    }
    out
}

/// The plan as nav_msgs/Path: each pose faces along the path; the last takes `goal_yaw` if given.
pub fn to_path_msg(pts: &[(f64, f64)], goal_yaw: Option<f64>, header: &Header) -> Path {
    let mut poses = Vec::with_capacity(pts.len());
    for i in 0..pts.len() {
        let (a, b) = if i + 1 < pts.len() {
            (pts[i], pts[i + 1])
        } else if i > 0 {
            (pts[i - 1], pts[i])
        } else {
            (pts[i], pts[i])
        };
        let mut yaw = (b.1 - a.1).atan2(b.0 - a.0);
        if i + 1 == pts.len() {
            if let Some(gy) = goal_yaw {
                yaw = gy;
            }
        }
        poses.push(PoseStamped { header: header.clone(), pose: Pose2::new(pts[i].0, pts[i].1, yaw).into() });
    }
    Path { header: header.clone(), poses }
}
