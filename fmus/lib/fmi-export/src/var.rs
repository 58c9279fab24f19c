//! The variable table a model declares: one [`Var`] per variable (causality, variability,
//! type and start value, unit, range, description, Binary size bound, initial dependencies)
//! and the [`variables!`](crate::variables) macro that declares the table and its index
//! constants together. The store, the export layer, the instantiation token and the model
//! all read this table.

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

/// Default [`Var::max_size`] of a Binary variable: 64 MiB, room for any message whose size
/// the model cannot bound from its parameters (point clouds, images, scene-sized lists).
pub const DEFAULT_MAX_SIZE: usize = 64 << 20;

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
    /// Binary only (FMI 3 `maxSize`): the largest value in bytes. A larger input is refused
    /// (Error); a model producing a larger output fails its step, so the bound always holds.
    /// [`DEFAULT_MAX_SIZE`] unless set with [`Var::max_size`]; 0 for other types.
    pub max_size: usize,
    /// Outputs and calculated parameters: the knowns (indices of parameters and inputs in the
    /// table, or [`Var::TIME`]) whose values in Initialization Mode this variable's initial
    /// value depends on (ModelStructure `<InitialUnknown dependencies>`). `None`: not declared,
    /// the attribute is omitted, which means "depends on every known".
    pub initial_dependencies: Option<&'static [usize]>,
    pub description: &'static str,
}

impl Var {
    /// Stands for the independent variable `time` (its start time) in
    /// [`Var::init_depends_on`] lists.
    pub const TIME: usize = usize::MAX;

    const fn new(name: &'static str, causality: Causality, variability: Variability, start: Start) -> Self {
        let max_size = if matches!(start, Start::Binary(_)) { DEFAULT_MAX_SIZE } else { 0 };
        Var {
            name,
            causality,
            variability,
            start,
            unit: "",
            min: None,
            max: None,
            mime_type: "",
            max_size,
            initial_dependencies: None,
            description: "",
        }
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
    /// Continuous Float64 local (e.g. a state derivative of a model-exchange model).
    pub const fn local(name: &'static str) -> Self {
        Self::new(name, Causality::Local, Variability::Continuous, Start::Float64(0.0))
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
    /// Largest Binary value in bytes (FMI 3 `maxSize`; see [`Var::max_size`](Var#structfield.max_size)).
    pub const fn max_size(mut self, bytes: usize) -> Self {
        self.max_size = bytes;
        self
    }
    /// Declares what this output's initial value (computed by `Model::initialize`, read in
    /// Initialization Mode) depends on: indices of parameters and inputs of the table and
    /// [`Var::TIME`] for the start time; `&[]` for none. Model code runs only in
    /// `initialize` and `do_step`, so no output ever depends on an input within a
    /// communication point (ModelStructure `<Output dependencies="">`, written for every
    /// output); this declaration is about Initialization Mode only.
    pub const fn init_depends_on(mut self, knowns: &'static [usize]) -> Self {
        self.initial_dependencies = Some(knowns);
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

/// The lists in `parts` one after the other, for building [`Var::init_depends_on`] lists
/// from shared pieces in const context: `const B: [usize; 3] = concat(&[A, &[X]]);`.
/// Panics (at compile time) unless the lengths add up to `N`.
pub const fn concat<const N: usize>(parts: &[&[usize]]) -> [usize; N] {
    let mut out = [0; N];
    let (mut n, mut p) = (0, 0);
    while p < parts.len() {
        let mut i = 0;
        while i < parts[p].len() {
            assert!(n < N, "concat: the parts hold more than N indices");
            out[n] = parts[p][i];
            n += 1;
            i += 1;
        }
        p += 1;
    }
    assert!(n == N, "concat: the parts hold fewer than N indices");
    out
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
