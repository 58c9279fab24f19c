//! The navigable structure of the greenhouse, as numbers the navigation stack and the
//! benchmark use directly (rather than re-deriving it from the geometry): where the rows are,
//! which aisles are goals, where the headland is and where the robot starts.

use crate::config::GreenhouseConfig;

/// A plant row: its line at `y`, from `x_start` to `x_end` (map frame).
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub index: usize,
    pub y: f64,
    pub x_start: f64,
    pub x_end: f64,
    /// Width of the foliage envelope (every plant part stays inside it), centred on `y` [m].
    pub width: f64,
    /// Active rows take part in experiments; inactive rows are geometry only.
    pub active: bool,
}

/// A drivable aisle between two neighbouring active rows; `width` is the free space between
/// their foliage envelopes, centred on `y`.
#[derive(Clone, Debug, PartialEq)]
pub struct Aisle {
    pub index: usize,
    pub y: f64,
    pub x_start: f64,
    pub x_end: f64,
    pub width: f64,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Layout {
    /// xmin, ymin, xmax, ymax of the floor inside the walls.
    pub bounds: [f64; 4],
    pub rows: Vec<Row>,
    pub aisles: Vec<Aisle>,
    /// xmin, ymin, xmax, ymax of the headland path in front of the rows (x < row start).
    pub headland: [f64; 4],
    /// x, y, yaw: in the headland, facing +x toward aisle 0.
    pub start_pose: [f64; 3],
}

impl Layout {
    /// The layout a (validated) configuration describes. Rows are centred across the hall.
    pub fn from_config(cfg: &GreenhouseConfig) -> Layout {
        let pitch = cfg.row_pitch();
        let y0 = 0.5 * (cfg.width - (cfg.rows as f64 - 1.0) * pitch);
        let x_start = cfg.headland;
        let x_end = x_start + cfg.row_length;
        let active = cfg.first_active_row..cfg.first_active_row + cfg.active_rows;
        let rows: Vec<Row> = (0..cfg.rows)
            .map(|i| Row {
                index: i,
                y: y0 + i as f64 * pitch,
                x_start,
                x_end,
                width: cfg.row_width,
                active: active.contains(&i),
            })
            .collect();
        let act: Vec<&Row> = rows.iter().filter(|r| r.active).collect();
        let aisles: Vec<Aisle> = act
            .windows(2)
            .enumerate()
            .map(|(i, w)| Aisle { index: i, y: 0.5 * (w[0].y + w[1].y), x_start, x_end, width: cfg.aisle_width })
            .collect();
        let half = 0.5 * cfg.row_width;
        let (y_lo, y_hi) = match (act.first(), act.last()) {
            (Some(a), Some(b)) => (a.y - half, b.y + half),
            _ => (0.0, cfg.width),
        };
        let y_start = match (aisles.first(), act.first()) {
            (Some(a), _) => a.y,
            (None, Some(r)) => r.y + 0.5 * pitch,
            _ => 0.5 * cfg.width,
        };
        Layout {
            bounds: [0.0, 0.0, cfg.length, cfg.width],
            rows,
            aisles,
            headland: [0.0, y_lo.max(0.0), x_start, y_hi.min(cfg.width)],
            start_pose: [0.5 * x_start, y_start, 0.0],
        }
    }
}
