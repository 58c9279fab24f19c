//! The fruit's shape: round greenhouse tomatoes are slightly flattened, an oblate spheroid
//! about the vertical (the fruit hangs from its pedicel), of height / width (Tomato
//! Analyzer's fruit shape index: Brewer et al. 2006, J. Am. Soc. Hortic. Sci. 131) below 1.
//!
//! A sphere fitted to such a fruit's visible cap takes a radius between its polar and
//! equatorial radii, so it reads the fruit's width a few per cent small and places its centre
//! toward the camera. Stretching every point along the world's up by 1 / index maps the
//! spheroid onto the sphere of its equatorial radius, so the sphere fit runs on stretched
//! points and its centre is mapped back. The map is linear, so the camera stays at the
//! origin, as the fit assumes. The equatorial radius is also what a gripper must open for.

/// The stretch along the world's up that rounds an oblate fruit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spheroid {
    /// The world's up in the camera's frame (unit).
    up: [f64; 3],
    /// Height / width of the fruit (1: a sphere).
    index: f64,
}

impl Spheroid {
    /// `up` need not be unit; a zero `up` or an index outside (0.5, 1.5) gives a sphere.
    pub fn new(up: [f64; 3], index: f64) -> Spheroid {
        let n = (up[0] * up[0] + up[1] * up[1] + up[2] * up[2]).sqrt();
        let ok = n > 1e-9 && (0.5..1.5).contains(&index);
        Spheroid { up: if ok { up.map(|v| v / n) } else { [0.0, -1.0, 0.0] }, index: if ok { index } else { 1.0 } }
    }

    fn scale_up(&self, p: [f64; 3], s: f64) -> [f64; 3] {
        let h = (s - 1.0) * (p[0] * self.up[0] + p[1] * self.up[1] + p[2] * self.up[2]);
        [p[0] + h * self.up[0], p[1] + h * self.up[1], p[2] + h * self.up[2]]
    }

    /// A point of the camera's frame in the rounded space, where the fruit is a sphere.
    pub fn round(&self, p: [f64; 3]) -> [f64; 3] {
        self.scale_up(p, 1.0 / self.index)
    }

    /// A point of the rounded space back in the camera's frame.
    pub fn unround(&self, p: [f64; 3]) -> [f64; 3] {
        self.scale_up(p, self.index)
    }

    /// The least factor by which [`Self::round`] scales a distance (1 for an oblate fruit).
    pub fn least_stretch(&self) -> f64 {
        (1.0 / self.index).min(1.0)
    }

    /// The world's up (unit) in the camera's frame.
    pub fn up(&self) -> [f64; 3] {
        self.up
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_spheroid_surface_is_rounded_onto_its_equatorial_sphere() {
        let s = Spheroid::new([0.0, -2.0, 1.0], 0.85);
        let up = s.up();
        let (c, a) = ([0.1, -0.05, 0.7], 0.035);
        // An equatorial direction and the pole: both at distance a from the centre once rounded.
        let side = [1.0, 0.0, 0.0];
        let pole = up.map(|v| 0.85 * a * v);
        for off in [side.map(|v| a * v), pole] {
            let p = [c[0] + off[0], c[1] + off[1], c[2] + off[2]];
            let (rp, rc) = (s.round(p), s.round(c));
            let d = ((rp[0] - rc[0]).powi(2) + (rp[1] - rc[1]).powi(2) + (rp[2] - rc[2]).powi(2)).sqrt();
            assert!((d - a).abs() < 1e-12, "{d}");
        }
        let back = s.unround(s.round(c));
        assert!((0..3).all(|i| (back[i] - c[i]).abs() < 1e-12));
        assert_eq!(Spheroid::new([0.0; 3], 0.9).round(c), c);
        assert_eq!(Spheroid::new(up, 1.0).round(c), c);
        // No rounded distance is shorter than the least stretch of the distance.
        for k in [0.85, 1.0, 1.3] {
            let s = Spheroid::new([0.3, -1.0, 0.2], k);
            for d in [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.3, -1.0, 0.2], [0.5, 0.5, -0.7]] {
                let (r, n) = (s.round(d), (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt());
                let rn = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
                assert!(rn >= s.least_stretch() * n * (1.0 - 1e-12), "{k} {d:?}");
            }
        }
    }
}
