//! agrisim-perception: finds tomatoes in RGB-D frames, as an algorithm node that speaks only
//! ROS 2 messages (colour image, aligned depth, CameraInfo and TF in; vision_msgs out), so a
//! ROS 2 node can take its place and be judged the same way (`agrisim bench perception`).
//!
//! Per frame ([`detect`]): pixels whose CIELAB colour may be a tomato ([`colour`]), grouped
//! into components connected in the image and in depth, each fitted with a robust sphere on
//! its depth points ([`sphere`]: the visible cap, radius 20-45 mm) stretched along the
//! world's up so that the oblate fruit is round ([`spheroid`]), its USDA ripeness stage
//! from the coloured fraction of its surface ([`ripeness`]: the height of the colour's front
//! on the sphere, along the world's up from TF). Across frames ([`tracker`]): detections
//! moved into the world frame by TF ([`tf`]) and merged into a fruit map with stable ids.
//!
//! Classical and calibrated to the simulated camera's colours: green fruit (stage 1) look like
//! the foliage in colour and are not found; touching fruit of one colour at one depth may be
//! merged or split wrongly.

pub mod colour;
pub mod cost;
pub mod detect;
pub mod frame;
pub mod haze;
pub mod node;
pub mod ripeness;
pub mod sphere;
pub mod spheroid;
pub mod tf;
pub mod tracker;

pub use agrisim_bus::Charged;
pub use colour::{is_ripe, stage_of, STAGES};
pub use cost::CostModel;
pub use detect::{DetectWork, Detection, Detector, DetectorConfig, Frame, FrameResult, Intrinsics};
pub use node::{Perception, PerceptionConfig};
