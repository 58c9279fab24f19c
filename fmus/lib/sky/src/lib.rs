//! Sun and weather for the sensors: a scenario's `[environment]` ([`environment`]: date, place,
//! weather, cover, render quality), the sun's position (NREL SPA, [`solar`]) and what they
//! mean for light and visibility ([`weather`]). Nothing here touches geometry: the scene
//! depends on `[greenhouse]` and its seed only.
//!
//! ```
//! use agrisim_sky::{environment::Environment, weather::Conditions};
//! let env = Environment::from_toml_str("date = \"2024-06-21\"\ntime = \"12:00\"").unwrap();
//! let c = Conditions::of(&env);
//! assert!(c.sun.elevation > 0.0 && c.dni > 0.0);
//! ```

pub mod environment;
pub mod solar;
pub mod solar_terms;
pub mod weather;
