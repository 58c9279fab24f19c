//! Randomized call-sequence harness for any [`Model`]: every FMU crate runs
//! `agrisim_fmi::testing::fuzz_fmi3::<M>(seed, cases)` and `fuzz_fmi2` in a one-line test.
//!
//! Each case instantiates (sometimes wrongly), then issues random calls into the generic API
//! layer: legal and illegal order, NULL and garbage handles and pointers, unknown value
//! references, type mismatches, wrong array sizes, NaN/huge/negative times, FMU-state
//! round trips, unsupported functions. A shadow state machine predicts what must happen.
//! Asserted: no panic escapes, every status is a valid value, illegal calls fail, errors move
//! the instance to Error (where only the allowed calls work), every failure on a live
//! instance is logged with the function's name, time after a step is `tc + h`.
//! Failures panic with the seed, case and call trace.

use std::ffi::{c_char, c_int, c_void, CString};

use crate::ctype::{self, CType};
use crate::fmi2::{self, CallbackFunctions};
use crate::fmi3;
use crate::instance::Instance;
use crate::logger::Fmi2Logger;
use crate::model::{Model, Quiet};
use crate::state::{self, Mask, Mode, Status};
use crate::store::{Store, Value};
use crate::var::{Causality, Start, Var, Variability};
use crate::xml::is_initial_unknown;

/// Asserts that `M`'s variable table yields a valid FMU (see [`crate::xml::check_table`]),
/// that every initial unknown declares its dependencies and that the tokens are the derived ones.
pub fn assert_valid_table<M: Model>() {
    let mut problems = crate::xml::check_table(M::VARIABLES);
    for v in M::VARIABLES.iter().filter(|v| is_initial_unknown(v) && v.initial_dependencies.is_none()) {
        problems.push(format!("'{}': no init_depends_on declaration (what its initial value depends on)", v.name));
    }
    let derived = |version| crate::token::guid(crate::token::hash(version, M::NAME, M::VARIABLES));
    if M::TOKEN.as_bytes() != derived("3.0") || M::GUID.as_bytes() != derived("2.0") {
        problems.push("TOKEN / GUID overridden: they must be the hashes of the table (crate::token)".into());
    }
    assert!(problems.is_empty(), "{}: invalid variable table:\n{}", M::NAME, problems.join("\n"));
}

/// Same value (NaN equals NaN).
fn same(a: &Value, b: &Value) -> bool {
    match (a, b) {
        (Value::Float64(x), Value::Float64(y)) => x.to_bits() == y.to_bits() || x == y,
        _ => a == b,
    }
}

/// Values a known can take instead of its start value `v`, nearest first, within its range.
fn perturbations(var: &Var, v: &Value) -> Vec<Value> {
    let within = |x: f64| var.min.is_none_or(|m| x >= m) && var.max.is_none_or(|m| x <= m);
    match *v {
        Value::Float64(x) => {
            let d = (x.abs() * 0.25).max(0.1);
            [x + d, x - d, x * 2.0, x * 0.5].into_iter().filter(|&y| y != x && within(y)).map(Value::Float64).collect()
        }
        Value::Int32(x) => [x.wrapping_add(1), x.wrapping_sub(1), x.wrapping_add(7)]
            .into_iter()
            .filter(|&y| within(y as f64))
            .map(Value::Int32)
            .collect(),
        Value::Int64(x) => vec![Value::Int64(x.wrapping_add(1))],
        Value::Boolean(b) => vec![Value::Boolean(!b)],
        Value::String(ref s) if !s.is_empty() => vec![Value::String(String::new())],
        _ => Vec::new(),
    }
}

/// Checks `M`'s declared initial dependencies ([`Var::init_depends_on`]) against the model:
/// with every known at its start value but one, changed to the first value the model
/// initializes with (from `extra` for that known, then a nearby value within its range, the
/// negated Boolean, an empty String), every initial unknown whose value changes must list
/// that known; likewise for a later start time ([`Var::TIME`]). A falsification test: it
/// finds dependencies the table misses.
pub fn assert_initial_dependencies<M: Model>(extra: &[(usize, Value)]) {
    let unknowns: Vec<usize> = (0..M::VARIABLES.len()).filter(|&i| is_initial_unknown(&M::VARIABLES[i])).collect();
    let initial = |store: &mut Store, start: f64| M::new().initialize(store, start, &mut Quiet).map(|_| store.clone());
    let base = initial(&mut Store::new(M::VARIABLES), 0.0)
        .unwrap_or_else(|e| panic!("{}: does not initialize with its start values: {e}", M::NAME));
    let mut problems = Vec::new();
    let mut compare = |changed: &Store, known: usize, what: &str| {
        for &i in &unknowns {
            let listed = M::VARIABLES[i].initial_dependencies.is_none_or(|d| d.contains(&known));
            if !listed && !same(changed.value(i), base.value(i)) {
                problems.push(format!("'{}' changes with {what} but does not list it", M::VARIABLES[i].name));
            }
        }
    };
    if let Ok(later) = initial(&mut Store::new(M::VARIABLES), 0.37) {
        compare(&later, Var::TIME, "the start time");
    }
    for (k, var) in M::VARIABLES.iter().enumerate() {
        if !matches!(var.causality, Causality::Parameter | Causality::Input) {
            continue;
        }
        let start = Value::from_start(&var.start);
        let own = extra.iter().filter(|(i, _)| *i == k).map(|(_, v)| v.clone());
        for value in own.chain(perturbations(var, &start)) {
            let mut store = Store::new(M::VARIABLES);
            *store.value_mut(k) = value;
            if let Ok(changed) = initial(&mut store, 0.0) {
                compare(&changed, k, &format!("'{}'", var.name));
                break;
            }
        }
    }
    assert!(problems.is_empty(), "{}: initial dependencies incomplete:\n{}", M::NAME, problems.join("\n"));
}

/// Sets variable `i` to `value` (when given) and reads it back, through the FMI 3 layer's
/// setter and getter of type `T`.
unsafe fn access<M: Model, T: CType>(inst: *mut c_void, i: usize, value: Option<&Value>) -> Value {
    let vr = [i as u32 + 1];
    let name = M::VARIABLES[i].name;
    if let Some(v) = value {
        let mut keep = Vec::new();
        let x = T::read(v, &mut keep);
        assert_eq!(fmi3::set::<M, T>(inst, "set", vr.as_ptr(), 1, &x, 1), Status::Ok, "{}: setting '{name}'", M::NAME);
    }
    let mut x = zeroed::<T::C>(1);
    assert_eq!(
        fmi3::get::<M, T>(inst, "get", vr.as_ptr(), 1, x.as_mut_ptr(), 1),
        Status::Ok,
        "{}: getting '{name}'",
        M::NAME
    );
    T::decode(x[0]).unwrap_or_else(|e| panic!("{}: '{name}' read back: {e}", M::NAME))
}

/// [`access`] with the type of variable `i`.
unsafe fn access3<M: Model>(inst: *mut c_void, i: usize, value: Option<&Value>) -> Value {
    match M::VARIABLES[i].start {
        Start::Float64(_) => access::<M, ctype::Float64>(inst, i, value),
        Start::Int32(_) => access::<M, ctype::Int32>(inst, i, value),
        Start::Int64(_) => access::<M, ctype::Int64>(inst, i, value),
        Start::Boolean(_) => access::<M, ctype::Bool3>(inst, i, value),
        Start::String(_) => access::<M, ctype::Str>(inst, i, value),
        Start::Binary(_) => access::<M, ctype::Bin>(inst, i, value),
    }
}

/// Checks what `<Output dependencies="">` declares: within a communication point no output
/// changes when inputs or tunable parameters are set (after initialization and after a step,
/// each of them is set to another value and every output read again).
pub fn assert_no_direct_feedthrough<M: Model>() {
    unsafe {
        let token = CString::new(M::TOKEN).unwrap_or_default();
        let inst = fmi3::instantiate_co_simulation::<M>(
            c"feedthrough".as_ptr(),
            token.as_ptr(),
            std::ptr::null(),
            0,
            0,
            0,
            0,
            std::ptr::null(),
            0,
            std::ptr::null_mut(),
            None,
            None,
        );
        assert!(!inst.is_null(), "{}: instantiation failed", M::NAME);
        assert_eq!(fmi3::enter_initialization_mode::<M>(inst, 0, 0.0, 0.0, 0, 0.0), Status::Ok);
        assert_eq!(fmi3::exit_initialization_mode::<M>(inst), Status::Ok, "{}: initialization failed", M::NAME);
        let with = |c| (0..M::VARIABLES.len()).filter(move |&i| M::VARIABLES[i].causality == c);
        let outputs = || with(Causality::Output).map(|i| access3::<M>(inst, i, None)).collect::<Vec<_>>();
        let tunable = |&i: &usize| M::VARIABLES[i].variability == Variability::Tunable;
        let knowns = || with(Causality::Input).chain(with(Causality::Parameter).filter(tunable));
        for round in 0..2 {
            if round == 1 {
                let (mut ev, mut term, mut early, mut last) = (0, 0, 0, 0.0);
                assert_eq!(
                    fmi3::do_step::<M>(inst, 0.0, 0.02, 0, &mut ev, &mut term, &mut early, &mut last),
                    Status::Ok
                );
            }
            let before = outputs();
            for i in knowns() {
                let var = &M::VARIABLES[i];
                if let Some(v) = perturbations(var, &Value::from_start(&var.start)).first() {
                    access3::<M>(inst, i, Some(v));
                }
            }
            let after = outputs();
            for ((i, a), b) in with(Causality::Output).zip(&before).zip(&after) {
                assert!(
                    same(a, b),
                    "{}: output '{}' changed when inputs were set without a step",
                    M::NAME,
                    M::VARIABLES[i].name
                );
            }
            // Back to the start values, which the model steps with.
            for i in knowns() {
                access3::<M>(inst, i, Some(&Value::from_start(&M::VARIABLES[i].start)));
            }
        }
        fmi3::free_instance::<M>(inst);
    }
}

/// The allowed-call tables, written out again on purpose: the harness is an independent
/// oracle and must not share the layer's masks (FMI 3.0 section 4.2 / FMI 2.0 section 4.2.4,
/// co-simulation without event mode; Error = after a call returned Error).
mod spec3 {
    use crate::state::{Mask, ERROR, INITIALIZATION, INSTANTIATED, STEP, TERMINATED};
    const ALIVE: Mask = INSTANTIATED | INITIALIZATION | STEP | TERMINATED;
    pub const SET_DEBUG_LOGGING: Mask = ALIVE | ERROR;
    pub const ENTER_INITIALIZATION_MODE: Mask = INSTANTIATED;
    pub const EXIT_INITIALIZATION_MODE: Mask = INITIALIZATION;
    pub const TERMINATE: Mask = STEP;
    pub const RESET: Mask = ALIVE | ERROR;
    pub const GET: Mask = INITIALIZATION | STEP | TERMINATED;
    pub const SET: Mask = INSTANTIATED | INITIALIZATION | STEP;
    pub const GET_FMU_STATE: Mask = ALIVE;
    pub const SET_FMU_STATE: Mask = ALIVE | ERROR;
    pub const FREE_FMU_STATE: Mask = ALIVE | ERROR;
    pub const DESERIALIZE_FMU_STATE: Mask = ALIVE | ERROR;
    pub const DO_STEP: Mask = STEP;
}

mod spec2 {
    use crate::state::{Mask, ERROR, INITIALIZATION, INSTANTIATED, STEP, TERMINATED};
    const ALIVE: Mask = INSTANTIATED | INITIALIZATION | STEP | TERMINATED;
    pub const SET_DEBUG_LOGGING: Mask = ALIVE | ERROR;
    pub const SETUP_EXPERIMENT: Mask = INSTANTIATED;
    pub const ENTER_INITIALIZATION_MODE: Mask = INSTANTIATED;
    pub const EXIT_INITIALIZATION_MODE: Mask = INITIALIZATION;
    pub const TERMINATE: Mask = STEP;
    pub const RESET: Mask = ALIVE | ERROR;
    pub const GET: Mask = INITIALIZATION | STEP | TERMINATED | ERROR;
    pub const SET: Mask = INSTANTIATED | INITIALIZATION | STEP;
    pub const GET_FMU_STATE: Mask = ALIVE | ERROR;
    pub const SET_FMU_STATE: Mask = ALIVE | ERROR;
    pub const FREE_FMU_STATE: Mask = ALIVE | ERROR;
    pub const DESERIALIZE_FMU_STATE: Mask = ALIVE | ERROR;
    pub const DO_STEP: Mask = STEP;
    pub const GET_STATUS: Mask = STEP | TERMINATED | ERROR;
}

/// The harness' draws, on the workspace's generator (`agrisim_math::Rng`, noise flavour):
/// reproducible per seed; indices are `usize` (`below(0)` is 0), plus percent chances and
/// special float and integer values.
pub struct FuzzRng(agrisim_math::Rng);

impl FuzzRng {
    pub fn new(seed: u64) -> FuzzRng {
        FuzzRng(agrisim_math::Rng::new(seed))
    }
    pub fn next_u64(&mut self) -> u64 {
        self.0.next_u64()
    }
    pub fn below(&mut self, n: usize) -> usize {
        self.0.below(n.max(1) as u64) as usize
    }
    pub fn chance(&mut self, percent: u64) -> bool {
        self.next_u64() % 100 < percent
    }
    fn pick<T: Copy>(&mut self, xs: &[T]) -> T {
        xs[self.below(xs.len())]
    }
    fn f64(&mut self) -> f64 {
        match self.below(10) {
            0 => f64::NAN,
            1 => self.pick(&[f64::INFINITY, f64::NEG_INFINITY, 1e300, -1e300]),
            2 => 0.0,
            _ => (self.next_u64() % 2001) as f64 / 100.0 - 10.0,
        }
    }
    fn int(&mut self) -> i64 {
        match self.below(4) {
            0 => self.next_u64() as i64,
            _ => self.below(7) as i64 - 2,
        }
    }
}

/// Log messages received through the logger callback of the current case.
#[derive(Default)]
struct Logs(Vec<(Status, String)>);

unsafe extern "C" fn log3(env: *mut c_void, status: Status, _category: *const c_char, message: *const c_char) {
    let logs = &mut *(env as *mut Logs);
    logs.0.push((status, std::ffi::CStr::from_ptr(message).to_string_lossy().into_owned()));
}

unsafe extern "C" fn log2_fixed(
    env: *mut c_void,
    _name: *const c_char,
    status: Status,
    category: *const c_char,
    message: *const c_char,
) {
    log3(env, status, category, message)
}

/// A non-variadic function called through the variadic `fmi2CallbackLogger` type (what
/// every non-C importer does; no variadic arguments are ever passed).
fn log2() -> Fmi2Logger {
    // SAFETY: identical fixed arguments; the FMU passes no variadic arguments.
    unsafe {
        std::mem::transmute::<
            unsafe extern "C" fn(*mut c_void, *const c_char, Status, *const c_char, *const c_char),
            Fmi2Logger,
        >(log2_fixed)
    }
}

/// What the shadow expects of a call's result.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Must {
    /// Any status (e.g. the model may fail).
    Any,
    /// Arguments are wrong: Error (or Fatal in Fatal).
    Fail,
    /// Arguments are right and no model code runs: OK (or Warning) when the mode allows it.
    Succeed,
}

#[derive(Clone, Copy, Debug)]
enum Then {
    Nothing,
    Mode(Mode),
    Restore(*mut c_void),
    NewState(*mut c_void),
    FreedState(*mut c_void),
    /// A new state holding what the first one holds (a deserialized copy).
    Copied(*mut c_void, *mut c_void),
    Stepped(f64),
}

struct Outcome {
    function: &'static str,
    mask: Mask,
    status: Status,
    must: Must,
    then: Then,
}

/// The shadow of one instance.
struct Shadow {
    mode: Mode,
    /// Live FMU states and the mode they captured.
    states: Vec<(*mut c_void, Mode, f64)>,
    /// Freed state pointers (to pass again: must fail).
    freed: Vec<*mut c_void>,
    time: f64,
}

/// Things whose pointers are handed to the FMU during one call.
#[derive(Default)]
struct Keep {
    strings: Vec<CString>,
    bytes: Vec<Vec<u8>>,
}

fn garbage_ptr(rng: &mut FuzzRng) -> *mut c_void {
    // Never dereferenced by a correct layer: only compared against its registries.
    (0x1000 + (rng.next_u64() % 0xFFFF_0000) * 8) as *mut c_void
}

/// Value references: mostly ones accepting `T`, sometimes any, sometimes unknown.
fn pick_vrs<M: Model, T: CType>(rng: &mut FuzzRng, fmi2_only: bool) -> Vec<u32> {
    let n = match rng.below(6) {
        0 => 0,
        1 => 2 + rng.below(3),
        _ => 1,
    };
    let visible = |i: usize| !fmi2_only || M::VARIABLES[i].fmi2_representable();
    let mut matching: Vec<u32> = (0..M::VARIABLES.len())
        .filter(|&i| visible(i) && T::accepts(&Value::from_start(&M::VARIABLES[i].start)))
        .map(|i| i as u32 + 1)
        .collect();
    if T::accepts(&Value::Float64(0.0)) {
        matching.push(0);
    }
    (0..n)
        .map(|_| match rng.below(10) {
            0 => rng.pick(&[M::VARIABLES.len() as u32 + 1, u32::MAX, 1_000_000]),
            1 | 2 => rng.below(M::VARIABLES.len() + 1) as u32,
            _ if !matching.is_empty() => rng.pick(&matching),
            _ => rng.below(M::VARIABLES.len() + 1) as u32,
        })
        .collect()
}

/// True when every reference in `vrs` is visible and of a type `T` can access.
fn all_match<M: Model, T: CType>(vrs: &[u32], fmi2_only: bool) -> bool {
    vrs.iter().all(|&vr| {
        if vr == 0 {
            return T::accepts(&Value::Float64(0.0));
        }
        match M::VARIABLES.get(vr as usize - 1) {
            Some(v) => (!fmi2_only || v.fmi2_representable()) && T::accepts(&Value::from_start(&v.start)),
            None => false,
        }
    })
}

/// Random C values for the setters.
trait Gen: CType {
    fn gen(rng: &mut FuzzRng, keep: &mut Keep) -> Self::C;
}

macro_rules! gen_int {
    ($($m:ident),*) => {$(
        impl Gen for ctype::$m {
            fn gen(rng: &mut FuzzRng, _: &mut Keep) -> Self::C {
                rng.int() as Self::C
            }
        }
    )*};
}
gen_int!(Int8, UInt8, Int16, UInt16, Int32, UInt32, Int64, UInt64, Bool2);

impl Gen for ctype::Float64 {
    fn gen(rng: &mut FuzzRng, _: &mut Keep) -> f64 {
        rng.f64()
    }
}
impl Gen for ctype::Float32 {
    fn gen(rng: &mut FuzzRng, _: &mut Keep) -> f32 {
        rng.f64() as f32
    }
}
impl Gen for ctype::Bool3 {
    fn gen(rng: &mut FuzzRng, _: &mut Keep) -> u8 {
        rng.pick(&[0, 1, 1, 2, 255])
    }
}
impl Gen for ctype::Str {
    fn gen(rng: &mut FuzzRng, keep: &mut Keep) -> *const c_char {
        let s = match rng.below(8) {
            0 => return std::ptr::null(),
            1 => CString::new(vec![0xC3u8, 0x28]).unwrap_or_default(), // invalid UTF-8
            2 => CString::new("äöü <&> \"quoted\" 100%").unwrap_or_default(),
            _ => CString::new(format!("s{}", rng.next_u64() % 1000)).unwrap_or_default(),
        };
        keep.strings.push(s);
        keep.strings.last().map_or(std::ptr::null(), |s| s.as_ptr())
    }
}
impl Gen for ctype::Bin {
    fn gen(rng: &mut FuzzRng, keep: &mut Keep) -> (usize, *const u8) {
        match rng.below(8) {
            0 => (1 + rng.below(4), std::ptr::null()),
            1 => (0, std::ptr::null()),
            _ => {
                let n = rng.below(64);
                keep.bytes.push((0..n).map(|_| rng.next_u64() as u8).collect());
                let b = keep.bytes.last().map_or(&[][..], |b| &b[..]);
                (b.len(), b.as_ptr())
            }
        }
    }
}

/// Array sizes for a get/set: (nValues, NULL values array?) and whether they are right.
fn sizes(rng: &mut FuzzRng, n_vr: usize) -> (usize, bool, bool) {
    match rng.below(12) {
        0 => (n_vr + 1, false, false),
        1 if n_vr > 0 => (n_vr - 1, false, false),
        2 if n_vr > 0 => (n_vr, true, false),
        _ => (n_vr, false, true),
    }
}

fn zeroed<T>(n: usize) -> Vec<T> {
    // SAFETY: only instantiated with C number/pointer types, for which all-zero is valid.
    (0..n).map(|_| unsafe { std::mem::zeroed() }).collect()
}

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

/// Serializes a live state, deserializes it as a new state and checks that the copy
/// serializes to the very same bytes; sometimes corrupts the bytes first (refused or
/// accepted, never a crash). A state that cannot be serialized gets junk bytes, which must
/// be refused. Only the deserialize call may fail (its outcome is the one checked).
unsafe fn round_trip(
    rng: &mut FuzzRng,
    sh: &Shadow,
    size: impl Fn(*mut c_void, *mut usize) -> Status,
    serialize: impl Fn(*mut c_void, *mut u8, usize) -> Status,
    deserialize: impl Fn(*const u8, usize, *mut *mut c_void) -> Status,
    free: impl Fn(*mut *mut c_void) -> Status,
) -> (Must, Then, Status) {
    let (src, good) = pick_state(rng, sh);
    let live = sh.mode != Mode::Fatal && good && sh.states.iter().any(|s| s.0 == src && s.1 != Mode::Error);
    let mut p = std::ptr::null_mut();
    if !live {
        let junk = [b'A', b'G', b'S', 1, 0, 7];
        let s = deserialize(junk.as_ptr(), rng.below(junk.len() + 1), &mut p);
        return (Must::Fail, Then::Nothing, s);
    }
    let mut n = 0usize;
    assert!(size(src, &mut n) <= Status::Warning, "SerializedFMUStateSize failed on a live state");
    let mut bytes = vec![0u8; n];
    assert!(serialize(src, bytes.as_mut_ptr(), n) <= Status::Warning, "SerializeFMUState failed on a live state");
    if rng.chance(10) {
        let i = rng.below(bytes.len());
        bytes[i] ^= 1 << rng.below(8);
        bytes.truncate(bytes.len() - rng.below(2) * rng.below(bytes.len()));
        let s = deserialize(bytes.as_ptr(), bytes.len(), &mut p);
        if s <= Status::Warning {
            // Accepted (a flipped bit in a value): not tracked, so freed at once.
            assert!(free(&mut p) <= Status::Warning);
        }
        return (Must::Any, Then::Nothing, s);
    }
    let s = deserialize(bytes.as_ptr(), bytes.len(), &mut p);
    if s > Status::Warning {
        return (Must::Succeed, Then::Nothing, s);
    }
    let mut again = 0usize;
    assert!(
        size(p, &mut again) <= Status::Warning && again == n,
        "a deserialized state must serialize to the same size"
    );
    let mut copy = vec![0u8; again];
    assert!(serialize(p, copy.as_mut_ptr(), again) <= Status::Warning);
    assert!(copy == bytes, "a deserialized state must serialize to the same bytes");
    (Must::Succeed, Then::Copied(src, p), s)
}

/// A state pointer: live (true), freed, garbage or NULL (false).
fn pick_state(rng: &mut FuzzRng, sh: &Shadow) -> (*mut c_void, bool) {
    match rng.below(10) {
        0 => (std::ptr::null_mut(), false),
        1 => (garbage_ptr(rng), false),
        2 if !sh.freed.is_empty() => {
            let p = sh.freed[rng.below(sh.freed.len())];
            // A freed address may have been reused by a newer live state.
            (p, sh.states.iter().any(|s| s.0 == p))
        }
        _ if !sh.states.is_empty() => (sh.states[rng.below(sh.states.len())].0, true),
        _ => (garbage_ptr(rng), false),
    }
}

/// Applies an outcome to the shadow and checks it; `trace` names the calls so far.
unsafe fn check<M: Model>(o: &Outcome, sh: &mut Shadow, inst: *mut c_void, logs: &mut Logs, trace: &str) {
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
    if matches!(sh.mode, Mode::StepMode | Mode::Terminated) && o.status <= Status::Warning {
        assert_eq!(actual.time, sh.time, "time differs from tc + h; {}", ctx());
    }
    logs.0.clear();
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

/// The conformance tests every FMU crate runs, in one line of its `tests/fmi_fuzz.rs`:
/// its variable table makes a valid FMU, its ModelStructure dependencies hold (initial
/// dependencies complete, no direct feedthrough), and `seeds` x `cases` random FMI 3 and
/// FMI 2 call sequences (illegal orders, NULLs, bad value references, wrong sizes, NaN, odd
/// step sizes) never let a panic escape nor return an invalid status.
///
/// ```ignore
/// agrisim_fmi::fmu_conformance_tests!(agrisim_chassis::ChassisKinematic, seeds = 4, cases = 300);
/// ```
#[macro_export]
macro_rules! fmu_conformance_tests {
    ($model:ty, seeds = $seeds:expr, cases = $cases:expr) => {
        #[test]
        fn variable_table_makes_a_valid_fmu() {
            $crate::testing::assert_valid_table::<$model>();
        }

        #[test]
        fn initial_dependencies_are_complete() {
            $crate::testing::assert_initial_dependencies::<$model>(&[]);
        }

        #[test]
        fn no_output_changes_when_inputs_are_set() {
            $crate::testing::assert_no_direct_feedthrough::<$model>();
        }

        #[test]
        fn random_fmi3_call_sequences() {
            for seed in 0..$seeds {
                $crate::testing::fuzz_fmi3::<$model>(seed, $cases);
            }
        }

        #[test]
        fn random_fmi2_call_sequences() {
            for seed in 0..$seeds {
                $crate::testing::fuzz_fmi2::<$model>(seed, $cases);
            }
        }

        #[test]
        fn serialized_states_restore_exactly() {
            let h = <$model as $crate::Model>::STEP_SIZE;
            $crate::testing::assert_state_round_trip::<$model>(
                &[],
                h,
                13,
                12,
                &$crate::testing::wiggle_inputs::<$model>,
            );
        }
    };
}

/// Sets every Float64 input to a slow wave around its start value (inside its bounds) and
/// every Int32 `*_seq` input (a scalar command counter) to a new value, so a model driven by
/// it moves: a default drive for [`assert_state_round_trip`].
pub fn wiggle_inputs<M: Model>(io: &mut Store, k: usize) {
    for (i, v) in M::VARIABLES.iter().enumerate() {
        match (v.causality, &v.start) {
            (Causality::Input, Start::Float64(start)) => {
                let x = start + 0.3 * (0.37 * k as f64 + i as f64).sin();
                io.set_f64(i, x.clamp(v.min.unwrap_or(f64::MIN), v.max.unwrap_or(f64::MAX)));
            }
            (Causality::Input, Start::Int32(_)) if v.name.ends_with("_seq") => io.set_i32(i, k as i32 + 1),
            _ => {}
        }
    }
}

/// One instance driven through the FMI 3 layer for [`assert_state_round_trip`].
struct Driven<M: Model> {
    p: *mut c_void,
    logs: Box<Logs>,
    _m: std::marker::PhantomData<M>,
}

impl<M: Model> Driven<M> {
    /// Instantiated, `params` set (straight into the store: any type).
    unsafe fn new(params: &[(usize, Value)]) -> Driven<M> {
        let token = CString::new(M::TOKEN).unwrap_or_default();
        let mut logs = Box::new(Logs::default());
        let env = (&mut *logs as *mut Logs).cast::<c_void>();
        let p = fmi3::instantiate_co_simulation::<M>(
            c"rt".as_ptr(),
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
        assert!(!p.is_null(), "{}: instantiation failed: {:?}", M::NAME, logs.0);
        let d = Driven { p, logs, _m: std::marker::PhantomData };
        for (i, v) in params {
            *d.inst().store.value_mut(*i) = v.clone();
        }
        d
    }

    unsafe fn inst(&self) -> &mut Instance<M> {
        &mut *self.p.cast::<Instance<M>>()
    }

    unsafe fn ok(&self, s: Status, what: &str) {
        assert!(s <= Status::Warning, "{}: {what} returned {s:?}; log: {:?}", M::NAME, self.logs.0);
    }

    unsafe fn initialize(&self) {
        self.ok(fmi3::enter_initialization_mode::<M>(self.p, 0, 0.0, 0.0, 0, 0.0), "EnterInitializationMode");
        self.ok(fmi3::exit_initialization_mode::<M>(self.p), "ExitInitializationMode");
    }

    /// Steps `n` times from step `first`, `drive` setting inputs before each; returns every
    /// value after every step (time included).
    unsafe fn run(&self, first: usize, n: usize, h: f64, drive: &dyn Fn(&mut Store, usize)) -> Vec<(f64, Store)> {
        let mut out = Vec::with_capacity(n);
        for k in first..first + n {
            drive(&mut self.inst().store, k);
            let t = self.inst().time;
            let (mut e, mut term, mut early, mut last) = (0u8, 0u8, 0u8, 0.0);
            self.ok(fmi3::do_step::<M>(self.p, t, h, 0, &mut e, &mut term, &mut early, &mut last), "DoStep");
            out.push((self.inst().time, self.inst().store.clone()));
        }
        out
    }

    unsafe fn serialize(&self, state: *mut c_void) -> Vec<u8> {
        let mut n = 0usize;
        self.ok(fmi3::serialized_fmu_state_size::<M>(self.p, state, &mut n), "SerializedFMUStateSize");
        let mut bytes = vec![0u8; n];
        self.ok(fmi3::serialize_fmu_state::<M>(self.p, state, bytes.as_mut_ptr(), n), "SerializeFMUState");
        bytes
    }

    /// The serialized form of the current state.
    unsafe fn serialize_current(&self) -> Vec<u8> {
        let mut s = std::ptr::null_mut();
        self.ok(fmi3::get_fmu_state::<M>(self.p, &mut s), "GetFMUState");
        let bytes = self.serialize(s);
        self.ok(fmi3::free_fmu_state::<M>(self.p, &mut s), "FreeFMUState");
        bytes
    }

    unsafe fn restore(&self, bytes: &[u8]) {
        let mut s = std::ptr::null_mut();
        self.ok(fmi3::deserialize_fmu_state::<M>(self.p, bytes.as_ptr(), bytes.len(), &mut s), "DeserializeFMUState");
        self.ok(fmi3::set_fmu_state::<M>(self.p, s), "SetFMUState");
        self.ok(fmi3::free_fmu_state::<M>(self.p, &mut s), "FreeFMUState");
    }
}

impl<M: Model> Drop for Driven<M> {
    fn drop(&mut self) {
        unsafe { fmi3::free_instance::<M>(self.p) };
    }
}

fn assert_same_run<M: Model>(what: &str, expected: &[(f64, Store)], got: &[(f64, Store)]) {
    assert_eq!(expected.len(), got.len());
    for (k, ((t0, a), (t1, b))) in expected.iter().zip(got).enumerate() {
        assert_eq!(t0.to_bits(), t1.to_bits(), "{}: {what}: time differs after step {k}", M::NAME);
        for (i, v) in M::VARIABLES.iter().enumerate() {
            assert!(
                a.value(i).identical(b.value(i)),
                "{}: {what}: variable '{}' differs {k} steps after the restore",
                M::NAME,
                v.name
            );
        }
    }
}

/// Serialized FMU states restore exactly: a model run `before` steps, its state serialized,
/// then `after` more steps; the same bytes deserialized into this instance and into a fresh
/// instance (which rebuilds the model from the saved parameters), restored and stepped give
/// every variable bit for bit as the uninterrupted run. `drive` sets inputs before step k.
/// Also: a serialized Instantiated state restores, and corrupt or foreign bytes are refused.
/// Returns the size of the serialized state.
pub fn assert_state_round_trip<M: Model>(
    params: &[(usize, Value)],
    h: f64,
    before: usize,
    after: usize,
    drive: &dyn Fn(&mut Store, usize),
) -> usize {
    unsafe {
        let a = Driven::<M>::new(params);
        let mut s0 = std::ptr::null_mut();
        a.ok(fmi3::get_fmu_state::<M>(a.p, &mut s0), "GetFMUState (Instantiated)");
        let instantiated = a.serialize(s0);
        a.ok(fmi3::free_fmu_state::<M>(a.p, &mut s0), "FreeFMUState");
        a.initialize();
        a.run(0, before, h, drive);
        let mut s = std::ptr::null_mut();
        a.ok(fmi3::get_fmu_state::<M>(a.p, &mut s), "GetFMUState");
        let bytes = a.serialize(s);
        let expected = a.run(before, after, h, drive);
        let moved = expected.windows(2).any(|w| {
            M::VARIABLES
                .iter()
                .enumerate()
                .any(|(i, v)| v.causality == Causality::Output && !w[0].1.value(i).identical(w[1].1.value(i)))
        });
        assert!(moved, "{}: no output changes after the saved point: the comparison would say nothing", M::NAME);

        // This instance: same parameters, its own model is reused.
        a.restore(&bytes);
        assert_eq!(a.inst().mode, Mode::StepMode);
        assert_same_run::<M>("restored in the same instance", &expected, &a.run(before, after, h, drive));

        // A fresh instance with default parameters: the model is rebuilt from the saved ones.
        let b = Driven::<M>::new(&[]);
        b.restore(&bytes);
        assert_same_run::<M>("restored in a fresh instance", &expected, &b.run(before, after, h, drive));
        assert!(
            b.serialize_current() == a.serialize_current(),
            "{}: the two restored runs end in different states",
            M::NAME
        );

        // Instantiated state: back to the start, initializes and runs as the first time.
        b.restore(&instantiated);
        assert_eq!(b.inst().mode, Mode::Instantiated);
        b.initialize();
        let first = b.run(0, before, h, drive);
        let c = Driven::<M>::new(params);
        c.initialize();
        assert_same_run::<M>("restored Instantiated state", &c.run(0, before, h, drive), &first);

        // Corrupt, truncated and foreign bytes: an error, never a crash.
        for bad in [&bytes[..bytes.len() / 2], &bytes[..4], b"AGS\x02....", &[][..]] {
            let mut p = std::ptr::null_mut();
            let st = fmi3::deserialize_fmu_state::<M>(c.p, bad.as_ptr(), bad.len(), &mut p);
            assert_eq!(st, Status::Error, "{}: bad serialized state accepted", M::NAME);
            assert!(p.is_null());
            assert!(
                c.logs.0.iter().any(|(_, m)| m.contains("fmi3DeserializeFMUState")),
                "{}: refusal not logged",
                M::NAME
            );
            fmi3::reset::<M>(c.p);
        }
        let mut short = vec![0u8; bytes.len() - 1];
        assert_eq!(
            fmi3::serialize_fmu_state::<M>(a.p, s, short.as_mut_ptr(), short.len()),
            Status::Error,
            "{}: short buffer accepted",
            M::NAME
        );
        bytes.len()
    }
}
