//! SSP 1.0 SystemStructure.ssd: parsing the agrisim subset, and validation against model
//! descriptions with errors that name the file, the connection or component and the variable.

use std::collections::BTreeMap;
use std::path::Path;

use agrisim_cosim::model_description::ModelDescription;
use agrisim_cosim::ssp::{
    resolve_source, validate, ConnectorKind, ConnectorType, Endpoint, ParamValue, SystemStructure,
};

const SSD: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription version="1.0" name="greenhouse"
    xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon"
    xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues"
    xmlns:ag="http://agrisim.org/ssp">
  <ssd:System name="robot">
    <ssd:Connectors>
      <ssd:Connector name="/cmd_vel" kind="input">
        <ssc:Binary mime-type="application/x-ros2-cdr; type=geometry_msgs/msg/Twist"/>
      </ssd:Connector>
      <ssd:Connector name="/odom" kind="output"><ssc:Binary/></ssd:Connector>
      <ssd:Connector name="speed" kind="output"/>
    </ssd:Connectors>
    <ssd:Elements>
      <ssd:Component name="chassis" source="fmus/Chassis.fmu" type="application/x-fmu-sharedlibrary">
        <ssd:Connectors>
          <ssd:Connector name="cmd_vel" kind="input">
            <ssc:Binary mime-type="application/x-ros2-cdr; type=geometry_msgs/msg/Twist"/>
          </ssd:Connector>
          <ssd:Connector name="odom" kind="output"><ssc:Binary/></ssd:Connector>
          <ssd:Connector name="vx" kind="output"><ssc:Real unit="m/s"/></ssd:Connector>
          <ssd:Connector name="seq" kind="output"><ssc:Integer/></ssd:Connector>
          <ssd:Connector name="lift_h" kind="input"><ssc:Real/></ssd:Connector>
        </ssd:Connectors>
        <ssd:ParameterBindings>
          <ssd:ParameterBinding>
            <ssd:ParameterValues>
              <ssv:ParameterSet version="1.0" name="chassis">
                <ssv:Parameters>
                  <ssv:Parameter name="wheel_base"><ssv:Real value="0.55"/></ssv:Parameter>
                  <ssv:Parameter name="seed"><ssv:Integer value="42"/></ssv:Parameter>
                  <ssv:Parameter name="holonomic"><ssv:Boolean value="true"/></ssv:Parameter>
                  <ssv:Parameter name="scenario"><ssv:String value="default.toml"/></ssv:Parameter>
                </ssv:Parameters>
              </ssv:ParameterSet>
            </ssd:ParameterValues>
          </ssd:ParameterBinding>
        </ssd:ParameterBindings>
      </ssd:Component>
      <ssd:Component name="lift" source="Lift.fmu">
        <ssd:Connectors>
          <ssd:Connector name="h" kind="output"><ssc:Real/></ssd:Connector>
          <ssd:Connector name="vx_in" kind="input"><ssc:Real/></ssd:Connector>
        </ssd:Connectors>
      </ssd:Component>
    </ssd:Elements>
    <ssd:Connections>
      <ssd:Connection startConnector="/cmd_vel" endElement="chassis" endConnector="cmd_vel">
        <ssd:Annotations>
          <ssc:Annotation type="org.agrisim.exchange"><ag:Exchange period="0.1"/></ssc:Annotation>
        </ssd:Annotations>
      </ssd:Connection>
      <ssd:Connection startElement="chassis" startConnector="odom" endConnector="/odom"/>
      <ssd:Connection startElement="chassis" startConnector="vx" endElement="lift" endConnector="vx_in"/>
      <ssd:Connection startElement="lift" startConnector="h" endElement="chassis" endConnector="lift_h"/>
      <ssd:Connection startElement="chassis" startConnector="vx" endConnector="speed"/>
    </ssd:Connections>
  </ssd:System>
  <ssd:DefaultExperiment startTime="0" stopTime="60"/>
</ssd:SystemStructureDescription>"#;

const CHASSIS_MD: &str = r#"<fmiModelDescription fmiVersion="3.0" modelName="ChassisKinematic" instantiationToken="t">
  <CoSimulation modelIdentifier="chassis"/>
  <ModelVariables>
    <Float64 name="time" valueReference="0" causality="independent"/>
    <Binary name="cmd_vel" valueReference="1" causality="input" mimeType="application/x-ros2-cdr; type=geometry_msgs/msg/Twist"/>
    <Binary name="odom" valueReference="2" causality="output" mimeType="application/x-ros2-cdr; type=nav_msgs/msg/Odometry"/>
    <Float64 name="vx" valueReference="3" causality="output"/>
    <Int64 name="seq" valueReference="4" causality="output"/>
    <Float64 name="lift_h" valueReference="5" causality="input" start="0"/>
    <Float64 name="wheel_base" valueReference="6" causality="parameter" variability="fixed" start="0.5"/>
    <Int32 name="seed" valueReference="7" causality="parameter" variability="fixed" start="0"/>
    <Boolean name="holonomic" valueReference="8" causality="parameter" variability="fixed" start="false"/>
    <String name="scenario" valueReference="9" causality="parameter" variability="fixed"><Start value=""/></String>
    <Float64 name="x" valueReference="10" causality="output"/>
    <Float32 name="f32_out" valueReference="11" causality="output"/>
    <Float64 name="mass" valueReference="12" causality="local"/>
  </ModelVariables>
</fmiModelDescription>"#;

const LIFT_MD: &str = r#"<fmiModelDescription fmiVersion="3.0" modelName="Lift" instantiationToken="t">
  <CoSimulation modelIdentifier="lift"/>
  <ModelVariables>
    <Float64 name="h" valueReference="1" causality="output"/>
    <Float64 name="vx_in" valueReference="2" causality="input" start="0"/>
    <Boolean name="b_in" valueReference="3" causality="input" start="false"/>
  </ModelVariables>
</fmiModelDescription>"#;

fn mds() -> BTreeMap<String, ModelDescription> {
    let mut m = BTreeMap::new();
    m.insert("chassis".to_string(), ModelDescription::parse(CHASSIS_MD, "chassis").unwrap());
    m.insert("lift".to_string(), ModelDescription::parse(LIFT_MD, "lift").unwrap());
    m
}

fn parse(xml: &str) -> SystemStructure {
    SystemStructure::parse(xml, Path::new("models/systems/SystemStructure.ssd")).unwrap()
}

#[test]
fn parses_the_agrisim_subset() {
    let s = parse(SSD);
    assert_eq!(s.name, "robot");
    assert_eq!(s.path, Path::new("models/systems/SystemStructure.ssd"));
    assert_eq!(s.components.len(), 2);
    let c = &s.components[0];
    assert_eq!((c.name.as_str(), c.source.as_str()), ("chassis", "fmus/Chassis.fmu"));
    assert_eq!(c.connectors.len(), 5);
    assert_eq!(c.connector("vx").unwrap().ty, Some(ConnectorType::Real));
    assert_eq!(c.connector("seq").unwrap().ty, Some(ConnectorType::Integer));
    assert_eq!(c.connector("cmd_vel").unwrap().kind, ConnectorKind::Input);
    assert_eq!(
        c.connector("cmd_vel").unwrap().ty,
        Some(ConnectorType::Binary { mime_type: Some("application/x-ros2-cdr; type=geometry_msgs/msg/Twist".into()) })
    );
    assert_eq!(
        c.parameters,
        vec![
            ("wheel_base".to_string(), ParamValue::Real(0.55)),
            ("seed".to_string(), ParamValue::Integer(42)),
            ("holonomic".to_string(), ParamValue::Boolean(true)),
            ("scenario".to_string(), ParamValue::String("default.toml".into())),
        ]
    );
    assert_eq!(s.system_connectors.len(), 3);
    assert_eq!(s.system_connector("speed").unwrap().ty, None);
    assert_eq!(s.connections.len(), 5);
    let first = &s.connections[0];
    assert_eq!(first.start, Endpoint { element: None, connector: "/cmd_vel".into() });
    assert_eq!(first.end, Endpoint { element: Some("chassis".into()), connector: "cmd_vel".into() });
    assert_eq!(first.period, Some(0.1));
    assert_eq!(s.connections[1].period, None);
    assert_eq!(s.connections[1].end.element, None);
    let de = s.default_experiment.unwrap();
    assert_eq!((de.start_time, de.stop_time), (Some(0.0), Some(60.0)));
}

#[test]
fn good_system_validates() {
    validate(&parse(SSD), &mds()).unwrap();
}

/// Validation error text for the fixture with one substitution.
fn validation_error(from: &str, to: &str) -> String {
    assert!(SSD.contains(from), "fixture lacks {from:?}");
    let s = parse(&SSD.replacen(from, to, 1));
    validate(&s, &mds()).unwrap_err().to_string()
}

#[track_caller]
fn assert_contains(e: &str, expected: &str) {
    assert!(e.starts_with("models/systems/SystemStructure.ssd: "), "{e}");
    assert!(e.contains(expected), "error {e:?} does not contain {expected:?}");
}

#[test]
fn unknown_component_in_connection() {
    let e = validation_error(r#"endElement="lift" endConnector="vx_in""#, r#"endElement="arm" endConnector="vx_in""#);
    assert_contains(&e, "connection chassis.vx -> arm.vx_in: there is no component 'arm'");
}

#[test]
fn undeclared_connector_in_connection() {
    let e = validation_error(r#"startConnector="h""#, r#"startConnector="height""#);
    assert_contains(&e, "connection lift.height -> chassis.lift_h: component 'lift' declares no connector 'height'");
}

#[test]
fn connector_without_fmu_variable() {
    let e = validation_error(r#"<ssd:Connector name="h" kind="output">"#, r#"<ssd:Connector name="hh" kind="output">"#);
    assert_contains(&e, "component 'lift' (FMU Lift): connector 'hh' names no variable of the FMU");
}

#[test]
fn unknown_system_connector() {
    let e = validation_error(r#"endConnector="/odom""#, r#"endConnector="/odometry""#);
    assert_contains(&e, "connection chassis.odom -> <system>./odometry: the system has no connector '/odometry'");
}

#[test]
fn wrong_direction_is_rejected() {
    // input -> output between components
    let e = validation_error(
        r#"startElement="lift" startConnector="h" endElement="chassis" endConnector="lift_h""#,
        r#"startElement="chassis" startConnector="lift_h" endElement="lift" endConnector="h""#,
    );
    assert_contains(&e, "start variable 'lift_h' of component 'chassis' has causality input, expected output");
    assert_contains(&e, "end variable 'h' of component 'lift' has causality output, expected input");
    // a system output used as a source
    let e = validation_error(
        r#"startElement="chassis" startConnector="odom" endConnector="/odom""#,
        r#"startConnector="/odom" endElement="chassis" endConnector="lift_h""#,
    );
    assert_contains(&e, "system connector '/odom' has kind output and cannot be the start of a connection");
}

#[test]
fn connector_kind_must_match_causality() {
    let e = validation_error(r#"<ssd:Connector name="vx" kind="output">"#, r#"<ssd:Connector name="vx" kind="input">"#);
    assert_contains(&e, "component 'chassis' (FMU ChassisKinematic): connector 'vx' has kind input but the FMU variable has causality output");
}

#[test]
fn type_mismatches_are_rejected() {
    // Real output into a Boolean input.
    let s = parse(&SSD.replacen(
        r#"<ssd:Connector name="vx_in" kind="input"><ssc:Real/></ssd:Connector>"#,
        r#"<ssd:Connector name="vx_in" kind="input"><ssc:Real/></ssd:Connector><ssd:Connector name="b_in" kind="input"/>"#,
        1,
    ).replacen(r#"endElement="lift" endConnector="vx_in""#, r#"endElement="lift" endConnector="b_in""#, 1));
    let e = validate(&s, &mds()).unwrap_err().to_string();
    assert_contains(&e, "connection chassis.vx -> lift.b_in: types differ: Real -> Boolean");

    // Declared connector type disagrees with the FMU variable.
    let e = validation_error(
        r#"<ssd:Connector name="seq" kind="output"><ssc:Integer/>"#,
        r#"<ssd:Connector name="seq" kind="output"><ssc:Real/>"#,
    );
    assert_contains(&e, "connector 'seq' is declared Real but the FMU variable is Int64 (Integer)");

    // Binary mime types must agree: a Twist topic into the Odometry output.
    let e = validation_error(
        r#"<ssd:Connector name="/odom" kind="output"><ssc:Binary/></ssd:Connector>"#,
        r#"<ssd:Connector name="/odom" kind="output"><ssc:Binary mime-type="application/x-ros2-cdr; type=geometry_msgs/msg/Twist"/></ssd:Connector>"#,
    );
    assert_contains(
        &e,
        "connection chassis.odom -> <system>./odom: types differ: Binary (application/x-ros2-cdr; type=nav_msgs/msg/Odometry) -> Binary (application/x-ros2-cdr; type=geometry_msgs/msg/Twist)",
    );
}

#[test]
fn unsupported_fmu_type_is_reported_when_connected() {
    let s = parse(
        &SSD.replacen(
            r#"<ssd:Connector name="seq" kind="output"><ssc:Integer/></ssd:Connector>"#,
            r#"<ssd:Connector name="seq" kind="output"><ssc:Integer/></ssd:Connector><ssd:Connector name="f32_out" kind="output"/>"#,
            1,
        )
        .replacen(r#"startConnector="vx" endConnector="speed""#, r#"startConnector="f32_out" endConnector="speed""#, 1),
    );
    let e = validate(&s, &mds()).unwrap_err().to_string();
    assert_contains(&e, "connection chassis.f32_out -> <system>.speed: component 'chassis': variable 'f32_out' has type Float32, which agrisim does not support");
}

#[test]
fn input_driven_twice_is_rejected() {
    let e = validation_error(
        r#"<ssd:Connection startElement="chassis" startConnector="vx" endConnector="speed"/>"#,
        r#"<ssd:Connection startElement="chassis" startConnector="vx" endElement="chassis" endConnector="lift_h"/>"#,
    );
    assert_contains(&e, "connection chassis.vx -> chassis.lift_h: input chassis.lift_h is already driven by connection lift.h -> chassis.lift_h");
}

#[test]
fn parameter_errors() {
    let e = validation_error(r#"name="wheel_base""#, r#"name="wheelbase""#);
    assert_contains(
        &e,
        "component 'chassis' (FMU ChassisKinematic): parameter 'wheelbase' is not a variable of the FMU",
    );
    let e = validation_error(r#"name="wheel_base""#, r#"name="x""#);
    assert_contains(&e, "'x' has causality output, not parameter, so it cannot be bound");
    let e = validation_error(r#"<ssv:Real value="0.55"/>"#, r#"<ssv:String value="wide"/>"#);
    assert_contains(&e, "parameter 'wheel_base' is Float64 but the value String(\"wide\") does not fit it");
    let e = validation_error(r#"<ssv:Integer value="42"/>"#, r#"<ssv:Integer value="4294967296"/>"#);
    assert_contains(&e, "parameter 'seed' is Int32 but the value Integer(4294967296) does not fit it");
}

#[test]
fn missing_model_description_is_reported() {
    let s = parse(SSD);
    let mut m = mds();
    m.remove("lift");
    let e = validate(&s, &m).unwrap_err();
    assert!(e.problems.iter().any(|p| p == "component 'lift': no model description was loaded for it"), "{e}");
}

#[test]
fn all_problems_are_listed() {
    let s = parse(&SSD.replacen(r#"name="wheel_base""#, r#"name="wheelbase""#, 1).replacen(
        r#"endConnector="/odom""#,
        r#"endConnector="/o""#,
        1,
    ));
    let e = validate(&s, &mds()).unwrap_err();
    assert_eq!(e.problems.len(), 2, "{e}");
    assert!(e.to_string().starts_with("models/systems/SystemStructure.ssd: 2 problems:\n  - "), "{e}");
}

#[track_caller]
fn parse_err(from: &str, to: &str, expected: &str) {
    assert!(SSD.contains(from), "fixture lacks {from:?}");
    let e = SystemStructure::parse(&SSD.replacen(from, to, 1), Path::new("sys.ssd")).unwrap_err().to_string();
    assert!(e.starts_with("sys.ssd: "), "{e}");
    assert!(e.contains(expected), "error {e:?} does not contain {expected:?}");
}

#[test]
fn malformed_files_are_rejected_by_parse() {
    parse_err(
        r#"<ssd:Component name="lift" source="Lift.fmu">"#,
        r#"<ssd:Component name="lift">"#,
        "component 'lift' has no attribute 'source'",
    );
    parse_err(
        r#"<ssd:Component name="lift" source="Lift.fmu">"#,
        r#"<ssd:Component name="chassis" source="Lift.fmu">"#,
        "two components are named 'chassis'",
    );
    parse_err(
        r#"type="application/x-fmu-sharedlibrary""#,
        r#"type="application/x-ssp-package""#,
        "type \"application/x-ssp-package\" is not supported",
    );
    parse_err(
        r#"name="speed" kind="output""#,
        r#"name="speed" kind="sideways""#,
        "connector 'speed' of the system: unknown kind \"sideways\"",
    );
    parse_err(
        r#"period="0.1""#,
        r#"period="-1""#,
        "connection <system>./cmd_vel -> chassis.cmd_vel: exchange period \"-1\" must be a positive number",
    );
    parse_err(r#"period="0.1""#, r#"every="0.1""#, "the org.agrisim.exchange annotation has no period attribute");
    parse_err(
        r#"<ssv:Real value="0.55"/>"#,
        r#"<ssv:Real value="wide"/>"#,
        "component 'chassis', parameter 'wheel_base': ssv:Real value=\"wide\" is not valid",
    );
    parse_err(
        r#"<ssd:ParameterBinding>"#,
        r#"<ssd:ParameterBinding source="chassis.ssv">"#,
        "component 'chassis': ssd:ParameterBinding has both source \"chassis.ssv\" and inline values",
    );
    parse_err(r#"<ssd:System name="robot">"#, r#"<ssd:System>"#, "ssd:System has no attribute 'name'");
    parse_err(r#"startConnector="h""#, "", "an ssd:Connection has no attribute 'startConnector'");
    parse_err(r#"<ssc:Real unit="m/s"/>"#, r#"<ssc:Float64/>"#, "unknown type element ssc:Float64");
    parse_err(r#"stopTime="60""#, r#"stopTime="forever""#, "stopTime=\"forever\" is not a number");
    parse_err(
        r#"xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription""#,
        r#"xmlns:ssd="http://example.org/other""#,
        "expected ssd:SystemStructureDescription",
    );
    parse_err(
        r#"<ssd:Component name="lift" source="Lift.fmu">"#,
        r#"<ssd:System name="nested"/><ssd:Component name="lift" source="Lift.fmu">"#,
        "element <System> in ssd:Elements is not supported",
    );
}

#[test]
fn from_file_names_the_file() {
    let tmp = tempfile::tempdir().unwrap();
    let p = tmp.path().join("SystemStructure.ssd");
    let e = SystemStructure::from_file(&p).unwrap_err();
    assert_eq!(e.file, p);
    std::fs::write(&p, SSD).unwrap();
    assert_eq!(SystemStructure::from_file(&p).unwrap().path, p);
}

#[test]
fn sources_resolve_next_to_the_ssd_then_in_the_fmu_dir() {
    let tmp = tempfile::tempdir().unwrap();
    let sys_dir = tmp.path().join("models/systems");
    let fmu_dir = tmp.path().join("target/fmu");
    std::fs::create_dir_all(sys_dir.join("fmus")).unwrap();
    std::fs::create_dir_all(&fmu_dir).unwrap();
    let ssd = sys_dir.join("SystemStructure.ssd");
    std::fs::write(sys_dir.join("fmus/Chassis.fmu"), b"").unwrap();
    assert_eq!(resolve_source(&ssd, "fmus/Chassis.fmu", &fmu_dir), sys_dir.join("fmus/Chassis.fmu"));
    assert_eq!(resolve_source(&ssd, "resources/Lift.fmu", &fmu_dir), fmu_dir.join("Lift.fmu"));
    assert_eq!(resolve_source(&ssd, "file:fmus/Chassis.fmu", &fmu_dir), sys_dir.join("fmus/Chassis.fmu"));
}

#[test]
fn topic_annotation_names_a_system_connector_outside_the_engine() {
    let annotated = SSD.replace(
        r#"<ssd:Connector name="/odom" kind="output"><ssc:Binary/></ssd:Connector>"#,
        r#"<ssd:Connector name="odom" kind="output"><ssc:Binary/><ssd:Annotations><ssc:Annotation type="org.agrisim.topic"><ag:Topic name="/odom"/></ssc:Annotation></ssd:Annotations></ssd:Connector>"#,
    );
    assert_ne!(annotated, SSD);
    let s = parse(&annotated);
    let odom = s.system_connector("odom").unwrap();
    assert_eq!((odom.topic.as_deref(), odom.external_name()), (Some("/odom"), "/odom"));
    assert_eq!(s.system_connector("/cmd_vel").unwrap().external_name(), "/cmd_vel");
    let nameless = annotated.replace(r#"<ag:Topic name="/odom"/>"#, "<ag:Topic/>");
    let e = SystemStructure::parse(&nameless, Path::new("x.ssd")).unwrap_err().to_string();
    assert!(e.contains("x.ssd") && e.contains("connector 'odom'") && e.contains("org.agrisim.topic"), "{e}");
}
