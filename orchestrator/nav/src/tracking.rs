//! Where the robot is along its plan: the projection onto the path (searched forward from
//! the last one, so a path that folds back past itself, e.g. out of one aisle and into the
//! next, is not short-circuited), the carrot ahead for the controller, and what remains.

#[derive(Debug, Clone, Default)]
pub struct TrackedPath {
    pub points: Vec<(f64, f64)>,
    /// Arc length at each point [m].
    pub arc: Vec<f64>,
    /// Index of the current projection.
    pub index: usize,
}

impl TrackedPath {
    pub fn new(points: Vec<(f64, f64)>) -> TrackedPath {
        let mut arc = Vec::with_capacity(points.len());
        let mut s = 0.0;
        for i in 0..points.len() {
            if i > 0 {
                s += (points[i].0 - points[i - 1].0).hypot(points[i].1 - points[i - 1].1);
            }
            arc.push(s);
        }
        TrackedPath { points, arc, index: 0 }
    }

    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    pub fn length(&self) -> f64 {
        self.arc.last().copied().unwrap_or(0.0)
    }

    /// Moves the projection to the nearest point within `window` metres of arc ahead of the
    /// current one (and a little behind), and returns the robot's distance to it.
    pub fn project(&mut self, x: f64, y: f64, window: f64) -> f64 {
        if self.points.is_empty() {
            return f64::INFINITY;
        }
        let s0 = self.arc[self.index];
        let mut i = self.index;
        while i > 0 && s0 - self.arc[i - 1] <= 0.25 * window {
            i -= 1;
        }
        let (mut best, mut best_d) = (self.index, f64::INFINITY);
        while i < self.points.len() && self.arc[i] - s0 <= window {
            let d = (self.points[i].0 - x).hypot(self.points[i].1 - y);
            if d < best_d {
                best = i;
                best_d = d;
            }
            i += 1;
        }
        self.index = best;
        best_d
    }

    /// Arc length left from the projection to the end.
    pub fn remaining(&self) -> f64 {
        self.length() - self.arc.get(self.index).copied().unwrap_or(0.0)
    }

    /// Index of the point `ahead` metres of arc past the projection (the last one at most).
    pub fn index_ahead(&self, ahead: f64) -> usize {
        let target = self.arc[self.index] + ahead;
        let mut i = self.index;
        while i + 1 < self.points.len() && self.arc[i] < target {
            i += 1;
        }
        i
    }

    /// Direction of travel at point `i`.
    pub fn tangent(&self, i: usize) -> f64 {
        let n = self.points.len();
        let (a, b) = if i + 1 < n {
            (self.points[i], self.points[i + 1])
        } else if n >= 2 {
            (self.points[n - 2], self.points[n - 1])
        } else {
            return 0.0;
        };
        (b.1 - a.1).atan2(b.0 - a.0)
    }

    /// Points from the projection to `ahead` metres past it.
    pub fn ahead(&self, ahead: f64) -> &[(f64, f64)] {
        &self.points[self.index..=self.index_ahead(ahead)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projection_does_not_jump_to_a_parallel_leg() {
        // Out along y = 0, across, back along y = 2.5 (a U-turn between aisles).
        let mut pts: Vec<(f64, f64)> = (0..=100).map(|i| (10.0 - 0.1 * i as f64, 0.0)).collect();
        pts.extend((1..=25).map(|i| (0.0, 0.1 * i as f64)));
        pts.extend((1..=100).map(|i| (0.1 * i as f64, 2.5)));
        let mut t = TrackedPath::new(pts);
        // Robot near the start, but closer to the far leg's end than... it stays on leg one.
        let d = t.project(9.0, 1.3, 2.0);
        assert!(t.index <= 15 && (d - 1.3).abs() < 0.01, "index {} d {d}", t.index);
        assert!((t.length() - 22.5).abs() < 1e-9);
        assert!((t.remaining() - (22.5 - t.arc[t.index])).abs() < 1e-12);
        let i = t.index_ahead(1.0);
        assert!((t.arc[i] - t.arc[t.index] - 1.0).abs() < 0.11);
        assert!((t.tangent(0) - std::f64::consts::PI).abs() < 1e-9);
    }
}
