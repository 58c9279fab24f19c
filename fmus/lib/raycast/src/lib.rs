//! Ray casting at the greenhouse scene (`agrisim-scene`), for the LiDAR and the camera:
//! a binned-SAH BVH collapsed into a conservative 4-wide f32 tree, over exact f64 primitives
//! (box, capped cylinder, sphere). The nearest hit wins, ties go to the lower object id, so
//! every answer equals a brute-force scan over all objects ([`cast_brute_force`], which the
//! tests compare with). [`cast_scene`] keeps the scene a run's sensors share.
//!
//! ```
//! use agrisim_raycast::RayCaster;
//! use agrisim_scene::{generate, GreenhouseConfig};
//! let cfg = GreenhouseConfig::from_toml_str("rows = 3\nactive_rows = 3\nrow_length = 5.0").unwrap();
//! let gh = generate(&cfg, cfg.seed);
//! let rc = RayCaster::new(&gh.objects);
//! let [x, y, _] = gh.layout.start_pose;
//! let hit = rc.cast([x, y, 0.5], [1.0, 0.0, 0.0], 0.1, 100.0, &[]).unwrap();
//! assert!(hit.distance > 0.1);
//! ```

mod bvh;
pub mod cast_scene;
mod caster;
pub mod moved;
mod packet;
mod primitives;
mod sun_columns;
mod wide;

pub use caster::{cast_brute_force, Hit, Occluders, RayCaster, RigidPose};
pub use moved::MovedScene;
pub use packet::MAX_PACKET;
pub use sun_columns::{Shadow, SunColumns};
