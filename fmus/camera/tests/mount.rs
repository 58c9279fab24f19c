//! Where the camera is: on a URDF link (`mount_parent`) placed by the robot's forward
//! kinematics from the lift and arm inputs. A wrist camera moves with its arm's joints and its
//! published TF chained onto the URDF's FK is the pose it renders from; a camera on the lift
//! carriage sees the arm reaching in front of it, labelled as the robot's parts; the default
//! camera is the URDF's camera_link; bad mounts are refused naming the parameter.

use agrisim_fmi::{Model, Quiet, Store, Value};
use agrisim_fmu_camera::ports::*;
use agrisim_fmu_camera::{image, Camera};
use agrisim_msgs::sensor_msgs::Image;
use agrisim_msgs::tf2_msgs::TFMessage;
use agrisim_msgs::Message;
use agrisim_robot::model::{Coords, READY_POSE, URDF};
use agrisim_robot::{Pose, Robot};
use agrisim_scene::{generate, GreenhouseConfig, Kind, Shape};
use std::collections::BTreeMap;
use std::f64::consts::FRAC_PI_2;

/// Both arms reaching forward and down (as the harvest's working pose).
const WORKING: [f64; 7] = [0.0, 0.6, 0.0, -1.6, 0.0, 2.2, 0.785];

/// base_link in the middle of the default greenhouse's first aisle, driving along it.
fn in_aisle() -> [f64; 3] {
    let cfg = GreenhouseConfig::from_toml_str("").unwrap();
    let gh = generate(&cfg, cfg.seed);
    let a = &gh.layout.aisles[0];
    [0.5 * (a.x_start + a.x_end), a.y, 0.0]
}

fn set_str(io: &mut Store, i: usize, v: &str) {
    *io.value_mut(i) = Value::String(v.into());
}

/// A camera's store: `w` x `h`, noise-free depth, base in the aisle, then `set`.
fn store(w: i32, h: i32, set: impl FnOnce(&mut Store)) -> Store {
    let mut io = Store::new(Camera::VARIABLES);
    *io.value_mut(WIDTH) = Value::Int32(w);
    *io.value_mut(HEIGHT) = Value::Int32(h);
    *io.value_mut(DEPTH_NOISE_MODEL) = Value::Int32(0);
    *io.value_mut(INVALID_BAND) = Value::Boolean(false);
    *io.value_mut(EDGE_RATIO) = Value::Float64(0.0);
    let [x, y, yaw] = in_aisle();
    io.set_f64(BASE_X, x);
    io.set_f64(BASE_Y, y);
    io.set_f64(BASE_YAW, yaw);
    set(&mut io);
    io
}

/// A RealSense D405 on the left hand, beside the gripper, looking along the approach axis.
fn left_wrist(io: &mut Store) {
    set_str(io, MOUNT_PARENT, "left_hand");
    set_str(io, LINK_FRAME, "left_wrist_camera_link");
    set_str(io, FRAME_ID, "left_wrist_camera_color_optical_frame");
    io.set_f64(MOUNT_X, 0.065);
    io.set_f64(MOUNT_Z, 0.03);
    io.set_f64(MOUNT_PITCH, -FRAC_PI_2);
    io.set_f64(RANGE_MIN, 0.07);
}

/// A D435i on the lift carriage's left end looking left, into the row.
fn lift_left(io: &mut Store) {
    set_str(io, MOUNT_PARENT, "lift_link");
    set_str(io, LINK_FRAME, "camera_left_link");
    set_str(io, FRAME_ID, "camera_left_color_optical_frame");
    io.set_f64(MOUNT_X, 0.05);
    io.set_f64(MOUNT_Y, 0.36);
    io.set_f64(MOUNT_Z, 0.10);
    io.set_f64(MOUNT_YAW, FRAC_PI_2);
}

fn set_coords(io: &mut Store, c: &Coords) {
    io.set_f64(LIFT_POSITION, c.lift);
    for i in 0..7 {
        io.set_f64(LEFT_Q1 + i, c.arms[0][i]);
        io.set_f64(RIGHT_Q1 + i, c.arms[1][i]);
    }
}

/// The URDF's FK (the tree walk of `Robot::fk`, by joint name) of every link at `c`.
fn urdf_fk(c: &Coords) -> BTreeMap<String, Pose> {
    let robot = Robot::from_urdf_str(URDF).unwrap();
    let mut q = BTreeMap::from([("lift_joint".to_string(), c.lift)]);
    for (s, side) in ["left", "right"].iter().enumerate() {
        for i in 0..7 {
            q.insert(format!("{side}_joint{}", i + 1), c.arms[s][i]);
        }
    }
    robot.fk(&q).unwrap()
}

/// A TF transform as a pose.
fn pose_of(t: &agrisim_msgs::geometry_msgs::Transform) -> Pose {
    let (x, y, z, w) = (t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w);
    Pose {
        rot: [
            [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - z * w), 2.0 * (x * z + y * w)],
            [2.0 * (x * y + z * w), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - x * w)],
            [2.0 * (x * z - y * w), 2.0 * (y * z + x * w), 1.0 - 2.0 * (x * x + y * y)],
        ],
        trans: [t.translation.x, t.translation.y, t.translation.z],
    }
}

fn latest_image(io: &Store, port: usize) -> Image {
    Image::from_cdr(agrisim_fmi::port::latest(io, port)).unwrap()
}

#[test]
fn a_wrist_camera_moves_with_its_arm_and_its_tf_is_the_urdf_fk() {
    let a = Coords { lift: 0.35, arms: [[0.3, 0.4, -0.2, -1.9, 0.1, 2.0, 0.5], READY_POSE], ..Coords::default() };
    let mut io = store(96, 72, left_wrist);
    set_coords(&mut io, &a);
    let mut m = Camera::new();
    m.initialize(&mut io, 0.0, &mut Quiet).unwrap();
    m.do_step(&mut io, 0.0, 0.02, &mut Quiet).unwrap();

    // The camera's frames, published once, hang it on the hand.
    assert_eq!(io.i64(TF_STATIC_SEQ), 1);
    let tf = TFMessage::from_cdr(agrisim_fmi::port::latest(&io, TF_STATIC)).unwrap();
    let names: Vec<(&str, &str)> =
        tf.transforms.iter().map(|t| (t.header.frame_id.as_str(), t.child_frame_id.as_str())).collect();
    assert_eq!(
        names,
        [("left_hand", "left_wrist_camera_link"), ("left_wrist_camera_link", "left_wrist_camera_color_optical_frame")]
    );
    let rgb = latest_image(&io, IMAGE);
    assert_eq!(rgb.header.frame_id, "left_wrist_camera_color_optical_frame");

    // TF chained onto the URDF's FK is the pose the camera renders from.
    let c = m.config().unwrap();
    let chained = |coords: &Coords| {
        urdf_fk(coords)["left_hand"]
            .mul(&pose_of(&tf.transforms[0].transform))
            .mul(&pose_of(&tf.transforms[1].transform))
    };
    for coords in [a, Coords { arms: [WORKING, WORKING], ..a }, Coords::default()] {
        let got = c.optical_in_base(&coords);
        assert!(got.max_abs_diff(&chained(&coords)) < 1e-9, "{got:?} vs {:?}", chained(&coords));
        // It looks along the hand's approach axis (hand z), from beside the gripper.
        let hand = urdf_fk(&coords)["left_hand"];
        let along: f64 = (0..3).map(|i| hand.axis(2)[i] * got.axis(2)[i]).sum();
        assert!((along - 1.0).abs() < 1e-9);
        let [x, y, yaw] = in_aisle();
        let map = c.camera_pose(&coords, x, y, yaw);
        let want = Pose::from_xyz_rpy([x, y, 0.0], [0.0, 0.0, yaw]).mul(&got);
        assert!((0..3).all(|i| (map.origin[i] - want.trans[i]).abs() < 1e-12));
    }
    // The other arm's joints do not move it; its own do.
    let other = Coords { arms: [a.arms[0], WORKING], ..a };
    assert!(c.optical_in_base(&a).max_abs_diff(&c.optical_in_base(&other)) < 1e-12);
    let moved = Coords { arms: [[0.9, 0.4, -0.2, -1.9, 0.1, 2.0, 0.5], READY_POSE], ..a };
    assert!(c.optical_in_base(&a).max_abs_diff(&c.optical_in_base(&moved)) > 0.1);

    // Through the FMU: the next frame, after joint 1 turned, is another image.
    let depth_a = latest_image(&io, DEPTH).data;
    let labels_a = latest_image(&io, LABELS_IMAGE).data;
    set_coords(&mut io, &moved);
    for k in 1..=5 {
        m.do_step(&mut io, k as f64 * 0.02, 0.02, &mut Quiet).unwrap();
    }
    assert_eq!((io.i64(IMAGE_SEQ), io.i64(TF_STATIC_SEQ)), (2, 1));
    let (depth_b, labels_b) = (latest_image(&io, DEPTH).data, latest_image(&io, LABELS_IMAGE).data);
    let differ = depth_a.chunks(4).zip(depth_b.chunks(4)).filter(|(p, q)| p != q).count();
    let valid = depth_a.chunks(4).filter(|p| f32::from_le_bytes([p[0], p[1], p[2], p[3]]) > 0.0).count();
    println!("{differ} of {} depth pixels changed ({valid} with depth before)", 96 * 72);
    assert!(differ > 96 * 72 / 10, "{differ} of {} depth pixels changed", 96 * 72);
    assert_ne!(labels_a, labels_b);
}

/// Pixels of a frame of the left lift camera showing robot parts (label -> count), after
/// checking that each such pixel's depth reprojects onto the part its label names.
fn robot_in_lift_camera(coords: &Coords) -> BTreeMap<String, usize> {
    let (w, h) = (160, 120);
    let mut io = store(w, h, lift_left);
    set_coords(&mut io, coords);
    let mut m = Camera::new();
    m.initialize(&mut io, 0.0, &mut Quiet).unwrap();
    m.do_step(&mut io, 0.0, 0.02, &mut Quiet).unwrap();
    let c = m.config().unwrap();
    let first = c.scene.object_count();
    let [x, y, yaw] = in_aisle();
    let parts = c.robot.objects(Some(coords), x, y, yaw);
    let pose = c.camera_pose(coords, x, y, yaw);
    let labels = image::read_32sc1(&latest_image(&io, LABELS_IMAGE)).unwrap();
    let depth = image::read_32fc1(&latest_image(&io, DEPTH)).unwrap();
    let mut seen = BTreeMap::new();
    for (i, &l) in labels.iter().enumerate() {
        let id = (l - 1) as usize;
        if l <= 0 || id < first {
            continue;
        }
        let part = &parts[id - first];
        assert_eq!((part.id as usize, part.kind), (id, Kind::Robot));
        if depth[i] > 0.0 {
            let p =
                pose.to_map(c.intrinsics.reproject((i % w as usize) as f64, (i / w as usize) as f64, depth[i] as f64));
            let o = part.placement.translation;
            let r = ((p[0] - o[0]).powi(2) + (p[1] - o[1]).powi(2) + (p[2] - o[2]).powi(2)).sqrt();
            let bound = match part.shape {
                Shape::Box { half } => (half[0] * half[0] + half[1] * half[1] + half[2] * half[2]).sqrt(),
                Shape::Cylinder { radius, half_height } => radius.hypot(half_height),
                Shape::Sphere { radius } => radius,
            };
            assert!(r <= bound + 1e-4, "pixel {i}: {p:?} is {r} m from {}'s centre (bound {bound})", part.name);
        }
        *seen.entry(part.name.clone()).or_insert(0) += 1;
    }
    seen
}

#[test]
fn the_arm_raised_in_front_of_a_lift_camera_is_seen_as_the_robot() {
    // The left arm turned (joint 1) from reaching forward to reaching left, into the row,
    // with the lift up: in front of the camera on the carriage's left end.
    let forward = Coords { lift: 0.4, arms: [WORKING, WORKING], ..Coords::default() };
    let mut sideways = forward;
    sideways.arms[0][0] = FRAC_PI_2;
    let before = robot_in_lift_camera(&forward);
    let after = robot_in_lift_camera(&sideways);
    let left =
        |m: &BTreeMap<String, usize>| m.iter().filter(|(n, _)| n.starts_with("left_")).map(|(_, k)| k).sum::<usize>();
    println!("robot pixels, arm forward {before:?}; arm in front of the camera {after:?}");
    assert!(left(&after) > 160 * 120 / 50, "{after:?}");
    assert!(left(&after) > 4 * left(&before), "{before:?} vs {after:?}");
    // The hand, the fingers and the wrist links each carry their own labels.
    for link in ["left_hand", "left_finger1", "left_finger2", "left_link7"] {
        assert!(after.get(link).is_some_and(|&k| k > 0), "{link} not seen: {after:?}");
    }
    assert!(!after.keys().any(|n| n.starts_with("right_")), "{after:?}");
}

#[test]
fn the_default_camera_is_the_urdf_camera_link() {
    let mut io = store(32, 24, |_| {});
    let mut m = Camera::new();
    m.initialize(&mut io, 0.0, &mut Quiet).unwrap();
    let c = m.config().unwrap();
    for lift in [0.0, 0.3, 0.8] {
        let coords = Coords { lift, ..Coords::default() };
        let want = urdf_fk(&coords)["camera_color_optical_frame"];
        assert!(c.optical_in_base(&coords).max_abs_diff(&want) < 1e-9, "lift {lift}");
    }
    assert_eq!((c.parent.0.as_str(), c.link_frame.as_str()), ("lift_link", "camera_link"));
    // The URDF's camera_link is this camera's housing: not among the parts it sees.
    assert!(!c.robot.objects(Some(&Coords::default()), 0.0, 0.0, 0.0).iter().any(|o| o.name == "camera_link"));
    // Another camera sees it.
    let mut io = store(32, 24, lift_left);
    let mut m = Camera::new();
    m.initialize(&mut io, 0.0, &mut Quiet).unwrap();
    let parts = m.config().unwrap().robot.objects(Some(&Coords::default()), 0.0, 0.0, 0.0);
    assert!(parts.iter().any(|o| o.name == "camera_link"));
}

/// A bad setting: what it is, how to make it, the words its error must hold.
type Case = (&'static str, fn(&mut Store), &'static [&'static str]);

#[test]
fn bad_mounts_are_refused_naming_the_parameter() {
    let cases: [Case; 4] = [
        ("unknown parent", |io| set_str(io, MOUNT_PARENT, "nose_link"), &["mount_parent", "nose_link", "left_hand"]),
        ("empty frame", |io| set_str(io, LINK_FRAME, ""), &["link_frame"]),
        ("slash frame", |io| set_str(io, FRAME_ID, "/camera_color_optical_frame"), &["frame_id"]),
        ("same frames", |io| set_str(io, LINK_FRAME, "lift_link"), &["mount_parent", "link_frame", "lift_link"]),
    ];
    for (what, set, words) in cases {
        let mut io = store(32, 24, set);
        let e = Camera::new().initialize(&mut io, 0.0, &mut Quiet).unwrap_err();
        assert!(words.iter().all(|w| e.contains(w)), "{what}: {e}");
    }
    // A non-finite joint input, which places a wrist camera, is refused by name.
    let mut io = store(32, 24, left_wrist);
    let mut m = Camera::new();
    m.initialize(&mut io, 0.0, &mut Quiet).unwrap();
    io.set_f64(LEFT_Q4, f64::NAN);
    let e = m.do_step(&mut io, 0.0, 0.02, &mut Quiet).unwrap_err();
    assert!(e.contains("left_q4"), "{e}");
}
