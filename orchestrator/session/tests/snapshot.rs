//! A whole-system snapshot, restored, steps on exactly as the run it was taken from: every
//! message and every FMU signal byte-identical. Covers every FMU kind: harvest.ssd (both
//! chassis models, lift, LiDAR, IMU, both arms with a trajectory and a gripper command, the
//! world) and sensors.ssd (the camera, small), in memory and serialized to bytes restored in
//! a fresh master. Needs the packed FMUs (target/fmu).

use agrisim_cosim::{Hooks, LoadOptions, Master, System};
use agrisim_error::Result;
use agrisim_msgs::control_msgs::GripperCommand;
use agrisim_msgs::Message;
use agrisim_session::Scenario;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().unwrap()
}

/// System inputs that make things move (lift up, base forward, a gripper closing), and a
/// log of everything that comes out.
struct Drive {
    log: Vec<u8>,
    cmd_vel: Vec<u8>,
    grip: Vec<u8>,
}

impl Hooks for Drive {
    fn message(&mut self, system: &System, route: usize, t_ns: i64, bytes: &[u8]) -> Result<()> {
        self.log.extend_from_slice(system.routes[route].topic.as_bytes());
        self.log.extend_from_slice(&t_ns.to_le_bytes());
        self.log.extend_from_slice(bytes);
        Ok(())
    }
    fn scalar(&mut self, connector: &str, value: f64) {
        self.log.extend_from_slice(connector.as_bytes());
        self.log.extend_from_slice(&value.to_bits().to_le_bytes());
    }
    fn message_input(&mut self, _route: usize, connector: &str, out: &mut Vec<(i64, Vec<u8>)>) -> Result<()> {
        match connector {
            "/cmd_vel" => out.push((0, self.cmd_vel.clone())),
            "/left_gripper/command" => out.push((0, self.grip.clone())),
            _ => {}
        }
        Ok(())
    }
    fn scalar_input(&self, connector: &str) -> Option<f64> {
        (connector == "/lift/setpoint").then_some(0.4)
    }
    fn point(&mut self, system: &mut System, _t_ns: i64) -> Result<()> {
        let mut v = vec![];
        for c in &mut system.components {
            c.read_signals(&mut v)?;
            for x in &v {
                self.log.extend_from_slice(&x.to_bits().to_le_bytes());
            }
        }
        Ok(())
    }
}

fn drive() -> Drive {
    let twist = agrisim_msgs::geometry_msgs::Twist {
        linear: agrisim_msgs::geometry_msgs::Vector3 { x: 0.3, y: 0.05, z: 0.0 },
        angular: agrisim_msgs::geometry_msgs::Vector3 { x: 0.0, y: 0.0, z: 0.1 },
    };
    Drive { log: vec![], cmd_vel: twist.to_cdr(), grip: GripperCommand { position: 0.02, max_effort: 20.0 }.to_cdr() }
}

fn master(
    system_file: &str,
    scenario: &str,
    params: &[(&str, &str, toml::Value)],
    fmus: &[(&str, &str)],
    cache: &Path,
) -> Master {
    let s = Scenario::load(&root().join("models/scenarios").join(scenario)).unwrap();
    let mut opts = LoadOptions::new(root().join("target/fmu"), cache, 0.02, 0.1);
    opts.fmu_overrides = fmus.iter().map(|(c, f)| (c.to_string(), f.to_string())).collect();
    let mut system = System::load(&root().join("models/systems").join(system_file), &opts).unwrap();
    let mut p: BTreeMap<String, BTreeMap<String, toml::Value>> = BTreeMap::new();
    for (c, n, v) in params {
        p.entry(c.to_string()).or_default().insert(n.to_string(), v.clone());
    }
    system.apply_parameters(&p, 7, &BTreeMap::from([("scene".to_string(), s.scene_toml())])).unwrap();
    let mut m = Master::new(system, 0.02, 0.1).unwrap();
    m.initialize().unwrap();
    m
}

/// Steps `n` times and returns what came out.
fn run(m: &mut Master, n: usize) -> Vec<u8> {
    let mut d = drive();
    for _ in 0..n {
        m.advance(&mut d).unwrap();
    }
    d.log
}

/// Runs `before` steps, snapshots, runs `after` more; the snapshot restored in this master,
/// and its serialized bytes restored in a fresh master of the same system (as another
/// process would), step on to the very same bytes.
fn check(make: impl Fn() -> Master, before: usize, after: usize) {
    let mut m = make();
    run(&mut m, before);
    let snap = m.snapshot().unwrap();
    let bytes = m.serialize_snapshot(&snap).unwrap();
    let first = run(&mut m, after);
    m.restore(&snap).unwrap();
    assert_eq!(m.tick(), before as u64);
    let again = run(&mut m, after);
    assert!(first.len() > 10_000, "something happened ({} bytes)", first.len());
    assert!(first == again, "the run after restoring differs from the run after the snapshot");
    // And once more from the same snapshot, after freeing nothing: snapshots are reusable.
    m.restore(&snap).unwrap();
    assert!(run(&mut m, after) == first);
    m.free_snapshot(snap).unwrap();

    // Serialized: a fresh master (its FMUs rebuild their scenes) goes on exactly the same.
    let mut fresh = make();
    let snap = fresh.deserialize_snapshot(&bytes).unwrap();
    fresh.restore(&snap).unwrap();
    assert_eq!(fresh.tick(), before as u64);
    assert!(run(&mut fresh, after) == first, "the run after restoring the serialized snapshot differs");
    // Loaded into the master it came from (its FMUs reuse their scenes): the same again.
    let snap = m.deserialize_snapshot(&bytes).unwrap();
    m.restore(&snap).unwrap();
    assert!(run(&mut m, after) == first, "the serialized snapshot restored in its own master differs");

    // Damaged bytes are refused with a reason, and the master stays usable.
    for bad in [&bytes[..bytes.len() / 3], &bytes[6..], &b"AGSYS\x01"[..]] {
        let e = fresh.deserialize_snapshot(bad).err().expect("damaged snapshot accepted").to_string();
        assert!(e.contains("snapshot") || e.contains("FMU"), "{e}");
    }
    let snap = fresh.deserialize_snapshot(&bytes).unwrap();
    fresh.restore(&snap).unwrap();
    assert!(run(&mut fresh, after) == first);
}

#[test]
fn harvest_system_restores_byte_identically() {
    for chassis in ["ChassisKinematic.fmu", "ChassisDynamic.fmu"] {
        let cache = tempfile::tempdir().unwrap();
        check(|| master("harvest.ssd", "harvest.toml", &[], &[("chassis", chassis)], cache.path()), 30, 40);
    }
}

#[test]
fn sensor_system_with_camera_restores_byte_identically() {
    let cache = tempfile::tempdir().unwrap();
    let small = [("camera", "width", toml::Value::Integer(64)), ("camera", "height", toml::Value::Integer(48))];
    check(|| master("sensors.ssd", "sensors.toml", &small, &[], cache.path()), 12, 15);
}
