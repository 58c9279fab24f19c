//! The shadow state machine: what a call's outcome must be in the mode the shadow predicts,
//! and the check of every outcome against it and against the real instance.

use std::ffi::c_void;

use agrisim_fmi::state::{Mask, Mode, Status};
use agrisim_fmi::{Instance, Model};

use crate::logs::Logs;

/// What the shadow expects of a call's result.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(crate) enum Must {
    /// Any status (e.g. the model may fail).
    Any,
    /// Arguments are wrong: Error (or Fatal in Fatal).
    Fail,
    /// Arguments are right and no model code runs: OK (or Warning) when the mode allows it.
    Succeed,
}

#[derive(Clone, Copy, Debug)]
pub(crate) enum Then {
    Nothing,
    Mode(Mode),
    Restore(*mut c_void),
    NewState(*mut c_void),
    FreedState(*mut c_void),
    /// A new state holding what the first one holds (a deserialized copy).
    Copied(*mut c_void, *mut c_void),
    Stepped(f64),
}

pub(crate) struct Outcome {
    pub(crate) function: &'static str,
    pub(crate) mask: Mask,
    pub(crate) status: Status,
    pub(crate) must: Must,
    pub(crate) then: Then,
}

/// The shadow of one instance.
pub(crate) struct Shadow {
    pub(crate) mode: Mode,
    /// Live FMU states and the mode they captured.
    pub(crate) states: Vec<(*mut c_void, Mode, f64)>,
    /// Freed state pointers (to pass again: must fail).
    pub(crate) freed: Vec<*mut c_void>,
    pub(crate) time: f64,
}

/// Applies an outcome to the shadow and checks it; `trace` names the calls so far.
pub(crate) unsafe fn check<M: Model>(o: &Outcome, sh: &mut Shadow, inst: *mut c_void, logs: &mut Logs, trace: &str) {
    let before = sh.mode;
    let ctx = || format!("{}: {} returned {:?} in {:?}\ntrace:\n{trace}", M::NAME, o.function, o.status, before);
    let code = o.status as i32;
    assert!((0..=4).contains(&code), "invalid status value; {}", ctx());
    let allowed = o.mask & sh.mode.bit() != 0;
    if sh.mode == Mode::Fatal {
        assert_eq!(o.status, Status::Fatal, "only Fatal in Fatal; {}", ctx());
    } else if !allowed {
        assert_eq!(o.status, Status::Error, "call not allowed in this mode must fail; {}", ctx());
    } else {
        match o.must {
            Must::Fail => assert_eq!(o.status, Status::Error, "bad arguments must fail; {}", ctx()),
            Must::Succeed => assert!(o.status <= Status::Warning, "valid call must succeed; {}", ctx()),
            Must::Any => {}
        }
        assert!(o.status != Status::Discard || o.function.contains("Status"), "unexpected Discard; {}", ctx());
    }
    if o.status >= Status::Error {
        let logged = logs.0.iter().any(|(s, m)| *s >= Status::Error && m.contains(o.function));
        assert!(logged, "failure not logged with the function name; logs: {:?}; {}", logs.0, ctx());
        if o.status == Status::Fatal {
            sh.mode = Mode::Fatal;
        } else {
            sh.mode = Mode::Error;
        }
    } else {
        match o.then {
            Then::Nothing => {}
            Then::Mode(m) => {
                sh.mode = m;
                if m == Mode::Instantiated {
                    sh.time = 0.0;
                }
                if m == Mode::InitializationMode {
                    sh.time = (*inst.cast::<Instance<M>>()).start_time;
                }
            }
            Then::Stepped(end) => sh.time = end,
            Then::NewState(p) => {
                sh.freed.retain(|&q| q != p);
                sh.states.push((p, sh.mode, sh.time));
            }
            Then::Restore(p) => {
                let (_, m, t) =
                    *sh.states.iter().find(|s| s.0 == p).expect("restored a state the shadow does not know");
                sh.mode = m;
                sh.time = t;
            }
            Then::Copied(src, p) => {
                let (_, m, t) =
                    *sh.states.iter().find(|s| s.0 == src).expect("copied a state the shadow does not know");
                sh.freed.retain(|&q| q != p);
                sh.states.push((p, m, t));
            }
            Then::FreedState(p) => {
                if !p.is_null() {
                    sh.states.retain(|s| s.0 != p);
                    sh.freed.push(p);
                }
                if o.function.contains("GetFMU") {
                    // overwrite: same pointer, new content
                    sh.freed.retain(|&q| q != p);
                    sh.states.push((p, sh.mode, sh.time));
                }
            }
        }
    }
    let actual = &*inst.cast::<Instance<M>>();
    assert_eq!(actual.mode, sh.mode, "mode differs from the shadow; {}", ctx());
    assert_eq!(actual.live_states(), sh.states.len(), "live FMU states differ; {}", ctx());
    let running = matches!(sh.mode, Mode::StepMode | Mode::Terminated | Mode::EventMode | Mode::ContinuousTimeMode);
    if running && o.status <= Status::Warning {
        assert_eq!(actual.time, sh.time, "time differs from tc + h (or the time set); {}", ctx());
    }
    logs.0.clear();
}
