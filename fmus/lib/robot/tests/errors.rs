//! Load errors name the file and the element, so a broken description is fixed quickly.

use agrisim_robot::Robot;

const HEAD: &str = r#"<?xml version="1.0"?><robot name="t">"#;

#[test]
fn missing_file_is_named() {
    let e = Robot::from_urdf_file("/nonexistent/robot.urdf").unwrap_err();
    assert!(e.contains("/nonexistent/robot.urdf"), "{e}");
}

#[test]
fn bad_file_errors_carry_the_path_and_element() {
    let dir = std::env::temp_dir().join(format!("agrisim-robot-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("bad.urdf");
    std::fs::write(&p, format!(
        r#"{HEAD}<link name="a"/><joint name="j" type="fixed"><parent link="a"/><child link="ghost"/></joint></robot>"#
    )).unwrap();
    let e = Robot::from_urdf_file(&p).unwrap_err();
    assert!(e.contains("bad.urdf") && e.contains("joint \"j\"") && e.contains("ghost"), "{e}");
    std::fs::write(&p, "<robot name=").unwrap();
    let e = Robot::from_urdf_file(&p).unwrap_err();
    assert!(e.contains("bad.urdf"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn mesh_collisions_are_refused() {
    let e = Robot::from_urdf_str(&format!(
        r#"{HEAD}<link name="a"><collision><geometry><mesh filename="x.stl"/></geometry></collision></link></robot>"#
    ))
    .unwrap_err();
    assert!(e.contains("link \"a\"") && e.contains("x.stl"), "{e}");
}

#[test]
fn tree_shape_is_checked() {
    let two_roots = format!(r#"{HEAD}<link name="a"/><link name="b"/></robot>"#);
    assert!(Robot::from_urdf_str(&two_roots).unwrap_err().contains("root"));
    let two_parents = format!(
        r#"{HEAD}<link name="a"/><link name="b"/><link name="c"/>
        <joint name="j1" type="fixed"><parent link="a"/><child link="c"/></joint>
        <joint name="j2" type="fixed"><parent link="b"/><child link="c"/></joint></robot>"#
    );
    assert!(Robot::from_urdf_str(&two_parents).unwrap_err().contains("j2"));
    let floating = format!(
        r#"{HEAD}<link name="a"/><link name="b"/><joint name="f" type="floating"><parent link="a"/><child link="b"/></joint></robot>"#
    );
    assert!(Robot::from_urdf_str(&floating).unwrap_err().contains("joint \"f\""));
}

#[test]
fn pose_algebra() {
    use agrisim_robot::Pose;
    let a = Pose::from_xyz_rpy([0.1, -0.2, 0.3], [0.4, -0.5, 0.6]);
    let id = a.mul(&a.inverse());
    assert!(id.max_abs_diff(&Pose::IDENTITY) < 1e-15);
    // rpy is fixed-axis x, then y, then z.
    let b = Pose::from_axis_angle([0.0, 0.0, 1.0], 0.6)
        .mul(&Pose::from_axis_angle([0.0, 1.0, 0.0], -0.5))
        .mul(&Pose::from_axis_angle([1.0, 0.0, 0.0], 0.4));
    assert!(Pose::from_xyz_rpy([0.0; 3], [0.4, -0.5, 0.6]).max_abs_diff(&b) < 1e-15);
}
