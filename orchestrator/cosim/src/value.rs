//! Typed access to one FMU variable through the importer, so the master can move values of
//! any supported type without a match in every loop.

use crate::error::Result;
use crate::fmi3::Instance;
use crate::model_description::{ModelVariable, VarType};

/// A scalar or binary value read from or written to an FMU.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    F64(f64),
    I32(i32),
    I64(i64),
    Bool(bool),
    Str(String),
    Bin(Vec<u8>),
}

impl Value {
    /// As a number for recording (Signals messages carry float64).
    pub fn as_f64(&self) -> Option<f64> {
        match *self {
            Value::F64(v) => Some(v),
            Value::I32(v) => Some(v as f64),
            Value::I64(v) => Some(v as f64),
            Value::Bool(v) => Some(v as u8 as f64),
            _ => None,
        }
    }

    /// Text form for run metadata (parameters): exact round trip for floats.
    pub fn to_text(&self) -> String {
        match self {
            Value::F64(v) => format!("{v:?}"),
            Value::I32(v) => v.to_string(),
            Value::I64(v) => v.to_string(),
            Value::Bool(v) => v.to_string(),
            Value::Str(s) => s.clone(),
            Value::Bin(b) => b.iter().map(|x| format!("{x:02x}")).collect(),
        }
    }
}

/// True for the types the master moves and records.
pub fn supported(ty: VarType) -> bool {
    matches!(ty, VarType::Float64 | VarType::Int32 | VarType::Int64 | VarType::Boolean | VarType::String | VarType::Binary)
}

pub fn get(inst: &mut Instance, v: &ModelVariable) -> Result<Value> {
    let vr = [v.value_reference];
    Ok(match v.ty {
        VarType::Float64 => {
            let mut x = [0.0];
            inst.get_f64(&vr, &mut x)?;
            Value::F64(x[0])
        }
        VarType::Int32 => {
            let mut x = [0];
            inst.get_i32(&vr, &mut x)?;
            Value::I32(x[0])
        }
        VarType::Int64 => {
            let mut x = [0];
            inst.get_i64(&vr, &mut x)?;
            Value::I64(x[0])
        }
        VarType::Boolean => {
            let mut x = [false];
            inst.get_bool(&vr, &mut x)?;
            Value::Bool(x[0])
        }
        VarType::String => Value::Str(inst.get_string(v.value_reference)?),
        VarType::Binary => Value::Bin(inst.get_binary(v.value_reference)?),
        other => return Err(crate::err!("FMU '{}': variable {} has type {}, which agrisim does not exchange", inst.name(), v.name, other.name())),
    })
}

pub fn set(inst: &mut Instance, v: &ModelVariable, value: &Value) -> Result<()> {
    let vr = [v.value_reference];
    match (v.ty, value) {
        (VarType::Float64, Value::F64(x)) => inst.set_f64(&vr, &[*x])?,
        (VarType::Int32, Value::I32(x)) => inst.set_i32(&vr, &[*x])?,
        (VarType::Int64, Value::I64(x)) => inst.set_i64(&vr, &[*x])?,
        (VarType::Boolean, Value::Bool(x)) => inst.set_bool(&vr, &[*x])?,
        (VarType::String, Value::Str(x)) => inst.set_string(v.value_reference, x)?,
        (VarType::Binary, Value::Bin(x)) => inst.set_binary(v.value_reference, x)?,
        (ty, value) => return Err(crate::err!("FMU '{}': variable {} is {}, cannot set {value:?}", inst.name(), v.name, ty.name())),
    }
    Ok(())
}

/// Converts a parameter value given in a scenario (TOML) to the variable's type.
pub fn from_toml(v: &ModelVariable, x: &toml::Value) -> Option<Value> {
    Some(match (v.ty, x) {
        (VarType::Float64, toml::Value::Float(f)) => Value::F64(*f),
        (VarType::Float64, toml::Value::Integer(i)) => Value::F64(*i as f64),
        (VarType::Int32, toml::Value::Integer(i)) => Value::I32(i32::try_from(*i).ok()?),
        (VarType::Int64, toml::Value::Integer(i)) => Value::I64(*i),
        (VarType::Boolean, toml::Value::Boolean(b)) => Value::Bool(*b),
        (VarType::String, toml::Value::String(s)) => Value::Str(s.clone()),
        _ => return None,
    })
}

/// Converts an SSP parameter value to the variable's type.
pub fn from_ssp(v: &ModelVariable, x: &crate::ssp::ParamValue) -> Option<Value> {
    use crate::ssp::ParamValue as P;
    Some(match (v.ty, x) {
        (VarType::Float64, P::Real(f)) => Value::F64(*f),
        (VarType::Int32, P::Integer(i)) => Value::I32(i32::try_from(*i).ok()?),
        (VarType::Int64, P::Integer(i)) => Value::I64(*i),
        (VarType::Boolean, P::Boolean(b)) => Value::Bool(*b),
        (VarType::String, P::String(s)) => Value::Str(s.clone()),
        (VarType::Binary, P::Binary(b)) => Value::Bin(b.clone()),
        _ => return None,
    })
}
