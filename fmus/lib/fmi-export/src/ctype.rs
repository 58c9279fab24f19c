//! Conversion between C argument types of the `Get*`/`Set*` functions and stored [`Value`]s.
//!
//! One marker type per C getter/setter family lets a single generic get/set path serve every
//! type of both APIs. Types this layer never stores (Float32, Int8, ...) accept no variable,
//! so their getters/setters fail with a type-mismatch message naming the variable.

use std::ffi::{c_char, CStr, CString};

use crate::store::Value;

/// One C value type of a `Get*`/`Set*` function family.
pub trait CType {
    /// The element type of the C values array (for Binary: size and data pointer).
    type C: Copy;
    /// True if variables holding `v` can be accessed through this type.
    fn accepts(v: &Value) -> bool;
    /// C representation of `v` (only called when `accepts(v)`). Strings are kept alive in
    /// `strings` until the next call on the instance.
    fn read(v: &Value, strings: &mut Vec<CString>) -> Self::C;
    /// Stored representation of a C value (only called when the target variable accepts this type).
    ///
    /// # Safety
    /// Pointers in `x` must be valid as the FMI standard requires (checked for NULL here).
    unsafe fn decode(x: Self::C) -> Result<Value, String>;
    /// Size in bytes `x` claims (Binary: its size argument; 0 for other types), checked
    /// against the variable's maxSize before anything is read.
    fn size(_x: Self::C) -> usize {
        0
    }
}

macro_rules! direct {
    ($marker:ident, $c:ty, $variant:ident, $doc:literal) => {
        #[doc = $doc]
        pub struct $marker;
        impl CType for $marker {
            type C = $c;
            fn accepts(v: &Value) -> bool {
                matches!(v, Value::$variant(_))
            }
            fn read(v: &Value, _: &mut Vec<CString>) -> $c {
                match v {
                    Value::$variant(x) => *x,
                    _ => Default::default(),
                }
            }
            unsafe fn decode(x: $c) -> Result<Value, String> {
                Ok(Value::$variant(x))
            }
        }
    };
}

direct!(Float64, f64, Float64, "fmi3Float64 / fmi2Real.");
direct!(Int32, i32, Int32, "fmi3Int32 / fmi2Integer.");
direct!(Int64, i64, Int64, "fmi3Int64.");

/// `fmi3Boolean` (C `bool`, read as a byte so any bit pattern from C is defined behaviour).
pub struct Bool3;
impl CType for Bool3 {
    type C = u8;
    fn accepts(v: &Value) -> bool {
        matches!(v, Value::Boolean(_))
    }
    fn read(v: &Value, _: &mut Vec<CString>) -> u8 {
        matches!(v, Value::Boolean(true)) as u8
    }
    unsafe fn decode(x: u8) -> Result<Value, String> {
        Ok(Value::Boolean(x != 0))
    }
}

/// `fmi2Boolean` (C `int`; any non-zero value is true).
pub struct Bool2;
impl CType for Bool2 {
    type C = i32;
    fn accepts(v: &Value) -> bool {
        matches!(v, Value::Boolean(_))
    }
    fn read(v: &Value, _: &mut Vec<CString>) -> i32 {
        matches!(v, Value::Boolean(true)) as i32
    }
    unsafe fn decode(x: i32) -> Result<Value, String> {
        Ok(Value::Boolean(x != 0))
    }
}

/// `fmi3String` / `fmi2String`: NUL-terminated UTF-8.
pub struct Str;
impl CType for Str {
    type C = *const c_char;
    fn accepts(v: &Value) -> bool {
        matches!(v, Value::String(_))
    }
    fn read(v: &Value, strings: &mut Vec<CString>) -> *const c_char {
        let s = match v {
            Value::String(s) => s.split('\0').next().unwrap_or(""),
            _ => "",
        };
        strings.push(CString::new(s).unwrap_or_default());
        strings.last().map_or(std::ptr::null(), |c| c.as_ptr())
    }
    unsafe fn decode(x: *const c_char) -> Result<Value, String> {
        if x.is_null() {
            return Err("the string pointer is NULL".into());
        }
        match CStr::from_ptr(x).to_str() {
            Ok(s) => Ok(Value::String(s.to_owned())),
            Err(_) => Err("the string is not valid UTF-8".into()),
        }
    }
}

/// Data pointer returned for empty binaries (never dangling, never NULL).
static EMPTY: [u8; 1] = [0];

/// `fmi3Binary` with its size.
pub struct Bin;
impl CType for Bin {
    type C = (usize, *const u8);
    fn accepts(v: &Value) -> bool {
        matches!(v, Value::Binary(_))
    }
    fn read(v: &Value, _: &mut Vec<CString>) -> (usize, *const u8) {
        match v {
            Value::Binary(b) if !b.is_empty() => (b.len(), b.as_ptr()),
            _ => (0, EMPTY.as_ptr()),
        }
    }
    unsafe fn decode((size, ptr): (usize, *const u8)) -> Result<Value, String> {
        if size == 0 {
            return Ok(Value::Binary(Vec::new()));
        }
        if ptr.is_null() {
            return Err(format!("the data pointer is NULL but its size is {size}"));
        }
        Ok(Value::Binary(std::slice::from_raw_parts(ptr, size).to_vec()))
    }
    fn size((size, _): (usize, *const u8)) -> usize {
        size
    }
}

macro_rules! unused {
    ($marker:ident, $c:ty) => {
        #[doc = concat!("`fmi3", stringify!($marker), "`: this layer stores no variable of this type.")]
        pub struct $marker;
        impl CType for $marker {
            type C = $c;
            fn accepts(_: &Value) -> bool {
                false
            }
            fn read(_: &Value, _: &mut Vec<CString>) -> $c {
                Default::default()
            }
            unsafe fn decode(_: $c) -> Result<Value, String> {
                Err(concat!("no variable has type ", stringify!($marker)).into())
            }
        }
    };
}

unused!(Float32, f32);
unused!(Int8, i8);
unused!(UInt8, u8);
unused!(Int16, i16);
unused!(UInt16, u16);
unused!(UInt32, u32);
unused!(UInt64, u64);
