//! The `joints` parameter: which message joint drives which output.

use crate::ports::N;

/// Parses "a,b,c": 1 to [`N`] distinct, non-empty names.
pub fn parse(text: &str) -> Result<Vec<String>, String> {
    let names: Vec<String> = text.split(',').map(|s| s.trim().to_owned()).collect();
    if names.is_empty() || names.len() > N || names.iter().any(|n| n.is_empty()) {
        return Err(format!("parameter joints must list 1 to {N} comma-separated joint names, got {text:?}"));
    }
    for (i, n) in names.iter().enumerate() {
        if names[..i].contains(n) {
            return Err(format!("parameter joints names {n:?} twice"));
        }
    }
    Ok(names)
}

/// For each column of a message's `joint_names`, the output index it drives; every configured
/// joint must be named exactly once.
pub fn columns(joints: &[String], names: &[String]) -> Result<Vec<usize>, String> {
    let mut cols = Vec::with_capacity(names.len());
    for name in names {
        let Some(i) = joints.iter().position(|j| j == name) else {
            return Err(format!("unknown joint name {name:?} (this adapter drives {})", joints.join(", ")));
        };
        if cols.contains(&i) {
            return Err(format!("joint name {name:?} given twice"));
        }
        cols.push(i);
    }
    if let Some(missing) = (0..joints.len()).find(|i| !cols.contains(i)) {
        return Err(format!("joint {:?} missing from joint_names", joints[missing]));
    }
    Ok(cols)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_map_to_outputs_in_any_order_and_mistakes_are_named() {
        let j = parse(" a, b ,c").unwrap();
        assert_eq!(columns(&j, &["c".into(), "a".into(), "b".into()]).unwrap(), [2, 0, 1]);
        assert!(columns(&j, &["a".into(), "b".into(), "x".into()]).unwrap_err().contains("unknown joint name \"x\""));
        assert!(columns(&j, &["a".into(), "b".into()]).unwrap_err().contains("\"c\" missing"));
        assert!(columns(&j, &["a".into(), "a".into(), "b".into()]).unwrap_err().contains("twice"));
        assert!(parse("a,,b").is_err() && parse("a,a").is_err() && parse("1,2,3,4,5,6,7,8").is_err());
    }
}
