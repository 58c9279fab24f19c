//! The scene as ray-casting sensors need it (LiDAR, camera): the greenhouse generated from a
//! scenario's `[greenhouse]` TOML and seed, in a BVH, with each object's kind; plus the
//! robot's base box, which moves and is passed to every cast.
//!
//! Generating a greenhouse and its BVH takes a while and every sensor instance of a run (and
//! every trial of a benchmark) asks for the same one, so the last scene built is kept per
//! process and shared read-only.

use crate::RayCaster;
use agrisim_scene::{generate, GreenhouseConfig, Kind, Object, Placement, Shape};
use std::sync::{Arc, Mutex};

#[derive(Clone)]
pub struct CastScene {
    pub caster: RayCaster,
    /// Kind per object id (ids dense from 0).
    pub kinds: Vec<Kind>,
    /// Shape and placement per object id, for the camera's detail inside an object's
    /// collider (a fruit's shape and calyx, a leaflet's outline).
    pub geometry: Vec<(Shape, Placement)>,
}

impl std::fmt::Debug for CastScene {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "CastScene({} objects)", self.kinds.len())
    }
}

impl CastScene {
    /// Any object list with dense ids (for tests and tools).
    pub fn from_objects(objects: &[Object]) -> CastScene {
        let mut kinds = vec![Kind::Obstacle; objects.len()];
        let mut geometry = vec![(Shape::Sphere { radius: 0.0 }, Placement::IDENTITY); objects.len()];
        for o in objects {
            if let (Some(k), Some(g)) = (kinds.get_mut(o.id as usize), geometry.get_mut(o.id as usize)) {
                *k = o.kind;
                *g = (o.shape, o.placement);
            }
        }
        CastScene { caster: RayCaster::new(objects), kinds, geometry }
    }

    pub fn object_count(&self) -> usize {
        self.kinds.len()
    }

    /// Kind of a hit object id; ids beyond the scene are the robot's own links.
    pub fn kind(&self, id: u32) -> Kind {
        self.kinds.get(id as usize).copied().unwrap_or(Kind::Robot)
    }
}

type Cached = (String, u64, Arc<CastScene>);
static LAST: Mutex<Option<Cached>> = Mutex::new(None);

/// The scene for `toml` (keys of `[greenhouse]`, "" = default) and `seed` (< 0: the
/// configuration's own seed key, as the world FMU does). Errors name the `scene` parameter.
pub fn load_cached(toml: &str, seed: i32) -> Result<Arc<CastScene>, String> {
    let cfg = GreenhouseConfig::from_toml_str(toml).map_err(|e| format!("parameter scene: {e}"))?;
    let seed = if seed < 0 { cfg.seed } else { seed as u64 };
    let mut last = LAST.lock().unwrap_or_else(|p| p.into_inner());
    if let Some((t, s, scene)) = last.as_ref() {
        if t == toml && *s == seed {
            return Ok(scene.clone());
        }
    }
    let scene = Arc::new(CastScene::from_objects(&generate(&cfg, seed).objects));
    *last = Some((toml.to_string(), seed, scene.clone()));
    Ok(scene)
}

/// The robot base as a box around base_link (footprint length x width, from `clearance` to
/// `clearance + height` above the floor; `dims` = [length, width, height, clearance]), as the
/// world FMU has it, for base_link at (x, y, yaw). `id` should follow the scene's ids.
pub fn base_box(id: u32, dims: [f64; 4], x: f64, y: f64, yaw: f64) -> Object {
    let [length, width, height, clearance] = dims;
    Object {
        id,
        name: "base_link".into(),
        kind: Kind::Robot,
        shape: Shape::Box { half: [0.5 * length, 0.5 * width, 0.5 * height] },
        placement: Placement::yawed([x, y, clearance + 0.5 * height], yaw),
    }
}
