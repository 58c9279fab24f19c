//! A benchmark's own options (the row harvest's `--length`): named numbers with a default and
//! a help line. Declared as data, so the command line, the worker processes and Python take
//! them for any benchmark without knowing it.

use agrisim_error::{err, Result};
use std::collections::BTreeMap;
use std::fmt;

/// An option's value; its variant is the option's type.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum OptionValue {
    F64(f64),
    U64(u64),
}

impl OptionValue {
    /// `text` read as a value of this one's type.
    pub fn parse_like(self, text: &str) -> std::result::Result<OptionValue, String> {
        match self {
            OptionValue::F64(_) => {
                text.trim().parse().map(OptionValue::F64).map_err(|_| format!("{text}: not a number"))
            }
            OptionValue::U64(_) => {
                text.trim().parse().map(OptionValue::U64).map_err(|_| format!("{text}: not a whole number >= 0"))
            }
        }
    }
}

/// As typed on a command line (`f64`'s shortest form that reads back to the same value), so a
/// worker process gets exactly its parent's values.
impl fmt::Display for OptionValue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            OptionValue::F64(v) => write!(f, "{v}"),
            OptionValue::U64(v) => write!(f, "{v}"),
        }
    }
}

/// One option a benchmark declares: `--name VALUE` on the command line, `name=VALUE` in
/// Python (hyphens as underscores).
#[derive(Clone, Copy, Debug)]
pub struct OptionSpec {
    pub name: &'static str,
    pub help: &'static str,
    pub default: OptionValue,
}

/// The values of a benchmark's options: every declared option has one (its default unless
/// given), and no other.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OptionValues(BTreeMap<&'static str, OptionValue>);

impl OptionValues {
    /// Every option at its default.
    pub fn defaults(spec: &[OptionSpec]) -> OptionValues {
        OptionValues(spec.iter().map(|o| (o.name, o.default)).collect())
    }

    /// The defaults with `given` (name, text) pairs read over them. Errors name the option and
    /// the benchmark.
    pub fn parse<'a>(
        bench: &str,
        spec: &[OptionSpec],
        given: impl IntoIterator<Item = (&'a str, &'a str)>,
    ) -> Result<OptionValues> {
        let mut v = OptionValues::defaults(spec);
        for (name, text) in given {
            let o = spec.iter().find(|o| o.name == name).ok_or_else(|| {
                let names: Vec<String> = spec.iter().map(|o| format!("--{}", o.name)).collect();
                err!("benchmark {bench} has no option --{name} (its options: {})", list_or_none(&names))
            })?;
            v.set(o.name, o.default.parse_like(text).map_err(|e| err!("benchmark {bench}: --{name} {e}"))?);
        }
        Ok(v)
    }

    /// Sets a declared option (of its declared type).
    pub fn set(&mut self, name: &'static str, value: OptionValue) {
        let old = self.0.get(name).unwrap_or_else(|| panic!("option --{name} is not declared"));
        assert_eq!(std::mem::discriminant(old), std::mem::discriminant(&value), "option --{name} changes type");
        self.0.insert(name, value);
    }

    /// The value of the declared `f64` option `name`.
    pub fn f64(&self, name: &str) -> f64 {
        match self.0.get(name) {
            Some(OptionValue::F64(v)) => *v,
            other => panic!("option --{name} is not a declared f64 option ({other:?})"),
        }
    }

    /// The value of the declared `u64` option `name`.
    pub fn u64(&self, name: &str) -> u64 {
        match self.0.get(name) {
            Some(OptionValue::U64(v)) => *v,
            other => panic!("option --{name} is not a declared u64 option ({other:?})"),
        }
    }

    /// As command-line arguments: `--name value` for every option.
    pub fn args(&self) -> Vec<String> {
        self.0.iter().flat_map(|(k, v)| [format!("--{k}"), v.to_string()]).collect()
    }
}

fn list_or_none(names: &[String]) -> String {
    if names.is_empty() {
        "none".into()
    } else {
        names.join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SPEC: [OptionSpec; 2] = [
        OptionSpec { name: "length", help: "", default: OptionValue::F64(10.0) },
        OptionSpec { name: "flips", help: "", default: OptionValue::U64(3) },
    ];

    #[test]
    fn values_parse_by_their_declared_type_and_print_back_the_same() {
        let v = OptionValues::parse("row", &SPEC, [("length", "0.1")]).unwrap();
        assert_eq!((v.f64("length"), v.u64("flips")), (0.1, 3));
        assert_eq!(v.args(), ["--flips", "3", "--length", "0.1"]);
        let again = OptionValues::parse("row", &SPEC, [("flips", "3"), ("length", "0.1")]).unwrap();
        assert_eq!(again, v);
        let e = OptionValues::parse("row", &SPEC, [("flips", "2.5")]).unwrap_err().to_string();
        assert!(e.contains("--flips 2.5: not a whole number"), "{e}");
        let e = OptionValues::parse("row", &SPEC, [("width", "1")]).unwrap_err().to_string();
        assert!(e.contains("row has no option --width (its options: --length, --flips)"), "{e}");
        assert!(OptionValues::parse("nav", &[], [("x", "1")]).unwrap_err().to_string().contains("options: none"));
    }
}
