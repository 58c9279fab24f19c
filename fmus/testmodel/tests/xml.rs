//! modelDescription.xml of the test model: structure, escaping, determinism, table checks.

use agrisim_fmi::{xml, Model, Start, Var};
use agrisim_fmu_testmodel::TestModel;

#[test]
fn fmi3_description_has_the_required_parts() {
    let x = xml::fmi3::<TestModel>();
    assert!(x.contains(&format!(r#"instantiationToken="{}""#, TestModel::TOKEN)));
    for needle in [
        r#"fmiVersion="3.0""#,
        r#"<CoSimulation modelIdentifier="TestModel""#,
        r#"canHandleVariableCommunicationStepSize="true""#,
        r#"canGetAndSetFMUState="true""#,
        r#"canSerializeFMUState="true""#,
        r#"<Float64 name="time" valueReference="0""#,
        r#"causality="independent""#,
        r#"<Unit name="1/s">"#,
        r#"<BaseUnit s="-1"/>"#,
        r#"<Binary name="msg_in" valueReference="5""#,
        r#"mimeType="application/x-ros2-cdr; type=std_msgs/msg/String" maxSize="1048576">"#,
        r#"<Start value="000100000100000000"/>"#,
        r#"<Start value="agrisim &quot;test&quot; &lt;model&gt; &amp; more"/>"#,
        r#"name="x" valueReference="8" description="State x(t)" causality="output" variability="continuous" initial="calculated" declaredType="m"/>"#,
        r#"<Float64Type name="m" unit="m"/>"#,
        r#"<Output valueReference="8" dependencies=""/>"#,
        r#"<InitialUnknown valueReference="8" dependencies="2"/>"#,
        r#"<InitialUnknown valueReference="9" dependencies=""/>"#,
        r#"<InitialUnknown valueReference="12" dependencies="5"/>"#,
        r#"<DefaultExperiment startTime="0.0" stepSize="0.02"/>"#,
    ] {
        assert!(x.contains(needle), "missing {needle} in\n{x}");
    }
    assert_eq!(x.matches("<Output ").count(), 5);
    assert_eq!(x.matches(r#"dependencies="""#).count(), 6, "every output, and steps initially");
    assert_eq!(x.matches("<InitialUnknown ").count(), 5);
    assert_eq!(x, xml::fmi3::<TestModel>(), "deterministic");
}

#[test]
fn fmi2_description_hides_fmi3_only_variables_and_indexes_by_position() {
    let x = xml::fmi2::<TestModel>();
    assert!(x.contains(r#"fmiVersion="2.0""#) && x.contains(&format!(r#"guid="{}""#, TestModel::GUID)));
    assert_ne!(TestModel::GUID, TestModel::TOKEN, "the FMI 2 interface is another interface");
    assert!(!x.contains("msg_in") && !x.contains("msg_seq") && !x.contains("msg_out") && !x.contains("maxSize"));
    // time, k, x0, u, hold, label, fault, x, steps, above_half -> x is position 8, x0 position 3
    assert!(
        x.contains(
            r#"<Outputs>
      <Unknown index="8" dependencies=""/>"#
        ),
        "{x}"
    );
    assert!(
        x.contains(
            r#"<InitialUnknowns>
      <Unknown index="8" dependencies="3"/>"#
        ),
        "{x}"
    );
    assert_eq!(x.matches("<ScalarVariable").count(), 10);
    assert!(x.contains(r#"<String start="agrisim &quot;test&quot; &lt;model&gt; &amp; more"/>"#));
}

#[test]
fn the_table_is_valid_and_bad_tables_are_reported() {
    assert!(xml::check_table(TestModel::VARIABLES).is_empty());
    let bad = [
        Var::input_discrete("time", Start::Int32(0)),
        Var::param("p", Start::Boolean(true)).unit("m"),
        Var::param("p", Start::Float64(f64::NAN)),
        Var { variability: agrisim_fmi::Variability::Continuous, ..Var::input_discrete("i", Start::Int32(0)) },
        Var::param("q", Start::Float64(5.0)).range(0.0, 1.0),
        Var::param("r", Start::Int32(0)).max_size(8),
        Var::input_discrete("b", Start::Binary(&[1, 2, 3])).max_size(2),
        Var::output("y").init_depends_on(&[9]),
        Var::output("z").init_depends_on(&[7, 99]),
        Var::input("w", 0.0).init_depends_on(&[Var::TIME]),
    ];
    let problems = xml::check_table(&bad);
    for needle in [
        "reserved",
        "unit",
        "duplicate",
        "not finite",
        "continuous",
        "outside",
        "only Binary variables can have a maxSize",
        "maxSize 2 must be positive and hold the start value (3 bytes)",
        "initial dependency 'y' is neither a parameter nor an input",
        "initial dependency 99 is not in the table",
        "only initial unknowns",
    ] {
        assert!(problems.iter().any(|p| p.contains(needle)), "{needle}: {problems:?}");
    }
}

#[test]
fn escaping_and_number_formatting() {
    assert_eq!(xml::escape("a<b>&\"'\n"), "a&lt;b&gt;&amp;&quot;&apos;&#10;");
    assert_eq!(xml::escape("\u{1}"), "\u{FFFD}");
    assert_eq!(xml::fmt_f64(0.1), "0.1");
    assert_eq!(xml::fmt_f64(1e-20), "1e-20");
    assert_eq!(xml::fmt_f64(f64::INFINITY), "INF");
    assert_eq!(xml::fmt_f64(2.0), "2.0");
}

#[test]
fn tokens_are_hashes_of_the_interface() {
    let t = TestModel::TOKEN;
    assert_eq!(t.len(), 38);
    assert!(t.starts_with('{') && t.ends_with('}') && t.matches('-').count() == 4, "{t}");
    assert_eq!(
        t.as_bytes(),
        agrisim_fmi::token::guid(agrisim_fmi::token::hash("3.0", "TestModel", TestModel::VARIABLES))
    );
    // Another start value is another interface.
    let mut vars = TestModel::VARIABLES.to_vec();
    vars[0] = Var::tunable("k", Start::Float64(2.0));
    assert_ne!(
        agrisim_fmi::token::hash("3.0", "TestModel", &vars),
        agrisim_fmi::token::hash("3.0", "TestModel", TestModel::VARIABLES)
    );
}
