//! Small pieces every agrisim model uses: seeded, platform-independent noise ([`noise`]) and
//! publication schedules on simulation time ([`schedule`]).

pub mod noise;
pub mod schedule;

pub use noise::Rng;
pub use schedule::{to_ns, Schedule};
