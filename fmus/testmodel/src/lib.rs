//! A tiny FMU with one variable of every kind, to test the export layer end to end.
//!
//! Physics: Dahlquist's test equation with an input, x' = -k x + u, stepped with its exact
//! solution for piecewise-constant k and u, so any importer's result can be compared with
//! x(t) = x0 exp(-k t) (u = 0). A Binary message input is echoed to a Binary output with an
//! Int64 sequence counter, as message ports are in agrisim. `fault` injects a model error
//! (1) or a panic (2) so the error paths of the layer can be exercised.

use agrisim_fmi::{Log, Model, ModelError, Start, Store, Var};

/// ROS 2 CDR of an empty `std_msgs/msg/String`: encapsulation header (CDR_LE), length 1, NUL.
pub const EMPTY_STRING_CDR: &[u8] = &[0x00, 0x01, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x00];
pub const MIME: &str = "application/x-ros2-cdr; type=std_msgs/msg/String";

agrisim_fmi::variables! { pub VARIABLES {
    K = Var::tunable("k", Start::Float64(1.0)).unit("1/s").range(0.0, 100.0).desc("Decay rate (tunable)"),
    X0 = Var::param("x0", Start::Float64(1.0)).unit("m").desc("Initial state (fixed)"),
    U = Var::input("u", 0.0).unit("m/s").desc("Additive input: x' = -k x + u"),
    HOLD = Var::input_discrete("hold", Start::Boolean(false)).desc("Freeze the state while true"),
    MSG_IN = Var::input_discrete("msg_in", Start::Binary(EMPTY_STRING_CDR)).mime(MIME).max_size(MAX_MESSAGE)
        .desc("Message to echo"),
    LABEL = Var::param("label", Start::String("agrisim \"test\" <model> & more")).desc("Free text, logged at initialization"),
    FAULT = Var::tunable("fault", Start::Int32(0)).range(0.0, 2.0).desc("0: none, 1: step fails, 2: step panics"),
    X = Var::output("x").unit("m").init_depends_on(&[X0]).desc("State x(t)"),
    STEPS = Var::output_discrete("steps", Start::Int32(0)).init_depends_on(&[]).desc("Number of steps taken"),
    ABOVE_HALF = Var::output_discrete("above_half", Start::Boolean(false)).init_depends_on(&[X0]).desc("x > x0 / 2"),
    MSG_OUT = Var::output_discrete("msg_out", Start::Binary(EMPTY_STRING_CDR)).mime(MIME).max_size(MAX_MESSAGE)
        .init_depends_on(&[MSG_IN]).desc("Echo of msg_in"),
    MSG_SEQ = Var::output_discrete("msg_seq", Start::Int64(0)).init_depends_on(&[MSG_IN])
        .desc("Increments whenever msg_out changes"),
}}

/// maxSize of msg_in, and so of its echo msg_out.
pub const MAX_MESSAGE: usize = 1 << 20;

#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct TestModel {
    x: f64,
    steps: i32,
    seq: i64,
}

impl TestModel {
    fn publish(&self, io: &mut Store) {
        io.set_f64(X, self.x);
        io.set_i32(STEPS, self.steps);
        io.set_bool(ABOVE_HALF, self.x > io.f64(X0) / 2.0);
        io.set_i64(MSG_SEQ, self.seq);
    }

    fn echo(&mut self, io: &mut Store) {
        if io.binary(MSG_IN) != io.binary(MSG_OUT) {
            let msg = io.binary(MSG_IN).to_vec();
            io.set_binary(MSG_OUT, &msg);
            self.seq += 1;
        }
    }
}

impl Model for TestModel {
    const NAME: &'static str = "TestModel";
    const DESCRIPTION: &'static str = "Dahlquist test model with every variable type (agrisim export-layer test)";
    const VARIABLES: &'static [Var] = VARIABLES;

    fn new() -> Self {
        TestModel::default()
    }

    fn initialize(&mut self, io: &mut Store, _start_time: f64, log: &mut dyn Log) -> Result<(), ModelError> {
        self.x = io.f64(X0);
        self.steps = 0;
        self.seq = 0;
        self.echo(io);
        self.publish(io);
        log.info(format_args!("initialized with label {:?}", io.string(LABEL)));
        Ok(())
    }

    agrisim_fmi::whole_state!();

    fn do_step(&mut self, io: &mut Store, t: f64, h: f64, _log: &mut dyn Log) -> Result<(), ModelError> {
        match io.i32(FAULT) {
            1 => return Err(format!("injected failure at t={t}")),
            2 => panic!("testmodel: injected panic at t={t}"),
            _ => {}
        }
        if !io.bool(HOLD) {
            let (k, u) = (io.f64(K), io.f64(U));
            let decay = (-k * h).exp();
            // Exact solution of x' = -k x + u over the step (k = 0: x' = u).
            let forced = if k * h > 1e-12 { u / k * (1.0 - decay) } else { u * h };
            self.x = self.x * decay + forced;
        }
        self.steps = self.steps.wrapping_add(1);
        self.echo(io);
        self.publish(io);
        Ok(())
    }
}

agrisim_fmi::export_fmu!(crate::TestModel);
