//! FMI 2.0 import: every agrisim FMU's FMI 2 build (target/fmu/fmi2, scalar ports only) runs
//! 10 s in the engine; FMI 2 and FMI 3 builds of one model give the same outputs bit for bit
//! on the same inputs; and a system mixing both versions (harvest.ssd with the FMI 2 lift)
//! moves the very same messages and signals as the FMI 3-only system.
//!
//! Needs the packed FMUs (target/fmu, `agrisim fmu pack`).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use agrisim_cosim::archive::FmuArchive;
use agrisim_cosim::model_description::{Causality, FmiVersion, Interface, VarType};
use agrisim_cosim::system::instantiate_archive;
use agrisim_cosim::{FmuInstance, LoadOptions, Master, System};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().unwrap()
}

fn fmu_dir() -> PathBuf {
    let d = root().join("target/fmu");
    assert!(
        d.join("fmi2/Lift.fmu").exists(),
        "{} has no packed FMUs: run `target/release/agrisim fmu pack`",
        d.display()
    );
    d
}

fn packed(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "fmu"))
        .collect();
    v.sort();
    v
}

/// Instantiates, initializes with default parameters, and steps 10 s at 0.02 s; returns
/// the Float64 outputs at the end.
fn run_10s(inst: &mut dyn FmuInstance, archive: &FmuArchive) -> BTreeMap<String, f64> {
    inst.enter_initialization_mode(0.0, None).unwrap();
    inst.exit_initialization_mode().unwrap();
    for k in 0..500 {
        inst.do_step(k as f64 * 0.02, 0.02).unwrap_or_else(|e| panic!("{}: step {k}: {e}", archive.path.display()));
    }
    let outs: Vec<_> =
        archive.md.variables.iter().filter(|v| v.causality == Causality::Output && v.ty == VarType::Float64).collect();
    outs.iter()
        .map(|v| {
            let mut x = [0.0];
            inst.get_f64(&[v.value_reference], &mut x).unwrap();
            (v.name.clone(), x[0])
        })
        .collect()
}

#[test]
fn every_fmi2_build_runs_ten_seconds() {
    let dir = fmu_dir();
    let cache = tempfile::tempdir().unwrap();
    let all = packed(&dir.join("fmi2"));
    assert!(all.len() >= 8, "expected every agrisim FMU in {}, found {}", dir.join("fmi2").display(), all.len());
    for fmu in all {
        let a = FmuArchive::open(&fmu, cache.path()).unwrap();
        assert_eq!(a.md.version, FmiVersion::V2, "{}", fmu.display());
        let mut inst = instantiate_archive(&a, "c", false).unwrap_or_else(|e| panic!("{}: {e}", fmu.display()));
        assert_eq!(inst.fmi_version(), FmiVersion::V2);
        let outs = run_10s(inst.as_mut(), &a);
        assert!(outs.values().all(|x| x.is_finite()), "{}: {outs:?}", fmu.display());
        if a.md.interface == Interface::CoSimulation {
            inst.terminate().unwrap();
        }
    }
}

/// Same model, same inputs: FMI 2 and FMI 3 builds agree bit for bit (one Rust model
/// behind both APIs), also after scalar inputs change mid-run.
#[test]
fn fmi2_and_fmi3_builds_agree_bit_for_bit() {
    let dir = fmu_dir();
    let cache = tempfile::tempdir().unwrap();
    for (name, inputs) in
        [("Lift", vec![("setpoint", 0.6)]), ("ChassisKinematic", vec![("cmd_vx", 0.4), ("cmd_wz", 0.2)])]
    {
        let mut results = vec![];
        for path in [dir.join(format!("{name}.fmu")), dir.join(format!("fmi2/{name}.fmu"))] {
            let a = FmuArchive::open(&path, cache.path()).unwrap();
            let mut inst = instantiate_archive(&a, name, false).unwrap();
            inst.enter_initialization_mode(0.0, None).unwrap();
            inst.exit_initialization_mode().unwrap();
            let mut trace = vec![];
            for k in 0..250 {
                if k == 50 {
                    for (var, x) in &inputs {
                        let vr = a.md.variable(var).unwrap().value_reference;
                        inst.set_f64(&[vr], &[*x]).unwrap();
                    }
                    if let Some(seq) = a.md.variable("cmd_seq") {
                        inst.set_i32(&[seq.value_reference], &[1]).unwrap();
                    }
                }
                inst.do_step(k as f64 * 0.02, 0.02).unwrap();
                for v in a.md.variables.iter().filter(|v| v.causality == Causality::Output && v.ty == VarType::Float64)
                {
                    let mut x = [0.0];
                    inst.get_f64(&[v.value_reference], &mut x).unwrap();
                    trace.push((v.name.clone(), x[0].to_bits()));
                }
            }
            results.push(trace);
        }
        assert!(!results[0].is_empty());
        assert_eq!(results[0], results[1], "{name}: FMI 2 and FMI 3 outputs differ");
        let moved = results[0].iter().any(|(n, x)| (n == "position" || n == "x") && f64::from_bits(*x) > 0.1);
        assert!(moved, "{name}: the inputs did not move the model");
    }
}

/// Every message (route, stamp, bytes) and every signal of a run.
#[derive(Default)]
struct Record {
    messages: Vec<(usize, i64, Vec<u8>)>,
}

impl agrisim_cosim::Hooks for Record {
    fn message(&mut self, _s: &System, route: usize, t_ns: i64, bytes: &[u8]) -> agrisim_error::Result<()> {
        self.messages.push((route, t_ns, bytes.to_vec()));
        Ok(())
    }
    fn scalar_input(&self, connector: &str) -> Option<f64> {
        // Move the lift mid-run so its FMI 2 build has something to do.
        connector.contains("lift").then_some(0.5)
    }
}

/// Every message (route, stamp, bytes) and every step's signals, as bits.
type Trace = (Vec<(usize, i64, Vec<u8>)>, Vec<Vec<u64>>);

fn run_harvest(overrides: BTreeMap<String, String>) -> Trace {
    let cache = tempfile::tempdir().unwrap();
    let mut opts = LoadOptions::new(fmu_dir(), cache.path(), 0.02, 0.1);
    opts.fmu_overrides = overrides;
    let mut system = System::load(&root().join("models/systems/harvest.ssd"), &opts).unwrap();
    system.apply_parameters(&Default::default(), 1, &Default::default()).unwrap();
    let mut master = Master::new(system, 0.02, 0.1).unwrap();
    master.initialize().unwrap();
    let mut rec = Record::default();
    let mut signals = vec![];
    let mut buf = vec![];
    for _ in 0..150 {
        master.advance(&mut rec).unwrap();
        let mut row = vec![];
        for c in &mut master.system.components {
            c.read_signals(&mut buf).unwrap();
            row.extend(buf.iter().map(|x| x.to_bits()));
        }
        signals.push(row);
    }
    (rec.messages, signals)
}

#[test]
fn a_mixed_fmi2_fmi3_harvest_system_matches_the_fmi3_one() {
    let fmi3 = run_harvest(BTreeMap::new());
    let lift2 = fmu_dir().join("fmi2/Lift.fmu").display().to_string();
    let mixed = run_harvest(BTreeMap::from([("lift".to_string(), lift2)]));
    assert!(fmi3.0.len() > 50, "the harvest system sent only {} messages", fmi3.0.len());
    assert_eq!(fmi3.0, mixed.0, "messages differ");
    assert_eq!(fmi3.1, mixed.1, "signals differ");
}
