//! Physical units as SSP (`ssc:Unit`) and FMI (`<UnitDefinitions>`) define them: exponents of
//! the SI base units plus an affine map to them (`value_in_base = factor * value + offset`).
//! Two units convert into each other only when their exponents agree, so a connection from
//! a length into a time fails at load time instead of moving a meaningless number.

use std::collections::BTreeMap;
use std::fmt;

use roxmltree::Node;

use crate::model_description::parse_f64;

/// The base units, in the order of [`BaseUnit::exponents`] (the attribute names of
/// `ssc:BaseUnit` and FMI's `<BaseUnit>`).
pub const BASE_UNITS: [&str; 8] = ["kg", "m", "s", "A", "K", "mol", "cd", "rad"];

/// `value_in_base = factor * value + offset`, with the exponents of [`BASE_UNITS`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BaseUnit {
    pub exponents: [i32; 8],
    pub factor: f64,
    pub offset: f64,
}

/// A named unit; `base: None` when the definition gives no `BaseUnit` (FMI allows that: the
/// unit then converts to nothing but itself).
#[derive(Clone, Debug, PartialEq)]
pub struct Unit {
    pub name: String,
    pub base: Option<BaseUnit>,
}

/// `y = factor * x + offset`: a unit conversion, a `ssc:LinearTransformation`, or both composed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Affine {
    pub factor: f64,
    pub offset: f64,
}

impl Affine {
    pub const IDENTITY: Affine = Affine { factor: 1.0, offset: 0.0 };

    pub fn apply(self, x: f64) -> f64 {
        self.factor * x + self.offset
    }

    /// `self` first, then `next`.
    pub fn then(self, next: Affine) -> Affine {
        Affine { factor: next.factor * self.factor, offset: next.factor * self.offset + next.offset }
    }

    pub fn is_identity(self) -> bool {
        self == Affine::IDENTITY
    }
}

impl BaseUnit {
    /// The exponents in words, e.g. `m.s-1` (`1` for a dimensionless unit).
    pub fn dimension(&self) -> String {
        let parts: Vec<String> = BASE_UNITS
            .iter()
            .zip(self.exponents)
            .filter(|(_, e)| *e != 0)
            .map(|(n, e)| if e == 1 { n.to_string() } else { format!("{n}{e}") })
            .collect();
        if parts.is_empty() {
            "1".into()
        } else {
            parts.join(".")
        }
    }
}

impl fmt::Display for Unit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.base {
            Some(b) => write!(f, "{} ({})", self.name, b.dimension()),
            None => write!(f, "{} (no base unit)", self.name),
        }
    }
}

impl Unit {
    /// An `ssc:Unit` or FMI `<Unit>` element (namespaces are not checked: both files give the
    /// same attributes). `what` names the file or element in errors.
    pub fn parse(node: Node, what: &str) -> Result<Unit, String> {
        let name = node.attribute("name").ok_or_else(|| format!("{what}: a unit has no attribute 'name'"))?.to_string();
        let Some(b) = node.children().find(|n| n.is_element() && n.tag_name().name() == "BaseUnit") else {
            return Ok(Unit { name, base: None });
        };
        let mut exponents = [0; 8];
        for (i, attr) in BASE_UNITS.iter().enumerate() {
            if let Some(v) = b.attribute(*attr) {
                exponents[i] =
                    v.trim().parse().map_err(|_| format!("{what}: unit '{name}': {attr}=\"{v}\" is not an integer"))?;
            }
        }
        let num = |attr: &str, default: f64| -> Result<f64, String> {
            match b.attribute(attr) {
                None => Ok(default),
                Some(v) => parse_f64(v)
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| format!("{what}: unit '{name}': {attr}=\"{v}\" is not a finite number")),
            }
        };
        let (factor, offset) = (num("factor", 1.0)?, num("offset", 0.0)?);
        if factor == 0.0 {
            return Err(format!("{what}: unit '{name}': factor must not be 0"));
        }
        Ok(Unit { name, base: Some(BaseUnit { exponents, factor, offset }) })
    }

    /// The map from values in `self` to values in `to`. The same name is the same unit;
    /// otherwise both need base units with the same exponents.
    pub fn conversion_to(&self, to: &Unit) -> Result<Affine, String> {
        match (&self.base, &to.base) {
            (Some(a), Some(b)) if a.exponents == b.exponents => {
                // base = fa * x + oa = fb * y + ob
                Ok(Affine { factor: a.factor / b.factor, offset: (a.offset - b.offset) / b.factor })
            }
            (Some(_), Some(_)) => Err(format!("incompatible units: {self} -> {to}")),
            _ if self.name == to.name => Ok(Affine::IDENTITY),
            _ => Err(format!("cannot convert {self} -> {to}: a unit without a base unit converts only to itself")),
        }
    }
}

/// The `Unit` children of a units element (`ssd:Units`, `ssv:Units`, FMI `<UnitDefinitions>`),
/// by name; a name defined twice is an error.
pub fn parse_units(units: Node, what: &str) -> Result<BTreeMap<String, Unit>, String> {
    let mut out = BTreeMap::new();
    for u in units.children().filter(|n| n.is_element() && n.tag_name().name() == "Unit") {
        let unit = Unit::parse(u, what)?;
        if out.contains_key(&unit.name) {
            return Err(format!("{what}: unit '{}' is defined twice", unit.name));
        }
        out.insert(unit.name.clone(), unit);
    }
    Ok(out)
}

/// The unit of every variable of an FMI 2.0 or 3.0 modelDescription.xml that has one (its
/// own `unit`, else its declared type's), by variable name. A unit the description names but
/// does not define has no base unit. Kept apart from [`crate::model_description`] so the
/// importer's parser stays as it is; only SSP unit conversion needs this.
pub fn fmu_variable_units(xml: &str, origin: &str) -> Result<BTreeMap<String, Unit>, String> {
    let doc = roxmltree::Document::parse(xml).map_err(|e| format!("{origin}: not well-formed XML: {e}"))?;
    let root = doc.root_element();
    let defs = match child(root, "UnitDefinitions") {
        Some(u) => parse_units(u, origin)?,
        None => BTreeMap::new(),
    };
    // FMI 3: <Float64Type name unit/>; FMI 2: <SimpleType name><Real unit/></SimpleType>.
    let mut type_units: BTreeMap<&str, &str> = BTreeMap::new();
    if let Some(td) = child(root, "TypeDefinitions") {
        for t in td.children().filter(Node::is_element) {
            let unit =
                t.attribute("unit").or_else(|| t.children().find(Node::is_element).and_then(|r| r.attribute("unit")));
            if let (Some(name), Some(unit)) = (t.attribute("name"), unit) {
                type_units.insert(name, unit);
            }
        }
    }
    let mut out = BTreeMap::new();
    let Some(vars) = child(root, "ModelVariables") else { return Ok(out) };
    for v in vars.children().filter(Node::is_element) {
        let Some(name) = v.attribute("name") else { continue };
        // FMI 2 puts the type element (<Real unit=..>) inside <ScalarVariable>.
        let typed = if v.tag_name().name() == "ScalarVariable" { v.children().find(Node::is_element) } else { Some(v) };
        let Some(typed) = typed else { continue };
        let unit = typed
            .attribute("unit")
            .or_else(|| typed.attribute("declaredType").and_then(|t| type_units.get(t).copied()));
        if let Some(u) = unit.filter(|u| !u.is_empty()) {
            let def = defs.get(u).cloned().unwrap_or_else(|| Unit { name: u.to_string(), base: None });
            out.insert(name.to_string(), def);
        }
    }
    Ok(out)
}

fn child<'a, 'i>(n: Node<'a, 'i>, name: &str) -> Option<Node<'a, 'i>> {
    n.children().find(|c| c.is_element() && c.tag_name().name() == name)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit(xml: &str) -> Unit {
        let doc = roxmltree::Document::parse(xml).unwrap();
        Unit::parse(doc.root_element(), "test").unwrap()
    }

    #[test]
    fn conversions_follow_factor_and_offset() {
        let kmh = unit(r#"<Unit name="km/h"><BaseUnit m="1" s="-1" factor="0.2777777777777778"/></Unit>"#);
        let ms = unit(r#"<Unit name="m/s"><BaseUnit m="1" s="-1"/></Unit>"#);
        let c = kmh.conversion_to(&ms).unwrap();
        assert!((c.apply(36.0) - 10.0).abs() < 1e-12);
        assert!((ms.conversion_to(&kmh).unwrap().apply(10.0) - 36.0).abs() < 1e-9);
        let degc = unit(r#"<Unit name="degC"><BaseUnit K="1" offset="273.15"/></Unit>"#);
        let degf = unit(
            r#"<Unit name="degF"><BaseUnit K="1" factor="0.5555555555555556" offset="255.3722222222222"/></Unit>"#,
        );
        assert!((degc.conversion_to(&degf).unwrap().apply(100.0) - 212.0).abs() < 1e-9);
        let k = unit(r#"<Unit name="K"><BaseUnit K="1"/></Unit>"#);
        assert!((degc.conversion_to(&k).unwrap().apply(0.0) - 273.15).abs() < 1e-12);
    }

    #[test]
    fn different_exponents_do_not_convert() {
        let m = unit(r#"<Unit name="m"><BaseUnit m="1"/></Unit>"#);
        let s = unit(r#"<Unit name="s"><BaseUnit s="1"/></Unit>"#);
        let e = m.conversion_to(&s).unwrap_err();
        assert_eq!(e, "incompatible units: m (m) -> s (s)");
        let bare = Unit { name: "N.s/m".into(), base: None };
        assert_eq!(bare.conversion_to(&bare.clone()).unwrap(), Affine::IDENTITY);
        assert!(bare.conversion_to(&m).unwrap_err().contains("without a base unit"));
    }

    #[test]
    fn affine_maps_compose_in_order() {
        let a = Affine { factor: 2.0, offset: 1.0 };
        let b = Affine { factor: 3.0, offset: -4.0 };
        assert_eq!(a.then(b).apply(5.0), b.apply(a.apply(5.0)));
        assert!(Affine::IDENTITY.then(Affine::IDENTITY).is_identity());
    }

    #[test]
    fn bad_definitions_are_refused() {
        let doc = roxmltree::Document::parse(r#"<Unit name="x"><BaseUnit m="one"/></Unit>"#).unwrap();
        assert!(Unit::parse(doc.root_element(), "f.ssd").unwrap_err().contains("f.ssd: unit 'x': m=\"one\""));
        let doc = roxmltree::Document::parse(r#"<Unit name="x"><BaseUnit factor="0"/></Unit>"#).unwrap();
        assert!(Unit::parse(doc.root_element(), "f").unwrap_err().contains("factor must not be 0"));
        let doc = roxmltree::Document::parse(r#"<U><Unit name="a"/><Unit name="a"/></U>"#).unwrap();
        assert!(parse_units(doc.root_element(), "f").unwrap_err().contains("'a' is defined twice"));
    }

    #[test]
    fn fmu_units_come_from_the_variable_or_its_declared_type() {
        let fmi3 = r#"<fmiModelDescription fmiVersion="3.0">
          <UnitDefinitions><Unit name="m"><BaseUnit m="1"/></Unit><Unit name="km"><BaseUnit m="1" factor="1000"/></Unit></UnitDefinitions>
          <TypeDefinitions><Float64Type name="Length" unit="m"/></TypeDefinitions>
          <ModelVariables>
            <Float64 name="a" valueReference="1" declaredType="Length"/>
            <Float64 name="b" valueReference="2" declaredType="Length" unit="km"/>
            <Float64 name="c" valueReference="3" unit="furlong"/>
            <Int32 name="n" valueReference="4"/>
          </ModelVariables></fmiModelDescription>"#;
        let u = fmu_variable_units(fmi3, "md").unwrap();
        assert_eq!(u["a"].name, "m");
        assert_eq!(u["b"].base.unwrap().factor, 1000.0);
        assert_eq!(u["c"], Unit { name: "furlong".into(), base: None });
        assert!(!u.contains_key("n"));
        let fmi2 = r#"<fmiModelDescription fmiVersion="2.0">
          <UnitDefinitions><Unit name="m/s"><BaseUnit m="1" s="-1"/></Unit></UnitDefinitions>
          <TypeDefinitions><SimpleType name="Speed"><Real unit="m/s"/></SimpleType></TypeDefinitions>
          <ModelVariables>
            <ScalarVariable name="v" valueReference="1"><Real declaredType="Speed"/></ScalarVariable>
            <ScalarVariable name="w" valueReference="2"><Real unit="m/s"/></ScalarVariable>
            <ScalarVariable name="k" valueReference="3"><Integer/></ScalarVariable>
          </ModelVariables></fmiModelDescription>"#;
        let u = fmu_variable_units(fmi2, "md").unwrap();
        assert_eq!(u["v"].base.unwrap().exponents, [0, 1, -1, 0, 0, 0, 0, 0]);
        assert_eq!(u["w"].name, "m/s");
        assert_eq!(u.len(), 2);
    }
}
