//! Benchmarks: the master's overhead, and the many-trial evaluations (navigation) with honest
//! statistics and every trial recorded.

pub mod harvest;
pub mod harvest_targets;
pub mod nav;
pub mod overhead;
pub mod report;
pub mod stats;
pub mod targets;

pub use overhead::{overhead, OverheadReport};
