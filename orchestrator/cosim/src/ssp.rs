//! SSP 1.0 system structure (`SystemStructure.ssd`): which FMUs make up the system, their
//! parameter values, and what is wired to what.
//!
//! Only the subset agrisim composes is accepted (one flat system of FMU components, parameter
//! values inline or from `.ssv` files with `.ssm` mappings, units and transformations on
//! connections); anything else is rejected by name rather than silently ignored, so a system
//! file never means something different here than in another SSP tool.
//! [`validate`] (or [`plan_transfers`], which also knows the FMUs' units) then checks the
//! wiring against the FMUs' model descriptions before anything is instantiated, reporting
//! every problem at once.

mod params;
pub mod transform;
pub mod units;

pub use params::{Binding, ParamUnit};
pub use transform::{Transfer, Transformation};
pub use units::{Affine, Unit};

use std::collections::{BTreeMap, BTreeSet};
use std::fmt;
use std::path::{Path, PathBuf};

use roxmltree::Node;

use crate::model_description::{parse_bool, parse_f64, Causality, ModelDescription, ModelVariable, VarType};

pub const NS_SSD: &str = "http://ssp-standard.org/SSP1/SystemStructureDescription";
pub const NS_SSC: &str = "http://ssp-standard.org/SSP1/SystemStructureCommon";
pub const NS_SSV: &str = "http://ssp-standard.org/SSP1/SystemStructureParameterValues";
pub const NS_SSM: &str = "http://ssp-standard.org/SSP1/SystemStructureParameterMapping";
/// `ssc:Annotation/@type` carrying agrisim's per-connection exchange period.
pub const EXCHANGE_ANNOTATION: &str = "org.agrisim.exchange";
/// Annotation type on a system connector: the name of the message-layer topic (or scalar)
/// it stands for (e.g. `/cmd_vel`), which SSP tools would refuse as a connector name.
pub const TOPIC_ANNOTATION: &str = "org.agrisim.topic";
/// The only component type supported.
pub const FMU_COMPONENT_TYPE: &str = "application/x-fmu-sharedlibrary";

/// A problem with a system structure file: names the file and lists every problem found.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SspError {
    pub file: PathBuf,
    pub problems: Vec<String>,
}

impl SspError {
    fn one(file: &Path, problem: impl Into<String>) -> SspError {
        SspError { file: file.to_path_buf(), problems: vec![problem.into()] }
    }
}

impl fmt::Display for SspError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.problems.as_slice() {
            [one] => write!(f, "{}: {one}", self.file.display()),
            many => {
                write!(f, "{}: {} problems:", self.file.display(), many.len())?;
                for p in many {
                    write!(f, "\n  - {p}")?;
                }
                Ok(())
            }
        }
    }
}

impl std::error::Error for SspError {}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConnectorKind {
    Input,
    Output,
    Inout,
    Parameter,
    CalculatedParameter,
}

impl ConnectorKind {
    fn parse(s: &str) -> Option<ConnectorKind> {
        Some(match s {
            "input" => ConnectorKind::Input,
            "output" => ConnectorKind::Output,
            "inout" => ConnectorKind::Inout,
            "parameter" => ConnectorKind::Parameter,
            "calculatedParameter" => ConnectorKind::CalculatedParameter,
            _ => return None,
        })
    }

    pub fn name(self) -> &'static str {
        match self {
            ConnectorKind::Input => "input",
            ConnectorKind::Output => "output",
            ConnectorKind::Inout => "inout",
            ConnectorKind::Parameter => "parameter",
            ConnectorKind::CalculatedParameter => "calculatedParameter",
        }
    }
}

/// The `ssc:` type element of a connector.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ConnectorType {
    Real,
    Integer,
    Boolean,
    String,
    Enumeration,
    Binary { mime_type: Option<String> },
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Connector {
    pub name: String,
    pub kind: ConnectorKind,
    /// `None` when the connector declares no type (it is then taken from the FMU).
    pub ty: Option<ConnectorType>,
    /// The topic from an `org.agrisim.topic` annotation (system connectors).
    pub topic: Option<String>,
    /// `ssc:Real/@unit`: a unit of [`SystemStructure::units`], or of the component's FMU.
    pub unit: Option<String>,
}

impl Connector {
    /// What the program around the engine calls this connector: its topic if annotated,
    /// else its name.
    pub fn external_name(&self) -> &str {
        self.topic.as_deref().unwrap_or(&self.name)
    }
}

/// A parameter value from an inline `ssv:ParameterSet`.
#[derive(Clone, Debug, PartialEq)]
pub enum ParamValue {
    Real(f64),
    Integer(i64),
    Boolean(bool),
    String(String),
    Enumeration(String),
    Binary(Vec<u8>),
}

impl ParamValue {
    /// The value as variable `v`'s type, if it fits.
    pub fn to_value(&self, v: &crate::model_description::ModelVariable) -> Option<crate::value::Value> {
        use crate::model_description::VarType;
        use crate::value::Value;
        Some(match (v.ty, self) {
            (VarType::Float64, ParamValue::Real(f)) => Value::F64(*f),
            (VarType::Int32, ParamValue::Integer(i)) => Value::I32(i32::try_from(*i).ok()?),
            (VarType::Int64, ParamValue::Integer(i)) => Value::I64(*i),
            (VarType::Boolean, ParamValue::Boolean(b)) => Value::Bool(*b),
            (VarType::String, ParamValue::String(s)) => Value::Str(s.clone()),
            (VarType::Binary, ParamValue::Binary(b)) => Value::Bin(b.clone()),
            _ => return None,
        })
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Component {
    pub name: String,
    /// `source` as written (see [`resolve_source`]).
    pub source: String,
    pub connectors: Vec<Connector>,
    /// In precedence order (SSP 1.0): the component's bindings in file order, then the
    /// system's (`component.parameter`); a later binding of the same name overrides an
    /// earlier one when applied.
    pub parameters: Vec<(String, ParamValue)>,
    /// The unit of each Real parameter that was given in one (the value that wins), until
    /// [`convert_parameter_units`] converts it to the FMU variable's unit.
    pub parameter_units: BTreeMap<String, ParamUnit>,
}

impl Component {
    pub fn connector(&self, name: &str) -> Option<&Connector> {
        self.connectors.iter().find(|c| c.name == name)
    }
}

/// One end of a connection; `element: None` is the system itself (an external port).
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct Endpoint {
    pub element: Option<String>,
    pub connector: String,
}

impl fmt::Display for Endpoint {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.element {
            Some(e) => write!(f, "{e}.{}", self.connector),
            None => write!(f, "<system>.{}", self.connector),
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Connection {
    pub start: Endpoint,
    pub end: Endpoint,
    /// Exchange period \[s\] from the `org.agrisim.exchange` annotation; `None` = every step.
    pub period: Option<f64>,
    /// The connection's `ssc:` transformation, applied after unit conversion.
    pub transformation: Option<Transformation>,
    /// `suppressUnitConversion`: only the transformation changes the value.
    pub suppress_unit_conversion: bool,
}

impl fmt::Display for Connection {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "connection {} -> {}", self.start, self.end)
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DefaultExperiment {
    pub start_time: Option<f64>,
    pub stop_time: Option<f64>,
}

/// A parsed SystemStructure.ssd.
#[derive(Clone, Debug, PartialEq)]
pub struct SystemStructure {
    /// The .ssd file (for error messages and resolving sources).
    pub path: PathBuf,
    /// `ssd:System/@name`.
    pub name: String,
    pub components: Vec<Component>,
    /// The system's external ports (e.g. ROS topics such as `/cmd_vel`).
    pub system_connectors: Vec<Connector>,
    pub connections: Vec<Connection>,
    pub default_experiment: Option<DefaultExperiment>,
    /// `ssd:Units`, by name.
    pub units: BTreeMap<String, Unit>,
}

impl SystemStructure {
    pub fn from_file(path: &Path) -> Result<SystemStructure, SspError> {
        let xml = std::fs::read_to_string(path).map_err(|e| SspError::one(path, format!("cannot read: {e}")))?;
        Self::parse(&xml, path)
    }

    /// Parses SSD text; `path` is recorded and used in errors, and `.ssv`/`.ssm` files that
    /// parameter bindings name are read relative to its directory.
    pub fn parse(xml: &str, path: &Path) -> Result<SystemStructure, SspError> {
        let err = |m: String| SspError::one(path, m);
        let doc = roxmltree::Document::parse(xml).map_err(|e| err(format!("not well-formed XML: {e}")))?;
        let root = doc.root_element();
        if !is(root, NS_SSD, "SystemStructureDescription") {
            return Err(err(format!(
                "root element is <{}> (namespace {:?}), expected ssd:SystemStructureDescription in {NS_SSD}",
                root.tag_name().name(),
                root.tag_name().namespace().unwrap_or("none")
            )));
        }
        let system = child(root, NS_SSD, "System").ok_or_else(|| err("no ssd:System element".into()))?;
        let name = req(system, "name", "ssd:System").map_err(err)?;
        if child(root, NS_SSD, "Enumerations").is_some() {
            return Err(err("ssd:Enumerations are not supported (agrisim exchanges no enumerations)".into()));
        }
        let units = match child(root, NS_SSD, "Units") {
            Some(u) => units::parse_units(u, "ssd:Units").map_err(err)?,
            None => BTreeMap::new(),
        };
        let ctx = params::Context { dir: path.parent().unwrap_or_else(|| Path::new(".")), ssd_units: &units };

        let system_connectors = match child(system, NS_SSD, "Connectors") {
            Some(c) => parse_connectors(c, "the system").map_err(err)?,
            None => Vec::new(),
        };

        let mut components = Vec::new();
        if let Some(elements) = child(system, NS_SSD, "Elements") {
            for el in elements.children().filter(Node::is_element) {
                match el.tag_name().name() {
                    "Component" if el.tag_name().namespace() == Some(NS_SSD) => {
                        components.push(parse_component(el, &ctx).map_err(err)?)
                    }
                    other => {
                        return Err(err(format!(
                            "element <{other}> in ssd:Elements is not supported (only ssd:Component; no nested systems)"
                        )))
                    }
                }
            }
        }
        let mut seen = BTreeSet::new();
        for c in &components {
            if !seen.insert(c.name.as_str()) {
                return Err(err(format!("two components are named '{}'", c.name)));
            }
        }
        if let Some(pbs) = child(system, NS_SSD, "ParameterBindings") {
            for b in params::read_bindings(pbs, &ctx, "the system").map_err(err)? {
                // Hierarchical names: the longest component name that prefixes `name` and a dot.
                let comp = components
                    .iter_mut()
                    .filter(|c| b.name.strip_prefix(c.name.as_str()).is_some_and(|r| r.starts_with('.')))
                    .max_by_key(|c| c.name.len())
                    .ok_or_else(|| {
                        err(format!(
                            "system parameter binding '{}' names no component (expected component.parameter; \
                             system connectors cannot be parameterized)",
                            b.name
                        ))
                    })?;
                let local = b.name[comp.name.len() + 1..].to_string();
                bind(comp, Binding { name: local, ..b });
            }
        }

        let mut connections = Vec::new();
        if let Some(conns) = child(system, NS_SSD, "Connections") {
            for c in elements(conns, NS_SSD, "Connection") {
                connections.push(parse_connection(c).map_err(err)?);
            }
        }

        let default_experiment = match child(root, NS_SSD, "DefaultExperiment") {
            None => None,
            Some(d) => Some(DefaultExperiment {
                start_time: opt_f64(d, "startTime", "ssd:DefaultExperiment").map_err(err)?,
                stop_time: opt_f64(d, "stopTime", "ssd:DefaultExperiment").map_err(err)?,
            }),
        };

        Ok(SystemStructure {
            path: path.to_path_buf(),
            name,
            components,
            system_connectors,
            connections,
            default_experiment,
            units,
        })
    }

    pub fn component(&self, name: &str) -> Option<&Component> {
        self.components.iter().find(|c| c.name == name)
    }

    pub fn system_connector(&self, name: &str) -> Option<&Connector> {
        self.system_connectors.iter().find(|c| c.name == name)
    }
}

fn is(node: Node, ns: &str, name: &str) -> bool {
    node.is_element() && node.tag_name().namespace() == Some(ns) && node.tag_name().name() == name
}

fn child<'a, 'i>(node: Node<'a, 'i>, ns: &str, name: &str) -> Option<Node<'a, 'i>> {
    node.children().find(|n| is(*n, ns, name))
}

fn elements<'a, 'i: 'a>(node: Node<'a, 'i>, ns: &'a str, name: &'a str) -> impl Iterator<Item = Node<'a, 'i>> + 'a {
    node.children().filter(move |n| is(*n, ns, name))
}

fn req(node: Node, attr: &str, what: &str) -> Result<String, String> {
    node.attribute(attr).map(str::to_string).ok_or_else(|| format!("{what} has no attribute '{attr}'"))
}

fn opt_f64(node: Node, attr: &str, what: &str) -> Result<Option<f64>, String> {
    match node.attribute(attr) {
        None => Ok(None),
        Some(v) => parse_f64(v).map(Some).ok_or_else(|| format!("{what}: {attr}=\"{v}\" is not a number")),
    }
}

fn parse_connectors(node: Node, owner: &str) -> Result<Vec<Connector>, String> {
    let mut out: Vec<Connector> = Vec::new();
    for c in elements(node, NS_SSD, "Connector") {
        let name = req(c, "name", &format!("a connector of {owner}"))?;
        let what = format!("connector '{name}' of {owner}");
        let kind_s = req(c, "kind", &what)?;
        let kind = ConnectorKind::parse(&kind_s).ok_or_else(|| format!("{what}: unknown kind \"{kind_s}\""))?;
        let type_el = c.children().find(|n| n.is_element() && n.tag_name().namespace() == Some(NS_SSC));
        let unit =
            type_el.filter(|t| t.tag_name().name() == "Real").and_then(|t| t.attribute("unit")).map(str::to_string);
        let ty = match type_el {
            None => None,
            Some(t) => Some(match t.tag_name().name() {
                "Real" => ConnectorType::Real,
                "Integer" => ConnectorType::Integer,
                "Boolean" => ConnectorType::Boolean,
                "String" => ConnectorType::String,
                "Enumeration" => ConnectorType::Enumeration,
                "Binary" => ConnectorType::Binary {
                    mime_type: t.attribute("mime-type").or_else(|| t.attribute("mimeType")).map(str::to_string),
                },
                other => return Err(format!("{what}: unknown type element ssc:{other}")),
            }),
        };
        let mut topic = None;
        if let Some(anns) = child(c, NS_SSD, "Annotations") {
            for ann in elements(anns, NS_SSC, "Annotation").filter(|a| a.attribute("type") == Some(TOPIC_ANNOTATION)) {
                let t = ann
                    .descendants()
                    .filter(|n| n.is_element())
                    .find_map(|n| n.attribute("name"))
                    .filter(|t| !t.is_empty());
                topic = Some(t.ok_or_else(|| format!("{what}: the {TOPIC_ANNOTATION} annotation names no topic (expected an element with a name attribute)"))?.to_string());
            }
        }
        if out.iter().any(|o| o.name == name) {
            return Err(format!("{owner} declares connector '{name}' twice"));
        }
        out.push(Connector { name, kind, ty, topic, unit });
    }
    Ok(out)
}

fn parse_component(el: Node, ctx: &params::Context) -> Result<Component, String> {
    let name = req(el, "name", "an ssd:Component")?;
    let what = format!("component '{name}'");
    let source = req(el, "source", &what)?;
    if let Some(t) = el.attribute("type") {
        if t != FMU_COMPONENT_TYPE {
            return Err(format!("{what}: type \"{t}\" is not supported (only {FMU_COMPONENT_TYPE})"));
        }
    }
    let connectors = match child(el, NS_SSD, "Connectors") {
        Some(c) => parse_connectors(c, &what)?,
        None => Vec::new(),
    };
    let mut comp = Component { name, source, connectors, parameters: Vec::new(), parameter_units: BTreeMap::new() };
    if let Some(pbs) = child(el, NS_SSD, "ParameterBindings") {
        for b in params::read_bindings(pbs, ctx, &what)? {
            bind(&mut comp, b);
        }
    }
    Ok(comp)
}

/// Appends a binding; its unit (or its lack of one) replaces that of an earlier binding.
fn bind(comp: &mut Component, b: Binding) {
    match b.unit {
        Some(u) => comp.parameter_units.insert(b.name.clone(), u),
        None => comp.parameter_units.remove(&b.name),
    };
    comp.parameters.push((b.name, b.value));
}

fn parse_param_value(p: Node, what: &str) -> Result<ParamValue, String> {
    let v = p
        .children()
        .find(|n| n.is_element() && n.tag_name().namespace() == Some(NS_SSV))
        .ok_or_else(|| format!("{what}: no value element (ssv:Real, ssv:Integer, ...)"))?;
    let tag = v.tag_name().name();
    let text = req(v, "value", &format!("{what}: ssv:{tag}"))?;
    let bad = || format!("{what}: ssv:{tag} value=\"{text}\" is not valid");
    Ok(match tag {
        "Real" => ParamValue::Real(parse_f64(&text).ok_or_else(bad)?),
        "Integer" => ParamValue::Integer(text.trim().parse().map_err(|_| bad())?),
        "Boolean" => ParamValue::Boolean(parse_bool(&text).ok_or_else(bad)?),
        "String" => ParamValue::String(text),
        "Enumeration" => ParamValue::Enumeration(text),
        "Binary" => ParamValue::Binary(decode_hex(&text).ok_or_else(bad)?),
        other => return Err(format!("{what}: unknown value element ssv:{other}")),
    })
}

fn decode_hex(s: &str) -> Option<Vec<u8>> {
    let s = s.trim();
    if s.len() & 1 == 1 {
        return None;
    }
    (0..s.len()).step_by(2).map(|i| u8::from_str_radix(s.get(i..i + 2)?, 16).ok()).collect()
}

fn parse_connection(c: Node) -> Result<Connection, String> {
    let endpoint = |el: &str, conn: &str| -> Result<Endpoint, String> {
        Ok(Endpoint {
            element: c.attribute(el).filter(|s| !s.is_empty()).map(str::to_string),
            connector: req(c, conn, "an ssd:Connection")?,
        })
    };
    let start = endpoint("startElement", "startConnector")?;
    let end = endpoint("endElement", "endConnector")?;
    let what = format!("connection {start} -> {end}");
    let transformation = Transformation::parse_child(c, &what)?;
    let suppress_unit_conversion = match c.attribute("suppressUnitConversion") {
        None => false,
        Some(v) => parse_bool(v).ok_or_else(|| format!("{what}: suppressUnitConversion=\"{v}\" is not a boolean"))?,
    };
    let mut period = None;
    if let Some(anns) = child(c, NS_SSD, "Annotations") {
        for ann in elements(anns, NS_SSC, "Annotation").filter(|a| a.attribute("type") == Some(EXCHANGE_ANNOTATION)) {
            let p = ann
                .descendants()
                .find_map(|n| n.attribute("period"))
                .ok_or_else(|| format!("{what}: the {EXCHANGE_ANNOTATION} annotation has no period attribute"))?;
            let v = parse_f64(p)
                .filter(|v| v.is_finite() && *v > 0.0)
                .ok_or_else(|| format!("{what}: exchange period \"{p}\" must be a positive number of seconds"))?;
            period = Some(v);
        }
    }
    Ok(Connection { start, end, period, transformation, suppress_unit_conversion })
}

/// Where a component's `source` lives: relative to the .ssd's directory if that file exists
/// (SSP semantics), else by file name in `fmu_dir` (where `agrisim fmu pack` writes FMUs).
pub fn resolve_source(ssd_path: &Path, source: &str, fmu_dir: &Path) -> PathBuf {
    let s = source.strip_prefix("file://").or_else(|| source.strip_prefix("file:")).unwrap_or(source);
    let base = ssd_path.parent().unwrap_or_else(|| Path::new("."));
    let direct = base.join(s);
    if direct.is_file() {
        return direct;
    }
    match Path::new(s).file_name() {
        Some(f) => fmu_dir.join(f),
        None => direct,
    }
}

/// What can flow through a port, independent of how SSP or FMI spell it.
#[derive(Clone, Debug, PartialEq, Eq)]
enum PortType {
    Real,
    Integer,
    Boolean,
    String,
    Binary(Option<String>),
}

impl fmt::Display for PortType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PortType::Real => f.write_str("Real"),
            PortType::Integer => f.write_str("Integer"),
            PortType::Boolean => f.write_str("Boolean"),
            PortType::String => f.write_str("String"),
            PortType::Binary(Some(m)) => write!(f, "Binary ({m})"),
            PortType::Binary(None) => f.write_str("Binary"),
        }
    }
}

impl PortType {
    fn of_var(v: &ModelVariable) -> Result<PortType, String> {
        Ok(match v.ty {
            VarType::Float64 => PortType::Real,
            VarType::Int32 | VarType::Int64 => PortType::Integer,
            VarType::Boolean => PortType::Boolean,
            VarType::String => PortType::String,
            VarType::Binary => PortType::Binary(v.mime_type.as_deref().map(|m| m.trim().to_string())),
            other => return Err(format!("variable '{}' has type {other}, which agrisim does not support", v.name)),
        })
    }

    fn of_connector(t: &ConnectorType) -> Result<PortType, String> {
        Ok(match t {
            ConnectorType::Real => PortType::Real,
            ConnectorType::Integer => PortType::Integer,
            ConnectorType::Boolean => PortType::Boolean,
            ConnectorType::String => PortType::String,
            ConnectorType::Binary { mime_type } => PortType::Binary(mime_type.as_deref().map(|m| m.trim().to_string())),
            ConnectorType::Enumeration => return Err("type ssc:Enumeration is not supported".into()),
        })
    }

    /// Same kind, and for Binary the same mimeType when both sides state one.
    fn compatible(&self, other: &PortType) -> bool {
        match (self, other) {
            (PortType::Binary(Some(a)), PortType::Binary(Some(b))) => a == b,
            (PortType::Binary(_), PortType::Binary(_)) => true,
            (a, b) => a == b,
        }
    }
}

/// The units of each component's FMU variables (component name -> variable name -> unit), as
/// [`units::fmu_variable_units`] reads them from the FMUs' model descriptions.
pub type FmuUnits = BTreeMap<String, BTreeMap<String, Unit>>;

/// Checks the system against the FMUs' model descriptions, keyed by component name.
/// Reports every problem found, each naming the connection or component and the variable.
/// Units are checked as far as the system file declares them; [`plan_transfers`] also knows
/// the FMUs' own.
pub fn validate(sys: &SystemStructure, mds: &BTreeMap<String, ModelDescription>) -> Result<(), SspError> {
    plan_transfers(sys, mds, &FmuUnits::new()).map(|_| ())
}

/// [`validate`], plus units and transformations: returns, for each of `sys.connections` in
/// order, what its route does to a scalar value (`None`: passes it unchanged).
pub fn plan_transfers(
    sys: &SystemStructure,
    mds: &BTreeMap<String, ModelDescription>,
    fmu_units: &FmuUnits,
) -> Result<Vec<Option<Transfer>>, SspError> {
    let mut problems = Vec::new();
    let mut transfers = Vec::with_capacity(sys.connections.len());

    for comp in &sys.components {
        let Some(md) = mds.get(&comp.name) else {
            problems.push(format!("component '{}': no model description was loaded for it", comp.name));
            continue;
        };
        let fmu = format!("component '{}' (FMU {})", comp.name, md.model_name);
        for c in &comp.connectors {
            let Some(v) = md.variable(&c.name) else {
                problems.push(format!("{fmu}: connector '{}' names no variable of the FMU", c.name));
                continue;
            };
            let kind_ok = match c.kind {
                ConnectorKind::Input => v.causality == Causality::Input,
                ConnectorKind::Output => v.causality == Causality::Output,
                ConnectorKind::Parameter => v.causality.is_settable_parameter(),
                ConnectorKind::CalculatedParameter => v.causality == Causality::CalculatedParameter,
                ConnectorKind::Inout => false,
            };
            if !kind_ok {
                problems.push(format!(
                    "{fmu}: connector '{}' has kind {} but the FMU variable has causality {}",
                    c.name,
                    c.kind.name(),
                    v.causality
                ));
            }
            if let Some(t) = &c.ty {
                match (PortType::of_connector(t), PortType::of_var(v)) {
                    (Ok(a), Ok(b)) if !a.compatible(&b) => problems.push(format!(
                        "{fmu}: connector '{}' is declared {a} but the FMU variable is {} ({b})",
                        c.name, v.ty
                    )),
                    (Err(e), _) | (_, Err(e)) => problems.push(format!("{fmu}: connector '{}': {e}", c.name)),
                    _ => {}
                }
            }
        }
        for (pname, value) in &comp.parameters {
            let Some(v) = md.variable(pname) else {
                problems.push(format!("{fmu}: parameter '{pname}' is not a variable of the FMU"));
                continue;
            };
            if !v.causality.is_settable_parameter() {
                problems.push(format!(
                    "{fmu}: '{pname}' has causality {}, not parameter, so it cannot be bound",
                    v.causality
                ));
                continue;
            }
            let ok = match (value, v.ty) {
                (ParamValue::Real(_), VarType::Float64) => true,
                (ParamValue::Integer(_), VarType::Int64) => true,
                (ParamValue::Integer(i), VarType::Int32) => i32::try_from(*i).is_ok(),
                (ParamValue::Boolean(_), VarType::Boolean) => true,
                (ParamValue::String(_), VarType::String) => true,
                (ParamValue::Binary(_), VarType::Binary) => true,
                _ => false,
            };
            if !ok {
                problems
                    .push(format!("{fmu}: parameter '{pname}' is {} but the value {value:?} does not fit it", v.ty));
            }
        }
    }

    let mut driven: BTreeMap<&Endpoint, &Connection> = BTreeMap::new();
    for conn in &sys.connections {
        let start = endpoint_type(sys, mds, conn, &conn.start, true);
        let end = endpoint_type(sys, mds, conn, &conn.end, false);
        let mut transfer = None;
        match (start, end) {
            (Ok(a), Ok(b)) => match (&a, &b) {
                (Some(a), Some(b)) if !a.compatible(b) => problems.push(format!("{conn}: types differ: {a} -> {b}")),
                _ => match plan_transfer(sys, fmu_units, conn, a.as_ref().or(b.as_ref())) {
                    Ok(t) => transfer = t,
                    Err(e) => problems.push(format!("{conn}: {e}")),
                },
            },
            (a, b) => problems.extend(a.err().into_iter().chain(b.err())),
        }
        transfers.push(transfer);
        if conn.start.element.is_none() && conn.end.element.is_none() {
            problems.push(format!(
                "{conn}: both ends are system connectors; a connection must start or end at a component"
            ));
        }
        if let Some(first) = driven.insert(&conn.end, conn) {
            problems.push(format!("{conn}: input {} is already driven by {first}", conn.end));
        }
    }

    if problems.is_empty() {
        Ok(transfers)
    } else {
        Err(SspError { file: sys.path.clone(), problems })
    }
}

/// A unit named on a connector: the .ssd's definition, else the component FMU's of that name,
/// else the bare name (which converts only to a unit of the same name).
fn connector_unit(sys: &SystemStructure, fmu_units: &FmuUnits, comp: Option<&str>, name: &str) -> Unit {
    sys.units
        .get(name)
        .or_else(|| comp.and_then(|c| fmu_units.get(c)).and_then(|us| us.values().find(|u| u.name == name)))
        .cloned()
        .unwrap_or_else(|| Unit { name: name.to_string(), base: None })
}

/// The units a value passes through at one end of a connection: the FMU variable's (none for
/// a system connector: the bus carries the connector's unit) and the connector's.
fn endpoint_units(
    sys: &SystemStructure,
    fmu_units: &FmuUnits,
    ep: &Endpoint,
) -> (Option<Unit>, Option<Unit>, Option<String>) {
    match &ep.element {
        None => {
            let c = sys.system_connector(&ep.connector).and_then(|c| c.unit.as_deref());
            (None, c.map(|u| connector_unit(sys, fmu_units, None, u)), None)
        }
        Some(comp) => {
            let var = fmu_units.get(comp).and_then(|u| u.get(&ep.connector)).cloned();
            let conn = sys.component(comp).and_then(|c| c.connector(&ep.connector)).and_then(|c| c.unit.as_deref());
            (var, conn.map(|u| connector_unit(sys, fmu_units, Some(comp), u)), Some(format!("{comp}.{}", ep.connector)))
        }
    }
}

/// `from` -> `to` where both are known; identity otherwise (SSP converts only between two
/// declared units).
fn convert(from: Option<&Unit>, to: Option<&Unit>) -> Result<Affine, String> {
    match (from, to) {
        (Some(a), Some(b)) => a.conversion_to(b),
        _ => Ok(Affine::IDENTITY),
    }
}

/// What connection `conn` of type `ty` does to a value: the value goes from the start
/// variable's unit to its connector's, to the end connector's, through a
/// LinearTransformation (SSP: in the end unit, after conversion), into the end variable's
/// unit. Checks that the transformation fits the type.
fn plan_transfer(
    sys: &SystemStructure,
    fmu_units: &FmuUnits,
    conn: &Connection,
    ty: Option<&PortType>,
) -> Result<Option<Transfer>, String> {
    if let Some(t) = &conn.transformation {
        match ty {
            Some(PortType::Binary(_)) => {
                return Err(format!(
                    "{} on a message (Binary) connection: transformations apply to scalars",
                    t.element()
                ))
            }
            Some(p) if p.to_string() == t.applies_to() => {}
            Some(p) => return Err(format!("{} applies only to {} connections, not {p}", t.element(), t.applies_to())),
            None => {
                return Err(format!(
                    "{}: the connection's type is unknown (declare a type on its connectors)",
                    t.element()
                ))
            }
        }
    }
    Ok(match (ty, &conn.transformation) {
        (Some(PortType::Real), t) => {
            let linear = match t {
                Some(Transformation::Linear(a)) => *a,
                _ => Affine::IDENTITY,
            };
            let a = if conn.suppress_unit_conversion {
                linear
            } else {
                let (v0, c0, n0) = endpoint_units(sys, fmu_units, &conn.start);
                let (v1, c1, n1) = endpoint_units(sys, fmu_units, &conn.end);
                let side = |n: Option<String>, e: String| match n {
                    Some(n) => format!("connector {n} and its FMU variable: {e}"),
                    None => e,
                };
                let start = convert(v0.as_ref(), c0.as_ref()).map_err(|e| side(n0, e))?;
                let between = convert(c0.as_ref().or(v0.as_ref()), c1.as_ref().or(v1.as_ref()))?;
                let end = convert(c1.as_ref(), v1.as_ref()).map_err(|e| side(n1, e))?;
                start.then(between).then(linear).then(end)
            };
            (!a.is_identity()).then_some(Transfer::Affine(a))
        }
        (_, Some(Transformation::Boolean(m))) => Some(Transfer::Boolean(m.clone())),
        (_, Some(Transformation::Integer(m))) => Some(Transfer::Integer(m.clone())),
        _ => None,
    })
}

/// Converts every Real parameter value that was given in a unit to the unit of its FMU
/// variable, then applies its mapping's linear transformation; a variable that declares no
/// unit takes the value as given. Call once, after the FMUs are known (it empties
/// [`Component::parameter_units`]).
pub fn convert_parameter_units(sys: &mut SystemStructure, fmu_units: &FmuUnits) -> Result<(), SspError> {
    let mut problems = Vec::new();
    for comp in &mut sys.components {
        for (name, pu) in std::mem::take(&mut comp.parameter_units) {
            let conv = match fmu_units.get(&comp.name).and_then(|u| u.get(&name)) {
                None => Ok(Affine::IDENTITY),
                Some(to) => pu.unit.conversion_to(to),
            };
            match conv {
                Ok(c) => {
                    let a = c.then(pu.then);
                    // The unit belongs to the binding that wins: the last of that name.
                    if let Some((_, ParamValue::Real(x))) = comp.parameters.iter_mut().rev().find(|(n, _)| *n == name) {
                        *x = a.apply(*x);
                    }
                }
                Err(e) => {
                    problems.push(format!("component '{}': parameter '{name}' (from {}): {e}", comp.name, pu.origin))
                }
            }
        }
    }
    if problems.is_empty() {
        Ok(())
    } else {
        Err(SspError { file: sys.path.clone(), problems })
    }
}

/// Type of a connection endpoint after checking it exists and has the right direction.
/// `Ok(None)` = an untyped system connector (takes the other side's type).
fn endpoint_type(
    sys: &SystemStructure,
    mds: &BTreeMap<String, ModelDescription>,
    conn: &Connection,
    ep: &Endpoint,
    is_start: bool,
) -> Result<Option<PortType>, String> {
    let side = if is_start { "start" } else { "end" };
    match &ep.element {
        None => {
            let c = sys
                .system_connector(&ep.connector)
                .ok_or_else(|| format!("{conn}: the system has no connector '{}'", ep.connector))?;
            // Inside the system, a system input is a source and a system output a sink.
            let ok = match c.kind {
                ConnectorKind::Input => is_start,
                ConnectorKind::Output => !is_start,
                _ => false,
            };
            if !ok {
                return Err(format!(
                    "{conn}: system connector '{}' has kind {} and cannot be the {side} of a connection",
                    c.name,
                    c.kind.name()
                ));
            }
            c.ty.as_ref().map(PortType::of_connector).transpose().map_err(|e| format!("{conn}: {e}"))
        }
        Some(el) => {
            let comp = sys.component(el).ok_or_else(|| format!("{conn}: there is no component '{el}'"))?;
            if comp.connector(&ep.connector).is_none() {
                return Err(format!("{conn}: component '{el}' declares no connector '{}'", ep.connector));
            }
            let md = mds.get(el).ok_or_else(|| format!("{conn}: no model description for component '{el}'"))?;
            let v = md.variable(&ep.connector).ok_or_else(|| {
                format!("{conn}: FMU {} of component '{el}' has no variable '{}'", md.model_name, ep.connector)
            })?;
            let want = if is_start { Causality::Output } else { Causality::Input };
            if v.causality != want {
                return Err(format!(
                    "{conn}: {side} variable '{}' of component '{el}' has causality {}, expected {}",
                    v.name, v.causality, want
                ));
            }
            PortType::of_var(v).map(Some).map_err(|e| format!("{conn}: component '{el}': {e}"))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hex() {
        assert_eq!(decode_hex("00ff10"), Some(vec![0, 255, 16]));
        assert_eq!(decode_hex("0"), None);
        assert_eq!(decode_hex("zz"), None);
        assert_eq!(decode_hex(""), Some(vec![]));
    }

    const HEAD: &str = r#"<ssd:SystemStructureDescription version="1.0" name="t"
        xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
        xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon"
        xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues"
        xmlns:ssm="http://ssp-standard.org/SSP1/SystemStructureParameterMapping">"#;

    /// A system with component `a` (FMU variables: Float64 output `x` \[m/s\], input `u`
    /// \[m/s\], Int32 output `n`, input `k`, Boolean output `b`, input `c`, Binary output
    /// `msg`, Float64 parameters `p` \[m\] and `q`), system connectors `sys_in` (km/h) and
    /// `sys_out`, and `body` inside ssd:System after the elements.
    fn system(connectors: &str, body: &str, after_system: &str) -> String {
        format!(
            r#"{HEAD}<ssd:System name="s">
              <ssd:Connectors>
                <ssd:Connector name="sys_in" kind="input"><ssc:Real unit="km/h"/></ssd:Connector>
                <ssd:Connector name="sys_out" kind="output"><ssc:Real unit="km/h"/></ssd:Connector>
              </ssd:Connectors>
              <ssd:Elements><ssd:Component name="a" source="A.fmu"><ssd:Connectors>
                <ssd:Connector name="x" kind="output"/><ssd:Connector name="u" kind="input"/>
                <ssd:Connector name="n" kind="output"/><ssd:Connector name="k" kind="input"/>
                <ssd:Connector name="b" kind="output"/><ssd:Connector name="c" kind="input"/>
                <ssd:Connector name="msg" kind="output"/>{connectors}
              </ssd:Connectors></ssd:Component></ssd:Elements>
              {body}
            </ssd:System>
            <ssd:Units>
              <ssc:Unit name="km/h"><ssc:BaseUnit m="1" s="-1" factor="0.2777777777777778"/></ssc:Unit>
              <ssc:Unit name="mm"><ssc:BaseUnit m="1" factor="0.001"/></ssc:Unit>
              <ssc:Unit name="s"><ssc:BaseUnit s="1"/></ssc:Unit>
            </ssd:Units>{after_system}
            </ssd:SystemStructureDescription>"#
        )
    }

    const MD: &str = r#"<fmiModelDescription fmiVersion="3.0" modelName="A" instantiationToken="t">
      <CoSimulation modelIdentifier="a"/>
      <UnitDefinitions><Unit name="m/s"><BaseUnit m="1" s="-1"/></Unit><Unit name="m"><BaseUnit m="1"/></Unit></UnitDefinitions>
      <TypeDefinitions><Float64Type name="Speed" unit="m/s"/></TypeDefinitions>
      <ModelVariables>
        <Float64 name="x" valueReference="1" causality="output" declaredType="Speed"/>
        <Float64 name="u" valueReference="2" causality="input" declaredType="Speed" start="0"/>
        <Int32 name="n" valueReference="3" causality="output"/>
        <Int32 name="k" valueReference="4" causality="input" start="0"/>
        <Boolean name="b" valueReference="5" causality="output"/>
        <Boolean name="c" valueReference="6" causality="input" start="false"/>
        <Binary name="msg" valueReference="7" causality="output"/>
        <Int64 name="msg_seq" valueReference="8" causality="output"/>
        <Float64 name="p" valueReference="9" causality="parameter" variability="fixed" unit="m" start="0"/>
        <Float64 name="q" valueReference="10" causality="parameter" variability="fixed" start="0"/>
        <Int32 name="i" valueReference="11" causality="parameter" variability="fixed" start="0"/>
      </ModelVariables></fmiModelDescription>"#;

    fn plan(xml: &str) -> Result<Vec<Option<Transfer>>, String> {
        plan_at(xml, Path::new("t.ssd"))
    }

    fn plan_at(xml: &str, path: &Path) -> Result<Vec<Option<Transfer>>, String> {
        let sys = SystemStructure::parse(xml, path).map_err(|e| e.to_string())?;
        let md = ModelDescription::parse(MD, "A").unwrap();
        let mds = BTreeMap::from([("a".to_string(), md)]);
        let units = FmuUnits::from([("a".to_string(), units::fmu_variable_units(MD, "A").unwrap())]);
        plan_transfers(&sys, &mds, &units).map_err(|e| e.to_string())
    }

    fn conn(start: &str, end: &str, inner: &str) -> String {
        let ep = |attr: &str, e: &str| match e.split_once('.') {
            Some((el, c)) => format!(r#"{attr}Element="{el}" {attr}Connector="{c}""#),
            None => format!(r#"{attr}Connector="{e}""#),
        };
        format!(
            r#"<ssd:Connections><ssd:Connection {} {}>{inner}</ssd:Connection></ssd:Connections>"#,
            ep("start", start),
            ep("end", end)
        )
    }

    fn affine(t: &Option<Transfer>) -> Affine {
        match t {
            Some(Transfer::Affine(a)) => *a,
            None => Affine::IDENTITY,
            other => panic!("not affine: {other:?}"),
        }
    }

    #[test]
    fn units_parse_on_connectors_and_the_root() {
        let s = SystemStructure::parse(&system("", "", ""), Path::new("t.ssd")).unwrap();
        assert_eq!(s.system_connector("sys_in").unwrap().unit.as_deref(), Some("km/h"));
        assert_eq!(s.component("a").unwrap().connector("x").unwrap().unit, None);
        assert_eq!(s.units["mm"].base.unwrap().factor, 0.001);
        assert_eq!(s.units.len(), 3);
    }

    #[test]
    fn unit_conversion_and_linear_transformation_compose_in_ssp_order() {
        // km/h system input into an m/s FMU input: 36 km/h is 10 m/s.
        let t = plan(&system("", &conn("sys_in", "a.u", ""), "")).unwrap();
        assert!((affine(&t[0]).apply(36.0) - 10.0).abs() < 1e-12);
        // m/s output to a km/h system output, then factor 2, offset 1 in km/h.
        let t = plan(&system("", &conn("a.x", "sys_out", r#"<ssc:LinearTransformation factor="2" offset="1"/>"#), ""))
            .unwrap();
        assert!((affine(&t[0]).apply(10.0) - 73.0).abs() < 1e-9);
        // suppressUnitConversion: only the transformation.
        let x = system("", &conn("a.x", "sys_out", r#"<ssc:LinearTransformation factor="2"/>"#), "")
            .replace("<ssd:Connection ", r#"<ssd:Connection suppressUnitConversion="true" "#);
        assert_eq!(affine(&plan(&x).unwrap()[0]), Affine { factor: 2.0, offset: 0.0 });
        // Same units both sides: nothing to do.
        assert_eq!(plan(&system("", &conn("a.x", "a.u", ""), "")).unwrap(), vec![None]);
        // A component connector may declare its own unit: converted from and to the variable's.
        let t = plan(&system("", &conn("a.x", "a.u", ""), "").replace(
            r#"<ssd:Connector name="x" kind="output"/>"#,
            r#"<ssd:Connector name="x" kind="output"><ssc:Real unit="km/h"/></ssd:Connector>"#,
        ))
        .unwrap();
        assert!((affine(&t[0]).apply(3.0) - 3.0).abs() < 1e-12);
    }

    #[test]
    fn incompatible_units_name_the_connection() {
        let x = system("", &conn("sys_in", "a.u", ""), "").replace(
            r#"<ssc:Real unit="km/h"/></ssd:Connector>
                <ssd:Connector name="sys_out""#,
            r#"<ssc:Real unit="s"/></ssd:Connector>
                <ssd:Connector name="sys_out""#,
        );
        let e = plan(&x).unwrap_err();
        assert!(e.contains("connection <system>.sys_in -> a.u: incompatible units: s (s) -> m/s (m.s-1)"), "{e}");
        let x = system("", &conn("a.x", "a.u", ""), "").replace(
            r#"<ssd:Connector name="u" kind="input"/>"#,
            r#"<ssd:Connector name="u" kind="input"><ssc:Real unit="mm"/></ssd:Connector>"#,
        );
        let e = plan(&x).unwrap_err();
        assert!(e.contains("connection a.x -> a.u: incompatible units: m/s (m.s-1) -> mm (m)"), "{e}");
    }

    #[test]
    fn transformations_must_fit_the_connection_type() {
        let map = r#"<ssc:IntegerMappingTransformation><ssc:MapEntry source="1" target="7"/></ssc:IntegerMappingTransformation>"#;
        let t = plan(&system("", &conn("a.n", "a.k", map), "")).unwrap();
        assert_eq!(t[0], Some(Transfer::Integer([(1, 7)].into())));
        let not = r#"<ssc:BooleanMappingTransformation><ssc:MapEntry source="true" target="false"/><ssc:MapEntry source="false" target="true"/></ssc:BooleanMappingTransformation>"#;
        assert!(matches!(plan(&system("", &conn("a.b", "a.c", not), "")).unwrap()[0], Some(Transfer::Boolean(_))));
        for (c, why) in [
            (
                conn("a.n", "a.k", r#"<ssc:LinearTransformation factor="2"/>"#),
                "connection a.n -> a.k: ssc:LinearTransformation applies only to Real connections, not Integer",
            ),
            (
                conn("a.x", "a.u", map),
                "connection a.x -> a.u: ssc:IntegerMappingTransformation applies only to Integer connections, not Real",
            ),
            (
                conn("a.n", "a.k", not),
                "ssc:BooleanMappingTransformation applies only to Boolean connections, not Integer",
            ),
            (
                conn("a.msg", "sys_bin", r#"<ssc:LinearTransformation/>"#),
                "connection a.msg -> <system>.sys_bin: ssc:LinearTransformation on a message (Binary) connection",
            ),
        ] {
            let x = system("", &c, "").replace(
                "</ssd:Connectors>\n              <ssd:Elements>",
                r#"<ssd:Connector name="sys_bin" kind="output"><ssc:Binary/></ssd:Connector></ssd:Connectors>
              <ssd:Elements>"#,
            );
            let e = plan(&x).unwrap_err();
            assert!(e.contains(why), "{e}");
        }
    }

    #[test]
    fn a_connection_between_two_system_connectors_is_refused() {
        let e = plan(&system("", &conn("sys_in", "sys_out", ""), "")).unwrap_err();
        assert!(e.contains("connection <system>.sys_in -> <system>.sys_out: both ends are system connectors"), "{e}");
    }

    /// `files` written beside `t.ssd` in a temporary directory; the parsed system.
    fn with_files(xml: &str, files: &[(&str, &str)]) -> (tempfile::TempDir, Result<SystemStructure, String>) {
        let dir = tempfile::tempdir().unwrap();
        for (name, text) in files {
            let p = dir.path().join(name);
            std::fs::create_dir_all(p.parent().unwrap()).unwrap();
            std::fs::write(p, text).unwrap();
        }
        let path = dir.path().join("t.ssd");
        let s = SystemStructure::parse(xml, &path).map_err(|e| e.to_string());
        (dir, s)
    }

    const SSV: &str = r#"<ssv:ParameterSet version="1.0" name="set"
        xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues"
        xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon">
      <ssv:Parameters>
        <ssv:Parameter name="p"><ssv:Real value="250" unit="mm"/></ssv:Parameter>
        <ssv:Parameter name="q"><ssv:Real value="1.5"/></ssv:Parameter>
        <ssv:Parameter name="gear"><ssv:Integer value="2"/></ssv:Parameter>
      </ssv:Parameters>
      <ssv:Units><ssc:Unit name="mm"><ssc:BaseUnit m="1" factor="0.001"/></ssc:Unit></ssv:Units>
    </ssv:ParameterSet>"#;

    fn component_bindings(bindings: &str) -> String {
        system("", "", "").replace(
            r#"<ssd:Connector name="msg" kind="output"/>
              </ssd:Connectors>"#,
            &format!(r#"<ssd:Connector name="msg" kind="output"/></ssd:Connectors><ssd:ParameterBindings>{bindings}</ssd:ParameterBindings>"#),
        )
    }

    #[test]
    fn ssv_files_bind_values_with_units() {
        let xml = component_bindings(r#"<ssd:ParameterBinding source="resources/a.ssv"/>"#);
        let (_d, s) = with_files(&xml, &[("resources/a.ssv", SSV)]);
        let mut s = s.unwrap();
        let a = s.component("a").unwrap();
        assert_eq!(a.parameters[0], ("p".to_string(), ParamValue::Real(250.0)));
        assert_eq!(a.parameter_units["p"].unit.name, "mm");
        assert!(a.parameter_units["p"].origin.ends_with("resources/a.ssv"));
        let units = FmuUnits::from([("a".to_string(), units::fmu_variable_units(MD, "A").unwrap())]);
        convert_parameter_units(&mut s, &units).unwrap();
        let a = s.component("a").unwrap();
        assert_eq!(a.parameters[0], ("p".to_string(), ParamValue::Real(0.25)));
        assert!(a.parameter_units.is_empty());
    }

    #[test]
    fn mappings_rename_and_transform_and_later_bindings_win() {
        let ssm = r#"<ssm:ParameterMapping version="1.0"
            xmlns:ssm="http://ssp-standard.org/SSP1/SystemStructureParameterMapping"
            xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon">
          <ssm:MappingEntry source="set.gear" target="i">
            <ssc:IntegerMappingTransformation><ssc:MapEntry source="2" target="20"/></ssc:IntegerMappingTransformation>
          </ssm:MappingEntry>
          <ssm:MappingEntry source="set.p" target="p"><ssc:LinearTransformation factor="2"/></ssm:MappingEntry>
          <ssm:MappingEntry source="set.q" target="q"><ssc:LinearTransformation offset="1"/></ssm:MappingEntry>
        </ssm:ParameterMapping>"#;
        let xml = component_bindings(
            r#"<ssd:ParameterBinding source="a.ssv" prefix="set."><ssd:ParameterMapping source="a.ssm"/></ssd:ParameterBinding>"#,
        )
        .replace(
            "</ssd:System>",
            r#"<ssd:ParameterBindings><ssd:ParameterBinding><ssd:ParameterValues><ssv:ParameterSet version="1.0" name="sys">
                <ssv:Parameters><ssv:Parameter name="a.q"><ssv:Real value="9"/></ssv:Parameter></ssv:Parameters>
              </ssv:ParameterSet></ssd:ParameterValues></ssd:ParameterBinding></ssd:ParameterBindings></ssd:System>"#,
        );
        let (_d, s) = with_files(&xml, &[("a.ssv", SSV), ("a.ssm", ssm)]);
        let mut s = s.unwrap();
        let units = FmuUnits::from([("a".to_string(), units::fmu_variable_units(MD, "A").unwrap())]);
        convert_parameter_units(&mut s, &units).unwrap();
        let a = s.component("a").unwrap();
        assert_eq!(
            a.parameters,
            vec![
                // 250 mm is 0.25 m, then doubled (the transformation works on the converted value).
                ("p".to_string(), ParamValue::Real(0.5)),
                ("q".to_string(), ParamValue::Real(2.5)),
                ("i".to_string(), ParamValue::Integer(20)),
                // The system's binding comes last, so it wins.
                ("q".to_string(), ParamValue::Real(9.0)),
            ]
        );
    }

    #[test]
    fn parameter_binding_errors_name_the_file() {
        let xml = component_bindings(r#"<ssd:ParameterBinding source="missing.ssv"/>"#);
        let e = with_files(&xml, &[]).1.unwrap_err();
        assert!(e.contains("component 'a': cannot read") && e.contains("missing.ssv"), "{e}");
        let xml = component_bindings(r#"<ssd:ParameterBinding source="a.ssv"/>"#);
        let e = with_files(&xml, &[("a.ssv", &SSV.replace(r#"value="1.5""#, r#"value="lots""#))]).1.unwrap_err();
        assert!(e.contains("a.ssv, parameter 'q': ssv:Real value=\"lots\" is not valid"), "{e}");
        let e = with_files(&xml, &[("a.ssv", "<x/>")]).1.unwrap_err();
        assert!(e.contains("a.ssv: root element is <x>, expected ssv:ParameterSet"), "{e}");
        let xml = component_bindings(
            r#"<ssd:ParameterBinding source="a.ssv"><ssd:ParameterMapping><ssm:ParameterMapping version="1.0">
              <ssm:MappingEntry source="gear" target="i"><ssc:LinearTransformation/></ssm:MappingEntry>
            </ssm:ParameterMapping></ssd:ParameterMapping></ssd:ParameterBinding>"#,
        );
        let e = with_files(&xml, &[("a.ssv", SSV)]).1.unwrap_err();
        assert!(e.contains("parameter 'gear': ssc:LinearTransformation applies only to Real values"), "{e}");
        let xml = system("", "", "").replace(
            "</ssd:System>",
            r#"<ssd:ParameterBindings><ssd:ParameterBinding source="a.ssv"/></ssd:ParameterBindings></ssd:System>"#,
        );
        let e = with_files(&xml, &[("a.ssv", SSV)]).1.unwrap_err();
        assert!(e.contains("system parameter binding 'p' names no component"), "{e}");
        // A .ssv value in a unit that does not fit the FMU variable's.
        let xml = component_bindings(r#"<ssd:ParameterBinding source="a.ssv"/>"#);
        let (_d, s) = with_files(&xml, &[("a.ssv", &SSV.replace(r#"unit="mm""#, r#"unit="s""#))]);
        let mut s = s.unwrap();
        let units = FmuUnits::from([("a".to_string(), units::fmu_variable_units(MD, "A").unwrap())]);
        let e = convert_parameter_units(&mut s, &units).unwrap_err().to_string();
        assert!(
            e.contains("component 'a': parameter 'p' (from ") && e.contains("incompatible units: s (s) -> m (m)"),
            "{e}"
        );
    }

    #[test]
    fn endpoint_display() {
        let e = Endpoint { element: None, connector: "/cmd_vel".into() };
        assert_eq!(e.to_string(), "<system>./cmd_vel");
    }
}
