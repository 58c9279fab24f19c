//! The engine embedded in another program with its own hooks, as the crate docs show: load
//! base.ssd, drive the lift through a scalar system input, collect the odometry messages the
//! chassis sends to the system's output connector.
//!
//! Needs the packed FMUs (target/fmu, written by `agrisim fmu pack`, which scripts/setup runs).

use agrisim_cosim::{Hooks, LoadOptions, Master, System};
use agrisim_error::Result;
use std::path::{Path, PathBuf};

/// A program around the engine: a lift set-point in, odometry messages out.
#[derive(Default)]
struct Program {
    odom: Vec<(i64, usize)>,
    exchanges: u64,
    message_instants: u64,
    points: u64,
}

impl Hooks for Program {
    fn message(&mut self, system: &System, route: usize, t_ns: i64, bytes: &[u8]) -> Result<()> {
        assert_eq!(system.routes[route].topic, "/odom");
        assert!(system.routes[route].mime_type.as_deref().unwrap().contains("nav_msgs/msg/Odometry"));
        self.odom.push((t_ns, bytes.len()));
        Ok(())
    }
    fn exchange(&mut self, _: i64, message_instant: bool) -> Result<()> {
        self.exchanges += 1;
        self.message_instants += message_instant as u64;
        Ok(())
    }
    fn scalar_input(&self, connector: &str) -> Option<f64> {
        (connector == "/lift/setpoint").then_some(0.5)
    }
    fn point(&mut self, _: &mut System, _: i64) -> Result<()> {
        self.points += 1;
        Ok(())
    }
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().unwrap()
}

#[test]
fn embedded_engine_runs_base_ssd_with_its_own_hooks() {
    let fmu_dir = root().join("target/fmu");
    assert!(
        fmu_dir.join("Lift.fmu").exists(),
        "{} has no packed FMUs: run `target/release/agrisim fmu pack`",
        fmu_dir.display()
    );
    let cache = tempfile::tempdir().unwrap();
    let opts = LoadOptions::new(&fmu_dir, cache.path(), 0.02, 0.1);
    let mut system = System::load(&root().join("models/systems/base.ssd"), &opts).unwrap();
    system.apply_parameters(&Default::default(), 1, &Default::default()).unwrap();
    let mut master = Master::new(system, 0.02, 0.1).unwrap();
    master.initialize().unwrap();
    let mut program = Program::default();
    for _ in 0..250 {
        master.advance(&mut program).unwrap();
    }
    master.finish_point(&mut program).unwrap();
    assert_eq!(master.time(), 5.0);
    assert_eq!((program.exchanges, program.message_instants, program.points), (250, 50, 251));
    let lift = master.system.component_index("lift").unwrap();
    // 0.2 m -> 0.5 m at 0.2 m/s and 0.5 m/s²: there in under 2.5 s.
    assert!((master.system.number(lift, "position").unwrap() - 0.5).abs() < 1e-9);
    // The chassis publishes odometry at 10 Hz; the route takes each new one at 10 Hz.
    assert!(program.odom.len() >= 49 && program.odom.iter().all(|&(_, n)| n > 100), "{:?}", program.odom.len());
    assert!(program.odom.windows(2).all(|w| w[1].0 - w[0].0 == 100_000_000));
    assert!(master.system.number(lift, "no_such_variable").unwrap_err().0.contains("no_such_variable"));
}
