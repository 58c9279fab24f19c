//! The `joints` parameter: the names the inputs are reported under.

use crate::ports::N;

/// Parses "a,b,c": 1 to [`N`] distinct, non-empty names.
pub fn parse(text: &str) -> Result<Vec<String>, String> {
    let names: Vec<String> = text.split(',').map(|s| s.trim().to_owned()).collect();
    if names.len() > N || names.iter().any(|n| n.is_empty()) {
        return Err(format!("parameter joints must list 1 to {N} comma-separated joint names, got {text:?}"));
    }
    for (i, n) in names.iter().enumerate() {
        if names[..i].contains(n) {
            return Err(format!("parameter joints names {n:?} twice"));
        }
    }
    Ok(names)
}
