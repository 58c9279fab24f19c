//! agrisim's FMU export layer: write a model once as a Rust type implementing [`Model`], get
//! the FMI 3.0 co-simulation C API, modelDescription.xml and (for the FMI-2-representable
//! variables) the FMI 2.0 co-simulation API from one variable table. A model that declares
//! continuous states ([`Model::CONTINUOUS_STATES`]) is exported as a model-exchange FMU
//! (FMI 3.0 and FMI 2.0) instead.
//!
//! - [`export_fmu!`] emits the C symbols of a cdylib (both APIs + the XML texts);
//! - [`fmi3`] / [`fmi2`] are the generic API layers those symbols wrap (call them in tests);
//! - [`xml`] generates modelDescription.xml.
//!
//! The test harness every FMU crate runs (table and dependency checks, random call
//! sequences) is the dev-only crate `agrisim-fmi-testing`, so no product links it.

pub mod ctype;
mod export;
pub mod fmi2;
pub mod fmi3;
mod guard;
mod instance;
pub mod logger;
mod model;
pub mod port;
mod registry;
pub mod serial;
pub mod state;
mod store;
pub mod token;
mod units;
mod var;
pub mod xml;

pub use instance::EventInfo;
/// The instance behind an FMI handle, for `agrisim-fmi-testing` alone (its shadow state
/// machine compares mode, time and live FMU states); not an API.
#[doc(hidden)]
pub use instance::Instance;
pub use model::{is_model_exchange, ContinuousState, Log, Model, ModelError, Quiet};
pub use port::{port_window, InPort, OutPort};
pub use state::{Mode, Status};
pub use store::{checked_f64, Store, Value};
pub use var::{concat, Causality, Start, Var, Variability, DEFAULT_MAX_SIZE};
