//! agrisim-bus: the communication layer. ROS 2 topics as the algorithm layer sees them
//! ([`Bus`]), the [`Node`] trait every algorithm implements, message checks against the
//! types named by FMU ports' mimeTypes ([`check`]), and MCAP recording in the ROS 2 profile
//! ([`Recorder`]).
//!
//! No FMI in here: the engine (agrisim-cosim) and this layer meet in agrisim-session, so an
//! algorithm crate that depends on this one never links the FMU importer.

pub mod bus;
pub mod check;
pub mod node;
pub mod policy;
mod record_queue;
pub mod recorder;

pub use agrisim_error::{err, Context, Error, Result};
pub use bus::{Bus, Published, Reader, Sample, Tap};
pub use node::Node;
pub use policy::{Profile, RecordPolicy};
pub use recorder::{part_path, Channel, Chunks, Payload, Recorder};

/// `crate::error::...` paths inside this crate.
pub(crate) mod error {
    pub use agrisim_error::{Context, Result};
}
