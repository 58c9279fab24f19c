//! Seeded harvest trials: which fruit to pick and where the robot starts.
//!
//! Like the paper's experiment, a trial's target is a ripe tomato the robot can see from an
//! aisle: USDA stage 5 or 6, on the aisle side of its row (not behind the stem), the first
//! fruit met when reaching in from the aisle (no other fruit between it and the aisle), at a
//! height the lift and arms cover, and away from the row ends. The robot starts on the
//! aisle's centre line, facing +x, 0.3-1.5 m short of the fruit, so every trial also has to
//! position the base. Only judging uses ground truth; the harvest node gets the target pose
//! from the world's `/target_fruit` message, as in the paper.

use agrisim_math::Rng;
use agrisim_greenhouse::{Kind, Layout, Object, Shape};

/// Lowest USDA ripeness stage that is harvested (5 light red, 6 red).
pub const RIPE_STAGE: u8 = 5;
/// Fruit centre heights the robot harvests [m]: lift 0-0.8 m with arms reaching about
/// 0.35 m below and 0.25 m above the shoulder (0.81 m at lift 0).
pub const HEIGHT_RANGE: (f64, f64) = (0.55, 1.75);
/// Minimum distance of the fruit centre from the row line toward the aisle [m]: fruit
/// closer to the stem are hidden behind it.
pub const MIN_AISLE_OFFSET: f64 = 0.1;
/// Distance kept from the row ends [m] (the base is 1.2 m long and stops 0.4 m short of
/// the fruit).
pub const ROW_END_MARGIN: f64 = 1.5;

/// One trial's target and start pose.
#[derive(Debug, Clone, PartialEq)]
pub struct HarvestTarget {
    /// Index into the world's fruit list (order of `/fruits`), the `target_fruit` input.
    pub fruit_index: usize,
    /// Scene object id (as in collision states and held ids).
    pub object_id: u32,
    pub name: String,
    pub center: [f64; 3],
    pub radius: f64,
    /// +1: the fruit's row is on the robot's left (+y), -1: on its right.
    pub side: f64,
    /// Start pose (x, y, yaw) of base_link in the map frame.
    pub start: [f64; 3],
}

/// The fruit a harvest trial may target, in fruit-list order.
pub fn eligible(objects: &[Object], layout: &Layout) -> Vec<HarvestTarget> {
    let fruits: Vec<(usize, &Object)> = objects.iter().filter(|o| matches!(o.kind, Kind::Fruit { .. })).enumerate().collect();
    let mut out = vec![];
    for &(index, o) in &fruits {
        let Kind::Fruit { ripeness } = o.kind else { continue };
        let Shape::Sphere { radius } = o.shape else { continue };
        let c = o.placement.translation;
        if ripeness < RIPE_STAGE || c[2] < HEIGHT_RANGE.0 || c[2] > HEIGHT_RANGE.1 {
            continue;
        }
        let Some(row) = layout.rows.iter().filter(|r| r.active).min_by(|a, b| (a.y - c[1]).abs().total_cmp(&(b.y - c[1]).abs())) else { continue };
        if c[0] < row.x_start + ROW_END_MARGIN || c[0] > row.x_end - ROW_END_MARGIN {
            continue;
        }
        let offset = c[1] - row.y;
        if offset.abs() < MIN_AISLE_OFFSET {
            continue;
        }
        // The aisle on the fruit's side must exist (the outer rows face a wall on one side).
        let toward = offset.signum();
        let Some(aisle) = layout.aisles.iter().find(|a| (a.y - row.y) * toward > 0.0 && (a.y - row.y).abs() <= a.width && a.x_start <= c[0] && c[0] <= a.x_end) else { continue };
        // Nothing else of the plant's fruit between this one and the aisle.
        let blocked = fruits.iter().any(|&(j, p)| {
            let Shape::Sphere { radius: rp } = p.shape else { return false };
            let q = p.placement.translation;
            j != index && (q[1] - row.y) * toward > offset * toward && (q[0] - c[0]).abs() < radius + rp && (q[2] - c[2]).abs() < radius + rp
        });
        if blocked {
            continue;
        }
        out.push(HarvestTarget { fruit_index: index, object_id: o.id, name: o.name.clone(), center: c, radius, side: -toward, start: [0.0, aisle.y, 0.0] });
    }
    out
}

/// Draws a trial: a uniformly chosen eligible fruit and a start 0.3-1.5 m behind the base
/// pose that reaches it (never before the aisle start).
pub fn draw(candidates: &[HarvestTarget], layout: &Layout, rng: &mut Rng) -> Option<HarvestTarget> {
    if candidates.is_empty() {
        return None;
    }
    let i = ((rng.uniform() * candidates.len() as f64) as usize).min(candidates.len() - 1);
    let mut t = candidates[i].clone();
    let aisle_start = layout.aisles.iter().filter(|a| (a.y - t.start[1]).abs() < 1e-9).map(|a| a.x_start).next().unwrap_or(f64::NEG_INFINITY);
    let back = 0.3 + 1.2 * rng.uniform();
    t.start[0] = (agrisim_harvest::geometry::standoff(t.center, t.side)[0] - back).max(aisle_start + 0.7);
    Some(t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use agrisim_greenhouse::{generate, GreenhouseConfig};

    #[test]
    fn default_greenhouse_has_many_eligible_fruit_all_facing_an_aisle() {
        let cfg = GreenhouseConfig::default();
        let g = generate(&cfg, cfg.seed);
        let c = eligible(&g.objects, &g.layout);
        assert!(c.len() >= 30, "only {} eligible fruit", c.len());
        for t in &c {
            let row = g.layout.rows.iter().filter(|r| r.active).min_by(|a, b| (a.y - t.center[1]).abs().total_cmp(&(b.y - t.center[1]).abs())).unwrap();
            // The robot's aisle is on the fruit's side of the row, and the fruit is ripe.
            assert!((t.start[1] - row.y) * (t.center[1] - row.y) > 0.0);
            assert_eq!(t.side, -(t.center[1] - row.y).signum());
            let o = g.objects.iter().find(|o| o.id == t.object_id).unwrap();
            assert!(matches!(o.kind, Kind::Fruit { ripeness } if ripeness >= RIPE_STAGE));
        }
        let mut rng = Rng::new(3);
        let a = draw(&c, &g.layout, &mut rng).unwrap();
        let mut rng = Rng::new(3);
        assert_eq!(draw(&c, &g.layout, &mut rng).unwrap(), a, "seeded");
        assert!(a.start[0] < a.center[0]);
    }
}
