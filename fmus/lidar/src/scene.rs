//! The geometry rays are cast at: the greenhouse generated from the scenario's TOML and seed
//! (exactly what the world FMU builds) plus the robot's own base box, which moves.
//!
//! Generating a greenhouse and its BVH takes a while and every instance of a run (and every
//! trial of a benchmark) asks for the same one, so the last scene built is kept per process
//! and shared read-only.

use crate::reflectivity;
use agrisim_greenhouse::{generate, GreenhouseConfig, Kind, Object, Placement, RayCaster, Shape};
use std::sync::{Arc, Mutex};

/// The static scene, prepared for casting.
pub struct Scene {
    pub caster: RayCaster,
    /// Diffuse reflectivity per object id (ids are dense from 0).
    pub reflectivity: Vec<f64>,
    pub object_count: usize,
}

impl std::fmt::Debug for Scene {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Scene({} objects)", self.object_count)
    }
}

type Cached = (String, u64, Arc<Scene>);
static LAST: Mutex<Option<Cached>> = Mutex::new(None);

/// The scene for `toml` (keys of `[greenhouse]`, "" = default) and `seed` (< 0: the
/// configuration's own seed key, as the world FMU does).
pub fn load(toml: &str, seed: i32) -> Result<Arc<Scene>, String> {
    let cfg = GreenhouseConfig::from_toml_str(toml).map_err(|e| format!("parameter scene: {e}"))?;
    let seed = if seed < 0 { cfg.seed } else { seed as u64 };
    let mut last = LAST.lock().unwrap_or_else(|p| p.into_inner());
    if let Some((t, s, scene)) = last.as_ref() {
        if t == toml && *s == seed {
            return Ok(scene.clone());
        }
    }
    let gh = generate(&cfg, seed);
    let mut reflectivity = vec![0.0; gh.objects.len()];
    for o in &gh.objects {
        if let Some(r) = reflectivity.get_mut(o.id as usize) {
            *r = reflectivity::of_kind(o.kind);
        }
    }
    let scene = Arc::new(Scene { caster: RayCaster::new(&gh.objects), object_count: gh.objects.len(), reflectivity });
    *last = Some((toml.to_string(), seed, scene.clone()));
    Ok(scene)
}

/// The robot base as a box around base_link: footprint length x width, from `clearance` to
/// `clearance + height` above the floor (base_link on the floor, as the world FMU has it).
#[derive(Clone, Debug)]
pub struct BaseBox {
    pub object: Object,
    half_height: f64,
    clearance: f64,
}

impl BaseBox {
    /// `id` should not collide with scene ids (use the scene's object count).
    pub fn new(id: u32, length: f64, width: f64, height: f64, clearance: f64) -> BaseBox {
        let half = [length / 2.0, width / 2.0, height / 2.0];
        let object = Object { id, name: "base_link".into(), kind: Kind::Robot, shape: Shape::Box { half }, placement: Placement::IDENTITY };
        BaseBox { object, half_height: half[2], clearance }
    }

    /// Moves the box to base_link at (x, y, yaw).
    pub fn place(&mut self, x: f64, y: f64, yaw: f64) {
        self.object.placement = Placement::yawed([x, y, self.clearance + self.half_height], yaw);
    }
}
