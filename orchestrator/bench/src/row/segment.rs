//! A row trial's segment: an aisle stretch of a given length, its reachable ripe fruit in
//! harvesting order, and where the robot starts.

use crate::harvest::targets::HarvestTarget;
use crate::harvest::HarvestSetup;
use agrisim_math::Rng;

/// The robot starts this far before the segment's first stand-off [m].
const LEAD_IN: f64 = 0.8;

/// One trial's segment: its aisle, extent, fruit in harvesting order and start pose.
#[derive(Debug, Clone)]
pub struct Segment {
    pub aisle_y: f64,
    pub x_range: [f64; 2],
    pub targets: Vec<HarvestTarget>,
    pub start: [f64; 3],
}

/// Draws a segment `length` m long: a uniformly chosen aisle with reachable ripe fruit,
/// a uniformly placed stretch of it within the reachable fruit's extent; its fruit (both
/// sides) in order along +x, the robot on the centre line before the first, facing +x.
pub fn draw_segment(setup: &HarvestSetup, length: f64, rng: &mut Rng) -> Option<Segment> {
    // Aisle centre lines, in order (every candidate of an aisle starts on the same one).
    let mut aisles: Vec<f64> = setup.candidates.iter().map(|t| t.start[1]).collect();
    aisles.sort_by(f64::total_cmp);
    aisles.dedup();
    if aisles.is_empty() {
        return None;
    }
    let aisle_y = aisles[((rng.uniform() * aisles.len() as f64) as usize).min(aisles.len() - 1)];
    let along: Vec<&HarvestTarget> = setup.candidates.iter().filter(|t| (t.start[1] - aisle_y).abs() < 1e-9).collect();
    let lo = along.iter().map(|t| t.center[0]).fold(f64::INFINITY, f64::min);
    let hi = along.iter().map(|t| t.center[0]).fold(f64::NEG_INFINITY, f64::max);
    let x0 = lo + (hi - lo - length).max(0.0) * rng.uniform();
    let x1 = x0 + length;
    let mut targets: Vec<HarvestTarget> =
        along.into_iter().filter(|t| (x0..x1).contains(&t.center[0])).cloned().collect();
    targets.sort_by(|a, b| a.center[0].total_cmp(&b.center[0]).then(a.fruit_index.cmp(&b.fruit_index)));
    let first = targets.first().map_or(x0, |t| agrisim_robot::reach::standoff(t.center, t.side)[0]);
    Some(Segment { aisle_y, x_range: [x0, x1], start: [first - LEAD_IN, aisle_y, 0.0], targets })
}
