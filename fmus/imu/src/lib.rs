//! IMU FMU (`Imu`): sensor_msgs/Imu of a MEMS IMU on the mobile base.
//!
//! - [`motion`]: what an ideal IMU at the mount reads while the planar base moves (specific
//!   force with gravity, angular rate, orientation), from the chassis' ground truth;
//! - [`noise`]: gz-sensors' Gaussian noise model per axis (white noise, turn-on bias, dynamic
//!   bias) plus a bias-instability term ([`flicker`]) built from [`gauss_markov`] processes;
//! - [`datasheet`]: default figures (TDK InvenSense ICM-40609-D, the IMU in the Livox MID-360)
//!   and their sources;
//! - [`sensor`]: the sample clock and noise state; [`imu`]: the FMI model; [`ports`]: its table.
//!
//! Samples are taken at `rate` on simulation time (integer ns), whatever the importer's step;
//! with the 0.02 s co-simulation step and 200 Hz, each step computes four samples and the
//! `imu` port carries the last one (its stamp is its own sample time).

pub mod datasheet;
pub mod flicker;
pub mod frame;
pub mod gauss_markov;
pub mod imu;
pub mod motion;
pub mod noise;
pub mod ports;
pub mod sensor;

pub use imu::Imu;

agrisim_fmi::export_fmu!(crate::Imu);
