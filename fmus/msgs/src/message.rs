//! The [`Message`] trait shared by every ROS 2 type, and the FMI mimeType convention.

use crate::cdr::{CdrError, CdrReader, CdrWriter};

/// Prefix of the FMI 3 Binary `mimeType` for ports carrying a CDR-encoded ROS 2 message
/// (DESIGN.md §3); the full value is `application/x-ros2-cdr; type=<TYPE_NAME>`.
pub const MIME_PREFIX: &str = "application/x-ros2-cdr; type=";

/// A ROS 2 message type with its CDR encoding.
///
/// `write`/`read` handle the body only (no encapsulation header) so that messages nest;
/// `to_cdr`/`from_cdr` add/check the header and are what ports and MCAP records carry.
pub trait Message: Sized {
    /// Full ROS 2 name, `pkg/msg/Type` (what rosbag2 stores as the topic type and MCAP as
    /// the schema name).
    const TYPE_NAME: &'static str;

    /// Appends the fields in declaration order.
    fn write(&self, w: &mut CdrWriter);

    /// Reads the fields in declaration order.
    fn read(r: &mut CdrReader<'_>) -> Result<Self, CdrError>;

    /// Header + body, ready for an FMI Binary port or an MCAP message record.
    fn to_cdr(&self) -> Vec<u8> {
        let mut w = CdrWriter::new();
        self.write(&mut w);
        w.into_bytes()
    }

    /// Decodes header + body; trailing bytes (peers pad to 4 bytes) are ignored.
    fn from_cdr(bytes: &[u8]) -> Result<Self, CdrError> {
        let mut r = CdrReader::new(bytes)?;
        Self::read(&mut r)
    }
}

/// `application/x-ros2-cdr; type=<M::TYPE_NAME>`. Every built-in type also has an
/// inherent `MIME_TYPE` const with the same value for use in const contexts.
pub fn mime_type<M: Message>() -> String {
    mime_type_for(M::TYPE_NAME)
}

/// The mimeType for a type given by name (e.g. read from an SSP file).
pub fn mime_type_for(type_name: &str) -> String {
    format!("{MIME_PREFIX}{type_name}")
}

/// Inverse of [`mime_type_for`]: the ROS type name in a ROS 2 CDR mimeType, tolerating
/// extra spaces around `;` and `=`. `None` for any other mimeType.
pub fn type_name_from_mime(mime: &str) -> Option<&str> {
    let (media, param) = mime.split_once(';')?;
    if media.trim() != "application/x-ros2-cdr" {
        return None;
    }
    let (key, value) = param.split_once('=')?;
    if key.trim() != "type" {
        return None;
    }
    let value = value.trim();
    (!value.is_empty()).then_some(value)
}

/// Defines a message struct and implements [`Message`] and [`CdrField`](crate::cdr::CdrField)
/// for it by encoding the fields in declaration order (which is exactly the CDR rule for
/// structs). Derives are given at the call site because some types need a hand-written
/// `Default` (arrays longer than 32, Quaternion's `w = 1`).
macro_rules! ros_message {
    (
        $(#[$meta:meta])*
        pub struct $name:ident = $type_name:literal {
            $( $(#[$fmeta:meta])* pub $field:ident : $fty:ty ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        pub struct $name {
            $( $(#[$fmeta])* pub $field: $fty, )*
        }

        impl $name {
            /// FMI Binary mimeType for ports carrying this type.
            pub const MIME_TYPE: &'static str =
                concat!("application/x-ros2-cdr; type=", $type_name);
        }

        impl $crate::message::Message for $name {
            const TYPE_NAME: &'static str = $type_name;
            fn write(&self, w: &mut $crate::cdr::CdrWriter) {
                $( $crate::cdr::CdrField::write_field(&self.$field, w); )*
            }
            fn read(
                r: &mut $crate::cdr::CdrReader<'_>,
            ) -> Result<Self, $crate::cdr::CdrError> {
                // Struct-literal fields are evaluated in source order: the wire order.
                Ok(Self { $( $field: <$fty as $crate::cdr::CdrField>::read_field(r)?, )* })
            }
        }

        impl $crate::cdr::CdrField for $name {
            const MIN_SIZE: usize = 0 $( + <$fty as $crate::cdr::CdrField>::MIN_SIZE )*;
            fn write_field(&self, w: &mut $crate::cdr::CdrWriter) {
                $crate::message::Message::write(self, w)
            }
            fn read_field(
                r: &mut $crate::cdr::CdrReader<'_>,
            ) -> Result<Self, $crate::cdr::CdrError> {
                <Self as $crate::message::Message>::read(r)
            }
        }
    };
}
pub(crate) use ros_message;
