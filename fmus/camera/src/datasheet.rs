//! Intel RealSense D435i figures the defaults come from.
//!
//! Intel RealSense Product Family D400 Series Datasheet (Intel document 337029), "Intel
//! RealSense Depth Camera D435/D435i": depth field of view (H x V) 87 deg x 58 deg (+/- 3 deg),
//! depth output resolution up to 1280 x 720, stereo baseline 50 mm, ideal range up to 10 m.
//! The near clip 0.105 m is the figure of the D435i profile in the issue; the datasheet's own
//! Min-Z at 1280x720 is larger (about 0.28 m), so set `range_min` to that for a stricter sensor.
//! 10 Hz is the paper's rate, not a D435i mode (the sensor runs 6-90 fps).
//!
//! With FOV 87 x 58 deg on 1280 x 720 the pixels are not square (fx = 674.4, fy = 649.4 px);
//! K carries both focal lengths, so reprojection is exact either way.
//!
//! Depth noise: Intel RealSense white paper "Tuning depth cameras for best performance"
//! (Grunnet-Jepsen, Sweetser, Woodfill), depth RMS error
//! RMS = Z^2 x subpixel / (focal length [px] x baseline), subpixel typically 0.08; and, in the
//! same paper, the invalid depth band at the left edge of a left-referenced stereo pair,
//! width [px] = focal length [px] x baseline / Z.

pub const WIDTH: u32 = 1280;
pub const HEIGHT: u32 = 720;
pub const FOV_H_DEG: f64 = 87.0;
pub const FOV_V_DEG: f64 = 58.0;
pub const RANGE_MIN: f64 = 0.105;
pub const RANGE_MAX: f64 = 10.0;
pub const FRAME_RATE: f64 = 10.0;
pub const BASELINE: f64 = 0.050;
pub const SUBPIXEL: f64 = 0.08;
/// The paper's fixed depth noise (1 sigma).
pub const FIXED_SIGMA: f64 = 0.015;
