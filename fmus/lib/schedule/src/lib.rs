//! When and on how many threads agrisim's models do their work: publication schedules on
//! simulation time ([`schedule`]) and work shared by a few threads ([`workers`]). Seeded noise
//! lives in `agrisim_math` (the workspace's one generator).

pub mod schedule;
pub mod workers;

pub use schedule::{to_ns, Schedule};
pub use workers::on_threads;
