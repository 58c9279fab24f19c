//! Tomato greenhouse scene for agrisim: configuration (`[greenhouse]` of a scenario), a
//! deterministic generator, the layout the navigation stack uses, exact ray casting over a
//! BVH, a static occupancy map, and glTF export; for the sensors also the sun's position (NREL
//! SPA, [`solar`]), the scenario's `[environment]` ([`environment`]) and what it means for
//! light and visibility ([`weather`]).
//!
//! ```
//! use agrisim_greenhouse::{generate, GreenhouseConfig, RayCaster};
//! let cfg = GreenhouseConfig::from_toml_str("rows = 3\nactive_rows = 3\nrow_length = 5.0").unwrap();
//! let gh = generate(&cfg, cfg.seed);
//! let rc = RayCaster::new(&gh.objects);
//! let [x, y, _] = gh.layout.start_pose;
//! let hit = rc.cast([x, y, 0.5], [1.0, 0.0, 0.0], 0.1, 100.0, &[]).unwrap();
//! assert!(hit.distance > 0.1);
//! ```

pub mod cast_scene;
pub mod config;
pub mod environment;
pub mod generate;
pub mod gltf;
pub mod layout;
pub mod mesh;
pub mod occupancy;
pub mod raycast;
pub mod scene;
pub mod solar;
pub mod solar_terms;
pub mod weather;

pub use config::{GreenhouseConfig, ObstacleConfig};
pub use generate::{generate, Greenhouse};
pub use layout::{Aisle, Layout, Row};
pub use raycast::{Hit, RayCaster, RigidPose};
pub use scene::{Kind, Object, Placement, Shape};
