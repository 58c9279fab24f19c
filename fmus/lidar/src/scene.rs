//! The geometry rays are cast at: the shared sensor scene of the greenhouse crate (exactly
//! what the world FMU builds) plus the robot's own body (base box and URDF links, see
//! `agrisim_sensor_ports::robot`), prepared in base_link: rays are taken into base_link at
//! each pose of the scan instead of the robot being re-placed, and the body is rebuilt only
//! when the lift, arm or finger inputs change.

use agrisim_raycast::RayCaster;
use agrisim_sensor_ports::robot::{Coords, RobotBody};

pub use agrisim_raycast::cast_scene::{load_cached as load, CastScene as Scene};

/// The robot in base_link for the configuration it was last built for.
#[derive(Clone, Debug)]
pub struct RobotInBaseLink {
    body: RobotBody,
    coords: Option<Coords>,
    pub caster: RayCaster,
}

impl RobotInBaseLink {
    pub fn new(body: RobotBody, coords: Option<Coords>) -> RobotInBaseLink {
        let caster = RayCaster::new(&body.objects(coords.as_ref(), 0.0, 0.0, 0.0));
        RobotInBaseLink { body, coords, caster }
    }

    /// Re-poses the links for `coords` (nothing to do when they are unchanged).
    pub fn update(&mut self, coords: Option<Coords>) {
        if coords != self.coords {
            self.caster = RayCaster::new(&self.body.objects(coords.as_ref(), 0.0, 0.0, 0.0));
            self.coords = coords;
        }
    }
}
