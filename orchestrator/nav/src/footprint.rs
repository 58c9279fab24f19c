//! The robot's footprint: a rectangle centred on base_link. The omni base can drive sideways,
//! so no single circle describes it: the planner keeps the centre an inscribed radius (half
//! the width) away from obstacles, and the controller checks the oriented rectangle's outline.

use agrisim_math::pose2::Pose2;
use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Footprint {
    /// Along base_link x [m].
    pub length: f64,
    /// Along base_link y [m].
    pub width: f64,
}

impl Default for Footprint {
    fn default() -> Self {
        Footprint { length: 1.2, width: 0.9 }
    }
}

impl Footprint {
    /// Largest circle inside the rectangle: the lateral clearance the centre needs.
    pub fn inscribed_radius(&self) -> f64 {
        0.5 * self.length.min(self.width)
    }

    /// Smallest circle around the rectangle: the room needed to turn in place.
    pub fn circumscribed_radius(&self) -> f64 {
        0.5 * self.length.hypot(self.width)
    }

    /// Points on the outline (base frame), at most `spacing` apart, corners included, in a
    /// fixed order.
    pub fn outline(&self, spacing: f64) -> Vec<(f64, f64)> {
        let (hx, hy) = (0.5 * self.length, 0.5 * self.width);
        let corners = [(hx, hy), (-hx, hy), (-hx, -hy), (hx, -hy)];
        let mut pts = Vec::new();
        for k in 0..4 {
            let (a, b) = (corners[k], corners[(k + 1) % 4]);
            let len = (b.0 - a.0).hypot(b.1 - a.1);
            let n = (len / spacing).ceil().max(1.0) as usize;
            for i in 0..n {
                let t = i as f64 / n as f64;
                pts.push((a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1)));
            }
        }
        pts
    }

    /// Is a base-frame point inside the rectangle grown by `margin`?
    pub fn contains(&self, px: f64, py: f64, margin: f64) -> bool {
        px.abs() <= 0.5 * self.length + margin && py.abs() <= 0.5 * self.width + margin
    }

    /// Smallest obstacle distance over the outline at `pose`, with `dist` the distance field
    /// of an obstacle map (map-frame lookup).
    pub fn clearance(outline: &[(f64, f64)], pose: &Pose2, mut dist: impl FnMut(f64, f64) -> f64) -> f64 {
        let (s, c) = pose.yaw.sin_cos();
        let mut best = f64::INFINITY;
        for &(px, py) in outline {
            let d = dist(pose.x + c * px - s * py, pose.y + s * px + c * py);
            if d < best {
                best = d;
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radii_and_outline() {
        let f = Footprint::default();
        assert!((f.inscribed_radius() - 0.45).abs() < 1e-12);
        assert!((f.circumscribed_radius() - 0.75).abs() < 1e-12);
        let o = f.outline(0.05);
        assert!(o.len() >= 84);
        assert!(o.iter().all(|&(x, y)| f.contains(x, y, 1e-9) && !f.contains(x, y, -1e-9)));
        for w in o.windows(2) {
            assert!((w[0].0 - w[1].0).hypot(w[0].1 - w[1].1) <= 0.05 + 1e-9);
        }
    }
}
