//! agrisim-bus: the communication layer. ROS 2 topics as the algorithm layer sees them
//! ([`Bus`]), the [`Node`] trait every algorithm implements, message checks against the
//! types named by FMU ports' mimeTypes ([`check`]), and MCAP recording in the ROS 2 profile
//! ([`Recorder`]).
//!
//! No FMI in here: the engine (agrisim-cosim) and this layer meet in agrisim-session, so an
//! algorithm crate that depends on this one never links the FMU importer.

pub mod bus;
pub mod check;
pub mod ground_truth;
pub mod node;
pub mod policy;
mod record_queue;
pub mod recorder;

pub use agrisim_error::{err, Context, Error, Result};
pub use bus::{Bus, Published, Reader, Sample, Tap};
pub use node::{Charged, Node};
pub use policy::{Profile, RecordPolicy};

/// Topics whose publisher sends a message once (or on change) and whose readers need the last
/// one whenever they join: ROS 2's transient local durability ("latched"). The bridges offer
/// them so, the recorder marks them so in `offered_qos_profiles`, and the Foxglove view sends
/// a late subscriber the last message.
pub const LATCHED_TOPICS: [&str; 5] =
    ["/tf_static", "/map", "/robot_description", "/scene/markers", "/scene/fruit_markers"];

/// Whether `topic` is one of [`LATCHED_TOPICS`].
pub fn is_latched(topic: &str) -> bool {
    LATCHED_TOPICS.contains(&topic)
}
pub use recorder::{part_path, Channel, Chunks, Payload, Recorder};

/// `crate::error::...` paths inside this crate.
pub(crate) mod error {
    pub use agrisim_error::{Context, Result};
}
