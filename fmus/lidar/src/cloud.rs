//! The frame as sensor_msgs/PointCloud2: one row of points with float32 fields x, y, z
//! (lidar_link, m), intensity (Livox scale, [`crate::reflectivity`]) and t (s, the point's
//! measurement time minus header.stamp), little-endian, 20 bytes per point.
//!
//! Rays without a return (nothing within range, or nearer than the blind zone) are kept as
//! points at (0, 0, 0) with intensity 0, as the Livox driver delivers them, so every frame has
//! point rate / frame rate points; consumers drop them by range (`drop_no_return` removes them
//! here instead). No NaN is ever written, so `is_dense` is true.

use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::sensor_msgs::{PointCloud2, PointField};
use agrisim_msgs::std_msgs::Header;

/// Bytes per point.
pub const POINT_STEP: usize = 20;
pub const FIELDS: [&str; 5] = ["x", "y", "z", "intensity", "t"];

/// One point as published.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Point {
    pub xyz: [f32; 3],
    pub intensity: f32,
    pub t: f32,
}

/// Points of one frame, packed as they are produced.
#[derive(Clone, Debug, Default)]
pub struct CloudBuilder {
    data: Vec<u8>,
}

impl CloudBuilder {
    pub fn with_capacity(points: usize) -> CloudBuilder {
        CloudBuilder { data: Vec::with_capacity(points * POINT_STEP) }
    }

    pub fn push(&mut self, p: &Point) {
        for v in [p.xyz[0], p.xyz[1], p.xyz[2], p.intensity, p.t] {
            self.data.extend_from_slice(&v.to_le_bytes());
        }
    }

    pub fn len(&self) -> usize {
        self.data.len() / POINT_STEP
    }

    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    pub fn finish(self, stamp_ns: i64, frame_id: &str) -> PointCloud2 {
        let width = self.len() as u32;
        PointCloud2 {
            header: Header::new(Time::from_nanos(stamp_ns), frame_id),
            height: 1,
            width,
            fields: FIELDS
                .iter()
                .enumerate()
                .map(|(i, name)| PointField {
                    name: name.to_string(),
                    offset: 4 * i as u32,
                    datatype: PointField::FLOAT32,
                    count: 1,
                })
                .collect(),
            is_bigendian: false,
            point_step: POINT_STEP as u32,
            row_step: width * POINT_STEP as u32,
            data: self.data,
            is_dense: true,
        }
    }
}

/// Reads the points of a cloud this module wrote (fields found by name, so any order of
/// float32 x, y, z, intensity, t works). For tests and tools.
pub fn read(cloud: &PointCloud2) -> Result<Vec<Point>, String> {
    if cloud.is_bigendian {
        return Err("big-endian cloud".into());
    }
    let offset = |name: &str| {
        cloud
            .fields
            .iter()
            .find(|f| f.name == name && f.datatype == PointField::FLOAT32 && f.count == 1)
            .map(|f| f.offset as usize)
            .ok_or(format!("no float32 field {name}"))
    };
    let offs = [offset("x")?, offset("y")?, offset("z")?, offset("intensity")?, offset("t")?];
    let step = cloud.point_step as usize;
    let n = (cloud.width * cloud.height) as usize;
    if offs.iter().any(|o| o + 4 > step) || cloud.data.len() < n * step {
        return Err(format!("{} data bytes for {n} points of {step} bytes", cloud.data.len()));
    }
    Ok((0..n)
        .map(|i| {
            let f = |k: usize| {
                let at = i * step + offs[k];
                f32::from_le_bytes(cloud.data[at..at + 4].try_into().expect("4 bytes"))
            };
            Point { xyz: [f(0), f(1), f(2)], intensity: f(3), t: f(4) }
        })
        .collect())
}
