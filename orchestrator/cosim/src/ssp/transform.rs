//! SSP value transformations (`ssc:LinearTransformation`, `ssc:BooleanMappingTransformation`,
//! `ssc:IntegerMappingTransformation`, `ssc:EnumerationMappingTransformation`) on connections
//! and parameter mappings, and [`Transfer`]: what a scalar route does to a value on its way,
//! unit conversion and transformation compiled into one step when the system is loaded.

use std::collections::BTreeMap;
use std::fmt;

use roxmltree::Node;

use super::units::Affine;
use super::NS_SSC;
use crate::model_description::{parse_bool, parse_f64};
use crate::value::Value;

/// The transformation of one connection or parameter mapping entry.
#[derive(Clone, Debug, PartialEq)]
pub enum Transformation {
    /// `target = factor * source + offset`, after unit conversion (Real only).
    Linear(Affine),
    Boolean(BTreeMap<bool, bool>),
    Integer(BTreeMap<i64, i64>),
    /// Parsed so it is refused by name: agrisim exchanges no enumerations.
    Enumeration(BTreeMap<String, String>),
}

impl Transformation {
    /// The element name, for messages.
    pub fn element(&self) -> &'static str {
        match self {
            Transformation::Linear(_) => "ssc:LinearTransformation",
            Transformation::Boolean(_) => "ssc:BooleanMappingTransformation",
            Transformation::Integer(_) => "ssc:IntegerMappingTransformation",
            Transformation::Enumeration(_) => "ssc:EnumerationMappingTransformation",
        }
    }

    /// The one connector type the standard allows it on.
    pub fn applies_to(&self) -> &'static str {
        match self {
            Transformation::Linear(_) => "Real",
            Transformation::Boolean(_) => "Boolean",
            Transformation::Integer(_) => "Integer",
            Transformation::Enumeration(_) => "Enumeration",
        }
    }

    /// The transformation among `parent`'s `ssc:` children (a connection or mapping entry),
    /// if any. Two of them, or an `ssc:` element the standard does not define there (such as
    /// a `MapTransformation`), are errors.
    pub fn parse_child(parent: Node, what: &str) -> Result<Option<Transformation>, String> {
        let mut found = None;
        for t in parent.children().filter(|n| n.is_element() && n.tag_name().namespace() == Some(NS_SSC)) {
            let tag = t.tag_name().name();
            let parsed = match tag {
                "Annotations" => continue,
                "LinearTransformation" => {
                    let num = |attr: &str, default: f64| -> Result<f64, String> {
                        match t.attribute(attr) {
                            None => Ok(default),
                            Some(v) => parse_f64(v).filter(|x| x.is_finite()).ok_or_else(|| {
                                format!("{what}: ssc:LinearTransformation {attr}=\"{v}\" is not a finite number")
                            }),
                        }
                    };
                    Transformation::Linear(Affine { factor: num("factor", 1.0)?, offset: num("offset", 0.0)? })
                }
                "BooleanMappingTransformation" => Transformation::Boolean(entries(t, what, parse_bool)?),
                "IntegerMappingTransformation" => Transformation::Integer(entries(t, what, |s| s.trim().parse().ok())?),
                "EnumerationMappingTransformation" => {
                    Transformation::Enumeration(entries(t, what, |s| Some(s.to_string()))?)
                }
                other => {
                    return Err(format!(
                        "{what}: ssc:{other} is not an SSP 1.0 transformation (ssc:LinearTransformation, \
                         ssc:BooleanMappingTransformation, ssc:IntegerMappingTransformation or \
                         ssc:EnumerationMappingTransformation)"
                    ))
                }
            };
            if found.is_some() {
                return Err(format!("{what}: more than one transformation"));
            }
            found = Some(parsed);
        }
        Ok(found)
    }
}

/// The `ssc:MapEntry source= target=` children of a mapping transformation; a source listed
/// twice would make the table ambiguous.
fn entries<K: Ord + fmt::Display, F: Fn(&str) -> Option<K>>(
    t: Node,
    what: &str,
    parse: F,
) -> Result<BTreeMap<K, K>, String> {
    let tag = t.tag_name().name();
    let mut map = BTreeMap::new();
    for e in t.children().filter(|n| n.is_element() && n.tag_name().name() == "MapEntry") {
        let get = |attr: &str| -> Result<K, String> {
            let v = e.attribute(attr).ok_or_else(|| format!("{what}: an ssc:{tag} entry has no attribute '{attr}'"))?;
            parse(v).ok_or_else(|| format!("{what}: ssc:{tag} entry {attr}=\"{v}\" is not valid"))
        };
        let source = get("source")?;
        let target = get("target")?;
        if map.contains_key(&source) {
            return Err(format!("{what}: ssc:{tag} maps source {source} twice"));
        }
        map.insert(source, target);
    }
    if map.is_empty() {
        return Err(format!("{what}: ssc:{tag} has no ssc:MapEntry"));
    }
    Ok(map)
}

/// What a scalar route does to a value between source and destination: unit conversion and
/// an `ssc:LinearTransformation` folded into one [`Affine`] (Real), or a mapping table. A
/// value a table does not list stops the run (passing it unchanged would hide a gap in the
/// table).
#[derive(Clone, Debug, PartialEq)]
pub enum Transfer {
    Affine(Affine),
    Boolean(BTreeMap<bool, bool>),
    Integer(BTreeMap<i64, i64>),
}

impl Transfer {
    /// The value delivered for source value `v`; keeps `v`'s variant (an Int32 stays Int32).
    pub fn apply(&self, v: Value) -> Result<Value, String> {
        match (self, v) {
            (Transfer::Affine(a), Value::F64(x)) => Ok(Value::F64(a.apply(x))),
            (Transfer::Boolean(m), Value::Bool(b)) => {
                m.get(&b).map(|t| Value::Bool(*t)).ok_or_else(|| format!("value {b} has no entry in its mapping table"))
            }
            (Transfer::Integer(m), Value::I64(i)) => {
                m.get(&i).map(|t| Value::I64(*t)).ok_or_else(|| format!("value {i} has no entry in its mapping table"))
            }
            (Transfer::Integer(m), Value::I32(i)) => {
                let t = m.get(&(i as i64)).ok_or_else(|| format!("value {i} has no entry in its mapping table"))?;
                i32::try_from(*t).map(Value::I32).map_err(|_| format!("value {i} maps to {t}, out of range for Int32"))
            }
            (t, v) => Err(format!("cannot apply {t:?} to {v:?}")),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(inner: &str) -> Result<Option<Transformation>, String> {
        let xml = format!(r#"<c xmlns:ssc="{NS_SSC}">{inner}</c>"#);
        let doc = roxmltree::Document::parse(&xml).unwrap();
        Transformation::parse_child(doc.root_element(), "connection a.x -> b.y")
    }

    #[test]
    fn parses_the_ssp_transformations() {
        assert_eq!(parse("").unwrap(), None);
        assert_eq!(
            parse(r#"<ssc:LinearTransformation factor="2" offset="-1"/>"#).unwrap(),
            Some(Transformation::Linear(Affine { factor: 2.0, offset: -1.0 }))
        );
        assert_eq!(parse(r#"<ssc:LinearTransformation/>"#).unwrap(), Some(Transformation::Linear(Affine::IDENTITY)));
        let t = parse(
            r#"<ssc:IntegerMappingTransformation><ssc:MapEntry source="1" target="10"/><ssc:MapEntry source="2" target="20"/></ssc:IntegerMappingTransformation>"#,
        )
        .unwrap()
        .unwrap();
        assert_eq!(t, Transformation::Integer([(1, 10), (2, 20)].into()));
        let t = parse(r#"<ssc:BooleanMappingTransformation><ssc:MapEntry source="true" target="false"/><ssc:MapEntry source="false" target="true"/></ssc:BooleanMappingTransformation>"#).unwrap().unwrap();
        assert_eq!(t, Transformation::Boolean([(true, false), (false, true)].into()));
    }

    #[test]
    fn malformed_transformations_are_refused() {
        for (inner, why) in [
            (r#"<ssc:LinearTransformation factor="x"/>"#, "factor=\"x\" is not a finite number"),
            (r#"<ssc:MapTransformation/>"#, "ssc:MapTransformation is not an SSP 1.0 transformation"),
            (r#"<ssc:IntegerMappingTransformation/>"#, "has no ssc:MapEntry"),
            (
                r#"<ssc:IntegerMappingTransformation><ssc:MapEntry source="1.5" target="2"/></ssc:IntegerMappingTransformation>"#,
                "entry source=\"1.5\" is not valid",
            ),
            (
                r#"<ssc:IntegerMappingTransformation><ssc:MapEntry source="1" target="2"/><ssc:MapEntry source="1" target="3"/></ssc:IntegerMappingTransformation>"#,
                "maps source 1 twice",
            ),
            (r#"<ssc:LinearTransformation/><ssc:LinearTransformation/>"#, "more than one transformation"),
        ] {
            let e = parse(inner).unwrap_err();
            assert!(e.starts_with("connection a.x -> b.y: ") && e.contains(why), "{inner}: {e}");
        }
    }

    #[test]
    fn transfers_keep_the_value_type() {
        let lin = Transfer::Affine(Affine { factor: 2.0, offset: 1.0 });
        assert_eq!(lin.apply(Value::F64(3.0)).unwrap(), Value::F64(7.0));
        let map = Transfer::Integer([(1, 10), (2, 5_000_000_000)].into());
        assert_eq!(map.apply(Value::I32(1)).unwrap(), Value::I32(10));
        assert_eq!(map.apply(Value::I64(2)).unwrap(), Value::I64(5_000_000_000));
        assert!(map.apply(Value::I32(2)).unwrap_err().contains("out of range for Int32"));
        assert_eq!(map.apply(Value::I32(3)).unwrap_err(), "value 3 has no entry in its mapping table");
        let not = Transfer::Boolean([(true, false)].into());
        assert_eq!(not.apply(Value::Bool(true)).unwrap(), Value::Bool(false));
        assert!(not.apply(Value::Bool(false)).is_err());
        assert!(lin.apply(Value::I32(1)).is_err());
    }
}
