//! A row trial's segment: an aisle stretch of a given length, its reachable ripe fruit in
//! harvesting order, and where the robot starts.

use crate::harvest::targets::{HarvestTarget, HEIGHT_RANGE};
use crate::harvest::HarvestSetup;
use agrisim_harvest::sight::Region;
use agrisim_math::Rng;
use agrisim_scene::Layout;

/// By sight, the segment is handed over as stretches of row this long [m] (as the harvest
/// benchmark's task by sight).
pub const REGION_LENGTH: f64 = 1.0;

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

/// The task of a row harvest by sight: the segment's stretches of [`REGION_LENGTH`] along
/// +x, at each the row on the left (+y) then the one on the right, each from its plant line
/// to the aisle's centre line, at the harvestable heights. Nothing of the fruit is in it.
pub fn regions_of(seg: &Segment, layout: &Layout) -> Vec<Region> {
    let rows: Vec<f64> = layout.rows.iter().filter(|r| r.active).map(|r| r.y).collect();
    let nearest = |side: f64| {
        rows.iter()
            .copied()
            .filter(|y| (y - seg.aisle_y) * side > 0.0)
            .min_by(|a, b| (a - seg.aisle_y).abs().total_cmp(&(b - seg.aisle_y).abs()))
    };
    let sides: Vec<f64> = [1.0, -1.0].into_iter().filter_map(nearest).collect();
    let [x0, x1] = seg.x_range;
    let n = ((x1 - x0) / REGION_LENGTH - 1e-9).ceil().max(1.0) as usize;
    (0..n)
        .flat_map(|k| {
            let x = [x0 + k as f64 * REGION_LENGTH, (x0 + (k + 1) as f64 * REGION_LENGTH).min(x1)];
            sides.iter().map(move |&row_y| Region {
                x,
                y: [row_y.min(seg.aisle_y), row_y.max(seg.aisle_y)],
                z: [HEIGHT_RANGE.0, HEIGHT_RANGE.1],
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use agrisim_scene::layout::Row;

    fn row(index: usize, y: f64, active: bool) -> Row {
        Row { index, y, x_start: 0.0, x_end: 30.0, width: 0.6, active }
    }

    /// Stretches of REGION_LENGTH along the segment (the last one shorter), each on the
    /// nearest active row to the left then to the right, from its plant line to the aisle line.
    #[test]
    fn a_segment_is_handed_over_as_stretches_of_both_rows() {
        let layout = Layout {
            bounds: [0.0, 0.0, 30.0, 10.0],
            rows: vec![row(0, 1.0, true), row(1, 2.3, true), row(2, 3.6, false)],
            aisles: vec![],
            headland: [0.0; 4],
            start_pose: [0.0; 3],
        };
        let seg = Segment { aisle_y: 1.65, x_range: [4.0, 6.5], targets: vec![], start: [3.0, 1.65, 0.0] };
        let r = regions_of(&seg, &layout);
        assert_eq!(r.len(), 6);
        assert_eq!(r[0].x, [4.0, 5.0]);
        assert_eq!(r[0].y, [1.65, 2.3]); // left (+y) first
        assert_eq!(r[1].y, [1.0, 1.65]);
        assert_eq!(r[4].x, [6.0, 6.5]);
        assert!(r.iter().all(|g| g.z == [HEIGHT_RANGE.0, HEIGHT_RANGE.1]));
        // The outer aisle beside an inactive row: only the active side.
        let outer = Segment { aisle_y: 2.95, ..seg };
        let r = regions_of(&outer, &layout);
        assert_eq!(r.len(), 3);
        assert!(r.iter().all(|g| g.y == [2.3, 2.95]));
    }
}
