//! The geometry rays are cast at: the shared sensor scene of the greenhouse crate (exactly
//! what the world FMU builds) plus the robot, prepared once in base_link: rays are taken into
//! base_link at each pose of the scan instead of the robot being re-placed.

use agrisim_greenhouse::cast_scene::base_box;
use agrisim_greenhouse::RayCaster;

pub use agrisim_greenhouse::cast_scene::{load_cached as load, CastScene as Scene};

/// The robot base box in base_link (`dims` = [length, width, height, clearance]), with ids
/// from `first_id` (use the scene's object count so they do not collide with scene ids).
pub fn robot_in_base_link(first_id: u32, dims: [f64; 4]) -> RayCaster {
    RayCaster::new(&[base_box(first_id, dims, 0.0, 0.0, 0.0)])
}
