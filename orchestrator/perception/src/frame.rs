//! One RGB-D frame as the detector reads it: colour, aligned depth and the pinhole model.

/// Pinhole intrinsics (CameraInfo's K).
pub use agrisim_msgs::sensor_msgs::Pinhole as Intrinsics;

/// A colour frame with its aligned depth (z in metres, 0 or non-finite = none).
#[derive(Clone, Copy)]
pub struct Frame<'a> {
    pub width: usize,
    pub height: usize,
    /// rgb8, `width * height * 3` bytes, rows without padding.
    pub rgb: &'a [u8],
    pub depth: &'a [f32],
    pub k: Intrinsics,
    /// The world's up (unit) in the camera's frame, from TF; `None`: the optical frame's -y
    /// (a level camera).
    pub up: Option<[f64; 3]>,
}
