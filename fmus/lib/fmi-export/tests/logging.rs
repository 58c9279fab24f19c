//! Logging is lazy: with debug logging off nothing is formatted and no callback runs (except
//! for errors and warnings); with it on, exactly the enabled categories are.

use std::cell::Cell;
use std::ffi::{c_char, c_void, CStr, CString};
use std::fmt;

use agrisim_fmi::{fmi3, Log, Model, ModelError, Start, Status, Store, Var};

thread_local! {
    /// Times a log message argument of the model was formatted (on this test's thread).
    static FORMATTED: Cell<usize> = const { Cell::new(0) };
}

/// A message argument that counts its formatting.
struct Counted;

impl fmt::Display for Counted {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        FORMATTED.with(|c| c.set(c.get() + 1));
        f.write_str("counted")
    }
}

agrisim_fmi::variables! { VARIABLES {
    WARN = Var::tunable("warn", Start::Boolean(false)),
    Y = Var::output("y").init_depends_on(&[]),
}}

/// Logs an info message every step, and a warning when `warn` is set.
#[derive(Clone, serde::Serialize, serde::Deserialize)]
struct Chatty;

impl Model for Chatty {
    const NAME: &'static str = "Chatty";
    const DESCRIPTION: &'static str = "logs on every step";
    const VARIABLES: &'static [Var] = VARIABLES;
    agrisim_fmi::whole_state!();
    fn new() -> Self {
        Chatty
    }
    fn initialize(&mut self, _: &mut Store, _: f64, log: &mut dyn Log) -> Result<(), ModelError> {
        log.info(format_args!("initialized: {Counted}"));
        Ok(())
    }
    fn do_step(&mut self, io: &mut Store, t: f64, _: f64, log: &mut dyn Log) -> Result<(), ModelError> {
        log.info(format_args!("step at {t}: {Counted}"));
        if io.bool(WARN) {
            log.warning(format_args!("warned: {Counted}"));
        }
        Ok(())
    }
}

type Calls = Vec<(Status, String, String)>;

unsafe extern "C" fn record(env: *mut c_void, status: Status, category: *const c_char, message: *const c_char) {
    let calls = &mut *(env as *mut Calls);
    calls.push((
        status,
        CStr::from_ptr(category).to_string_lossy().into(),
        CStr::from_ptr(message).to_string_lossy().into(),
    ));
}

/// Runs `steps` steps (warning in the last one) and one failing call with the given logging
/// set-up; returns the callbacks received and the formatting count.
fn run(logging_on: bool, categories: Option<&[&CStr]>, steps: usize) -> (Calls, usize) {
    FORMATTED.with(|c| c.set(0));
    let mut calls: Box<Calls> = Box::default();
    let env = (&mut *calls as *mut Calls).cast();
    let token = CString::new(Chatty::TOKEN).unwrap();
    unsafe {
        let p = fmi3::instantiate_co_simulation::<Chatty>(
            c"chatty".as_ptr(),
            token.as_ptr(),
            std::ptr::null(),
            0,
            logging_on as u8,
            0,
            0,
            std::ptr::null(),
            0,
            env,
            Some(record),
            None,
        );
        assert!(!p.is_null());
        if let Some(cats) = categories {
            let ptrs: Vec<*const c_char> = cats.iter().map(|c| c.as_ptr()).collect();
            assert_eq!(fmi3::set_debug_logging::<Chatty>(p, 1, ptrs.len(), ptrs.as_ptr()), Status::Ok);
        }
        assert_eq!(fmi3::enter_initialization_mode::<Chatty>(p, 0, 0.0, 0.0, 0, 0.0), Status::Ok);
        assert_eq!(fmi3::exit_initialization_mode::<Chatty>(p), Status::Ok);
        let (mut a, mut b, mut c, mut last) = (0, 0, 0, 0.0);
        for k in 0..steps {
            if k + 1 == steps {
                assert_eq!(fmi3::set_boolean::<Chatty>(p, &1, 1, &1, 1), Status::Ok);
            }
            assert_eq!(
                fmi3::do_step::<Chatty>(p, k as f64 * 0.5, 0.5, 0, &mut a, &mut b, &mut c, &mut last),
                Status::Ok
            );
        }
        assert_eq!(fmi3::get_float64::<Chatty>(p, &99, 1, &mut 0.0, 1), Status::Error);
        fmi3::free_instance::<Chatty>(p);
    }
    (*calls, FORMATTED.with(Cell::get))
}

fn count(calls: &Calls, category: &str) -> usize {
    calls.iter().filter(|(_, c, _)| c == category).count()
}

#[test]
fn logging_off_formats_nothing_but_still_reports_warnings_and_errors() {
    let (calls, formatted) = run(false, None, 100);
    assert_eq!(count(&calls, "logModel") + count(&calls, "logCalls"), 0, "{calls:?}");
    assert_eq!(formatted, 1, "only the warning's argument is formatted");
    assert_eq!(count(&calls, "logStatusWarning"), 1);
    assert_eq!(count(&calls, "logStatusError"), 1);
    assert_eq!(calls.len(), 2, "{calls:?}");
    assert!(calls[1].2.contains("fmi3GetFloat64") && calls[1].2.contains("99"), "{calls:?}");
}

#[test]
fn logging_on_without_categories_enables_all() {
    let (calls, formatted) = run(true, None, 100);
    assert_eq!(count(&calls, "logModel"), 101, "initialize + every step");
    assert_eq!(formatted, 102, "the info messages and the warning");
    // Every API call is traced: instantiate is not (no instance yet), the rest are.
    let traced = count(&calls, "logCalls");
    assert_eq!(traced, 2 + 1 + 100 + 1, "enter/exit, set, steps, the failing get: {calls:?}");
    assert_eq!(count(&calls, "logStatusWarning") + count(&calls, "logStatusError"), 2);
}

#[test]
fn categories_select_what_is_formatted() {
    let (calls, formatted) = run(true, Some(&[c"logCalls"]), 100);
    assert_eq!((count(&calls, "logModel"), formatted), (0, 1), "model messages off: only the warning formats");
    assert!(count(&calls, "logCalls") > 100);
    let (calls, formatted) = run(true, Some(&[c"logModel"]), 100);
    // (SetDebugLogging itself is still traced: logging was fully on when it was called.)
    assert_eq!((count(&calls, "logModel"), count(&calls, "logCalls"), formatted), (101, 1, 102), "{calls:?}");
    assert_eq!(count(&calls, "logStatusWarning") + count(&calls, "logStatusError"), 2, "always reported");
}
