//! The [`Message`] trait shared by every ROS 2 type, and the FMI mimeType convention.

use crate::cdr::{CdrError, CdrReader, CdrWriter};

/// Prefix of the FMI 3 Binary `mimeType` of agrisim message ports: a frame list of CDR
/// ROS 2 messages (the `agrisim-frames` format, version 1; DESIGN.md §3); the full value is
/// `application/x-ros2-cdr-frames; version=1; type=<TYPE_NAME>`.
pub const MIME_PREFIX: &str = "application/x-ros2-cdr-frames; version=1; type=";

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

    /// Reads past the fields, failing exactly where [`Message::read`] would, without
    /// building the message.
    fn skip(r: &mut CdrReader<'_>) -> Result<(), CdrError> {
        Self::read(r).map(drop)
    }

    /// [`Message::from_cdr`]'s verdict without the message: the same error, or Ok.
    fn check_cdr(bytes: &[u8]) -> Result<(), CdrError> {
        let mut r = CdrReader::new(bytes)?;
        Self::skip(&mut r)
    }
}

/// `application/x-ros2-cdr-frames; version=1; type=<M::TYPE_NAME>`. Every built-in type also has an
/// inherent `MIME_TYPE` const with the same value for use in const contexts.
pub fn mime_type<M: Message>() -> String {
    mime_type_for(M::TYPE_NAME)
}

/// The mimeType for a type given by name (e.g. read from an SSP file).
pub fn mime_type_for(type_name: &str) -> String {
    format!("{MIME_PREFIX}{type_name}")
}

/// The ROS type name of a message port's mimeType: a frame list
/// (`application/x-ros2-cdr-frames; version=1; type=...`, see [`mime_type_for`]) or a single
/// CDR message (`application/x-ros2-cdr; type=...`), parameters in any order, tolerating
/// spaces around `;` and `=`. `None` for any other mimeType.
pub fn type_name_from_mime(mime: &str) -> Option<&str> {
    let mut parts = mime.split(';');
    let media = parts.next()?.trim();
    if media != "application/x-ros2-cdr" && media != "application/x-ros2-cdr-frames" {
        return None;
    }
    let value = parts.find_map(|p| p.split_once('=').filter(|(k, _)| k.trim() == "type").map(|(_, v)| v.trim()))?;
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
                concat!("application/x-ros2-cdr-frames; version=1; type=", $type_name);
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
            fn skip(
                r: &mut $crate::cdr::CdrReader<'_>,
            ) -> Result<(), $crate::cdr::CdrError> {
                $( <$fty as $crate::cdr::CdrField>::skip_field(r)?; )*
                Ok(())
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
            fn skip_field(
                r: &mut $crate::cdr::CdrReader<'_>,
            ) -> Result<(), $crate::cdr::CdrError> {
                <Self as $crate::message::Message>::skip(r)
            }
        }
    };
}
pub(crate) use ros_message;
