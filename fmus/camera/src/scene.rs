//! The geometry the camera sees: the greenhouse generated from the scenario's TOML and seed
//! (what the world and LiDAR FMUs build) plus the robot's base box. Kept per process for the
//! last (scene, seed) asked for, shared read-only.

use agrisim_greenhouse::{generate, GreenhouseConfig, Kind, Object, Placement, RayCaster, Shape};
use std::sync::{Arc, Mutex};

pub struct Scene {
    pub caster: RayCaster,
    /// Kind per object id (ids dense from 0).
    pub kinds: Vec<Kind>,
}

impl std::fmt::Debug for Scene {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Scene({} objects)", self.kinds.len())
    }
}

impl Scene {
    /// Any object list with dense ids (for tests and tools).
    pub fn from_objects(objects: &[Object]) -> Scene {
        let mut kinds = vec![Kind::Obstacle; objects.len()];
        for o in objects {
            if let Some(k) = kinds.get_mut(o.id as usize) {
                *k = o.kind;
            }
        }
        Scene {
            caster: RayCaster::new(objects),
            kinds,
        }
    }

    pub fn object_count(&self) -> usize {
        self.kinds.len()
    }

    /// Kind of a hit object id; ids beyond the scene are the robot's own links.
    pub fn kind(&self, id: u32) -> Kind {
        self.kinds.get(id as usize).copied().unwrap_or(Kind::Robot)
    }
}

type Cached = (String, u64, Arc<Scene>);
static LAST: Mutex<Option<Cached>> = Mutex::new(None);

/// The scene for `toml` (keys of `[greenhouse]`, "" = default) and `seed` (< 0: the
/// configuration's own seed key).
pub fn load(toml: &str, seed: i32) -> Result<Arc<Scene>, String> {
    let cfg = GreenhouseConfig::from_toml_str(toml).map_err(|e| format!("parameter scene: {e}"))?;
    let seed = if seed < 0 { cfg.seed } else { seed as u64 };
    let mut last = LAST.lock().unwrap_or_else(|p| p.into_inner());
    if let Some((t, s, scene)) = last.as_ref() {
        if t == toml && *s == seed {
            return Ok(scene.clone());
        }
    }
    let scene = Arc::new(Scene::from_objects(&generate(&cfg, seed).objects));
    *last = Some((toml.to_string(), seed, scene.clone()));
    Ok(scene)
}

/// The robot base as a box around base_link (footprint length x width, from `clearance` to
/// `clearance + height` above the floor; `dims` = [length, width, height, clearance]), as the
/// world and LiDAR FMUs have it, for base_link at (x, y, yaw).
pub fn base_box(id: u32, dims: [f64; 4], x: f64, y: f64, yaw: f64) -> Object {
    let [length, width, height, clearance] = dims;
    Object {
        id,
        name: "base_link".into(),
        kind: Kind::Robot,
        shape: Shape::Box {
            half: [0.5 * length, 0.5 * width, 0.5 * height],
        },
        placement: Placement::yawed([x, y, clearance + 0.5 * height], yaw),
    }
}
