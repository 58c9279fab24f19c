//! Parameter bindings: `ssd:ParameterBinding` with inline `ssd:ParameterValues` or an `.ssv`
//! file (`source`), an optional `prefix`, and an optional `ssd:ParameterMapping` (inline or an
//! `.ssm` file) that renames entries and may transform their values.
//!
//! Precedence follows SSP 1.0: within one element a later binding wins over an earlier one
//! (and within one parameter set a later entry over an earlier one), and the system's own
//! bindings (hierarchical names `component.parameter`) win over the component's. Scenario
//! overrides ([`crate::System::apply_parameters`]) come after all of them.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use roxmltree::Node;

use super::transform::Transformation;
use super::units::{parse_units, Affine, Unit};
use super::{child, elements, parse_param_value, req, ParamValue, NS_SSD, NS_SSM, NS_SSV};
use crate::model_description::parse_bool;

/// The only binding type SSP 1.0 defines.
const PARAMETER_SET_TYPE: &str = "application/x-ssp-parameter-set";
const PARAMETER_MAPPING_TYPE: &str = "application/x-ssp-parameter-mapping";

/// A Real parameter value given in a unit (`ssv:Real unit=`): converted to the FMU variable's
/// unit when the FMUs are known ([`super::convert_parameter_units`]), then `then` applied (a
/// mapping's `ssc:LinearTransformation` works on the converted value, as SSP orders it).
#[derive(Clone, Debug, PartialEq)]
pub struct ParamUnit {
    pub unit: Unit,
    pub then: Affine,
    /// The file or element that gave the value, for errors.
    pub origin: String,
}

/// One bound value after prefix and name mapping.
#[derive(Clone, Debug, PartialEq)]
pub struct Binding {
    pub name: String,
    pub value: ParamValue,
    pub unit: Option<ParamUnit>,
}

/// Where relative `source` URIs point and which units the .ssd defines.
pub(super) struct Context<'a> {
    pub dir: &'a Path,
    pub ssd_units: &'a BTreeMap<String, Unit>,
}

impl Context<'_> {
    /// A `source` relative to the .ssd (inside an unpacked .ssp: `resources/x.ssv`).
    fn resolve(&self, source: &str, what: &str) -> Result<PathBuf, String> {
        let s = source.strip_prefix("file://").or_else(|| source.strip_prefix("file:")).unwrap_or(source);
        if s.contains("://") {
            return Err(format!("{what}: source \"{source}\" is not a file beside the .ssd"));
        }
        Ok(self.dir.join(s))
    }

    fn read(&self, source: &str, what: &str) -> Result<(String, String), String> {
        let path = self.resolve(source, what)?;
        let text =
            std::fs::read_to_string(&path).map_err(|e| format!("{what}: cannot read {}: {e}", path.display()))?;
        Ok((text, path.display().to_string()))
    }
}

/// Every value of an `ssd:ParameterBindings` element, in precedence order (later wins).
pub(super) fn read_bindings(bindings: Node, ctx: &Context, what: &str) -> Result<Vec<Binding>, String> {
    let mut out = Vec::new();
    for pb in elements(bindings, NS_SSD, "ParameterBinding") {
        if let Some(t) = pb.attribute("type").filter(|t| *t != PARAMETER_SET_TYPE) {
            return Err(format!(
                "{what}: ssd:ParameterBinding type \"{t}\" is not supported (only {PARAMETER_SET_TYPE})"
            ));
        }
        if pb.attribute("sourceBase") == Some("component") {
            return Err(format!("{what}: ssd:ParameterBinding sourceBase=\"component\" is not supported"));
        }
        let prefix = pb.attribute("prefix").unwrap_or("");
        let inline = child(pb, NS_SSD, "ParameterValues");
        let values = match (pb.attribute("source"), inline) {
            (Some(src), Some(_)) => {
                return Err(format!("{what}: ssd:ParameterBinding has both source \"{src}\" and inline values"))
            }
            (Some(src), None) => {
                let (text, origin) = ctx.read(src, what)?;
                let doc =
                    roxmltree::Document::parse(&text).map_err(|e| format!("{origin}: not well-formed XML: {e}"))?;
                let set = doc.root_element();
                if !super::is(set, NS_SSV, "ParameterSet") {
                    return Err(format!(
                        "{origin}: root element is <{}>, expected ssv:ParameterSet",
                        set.tag_name().name()
                    ));
                }
                parse_parameter_set(set, &origin, ctx)?
            }
            (None, Some(v)) => {
                let mut all = Vec::new();
                for set in elements(v, NS_SSV, "ParameterSet") {
                    all.extend(parse_parameter_set(set, what, ctx)?);
                }
                all
            }
            (None, None) => continue,
        };
        let mapping = match child(pb, NS_SSD, "ParameterMapping") {
            None => BTreeMap::new(),
            Some(m) => read_mapping(m, ctx, what)?,
        };
        for (name, value, unit) in values {
            let full = format!("{prefix}{name}");
            out.push(match mapping.get(&full) {
                None => Binding { name: full, value, unit },
                Some(entry) => {
                    entry.apply(value, unit).map_err(|e| format!("{}: parameter '{full}': {e}", entry.origin))?
                }
            });
        }
    }
    Ok(out)
}

/// The parameters of one `ssv:ParameterSet`, with the unit each Real value is given in
/// (looked up in the set's own `ssv:Units`, then the .ssd's; a unit defined in neither is kept
/// by name and converts only to a unit of the same name).
fn parse_parameter_set(
    set: Node,
    origin: &str,
    ctx: &Context,
) -> Result<Vec<(String, ParamValue, Option<ParamUnit>)>, String> {
    let own_units = match child(set, NS_SSV, "Units") {
        Some(u) => parse_units(u, origin)?,
        None => BTreeMap::new(),
    };
    if child(set, NS_SSV, "Enumerations").is_some() {
        return Err(format!("{origin}: ssv:Enumerations are not supported"));
    }
    let mut out = Vec::new();
    let Some(params) = child(set, NS_SSV, "Parameters") else { return Ok(out) };
    for p in elements(params, NS_SSV, "Parameter") {
        let name = req(p, "name", &format!("an ssv:Parameter of {origin}"))?;
        let what = format!("{origin}, parameter '{name}'");
        let value = parse_param_value(p, &what)?;
        let unit =
            match (&value, p.children().find(|n| super::is(*n, NS_SSV, "Real")).and_then(|r| r.attribute("unit"))) {
                (ParamValue::Real(_), Some(u)) => {
                    let unit = own_units
                        .get(u)
                        .or_else(|| ctx.ssd_units.get(u))
                        .cloned()
                        .unwrap_or_else(|| Unit { name: u.to_string(), base: None });
                    Some(ParamUnit { unit, then: Affine::IDENTITY, origin: origin.to_string() })
                }
                _ => None,
            };
        out.push((name, value, unit));
    }
    Ok(out)
}

/// One `ssm:MappingEntry`.
struct MappingEntry {
    target: String,
    transformation: Option<Transformation>,
    suppress_unit_conversion: bool,
    origin: String,
}

impl MappingEntry {
    /// The binding of `value` under this entry: renamed, transformed (a Real value with a
    /// unit keeps a linear transformation for after the unit conversion).
    fn apply(&self, value: ParamValue, unit: Option<ParamUnit>) -> Result<Binding, String> {
        let unit = if self.suppress_unit_conversion { None } else { unit };
        let wrong =
            |t: &Transformation| format!("{} applies only to {} values, not {value:?}", t.element(), t.applies_to());
        let (value, unit) = match (&self.transformation, value.clone(), unit) {
            (None, v, u) => (v, u),
            (Some(Transformation::Linear(a)), ParamValue::Real(x), None) => (ParamValue::Real(a.apply(x)), None),
            (Some(Transformation::Linear(a)), ParamValue::Real(x), Some(u)) => {
                (ParamValue::Real(x), Some(ParamUnit { then: u.then.then(*a), ..u }))
            }
            (Some(t @ Transformation::Boolean(m)), ParamValue::Boolean(b), u) => {
                (ParamValue::Boolean(*m.get(&b).ok_or_else(|| format!("{}: value {b} has no entry", t.element()))?), u)
            }
            (Some(t @ Transformation::Integer(m)), ParamValue::Integer(i), u) => {
                (ParamValue::Integer(*m.get(&i).ok_or_else(|| format!("{}: value {i} has no entry", t.element()))?), u)
            }
            (Some(t), _, _) => return Err(wrong(t)),
        };
        Ok(Binding { name: self.target.clone(), value, unit })
    }
}

/// An `ssd:ParameterMapping`: inline `ssm:ParameterMapping` or an `.ssm` file, by source name.
fn read_mapping(m: Node, ctx: &Context, what: &str) -> Result<BTreeMap<String, MappingEntry>, String> {
    if let Some(t) = m.attribute("type").filter(|t| *t != PARAMETER_MAPPING_TYPE) {
        return Err(format!(
            "{what}: ssd:ParameterMapping type \"{t}\" is not supported (only {PARAMETER_MAPPING_TYPE})"
        ));
    }
    if m.attribute("sourceBase") == Some("component") {
        return Err(format!("{what}: ssd:ParameterMapping sourceBase=\"component\" is not supported"));
    }
    let inline = child(m, NS_SSM, "ParameterMapping");
    match (m.attribute("source"), inline) {
        (Some(src), Some(_)) => {
            Err(format!("{what}: ssd:ParameterMapping has both source \"{src}\" and inline content"))
        }
        (Some(src), None) => {
            let (text, origin) = ctx.read(src, what)?;
            let doc = roxmltree::Document::parse(&text).map_err(|e| format!("{origin}: not well-formed XML: {e}"))?;
            let root = doc.root_element();
            if !super::is(root, NS_SSM, "ParameterMapping") {
                return Err(format!(
                    "{origin}: root element is <{}>, expected ssm:ParameterMapping",
                    root.tag_name().name()
                ));
            }
            parse_mapping(root, &origin)
        }
        (None, Some(inline)) => parse_mapping(inline, what),
        (None, None) => {
            Err(format!("{what}: ssd:ParameterMapping has neither a source nor an inline ssm:ParameterMapping"))
        }
    }
}

fn parse_mapping(root: Node, origin: &str) -> Result<BTreeMap<String, MappingEntry>, String> {
    let mut out = BTreeMap::new();
    for e in elements(root, NS_SSM, "MappingEntry") {
        let source = req(e, "source", &format!("an ssm:MappingEntry of {origin}"))?;
        let what = format!("{origin}, mapping entry '{source}'");
        let target = req(e, "target", &what)?;
        let suppress = match e.attribute("suppressUnitConversion") {
            None => false,
            Some(v) => {
                parse_bool(v).ok_or_else(|| format!("{what}: suppressUnitConversion=\"{v}\" is not a boolean"))?
            }
        };
        let transformation = Transformation::parse_child(e, &what)?;
        if let Some(t @ Transformation::Enumeration(_)) = &transformation {
            return Err(format!("{what}: {} is not supported (agrisim has no enumerations)", t.element()));
        }
        let entry =
            MappingEntry { target, transformation, suppress_unit_conversion: suppress, origin: origin.to_string() };
        if out.insert(source.clone(), entry).is_some() {
            return Err(format!("{origin}: source '{source}' is mapped twice"));
        }
    }
    Ok(out)
}
