//! Rotations for the mount pose: unit quaternions (x, y, z, w) acting on 3-vectors.

pub use agrisim_math::vec3::Vec3;
use agrisim_math::vec3::{add, cross, scale};

#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Quat {
    pub x: f64,
    pub y: f64,
    pub z: f64,
    pub w: f64,
}

impl Default for Quat {
    fn default() -> Self {
        Quat::IDENTITY
    }
}

impl Quat {
    pub const IDENTITY: Quat = Quat { x: 0.0, y: 0.0, z: 0.0, w: 1.0 };

    /// Rotation about z.
    pub fn yaw(angle: f64) -> Quat {
        let (s, c) = (angle / 2.0).sin_cos();
        Quat { x: 0.0, y: 0.0, z: s, w: c }
    }

    /// URDF/REP 103 roll-pitch-yaw about fixed x, y, z: R = Rz(yaw) Ry(pitch) Rx(roll).
    pub fn from_rpy(roll: f64, pitch: f64, yaw: f64) -> Quat {
        let (sr, cr) = (roll / 2.0).sin_cos();
        let (sp, cp) = (pitch / 2.0).sin_cos();
        let (sy, cy) = (yaw / 2.0).sin_cos();
        Quat {
            x: sr * cp * cy - cr * sp * sy,
            y: cr * sp * cy + sr * cp * sy,
            z: cr * cp * sy - sr * sp * cy,
            w: cr * cp * cy + sr * sp * sy,
        }
    }

    /// Hamilton product self * o: a frame rotated by `o` within the frame `self` (vectors: o first, then self).
    pub fn compose(self, o: Quat) -> Quat {
        Quat {
            w: self.w * o.w - self.x * o.x - self.y * o.y - self.z * o.z,
            x: self.w * o.x + self.x * o.w + self.y * o.z - self.z * o.y,
            y: self.w * o.y - self.x * o.z + self.y * o.w + self.z * o.x,
            z: self.w * o.z + self.x * o.y - self.y * o.x + self.z * o.w,
        }
    }

    pub fn conjugate(self) -> Quat {
        Quat { x: -self.x, y: -self.y, z: -self.z, w: self.w }
    }

    /// R v.
    pub fn rotate(self, v: Vec3) -> Vec3 {
        // v + 2 w (u x v) + 2 u x (u x v), u = vector part.
        let u = [self.x, self.y, self.z];
        let t = scale(cross(u, v), 2.0);
        add(add(v, scale(t, self.w)), cross(u, t))
    }

    /// R^T v (expresses a parent-frame vector in this frame).
    pub fn inverse_rotate(self, v: Vec3) -> Vec3 {
        self.conjugate().rotate(v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec3, b: Vec3) -> bool {
        (0..3).all(|i| (a[i] - b[i]).abs() < 1e-12)
    }

    #[test]
    fn rpy_composes_fixed_axes_in_urdf_order() {
        let (r, p, y) = (0.3, -0.7, 1.9);
        let q = Quat::from_rpy(r, p, y);
        let qx = Quat { x: (r / 2.0).sin(), y: 0.0, z: 0.0, w: (r / 2.0).cos() };
        let qy = Quat { x: 0.0, y: (p / 2.0).sin(), z: 0.0, w: (p / 2.0).cos() };
        let want = Quat::yaw(y).compose(qy).compose(qx);
        let v = [0.2, -1.0, 0.5];
        assert!(close(q.rotate(v), want.rotate(v)));
        assert!(close(q.inverse_rotate(q.rotate(v)), v));
        // A quarter turn about z takes x to y.
        assert!(close(Quat::yaw(std::f64::consts::FRAC_PI_2).rotate([1.0, 0.0, 0.0]), [0.0, 1.0, 0.0]));
    }
}
