//! Random FMI 3.0 call sequences against the generic API layer, checked by the shadow.

use std::ffi::{c_void, CString};

use agrisim_fmi::ctype::{self, CType};
use agrisim_fmi::fmi3;
use agrisim_fmi::state::{self, Mode, Status};
use agrisim_fmi::Model;

use crate::args::{all_match, garbage_ptr, pick_vrs, sizes, zeroed, Gen, Keep};
use crate::logs::{log3, Logs};
use crate::rng::FuzzRng;
use crate::shadow::{check, Must, Outcome, Shadow, Then};
use crate::spec::fmi3 as spec3;
use crate::states::{pick_state, round_trip};
use crate::structure::assert_valid_table;

unsafe fn get3<M: Model, T: CType>(
    rng: &mut FuzzRng,
    inst: *mut c_void,
    function: &'static str,
    mode: Mode,
) -> Outcome {
    let vrs = pick_vrs::<M, T>(rng, false);
    let (n_values, null_values, right) = sizes(rng, vrs.len());
    let mut values: Vec<T::C> = zeroed(n_values.max(vrs.len()) + 1);
    let vp = if null_values { std::ptr::null_mut() } else { values.as_mut_ptr() };
    let status = fmi3::get::<M, T>(inst, function, vrs.as_ptr(), vrs.len(), vp, n_values);
    let ok = right && all_match::<M, T>(&vrs, false);
    let must = if !ok {
        Must::Fail
    } else if mode == Mode::InitializationMode {
        Must::Any
    } else {
        Must::Succeed
    };
    Outcome { function, mask: spec3::GET, status, must, then: Then::Nothing }
}

unsafe fn set3<M: Model, T: Gen>(rng: &mut FuzzRng, inst: *mut c_void, function: &'static str) -> Outcome {
    let vrs = pick_vrs::<M, T>(rng, false);
    let (n_values, null_values, right) = sizes(rng, vrs.len());
    let mut keep = Keep::default();
    let values: Vec<T::C> = (0..n_values.max(vrs.len()) + 1).map(|_| T::gen(rng, &mut keep)).collect();
    let vp = if null_values { std::ptr::null() } else { values.as_ptr() };
    let status = fmi3::set::<M, T>(inst, function, vrs.as_ptr(), vrs.len(), vp, n_values);
    let must = if !right || !all_match::<M, T>(&vrs, false) { Must::Fail } else { Must::Any };
    Outcome { function, mask: spec3::SET, status, must, then: Then::Nothing }
}

const UNSUPPORTED3: &[&str] = &[
    "fmi3EnterEventMode",
    "fmi3EnterStepMode",
    "fmi3UpdateDiscreteStates",
    "fmi3GetClock",
    "fmi3SetIntervalDecimal",
    "fmi3EnterConfigurationMode",
    "fmi3GetDirectionalDerivative",
    "fmi3GetNumberOfContinuousStates",
    "fmi3SetTime",
    "fmi3GetOutputDerivatives",
    "fmi3GetVariableDependencies",
    "fmi3ActivateModelPartition",
];

unsafe fn random_call3<M: Model>(rng: &mut FuzzRng, inst: *mut c_void, sh: &Shadow) -> Outcome {
    use spec3 as m;
    let o = |function, mask, status, must, then| Outcome { function, mask, status, must, then };
    match rng.below(22) {
        0 => {
            let cats = [c"logStatusError".as_ptr(), c"logCalls".as_ptr(), c"noSuchCategory".as_ptr()];
            let n = rng.below(4);
            let null = rng.chance(10) && n > 0;
            let p = if null { std::ptr::null() } else { cats.as_ptr() };
            let s = fmi3::set_debug_logging::<M>(inst, rng.below(2) as u8, n, p);
            o(
                "fmi3SetDebugLogging",
                m::SET_DEBUG_LOGGING,
                s,
                if null { Must::Fail } else { Must::Succeed },
                Then::Nothing,
            )
        }
        1 | 2 => {
            let start = if rng.chance(85) { 0.0 } else { rng.f64() };
            let stop_defined = rng.chance(30);
            let stop = if rng.chance(80) { start + 1e6 } else { rng.f64() };
            let s = fmi3::enter_initialization_mode::<M>(inst, 0, 0.0, start, stop_defined as u8, stop);
            let good = start.is_finite() && (!stop_defined || stop >= start);
            let must = if good { Must::Succeed } else { Must::Fail };
            o(
                "fmi3EnterInitializationMode",
                m::ENTER_INITIALIZATION_MODE,
                s,
                must,
                Then::Mode(Mode::InitializationMode),
            )
        }
        3 | 4 => {
            let s = fmi3::exit_initialization_mode::<M>(inst);
            o("fmi3ExitInitializationMode", m::EXIT_INITIALIZATION_MODE, s, Must::Any, Then::Mode(Mode::StepMode))
        }
        5..=8 => {
            let tc = match rng.below(12) {
                0 => f64::NAN,
                1 => sh.time + 1.0,
                _ => sh.time,
            };
            let h = match rng.below(12) {
                0 => rng.pick(&[0.0, -0.02, f64::NAN, f64::INFINITY]),
                1 => rng.pick(&[1e-12, 1e300, 1e6]),
                _ => 0.02,
            };
            let (mut ev, mut term, mut early, mut last) = (7u8, 7u8, 7u8, -1.0f64);
            let null = rng.chance(5);
            let s = fmi3::do_step::<M>(
                inst,
                tc,
                h,
                0,
                if null { std::ptr::null_mut() } else { &mut ev },
                &mut term,
                &mut early,
                &mut last,
            );
            let must = if null || !tc.is_finite() || !(h > 0.0 && h.is_finite()) || tc != sh.time {
                Must::Fail
            } else {
                Must::Any
            };
            if s == Status::Ok {
                assert!(
                    ev == 0 && term == 0 && early == 0 && last == tc + h,
                    "fmi3DoStep outputs wrong: {ev} {term} {early} {last}"
                );
            }
            o("fmi3DoStep", m::DO_STEP, s, must, Then::Stepped(tc + h))
        }
        9 => o("fmi3Terminate", m::TERMINATE, fmi3::terminate::<M>(inst), Must::Succeed, Then::Mode(Mode::Terminated)),
        10 => o("fmi3Reset", m::RESET, fmi3::reset::<M>(inst), Must::Any, Then::Mode(Mode::Instantiated)),
        11 | 12 => match rng.below(13) {
            0 => get3::<M, ctype::Float32>(rng, inst, "fmi3GetFloat32", sh.mode),
            1 => get3::<M, ctype::Int8>(rng, inst, "fmi3GetInt8", sh.mode),
            2 => get3::<M, ctype::UInt64>(rng, inst, "fmi3GetUInt64", sh.mode),
            3 => get3::<M, ctype::Int32>(rng, inst, "fmi3GetInt32", sh.mode),
            4 => get3::<M, ctype::Int64>(rng, inst, "fmi3GetInt64", sh.mode),
            5 => get3::<M, ctype::Bool3>(rng, inst, "fmi3GetBoolean", sh.mode),
            6 => get3::<M, ctype::Str>(rng, inst, "fmi3GetString", sh.mode),
            7 | 8 => {
                let vrs = pick_vrs::<M, ctype::Bin>(rng, false);
                let (n, null, right) = sizes(rng, vrs.len());
                let mut sz = vec![0usize; n + 1];
                let mut ptrs: Vec<*const u8> = vec![std::ptr::null(); n + 1];
                let pp = if null { std::ptr::null_mut() } else { ptrs.as_mut_ptr() };
                let s = fmi3::get_binary::<M>(inst, vrs.as_ptr(), vrs.len(), sz.as_mut_ptr(), pp, n);
                if s == Status::Ok {
                    for k in 0..n {
                        assert!(!ptrs[k].is_null(), "fmi3GetBinary returned NULL data");
                        // Touch the bytes: they must be readable.
                        let _ = std::slice::from_raw_parts(ptrs[k], sz[k]).iter().fold(0u8, |a, b| a ^ b);
                    }
                }
                let ok = right && all_match::<M, ctype::Bin>(&vrs, false);
                let must = if !ok {
                    Must::Fail
                } else if sh.mode == Mode::InitializationMode {
                    Must::Any
                } else {
                    Must::Succeed
                };
                o("fmi3GetBinary", m::GET, s, must, Then::Nothing)
            }
            _ => get3::<M, ctype::Float64>(rng, inst, "fmi3GetFloat64", sh.mode),
        },
        13..=15 => match rng.below(12) {
            0 => set3::<M, ctype::Float32>(rng, inst, "fmi3SetFloat32"),
            1 => set3::<M, ctype::UInt16>(rng, inst, "fmi3SetUInt16"),
            2 | 3 => set3::<M, ctype::Int32>(rng, inst, "fmi3SetInt32"),
            4 => set3::<M, ctype::Int64>(rng, inst, "fmi3SetInt64"),
            5 => set3::<M, ctype::Bool3>(rng, inst, "fmi3SetBoolean"),
            6 => set3::<M, ctype::Str>(rng, inst, "fmi3SetString"),
            7 | 8 => {
                let vrs = pick_vrs::<M, ctype::Bin>(rng, false);
                let (n, null, right) = sizes(rng, vrs.len());
                let mut keep = Keep::default();
                let vals: Vec<(usize, *const u8)> =
                    (0..n + 1).map(|_| <ctype::Bin as Gen>::gen(rng, &mut keep)).collect();
                let sz: Vec<usize> = vals.iter().map(|v| v.0).collect();
                let ptrs: Vec<*const u8> = vals.iter().map(|v| v.1).collect();
                let pp = if null { std::ptr::null() } else { ptrs.as_ptr() };
                let s = fmi3::set_binary::<M>(inst, vrs.as_ptr(), vrs.len(), sz.as_ptr(), pp, n);
                let must = if !right || !all_match::<M, ctype::Bin>(&vrs, false) { Must::Fail } else { Must::Any };
                o("fmi3SetBinary", m::SET, s, must, Then::Nothing)
            }
            _ => set3::<M, ctype::Float64>(rng, inst, "fmi3SetFloat64"),
        },
        16 | 17 => {
            let overwrite = !sh.states.is_empty() && rng.chance(30);
            let mut p = if overwrite { sh.states[rng.below(sh.states.len())].0 } else { std::ptr::null_mut() };
            let null = rng.chance(5);
            let s = fmi3::get_fmu_state::<M>(inst, if null { std::ptr::null_mut() } else { &mut p });
            let then = if overwrite { Then::FreedState(p) } else { Then::NewState(p) };
            let then = if s == Status::Ok { then } else { Then::Nothing };
            // Overwriting = free + new at the same address in the shadow.
            o("fmi3GetFMUState", m::GET_FMU_STATE, s, if null { Must::Fail } else { Must::Succeed }, then)
        }
        18 => {
            let (p, good) = pick_state(rng, sh);
            let s = fmi3::set_fmu_state::<M>(inst, p);
            o("fmi3SetFMUState", m::SET_FMU_STATE, s, if good { Must::Succeed } else { Must::Fail }, Then::Restore(p))
        }
        19 => {
            let (mut p, good) = pick_state(rng, sh);
            let orig = p;
            let s = fmi3::free_fmu_state::<M>(inst, &mut p);
            if s == Status::Ok {
                assert!(p.is_null(), "fmi3FreeFMUState must set *FMUState = NULL");
            }
            let must = if good || orig.is_null() { Must::Succeed } else { Must::Fail };
            o("fmi3FreeFMUState", m::FREE_FMU_STATE, s, must, Then::FreedState(orig))
        }
        20 => {
            let (must, then, s) = round_trip(
                rng,
                sh,
                |st, n| fmi3::serialized_fmu_state_size::<M>(inst, st, n),
                |st, b, n| fmi3::serialize_fmu_state::<M>(inst, st, b, n),
                |b, n, p| fmi3::deserialize_fmu_state::<M>(inst, b, n, p),
                |p| fmi3::free_fmu_state::<M>(inst, p),
            );
            o("fmi3DeserializeFMUState", m::DESERIALIZE_FMU_STATE, s, must, then)
        }
        _ => {
            let f = rng.pick(UNSUPPORTED3);
            o(f, state::NEVER, fmi3::unsupported::<M>(inst, f), Must::Fail, Then::Nothing)
        }
    }
}

/// Runs `cases` random FMI 3.0 call sequences against `M` (see the module docs).
pub fn fuzz_fmi3<M: Model>(seed: u64, cases: usize) {
    assert_valid_table::<M>();
    let mut rng = FuzzRng::new(seed);
    let token = CString::new(M::TOKEN).unwrap_or_default();
    for case in 0..cases {
        let mut logs = Box::new(Logs::default());
        let env = (&mut *logs as *mut Logs).cast::<c_void>();
        unsafe {
            // Wrong instantiations: NULL, logged.
            let bad_token = c"{not-the-token}";
            let (name, tok, event_mode, n_req) = match rng.below(6) {
                0 => (c"".as_ptr(), token.as_ptr(), 0u8, 0usize),
                1 => (c"fuzz".as_ptr(), bad_token.as_ptr(), 0, 0),
                2 => (c"fuzz".as_ptr(), std::ptr::null(), 0, 0),
                3 => (c"fuzz".as_ptr(), token.as_ptr(), 1, 0),
                4 => (c"fuzz".as_ptr(), token.as_ptr(), 0, 1),
                _ => (std::ptr::null(), token.as_ptr(), 0, 0),
            };
            let req = [1u32];
            let p = fmi3::instantiate_co_simulation::<M>(
                name,
                tok,
                std::ptr::null(),
                0,
                0,
                event_mode,
                0,
                req.as_ptr(),
                n_req,
                env,
                Some(log3),
                None,
            );
            assert!(p.is_null(), "{}: bad instantiation accepted (case {case})", M::NAME);
            assert!(!logs.0.is_empty(), "{}: bad instantiation not logged (case {case})", M::NAME);
            let p = fmi3::instantiate_model_exchange::<M>(
                c"me".as_ptr(),
                token.as_ptr(),
                std::ptr::null(),
                0,
                0,
                env,
                Some(log3),
            );
            assert!(p.is_null(), "{}: Model Exchange instantiated", M::NAME);
            logs.0.clear();

            let inst = fmi3::instantiate_co_simulation::<M>(
                c"fuzz".as_ptr(),
                token.as_ptr(),
                std::ptr::null(),
                0,
                rng.below(2) as u8,
                0,
                rng.below(2) as u8,
                std::ptr::null(),
                0,
                env,
                Some(log3),
                None,
            );
            assert!(!inst.is_null(), "{}: instantiation failed: {:?}", M::NAME, logs.0);
            let mut sh = Shadow { mode: Mode::Instantiated, states: Vec::new(), freed: Vec::new(), time: 0.0 };
            let mut trace = String::new();
            // Bias towards a legal run first, so that Step Mode gets exercised.
            let legal_prefix = rng.chance(70);
            let n_calls = 10 + rng.below(60);
            for k in 0..n_calls {
                let o = if legal_prefix && k == 0 {
                    Outcome {
                        function: "fmi3EnterInitializationMode",
                        mask: spec3::ENTER_INITIALIZATION_MODE,
                        status: fmi3::enter_initialization_mode::<M>(inst, 0, 0.0, 0.0, 0, 0.0),
                        must: Must::Succeed,
                        then: Then::Mode(Mode::InitializationMode),
                    }
                } else if legal_prefix && k == 1 {
                    Outcome {
                        function: "fmi3ExitInitializationMode",
                        mask: spec3::EXIT_INITIALIZATION_MODE,
                        status: fmi3::exit_initialization_mode::<M>(inst),
                        must: Must::Any,
                        then: Then::Mode(Mode::StepMode),
                    }
                } else if rng.chance(3) {
                    // NULL and garbage handles: Error, no effect on the real instance.
                    let bad = if rng.chance(50) { std::ptr::null_mut() } else { garbage_ptr(&mut rng) };
                    assert_eq!(
                        fmi3::do_step::<M>(
                            bad,
                            0.0,
                            0.02,
                            0,
                            std::ptr::null_mut(),
                            std::ptr::null_mut(),
                            std::ptr::null_mut(),
                            std::ptr::null_mut()
                        ),
                        Status::Error
                    );
                    assert_eq!(fmi3::reset::<M>(bad), Status::Error);
                    fmi3::free_instance::<M>(bad);
                    continue;
                } else {
                    random_call3::<M>(&mut rng, inst, &sh)
                };
                trace.push_str(&format!("  {} -> {:?}\n", o.function, o.status));
                check::<M>(&o, &mut sh, inst, &mut logs, &trace);
            }
            // Free some states explicitly; FreeInstance frees the rest.
            if let Some(&(mut p, _, _)) = sh.states.first() {
                let s = fmi3::free_fmu_state::<M>(inst, &mut p);
                assert!(sh.mode == Mode::Fatal || s == Status::Ok, "{}: FreeFMUState failed in {:?}", M::NAME, sh.mode);
            }
            fmi3::free_instance::<M>(inst);
            // The handle is dead now: Error, never a crash.
            assert_eq!(fmi3::terminate::<M>(inst), Status::Error);
            fmi3::free_instance::<M>(inst);
        }
    }
}
