//! Benchmarks: the master's overhead, and the many-trial evaluations (navigation) with honest
//! statistics and every trial recorded.

pub mod harvest;
pub mod harvest_targets;
pub mod nav;
pub mod overhead;
pub mod report;
pub mod stats;
pub mod targets;

pub use overhead::{overhead, OverheadReport};

use crate::error::Result;
use crate::master::Master;
use crate::value::{self, Value};

/// A numeric variable of component `comp`, read by a benchmark to judge a trial (ground
/// truth the algorithm layer never sees).
pub fn read_number(m: &mut Master, comp: usize, name: &str) -> Result<f64> {
    let c = &mut m.system.components[comp];
    let v = c.archive.md.variable(name).cloned().ok_or_else(|| crate::err!("FMU '{}' has no variable '{name}' (benchmark)", c.name))?;
    match value::get(&mut c.instance, &v)? {
        Value::F64(x) => Ok(x),
        Value::Bool(b) => Ok(b as u8 as f64),
        Value::I32(i) => Ok(i as f64),
        Value::I64(i) => Ok(i as f64),
        other => Err(crate::err!("FMU '{}': {name} is {other:?}, expected a number", c.name)),
    }
}
