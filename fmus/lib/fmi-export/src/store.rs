//! Current values of all of a model's variables, indexed like its variable table.

use crate::var::{Start, Var};
use serde::{Deserialize, Serialize};

/// One variable's current value.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Value {
    Float64(f64),
    Int32(i32),
    Int64(i64),
    Boolean(bool),
    String(String),
    Binary(Vec<u8>),
}

impl Value {
    /// The very same value: floats bit for bit (so -0.0 differs from 0.0 and a NaN equals
    /// itself). Setting an identical value changes nothing a model could compute from it.
    pub fn identical(&self, other: &Value) -> bool {
        match (self, other) {
            (Value::Float64(a), Value::Float64(b)) => a.to_bits() == b.to_bits(),
            _ => self == other,
        }
    }

    pub fn from_start(start: &Start) -> Value {
        match *start {
            Start::Float64(v) => Value::Float64(v),
            Start::Int32(v) => Value::Int32(v),
            Start::Int64(v) => Value::Int64(v),
            Start::Boolean(v) => Value::Boolean(v),
            Start::String(v) => Value::String(v.to_string()),
            Start::Binary(v) => Value::Binary(v.to_vec()),
        }
    }
}

/// Values of a model's variables. Index = position in the model's variable table.
///
/// Typed accessors panic on a type mismatch: that is a bug in the model (its table and its
/// code disagree), caught by the model's own tests; the export layer catches the unwind.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Store {
    values: Vec<Value>,
}

impl Store {
    /// Start values of every variable in `vars`.
    pub fn new(vars: &[Var]) -> Store {
        Store { values: vars.iter().map(|v| Value::from_start(&v.start)).collect() }
    }
    pub fn len(&self) -> usize {
        self.values.len()
    }
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }
    pub fn value(&self, i: usize) -> &Value {
        &self.values[i]
    }
    pub fn value_mut(&mut self, i: usize) -> &mut Value {
        &mut self.values[i]
    }

    pub fn f64(&self, i: usize) -> f64 {
        match &self.values[i] {
            Value::Float64(v) => *v,
            other => panic!("variable {i} is {other:?}, not Float64"),
        }
    }
    pub fn set_f64(&mut self, i: usize, v: f64) {
        match &mut self.values[i] {
            Value::Float64(x) => *x = v,
            other => panic!("variable {i} is {other:?}, not Float64"),
        }
    }
    pub fn i32(&self, i: usize) -> i32 {
        match &self.values[i] {
            Value::Int32(v) => *v,
            other => panic!("variable {i} is {other:?}, not Int32"),
        }
    }
    pub fn set_i32(&mut self, i: usize, v: i32) {
        match &mut self.values[i] {
            Value::Int32(x) => *x = v,
            other => panic!("variable {i} is {other:?}, not Int32"),
        }
    }
    pub fn i64(&self, i: usize) -> i64 {
        match &self.values[i] {
            Value::Int64(v) => *v,
            other => panic!("variable {i} is {other:?}, not Int64"),
        }
    }
    pub fn set_i64(&mut self, i: usize, v: i64) {
        match &mut self.values[i] {
            Value::Int64(x) => *x = v,
            other => panic!("variable {i} is {other:?}, not Int64"),
        }
    }
    pub fn bool(&self, i: usize) -> bool {
        match &self.values[i] {
            Value::Boolean(v) => *v,
            other => panic!("variable {i} is {other:?}, not Boolean"),
        }
    }
    pub fn set_bool(&mut self, i: usize, v: bool) {
        match &mut self.values[i] {
            Value::Boolean(x) => *x = v,
            other => panic!("variable {i} is {other:?}, not Boolean"),
        }
    }
    pub fn string(&self, i: usize) -> &str {
        match &self.values[i] {
            Value::String(v) => v,
            other => panic!("variable {i} is {other:?}, not String"),
        }
    }
    pub fn binary(&self, i: usize) -> &[u8] {
        match &self.values[i] {
            Value::Binary(v) => v,
            other => panic!("variable {i} is {other:?}, not Binary"),
        }
    }
    /// A Binary value to write in place.
    pub fn binary_mut(&mut self, i: usize) -> &mut Vec<u8> {
        match &mut self.values[i] {
            Value::Binary(x) => x,
            other => panic!("variable {i} is {other:?}, not Binary"),
        }
    }
    /// Replace a Binary value (reuses the allocation).
    pub fn set_binary(&mut self, i: usize, bytes: &[u8]) {
        match &mut self.values[i] {
            Value::Binary(x) => {
                x.clear();
                x.extend_from_slice(bytes);
            }
            other => panic!("variable {i} is {other:?}, not Binary"),
        }
    }
}

/// A Float64 parameter that must be finite and pass `ok`; the error names the variable and
/// says what was expected (`what`, e.g. "positive"), so every model reports bad parameters
/// the same way.
pub fn checked_f64(io: &Store, vars: &[Var], i: usize, ok: impl Fn(f64) -> bool, what: &str) -> Result<f64, String> {
    let v = io.f64(i);
    if v.is_finite() && ok(v) {
        Ok(v)
    } else {
        Err(format!("parameter {} must be {what}, got {v}", vars[i].name))
    }
}
