//! Pinhole geometry: intrinsics from the field of view, CameraInfo, and the optical frame's
//! pose in the map.
//!
//! Pixel centres sit at integer coordinates (ROS / OpenCV convention), so the principal point
//! of an ideal sensor is ((w - 1) / 2, (h - 1) / 2) and the field of view spans w pixels:
//! fx = (w / 2) / tan(fov_h / 2), fy = (h / 2) / tan(fov_v / 2).

use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::sensor_msgs::{CameraInfo, RegionOfInterest};
use agrisim_msgs::std_msgs::Header;

use agrisim_math::vec3::{mat_mul, mat_vec};
pub use agrisim_math::vec3::{Mat3, Vec3};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Intrinsics {
    pub width: u32,
    pub height: u32,
    pub fx: f64,
    pub fy: f64,
    pub cx: f64,
    pub cy: f64,
}

impl Intrinsics {
    pub fn from_fov(width: u32, height: u32, fov_h_deg: f64, fov_v_deg: f64) -> Intrinsics {
        let fx = 0.5 * width as f64 / (0.5 * fov_h_deg.to_radians()).tan();
        let fy = 0.5 * height as f64 / (0.5 * fov_v_deg.to_radians()).tan();
        Intrinsics { width, height, fx, fy, cx: 0.5 * (width as f64 - 1.0), cy: 0.5 * (height as f64 - 1.0) }
    }

    /// Row-major K.
    pub fn k(&self) -> [f64; 9] {
        [self.fx, 0.0, self.cx, 0.0, self.fy, self.cy, 0.0, 0.0, 1.0]
    }

    /// Unit ray of pixel (u, v) in the optical frame (z forward, x right, y down).
    pub fn ray(&self, u: f64, v: f64) -> Vec3 {
        ray_through(self.plane_x(u), self.plane_y(v))
    }

    /// x on the z = 1 plane of the pixel column u (shared by a column's pixels).
    pub fn plane_x(&self, u: f64) -> f64 {
        (u - self.cx) / self.fx
    }

    /// y on the z = 1 plane of the pixel row v.
    pub fn plane_y(&self, v: f64) -> f64 {
        (v - self.cy) / self.fy
    }

    /// Optical-frame point of pixel (u, v) at depth z (what a consumer does with K).
    pub fn reproject(&self, u: f64, v: f64, z: f64) -> Vec3 {
        [(u - self.cx) / self.fx * z, (v - self.cy) / self.fy * z, z]
    }

    /// Monocular, undistorted: plumb_bob with zero coefficients, R = I, P = [K | 0].
    pub fn camera_info(&self, stamp_ns: i64, frame_id: &str) -> CameraInfo {
        let k = self.k();
        CameraInfo {
            header: Header::new(Time::from_nanos(stamp_ns), frame_id),
            height: self.height,
            width: self.width,
            distortion_model: "plumb_bob".into(),
            d: vec![0.0; 5],
            k,
            r: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
            p: [k[0], 0.0, k[2], 0.0, 0.0, k[4], k[5], 0.0, 0.0, 0.0, 1.0, 0.0],
            binning_x: 0,
            binning_y: 0,
            roi: RegionOfInterest::default(),
        }
    }
}

/// Rz(yaw) Ry(pitch) Rx(roll): URDF fixed-axis roll-pitch-yaw.
pub fn rpy(roll: f64, pitch: f64, yaw: f64) -> Mat3 {
    let (sr, cr) = roll.sin_cos();
    let (sp, cp) = pitch.sin_cos();
    let (sy, cy) = yaw.sin_cos();
    let rx = [[1.0, 0.0, 0.0], [0.0, cr, -sr], [0.0, sr, cr]];
    let ry = [[cp, 0.0, sp], [0.0, 1.0, 0.0], [-sp, 0.0, cp]];
    let rz = [[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]];
    mat_mul(&rz, &mat_mul(&ry, &rx))
}

/// Optical frame axes in camera_link (REP 103 body: x forward, y left, z up): optical x
/// (right) = -y, optical y (down) = -z, optical z (forward) = +x. Columns are the optical axes.
pub const OPTICAL_IN_BODY: Mat3 = [[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]];

/// Mount of camera_link on base_link (the shared sensor mount parameters).
pub use agrisim_sensor_ports::Mount;

/// The optical frame in the map: origin and rotation (optical -> map).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraPose {
    pub origin: Vec3,
    pub rotation: Mat3,
}

impl CameraPose {
    /// For base_link at (x, y, yaw) on the floor (z = 0).
    pub fn new(mount: &Mount, x: f64, y: f64, base_yaw: f64) -> CameraPose {
        let base = rpy(0.0, 0.0, base_yaw);
        let body = mat_mul(&base, &rpy(mount.roll, mount.pitch, mount.yaw));
        let t = mat_vec(&base, mount.translation);
        CameraPose { origin: [x + t[0], y + t[1], t[2]], rotation: mat_mul(&body, &OPTICAL_IN_BODY) }
    }

    /// An optical-frame point in the map.
    pub fn to_map(&self, p: Vec3) -> Vec3 {
        let r = mat_vec(&self.rotation, p);
        [r[0] + self.origin[0], r[1] + self.origin[1], r[2] + self.origin[2]]
    }
}

/// The unit ray through (x, y, 1): [`Intrinsics::ray`] from a pixel's plane coordinates.
#[inline]
pub fn ray_through(x: f64, y: f64) -> Vec3 {
    let n = (x * x + y * y + 1.0).sqrt();
    [x / n, y / n, 1.0 / n]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn d435i_intrinsics_and_axes() {
        let k = Intrinsics::from_fov(1280, 720, 87.0, 58.0);
        assert!((k.fx - 674.4).abs() < 0.1 && (k.fy - 649.4).abs() < 0.1, "{k:?}");
        assert_eq!((k.cx, k.cy), (639.5, 359.5));
        // Edge pixels see half the field of view (at their outer boundary).
        let r = k.ray(-0.5, k.cy);
        assert!(((-r[0] / r[2]).atan().to_degrees() - 43.5).abs() < 1e-9);
        let pose =
            CameraPose::new(&Mount { translation: [0.6, 0.0, 1.2], roll: 0.0, pitch: 0.0, yaw: 0.0 }, 1.0, 2.0, 0.0);
        let near = |a: Vec3, b: Vec3| (0..3).all(|i| (a[i] - b[i]).abs() < 1e-12);
        assert!(near(pose.to_map([0.0, 0.0, 1.0]), [2.6, 2.0, 1.2])); // z forward = map +x
        assert!(near(pose.to_map([1.0, 0.0, 0.0]), [1.6, 1.0, 1.2])); // x right = map -y
        assert!(near(pose.to_map([0.0, 1.0, 0.0]), [1.6, 2.0, 0.2])); // y down = map -z
    }
}
