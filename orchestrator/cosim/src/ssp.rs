//! SSP 1.0 system structure (`SystemStructure.ssd`): which FMUs make up the system, their
//! parameter values, and what is wired to what.
//!
//! Only the subset agrisim composes is accepted (one flat system of FMU components, inline
//! parameter values); anything else is rejected by name rather than silently ignored, so a
//! system file never means something different here than in another SSP tool.
//! [`validate`] then checks the wiring against the FMUs' model descriptions before anything
//! is instantiated, reporting every problem at once.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt;
use std::path::{Path, PathBuf};

use roxmltree::Node;

use crate::model_description::{parse_bool, parse_f64, Causality, ModelDescription, ModelVariable, VarType};

pub const NS_SSD: &str = "http://ssp-standard.org/SSP1/SystemStructureDescription";
pub const NS_SSC: &str = "http://ssp-standard.org/SSP1/SystemStructureCommon";
pub const NS_SSV: &str = "http://ssp-standard.org/SSP1/SystemStructureParameterValues";
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

#[derive(Clone, Debug, PartialEq)]
pub struct Component {
    pub name: String,
    /// `source` as written (see [`resolve_source`]).
    pub source: String,
    pub connectors: Vec<Connector>,
    /// In file order; a later binding of the same name overrides an earlier one when applied.
    pub parameters: Vec<(String, ParamValue)>,
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
}

impl SystemStructure {
    pub fn from_file(path: &Path) -> Result<SystemStructure, SspError> {
        let xml = std::fs::read_to_string(path).map_err(|e| SspError::one(path, format!("cannot read: {e}")))?;
        Self::parse(&xml, path)
    }

    /// Parses SSD text; `path` is recorded and used in errors.
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

        let system_connectors = match child(system, NS_SSD, "Connectors") {
            Some(c) => parse_connectors(c, "the system").map_err(err)?,
            None => Vec::new(),
        };

        let mut components = Vec::new();
        if let Some(elements) = child(system, NS_SSD, "Elements") {
            for el in elements.children().filter(Node::is_element) {
                match el.tag_name().name() {
                    "Component" if el.tag_name().namespace() == Some(NS_SSD) => {
                        components.push(parse_component(el).map_err(err)?)
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
        if child(system, NS_SSD, "ParameterBindings").is_some() {
            return Err(err(
                "system-level ssd:ParameterBindings are not supported; bind parameters on each component".into()
            ));
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
        let ty = match c.children().find(|n| n.is_element() && n.tag_name().namespace() == Some(NS_SSC)) {
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
        out.push(Connector { name, kind, ty, topic });
    }
    Ok(out)
}

fn parse_component(el: Node) -> Result<Component, String> {
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
    let mut parameters = Vec::new();
    if let Some(pbs) = child(el, NS_SSD, "ParameterBindings") {
        for pb in elements(pbs, NS_SSD, "ParameterBinding") {
            if let Some(src) = pb.attribute("source") {
                return Err(format!(
                    "{what}: external parameter source \"{src}\" is not supported; put the values inline"
                ));
            }
            if pb.attribute("prefix").is_some_and(|p| !p.is_empty()) {
                return Err(format!("{what}: ssd:ParameterBinding prefix is not supported"));
            }
            let Some(values) = child(pb, NS_SSD, "ParameterValues") else {
                continue;
            };
            for set in elements(values, NS_SSV, "ParameterSet") {
                let Some(params) = child(set, NS_SSV, "Parameters") else {
                    continue;
                };
                for p in elements(params, NS_SSV, "Parameter") {
                    let pname = req(p, "name", &format!("an ssv:Parameter of {what}"))?;
                    parameters.push((pname.clone(), parse_param_value(p, &format!("{what}, parameter '{pname}'"))?));
                }
            }
        }
    }
    Ok(Component { name, source, connectors, parameters })
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
    Ok(Connection { start, end, period })
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

/// Checks the system against the FMUs' model descriptions, keyed by component name.
/// Reports every problem found, each naming the connection or component and the variable.
pub fn validate(sys: &SystemStructure, mds: &BTreeMap<String, ModelDescription>) -> Result<(), SspError> {
    let mut problems = Vec::new();

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
        match (start, end) {
            (Ok(a), Ok(b)) => {
                if let (Some(a), Some(b)) = (&a, &b) {
                    if !a.compatible(b) {
                        problems.push(format!("{conn}: types differ: {a} -> {b}"));
                    }
                }
            }
            (a, b) => problems.extend(a.err().into_iter().chain(b.err())),
        }
        if let Some(first) = driven.insert(&conn.end, conn) {
            problems.push(format!("{conn}: input {} is already driven by {first}", conn.end));
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

    #[test]
    fn endpoint_display() {
        let e = Endpoint { element: None, connector: "/cmd_vel".into() };
        assert_eq!(e.to_string(), "<system>./cmd_vel");
    }
}
