//! The FMI 3.0 layer through its generic functions: legal runs, the state machine, argument
//! checks and error messages.

mod common;

use std::ffi::{CStr, CString};

use agrisim_fmi::{fmi3, Mode, Model, Status};
use agrisim_fmu_testmodel::*;
use common::*;

#[test]
fn legal_run_matches_the_analytic_solution_and_keeps_time_exact() {
    let i = I3::new();
    assert_eq!(i.set_f64(vr(K), 2.0), Status::Ok);
    assert_eq!(unsafe { fmi3::enter_initialization_mode::<TestModel>(i.p, 0, 0.0, 0.0, 1, 10.0) }, Status::Ok);
    assert_eq!(i.set_f64(vr(X0), 3.0), Status::Ok);
    // Initial unknowns are available in Initialization Mode.
    assert_eq!(i.f64(vr(X)), (Status::Ok, 3.0));
    assert_eq!(unsafe { fmi3::exit_initialization_mode::<TestModel>(i.p) }, Status::Ok);
    for n in 0..50 {
        let tc = n as f64 * 0.02;
        assert_eq!(i.step(tc, 0.02), Status::Ok);
        let (_, t) = i.f64(0);
        assert_eq!(t, tc + 0.02, "time is the importer's tc + h");
    }
    let (_, x) = i.f64(vr(X));
    assert!((x - 3.0 * (-2.0f64).exp()).abs() < 1e-12, "x = {x}");
    let mut steps = 0;
    assert_eq!(unsafe { fmi3::get_int32::<TestModel>(i.p, &vr(STEPS), 1, &mut steps, 1) }, Status::Ok);
    assert_eq!(steps, 50);
    assert_eq!(unsafe { fmi3::terminate::<TestModel>(i.p) }, Status::Ok);
    assert_eq!(i.f64(vr(X)).0, Status::Ok, "getters work after Terminate");
    assert!(i.logs.iter().all(|(s, _)| *s < Status::Error), "{:?}", i.logs);
}

#[test]
fn step_before_initialization_is_an_error_and_only_reset_helps() {
    let i = I3::new();
    assert_eq!(i.step(0.0, 0.02), Status::Error);
    assert!(i.last_error().contains("fmi3DoStep") && i.last_error().contains("Instantiated"), "{}", i.last_error());
    // In Error: getters and steps are refused, Reset works.
    assert_eq!(i.f64(vr(X)).0, Status::Error);
    assert_eq!(unsafe { fmi3::enter_initialization_mode::<TestModel>(i.p, 0, 0.0, 0.0, 0, 0.0) }, Status::Error);
    assert_eq!(unsafe { fmi3::reset::<TestModel>(i.p) }, Status::Ok);
    assert_eq!(unsafe { fmi3::enter_initialization_mode::<TestModel>(i.p, 0, 0.0, 0.0, 0, 0.0) }, Status::Ok);
}

#[test]
fn errors_name_the_function_the_variable_and_the_reason() {
    type Case = (Box<dyn Fn(&I3) -> Status>, &'static [&'static str]);
    let cases: Vec<Case> = vec![
        (Box::new(|i| i.set_f64(vr(X), 1.0)), &["fmi3SetFloat64", "'x'", "output"]),
        (Box::new(|i| i.set_f64(vr(X0), 1.0)), &["fmi3SetFloat64", "'x0'", "fixed parameter"]),
        (Box::new(|i| i.set_f64(vr(K), 1e6)), &["fmi3SetFloat64", "'k'", "maximum"]),
        (Box::new(|i| i.set_f64(vr(U), f64::NAN)), &["fmi3SetFloat64", "'u'", "finite"]),
        (Box::new(|i| i.set_f64(0, 1.0)), &["fmi3SetFloat64", "'time'"]),
        (Box::new(|i| i.set_f64(999, 1.0)), &["fmi3SetFloat64", "unknown value reference 999"]),
        (Box::new(|i| i.set_i32(vr(X), 1)), &["fmi3SetInt32", "'x'", "Float64"]),
        (
            Box::new(|i| unsafe {
                let mut v = [0i64; 2];
                fmi3::get_int64::<TestModel>(i.p, &vr(MSG_SEQ), 1, v.as_mut_ptr(), 2)
            }),
            &["fmi3GetInt64", "nValues (2)"],
        ),
        (
            Box::new(|i| unsafe { fmi3::get_float64::<TestModel>(i.p, std::ptr::null(), 1, [0.0].as_mut_ptr(), 1) }),
            &["fmi3GetFloat64", "valueReferences is NULL"],
        ),
        (
            Box::new(|i| unsafe { fmi3::get_float32::<TestModel>(i.p, &vr(X), 1, [0.0f32].as_mut_ptr(), 1) }),
            &["fmi3GetFloat32", "'x'"],
        ),
        (Box::new(|i| i.step(0.5, 0.02)), &["fmi3DoStep", "currentCommunicationPoint"]),
        (Box::new(|i| i.step(0.0, -0.02)), &["fmi3DoStep", "communicationStepSize"]),
        (Box::new(|i| i.step(0.0, f64::NAN)), &["fmi3DoStep", "communicationStepSize"]),
        (
            Box::new(|i| unsafe {
                fmi3::do_step::<TestModel>(
                    i.p,
                    0.0,
                    0.02,
                    0,
                    std::ptr::null_mut(),
                    std::ptr::null_mut(),
                    std::ptr::null_mut(),
                    std::ptr::null_mut(),
                )
            }),
            &["fmi3DoStep", "NULL"],
        ),
        (
            Box::new(|i| unsafe { fmi3::unsupported::<TestModel>(i.p, "fmi3EnterEventMode") }),
            &["fmi3EnterEventMode", "event mode"],
        ),
        (
            Box::new(|i| unsafe { fmi3::set_fmu_state::<TestModel>(i.p, 0x1234 as *mut _) }),
            &["fmi3SetFMUState", "not a live FMU state"],
        ),
    ];
    for (call, needles) in cases {
        let i = I3::stepping();
        assert_eq!(call(&i), Status::Error, "{needles:?}");
        let msg = i.last_error();
        for n in needles {
            assert!(msg.contains(n), "message {msg:?} lacks {n:?}");
        }
    }
}

#[test]
fn tunable_parameters_and_inputs_can_change_while_stepping() {
    let i = I3::stepping();
    assert_eq!(i.set_f64(vr(K), 0.0), Status::Ok);
    assert_eq!(i.set_f64(vr(U), 1.0), Status::Ok);
    assert_eq!(i.step(0.0, 0.5), Status::Ok);
    assert_eq!(i.f64(vr(X)), (Status::Ok, 1.5));
    let hold = 1u8;
    assert_eq!(unsafe { fmi3::set_boolean::<TestModel>(i.p, &vr(HOLD), 1, &hold, 1) }, Status::Ok);
    assert_eq!(i.step(0.5, 0.5), Status::Ok);
    assert_eq!(i.f64(vr(X)), (Status::Ok, 1.5));
}

#[test]
fn model_errors_and_panics_become_error_and_fmu_state_recovers() {
    let i = I3::stepping();
    let mut state = std::ptr::null_mut();
    assert_eq!(i.step(0.0, 0.02), Status::Ok);
    assert_eq!(unsafe { fmi3::get_fmu_state::<TestModel>(i.p, &mut state) }, Status::Ok);
    let (_, x_saved) = i.f64(vr(X));
    for fault in [1, 2] {
        assert_eq!(unsafe { fmi3::set_fmu_state::<TestModel>(i.p, state) }, Status::Ok);
        assert_eq!(i.set_i32(vr(FAULT), fault), Status::Ok);
        assert_eq!(i.step(0.02, 0.02), Status::Error);
        let msg = i.last_error();
        assert!(
            msg.contains("fmi3DoStep") && msg.contains(if fault == 1 { "injected failure" } else { "panicked" }),
            "{msg}"
        );
        assert_eq!(i.f64(vr(X)).0, Status::Error, "no getters in Error");
    }
    // Restoring the state leaves Error and rewinds everything, including time and fault.
    assert_eq!(unsafe { fmi3::set_fmu_state::<TestModel>(i.p, state) }, Status::Ok);
    assert_eq!(i.f64(vr(X)), (Status::Ok, x_saved));
    assert_eq!(i.step(0.02, 0.02), Status::Ok);
    assert_eq!(unsafe { fmi3::free_fmu_state::<TestModel>(i.p, &mut state) }, Status::Ok);
    assert!(state.is_null());
    assert_eq!(unsafe { fmi3::free_fmu_state::<TestModel>(i.p, &mut state) }, Status::Ok, "freeing NULL is a no-op");
}

#[test]
fn binary_echo_returns_fmu_owned_bytes_and_counts_messages() {
    let i = I3::stepping();
    let msg = [0u8, 1, 0, 0, 3, 0, 0, 0, b'h', b'i', 0];
    let (size, ptr) = (msg.len(), msg.as_ptr());
    assert_eq!(unsafe { fmi3::set_binary::<TestModel>(i.p, &vr(MSG_IN), 1, &size, &ptr, 1) }, Status::Ok);
    assert_eq!(i.step(0.0, 0.02), Status::Ok);
    let (mut sizes, mut ptrs) = ([0usize; 2], [std::ptr::null::<u8>(); 2]);
    let vrs = [vr(MSG_OUT), vr(MSG_IN)];
    assert_eq!(
        unsafe { fmi3::get_binary::<TestModel>(i.p, vrs.as_ptr(), 2, sizes.as_mut_ptr(), ptrs.as_mut_ptr(), 2) },
        Status::Ok
    );
    for k in 0..2 {
        assert_eq!(unsafe { std::slice::from_raw_parts(ptrs[k], sizes[k]) }, &msg);
    }
    let mut seq = 0i64;
    assert_eq!(unsafe { fmi3::get_int64::<TestModel>(i.p, &vr(MSG_SEQ), 1, &mut seq, 1) }, Status::Ok);
    assert_eq!(seq, 1);
    // An empty binary is returned as size 0 with a non-NULL pointer.
    let empty: *const u8 = std::ptr::null();
    assert_eq!(unsafe { fmi3::set_binary::<TestModel>(i.p, &vr(MSG_IN), 1, &0, &empty, 1) }, Status::Ok);
    assert_eq!(
        unsafe { fmi3::get_binary::<TestModel>(i.p, &vr(MSG_IN), 1, sizes.as_mut_ptr(), ptrs.as_mut_ptr(), 1) },
        Status::Ok
    );
    assert!(sizes[0] == 0 && !ptrs[0].is_null());
}

#[test]
fn strings_round_trip() {
    let i = I3::new();
    let s = CString::new("new <label> & ü").unwrap();
    let p = s.as_ptr();
    assert_eq!(unsafe { fmi3::set_string::<TestModel>(i.p, &vr(LABEL), 1, &p, 1) }, Status::Ok);
    assert_eq!(unsafe { fmi3::enter_initialization_mode::<TestModel>(i.p, 0, 0.0, 0.0, 0, 0.0) }, Status::Ok);
    let mut out = std::ptr::null();
    assert_eq!(unsafe { fmi3::get_string::<TestModel>(i.p, &vr(LABEL), 1, &mut out, 1) }, Status::Ok);
    assert_eq!(unsafe { CStr::from_ptr(out) }, s.as_c_str());
}

#[test]
fn instantiation_checks_token_event_mode_and_accepts_null_resource_path() {
    let mut logs: Box<Logs> = Box::default();
    let env = (&mut *logs as *mut Logs).cast();
    let good = CString::new(TestModel::TOKEN).unwrap();
    let inst = |token: &CStr, event_mode: u8| unsafe {
        fmi3::instantiate_co_simulation::<TestModel>(
            c"x".as_ptr(),
            token.as_ptr(),
            std::ptr::null(),
            0,
            0,
            event_mode,
            0,
            std::ptr::null(),
            0,
            env,
            Some(capture),
            None,
        )
    };
    assert!(inst(c"{other}", 0).is_null());
    assert!(inst(&good, 1).is_null());
    let p = inst(&good, 0);
    assert!(!p.is_null());
    unsafe { fmi3::free_instance::<TestModel>(p) };
    assert!(logs[0].1.contains("instantiationToken") && logs[1].1.contains("eventModeUsed"), "{logs:?}");
    assert!(unsafe {
        fmi3::instantiate_model_exchange::<TestModel>(
            c"x".as_ptr(),
            good.as_ptr(),
            std::ptr::null(),
            0,
            0,
            env,
            Some(capture),
        )
    }
    .is_null());
    assert!(logs.last().unwrap().1.contains("Co-Simulation only"));
}

#[test]
fn invalid_handles_are_errors_not_crashes() {
    unsafe {
        assert_eq!(fmi3::terminate::<TestModel>(std::ptr::null_mut()), Status::Error);
        assert_eq!(fmi3::reset::<TestModel>(0xdead_bee8 as *mut _), Status::Error);
        fmi3::free_instance::<TestModel>(std::ptr::null_mut());
        // An FMI 2 handle is not an FMI 3 instance.
        let guid = CString::new(TestModel::GUID).unwrap();
        let cb = agrisim_fmi::fmi2::CallbackFunctions {
            logger: None,
            allocate_memory: None,
            free_memory: None,
            step_finished: None,
            component_environment: std::ptr::null_mut(),
        };
        let c =
            agrisim_fmi::fmi2::instantiate::<TestModel>(c"x".as_ptr(), 1, guid.as_ptr(), std::ptr::null(), &cb, 0, 0);
        assert!(!c.is_null());
        assert_eq!(fmi3::terminate::<TestModel>(c), Status::Error);
        agrisim_fmi::fmi2::free_instance::<TestModel>(c);
        let i = I3::new();
        fmi3::free_instance::<TestModel>(i.p);
        assert_eq!(fmi3::reset::<TestModel>(i.p), Status::Error, "freed handle");
        std::mem::forget(i);
    }
    let _ = Mode::Error;
}

#[test]
fn exported_symbols_serve_the_same_xml() {
    let p = agrisim_fmu_testmodel::__agrisim_fmi_exports::agrisim_model_description_fmi3();
    assert_eq!(unsafe { CStr::from_ptr(p) }.to_str().unwrap(), agrisim_fmi::xml::fmi3::<TestModel>());
    let p = agrisim_fmu_testmodel::__agrisim_fmi_exports::agrisim_model_description_fmi2();
    assert_eq!(unsafe { CStr::from_ptr(p) }.to_str().unwrap(), agrisim_fmi::xml::fmi2::<TestModel>());
}

#[test]
fn binary_input_above_its_max_size_is_refused_before_it_is_read() {
    let i = I3::stepping();
    let set =
        |bytes: &[u8]| unsafe { fmi3::set_binary::<TestModel>(i.p, &vr(MSG_IN), 1, &bytes.len(), &bytes.as_ptr(), 1) };
    let mut bytes = vec![0u8; MAX_MESSAGE];
    bytes[..9].copy_from_slice(EMPTY_STRING_CDR);
    assert_eq!(set(&bytes), Status::Ok, "maxSize bytes are fine");
    bytes.push(0);
    assert_eq!(set(&bytes), Status::Error);
    let msg = i.last_error();
    for needle in ["fmi3SetBinary", "'msg_in'", "1048577 bytes exceed its maxSize of 1048576 bytes"] {
        assert!(msg.contains(needle), "{msg:?} lacks {needle:?}");
    }
}
