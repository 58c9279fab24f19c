//! The one trait a model implements, and the variable table it declares.
//!
//! A model is only physics: it reads its parameters and inputs from a [`Store`], writes its
//! outputs back, and keeps whatever internal state it needs in `Self`. Everything FMI-specific
//! (the C API, the call-sequence state machine, modelDescription.xml) lives in the export
//! layer and is driven by the same [`Var`] table, so the XML can never drift from the code.

use crate::store::Store;

/// FMI causality of a variable. The independent variable `time` is added by the export layer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Causality {
    Parameter,
    CalculatedParameter,
    Input,
    Output,
    Local,
}

/// FMI variability of a variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variability {
    Constant,
    Fixed,
    Tunable,
    Discrete,
    Continuous,
}

/// Type and start value of a variable. The type of a variable is the kind of its start value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Start {
    Float64(f64),
    /// FMI 3 Int32; FMI 2 Integer.
    Int32(i32),
    /// FMI 3 only (sequence counters of message ports).
    Int64(i64),
    Boolean(bool),
    String(&'static str),
    /// FMI 3 only: a serialized message (CDR bytes); see [`Var::mime_type`].
    Binary(&'static [u8]),
}

/// One row of a model's variable table. Value reference = 1 + index in the table (0 is time).
#[derive(Clone, Copy, Debug)]
pub struct Var {
    pub name: &'static str,
    pub causality: Causality,
    pub variability: Variability,
    pub start: Start,
    /// Unit name ("" = none); written to the unit definitions of modelDescription.xml.
    pub unit: &'static str,
    pub min: Option<f64>,
    pub max: Option<f64>,
    /// MIME type of a Binary variable, e.g. `application/x-ros2-cdr; type=geometry_msgs/msg/Twist`.
    pub mime_type: &'static str,
    pub description: &'static str,
}

impl Var {
    const fn new(name: &'static str, causality: Causality, variability: Variability, start: Start) -> Self {
        Var { name, causality, variability, start, unit: "", min: None, max: None, mime_type: "", description: "" }
    }
    /// Continuous Float64 input.
    pub const fn input(name: &'static str, start: f64) -> Self {
        Self::new(name, Causality::Input, Variability::Continuous, Start::Float64(start))
    }
    /// Discrete input of any type (integers, booleans, binaries).
    pub const fn input_discrete(name: &'static str, start: Start) -> Self {
        Self::new(name, Causality::Input, Variability::Discrete, start)
    }
    /// Continuous Float64 output.
    pub const fn output(name: &'static str) -> Self {
        Self::new(name, Causality::Output, Variability::Continuous, Start::Float64(0.0))
    }
    /// Discrete output of any type; `start` gives the type (outputs' start values are not written to XML).
    pub const fn output_discrete(name: &'static str, start: Start) -> Self {
        Self::new(name, Causality::Output, Variability::Discrete, start)
    }
    /// Fixed parameter (settable before initialization ends).
    pub const fn param(name: &'static str, start: Start) -> Self {
        Self::new(name, Causality::Parameter, Variability::Fixed, start)
    }
    /// Tunable parameter (settable during stepping too).
    pub const fn tunable(name: &'static str, start: Start) -> Self {
        Self::new(name, Causality::Parameter, Variability::Tunable, start)
    }
    pub const fn unit(mut self, unit: &'static str) -> Self {
        self.unit = unit;
        self
    }
    pub const fn range(mut self, min: f64, max: f64) -> Self {
        self.min = Some(min);
        self.max = Some(max);
        self
    }
    pub const fn mime(mut self, mime_type: &'static str) -> Self {
        self.mime_type = mime_type;
        self
    }
    pub const fn desc(mut self, description: &'static str) -> Self {
        self.description = description;
        self
    }
    /// True when FMI 2.0 can represent this variable (not Int64, not Binary).
    pub const fn fmi2_representable(&self) -> bool {
        !matches!(self.start, Start::Int64(_) | Start::Binary(_))
    }
}

/// What a model returns when it cannot go on; the export layer logs it and returns an error status.
pub type ModelError = String;

/// Log sink handed to a model; messages reach the importer's logger callback.
pub trait Log {
    fn info(&mut self, msg: &str);
    fn warning(&mut self, msg: &str);
}

/// A co-simulation model. Implementors are plain Rust; see `export_fmu!` for the C API.
pub trait Model: Clone + Send + 'static {
    /// modelIdentifier: the FMU's shared-library name and its model name.
    const NAME: &'static str;
    /// instantiationToken (FMI 3) / guid (FMI 2): checked at instantiation.
    const TOKEN: &'static str;
    const DESCRIPTION: &'static str;
    /// Variable table, in value-reference order (vr = index + 1).
    const VARIABLES: &'static [Var];
    /// Default experiment step size [s].
    const STEP_SIZE: f64 = 0.02;

    /// A model in its initial state (before parameters are applied).
    fn new() -> Self;

    /// Called when initialization ends: parameters and inputs are final for t = `start_time`.
    /// Set every output consistent with them.
    fn initialize(&mut self, io: &mut Store, start_time: f64, log: &mut dyn Log) -> Result<(), ModelError>;

    /// Advance from `t` to `t + h` with the inputs in `io`; write outputs for `t + h`.
    fn do_step(&mut self, io: &mut Store, t: f64, h: f64, log: &mut dyn Log) -> Result<(), ModelError>;
}

/// Declares index constants and the variable table in one place, so they cannot disagree:
///
/// ```ignore
/// agrisim_fmi::variables! { pub VARIABLES {
///     CMD_VX = Var::input("cmd_vx", 0.0).unit("m/s"),
///     X = Var::output("x").unit("m"),
/// }}
/// // CMD_VX == 0, X == 1, VARIABLES.len() == 2
/// ```
#[macro_export]
macro_rules! variables {
    ($vis:vis $table:ident { $( $id:ident = $var:expr ),* $(,)? }) => {
        #[allow(non_camel_case_types, dead_code, clippy::upper_case_acronyms)]
        #[repr(usize)]
        enum __VarIndex { $( $id ),* }
        $( #[allow(dead_code)] $vis const $id: usize = __VarIndex::$id as usize; )*
        $vis const $table: &[$crate::Var] = &[ $( $var ),* ];
    };
}
