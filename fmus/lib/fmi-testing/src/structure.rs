//! The variable table's own checks: a valid FMU, and the ModelStructure dependencies it
//! declares hold against the model (initial dependencies complete, no direct feedthrough).

use std::ffi::{c_void, CString};

use agrisim_fmi::ctype::{self, CType};
use agrisim_fmi::fmi3;
use agrisim_fmi::xml::is_initial_unknown;
use agrisim_fmi::{Causality, Model, Quiet, Start, Status, Store, Value, Var, Variability};

use crate::args::zeroed;

/// Asserts that `M`'s variable table yields a valid FMU (see [`agrisim_fmi::xml::check_table`]),
/// that every initial unknown declares its dependencies and that the tokens are the derived ones.
pub fn assert_valid_table<M: Model>() {
    let mut problems = agrisim_fmi::xml::check_table(M::VARIABLES);
    problems.extend(agrisim_fmi::xml::check_continuous_states(M::VARIABLES, M::CONTINUOUS_STATES));
    for v in M::VARIABLES.iter().filter(|v| is_initial_unknown(v) && v.initial_dependencies.is_none()) {
        problems.push(format!("'{}': no init_depends_on declaration (what its initial value depends on)", v.name));
    }
    let derived = |version| agrisim_fmi::token::guid(agrisim_fmi::token::hash(version, M::NAME, M::VARIABLES));
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
