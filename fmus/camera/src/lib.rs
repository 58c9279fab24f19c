//! RGB-D camera FMU (`Camera`) modelled on the Intel RealSense D435i.
//!
//! - [`optics`]: intrinsics from the field of view, CameraInfo, the optical frame's pose;
//! - [`scene`]: the greenhouse (same TOML and seed as the world FMU); the robot's own links
//!   come from `agrisim_sensor_ports::robot`;
//! - [`render`]: one ray per pixel on several threads, shadow rays toward the sun (hard or
//!   soft by render quality), fog, labels, and the depth model (range clip, fog limit,
//!   discontinuities, left invalid band, fixed or stereo noise keyed per pixel);
//! - [`lighting`]: the sun's beam, sky and floor light, cover, shadows and fog of a frame, and
//!   the irradiance sum on a surface;
//! - [`crop`]: the crop's detail inside its colliders (oblate fruit with calyx, serrated
//!   leaflets), ripeness colour from the blossom end, glossy skin;
//! - [`shading`]: albedo by kind (tomatoes by USDA ripeness stage), the fixed exposure, sRGB;
//! - light and weather come from the `environment` parameter through
//!   `agrisim_sky::{environment, weather, solar}` (NREL SPA sun position);
//! - [`image`]: sensor_msgs/Image encodings; [`datasheet`]: the D435i figures and sources;
//! - [`camera`]: the FMI model, where the camera is (camera_link on the URDF link
//!   `mount_parent`, placed by the robot's forward kinematics from the lift and arm inputs) and
//!   its frames for TF; [`ports`]: its variable table.

pub mod camera;
pub mod crop;
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
