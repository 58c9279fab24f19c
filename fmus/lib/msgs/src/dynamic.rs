//! Messages by type name at run time: CDR decoded into a [`Value`] tree, and a tree encoded
//! back, driven by the .msg texts (the same single source the typed structs and the MCAP
//! schemas follow). For the places that meet types only as names: the Python binding, and
//! bridges that carry every topic of a system.
//!
//! The typed structs stay the fast, checked path inside the engine; tests hold the two to
//! the same bytes for every type (`tests/dynamic.rs`).

use crate::cdr::{CdrError, CdrReader, CdrWriter};
use crate::schema::{all_type_names, msg_text};
use std::collections::BTreeMap;
use std::fmt;
use std::sync::OnceLock;

/// A decoded message or field. `uint8[]`/`byte[]` fields (images, point clouds) are
/// [`Value::Bytes`]; other arrays are [`Value::Array`].
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    Bool(bool),
    Int(i64),
    UInt(u64),
    Float(f64),
    String(String),
    Bytes(Vec<u8>),
    Array(Vec<Value>),
    /// Fields in declaration order.
    Struct(Vec<(String, Value)>),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Prim {
    Bool,
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
    Str,
}

impl Prim {
    fn parse(name: &str) -> Option<Prim> {
        Some(match name {
            "bool" => Prim::Bool,
            "int8" => Prim::I8,
            "uint8" | "byte" | "char" => Prim::U8,
            "int16" => Prim::I16,
            "uint16" => Prim::U16,
            "int32" => Prim::I32,
            "uint32" => Prim::U32,
            "int64" => Prim::I64,
            "uint64" => Prim::U64,
            "float32" => Prim::F32,
            "float64" => Prim::F64,
            "string" => Prim::Str,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Prim::Bool | Prim::I8 | Prim::U8 => 1,
            Prim::I16 | Prim::U16 => 2,
            Prim::I32 | Prim::U32 | Prim::F32 | Prim::Str => 4,
            Prim::I64 | Prim::U64 | Prim::F64 => 8,
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
enum Base {
    Prim(Prim),
    /// `pkg/Type`.
    Msg(String),
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Arity {
    One,
    Fixed(usize),
    /// Unbounded or bounded (`[<=N]`): a counted sequence on the wire.
    Seq,
}

#[derive(Clone, Debug)]
struct Field {
    name: String,
    base: Base,
    arity: Arity,
}

/// Every known type's fields, parsed once.
fn table() -> &'static BTreeMap<String, Vec<Field>> {
    static TABLE: OnceLock<BTreeMap<String, Vec<Field>>> = OnceLock::new();
    TABLE.get_or_init(|| {
        all_type_names()
            .iter()
            .map(|full| {
                let (pkg, ty) = short(full).expect("table names are pkg/msg/Type");
                (format!("{pkg}/{ty}"), parse_fields(pkg, msg_text(full).expect("table text")))
            })
            .collect()
    })
}

/// `pkg/msg/Type` or `pkg/Type` -> (pkg, Type).
fn short(name: &str) -> Option<(&str, &str)> {
    let parts: Vec<&str> = name.split('/').collect();
    match parts.as_slice() {
        [p, t] | [p, "msg", t] if !p.is_empty() && !t.is_empty() => Some((p, t)),
        _ => None,
    }
}

/// Field lines of a .msg text; constants (`uint8 X=1`, `uint8 X = 1`) and default values
/// are not fields on the wire.
fn parse_fields(package: &str, text: &str) -> Vec<Field> {
    let mut out = vec![];
    for line in text.lines() {
        let line = line.split('#').next().unwrap_or("").trim();
        let mut tokens = line.split_whitespace();
        let (Some(ty), Some(name)) = (tokens.next(), tokens.next()) else { continue };
        if name.contains('=') || tokens.next().is_some_and(|t| t.starts_with('=')) {
            continue;
        }
        let (ty, arity) = match ty.split_once('[') {
            Some((t, rest)) => {
                let inner = rest.trim_end_matches(']');
                (
                    t,
                    if inner.is_empty() || inner.starts_with("<=") {
                        Arity::Seq
                    } else {
                        inner.parse().map_or(Arity::Seq, Arity::Fixed)
                    },
                )
            }
            None => (ty, Arity::One),
        };
        let ty = ty.split("<=").next().unwrap_or(ty);
        let base = match Prim::parse(ty) {
            Some(p) => Base::Prim(p),
            None => Base::Msg(match short(ty) {
                Some((p, t)) => format!("{p}/{t}"),
                None if ty == "Header" => "std_msgs/Header".into(),
                None => format!("{package}/{ty}"),
            }),
        };
        out.push(Field { name: name.to_string(), base, arity });
    }
    out
}

/// Why a value could not be encoded or a type is unknown.
#[derive(Clone, Debug, PartialEq)]
pub enum DynError {
    UnknownType(String),
    /// `path` is the field's place in the message (`pose.position.x`).
    Field {
        path: String,
        reason: String,
    },
    Cdr(CdrError),
}

impl fmt::Display for DynError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DynError::UnknownType(t) => write!(f, "unknown message type {t} (not in models/msgs)"),
            DynError::Field { path, reason } => write!(f, "field {path}: {reason}"),
            DynError::Cdr(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for DynError {}

impl From<CdrError> for DynError {
    fn from(e: CdrError) -> Self {
        DynError::Cdr(e)
    }
}

fn fields_of(type_name: &str) -> Result<&'static [Field], DynError> {
    let (p, t) = short(type_name).ok_or_else(|| DynError::UnknownType(type_name.to_string()))?;
    table().get(&format!("{p}/{t}")).map(|v| v.as_slice()).ok_or_else(|| DynError::UnknownType(type_name.to_string()))
}

/// Whether `type_name` (`pkg/msg/Type` or `pkg/Type`) is known.
pub fn is_known(type_name: &str) -> bool {
    fields_of(type_name).is_ok()
}

/// Fewest bytes one encoded element of `base` takes (bounds sequence counts).
fn min_size(base: &Base) -> usize {
    match base {
        Base::Prim(p) => p.size(),
        Base::Msg(m) => fields_of(m)
            .map(|fs| {
                fs.iter()
                    .map(|f| match f.arity {
                        Arity::One => min_size(&f.base),
                        Arity::Fixed(n) => n * min_size(&f.base),
                        Arity::Seq => 4,
                    })
                    .sum()
            })
            .unwrap_or(1),
    }
}

/// Decodes CDR bytes (header included) as `type_name`.
pub fn decode(type_name: &str, bytes: &[u8]) -> Result<Value, DynError> {
    let fields = fields_of(type_name)?;
    let mut r = CdrReader::new(bytes)?;
    read_struct(fields, &mut r)
}

fn read_struct(fields: &[Field], r: &mut CdrReader<'_>) -> Result<Value, DynError> {
    let mut out = Vec::with_capacity(fields.len());
    for f in fields {
        let v = match f.arity {
            Arity::One => read_one(&f.base, r)?,
            Arity::Fixed(n) => read_many(&f.base, n, r)?,
            Arity::Seq => {
                let n = r.read_sequence_len(min_size(&f.base))?;
                read_many(&f.base, n, r)?
            }
        };
        out.push((f.name.clone(), v));
    }
    Ok(Value::Struct(out))
}

fn read_many(base: &Base, n: usize, r: &mut CdrReader<'_>) -> Result<Value, DynError> {
    if *base == Base::Prim(Prim::U8) {
        return Ok(Value::Bytes(r.read_bytes(n)?.to_vec()));
    }
    let mut v = Vec::with_capacity(n.min(r.remaining()));
    for _ in 0..n {
        v.push(read_one(base, r)?);
    }
    Ok(Value::Array(v))
}

fn read_one(base: &Base, r: &mut CdrReader<'_>) -> Result<Value, DynError> {
    Ok(match base {
        Base::Msg(m) => return read_struct(fields_of(m)?, r),
        Base::Prim(p) => match p {
            Prim::Bool => Value::Bool(r.read_bool()?),
            Prim::I8 => Value::Int(r.read_i8()? as i64),
            Prim::U8 => Value::UInt(r.read_u8()? as u64),
            Prim::I16 => Value::Int(r.read_i16()? as i64),
            Prim::U16 => Value::UInt(r.read_u16()? as u64),
            Prim::I32 => Value::Int(r.read_i32()? as i64),
            Prim::U32 => Value::UInt(r.read_u32()? as u64),
            Prim::I64 => Value::Int(r.read_i64()?),
            Prim::U64 => Value::UInt(r.read_u64()?),
            Prim::F32 => Value::Float(r.read_f32()? as f64),
            Prim::F64 => Value::Float(r.read_f64()?),
            Prim::Str => Value::String(r.read_string()?),
        },
    })
}

/// Encodes `value` as `type_name`. A struct may leave fields out (they get ROS 2's defaults:
/// zero, empty, false); a field the type does not have is an error naming it, as is a value
/// of the wrong kind or out of its type's range.
pub fn encode(type_name: &str, value: &Value) -> Result<Vec<u8>, DynError> {
    let fields = fields_of(type_name)?;
    let mut w = CdrWriter::new();
    write_struct(fields, Some(value), &mut w, "")?;
    Ok(w.into_bytes())
}

fn bad(path: &str, reason: impl Into<String>) -> DynError {
    DynError::Field { path: if path.is_empty() { "(message)".into() } else { path.to_string() }, reason: reason.into() }
}

fn join(path: &str, name: &str) -> String {
    if path.is_empty() {
        name.to_string()
    } else {
        format!("{path}.{name}")
    }
}

fn write_struct(fields: &[Field], value: Option<&Value>, w: &mut CdrWriter, path: &str) -> Result<(), DynError> {
    let given: &[(String, Value)] = match value {
        None => &[],
        Some(Value::Struct(v)) => v,
        Some(other) => return Err(bad(path, format!("expected a message (fields by name), got {}", kind(other)))),
    };
    for (name, _) in given {
        if !fields.iter().any(|f| &f.name == name) {
            let known: Vec<&str> = fields.iter().map(|f| f.name.as_str()).collect();
            return Err(bad(&join(path, name), format!("no such field (fields: {})", known.join(", "))));
        }
    }
    for f in fields {
        let v = given.iter().find(|(n, _)| n == &f.name).map(|(_, v)| v);
        let p = join(path, &f.name);
        match f.arity {
            Arity::One => write_one(&f.base, v, w, &p)?,
            Arity::Fixed(n) => {
                let items = elements(v, &p)?;
                if !items.is_empty() && items.len() != n {
                    return Err(bad(&p, format!("expected {n} elements, got {}", items.len())));
                }
                for k in 0..n {
                    write_one(&f.base, items.get(k).map(|e| e.as_ref()), w, &format!("{p}[{k}]"))?;
                }
            }
            Arity::Seq => {
                let items = elements(v, &p)?;
                w.write_sequence_len(items.len());
                for (k, e) in items.iter().enumerate() {
                    write_one(&f.base, Some(e.as_ref()), w, &format!("{p}[{k}]"))?;
                }
            }
        }
    }
    Ok(())
}

/// The elements of an array value (absent = empty); bytes count as unsigned integers.
fn elements<'a>(v: Option<&'a Value>, path: &str) -> Result<Vec<std::borrow::Cow<'a, Value>>, DynError> {
    use std::borrow::Cow;
    Ok(match v {
        None => vec![],
        Some(Value::Array(a)) => a.iter().map(Cow::Borrowed).collect(),
        Some(Value::Bytes(b)) => b.iter().map(|&x| Cow::Owned(Value::UInt(x as u64))).collect(),
        Some(other) => return Err(bad(path, format!("expected an array, got {}", kind(other)))),
    })
}

fn kind(v: &Value) -> &'static str {
    match v {
        Value::Bool(_) => "a bool",
        Value::Int(_) | Value::UInt(_) => "an integer",
        Value::Float(_) => "a float",
        Value::String(_) => "a string",
        Value::Bytes(_) => "bytes",
        Value::Array(_) => "an array",
        Value::Struct(_) => "a message",
    }
}

fn int_of(v: Option<&Value>, path: &str, lo: i128, hi: i128) -> Result<i128, DynError> {
    let x = match v {
        None => 0,
        Some(Value::Int(i)) => *i as i128,
        Some(Value::UInt(u)) => *u as i128,
        Some(Value::Bool(b)) => *b as i128,
        Some(other) => return Err(bad(path, format!("expected an integer, got {}", kind(other)))),
    };
    if x < lo || x > hi {
        return Err(bad(path, format!("{x} is out of range [{lo}, {hi}]")));
    }
    Ok(x)
}

fn write_one(base: &Base, v: Option<&Value>, w: &mut CdrWriter, path: &str) -> Result<(), DynError> {
    let p = match base {
        Base::Msg(m) => return write_struct(fields_of(m)?, v, w, path),
        Base::Prim(p) => *p,
    };
    match p {
        Prim::Bool => w.write_bool(match v {
            None => false,
            Some(Value::Bool(b)) => *b,
            Some(other) => return Err(bad(path, format!("expected a bool, got {}", kind(other)))),
        }),
        Prim::I8 => w.write_i8(int_of(v, path, i8::MIN as i128, i8::MAX as i128)? as i8),
        Prim::U8 => w.write_u8(int_of(v, path, 0, u8::MAX as i128)? as u8),
        Prim::I16 => w.write_i16(int_of(v, path, i16::MIN as i128, i16::MAX as i128)? as i16),
        Prim::U16 => w.write_u16(int_of(v, path, 0, u16::MAX as i128)? as u16),
        Prim::I32 => w.write_i32(int_of(v, path, i32::MIN as i128, i32::MAX as i128)? as i32),
        Prim::U32 => w.write_u32(int_of(v, path, 0, u32::MAX as i128)? as u32),
        Prim::I64 => w.write_i64(int_of(v, path, i64::MIN as i128, i64::MAX as i128)? as i64),
        Prim::U64 => w.write_u64(int_of(v, path, 0, u64::MAX as i128)? as u64),
        Prim::F32 | Prim::F64 => {
            let x = match v {
                None => 0.0,
                Some(Value::Float(x)) => *x,
                Some(Value::Int(i)) => *i as f64,
                Some(Value::UInt(u)) => *u as f64,
                Some(other) => return Err(bad(path, format!("expected a number, got {}", kind(other)))),
            };
            if p == Prim::F32 {
                w.write_f32(x as f32)
            } else {
                w.write_f64(x)
            }
        }
        Prim::Str => w.write_string(match v {
            None => "",
            Some(Value::String(s)) => s,
            Some(other) => return Err(bad(path, format!("expected a string, got {}", kind(other)))),
        }),
    }
    Ok(())
}
