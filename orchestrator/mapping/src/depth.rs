//! Depth images as the camera FMU publishes them (`sensor_msgs/Image`, 32FC1 in metres or
//! 16UC1 in millimetres, REP 118) and their points in the map frame.

use agrisim_msgs::sensor_msgs::Image;
use nalgebra::{Isometry3, Point3};

/// Pinhole intrinsics from CameraInfo's K (pixel centres at `u + 0.5`, as the camera renders
/// and the perception node reads them).
pub use agrisim_msgs::sensor_msgs::Pinhole as Intrinsics;

/// A decoded depth image: z along the optical axis in metres, row-major; 0 or non-finite
/// where the sensor has no return.
#[derive(Debug, Clone, PartialEq)]
pub struct DepthFrame {
    pub width: usize,
    pub height: usize,
    pub z: Vec<f32>,
}

impl DepthFrame {
    /// Decodes 32FC1 (m) or 16UC1 (mm, 0 = none), either byte order, rows possibly padded.
    pub fn from_image(img: &Image) -> Result<DepthFrame, String> {
        let (w, h, step) = (img.width as usize, img.height as usize, img.step as usize);
        let bpp = match img.encoding.as_str() {
            "32FC1" => 4,
            "16UC1" | "mono16" => 2,
            e => return Err(format!("depth encoding {e:?}, expected 32FC1 or 16UC1")),
        };
        let need = step.checked_mul(h.saturating_sub(1)).and_then(|v| v.checked_add(w * bpp));
        if step < w * bpp || need.is_none_or(|n| img.data.len() < n) {
            return Err(format!(
                "depth image {w}x{h} {} with step {step} and {} bytes is truncated",
                img.encoding,
                img.data.len()
            ));
        }
        let big = img.is_bigendian != 0;
        let mut z = Vec::with_capacity(w * h);
        for v in 0..h {
            let row = &img.data[v * step..v * step + w * bpp];
            if bpp == 4 {
                z.extend(row.chunks_exact(4).map(|b| {
                    let b = [b[0], b[1], b[2], b[3]];
                    if big {
                        f32::from_be_bytes(b)
                    } else {
                        f32::from_le_bytes(b)
                    }
                }));
            } else {
                z.extend(row.chunks_exact(2).map(|b| {
                    let mm = if big { u16::from_be_bytes([b[0], b[1]]) } else { u16::from_le_bytes([b[0], b[1]]) };
                    mm as f32 / 1000.0
                }));
            }
        }
        Ok(DepthFrame { width: w, height: h, z })
    }

    /// The returns as points in the frame `camera_pose` maps into (the optical frame's pose:
    /// z forward, x right, y down), in single precision as a point cloud carries them;
    /// pixels without a return are left out. Also gives the camera origin.
    pub fn points(&self, k: &Intrinsics, camera_pose: &Isometry3<f64>) -> ([f32; 3], Vec<[f32; 3]>) {
        self.points_every(k, camera_pose, 1)
    }

    /// [`points`](Self::points) of every `stride`-th pixel of every `stride`-th row (MoveIt's
    /// depth-image octomap updater skips pixels the same way): stride^2 fewer rays, and at
    /// the crop's distance still several points per voxel.
    pub fn points_every(
        &self,
        k: &Intrinsics,
        camera_pose: &Isometry3<f64>,
        stride: usize,
    ) -> ([f32; 3], Vec<[f32; 3]>) {
        let stride = stride.max(1);
        let mut out = Vec::with_capacity(self.z.len() / (stride * stride));
        let rx: Vec<f64> = (0..self.width).map(|u| (u as f64 + 0.5 - k.cx) / k.fx).collect();
        for v in (0..self.height).step_by(stride) {
            let ry = (v as f64 + 0.5 - k.cy) / k.fy;
            let row = &self.z[v * self.width..(v + 1) * self.width];
            for (u, &z) in row.iter().enumerate().step_by(stride) {
                if !(z > 0.0 && z.is_finite()) {
                    continue;
                }
                let z = z as f64;
                let p = camera_pose * Point3::new(rx[u] * z, ry * z, z);
                out.push([p.x as f32, p.y as f32, p.z as f32]);
            }
        }
        let o = camera_pose.translation.vector;
        ([o.x as f32, o.y as f32, o.z as f32], out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(encoding: &str, w: u32, h: u32, step: u32, data: Vec<u8>) -> Image {
        Image { encoding: encoding.into(), width: w, height: h, step, data, ..Default::default() }
    }

    #[test]
    fn decodes_both_encodings() {
        let d = DepthFrame::from_image(&image("16UC1", 2, 1, 4, vec![0xe8, 0x03, 0, 0])).unwrap();
        assert_eq!(d.z, vec![1.0, 0.0]);
        let mut bytes = 1.5f32.to_be_bytes().to_vec();
        bytes.extend([9, 9, 9, 9]); // row padding
        bytes.extend(2.0f32.to_be_bytes());
        let mut img = image("32FC1", 1, 2, 8, bytes);
        img.is_bigendian = 1;
        assert_eq!(DepthFrame::from_image(&img).unwrap().z, vec![1.5, 2.0]);
        let e = DepthFrame::from_image(&image("rgb8", 1, 1, 3, vec![0; 3])).unwrap_err();
        assert!(e.contains("rgb8"), "{e}");
        let e = DepthFrame::from_image(&image("32FC1", 2, 2, 8, vec![0; 12])).unwrap_err();
        assert!(e.contains("truncated"), "{e}");
    }

    #[test]
    fn unprojects_through_the_pose() {
        let k = Intrinsics::from_k(&[100.0, 0.0, 1.0, 0.0, 100.0, 1.0, 0.0, 0.0, 1.0]).unwrap();
        let d = DepthFrame { width: 2, height: 2, z: vec![2.0, 0.0, f32::NAN, 1.0] };
        let pose = Isometry3::translation(1.0, 2.0, 3.0);
        let (o, pts) = d.points(&k, &pose);
        assert_eq!(o, [1.0, 2.0, 3.0]);
        assert_eq!(pts.len(), 2);
        // Pixel (0, 0): (0.5 - 1) / 100 * 2 = -0.01.
        assert!((pts[0][0] - 0.99).abs() < 1e-6 && (pts[0][1] - 1.99).abs() < 1e-6 && pts[0][2] == 5.0);
        assert!(Intrinsics::from_k(&[0.0; 9]).is_none());
    }
}
