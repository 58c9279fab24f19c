//! Tomato greenhouse scene for agrisim: configuration (`[greenhouse]` of a scenario), a
//! deterministic generator, the layout the navigation stack uses, and a static occupancy map.
//! Ray casting at the scene (`agrisim-raycast`), its glTF export (`agrisim-gltf`) and the sun
//! and weather (`agrisim-sky`) are crates of their own over this one.
//!
//! ```
//! use agrisim_scene::{generate, GreenhouseConfig, Kind};
//! let cfg = GreenhouseConfig::from_toml_str("rows = 3\nactive_rows = 3\nrow_length = 5.0").unwrap();
//! let gh = generate(&cfg, cfg.seed);
//! assert_eq!(gh.layout.rows.len(), 3);
//! assert!(gh.objects.iter().any(|o| matches!(o.kind, Kind::Fruit { .. })));
//! ```

pub mod config;
pub mod crop;
pub mod family;
pub mod generate;
pub mod layout;
pub mod occupancy;
pub mod scene;

pub use config::{GreenhouseConfig, ObstacleConfig};
pub use crop::Crop;
pub use family::FamilyConfig;
pub use generate::{generate, Greenhouse};
pub use layout::{Aisle, Layout, Row};
pub use scene::{Kind, Object, Placement, Shape};
