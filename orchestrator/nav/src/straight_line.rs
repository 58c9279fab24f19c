//! A global planner for open ground: the straight segment from the robot to the goal, or an
//! error when the segment is not free. It never searches around an obstacle (that is what
//! A* is for), so in a field with nothing in the way it gives the shortest path at no search
//! cost, and elsewhere it fails honestly instead of driving into a row.
//!
//! The segment is checked as A*'s shortcuts are: sampled every quarter cell, and the robot
//! centre may not enter a cell at or above the inscribed cost. A start already inside an
//! inscribed zone (localization error, a newly sensed obstacle) may leave it through
//! non-lethal cells within `start_escape_radius`, as A* lets it.

use super::astar::PlannerConfig;
use super::costmap::{GlobalCostmap, LETHAL};
use super::global_planner::{densify, traversable, GlobalPlanner, PlanError};
use agrisim_math::pose2::Pose2;

/// The straight-line planner; of [`PlannerConfig`] it uses `path_spacing` and
/// `start_escape_radius`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StraightLine {
    pub cfg: PlannerConfig,
}

impl GlobalPlanner for StraightLine {
    fn plan(&mut self, costmap: &GlobalCostmap, start: &Pose2, goal: &Pose2) -> Result<Vec<(f64, f64)>, PlanError> {
        let geom = &costmap.geom;
        let s = geom.index_of(start.x, start.y).ok_or(PlanError::StartOutside)?;
        let g = geom.index_of(goal.x, goal.y).ok_or(PlanError::GoalOutside)?;
        if !traversable(costmap.cost[g]) {
            return Err(PlanError::GoalBlocked);
        }
        if costmap.cost[s] >= LETHAL {
            return Err(PlanError::StartBlocked);
        }
        let escaping = !traversable(costmap.cost[s]);
        let (a, b) = ((start.x, start.y), (goal.x, goal.y));
        let len = (b.0 - a.0).hypot(b.1 - a.1);
        let n = ((len / (0.25 * geom.resolution)).ceil() as usize).max(1);
        for i in 1..=n {
            let t = i as f64 / n as f64;
            let c = costmap.cost_at(a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1));
            let may_escape = escaping && c < LETHAL && t * len <= self.cfg.start_escape_radius;
            if !traversable(c) && !may_escape {
                return Err(PlanError::LineBlocked);
            }
        }
        Ok(densify(&[a, b], self.cfg.path_spacing))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::costmap::InflationConfig;
    use crate::map::{GridGeom, StaticMap};

    /// A 10 x 6 m walled field with a 1 m square post at (5, 3).
    fn field() -> GlobalCostmap {
        let geom = GridGeom { origin_x: 0.0, origin_y: 0.0, resolution: 0.05, width: 200, height: 120 };
        let occ = (0..geom.len())
            .map(|i| {
                let (x, y) = geom.center(i % geom.width, i / geom.width);
                x < 0.1 || y < 0.1 || x > 9.9 || y > 5.9 || ((x - 5.0).abs() < 0.5 && (y - 3.0).abs() < 0.5)
            })
            .collect();
        GlobalCostmap::new(&StaticMap::from_cells(geom, occ, "map".into()), 0.45, InflationConfig::default())
    }

    fn planner() -> StraightLine {
        StraightLine { cfg: PlannerConfig::default() }
    }

    #[test]
    fn a_free_line_is_one_straight_densified_segment_from_start_to_goal() {
        let cm = field();
        let (start, goal) = (Pose2::new(1.0, 1.0, 0.3), Pose2::new(8.5, 1.6, -2.0));
        let pts = planner().plan(&cm, &start, &goal).unwrap();
        assert!(pts.len() >= 2);
        assert_eq!((pts[0], *pts.last().unwrap()), ((1.0, 1.0), (8.5, 1.6)));
        let (dx, dy) = (7.5, 0.6);
        let len = f64::hypot(dx, dy);
        for p in &pts {
            // Distance of every point from the start-goal line.
            let off = ((p.0 - 1.0) * dy - (p.1 - 1.0) * dx).abs() / len;
            assert!(off < 1e-9, "{p:?} is {off} m off the line");
        }
        for w in pts.windows(2) {
            let step = (w[1].0 - w[0].0).hypot(w[1].1 - w[0].1);
            assert!(step > 0.0 && step <= PlannerConfig::default().path_spacing + 1e-12, "step {step}");
        }
    }

    #[test]
    fn a_line_through_the_post_or_along_a_wall_is_refused() {
        let cm = field();
        let through = planner().plan(&cm, &Pose2::new(1.0, 3.0, 0.0), &Pose2::new(9.0, 3.0, 0.0));
        assert_eq!(through, Err(PlanError::LineBlocked));
        // Only grazing the post's inscribed zone is refused too: the footprint would touch it.
        let grazing = planner().plan(&cm, &Pose2::new(1.0, 2.2, 0.0), &Pose2::new(9.0, 2.2, 0.0));
        assert_eq!(grazing, Err(PlanError::LineBlocked));
        let along_wall = planner().plan(&cm, &Pose2::new(1.0, 1.0, 0.0), &Pose2::new(1.0, 0.3, 0.0));
        assert_eq!(along_wall, Err(PlanError::GoalBlocked));
        let outside = planner().plan(&cm, &Pose2::new(1.0, 1.0, 0.0), &Pose2::new(12.0, 1.0, 0.0));
        assert_eq!(outside, Err(PlanError::GoalOutside));
    }

    #[test]
    fn a_start_inside_an_inscribed_zone_may_leave_it() {
        let cm = field();
        // 0.33 m from the post's edge (inscribed radius 0.45 m), heading away from it.
        let start = Pose2::new(5.83, 3.0, 0.0);
        assert!(!traversable(cm.cost_at(start.x, start.y)));
        let pts = planner().plan(&cm, &start, &Pose2::new(8.5, 3.0, 0.0)).unwrap();
        assert_eq!(*pts.last().unwrap(), (8.5, 3.0));
        // Not through the post, though.
        assert_eq!(planner().plan(&cm, &start, &Pose2::new(1.0, 3.0, 0.0)), Err(PlanError::LineBlocked));
    }
}
