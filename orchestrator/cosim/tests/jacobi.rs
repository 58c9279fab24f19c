//! `Algorithm::Jacobi`: every FMU-to-FMU input of a step is read from its source's value at
//! the step's start (as libcosim's fixed-step algorithm does), where Gauss-Seidel lets a
//! component read the sources that stepped before it at the step's end. On the FMI 2.0 core
//! system (models/systems/fmi2/core.ssd): the world's base_x input after step k is the
//! chassis' x at t_k with Jacobi, at t_k+1 with Gauss-Seidel (the chassis steps first).
//! tests/test_libcosim.py compares the Jacobi master with libcosim itself.
//!
//! Needs the packed FMI 2.0 FMUs (target/fmu/fmi2).

use agrisim_cosim::master::Algorithm;
use agrisim_cosim::{value, LoadOptions, Master, NoHooks, System};
use std::path::Path;

fn get(master: &mut Master, comp: &str, name: &str) -> f64 {
    let c = master.system.components.iter().position(|c| c.name == comp).expect("component");
    let v = master.system.components[c].archive.md.variable(name).cloned().expect("variable");
    value::get(master.system.components[c].instance.as_mut(), &v).expect("get").as_f64().expect("a number")
}

fn set(master: &mut Master, comp: &str, name: &str, x: value::Value) {
    let c = master.system.components.iter().position(|c| c.name == comp).expect("component");
    let v = master.system.components[c].archive.md.variable(name).cloned().expect("variable");
    value::set(master.system.components[c].instance.as_mut(), &v, &x).expect("set");
}

/// Per step: (chassis.x before the step, chassis.x after it, world.base_x after it).
fn drive(algorithm: Algorithm) -> Vec<(f64, f64, f64)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().unwrap();
    let fmu_dir = root.join("target/fmu/fmi2");
    assert!(
        fmu_dir.join("ChassisKinematic.fmu").exists(),
        "{} has no packed FMUs: run `target/release/agrisim fmu pack`",
        fmu_dir.display()
    );
    let cache = tempfile::tempdir().unwrap();
    let mut system =
        System::load(&root.join("models/systems/fmi2/core.ssd"), &LoadOptions::new(&fmu_dir, cache.path(), 0.02, 0.1))
            .unwrap();
    system.apply_parameters(&Default::default(), 1, &Default::default()).unwrap();
    let mut master = Master::new(system, 0.02, 0.1).unwrap().with_algorithm(algorithm);
    assert_eq!(master.algorithm(), algorithm);
    master.initialize().unwrap();
    set(&mut master, "chassis", "cmd_vx", value::Value::F64(0.5));
    set(&mut master, "chassis", "cmd_seq", value::Value::I32(1));
    let mut out = vec![];
    for _ in 0..20 {
        let before = get(&mut master, "chassis", "x");
        master.advance(&mut NoHooks).unwrap();
        out.push((before, get(&mut master, "chassis", "x"), get(&mut master, "world", "base_x")));
    }
    out
}

#[test]
fn jacobi_reads_every_source_at_the_start_of_the_step() {
    let jacobi = drive(Algorithm::Jacobi);
    let gauss_seidel = drive(Algorithm::GaussSeidel);
    assert!(jacobi.last().unwrap().1 > jacobi[0].0 + 0.01, "the base moves: {jacobi:?}");
    for (k, (&(before, _, base_x), &(_, after, gs_base_x))) in jacobi.iter().zip(&gauss_seidel).enumerate() {
        assert_eq!(base_x, before, "Jacobi, step {k}: the world sees the base at t_k");
        assert_eq!(gs_base_x, after, "Gauss-Seidel, step {k}: the world sees the base at t_k+1");
    }
    assert!(jacobi.iter().zip(&gauss_seidel).any(|(j, g)| j.2 != g.2), "the two algorithms differ");
    // Each chassis trajectory is its own (its inputs come from the lift, which does not move).
    assert!(jacobi.iter().zip(&gauss_seidel).all(|(j, g)| j.1 == g.1));
}
