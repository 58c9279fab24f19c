//! The variable table a model declares: one [`Var`] per variable (causality, variability,
//! type and start value, unit, range, description) and the [`variables!`](crate::variables)
//! macro that declares the table and its index constants together. The store, the export
//! layer and the model all read this table.

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
