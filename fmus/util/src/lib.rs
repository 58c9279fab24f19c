//! Small pieces every agrisim model uses: publication schedules on simulation time
//! ([`schedule`]). Seeded noise lives in `agrisim_math` ([`Rng`] is re-exported here only
//! until the last users switch to `agrisim_math::Rng`).

pub mod schedule;

pub use agrisim_math::Rng;
pub use schedule::{to_ns, Schedule};
