//! The Twist fields that become Float64 outputs, generated at build time from the .msg
//! definition (see `build.rs`): `FIELDS` and `field_values`.

use agrisim_msgs::geometry_msgs::Twist;

/// One float64 leaf of the message.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Field {
    /// Port name: the field path joined with `_` (`linear_x`).
    pub name: &'static str,
    /// Field path as in the .msg (`linear.x`).
    pub path: &'static str,
    pub unit: &'static str,
    pub desc: &'static str,
}

include!(concat!(env!("OUT_DIR"), "/twist_fields.rs"));

/// Number of Float64 outputs.
pub const N: usize = FIELDS.len();
