//! Sample messages shared by the crate's tests and the `write_samples` example (which the
//! Python cross-check decodes). The values are mirrored in tests/test_msgs_crosscheck.py
//! (EXPECTED): change both together. Values are chosen to be exact in decimal (or the same
//! single IEEE operation on both sides) and to exercise alignment after strings.
#![allow(dead_code)]

use agrisim_msgs::agrisim::{
    CollisionObject, CollisionState, Contact, FmuStatus, GripperState, HarvestStatus, MovedObjects, NavigationStatus,
    PlanResult, PlanningScene, PlantDamage, Signals, TrajectoryStatus,
};
use agrisim_msgs::builtin_interfaces::{Duration, Time};
use agrisim_msgs::control_msgs::GripperCommand;
use agrisim_msgs::geometry_msgs::*;
use agrisim_msgs::nav_msgs::{MapMetaData, OccupancyGrid, Odometry, Path};
use agrisim_msgs::rosgraph_msgs::Clock;
use agrisim_msgs::sensor_msgs::{
    CameraInfo, CompressedImage, Image, Imu, JointState, PointCloud2, PointField, RegionOfInterest,
};
use agrisim_msgs::shape_msgs::SolidPrimitive;
use agrisim_msgs::std_msgs::{ColorRGBA, Float64, Header};
use agrisim_msgs::tf2_msgs::TFMessage;
use agrisim_msgs::trajectory_msgs::{JointTrajectory, JointTrajectoryPoint};
use agrisim_msgs::vision_msgs::{
    BoundingBox3D, Detection3D, Detection3DArray, ObjectHypothesis, ObjectHypothesisWithPose,
};
use agrisim_msgs::visualization_msgs::{Marker, MarkerArray, MeshFile, UVCoordinate};
use agrisim_msgs::{CdrError, Message};
use std::fmt::Debug;

pub type Checker = Box<dyn Fn(&[u8]) -> Result<(), String>>;

pub struct Sample {
    pub name: &'static str,
    pub type_name: &'static str,
    pub bytes: Vec<u8>,
    /// Decodes bytes as this sample's type and compares with the sample value.
    pub check: Checker,
    /// Decodes bytes as this sample's type; on success re-encodes and decodes again
    /// (must succeed). For fuzzing: exercises the decoder without comparing values.
    pub decode: fn(&[u8]) -> Result<(), CdrError>,
}

fn decode_reencode<M: Message>(b: &[u8]) -> Result<(), CdrError> {
    let m = M::from_cdr(b)?;
    let again = m.to_cdr();
    M::from_cdr(&again).expect("re-encoded message must decode");
    Ok(())
}

pub fn sample<M: Message + PartialEq + Debug + 'static>(name: &'static str, msg: M) -> Sample {
    let bytes = msg.to_cdr();
    Sample {
        name,
        type_name: M::TYPE_NAME,
        bytes,
        check: Box::new(move |b| {
            let got = M::from_cdr(b).map_err(|e| e.to_string())?;
            if got == msg {
                Ok(())
            } else {
                Err(format!("decoded {got:?}\nexpected {msg:?}"))
            }
        }),
        decode: decode_reencode::<M>,
    }
}

fn hdr(sec: i32, nanosec: u32, frame: &str) -> Header {
    Header::new(Time::new(sec, nanosec), frame)
}

fn v3(x: f64, y: f64, z: f64) -> Vector3 {
    Vector3 { x, y, z }
}

fn q(x: f64, y: f64, z: f64, w: f64) -> Quaternion {
    Quaternion { x, y, z, w }
}

fn pose(x: f64, y: f64, z: f64, o: Quaternion) -> Pose {
    Pose { position: Point { x, y, z }, orientation: o }
}

fn twist() -> Twist {
    Twist { linear: v3(0.5, 0.0, 0.0), angular: v3(0.0, 0.0, -0.25) }
}

fn pose_cov() -> PoseWithCovariance {
    let mut covariance = [0.0; 36];
    for (i, c) in covariance.iter_mut().enumerate() {
        *c = i as f64 * 0.5;
    }
    PoseWithCovariance { pose: pose(1.0, 2.0, 3.0, q(0.5, 0.5, 0.5, 0.5)), covariance }
}

fn twist_cov() -> TwistWithCovariance {
    let mut covariance = [0.0; 36];
    for i in 0..6 {
        covariance[i * 7] = (i + 1) as f64 * 0.01;
    }
    TwistWithCovariance { twist: twist(), covariance }
}

fn tf(sec: i32, parent: &str, child: &str, x: f64) -> TransformStamped {
    TransformStamped {
        header: hdr(sec, 2, parent),
        child_frame_id: child.into(),
        transform: Transform { translation: v3(x, 0.0, 0.45), rotation: Quaternion::IDENTITY },
    }
}

fn field(name: &str, offset: u32, datatype: u8) -> PointField {
    PointField { name: name.into(), offset, datatype, count: 1 }
}

/// Two points of (x, y, z, intensity) float32, little-endian: 32 bytes.
fn cloud() -> PointCloud2 {
    let values: [f32; 8] = [1.0, 2.0, 3.0, 0.5, -1.0, 0.25, 0.0, 100.0];
    PointCloud2 {
        header: hdr(4, 100_000_000, "lidar_link"),
        height: 1,
        width: 2,
        fields: vec![
            field("x", 0, PointField::FLOAT32),
            field("y", 4, PointField::FLOAT32),
            field("z", 8, PointField::FLOAT32),
            field("intensity", 12, PointField::FLOAT32),
        ],
        is_bigendian: false,
        point_step: 16,
        row_step: 32,
        data: values.iter().flat_map(|v| v.to_le_bytes()).collect(),
        is_dense: true,
    }
}

fn map_meta() -> MapMetaData {
    MapMetaData {
        map_load_time: Time::new(0, 5),
        resolution: 0.25,
        width: 3,
        height: 2,
        origin: pose(-1.5, -0.5, 0.0, Quaternion::IDENTITY),
    }
}

fn contact(id: u32, name: &str, link: &str) -> Contact {
    Contact {
        object_id: id,
        object_name: name.into(),
        object_kind: "post".into(),
        robot_link: link.into(),
        position: Point { x: 2.5, y: -1.0, z: 0.25 },
        normal: v3(-1.0, 0.0, 0.0),
        depth: 0.125,
    }
}

fn traj_point(positions: Vec<f64>, velocities: Vec<f64>, sec: i32, nanosec: u32) -> JointTrajectoryPoint {
    JointTrajectoryPoint {
        positions,
        velocities,
        accelerations: vec![],
        effort: vec![],
        time_from_start: Duration::new(sec, nanosec),
    }
}

fn p32(x: f32, y: f32, z: f32) -> Point32 {
    Point32 { x, y, z }
}

fn stem_object() -> CollisionObject {
    CollisionObject {
        id: "stem_3".into(),
        kind: "stem".into(),
        primitive: SolidPrimitive::cylinder(1.5, 0.0125),
        pose: pose(2.0, -0.75, 0.75, Quaternion::IDENTITY),
    }
}

fn prism() -> SolidPrimitive {
    SolidPrimitive {
        r#type: SolidPrimitive::PRISM,
        dimensions: vec![0.5],
        polygon: Polygon { points: vec![p32(0.0, 0.0, 0.0), p32(1.0, 0.0, 0.0), p32(0.0, 1.0, 0.0)] },
    }
}

/// Samples of the arm/manipulation types (issue 4).
fn manipulation_samples() -> Vec<Sample> {
    vec![
        sample("duration", Duration::new(3, 250_000_000)),
        sample("duration_negative", Duration::new(-2, 300_000_000)),
        sample(
            "joint_trajectory_point",
            JointTrajectoryPoint {
                positions: vec![0.5, -1.25, 0.0],
                velocities: vec![0.125, 0.0, -0.5],
                accelerations: vec![1.0, 2.0, 3.0],
                effort: vec![],
                time_from_start: Duration::new(1, 500_000_000),
            },
        ),
        sample(
            "joint_trajectory",
            JointTrajectory {
                header: hdr(5, 0, "base_link"),
                joint_names: vec!["left_joint1".into(), "left_joint2".into()],
                points: vec![
                    traj_point(vec![0.0, 0.25], vec![], 0, 0),
                    traj_point(vec![0.5, -0.25], vec![0.0, 0.0], 2, 5),
                ],
            },
        ),
        sample("joint_trajectory_empty", JointTrajectory::default()),
        sample("gripper_command", GripperCommand { position: 0.04, max_effort: 70.0 }),
        sample("point32", p32(1.5, -0.25, 0.125)),
        sample("polygon", Polygon { points: vec![p32(0.0, 0.0, 0.0), p32(1.0, 0.0, 0.5), p32(0.0, -1.0, 0.25)] }),
        sample("solid_primitive_box", SolidPrimitive::new_box(0.1, 0.2, 0.3)),
        sample("solid_primitive_prism", prism()),
        sample(
            "gripper_state",
            GripperState {
                header: hdr(4, 20_000_000, "left_hand"),
                position: 0.035,
                effort: 70.0,
                stalled: true,
                reached_goal: false,
            },
        ),
        sample(
            "trajectory_status",
            TrajectoryStatus {
                header: hdr(6, 0, "left"),
                state: TrajectoryStatus::REJECTED,
                trajectory_count: 3,
                rejected_count: 1,
                reason: "point 2: time_from_start not strictly increasing".into(),
                rms_tracking_error: 0.0025,
                max_tracking_error: 0.0078125,
            },
        ),
        sample("collision_object", stem_object()),
        sample(
            "planning_scene",
            PlanningScene {
                header: hdr(7, 500_000_000, "base_link"),
                objects: vec![
                    stem_object(),
                    CollisionObject {
                        id: "floor".into(),
                        kind: "floor".into(),
                        primitive: SolidPrimitive::new_box(10.0, 10.0, 0.01),
                        pose: pose(0.0, 0.0, -0.005, Quaternion::IDENTITY),
                    },
                    CollisionObject {
                        id: "fruit_12".into(),
                        kind: "fruit".into(),
                        primitive: SolidPrimitive::sphere(0.035),
                        pose: pose(0.75, 0.5, 1.25, Quaternion::IDENTITY),
                    },
                ],
            },
        ),
        sample("planning_scene_empty", PlanningScene::default()),
        sample(
            "harvest_status",
            HarvestStatus {
                header: hdr(30, 0, "map"),
                stage: "handover".into(),
                target_id: 12,
                target_name: "fruit_12".into(),
                outcome: "failure".into(),
                failure_category: "handover".into(),
                detail: "right gripper stalled at 0 m".into(),
                plans: 7,
            },
        ),
        sample(
            "plan_result",
            PlanResult {
                header: hdr(12, 500_000_000, "map"),
                stage: "pre_grasp".into(),
                arm: "left".into(),
                kind: "pregrasp".into(),
                ok: false,
                optional: false,
                detail: "no IK solution for any of 6 grasps".into(),
                planning_time: 0.0123,
            },
        ),
        sample(
            "plant_damage",
            PlantDamage {
                header: hdr(41, 250_000_000, "map"),
                bruised_by_grip: 1,
                bruised_by_impact: 2,
                unripe_detached: 1,
                stems_broken: 0,
                detached_by_pull: 3,
                detached_by_bend: 4,
                detached_by_twist: 0,
                last_detach_mode: "bend".into(),
                last_detach_force: 6.5,
                last_detach_moment: 0.375,
                leaf_pushes: 5,
                peak_leaf_force: 1.25,
                peak_stem_load: 0.5,
            },
        ),
        sample(
            "moved_objects",
            MovedObjects {
                header: hdr(41, 500_000_000, "map"),
                ids: vec![7, 1024, 70000],
                poses: vec![
                    pose(1.5, -2.0, 0.75, q(0.0, 0.0, 0.0, 1.0)),
                    pose(0.25, 0.5, 1.125, q(0.5, 0.5, 0.5, 0.5)),
                    pose(-3.0, 4.0, 0.0625, q(0.0, 0.0, 1.0, 0.0)),
                ],
            },
        ),
    ]
}

pub fn all_samples() -> Vec<Sample> {
    let mut all = base_samples();
    all.extend(manipulation_samples());
    all.extend(vision_samples());
    all.extend(visualization_samples());
    all
}

fn hypothesis(class_id: &str, score: f64, x: f64, y: f64, z: f64) -> ObjectHypothesisWithPose {
    let mut cov = [0.0; 36];
    for i in 0..3 {
        cov[i * 7] = 2.5e-5 * (i + 1) as f64;
    }
    ObjectHypothesisWithPose {
        hypothesis: ObjectHypothesis { class_id: class_id.into(), score },
        pose: PoseWithCovariance { pose: pose(x, y, z, Quaternion::IDENTITY), covariance: cov },
    }
}

fn tomato(id: &str, class_id: &str, score: f64) -> Detection3D {
    Detection3D {
        header: hdr(9, 100_000_000, "camera_color_optical_frame"),
        results: vec![hypothesis(class_id, score, 0.125, -0.25, 0.75)],
        bbox: BoundingBox3D {
            center: pose(0.125, -0.25, 0.75, Quaternion::IDENTITY),
            size: Vector3 { x: 0.0625, y: 0.0625, z: 0.0625 },
        },
        id: id.into(),
    }
}

/// Samples of the perception types (vision_msgs).
fn vision_samples() -> Vec<Sample> {
    vec![
        sample("object_hypothesis", ObjectHypothesis { class_id: "ripe".into(), score: 0.875 }),
        sample("object_hypothesis_with_pose", hypothesis("stage_6", 0.5, 1.0, 2.0, 0.5)),
        sample(
            "bounding_box3d",
            BoundingBox3D {
                center: pose(1.0, 2.0, 3.0, Quaternion::IDENTITY),
                size: Vector3 { x: 0.5, y: 0.25, z: 0.125 },
            },
        ),
        sample("detection3d", tomato("17", "stage_5", 0.75)),
        sample(
            "detection3d_array",
            Detection3DArray {
                header: hdr(9, 100_000_000, "camera_color_optical_frame"),
                detections: vec![tomato("17", "stage_5", 0.75), tomato("", "stage_1", 0.25)],
            },
        ),
        sample("detection3d_array_empty", Detection3DArray::default()),
    ]
}

fn base_samples() -> Vec<Sample> {
    let h = std::f64::consts::FRAC_1_SQRT_2; // 0.7071067811865476
    vec![
        sample("time", Time::new(1_700_000_000, 123_456_789)),
        sample("time_negative", Time::new(-2, 300_000_000)),
        sample("header", hdr(12, 500_000_000, "odom")),
        sample("header_empty_frame", hdr(0, 1, "")),
        sample("float64", Float64 { data: -0.125 }),
        sample("vector3", v3(1.5, -2.25, 1e-300)),
        sample("point", Point { x: 0.1, y: 0.2, z: 0.3 }),
        sample("quaternion", q(0.0, 0.0, h, h)),
        sample("pose", pose(1.0, 2.0, 3.0, q(0.5, 0.5, 0.5, 0.5))),
        sample(
            "pose_stamped",
            PoseStamped { header: hdr(3, 0, "map"), pose: pose(-1.0, 0.5, 0.0, Quaternion::IDENTITY) },
        ),
        sample("pose_with_covariance", pose_cov()),
        sample("twist", twist()),
        sample("twist_stamped", TwistStamped { header: hdr(7, 20_000_000, "base_link"), twist: twist() }),
        sample("twist_with_covariance", twist_cov()),
        sample("transform", Transform { translation: v3(0.2, 0.0, 0.45), rotation: Quaternion::IDENTITY }),
        sample("transform_stamped", tf(1, "base_link", "camera_optical_frame", 0.2)),
        sample(
            "odometry",
            Odometry {
                header: hdr(10, 0, "odom"),
                child_frame_id: "base_link".into(),
                pose: pose_cov(),
                twist: twist_cov(),
            },
        ),
        sample(
            "path",
            Path {
                header: hdr(5, 0, "map"),
                poses: vec![
                    PoseStamped { header: hdr(5, 0, "map"), pose: pose(0.0, 0.0, 0.0, Quaternion::IDENTITY) },
                    PoseStamped { header: hdr(5, 1, "m"), pose: pose(1.0, 0.0, 0.0, q(0.0, 0.0, h, h)) },
                    PoseStamped { header: hdr(6, 2, ""), pose: pose(1.0, 1.0, 0.0, q(0.0, 0.0, 1.0, 0.0)) },
                ],
            },
        ),
        sample("path_empty", Path { header: hdr(0, 0, "map"), poses: vec![] }),
        sample(
            "tf_message",
            TFMessage { transforms: vec![tf(1, "odom", "base_link", 1.25), tf(1, "base_link", "lift_link", -0.125)] },
        ),
        sample("tf_message_empty", TFMessage::default()),
        sample("clock", Clock { clock: Time::new(42, 999_999_999) }),
        sample(
            "joint_state",
            JointState {
                header: hdr(2, 40_000_000, ""),
                name: vec!["lift_joint".into(), "wheel_fl".into(), "gr\u{fc}n".into()],
                position: vec![0.1, 0.2, 0.3],
                velocity: vec![],
                effort: vec![1.0],
            },
        ),
        sample(
            "signals",
            Signals {
                header: hdr(0, 20_000_000, "chassis"),
                names: vec!["v_x".into(), "omega".into(), "collided".into()],
                values: vec![0.5, -0.1, 1.0],
            },
        ),
        sample(
            "fmu_status",
            FmuStatus {
                header: hdr(1, 240_000_000, "lift"),
                instance: "lift".into(),
                status: "Error".into(),
                message: "fmi3DoStep returned fmi3Error at t=1.24 s: wheel slip > 1".into(),
            },
        ),
        sample("point_field", field("intensity", 12, PointField::FLOAT32)),
        sample("point_cloud2", cloud()),
        sample("point_cloud2_empty", PointCloud2 { header: hdr(0, 0, "l"), ..Default::default() }),
        sample(
            "imu",
            Imu {
                header: hdr(9, 5_000_000, "imu_link"),
                orientation: q(0.0, 0.0, h, h),
                orientation_covariance: [-1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
                angular_velocity: v3(0.001, -0.002, 0.5),
                angular_velocity_covariance: [1e-6, 0.0, 0.0, 0.0, 1e-6, 0.0, 0.0, 0.0, 1e-6],
                linear_acceleration: v3(0.125, 0.0, 9.80665),
                linear_acceleration_covariance: [4e-4, 0.0, 0.0, 0.0, 4e-4, 0.0, 0.0, 0.0, 4e-4],
            },
        ),
        sample(
            "pose_array",
            PoseArray {
                header: hdr(8, 0, "map"),
                poses: vec![pose(1.0, 2.0, 0.75, Quaternion::IDENTITY), pose(-0.5, 0.0, 1.25, q(0.0, 0.0, h, h))],
            },
        ),
        sample("map_meta_data", map_meta()),
        sample(
            "occupancy_grid",
            OccupancyGrid { header: hdr(0, 0, "map"), info: map_meta(), data: vec![0, 100, -1, 0, 50, 100] },
        ),
        sample("contact", contact(7, "row3/post2", "base_link")),
        sample(
            "collision_state",
            CollisionState {
                header: hdr(11, 20_000_000, "map"),
                in_collision: true,
                count: 2,
                contacts: vec![contact(7, "row3/post2", "base_link"), contact(42, "", "arm_l_link4")],
            },
        ),
        sample(
            "collision_state_empty",
            CollisionState { header: hdr(0, 0, "map"), in_collision: false, count: 0, contacts: vec![] },
        ),
        sample(
            "navigation_status",
            NavigationStatus {
                header: hdr(13, 0, "map"),
                state: "failed".into(),
                detail: "no_path".into(),
                goal: PoseStamped {
                    header: hdr(12, 900_000_000, "map"),
                    pose: pose(4.0, 2.0, 0.0, q(0.0, 0.0, 1.0, 0.0)),
                },
            },
        ),
        sample(
            "image",
            Image {
                header: hdr(3, 100_000_000, "camera_color_optical_frame"),
                height: 2,
                width: 2,
                encoding: "rgb8".into(),
                is_bigendian: 0,
                step: 6,
                data: vec![255, 0, 0, 0, 255, 0, 0, 0, 255, 10, 20, 30],
            },
        ),
        sample(
            "region_of_interest",
            RegionOfInterest { x_offset: 3, y_offset: 5, height: 7, width: 11, do_rectify: true },
        ),
        sample(
            "camera_info",
            CameraInfo {
                header: hdr(3, 100_000_000, "camera_color_optical_frame"),
                height: 480,
                width: 640,
                distortion_model: "plumb_bob".into(),
                d: vec![0.0; 5],
                k: [400.5, 0.0, 319.5, 0.0, 400.5, 239.5, 0.0, 0.0, 1.0],
                r: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
                p: [400.5, 0.0, 319.5, 0.0, 0.0, 400.5, 239.5, 0.0, 0.0, 0.0, 1.0, 0.0],
                binning_x: 0,
                binning_y: 0,
                roi: RegionOfInterest::default(),
            },
        ),
    ]
}

/// Samples of the viewer types (std_msgs String and ColorRGBA, visualization_msgs).
fn visualization_samples() -> Vec<Sample> {
    let red = ColorRGBA::new(0.75, 0.125, 0.0, 1.0);
    let list = Marker {
        header: hdr(3, 0, "map"),
        ns: "fruit".into(),
        id: 7,
        r#type: Marker::SPHERE_LIST,
        action: Marker::ADD,
        pose: pose(0.0, 0.0, 0.0, Quaternion::IDENTITY),
        scale: Vector3 { x: 0.0625, y: 0.0625, z: 0.0625 },
        color: ColorRGBA::new(1.0, 1.0, 1.0, 1.0),
        frame_locked: true,
        points: vec![Point { x: 1.5, y: -2.0, z: 0.75 }, Point { x: 1.5, y: -2.25, z: 1.0 }],
        colors: vec![red, ColorRGBA::new(0.25, 0.5, 0.0, 0.5)],
        ..Default::default()
    };
    let everything = Marker {
        header: hdr(4, 250_000_000, "base_link"),
        ns: "robot".into(),
        id: -1,
        r#type: Marker::TRIANGLE_LIST,
        action: Marker::MODIFY,
        pose: pose(1.0, 2.0, 3.0, q(0.5, 0.5, 0.5, 0.5)),
        scale: Vector3 { x: 1.0, y: 1.0, z: 1.0 },
        color: red,
        lifetime: Duration::new(2, 500_000_000),
        frame_locked: false,
        points: vec![
            Point { x: 0.0, y: 0.0, z: 0.0 },
            Point { x: 1.0, y: 0.0, z: 0.0 },
            Point { x: 0.0, y: 1.0, z: 0.0 },
        ],
        colors: vec![],
        texture_resource: "embedded://leaf.png".into(),
        texture: CompressedImage { header: hdr(4, 0, "camera"), format: "png".into(), data: vec![137, 80, 78, 71] },
        uv_coordinates: vec![
            UVCoordinate { u: 0.0, v: 0.0 },
            UVCoordinate { u: 1.0, v: 0.0 },
            UVCoordinate { u: 0.0, v: 1.0 },
        ],
        text: "tomato".into(),
        mesh_resource: "package://agrisim/leaf.stl".into(),
        mesh_file: MeshFile { filename: "leaf.stl".into(), data: vec![1, 2, 3] },
        mesh_use_embedded_materials: true,
    };
    vec![
        sample("string", agrisim_msgs::std_msgs::String { data: "<robot name=\"r\"/>".into() }),
        sample("color_rgba", red),
        sample(
            "compressed_image",
            CompressedImage { header: hdr(5, 0, "camera"), format: "jpeg".into(), data: vec![255, 216, 255] },
        ),
        sample("uv_coordinate", UVCoordinate { u: 0.25, v: 0.75 }),
        sample("mesh_file", MeshFile { filename: "a.dae".into(), data: vec![9, 8] }),
        sample("marker_sphere_list", list.clone()),
        sample("marker_everything", everything.clone()),
        sample("marker_array", MarkerArray { markers: vec![list, everything] }),
        sample("marker_array_empty", MarkerArray::default()),
    ]
}
