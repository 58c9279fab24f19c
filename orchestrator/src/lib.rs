//! agrisim orchestrator: imports FMI 3.0 co-simulation FMUs, composes them from an SSP
//! system structure, steps them on integer ticks with per-connection exchange rates, runs
//! the algorithm layer's nodes on ROS 2 messages, and records everything to MCAP.

pub mod archive;
pub mod bench;
pub mod bus;
pub mod error;
pub mod fmi3;
pub mod harvest;
pub mod master;
pub mod model_description;
pub mod nav;
pub mod nodes;
pub mod pack;
pub mod png;
pub mod recorder;
pub mod run;
pub mod scenario;
pub mod scene;
pub mod snapshot;
pub mod ssp;
pub mod system;
pub mod value;
