//! Small pieces every agrisim model uses: publication schedules on simulation time
//! ([`schedule`]), work shared by a few threads ([`workers`]). Seeded noise lives in `agrisim_math` (the workspace's one generator).

pub mod schedule;
pub mod workers;

pub use schedule::{to_ns, Schedule};
pub use workers::on_threads;
