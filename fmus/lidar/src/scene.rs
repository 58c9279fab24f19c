//! The geometry rays are cast at: the shared sensor scene of the greenhouse crate (exactly
//! what the world FMU builds) plus the robot's own base box, which moves.

use agrisim_greenhouse::cast_scene::base_box;
use agrisim_greenhouse::Object;

pub use agrisim_greenhouse::cast_scene::{load_cached as load, CastScene as Scene};

/// The robot base box, re-placed at every pose the scan is taken from.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct BaseBox {
    pub object: Object,
    dims: [f64; 4],
}

impl BaseBox {
    /// `id` should not collide with scene ids (use the scene's object count).
    pub fn new(id: u32, length: f64, width: f64, height: f64, clearance: f64) -> BaseBox {
        let dims = [length, width, height, clearance];
        BaseBox { object: base_box(id, dims, 0.0, 0.0, 0.0), dims }
    }

    /// Moves the box to base_link at (x, y, yaw).
    pub fn place(&mut self, x: f64, y: f64, yaw: f64) {
        self.object = base_box(self.object.id, self.dims, x, y, yaw);
    }
}
