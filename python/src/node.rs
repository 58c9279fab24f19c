//! `agrisim.Node`: a built-in algorithm node run from Python, outside any simulation, fed and
//! read as messages (CDR bytes) and scalars. What a Python process needs to put agrisim's own
//! harvest node on the other side of the ROS 2 link (an external node in Python over DDS), or
//! to wrap it in a user's own code.

use crate::py_err;
use agrisim_bus::Bus;
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use std::collections::BTreeMap;
use std::collections::BTreeSet;

#[pyclass(unsendable, module = "agrisim._agrisim")]
pub struct Node {
    node: Box<dyn agrisim_bus::Node>,
    bus: Bus,
    /// Scalars the caller feeds in (not the node's own).
    inputs: BTreeSet<String>,
}

/// One step's output: messages (topic, type, CDR) and the scalars the node set.
type Outputs<'py> = (Vec<(String, String, Bound<'py, PyBytes>)>, BTreeMap<String, f64>);

#[pymethods]
impl Node {
    /// `kind`: "harvest" (the dual-arm harvest of fruit `fruit_index` of the world's list;
    /// `seed` drives its planners).
    #[new]
    #[pyo3(signature = (kind, fruit_index=0, seed=0))]
    fn new(kind: &str, fruit_index: usize, seed: u64) -> PyResult<Node> {
        let node: Box<dyn agrisim_bus::Node> = match kind {
            "harvest" => Box::new(agrisim_harvest::HarvestNode::new(fruit_index, seed)),
            other => return Err(py_err(format!("unknown node kind '{other}' (harvest)"))),
        };
        Ok(Node { node, bus: Bus::default(), inputs: BTreeSet::new() })
    }

    /// The node's name.
    #[getter]
    fn name(&self) -> String {
        self.node.name().to_string()
    }

    /// One step at simulated time `t_ns`: `messages` (topic, ROS 2 type, CDR bytes) and
    /// `scalars` arrived since the last step; returns what the node published and the scalars
    /// it has set (all of them, each step: they are its standing set-points).
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        t_ns: i64,
        messages: Vec<(String, String, Vec<u8>)>,
        scalars: BTreeMap<String, f64>,
    ) -> PyResult<Outputs<'py>> {
        for (topic, ty, cdr) in messages {
            self.bus.publish_raw(&topic, &ty, t_ns, cdr);
        }
        for (k, v) in &scalars {
            self.bus.set_scalar(k, *v);
            self.inputs.insert(k.clone());
        }
        self.bus.drain();
        self.node
            .step(t_ns, &mut self.bus)
            .map_err(|e| py_err(format!("node {} at t={} s: {e}", self.node.name(), t_ns as f64 * 1e-9)))?;
        let out = self.bus.drain().into_iter().map(|m| (m.topic, m.type_name, PyBytes::new(py, &m.cdr))).collect();
        let set = self
            .bus
            .scalars()
            .iter()
            .filter(|(k, _)| !self.inputs.contains(*k))
            .map(|(k, v)| (k.clone(), *v))
            .collect();
        for r in self.bus.take_rejected() {
            eprintln!("agrisim.Node: {r}");
        }
        Ok((out, set))
    }
}
