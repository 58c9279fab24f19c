//! Messages between CDR and Python objects, through the run-time codec
//! (`agrisim_msgs::dynamic`): a message is a dict of its fields in declaration order,
//! `uint8[]` fields are `bytes`, other arrays lists. Encoding takes dicts (missing fields
//! get ROS 2 defaults), lists, tuples, bytes, numbers, bools and strings.

use crate::py_err;
use agrisim_msgs::dynamic::{self, Value};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyBytes, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

pub fn to_py<'py>(py: Python<'py>, v: &Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        Value::Bool(b) => PyBool::new(py, *b).to_owned().into_any(),
        Value::Int(i) => i.into_pyobject(py)?.into_any(),
        Value::UInt(u) => u.into_pyobject(py)?.into_any(),
        Value::Float(x) => PyFloat::new(py, *x).into_any(),
        Value::String(s) => PyString::new(py, s).into_any(),
        Value::Bytes(b) => PyBytes::new(py, b).into_any(),
        Value::Array(a) => PyList::new(py, a.iter().map(|e| to_py(py, e)).collect::<PyResult<Vec<_>>>()?)?.into_any(),
        Value::Struct(fields) => {
            let d = PyDict::new(py);
            for (k, e) in fields {
                d.set_item(k, to_py(py, e)?)?;
            }
            d.into_any()
        }
    })
}

pub fn from_py(obj: &Bound<'_, PyAny>, path: &str) -> PyResult<Value> {
    if let Ok(b) = obj.cast::<PyBool>() {
        return Ok(Value::Bool(b.is_true()));
    }
    if obj.is_instance_of::<PyInt>() {
        return match obj.extract::<i64>() {
            Ok(i) => Ok(Value::Int(i)),
            Err(_) => Ok(Value::UInt(
                obj.extract::<u64>().map_err(|_| py_err(format!("field {path}: integer out of range")))?,
            )),
        };
    }
    if obj.is_instance_of::<PyFloat>() {
        return Ok(Value::Float(obj.extract::<f64>()?));
    }
    if let Ok(s) = obj.cast::<PyString>() {
        return Ok(Value::String(s.to_str()?.to_string()));
    }
    if let Ok(b) = obj.cast::<PyBytes>() {
        return Ok(Value::Bytes(b.as_bytes().to_vec()));
    }
    if let Ok(d) = obj.cast::<PyDict>() {
        let mut fields = Vec::with_capacity(d.len());
        for (k, v) in d.iter() {
            let k: String =
                k.extract().map_err(|_| py_err(format!("field {path}: keys must be field names (strings)")))?;
            let p = if path.is_empty() { k.clone() } else { format!("{path}.{k}") };
            fields.push((k, from_py(&v, &p)?));
        }
        return Ok(Value::Struct(fields));
    }
    if obj.is_instance_of::<PyList>() || obj.is_instance_of::<PyTuple>() {
        let mut items = vec![];
        for (k, e) in obj.try_iter()?.enumerate() {
            items.push(from_py(&e?, &format!("{path}[{k}]"))?);
        }
        return Ok(Value::Array(items));
    }
    // numpy scalars and arrays, bytearray, memoryview: through their Python forms.
    if obj.hasattr("tolist")? {
        return from_py(&obj.call_method0("tolist")?, path);
    }
    if let Ok(b) = obj.extract::<Vec<u8>>() {
        return Ok(Value::Bytes(b));
    }
    Err(py_err(format!(
        "field {}: cannot encode a {}",
        if path.is_empty() { "(message)" } else { path },
        obj.get_type().name()?
    )))
}

/// Decodes CDR bytes (header included) of ROS 2 type `type_name` into a dict.
#[pyfunction]
pub fn decode<'py>(py: Python<'py>, type_name: &str, data: &[u8]) -> PyResult<Bound<'py, PyAny>> {
    let v = dynamic::decode(type_name, data).map_err(|e| py_err(format!("{type_name}: {e}")))?;
    to_py(py, &v)
}

/// Encodes a message (a dict of fields) as CDR bytes of ROS 2 type `type_name`.
#[pyfunction]
pub fn encode<'py>(py: Python<'py>, type_name: &str, msg: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyBytes>> {
    let bytes = encode_value(type_name, msg)?;
    Ok(PyBytes::new(py, &bytes))
}

pub fn encode_value(type_name: &str, msg: &Bound<'_, PyAny>) -> PyResult<Vec<u8>> {
    let v = from_py(msg, "")?;
    dynamic::encode(type_name, &v).map_err(|e| py_err(format!("{type_name}: {e}")))
}

/// Every ROS 2 message type agrisim knows (`pkg/msg/Type`).
#[pyfunction]
pub fn message_types() -> Vec<&'static str> {
    agrisim_msgs::all_type_names().to_vec()
}
