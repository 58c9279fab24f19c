//! Message ports lose nothing, end to end through the engine (packed FMUs, target/fmu):
//! - the IMU's 200 Hz samples all reach the program around the engine, 5 ms apart, in order;
//! - a route that reads a port less often than the FMU keeps messages stops the run with an
//!   error naming the FMU and the port;
//! - a base-plant contact lasting one step, between two 10 Hz message instants, arrives as
//!   an onset and an end, each at its own stamp;
//! - Gauss-Seidel: the world sees the lift where it is after the step, not one step late.

use agrisim_cosim::{Hooks, LoadOptions, Master, System};
use agrisim_error::Result;
use agrisim_msgs::agrisim::CollisionState;
use agrisim_msgs::sensor_msgs::Imu;
use agrisim_msgs::Message;
use agrisim_session::Scenario;
use std::collections::BTreeMap;
use std::path::PathBuf;

mod common;
use common::root;

fn fmu_dir() -> PathBuf {
    common::fmu_dir("Imu.fmu")
}

/// A system of the world and the IMU whose base pose and yaw rate come from system inputs.
const SSD: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription version="1.0" name="ports_test"
    xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon">
  <ssd:System name="ports_test">
    <ssd:Connectors>
      <ssd:Connector name="base_x" kind="input"><ssc:Real/></ssd:Connector>
      <ssd:Connector name="base_y" kind="input"><ssc:Real/></ssd:Connector>
      <ssd:Connector name="wz" kind="input"><ssc:Real/></ssd:Connector>
      <ssd:Connector name="imu" kind="output"><ssc:Binary mime-type="application/x-ros2-cdr-frames; version=1; type=sensor_msgs/msg/Imu"/></ssd:Connector>
      <ssd:Connector name="collision" kind="output"><ssc:Binary mime-type="application/x-ros2-cdr-frames; version=1; type=agrisim_msgs/msg/CollisionState"/></ssd:Connector>
    </ssd:Connectors>
    <ssd:Elements>
      <ssd:Component name="world" source="Greenhouse.fmu">
        <ssd:Connectors>
          <ssd:Connector name="base_x" kind="input"><ssc:Real/></ssd:Connector>
          <ssd:Connector name="base_y" kind="input"><ssc:Real/></ssd:Connector>
          <ssd:Connector name="collision_state" kind="output"><ssc:Binary mime-type="application/x-ros2-cdr-frames; version=1; type=agrisim_msgs/msg/CollisionState"/></ssd:Connector>
        </ssd:Connectors>
      </ssd:Component>
      <ssd:Component name="imu" source="Imu.fmu">
        <ssd:Connectors>
          <ssd:Connector name="wz" kind="input"><ssc:Real/></ssd:Connector>
          <ssd:Connector name="imu" kind="output"><ssc:Binary mime-type="application/x-ros2-cdr-frames; version=1; type=sensor_msgs/msg/Imu"/></ssd:Connector>
        </ssd:Connectors>
      </ssd:Component>
    </ssd:Elements>
    <ssd:Connections>
      <ssd:Connection startConnector="base_x" endElement="world" endConnector="base_x"/>
      <ssd:Connection startConnector="base_y" endElement="world" endConnector="base_y"/>
      <ssd:Connection startConnector="wz" endElement="imu" endConnector="wz"/>
      <ssd:Connection startElement="imu" startConnector="imu" endConnector="imu"/>
      <ssd:Connection startElement="world" startConnector="collision_state" endConnector="collision"/>
    </ssd:Connections>
  </ssd:System>
</ssd:SystemStructureDescription>
"#;

/// Scalar inputs from a schedule (tick -> base pose), and every message by topic.
struct Probe {
    tick: u64,
    pose: Box<dyn Fn(u64) -> (f64, f64)>,
    messages: BTreeMap<String, Vec<(i64, Vec<u8>)>>,
}

impl Hooks for Probe {
    fn message(&mut self, system: &System, route: usize, t_ns: i64, bytes: &[u8]) -> Result<()> {
        self.messages.entry(system.routes[route].topic.clone()).or_default().push((t_ns, bytes.to_vec()));
        Ok(())
    }
    fn scalar_input(&self, connector: &str) -> Option<f64> {
        let (x, y) = (self.pose)(self.tick);
        match connector {
            "base_x" => Some(x),
            "base_y" => Some(y),
            "wz" => Some(0.3),
            _ => None,
        }
    }
    fn exchange(&mut self, t_ns: i64, _message_instant: bool) -> Result<()> {
        self.tick = (t_ns / 20_000_000) as u64;
        Ok(())
    }
}

impl Probe {
    fn new(pose: impl Fn(u64) -> (f64, f64) + 'static) -> Probe {
        Probe { tick: 0, pose: Box::new(pose), messages: BTreeMap::new() }
    }
}

struct Setup {
    _dir: tempfile::TempDir,
    master: Master,
}

fn setup(overrides: &[(&str, &str, f64)]) -> Result<Setup> {
    let dir = tempfile::tempdir().unwrap();
    let ssd = dir.path().join("ports.ssd");
    std::fs::write(&ssd, SSD).unwrap();
    let s = Scenario::load(&root().join("models/scenarios/default.toml"))?;
    let mut system = System::load(&ssd, &LoadOptions::new(fmu_dir(), dir.path().join("cache"), 0.02, 0.1))?;
    let mut params: BTreeMap<String, BTreeMap<String, toml::Value>> = BTreeMap::new();
    for (comp, name, v) in overrides {
        params.entry(comp.to_string()).or_default().insert(name.to_string(), toml::Value::Float(*v));
    }
    system.apply_parameters(&params, 1, &BTreeMap::from([("scene".to_string(), s.scene_toml())]))?;
    let mut master = Master::new(system, 0.02, 0.1)?;
    master.initialize()?;
    Ok(Setup { _dir: dir, master })
}

fn run(master: &mut Master, probe: &mut Probe, steps: u64) -> Result<()> {
    for _ in 0..steps {
        master.advance(probe)?;
    }
    master.finish_point(probe)
}

#[test]
fn every_imu_sample_arrives_in_order() {
    let mut s = setup(&[]).unwrap();
    let mut probe = Probe::new(|_| (1.0, 1.0));
    run(&mut s.master, &mut probe, 500).unwrap();
    let imu = &probe.messages["imu"];
    assert_eq!(imu.len(), 2001, "10 s at 200 Hz, and the sample at t = 0");
    for (i, (t_ns, bytes)) in imu.iter().enumerate() {
        assert_eq!(*t_ns, i as i64 * 5_000_000);
        let m = Imu::from_cdr(bytes).unwrap();
        assert_eq!(m.header.stamp.to_nanos(), *t_ns, "the message's own stamp is its log time");
    }
}

#[test]
fn a_route_that_drops_messages_is_an_error_naming_the_fmu_and_port() {
    // The IMU keeps 0.02 s of samples; the route reads every 0.1 s.
    let mut s = setup(&[("imu", "port_window", 0.02)]).unwrap();
    let mut probe = Probe::new(|_| (0.0, 0.0));
    let e = run(&mut s.master, &mut probe, 10).unwrap_err().0;
    assert!(
        e.contains("FMU 'imu'")
            && e.contains("message port 'imu'")
            && e.contains("were lost (sequence gap)")
            && e.contains("port_window"),
        "{e}"
    );
    // With a window as long as the route's period nothing is lost.
    let mut s = setup(&[("imu", "port_window", 0.1)]).unwrap();
    run(&mut s.master, &mut Probe::new(|_| (0.0, 0.0)), 10).unwrap();
}

#[test]
fn a_contact_lasting_one_step_is_reported_as_onset_and_end() {
    // Find a base pose touching the crop: walk across the rows (y) at the middle of the house.
    let mut s = setup(&[]).unwrap();
    let ys: Vec<f64> = (0..400).map(|i| -10.0 + 0.05 * i as f64).collect();
    let ys2 = ys.clone();
    let mut probe = Probe::new(move |k| (10.0, ys2[(k as usize).min(ys2.len() - 1)]));
    let world = s.master.system.component_index("world").unwrap();
    let mut hit = None;
    for k in 0..ys.len() as u64 {
        s.master.advance(&mut probe).unwrap();
        if s.master.system.number(world, "collision").unwrap() > 0.0 {
            hit = Some(ys[k as usize]);
            break;
        }
    }
    let y_hit = hit.expect("some y between -10 and 10 m touches a plant at x = 10 m");
    let y_free = -10.0;
    // Touch for exactly the step from tick 7 to 8 (0.14 -> 0.16 s): between message instants.
    let mut s = setup(&[]).unwrap();
    let mut probe = Probe::new(move |k| (10.0, if k == 7 { y_hit } else { y_free }));
    run(&mut s.master, &mut probe, 20).unwrap();
    let states: Vec<(i64, CollisionState)> =
        probe.messages["collision"].iter().map(|(t, b)| (*t, CollisionState::from_cdr(b).unwrap())).collect();
    let base_contact = |c: &CollisionState| c.contacts.iter().any(|c| c.robot_link == "base_link");
    // The world starts from its inputs' start values (the origin), before the first
    // system input reaches it: look after the base is placed clear.
    let clear = states.iter().position(|(t, c)| *t > 0 && !base_contact(c)).expect("the base is clear at first");
    assert!(states[clear].0 < 140_000_000);
    let onset = states[clear..].iter().find(|(_, c)| base_contact(c)).expect("the onset is delivered");
    assert_eq!(onset.0, 160_000_000, "stamped at the end of the step that touched");
    let end = states.iter().find(|(t, c)| *t > onset.0 && !base_contact(c)).expect("the end is delivered");
    assert_eq!(end.0, 180_000_000);
    assert!(onset.0 % 100_000_000 != 0 && end.0 % 100_000_000 != 0, "neither falls on a 10 Hz instant");
}

#[test]
fn the_world_sees_the_lift_after_its_step() {
    // harvest.ssd: the lift steps before the world (Gauss-Seidel), so after every step the
    // world's lift input equals the lift's position at the same time.
    let dir = tempfile::tempdir().unwrap();
    let s = Scenario::load(&root().join("models/scenarios/harvest.toml")).unwrap();
    let mut system =
        System::load(&root().join("models/systems/harvest.ssd"), &LoadOptions::new(fmu_dir(), dir.path(), 0.02, 0.1))
            .unwrap();
    system.apply_parameters(&BTreeMap::new(), 1, &BTreeMap::from([("scene".to_string(), s.scene_toml())])).unwrap();
    let mut master = Master::new(system, 0.02, 0.1).unwrap();
    let names = |m: &Master, rs: &[usize]| rs.iter().map(|&r| m.system.routes[r].label.clone()).collect::<Vec<_>>();
    assert_eq!(
        names(&master, &master.order().delayed),
        ["left", "right"]
            .iter()
            .flat_map(|s| {
                std::iter::once(format!("world.{s}_grasp_width -> arm_{s}.grasp_width")).chain(
                    ["fx", "fy", "fz", "mx", "my", "mz"].map(|k| format!("world.{s}_load_{k} -> arm_{s}.load_{k}")),
                )
            })
            .collect::<Vec<_>>()
    );
    assert!(master.order().init_loops.is_empty());
    master.initialize().unwrap();
    struct Lift;
    impl Hooks for Lift {
        fn scalar_input(&self, connector: &str) -> Option<f64> {
            (connector == "lift_setpoint").then_some(0.5)
        }
    }
    let (lift, world) =
        (master.system.component_index("lift").unwrap(), master.system.component_index("world").unwrap());
    let mut moved = 0.0;
    for _ in 0..50 {
        master.advance(&mut Lift).unwrap();
        let p = master.system.number(lift, "position").unwrap();
        assert_eq!(master.system.number(world, "lift_position").unwrap(), p);
        moved = p;
    }
    assert!(moved > 0.1, "the lift moved ({moved} m)");
}
