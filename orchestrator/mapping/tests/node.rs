//! The depth mapper node in a run's shape: several cameras into one map, the self-filter from
//! /robot_description and TF, the allowed objects from /harvest/allowed.

use agrisim_bus::{Bus, Node, Reader};
use agrisim_mapping::node::{ALLOWED, ROBOT_DESCRIPTION, SCENE, STATUS, TF, TF_STATIC};
use agrisim_mapping::{CameraTopics, DepthMapper, Key, MapperConfig, Occupancy};
use agrisim_msgs::agrisim::{FmuStatus, PlanningScene};
use agrisim_msgs::builtin_interfaces::Time;
use agrisim_msgs::geometry_msgs::{Point, Pose, Vector3};
use agrisim_msgs::sensor_msgs::{CameraInfo, Image};
use agrisim_msgs::std_msgs::Header;
use agrisim_msgs::vision_msgs::{BoundingBox3D, Detection3D, Detection3DArray};
use agrisim_msgs::Message;
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3 as V3};
use std::collections::BTreeSet;

mod common;
use common::tf;

const W: usize = 64;
const H: usize = 48;
const F: f64 = 50.0;
const RES: f64 = 0.01;

fn info(frame: &str) -> CameraInfo {
    CameraInfo {
        header: Header { frame_id: frame.into(), ..Default::default() },
        width: W as u32,
        height: H as u32,
        k: [F, 0.0, 32.0, 0.0, F, 24.0, 0.0, 0.0, 1.0],
        ..Default::default()
    }
}

/// A 32FC1 depth image of the depths `z(u, v)`.
fn image(frame: &str, stamp: i64, z: impl Fn(usize, usize) -> f32) -> Image {
    Image {
        header: Header { stamp: Time::from_nanos(stamp), frame_id: frame.into() },
        width: W as u32,
        height: H as u32,
        encoding: "32FC1".into(),
        step: (W * 4) as u32,
        data: (0..W * H).flat_map(|i| z(i % W, i / W).to_le_bytes()).collect(),
        ..Default::default()
    }
}

/// A camera at `at` looking along the map's +x (`forward`) or -x, optical y down (map -z).
fn camera(at: [f64; 3], forward: bool) -> Isometry3<f64> {
    let s = if forward { 1.0 } else { -1.0 };
    let r =
        UnitQuaternion::from_basis_unchecked(&[V3::new(0.0, -s, 0.0), V3::new(0.0, 0.0, -1.0), V3::new(s, 0.0, 0.0)]);
    Isometry3::from_parts(Translation3::new(at[0], at[1], at[2]), r)
}

/// The voxels the scene's boxes cover.
fn scene_voxels(s: &PlanningScene) -> BTreeSet<Key> {
    let mut out = BTreeSet::new();
    for o in &s.objects {
        let (c, d) = (o.pose.position, &o.primitive.dimensions);
        let lo = [c.x - d[0] / 2.0, c.y - d[1] / 2.0, c.z - d[2] / 2.0].map(|v| (v / RES).round() as i32);
        let n = [0, 1, 2].map(|i| (d[i] / RES).round() as i32);
        for x in 0..n[0] {
            for y in 0..n[1] {
                for z in 0..n[2] {
                    out.insert([lo[0] + x, lo[1] + y, lo[2] + z]);
                }
            }
        }
    }
    out
}

fn scenes(reader: &mut Reader, bus: &mut Bus) -> Vec<PlanningScene> {
    reader.take::<PlanningScene>(bus).unwrap()
}

fn statuses(reader: &mut Reader, bus: &mut Bus) -> Vec<String> {
    reader.take::<FmuStatus>(bus).unwrap().into_iter().map(|s| s.message).collect()
}

#[test]
fn camera_topics_follow_the_namespaces() {
    let c = MapperConfig::for_cameras(&["camera_left", "/camera_right"]);
    assert_eq!(
        c.cameras,
        [
            CameraTopics {
                depth: "/camera_left/aligned_depth_to_color/image_raw".into(),
                camera_info: "/camera_left/color/camera_info".into()
            },
            CameraTopics {
                depth: "/camera_right/aligned_depth_to_color/image_raw".into(),
                camera_info: "/camera_right/color/camera_info".into()
            },
        ]
    );
    assert_eq!(MapperConfig::default().cameras, [CameraTopics::named("camera")]);
    assert_eq!(MapperConfig::default().scene_topic, SCENE);
    assert!(DepthMapper::new(MapperConfig { cameras: vec![], ..MapperConfig::default() }).is_err());
}

#[test]
fn two_cameras_land_in_one_map() {
    let config = MapperConfig::for_cameras(&["camera_left", "camera_right"]);
    let (left, right) = (config.cameras[0].clone(), config.cameras[1].clone());
    let mut bus = Bus::default();
    let mut node = DepthMapper::new(config).unwrap();
    let mut scene_reader = Reader::subscribe(&mut bus, SCENE);
    // Left looks along +x at a wall 1 m ahead (x = 1.005), right along -x (x = -1.005).
    bus.publish(TF_STATIC, 0, &tf("map", "left_optical", &camera([0.005, 0.0, 1.0], true)));
    bus.publish(TF, 0, &tf("map", "right_optical", &camera([-0.005, 0.0, 1.0], false)));
    bus.publish(&left.camera_info, 0, &info("left_optical"));
    bus.publish(&right.camera_info, 0, &info("right_optical"));
    bus.publish(&left.depth, 1, &image("left_optical", 10, |_, _| 1.0));
    node.step(1, &mut bus).unwrap();
    assert_eq!(node.frames, 1);
    let front = |k: &Key| k[0] == 100;
    let back = |k: &Key| k[0] == -101;
    let occ = node.map().occupied();
    assert!(occ.iter().filter(|k| front(k)).count() > 1000);
    assert_eq!(occ.iter().filter(|k| back(k)).count(), 0);
    assert_eq!(scenes(&mut scene_reader, &mut bus).len(), 1);
    // Both cameras in one step (right's frame the newer, left's second frame older): both
    // integrated, one scene, stamped with the newest frame.
    bus.publish(&right.depth, 2, &image("right_optical", 30, |_, _| 1.0));
    bus.publish(&left.depth, 2, &image("left_optical", 20, |_, _| 1.0));
    node.step(2, &mut bus).unwrap();
    assert_eq!((node.frames, node.skipped), (3, 0));
    let occ = node.map().occupied();
    let (n_front, n_back) = (occ.iter().filter(|k| front(k)).count(), occ.iter().filter(|k| back(k)).count());
    assert!(n_front > 1000 && n_back > 1000, "{n_front} {n_back}");
    assert_eq!(n_front + n_back, occ.len(), "only the two walls");
    assert_eq!(node.map().state_at(&Point3::new(-0.5, 0.0, 1.0)), Occupancy::Free);
    let published = scenes(&mut scene_reader, &mut bus);
    assert_eq!(published.len(), 1);
    assert_eq!(published[0].header.stamp, Time::from_nanos(30));
    assert_eq!(scene_voxels(&published[0]), occ.into_iter().collect());
    // A step without frames publishes nothing.
    node.step(3, &mut bus).unwrap();
    assert!(scenes(&mut scene_reader, &mut bus).is_empty());
}

/// A box link "arm" (20 cm cube, its collision origin 10 cm ahead of the link frame) at
/// x = 0.7..0.9 in front of the camera; a second link "ghost" when `ghost`.
fn urdf(ghost: bool) -> String {
    let ghost = if ghost {
        r#"<link name="ghost"><collision><geometry><sphere radius="0.05"/></geometry></collision></link>
           <joint name="g" type="revolute"><parent link="base_link"/><child link="ghost"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>"#
    } else {
        ""
    };
    format!(
        r#"<robot name="r">
      <link name="base_link"/>
      <link name="arm"><collision><origin xyz="0.1 0 0" rpy="0 0 0"/><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
      <joint name="j" type="revolute"><parent link="base_link"/><child link="arm"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
      {ghost}
    </robot>"#
    )
}

/// The camera at (0.005, 0, 1) looking along +x sees the arm's near face (x = 0.7) where its
/// rays meet it and a wall at x = 1.505 elsewhere.
fn arm_scene_bus(description: Option<String>) -> (Bus, DepthMapper) {
    let mut bus = Bus::default();
    let node = DepthMapper::new(MapperConfig::default()).unwrap();
    let cam = MapperConfig::default().cameras[0].clone();
    if let Some(d) = description {
        bus.publish(ROBOT_DESCRIPTION, 0, &agrisim_msgs::std_msgs::String { data: d });
    }
    bus.publish(TF_STATIC, 0, &tf("map", "camera_optical", &camera([0.005, 0.0, 1.0], true)));
    // One /tf message as robot_state_publisher sends (a reader joining sees the newest).
    let mut links = tf("map", "base_link", &Isometry3::translation(0.3, 0.0, 1.0));
    links.transforms.extend(tf("base_link", "arm", &Isometry3::translation(0.4, 0.0, 0.0)).transforms);
    bus.publish(TF, 0, &links);
    bus.publish(&cam.camera_info, 0, &info("camera_optical"));
    let face = 0.695f32;
    bus.publish(
        &cam.depth,
        1,
        &image("camera_optical", 1, |u, v| {
            let (x, y) = ((u as f64 - 32.0) / F * face as f64, (v as f64 - 24.0) / F * face as f64);
            if x.abs() < 0.099 && y.abs() < 0.099 {
                face
            } else {
                1.5
            }
        }),
    );
    (bus, node)
}

#[test]
fn the_robot_links_from_the_description_are_filtered_out() {
    let near_arm = |k: &Key| {
        let c = [k[0], k[1], k[2]].map(|i| (i as f64 + 0.5) * RES);
        (0.68..0.92).contains(&c[0]) && c[1].abs() < 0.12 && (c[2] - 1.0).abs() < 0.12
    };
    let wall = |k: &Key| k[0] == 150;
    // Without a description the arm's face is an obstacle: the control.
    let (mut bus, mut plain) = arm_scene_bus(None);
    plain.step(1, &mut bus).unwrap();
    let occ = plain.map().occupied();
    // The face's 15 x 15 pixels, one voxel each.
    assert_eq!(occ.iter().filter(|k| near_arm(k)).count(), 225);
    assert!(plain.robot_links().is_empty());
    // With it, the arm placed by TF (map -> base_link -> arm) is the robot.
    let (mut bus, mut node) = arm_scene_bus(Some(urdf(false)));
    node.step(1, &mut bus).unwrap();
    assert_eq!((node.frames, node.skipped), (1, 0));
    assert_eq!(node.robot_links().len(), 1);
    let c = node.robot_links()[0].pose.translation.vector;
    assert!((c - V3::new(0.8, 0.0, 1.0)).norm() < 1e-12, "{c:?}");
    assert_eq!(node.last.self_filtered, 225, "{:?}", node.last);
    let occ = node.map().occupied();
    assert_eq!(occ.iter().filter(|k| near_arm(k)).count(), 0);
    let n_wall = occ.iter().filter(|k| wall(k)).count();
    assert!(n_wall > 1000, "{n_wall}");
    // The wall beside the arm is seen; behind it, not (the arm hides it).
    let beside = |k: &&Key| (k[1] as f64 * RES).abs() > 0.2;
    let behind = |k: &&Key| (k[1] as f64 * RES).abs() < 0.15 && ((k[2] as f64 + 0.5) * RES - 1.0).abs() < 0.15;
    assert!(occ.iter().filter(|k| wall(k)).filter(beside).count() > 300);
    assert_eq!(occ.iter().filter(|k| wall(k)).filter(behind).count(), 0);
    // The rays to the arm's face still clear the space before it.
    assert_eq!(node.map().state_at(&Point3::new(0.5, 0.0, 1.0)), Occupancy::Free);
    let scene = PlanningScene::from_cdr(&bus.latest(SCENE).unwrap().cdr).unwrap();
    assert_eq!(scene_voxels(&scene), occ.into_iter().collect());
    // The owner's extra primitives add to the description's.
    let extra = agrisim_mapping::Primitive::new(
        agrisim_mapping::Shape::Sphere { radius: 0.1 },
        Isometry3::translation(1.5, 0.4, 1.0),
    );
    node.set_robot_links(vec![extra]);
    let cam = MapperConfig::default().cameras[0].clone();
    bus.publish(&cam.depth, 2, &image("camera_optical", 2, |_, _| 1.5));
    node.step(2, &mut bus).unwrap();
    assert_eq!(node.robot_links().len(), 2);
}

/// A fruit at a hand (the face 2.5 cm before the hand's grasp point, here with no links
/// described) is the robot's: its pixels within the hand's sphere leave no voxels; the rest
/// of the face does, and without hands configured all of it.
#[test]
fn a_fruit_at_a_hand_is_filtered_out() {
    let near_hand = |k: &Key| {
        let c = [k[0], k[1], k[2]].map(|i| (i as f64 + 0.5) * RES);
        (c[0] - 0.72).powi(2) + c[1].powi(2) + (c[2] - 1.0).powi(2) < 0.05f64.powi(2)
    };
    let face = |k: &Key| (0.68..0.72).contains(&((k[0] as f64 + 0.5) * RES));
    let run = |hands: Vec<String>| {
        let (mut bus, _) = arm_scene_bus(None);
        let mut node = DepthMapper::new(MapperConfig { hands, ..MapperConfig::default() }).unwrap();
        bus.publish(TF, 0, &tf("map", "left_hand_tcp", &Isometry3::translation(0.72, 0.0, 1.0)));
        node.step(1, &mut bus).unwrap();
        node
    };
    let node = run(MapperConfig::default().hands);
    assert_eq!(node.robot_links().len(), 1);
    let occ = node.map().occupied();
    assert!(node.last.self_filtered > 50, "{:?}", node.last);
    assert_eq!(occ.iter().filter(|k| near_hand(k)).count(), 0);
    assert!(occ.iter().filter(|k| face(k)).count() > 100, "the face beyond the hand's sphere is seen");
    let plain = run(vec![]);
    assert_eq!((plain.robot_links().len(), plain.last.self_filtered), (0, 0));
    let n = plain.map().occupied().iter().filter(|k| near_hand(k)).count();
    assert!(n > 20, "{n}");
}

#[test]
fn the_allowed_fruit_comes_from_the_message() {
    let mut bus = Bus::default();
    let mut node = DepthMapper::new(MapperConfig::default()).unwrap();
    let cam = MapperConfig::default().cameras[0].clone();
    let mut scene_reader = Reader::subscribe(&mut bus, SCENE);
    bus.publish(TF_STATIC, 0, &tf("map", "camera_optical", &camera([0.005, 0.0, 1.0], true)));
    bus.publish(&cam.camera_info, 0, &info("camera_optical"));
    bus.publish(&cam.depth, 1, &image("camera_optical", 1, |_, _| 1.0));
    node.step(1, &mut bus).unwrap();
    let full = scene_voxels(&scenes(&mut scene_reader, &mut bus)[0]);
    assert!(full.len() > 1000);
    let detection = |frame: &str, c: [f64; 3], size: [f64; 3]| Detection3D {
        header: Header { frame_id: frame.into(), ..Default::default() },
        bbox: BoundingBox3D {
            center: Pose { position: Point { x: c[0], y: c[1], z: c[2] }, ..Default::default() },
            size: Vector3 { x: size[0], y: size[1], z: size[2] },
        },
        ..Default::default()
    };
    let touches = |k: &Key, c: [f64; 3], r: f64| {
        let d2: f64 = (0..3)
            .map(|i| {
                let (lo, hi) = (k[i] as f64 * RES, (k[i] + 1) as f64 * RES);
                (lo - c[i]).max(c[i] - hi).max(0.0).powi(2)
            })
            .sum();
        d2 <= r * r
    };
    // A fruit of 9.4 cm (the largest side) on the wall (off the voxel borders: no ties): the scene is republished without it,
    // though no new frame came, stamped with the last frame.
    let fruit = [1.005, 0.003, 1.002];
    let msg = Detection3DArray {
        header: Header { frame_id: "map".into(), ..Default::default() },
        detections: vec![detection("", fruit, [0.06, 0.094, 0.08])],
    };
    bus.publish(ALLOWED, 2, &msg);
    node.step(2, &mut bus).unwrap();
    let published = scenes(&mut scene_reader, &mut bus);
    assert_eq!(published.len(), 1);
    assert_eq!(published[0].header.stamp, Time::from_nanos(1));
    let without = scene_voxels(&published[0]);
    let removed: BTreeSet<Key> = full.difference(&without).copied().collect();
    assert!(without.is_subset(&full));
    // Exactly the wall voxels touching the sphere (pixels 2 cm apart at 1 m: about 20).
    let want: BTreeSet<Key> = full.iter().filter(|k| touches(k, fruit, 0.047)).copied().collect();
    assert!(want.len() > 15, "{}", want.len());
    assert_eq!(removed, want);
    // Given in the camera's frame (1 m ahead, 20 cm to its right = map -y): moved to the map.
    let msg = Detection3DArray {
        header: Header { frame_id: "map".into(), ..Default::default() },
        detections: vec![detection("camera_optical", [0.2, -0.002, 1.0], [0.094, 0.094, 0.094])],
    };
    bus.publish(ALLOWED, 3, &msg);
    node.step(3, &mut bus).unwrap();
    let moved = scene_voxels(&scenes(&mut scene_reader, &mut bus)[0]);
    let at = [1.005, -0.2, 1.002];
    let want: BTreeSet<Key> = full.iter().filter(|k| touches(k, at, 0.047)).copied().collect();
    assert!(want.len() > 15 && want != removed, "{}", want.len());
    assert_eq!(full.difference(&moved).copied().collect::<BTreeSet<Key>>(), want);
    // An empty array clears.
    bus.publish(ALLOWED, 4, &Detection3DArray::default());
    node.step(4, &mut bus).unwrap();
    assert_eq!(scene_voxels(&scenes(&mut scene_reader, &mut bus)[0]), full);
    assert!(node.map().allowed().is_empty());
}

#[test]
fn a_link_without_tf_is_reported_once_and_the_frame_still_counts() {
    let (mut bus, mut node) = arm_scene_bus(Some(urdf(true)));
    let mut status = Reader::subscribe(&mut bus, STATUS);
    node.step(1, &mut bus).unwrap();
    assert_eq!((node.frames, node.skipped), (1, 0));
    assert_eq!(node.missing_links().collect::<Vec<_>>(), ["ghost"]);
    // The arm is still filtered.
    assert_eq!(node.robot_links().len(), 1);
    let said = statuses(&mut status, &mut bus);
    assert_eq!(said.len(), 1, "{said:?}");
    assert!(said[0].contains("no TF from ghost to map"), "{}", said[0]);
    assert!(!said[0].contains("arm"), "{}", said[0]);
    let cam = MapperConfig::default().cameras[0].clone();
    for t in 2..4 {
        bus.publish(&cam.depth, t, &image("camera_optical", t, |_, _| 1.5));
        node.step(t, &mut bus).unwrap();
    }
    assert_eq!((node.frames, node.skipped), (3, 0));
    assert!(statuses(&mut status, &mut bus).is_empty());
    // Its TF appears: it joins the self-filter.
    bus.publish(TF, 4, &tf("base_link", "ghost", &Isometry3::translation(0.0, 0.5, 0.0)));
    bus.publish(&cam.depth, 4, &image("camera_optical", 4, |_, _| 1.5));
    node.step(4, &mut bus).unwrap();
    assert_eq!(node.robot_links().len(), 2);
}

#[test]
fn every_link_of_the_project_robot_is_placed_from_robot_state_publisher() {
    use agrisim_nodes::RobotStatePublisher;
    let mut bus = Bus::default();
    let mut node = DepthMapper::new(MapperConfig::default()).unwrap();
    let mut status = Reader::subscribe(&mut bus, STATUS);
    node.step(0, &mut bus).unwrap();
    // The base 2 m along the row, as odometry and localization would place it.
    bus.publish(TF, 0, &tf("map", "base_link", &Isometry3::translation(2.0, 0.5, 0.0)));
    RobotStatePublisher::agrisim().step(0, &mut bus).unwrap();
    let urdf = agrisim_msgs::std_msgs::String::from_cdr(&bus.latest(ROBOT_DESCRIPTION).unwrap().cdr).unwrap().data;
    let shapes = agrisim_mapping::RobotShapes::from_urdf(&urdf).unwrap();
    assert!(shapes.ignored.is_empty(), "{:?}", shapes.ignored);
    let n: usize = shapes.links.iter().map(|l| l.shapes.len()).sum();
    assert_eq!(n, urdf.matches("<collision").count());
    assert!(n > 20, "{n}");
    let cam = MapperConfig::default().cameras[0].clone();
    bus.publish(&cam.camera_info, 0, &info("camera_color_optical_frame"));
    bus.publish(&cam.depth, 0, &image("camera_color_optical_frame", 0, |_, _| 1.0));
    node.step(1, &mut bus).unwrap();
    assert_eq!((node.frames, node.skipped), (1, 0));
    assert_eq!(node.missing_links().count(), 0);
    // Every collision shape, and a sphere about each hand's grasp point.
    assert_eq!(node.robot_links().len(), n + 2);
    assert!(statuses(&mut status, &mut bus).is_empty());
    // Placed, not left at the origin: the base's collision box is about the base's pose.
    let near_base =
        node.robot_links().iter().filter(|p| (p.pose.translation.vector - V3::new(2.0, 0.5, 0.0)).norm() < 1.0);
    assert!(near_base.count() > 5);
}

/// Depth frames of a wall 1 m ahead stamped 0, 0.1 and 0.2 s, each published at its stamp;
/// the node stepped every 0.1 s (the bus's message instants) to 0.6 s. Returns (step,
/// stamp) of every scene published, and the node.
fn charged_run(cost: agrisim_mapping::CostModel) -> (Vec<(i64, i64)>, DepthMapper) {
    const STEP: i64 = 100_000_000;
    let mut bus = Bus::default();
    let mut node = DepthMapper::new(MapperConfig::default()).unwrap().with_cost(cost);
    let mut reader = Reader::subscribe(&mut bus, SCENE);
    bus.publish(TF_STATIC, 0, &tf("map", "optical", &camera([0.005, 0.0, 1.0], true)));
    bus.publish(agrisim_mapping::node::CAMERA_INFO, 0, &info("optical"));
    let mut out = vec![];
    for k in 0..=6 {
        let t = k * STEP;
        if k <= 2 {
            bus.publish(agrisim_mapping::node::DEPTH, t, &image("optical", t, |_, _| 1.0));
        }
        node.step(t, &mut bus).unwrap();
        out.extend(scenes(&mut reader, &mut bus).into_iter().map(|s| (t, s.header.stamp.to_nanos())));
    }
    (out, node)
}

#[test]
fn the_scene_waits_for_the_modelled_compute() {
    use agrisim_mapping::CostModel;
    const STEP: i64 = 100_000_000;
    // 0.25 s per frame: frame 0 is done at 0.25 s, its scene out at the step of 0.3 s; frame
    // 0.1 s is replaced while waiting by frame 0.2 s, taken up at 0.25 s, done at 0.5 s.
    let cost = CostModel { per_pixel: 0.25 / (W * H) as f64, ..CostModel::FREE };
    let (out, node) = charged_run(cost);
    assert_eq!(out, [(3 * STEP, 0), (5 * STEP, 2 * STEP)]);
    assert_eq!((node.frames, node.dropped), (2, 1));
    assert!((node.charged().seconds() - 0.5).abs() < 1e-9, "{}", node.charged().seconds());
    // Charged by the rays' walks alone: the same timing when they cost the same.
    let steps = node.work.ray_steps as f64 / 2.0;
    let (by_steps, _) = charged_run(CostModel { per_ray_step: 0.25 / steps, ..CostModel::FREE });
    assert_eq!(by_steps, out);
    // Free compute: every frame in the scene of its step, none dropped, nothing charged.
    let (out, free) = charged_run(CostModel::FREE);
    assert_eq!(out, [(0, 0), (STEP, STEP), (2 * STEP, 2 * STEP)]);
    assert_eq!((free.frames, free.dropped, free.charged().seconds()), (3, 0, 0.0));
    // The work is counted deterministically: three identical frames, three times the work of
    // one (the first frame's walks clear the same voxels the others do).
    let (_, one) = {
        let mut bus = Bus::default();
        let mut n = DepthMapper::new(MapperConfig::default()).unwrap();
        bus.publish(TF_STATIC, 0, &tf("map", "optical", &camera([0.005, 0.0, 1.0], true)));
        bus.publish(agrisim_mapping::node::CAMERA_INFO, 0, &info("optical"));
        bus.publish(agrisim_mapping::node::DEPTH, 0, &image("optical", 0, |_, _| 1.0));
        n.step(0, &mut bus).unwrap();
        ((), n)
    };
    let w = one.work;
    assert!(w.ray_steps > (W * H) as u64 && w.points == (W * H) as u64, "{w:?}");
    assert_eq!(
        (free.work.pixels, free.work.points, free.work.ray_steps, free.work.dense_cells),
        (3 * w.pixels, 3 * w.points, 3 * w.ray_steps, 3 * w.dense_cells)
    );
}
