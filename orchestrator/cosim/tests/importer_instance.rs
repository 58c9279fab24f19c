//! Live tests of the FMI 3.0 wrapper against a small C FMU compiled at test time with the
//! system C compiler (skipped, with the reason printed, when there is none). The C model
//! exists only to exercise the importer: every data type, log statuses, Error/Discard/Fatal
//! paths, debug logging, FMU state, and counters that reveal leaked or double-freed instances
//! and calls FMI does not allow (fmi3Terminate outside Step Mode).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

use agrisim_cosim::archive::{FmuArchive, PLATFORM};
use agrisim_cosim::fmi3::{Instance, InstanceState, Status};

const C_SOURCE: &str = r#"
#include <stdbool.h>
#include <stdint.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <stdio.h>

typedef void (*logcb)(void*, int, const char*, const char*);
enum { OK, WARNING, DISCARD, ERROR, FATAL };

typedef struct {
    int freed; void* env; logcb log; bool logging, log_calls;
    double time, x, u; int32_t n, fail; int64_t k; bool flag;
    char s[256]; char res[1024];
    uint8_t bin[256]; size_t bin_len; uint8_t bout[256]; size_t bout_len;
    int mode; /* 0 instantiated, 1 init, 2 step, 3 terminated */
} Inst;
typedef struct { double x; int64_t k; } State;

static int live = 0, double_frees = 0, live_states = 0, bad_terminates = 0;
int test_live_instances(void) { return live; }
int test_double_frees(void) { return double_frees; }
int test_live_states(void) { return live_states; }
int test_bad_terminates(void) { return bad_terminates; }

static void lg(Inst* c, int st, const char* m) { if (c->log) c->log(c->env, st, "test", m); }
/* A debug message: only while debug logging is on for category logCalls. */
static void trace(Inst* c, const char* m) { if (c->log && c->logging && c->log_calls) c->log(c->env, OK, "logCalls", m); }
static int bad_vr(Inst* c, uint32_t vr) { char m[64]; snprintf(m, 64, "unknown value reference %u", vr); lg(c, ERROR, m); return ERROR; }

const char* fmi3GetVersion(void) { return "3.0"; }

void* fmi3InstantiateCoSimulation(const char* name, const char* token, const char* res, bool visible,
    bool loggingOn, bool em, bool er, const uint32_t* req, size_t nreq, void* env, logcb log, void* iu) {
    if (!token || strcmp(token, "{agrisim-test-token}") != 0) {
        if (log) log(env, ERROR, "test", "wrong instantiation token");
        return NULL;
    }
    Inst* c = calloc(1, sizeof(Inst));
    c->env = env; c->log = log; c->logging = loggingOn; c->log_calls = true;
    snprintf(c->res, sizeof c->res, "%s", res ? res : "");
    strcpy(c->s, "hello");
    live++;
    lg(c, OK, name);
    return c;
}
/* Instances are never really freed, so a second free is detectable instead of undefined. */
void fmi3FreeInstance(void* p) { Inst* c = p; if (!c || c->freed) { double_frees++; return; } c->freed = 1; live--; }
int fmi3EnterInitializationMode(void* p, bool td, double tol, double start, bool sd, double stop) {
    Inst* c = p; c->mode = 1; c->time = start; return OK; }
int fmi3ExitInitializationMode(void* p) { Inst* c = p;
    if (c->mode != 1) { lg(c, ERROR, "exit without enter"); return ERROR; } c->mode = 2; return OK; }
#ifndef OMIT_SET_DEBUG_LOGGING
int fmi3SetDebugLogging(void* p, bool on, size_t n, const char* const* cats) { Inst* c = p;
    c->logging = on; c->log_calls = n == 0;
    for (size_t i = 0; i < n; i++) if (strcmp(cats[i], "logCalls") == 0) c->log_calls = true;
    return OK; }
#endif
/* FMI 3.0 allows fmi3Terminate only in Step Mode (among the modes used here). */
int fmi3Terminate(void* p) { Inst* c = p;
    if (c->mode != 2) { bad_terminates++; lg(c, ERROR, "fmi3Terminate outside step mode"); return ERROR; }
    c->mode = 3; return OK; }
int fmi3Reset(void* p) { Inst* c = p; c->mode = 0; c->x = 0; c->k = 0; c->fail = 0; return OK; }
#ifndef OMIT_DOSTEP
int fmi3DoStep(void* p, double t, double h, bool nos, bool* ehn, bool* term, bool* er, double* lst) {
    Inst* c = p;
    if (c->mode != 2) { lg(c, ERROR, "fmi3DoStep called outside step mode"); return ERROR; }
    if (c->fail == 1) { char m[128]; snprintf(m, 128, "commanded failure at t=%g", t); lg(c, ERROR, m); return ERROR; }
    if (c->fail == 2) { lg(c, FATAL, "commanded fatal"); return FATAL; }
    if (c->fail == 4) { lg(c, WARNING, "commanded discard: stopped half way");
        c->time = t + h / 2; *ehn = false; *term = false; *er = false; *lst = t + h / 2; return DISCARD; }
    trace(c, "fmi3DoStep");
    c->x += c->u * h; c->k += 1; c->time = t + h;
    c->bout_len = c->bin_len;
    for (size_t i = 0; i < c->bin_len; i++) c->bout[i] = c->bin[c->bin_len - 1 - i];
    *ehn = false; *term = c->flag; *er = false; *lst = t + h;
    if (c->fail == 3) { lg(c, WARNING, "commanded warning"); return WARNING; }
    return OK;
}
#endif
int fmi3GetFloat64(void* p, const uint32_t* vr, size_t n, double* v, size_t nv) { Inst* c = p;
    for (size_t i = 0; i < n; i++) switch (vr[i]) {
        case 0: v[i] = c->time; break; case 1: v[i] = c->x; break; case 2: v[i] = c->u; break;
        default: return bad_vr(c, vr[i]); }
    return OK; }
int fmi3SetFloat64(void* p, const uint32_t* vr, size_t n, const double* v, size_t nv) { Inst* c = p;
    for (size_t i = 0; i < n; i++) switch (vr[i]) { case 2: c->u = v[i]; break; default: return bad_vr(c, vr[i]); }
    return OK; }
int fmi3GetInt32(void* p, const uint32_t* vr, size_t n, int32_t* v, size_t nv) { Inst* c = p;
    for (size_t i = 0; i < n; i++) switch (vr[i]) { case 3: v[i] = c->n; break; case 9: v[i] = c->fail; break;
        default: return bad_vr(c, vr[i]); }
    return OK; }
int fmi3SetInt32(void* p, const uint32_t* vr, size_t n, const int32_t* v, size_t nv) { Inst* c = p;
    for (size_t i = 0; i < n; i++) switch (vr[i]) { case 3: c->n = v[i]; break; case 9: c->fail = v[i]; break;
        default: return bad_vr(c, vr[i]); }
    return OK; }
int fmi3GetInt64(void* p, const uint32_t* vr, size_t n, int64_t* v, size_t nv) { Inst* c = p;
    for (size_t i = 0; i < n; i++) switch (vr[i]) { case 4: v[i] = c->k; break; default: return bad_vr(c, vr[i]); }
    return OK; }
int fmi3SetInt64(void* p, const uint32_t* vr, size_t n, const int64_t* v, size_t nv) { Inst* c = p;
    return bad_vr(c, n ? vr[0] : 0); }
int fmi3GetBoolean(void* p, const uint32_t* vr, size_t n, bool* v, size_t nv) { Inst* c = p;
    for (size_t i = 0; i < n; i++) switch (vr[i]) { case 5: v[i] = c->flag; break; default: return bad_vr(c, vr[i]); }
    return OK; }
int fmi3SetBoolean(void* p, const uint32_t* vr, size_t n, const bool* v, size_t nv) { Inst* c = p;
    for (size_t i = 0; i < n; i++) switch (vr[i]) { case 5: c->flag = v[i]; break; default: return bad_vr(c, vr[i]); }
    return OK; }
int fmi3GetString(void* p, const uint32_t* vr, size_t n, const char** v, size_t nv) { Inst* c = p;
    for (size_t i = 0; i < n; i++) switch (vr[i]) { case 6: v[i] = c->s; break; case 10: v[i] = c->res; break;
        default: return bad_vr(c, vr[i]); }
    return OK; }
int fmi3SetString(void* p, const uint32_t* vr, size_t n, const char* const* v, size_t nv) { Inst* c = p;
    for (size_t i = 0; i < n; i++) switch (vr[i]) { case 6: snprintf(c->s, sizeof c->s, "%s", v[i]); break;
        default: return bad_vr(c, vr[i]); }
    return OK; }
int fmi3GetBinary(void* p, const uint32_t* vr, size_t n, size_t* sz, const uint8_t** v, size_t nv) { Inst* c = p;
    for (size_t i = 0; i < n; i++) switch (vr[i]) {
        case 7: sz[i] = c->bin_len; v[i] = c->bin; break; case 8: sz[i] = c->bout_len; v[i] = c->bout; break;
        default: return bad_vr(c, vr[i]); }
    return OK; }
int fmi3SetBinary(void* p, const uint32_t* vr, size_t n, const size_t* sz, const uint8_t* const* v, size_t nv) { Inst* c = p;
    for (size_t i = 0; i < n; i++) switch (vr[i]) {
        case 7: if (sz[i] > sizeof c->bin) { lg(c, ERROR, "binary too long"); return ERROR; }
                memcpy(c->bin, v[i], sz[i]); c->bin_len = sz[i]; break;
        default: return bad_vr(c, vr[i]); }
    return OK; }
#ifndef OMIT_STATE
int fmi3GetFMUState(void* p, void** s) { Inst* c = p; State* st = malloc(sizeof(State));
    st->x = c->x; st->k = c->k; *s = st; live_states++; return OK; }
int fmi3SetFMUState(void* p, void* s) { Inst* c = p; State* st = s; c->x = st->x; c->k = st->k; return OK; }
int fmi3FreeFMUState(void* p, void** s) { if (*s) { free(*s); *s = NULL; live_states--; } return OK; }
#endif
"#;

fn model_description(token: &str, can_get_and_set_state: bool) -> String {
    format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="3.0" modelName="TestModel" instantiationToken="{token}">
  <CoSimulation modelIdentifier="testmodel" canGetAndSetFMUState="{can_get_and_set_state}"/>
  <LogCategories>
    <Category name="logStatusWarning"/>
    <Category name="logCalls"/>
  </LogCategories>
  <DefaultExperiment stepSize="0.1"/>
  <ModelVariables>
    <Float64 name="time" valueReference="0" causality="independent" variability="continuous"/>
    <Float64 name="x" valueReference="1" causality="output"/>
    <Float64 name="u" valueReference="2" causality="input" start="0"/>
    <Int32 name="n" valueReference="3" causality="input" start="0"/>
    <Int64 name="k" valueReference="4" causality="output"/>
    <Boolean name="flag" valueReference="5" causality="input" start="false"/>
    <String name="s" valueReference="6" causality="parameter" variability="tunable"><Start value="hello"/></String>
    <Binary name="bin" valueReference="7" causality="input" mimeType="application/x-test"><Start value=""/></Binary>
    <Binary name="bout" valueReference="8" causality="output" mimeType="application/x-test"/>
    <Int32 name="fail" valueReference="9" causality="input" start="0"/>
    <String name="res" valueReference="10" causality="output"/>
  </ModelVariables>
</fmiModelDescription>"#
    )
}

/// Compiles the C model into `dir`; `None` (with a printed reason) when no C compiler works.
fn compile(dir: &Path, extra: &[&str]) -> Option<PathBuf> {
    let src = dir.join("testmodel.c");
    std::fs::write(&src, C_SOURCE).unwrap();
    let out = dir.join("testmodel.so");
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".to_string());
    let res = Command::new(&cc).args(["-shared", "-fPIC", "-O1", "-o"]).arg(&out).arg(&src).args(extra).output();
    match res {
        Ok(o) if o.status.success() => Some(out),
        Ok(o) => {
            eprintln!("SKIPPED: C compiler '{cc}' failed: {}", String::from_utf8_lossy(&o.stderr));
            None
        }
        Err(e) => {
            eprintln!("SKIPPED: no C compiler '{cc}' to build the test FMU: {e}");
            None
        }
    }
}

fn pack(fmu: &Path, md: &str, so: &Path) {
    let f = std::fs::File::create(fmu).unwrap();
    let mut z = zip::ZipWriter::new(f);
    let opts = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
    z.start_file("modelDescription.xml", opts).unwrap();
    z.write_all(md.as_bytes()).unwrap();
    z.start_file(format!("binaries/{PLATFORM}/testmodel.so"), opts).unwrap();
    z.write_all(&std::fs::read(so).unwrap()).unwrap();
    z.finish().unwrap();
}

struct Fixture {
    /// Keeps the library loaded for the whole test, so its counters survive instances being
    /// dropped (the last `dlclose` would reset them).
    lib: libloading::Library,
    archive: FmuArchive,
    _tmp: tempfile::TempDir,
}

fn fixture(token: &str, extra_cflags: &[&str]) -> Option<Fixture> {
    fixture_with(token, extra_cflags, true)
}

fn fixture_with(token: &str, extra_cflags: &[&str], can_get_and_set_state: bool) -> Option<Fixture> {
    let tmp = tempfile::tempdir().unwrap();
    let so = compile(tmp.path(), extra_cflags)?;
    let fmu = tmp.path().join("TestModel.fmu");
    pack(&fmu, &model_description(token, can_get_and_set_state), &so);
    let archive = FmuArchive::open(&fmu, &tmp.path().join("cache")).unwrap();
    let lib = unsafe { libloading::Library::new(&archive.library_path) }.unwrap();
    Some(Fixture { lib, archive, _tmp: tmp })
}

/// Reads a counter the C model exports (same file, same loaded image, shared globals).
fn counter(fx: &Fixture, name: &str) -> i32 {
    unsafe {
        let f: libloading::Symbol<unsafe extern "C" fn() -> i32> = fx.lib.get(name.as_bytes()).unwrap();
        f()
    }
}

const X: u32 = 1;
const U: u32 = 2;
const N: u32 = 3;
const K: u32 = 4;
const FLAG: u32 = 5;
const S: u32 = 6;
const BIN: u32 = 7;
const BOUT: u32 = 8;
const FAIL: u32 = 9;
const RES: u32 = 10;

/// Through Initialization Mode into Step Mode.
fn start(i: &mut Instance) {
    i.enter_initialization_mode(0.0, Some(10.0)).unwrap();
    i.exit_initialization_mode().unwrap();
}

/// Commands the model's failure mode `code` (see `fail` in the C source) and steps: the error.
fn failing_step(i: &mut Instance, code: i32, t: f64, h: f64) -> agrisim_cosim::fmi3::FmiError {
    i.set_i32(&[FAIL], &[code]).unwrap();
    i.do_step(t, h).unwrap_err()
}

fn ready(fx: &Fixture, name: &str) -> Instance {
    let mut i = Instance::instantiate(&fx.archive, name, true).unwrap();
    start(&mut i);
    i
}

#[test]
fn two_instances_of_one_library_step_independently() {
    let Some(fx) = fixture("{agrisim-test-token}", &[]) else {
        return;
    };
    let mut a = Instance::instantiate(&fx.archive, "left", false).unwrap();
    let mut b = Instance::instantiate(&fx.archive, "right", false).unwrap();
    assert_eq!(counter(&fx, "test_live_instances"), 2);
    a.enter_initialization_mode(0.0, None).unwrap();
    b.enter_initialization_mode(0.0, None).unwrap();
    a.set_f64(&[U], &[2.0]).unwrap();
    b.set_f64(&[U], &[-1.0]).unwrap();
    a.exit_initialization_mode().unwrap();
    b.exit_initialization_mode().unwrap();
    for i in 0..5 {
        let t = i as f64 * 0.1;
        let r = a.do_step(t, 0.1).unwrap();
        assert!(!r.terminate_simulation && !r.early_return);
        assert!((r.last_successful_time - (t + 0.1)).abs() < 1e-12);
        b.do_step(t, 0.1).unwrap();
    }
    let mut x = [0.0; 2];
    a.get_f64(&[X, U], &mut x).unwrap();
    assert!((x[0] - 1.0).abs() < 1e-12 && x[1] == 2.0);
    b.get_f64(&[X], &mut x[..1]).unwrap();
    assert!((x[0] + 0.5).abs() < 1e-12);
    let mut k = [0i64];
    a.get_i64(&[K], &mut k).unwrap();
    assert_eq!(k[0], 5);
    // The instantiation message went to each instance's own log.
    assert_eq!(a.take_log().first().map(|m| m.message.as_str()), Some("left"));
    assert_eq!(b.take_log().first().map(|m| m.message.as_str()), Some("right"));
    assert!(a.take_log().is_empty());
    drop(a);
    assert_eq!(counter(&fx, "test_live_instances"), 1);
    drop(b);
    assert_eq!(counter(&fx, "test_live_instances"), 0);
    assert_eq!(counter(&fx, "test_double_frees"), 0);
}

#[test]
fn every_supported_type_round_trips() {
    let Some(fx) = fixture("{agrisim-test-token}", &[]) else {
        return;
    };
    let mut i = ready(&fx, "types");
    i.set_i32(&[N], &[-42]).unwrap();
    let mut n = [0i32];
    i.get_i32(&[N], &mut n).unwrap();
    assert_eq!(n[0], -42);
    i.set_bool(&[FLAG], &[true]).unwrap();
    let mut f = [false];
    i.get_bool(&[FLAG], &mut f).unwrap();
    assert!(f[0]);
    assert_eq!(i.get_string(S).unwrap(), "hello");
    i.set_string(S, "grüße").unwrap();
    assert_eq!(i.get_string(S).unwrap(), "grüße");
    i.set_binary(BIN, &[1, 2, 3, 0, 255]).unwrap();
    assert_eq!(i.get_binary(BIN).unwrap(), vec![1, 2, 3, 0, 255]);
    let r = i.do_step(0.0, 0.1).unwrap();
    assert!(r.terminate_simulation, "flag=true asks to terminate in this model");
    assert_eq!(i.get_binary(BOUT).unwrap(), vec![255, 0, 3, 2, 1]);
    i.set_binary(BIN, &[]).unwrap();
    i.do_step(0.1, 0.1).unwrap();
    assert_eq!(i.get_binary(BOUT).unwrap(), Vec::<u8>::new());
    // resourcePath: absolute, native, trailing separator, pointing at the unpacked resources/.
    let res = i.get_string(RES).unwrap();
    assert!(res.ends_with("/resources/"), "{res}");
    assert!(Path::new(&res).is_absolute() && Path::new(&res).is_dir(), "{res}");
    // A NUL byte cannot cross the C API.
    let e = i.set_string(S, "a\0b").unwrap_err();
    assert!(e.to_string().contains("NUL"), "{e}");
    // Mismatched lengths are refused before calling the FMU.
    let e = i.set_f64(&[U, X], &[1.0]).unwrap_err();
    assert_eq!(e.status, None);
    assert_eq!(e.variables, vec!["u", "x"]);
}

#[test]
fn errors_name_instance_model_function_variables_and_reason() {
    let Some(fx) = fixture("{agrisim-test-token}", &[]) else {
        return;
    };
    let mut i = ready(&fx, "chassis");
    i.take_log();

    // Unknown value reference: the FMU's reason and the vr appear.
    let mut v = [0.0];
    let e = i.get_f64(&[99], &mut v).unwrap_err();
    assert_eq!(e.status, Some(Status::Error));
    assert_eq!(
        e.to_string(),
        "FMU 'chassis' (TestModel): fmi3GetFloat64(vr 99) returned fmi3Error: unknown value reference 99"
    );
    i.reset().unwrap();
    i.enter_initialization_mode(0.0, None).unwrap();
    i.exit_initialization_mode().unwrap();

    // A warning is not an error, but it is kept in the log.
    i.set_i32(&[FAIL], &[3]).unwrap();
    i.do_step(0.0, 0.02).unwrap();
    let log = i.take_log();
    assert!(log.iter().any(|m| m.status == Status::Warning && m.message == "commanded warning"), "{log:?}");

    // An error carries the time and the FMU's logged reason, and the state becomes Error.
    i.set_i32(&[FAIL], &[1]).unwrap();
    let e = i.do_step(1.24, 0.02).unwrap_err();
    assert_eq!(
        e.to_string(),
        "FMU 'chassis' (TestModel): fmi3DoStep at t=1.24 (h=0.02) returned fmi3Error: commanded failure at t=1.24"
    );
    assert_eq!(e.function, "fmi3DoStep");
    assert_eq!(e.instance, "chassis");
    assert_eq!(e.model, "TestModel");
    assert_eq!(e.messages.len(), 1);
    assert_eq!(i.state(), InstanceState::Error);
    // Messages of a failed call also stay available to take_log.
    assert!(i.take_log().iter().any(|m| m.status == Status::Error));

    // Reset recovers.
    i.reset().unwrap();
    assert_eq!(i.state(), InstanceState::Instantiated);
    i.enter_initialization_mode(0.0, None).unwrap();
    i.exit_initialization_mode().unwrap();
    i.do_step(0.0, 0.02).unwrap();

    // Call-order errors reported by the FMU come through too.
    i.reset().unwrap();
    let e = i.do_step(0.0, 0.02).unwrap_err();
    assert!(e.to_string().ends_with("returned fmi3Error: fmi3DoStep called outside step mode"), "{e}");
}

#[test]
fn fatal_makes_the_wrapper_refuse_everything_and_never_free() {
    let Some(fx) = fixture("{agrisim-test-token}", &[]) else {
        return;
    };
    {
        let mut i = ready(&fx, "arm_left");
        i.set_i32(&[FAIL], &[2]).unwrap();
        let e = i.do_step(0.0, 0.02).unwrap_err();
        assert!(e.is_fatal());
        assert!(e.to_string().contains("returned fmi3Fatal: commanded fatal"), "{e}");
        assert_eq!(i.state(), InstanceState::Fatal);
        let e = i.set_f64(&[U], &[1.0]).unwrap_err();
        assert_eq!(e.status, Some(Status::Fatal));
        assert!(e.to_string().contains("refused"), "{e}");
        assert!(i.reset().is_err());
    }
    // Dropped without fmi3FreeInstance (the standard forbids any call after Fatal).
    assert_eq!(counter(&fx, "test_live_instances"), 1);
    assert_eq!(counter(&fx, "test_double_frees"), 0);
}

#[test]
fn fmu_state_save_restore_and_free() {
    let Some(fx) = fixture("{agrisim-test-token}", &[]) else {
        return;
    };
    let mut i = ready(&fx, "s");
    i.set_f64(&[U], &[1.0]).unwrap();
    i.do_step(0.0, 0.5).unwrap();
    let saved = i.get_state().unwrap();
    i.do_step(0.5, 0.5).unwrap();
    let mut x = [0.0];
    i.get_f64(&[X], &mut x).unwrap();
    assert_eq!(x[0], 1.0);
    i.set_state(&saved).unwrap();
    i.get_f64(&[X], &mut x).unwrap();
    assert_eq!(x[0], 0.5);
    let _kept = i.get_state().unwrap();
    assert_eq!(counter(&fx, "test_live_states"), 2);
    i.free_state(saved).unwrap();
    assert_eq!(counter(&fx, "test_live_states"), 1);

    // A state of another instance is refused.
    let mut other = ready(&fx, "t");
    let foreign = other.get_state().unwrap();
    let e = i.set_state(&foreign).unwrap_err();
    assert!(e.to_string().contains("another instance"), "{e}");
    drop(other);
    drop(i); // frees the remaining state
    assert_eq!(counter(&fx, "test_live_states"), 0);
}

#[test]
fn wrong_token_fails_with_the_fmus_reason() {
    let Some(fx) = fixture("{some-other-token}", &[]) else {
        return;
    };
    let e = Instance::instantiate(&fx.archive, "chassis", false).err().unwrap();
    assert_eq!(
        e.to_string(),
        "FMU 'chassis' (TestModel): fmi3InstantiateCoSimulation failed: wrong instantiation token; returned NULL (instantiation failed)"
    );
}

#[test]
fn missing_symbol_is_named() {
    let Some(fx) = fixture("{agrisim-test-token}", &["-DOMIT_DOSTEP"]) else {
        return;
    };
    let e = Instance::instantiate(&fx.archive, "lift", false).err().unwrap();
    let s = e.to_string();
    assert!(s.starts_with("FMU 'lift' (TestModel): loading failed: shared library '"), "{s}");
    assert!(s.ends_with("testmodel.so' does not export fmi3DoStep"), "{s}");
}

#[test]
fn instances_can_move_to_another_thread() {
    let Some(fx) = fixture("{agrisim-test-token}", &[]) else {
        return;
    };
    let mut i = ready(&fx, "moved");
    let h = std::thread::spawn(move || {
        i.do_step(0.0, 0.1).unwrap();
        i
    });
    let mut i = h.join().unwrap();
    i.terminate().unwrap();
    assert_eq!(i.state(), InstanceState::Terminated);
}

#[test]
fn debug_logging_is_off_unless_asked_and_chosen_by_category() {
    let Some(fx) = fixture("{agrisim-test-token}", &[]) else {
        return;
    };
    let steps = |i: &mut Instance| {
        i.take_log();
        for k in 0..5 {
            i.do_step(k as f64 * 0.1, 0.1).unwrap();
        }
        i.take_log().iter().filter(|m| m.category == "logCalls").count()
    };
    // Off by default: not a single callback while stepping.
    let mut off = Instance::instantiate(&fx.archive, "off", false).unwrap();
    start(&mut off);
    let before = off.log_count();
    assert_eq!(steps(&mut off), 0);
    assert_eq!(off.log_count(), before);
    // loggingOn: every step traced.
    let mut on = ready(&fx, "on");
    assert_eq!(steps(&mut on), 5);
    // fmi3SetDebugLogging by category: another category silences the trace, logCalls brings
    // it back, and logging off stops it.
    on.set_debug_logging(true, &["logStatusWarning"]).unwrap();
    assert_eq!(steps(&mut on), 0);
    off.set_debug_logging(true, &["logCalls"]).unwrap();
    assert_eq!(steps(&mut off), 5);
    off.set_debug_logging(false, &[]).unwrap();
    assert_eq!(steps(&mut off), 0);
    // A category the modelDescription does not declare is refused without calling the FMU.
    let e = on.set_debug_logging(true, &["logCall"]).unwrap_err();
    assert!(e.is_refused());
    assert_eq!(
        e.to_string(),
        "FMU 'on' (TestModel): fmi3SetDebugLogging failed: refused: unknown log category logCall (the FMU declares: logStatusWarning, logCalls)"
    );
    assert_eq!(on.state(), InstanceState::StepMode);
}

#[test]
fn errors_reach_the_user_with_debug_logging_off() {
    let Some(fx) = fixture("{agrisim-test-token}", &[]) else {
        return;
    };
    let mut i = Instance::instantiate(&fx.archive, "chassis", false).unwrap();
    start(&mut i);
    let e = failing_step(&mut i, 1, 0.5, 0.1);
    assert_eq!(
        e.to_string(),
        "FMU 'chassis' (TestModel): fmi3DoStep at t=0.5 (h=0.1) returned fmi3Error: commanded failure at t=0.5"
    );
    assert_eq!(e.messages.len(), 1);
}

#[test]
fn discard_is_its_own_outcome_and_keeps_the_instance_usable() {
    let Some(fx) = fixture("{agrisim-test-token}", &[]) else {
        return;
    };
    let mut i = ready(&fx, "lift");
    let e = failing_step(&mut i, 4, 1.0, 0.1);
    assert!(e.is_discard() && !e.is_fatal() && !e.is_refused());
    assert_eq!(e.status, Some(Status::Discard));
    let r = e.step.expect("the step's flags come with a discard");
    assert!((r.last_successful_time - 1.05).abs() < 1e-12, "{r:?}");
    assert_eq!(
        e.to_string(),
        "FMU 'lift' (TestModel): fmi3DoStep at t=1 (h=0.1) returned fmi3Discard: commanded discard: stopped half way (the step ended early, at t=1.05)"
    );
    // Not the Error state: the instance goes on (outputs, the rest of the step, terminate).
    assert_eq!(i.state(), InstanceState::StepMode);
    let mut t = [0.0];
    i.get_f64(&[0], &mut t).unwrap();
    assert!((t[0] - 1.05).abs() < 1e-12);
    i.set_i32(&[FAIL], &[0]).unwrap();
    i.do_step(1.05, 0.05).unwrap();
    i.terminate().unwrap();
    assert_eq!(counter(&fx, "test_bad_terminates"), 0);
}

#[test]
fn drop_and_terminate_call_fmi3_terminate_only_in_step_mode() {
    let Some(fx) = fixture("{agrisim-test-token}", &[]) else {
        return;
    };
    // Dropped in Initialization Mode, Instantiated, Step Mode, Terminated and Error: freed
    // every time, terminated only from Step Mode.
    let mut init = Instance::instantiate(&fx.archive, "init", false).unwrap();
    init.enter_initialization_mode(0.0, None).unwrap();
    // terminate() in Initialization Mode is refused up front, the state unchanged.
    let e = init.terminate().unwrap_err();
    assert!(e.is_refused(), "{e}");
    assert!(
        e.to_string().starts_with(
            "FMU 'init' (TestModel): fmi3Terminate failed: refused: not allowed in state InitializationMode"
        ),
        "{e}"
    );
    assert_eq!(init.state(), InstanceState::InitializationMode);
    init.exit_initialization_mode().unwrap();
    init.reset().unwrap();
    init.enter_initialization_mode(0.0, None).unwrap();
    let fresh = Instance::instantiate(&fx.archive, "fresh", false).unwrap();
    let stepping = ready(&fx, "stepping");
    let mut done = ready(&fx, "done");
    done.terminate().unwrap();
    assert!(done.terminate().unwrap_err().is_refused());
    let mut failed = ready(&fx, "failed");
    failing_step(&mut failed, 1, 0.0, 0.1);
    assert_eq!(failed.state(), InstanceState::Error);
    assert!(failed.terminate().unwrap_err().is_refused());
    assert_eq!(counter(&fx, "test_live_instances"), 5);
    drop((init, fresh, stepping, done, failed));
    assert_eq!(counter(&fx, "test_live_instances"), 0);
    assert_eq!(counter(&fx, "test_bad_terminates"), 0);
    assert_eq!(counter(&fx, "test_double_frees"), 0);
}

#[test]
fn unsupported_fmu_state_is_refused_up_front_leaving_the_instance_usable() {
    // canGetAndSetFMUState="false" (the functions exist, but the FMU says it cannot).
    let Some(fx) = fixture_with("{agrisim-test-token}", &[], false) else {
        return;
    };
    let mut i = ready(&fx, "world");
    let e = i.get_state().unwrap_err();
    assert!(e.is_refused());
    assert_eq!(
        e.to_string(),
        "FMU 'world' (TestModel): fmi3GetFMUState failed: refused: not supported, the FMU declares canGetAndSetFMUState=\"false\" (not called; instance state unchanged)"
    );
    assert_eq!(counter(&fx, "test_live_states"), 0, "the FMU was not called");
    assert_eq!(i.state(), InstanceState::StepMode);
    i.do_step(0.0, 0.1).unwrap();

    // Declared, but the library does not export the functions (nor fmi3SetDebugLogging).
    let Some(fx) = fixture("{agrisim-test-token}", &["-DOMIT_STATE", "-DOMIT_SET_DEBUG_LOGGING"]) else {
        return;
    };
    let mut i = ready(&fx, "arm");
    let e = i.get_state().unwrap_err();
    assert!(
        e.is_refused()
            && e.to_string()
                .contains("fmi3GetFMUState failed: refused: the shared library does not export this function"),
        "{e}"
    );
    let e = i.set_debug_logging(true, &[]).unwrap_err();
    assert!(
        e.is_refused()
            && e.to_string().starts_with(
                "FMU 'arm' (TestModel): fmi3SetDebugLogging failed: refused: the shared library does not export"
            ),
        "{e}"
    );
    assert_eq!(i.state(), InstanceState::StepMode);
    i.do_step(0.0, 0.1).unwrap();
    i.terminate().unwrap();
}

#[test]
fn restoring_a_state_restores_the_wrappers_state_too() {
    let Some(fx) = fixture("{agrisim-test-token}", &[]) else {
        return;
    };
    let mut i = ready(&fx, "s");
    let saved = i.get_state().unwrap();
    failing_step(&mut i, 1, 0.0, 0.1);
    assert_eq!(i.state(), InstanceState::Error);
    i.set_state(&saved).unwrap();
    assert_eq!(i.state(), InstanceState::StepMode);
    i.set_i32(&[FAIL], &[0]).unwrap();
    i.do_step(0.0, 0.1).unwrap();
}
