//! Many scenes (`--scenes K`): trial i runs in scene i mod K, the scenario's greenhouse grown
//! from its scene seed plus that index (scene 0 is the scenario's own). Trials in one scene
//! share its plants and obstacles, so they are not independent draws: the summary reports
//! every scene and a cluster-bootstrap interval beside the plain Wilson interval.

use super::stats::cluster_bootstrap95;
use agrisim_session::Scenario;
use serde::Serialize;

/// Bootstrap resamples of the per-scene interval.
const RESAMPLES: usize = 4000;

/// The scene of trial `trial` among `scenes` (round robin: every scene gets its share).
pub fn scene_of(trial: u64, scenes: u64) -> u64 {
    trial % scenes.max(1)
}

/// The greenhouse seed of the scenario's scene 0: its `[greenhouse] seed`, else its `seed`.
fn base_seed(s: &Scenario) -> u64 {
    match s.greenhouse.get("seed").and_then(|v| v.as_integer()) {
        Some(v) => v as u64,
        None => s.seed,
    }
}

/// The scenario with its greenhouse in scene `scene` (the same scenario for scene 0).
pub fn in_scene(s: &Scenario, scene: u64) -> Scenario {
    let mut s = s.clone();
    if scene > 0 {
        let seed = base_seed(&s).wrapping_add(scene);
        s.greenhouse.insert("seed".into(), toml::Value::Integer(seed as i64));
    }
    s
}

/// The scenes a benchmark's trials run in: each scene's index, scenario and what the
/// benchmark's setup makes of it (map, targets).
pub struct Scenes<T> {
    scenes: u64,
    list: Vec<(u64, Scenario, T)>,
}

impl<T> Scenes<T> {
    /// All `scenes` scenes, scene 0 first.
    pub fn all(
        s: &Scenario,
        scenes: u64,
        setup: impl Fn(&Scenario) -> agrisim_error::Result<T>,
    ) -> agrisim_error::Result<Scenes<T>> {
        Scenes::of_indices(s, scenes, 0..scenes.max(1), setup)
    }

    /// Only trial `trial`'s scene (a worker process runs one trial).
    pub fn for_trial(
        s: &Scenario,
        scenes: u64,
        trial: u64,
        setup: impl Fn(&Scenario) -> agrisim_error::Result<T>,
    ) -> agrisim_error::Result<Scenes<T>> {
        let k = scene_of(trial, scenes);
        Scenes::of_indices(s, scenes, k..k + 1, setup)
    }

    fn of_indices(
        s: &Scenario,
        scenes: u64,
        ks: std::ops::Range<u64>,
        setup: impl Fn(&Scenario) -> agrisim_error::Result<T>,
    ) -> agrisim_error::Result<Scenes<T>> {
        let list = ks
            .map(|k| {
                let s = in_scene(s, k);
                setup(&s).map(|t| (k, s, t))
            })
            .collect::<agrisim_error::Result<_>>()?;
        Ok(Scenes { scenes, list })
    }

    /// Trial `trial`'s scene index, scenario and setup (its scene must be held).
    pub fn of(&self, trial: u64) -> (u64, &Scenario, &T) {
        let k = scene_of(trial, self.scenes);
        let (_, s, t) = self.list.iter().find(|e| e.0 == k).expect("the trial's scene was set up");
        (k, s, t)
    }

    /// The first scene's setup (scene 0 for a whole benchmark).
    pub fn first(&self) -> &T {
        &self.list[0].2
    }
}

/// One scene's share of a benchmark.
#[derive(Debug, Clone, Serialize)]
pub struct SceneResult {
    pub scene: u64,
    /// The greenhouse seed the scene was grown from.
    pub scene_seed: u64,
    pub trials: u64,
    pub successes: u64,
    /// The scene's greenhouse drawn from the scenario's `[greenhouse.family]` (absent when the
    /// scenario has no family): what success can be read against.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub draw: Option<FamilyDraw>,
}

/// The values a scenario family drew for one scene (`agrisim_scene::family`).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct FamilyDraw {
    pub aisle_width: f64,
    pub fruit_per_truss: usize,
    pub leaf_density: usize,
    pub fruit_radius: f64,
    pub fruit_height: [f64; 2],
    pub trusses_per_plant: usize,
    pub plant_spacing: f64,
}

/// Scene `s`'s family draw, if its greenhouse is drawn from a family.
fn family_draw(s: &Scenario) -> Option<FamilyDraw> {
    let c = agrisim_scene::GreenhouseConfig::from_toml_str(&s.scene_toml()).ok()?;
    c.family.as_ref()?;
    Some(FamilyDraw {
        aisle_width: c.aisle_width,
        fruit_per_truss: c.fruit_per_truss,
        leaf_density: c.leaf_density,
        fruit_radius: c.fruit_radius,
        fruit_height: c.fruit_height,
        trusses_per_plant: c.trusses_per_plant,
        plant_spacing: c.plant_spacing,
    })
}

/// Per-scene results of `outcomes` ((scene, success) per trial) and the cluster-bootstrap
/// 95 % interval of the success rate over scenes (seeded by the benchmark's `seed`).
pub fn by_scene(s: &Scenario, scenes: u64, seed: u64, outcomes: &[(u64, bool)]) -> (Vec<SceneResult>, [f64; 2]) {
    let mut per: Vec<SceneResult> = (0..scenes.max(1))
        .map(|k| {
            let sk = in_scene(s, k);
            SceneResult { scene: k, scene_seed: base_seed(&sk), trials: 0, successes: 0, draw: family_draw(&sk) }
        })
        .collect();
    for &(k, ok) in outcomes {
        if let Some(r) = per.get_mut(k as usize) {
            r.trials += 1;
            r.successes += ok as u64;
        }
    }
    let clusters: Vec<(u64, u64)> = per.iter().filter(|r| r.trials > 0).map(|r| (r.successes, r.trials)).collect();
    let ci = cluster_bootstrap95(&clusters, RESAMPLES, seed ^ 0xB007_57A9);
    (per, ci)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    /// A family's scenes report their draws, scene k being the draw for greenhouse seed + k;
    /// a scenario without a family reports none.
    #[test]
    fn family_scenes_report_their_draw() {
        let text = "[system]\nfile = \"a.ssd\"\n[greenhouse]\n[greenhouse.family]\nfruit_per_truss = [3, 8]\naisle_width = [1.6, 2.2]\n";
        let s = Scenario::parse(text, Path::new("family.toml")).unwrap();
        let (per, _) = by_scene(&s, 8, 1, &[]);
        let draws: Vec<FamilyDraw> = per.iter().map(|r| r.draw.clone().expect("a family scene has a draw")).collect();
        for (r, d) in per.iter().zip(&draws) {
            let mut t = s.greenhouse.clone();
            t.insert("seed".into(), toml::Value::Integer(r.scene_seed as i64));
            let c = agrisim_scene::GreenhouseConfig::from_toml_str(&toml::to_string(&t).unwrap()).unwrap();
            assert_eq!((d.fruit_per_truss, d.aisle_width), (c.fruit_per_truss, c.aisle_width));
            assert!((3..=8).contains(&d.fruit_per_truss) && (1.6..=2.2).contains(&d.aisle_width));
        }
        assert!(draws.windows(2).any(|w| w[0] != w[1]), "the scenes drew one greenhouse: {draws:?}");
        let plain = Scenario::parse("[system]\nfile = \"a.ssd\"\n", Path::new("x.toml")).unwrap();
        assert!(by_scene(&plain, 2, 1, &[]).0.iter().all(|r| r.draw.is_none()));
    }
}
