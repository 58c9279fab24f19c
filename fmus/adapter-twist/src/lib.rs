//! TwistToScalars: an adapter FMU that lets a model with plain Real velocity inputs (an FMI
//! 2.0 chassis from another tool, say) stand where agrisim's chassis takes `cmd_vel`
//! messages. Input: the message port `cmd_vel` (geometry_msgs/msg/Twist frames, the chassis's
//! MIME type) with `cmd_vel_seq`; outputs: one Float64 per field of the message
//! (`linear_x` ... `angular_z`), `count` and `active`; parameter `timeout` (the chassis's
//! cmd_timeout watchdog).
//!
//! The output names are generated at build time from models/msgs/geometry_msgs/msg/Twist.msg
//! (`build.rs`: flattened field paths, `linear.x` -> `linear_x`), never typed by hand.
//!
//! - [`fields`]: the generated field table; [`ports`]: the variable table;
//! - [`adapter`]: the model (command intake, watchdog, outputs).

pub mod adapter;
pub mod fields;
pub mod ports;

pub use adapter::TwistToScalars;

agrisim_fmi::export_fmu!(crate::TwistToScalars);
