//! FMI 3.0 and FMI 2.0 `modelDescription.xml`: the part of it the orchestrator needs, in one
//! shape (FMI 2 types map onto FMI 3's: Real is Float64, Integer is Int32).
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
    /// Float64 (FMI 2 Real) only: the `unit` attribute, when declared.
    pub unit: Option<String>,
}

/// Which FMI standard a description (and so its binary) follows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum FmiVersion {
    V2,
    V3,
}

/// How the importer drives the FMU: co-simulation (the FMU steps itself) or model exchange
/// (the master integrates its continuous states).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Interface {
    CoSimulation,
    ModelExchange,
}

/// What a model-exchange FMU declares about its continuous part.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ModelExchangeInfo {
    /// Continuous states, in the order of the FMU's state vector: (state vr, derivative vr).
    pub states: Vec<(u32, u32)>,
    pub number_of_event_indicators: usize,
    /// `needsCompletedIntegratorStep` (FMI 2 `completedIntegratorStepNotNeeded` negated).
    pub needs_completed_integrator_step: bool,
}

/// The parts of an FMI 3.0 or 2.0 model description the orchestrator uses.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelDescription {
    pub fmi_version: String,
    pub version: FmiVersion,
    /// Co-simulation when the FMU offers it, else model exchange.
    pub interface: Interface,
    /// The model-exchange part, when the FMU offers it.
    pub model_exchange: Option<ModelExchangeInfo>,
    pub model_name: String,
    /// FMI 3 `instantiationToken`, FMI 2 `guid`.
    pub instantiation_token: String,
    /// `modelIdentifier` of the chosen interface: the shared library's file stem.
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
        let fmi_version = root
            .attribute("fmiVersion")
            .ok_or_else(|| err("<fmiModelDescription> has no attribute 'fmiVersion'".into()))?
            .to_string();
        let p = Parser { origin };
        if fmi_version == "3.0" || fmi_version.starts_with("3.0.") {
            p.fmi3(root, fmi_version)
        } else if fmi_version == "2.0" || fmi_version.starts_with("2.0.") {
            p.fmi2(root, fmi_version)
        } else {
            Err(err(format!("fmiVersion is \"{fmi_version}\", only FMI 2.0 and 3.0 are supported here")))
        }
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

/// More event indicators than any model has: a bound so a damaged description cannot make
/// the importer allocate without limit.
const MAX_EVENT_INDICATORS: usize = 1 << 20;

/// The parts both FMI versions share, and one function per version.
struct Parser<'o> {
    origin: &'o str,
}

type Node<'a, 'i> = roxmltree::Node<'a, 'i>;

impl Parser<'_> {
    fn err(&self, message: String) -> ModelDescriptionError {
        ModelDescriptionError { origin: self.origin.to_string(), message }
    }

    fn attr(&self, node: Node, name: &str, what: &str) -> Result<String, ModelDescriptionError> {
        node.attribute(name).map(str::to_string).ok_or_else(|| self.err(format!("{what} has no attribute '{name}'")))
    }

    /// The interface element to use (CoSimulation when present, else ModelExchange) and
    /// its model identifier.
    fn interface<'a, 'i>(
        &self,
        root: Node<'a, 'i>,
    ) -> Result<(Interface, Node<'a, 'i>, String), ModelDescriptionError> {
        let (interface, el) = match (child(root, "CoSimulation"), child(root, "ModelExchange")) {
            (Some(cs), _) => (Interface::CoSimulation, cs),
            (None, Some(me)) => (Interface::ModelExchange, me),
            (None, None) => {
                return Err(self.err(
                    "neither <CoSimulation> nor <ModelExchange>: agrisim imports co-simulation and model-exchange FMUs only"
                        .into(),
                ))
            }
        };
        let tag = el.tag_name().name();
        let id = self.attr(el, "modelIdentifier", &format!("<{tag}>"))?;
        if id.is_empty() || id.contains(['/', '\\']) {
            return Err(self.err(format!("<{tag}> modelIdentifier \"{id}\" is not a valid file stem")));
        }
        Ok((interface, el, id))
    }

    /// A capability flag of an interface element: absent is `default`.
    fn flag(&self, el: Node, name: &str, default: bool) -> Result<bool, ModelDescriptionError> {
        match el.attribute(name) {
            None => Ok(default),
            Some(v) => parse_bool(v)
                .ok_or_else(|| self.err(format!("<{}> {name}=\"{v}\" is not a boolean", el.tag_name().name()))),
        }
    }

    fn log_categories(&self, root: Node) -> Result<Vec<String>, ModelDescriptionError> {
        match child(root, "LogCategories") {
            None => Ok(Vec::new()),
            Some(lc) => lc
                .children()
                .filter(|n| n.is_element() && n.tag_name().name() == "Category")
                .map(|n| self.attr(n, "name", "a <LogCategories> <Category>"))
                .collect(),
        }
    }

    fn default_step_size(&self, root: Node) -> Result<Option<f64>, ModelDescriptionError> {
        match child(root, "DefaultExperiment").and_then(|d| d.attribute("stepSize")) {
            None => Ok(None),
            Some(v) => Ok(Some(
                parse_f64(v)
                    .ok_or_else(|| self.err(format!("<DefaultExperiment> stepSize=\"{v}\" is not a number")))?,
            )),
        }
    }

    fn causality(&self, node: Node, what: &str) -> Result<Causality, ModelDescriptionError> {
        match node.attribute("causality") {
            None => Ok(Causality::Local),
            Some(c) => Causality::parse(c).ok_or_else(|| self.err(format!("{what}: unknown causality \"{c}\""))),
        }
    }

    fn value_reference(&self, node: Node, what: &str) -> Result<u32, ModelDescriptionError> {
        let text = self.attr(node, "valueReference", what)?;
        text.trim()
            .parse()
            .map_err(|_| self.err(format!("{what}: valueReference=\"{text}\" is not an unsigned 32-bit integer")))
    }

    fn dependencies(&self, node: Node, what: &str, key: u32) -> Result<Option<Vec<u32>>, ModelDescriptionError> {
        match node.attribute("dependencies") {
            None => Ok(None),
            Some(text) => text
                .split_whitespace()
                .map(|d| d.parse::<u32>().map_err(|e| self.err(format!("{what} {key}: bad dependency {d:?}: {e}"))))
                .collect::<Result<Vec<u32>, _>>()
                .map(Some),
        }
    }

    fn fmi3(&self, root: Node, fmi_version: String) -> Result<ModelDescription, ModelDescriptionError> {
        let model_name = self.attr(root, "modelName", "<fmiModelDescription>")?;
        let instantiation_token = self.attr(root, "instantiationToken", "<fmiModelDescription>")?;
        let (interface, el, model_identifier) = self.interface(root)?;
        let can_get_and_set_fmu_state = self.flag(el, "canGetAndSetFMUState", false)?;
        let can_serialize_fmu_state = self.flag(el, "canSerializeFMUState", false)?;
        let log_categories = self.log_categories(root)?;
        let default_step_size = self.default_step_size(root)?;

        let mut variables = Vec::new();
        // Derivative vr -> state vr (the `derivative` attribute).
        let mut derivative_of = BTreeMap::new();
        if let Some(mv) = child(root, "ModelVariables") {
            let mut vrs: BTreeMap<u32, String> = BTreeMap::new();
            let mut names = BTreeSet::new();
            for node in mv.children().filter(|n| n.is_element()) {
                let tag = node.tag_name().name();
                let ty = VarType::from_element(tag)
                    .ok_or_else(|| self.err(format!("unknown variable element <{tag}> in <ModelVariables>")))?;
                let name = self.attr(node, "name", &format!("a <{tag}> variable"))?;
                let what = format!("variable '{name}'");
                let value_reference = self.value_reference(node, &what)?;
                let causality = self.causality(node, &what)?;
                let variability = match node.attribute("variability") {
                    // FMI 3.0 default: continuous for Float32/64, discrete otherwise.
                    None if matches!(ty, VarType::Float32 | VarType::Float64) => Variability::Continuous,
                    None => Variability::Discrete,
                    Some(v) => {
                        Variability::parse(v).ok_or_else(|| self.err(format!("{what}: unknown variability \"{v}\"")))?
                    }
                };
                if variability == Variability::Continuous && !matches!(ty, VarType::Float32 | VarType::Float64) {
                    return Err(self.err(format!(
                        "{what}: variability \"continuous\" is only allowed for Float32/Float64, not {ty}"
                    )));
                }
                if let Some(other) = vrs.insert(value_reference, name.clone()) {
                    return Err(
                        self.err(format!("duplicate valueReference {value_reference}: used by '{other}' and '{name}'"))
                    );
                }
                if !names.insert(name.clone()) {
                    return Err(self.err(format!("duplicate variable name '{name}'")));
                }
                if let Some(d) = node.attribute("derivative") {
                    let state: u32 = d
                        .trim()
                        .parse()
                        .map_err(|_| self.err(format!("{what}: derivative=\"{d}\" is not a value reference")))?;
                    derivative_of.insert(value_reference, state);
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
                let unit = if ty == VarType::Float64 { node.attribute("unit").map(str::to_string) } else { None };
                variables.push(ModelVariable {
                    name,
                    value_reference,
                    ty,
                    causality,
                    variability,
                    start,
                    mime_type,
                    description: node.attribute("description").map(str::to_string),
                    unit,
                });
            }
        }
        let mut output_dependencies = BTreeMap::new();
        let mut initial_dependencies = BTreeMap::new();
        let mut states = Vec::new();
        let mut number_of_event_indicators = 0;
        if let Some(ms) = child(root, "ModelStructure") {
            for node in ms.children().filter(|n| n.is_element()) {
                let tag = node.tag_name().name();
                let what = format!("ModelStructure/{tag}");
                let vr = self.value_reference(node, &what)?;
                match tag {
                    "Output" => {
                        output_dependencies.insert(vr, self.dependencies(node, &what, vr)?);
                    }
                    "InitialUnknown" => {
                        initial_dependencies.insert(vr, self.dependencies(node, &what, vr)?);
                    }
                    "ContinuousStateDerivative" => {
                        let state = *derivative_of.get(&vr).ok_or_else(|| {
                            self.err(format!("{what} {vr}: no variable with this valueReference has a 'derivative'"))
                        })?;
                        states.push((state, vr));
                    }
                    "EventIndicator" => number_of_event_indicators += 1,
                    _ => {}
                }
            }
        }
        let model_exchange = match child(root, "ModelExchange") {
            None => None,
            Some(me) => Some(ModelExchangeInfo {
                states,
                number_of_event_indicators,
                needs_completed_integrator_step: self.flag(me, "needsCompletedIntegratorStep", false)?,
            }),
        };
        Ok(ModelDescription {
            fmi_version,
            version: FmiVersion::V3,
            interface,
            model_exchange,
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

    /// FMI 2.0: `<ScalarVariable>` with a typed child; ModelStructure refers to variables by
    /// 1-based index, turned into value references here. Value references are unique per
    /// type only (aliases share one), so a (type, vr) pair may repeat under another name.
    fn fmi2(&self, root: Node, fmi_version: String) -> Result<ModelDescription, ModelDescriptionError> {
        let model_name = self.attr(root, "modelName", "<fmiModelDescription>")?;
        let instantiation_token = self.attr(root, "guid", "<fmiModelDescription>")?;
        let (interface, el, model_identifier) = self.interface(root)?;
        let can_get_and_set_fmu_state = self.flag(el, "canGetAndSetFMUstate", false)?;
        let can_serialize_fmu_state = self.flag(el, "canSerializeFMUstate", false)?;
        let log_categories = self.log_categories(root)?;
        let default_step_size = self.default_step_size(root)?;

        let mut variables = Vec::new();
        // 1-based index of the state whose derivative a Real is (its `derivative` attribute).
        let mut derivative_of: Vec<Option<usize>> = Vec::new();
        if let Some(mv) = child(root, "ModelVariables") {
            let mut names = BTreeSet::new();
            for node in mv.children().filter(|n| n.is_element()) {
                if node.tag_name().name() != "ScalarVariable" {
                    return Err(self.err(format!(
                        "unknown element <{}> in <ModelVariables> (FMI 2.0 has <ScalarVariable> only)",
                        node.tag_name().name()
                    )));
                }
                let name = self.attr(node, "name", "a <ScalarVariable>")?;
                let what = format!("variable '{name}'");
                let value_reference = self.value_reference(node, &what)?;
                let causality = self.causality(node, &what)?;
                if causality == Causality::StructuralParameter {
                    return Err(self.err(format!("{what}: causality \"structuralParameter\" is not FMI 2.0")));
                }
                let typed = node
                    .children()
                    .find(|n| n.is_element())
                    .ok_or_else(|| self.err(format!("{what}: no type element (<Real>, <Integer>, ...)")))?;
                let ty = match typed.tag_name().name() {
                    "Real" => VarType::Float64,
                    "Integer" => VarType::Int32,
                    "Boolean" => VarType::Boolean,
                    "String" => VarType::String,
                    "Enumeration" => VarType::Enumeration,
                    other => return Err(self.err(format!("{what}: unknown FMI 2.0 type element <{other}>"))),
                };
                let variability = match node.attribute("variability") {
                    // FMI 2.0's default is continuous, which only a Real can be.
                    None if ty == VarType::Float64 => Variability::Continuous,
                    None => Variability::Discrete,
                    Some(v) => {
                        Variability::parse(v).ok_or_else(|| self.err(format!("{what}: unknown variability \"{v}\"")))?
                    }
                };
                if variability == Variability::Continuous && ty != VarType::Float64 {
                    return Err(self.err(format!(
                        "{what}: variability \"continuous\" is only allowed for Real, not {}",
                        typed.tag_name().name()
                    )));
                }
                if !names.insert(name.clone()) {
                    return Err(self.err(format!("duplicate variable name '{name}'")));
                }
                derivative_of.push(match typed.attribute("derivative") {
                    None => None,
                    Some(d) => {
                        Some(
                            d.trim().parse::<usize>().ok().filter(|&i| i >= 1).ok_or_else(|| {
                                self.err(format!("{what}: derivative=\"{d}\" is not a variable index"))
                            })?,
                        )
                    }
                });
                let unit = if ty == VarType::Float64 { typed.attribute("unit").map(str::to_string) } else { None };
                variables.push(ModelVariable {
                    name,
                    value_reference,
                    ty,
                    causality,
                    variability,
                    start: typed.attribute("start").map(str::to_string),
                    mime_type: None,
                    description: node.attribute("description").map(str::to_string),
                    unit,
                });
            }
        }
        let vr_of = |index: u32, what: &str| -> Result<u32, ModelDescriptionError> {
            let i = index as usize;
            if i == 0 || i > variables.len() {
                return Err(self.err(format!(
                    "{what}: index {index} is not a variable (1..{} in <ModelVariables>)",
                    variables.len()
                )));
            }
            Ok(variables[i - 1].value_reference)
        };
        let mut output_dependencies = BTreeMap::new();
        let mut initial_dependencies = BTreeMap::new();
        let mut states = Vec::new();
        if let Some(ms) = child(root, "ModelStructure") {
            for section in ms.children().filter(|n| n.is_element()) {
                let tag = section.tag_name().name();
                for node in section.children().filter(|n| n.is_element() && n.tag_name().name() == "Unknown") {
                    let what = format!("ModelStructure/{tag}/Unknown");
                    let index: u32 = self
                        .attr(node, "index", &what)?
                        .trim()
                        .parse()
                        .map_err(|e| self.err(format!("{what}: bad index: {e}")))?;
                    let vr = vr_of(index, &what)?;
                    let deps = match self.dependencies(node, &what, index)? {
                        None => None,
                        Some(d) => Some(d.into_iter().map(|i| vr_of(i, &what)).collect::<Result<Vec<u32>, _>>()?),
                    };
                    match tag {
                        "Outputs" => {
                            output_dependencies.insert(vr, deps);
                        }
                        "InitialUnknowns" => {
                            initial_dependencies.insert(vr, deps);
                        }
                        "Derivatives" => {
                            let state = derivative_of[index as usize - 1].ok_or_else(|| {
                                self.err(format!("{what}: variable {index} has no 'derivative' attribute"))
                            })?;
                            states.push((vr_of(state as u32, &what)?, vr));
                        }
                        _ => {}
                    }
                }
            }
        }
        let model_exchange = match child(root, "ModelExchange") {
            None => None,
            Some(me) => {
                let n = root.attribute("numberOfEventIndicators").unwrap_or("0");
                Some(ModelExchangeInfo {
                    states,
                    number_of_event_indicators: n
                        .trim()
                        .parse()
                        .ok()
                        .filter(|&k: &usize| k <= MAX_EVENT_INDICATORS)
                        .ok_or_else(|| {
                            self.err(format!(
                                "numberOfEventIndicators=\"{n}\" is not an integer in 0..={MAX_EVENT_INDICATORS}"
                            ))
                        })?,
                    needs_completed_integrator_step: !self.flag(me, "completedIntegratorStepNotNeeded", false)?,
                })
            }
        };
        Ok(ModelDescription {
            fmi_version,
            version: FmiVersion::V2,
            interface,
            model_exchange,
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
