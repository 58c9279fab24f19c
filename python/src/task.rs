//! `agrisim.NavTask`: a navigation benchmark's task definition for Python environments:
//! where the robot starts and the seeded goal a nav trial with that seed gets, drawn by the
//! same rule (aisles and headland, away from obstacles), so an environment and the benchmark
//! pose the same problems.

use crate::paths::scenario_path;
use crate::{py_err, OnThisThread};
use agrisim_bench::nav::{draw_target, NavSetup};
use agrisim_math::Rng;
use agrisim_session::Scenario;
use pyo3::prelude::*;
use std::path::PathBuf;

#[pyclass(unsendable, module = "agrisim._agrisim")]
pub struct NavTask {
    setup: NavSetup,
    scenario: Scenario,
}

#[pymethods]
impl NavTask {
    #[new]
    #[pyo3(signature = (scenario="default".into()), text_signature = "(scenario='default')")]
    fn new(py: Python<'_>, scenario: PathBuf) -> PyResult<NavTask> {
        let s = Scenario::load(&scenario_path(scenario)).map_err(py_err)?;
        let mut job = OnThisThread(s.clone());
        let setup = py.detach(move || NavSetup::new(job.get()).map(OnThisThread)).map_err(py_err)?.0;
        Ok(NavTask { setup, scenario: s })
    }

    /// The goal (x, y, yaw) [m, m, rad] in the map frame of a nav trial seeded `seed`.
    fn goal(&self, seed: u64) -> PyResult<(f64, f64, f64)> {
        let nav = &self.scenario.nav;
        draw_target(
            &self.setup.layout,
            &self.setup.truth,
            &mut Rng::new(seed),
            nav.targets_in_headland,
            nav.aisle_margin,
            0.7,
        )
        .map(|[x, y, yaw]| (x, y, yaw))
        .ok_or_else(|| {
            py_err(format!("scenario {}: no free navigation target could be drawn", self.scenario.path.display()))
        })
    }

    /// The start pose (x, y, yaw) of the scenario's layout, in the map frame.
    #[getter]
    fn start_pose(&self) -> (f64, f64, f64) {
        let [x, y, yaw] = self.setup.layout.start_pose;
        (x, y, yaw)
    }

    /// Success radius [m] of the nav judge.
    #[getter]
    fn goal_tolerance(&self) -> f64 {
        self.scenario.nav.goal_tolerance
    }

    /// Simulated time limit of a nav trial [s].
    #[getter]
    fn trial_timeout(&self) -> f64 {
        self.scenario.nav.trial_timeout
    }
}
