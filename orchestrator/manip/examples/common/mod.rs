//! Command-line handling shared by the benchmark examples (`mod common;` in each).

/// The integer after `name` on the command line (`--n 200`), `default` when it is missing
/// or not a number.
pub fn arg(name: &str, default: u64) -> u64 {
    let a: Vec<String> = std::env::args().collect();
    a.iter()
        .position(|x| x == name)
        .and_then(|i| a.get(i + 1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}
