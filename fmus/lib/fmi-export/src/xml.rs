//! modelDescription.xml (FMI 3.0 and FMI 2.0) generated from a model's variable table.
//!
//! Rules (FMI 3.0 tables 17/18, FMI 2.0 section 2.2.7):
//! - `time` (vr 0) is the one `independent` variable, without start value.
//! - parameters and inputs: initial defaults to `exact`, start written;
//! - outputs (continuous/discrete), locals and calculated parameters: `initial="calculated"`,
//!   no start; they are listed as InitialUnknowns; constants: start written.
//! - every output is listed under ModelStructure/Output(s) with `dependencies=""`: model code
//!   runs only in `initialize` and `do_step`, getters and setters only move values, so no
//!   output changes when an input is set within a communication point (no direct feedthrough);
//! - InitialUnknowns carry the dependencies the table declares ([`Var::init_depends_on`]:
//!   parameters, inputs, the start time); undeclared ones omit the attribute (= all knowns);
//! - Binary variables carry `maxSize` (FMI 3).
//! - Model exchange (a model with [`Model::CONTINUOUS_STATES`]): a `<ModelExchange>` element
//!   instead of `<CoSimulation>`; each derivative variable names its state (`derivative=`,
//!   FMI 3 a value reference, FMI 2 a 1-based position); ModelStructure lists the
//!   derivatives (`ContinuousStateDerivative` / `Derivatives`) and adds calculated states
//!   and derivatives to the initial unknowns. Outputs and derivatives there omit
//!   `dependencies` (= every known): the layer cannot know which states and inputs the
//!   model's `evaluate` reads, and omitting is the one declaration that is always true.
//!
//! Output is deterministic (no timestamps); floats are written in round-trip form.

use std::collections::BTreeSet;
use std::fmt::Write;

use crate::logger::LOG_CATEGORIES;
use crate::model::{is_model_exchange, ContinuousState, Model};
use crate::units::{base_unit, EXPONENT_NAMES};
use crate::var::{Causality, Start, Var, Variability};

/// Escapes text for an XML attribute value. Characters XML 1.0 cannot carry become U+FFFD.
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\t' => out.push_str("&#9;"),
            '\n' => out.push_str("&#10;"),
            '\r' => out.push_str("&#13;"),
            c if (c as u32) < 0x20 || c == '\u{FFFE}' || c == '\u{FFFF}' => out.push('\u{FFFD}'),
            c => out.push(c),
        }
    }
    out
}

/// xs:double text that parses back to exactly `x`.
pub fn fmt_f64(x: f64) -> String {
    if x.is_nan() {
        "NaN".into()
    } else if x == f64::INFINITY {
        "INF".into()
    } else if x == f64::NEG_INFINITY {
        "-INF".into()
    } else {
        format!("{x:?}")
    }
}

fn fmt_int(x: f64) -> String {
    format!("{}", x as i64)
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().fold(String::with_capacity(bytes.len() * 2), |mut s, b| {
        let _ = write!(s, "{b:02X}");
        s
    })
}

fn causality(c: Causality) -> &'static str {
    match c {
        Causality::Parameter => "parameter",
        Causality::CalculatedParameter => "calculatedParameter",
        Causality::Input => "input",
        Causality::Output => "output",
        Causality::Local => "local",
    }
}

fn variability(v: Variability) -> &'static str {
    match v {
        Variability::Constant => "constant",
        Variability::Fixed => "fixed",
        Variability::Tunable => "tunable",
        Variability::Discrete => "discrete",
        Variability::Continuous => "continuous",
    }
}

/// True when the variable's value is computed by the model (initial="calculated", no start).
pub fn is_calculated(v: &Var) -> bool {
    v.variability != Variability::Constant
        && matches!(v.causality, Causality::Output | Causality::Local | Causality::CalculatedParameter)
}

/// True for the variables listed as ModelStructure InitialUnknowns.
pub fn is_initial_unknown(v: &Var) -> bool {
    is_calculated(v) && matches!(v.causality, Causality::Output | Causality::CalculatedParameter)
}

/// Value references of `v`'s declared initial dependencies, sorted and unique (time = 0);
/// `None` when undeclared.
fn initial_dependency_vrs(v: &Var) -> Option<Vec<usize>> {
    let mut vrs: Vec<usize> = v.initial_dependencies?.iter().map(|&d| if d == Var::TIME { 0 } else { d + 1 }).collect();
    vrs.sort_unstable();
    vrs.dedup();
    Some(vrs)
}

fn join(xs: impl IntoIterator<Item = usize>) -> String {
    xs.into_iter().map(|x| x.to_string()).collect::<Vec<_>>().join(" ")
}

fn type_name(s: &Start) -> &'static str {
    match s {
        Start::Float64(_) => "Float64",
        Start::Int32(_) => "Int32",
        Start::Int64(_) => "Int64",
        Start::Boolean(_) => "Boolean",
        Start::String(_) => "String",
        Start::Binary(_) => "Binary",
    }
}

/// Everything in a variable table that would make an invalid FMU; empty = fine.
/// Checked by the tests of every FMU crate (via `agrisim-fmi-testing`) and by [`fmi3`]'s callers.
pub fn check_table(vars: &[Var]) -> Vec<String> {
    let mut problems = Vec::new();
    let mut names = BTreeSet::new();
    if vars.len() >= u32::MAX as usize {
        problems.push("too many variables".into());
    }
    for (i, v) in vars.iter().enumerate() {
        let who = format!("variable {} ('{}', vr {})", i, v.name, i + 1);
        let mut bad = |p: String| problems.push(format!("{who}: {p}"));
        if v.name.is_empty() {
            bad("empty name".into());
        }
        if v.name == "time" {
            bad("the name 'time' is reserved for the independent variable".into());
        }
        if v.name.chars().any(|c| c.is_control()) {
            bad("the name contains control characters".into());
        }
        if !names.insert(v.name) {
            bad("duplicate name".into());
        }
        let is_float = matches!(v.start, Start::Float64(_));
        let numeric = matches!(v.start, Start::Float64(_) | Start::Int32(_) | Start::Int64(_));
        if v.variability == Variability::Continuous && !is_float {
            bad(format!("{} variables cannot be continuous (use discrete)", type_name(&v.start)));
        }
        let ok = match v.causality {
            Causality::Parameter | Causality::CalculatedParameter => {
                matches!(v.variability, Variability::Fixed | Variability::Tunable)
            }
            Causality::Input => matches!(v.variability, Variability::Discrete | Variability::Continuous),
            Causality::Output => v.variability != Variability::Fixed && v.variability != Variability::Tunable,
            Causality::Local => true,
        };
        if !ok {
            bad(format!(
                "causality {} with variability {} is not allowed",
                causality(v.causality),
                variability(v.variability)
            ));
        }
        if !v.unit.is_empty() && !is_float {
            bad("only Float64 variables can have a unit".into());
        }
        if !v.mime_type.is_empty() && !matches!(v.start, Start::Binary(_)) {
            bad("only Binary variables can have a mimeType".into());
        }
        match v.start {
            Start::Binary(b) if v.max_size == 0 || b.len() > v.max_size => {
                bad(format!("maxSize {} must be positive and hold the start value ({} bytes)", v.max_size, b.len()))
            }
            Start::Binary(_) => {}
            _ if v.max_size != 0 => bad("only Binary variables can have a maxSize".into()),
            _ => {}
        }
        if let Some(deps) = v.initial_dependencies {
            if !is_initial_unknown(v) {
                bad("only initial unknowns (calculated outputs and calculated parameters) have initial dependencies"
                    .into());
            }
            for &d in deps {
                match vars.get(d) {
                    _ if d == Var::TIME => {}
                    Some(k) if matches!(k.causality, Causality::Parameter | Causality::Input) => {}
                    Some(k) => bad(format!("initial dependency '{}' is neither a parameter nor an input", k.name)),
                    None => bad(format!("initial dependency {d} is not in the table")),
                }
            }
        }
        if (v.min.is_some() || v.max.is_some()) && !numeric {
            bad("only numeric variables can have min/max".into());
        }
        if let (Some(min), Some(max)) = (v.min, v.max) {
            if min.is_nan() || max.is_nan() || min > max {
                bad(format!("min {min} > max {max}"));
            }
        }
        if !is_float {
            for m in [v.min, v.max].into_iter().flatten() {
                if m.fract() != 0.0 || !m.is_finite() {
                    bad(format!("integer min/max {m} is not an integer"));
                }
            }
        }
        if !is_calculated(v) {
            let x = match v.start {
                Start::Float64(x) => Some(x),
                Start::Int32(x) => Some(x as f64),
                Start::Int64(x) => Some(x as f64),
                _ => None,
            };
            if let Some(x) = x {
                if !x.is_finite() {
                    bad(format!("start value {x} is not finite"));
                }
                if v.min.is_some_and(|m| x < m) || v.max.is_some_and(|m| x > m) {
                    bad(format!("start value {x} is outside [min, max]"));
                }
            }
            if let Start::String(s) = v.start {
                if s.contains('\0') {
                    bad("the String start value contains NUL".into());
                }
            }
        }
    }
    problems
}

/// Everything in a model's continuous-state declaration that would make an invalid
/// model-exchange FMU; empty = fine. States and derivatives must be distinct continuous
/// Float64 outputs or locals (computed by the model, never set from outside), nominals
/// positive and finite.
pub fn check_continuous_states(vars: &[Var], states: &[ContinuousState]) -> Vec<String> {
    let mut problems = Vec::new();
    let mut used = BTreeSet::new();
    for (k, s) in states.iter().enumerate() {
        for (what, i) in [("state", s.state), ("derivative", s.derivative)] {
            let Some(v) = vars.get(i) else {
                problems.push(format!("continuous state {k}: {what} index {i} is not in the table"));
                continue;
            };
            if !used.insert(i) {
                problems.push(format!("continuous state {k}: '{}' is used twice", v.name));
            }
            let ok = matches!(v.start, Start::Float64(_))
                && v.variability == Variability::Continuous
                && matches!(v.causality, Causality::Output | Causality::Local);
            if !ok {
                problems.push(format!(
                    "continuous state {k}: {what} '{}' must be a continuous Float64 output or local",
                    v.name
                ));
            }
        }
        if !(s.nominal.is_finite() && s.nominal > 0.0) {
            problems.push(format!("continuous state {k}: nominal {} must be positive and finite", s.nominal));
        }
    }
    problems
}

/// The index of the state whose derivative is variable `i`, for model-exchange models.
fn state_of_derivative<M: Model>(i: usize) -> Option<usize> {
    M::CONTINUOUS_STATES.iter().find(|s| s.derivative == i).map(|s| s.state)
}

/// Initial unknowns of `M`: [`is_initial_unknown`] plus, for model exchange, the calculated
/// continuous states and derivatives (FMI 3.0 section 2.4.8, FMI 2.0 section 2.2.8).
fn is_initial_unknown_of<M: Model>(i: usize, v: &Var) -> bool {
    is_initial_unknown(v)
        || (is_calculated(v) && M::CONTINUOUS_STATES.iter().any(|s| s.state == i || s.derivative == i))
}

/// Units used by the table (sorted, unique), plus "s" for time.
fn used_units(vars: &[&Var]) -> BTreeSet<&'static str> {
    let mut units: BTreeSet<&'static str> = vars.iter().map(|v| v.unit).filter(|u| !u.is_empty()).collect();
    units.insert("s");
    units
}

fn unit_definitions(out: &mut String, units: &BTreeSet<&str>) {
    out.push_str("  <UnitDefinitions>\n");
    for u in units {
        match base_unit(u) {
            Some(b) => {
                let _ = write!(out, "    <Unit name=\"{}\">\n      <BaseUnit", escape(u));
                for (name, e) in EXPONENT_NAMES.iter().zip(b.exponents) {
                    if e != 0 {
                        let _ = write!(out, " {name}=\"{e}\"");
                    }
                }
                if b.factor != 1.0 {
                    let _ = write!(out, " factor=\"{}\"", fmt_f64(b.factor));
                }
                out.push_str("/>\n    </Unit>\n");
            }
            None => {
                let _ = writeln!(out, "    <Unit name=\"{}\"/>", escape(u));
            }
        }
    }
    out.push_str("  </UnitDefinitions>\n");
}

fn log_categories(out: &mut String) {
    out.push_str("  <LogCategories>\n");
    for (name, description) in LOG_CATEGORIES {
        let _ = writeln!(out, "    <Category name=\"{name}\" description=\"{}\"/>", escape(description));
    }
    out.push_str("  </LogCategories>\n");
}

/// Common variable attributes (name, vr, description, causality, variability, initial).
fn common_attributes(out: &mut String, v: &Var, vr: usize) {
    let _ = write!(out, " name=\"{}\" valueReference=\"{vr}\"", escape(v.name));
    if !v.description.is_empty() {
        let _ = write!(out, " description=\"{}\"", escape(v.description));
    }
    let _ = write!(out, " causality=\"{}\" variability=\"{}\"", causality(v.causality), variability(v.variability));
    if is_calculated(v) {
        out.push_str(" initial=\"calculated\"");
    }
}

fn min_max(out: &mut String, v: &Var, int: bool) {
    let f = if int { fmt_int } else { fmt_f64 };
    if let Some(m) = v.min {
        let _ = write!(out, " min=\"{}\"", f(m));
    }
    if let Some(m) = v.max {
        let _ = write!(out, " max=\"{}\"", f(m));
    }
}

/// FMI 3.0 modelDescription.xml of `M`.
pub fn fmi3<M: Model>() -> String {
    let vars: Vec<&Var> = M::VARIABLES.iter().collect();
    let mut o = String::new();
    o.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(
        o,
        "<fmiModelDescription fmiVersion=\"3.0\" modelName=\"{}\" instantiationToken=\"{}\" description=\"{}\" generationTool=\"agrisim-fmi {}\" variableNamingConvention=\"flat\">",
        escape(M::NAME),
        escape(M::TOKEN),
        escape(M::DESCRIPTION),
        env!("CARGO_PKG_VERSION")
    );
    let me = is_model_exchange::<M>();
    if me {
        let _ = writeln!(
            o,
            "  <ModelExchange modelIdentifier=\"{}\" needsExecutionTool=\"false\" canBeInstantiatedOnlyOncePerProcess=\"false\" canGetAndSetFMUState=\"true\" canSerializeFMUState=\"true\" providesDirectionalDerivatives=\"false\" providesAdjointDerivatives=\"false\" providesPerElementDependencies=\"false\" needsCompletedIntegratorStep=\"false\" providesEvaluateDiscreteStates=\"false\"/>",
            escape(M::NAME)
        );
    } else {
        let _ = writeln!(
            o,
            "  <CoSimulation modelIdentifier=\"{}\" needsExecutionTool=\"false\" canBeInstantiatedOnlyOncePerProcess=\"false\" canGetAndSetFMUState=\"true\" canSerializeFMUState=\"true\" providesDirectionalDerivatives=\"false\" providesAdjointDerivatives=\"false\" providesPerElementDependencies=\"false\" canHandleVariableCommunicationStepSize=\"true\" maxOutputDerivativeOrder=\"0\" providesIntermediateUpdate=\"false\" mightReturnEarlyFromDoStep=\"false\" canReturnEarlyAfterIntermediateUpdate=\"false\" hasEventMode=\"false\" providesEvaluateDiscreteStates=\"false\"/>",
            escape(M::NAME)
        );
    }
    let units = used_units(&vars);
    unit_definitions(&mut o, &units);
    // Units through one Float64Type per unit (declaredType) rather than a unit attribute on
    // each variable: both are FMI 3, and some importers (fmi-sim 0.7) read only the former.
    o.push_str("  <TypeDefinitions>\n");
    for u in &units {
        let _ = writeln!(o, "    <Float64Type name=\"{}\" unit=\"{}\"/>", escape(u), escape(u));
    }
    o.push_str("  </TypeDefinitions>\n");
    log_categories(&mut o);
    let _ = writeln!(o, "  <DefaultExperiment startTime=\"0.0\" stepSize=\"{}\"/>", fmt_f64(M::STEP_SIZE));
    o.push_str("  <ModelVariables>\n");
    o.push_str("    <Float64 name=\"time\" valueReference=\"0\" description=\"Simulation time\" causality=\"independent\" variability=\"continuous\" declaredType=\"s\"/>\n");
    for (i, v) in vars.iter().enumerate() {
        let vr = i + 1;
        let with_start = !is_calculated(v);
        let tag = type_name(&v.start);
        let _ = write!(o, "    <{tag}");
        common_attributes(&mut o, v, vr);
        match v.start {
            Start::Float64(x) => {
                if !v.unit.is_empty() {
                    let _ = write!(o, " declaredType=\"{}\"", escape(v.unit));
                }
                min_max(&mut o, v, false);
                if let Some(state) = state_of_derivative::<M>(i) {
                    let _ = write!(o, " derivative=\"{}\"", state + 1);
                }
                if with_start {
                    let _ = write!(o, " start=\"{}\"", fmt_f64(x));
                }
                o.push_str("/>\n");
            }
            Start::Int32(x) => {
                min_max(&mut o, v, true);
                if with_start {
                    let _ = write!(o, " start=\"{x}\"");
                }
                o.push_str("/>\n");
            }
            Start::Int64(x) => {
                min_max(&mut o, v, true);
                if with_start {
                    let _ = write!(o, " start=\"{x}\"");
                }
                o.push_str("/>\n");
            }
            Start::Boolean(b) => {
                if with_start {
                    let _ = write!(o, " start=\"{b}\"");
                }
                o.push_str("/>\n");
            }
            Start::String(s) => {
                if with_start {
                    let _ = write!(o, ">\n      <Start value=\"{}\"/>\n    </String>\n", escape(s));
                } else {
                    o.push_str("/>\n");
                }
            }
            Start::Binary(b) => {
                if !v.mime_type.is_empty() {
                    let _ = write!(o, " mimeType=\"{}\"", escape(v.mime_type));
                }
                let _ = write!(o, " maxSize=\"{}\"", v.max_size);
                if with_start {
                    let _ = write!(o, ">\n      <Start value=\"{}\"/>\n    </Binary>\n", hex(b));
                } else {
                    o.push_str("/>\n");
                }
            }
        }
    }
    o.push_str("  </ModelVariables>\n  <ModelStructure>\n");
    for (i, v) in vars.iter().enumerate() {
        if v.causality == Causality::Output {
            if me {
                let _ = writeln!(o, "    <Output valueReference=\"{}\"/>", i + 1);
            } else {
                let _ = writeln!(o, "    <Output valueReference=\"{}\" dependencies=\"\"/>", i + 1);
            }
        }
    }
    for s in M::CONTINUOUS_STATES {
        let _ = writeln!(o, "    <ContinuousStateDerivative valueReference=\"{}\"/>", s.derivative + 1);
    }
    for (i, v) in vars.iter().enumerate() {
        if is_initial_unknown_of::<M>(i, v) {
            let _ = write!(o, "    <InitialUnknown valueReference=\"{}\"", i + 1);
            if let Some(deps) = initial_dependency_vrs(v) {
                let _ = write!(o, " dependencies=\"{}\"", join(deps));
            }
            o.push_str("/>\n");
        }
    }
    o.push_str("  </ModelStructure>\n</fmiModelDescription>\n");
    o
}

/// FMI 2.0 modelDescription.xml of `M`: only [`Var::fmi2_representable`] variables, with
/// the same value references as FMI 3; ModelStructure refers to 1-based positions.
pub fn fmi2<M: Model>() -> String {
    // (vr, var) of the visible variables, in order; position k in ModelVariables is k + 2
    // (time is position 1).
    let visible: Vec<(usize, &Var)> =
        M::VARIABLES.iter().enumerate().filter(|(_, v)| v.fmi2_representable()).map(|(i, v)| (i + 1, v)).collect();
    // Position of a visible variable by value reference (time = vr 0 is position 1); knowns
    // FMI 2 cannot see are frozen at their start values there and drop out.
    let position =
        |vr: usize| if vr == 0 { Some(1) } else { visible.iter().position(|&(r, _)| r == vr).map(|k| k + 2) };
    let vars: Vec<&Var> = visible.iter().map(|(_, v)| *v).collect();
    let mut o = String::new();
    o.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(
        o,
        "<fmiModelDescription fmiVersion=\"2.0\" modelName=\"{}\" guid=\"{}\" description=\"{}\" generationTool=\"agrisim-fmi {}\" variableNamingConvention=\"flat\" numberOfEventIndicators=\"0\">",
        escape(M::NAME),
        escape(M::GUID),
        escape(M::DESCRIPTION),
        env!("CARGO_PKG_VERSION")
    );
    let me = is_model_exchange::<M>();
    if me {
        let _ = writeln!(
            o,
            "  <ModelExchange modelIdentifier=\"{}\" needsExecutionTool=\"false\" completedIntegratorStepNotNeeded=\"true\" canBeInstantiatedOnlyOncePerProcess=\"false\" canNotUseMemoryManagementFunctions=\"true\" canGetAndSetFMUstate=\"true\" canSerializeFMUstate=\"true\" providesDirectionalDerivative=\"false\"/>",
            escape(M::NAME)
        );
    } else {
        let _ = writeln!(
            o,
            "  <CoSimulation modelIdentifier=\"{}\" needsExecutionTool=\"false\" canHandleVariableCommunicationStepSize=\"true\" canInterpolateInputs=\"false\" maxOutputDerivativeOrder=\"0\" canRunAsynchronuously=\"false\" canBeInstantiatedOnlyOncePerProcess=\"false\" canNotUseMemoryManagementFunctions=\"true\" canGetAndSetFMUstate=\"true\" canSerializeFMUstate=\"true\" providesDirectionalDerivative=\"false\"/>",
            escape(M::NAME)
        );
    }
    unit_definitions(&mut o, &used_units(&vars));
    log_categories(&mut o);
    let _ = writeln!(o, "  <DefaultExperiment startTime=\"0.0\" stepSize=\"{}\"/>", fmt_f64(M::STEP_SIZE));
    o.push_str("  <ModelVariables>\n");
    o.push_str("    <ScalarVariable name=\"time\" valueReference=\"0\" description=\"Simulation time\" causality=\"independent\" variability=\"continuous\">\n      <Real unit=\"s\"/>\n    </ScalarVariable>\n");
    for &(vr, v) in &visible {
        let with_start = !is_calculated(v);
        o.push_str("    <ScalarVariable");
        common_attributes(&mut o, v, vr);
        o.push_str(">\n      ");
        match v.start {
            Start::Float64(x) => {
                o.push_str("<Real");
                if !v.unit.is_empty() {
                    let _ = write!(o, " unit=\"{}\"", escape(v.unit));
                }
                min_max(&mut o, v, false);
                if let Some(p) = state_of_derivative::<M>(vr - 1).and_then(|s| position(s + 1)) {
                    let _ = write!(o, " derivative=\"{p}\"");
                }
                if with_start {
                    let _ = write!(o, " start=\"{}\"", fmt_f64(x));
                }
            }
            Start::Int32(x) => {
                o.push_str("<Integer");
                min_max(&mut o, v, true);
                if with_start {
                    let _ = write!(o, " start=\"{x}\"");
                }
            }
            Start::Boolean(b) => {
                o.push_str("<Boolean");
                if with_start {
                    let _ = write!(o, " start=\"{b}\"");
                }
            }
            Start::String(s) => {
                o.push_str("<String");
                if with_start {
                    let _ = write!(o, " start=\"{}\"", escape(s));
                }
            }
            Start::Int64(_) | Start::Binary(_) => unreachable!("filtered by fmi2_representable"),
        }
        o.push_str("/>\n    </ScalarVariable>\n");
    }
    o.push_str("  </ModelVariables>\n  <ModelStructure>\n");
    let outputs: Vec<usize> =
        visible.iter().filter(|(_, v)| v.causality == Causality::Output).filter_map(|&(vr, _)| position(vr)).collect();
    if !outputs.is_empty() {
        o.push_str("    <Outputs>\n");
        for i in &outputs {
            if me {
                let _ = writeln!(o, "      <Unknown index=\"{i}\"/>");
            } else {
                let _ = writeln!(o, "      <Unknown index=\"{i}\" dependencies=\"\"/>");
            }
        }
        o.push_str("    </Outputs>\n");
    }
    if me {
        o.push_str("    <Derivatives>\n");
        for s in M::CONTINUOUS_STATES {
            if let Some(i) = position(s.derivative + 1) {
                let _ = writeln!(o, "      <Unknown index=\"{i}\"/>");
            }
        }
        o.push_str("    </Derivatives>\n");
    }
    let initial: Vec<(usize, &Var)> = visible
        .iter()
        .filter(|&&(vr, v)| is_initial_unknown_of::<M>(vr - 1, v))
        .filter_map(|&(vr, v)| Some((position(vr)?, v)))
        .collect();
    if !initial.is_empty() {
        o.push_str("    <InitialUnknowns>\n");
        for (i, v) in initial {
            let _ = write!(o, "      <Unknown index=\"{i}\"");
            if let Some(deps) = initial_dependency_vrs(v) {
                let _ = write!(o, " dependencies=\"{}\"", join(deps.into_iter().filter_map(position)));
            }
            o.push_str("/>\n");
        }
        o.push_str("    </InitialUnknowns>\n");
    }
    o.push_str("  </ModelStructure>\n</fmiModelDescription>\n");
    o
}

/// Lazily built NUL-terminated XML for the exported `agrisim_model_description_*` symbols;
/// NULL if building panicked (it cannot cross the C boundary).
pub fn c_text(cell: &std::sync::OnceLock<Option<std::ffi::CString>>, build: fn() -> String) -> *const std::ffi::c_char {
    cell.get_or_init(|| std::panic::catch_unwind(build).ok().and_then(|s| std::ffi::CString::new(s).ok()))
        .as_ref()
        .map_or(std::ptr::null(), |c| c.as_ptr())
}
