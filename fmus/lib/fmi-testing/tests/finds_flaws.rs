//! The harness can fail: a small integrator passes every check (the conformance tests run on
//! it), and each flaw planted in it (an initial dependency its table hides, a saved state
//! that leaves out the step count, a table that overrides its token) is reported by the check
//! that exists for it.

use agrisim_fmi::{Log, Model, ModelError, Start, Store, Var};

agrisim_fmi::variables! { VARIABLES {
    RATE = Var::input("rate", 0.5).desc("dx/dt"),
    X0 = Var::param("x0", Start::Float64(1.0)).desc("x at the start"),
    X = Var::output("x").init_depends_on(&[X0]).desc("x0 + the integral of rate"),
    STEPS = Var::output_discrete("steps", Start::Int32(0)).init_depends_on(&[]).desc("Steps taken"),
}}

/// What is wrong with an [`Integrator`].
const SOUND: u8 = 0;
/// Initial x also depends on `rate`, which the table does not declare.
const HIDDEN_DEPENDENCY: u8 = 1;
/// `save_state` leaves out the step count.
const FORGETFUL: u8 = 2;
/// The FMI 3 instantiation token is not the hash of the table.
const OWN_TOKEN: u8 = 3;

#[derive(Clone, Default)]
struct Integrator<const FLAW: u8> {
    x: f64,
    steps: i32,
}

impl<const FLAW: u8> Integrator<FLAW> {
    fn publish(&self, io: &mut Store) {
        io.set_f64(X, self.x);
        io.set_i32(STEPS, self.steps);
    }
}

impl<const FLAW: u8> Model for Integrator<FLAW> {
    const NAME: &'static str = "Integrator";
    const DESCRIPTION: &'static str = "x' = rate (agrisim-fmi-testing's own test model)";
    const VARIABLES: &'static [Var] = VARIABLES;
    const TOKEN: &'static str =
        if FLAW == OWN_TOKEN { "{00000000-0000-0000-0000-000000000000}" } else { Self::DERIVED };

    fn new() -> Self {
        Self::default()
    }

    fn initialize(&mut self, io: &mut Store, _start_time: f64, _log: &mut dyn Log) -> Result<(), ModelError> {
        self.x = io.f64(X0) + if FLAW == HIDDEN_DEPENDENCY { io.f64(RATE) } else { 0.0 };
        self.steps = 0;
        self.publish(io);
        Ok(())
    }

    fn do_step(&mut self, io: &mut Store, _t: f64, h: f64, _log: &mut dyn Log) -> Result<(), ModelError> {
        self.x += io.f64(RATE) * h;
        self.steps += 1;
        self.publish(io);
        Ok(())
    }

    fn save_state(&self, out: &mut Vec<u8>) -> Result<(), ModelError> {
        let steps = if FLAW == FORGETFUL { 0 } else { self.steps };
        agrisim_fmi::serial::write(&(self.x, steps), out)
    }

    fn load_state(&mut self, bytes: &[u8]) -> Result<(), ModelError> {
        let (x, steps): (f64, i32) = agrisim_fmi::serial::read(bytes)?;
        self.x = x;
        if FLAW != FORGETFUL {
            self.steps = steps;
        }
        Ok(())
    }
}

impl<const FLAW: u8> Integrator<FLAW> {
    /// The token `Model` derives (a default cannot be named from an override).
    const DERIVED: &'static str = agrisim_fmi::token::as_str(&Self::TOKEN_BYTES);
}

agrisim_fmi_testing::fmu_conformance_tests!(Integrator<SOUND>, seeds = 2, cases = 100);

/// The panic message of `f`, which must panic.
fn failure(f: impl FnOnce() + std::panic::UnwindSafe) -> String {
    let payload = std::panic::catch_unwind(f).expect_err("the harness let a flawed model pass");
    payload
        .downcast_ref::<String>()
        .cloned()
        .or_else(|| payload.downcast_ref::<&str>().map(|s| s.to_string()))
        .unwrap_or_default()
}

#[test]
fn a_hidden_initial_dependency_is_found() {
    let e = failure(|| agrisim_fmi_testing::assert_initial_dependencies::<Integrator<HIDDEN_DEPENDENCY>>(&[]));
    assert!(e.contains("'x' changes with 'rate' but does not list it"), "{e}");
}

#[test]
fn a_state_that_forgets_is_found() {
    let e = failure(|| {
        agrisim_fmi_testing::assert_state_round_trip::<Integrator<FORGETFUL>>(
            &[],
            0.02,
            5,
            5,
            &agrisim_fmi_testing::wiggle_inputs::<Integrator<FORGETFUL>>,
        );
    });
    assert!(e.contains("variable 'steps' differs"), "{e}");
}

#[test]
fn an_overridden_token_is_found() {
    let e = failure(agrisim_fmi_testing::assert_valid_table::<Integrator<OWN_TOKEN>>);
    assert!(e.contains("TOKEN / GUID overridden"), "{e}");
}
