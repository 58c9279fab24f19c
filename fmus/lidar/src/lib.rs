//! LiDAR FMU (`Lidar`) modelled on the Livox MID-360.
//!
//! - [`pattern`]: the non-repetitive scan pattern (which direction the n-th point looks);
//! - [`scene`]: the greenhouse the rays hit (same TOML and seed as the world FMU) plus the
//!   robot's own base box;
//! - [`trajectory`]: the base's recent path, so every point is cast from where the robot was
//!   when it was measured;
//! - [`reflectivity`]: intensity from surface kind and incidence angle;
//! - [`cloud`]: the sensor_msgs/PointCloud2 layout;
//! - [`datasheet`]: the MID-360 figures and the sources of the pattern geometry;
//! - [`lidar`]: the FMI model; [`ports`]: its variable table; [`frame`]: the mount pose.
//!
//! Frames are due at multiples of 1/frame_rate on simulation time, whatever the importer's
//! step; each holds point_rate / frame_rate rays (20,000 at the defaults), cast one by one
//! with `agrisim_raycast::RayCaster`. Range noise is Gaussian (2 cm, seeded). With the
//! `environment` parameter (the scenario's `[environment]`), fog, rain and haze drop returns
//! whose two-way-attenuated echo falls below the detection threshold ([`lidar::detected`]).

pub mod cloud;
pub mod datasheet;
pub mod frame;
pub mod lidar;
pub mod pattern;
pub mod ports;
pub mod reflectivity;
pub mod scene;
pub mod trajectory;

pub use lidar::Lidar;

agrisim_fmi::export_fmu!(crate::Lidar);
