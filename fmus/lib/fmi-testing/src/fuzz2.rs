//! Random FMI 2.0 call sequences against the generic API layer, checked by the shadow.

use std::ffi::{c_char, c_int, c_void, CString};

use agrisim_fmi::ctype::{self, CType};
use agrisim_fmi::fmi2::{self, CallbackFunctions};
use agrisim_fmi::state::{self, Mode, Status};
use agrisim_fmi::{Instance, Model};

use crate::args::{all_match, garbage_ptr, pick_vrs, zeroed, Gen, Keep};
use crate::logs::{log2, Logs};
use crate::rng::FuzzRng;
use crate::shadow::{check, Must, Outcome, Shadow, Then};
use crate::spec::fmi2 as spec2;
use crate::states::{pick_state, round_trip};
use crate::structure::assert_valid_table;

const UNSUPPORTED2: &[&str] = &[
    "fmi2GetDirectionalDerivative",
    "fmi2EnterEventMode",
    "fmi2NewDiscreteStates",
    "fmi2SetTime",
    "fmi2GetDerivatives",
    "fmi2SetRealInputDerivatives",
    "fmi2GetRealOutputDerivatives",
    "fmi2CancelStep",
];

unsafe fn get2<M: Model, T: CType>(rng: &mut FuzzRng, c: *mut c_void, function: &'static str, mode: Mode) -> Outcome {
    let vrs = pick_vrs::<M, T>(rng, true);
    let null = rng.chance(8) && !vrs.is_empty();
    let mut values: Vec<T::C> = zeroed(vrs.len() + 1);
    let vp = if null { std::ptr::null_mut() } else { values.as_mut_ptr() };
    let status = fmi2::get::<M, T>(c, function, vrs.as_ptr(), vrs.len(), vp);
    let ok = !null && all_match::<M, T>(&vrs, true);
    let must = if !ok {
        Must::Fail
    } else if matches!(mode, Mode::InitializationMode | Mode::Error) {
        Must::Any
    } else {
        Must::Succeed
    };
    Outcome { function, mask: spec2::GET, status, must, then: Then::Nothing }
}

unsafe fn set2<M: Model, T: Gen>(rng: &mut FuzzRng, c: *mut c_void, function: &'static str) -> Outcome {
    let vrs = pick_vrs::<M, T>(rng, true);
    let null = rng.chance(8) && !vrs.is_empty();
    let mut keep = Keep::default();
    let values: Vec<T::C> = (0..vrs.len() + 1).map(|_| T::gen(rng, &mut keep)).collect();
    let vp = if null { std::ptr::null() } else { values.as_ptr() };
    let status = fmi2::set::<M, T>(c, function, vrs.as_ptr(), vrs.len(), vp);
    let must = if null || !all_match::<M, T>(&vrs, true) { Must::Fail } else { Must::Any };
    Outcome { function, mask: spec2::SET, status, must, then: Then::Nothing }
}

unsafe fn random_call2<M: Model>(rng: &mut FuzzRng, c: *mut c_void, sh: &Shadow) -> Outcome {
    use spec2 as m;
    let o = |function, mask, status, must, then| Outcome { function, mask, status, must, then };
    match rng.below(22) {
        0 => {
            let s = fmi2::set_debug_logging::<M>(c, 1, 0, std::ptr::null());
            o("fmi2SetDebugLogging", m::SET_DEBUG_LOGGING, s, Must::Succeed, Then::Nothing)
        }
        1 => {
            let start = if rng.chance(85) { 0.0 } else { rng.f64() };
            let s = fmi2::setup_experiment::<M>(c, 0, 0.0, start, 0, 0.0);
            o(
                "fmi2SetupExperiment",
                m::SETUP_EXPERIMENT,
                s,
                if start.is_finite() { Must::Succeed } else { Must::Fail },
                Then::Nothing,
            )
        }
        2 => o(
            "fmi2EnterInitializationMode",
            m::ENTER_INITIALIZATION_MODE,
            fmi2::enter_initialization_mode::<M>(c),
            Must::Succeed,
            Then::Mode(Mode::InitializationMode),
        ),
        3 | 4 => o(
            "fmi2ExitInitializationMode",
            m::EXIT_INITIALIZATION_MODE,
            fmi2::exit_initialization_mode::<M>(c),
            Must::Any,
            Then::Mode(Mode::StepMode),
        ),
        5..=8 => {
            let tc = if rng.chance(90) { sh.time } else { rng.pick(&[f64::NAN, sh.time - 1.0]) };
            let h = if rng.chance(85) { 0.02 } else { rng.pick(&[0.0, -1.0, f64::NAN, 1e300, 1e-12]) };
            let s = fmi2::do_step::<M>(c, tc, h, 1);
            let must = if tc != sh.time || !(h > 0.0 && h.is_finite()) { Must::Fail } else { Must::Any };
            o("fmi2DoStep", m::DO_STEP, s, must, Then::Stepped(tc + h))
        }
        9 => o("fmi2Terminate", m::TERMINATE, fmi2::terminate::<M>(c), Must::Succeed, Then::Mode(Mode::Terminated)),
        10 => o("fmi2Reset", m::RESET, fmi2::reset::<M>(c), Must::Any, Then::Mode(Mode::Instantiated)),
        11 | 12 => match rng.below(4) {
            0 => get2::<M, ctype::Int32>(rng, c, "fmi2GetInteger", sh.mode),
            1 => get2::<M, ctype::Bool2>(rng, c, "fmi2GetBoolean", sh.mode),
            2 => get2::<M, ctype::Str>(rng, c, "fmi2GetString", sh.mode),
            _ => get2::<M, ctype::Float64>(rng, c, "fmi2GetReal", sh.mode),
        },
        13..=15 => match rng.below(4) {
            0 => set2::<M, ctype::Int32>(rng, c, "fmi2SetInteger"),
            1 => set2::<M, ctype::Bool2>(rng, c, "fmi2SetBoolean"),
            2 => set2::<M, ctype::Str>(rng, c, "fmi2SetString"),
            _ => set2::<M, ctype::Float64>(rng, c, "fmi2SetReal"),
        },
        16 => {
            let mut p = std::ptr::null_mut();
            let s = fmi2::get_fmu_state::<M>(c, &mut p);
            o(
                "fmi2GetFMUstate",
                m::GET_FMU_STATE,
                s,
                Must::Succeed,
                if s == Status::Ok { Then::NewState(p) } else { Then::Nothing },
            )
        }
        17 => {
            let (p, good) = pick_state(rng, sh);
            let s = fmi2::set_fmu_state::<M>(c, p);
            o("fmi2SetFMUstate", m::SET_FMU_STATE, s, if good { Must::Succeed } else { Must::Fail }, Then::Restore(p))
        }
        18 => {
            let (mut p, good) = pick_state(rng, sh);
            let orig = p;
            let s = fmi2::free_fmu_state::<M>(c, &mut p);
            let must = if good || orig.is_null() { Must::Succeed } else { Must::Fail };
            o("fmi2FreeFMUstate", m::FREE_FMU_STATE, s, must, Then::FreedState(orig))
        }
        19 => {
            let mut t = -1.0;
            let s = fmi2::get_real_status::<M>(c, fmi2::FMI2_LAST_SUCCESSFUL_TIME, &mut t);
            if s == Status::Ok {
                assert_eq!(t, (*c.cast::<Instance<M>>()).time);
            }
            o("fmi2GetRealStatus", m::GET_STATUS, s, Must::Succeed, Then::Nothing)
        }
        20 => {
            let (must, then, s) = round_trip(
                rng,
                sh,
                |st, n| fmi2::serialized_fmu_state_size::<M>(c, st, n),
                |st, b, n| fmi2::serialize_fmu_state::<M>(c, st, b.cast(), n),
                |b, n, p| fmi2::deserialize_fmu_state::<M>(c, b.cast(), n, p),
                |p| fmi2::free_fmu_state::<M>(c, p),
            );
            o("fmi2DeSerializeFMUstate", m::DESERIALIZE_FMU_STATE, s, must, then)
        }
        _ => {
            let f = rng.pick(UNSUPPORTED2);
            o(f, state::NEVER, fmi2::unsupported::<M>(c, f), Must::Fail, Then::Nothing)
        }
    }
}

/// Runs `cases` random FMI 2.0 call sequences against `M` (see the module docs).
pub fn fuzz_fmi2<M: Model>(seed: u64, cases: usize) {
    assert_valid_table::<M>();
    let mut rng = FuzzRng::new(seed);
    let guid = CString::new(M::GUID).unwrap_or_default();
    for case in 0..cases {
        let mut logs = Box::new(Logs::default());
        let env = (&mut *logs as *mut Logs).cast::<c_void>();
        let callbacks = CallbackFunctions {
            logger: Some(log2()),
            allocate_memory: None,
            free_memory: None,
            step_finished: None,
            component_environment: env,
        };
        unsafe {
            let (name, ty, g): (*const c_char, c_int, *const c_char) = match rng.below(4) {
                0 => (c"fuzz".as_ptr(), 0, guid.as_ptr()),
                1 => (c"fuzz".as_ptr(), 1, c"{wrong}".as_ptr()),
                2 => (c"".as_ptr(), 1, guid.as_ptr()),
                _ => (c"fuzz".as_ptr(), 7, guid.as_ptr()),
            };
            let p = fmi2::instantiate::<M>(name, ty, g, std::ptr::null(), &callbacks, 0, 0);
            assert!(
                p.is_null() && !logs.0.is_empty(),
                "{}: bad fmi2Instantiate accepted or not logged (case {case})",
                M::NAME
            );
            assert!(fmi2::instantiate::<M>(c"x".as_ptr(), 1, guid.as_ptr(), std::ptr::null(), std::ptr::null(), 0, 0)
                .is_null());
            logs.0.clear();
            let c = fmi2::instantiate::<M>(c"fuzz".as_ptr(), 1, guid.as_ptr(), std::ptr::null(), &callbacks, 0, 0);
            assert!(!c.is_null(), "{}: fmi2Instantiate failed: {:?}", M::NAME, logs.0);
            let mut sh = Shadow { mode: Mode::Instantiated, states: Vec::new(), freed: Vec::new(), time: 0.0 };
            let mut trace = String::new();
            let legal_prefix = rng.chance(70);
            for k in 0..10 + rng.below(60) {
                let o = if legal_prefix && k == 0 {
                    Outcome {
                        function: "fmi2EnterInitializationMode",
                        mask: spec2::ENTER_INITIALIZATION_MODE,
                        status: fmi2::enter_initialization_mode::<M>(c),
                        must: Must::Succeed,
                        then: Then::Mode(Mode::InitializationMode),
                    }
                } else if legal_prefix && k == 1 {
                    Outcome {
                        function: "fmi2ExitInitializationMode",
                        mask: spec2::EXIT_INITIALIZATION_MODE,
                        status: fmi2::exit_initialization_mode::<M>(c),
                        must: Must::Any,
                        then: Then::Mode(Mode::StepMode),
                    }
                } else if rng.chance(3) {
                    let bad = if rng.chance(50) { std::ptr::null_mut() } else { garbage_ptr(&mut rng) };
                    assert_eq!(fmi2::do_step::<M>(bad, 0.0, 0.02, 0), Status::Error);
                    fmi2::free_instance::<M>(bad);
                    continue;
                } else {
                    random_call2::<M>(&mut rng, c, &sh)
                };
                trace.push_str(&format!("  {} -> {:?}\n", o.function, o.status));
                check::<M>(&o, &mut sh, c, &mut logs, &trace);
            }
            fmi2::free_instance::<M>(c);
            assert_eq!(fmi2::terminate::<M>(c), Status::Error);
        }
    }
}
