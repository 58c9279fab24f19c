//! Numerical building blocks shared by agrisim's models and orchestrator, kept in one place
//! so that no two crates grow their own copy:
//!
//! - [`rng`]: the workspace's one random-number generator ([`Rng`], SplitMix64), with the
//!   sensor-noise flavour ([`Rng::new`]) and the scene-generation flavour ([`Rng::scene`],
//!   [`Rng::stream`]);
//! - [`pose2`]: the one planar pose / rigid transform ([`Pose2`]) with [`yaw_of`] and the
//!   angle wraps [`wrap_angle`] and [`wrap_angle_euclid`].
//!
//! Everything here feeds byte-compared simulation logs: a change to an arithmetic expression
//! or a draw order changes results. `tests/pinned.rs` pins the sequences.

pub mod pose2;
pub mod rng;

pub use pose2::{wrap_angle, wrap_angle_euclid, yaw_of, Pose2};
pub use rng::Rng;
