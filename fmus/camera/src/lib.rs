//! RGB-D camera FMU (`Camera`) modelled on the Intel RealSense D435i.
//!
//! - [`optics`]: intrinsics from the field of view, CameraInfo, the optical frame's pose;
//! - [`scene`]: the greenhouse (same TOML and seed as the world FMU) plus the robot's base box;
//! - [`render`]: one ray per pixel on several threads, shadow rays toward the sun (hard or
//!   soft by render quality), fog, labels, and the depth model (range clip, fog limit,
//!   discontinuities, left invalid band, fixed or stereo noise keyed per pixel);
//! - [`lighting`]: the sun's beam, sky and floor light, cover, shadows and fog of a frame, and
//!   the irradiance sum on a surface;
//! - [`shading`]: albedo by kind (tomatoes by USDA ripeness stage), the fixed exposure, sRGB;
//! - light and weather come from the `environment` parameter through
//!   `agrisim_sky::{environment, weather, solar}` (NREL SPA sun position);
//! - [`image`]: sensor_msgs/Image encodings; [`datasheet`]: the D435i figures and sources;
//! - [`camera`]: the FMI model; [`ports`]: its variable table.

pub mod camera;
pub mod datasheet;
pub mod image;
pub mod lighting;
pub mod optics;
pub mod ports;
pub mod render;
pub mod scene;
pub mod shading;

pub use camera::Camera;

agrisim_fmi::export_fmu!(crate::Camera);
