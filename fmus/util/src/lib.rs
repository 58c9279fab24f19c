//! Small pieces every agrisim model uses: publication schedules on simulation time
//! ([`schedule`]). Seeded noise lives in `agrisim_math` (the workspace's one generator).

pub mod schedule;

pub use schedule::{to_ns, Schedule};
