//! The FMI 2.0 layer through its generic functions.

use std::ffi::{c_char, c_void, CStr, CString};

use agrisim_fmi::{fmi2, Model, Status};
use agrisim_fmu_testmodel::*;

type Logs = Vec<String>;

unsafe extern "C" fn capture(
    env: *mut c_void,
    _name: *const c_char,
    _s: Status,
    _cat: *const c_char,
    msg: *const c_char,
) {
    (*(env as *mut Logs)).push(CStr::from_ptr(msg).to_string_lossy().into_owned());
}

fn callbacks(logs: &mut Logs) -> fmi2::CallbackFunctions {
    fmi2::CallbackFunctions {
        // SAFETY: called without variadic arguments.
        logger: Some(unsafe {
            std::mem::transmute::<
                unsafe extern "C" fn(*mut c_void, *const c_char, Status, *const c_char, *const c_char),
                agrisim_fmi::logger::Fmi2Logger,
            >(capture)
        }),
        allocate_memory: None,
        free_memory: None,
        step_finished: None,
        component_environment: (logs as *mut Logs).cast(),
    }
}

fn vr(i: usize) -> u32 {
    i as u32 + 1
}

#[test]
fn legal_run_with_setup_experiment() {
    let mut logs = Logs::new();
    let cb = callbacks(&mut logs);
    let guid = CString::new(TestModel::GUID).unwrap();
    unsafe {
        let c = fmi2::instantiate::<TestModel>(
            c"a".as_ptr(),
            fmi2::FMI2_CO_SIMULATION,
            guid.as_ptr(),
            std::ptr::null(),
            &cb,
            0,
            0,
        );
        assert!(!c.is_null());
        assert_eq!(fmi2::setup_experiment::<TestModel>(c, 0, 0.0, 1.0, 1, 3.0), Status::Ok);
        assert_eq!(fmi2::enter_initialization_mode::<TestModel>(c), Status::Ok);
        assert_eq!(fmi2::exit_initialization_mode::<TestModel>(c), Status::Ok);
        for n in 0..10 {
            assert_eq!(fmi2::do_step::<TestModel>(c, 1.0 + n as f64 * 0.1, 0.1, 1), Status::Ok);
        }
        let (mut x, mut steps, mut t) = (0.0, 0, 0.0);
        assert_eq!(fmi2::get_real::<TestModel>(c, &vr(X), 1, &mut x), Status::Ok);
        assert_eq!(fmi2::get_integer::<TestModel>(c, &vr(STEPS), 1, &mut steps), Status::Ok);
        assert_eq!(fmi2::get_real_status::<TestModel>(c, fmi2::FMI2_LAST_SUCCESSFUL_TIME, &mut t), Status::Ok);
        assert!((x - (-1.0f64).exp()).abs() < 1e-12 && steps == 10 && (t - 2.0).abs() < 1e-12, "{x} {steps} {t}");
        // Beyond stopTime.
        assert_eq!(fmi2::do_step::<TestModel>(c, t, 1.5, 1), Status::Error);
        assert!(logs.last().unwrap().contains("stopTime"), "{logs:?}");
        fmi2::free_instance::<TestModel>(c);
    }
}

#[test]
fn fmi3_only_variables_are_invisible_and_set_is_all_or_nothing() {
    let mut logs = Logs::new();
    let cb = callbacks(&mut logs);
    let guid = CString::new(TestModel::GUID).unwrap();
    unsafe {
        let c = fmi2::instantiate::<TestModel>(c"a".as_ptr(), 1, guid.as_ptr(), std::ptr::null(), &cb, 0, 0);
        assert_eq!(fmi2::enter_initialization_mode::<TestModel>(c), Status::Ok);
        let mut v = 0;
        assert_eq!(fmi2::get_integer::<TestModel>(c, &vr(MSG_SEQ), 1, &mut v), Status::Error);
        assert!(logs.last().unwrap().contains("not available through FMI 2.0"), "{logs:?}");
        // In Error, FMI 2 still allows getters for debugging: u kept its value.
        let vrs = [vr(U), vr(X)];
        assert_eq!(fmi2::set_real::<TestModel>(c, vrs.as_ptr(), 2, [5.0, 1.0].as_ptr()), Status::Error);
        let mut u = f64::NAN;
        assert_eq!(fmi2::get_real::<TestModel>(c, &vr(U), 1, &mut u), Status::Ok);
        assert_eq!(u, 0.0, "a failed multi-value set changes nothing");
        assert_eq!(fmi2::reset::<TestModel>(c), Status::Ok);
        fmi2::free_instance::<TestModel>(c);
    }
}

#[test]
fn instantiate_checks_guid_and_type() {
    let mut logs = Logs::new();
    let cb = callbacks(&mut logs);
    let guid = CString::new(TestModel::GUID).unwrap();
    unsafe {
        assert!(fmi2::instantiate::<TestModel>(c"a".as_ptr(), 0, guid.as_ptr(), std::ptr::null(), &cb, 0, 0).is_null());
        assert!(
            fmi2::instantiate::<TestModel>(c"a".as_ptr(), 1, c"{x}".as_ptr(), std::ptr::null(), &cb, 0, 0).is_null()
        );
    }
    assert!(logs[0].contains("Co-Simulation") && logs[1].contains("fmuGUID"), "{logs:?}");
}

#[test]
fn percent_signs_are_escaped_for_printf_style_loggers() {
    let mut logs = Logs::new();
    let cb = callbacks(&mut logs);
    unsafe {
        assert!(
            fmi2::instantiate::<TestModel>(c"a".as_ptr(), 1, c"100%s".as_ptr(), std::ptr::null(), &cb, 0, 0).is_null()
        );
    }
    assert!(logs[0].contains("100%%s"), "{logs:?}");
}
