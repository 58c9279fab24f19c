//! REP 2011 type hashes (`RIHS01_<sha256>`): what ROS 2 Iron and later send beside a type's
//! name (rmw_zenoh in its key expressions, DDS in USER_DATA) so that peers with different
//! definitions of one name notice.
//!
//! The hash is the SHA-256 of a JSON text describing the type and, sorted by name, every
//! type it refers to: per field its name and a `FieldType` (type id, array capacity, string
//! bound, nested type name). Comments, constants and default values do not enter it. The
//! ids are those of `type_description_interfaces/msg/FieldType` (ROS 2 Iron); an array adds
//! 48 to its element's id, a bounded sequence 96, an unbounded one 144. The JSON is written
//! as Python's `json.dumps` writes it with default settings (the reference implementation
//! in rosidl is Python): `", "` and `": "` as separators, keys in the order given.

use crate::schema::{all_type_names, msg_text};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::fmt::Write;

/// `FieldType` ids of the primitive types a .msg may name (`char` is `uint8` in ROS 2).
fn primitive_id(name: &str) -> Option<u8> {
    Some(match name {
        "int8" => 2,
        "uint8" | "char" => 3,
        "int16" => 4,
        "uint16" => 5,
        "int32" => 6,
        "uint32" => 7,
        "int64" => 8,
        "uint64" => 9,
        "float32" => 10,
        "float64" => 11,
        "bool" => 15,
        "byte" => 16,
        "string" => 17,
        "wstring" => 18,
        _ => return None,
    })
}

const NESTED: u8 = 1;
const BOUNDED_STRING: u8 = 21;
const BOUNDED_WSTRING: u8 = 22;

/// One field as the type description has it.
#[derive(Clone, Debug, PartialEq)]
struct FieldType {
    type_id: u8,
    capacity: u64,
    string_capacity: u64,
    nested_type_name: String,
}

/// Why a type has no hash.
#[derive(Clone, Debug, PartialEq)]
pub enum TypeHashError {
    /// The type (or one it refers to) is not among this crate's definitions.
    Unknown(String),
    /// A field line of the type's .msg text could not be read.
    BadField { type_name: String, line: String },
}

impl std::fmt::Display for TypeHashError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TypeHashError::Unknown(t) => write!(f, "no message definition for '{t}'"),
            TypeHashError::BadField { type_name, line } => {
                write!(f, "message definition of '{type_name}': cannot read the field line '{line}'")
            }
        }
    }
}

impl std::error::Error for TypeHashError {}

/// `pkg/Type` or `pkg/msg/Type` -> `pkg/msg/Type`.
fn full_name(package: &str, ty: &str) -> String {
    let parts: Vec<&str> = ty.split('/').collect();
    match parts.as_slice() {
        [p, t] => format!("{p}/msg/{t}"),
        [p, "msg", t] => format!("{p}/msg/{t}"),
        // rosidl resolves a bare `Header` to std_msgs, any other bare name to the package.
        [t] if *t == "Header" => "std_msgs/msg/Header".into(),
        _ => format!("{package}/msg/{ty}"),
    }
}

/// The fields of a .msg text, in order (constants and comments left out).
fn fields(type_name: &str) -> Result<Vec<(String, FieldType)>, TypeHashError> {
    let text = msg_text(type_name).ok_or_else(|| TypeHashError::Unknown(type_name.to_string()))?;
    let package = type_name.split('/').next().unwrap_or("");
    let bad = |line: &str| TypeHashError::BadField { type_name: type_name.to_string(), line: line.to_string() };
    let mut out = vec![];
    for raw in text.lines() {
        let line = raw.split('#').next().unwrap_or("").trim();
        let mut tokens = line.split_whitespace();
        let (Some(ty), Some(name)) = (tokens.next(), tokens.next()) else { continue };
        // `TYPE NAME=VALUE` or `TYPE NAME = VALUE` is a constant; `TYPE NAME VALUE` a default.
        if name.contains('=') || tokens.next().is_some_and(|t| t.starts_with('=')) {
            continue;
        }
        let (element, array) = match ty.split_once('[') {
            Some((e, rest)) => (e, Some(rest.strip_suffix(']').ok_or_else(|| bad(line))?)),
            None => (ty, None),
        };
        let (increment, capacity) = match array {
            None => (0, 0),
            Some("") => (144, 0),
            Some(n) => match n.strip_prefix("<=") {
                Some(b) => (96, b.parse().map_err(|_| bad(line))?),
                None => (48, n.parse().map_err(|_| bad(line))?),
            },
        };
        let (base, bound) = match element.split_once("<=") {
            Some((b, n)) => (b, Some(n.parse::<u64>().map_err(|_| bad(line))?)),
            None => (element, None),
        };
        let ft = match (primitive_id(base), bound) {
            (Some(17), Some(b)) => FieldType {
                type_id: increment + BOUNDED_STRING,
                capacity,
                string_capacity: b,
                nested_type_name: String::new(),
            },
            (Some(18), Some(b)) => FieldType {
                type_id: increment + BOUNDED_WSTRING,
                capacity,
                string_capacity: b,
                nested_type_name: String::new(),
            },
            (Some(_), Some(_)) => return Err(bad(line)),
            (Some(id), None) => {
                FieldType { type_id: increment + id, capacity, string_capacity: 0, nested_type_name: String::new() }
            }
            (None, _) => FieldType {
                type_id: increment + NESTED,
                capacity,
                string_capacity: 0,
                nested_type_name: full_name(package, base),
            },
        };
        out.push((name.to_string(), ft));
    }
    if out.is_empty() {
        // An empty message is described with one placeholder member, as rosidl does.
        let ft = FieldType { type_id: 3, capacity: 0, string_capacity: 0, nested_type_name: String::new() };
        out.push(("structure_needs_at_least_one_member".into(), ft));
    }
    Ok(out)
}

/// Python's `json.dumps` of a str (ASCII: non-ASCII escaped as `\uXXXX`).
fn json_str(out: &mut String, s: &str) {
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            c if (c as u32) < 0x20 || !c.is_ascii() => {
                let mut buf = [0u16; 2];
                for u in c.encode_utf16(&mut buf) {
                    let _ = write!(out, "\\u{u:04x}");
                }
            }
            c => out.push(c),
        }
    }
    out.push('"');
}

fn describe(out: &mut String, type_name: &str, fields: &[(String, FieldType)]) {
    out.push_str("{\"type_name\": ");
    json_str(out, type_name);
    out.push_str(", \"fields\": [");
    for (i, (name, t)) in fields.iter().enumerate() {
        if i > 0 {
            out.push_str(", ");
        }
        out.push_str("{\"name\": ");
        json_str(out, name);
        let _ = write!(
            out,
            ", \"type\": {{\"type_id\": {}, \"capacity\": {}, \"string_capacity\": {}, \"nested_type_name\": ",
            t.type_id, t.capacity, t.string_capacity
        );
        json_str(out, &t.nested_type_name);
        out.push_str("}}");
    }
    out.push_str("]}");
}

/// The JSON text whose SHA-256 is the hash of `type_name` (`pkg/msg/Type` or `pkg/Type`).
pub fn type_description_json(type_name: &str) -> Result<String, TypeHashError> {
    let (pkg, _) = type_name.split_once('/').ok_or_else(|| TypeHashError::Unknown(type_name.to_string()))?;
    let root = full_name(pkg, type_name);
    // Every referenced type, by name (sorted, as the description lists them).
    let mut all: BTreeMap<String, Vec<(String, FieldType)>> = BTreeMap::new();
    let mut todo = vec![root.clone()];
    while let Some(t) = todo.pop() {
        if all.contains_key(&t) {
            continue;
        }
        let f = fields(&t)?;
        todo.extend(
            f.iter().filter(|(_, ft)| !ft.nested_type_name.is_empty()).map(|(_, ft)| ft.nested_type_name.clone()),
        );
        all.insert(t, f);
    }
    let mut out = String::from("{\"type_description\": ");
    describe(&mut out, &root, &all[&root]);
    out.push_str(", \"referenced_type_descriptions\": [");
    for (i, (name, f)) in all.iter().filter(|(n, _)| **n != root).enumerate() {
        if i > 0 {
            out.push_str(", ");
        }
        describe(&mut out, name, f);
    }
    out.push_str("]}");
    Ok(out)
}

/// The REP 2011 hash of a type, `RIHS01_` and 64 hex digits.
pub fn type_hash(type_name: &str) -> Result<String, TypeHashError> {
    let digest = Sha256::digest(type_description_json(type_name)?.as_bytes());
    let mut s = String::from("RIHS01_");
    for b in digest {
        let _ = write!(s, "{b:02x}");
    }
    Ok(s)
}

/// Every known type's hash, computed once (`pkg/msg/Type` -> hash).
pub fn type_hashes() -> &'static BTreeMap<String, String> {
    static HASHES: std::sync::OnceLock<BTreeMap<String, String>> = std::sync::OnceLock::new();
    HASHES.get_or_init(|| {
        all_type_names()
            .iter()
            .map(|t| (t.to_string(), type_hash(t).unwrap_or_else(|e| panic!("the crate's own definitions: {e}"))))
            .collect()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn describes_fields_arrays_and_references() {
        let j = type_description_json("shape_msgs/msg/SolidPrimitive").unwrap();
        // float64[<=3] dimensions: a bounded sequence of float64 (96 + 11), capacity 3.
        assert!(
            j.contains("{\"name\": \"dimensions\", \"type\": {\"type_id\": 107, \"capacity\": 3, \"string_capacity\": 0, \"nested_type_name\": \"\"}}"),
            "{j}"
        );
        let j = type_description_json("std_msgs/Header").unwrap();
        assert!(j.starts_with("{\"type_description\": {\"type_name\": \"std_msgs/msg/Header\", \"fields\": [{\"name\": \"stamp\", \"type\": {\"type_id\": 1, \"capacity\": 0, \"string_capacity\": 0, \"nested_type_name\": \"builtin_interfaces/msg/Time\"}}"), "{j}");
        assert!(j.ends_with("\"referenced_type_descriptions\": [{\"type_name\": \"builtin_interfaces/msg/Time\", \"fields\": [{\"name\": \"sec\", \"type\": {\"type_id\": 6, \"capacity\": 0, \"string_capacity\": 0, \"nested_type_name\": \"\"}}, {\"name\": \"nanosec\", \"type\": {\"type_id\": 7, \"capacity\": 0, \"string_capacity\": 0, \"nested_type_name\": \"\"}}]}]}"), "{j}");
        assert_eq!(type_hash("nope/msg/Nothing"), Err(TypeHashError::Unknown("nope/msg/Nothing".into())));
    }

    #[test]
    fn every_known_type_has_a_distinct_hash() {
        let h = type_hashes();
        assert_eq!(h.len(), all_type_names().len());
        let distinct: std::collections::BTreeSet<&String> = h.values().collect();
        assert_eq!(distinct.len(), h.len());
        assert!(h.values().all(|v| v.len() == 7 + 64 && v.starts_with("RIHS01_")));
    }
}
