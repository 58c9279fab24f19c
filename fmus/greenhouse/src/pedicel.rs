//! The pedicel as a breakable joint: a fruit a gripper closes on while it hangs on its plant
//! stays attached to its truss until the load at its abscission zone (AZ) breaks it.
//!
//! Model (lengths in m, forces in N, moments in N m):
//! - The joint sits at the AZ, on the pedicel axis `AZ_OFFSET` above the fruit's top (the
//!   calyx). Its truss side is fixed in the map frame (the truss is a static collider); its
//!   fruit side moves rigidly with the fruit, which follows the hand that grasped it.
//! - A linear 6-DoF spring-damper: with `d` the AZ's displacement from its rest position and
//!   `theta` the fruit's rotation vector from its rest orientation (both map frame), the
//!   pedicel pulls the fruit with `F = -k_t d - c_t d'` and turns it with
//!   `M = -k_b theta_bend - k_w theta_twist - c_r theta'` (`theta_twist` = the part along the
//!   pedicel axis `a`, from the AZ up to the truss; `theta_bend` the rest).
//! - The loads at the AZ compared with the fruit's thresholds:
//!   pull = the tension `F . a` (fruit pulled away from the truss);
//!   bend = `|M_bend + (l/2) a x F_shear|`: the rotational spring plus the moment a sideways
//!   force makes in the pedicel segment of length `l` between the AZ and the truss (a beam
//!   clamped at both ends carries `F l / 2` at each end);
//!   twist = `|M . a|`.
//!   The joint breaks in the first step where any exceeds its threshold; the fruit is then
//!   picked (carried as before).
//! - Thresholds are drawn per fruit from normal distributions (truncated at 20 % of the
//!   mean), seeded by the scene seed and the fruit's index: the same fruit of the same scene
//!   always holds the same.
//!
//! Figures (defaults of the `pedicel_*` parameters):
//! - Pull: the tensile detachment force at the abscission zone of greenhouse tomato. Weng et
//!   al., "Tomato Pedicel Physical Characterization for Fruit-Pedicel Separation Tomato
//!   Harvesting Robot", Agronomy 14(10) 2274, 2024 (doi:10.3390/agronomy14102274): tensile
//!   tests of the AZ (cv. Spectrum, early firm-ripe) give pull-off forces of the order of
//!   20 N, depending on the pedicel diameter; Li Zhiguo et al., "Mechanical properties of
//!   tomato fruits and peduncles", Trans. CSAE 24(12), 2008: all peduncles break at the
//!   abscission layer, and bending detaches with less effort than stretching. Default
//!   mean 20 N, SD 5 N (our reading of the reported ranges, 10-30 N).
//! - Bend: the same sources report bending as the cheaper mode. Default mean 0.15 N m,
//!   SD 0.04 N m: about 4 N at the fruit's centre for a 75 mm tomato, 5 times less than the
//!   pull (our choice within "bending needs less force"; cherry-tomato clusters measured at
//!   5-8 N tensile failure of the AZ for comparison, airobotsight.com summary of a cluster
//!   end-effector study).
//! - Twist: not measured in these sources; default mean 0.10 N m, SD 0.03 N m (an estimate,
//!   below the bending moment: twisting is used by hand pickers to snap the knuckle).
//! - Stiffness: the fruit yields a few cm on its truss before it comes off (trusses and
//!   pedicels flex); k_t = 500 N/m (4 cm at the mean pull), bending 0.3 N m/rad (the mean
//!   bend moment at ~30 deg), twist 0.06 N m/rad (~95 deg). Damping: c_t = 2 N s/m,
//!   c_r = 0.005 N m s/rad. These are estimates, not measurements.

use agrisim_math::vec3::{add, cross, dot, norm, scale, sub};
use agrisim_math::Rng;
use agrisim_robot::Pose as RPose;

/// Distance of the abscission zone above the fruit's top (the calyx) along the pedicel [m]:
/// the tomato's knuckle sits about 1-2 cm above the calyx (our reading of photographs).
pub const AZ_OFFSET: f64 = 0.015;
/// Thresholds are drawn no lower than this fraction of their mean.
pub const MIN_FRACTION: f64 = 0.2;
/// Label of the threshold stream under the scene seed.
const STREAM: u64 = 0x9ED1_CE15;

/// The pedicel parameters (the FMU's `pedicel_*` parameters).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PedicelParams {
    /// Whether grasped fruit stay attached until the pedicel breaks (false: the old rule,
    /// picked the instant the fingers close).
    pub enabled: bool,
    pub pull_mean: f64,
    pub pull_sd: f64,
    pub bend_mean: f64,
    pub bend_sd: f64,
    pub twist_mean: f64,
    pub twist_sd: f64,
    /// Translational stiffness [N/m] and damping [N s/m].
    pub stiffness: f64,
    pub damping: f64,
    /// Rotational stiffness in bending and twisting [N m/rad], damping [N m s/rad].
    pub bend_stiffness: f64,
    pub twist_stiffness: f64,
    pub rot_damping: f64,
}

impl Default for PedicelParams {
    fn default() -> Self {
        PedicelParams {
            enabled: true,
            pull_mean: 20.0,
            pull_sd: 5.0,
            bend_mean: 0.15,
            bend_sd: 0.04,
            twist_mean: 0.10,
            twist_sd: 0.03,
            stiffness: 500.0,
            damping: 2.0,
            bend_stiffness: 0.3,
            twist_stiffness: 0.06,
            rot_damping: 0.005,
        }
    }
}

/// A fruit's breaking thresholds.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Thresholds {
    pub pull: f64,
    pub bend: f64,
    pub twist: f64,
}

fn draw(rng: &mut Rng, mean: f64, sd: f64) -> f64 {
    (mean + sd * rng.normal()).max(MIN_FRACTION * mean)
}

impl PedicelParams {
    /// Thresholds of fruit `index` in the scene of seed `seed`.
    pub fn thresholds(&self, seed: u64, index: usize) -> Thresholds {
        let mut rng = Rng::stream(seed, &[STREAM, index as u64]);
        Thresholds {
            pull: draw(&mut rng, self.pull_mean, self.pull_sd),
            bend: draw(&mut rng, self.bend_mean, self.bend_sd),
            twist: draw(&mut rng, self.twist_mean, self.twist_sd),
        }
    }
}

/// Where a fruit's pedicel is, from the scene: the unit axis from the fruit's top up to the
/// truss, and the pedicel's length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PedicelGeometry {
    pub axis: [f64; 3],
    pub length: f64,
}

impl PedicelGeometry {
    /// A fruit without a pedicel in the scene hangs straight down from its truss.
    pub const VERTICAL: PedicelGeometry = PedicelGeometry { axis: [0.0, 0.0, 1.0], length: 0.01 };
}

/// Which load broke a pedicel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Mode {
    Pull,
    Bend,
    Twist,
}

impl Mode {
    pub fn code(self) -> i32 {
        match self {
            Mode::Pull => 1,
            Mode::Bend => 2,
            Mode::Twist => 3,
        }
    }

    /// The mode's name in messages and reports.
    pub fn label(self) -> &'static str {
        match self {
            Mode::Pull => "pull",
            Mode::Bend => "bend",
            Mode::Twist => "twist",
        }
    }
}

/// The load at the abscission zone in one step.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Load {
    /// Force of the pedicel on the fruit at the AZ (map frame) [N].
    pub force: [f64; 3],
    /// Moment of the pedicel on the fruit about the AZ (map frame) [N m].
    pub moment: [f64; 3],
    /// The AZ in the map frame (where `force` acts).
    pub at: [f64; 3],
    pub pull: f64,
    pub bend: f64,
    pub twist: f64,
}

impl Load {
    /// Moment of this load about point `p` [N m].
    pub fn moment_about(&self, p: [f64; 3]) -> [f64; 3] {
        add(self.moment, cross(sub(self.at, p), self.force))
    }

    /// The mode whose threshold this load exceeds (the largest ratio first), if any.
    pub fn breaks(&self, t: &Thresholds) -> Option<Mode> {
        let ratios =
            [(self.pull / t.pull, Mode::Pull), (self.bend / t.bend, Mode::Bend), (self.twist / t.twist, Mode::Twist)];
        ratios.iter().filter(|(r, _)| *r >= 1.0).max_by(|a, b| a.0.total_cmp(&b.0)).map(|&(_, m)| m)
    }
}

/// A grasped fruit still on its plant.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Attachment {
    /// The AZ's rest position (map frame).
    pub anchor: [f64; 3],
    /// The AZ in the fruit's frame.
    pub az_in_fruit: [f64; 3],
    /// Pedicel axis (map frame, unit, up to the truss) and length.
    pub axis: [f64; 3],
    pub length: f64,
    /// The fruit's rest pose (map frame).
    pub rest: RPose,
    pub thresholds: Thresholds,
    /// Displacement and rotation vector of the last step (for the damping terms).
    pub prev: Option<([f64; 3], [f64; 3])>,
    /// The largest pull / bend / twist load so far.
    pub peak: [f64; 3],
}

/// Rotation vector (axis * angle) of rotation matrix `m`.
pub fn rotation_vector(m: &[[f64; 3]; 3]) -> [f64; 3] {
    let tr = m[0][0] + m[1][1] + m[2][2];
    let c = ((tr - 1.0) * 0.5).clamp(-1.0, 1.0);
    let angle = c.acos();
    let v = [m[2][1] - m[1][2], m[0][2] - m[2][0], m[1][0] - m[0][1]];
    let s = angle.sin();
    if angle < 1e-9 {
        scale(v, 0.5)
    } else if s > 1e-6 {
        scale(v, angle / (2.0 * s))
    } else {
        // Near pi: the axis from the diagonal.
        let d = [(m[0][0] + 1.0) * 0.5, (m[1][1] + 1.0) * 0.5, (m[2][2] + 1.0) * 0.5];
        let k = (0..3).max_by(|&a, &b| d[a].total_cmp(&d[b])).unwrap_or(0);
        let mut axis = [0.0; 3];
        axis[k] = d[k].max(0.0).sqrt();
        for j in 0..3 {
            if j != k && axis[k] > 0.0 {
                axis[j] = (m[k][j] + m[j][k]) / (4.0 * axis[k]);
            }
        }
        let n = norm(axis).max(1e-12);
        scale(axis, angle / n)
    }
}

impl Attachment {
    /// The attachment of a fruit of `radius` resting at `rest` with pedicel `geom`.
    pub fn new(rest: RPose, radius: f64, geom: PedicelGeometry, thresholds: Thresholds) -> Attachment {
        let top = [rest.trans[0], rest.trans[1], rest.trans[2] + radius];
        let anchor = add(top, scale(geom.axis, AZ_OFFSET.min(0.5 * geom.length.max(0.0)).max(0.0)));
        let az_in_fruit = rest.inverse().transform_point(anchor);
        Attachment {
            anchor,
            az_in_fruit,
            axis: geom.axis,
            length: geom.length.max(0.0),
            rest,
            thresholds,
            prev: None,
            peak: [0.0; 3],
        }
    }

    /// The load with the fruit at `pose` after a step of `h` s; remembers the displacement
    /// for the next step's damping and the peaks.
    pub fn load(&mut self, p: &PedicelParams, pose: &RPose, h: f64) -> Load {
        let at = pose.transform_point(self.az_in_fruit);
        let d = sub(at, self.anchor);
        let rel = pose.mul(&self.rest.inverse());
        let theta = rotation_vector(&rel.rot);
        let (dd, dtheta) = match self.prev {
            Some((d0, t0)) if h > 0.0 => (scale(sub(d, d0), 1.0 / h), scale(sub(theta, t0), 1.0 / h)),
            _ => ([0.0; 3], [0.0; 3]),
        };
        self.prev = Some((d, theta));
        let a = self.axis;
        let force = sub(scale(d, -p.stiffness), scale(dd, p.damping));
        let tw = dot(theta, a);
        let bend_rot = sub(theta, scale(a, tw));
        let moment = sub(
            sub(scale(bend_rot, -p.bend_stiffness), scale(a, p.twist_stiffness * tw)),
            scale(dtheta, p.rot_damping),
        );
        let tension = dot(force, a);
        let shear = sub(force, scale(a, tension));
        let m_twist = dot(moment, a);
        let m_bend = add(sub(moment, scale(a, m_twist)), scale(cross(a, shear), 0.5 * self.length));
        let load = Load { force, moment, at, pull: tension.max(0.0), bend: norm(m_bend), twist: m_twist.abs() };
        self.peak = [self.peak[0].max(load.pull), self.peak[1].max(load.bend), self.peak[2].max(load.twist)];
        load
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_vector_inverts_axis_angle() {
        for (axis, angle) in
            [([0.0, 0.0, 1.0], 0.3), ([0.6, 0.0, 0.8], 2.0), ([0.0, 1.0, 0.0], 3.1), ([1.0, 0.0, 0.0], 0.0)]
        {
            let r = RPose::from_axis_angle(axis, angle);
            let v = rotation_vector(&r.rot);
            for i in 0..3 {
                assert!((v[i] - axis[i] * angle).abs() < 1e-6, "{axis:?} {angle}: {v:?}");
            }
        }
    }

    #[test]
    fn thresholds_are_deterministic_and_differ_between_fruit() {
        let p = PedicelParams::default();
        assert_eq!(p.thresholds(7, 3), p.thresholds(7, 3));
        assert_ne!(p.thresholds(7, 3), p.thresholds(7, 4));
        assert_ne!(p.thresholds(7, 3), p.thresholds(8, 3));
    }

    #[test]
    fn a_straight_pull_loads_only_the_tension_and_breaks_as_pull() {
        let p = PedicelParams { damping: 0.0, rot_damping: 0.0, ..Default::default() };
        let geom = PedicelGeometry { axis: [0.0, 0.0, 1.0], length: 0.02 };
        let t = Thresholds { pull: 10.0, bend: 1.0, twist: 1.0 };
        let mut a = Attachment::new(RPose::from_translation([1.0, 2.0, 1.0]), 0.03, geom, t);
        let l = a.load(&p, &RPose::from_translation([1.0, 2.0, 0.99]), 0.02);
        assert!((l.pull - 5.0).abs() < 1e-9 && l.bend < 1e-9 && l.twist < 1e-9, "{l:?}");
        assert_eq!(l.breaks(&t), None);
        let l = a.load(&p, &RPose::from_translation([1.0, 2.0, 0.979]), 0.02);
        assert_eq!(l.breaks(&t), Some(Mode::Pull));
    }
}
