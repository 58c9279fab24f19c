//! modelDescription.xml parsing: a full fixture, and each malformed case named in the error.

use agrisim_cosim::model_description::{Causality, FmiVersion, Interface, ModelDescription, VarType, Variability};

const GOOD: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="3.0" modelName="ChassisKinematic" instantiationToken="{1234-abcd}"
    description="kinematic chassis">
  <ModelExchange modelIdentifier="ignored_me"/>
  <CoSimulation modelIdentifier="agrisim_chassis_kinematic" canGetAndSetFMUState="true"
      canSerializeFMUState="false"/>
  <UnitDefinitions><Unit name="m/s"/></UnitDefinitions>
  <DefaultExperiment startTime="0" stopTime="10" stepSize="0.02"/>
  <ModelVariables>
    <Float64 name="time" valueReference="0" causality="independent" variability="continuous"/>
    <Float64 name="cmd_vx" valueReference="1" causality="input" start="0" unit="m/s" description="forward speed"/>
    <Float32 name="f32" valueReference="2"/>
    <Int8 name="i8" valueReference="3"/>
    <UInt8 name="u8" valueReference="4"/>
    <Int16 name="i16" valueReference="5"/>
    <UInt16 name="u16" valueReference="6"/>
    <Int32 name="mode" valueReference="7" causality="parameter" variability="fixed" start="2"/>
    <UInt32 name="u32" valueReference="8"/>
    <Int64 name="odom_seq" valueReference="9" causality="output"/>
    <UInt64 name="u64" valueReference="10"/>
    <Boolean name="enabled" valueReference="11" causality="input" start="true"/>
    <String name="scenario" valueReference="12" causality="structuralParameter" variability="fixed">
      <Start value="default.toml"/>
    </String>
    <Binary name="odom" valueReference="13" causality="output"
        mimeType="application/x-ros2-cdr; type=nav_msgs/msg/Odometry"/>
    <Clock name="tick" valueReference="14" causality="input" intervalVariability="constant"/>
    <Enumeration name="gear" valueReference="15" declaredType="Gear" start="1"/>
    <Float64 name="wheel_base" valueReference="16" causality="calculatedParameter" variability="tunable"/>
  </ModelVariables>
  <ModelStructure><Output valueReference="9"/><Output valueReference="13"/></ModelStructure>
</fmiModelDescription>"#;

#[test]
fn parses_the_good_fixture() {
    let md = ModelDescription::parse(GOOD, "good.xml").unwrap();
    assert_eq!(md.fmi_version, "3.0");
    assert_eq!(md.model_name, "ChassisKinematic");
    assert_eq!(md.instantiation_token, "{1234-abcd}");
    assert_eq!(md.model_identifier, "agrisim_chassis_kinematic");
    assert!(md.can_get_and_set_fmu_state);
    assert_eq!(md.default_step_size, Some(0.02));
    assert_eq!(md.variables.len(), 17);

    let types: Vec<VarType> = md.variables.iter().map(|v| v.ty).collect();
    use VarType::*;
    assert_eq!(
        types,
        vec![
            Float64,
            Float64,
            Float32,
            Int8,
            UInt8,
            Int16,
            UInt16,
            Int32,
            UInt32,
            Int64,
            UInt64,
            Boolean,
            String,
            Binary,
            Clock,
            Enumeration,
            Float64
        ]
    );
    let supported: Vec<&str> = md.variables.iter().filter(|v| v.ty.is_supported()).map(|v| v.name.as_str()).collect();
    assert_eq!(supported, ["time", "cmd_vx", "mode", "odom_seq", "enabled", "scenario", "odom", "wheel_base"]);

    let v = md.variable("cmd_vx").unwrap();
    assert_eq!(v.value_reference, 1);
    assert_eq!(v.causality, Causality::Input);
    assert_eq!(v.variability, Variability::Continuous);
    assert_eq!(v.start.as_deref(), Some("0"));
    assert_eq!(v.description.as_deref(), Some("forward speed"));
    assert_eq!(v.mime_type, None);

    let s = md.variable("scenario").unwrap();
    assert_eq!(s.causality, Causality::StructuralParameter);
    assert_eq!(s.start.as_deref(), Some("default.toml"));
    let b = md.variable("odom").unwrap();
    assert_eq!(b.mime_type.as_deref(), Some("application/x-ros2-cdr; type=nav_msgs/msg/Odometry"));
    assert_eq!(b.variability, Variability::Discrete);
    assert_eq!(md.variable("mode").unwrap().variability, Variability::Fixed);
    assert_eq!(md.variable("wheel_base").unwrap().causality, Causality::CalculatedParameter);
    assert!(md.variable("nope").is_none());
    assert_eq!(md.variable_by_vr(13).unwrap().name, "odom");
}

fn replace(from: &str, to: &str) -> String {
    assert!(GOOD.contains(from), "fixture lacks {from:?}");
    GOOD.replacen(from, to, 1)
}

fn error_of(xml: &str) -> String {
    ModelDescription::parse(xml, "fmus/Chassis.fmu!modelDescription.xml").unwrap_err().to_string()
}

#[track_caller]
fn assert_err(xml: &str, expected: &str) {
    let e = error_of(xml);
    assert!(e.starts_with("fmus/Chassis.fmu!modelDescription.xml: "), "{e}");
    assert!(e.contains(expected), "error {e:?} does not contain {expected:?}");
}

#[test]
fn fmi1_is_rejected() {
    assert_err(&replace(r#"fmiVersion="3.0""#, r#"fmiVersion="1.0""#), r#"fmiVersion is "1.0", only FMI 2.0 and 3.0"#);
}

#[test]
fn missing_version_is_rejected() {
    assert_err(&replace(r#"fmiVersion="3.0""#, ""), "<fmiModelDescription> has no attribute 'fmiVersion'");
}

#[test]
fn missing_model_name_and_token_are_rejected() {
    assert_err(&replace(r#"modelName="ChassisKinematic""#, ""), "has no attribute 'modelName'");
    assert_err(&replace(r#"instantiationToken="{1234-abcd}""#, ""), "has no attribute 'instantiationToken'");
}

#[test]
fn model_exchange_alone_is_imported_as_model_exchange() {
    let xml = replace(
        r#"<CoSimulation modelIdentifier="agrisim_chassis_kinematic" canGetAndSetFMUState="true"
      canSerializeFMUState="false"/>"#,
        "",
    );
    let md = ModelDescription::parse(&xml, "x").unwrap();
    assert_eq!(md.interface, Interface::ModelExchange);
    assert_eq!(md.model_identifier, "ignored_me");
    let none = xml.replace(r#"<ModelExchange modelIdentifier="ignored_me"/>"#, "");
    assert_err(&none, "neither <CoSimulation> nor <ModelExchange>");
}

/// An FMI 2.0 description in the same shape: types mapped, aliases allowed, ModelStructure
/// indices turned into value references, the ME state/derivative pairs found.
const FMI2: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="Osc" guid="{g-1}" numberOfEventIndicators="1">
  <ModelExchange modelIdentifier="osc" completedIntegratorStepNotNeeded="true"/>
  <CoSimulation modelIdentifier="osc" canGetAndSetFMUstate="true" canSerializeFMUstate="true"/>
  <LogCategories><Category name="logAll"/></LogCategories>
  <DefaultExperiment stepSize="0.01"/>
  <ModelVariables>
    <ScalarVariable name="x" valueReference="0" causality="output" initial="exact"><Real start="1" unit="m"/></ScalarVariable>
    <ScalarVariable name="der(x)" valueReference="1"><Real derivative="1"/></ScalarVariable>
    <ScalarVariable name="x_alias" valueReference="0" causality="local"><Real/></ScalarVariable>
    <ScalarVariable name="n" valueReference="0" causality="parameter" variability="fixed"><Integer start="3"/></ScalarVariable>
    <ScalarVariable name="on" valueReference="0" causality="input"><Boolean start="true"/></ScalarVariable>
    <ScalarVariable name="label" valueReference="0" causality="parameter" variability="fixed"><String start="a"/></ScalarVariable>
    <ScalarVariable name="u" valueReference="2" causality="input"><Real start="0"/></ScalarVariable>
  </ModelVariables>
  <ModelStructure>
    <Outputs><Unknown index="1" dependencies=""/></Outputs>
    <Derivatives><Unknown index="2" dependencies="1 7"/></Derivatives>
    <InitialUnknowns><Unknown index="1" dependencies="4"/></InitialUnknowns>
  </ModelStructure>
</fmiModelDescription>"#;

#[test]
fn fmi2_parses_into_the_same_shape() {
    let md = ModelDescription::parse(FMI2, "osc.fmu!modelDescription.xml").unwrap();
    assert_eq!(md.version, FmiVersion::V2);
    assert_eq!(md.interface, Interface::CoSimulation);
    assert_eq!(md.instantiation_token, "{g-1}");
    assert!(md.can_get_and_set_fmu_state && md.can_serialize_fmu_state);
    assert_eq!(md.variable("x").unwrap().ty, VarType::Float64);
    assert_eq!(md.variable("x").unwrap().unit.as_deref(), Some("m"));
    assert_eq!(md.variable("x").unwrap().variability, Variability::Continuous);
    assert_eq!(md.variable("n").unwrap().ty, VarType::Int32);
    assert_eq!(md.variable("on").unwrap().variability, Variability::Discrete);
    assert_eq!(md.variable("label").unwrap().start.as_deref(), Some("a"));
    assert_eq!(md.output_dependencies.get(&0), Some(&Some(vec![])));
    assert_eq!(md.initial_dependencies.get(&0), Some(&Some(vec![0])));
    let me = md.model_exchange.as_ref().unwrap();
    assert_eq!(me.states, vec![(0, 1)]);
    assert_eq!(me.number_of_event_indicators, 1);
    assert!(!me.needs_completed_integrator_step);
}

#[test]
fn fmi2_mistakes_are_named() {
    let bad = |from: &str, to: &str, expected: &str| {
        assert!(FMI2.contains(from), "fixture lacks {from:?}");
        let e = ModelDescription::parse(&FMI2.replacen(from, to, 1), "o.xml").unwrap_err().to_string();
        assert!(e.contains(expected), "error {e:?} does not contain {expected:?}");
    };
    bad(r#" guid="{g-1}""#, "", "has no attribute 'guid'");
    bad(
        r#"<Unknown index="1" dependencies=""/></Outputs>"#,
        r#"<Unknown index="9"/></Outputs>"#,
        "index 9 is not a variable",
    );
    bad(r#"<Real derivative="1"/>"#, r#"<Real derivative="x"/>"#, r#"derivative="x" is not a variable index"#);
    bad(r#"<Integer start="3"/>"#, r#"<Int64 start="3"/>"#, "unknown FMI 2.0 type element <Int64>");
    bad(
        r#"causality="input"><Boolean"#,
        r#"causality="input" variability="continuous"><Boolean"#,
        "only allowed for Real",
    );
    bad(r#"<Derivatives><Unknown index="2""#, r#"<Derivatives><Unknown index="1""#, "has no 'derivative' attribute");
}

#[test]
fn missing_model_identifier_is_rejected() {
    assert_err(
        &replace(r#"modelIdentifier="agrisim_chassis_kinematic""#, ""),
        "<CoSimulation> has no attribute 'modelIdentifier'",
    );
    assert_err(
        &replace(r#"modelIdentifier="agrisim_chassis_kinematic""#, r#"modelIdentifier="../x""#),
        "not a valid file stem",
    );
}

#[test]
fn duplicate_value_reference_is_rejected() {
    assert_err(
        &replace(r#"name="f32" valueReference="2""#, r#"name="f32" valueReference="1""#),
        "duplicate valueReference 1: used by 'cmd_vx' and 'f32'",
    );
}

#[test]
fn duplicate_name_is_rejected() {
    assert_err(&replace(r#"name="f32""#, r#"name="cmd_vx""#), "duplicate variable name 'cmd_vx'");
}

#[test]
fn missing_variable_attributes_are_rejected() {
    assert_err(
        &replace(r#"name="i8" valueReference="3""#, r#"name="i8""#),
        "variable 'i8' has no attribute 'valueReference'",
    );
    assert_err(&replace(r#"<Int8 name="i8" "#, "<Int8 "), "a <Int8> variable has no attribute 'name'");
}

#[test]
fn bad_values_are_rejected() {
    assert_err(
        &replace(r#"valueReference="3""#, r#"valueReference="-3""#),
        r#"variable 'i8': valueReference="-3" is not"#,
    );
    assert_err(
        &replace(r#"causality="input" start="0""#, r#"causality="sideways" start="0""#),
        r#"variable 'cmd_vx': unknown causality "sideways""#,
    );
    assert_err(
        &replace(r#"variability="fixed" start="2""#, r#"variability="sometimes""#),
        r#"variable 'mode': unknown variability "sometimes""#,
    );
    assert_err(
        &replace(r#"variability="fixed" start="2""#, r#"variability="continuous""#),
        "variable 'mode': variability \"continuous\" is only allowed for Float32/Float64, not Int32",
    );
    assert_err(&replace(r#"stepSize="0.02""#, r#"stepSize="fast""#), r#"stepSize="fast" is not a number"#);
    assert_err(
        &replace(r#"canGetAndSetFMUState="true""#, r#"canGetAndSetFMUState="yes""#),
        "canGetAndSetFMUState=\"yes\" is not a boolean",
    );
    assert_err(&replace("<UInt64 ", "<Float128 "), "unknown variable element <Float128>");
}

#[test]
fn not_xml_and_wrong_root_are_rejected() {
    assert_err("this is not xml", "not well-formed XML");
    assert_err("<fmiModelDescriptions/>", "root element is <fmiModelDescriptions>");
}

#[test]
fn from_file_names_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("modelDescription.xml");
    let e = ModelDescription::from_file(&p).unwrap_err();
    assert!(e.to_string().starts_with(&format!("{}: cannot read", p.display())), "{e}");
    std::fs::write(&p, GOOD).unwrap();
    assert_eq!(ModelDescription::from_file(&p).unwrap().model_name, "ChassisKinematic");
}

#[test]
fn minimal_description_has_defaults() {
    let md = ModelDescription::parse(
        r#"<fmiModelDescription fmiVersion="3.0" modelName="M" instantiationToken="t"><CoSimulation modelIdentifier="m"/></fmiModelDescription>"#,
        "m.xml",
    )
    .unwrap();
    assert!(md.variables.is_empty());
    assert!(!md.can_get_and_set_fmu_state);
    assert_eq!(md.default_step_size, None);
}

#[test]
fn log_categories_are_read() {
    let xml = GOOD.replace(
        "<UnitDefinitions>",
        r#"<LogCategories><Category name="logCalls" description="calls"/><Category name="logModel"/></LogCategories><UnitDefinitions>"#,
    );
    let md = ModelDescription::parse(&xml, "good.xml").unwrap();
    assert_eq!(md.log_categories, vec!["logCalls", "logModel"]);
    assert!(ModelDescription::parse(GOOD, "good.xml").unwrap().log_categories.is_empty());
    let bad = GOOD.replace("<UnitDefinitions>", "<LogCategories><Category/></LogCategories><UnitDefinitions>");
    let e = ModelDescription::parse(&bad, "bad.xml").unwrap_err();
    assert!(e.to_string().contains("bad.xml") && e.to_string().contains("<Category> has no attribute 'name'"), "{e}");
}
