//! Typed access to one FMU variable through the importer, so the master can move values of
//! any supported type without a match in every loop.

use crate::error::Result;
use crate::fmu::FmuInstance;
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
    /// The very same value: floats bit for bit (a NaN equals itself, so a loop that settles
    /// on NaN converges; -0.0 differs from 0.0, as an FMU could tell them apart).
    pub fn identical(&self, other: &Value) -> bool {
        match (self, other) {
            (Value::F64(a), Value::F64(b)) => a.to_bits() == b.to_bits(),
            _ => self == other,
        }
    }

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
    matches!(
        ty,
        VarType::Float64 | VarType::Int32 | VarType::Int64 | VarType::Boolean | VarType::String | VarType::Binary
    )
}

pub fn get(inst: &mut dyn FmuInstance, v: &ModelVariable) -> Result<Value> {
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
        other => {
            return Err(crate::err!(
                "FMU '{}': variable {} has type {}, which agrisim does not exchange",
                inst.name(),
                v.name,
                other.name()
            ))
        }
    })
}

pub fn set(inst: &mut dyn FmuInstance, v: &ModelVariable, value: &Value) -> Result<()> {
    let vr = [v.value_reference];
    match (v.ty, value) {
        (VarType::Float64, Value::F64(x)) => inst.set_f64(&vr, &[*x])?,
        (VarType::Int32, Value::I32(x)) => inst.set_i32(&vr, &[*x])?,
        (VarType::Int64, Value::I64(x)) => inst.set_i64(&vr, &[*x])?,
        (VarType::Boolean, Value::Bool(x)) => inst.set_bool(&vr, &[*x])?,
        (VarType::String, Value::Str(x)) => inst.set_string(v.value_reference, x)?,
        (VarType::Binary, Value::Bin(x)) => inst.set_binary(v.value_reference, x)?,
        (ty, value) => {
            return Err(crate::err!(
                "FMU '{}': variable {} is {}, cannot set {value:?}",
                inst.name(),
                v.name,
                ty.name()
            ))
        }
    }
    Ok(())
}

/// Converts a parameter value given in a scenario (TOML) to the variable's type; a float for
/// an integer variable must pass [`int_from_f64`]. The error names the variable and the value.
pub fn from_toml(v: &ModelVariable, x: &toml::Value) -> Result<Value> {
    Ok(match (v.ty, x) {
        (VarType::Float64, toml::Value::Float(f)) => Value::F64(*f),
        (VarType::Float64, toml::Value::Integer(i)) => Value::F64(*i as f64),
        (VarType::Int32, toml::Value::Integer(i)) => Value::I32(i32::try_from(*i).map_err(|_| out_of_range(v, i))?),
        (VarType::Int64, toml::Value::Integer(i)) => Value::I64(*i),
        (VarType::Int32 | VarType::Int64, toml::Value::Float(f)) => int_from_f64(v, *f)?,
        (VarType::Boolean, toml::Value::Boolean(b)) => Value::Bool(*b),
        (VarType::String, toml::Value::String(s)) => Value::Str(s.clone()),
        _ => return Err(crate::err!("variable '{}': value {x} does not fit type {}", v.name, v.ty.name())),
    })
}

/// Integral values within this relative distance of an integer count as that integer (an id
/// that went through floating-point arithmetic).
const INTEGER_TOLERANCE: f64 = 1e-9;

fn out_of_range(v: &ModelVariable, x: impl std::fmt::Display) -> crate::error::Error {
    let (lo, hi) = if v.ty == VarType::Int32 { (i32::MIN as i64, i32::MAX as i64) } else { (i64::MIN, i64::MAX) };
    crate::err!("variable '{}' ({}): value {x} is out of range for {} [{lo}, {hi}]", v.name, v.ty.name(), v.ty.name())
}

/// `x` as the value of the Int32 or Int64 variable `v`, rounded to the nearest integer. Refused,
/// naming the variable and the value, when `x` is not finite (a NaN id must not become 0), not
/// an integer (beyond a relative 1e-9), or outside the type's range (never saturated).
pub fn int_from_f64(v: &ModelVariable, x: f64) -> Result<Value> {
    if !x.is_finite() {
        return Err(crate::err!("variable '{}' ({}): value {x} is not a finite number", v.name, v.ty.name()));
    }
    let r = x.round();
    if (x - r).abs() > INTEGER_TOLERANCE * r.abs().max(1.0) {
        return Err(crate::err!("variable '{}' ({}): value {x} is not an integer", v.name, v.ty.name()));
    }
    // Both bounds are exact in f64: -2^31 and 2^31 - 1, -2^63 and 2^63 (excluded).
    match v.ty {
        VarType::Int32 if (i32::MIN as f64..=i32::MAX as f64).contains(&r) => Ok(Value::I32(r as i32)),
        VarType::Int64 if (i64::MIN as f64..-(i64::MIN as f64)).contains(&r) => Ok(Value::I64(r as i64)),
        VarType::Int32 | VarType::Int64 => Err(out_of_range(v, x)),
        other => Err(crate::err!("variable '{}' is {}, not an integer type", v.name, other.name())),
    }
}

/// A number (a scalar system input, always f64 on the bus) as the value of the Float64, Int32,
/// Int64 or Boolean variable `v`: integers through [`int_from_f64`]; Boolean is `x != 0`, and
/// NaN is refused for it. The error names the variable and the value.
pub fn scalar_from_f64(v: &ModelVariable, x: f64) -> Result<Value> {
    match v.ty {
        VarType::Float64 => Ok(Value::F64(x)),
        VarType::Int32 | VarType::Int64 => int_from_f64(v, x),
        VarType::Boolean if x.is_nan() => {
            Err(crate::err!("variable '{}' (Boolean): value NaN is not a truth value", v.name))
        }
        VarType::Boolean => Ok(Value::Bool(x != 0.0)),
        other => Err(crate::err!("variable '{}' of type {} cannot take a scalar", v.name, other.name())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model_description::{Causality, Variability};

    fn var(name: &str, ty: VarType) -> ModelVariable {
        ModelVariable {
            name: name.into(),
            value_reference: 1,
            ty,
            causality: Causality::Input,
            variability: Variability::Discrete,
            start: None,
            mime_type: None,
            description: None,
            unit: None,
        }
    }

    #[test]
    fn integers_from_f64_are_checked_not_cast() {
        let id = var("target_id", VarType::Int32);
        assert_eq!(int_from_f64(&id, 7.0).unwrap(), Value::I32(7));
        assert_eq!(int_from_f64(&id, -0.0).unwrap(), Value::I32(0));
        assert_eq!(int_from_f64(&id, 3.0 + 1e-12).unwrap(), Value::I32(3));
        assert_eq!(int_from_f64(&id, 2147483647.0).unwrap(), Value::I32(i32::MAX));
        assert_eq!(int_from_f64(&id, -2147483648.0).unwrap(), Value::I32(i32::MIN));
        for (x, why) in [
            (f64::NAN, "NaN is not a finite number"),
            (f64::INFINITY, "inf is not a finite number"),
            (2.5, "2.5 is not an integer"),
            (2147483648.0, "2147483648 is out of range for Int32 [-2147483648, 2147483647]"),
            (-1e10, "-10000000000 is out of range for Int32"),
        ] {
            let e = int_from_f64(&id, x).unwrap_err().0;
            assert!(e.starts_with("variable 'target_id' (Int32): value "), "{e}");
            assert!(e.contains(why), "{x}: {e}");
        }
        let n = var("count", VarType::Int64);
        let two_63 = -(i64::MIN as f64);
        assert_eq!(int_from_f64(&n, -two_63).unwrap(), Value::I64(i64::MIN));
        assert_eq!(int_from_f64(&n, (1u64 << 53) as f64).unwrap(), Value::I64(1 << 53));
        assert!(int_from_f64(&n, two_63).unwrap_err().0.contains("out of range for Int64"));
        assert!(int_from_f64(&n, f64::NEG_INFINITY).is_err());
        assert!(int_from_f64(&var("x", VarType::Float64), 1.0).unwrap_err().0.contains("not an integer type"));
    }

    #[test]
    fn scalars_from_f64_follow_the_variable_type() {
        assert_eq!(scalar_from_f64(&var("x", VarType::Float64), 0.25).unwrap(), Value::F64(0.25));
        assert_eq!(scalar_from_f64(&var("n", VarType::Int64), 4.0).unwrap(), Value::I64(4));
        assert_eq!(scalar_from_f64(&var("on", VarType::Boolean), 1.0).unwrap(), Value::Bool(true));
        assert_eq!(scalar_from_f64(&var("on", VarType::Boolean), 0.0).unwrap(), Value::Bool(false));
        assert!(scalar_from_f64(&var("on", VarType::Boolean), f64::NAN).unwrap_err().0.contains("'on'"));
        assert!(scalar_from_f64(&var("id", VarType::Int32), f64::NAN).unwrap_err().0.contains("'id'"));
        assert!(scalar_from_f64(&var("s", VarType::String), 1.0).is_err());
    }

    #[test]
    fn scenario_values_convert_with_the_same_checks() {
        let id = var("target_id", VarType::Int32);
        let t = |s: &str| -> toml::Value { s.parse::<toml::Table>().unwrap()["v"].clone() };
        assert_eq!(from_toml(&id, &t("v = 3")).unwrap(), Value::I32(3));
        assert_eq!(from_toml(&id, &t("v = 3.0")).unwrap(), Value::I32(3));
        assert!(from_toml(&id, &t("v = 3.5")).unwrap_err().0.contains("3.5 is not an integer"));
        assert!(from_toml(&id, &t("v = nan")).unwrap_err().0.contains("not a finite number"));
        assert!(from_toml(&id, &t("v = 4294967296")).unwrap_err().0.contains("4294967296 is out of range for Int32"));
        assert!(from_toml(&id, &t("v = true"))
            .unwrap_err()
            .0
            .contains("'target_id': value true does not fit type Int32"));
        assert_eq!(from_toml(&var("x", VarType::Float64), &t("v = 2")).unwrap(), Value::F64(2.0));
    }
}
