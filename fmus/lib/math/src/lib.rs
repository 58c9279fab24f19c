//! Numerical building blocks shared by agrisim's models and orchestrator, kept in one place
//! so that no two crates grow their own copy:
//!
//! - [`rng`]: the workspace's one random-number generator ([`Rng`], SplitMix64), with the
//!   sensor-noise flavour ([`Rng::new`]) and the scene-generation flavour ([`Rng::scene`],
//!   [`Rng::stream`]);
//! - [`pose2`]: the one planar pose / rigid transform ([`Pose2`]) with the angle wraps
//!   [`wrap_angle`] and [`wrap_angle_euclid`] (its message conversions are in `agrisim-msgs`);
//! - [`vec3`]: 3-vector and 3x3 matrix products on plain arrays (dot, cross, `m v`, `a b`).
//!
//! Everything here feeds byte-compared simulation logs: a change to an arithmetic expression
//! or a draw order changes results. `tests/pinned.rs` pins the sequences.

pub mod pose2;
pub mod rng;
pub mod vec3;

pub use pose2::{wrap_angle, wrap_angle_euclid, Pose2};
pub use rng::Rng;
