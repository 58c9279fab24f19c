//! Global planning pieces against independent references: A* against a brute-force
//! Dijkstra on random small grids (same move rules, written separately here), and the
//! inflation gradient (monotone, centred in an aisle).

use agrisim_math::Rng;
use agrisim_nav::astar::{astar, plan, PlannerConfig};
use agrisim_nav::costmap::{inflation_cost, GlobalCostmap, InflationConfig, INSCRIBED, LETHAL};
use agrisim_nav::map::{GridGeom, StaticMap};
use agrisim_nav::Pose2;

/// Reference: Dijkstra by repeated linear scan for the cheapest open cell (no heap, no
/// heuristic), 8-connected, diagonal moves need both side cells enterable.
fn dijkstra(w: usize, h: usize, res: f64, cost: &[u8], s: usize, g: usize, wt: f64) -> Option<f64> {
    let ok = |x: i64, y: i64| {
        x >= 0 && y >= 0 && (x as usize) < w && (y as usize) < h && cost[y as usize * w + x as usize] < INSCRIBED
    };
    let mut dist = vec![f64::INFINITY; w * h];
    let mut done = vec![false; w * h];
    dist[s] = 0.0;
    loop {
        let mut u = None;
        for i in 0..w * h {
            if !done[i] && dist[i].is_finite() && u.is_none_or(|j: usize| dist[i] < dist[j]) {
                u = Some(i);
            }
        }
        let u = u?;
        if u == g {
            return Some(dist[g]);
        }
        done[u] = true;
        let (x, y) = ((u % w) as i64, (u / w) as i64);
        for dx in -1i64..=1 {
            for dy in -1i64..=1 {
                if (dx, dy) == (0, 0) || !ok(x + dx, y + dy) {
                    continue;
                }
                if dx != 0 && dy != 0 && !(ok(x + dx, y) && ok(x, y + dy)) {
                    continue;
                }
                let v = (y + dy) as usize * w + (x + dx) as usize;
                let len = if dx != 0 && dy != 0 { 2f64.sqrt() } else { 1.0 } * res;
                let nd = dist[u] + len * (1.0 + wt * cost[v] as f64 / 252.0);
                if nd < dist[v] {
                    dist[v] = nd;
                }
            }
        }
    }
}

#[test]
fn astar_is_optimal_against_dijkstra() {
    let mut rng = Rng::new(7);
    let (mut compared, mut unreachable) = (0, 0);
    for trial in 0..300 {
        let (w, h) = (3 + rng.below(14) as usize, 3 + rng.below(14) as usize);
        let density = rng.below(40);
        let cost: Vec<u8> = (0..w * h)
            .map(|_| {
                if rng.below(100) < density {
                    if rng.below(2) == 0 {
                        LETHAL
                    } else {
                        INSCRIBED
                    }
                } else {
                    rng.below(253) as u8 * (rng.below(2) as u8)
                }
            })
            .collect();
        let free: Vec<usize> = (0..w * h).filter(|&i| cost[i] < INSCRIBED).collect();
        if free.len() < 2 {
            continue;
        }
        let s = free[rng.below(free.len() as u64) as usize];
        let g = free[rng.below(free.len() as u64) as usize];
        let wt = [0.0, 1.0, 3.0, 10.0][trial % 4];
        let res = 0.05;
        let a = astar(w, h, res, &cost, s, g, wt);
        let d = dijkstra(w, h, res, &cost, s, g, wt);
        match (a, d) {
            (Some(p), Some(dc)) => {
                assert!((p.cost - dc).abs() < 1e-9, "trial {trial}: A* {} vs Dijkstra {dc}", p.cost);
                // The returned cells are a valid path with that cost.
                assert_eq!((p.cells[0], *p.cells.last().unwrap()), (s, g));
                let mut c = 0.0;
                for pair in p.cells.windows(2) {
                    let (ax, ay, bx, by) = (pair[0] % w, pair[0] / w, pair[1] % w, pair[1] / w);
                    let (dx, dy) = (ax.abs_diff(bx), ay.abs_diff(by));
                    assert!(dx <= 1 && dy <= 1 && dx + dy > 0);
                    assert!(cost[pair[1]] < INSCRIBED);
                    c += if dx + dy == 2 { 2f64.sqrt() } else { 1.0 } * res * (1.0 + wt * cost[pair[1]] as f64 / 252.0);
                }
                assert!((c - p.cost).abs() < 1e-9);
                compared += 1;
            }
            (None, None) => unreachable += 1,
            (a, d) => panic!("trial {trial}: A* {a:?} vs Dijkstra {d:?}"),
        }
    }
    println!("A* = Dijkstra on {compared} reachable and {unreachable} unreachable random grids");
    assert!(compared > 150 && unreachable > 5);
}

#[test]
fn astar_is_deterministic() {
    // Open field, many equal-cost paths: the same one every time.
    let cost = vec![0u8; 30 * 30];
    let a = astar(30, 30, 0.05, &cost, 0, 30 * 30 - 1 - 5, 3.0).unwrap();
    for _ in 0..5 {
        assert_eq!(astar(30, 30, 0.05, &cost, 0, 30 * 30 - 1 - 5, 3.0).unwrap(), a);
    }
}

/// Two rows with a 2 m aisle between them (x along the aisle).
fn aisle_map() -> StaticMap {
    let geom = GridGeom { origin_x: 0.0, origin_y: 0.0, resolution: 0.05, width: 240, height: 80 };
    let mut occ = vec![false; geom.len()];
    for y in 0..80 {
        for x in 0..240 {
            let yy = y as f64 * 0.05;
            occ[y * 240 + x] = (!(0.5..2.5).contains(&yy) && (40..200).contains(&x)) || !(0.05..3.95).contains(&yy);
        }
    }
    StaticMap::from_cells(geom, occ, "map".into())
}

#[test]
fn inflation_gradient_is_monotone_and_centred() {
    let map = aisle_map();
    let cm = GlobalCostmap::new(&map, 0.45, InflationConfig::default());
    // Every cell's cost is the inflation function of its obstacle distance, and that
    // function never increases with distance.
    let mut pairs: Vec<(f32, u8)> = cm.distance.iter().copied().zip(cm.cost.iter().copied()).collect();
    for &(d, c) in &pairs {
        assert_eq!(c, inflation_cost(d as f64, 0.45, &InflationConfig::default()));
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    assert!(pairs.windows(2).all(|p| p[1].1 <= p[0].1));
    // Across the aisle: the cost falls to the centre and rises again, symmetric.
    let across: Vec<u8> = (10..50).map(|y| cm.cost[y * 240 + 120]).collect();
    let min_i = (0..across.len()).min_by_key(|&i| across[i]).unwrap();
    let centre_y = (10 + min_i) as f64 * 0.05 + 0.025;
    assert!((centre_y - 1.5).abs() <= 0.05, "cheapest cell at y = {centre_y}");
    for i in 0..across.len() / 2 {
        assert_eq!(across[i], across[across.len() - 1 - i]);
    }
    assert!(across[0] == INSCRIBED && cm.cost[9 * 240 + 120] == LETHAL && across[min_i] > 0 && across[min_i] < 100);
}

#[test]
fn plan_through_aisle_keeps_centre_and_reports_blocked_goal() {
    let map = aisle_map();
    let cm = GlobalCostmap::new(&map, 0.45, InflationConfig::default());
    let pts = plan(&cm, &Pose2::new(1.0, 1.0, 0.0), &Pose2::new(11.0, 2.0, 0.0), &PlannerConfig::default()).unwrap();
    let worst = pts.iter().filter(|p| p.0 > 3.0 && p.0 < 9.0).map(|p| (p.1 - 1.5).abs()).fold(0.0, f64::max);
    assert!(worst < 0.06, "path leaves the aisle centre by {worst} m");
    assert!(pts.windows(2).all(|s| (s[1].0 - s[0].0).hypot(s[1].1 - s[0].1) <= 0.05 + 1e-9));
    // Goal on a row: no path.
    assert!(plan(&cm, &Pose2::new(1.0, 1.0, 0.0), &Pose2::new(5.0, 0.3, 0.0), &PlannerConfig::default()).is_err());
}
