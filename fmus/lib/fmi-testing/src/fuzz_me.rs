//! Random model-exchange call sequences (FMI 3.0 and FMI 2.0) against the generic API layer,
//! checked by the shadow: the counterpart of [`fuzz_fmi3`](crate::fuzz_fmi3) for models with
//! continuous states. Besides the shadow's checks (no panic escapes, valid statuses, illegal
//! calls fail and are logged, mode and time follow the standard): co-simulation
//! instantiation is refused, states set are read back bit for bit, the event update's
//! outputs are sane (no iteration requested, a next event time after now).

use std::ffi::{c_int, c_void, CString};

use agrisim_fmi::fmi2::{self, CallbackFunctions, EventInfo, FMI2_CO_SIMULATION, FMI2_MODEL_EXCHANGE};
use agrisim_fmi::state::{Mode, Status};
use agrisim_fmi::{fmi3, is_model_exchange, Model};

use crate::args::garbage_ptr;
use crate::logs::{log2, log3, Logs};
use crate::rng::FuzzRng;
use crate::shadow::{check, Must, Outcome, Shadow, Then};
use crate::spec::me as spec;
use crate::states::{pick_state, round_trip};
use crate::structure::assert_valid_table;

/// Which API a case drives.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Api {
    Fmi3,
    Fmi2,
}

fn nx<M: Model>() -> usize {
    M::CONTINUOUS_STATES.len()
}

/// An array length: mostly right, sometimes off by one, sometimes with a NULL array.
fn length(rng: &mut FuzzRng, right: usize) -> (usize, bool, bool) {
    let n = match rng.below(8) {
        0 => right + 1,
        1 if right > 0 => right - 1,
        _ => right,
    };
    let null = rng.chance(5) && n > 0;
    (n, null, n == right && !null)
}

unsafe fn random_call<M: Model>(rng: &mut FuzzRng, api: Api, inst: *mut c_void, sh: &Shadow) -> Outcome {
    let v3 = api == Api::Fmi3;
    let o = |function, mask, status, must, then| Outcome { function, mask, status, must, then };
    let n = nx::<M>();
    match rng.below(24) {
        0 | 1 => {
            let start = if rng.chance(85) { 0.0 } else { rng.f64() };
            let good = start.is_finite();
            let must = if good { Must::Succeed } else { Must::Fail };
            if v3 {
                let s = fmi3::enter_initialization_mode::<M>(inst, 0, 0.0, start, 0, 0.0);
                o(
                    "fmi3EnterInitializationMode",
                    spec::ENTER_INITIALIZATION_MODE,
                    s,
                    must,
                    Then::Mode(Mode::InitializationMode),
                )
            } else if rng.chance(50) {
                let s = fmi2::setup_experiment::<M>(inst, 0, 0.0, start, 0, 0.0);
                o("fmi2SetupExperiment", spec::ENTER_INITIALIZATION_MODE, s, must, Then::Nothing)
            } else {
                let s = fmi2::enter_initialization_mode::<M>(inst);
                let then = Then::Mode(Mode::InitializationMode);
                o("fmi2EnterInitializationMode", spec::ENTER_INITIALIZATION_MODE, s, Must::Succeed, then)
            }
        }
        2 | 3 => {
            let (f, s) = if v3 {
                ("fmi3ExitInitializationMode", fmi3::exit_initialization_mode::<M>(inst))
            } else {
                ("fmi2ExitInitializationMode", fmi2::exit_initialization_mode::<M>(inst))
            };
            o(f, spec::EXIT_INITIALIZATION_MODE, s, Must::Any, Then::Mode(Mode::EventMode))
        }
        4 => {
            if v3 {
                let s = fmi3::enter_event_mode::<M>(inst);
                o("fmi3EnterEventMode", spec::ENTER_EVENT_MODE_3, s, Must::Succeed, Then::Mode(Mode::EventMode))
            } else {
                let s = fmi2::enter_event_mode::<M>(inst);
                o("fmi2EnterEventMode", spec::ENTER_EVENT_MODE_2, s, Must::Succeed, Then::Mode(Mode::EventMode))
            }
        }
        5 | 6 => {
            let null = rng.chance(5);
            let (f, s, need, next) = if v3 {
                let (mut need, mut term, mut nom, mut val, mut def, mut next) = (7u8, 7u8, 7u8, 7u8, 7u8, f64::NAN);
                let s = fmi3::update_discrete_states::<M>(
                    inst,
                    &mut need,
                    &mut term,
                    if null { std::ptr::null_mut() } else { &mut nom },
                    &mut val,
                    &mut def,
                    &mut next,
                );
                if s == Status::Ok {
                    assert!(term == 0 && nom == 0 && val <= 1 && def <= 1, "fmi3UpdateDiscreteStates flags");
                }
                ("fmi3UpdateDiscreteStates", s, need, (def == 1).then_some(next))
            } else {
                let mut ei = EventInfo { new_discrete_states_needed: 7, ..EventInfo::default() };
                let s = fmi2::new_discrete_states::<M>(inst, if null { std::ptr::null_mut() } else { &mut ei });
                let next = (ei.next_event_time_defined == 1).then_some(ei.next_event_time);
                ("fmi2NewDiscreteStates", s, ei.new_discrete_states_needed as u8, next)
            };
            if s == Status::Ok {
                assert_eq!(need, 0, "{f}: the layer never asks for another event iteration");
                if let Some(te) = next {
                    assert!(te > sh.time, "{f}: next event time {te} is not after the current time {}", sh.time);
                }
            }
            o(f, spec::UPDATE_DISCRETE_STATES, s, if null { Must::Fail } else { Must::Any }, Then::Nothing)
        }
        7 => {
            let (f, s) = if v3 {
                ("fmi3EnterContinuousTimeMode", fmi3::enter_continuous_time_mode::<M>(inst))
            } else {
                ("fmi2EnterContinuousTimeMode", fmi2::enter_continuous_time_mode::<M>(inst))
            };
            o(f, spec::ENTER_CONTINUOUS_TIME_MODE, s, Must::Succeed, Then::Mode(Mode::ContinuousTimeMode))
        }
        8 => {
            let null = rng.chance(10);
            let (f, s, enter, term) = if v3 {
                let (mut e, mut t) = (7u8, 7u8);
                let s = fmi3::completed_integrator_step::<M>(
                    inst,
                    1,
                    if null { std::ptr::null_mut() } else { &mut e },
                    &mut t,
                );
                ("fmi3CompletedIntegratorStep", s, e as c_int, t as c_int)
            } else {
                let (mut e, mut t) = (7, 7);
                let s = fmi2::completed_integrator_step::<M>(
                    inst,
                    1,
                    if null { std::ptr::null_mut() } else { &mut e },
                    &mut t,
                );
                ("fmi2CompletedIntegratorStep", s, e, t)
            };
            if s == Status::Ok {
                assert!(enter == 0 && term == 0, "{f}: no step events, no termination");
            }
            o(f, spec::COMPLETED_INTEGRATOR_STEP, s, if null { Must::Fail } else { Must::Succeed }, Then::Nothing)
        }
        9 | 10 => {
            let t = match rng.below(8) {
                0 => rng.f64(),
                1 => sh.time - 0.01,
                _ => sh.time + rng.pick(&[1e-3, 0.01, 0.1, 0.5]),
            };
            let (f, s) = if v3 {
                ("fmi3SetTime", fmi3::set_time::<M>(inst, t))
            } else {
                ("fmi2SetTime", fmi2::set_time::<M>(inst, t))
            };
            let must = if t.is_finite() { Must::Succeed } else { Must::Fail };
            o(f, spec::SET_TIME, s, must, Then::Stepped(t))
        }
        11 | 12 => {
            let (len, null, right) = length(rng, n);
            let x: Vec<f64> =
                (0..len + 1).map(|_| if rng.chance(90) { rng.f64().clamp(-5.0, 5.0) } else { rng.f64() }).collect();
            let finite = x[..len].iter().all(|v| v.is_finite());
            let p = if null { std::ptr::null() } else { x.as_ptr() };
            let (f, s) = if v3 {
                ("fmi3SetContinuousStates", fmi3::set_continuous_states::<M>(inst, p, len))
            } else {
                ("fmi2SetContinuousStates", fmi2::set_continuous_states::<M>(inst, p, len))
            };
            if s == Status::Ok {
                let mut back = vec![f64::NAN; n];
                let r = if v3 {
                    fmi3::get_continuous_states::<M>(inst, back.as_mut_ptr(), n)
                } else {
                    fmi2::get_continuous_states::<M>(inst, back.as_mut_ptr(), n)
                };
                assert_eq!(r, Status::Ok, "{f}: reading the states back failed");
                let same = back.iter().zip(&x).all(|(a, b)| a.to_bits() == b.to_bits());
                assert!(same, "{f}: set {:?}, read back {back:?}", &x[..n]);
            }
            o(
                f,
                spec::SET_CONTINUOUS_STATES,
                s,
                if right && finite { Must::Succeed } else { Must::Fail },
                Then::Nothing,
            )
        }
        13..=15 => {
            let which = rng.below(4);
            let (len, null, right) = length(rng, if which == 2 { 0 } else { n });
            let mut buf = vec![0.0f64; len + 1];
            let p = if null { std::ptr::null_mut() } else { buf.as_mut_ptr() };
            let (f, s, mask, must) = match (which, v3) {
                (0, true) => (
                    "fmi3GetContinuousStateDerivatives",
                    fmi3::get_continuous_state_derivatives::<M>(inst, p, len),
                    spec::GET_CONTINUOUS_3,
                    Must::Any,
                ),
                (0, false) => {
                    ("fmi2GetDerivatives", fmi2::get_derivatives::<M>(inst, p, len), spec::GET_CONTINUOUS_2, Must::Any)
                }
                (1, true) => (
                    "fmi3GetContinuousStates",
                    fmi3::get_continuous_states::<M>(inst, p, len),
                    spec::GET_CONTINUOUS_3,
                    Must::Any,
                ),
                (1, false) => (
                    "fmi2GetContinuousStates",
                    fmi2::get_continuous_states::<M>(inst, p, len),
                    spec::GET_CONTINUOUS_2,
                    Must::Any,
                ),
                (2, true) => (
                    "fmi3GetEventIndicators",
                    fmi3::get_event_indicators::<M>(inst, p, len),
                    spec::GET_CONTINUOUS_3,
                    Must::Any,
                ),
                (2, false) => (
                    "fmi2GetEventIndicators",
                    fmi2::get_event_indicators::<M>(inst, p, len),
                    spec::GET_CONTINUOUS_2,
                    Must::Any,
                ),
                (_, true) => (
                    "fmi3GetNominalsOfContinuousStates",
                    fmi3::get_nominals_of_continuous_states::<M>(inst, p, len),
                    spec::GET_NOMINALS_3,
                    Must::Succeed,
                ),
                (_, false) => (
                    "fmi2GetNominalsOfContinuousStates",
                    fmi2::get_nominals_of_continuous_states::<M>(inst, p, len),
                    spec::GET_NOMINALS_2,
                    Must::Succeed,
                ),
            };
            if s == Status::Ok && which == 3 {
                assert!(buf[..len].iter().all(|v| v.is_finite() && *v > 0.0), "{f}: nominals {buf:?}");
            }
            o(f, mask, s, if right { must } else { Must::Fail }, Then::Nothing)
        }
        16 => {
            let vr = rng.below(M::VARIABLES.len() + 2) as u32;
            let mut v = 0.0f64;
            let ok = vr == 0
                || M::VARIABLES.get(vr as usize - 1).is_some_and(|v| matches!(v.start, agrisim_fmi::Start::Float64(_)));
            let (f, s, mask) = if v3 {
                ("fmi3GetFloat64", fmi3::get_float64::<M>(inst, &vr, 1, &mut v, 1), spec::GET_3)
            } else {
                ("fmi2GetReal", fmi2::get_real::<M>(inst, &vr, 1, &mut v), spec::GET_2)
            };
            o(f, mask, s, if ok { Must::Any } else { Must::Fail }, Then::Nothing)
        }
        17 if v3 => {
            let null = rng.chance(10);
            let mut k = 99usize;
            let states = rng.chance(50);
            let p = if null { std::ptr::null_mut() } else { &mut k };
            let (f, s, want) = if states {
                ("fmi3GetNumberOfContinuousStates", fmi3::get_number_of_continuous_states::<M>(inst, p), n)
            } else {
                ("fmi3GetNumberOfEventIndicators", fmi3::get_number_of_event_indicators::<M>(inst, p), 0)
            };
            if s == Status::Ok {
                assert_eq!(k, want, "{f}");
            }
            o(f, spec::GET_NUMBER_OF, s, if null { Must::Fail } else { Must::Succeed }, Then::Nothing)
        }
        17 | 18 => {
            let (f, s) = if v3 {
                let (mut a, mut b, mut c, mut d) = (0u8, 0u8, 0u8, 0.0);
                ("fmi3DoStep", fmi3::do_step::<M>(inst, sh.time, 0.01, 0, &mut a, &mut b, &mut c, &mut d))
            } else {
                ("fmi2DoStep", fmi2::do_step::<M>(inst, sh.time, 0.01, 0))
            };
            o(f, spec::DO_STEP, s, Must::Fail, Then::Nothing)
        }
        19 => {
            let (f, s) = if v3 {
                ("fmi3Terminate", fmi3::terminate::<M>(inst))
            } else {
                ("fmi2Terminate", fmi2::terminate::<M>(inst))
            };
            o(f, spec::TERMINATE, s, Must::Succeed, Then::Mode(Mode::Terminated))
        }
        20 => {
            let (f, s) = if v3 { ("fmi3Reset", fmi3::reset::<M>(inst)) } else { ("fmi2Reset", fmi2::reset::<M>(inst)) };
            o(f, spec::RESET, s, Must::Any, Then::Mode(Mode::Instantiated))
        }
        21 => {
            let mut p = std::ptr::null_mut();
            let (f, s, mask) = if v3 {
                ("fmi3GetFMUState", fmi3::get_fmu_state::<M>(inst, &mut p), spec::GET_FMU_STATE_3)
            } else {
                ("fmi2GetFMUstate", fmi2::get_fmu_state::<M>(inst, &mut p), spec::GET_FMU_STATE_2)
            };
            o(f, mask, s, Must::Succeed, if s == Status::Ok { Then::NewState(p) } else { Then::Nothing })
        }
        22 => {
            let (p, good) = pick_state(rng, sh);
            let (f, s) = if v3 {
                ("fmi3SetFMUState", fmi3::set_fmu_state::<M>(inst, p))
            } else {
                ("fmi2SetFMUstate", fmi2::set_fmu_state::<M>(inst, p))
            };
            o(f, spec::SET_FMU_STATE, s, if good { Must::Succeed } else { Must::Fail }, Then::Restore(p))
        }
        _ if v3 => {
            let (must, then, s) = round_trip(
                rng,
                sh,
                |st, k| fmi3::serialized_fmu_state_size::<M>(inst, st, k),
                |st, b, k| fmi3::serialize_fmu_state::<M>(inst, st, b, k),
                |b, k, p| fmi3::deserialize_fmu_state::<M>(inst, b, k, p),
                |p| fmi3::free_fmu_state::<M>(inst, p),
            );
            o("fmi3DeserializeFMUState", spec::SET_FMU_STATE, s, must, then)
        }
        _ => {
            let (must, then, s) = round_trip(
                rng,
                sh,
                |st, k| fmi2::serialized_fmu_state_size::<M>(inst, st, k),
                |st, b, k| fmi2::serialize_fmu_state::<M>(inst, st, b.cast(), k),
                |b, k, p| fmi2::deserialize_fmu_state::<M>(inst, b.cast(), k, p),
                |p| fmi2::free_fmu_state::<M>(inst, p),
            );
            o("fmi2DeSerializeFMUstate", spec::SET_FMU_STATE, s, must, then)
        }
    }
}

unsafe fn instantiate<M: Model>(
    api: Api,
    name: &std::ffi::CStr,
    token: &CString,
    env: *mut c_void,
    cs: bool,
) -> *mut c_void {
    match api {
        Api::Fmi3 if cs => fmi3::instantiate_co_simulation::<M>(
            name.as_ptr(),
            token.as_ptr(),
            std::ptr::null(),
            0,
            0,
            0,
            0,
            std::ptr::null(),
            0,
            env,
            Some(log3),
            None,
        ),
        Api::Fmi3 => fmi3::instantiate_model_exchange::<M>(
            name.as_ptr(),
            token.as_ptr(),
            std::ptr::null(),
            0,
            0,
            env,
            Some(log3),
        ),
        Api::Fmi2 => {
            let cb = CallbackFunctions {
                logger: Some(log2()),
                allocate_memory: None,
                free_memory: None,
                step_finished: None,
                component_environment: env,
            };
            let kind = if cs { FMI2_CO_SIMULATION } else { FMI2_MODEL_EXCHANGE };
            fmi2::instantiate::<M>(name.as_ptr(), kind, token.as_ptr(), std::ptr::null(), &cb, 0, 0)
        }
    }
}

fn fuzz_me<M: Model>(api: Api, seed: u64, cases: usize) {
    assert!(is_model_exchange::<M>(), "{}: not a model-exchange model (no CONTINUOUS_STATES)", M::NAME);
    assert_valid_table::<M>();
    let mut rng = FuzzRng::new(seed);
    let token = CString::new(if api == Api::Fmi3 { M::TOKEN } else { M::GUID }).unwrap_or_default();
    type Free = unsafe fn(*mut c_void);
    type Terminate = unsafe fn(*mut c_void) -> Status;
    let (free, terminate): (Free, Terminate) = match api {
        Api::Fmi3 => (fmi3::free_instance::<M>, fmi3::terminate::<M>),
        Api::Fmi2 => (fmi2::free_instance::<M>, fmi2::terminate::<M>),
    };
    for case in 0..cases {
        let mut logs = Box::new(Logs::default());
        let env = (&mut *logs as *mut Logs).cast::<c_void>();
        unsafe {
            let cs = instantiate::<M>(api, c"cs", &token, env, true);
            assert!(cs.is_null(), "{}: a model-exchange FMU instantiated as co-simulation (case {case})", M::NAME);
            assert!(!logs.0.is_empty(), "{}: refused co-simulation instantiation not logged", M::NAME);
            logs.0.clear();
            let inst = instantiate::<M>(api, c"fuzz", &token, env, false);
            assert!(!inst.is_null(), "{}: model-exchange instantiation failed: {:?}", M::NAME, logs.0);
            let mut sh = Shadow { mode: Mode::Instantiated, states: Vec::new(), freed: Vec::new(), time: 0.0 };
            let mut trace = String::new();
            // Bias towards a legal start (initialization, initial event update, continuous
            // time), so that the later modes get exercised.
            let legal_prefix = rng.chance(70);
            for k in 0..10 + rng.below(60) {
                let o = if legal_prefix && k < 4 {
                    let v3 = api == Api::Fmi3;
                    let (f, s, mask, then) = match k {
                        0 if v3 => (
                            "fmi3EnterInitializationMode",
                            fmi3::enter_initialization_mode::<M>(inst, 0, 0.0, 0.0, 0, 0.0),
                            spec::ENTER_INITIALIZATION_MODE,
                            Then::Mode(Mode::InitializationMode),
                        ),
                        0 => (
                            "fmi2EnterInitializationMode",
                            fmi2::enter_initialization_mode::<M>(inst),
                            spec::ENTER_INITIALIZATION_MODE,
                            Then::Mode(Mode::InitializationMode),
                        ),
                        1 if v3 => (
                            "fmi3ExitInitializationMode",
                            fmi3::exit_initialization_mode::<M>(inst),
                            spec::EXIT_INITIALIZATION_MODE,
                            Then::Mode(Mode::EventMode),
                        ),
                        1 => (
                            "fmi2ExitInitializationMode",
                            fmi2::exit_initialization_mode::<M>(inst),
                            spec::EXIT_INITIALIZATION_MODE,
                            Then::Mode(Mode::EventMode),
                        ),
                        2 if v3 => {
                            let (mut a, mut b, mut c, mut d, mut e, mut t) = (0, 0, 0, 0, 0, 0.0);
                            let s =
                                fmi3::update_discrete_states::<M>(inst, &mut a, &mut b, &mut c, &mut d, &mut e, &mut t);
                            ("fmi3UpdateDiscreteStates", s, spec::UPDATE_DISCRETE_STATES, Then::Nothing)
                        }
                        2 => {
                            let mut ei = EventInfo::default();
                            (
                                "fmi2NewDiscreteStates",
                                fmi2::new_discrete_states::<M>(inst, &mut ei),
                                spec::UPDATE_DISCRETE_STATES,
                                Then::Nothing,
                            )
                        }
                        _ if v3 => (
                            "fmi3EnterContinuousTimeMode",
                            fmi3::enter_continuous_time_mode::<M>(inst),
                            spec::ENTER_CONTINUOUS_TIME_MODE,
                            Then::Mode(Mode::ContinuousTimeMode),
                        ),
                        _ => (
                            "fmi2EnterContinuousTimeMode",
                            fmi2::enter_continuous_time_mode::<M>(inst),
                            spec::ENTER_CONTINUOUS_TIME_MODE,
                            Then::Mode(Mode::ContinuousTimeMode),
                        ),
                    };
                    Outcome { function: f, mask, status: s, must: Must::Any, then }
                } else if rng.chance(3) {
                    // NULL and garbage handles: Error, no effect on the real instance.
                    let bad = if rng.chance(50) { std::ptr::null_mut() } else { garbage_ptr(&mut rng) };
                    let s = match api {
                        Api::Fmi3 => fmi3::set_time::<M>(bad, 1.0),
                        Api::Fmi2 => fmi2::set_time::<M>(bad, 1.0),
                    };
                    assert_eq!(s, Status::Error);
                    free(bad);
                    continue;
                } else {
                    random_call::<M>(&mut rng, api, inst, &sh)
                };
                trace.push_str(&format!("  {} -> {:?}\n", o.function, o.status));
                check::<M>(&o, &mut sh, inst, &mut logs, &trace);
            }
            free(inst);
            // The handle is dead now: Error, never a crash.
            assert_eq!(terminate(inst), Status::Error);
        }
    }
}

/// Runs `cases` random FMI 3.0 model-exchange call sequences against `M`.
pub fn fuzz_me3<M: Model>(seed: u64, cases: usize) {
    fuzz_me::<M>(Api::Fmi3, seed, cases)
}

/// Runs `cases` random FMI 2.0 model-exchange call sequences against `M`.
pub fn fuzz_me2<M: Model>(seed: u64, cases: usize) {
    fuzz_me::<M>(Api::Fmi2, seed, cases)
}
