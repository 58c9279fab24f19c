//! The Oscillator driven through the generic FMI 3 and FMI 2 model-exchange layers by a
//! small importer (classic RK4 with the step cut at the announced time event), compared
//! with the closed form; plus the refusals and FMU-state restores an importer relies on.

use std::ffi::{c_char, c_void, CString};

use agrisim_fmi::fmi2::{self, CallbackFunctions, EventInfo, FMI2_CO_SIMULATION, FMI2_MODEL_EXCHANGE};
use agrisim_fmi::{fmi3, Model, Status};
use agrisim_fmu_oscillator::{solution, Oscillator, Params, KICK_DV, KICK_TIME, OMEGA, V, V0, X, X0, ZETA};

agrisim_fmi_testing::fmu_me_conformance_tests!(Oscillator, seeds = 4, cases = 400);

/// Error messages the FMU logged.
#[derive(Default)]
struct Logs(Vec<String>);

unsafe extern "C" fn log3(env: *mut c_void, status: Status, _c: *const c_char, m: *const c_char) {
    if status >= Status::Error {
        (*env.cast::<Logs>()).0.push(std::ffi::CStr::from_ptr(m).to_string_lossy().into_owned());
    }
}

unsafe extern "C" fn log2_fixed(env: *mut c_void, _n: *const c_char, s: Status, c: *const c_char, m: *const c_char) {
    log3(env, s, c, m)
}

fn callbacks(env: *mut c_void) -> CallbackFunctions {
    // SAFETY: the FMU passes no variadic arguments (all messages are preformatted).
    let logger = unsafe {
        std::mem::transmute::<
            unsafe extern "C" fn(*mut c_void, *const c_char, Status, *const c_char, *const c_char),
            agrisim_fmi::logger::Fmi2Logger,
        >(log2_fixed)
    };
    CallbackFunctions {
        logger: Some(logger),
        allocate_memory: None,
        free_memory: None,
        step_finished: None,
        component_environment: env,
    }
}

/// The model-exchange calls an importer makes, over either API.
trait Me {
    fn set_time(&self, t: f64) -> Status;
    fn set_states(&self, x: &[f64]) -> Status;
    fn states(&self) -> [f64; 2];
    fn derivatives(&self) -> [f64; 2];
    fn enter_event_mode(&self) -> Status;
    /// (values changed, next event time)
    fn update(&self) -> (bool, Option<f64>);
    fn enter_continuous_time_mode(&self) -> Status;
    fn output(&self, vr: u32) -> f64;
}

struct Fmi3(*mut c_void);
struct Fmi2(*mut c_void);

impl Me for Fmi3 {
    fn set_time(&self, t: f64) -> Status {
        unsafe { fmi3::set_time::<Oscillator>(self.0, t) }
    }
    fn set_states(&self, x: &[f64]) -> Status {
        unsafe { fmi3::set_continuous_states::<Oscillator>(self.0, x.as_ptr(), x.len()) }
    }
    fn states(&self) -> [f64; 2] {
        let mut x = [0.0; 2];
        assert_eq!(unsafe { fmi3::get_continuous_states::<Oscillator>(self.0, x.as_mut_ptr(), 2) }, Status::Ok);
        x
    }
    fn derivatives(&self) -> [f64; 2] {
        let mut d = [0.0; 2];
        let s = unsafe { fmi3::get_continuous_state_derivatives::<Oscillator>(self.0, d.as_mut_ptr(), 2) };
        assert_eq!(s, Status::Ok);
        d
    }
    fn enter_event_mode(&self) -> Status {
        unsafe { fmi3::enter_event_mode::<Oscillator>(self.0) }
    }
    fn update(&self) -> (bool, Option<f64>) {
        let (mut need, mut term, mut nom, mut val, mut def, mut next) = (9, 9, 9, 9, 9, 0.0);
        let s = unsafe {
            fmi3::update_discrete_states::<Oscillator>(
                self.0, &mut need, &mut term, &mut nom, &mut val, &mut def, &mut next,
            )
        };
        assert_eq!(s, Status::Ok);
        assert_eq!((need, term, nom), (0, 0, 0));
        (val == 1, (def == 1).then_some(next))
    }
    fn enter_continuous_time_mode(&self) -> Status {
        unsafe { fmi3::enter_continuous_time_mode::<Oscillator>(self.0) }
    }
    fn output(&self, vr: u32) -> f64 {
        let mut v = f64::NAN;
        assert_eq!(unsafe { fmi3::get_float64::<Oscillator>(self.0, &vr, 1, &mut v, 1) }, Status::Ok);
        v
    }
}

impl Me for Fmi2 {
    fn set_time(&self, t: f64) -> Status {
        unsafe { fmi2::set_time::<Oscillator>(self.0, t) }
    }
    fn set_states(&self, x: &[f64]) -> Status {
        unsafe { fmi2::set_continuous_states::<Oscillator>(self.0, x.as_ptr(), x.len()) }
    }
    fn states(&self) -> [f64; 2] {
        let mut x = [0.0; 2];
        assert_eq!(unsafe { fmi2::get_continuous_states::<Oscillator>(self.0, x.as_mut_ptr(), 2) }, Status::Ok);
        x
    }
    fn derivatives(&self) -> [f64; 2] {
        let mut d = [0.0; 2];
        assert_eq!(unsafe { fmi2::get_derivatives::<Oscillator>(self.0, d.as_mut_ptr(), 2) }, Status::Ok);
        d
    }
    fn enter_event_mode(&self) -> Status {
        unsafe { fmi2::enter_event_mode::<Oscillator>(self.0) }
    }
    fn update(&self) -> (bool, Option<f64>) {
        let mut ei = EventInfo { new_discrete_states_needed: 9, terminate_simulation: 9, ..EventInfo::default() };
        assert_eq!(unsafe { fmi2::new_discrete_states::<Oscillator>(self.0, &mut ei) }, Status::Ok);
        assert_eq!((ei.new_discrete_states_needed, ei.terminate_simulation), (0, 0));
        (ei.values_of_continuous_states_changed == 1, (ei.next_event_time_defined == 1).then_some(ei.next_event_time))
    }
    fn enter_continuous_time_mode(&self) -> Status {
        unsafe { fmi2::enter_continuous_time_mode::<Oscillator>(self.0) }
    }
    fn output(&self, vr: u32) -> f64 {
        let mut v = f64::NAN;
        assert_eq!(unsafe { fmi2::get_real::<Oscillator>(self.0, &vr, 1, &mut v) }, Status::Ok);
        v
    }
}

const PARAMS: Params = Params { omega: 3.0, zeta: 0.2, x0: 0.5, v0: 1.0, kick_time: 0.73, kick_dv: -0.8 };

fn vr(i: usize) -> u32 {
    i as u32 + 1
}

/// Parameter (vr, value) pairs of `p`.
fn param_values(p: &Params) -> [(u32, f64); 6] {
    [
        (vr(OMEGA), p.omega),
        (vr(ZETA), p.zeta),
        (vr(X0), p.x0),
        (vr(V0), p.v0),
        (vr(KICK_TIME), p.kick_time),
        (vr(KICK_DV), p.kick_dv),
    ]
}

fn instantiate3(p: &Params, t0: f64, logs: &mut Logs) -> Fmi3 {
    let token = CString::new(Oscillator::TOKEN).unwrap();
    let env = (logs as *mut Logs).cast();
    unsafe {
        let i = fmi3::instantiate_model_exchange::<Oscillator>(
            c"osc".as_ptr(),
            token.as_ptr(),
            std::ptr::null(),
            0,
            0,
            env,
            Some(log3),
        );
        assert!(!i.is_null());
        for (r, v) in param_values(p) {
            assert_eq!(fmi3::set_float64::<Oscillator>(i, &r, 1, &v, 1), Status::Ok);
        }
        assert_eq!(fmi3::enter_initialization_mode::<Oscillator>(i, 0, 0.0, t0, 0, 0.0), Status::Ok);
        assert_eq!(fmi3::exit_initialization_mode::<Oscillator>(i), Status::Ok);
        Fmi3(i)
    }
}

fn instantiate2(p: &Params, t0: f64, logs: &mut Logs) -> (Fmi2, Box<CallbackFunctions>) {
    let guid = CString::new(Oscillator::GUID).unwrap();
    let cb = Box::new(callbacks((logs as *mut Logs).cast()));
    unsafe {
        let i = fmi2::instantiate::<Oscillator>(
            c"osc".as_ptr(),
            FMI2_MODEL_EXCHANGE,
            guid.as_ptr(),
            std::ptr::null(),
            &*cb,
            0,
            0,
        );
        assert!(!i.is_null());
        for (r, v) in param_values(p) {
            assert_eq!(fmi2::set_real::<Oscillator>(i, &r, 1, &v), Status::Ok);
        }
        assert_eq!(fmi2::setup_experiment::<Oscillator>(i, 0, 0.0, t0, 0, 0.0), Status::Ok);
        assert_eq!(fmi2::enter_initialization_mode::<Oscillator>(i), Status::Ok);
        assert_eq!(fmi2::exit_initialization_mode::<Oscillator>(i), Status::Ok);
        (Fmi2(i), cb)
    }
}

/// Integrates from `t0` to `t_end` with RK4 (step `h`, cut at time events), handling events
/// the FMI way; returns the largest deviation from the closed form seen at the step ends
/// and the times events were handled at.
fn integrate(fmu: &dyn Me, p: &Params, t0: f64, t_end: f64, h: f64) -> (f64, Vec<f64>) {
    let (changed, mut next) = fmu.update();
    let mut events = Vec::new();
    if changed {
        events.push(t0);
    }
    assert_eq!(fmu.enter_continuous_time_mode(), Status::Ok);
    let (mut t, mut worst) = (t0, 0.0f64);
    let f = |t: f64, x: [f64; 2]| {
        assert_eq!(fmu.set_time(t), Status::Ok);
        assert_eq!(fmu.set_states(&x), Status::Ok);
        fmu.derivatives()
    };
    while t < t_end {
        let target = next.map_or(t_end, |te| te.min(t_end));
        let step = h.min(target - t);
        let x = fmu.states();
        let k1 = f(t, x);
        let k2 = f(t + step / 2.0, [x[0] + step / 2.0 * k1[0], x[1] + step / 2.0 * k1[1]]);
        let k3 = f(t + step / 2.0, [x[0] + step / 2.0 * k2[0], x[1] + step / 2.0 * k2[1]]);
        let k4 = f(t + step, [x[0] + step * k3[0], x[1] + step * k3[1]]);
        let x1 = [
            x[0] + step / 6.0 * (k1[0] + 2.0 * k2[0] + 2.0 * k3[0] + k4[0]),
            x[1] + step / 6.0 * (k1[1] + 2.0 * k2[1] + 2.0 * k3[1] + k4[1]),
        ];
        t = if step == target - t { target } else { t + step };
        assert_eq!(fmu.set_time(t), Status::Ok);
        assert_eq!(fmu.set_states(&x1), Status::Ok);
        if next == Some(t) {
            assert_eq!(fmu.enter_event_mode(), Status::Ok);
            let (changed, n) = fmu.update();
            if changed {
                events.push(t);
            }
            next = n;
            assert_eq!(fmu.enter_continuous_time_mode(), Status::Ok);
        }
        let (xe, ve) = solution(p, t0, t);
        let got = [fmu.output(vr(X)), fmu.output(vr(V))];
        assert_eq!(got, fmu.states(), "the outputs are the states");
        let d = fmu.derivatives();
        let want_d = [ve, -2.0 * p.zeta * p.omega * ve - p.omega * p.omega * xe];
        worst = worst.max((got[0] - xe).abs()).max((got[1] - ve).abs());
        worst = worst.max((d[0] - want_d[0]).abs() / 10.0).max((d[1] - want_d[1]).abs() / 10.0);
    }
    (worst, events)
}

#[test]
fn fmi3_rk4_matches_the_closed_form_across_the_kick() {
    let mut logs = Logs::default();
    let fmu = instantiate3(&PARAMS, 0.0, &mut logs);
    assert_eq!(fmu.states(), [PARAMS.x0, PARAMS.v0]);
    let (worst, events) = integrate(&fmu, &PARAMS, 0.0, 3.0, 1e-3);
    assert_eq!(events, vec![PARAMS.kick_time]);
    assert!(worst < 1e-9, "max deviation {worst:e}");
    unsafe { fmi3::free_instance::<Oscillator>(fmu.0) };
    assert!(logs.0.is_empty(), "{:?}", logs.0);
}

#[test]
fn fmi2_rk4_matches_the_closed_form_across_the_kick() {
    let mut logs = Logs::default();
    let (fmu, _cb) = instantiate2(&PARAMS, 0.0, &mut logs);
    let (worst, events) = integrate(&fmu, &PARAMS, 0.0, 3.0, 1e-3);
    assert_eq!(events, vec![PARAMS.kick_time]);
    assert!(worst < 1e-9, "max deviation {worst:e}");
    unsafe { fmi2::free_instance::<Oscillator>(fmu.0) };
    assert!(logs.0.is_empty(), "{:?}", logs.0);
}

#[test]
fn every_damping_regime_and_a_later_start_match() {
    for zeta in [0.0, 1.0, 2.5] {
        let p = Params { zeta, ..PARAMS };
        let mut logs = Logs::default();
        let fmu = instantiate3(&p, 0.25, &mut logs);
        let (worst, events) = integrate(&fmu, &p, 0.25, 2.0, 1e-3);
        assert_eq!(events, vec![p.kick_time]);
        assert!(worst < 1e-8, "zeta {zeta}: max deviation {worst:e}");
        unsafe { fmi3::free_instance::<Oscillator>(fmu.0) };
    }
}

#[test]
fn kick_at_the_start_is_applied_in_the_initial_event_update_and_none_before_it() {
    let mut logs = Logs::default();
    let at_start = Params { kick_time: 0.5, ..PARAMS };
    let fmu = instantiate3(&at_start, 0.5, &mut logs);
    assert_eq!(fmu.output(vr(V)), at_start.v0, "initialization shows the state before the event");
    assert_eq!(fmu.update(), (true, None));
    assert_eq!(fmu.states(), [at_start.x0, at_start.v0 + at_start.kick_dv]);
    unsafe { fmi3::free_instance::<Oscillator>(fmu.0) };
    for kick_time in [0.0, -1.0, 0.2] {
        let fmu = instantiate3(&Params { kick_time, ..PARAMS }, 0.5, &mut logs);
        assert_eq!(fmu.update(), (false, None), "kick_time {kick_time}");
        unsafe { fmi3::free_instance::<Oscillator>(fmu.0) };
    }
    assert!(logs.0.is_empty(), "{:?}", logs.0);
}

#[test]
fn a_restored_state_before_the_kick_gets_the_kick_again() {
    let mut logs = Logs::default();
    let fmu = instantiate3(&PARAMS, 0.0, &mut logs);
    assert_eq!(fmu.update(), (false, Some(PARAMS.kick_time)));
    assert_eq!(fmu.enter_continuous_time_mode(), Status::Ok);
    let mut saved = std::ptr::null_mut();
    unsafe { assert_eq!(fmi3::get_fmu_state::<Oscillator>(fmu.0, &mut saved), Status::Ok) };
    // Through the serialized form too: the pending kick is part of the model's state.
    let mut n = 0;
    unsafe { assert_eq!(fmi3::serialized_fmu_state_size::<Oscillator>(fmu.0, saved, &mut n), Status::Ok) };
    let mut bytes = vec![0u8; n];
    unsafe { assert_eq!(fmi3::serialize_fmu_state::<Oscillator>(fmu.0, saved, bytes.as_mut_ptr(), n), Status::Ok) };
    let (first, _) = integrate_from_ct(&fmu);
    let mut copy = std::ptr::null_mut();
    unsafe {
        assert_eq!(fmi3::deserialize_fmu_state::<Oscillator>(fmu.0, bytes.as_ptr(), n, &mut copy), Status::Ok);
        assert_eq!(fmi3::set_fmu_state::<Oscillator>(fmu.0, copy), Status::Ok);
    }
    let (again, kicked) = integrate_from_ct(&fmu);
    assert!(kicked, "the kick must happen again after the restore");
    assert_eq!(first, again);
    unsafe { fmi3::free_instance::<Oscillator>(fmu.0) };
    assert!(logs.0.is_empty(), "{:?}", logs.0);
}

/// Euler steps of 0.1 s from 0 to 1 s in Continuous-Time Mode, with the kick at 0.73 s.
fn integrate_from_ct(fmu: &Fmi3) -> ([f64; 2], bool) {
    let mut kicked = false;
    let mut t = 0.0;
    for k in 1..=10 {
        let t1 = if k == 8 && !kicked { PARAMS.kick_time } else { k as f64 / 10.0 };
        let (x, d) = (fmu.states(), fmu.derivatives());
        assert_eq!(fmu.set_time(t1), Status::Ok);
        assert_eq!(fmu.set_states(&[x[0] + (t1 - t) * d[0], x[1] + (t1 - t) * d[1]]), Status::Ok);
        t = t1;
        if t1 == PARAMS.kick_time {
            assert_eq!(fmu.enter_event_mode(), Status::Ok);
            kicked = fmu.update().0;
            assert_eq!(fmu.enter_continuous_time_mode(), Status::Ok);
        }
    }
    (fmu.states(), kicked)
}

#[test]
fn co_simulation_and_wrong_calls_are_refused_and_logged() {
    let mut logs = Logs::default();
    let env: *mut c_void = (&mut logs as *mut Logs).cast();
    let token = CString::new(Oscillator::TOKEN).unwrap();
    let guid = CString::new(Oscillator::GUID).unwrap();
    unsafe {
        let cs = fmi3::instantiate_co_simulation::<Oscillator>(
            c"cs".as_ptr(),
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
        );
        assert!(cs.is_null());
        let cb = callbacks(env);
        let cs2 = fmi2::instantiate::<Oscillator>(
            c"cs".as_ptr(),
            FMI2_CO_SIMULATION,
            guid.as_ptr(),
            std::ptr::null(),
            &cb,
            0,
            0,
        );
        assert!(cs2.is_null());
        assert!(logs.0.iter().all(|m| m.contains("supports Model Exchange")) && logs.0.len() == 2, "{:?}", logs.0);
        logs.0.clear();

        let fmu = instantiate3(&PARAMS, 0.0, &mut logs);
        let i = fmu.0;
        // Event Mode after initialization: continuous states cannot be set yet.
        assert_eq!(fmi3::set_continuous_states::<Oscillator>(i, [0.0, 0.0].as_ptr(), 2), Status::Error);
        assert!(
            logs.0.last().unwrap().contains("fmi3SetContinuousStates") && logs.0.last().unwrap().contains("Event Mode")
        );
        assert_eq!(fmi3::reset::<Oscillator>(i), Status::Ok);
        let fmu = instantiate_again(i);
        let mut n = 0usize;
        assert_eq!(fmi3::get_number_of_continuous_states::<Oscillator>(fmu, &mut n), Status::Ok);
        assert_eq!(n, 2);
        assert_eq!(fmi3::get_number_of_event_indicators::<Oscillator>(fmu, &mut n), Status::Ok);
        assert_eq!(n, 0);
        let mut nominals = [0.0; 2];
        assert_eq!(fmi3::get_nominals_of_continuous_states::<Oscillator>(fmu, nominals.as_mut_ptr(), 2), Status::Ok);
        assert_eq!(nominals, [1.0, 1.0]);
        assert_eq!(fmi3::enter_continuous_time_mode::<Oscillator>(fmu), Status::Ok);
        type Call = unsafe fn(*mut c_void) -> Status;
        let bad: [(&str, Call); 5] = [
            ("nx", |i| fmi3::set_continuous_states::<Oscillator>(i, [0.0; 3].as_ptr(), 3)),
            ("not finite", |i| fmi3::set_continuous_states::<Oscillator>(i, [0.0, f64::NAN].as_ptr(), 2)),
            ("time must be finite", |i| fmi3::set_time::<Oscillator>(i, f64::INFINITY)),
            ("no event indicators", |i| fmi3::get_event_indicators::<Oscillator>(i, [0.0; 1].as_mut_ptr(), 1)),
            ("Model Exchange FMU", |i| fmi3::unsupported::<Oscillator>(i, "fmi3EnterStepMode")),
        ];
        for (why, call) in bad {
            assert_eq!(call(fmu), Status::Error, "{why}");
            assert!(logs.0.last().is_some_and(|m| m.contains(why)), "{why}: {:?}", logs.0);
            // Error is sticky: the next call fails too, until Reset.
            assert_eq!(fmi3::enter_event_mode::<Oscillator>(fmu), Status::Error);
            assert_eq!(fmi3::reset::<Oscillator>(fmu), Status::Ok);
            instantiate_again(fmu);
            assert_eq!(fmi3::enter_continuous_time_mode::<Oscillator>(fmu), Status::Ok);
        }
        let (mut a, mut b, mut c, mut d) = (0, 0, 0, 0.0);
        assert_eq!(fmi3::do_step::<Oscillator>(fmu, 0.0, 0.01, 0, &mut a, &mut b, &mut c, &mut d), Status::Error);
        fmi3::free_instance::<Oscillator>(fmu);
    }
}

/// After Reset: initialization again, ending in Event Mode.
unsafe fn instantiate_again(i: *mut c_void) -> *mut c_void {
    assert_eq!(fmi3::enter_initialization_mode::<Oscillator>(i, 0, 0.0, 0.0, 0, 0.0), Status::Ok);
    assert_eq!(fmi3::exit_initialization_mode::<Oscillator>(i), Status::Ok);
    i
}
