//! Model exchange under the master's RK4 ([`agrisim_cosim::me`]): the Oscillator FMU
//! (fmus/oscillator, ME only, FMI 3 and FMI 2 builds) integrated by the engine matches the
//! damped oscillator's closed form, written here from the textbook formula, and the error
//! falls by RK4's 2^4 when the step is halved, also across a time event (a velocity kick)
//! that does not fall on a step boundary.
//!
//! Needs the packed FMUs (target/fmu).

use std::path::{Path, PathBuf};

use agrisim_cosim::archive::FmuArchive;
use agrisim_cosim::model_description::{FmiVersion, Interface};
use agrisim_cosim::system::instantiate_archive;

const OMEGA: f64 = 2.0;
const ZETA: f64 = 0.1;
const X0: f64 = 1.0;
const KICK_T: f64 = 1.234;
const KICK_DV: f64 = 0.5;

fn fmu(version: &str) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/fmu");
    let p = if version == "3" { root.join("Oscillator.fmu") } else { root.join("fmi2/Oscillator.fmu") };
    assert!(p.exists(), "{} not packed: run `target/release/agrisim fmu pack`", p.display());
    p
}

/// Free response of x'' + 2 zeta omega x' + omega^2 x = 0 (underdamped) after dt.
fn free(x0: f64, v0: f64, dt: f64) -> (f64, f64) {
    let wd = OMEGA * (1.0 - ZETA * ZETA).sqrt();
    let (a, b) = (x0, (v0 + ZETA * OMEGA * x0) / wd);
    let e = (-ZETA * OMEGA * dt).exp();
    let (c, s) = ((wd * dt).cos(), (wd * dt).sin());
    let x = e * (a * c + b * s);
    let v = e * (-a * wd * s + b * wd * c) - ZETA * OMEGA * x;
    (x, v)
}

/// The closed form with the kick at KICK_T.
fn exact(t: f64) -> (f64, f64) {
    if t < KICK_T {
        return free(X0, 0.0, t);
    }
    let (x, v) = free(X0, 0.0, KICK_T);
    free(x, v + KICK_DV, t - KICK_T)
}

/// Runs the FMU to `t_end` with step h; returns the final (x, v) and the largest error
/// along the way.
fn run(version: &str, h: f64, t_end: f64) -> ((f64, f64), f64) {
    let cache = tempfile::tempdir().unwrap();
    let a = FmuArchive::open(&fmu(version), cache.path()).unwrap();
    assert_eq!(a.md.interface, Interface::ModelExchange);
    assert_eq!(a.md.version, if version == "3" { FmiVersion::V3 } else { FmiVersion::V2 });
    let vr = |n: &str| a.md.variable(n).unwrap().value_reference;
    let mut inst = instantiate_archive(&a, "osc", false).unwrap();
    assert_eq!(inst.interface(), Interface::ModelExchange);
    inst.set_f64(&[vr("omega"), vr("zeta"), vr("x0"), vr("v0")], &[OMEGA, ZETA, X0, 0.0]).unwrap();
    inst.set_f64(&[vr("kick_time"), vr("kick_dv")], &[KICK_T, KICK_DV]).unwrap();
    inst.enter_initialization_mode(0.0, None).unwrap();
    inst.exit_initialization_mode().unwrap();
    let n = (t_end / h).round() as usize;
    let mut worst: f64 = 0.0;
    let mut xv = [0.0; 2];
    for k in 0..n {
        let t = k as f64 * h;
        let r = inst.do_step(t, h).unwrap();
        assert!(!r.terminate_simulation);
        inst.get_f64(&[vr("x"), vr("v")], &mut xv).unwrap();
        let (x, v) = exact(t + h);
        worst = worst.max((xv[0] - x).abs()).max((xv[1] - v).abs());
    }
    inst.terminate().unwrap();
    ((xv[0], xv[1]), worst)
}

#[test]
fn rk4_matches_the_closed_form_and_converges_at_fourth_order() {
    for version in ["3", "2"] {
        let t_end = 4.0;
        let (end_h, err_h) = run(version, 0.04, t_end);
        let (_, err_h2) = run(version, 0.02, t_end);
        let (x, v) = exact(t_end);
        assert!((end_h.0 - x).abs() < 1e-5 && (end_h.1 - v).abs() < 1e-5, "FMI {version}: {end_h:?} vs {:?}", (x, v));
        let ratio = err_h / err_h2;
        eprintln!("FMI {version}: max error {err_h:.3e} (h = 0.04 s), {err_h2:.3e} (h = 0.02 s), ratio {ratio:.2}");
        // RK4: halving the step divides the global error by about 16 (the kick is stepped to
        // exactly, so the event costs no order).
        assert!((12.0..=20.0).contains(&ratio), "FMI {version}: error {err_h:e} -> {err_h2:e}, ratio {ratio}");
        // Without the event split the kick would land up to one step late: an O(h) error.
        assert!(err_h2 < 1e-6, "FMI {version}: error {err_h2:e}");
    }
}

#[test]
fn fmi3_and_fmi2_builds_integrate_identically() {
    let (a, ea) = run("3", 0.02, 2.0);
    let (b, eb) = run("2", 0.02, 2.0);
    assert_eq!((a.0.to_bits(), a.1.to_bits(), ea.to_bits()), (b.0.to_bits(), b.1.to_bits(), eb.to_bits()));
}
