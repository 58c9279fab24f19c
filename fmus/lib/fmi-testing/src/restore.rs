//! Serialized FMU states restore exactly: the same run continues bit for bit after a restore.

use std::ffi::{c_void, CString};

use agrisim_fmi::fmi3;
use agrisim_fmi::{Causality, Instance, Mode, Model, Start, Status, Store, Value};

use crate::logs::{log3, Logs};

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

    /// The instance behind the handle: owned by the FMI layer, not by `self` (as an importer
    /// holds it), so a shared `self` hands out the one live `&mut` at a time.
    #[allow(clippy::mut_from_ref)]
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
