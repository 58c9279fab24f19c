//! The domain randomization: every random choice of a scene or a frame, drawn from a stream
//! keyed by (dataset seed, what, scene or frame index) (`agrisim_math::Rng::stream`), so a
//! frame's draws depend on its index alone: a resumed run draws what an uninterrupted one did.

use agrisim_math::Rng;
use agrisim_scene::{Aisle, GreenhouseConfig};
use std::f64::consts::{FRAC_PI_2, PI};

// Stream labels, so streams of different purposes never coincide.
const SCENE: u64 = 1;
const FRAME: u64 = 2;
const HUE: u64 = 3;

/// Leaf density is scaled by a factor in this range (then rounded), leaf length and width
/// each by one in `LEAF_SIZE_SCALE`.
const LEAF_DENSITY_SCALE: (f64, f64) = (0.5, 1.5);
const LEAF_SIZE_SCALE: (f64, f64) = (0.7, 1.3);

/// Largest hue shift of a fruit's pixels [deg] (uniform in +-).
pub const FRUIT_HUE_DEG: f64 = 8.0;

fn uniform(r: &mut Rng, lo: f64, hi: f64) -> f64 {
    lo + (hi - lo) * r.scene_uniform()
}

/// A scene: the scenario's greenhouse grown from another seed, with leaf density and size
/// drawn around the scenario's values.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct SceneDraw {
    pub index: u64,
    /// The greenhouse generator's seed: the scenario's scene seed + index.
    pub greenhouse_seed: u64,
    pub leaf_density: usize,
    pub leaf_size: [f64; 2],
    /// The `[greenhouse]` keys of this scene as TOML (what the Camera FMU's `scene` gets).
    pub greenhouse: String,
}

/// Scene `index` of a scenario whose `[greenhouse]` table is `table` (its `seed` filled in).
pub fn scene(seed: u64, index: u64, table: &toml::Table) -> Result<SceneDraw, String> {
    let base = GreenhouseConfig::from_toml_str(&toml::to_string(table).map_err(|e| e.to_string())?)?;
    let mut r = Rng::stream(seed, &[SCENE, index]);
    let density = (base.leaf_density as f64 * uniform(&mut r, LEAF_DENSITY_SCALE.0, LEAF_DENSITY_SCALE.1)).round();
    let size = base.leaf_size.map(|s| s * uniform(&mut r, LEAF_SIZE_SCALE.0, LEAF_SIZE_SCALE.1));
    let greenhouse_seed = base.seed.wrapping_add(index);
    let mut t = table.clone();
    t.insert("seed".into(), toml::Value::Integer(greenhouse_seed as i64));
    t.insert("leaf_density".into(), toml::Value::Integer(density as i64));
    t.insert("leaf_size".into(), toml::Value::Array(size.iter().map(|&v| toml::Value::Float(v)).collect()));
    let text = toml::to_string(&t).map_err(|e| e.to_string())?;
    GreenhouseConfig::from_toml_str(&text)?;
    Ok(SceneDraw { index, greenhouse_seed, leaf_density: density as usize, leaf_size: size, greenhouse: text })
}

/// Which way the robot faces in its aisle.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Heading {
    /// Toward the row on the aisle's +y side (the camera looks at its plants).
    RowLeft,
    RowRight,
    /// Along the aisle, +x or -x.
    AisleForward,
    AisleBackward,
}

/// Everything random about one frame.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct FrameDraw {
    pub aisle: usize,
    pub heading: Heading,
    /// base_link in the map: x, y [m], yaw [rad].
    pub base: [f64; 3],
    /// Lift extension [m] (raises the camera).
    pub lift: f64,
    /// Added to the mount: x, y, z [m], roll, pitch, yaw [rad].
    pub mount_jitter: [f64; 6],
    /// Environment keys: date, local time, compass bearing of map +x, weather, visibility.
    pub date: String,
    pub time: String,
    pub map_x_bearing: f64,
    pub weather: &'static str,
    pub visibility: Option<f64>,
    /// Post-processing: exposure [EV] and white-balance gains (r, g, b) on linear light.
    pub exposure_ev: f64,
    pub white_balance: [f64; 3],
    /// Seed of the camera's depth noise.
    pub noise_seed: i32,
}

const DAYS: [u32; 12] = [31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31];

/// Frame `index`, in an aisle of `aisles` (at least one).
pub fn frame(seed: u64, index: u64, aisles: &[Aisle]) -> FrameDraw {
    let mut r = Rng::stream(seed, &[FRAME, index]);
    let aisle = r.next_u64() % aisles.len() as u64;
    let a = &aisles[aisle as usize];
    let heading = match uniform(&mut r, 0.0, 1.0) {
        h if h < 0.35 => Heading::RowLeft,
        h if h < 0.70 => Heading::RowRight,
        h if h < 0.85 => Heading::AisleForward,
        _ => Heading::AisleBackward,
    };
    let (yaw, dy) = match heading {
        // Turned across the aisle the 1.2 m base leaves 0.4 m to the foliage of a 2 m aisle.
        Heading::RowLeft => (FRAC_PI_2, 0.1),
        Heading::RowRight => (-FRAC_PI_2, 0.1),
        Heading::AisleForward => (0.0, 0.25),
        Heading::AisleBackward => (PI, 0.25),
    };
    let margin = 1.0f64.min(0.25 * (a.x_end - a.x_start));
    let base = [
        uniform(&mut r, a.x_start + margin, a.x_end - margin),
        a.y + uniform(&mut r, -dy, dy),
        yaw + uniform(&mut r, -5f64, 5.0).to_radians(),
    ];
    // The lift's travel (Lift FMU position_max 0.8 m).
    let lift = uniform(&mut r, 0.0, 0.8);
    let d = 0.02;
    let mount_jitter = [
        uniform(&mut r, -d, d),
        uniform(&mut r, -d, d),
        uniform(&mut r, -d, d),
        uniform(&mut r, -2.0, 2.0).to_radians(),
        uniform(&mut r, -8.0, 8.0).to_radians(),
        uniform(&mut r, -3.0, 3.0).to_radians(),
    ];
    let mut day = (r.next_u64() % 365) as u32;
    let mut month = 0;
    while day >= DAYS[month] {
        day -= DAYS[month];
        month += 1;
    }
    let minutes = 6 * 60 + r.next_u64() % (14 * 60);
    let map_x_bearing = uniform(&mut r, 0.0, 360.0);
    let (weather, visibility) = match uniform(&mut r, 0.0, 1.0) {
        w if w < 0.5 => ("clear", None),
        w if w < 0.8 => ("overcast", None),
        _ => ("fog", Some(uniform(&mut r, 10.0, 80.0))),
    };
    let exposure_ev = uniform(&mut r, -0.7, 0.7);
    let white_balance = [uniform(&mut r, -0.15, 0.15).exp(), 1.0, uniform(&mut r, -0.15, 0.15).exp()];
    FrameDraw {
        aisle: aisle as usize,
        heading,
        base,
        lift,
        mount_jitter,
        date: format!("2025-{:02}-{:02}", month + 1, day + 1),
        time: format!("{:02}:{:02}", minutes / 60, minutes % 60),
        map_x_bearing,
        weather,
        visibility,
        exposure_ev,
        white_balance,
        noise_seed: (r.next_u64() >> 33) as i32,
    }
}

impl FrameDraw {
    /// The scenario's `[environment]` (place, render quality, ...) with this frame's sun and
    /// weather keys; as TOML text for the camera's `environment` parameter.
    pub fn environment(&self, scenario: Option<&toml::Table>) -> String {
        let mut t = scenario.cloned().unwrap_or_default();
        t.insert("date".into(), toml::Value::String(self.date.clone()));
        t.insert("time".into(), toml::Value::String(self.time.clone()));
        t.insert("map_x_bearing".into(), toml::Value::Float(self.map_x_bearing));
        t.insert("weather".into(), toml::Value::String(self.weather.into()));
        match self.visibility {
            Some(v) => t.insert("visibility".into(), toml::Value::Float(v)),
            None => t.remove("visibility"),
        };
        toml::to_string(&t).expect("a TOML table serializes")
    }
}

/// The hue shift [deg] of fruit `object` in scene `scene` (one per fruit: its colour is the
/// fruit's own, the same in every frame of the scene).
pub fn fruit_hue(seed: u64, scene: u64, object: u32) -> f64 {
    uniform(&mut Rng::stream(seed, &[HUE, scene, object as u64]), -FRUIT_HUE_DEG, FRUIT_HUE_DEG)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn aisles() -> Vec<Aisle> {
        (0..3).map(|i| Aisle { index: i, y: 2.0 + 2.6 * i as f64, x_start: 4.0, x_end: 34.0, width: 2.0 }).collect()
    }

    #[test]
    fn draws_depend_on_the_index_alone_and_stay_in_range() {
        let a = aisles();
        let mut weathers = std::collections::BTreeSet::new();
        for i in 0..300 {
            let f = frame(7, i, &a);
            assert_eq!(f, frame(7, i, &a));
            assert_ne!(f, frame(8, i, &a));
            let aisle = &a[f.aisle];
            assert!(f.base[0] >= aisle.x_start + 1.0 && f.base[0] <= aisle.x_end - 1.0);
            assert!((f.base[1] - aisle.y).abs() <= 0.25);
            assert!((0.0..=0.8).contains(&f.lift));
            assert!(f.exposure_ev.abs() <= 0.7);
            weathers.insert(f.weather);
            let env = agrisim_sky::environment::Environment::from_toml_str(&f.environment(None));
            assert!(env.is_ok(), "{env:?}");
        }
        assert_eq!(weathers.len(), 3);
    }

    #[test]
    fn scenes_vary_leaves_and_seed_and_stay_valid() {
        let mut t = toml::Table::new();
        t.insert("seed".into(), toml::Value::Integer(5));
        let s0 = scene(1, 0, &t).unwrap();
        let s1 = scene(1, 1, &t).unwrap();
        assert_eq!((s0.greenhouse_seed, s1.greenhouse_seed), (5, 6));
        assert!((3..=9).contains(&s0.leaf_density));
        assert_ne!(s0.leaf_size, s1.leaf_size);
        let cfg = GreenhouseConfig::from_toml_str(&s1.greenhouse).unwrap();
        assert_eq!((cfg.seed, cfg.leaf_density, cfg.leaf_size), (6, s1.leaf_density, s1.leaf_size));
    }
}
