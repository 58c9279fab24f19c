//! The sensor side of the world's `moved_objects`: the newest list taken from the input and
//! the scene patched to it ([`MovedScene`]), shared by the camera and the LiDAR.

use crate::SensorPorts;
use agrisim_fmi::{InPort, Store};
use agrisim_raycast::cast_scene::CastScene;
use agrisim_raycast::MovedScene;
use agrisim_scene::{Object, Placement};

/// What a sensor knows of the moved objects. The list and the input's cursor are FMU state;
/// the patched scene follows from them and is rebuilt after a restore.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct MovedInput {
    port: Option<InPort>,
    moves: Vec<(u32, Placement)>,
    #[serde(skip)]
    view: MovedScene,
    /// `view` is patched to `moves`.
    #[serde(skip)]
    applied: bool,
}

impl MovedInput {
    pub fn new(ports: &SensorPorts) -> MovedInput {
        MovedInput { port: Some(InPort::new(ports.moved[0], ports.moved[1])), ..MovedInput::default() }
    }

    /// Takes what came in on `moved_objects` and patches the scene to the newest list. A
    /// malformed message is an error naming the input; the list stays as it was.
    pub fn take(&mut self, io: &Store, ports: &SensorPorts, base: &CastScene) -> Result<(), String> {
        let port = self.port.get_or_insert_with(|| InPort::new(ports.moved[0], ports.moved[1]));
        if let Some(moves) = ports.moved_objects(io, port, base.object_count())? {
            self.applied &= moves == self.moves;
            self.moves = moves;
        }
        if !self.applied {
            self.view.update(base, &self.moves);
            self.applied = true;
        }
        Ok(())
    }

    /// The scene to cast at (`base` while nothing moved).
    pub fn scene<'a>(&'a self, base: &'a CastScene) -> &'a CastScene {
        self.view.scene(base)
    }

    /// The moved objects at their placements, to cast among the frame's moving objects.
    pub fn objects(&self) -> Vec<Object> {
        self.view.objects()
    }
}
