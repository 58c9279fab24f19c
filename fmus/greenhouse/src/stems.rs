//! Main stems as beams that a robot part can break.
//!
//! Stems stay rigid colliders (the sensors and the planner see them where they grew); what a
//! press on one does is computed from beam theory and counted as damage:
//! - A main stem is an Euler-Bernoulli beam of its collider's radius `r` and length `L`,
//!   simply supported at both ends (the clip at its foot and the hook of the string it is
//!   wound on at its head, as in high-wire cultivation).
//! - A robot part pressing on it at distance `a` from the foot (`b = L - a`) pushes it aside
//!   by the contact's penetration depth `d` (the least move that frees the part). The load
//!   that takes is `F = k d`, with the beam's stiffness there `k = 3 E I L / (a^2 b^2)`,
//!   `I = pi r^4 / 4`; its bending moment under the load `M = F a b / L = 3 E I d / (a b)`.
//! - The stem breaks when `M` exceeds its bending strength `M_r = sigma pi r^3 / 4` (the
//!   modulus of rupture `sigma` times the section modulus). A broken stem counts once.
//!   `a` and `b` are taken no smaller than `r` (the supports have a size).
//! - Several presses on one stem in a step: the largest moment counts (no superposition).
//!
//! So a slender stem gives way, and only a press near a support, or a deep one, breaks it:
//! with the defaults, a 24 mm stem of 2.2 m needs a 0.78 m push at 0.2 m above its foot, but
//! 5 cm at 12 mm. That is the beam's physics; a robot that pinches or kinks a stem locally
//! (not modelled) can break it with far less.
//!
//! Figures (defaults of the `stem_*` parameters): no bending test of the tomato main stem was
//! found; both are estimates from a herbaceous stem measured the same way. "Loading Model and
//! Mechanical Properties of Mature Broccoli Stems at Harvest", Agriculture 12(10) 1519, 2022
//! (doi:10.3390/agriculture12101519): elastic moduli of 27-48 MPa (rind) and 19-111 MPa
//! (xylem), bending strength 6.9 MPa. Defaults: `stem_modulus` 100 MPa (a tomato stem is
//! woodier than broccoli's), `stem_strength` 7 MPa. "Biomechanical study of the effect of a
//! controlled bending on tomato stem elongation", J. Exp. Bot. 51(352) 1825-1842, 2000,
//! analyses bent tomato stems with the same beam theory.

use agrisim_math::vec3::{dot, norm, sub};
use agrisim_scene::scene::{Kind, Object};
use agrisim_scene::Shape;

/// The stem parameters (the FMU's `stem_*` parameters).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StemParams {
    /// Young's modulus of the stem [Pa].
    pub modulus: f64,
    /// Modulus of rupture in bending [Pa].
    pub strength: f64,
}

impl Default for StemParams {
    fn default() -> Self {
        StemParams { modulus: 100e6, strength: 7e6 }
    }
}

/// A main stem's axis and section, in the map frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StemGeometry {
    /// The scene object (index into the scene's objects).
    pub object: usize,
    /// The axis's lower end (the foot).
    pub foot: [f64; 3],
    /// Unit axis from the foot up.
    pub axis: [f64; 3],
    pub length: f64,
    pub radius: f64,
}

/// What a press does to a stem.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StemLoad {
    /// Distance of the press from the foot along the axis [m].
    pub at: f64,
    /// Lateral force [N].
    pub force: f64,
    /// Bending moment under the press [N m].
    pub moment: f64,
    /// `moment` over the bending strength: 1 or more breaks the stem.
    pub ratio: f64,
}

impl StemGeometry {
    /// Every main stem (a cylinder of kind [`Kind::Stem`]) of `objects`, in object order.
    pub fn all(objects: &[Object]) -> Vec<StemGeometry> {
        let mut out = Vec::new();
        for (object, o) in objects.iter().enumerate() {
            let (Kind::Stem, Shape::Cylinder { radius, half_height }) = (o.kind, o.shape) else { continue };
            let ends = [-half_height, half_height].map(|z| o.placement.transform_point([0.0, 0.0, z]));
            let (foot, head) = if ends[0][2] <= ends[1][2] { (ends[0], ends[1]) } else { (ends[1], ends[0]) };
            let length = 2.0 * half_height;
            let d = sub(head, foot);
            let n = norm(d);
            if !(n > 0.0 && radius > 0.0) {
                continue;
            }
            out.push(StemGeometry { object, foot, axis: d.map(|c| c / n), length, radius });
        }
        out
    }

    /// The load of a press at `point` (map frame) pushing the stem aside by `depth`.
    pub fn load(&self, point: [f64; 3], depth: f64, p: &StemParams) -> StemLoad {
        let r = self.radius;
        let lo = r.min(0.5 * self.length);
        let a = dot(sub(point, self.foot), self.axis).clamp(lo, self.length - lo);
        let b = self.length - a;
        let i = std::f64::consts::PI * r.powi(4) / 4.0;
        let d = depth.max(0.0);
        let stiffness = 3.0 * p.modulus * i * self.length / (a * a * b * b);
        let force = stiffness * d;
        let moment = force * a * b / self.length;
        let strength = p.strength * std::f64::consts::PI * r.powi(3) / 4.0;
        StemLoad { at: a, force, moment, ratio: moment / strength }
    }
}

/// The largest load on each stem pressed now, by the stem's object index, in press order.
/// A press is (scene object, point in the map frame, depth); presses on other objects are
/// skipped. `stems` is sorted by object index.
pub fn stem_loads(
    stems: &[StemGeometry],
    presses: impl IntoIterator<Item = (usize, [f64; 3], f64)>,
    p: &StemParams,
) -> Vec<(usize, StemLoad)> {
    let mut out: Vec<(usize, StemLoad)> = Vec::new();
    for (object, point, depth) in presses {
        let Ok(k) = stems.binary_search_by_key(&object, |s| s.object) else { continue };
        let load = stems[k].load(point, depth, p);
        match out.iter_mut().find(|(o, _)| *o == object) {
            Some((_, l)) if l.ratio < load.ratio => *l = load,
            Some(_) => {}
            None => out.push((object, load)),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stem() -> StemGeometry {
        StemGeometry { object: 0, foot: [0.0; 3], axis: [0.0, 0.0, 1.0], length: 2.2, radius: 0.012 }
    }

    /// The beam's midspan stiffness and moment against the textbook formulas
    /// (simply supported, central load: `delta = F L^3 / (48 E I)`, `M = F L / 4`).
    #[test]
    fn a_central_press_matches_the_simply_supported_beam() {
        let p = StemParams::default();
        let s = stem();
        let l = s.load([0.0, 0.0, 1.1], 0.02, &p);
        let ei = p.modulus * std::f64::consts::PI * 0.012f64.powi(4) / 4.0;
        let f = 0.02 * 48.0 * ei / 2.2f64.powi(3);
        assert!((l.force - f).abs() < 1e-9 * f, "{} vs {f}", l.force);
        assert!((l.moment - f * 2.2 / 4.0).abs() < 1e-9);
        assert!(l.ratio < 0.01, "a 2 cm push at midspan is far from breaking: {}", l.ratio);
    }

    /// The depth that breaks the stem is `sigma a b / (3 E r)`: a press there is at the
    /// strength (ratio 1), and the stem gives way easier far from its supports.
    #[test]
    fn the_breaking_depth_grows_away_from_the_supports() {
        let p = StemParams::default();
        let s = stem();
        let breaking = |a: f64| p.strength * a * (2.2 - a) / (3.0 * p.modulus * 0.012);
        for a in [0.012, 0.05, 0.2, 1.1, 2.0] {
            let l = s.load([0.3, -0.1, a], breaking(a), &p);
            assert!((l.ratio - 1.0).abs() < 1e-9, "at {a} m: {}", l.ratio);
        }
        assert!(breaking(0.2) > 0.7 && breaking(0.012) < 0.06, "{} {}", breaking(0.2), breaking(0.012));
        // Below the foot's support size, the press counts at the support's edge.
        assert_eq!(s.load([0.0, 0.0, -0.5], 0.01, &p), s.load([0.0, 0.0, 0.012], 0.01, &p));
    }
}
