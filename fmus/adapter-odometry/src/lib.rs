//! ScalarsToOdometry: an adapter FMU that lets a model with plain Real outputs (a bare
//! kinematic chassis from another tool, say) stand where agrisim's chassis publishes
//! `odom`. Inputs: the model's ground-truth planar pose in the map frame (`x`, `y`, `yaw`,
//! read at initialization as the odom origin) and body velocities (`vx`, `vy`, `wz`);
//! outputs: the message ports `odom` (nav_msgs/msg/Odometry, the chassis's MIME type and
//! conventions) and `tf` (tf2_msgs/msg/TFMessage, odom -> base_link), published at `rate`
//! on simulation time, plus the scalar odometry `odom_x` ... `odom_wz`.
//!
//! The odometry error model lives here, so the model itself can stay exact: seeded noise
//! per step (`v_noise`, `wz_noise`) and scale errors (`v_scale_error`, `wz_scale_error`);
//! all 0 gives exact dead reckoning. The same `seed` gives the same bytes.
//!
//! The input names are not message fields (they match the chassis's scalar outputs), so no
//! table is generated from a .msg file here.
//!
//! - [`ports`]: the variable table; [`noise`]: the error model; [`adapter`]: the model.

pub mod adapter;
pub mod noise;
pub mod ports;

pub use adapter::ScalarsToOdometry;

agrisim_fmi::export_fmu!(crate::ScalarsToOdometry);
