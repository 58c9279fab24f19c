//! SSP connection features with real FMUs (Lift and ChassisKinematic): unit conversion,
//! transformations, parameters from .ssv files with an .ssm mapping, as a plain .ssd and as
//! an .ssp archive, checked on the values the FMUs see while the master steps; and one bad
//! system per kind of wiring error, each naming the connection and why.
//!
//! The system is tests/ssp/units (valid against the SSP 1.0 schema). Needs the packed FMUs:
//! `AGRISIM_FMU_DIR`, else target/fmu of the workspace.

use std::io::Write;
use std::path::{Path, PathBuf};

use agrisim_cosim::{Hooks, LoadOptions, Master, System};
use agrisim_error::Result;

fn fmu_dir() -> PathBuf {
    let dir = std::env::var_os("AGRISIM_FMU_DIR").map(PathBuf::from).unwrap_or_else(|| {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/fmu").canonicalize().unwrap_or_default()
    });
    assert!(
        dir.join("Lift.fmu").exists() && dir.join("ChassisKinematic.fmu").exists(),
        "{} has no packed FMUs: run `target/release/agrisim fmu pack` or set AGRISIM_FMU_DIR",
        dir.display()
    );
    dir
}

fn fixture() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/ssp/units")
}

/// The fixture's files (path relative to it, text), `edit` applied to the .ssd.
fn fixture_files(edit: &dyn Fn(String) -> String) -> Vec<(String, String)> {
    let read = |p: &str| std::fs::read_to_string(fixture().join(p)).unwrap();
    let mut files = vec![("SystemStructure.ssd".to_string(), edit(read("SystemStructure.ssd")))];
    for f in ["resources/lift.ssv", "resources/lift.ssm", "resources/chassis.ssv"] {
        files.push((f.to_string(), read(f)));
    }
    files
}

/// The fixture (with `edit`) written as a directory: the FMUs are not beside it, so they come
/// from the FMU directory by file name.
fn write_dir(dir: &Path, edit: &dyn Fn(String) -> String) -> PathBuf {
    for (name, text) in fixture_files(edit) {
        let p = dir.join(name);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, text).unwrap();
    }
    dir.join("SystemStructure.ssd")
}

/// The fixture as a self-contained .ssp: the .ssd at the root, FMUs and parameter files
/// under resources/.
fn write_ssp(path: &Path) {
    let mut z = zip::ZipWriter::new(std::fs::File::create(path).unwrap());
    let o = zip::write::SimpleFileOptions::default();
    for (name, text) in fixture_files(&|s| s) {
        z.start_file(name, o).unwrap();
        z.write_all(text.as_bytes()).unwrap();
    }
    for fmu in ["Lift.fmu", "ChassisKinematic.fmu"] {
        z.start_file(format!("resources/{fmu}"), o).unwrap();
        z.write_all(&std::fs::read(fmu_dir().join(fmu)).unwrap()).unwrap();
    }
    z.finish().unwrap();
}

fn load(ssd: &Path, cache: &Path) -> Result<Master> {
    let mut system = System::load(ssd, &LoadOptions::new(fmu_dir(), cache, 0.02, 0.1))?;
    system.apply_parameters(&Default::default(), 1, &Default::default())?;
    let mut master = Master::new(system, 0.02, 0.1)?;
    master.initialize()?;
    Ok(master)
}

/// Speed command 3.6 km/h, lift set-point 50 cm; records the `speed` output.
#[derive(Default)]
struct Bus {
    speed: Vec<f64>,
}

impl Hooks for Bus {
    fn scalar_input(&self, connector: &str) -> Option<f64> {
        match connector {
            "speed_cmd" => Some(3.6),
            "lift_cm" => Some(50.0),
            _ => None,
        }
    }

    fn scalar(&mut self, connector: &str, value: f64) {
        assert_eq!(connector, "speed");
        self.speed.push(value);
    }
}

fn number(m: &mut Master, comp: &str, var: &str) -> f64 {
    let i = m.system.component_index(comp).unwrap();
    m.system.number(i, var).unwrap()
}

#[track_caller]
fn close(a: f64, b: f64, what: &str) {
    assert!((a - b).abs() < 1e-9, "{what}: {a} != {b}");
}

/// Steps the fixture system and checks every feature on the FMUs' own values.
fn check_run(mut m: Master) {
    // Parameters: 30 cm via the mapping to position0; 2000 mm and 90 deg on the system level.
    close(number(&mut m, "lift", "position0"), 0.3, "lift.position0 (30 cm, renamed by lift.ssm)");
    close(number(&mut m, "lift", "position"), 0.3, "lift.position after initialization");
    close(number(&mut m, "lift", "velocity_max"), 0.5, "lift.velocity_max (1.8 km/h)");
    close(number(&mut m, "lift", "acceleration_max"), 2.0, "lift.acceleration_max (1.0, doubled by lift.ssm)");
    close(number(&mut m, "chassis", "x0"), 2.0, "chassis.x0 (2000 mm)");
    close(number(&mut m, "chassis", "yaw0"), std::f64::consts::FRAC_PI_2, "chassis.yaw0 (90 deg)");
    // FMU to FMU in Initialization Mode too: suppressUnitConversion with factor 0.5, and the map.
    close(number(&mut m, "chassis", "cmd_vy"), 0.15, "chassis.cmd_vy = 0.5 * lift.position at t=0");

    let mut bus = Bus::default();
    let mut statuses = std::collections::BTreeSet::new();
    for k in 0..150 {
        let vx_before = number(&mut m, "chassis", "vx");
        m.advance(&mut bus).unwrap();
        // The speed output left at this point in km/h: the chassis's vx [m/s] before the step.
        close(*bus.speed.last().unwrap(), vx_before * 3.6, &format!("speed (km/h) at step {k}"));
        close(number(&mut m, "chassis", "cmd_vx"), 1.0, "chassis.cmd_vx from 3.6 km/h");
        close(number(&mut m, "lift", "setpoint"), 0.5, "lift.setpoint from 50 cm");
        let pos = number(&mut m, "lift", "position");
        close(number(&mut m, "chassis", "cmd_vy"), 0.5 * pos, "chassis.cmd_vy = 0.5 * lift.position");
        let status = number(&mut m, "lift", "status");
        statuses.insert(status as i64);
        close(number(&mut m, "chassis", "cmd_seq"), status + 5.0, "chassis.cmd_seq = map(lift.status)");
    }
    close(number(&mut m, "lift", "position"), 0.5, "lift reached 50 cm");
    assert_eq!(statuses, [0, 1].into(), "the lift moved and arrived");
    assert!(bus.speed.iter().any(|s| *s > 1.0), "the chassis drove: {:?}", &bus.speed[..5]);
}

#[test]
fn units_transformations_and_parameter_files_in_a_directory() {
    let tmp = tempfile::tempdir().unwrap();
    let ssd = write_dir(&tmp.path().join("sys"), &|s| s);
    check_run(load(&ssd, &tmp.path().join("cache")).unwrap());
}

#[test]
fn units_transformations_and_parameter_files_in_an_ssp_archive() {
    let tmp = tempfile::tempdir().unwrap();
    let ssp = tmp.path().join("units.ssp");
    write_ssp(&ssp);
    check_run(load(&ssp, &tmp.path().join("cache")).unwrap());
}

/// The load error of the fixture with `from` replaced by `to`.
fn load_error(from: &str, to: &str) -> String {
    let tmp = tempfile::tempdir().unwrap();
    let edit = |s: String| {
        assert!(s.contains(from), "fixture lacks {from:?}");
        s.replacen(from, to, 1)
    };
    let ssd = write_dir(&tmp.path().join("sys"), &edit);
    match load(&ssd, &tmp.path().join("cache")) {
        Ok(_) => panic!("{from:?} -> {to:?} loaded"),
        Err(e) => e.0,
    }
}

#[track_caller]
fn assert_error(e: &str, expected: &str) {
    assert!(e.contains("SystemStructure.ssd"), "{e}");
    assert!(e.contains(expected), "error {e:?} does not contain {expected:?}");
}

const LIFT_CM: &str = r#"<ssd:Connector name="lift_cm" kind="input"><ssc:Real unit="cm"/></ssd:Connector>"#;

#[test]
fn incompatible_units_are_refused() {
    // A time into a length.
    let e = load_error_multi(&[
        (LIFT_CM, r#"<ssd:Connector name="lift_cm" kind="input"><ssc:Real unit="s"/></ssd:Connector>"#),
        ("</ssd:Units>", r#"<ssc:Unit name="s"><ssc:BaseUnit s="1"/></ssc:Unit></ssd:Units>"#),
    ]);
    assert_error(&e, "connection <system>.lift_cm -> lift.setpoint: incompatible units: s (s) -> m (m)");
    // A unit nobody defines converts to nothing else.
    let e =
        load_error(LIFT_CM, r#"<ssd:Connector name="lift_cm" kind="input"><ssc:Real unit="furlong"/></ssd:Connector>"#);
    assert_error(&e, "connection <system>.lift_cm -> lift.setpoint: cannot convert furlong (no base unit) -> m (m)");
    // Between two FMUs: a length into a speed.
    let e = load_error(r#"suppressUnitConversion="true""#, "");
    assert_error(&e, "connection lift.position -> chassis.cmd_vy: incompatible units: m (m) -> m/s (m.s-1)");
    // A parameter file value in a unit that does not fit.
    let tmp = tempfile::tempdir().unwrap();
    let ssd = write_dir(&tmp.path().join("sys"), &|s| s);
    let ssv = tmp.path().join("sys/resources/chassis.ssv");
    std::fs::write(&ssv, std::fs::read_to_string(&ssv).unwrap().replace(r#"unit="deg""#, r#"unit="mm""#)).unwrap();
    let e = load(&ssd, &tmp.path().join("cache")).err().expect("loaded").0;
    assert_error(&e, "component 'chassis': parameter 'yaw0' (from ");
    assert!(e.contains("chassis.ssv): incompatible units: mm (m) -> rad (rad)"), "{e}");
}

#[test]
fn type_mismatches_are_refused() {
    let e =
        load_error(r#"endElement="chassis" endConnector="cmd_vx""#, r#"endElement="chassis" endConnector="cmd_vel""#);
    // The connector is not declared on the component: that is reported first.
    assert_error(
        &e,
        "connection <system>.speed_cmd -> chassis.cmd_vel: component 'chassis' declares no connector 'cmd_vel'",
    );
    let e = load_error_multi(&[
        (
            r#"<ssd:Connector name="cmd_vx" kind="input"><ssc:Real/></ssd:Connector>"#,
            r#"<ssd:Connector name="cmd_vx" kind="input"><ssc:Real/></ssd:Connector><ssd:Connector name="cmd_vel" kind="input"/>"#,
        ),
        (r#"endElement="chassis" endConnector="cmd_vx""#, r#"endElement="chassis" endConnector="cmd_vel""#),
    ]);
    assert_error(&e, "connection <system>.speed_cmd -> chassis.cmd_vel: types differ: Real -> Binary");
}

/// [`load_error`] with several replacements.
fn load_error_multi(edits: &[(&str, &str)]) -> String {
    let tmp = tempfile::tempdir().unwrap();
    let edit = |mut s: String| {
        for (from, to) in edits {
            assert!(s.contains(from), "fixture lacks {from:?}");
            s = s.replacen(from, to, 1);
        }
        s
    };
    let ssd = write_dir(&tmp.path().join("sys"), &edit);
    load(&ssd, &tmp.path().join("cache")).err().expect("loaded").0
}

#[test]
fn missing_connectors_are_refused() {
    let e = load_error(r#"startConnector="status""#, r#"startConnector="state""#);
    assert_error(&e, "connection lift.state -> chassis.cmd_seq: component 'lift' declares no connector 'state'");
    let e = load_error(r#"endConnector="speed""#, r#"endConnector="velocity""#);
    assert_error(&e, "connection chassis.vx -> <system>.velocity: the system has no connector 'velocity'");
}

#[test]
fn wrong_causality_is_refused() {
    // input to input
    let e = load_error_multi(&[
        (
            r#"<ssd:Connector name="setpoint" kind="input"><ssc:Real/></ssd:Connector>"#,
            r#"<ssd:Connector name="setpoint" kind="input"><ssc:Real/></ssd:Connector>"#,
        ),
        (r#"startElement="lift" startConnector="position""#, r#"startElement="lift" startConnector="setpoint""#),
    ]);
    assert_error(
        &e,
        "connection lift.setpoint -> chassis.cmd_vy: start variable 'setpoint' of component 'lift' has causality input, expected output",
    );
    // output to output
    let e = load_error_multi(&[(
        r#"startElement="lift" startConnector="position" endElement="chassis" endConnector="cmd_vy""#,
        r#"startElement="lift" startConnector="position" endElement="chassis" endConnector="vx""#,
    )]);
    assert_error(
        &e,
        "connection lift.position -> chassis.vx: end variable 'vx' of component 'chassis' has causality output, expected input",
    );
}

#[test]
fn misplaced_transformations_are_refused() {
    // On a type it does not apply to.
    let e = load_error(
        r#"<ssc:LinearTransformation factor="0.5"/>"#,
        r#"<ssc:BooleanMappingTransformation><ssc:MapEntry source="true" target="false"/></ssc:BooleanMappingTransformation>"#,
    );
    assert_error(
        &e,
        "connection lift.position -> chassis.cmd_vy: ssc:BooleanMappingTransformation applies only to Boolean connections, not Real",
    );
    let e = load_error(
        "<ssc:IntegerMappingTransformation>",
        r#"<ssc:LinearTransformation/><ssc:IntegerMappingTransformation>"#,
    );
    assert_error(&e, "connection lift.status -> chassis.cmd_seq: more than one transformation");
    // On a message connection.
    let e = load_error_multi(&[
        (
            r#"<ssd:Connector name="vx" kind="output"><ssc:Real/></ssd:Connector>"#,
            r#"<ssd:Connector name="vx" kind="output"><ssc:Real/></ssd:Connector><ssd:Connector name="odom" kind="output"><ssc:Binary/></ssd:Connector>"#,
        ),
        (
            r#"<ssd:Connector name="speed" kind="output"><ssc:Real unit="km/h"/></ssd:Connector>"#,
            r#"<ssd:Connector name="speed" kind="output"><ssc:Real unit="km/h"/></ssd:Connector><ssd:Connector name="odom" kind="output"/>"#,
        ),
        (
            r#"<ssd:Connection startElement="chassis" startConnector="vx" endConnector="speed"/>"#,
            r#"<ssd:Connection startElement="chassis" startConnector="vx" endConnector="speed"/><ssd:Connection startElement="chassis" startConnector="odom" endConnector="odom"><ssc:LinearTransformation factor="2"/></ssd:Connection>"#,
        ),
    ]);
    assert_error(
        &e,
        "connection chassis.odom -> <system>.odom: ssc:LinearTransformation on a message (Binary) connection",
    );
}

#[test]
fn a_value_missing_from_a_mapping_table_stops_the_run() {
    // Status 0 (at target) has no entry: the lift starts moving (1), then arrives.
    let tmp = tempfile::tempdir().unwrap();
    let ssd =
        write_dir(&tmp.path().join("sys"), &|s: String| s.replace(r#"<ssc:MapEntry source="0" target="5"/>"#, ""));
    let mut m = load(&ssd, &tmp.path().join("cache")).unwrap();
    let mut bus = Bus::default();
    let mut steps = 0;
    let e = loop {
        assert!(steps < 150, "the lift never arrived");
        match m.advance(&mut bus) {
            Ok(()) => steps += 1,
            Err(e) => break e.0,
        }
    };
    assert_eq!(e, "connection lift.status -> chassis.cmd_seq: value 0 has no entry in its mapping table");
    assert!(steps > 10, "the run went on while the lift moved ({steps} steps)");
    assert_eq!(number(&mut m, "lift", "status"), 0.0);
}
