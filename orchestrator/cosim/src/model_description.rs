//! FMI 3.0 `modelDescription.xml`: the part of it the orchestrator needs.
//!
//! The importer trusts nothing it has not checked: every variable it later addresses by value
//! reference comes from here, so a malformed description is rejected up front with the file
//! name and the offending element, instead of surfacing as a confusing FMU status mid-run.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt;
use std::path::Path;

/// A parse or consistency problem in a modelDescription.xml.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ModelDescriptionError {
    /// Where the XML came from (a file path, or `archive.fmu!modelDescription.xml`).
    pub origin: String,
    pub message: String,
}

impl fmt::Display for ModelDescriptionError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.origin, self.message)
    }
}

impl std::error::Error for ModelDescriptionError {}

/// FMI 3.0 variable types. All parse; only some are usable by the orchestrator
/// (see [`VarType::is_supported`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum VarType {
    Float32,
    Float64,
    Int8,
    UInt8,
    Int16,
    UInt16,
    Int32,
    UInt32,
    Int64,
    UInt64,
    Boolean,
    String,
    Binary,
    Clock,
    Enumeration,
}

impl VarType {
    fn from_element(name: &str) -> Option<VarType> {
        Some(match name {
            "Float32" => VarType::Float32,
            "Float64" => VarType::Float64,
            "Int8" => VarType::Int8,
            "UInt8" => VarType::UInt8,
            "Int16" => VarType::Int16,
            "UInt16" => VarType::UInt16,
            "Int32" => VarType::Int32,
            "UInt32" => VarType::UInt32,
            "Int64" => VarType::Int64,
            "UInt64" => VarType::UInt64,
            "Boolean" => VarType::Boolean,
            "String" => VarType::String,
            "Binary" => VarType::Binary,
            "Clock" => VarType::Clock,
            "Enumeration" => VarType::Enumeration,
            _ => return None,
        })
    }

    /// The XML element name (also used in messages).
    pub fn name(self) -> &'static str {
        match self {
            VarType::Float32 => "Float32",
            VarType::Float64 => "Float64",
            VarType::Int8 => "Int8",
            VarType::UInt8 => "UInt8",
            VarType::Int16 => "Int16",
            VarType::UInt16 => "UInt16",
            VarType::Int32 => "Int32",
            VarType::UInt32 => "UInt32",
            VarType::Int64 => "Int64",
            VarType::UInt64 => "UInt64",
            VarType::Boolean => "Boolean",
            VarType::String => "String",
            VarType::Binary => "Binary",
            VarType::Clock => "Clock",
            VarType::Enumeration => "Enumeration",
        }
    }

    /// Types the orchestrator can get, set and exchange.
    pub fn is_supported(self) -> bool {
        matches!(
            self,
            VarType::Float64 | VarType::Int32 | VarType::Int64 | VarType::Boolean | VarType::String | VarType::Binary
        )
    }
}

impl fmt::Display for VarType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Causality {
    Parameter,
    CalculatedParameter,
    StructuralParameter,
    Input,
    Output,
    Local,
    Independent,
}

impl Causality {
    fn parse(s: &str) -> Option<Causality> {
        Some(match s {
            "parameter" => Causality::Parameter,
            "calculatedParameter" => Causality::CalculatedParameter,
            "structuralParameter" => Causality::StructuralParameter,
            "input" => Causality::Input,
            "output" => Causality::Output,
            "local" => Causality::Local,
            "independent" => Causality::Independent,
            _ => return None,
        })
    }

    pub fn name(self) -> &'static str {
        match self {
            Causality::Parameter => "parameter",
            Causality::CalculatedParameter => "calculatedParameter",
            Causality::StructuralParameter => "structuralParameter",
            Causality::Input => "input",
            Causality::Output => "output",
            Causality::Local => "local",
            Causality::Independent => "independent",
        }
    }

    /// Parameters whose value the importer may set (structural ones included).
    pub fn is_settable_parameter(self) -> bool {
        matches!(self, Causality::Parameter | Causality::StructuralParameter)
    }
}

impl fmt::Display for Causality {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Variability {
    Constant,
    Fixed,
    Tunable,
    Discrete,
    Continuous,
}

impl Variability {
    fn parse(s: &str) -> Option<Variability> {
        Some(match s {
            "constant" => Variability::Constant,
            "fixed" => Variability::Fixed,
            "tunable" => Variability::Tunable,
            "discrete" => Variability::Discrete,
            "continuous" => Variability::Continuous,
            _ => return None,
        })
    }

    pub fn name(self) -> &'static str {
        match self {
            Variability::Constant => "constant",
            Variability::Fixed => "fixed",
            Variability::Tunable => "tunable",
            Variability::Discrete => "discrete",
            Variability::Continuous => "continuous",
        }
    }
}

impl fmt::Display for Variability {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// One entry of `<ModelVariables>`.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelVariable {
    pub name: String,
    pub value_reference: u32,
    pub ty: VarType,
    pub causality: Causality,
    pub variability: Variability,
    /// Start value as written (attribute `start`, or the first `<Start value=..>` child for
    /// String/Binary). Binary start values are hex.
    pub start: Option<String>,
    /// Binary only; FMI's default `application/octet-stream` when absent.
    pub mime_type: Option<String>,
    pub description: Option<String>,
}

/// The parts of an FMI 3.0 model description the orchestrator uses.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelDescription {
    pub fmi_version: String,
    pub model_name: String,
    pub instantiation_token: String,
    /// `CoSimulation/@modelIdentifier`: the shared library's file stem.
    pub model_identifier: String,
    pub can_get_and_set_fmu_state: bool,
    pub can_serialize_fmu_state: bool,
    /// Names of `<LogCategories>` (empty when the FMU declares none).
    pub log_categories: Vec<String>,
    pub default_step_size: Option<f64>,
    pub variables: Vec<ModelVariable>,
    /// ModelStructure `<Output>`: value reference -> the knowns it depends on within a
    /// communication point (`None`: not declared, so every input).
    pub output_dependencies: BTreeMap<u32, Option<Vec<u32>>>,
    /// ModelStructure `<InitialUnknown>`: value reference -> the knowns its value in
    /// Initialization Mode depends on (`None`: not declared, so every known).
    pub initial_dependencies: BTreeMap<u32, Option<Vec<u32>>>,
}

impl ModelDescription {
    /// Reads and parses a modelDescription.xml file.
    pub fn from_file(path: &Path) -> Result<ModelDescription, ModelDescriptionError> {
        let origin = path.display().to_string();
        let xml = std::fs::read_to_string(path)
            .map_err(|e| ModelDescriptionError { origin: origin.clone(), message: format!("cannot read: {e}") })?;
        Self::parse(&xml, &origin)
    }

    /// Parses XML text; `origin` names the source in errors.
    pub fn parse(xml: &str, origin: &str) -> Result<ModelDescription, ModelDescriptionError> {
        let err = |message: String| ModelDescriptionError { origin: origin.to_string(), message };
        let doc = roxmltree::Document::parse(xml).map_err(|e| err(format!("not well-formed XML: {e}")))?;
        let root = doc.root_element();
        if root.tag_name().name() != "fmiModelDescription" {
            return Err(err(format!("root element is <{}>, expected <fmiModelDescription>", root.tag_name().name())));
        }
        let attr = |node: roxmltree::Node, name: &str, what: &str| -> Result<String, ModelDescriptionError> {
            node.attribute(name).map(str::to_string).ok_or_else(|| err(format!("{what} has no attribute '{name}'")))
        };
        let fmi_version = attr(root, "fmiVersion", "<fmiModelDescription>")?;
        if !(fmi_version == "3.0" || fmi_version.starts_with("3.0.")) {
            return Err(err(format!("fmiVersion is \"{fmi_version}\", only FMI 3.0 is supported here")));
        }
        let model_name = attr(root, "modelName", "<fmiModelDescription>")?;
        let instantiation_token = attr(root, "instantiationToken", "<fmiModelDescription>")?;

        let cs = child(root, "CoSimulation")
            .ok_or_else(|| err("no <CoSimulation> element: this FMU does not support co-simulation".into()))?;
        let model_identifier = attr(cs, "modelIdentifier", "<CoSimulation>")?;
        if model_identifier.is_empty() || model_identifier.contains(['/', '\\']) {
            return Err(err(format!("<CoSimulation> modelIdentifier \"{model_identifier}\" is not a valid file stem")));
        }
        // A capability flag: absent is false.
        let flag = |name: &str| -> Result<bool, _> {
            match cs.attribute(name) {
                None => Ok(false),
                Some(v) => parse_bool(v).ok_or_else(|| err(format!("<CoSimulation> {name}=\"{v}\" is not a boolean"))),
            }
        };
        let can_get_and_set_fmu_state = flag("canGetAndSetFMUState")?;
        let can_serialize_fmu_state = flag("canSerializeFMUState")?;

        let log_categories = match child(root, "LogCategories") {
            None => Vec::new(),
            Some(lc) => lc
                .children()
                .filter(|n| n.is_element() && n.tag_name().name() == "Category")
                .map(|n| attr(n, "name", "a <LogCategories> <Category>"))
                .collect::<Result<Vec<_>, _>>()?,
        };

        let default_step_size = match child(root, "DefaultExperiment").and_then(|d| d.attribute("stepSize")) {
            None => None,
            Some(v) => {
                Some(parse_f64(v).ok_or_else(|| err(format!("<DefaultExperiment> stepSize=\"{v}\" is not a number")))?)
            }
        };

        let mut variables = Vec::new();
        if let Some(mv) = child(root, "ModelVariables") {
            let mut vrs: BTreeMap<u32, String> = BTreeMap::new();
            let mut names = BTreeSet::new();
            for node in mv.children().filter(|n| n.is_element()) {
                let tag = node.tag_name().name();
                let ty = VarType::from_element(tag)
                    .ok_or_else(|| err(format!("unknown variable element <{tag}> in <ModelVariables>")))?;
                let name = attr(node, "name", &format!("a <{tag}> variable"))?;
                let what = format!("variable '{name}'");
                let vr_text = attr(node, "valueReference", &what)?;
                let value_reference: u32 = vr_text.trim().parse().map_err(|_| {
                    err(format!("{what}: valueReference=\"{vr_text}\" is not an unsigned 32-bit integer"))
                })?;
                let causality = match node.attribute("causality") {
                    None => Causality::Local,
                    Some(c) => Causality::parse(c).ok_or_else(|| err(format!("{what}: unknown causality \"{c}\"")))?,
                };
                let variability = match node.attribute("variability") {
                    // FMI 3.0 default: continuous for Float32/64, discrete otherwise.
                    None if matches!(ty, VarType::Float32 | VarType::Float64) => Variability::Continuous,
                    None => Variability::Discrete,
                    Some(v) => {
                        Variability::parse(v).ok_or_else(|| err(format!("{what}: unknown variability \"{v}\"")))?
                    }
                };
                if variability == Variability::Continuous && !matches!(ty, VarType::Float32 | VarType::Float64) {
                    return Err(err(format!(
                        "{what}: variability \"continuous\" is only allowed for Float32/Float64, not {ty}"
                    )));
                }
                if let Some(other) = vrs.insert(value_reference, name.clone()) {
                    return Err(err(format!(
                        "duplicate valueReference {value_reference}: used by '{other}' and '{name}'"
                    )));
                }
                if !names.insert(name.clone()) {
                    return Err(err(format!("duplicate variable name '{name}'")));
                }
                let start = node
                    .attribute("start")
                    .map(str::to_string)
                    .or_else(|| child(node, "Start").and_then(|s| s.attribute("value")).map(str::to_string));
                let mime_type = if ty == VarType::Binary {
                    Some(node.attribute("mimeType").unwrap_or("application/octet-stream").to_string())
                } else {
                    None
                };
                variables.push(ModelVariable {
                    name,
                    value_reference,
                    ty,
                    causality,
                    variability,
                    start,
                    mime_type,
                    description: node.attribute("description").map(str::to_string),
                });
            }
        }
        let mut output_dependencies = BTreeMap::new();
        let mut initial_dependencies = BTreeMap::new();
        if let Some(ms) = child(root, "ModelStructure") {
            for node in ms.children().filter(|n| n.is_element()) {
                let map = match node.tag_name().name() {
                    "Output" => &mut output_dependencies,
                    "InitialUnknown" => &mut initial_dependencies,
                    _ => continue,
                };
                let what = format!("ModelStructure/{}", node.tag_name().name());
                let vr: u32 = attr(node, "valueReference", &what)?
                    .trim()
                    .parse()
                    .map_err(|e| err(format!("{what}: bad valueReference: {e}")))?;
                let deps = match node.attribute("dependencies") {
                    None => None,
                    Some(text) => Some(
                        text.split_whitespace()
                            .map(|d| {
                                d.parse::<u32>().map_err(|e| err(format!("{what} {vr}: bad dependency {d:?}: {e}")))
                            })
                            .collect::<Result<Vec<u32>, _>>()?,
                    ),
                };
                map.insert(vr, deps);
            }
        }
        Ok(ModelDescription {
            fmi_version,
            model_name,
            instantiation_token,
            model_identifier,
            can_get_and_set_fmu_state,
            can_serialize_fmu_state,
            log_categories,
            default_step_size,
            variables,
            output_dependencies,
            initial_dependencies,
        })
    }

    /// Whether output `output`'s value in Initialization Mode may depend on input `input`
    /// (true when the FMU does not say).
    pub fn initial_depends(&self, output: u32, input: u32) -> bool {
        match self.initial_dependencies.get(&output) {
            Some(Some(deps)) => deps.contains(&input),
            _ => true,
        }
    }

    /// Variable by name.
    pub fn variable(&self, name: &str) -> Option<&ModelVariable> {
        self.variables.iter().find(|v| v.name == name)
    }

    /// A parameter an importer may set (before or during initialization) by name.
    pub fn settable_parameter(&self, name: &str) -> Option<&ModelVariable> {
        self.variable(name).filter(|v| v.causality.is_settable_parameter())
    }

    /// Variable by value reference.
    pub fn variable_by_vr(&self, vr: u32) -> Option<&ModelVariable> {
        self.variables.iter().find(|v| v.value_reference == vr)
    }
}

fn child<'a, 'i>(node: roxmltree::Node<'a, 'i>, name: &str) -> Option<roxmltree::Node<'a, 'i>> {
    node.children().find(|n| n.is_element() && n.tag_name().name() == name)
}

/// xs:boolean.
pub(crate) fn parse_bool(s: &str) -> Option<bool> {
    match s.trim() {
        "true" | "1" => Some(true),
        "false" | "0" => Some(false),
        _ => None,
    }
}

/// xs:double (finite or not; Rust's parser accepts `inf`/`NaN` spellings too).
pub(crate) fn parse_f64(s: &str) -> Option<f64> {
    match s.trim() {
        "INF" => Some(f64::INFINITY),
        "-INF" => Some(f64::NEG_INFINITY),
        t => t.parse().ok(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_follow_fmi3() {
        let xml = r#"<fmiModelDescription fmiVersion="3.0" modelName="M" instantiationToken="{t}">
            <CoSimulation modelIdentifier="m"/>
            <ModelVariables>
              <Float64 name="x" valueReference="1"/>
              <Int32 name="n" valueReference="2"/>
              <Binary name="b" valueReference="3"><Start value="0aff"/></Binary>
            </ModelVariables></fmiModelDescription>"#;
        let md = ModelDescription::parse(xml, "t.xml").unwrap();
        assert_eq!(md.variable("x").unwrap().variability, Variability::Continuous);
        assert_eq!(md.variable("n").unwrap().variability, Variability::Discrete);
        assert_eq!(md.variable("n").unwrap().causality, Causality::Local);
        let b = md.variable("b").unwrap();
        assert_eq!(b.start.as_deref(), Some("0aff"));
        assert_eq!(b.mime_type.as_deref(), Some("application/octet-stream"));
        assert!(!md.can_get_and_set_fmu_state);
        assert!(md.log_categories.is_empty());
        assert_eq!(md.variable_by_vr(2).unwrap().name, "n");
    }
}
