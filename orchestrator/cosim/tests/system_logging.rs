//! FMU debug logging of a whole system (base.ssd with the packed FMUs in target/fmu): off by
//! default, every category or chosen ones through `LoadOptions::fmu_log`, and a category no
//! FMU declares is a load error.

use agrisim_cosim::{LoadOptions, Master, NoHooks, System};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().unwrap()
}

/// base.ssd loaded with `fmu_log`, initialized and stepped 50 times; the log messages of
/// every component.
fn run(fmu_log: Option<Vec<String>>) -> agrisim_error::Result<Vec<(String, agrisim_cosim::fmi3::LogMessage)>> {
    let fmu_dir = root().join("target/fmu");
    assert!(
        fmu_dir.join("Lift.fmu").exists(),
        "{} has no packed FMUs: run `target/release/agrisim fmu pack`",
        fmu_dir.display()
    );
    let cache = tempfile::tempdir().unwrap();
    let opts = LoadOptions { fmu_log, ..LoadOptions::new(&fmu_dir, cache.path(), 0.02, 0.1) };
    let mut system = System::load(&root().join("models/systems/base.ssd"), &opts)?;
    system.apply_parameters(&Default::default(), 1, &Default::default())?;
    let mut master = Master::new(system, 0.02, 0.1)?;
    master.initialize()?;
    for _ in 0..50 {
        master.advance(&mut NoHooks)?;
    }
    let mut log = vec![];
    for c in &mut master.system.components {
        let kept = c.instance.take_log();
        assert_eq!(
            c.instance.log_count().min(4096),
            kept.len() as u64,
            "{}: every callback is kept, up to the queue's bound",
            c.name
        );
        log.extend(kept.into_iter().map(|m| (c.name.clone(), m)));
    }
    Ok(log)
}

#[test]
fn debug_logging_is_off_by_default() {
    let log = run(None).unwrap();
    assert!(log.is_empty(), "{log:?}");
}

#[test]
fn every_category_or_the_chosen_ones() {
    let all = run(Some(vec![])).unwrap();
    assert!(all.iter().any(|(c, m)| c == "chassis" && m.category == "logCalls"), "{all:?}");
    assert!(all.iter().any(|(c, _)| c == "lift"));
    let calls = run(Some(vec!["logCalls".into()])).unwrap();
    assert!(!calls.is_empty() && calls.iter().all(|(_, m)| m.category == "logCalls"), "{calls:?}");
}

#[test]
fn a_category_no_fmu_declares_is_an_error() {
    let e = run(Some(vec!["logCall".into()])).err().unwrap();
    assert!(e.0.contains("FMU log category 'logCall'") && e.0.contains("base.ssd") && e.0.contains("logCalls"), "{e}");
}
