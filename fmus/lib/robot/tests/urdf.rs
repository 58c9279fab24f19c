//! The checked-in robot description against its sources: structure, the figures it must match
//! in other FMUs, the Franka Panda kinematics (independent DH product) and limits, and an
//! independent parser (`check_urdf`, urdfdom).

use agrisim_robot::{JointKind, Pose, Robot, Shape};
use std::collections::BTreeMap;
use std::f64::consts::{FRAC_PI_2, PI};
use std::path::PathBuf;

fn urdf_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../models/robot/agrisim_robot.urdf")
}

fn robot() -> Robot {
    Robot::from_urdf_file(urdf_path()).expect("robot URDF loads")
}

const SIDES: [&str; 2] = ["left", "right"];
const WHEELS: [(&str, f64, f64); 4] =
    [("front_left", 1.0, 1.0), ("front_right", 1.0, -1.0), ("rear_left", -1.0, 1.0), ("rear_right", -1.0, -1.0)];

// Franka Emika, FCI documentation "Robot and interface specifications": joint position,
// velocity and torque limits of the Panda.
const Q_MIN: [f64; 7] = [-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973];
const Q_MAX: [f64; 7] = [2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973];
const DQ_MAX: [f64; 7] = [2.1750, 2.1750, 2.1750, 2.1750, 2.6100, 2.6100, 2.6100];
const TAU_MAX: [f64; 7] = [87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0];
// Franka Emika, FCI documentation: Panda kinematic parameters, modified (Craig) DH:
// (a, d, alpha) for joints 1..7, then the flange with d = 0.107 m.
const DH: [(f64, f64, f64); 7] = [
    (0.0, 0.333, 0.0),
    (0.0, 0.0, -FRAC_PI_2),
    (0.0, 0.316, FRAC_PI_2),
    (0.0825, 0.0, FRAC_PI_2),
    (-0.0825, 0.384, -FRAC_PI_2),
    (0.0, 0.0, FRAC_PI_2),
    (0.088, 0.0, FRAC_PI_2),
];
const FLANGE_D: f64 = 0.107;

type M4 = [[f64; 4]; 4];

fn m4_mul(a: &M4, b: &M4) -> M4 {
    let mut c = [[0.0; 4]; 4];
    for i in 0..4 {
        for j in 0..4 {
            c[i][j] = (0..4).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    c
}

/// Modified DH link transform, written out as the closed-form matrix of
/// RotX(alpha) TransX(a) RotZ(theta) TransZ(d) (Craig, eq. 3.6).
fn dh(a: f64, d: f64, alpha: f64, theta: f64) -> M4 {
    let (st, ct) = theta.sin_cos();
    let (sa, ca) = alpha.sin_cos();
    [[ct, -st, 0.0, a], [st * ca, ct * ca, -sa, -d * sa], [st * sa, ct * sa, ca, d * ca], [0.0, 0.0, 0.0, 1.0]]
}

/// Flange (link8) in link0 by the DH product.
fn panda_dh_fk(q: &[f64; 7]) -> M4 {
    let mut t = dh(0.0, 0.0, 0.0, 0.0);
    for (i, &(a, d, alpha)) in DH.iter().enumerate() {
        t = m4_mul(&t, &dh(a, d, alpha, q[i]));
    }
    m4_mul(&t, &dh(0.0, FLANGE_D, 0.0, 0.0))
}

#[allow(clippy::needless_range_loop)]
fn to_m4(p: &Pose) -> M4 {
    let mut m = [[0.0; 4]; 4];
    for i in 0..3 {
        m[i][..3].copy_from_slice(&p.rot[i]);
        m[i][3] = p.trans[i];
    }
    m[3][3] = 1.0;
    m
}

fn max_diff(a: &M4, b: &M4) -> f64 {
    (0..4).flat_map(|i| (0..4).map(move |j| (i, j))).map(|(i, j)| (a[i][j] - b[i][j]).abs()).fold(0.0, f64::max)
}

/// Deterministic configurations inside the Franka limits (plus the zero pose and the
/// manual's "ready" pose), so failures are reproducible.
fn test_configs() -> Vec<[f64; 7]> {
    let mut out = vec![[0.0; 7], [0.0, -PI / 4.0, 0.0, -3.0 * PI / 4.0, 0.0, PI / 2.0, PI / 4.0], Q_MIN, Q_MAX];
    let mut s: u64 = 0x2545_F491_4F6C_DD1D;
    for _ in 0..20 {
        let mut q = [0.0; 7];
        for i in 0..7 {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            let u = (s >> 11) as f64 / (1u64 << 53) as f64;
            q[i] = Q_MIN[i] + u * (Q_MAX[i] - Q_MIN[i]);
        }
        out.push(q);
    }
    out
}

#[test]
fn parses_with_urdf_rs() {
    let u = urdf_rs::read_file(urdf_path()).expect("urdf-rs parses the robot URDF");
    assert_eq!(u.name, "agrisim_robot");
    assert!(u.links.len() > 30 && u.joints.len() == u.links.len() - 1);
}

#[test]
fn joint_counts_and_kinds() {
    let r = robot();
    assert_eq!(r.root, "base_link");
    let count =
        |f: &dyn Fn(&str) -> bool, k: JointKind| r.joints().iter().filter(|j| f(&j.name) && j.kind == k).count();
    assert_eq!(count(&|n| n.ends_with("_steer_joint"), JointKind::Revolute), 4);
    assert_eq!(count(&|n| n.ends_with("_drive_joint"), JointKind::Continuous), 4);
    assert_eq!(count(&|n| n == "lift_joint", JointKind::Prismatic), 1);
    let arm = |n: &str| SIDES.iter().any(|s| (1..=7).any(|i| n == format!("{s}_joint{i}")));
    assert_eq!(count(&arm, JointKind::Revolute), 14);
    assert_eq!(count(&|n| n.contains("_finger_joint"), JointKind::Prismatic), 4);
    // Nothing else moves.
    assert_eq!(r.movable_joints().count(), 8 + 1 + 14 + 4);
}

#[test]
fn base_wheels_lift_and_sensor_mounts_match_the_fmus() {
    let r = robot();
    let fk = r.fk(&BTreeMap::new()).unwrap();
    for (tag, sx, sy) in WHEELS {
        let steer = r.joint(&format!("{tag}_steer_joint")).unwrap();
        assert_eq!(steer.axis, [0.0, 0.0, 1.0]);
        let l = steer.limits.unwrap();
        assert!((l.lower + FRAC_PI_2).abs() < 1e-12 && (l.upper - FRAC_PI_2).abs() < 1e-12);
        // chassis ports.rs: wheel_base 1.0, track 0.8, wheel_radius 0.1 (axle at 0.1 m).
        let p = fk[&format!("{tag}_wheel_link")].trans;
        assert!(dist(p, [0.5 * sx, 0.4 * sy, 0.1]) < 1e-12, "{tag}: {p:?}");
        let drive = r.joint(&format!("{tag}_drive_joint")).unwrap();
        assert_eq!(drive.axis, [0.0, 1.0, 0.0]);
        let wheel = r.colliders(&format!("{tag}_wheel_link")).unwrap();
        assert!(matches!(wheel[0].shape, Shape::Cylinder { radius, .. } if radius == 0.1));
    }
    let base = r.colliders("base_link").unwrap();
    assert!(matches!(base[0].shape, Shape::Box { size } if size[0] == 1.2 && size[1] == 0.9));

    let lift = r.joint("lift_joint").unwrap();
    let l = lift.limits.unwrap();
    assert_eq!((l.lower, l.upper, l.velocity), (0.0, 0.8, 0.2));
    assert_eq!(lift.axis, [0.0, 0.0, 1.0]);
    let z0 = fk["lift_link"].trans[2];
    let up = r.fk(&BTreeMap::from([("lift_joint".to_string(), 0.8)])).unwrap();
    assert!((up["lift_link"].trans[2] - z0 - 0.8).abs() < 1e-12);
    assert!((up["left_hand"].trans[2] - fk["left_hand"].trans[2] - 0.8).abs() < 1e-12, "arms ride the lift");
    // lift lib.rs base_height: carried mass centre 0.45 m above the floor at 0.
    assert!((z0 - 0.45).abs() < 1e-12);

    for f in ["lidar_link", "imu_link"] {
        assert!(dist(fk[f].trans, [0.0, 0.0, 1.0]) < 1e-12, "{f}");
        assert!(fk[f].max_abs_diff(&Pose::from_translation([0.0, 0.0, 1.0])) < 1e-12, "{f} unrotated");
    }
}

#[test]
fn camera_optical_frame_convention() {
    let r = robot();
    for q in [BTreeMap::new(), BTreeMap::from([("lift_joint".to_string(), 0.3)])] {
        let fk = r.fk(&q).unwrap();
        let cam = fk["camera_link"];
        let opt = fk["camera_color_optical_frame"];
        let neg = |v: [f64; 3]| v.map(|x| -x);
        assert!(dist(opt.axis(2), cam.axis(0)) < 1e-12, "z_optical = x_camera (forward)");
        assert!(dist(opt.axis(0), neg(cam.axis(1))) < 1e-12, "x_optical = -y_camera (right)");
        assert!(dist(opt.axis(1), neg(cam.axis(2))) < 1e-12, "y_optical = -z_camera (down)");
        assert!(dist(opt.trans, cam.trans) < 1e-12);
    }
}

#[test]
fn harvest_box_is_an_open_box_with_a_frame_inside_at_the_bottom() {
    let r = robot();
    let c = r.colliders("harvest_box_link").unwrap();
    assert_eq!(c.len(), 5, "bottom + 4 walls");
    let boxes: Vec<([f64; 3], [f64; 3])> = c
        .iter()
        .map(|c| match c.shape {
            Shape::Box { size } => (size, c.origin.trans),
            s => panic!("not a box: {s:?}"),
        })
        .collect();
    let (bottom_size, bottom_pos) = boxes[0];
    let bottom_top = bottom_pos[2] + bottom_size[2] / 2.0;
    // Walls rise above the bottom and surround its centre on all four sides.
    for (s, p) in &boxes[1..] {
        assert!(p[2] + s[2] / 2.0 > bottom_top + 0.1);
    }
    let fk = r.fk(&BTreeMap::new()).unwrap();
    let frame = fk["harvest_box_link"].inverse().mul(&fk["harvest_box"]);
    assert!(dist(frame.trans, [bottom_pos[0], bottom_pos[1], bottom_top]) < 1e-12);
    // In the rear enclosure, behind the lift and arms, on top of the base.
    let hb = fk["harvest_box"].trans;
    assert!(hb[0] < -0.1 && hb[0] > -0.6 && hb[2] > 0.42, "{hb:?}");
    assert!(r.link("rear_enclosure_link").is_some());
}

#[test]
fn frames_present_and_moving_links_have_mass() {
    let r = robot();
    for f in
        ["base_link", "camera_link", "camera_color_optical_frame", "lidar_link", "imu_link", "harvest_box", "lift_link"]
    {
        assert!(r.link(f).is_some(), "{f} missing");
    }
    for s in SIDES {
        for l in ["hand", "hand_tcp", "link8", "finger1", "finger2"] {
            assert!(r.link(&format!("{s}_{l}")).is_some(), "{s}_{l} missing");
        }
    }
    // Every link whose pose depends on a joint coordinate and that has geometry carries mass;
    // the direct children of movable joints all do.
    let u = urdf_rs::read_file(urdf_path()).unwrap();
    for j in r.movable_joints() {
        let l = r.link(&j.child).unwrap();
        assert!(l.mass > 0.0, "{} (moved by {}) has no mass", l.name, j.name);
    }
    for l in &u.links {
        if !l.collision.is_empty() {
            assert!(l.inertial.mass.value > 0.0, "{} has geometry but no mass", l.name);
            let i = &l.inertial.inertia;
            let (a, b, c) = (i.ixx, i.iyy, i.izz);
            assert!(a > 0.0 && b > 0.0 && c > 0.0 && a + b >= c && b + c >= a && a + c >= b, "{}: inertia", l.name);
            assert!(!l.visual.is_empty(), "{}: visual geometry", l.name);
        }
    }
}

#[test]
fn panda_limits_equal_franka_figures() {
    let r = robot();
    for s in SIDES {
        for i in 0..7 {
            let j = r.joint(&format!("{s}_joint{}", i + 1)).unwrap();
            let l = j.limits.unwrap();
            assert_eq!(
                (l.lower, l.upper, l.velocity, l.effort),
                (Q_MIN[i], Q_MAX[i], DQ_MAX[i], TAU_MAX[i]),
                "{}",
                j.name
            );
            assert_eq!(j.axis, [0.0, 0.0, 1.0]);
        }
        for k in 1..=2 {
            let l = r.joint(&format!("{s}_finger_joint{k}")).unwrap().limits.unwrap();
            assert_eq!((l.lower, l.upper), (0.0, 0.04));
        }
    }
}

#[test]
fn panda_fk_matches_the_dh_product() {
    let r = robot();
    for s in SIDES {
        let chain = r.chain(&format!("{s}_link0"), &format!("{s}_link8")).unwrap();
        let names: Vec<&str> = chain.iter().filter(|j| j.kind.is_movable()).map(|j| j.name.as_str()).collect();
        let expect: Vec<String> = (1..=7).map(|i| format!("{s}_joint{i}")).collect();
        assert_eq!(names, expect);
        for q in test_configs() {
            let want = panda_dh_fk(&q);
            let got = Robot::chain_fk(&chain, &q).unwrap();
            assert!(
                max_diff(&to_m4(&got), &want) < 1e-9,
                "{s} {q:?}: chain_fk off by {}",
                max_diff(&to_m4(&got), &want)
            );
            // Whole-tree FK agrees: base_link -> link0 (fixed mount) times the DH product.
            let qm: BTreeMap<String, f64> = expect.iter().cloned().zip(q).collect();
            let fk = r.fk(&qm).unwrap();
            let via_dh = m4_mul(&to_m4(&fk[&format!("{s}_link0")]), &want);
            assert!(max_diff(&to_m4(&fk[&format!("{s}_link8")]), &via_dh) < 1e-9, "{s} {q:?}: fk");
        }
    }
    // Zero pose, spelled out: flange at (0.088, 0, 0.333 + 0.316 + 0.384 - 0.107), pointing down.
    let t = panda_dh_fk(&[0.0; 7]);
    assert!(dist([t[0][3], t[1][3], t[2][3]], [0.088, 0.0, 0.926]) < 1e-12);
    assert!((t[2][2] + 1.0).abs() < 1e-12);
}

#[test]
fn arm_chains_from_the_lift() {
    let r = robot();
    for s in SIDES {
        let chain = r.chain("lift_link", &format!("{s}_hand")).unwrap();
        assert_eq!(chain.first().unwrap().parent, "lift_link");
        assert_eq!(chain.last().unwrap().child, format!("{s}_hand"));
        assert_eq!(chain.iter().filter(|j| j.kind.is_movable()).count(), 7);
        // chain_fk equals the tree FK relative to lift_link.
        let q = [0.3, -0.5, 0.2, -2.0, 0.1, 1.6, 0.7];
        let qm: BTreeMap<String, f64> = (1..=7).map(|i| format!("{s}_joint{i}")).zip(q).collect();
        let fk = r.fk(&qm).unwrap();
        let rel = fk["lift_link"].inverse().mul(&fk[&format!("{s}_hand")]);
        assert!(rel.max_abs_diff(&Robot::chain_fk(&chain, &q).unwrap()) < 1e-12);
    }
    assert!(r.chain("left_hand", "lift_link").unwrap_err().contains("not an ancestor"));
    assert!(r.chain("lift_link", "nope").unwrap_err().contains("nope"));
    // The arms sit left (+y) and right (-y) of the carriage.
    let fk = r.fk(&BTreeMap::new()).unwrap();
    assert!(fk["left_link0"].trans[1] > 0.1 && fk["right_link0"].trans[1] < -0.1);
}

#[test]
fn fk_inputs_are_checked() {
    let r = robot();
    assert!(r.fk(&BTreeMap::from([("left_joint9".to_string(), 0.0)])).unwrap_err().contains("left_joint9"));
    assert!(r.fk(&BTreeMap::from([("lidar_joint".to_string(), 0.0)])).unwrap_err().contains("fixed"));
    assert!(r.fk_slice(&[0.0; 3]).is_err());
    let n = r.movable_joints().count();
    let a = r.fk_slice(&vec![0.0; n]).unwrap();
    let b = r.fk(&BTreeMap::new()).unwrap();
    assert_eq!(a.len(), r.links().len());
    assert!(a.iter().all(|(k, p)| p.max_abs_diff(&b[k]) == 0.0));
}

/// Independent checker: urdfdom's `check_urdf` (Debian liburdfdom-tools) must accept the file.
#[test]
fn check_urdf_accepts_the_file() {
    let out = std::process::Command::new("check_urdf").arg(urdf_path()).output().unwrap_or_else(|e| {
        panic!("cannot run check_urdf ({e}): install Debian's liburdfdom-tools (scripts/setup does)")
    });
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "check_urdf rejected the URDF:\n{text}");
    assert!(text.contains("Successfully Parsed XML") && text.contains("root Link: base_link"), "{text}");
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// The checked-in URDF is what models/robot/generate_urdf.py writes (no hand edits drift).
#[test]
fn urdf_is_up_to_date_with_its_generator() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../models/robot");
    let tmp = std::env::temp_dir().join(format!("agrisim_robot_gen_{}.urdf", std::process::id()));
    let st = std::process::Command::new("python3")
        .arg(dir.join("generate_urdf.py"))
        .arg(&tmp)
        .status()
        .expect("python3 runs the generator");
    assert!(st.success());
    let fresh = std::fs::read_to_string(&tmp).unwrap();
    std::fs::remove_file(&tmp).ok();
    assert!(fresh == std::fs::read_to_string(urdf_path()).unwrap(), "re-run models/robot/generate_urdf.py");
}
