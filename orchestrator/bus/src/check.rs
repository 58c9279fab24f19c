//! Messages that cross from an FMU port to the bus are checked against the ROS 2 type the
//! port's mimeType names (`application/x-ros2-cdr; type=pkg/msg/Type`).

use crate::error::Result;

/// The ROS 2 type named by a message port's mimeType, or an error naming the connection.
pub fn message_type(mime: &str, file: &str, label: &str) -> Result<String> {
    agrisim_msgs::type_name_from_mime(mime)
        .map(str::to_string)
        .ok_or_else(|| crate::err!("{file}: connection {label}: message port mimeType {mime:?} names no ROS 2 type (expected application/x-ros2-cdr; type=pkg/msg/Type)"))
}

/// A message leaving FMU `comp` on output `var` must decode as the type its port declares.
pub fn check_message(comp: &str, var: &str, ty: &str, bytes: &[u8], t_ns: i64) -> Result<()> {
    match agrisim_msgs::check_cdr(ty, bytes) {
        Some(Err(e)) => Err(crate::err!(
            "FMU '{comp}': output '{var}' at t={} is not a valid {ty} message ({} bytes): {e}",
            t_ns as f64 / 1e9,
            bytes.len()
        )),
        _ => Ok(()),
    }
}
