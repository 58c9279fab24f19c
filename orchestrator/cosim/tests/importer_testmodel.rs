//! End-to-end import of the export layer's test model (`fmus/testmodel`, crate
//! `agrisim-fmu-testmodel`): pack its built library into an .fmu with the modelDescription.xml
//! it generates itself, then instantiate, initialize, step, set and get every supported type.
//!
//! The test cannot build that crate (it belongs to another package); it is skipped, with the
//! reason printed, until `cargo build -p agrisim-fmu-testmodel` has produced the library.

use std::ffi::{c_char, CStr};
use std::io::Write;
use std::path::PathBuf;

use agrisim_cosim::archive::{FmuArchive, PLATFORM};
use agrisim_cosim::fmi3::{Instance, LogMessage, Status};
use agrisim_cosim::model_description::{Causality, ModelDescription, VarType};

const LIB: &str = "libagrisim_fmu_testmodel.so";

fn find_library() -> Option<PathBuf> {
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..").join("target"));
    ["debug", "release"].iter().map(|p| target.join(p).join(LIB)).find(|p| p.is_file())
}

/// The XML the library generates from its own variable table.
fn description_of(lib_path: &std::path::Path) -> String {
    unsafe {
        let lib = libloading::Library::new(lib_path).unwrap();
        let f: libloading::Symbol<unsafe extern "C" fn() -> *const c_char> =
            lib.get(b"agrisim_model_description_fmi3").expect("the test model exports agrisim_model_description_fmi3");
        let p = f();
        assert!(!p.is_null());
        CStr::from_ptr(p).to_str().unwrap().to_string()
    }
}

/// The TestModel packed into an .fmu (in the returned temporary directory) and opened; `None`
/// (with the reason printed) until its library has been built.
fn test_model() -> Option<(ModelDescription, FmuArchive, tempfile::TempDir)> {
    let Some(lib_path) = find_library() else {
        eprintln!(
            "SKIPPED: {LIB} not found in target/debug or target/release; build it with \
             `cargo build -p agrisim-fmu-testmodel` to run this end-to-end test"
        );
        return None;
    };
    let xml = description_of(&lib_path);
    let md = ModelDescription::parse(&xml, "agrisim_model_description_fmi3()").unwrap();

    let tmp = tempfile::tempdir().unwrap();
    let fmu = tmp.path().join(format!("{}.fmu", md.model_name));
    {
        let mut z = zip::ZipWriter::new(std::fs::File::create(&fmu).unwrap());
        let o = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
        z.start_file("modelDescription.xml", o).unwrap();
        z.write_all(xml.as_bytes()).unwrap();
        z.start_file(format!("binaries/{PLATFORM}/{}.so", md.model_identifier), o).unwrap();
        z.write_all(&std::fs::read(&lib_path).unwrap()).unwrap();
        z.finish().unwrap();
    }
    let archive = FmuArchive::open(&fmu, &tmp.path().join("cache")).unwrap();
    Some((md, archive, tmp))
}

#[test]
fn test_model_imports_steps_and_exchanges_every_type() {
    let Some((md, archive, _tmp)) = test_model() else {
        return;
    };
    let h = md.default_step_size.unwrap_or(0.02);

    // Two instances of the same library at once (as for the two arms).
    let mut a = Instance::instantiate(&archive, "first", true).unwrap();
    let mut b = Instance::instantiate(&archive, "second", false).unwrap();
    for inst in [&mut a, &mut b] {
        inst.enter_initialization_mode(0.0, None).unwrap();
        // Set every settable input of a supported type and read it back.
        for v in md.variables.iter().filter(|v| v.causality == Causality::Input) {
            let vr = v.value_reference;
            match v.ty {
                VarType::Float64 => {
                    inst.set_f64(&[vr], &[0.25]).unwrap();
                    let mut x = [0.0];
                    inst.get_f64(&[vr], &mut x).unwrap();
                    assert_eq!(x[0], 0.25, "{}", v.name);
                }
                VarType::Int32 => {
                    inst.set_i32(&[vr], &[3]).unwrap();
                    let mut x = [0];
                    inst.get_i32(&[vr], &mut x).unwrap();
                    assert_eq!(x[0], 3, "{}", v.name);
                }
                VarType::Int64 => {
                    inst.set_i64(&[vr], &[7]).unwrap();
                    let mut x = [0];
                    inst.get_i64(&[vr], &mut x).unwrap();
                    assert_eq!(x[0], 7, "{}", v.name);
                }
                VarType::Boolean => {
                    inst.set_bool(&[vr], &[true]).unwrap();
                    let mut x = [false];
                    inst.get_bool(&[vr], &mut x).unwrap();
                    assert!(x[0], "{}", v.name);
                }
                VarType::String => {
                    inst.set_string(vr, "agrisim").unwrap();
                    assert_eq!(inst.get_string(vr).unwrap(), "agrisim", "{}", v.name);
                }
                VarType::Binary => {
                    let bytes = [0u8, 1, 0, 0, 42, 0, 255];
                    inst.set_binary(vr, &bytes).unwrap();
                    assert_eq!(inst.get_binary(vr).unwrap(), bytes, "{}", v.name);
                }
                _ => {}
            }
        }
        inst.exit_initialization_mode().unwrap();
    }
    for i in 0..10 {
        let t = i as f64 * h;
        a.do_step(t, h).unwrap_or_else(|e| panic!("{e}"));
        b.do_step(t, h).unwrap_or_else(|e| panic!("{e}"));
    }
    // Every output of a supported type can be read.
    for v in md.variables.iter().filter(|v| v.causality == Causality::Output) {
        let vr = v.value_reference;
        let r = match v.ty {
            VarType::Float64 => a.get_f64(&[vr], &mut [0.0]),
            VarType::Int32 => a.get_i32(&[vr], &mut [0]),
            VarType::Int64 => a.get_i64(&[vr], &mut [0]),
            VarType::Boolean => a.get_bool(&[vr], &mut [false]),
            VarType::String => a.get_string(vr).map(drop),
            VarType::Binary => a.get_binary(vr).map(drop),
            _ => Ok(()),
        };
        r.unwrap_or_else(|e| panic!("{e}"));
    }
    check_test_model_semantics(&md, &mut a, &mut b, h);
    a.terminate().unwrap();
    drop(a);
    drop(b); // still in step mode: Drop terminates and frees it
}

/// Checks specific to the TestModel's documented behaviour (echo, counters, injected faults),
/// run only when its variables are there, so the generic part above survives model changes.
fn check_test_model_semantics(md: &ModelDescription, a: &mut Instance, b: &mut Instance, h: f64) {
    let vr = |n: &str| md.variable(n).map(|v| v.value_reference);
    let (Some(msg_in), Some(msg_out), Some(msg_seq), Some(steps), Some(fault)) =
        (vr("msg_in"), vr("msg_out"), vr("msg_seq"), vr("steps"), vr("fault"))
    else {
        eprintln!("NOTE: TestModel variables changed; semantic checks skipped");
        return;
    };
    let mut n = [0i32];
    a.get_i32(&[steps], &mut n).unwrap();
    assert_eq!(n[0], 10);
    // Binary echo through FMU-owned memory, with the sequence counter advancing.
    let mut seq0 = [0i64];
    a.get_i64(&[msg_seq], &mut seq0).unwrap();
    let msg = [0u8, 1, 0, 0, 6, 0, 0, 0, b'h', b'e', b'l', b'l', b'o', 0];
    a.set_binary(msg_in, &msg).unwrap();
    a.do_step(10.0 * h, h).unwrap();
    assert_eq!(a.get_binary(msg_out).unwrap(), msg);
    let mut seq1 = [0i64];
    a.get_i64(&[msg_seq], &mut seq1).unwrap();
    assert!(seq1[0] > seq0[0], "msg_seq did not advance: {} -> {}", seq0[0], seq1[0]);
    a.take_log();

    // An injected model error: one line naming instance, model, function, time and reason.
    a.set_i32(&[fault], &[1]).unwrap();
    let e = a.do_step(11.0 * h, h).unwrap_err();
    let line = e.to_string();
    assert!(line.starts_with("FMU 'first' (TestModel): fmi3DoStep at t=0.22"), "{line}");
    assert!(line.contains("returned fmi3Error") && line.contains("injected failure at t=0.22"), "{line}");
    a.reset().unwrap();
    a.enter_initialization_mode(0.0, None).unwrap();
    a.exit_initialization_mode().unwrap();
    a.do_step(0.0, h).unwrap();

    // A panic inside the model must come back as a status, not unwind into the importer.
    b.set_i32(&[fault], &[2]).unwrap();
    let e = b.do_step(10.0 * h, h).unwrap_err();
    assert!(e.status.is_some(), "{e}");
    eprintln!("panic in model reported as: {e}");
}

/// Initializes, steps 10 times and reads an output; returns the log messages of all that.
fn run_briefly(i: &mut Instance, md: &ModelDescription) -> Vec<LogMessage> {
    let h = md.default_step_size.unwrap_or(0.02);
    i.enter_initialization_mode(0.0, None).unwrap();
    i.exit_initialization_mode().unwrap();
    let x = md.variable("x").map_or(0, |v| v.value_reference);
    for k in 0..10 {
        i.do_step(k as f64 * h, h).unwrap();
        i.get_f64(&[x], &mut [0.0]).unwrap();
    }
    i.take_log()
}

#[test]
fn test_model_logs_nothing_by_default_and_what_is_asked_otherwise() {
    let Some((md, archive, _tmp)) = test_model() else {
        return;
    };
    // Debug logging off (the default of a run): not one logger callback.
    let mut quiet = Instance::instantiate(&archive, "quiet", false).unwrap();
    assert!(run_briefly(&mut quiet, &md).is_empty());
    assert_eq!(quiet.log_count(), 0);

    // loggingOn: the FMU traces its calls (and whatever else it enables by default).
    let mut all = Instance::instantiate(&archive, "all", true).unwrap();
    let log = run_briefly(&mut all, &md);
    assert!(log.len() >= 20, "{log:?}");
    assert!(log.iter().all(|m| m.status == Status::Ok));

    // One category, as the modelDescription declares it: only that one.
    assert!(md.log_categories.iter().any(|c| c == "logModel"), "{:?}", md.log_categories);
    let mut model_only = Instance::instantiate(&archive, "model_only", false).unwrap();
    model_only.set_debug_logging(true, &["logModel"]).unwrap();
    let log = run_briefly(&mut model_only, &md);
    assert!(!log.is_empty() && log.iter().all(|m| m.category == "logModel"), "{log:?}");
    let e = model_only.set_debug_logging(true, &["logEverything"]).unwrap_err();
    assert!(e.is_refused() && e.to_string().contains("unknown log category logEverything"), "{e}");
}

#[test]
fn test_model_errors_name_instance_and_reason_with_logging_off() {
    let Some((md, archive, _tmp)) = test_model() else {
        return;
    };
    let Some(fault) = md.variable("fault").map(|v| v.value_reference) else {
        eprintln!("NOTE: TestModel has no 'fault' variable; skipped");
        return;
    };
    let mut i = Instance::instantiate(&archive, "faulty", false).unwrap();
    run_briefly(&mut i, &md);
    i.set_i32(&[fault], &[1]).unwrap();
    let h = md.default_step_size.unwrap_or(0.02);
    let e = i.do_step(10.0 * h, h).unwrap_err();
    let line = e.to_string();
    assert!(line.starts_with("FMU 'faulty' (TestModel): fmi3DoStep at t="), "{line}");
    assert!(line.contains("returned fmi3Error") && line.contains("injected failure at t="), "{line}");
    assert_eq!(i.log_count(), e.messages.len() as u64, "only the error was logged");
}
