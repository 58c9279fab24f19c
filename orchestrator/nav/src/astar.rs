//! Global planner: A* (Hart, Nilsson and Raphael, 1968) on the inflated costmap, 8-connected,
//! then cost-aware shortcutting of the staircase the grid produces.
//!
//! Moving into a cell costs its length times `1 + w * cost / 252`, so the inflation gradient
//! pulls the path to the middle of an aisle; cells at or above the inscribed cost are not
//! entered, and diagonal moves may not cut an obstacle's corner. The heuristic is the octile
//! distance (admissible: no move is cheaper than its length), and ties are broken by
//! (f, h, cell index), so the same costmap always gives the same path. [`AStar`] is the
//! [`GlobalPlanner`] the executor runs by default.

use super::costmap::{GlobalCostmap, LETHAL, MAX_NON_OBSTACLE};
use super::global_planner::{densify, traversable, GlobalPlanner, PlanError};
use super::map::GridGeom;
use agrisim_math::pose2::Pose2;
use serde::{Deserialize, Serialize};
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// The global planner's parameters (the last two serve every planner here).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct PlannerConfig {
    /// Weight w of the inflation cost against distance.
    pub cost_weight: f64,
    /// Shortcut the grid path (cost-aware: never through costlier cells).
    pub smooth: bool,
    /// Longest shortcut tried [m].
    pub max_shortcut: f64,
    /// Spacing of the published poses [m].
    pub path_spacing: f64,
    /// When the robot's own cell is within the inscribed zone (after localization error or a
    /// newly sensed obstacle), the planner may leave it through non-lethal cells up to this far [m].
    pub start_escape_radius: f64,
}

impl Default for PlannerConfig {
    fn default() -> Self {
        PlannerConfig {
            cost_weight: 3.0,
            smooth: true,
            max_shortcut: 3.0,
            path_spacing: 0.05,
            start_escape_radius: 0.6,
        }
    }
}

/// Cost of moving `len` metres into a cell of cost `c`.
pub fn step_cost(len: f64, c: u8, w: f64) -> f64 {
    len * (1.0 + w * c as f64 / MAX_NON_OBSTACLE as f64)
}

/// A grid path: cell indices from start to goal and its total cost.
#[derive(Debug, Clone, PartialEq)]
pub struct GridPath {
    pub cells: Vec<usize>,
    pub cost: f64,
}

#[derive(PartialEq)]
struct Open {
    f: f64,
    h: f64,
    cell: usize,
}

impl Eq for Open {}

impl Ord for Open {
    /// Max-heap order: smaller f first, then smaller h (closer to the goal), then smaller index.
    fn cmp(&self, o: &Self) -> Ordering {
        o.f.total_cmp(&self.f).then(o.h.total_cmp(&self.h)).then(o.cell.cmp(&self.cell))
    }
}

impl PartialOrd for Open {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

/// The 8 moves as (dx, dy, length in cells).
pub const MOVES: [(i64, i64, f64); 8] = [
    (1, 0, 1.0),
    (-1, 0, 1.0),
    (0, 1, 1.0),
    (0, -1, 1.0),
    (1, 1, std::f64::consts::SQRT_2),
    (1, -1, std::f64::consts::SQRT_2),
    (-1, 1, std::f64::consts::SQRT_2),
    (-1, -1, std::f64::consts::SQRT_2),
];

/// The neighbours of `cell` the planner may move to, with the move's cost (diagonals need
/// both side cells traversable).
pub fn neighbours(
    width: usize,
    height: usize,
    cost: &[u8],
    cell: usize,
    res: f64,
    w: f64,
    mut f: impl FnMut(usize, f64),
) {
    let (x, y) = ((cell % width) as i64, (cell / width) as i64);
    let ok = |cx: i64, cy: i64| {
        cx >= 0
            && cy >= 0
            && (cx as usize) < width
            && (cy as usize) < height
            && traversable(cost[cy as usize * width + cx as usize])
    };
    for &(dx, dy, len) in &MOVES {
        let (nx, ny) = (x + dx, y + dy);
        if !ok(nx, ny) || (dx != 0 && dy != 0 && !(ok(x + dx, y) && ok(x, y + dy))) {
            continue;
        }
        let n = ny as usize * width + nx as usize;
        f(n, step_cost(len * res, cost[n], w));
    }
}

/// Cheapest 8-connected path between two traversable cells, or `None`.
pub fn astar(
    width: usize,
    height: usize,
    res: f64,
    cost: &[u8],
    start: usize,
    goal: usize,
    w: f64,
) -> Option<GridPath> {
    let n = width * height;
    if start >= n || goal >= n || !traversable(cost[goal]) {
        return None;
    }
    let (gx, gy) = ((goal % width) as f64, (goal / width) as f64);
    let h = |c: usize| {
        let (dx, dy) = (((c % width) as f64 - gx).abs(), ((c / width) as f64 - gy).abs());
        res * (dx.max(dy) + (std::f64::consts::SQRT_2 - 1.0) * dx.min(dy))
    };
    let mut g = vec![f64::INFINITY; n];
    let mut parent = vec![u32::MAX; n];
    let mut closed = vec![false; n];
    let mut open = BinaryHeap::new();
    g[start] = 0.0;
    open.push(Open { f: h(start), h: h(start), cell: start });
    while let Some(Open { cell, .. }) = open.pop() {
        if closed[cell] {
            continue;
        }
        closed[cell] = true;
        if cell == goal {
            let mut cells = vec![goal];
            while *cells.last().unwrap() != start {
                cells.push(parent[*cells.last().unwrap()] as usize);
            }
            cells.reverse();
            return Some(GridPath { cells, cost: g[goal] });
        }
        let gc = g[cell];
        neighbours(width, height, cost, cell, res, w, |nb, c| {
            let ng = gc + c;
            if !closed[nb] && ng < g[nb] {
                g[nb] = ng;
                parent[nb] = cell as u32;
                let hn = h(nb);
                open.push(Open { f: ng + hn, h: hn, cell: nb });
            }
        });
    }
    None
}

/// Plans from `start` to `goal` (map frame) on the global costmap: map-frame waypoints,
/// start and goal positions exact.
pub fn plan(
    costmap: &GlobalCostmap,
    start: &Pose2,
    goal: &Pose2,
    cfg: &PlannerConfig,
) -> Result<Vec<(f64, f64)>, PlanError> {
    let geom = &costmap.geom;
    let (w, h) = (geom.width, geom.height);
    let s = geom.index_of(start.x, start.y).ok_or(PlanError::StartOutside)?;
    let g = geom.index_of(goal.x, goal.y).ok_or(PlanError::GoalOutside)?;
    if !traversable(costmap.cost[g]) {
        return Err(PlanError::GoalBlocked);
    }
    let mut prefix = Vec::new();
    let mut s_cell = s;
    if !traversable(costmap.cost[s]) {
        prefix = escape(geom, &costmap.cost, s, cfg.start_escape_radius).ok_or(PlanError::StartBlocked)?;
        s_cell = *prefix.last().unwrap();
        prefix.pop();
    }
    let gp = astar(w, h, geom.resolution, &costmap.cost, s_cell, g, cfg.cost_weight).ok_or(PlanError::Unreachable)?;
    let mut cells = prefix;
    cells.extend_from_slice(&gp.cells);
    let mut pts: Vec<(f64, f64)> = cells.iter().map(|&c| geom.center(c % w, c / w)).collect();
    pts[0] = (start.x, start.y);
    if pts.len() == 1 {
        pts.push((goal.x, goal.y));
    } else {
        *pts.last_mut().unwrap() = (goal.x, goal.y);
    }
    if cfg.smooth {
        pts = shortcut(costmap, &pts, cfg);
    }
    Ok(densify(&pts, cfg.path_spacing))
}

/// A* behind the [`GlobalPlanner`] seam.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AStar {
    pub cfg: PlannerConfig,
}

impl GlobalPlanner for AStar {
    fn plan(&mut self, costmap: &GlobalCostmap, start: &Pose2, goal: &Pose2) -> Result<Vec<(f64, f64)>, PlanError> {
        plan(costmap, start, goal, &self.cfg)
    }
}

/// Shortest way (Dijkstra on lengths, through non-lethal cells, within `radius`) from an
/// inscribed-zone cell to a traversable one.
fn escape(geom: &GridGeom, cost: &[u8], start: usize, radius: f64) -> Option<Vec<usize>> {
    let (w, h, res) = (geom.width, geom.height, geom.resolution);
    let (sx, sy) = ((start % w) as i64, (start / w) as i64);
    let r_cells = radius / res;
    let mut dist: std::collections::BTreeMap<usize, (f64, usize)> = std::collections::BTreeMap::new();
    let mut open = BinaryHeap::new();
    dist.insert(start, (0.0, start));
    open.push(Open { f: 0.0, h: 0.0, cell: start });
    while let Some(Open { f, cell, .. }) = open.pop() {
        if dist.get(&cell).is_some_and(|&(d, _)| d < f) {
            continue;
        }
        if traversable(cost[cell]) {
            let mut path = vec![cell];
            while *path.last().unwrap() != start {
                path.push(dist[path.last().unwrap()].1);
            }
            path.reverse();
            return Some(path);
        }
        let (x, y) = ((cell % w) as i64, (cell / w) as i64);
        for &(dx, dy, len) in &MOVES {
            let (nx, ny) = (x + dx, y + dy);
            if nx < 0
                || ny < 0
                || nx as usize >= w
                || ny as usize >= h
                || (((nx - sx).pow(2) + (ny - sy).pow(2)) as f64).sqrt() > r_cells
            {
                continue;
            }
            let nb = ny as usize * w + nx as usize;
            if cost[nb] >= LETHAL {
                continue;
            }
            let nd = f + len;
            if dist.get(&nb).is_none_or(|&(d, _)| nd < d) {
                dist.insert(nb, (nd, cell));
                open.push(Open { f: nd, h: 0.0, cell: nb });
            }
        }
    }
    None
}

/// Cost of the straight segment a->b (sampled at a quarter cell), or `None` if it crosses a
/// cell the robot centre may not enter.
fn segment_cost(costmap: &GlobalCostmap, a: (f64, f64), b: (f64, f64), w: f64) -> Option<f64> {
    let len = (b.0 - a.0).hypot(b.1 - a.1);
    let n = ((len / (0.25 * costmap.geom.resolution)).ceil() as usize).max(1);
    let ds = len / n as f64;
    let mut total = 0.0;
    for i in 1..=n {
        let t = i as f64 / n as f64;
        let c = costmap.cost_at(a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1));
        if !traversable(c) {
            return None;
        }
        total += step_cost(ds, c, w);
    }
    Some(total)
}

/// Greedy shortcutting: from each kept point, jump to the farthest later point (within
/// `max_shortcut`) whose straight segment is traversable and no costlier than the path it
/// replaces, so shortcuts never trade clearance for length.
fn shortcut(costmap: &GlobalCostmap, pts: &[(f64, f64)], cfg: &PlannerConfig) -> Vec<(f64, f64)> {
    let w = cfg.cost_weight;
    // Cost of the original polyline up to each point, measured like the segments.
    let mut acc = vec![0.0; pts.len()];
    for i in 1..pts.len() {
        acc[i] = acc[i - 1] + segment_cost(costmap, pts[i - 1], pts[i], w).unwrap_or(f64::INFINITY);
    }
    let mut out = vec![pts[0]];
    let mut i = 0;
    while i + 1 < pts.len() {
        let mut best = i + 1;
        let mut j = i + 2;
        while j < pts.len() {
            let d = (pts[j].0 - pts[i].0).hypot(pts[j].1 - pts[i].1);
            if d > cfg.max_shortcut {
                break;
            }
            if let Some(c) = segment_cost(costmap, pts[i], pts[j], w) {
                if c <= acc[j] - acc[i] + 1e-9 {
                    best = j;
                }
            }
            j += 1;
        }
        out.push(pts[best]);
        i = best;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::costmap::InflationConfig;
    use crate::map::StaticMap;

    #[test]
    fn straight_line_and_walls() {
        let (w, h) = (10, 5);
        let mut cost = vec![0u8; w * h];
        let p = astar(w, h, 1.0, &cost, 0, 9, 0.0).unwrap();
        assert_eq!(p.cells.len(), 10);
        assert!((p.cost - 9.0).abs() < 1e-12);
        for y in 0..4 {
            cost[y * w + 5] = LETHAL;
        }
        let p = astar(w, h, 1.0, &cost, 0, 9, 0.0).unwrap();
        assert!(p.cells.contains(&(4 * w + 5)));
        cost[4 * w + 5] = LETHAL;
        assert!(astar(w, h, 1.0, &cost, 0, 9, 0.0).is_none());
    }

    #[test]
    fn planned_path_stays_clear_and_centred() {
        // A 2 m corridor between two walls along x: the path runs down the middle.
        let geom = GridGeom { origin_x: 0.0, origin_y: 0.0, resolution: 0.05, width: 200, height: 60 };
        let mut occ = vec![false; geom.len()];
        for x in 0..200 {
            for y in (0..10).chain(50..60) {
                occ[y * 200 + x] = true;
            }
        }
        let map = StaticMap::from_cells(geom, occ, "map".into());
        let cm = GlobalCostmap::new(&map, 0.45, InflationConfig::default());
        let pts = plan(&cm, &Pose2::new(1.0, 1.3, 0.0), &Pose2::new(9.0, 1.7, 0.0), &PlannerConfig::default()).unwrap();
        assert!(pts.iter().all(|&(x, y)| traversable(cm.cost_at(x, y))));
        let mid = pts.iter().filter(|p| p.0 > 3.0 && p.0 < 7.0).map(|p| (p.1 - 1.5).abs()).fold(0.0, f64::max);
        assert!(mid < 0.06, "path leaves the aisle centre by {mid}");
        let len: f64 = pts.windows(2).map(|s| (s[1].0 - s[0].0).hypot(s[1].1 - s[0].1)).sum();
        assert!(len < 8.3, "smoothed length {len}");
    }
}
