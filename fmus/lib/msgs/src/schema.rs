//! .msg texts and the MCAP `ros2msg` schema format.
//!
//! The texts live in `models/msgs/<pkg>/msg/<Type>.msg` (the single source; compiled in with
//! `include_str!`). A `ros2msg` schema is the type's own text followed, for each transitive
//! dependency, by a line of 80 `=`, a line `MSG: pkg/Type`, and that type's text.
//!
//! Choices made to match rosbag2's MCAP writer (rosbag2_cpp `MessageDefinitionCache`):
//! * the `MSG:` line uses the short `pkg/Type` form (the form the field types are written
//!   in), not `pkg/msg/Type`; mcap-ros2-support and Foxglove accept both;
//! * dependencies are visited depth-first, each message's direct dependencies in sorted
//!   order, every type emitted once (first visit wins). This makes our schemas the same
//!   sequence of definitions rosbag2 would record, and deterministic.

use std::collections::BTreeSet;

/// Separator line before each dependency in a `ros2msg` schema.
pub const SEPARATOR: &str = "================================================================================";

macro_rules! msg_table {
    ($( $pkg:literal / $ty:literal ),* $(,)?) => {
        /// (full type name, .msg text), in a fixed order.
        const MSG_TEXTS: &[(&str, &str)] = &[
            $( (
                concat!($pkg, "/msg/", $ty),
                include_str!(concat!("../../../../models/msgs/", $pkg, "/msg/", $ty, ".msg")),
            ), )*
        ];
        const TYPE_NAMES: &[&str] = &[ $( concat!($pkg, "/msg/", $ty), )* ];
    };
}

msg_table! {
    "builtin_interfaces" / "Time",
    "std_msgs" / "Header",
    "std_msgs" / "Float64",
    "geometry_msgs" / "Vector3",
    "geometry_msgs" / "Point",
    "geometry_msgs" / "Quaternion",
    "geometry_msgs" / "Pose",
    "geometry_msgs" / "PoseStamped",
    "geometry_msgs" / "PoseWithCovariance",
    "geometry_msgs" / "Twist",
    "geometry_msgs" / "TwistStamped",
    "geometry_msgs" / "TwistWithCovariance",
    "geometry_msgs" / "Transform",
    "geometry_msgs" / "TransformStamped",
    "nav_msgs" / "Odometry",
    "nav_msgs" / "Path",
    "tf2_msgs" / "TFMessage",
    "rosgraph_msgs" / "Clock",
    "sensor_msgs" / "JointState",
    "sensor_msgs" / "PointField",
    "sensor_msgs" / "PointCloud2",
    "sensor_msgs" / "Imu",
    "geometry_msgs" / "PoseArray",
    "nav_msgs" / "MapMetaData",
    "nav_msgs" / "OccupancyGrid",
    "agrisim_msgs" / "Contact",
    "agrisim_msgs" / "CollisionState",
    "agrisim_msgs" / "NavigationStatus",
    "agrisim_msgs" / "Signals",
    "agrisim_msgs" / "FmuStatus",
    "sensor_msgs" / "Image",
    "sensor_msgs" / "RegionOfInterest",
    "sensor_msgs" / "CameraInfo",
    "builtin_interfaces" / "Duration",
    "trajectory_msgs" / "JointTrajectoryPoint",
    "trajectory_msgs" / "JointTrajectory",
    "control_msgs" / "GripperCommand",
    "geometry_msgs" / "Point32",
    "geometry_msgs" / "Polygon",
    "shape_msgs" / "SolidPrimitive",
    "agrisim_msgs" / "GripperState",
    "agrisim_msgs" / "TrajectoryStatus",
    "agrisim_msgs" / "CollisionObject",
    "agrisim_msgs" / "PlanningScene",
    "agrisim_msgs" / "HarvestStatus",
    "agrisim_msgs" / "PlanResult",
    "agrisim_msgs" / "PlantDamage",
    "agrisim_msgs" / "MovedObjects",
    "vision_msgs" / "ObjectHypothesis",
    "vision_msgs" / "ObjectHypothesisWithPose",
    "vision_msgs" / "BoundingBox3D",
    "vision_msgs" / "Detection3D",
    "vision_msgs" / "Detection3DArray",
    "std_msgs" / "String",
    "std_msgs" / "ColorRGBA",
    "sensor_msgs" / "CompressedImage",
    "visualization_msgs" / "UVCoordinate",
    "visualization_msgs" / "MeshFile",
    "visualization_msgs" / "Marker",
    "visualization_msgs" / "MarkerArray",
}

/// Every type this crate knows, as `pkg/msg/Type`.
pub fn all_type_names() -> &'static [&'static str] {
    TYPE_NAMES
}

/// Normalizes `pkg/Type` or `pkg/msg/Type` to `(pkg, Type)`.
fn split_type_name(name: &str) -> Option<(&str, &str)> {
    let mut parts = name.split('/');
    let (pkg, ty) = match (parts.next(), parts.next(), parts.next(), parts.next()) {
        (Some(p), Some(t), None, None) => (p, t),
        (Some(p), Some("msg"), Some(t), None) => (p, t),
        _ => return None,
    };
    (!pkg.is_empty() && !ty.is_empty()).then_some((pkg, ty))
}

/// The .msg text of a type (`pkg/msg/Type` or `pkg/Type`), exactly as in models/msgs.
pub fn msg_text(type_name: &str) -> Option<&'static str> {
    let (pkg, ty) = split_type_name(type_name)?;
    MSG_TEXTS.iter().find_map(|(full, text)| (split_type_name(full) == Some((pkg, ty))).then_some(*text))
}

const PRIMITIVES: &[&str] = &[
    "bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64",
    "uint64", "string", "wstring",
];

/// Direct message-type dependencies of a .msg text, as `pkg/Type`, sorted and unique.
///
/// Per field line: drop the comment, take the first token, strip an array suffix
/// (`[]`, `[36]`, `[<=5]`) and a string bound (`string<=10`); skip primitives. An
/// unqualified name means the same package, except `Header`, which rosidl resolves to
/// `std_msgs/Header`. Constants (`int32 X=1`) are always primitive, so they fall out.
pub fn msg_dependencies(package: &str, text: &str) -> BTreeSet<String> {
    let mut deps = BTreeSet::new();
    for line in text.lines() {
        let line = line.split('#').next().unwrap_or("").trim();
        let Some(ty) = line.split_whitespace().next() else {
            continue;
        };
        let ty = ty.split('[').next().unwrap_or(ty);
        let ty = ty.split("<=").next().unwrap_or(ty);
        if ty.is_empty() || PRIMITIVES.contains(&ty) {
            continue;
        }
        let dep = match split_type_name(ty) {
            Some((pkg, name)) => format!("{pkg}/{name}"),
            None if ty == "Header" => "std_msgs/Header".to_owned(),
            None => format!("{package}/{ty}"),
        };
        deps.insert(dep);
    }
    deps
}

/// The complete `ros2msg` schema for an MCAP Schema record of `type_name`
/// (`pkg/msg/Type` or `pkg/Type`). `None` if the type or one of its dependencies is unknown.
pub fn ros2msg_schema(type_name: &str) -> Option<String> {
    let (pkg, ty) = split_type_name(type_name)?;
    let root = format!("{pkg}/{ty}");
    let mut out = String::new();
    push_text(&mut out, msg_text(&root)?);
    let mut seen = BTreeSet::from([root.clone()]);
    append_deps(&root, &mut seen, &mut out)?;
    Some(out)
}

fn push_text(out: &mut String, text: &str) {
    out.push_str(text);
    if !text.ends_with('\n') {
        out.push('\n');
    }
}

fn append_deps(name: &str, seen: &mut BTreeSet<String>, out: &mut String) -> Option<()> {
    let (pkg, _) = split_type_name(name)?;
    for dep in msg_dependencies(pkg, msg_text(name)?) {
        if seen.insert(dep.clone()) {
            let text = msg_text(&dep)?;
            out.push_str(SEPARATOR);
            out.push_str("\nMSG: ");
            out.push_str(&dep);
            out.push('\n');
            push_text(out, text);
            append_deps(&dep, seen, out)?;
        }
    }
    Some(())
}
