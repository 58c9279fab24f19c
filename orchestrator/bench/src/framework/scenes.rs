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
}

/// Per-scene results of `outcomes` ((scene, success) per trial) and the cluster-bootstrap
/// 95 % interval of the success rate over scenes (seeded by the benchmark's `seed`).
pub fn by_scene(s: &Scenario, scenes: u64, seed: u64, outcomes: &[(u64, bool)]) -> (Vec<SceneResult>, [f64; 2]) {
    let mut per: Vec<SceneResult> = (0..scenes.max(1))
        .map(|k| SceneResult { scene: k, scene_seed: base_seed(&in_scene(s, k)), trials: 0, successes: 0 })
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
