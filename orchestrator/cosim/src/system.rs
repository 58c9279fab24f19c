//! A composed system: the FMU instances of an SSP system structure and the routes that move
//! values between them and the message bus.
//!
//! Message ports are FMI 3 Binary variables named `X` with an Int64 counter `X_seq`: a
//! framed port ([`agrisim_frames`]) holds every message of the FMU's last `port_window`, a
//! plain one the newest message. A route takes each message once (by sequence number) and
//! numbers on the messages it writes to an input, so every consumer sees each message
//! exactly once.

use crate::archive::FmuArchive;
use crate::error::{Context, Result};
use crate::fmu::FmuInstance;
use crate::model_description::{Causality, FmiVersion, Interface, ModelDescription, ModelVariable, VarType};
use crate::seed::component_seed;
use crate::ssp::{self, SystemStructure};
use crate::value::{self, Value};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Where to find FMUs and how to time the exchange.
#[derive(Clone, Debug)]
pub struct LoadOptions {
    /// Directory `agrisim fmu pack` wrote the .fmu files to.
    pub fmu_dir: PathBuf,
    /// Where .fmu archives are unpacked.
    pub cache_dir: PathBuf,
    /// Component -> FMU file, replacing the system file's `source`.
    pub fmu_overrides: BTreeMap<String, String>,
    pub step: f64,
    /// Period of message connections without their own \[s\].
    pub message_period: f64,
    /// FMU debug logging (FMI `loggingOn`, then `fmi3SetDebugLogging`): `None` off, the
    /// default (the FMUs report only warnings and errors, which always reach the user: in a
    /// call's error, else on stderr); `Some(vec![])` every category; `Some(list)` those
    /// categories, each FMU getting the ones it declares. Debug messages go to stderr.
    pub fmu_log: Option<Vec<String>>,
}

impl LoadOptions {
    /// FMUs from `fmu_dir`, unpacked to `cache_dir`, no overrides.
    pub fn new(
        fmu_dir: impl Into<PathBuf>,
        cache_dir: impl Into<PathBuf>,
        step: f64,
        message_period: f64,
    ) -> LoadOptions {
        LoadOptions {
            fmu_dir: fmu_dir.into(),
            cache_dir: cache_dir.into(),
            fmu_overrides: BTreeMap::new(),
            step,
            message_period,
            fmu_log: None,
        }
    }
}

pub struct Component {
    pub name: String,
    pub archive: FmuArchive,
    /// FMI 3 or FMI 2; co-simulation, or model exchange under the master's integrator.
    pub instance: Box<dyn FmuInstance>,
    /// Scalar inputs and outputs, recorded every step.
    pub signals: Vec<ModelVariable>,
    /// [`Component::signals`] grouped by type: (type, their indices, their value references),
    /// built once so reading them every step allocates nothing but the values.
    signal_groups: Vec<(VarType, Vec<usize>, Vec<u32>)>,
}

impl Component {
    pub fn new(name: String, archive: FmuArchive, instance: Box<dyn FmuInstance>) -> Component {
        let signals: Vec<ModelVariable> = archive
            .md
            .variables
            .iter()
            .filter(|v| matches!(v.causality, Causality::Input | Causality::Output))
            .filter(|v| matches!(v.ty, VarType::Float64 | VarType::Int32 | VarType::Int64 | VarType::Boolean))
            .cloned()
            .collect();
        let signal_groups = [VarType::Float64, VarType::Int32, VarType::Int64, VarType::Boolean]
            .into_iter()
            .map(|ty| {
                let idx: Vec<usize> = (0..signals.len()).filter(|&i| signals[i].ty == ty).collect();
                let vrs = idx.iter().map(|&i| signals[i].value_reference).collect();
                (ty, idx, vrs)
            })
            .filter(|(_, idx, _)| !idx.is_empty())
            .collect();
        Component { name, archive, instance, signals, signal_groups }
    }

    /// Current values of all [`Component::signals`], in their order, read with one call per
    /// type (the recorder does this every step, so FFI round trips matter).
    pub fn read_signals(&mut self, out: &mut Vec<f64>) -> Result<()> {
        out.clear();
        out.resize(self.signals.len(), 0.0);
        for (ty, idx, vrs) in &self.signal_groups {
            match ty {
                VarType::Float64 => {
                    let mut v = vec![0.0; vrs.len()];
                    self.instance.get_f64(vrs, &mut v)?;
                    idx.iter().zip(v).for_each(|(&i, x)| out[i] = x);
                }
                VarType::Int32 => {
                    let mut v = vec![0; vrs.len()];
                    self.instance.get_i32(vrs, &mut v)?;
                    idx.iter().zip(v).for_each(|(&i, x)| out[i] = x as f64);
                }
                VarType::Int64 => {
                    let mut v = vec![0; vrs.len()];
                    self.instance.get_i64(vrs, &mut v)?;
                    idx.iter().zip(v).for_each(|(&i, x)| out[i] = x as f64);
                }
                _ => {
                    let mut v = vec![false; vrs.len()];
                    self.instance.get_bool(vrs, &mut v)?;
                    idx.iter().zip(v).for_each(|(&i, x)| out[i] = x as u8 as f64);
                }
            }
        }
        Ok(())
    }
}

/// One end of a route.
#[derive(Clone, Debug)]
#[allow(clippy::large_enum_variant, reason = "built once per connection, never on a hot path")]
pub enum Port {
    /// A variable of component `comp`; `seq` is the counter of a message port.
    Fmu { comp: usize, var: ModelVariable, seq: Option<ModelVariable> },
    /// A system connector: a topic (messages) or a named scalar on the bus.
    Bus { topic: String },
}

#[derive(Clone, Debug)]
pub struct Route {
    /// `chassis.odom -> /odom`, for errors and the timing check.
    pub label: String,
    pub from: Port,
    pub to: Port,
    /// Exchange every this many master steps.
    pub period_ticks: u64,
    /// mimeType of a message route's Binary port (the message layer reads the message type
    /// from it); None for scalar routes.
    pub mime_type: Option<String>,
    /// Topic a message route is recorded on.
    pub topic: String,
    /// An FMU source's message port: the last message taken.
    pub cursor: agrisim_frames::Cursor,
    /// The source / destination message port carries frame lists ([`agrisim_frames`]);
    /// otherwise one message at a time.
    pub framed_from: bool,
    pub framed_to: bool,
    /// Messages written to a message input (its counter).
    pub written: i64,
    /// What the route does to a scalar value on its way (SSP unit conversion and
    /// transformation); `None` passes it unchanged.
    pub transfer: Option<ssp::Transfer>,
}

impl Route {
    /// The value this route delivers for source value `v`.
    pub fn transfer_value(&self, v: Value) -> Result<Value> {
        match &self.transfer {
            None => Ok(v),
            Some(t) => t.apply(v).map_err(|e| crate::err!("connection {}: {e}", self.label)),
        }
    }
}

pub struct System {
    pub structure: SystemStructure,
    pub components: Vec<Component>,
    pub routes: Vec<Route>,
}

/// `x` is a whole multiple of `step` (to 1 ns): the number of steps.
pub fn ticks_of(x: f64, step: f64, what: &str) -> Result<u64> {
    let n = (x / step).round();
    if !(n >= 1.0) || ((n * step - x).abs() > 1e-9) {
        return Err(crate::err!("{what}: period {x} s is not a whole multiple of the step {step} s"));
    }
    Ok(n as u64)
}

fn port_label(e: &ssp::Endpoint) -> String {
    match &e.element {
        Some(c) => format!("{c}.{}", e.connector),
        None => e.connector.clone(),
    }
}

/// Every category of a `fmu_log` list must be declared by some FMU of the system (a typo
/// must not silently log nothing), unless some FMU declares no categories at all.
fn check_log_categories(categories: &[String], mds: &BTreeMap<String, ModelDescription>, ssd: &Path) -> Result<()> {
    if mds.values().any(|md| md.log_categories.is_empty()) {
        return Ok(());
    }
    for c in categories {
        if !mds.values().any(|md| md.log_categories.contains(c)) {
            let mut known: Vec<&str> =
                mds.values().flat_map(|md| md.log_categories.iter().map(String::as_str)).collect();
            known.sort_unstable();
            known.dedup();
            return Err(crate::err!(
                "FMU log category '{c}': no FMU of {} declares it (they declare: {})",
                ssd.display(),
                known.join(", ")
            ));
        }
    }
    Ok(())
}

/// Instantiates an archive as its description says: FMI 3 or FMI 2, co-simulation when
/// the FMU offers it, else model exchange under the master's RK4 ([`crate::me`]).
pub fn instantiate_archive(archive: &FmuArchive, name: &str, logging_on: bool) -> Result<Box<dyn FmuInstance>> {
    let md = &archive.md;
    let me_info = || {
        md.model_exchange.as_ref().ok_or_else(|| crate::err!("FMU '{name}': model exchange without its description"))
    };
    Ok(match (md.version, md.interface) {
        (FmiVersion::V3, Interface::CoSimulation) => {
            Box::new(crate::fmi3::Instance::instantiate(archive, name, logging_on)?)
        }
        (FmiVersion::V2, Interface::CoSimulation) => {
            Box::new(crate::fmi2::Instance::instantiate(archive, name, Interface::CoSimulation, logging_on)?)
        }
        (FmiVersion::V2, Interface::ModelExchange) => {
            let inner = crate::fmi2::Instance::instantiate(archive, name, Interface::ModelExchange, logging_on)?;
            Box::new(crate::me::Integrated::new(inner, me_info()?))
        }
        (FmiVersion::V3, Interface::ModelExchange) => {
            let inner = crate::fmi3::Instance::instantiate_model_exchange(archive, name, logging_on)?;
            Box::new(crate::me::Integrated::new(inner, me_info()?))
        }
    })
}

/// Instantiates component `name` with debug logging as `fmu_log` asks (see
/// [`LoadOptions::fmu_log`]): of a category list, the FMU gets those it declares (all of them
/// when it declares none); with none of them, debug logging stays off.
fn instantiate(archive: &FmuArchive, name: &str, fmu_log: Option<&[String]>) -> Result<Box<dyn FmuInstance>> {
    let Some(categories) = fmu_log else { return instantiate_archive(archive, name, false) };
    if categories.is_empty() {
        return instantiate_archive(archive, name, true);
    }
    let declared = &archive.md.log_categories;
    let mine: Vec<&str> = categories
        .iter()
        .map(String::as_str)
        .filter(|c| declared.is_empty() || declared.iter().any(|d| d == c))
        .collect();
    let mut instance = instantiate_archive(archive, name, false)?;
    if !mine.is_empty() {
        instance.set_debug_logging(true, &mine)?;
    }
    Ok(instance)
}

/// The units of an opened FMU's variables, from its unpacked modelDescription.xml (FMI 2 or 3).
fn read_fmu_units(a: &FmuArchive) -> Result<BTreeMap<String, ssp::Unit>> {
    let path = a.dir.join("modelDescription.xml");
    let xml = std::fs::read_to_string(&path).map_err(|e| crate::err!("cannot read {}: {e}", path.display()))?;
    let origin = format!("{}!modelDescription.xml", a.path.display());
    ssp::units::fmu_variable_units(&xml, &origin).map_err(|e| crate::err!("{e}"))
}

impl System {
    /// Reads the system file, opens every FMU, checks the wiring and instantiates.
    /// `ssd` is a SystemStructure.ssd or a self-contained `.ssp` archive (unpacked to the
    /// cache; its components' sources are inside it, under resources/).
    pub fn load(ssd: &Path, opts: &LoadOptions) -> Result<System> {
        let unpacked;
        let ssd = if ssd.extension().is_some_and(|e| e.eq_ignore_ascii_case("ssp")) {
            unpacked = crate::archive::unpack(ssd, &opts.cache_dir)?.join("SystemStructure.ssd");
            if !unpacked.is_file() {
                return Err(crate::err!("{}: no SystemStructure.ssd at the archive root", ssd.display()));
            }
            unpacked.as_path()
        } else {
            ssd
        };
        let mut structure = SystemStructure::from_file(ssd)?;
        for (comp, fmu) in &opts.fmu_overrides {
            let c = structure
                .components
                .iter_mut()
                .find(|c| &c.name == comp)
                .ok_or_else(|| crate::err!("FMU override for '{comp}': no such component in {}", ssd.display()))?;
            c.source = fmu.clone();
        }
        let mut archives = BTreeMap::new();
        let mut mds = BTreeMap::new();
        let mut fmu_units = ssp::FmuUnits::new();
        for c in &structure.components {
            let path = ssp::resolve_source(ssd, &c.source, &opts.fmu_dir);
            let a = FmuArchive::open(&path, &opts.cache_dir)
                .context(|| format!("component '{}' of {}", c.name, ssd.display()))?;
            mds.insert(c.name.clone(), a.md.clone());
            fmu_units.insert(c.name.clone(), read_fmu_units(&a)?);
            archives.insert(c.name.clone(), a);
        }
        let transfers = ssp::plan_transfers(&structure, &mds, &fmu_units)?;
        ssp::convert_parameter_units(&mut structure, &fmu_units)?;
        if let Some(categories) = &opts.fmu_log {
            check_log_categories(categories, &mds, ssd)?;
        }
        let mut components = vec![];
        for c in &structure.components {
            let archive = archives.remove(&c.name).expect("opened above");
            let instance = instantiate(&archive, &c.name, opts.fmu_log.as_deref())?;
            components.push(Component::new(c.name.clone(), archive, instance));
        }
        let mut sys = System { structure, components, routes: vec![] };
        sys.routes = sys.build_routes(opts)?;
        // build_routes makes one route per connection, in order.
        for (route, t) in sys.routes.iter_mut().zip(transfers) {
            route.transfer = t;
        }
        Ok(sys)
    }

    /// A system connector's name outside the engine (its topic annotation, else its name).
    fn external_name(&self, connector: &str) -> String {
        self.structure.system_connector(connector).map_or(connector, |c| c.external_name()).to_string()
    }

    pub fn component_index(&self, name: &str) -> Option<usize> {
        self.components.iter().position(|c| c.name == name)
    }

    fn port(&self, e: &ssp::Endpoint) -> Result<Port> {
        let Some(comp_name) = &e.element else { return Ok(Port::Bus { topic: self.external_name(&e.connector) }) };
        let comp = self.component_index(comp_name).ok_or_else(|| crate::err!("no component '{comp_name}'"))?;
        let md = &self.components[comp].archive.md;
        let var = md
            .variable(&e.connector)
            .ok_or_else(|| crate::err!("FMU '{comp_name}' ({}) has no variable '{}'", md.model_name, e.connector))?
            .clone();
        if !value::supported(var.ty) {
            return Err(crate::err!(
                "FMU '{comp_name}': variable '{}' has type {}, which agrisim cannot exchange",
                var.name,
                var.ty.name()
            ));
        }
        let seq = if var.ty == VarType::Binary {
            let name = format!("{}_seq", var.name);
            let s = md.variable(&name).filter(|s| s.ty == VarType::Int64).ok_or_else(|| {
                crate::err!("FMU '{comp_name}': message port '{}' has no Int64 counter '{name}'", var.name)
            })?;
            Some(s.clone())
        } else {
            None
        };
        Ok(Port::Fmu { comp, var, seq })
    }

    fn build_routes(&self, opts: &LoadOptions) -> Result<Vec<Route>> {
        let file = self.structure.path.display().to_string();
        let mut routes = vec![];
        for c in &self.structure.connections {
            let label = format!("{} -> {}", port_label(&c.start), port_label(&c.end));
            let ctx = |e: crate::error::Error| crate::err!("{file}: connection {label}: {e}");
            let from = self.port(&c.start).map_err(ctx)?;
            let to = self.port(&c.end).map_err(ctx)?;
            let mime = [&from, &to].iter().find_map(|p| match p {
                Port::Fmu { var, .. } if var.ty == VarType::Binary => Some(var.mime_type.clone().unwrap_or_default()),
                _ => None,
            });
            let is_message = mime.is_some();
            let period = c.period.unwrap_or(if is_message { opts.message_period } else { opts.step });
            let period_ticks = ticks_of(period, opts.step, &format!("{file}: connection {label}"))?;
            let topic = match (&c.start.element, &c.end.element) {
                (None, _) => self.external_name(&c.start.connector),
                (_, None) => self.external_name(&c.end.connector),
                (Some(e), Some(_)) => format!("/{e}/{}", c.start.connector),
            };
            let framed = |p: &Port| matches!(p, Port::Fmu { var, .. } if var.mime_type.as_deref().is_some_and(agrisim_frames::is_framed_mime));
            let (framed_from, framed_to) = (framed(&from), framed(&to));
            routes.push(Route {
                label,
                from,
                to,
                period_ticks,
                mime_type: mime,
                topic,
                cursor: Default::default(),
                framed_from,
                framed_to,
                written: 0,
                transfer: None,
            });
        }
        Ok(routes)
    }

    /// Applies parameters: the system file's bindings, then `overrides`, and a `seed`
    /// derived from the master seed for every component that has one (an Int32 parameter
    /// `seed`), and each of `shared` (name -> text) to every component with a settable
    /// String parameter of that name (e.g. one scene description for all FMUs that build
    /// the scene), unless overridden. Returns what was set, per component, for a run's
    /// metadata.
    pub fn apply_parameters(
        &mut self,
        overrides: &BTreeMap<String, BTreeMap<String, toml::Value>>,
        master_seed: u64,
        shared: &BTreeMap<String, String>,
    ) -> Result<BTreeMap<String, BTreeMap<String, String>>> {
        for name in overrides.keys() {
            if self.component_index(name).is_none() {
                return Err(crate::err!(
                    "scenario parameters for '{name}': no such component in {}",
                    self.structure.path.display()
                ));
            }
        }
        let mut applied = BTreeMap::new();
        for i in 0..self.components.len() {
            let mut set: BTreeMap<String, Value> = BTreeMap::new();
            let comp = &self.structure.components[i];
            let md = self.components[i].archive.md.clone();
            let param = |name: &str| -> Result<ModelVariable> {
                md.settable_parameter(name)
                    .cloned()
                    .ok_or_else(|| crate::err!("FMU '{}' ({}) has no parameter '{name}'", comp.name, md.model_name))
            };
            if md.settable_parameter("seed").is_some_and(|v| v.ty == VarType::Int32) {
                set.insert("seed".into(), Value::I32(component_seed(master_seed, &comp.name)));
            }
            for (name, text) in shared {
                if md.settable_parameter(name).is_some_and(|v| v.ty == VarType::String) {
                    set.insert(name.clone(), Value::Str(text.clone()));
                }
            }
            for (name, v) in &comp.parameters {
                let var = param(name)?;
                let val = v.to_value(&var).ok_or_else(|| {
                    crate::err!(
                        "{}: parameter {}.{name}: value {v:?} does not fit type {}",
                        self.structure.path.display(),
                        comp.name,
                        var.ty.name()
                    )
                })?;
                set.insert(name.clone(), val);
            }
            for (name, v) in overrides.get(&comp.name).into_iter().flatten() {
                let var = param(name)?;
                let val = value::from_toml(&var, v)
                    .map_err(|e| crate::err!("scenario parameter {}.{name}: {e}", comp.name))?;
                set.insert(name.clone(), val);
            }
            let mut texts = BTreeMap::new();
            let name_of_comp = comp.name.clone();
            for (name, val) in &set {
                let var = param(name)?;
                value::set(self.components[i].instance.as_mut(), &var, val)?;
                texts.insert(name.clone(), val.to_text());
            }
            applied.insert(name_of_comp, texts);
        }
        Ok(applied)
    }

    /// A numeric variable of component `comp` by name, as f64 (Float64, Int32, Int64,
    /// Boolean): how a benchmark reads ground-truth outputs.
    pub fn number(&mut self, comp: usize, name: &str) -> Result<f64> {
        let c = &mut self.components[comp];
        let v = c
            .archive
            .md
            .variable(name)
            .cloned()
            .ok_or_else(|| crate::err!("FMU '{}' has no variable '{name}'", c.name))?;
        match value::get(c.instance.as_mut(), &v)? {
            Value::F64(x) => Ok(x),
            Value::Bool(b) => Ok(b as u8 as f64),
            Value::I32(i) => Ok(i as f64),
            Value::I64(i) => Ok(i as f64),
            other => Err(crate::err!("FMU '{}': {name} is {other:?}, expected a number", c.name)),
        }
    }
}
