//! agrisim-session: what a scenario runs. A [`Session`] couples the engine (agrisim-cosim:
//! FMUs, system, master) to the message layer (agrisim-bus: topics, recorder) and the
//! algorithm nodes; [`run::prepare`] builds one from a scenario file ([`Scenario`]) with its
//! parameters, seed and recording. The CLI, the benchmarks and embedding programs (Python,
//! a ROS 2 bridge) start here.
//!
//! The engine knows nothing of the greenhouse: the scenario's `[greenhouse]` reaches the FMUs
//! as the text of their `scene` parameter, and the robot's start pose as parameters.

pub mod interrupt;
pub mod run;
pub mod scenario;
pub mod scene;
pub mod session;
pub mod viewer;

pub use agrisim_bus::{Profile, RecordPolicy};
pub use run::{prepare, RunOptions, RunSummary};
pub use scenario::{PriorMap, Scenario};
pub use session::{Session, SessionSnapshot};
