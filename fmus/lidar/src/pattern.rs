//! The non-repetitive scan pattern: where the n-th point of the sensor's life looks.
//!
//! Model (after the structure of Livox's published MID-360 pattern table, see
//! [`crate::datasheet`]): the head spins; every firing sends `BEAMS` beams whose fan, 2.8 deg
//! between neighbours, turns with the head (vertical at one azimuth, flat a quarter turn later,
//! vertical and reversed half a turn later, as in the table);
//! the head advances 1.3 deg per firing, so one revolution is 276.9 firings and successive
//! revolutions interleave instead of retracing. The fan centre sweeps the vertical field of
//! view up and down linearly (a triangle wave; beams that overshoot a limit fold back into the
//! field), which gives a point density uniform in elevation (per unit solid angle it grows as
//! 1/cos(elevation)).
//!
//! The table's rows are a sequence without timing, so the sweep speed is ours: 16.18 Hz
//! (10 Hz x the golden ratio) makes every 0.1 s frame span the whole vertical field at least
//! once, and being irrational against both the head rotation and the frame rate it never
//! lines up with either: each frame lands on new directions and coverage keeps growing with
//! integration time (the MID-360's selling point). Everything is a function of the global
//! point index n = time x point rate, so the pattern advances with simulation time and does
//! not depend on the co-simulation step.

use crate::datasheet as ds;
use std::f64::consts::TAU;

/// Vertical sweep frequency (one up-and-down cycle) [Hz]: 10 x the golden ratio.
pub const SWEEP_FREQUENCY: f64 = 10.0 * 1.618_033_988_749_895;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScanPattern {
    pub point_rate: f64,
    /// Elevation limits [rad].
    pub elevation_min: f64,
    pub elevation_max: f64,
    pub beams: usize,
    /// Angle between neighbouring beams along the fan [rad].
    pub beam_spacing: f64,
    /// Head azimuth advance per firing [rad].
    pub azimuth_step: f64,
    pub sweep_frequency: f64,
}

impl ScanPattern {
    /// The MID-360 pattern at `point_rate` within the elevation limits (rad).
    pub fn mid360(point_rate: f64, elevation_min: f64, elevation_max: f64) -> ScanPattern {
        ScanPattern {
            point_rate,
            elevation_min,
            elevation_max,
            beams: ds::BEAMS,
            beam_spacing: ds::BEAM_SPACING_DEG.to_radians(),
            azimuth_step: ds::AZIMUTH_STEP_DEG.to_radians(),
            sweep_frequency: SWEEP_FREQUENCY,
        }
    }

    /// Time of point n's firing [s] (the beams of one firing share it).
    pub fn time(&self, n: i64) -> f64 {
        let b = self.beams as i64;
        (n.div_euclid(b) * b) as f64 / self.point_rate
    }

    /// Beam (0..beams) of point n.
    pub fn beam(&self, n: i64) -> usize {
        n.rem_euclid(self.beams as i64) as usize
    }

    /// (azimuth, elevation) of point n in the sensor frame [rad]; azimuth in [0, 2 pi) up to
    /// the fan offset.
    pub fn angles(&self, n: i64) -> (f64, f64) {
        let b = self.beams as i64;
        self.beam_angles(&self.firing(n.div_euclid(b)), self.beam(n))
    }

    /// What the beams of firing `f` (points f * beams ..) share, computed once for all of them.
    pub fn firing(&self, f: i64) -> Firing {
        let b = self.beams as i64;
        let time = (f * b) as f64 / self.point_rate;
        let head = (f as f64 * self.azimuth_step).rem_euclid(TAU);
        let u = (time * self.sweep_frequency).rem_euclid(1.0);
        let (lo, hi) = (self.elevation_min, self.elevation_max);
        let centre = lo + (hi - lo) * (1.0 - (2.0 * u - 1.0).abs());
        let (sin, cos) = head.sin_cos();
        Firing { time, head, sin, cos, centre }
    }

    /// (azimuth, elevation) of beam `beam` of a firing.
    pub fn beam_angles(&self, f: &Firing, beam: usize) -> (f64, f64) {
        let (lo, hi) = (self.elevation_min, self.elevation_max);
        let offset = (beam as f64 - 0.5 * (self.beams - 1) as f64) * self.beam_spacing;
        let mut elevation = f.centre + offset * f.cos;
        // Fold overshoot back into the field (the spacing is far below its height).
        if elevation > hi {
            elevation = (2.0 * hi - elevation).max(lo);
        } else if elevation < lo {
            elevation = (2.0 * lo - elevation).min(hi);
        }
        // The fan's sideways offset is an angle on the sphere: wider in azimuth when raised.
        let azimuth = f.head + offset * f.sin / elevation.cos().max(0.1);
        (azimuth, elevation)
    }

    /// Unit direction of point n in the sensor frame (x forward, z up).
    pub fn direction(&self, n: i64) -> [f64; 3] {
        let b = self.beams as i64;
        self.beam_direction(&self.firing(n.div_euclid(b)), self.beam(n))
    }

    /// Unit direction of beam `beam` of a firing in the sensor frame.
    pub fn beam_direction(&self, f: &Firing, beam: usize) -> [f64; 3] {
        let (az, el) = self.beam_angles(f, beam);
        let (sa, ca) = az.sin_cos();
        let (se, ce) = el.sin_cos();
        [ce * ca, ce * sa, se]
    }
}

/// One firing of the head: its time [s], head azimuth [rad] with its sine and cosine, and the
/// fan centre's elevation [rad].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Firing {
    pub time: f64,
    pub head: f64,
    pub sin: f64,
    pub cos: f64,
    pub centre: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pattern() -> ScanPattern {
        ScanPattern::mid360(
            ds::POINT_RATE,
            ds::FOV_ELEVATION_MIN_DEG.to_radians(),
            ds::FOV_ELEVATION_MAX_DEG.to_radians(),
        )
    }

    /// Fraction of 1 deg x 1 deg (azimuth x elevation) cells of the field hit by points
    /// [n0, n0 + count).
    pub fn coverage(p: &ScanPattern, n0: i64, count: i64) -> f64 {
        let rows = (ds::FOV_ELEVATION_MAX_DEG - ds::FOV_ELEVATION_MIN_DEG).round() as usize;
        let mut hit = vec![false; 360 * rows];
        for n in n0..n0 + count {
            let (az, el) = p.angles(n);
            let a = (az.to_degrees().rem_euclid(360.0) as usize).min(359);
            let e = ((el.to_degrees() - ds::FOV_ELEVATION_MIN_DEG) as usize).min(rows - 1);
            hit[e * 360 + a] = true;
        }
        hit.iter().filter(|h| **h).count() as f64 / hit.len() as f64
    }

    #[test]
    fn every_direction_stays_in_the_field_of_view() {
        let p = pattern();
        for n in (0..2_000_000).step_by(7) {
            let (_, el) = p.angles(n);
            assert!((p.elevation_min..=p.elevation_max).contains(&el), "n {n}: {el}");
            let d = p.direction(n);
            assert!((d[0] * d[0] + d[1] * d[1] + d[2] * d[2] - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn each_frame_spans_the_vertical_field_and_frames_differ() {
        let p = pattern();
        let per_frame = 20_000;
        for f in 0..20 {
            let (mut lo, mut hi) = (f64::MAX, f64::MIN);
            for n in f * per_frame..(f + 1) * per_frame {
                let el = p.angles(n).1.to_degrees();
                lo = lo.min(el);
                hi = hi.max(el);
            }
            assert!(lo < -6.0 && hi > 51.0, "frame {f}: {lo}..{hi}");
            let a: Vec<_> = (0..100).map(|i| p.angles(f * per_frame + i)).collect();
            let b: Vec<_> = (0..100).map(|i| p.angles((f + 1) * per_frame + i)).collect();
            assert_ne!(a, b);
        }
    }

    #[test]
    fn coverage_grows_with_integration_time() {
        let p = pattern();
        let c01 = coverage(&p, 0, 20_000);
        let c1 = coverage(&p, 0, 200_000);
        eprintln!("coverage of 1x1 deg cells: 0.1 s {c01:.3}, 1 s {c1:.3}");
        assert!(c01 > 0.3 && c1 > 0.95 && c1 > c01 + 0.3, "{c01} {c1}");
    }
}
