//! The sensor's mount: a rigid pose on base_link (roll-pitch-yaw about fixed axes, as URDF).

use agrisim_math::vec3::mat_vec;
pub use agrisim_math::vec3::Vec3;

/// Rotation as a row-major 3x3 matrix plus translation.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Mount {
    pub translation: Vec3,
    pub rotation: [[f64; 3]; 3],
}

impl Default for Mount {
    fn default() -> Self {
        Mount::new([0.0; 3], 0.0, 0.0, 0.0)
    }
}

impl Mount {
    /// R = Rz(yaw) Ry(pitch) Rx(roll) (URDF / REP 103 fixed-axis roll-pitch-yaw).
    pub fn new(translation: Vec3, roll: f64, pitch: f64, yaw: f64) -> Mount {
        let (sr, cr) = roll.sin_cos();
        let (sp, cp) = pitch.sin_cos();
        let (sy, cy) = yaw.sin_cos();
        Mount {
            translation,
            rotation: [
                [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                [-sp, cp * sr, cp * cr],
            ],
        }
    }

    /// A sensor-frame direction in base_link.
    pub fn rotate(&self, v: Vec3) -> Vec3 {
        mat_vec(&self.rotation, v)
    }
}

/// A base_link vector in the map frame for a base at `yaw` (planar base: a rotation about z).
pub fn yaw_rotate(sin: f64, cos: f64, v: Vec3) -> Vec3 {
    [cos * v[0] - sin * v[1], sin * v[0] + cos * v[1], v[2]]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pitch_down_tilts_forward_axis_down() {
        // A positive pitch about y turns +x toward -z (right-handed).
        let m = Mount::new([0.0; 3], 0.0, 0.5, 0.0);
        let v = m.rotate([1.0, 0.0, 0.0]);
        assert!((v[0] - 0.5f64.cos()).abs() < 1e-15 && (v[2] + 0.5f64.sin()).abs() < 1e-15);
        let m = Mount::new([0.0; 3], 0.0, 0.0, std::f64::consts::FRAC_PI_2);
        let v = m.rotate([1.0, 0.0, 0.0]);
        assert!(v[0].abs() < 1e-15 && (v[1] - 1.0).abs() < 1e-15);
    }
}
