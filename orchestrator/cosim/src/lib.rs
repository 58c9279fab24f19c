//! agrisim-cosim: the co-simulation engine. It imports FMI 3.0 and FMI 2.0 FMUs (co-simulation,
//! and model exchange integrated by the master with fixed-step RK4: [`me`]), composes
//! them from an SSP system structure, and steps them on integer ticks with per-connection
//! exchange rates (physics every step, message connections at their own period).
//!
//! It knows no ROS, no greenhouse and no component names: values that cross the system's
//! own connectors (messages and scalars for the algorithm layer) go through the [`Hooks`]
//! the embedding program passes to [`Master::advance`]. Embedding in a few lines:
//!
//! ```no_run
//! use agrisim_cosim::{LoadOptions, Master, NoHooks, System};
//! # fn main() -> agrisim_error::Result<()> {
//! let opts = LoadOptions::new("target/fmu", "target/fmu-cache", 0.02, 0.1);
//! let mut system = System::load("models/systems/base.ssd".as_ref(), &opts)?;
//! system.apply_parameters(&Default::default(), 1, &Default::default())?;
//! let mut master = Master::new(system, 0.02, 0.1)?;
//! master.initialize()?;
//! for _ in 0..500 {
//!     master.advance(&mut NoHooks)?;
//! }
//! let x = master.system.number(master.system.component_index("chassis").unwrap(), "x")?;
//! # let _ = x; Ok(()) }
//! ```

pub mod archive;
pub mod fmi2;
pub mod fmi3;
pub mod fmu;
pub mod master;
pub mod me;
pub mod model_description;
pub mod order;
mod python;
pub mod saved;
pub mod seed;
pub mod ssp;
pub mod system;
pub mod value;

pub use agrisim_error::{err, Context, Error, Result};
pub use fmu::FmuInstance;
pub use master::{Algorithm, Hooks, Master, NoHooks, Snapshot};
pub use order::Order;
pub use system::{LoadOptions, Port, Route, System};

/// `crate::error::...` paths inside this crate.
pub(crate) mod error {
    pub use agrisim_error::{Context, Error, Result};
}

macro_rules! from_display {
    ($($t:ty),*) => { $( impl From<$t> for Error { fn from(e: $t) -> Self { Error(e.to_string()) } } )* };
}
from_display!(fmu::FmiError, archive::ImportError, model_description::ModelDescriptionError, ssp::SspError);
