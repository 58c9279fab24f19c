//! `agrisim.Simulation`: a scenario's system stepped from Python, which plays the algorithm
//! layer: it publishes commands and reads what the FMUs publish, as a ROS 2 node would.

use crate::convert::{encode_value, to_py};
use crate::paths::{fmu_dirs, scenario_path};
use crate::{py_err, OnThisThread};
use agrisim_bus::{Node, Reader};
use agrisim_cosim::value;
use agrisim_session::{Profile, RunOptions, Scenario, Session, SessionSnapshot};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// A saved state of a [`Simulation`] (engine and message bus), for `Simulation.restore`.
#[pyclass(unsendable, module = "agrisim._agrisim")]
pub struct Snapshot {
    inner: SessionSnapshot,
    #[pyo3(get)]
    time: f64,
}

/// A scenario's system, stepped from Python.
#[pyclass(unsendable, module = "agrisim._agrisim")]
pub struct Simulation {
    session: Option<Session>,
    scenario: Scenario,
    /// Per topic: the reader behind `messages(topic)`.
    readers: BTreeMap<String, Reader>,
    /// Message type of every topic the system routes (inputs and outputs).
    types: BTreeMap<String, String>,
    mcap: Option<PathBuf>,
    /// Holds the throw-away recording of a simulation that records nothing.
    _scratch: Option<tempfile::TempDir>,
}

fn toml_of(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<toml::Value> {
    if let Ok(b) = obj.extract::<bool>() {
        return Ok(toml::Value::Boolean(b));
    }
    if let Ok(i) = obj.extract::<i64>() {
        return Ok(toml::Value::Integer(i));
    }
    if let Ok(x) = obj.extract::<f64>() {
        return Ok(toml::Value::Float(x));
    }
    if let Ok(s) = obj.extract::<String>() {
        return Ok(toml::Value::String(s));
    }
    Err(py_err(format!("parameter {what}: expected a number, bool or string, got {}", obj.get_type().name()?)))
}

fn node_of(name: &str, s: &Scenario) -> PyResult<Box<dyn Node>> {
    Ok(match name {
        "odom_tf" => Box::new(agrisim_nodes::OdomTf::default()),
        "script" => Box::new(agrisim_nodes::CommandScript::new(s.base_commands.clone(), s.lift_commands.clone())),
        "inject" => Box::new(agrisim_nodes::FaultInjector::new(&s.inject)),
        other => return Err(py_err(format!("unknown node '{other}' (built-in nodes: odom_tf, script, inject)"))),
    })
}

impl Simulation {
    fn session(&mut self) -> PyResult<&mut Session> {
        self.session.as_mut().ok_or_else(|| py_err("the simulation is closed"))
    }

    fn variable(
        &mut self,
        component: &str,
        name: &str,
    ) -> PyResult<(usize, agrisim_cosim::model_description::ModelVariable)> {
        let s = self.session()?;
        let comp = s.component(component, "Simulation").map_err(py_err)?;
        let c = &s.master.system.components[comp];
        let v = c
            .archive
            .md
            .variable(name)
            .cloned()
            .ok_or_else(|| py_err(format!("FMU '{component}' has no variable '{name}'")))?;
        Ok((comp, v))
    }
}

#[pymethods]
impl Simulation {
    /// `scenario`: a scenario file, or the name of one in models/scenarios (`"default"`).
    /// `fmu`: component -> FMU file (e.g. `{"chassis": "ChassisDynamic.fmu"}`).
    /// `parameters`: component -> parameter -> value, over the scenario's.
    /// `record`: an MCAP file to record to (None: nothing kept); `profile`: full, standard,
    /// judge or none. `nodes`: built-in nodes to run beside Python (odom_tf, script, inject).
    #[new]
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (scenario="default".into(), seed=None, fmu=None, parameters=None, record=None, profile=None, nodes=None), text_signature = "(scenario='default', seed=None, fmu=None, parameters=None, record=None, profile=None, nodes=None)")]
    fn new(
        py: Python<'_>,
        scenario: PathBuf,
        seed: Option<u64>,
        fmu: Option<BTreeMap<String, String>>,
        parameters: Option<Bound<'_, PyDict>>,
        record: Option<PathBuf>,
        profile: Option<String>,
        nodes: Option<Vec<String>>,
    ) -> PyResult<Simulation> {
        let mut s = Scenario::load(&scenario_path(scenario)).map_err(py_err)?;
        if let Some(params) = parameters {
            for (comp, table) in params.iter() {
                let comp: String = comp.extract()?;
                let table = table
                    .cast::<PyDict>()
                    .map_err(|_| py_err(format!("parameters['{comp}']: expected a dict of parameter values")))?;
                for (name, v) in table.iter() {
                    let name: String = name.extract()?;
                    let value = toml_of(&v, &format!("{comp}.{name}"))?;
                    s.parameters.entry(comp.clone()).or_default().insert(name, value);
                }
            }
        }
        let profile = match profile {
            Some(p) => Some(p.parse::<Profile>().map_err(py_err)?),
            None if record.is_none() => Some(Profile::None),
            None => None,
        };
        let (scratch, mcap) = match &record {
            Some(p) => (None, p.clone()),
            None => {
                let d = tempfile::tempdir().map_err(|e| py_err(format!("cannot make a scratch directory: {e}")))?;
                let p = d.path().join("scratch.mcap");
                (Some(d), p)
            }
        };
        let nodes = nodes.unwrap_or_default().iter().map(|n| node_of(n, &s)).collect::<PyResult<Vec<_>>>()?;
        let (fmu_dir, cache_dir) = fmu_dirs();
        let o = RunOptions {
            fmu_dir,
            cache_dir,
            seed,
            duration: None,
            fmu_overrides: fmu.unwrap_or_default(),
            fmu_log: None,
            record: profile,
            nodes: Default::default(),
        };
        let mut task = OnThisThread((s.clone(), o, mcap.clone(), Some(nodes)));
        let session = py
            .detach(move || {
                let t = task.get();
                let nodes = t.3.take().expect("once");
                agrisim_session::prepare(&t.0, &t.1, &t.2, nodes).map(OnThisThread)
            })
            .map_err(py_err)?
            .0;
        let mut types = BTreeMap::new();
        let route_types = agrisim_session::session::message_types(&session.master.system).map_err(py_err)?;
        for (r, ty) in session.master.system.routes.iter().zip(route_types) {
            if let Some(ty) = ty {
                types.insert(r.topic.clone(), ty);
            }
        }
        Ok(Simulation {
            session: Some(session),
            scenario: s,
            readers: BTreeMap::new(),
            types,
            mcap: record,
            _scratch: scratch,
        })
    }

    /// Simulated time [s].
    #[getter]
    fn time(&self) -> PyResult<f64> {
        Ok(self.session.as_ref().ok_or_else(|| py_err("the simulation is closed"))?.time())
    }

    /// The master step [s] (0.02 in the paper's setup).
    #[getter]
    fn step_size(&self) -> f64 {
        self.scenario.timing.step
    }

    /// Seconds between message exchanges (0.1 at 10 Hz).
    #[getter]
    fn message_period(&self) -> f64 {
        1.0 / self.scenario.timing.message_rate
    }

    /// The scenario's file.
    #[getter]
    fn scenario(&self) -> PathBuf {
        self.scenario.path.clone()
    }

    /// Runs `n` master steps (the interpreter lock is released meanwhile). An engine error is
    /// recorded in the MCAP and raised as AgrisimError. Returns the simulated time.
    #[pyo3(signature = (n=1))]
    fn step(&mut self, py: Python<'_>, n: u64) -> PyResult<f64> {
        let mut s = OnThisThread(self.session()?);
        let result = py.detach(move || {
            let s = s.get();
            let r = (0..n).try_for_each(|_| s.advance());
            if let Err(e) = &r {
                s.record_failure(e);
            }
            r
        });
        result.map_err(py_err)?;
        self.time()
    }

    /// Publishes `msg` (a dict of fields, or CDR bytes) on `topic` now. The type is the
    /// topic's in the system unless `type_name` (`pkg/msg/Type`) says otherwise.
    #[pyo3(signature = (topic, msg, type_name=None))]
    fn publish(&mut self, topic: &str, msg: &Bound<'_, PyAny>, type_name: Option<String>) -> PyResult<()> {
        let ty = match type_name.or_else(|| self.types.get(topic).cloned()) {
            Some(t) => t,
            None => {
                return Err(py_err(format!(
                    "topic {topic}: not a topic of this system; pass type_name='pkg/msg/Type' to publish on it"
                )))
            }
        };
        let cdr = if let Ok(b) = msg.cast::<PyBytes>() {
            let b = b.as_bytes().to_vec();
            match agrisim_msgs::check_cdr(&ty, &b) {
                Some(Ok(())) => b,
                Some(Err(e)) => return Err(py_err(format!("topic {topic}: the bytes are not a valid {ty}: {e}"))),
                None => return Err(py_err(format!("topic {topic}: unknown message type {ty}"))),
            }
        } else {
            encode_value(&ty, msg).map_err(|e| py_err(format!("topic {topic}: {e}")))?
        };
        let s = self.session()?;
        let t = s.master.time_ns();
        s.bus.publish_raw(topic, &ty, t, cdr);
        Ok(())
    }

    /// The newest message on `topic` (a dict; CDR bytes with `raw=True`), or None.
    #[pyo3(signature = (topic, raw=false))]
    fn latest<'py>(&mut self, py: Python<'py>, topic: &str, raw: bool) -> PyResult<Option<Bound<'py, PyAny>>> {
        let s = self.session()?;
        let Some(sample) = s.bus.latest(topic) else { return Ok(None) };
        Ok(Some(sample_to_py(py, topic, &sample.type_name, &sample.cdr, raw)?))
    }

    /// Every message on `topic` since the last call (the first call starts with the newest
    /// one), oldest first, as (time [s], message) pairs.
    #[pyo3(signature = (topic, raw=false))]
    fn messages<'py>(&mut self, py: Python<'py>, topic: &str, raw: bool) -> PyResult<Bound<'py, PyList>> {
        let mut reader = self.readers.remove(topic).unwrap_or_else(|| Reader::new(topic));
        let samples = reader.take_samples(&mut self.session()?.bus);
        self.readers.insert(topic.to_string(), reader);
        let items = samples
            .iter()
            .map(|smp| Ok((smp.time_ns as f64 * 1e-9, sample_to_py(py, topic, &smp.type_name, &smp.cdr, raw)?)))
            .collect::<PyResult<Vec<_>>>()?;
        PyList::new(py, items)
    }

    /// The topics the system routes, with their message types.
    fn topics(&self) -> BTreeMap<String, String> {
        self.types.clone()
    }

    /// The system's component names.
    fn components(&self) -> PyResult<Vec<String>> {
        Ok(self
            .session
            .as_ref()
            .ok_or_else(|| py_err("the simulation is closed"))?
            .master
            .system
            .components
            .iter()
            .map(|c| c.name.clone())
            .collect())
    }

    /// An FMU variable's current value (float, int, bool, str or bytes).
    fn get<'py>(&mut self, py: Python<'py>, component: &str, name: &str) -> PyResult<Bound<'py, PyAny>> {
        let (comp, v) = self.variable(component, name)?;
        let inst = self.session()?.master.system.components[comp].instance.as_mut();
        let x = value::get(inst, &v).map_err(|e| py_err(format!("FMU '{component}', variable '{name}': {e}")))?;
        Ok(match x {
            value::Value::F64(f) => f.into_pyobject(py)?.into_any(),
            value::Value::I32(i) => i.into_pyobject(py)?.into_any(),
            value::Value::I64(i) => i.into_pyobject(py)?.into_any(),
            value::Value::Bool(b) => pyo3::types::PyBool::new(py, b).to_owned().into_any(),
            value::Value::Str(s) => s.into_pyobject(py)?.into_any(),
            value::Value::Bin(b) => PyBytes::new(py, &b).into_any(),
        })
    }

    /// Sets an FMU variable (an input or a tunable parameter), as the FMI rules allow.
    fn set(&mut self, component: &str, name: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let (comp, v) = self.variable(component, name)?;
        let x = match value.cast::<PyBytes>() {
            Ok(b) => value::Value::Bin(b.as_bytes().to_vec()),
            Err(_) => value::from_toml(&v, &toml_of(value, &format!("{component}.{name}"))?)
                .map_err(|e| py_err(format!("FMU '{component}': {e}")))?,
        };
        let inst = self.session()?.master.system.components[comp].instance.as_mut();
        value::set(inst, &v, &x).map_err(|e| py_err(format!("FMU '{component}', variable '{name}': {e}")))
    }

    /// Saves the engine (every FMU) and the message bus. Only without built-in nodes.
    fn snapshot(&mut self) -> PyResult<Snapshot> {
        let s = self.session()?;
        let time = s.time();
        Ok(Snapshot { inner: s.snapshot().map_err(py_err)?, time })
    }

    /// Returns to a snapshot of this simulation (any number of times).
    fn restore(&mut self, snapshot: &Snapshot) -> PyResult<()> {
        self.session()?.restore(&snapshot.inner).map_err(py_err)?;
        // Readers follow the bus they were saved with: start them afresh.
        self.readers.clear();
        Ok(())
    }

    /// Finishes the recording and frees the FMUs. Returns the MCAP's path (None without one).
    fn close(&mut self) -> PyResult<Option<PathBuf>> {
        if let Some(mut s) = self.session.take() {
            if self.mcap.is_some() {
                // The final point: the last step's outputs reach the bus and the log.
                s.finish_point().map_err(py_err)?;
            }
            s.recorder_finish().map_err(py_err)?;
        }
        Ok(self.mcap.clone())
    }

    fn __enter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    /// Closes the simulation; an exception in the `with` block goes on.
    fn __exit__(
        &mut self,
        exc_type: Option<Bound<'_, PyAny>>,
        exc_value: Option<Bound<'_, PyAny>>,
        traceback: Option<Bound<'_, PyAny>>,
    ) -> PyResult<bool> {
        let _ = (exc_type, exc_value, traceback);
        self.close()?;
        Ok(false)
    }
}

fn sample_to_py<'py>(py: Python<'py>, topic: &str, ty: &str, cdr: &[u8], raw: bool) -> PyResult<Bound<'py, PyAny>> {
    if raw {
        return Ok(PyBytes::new(py, cdr).into_any());
    }
    let v = agrisim_msgs::dynamic::decode(ty, cdr)
        .map_err(|e| py_err(format!("topic {topic}: message is not a valid {ty}: {e}")))?;
    to_py(py, &v)
}
