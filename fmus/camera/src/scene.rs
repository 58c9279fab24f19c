//! The geometry the camera sees: the shared sensor scene of the greenhouse crate (what the
//! world and LiDAR FMUs build); the robot's own body comes from `agrisim_sensor_ports::robot`.

pub use agrisim_raycast::cast_scene::{base_box, load_cached as load, CastScene as Scene};
