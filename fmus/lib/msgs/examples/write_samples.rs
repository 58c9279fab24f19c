//! Writes the shared sample messages for the Python cross-check
//! (tests/test_msgs_crosscheck.py):
//!
//! `write_samples DIR` writes, per sample, `DIR/<name>.cdr` (header + body) and
//! `DIR/<name>.ros2msg` (the MCAP schema text), plus `DIR/index.tsv` (`name<TAB>type`).
//!
//! `write_samples --check DIR` decodes every `DIR/<name>.cdr` with this crate and compares
//! with the sample value: used on bytes the Python peers serialized.

#[path = "../tests/common/samples.rs"]
mod samples;

use std::path::PathBuf;
use std::process::ExitCode;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (check, dir) = match args.as_slice() {
        [d] => (false, PathBuf::from(d)),
        [flag, d] if flag == "--check" => (true, PathBuf::from(d)),
        _ => {
            eprintln!("usage: write_samples [--check] DIR");
            return ExitCode::from(2);
        }
    };
    let samples = samples::all_samples();
    if check {
        let mut failed = 0;
        let mut checked = 0;
        for s in &samples {
            let path = dir.join(format!("{}.cdr", s.name));
            let Ok(bytes) = std::fs::read(&path) else {
                continue;
            };
            checked += 1;
            if let Err(e) = (s.check)(&bytes) {
                eprintln!("{}: {e}", path.display());
                failed += 1;
            }
        }
        println!("checked {checked} files, {failed} failed");
        return if failed == 0 && checked > 0 { ExitCode::SUCCESS } else { ExitCode::FAILURE };
    }
    if let Err(e) = std::fs::create_dir_all(&dir) {
        eprintln!("cannot create {}: {e}", dir.display());
        return ExitCode::FAILURE;
    }
    let mut index = String::new();
    for s in &samples {
        let schema = agrisim_msgs::ros2msg_schema(s.type_name).expect("schema for sample type");
        let written = std::fs::write(dir.join(format!("{}.cdr", s.name)), &s.bytes)
            .and_then(|_| std::fs::write(dir.join(format!("{}.ros2msg", s.name)), schema));
        if let Err(e) = written {
            eprintln!("cannot write sample {}: {e}", s.name);
            return ExitCode::FAILURE;
        }
        index.push_str(&format!("{}\t{}\n", s.name, s.type_name));
    }
    if let Err(e) = std::fs::write(dir.join("index.tsv"), index) {
        eprintln!("cannot write index: {e}");
        return ExitCode::FAILURE;
    }
    println!("wrote {} samples to {}", samples.len(), dir.display());
    ExitCode::SUCCESS
}
