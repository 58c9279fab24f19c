"""Cross-check agrisim-msgs (Rust) against ROS 2 CDR/msg code that no one here wrote.

The Rust example `write_samples` writes sample messages (fmus/lib/msgs/tests/common/samples.rs)
as CDR files plus their `ros2msg` schema texts. Here they are decoded by

* mcap-ros2-support's dynamic decoder built from our schema text (what Foxglove-style
  readers do with an MCAP Schema record), also through a real MCAP file;
* rosbags, with types registered from our .msg files and, separately, from our
  concatenated schema text; rosbags must also re-serialize them to the same bytes;

and compared with EXPECTED below (which mirrors samples.rs: change both together).
In the other direction, mcap-ros2-support serializes EXPECTED and the Rust example decodes
those bytes (`write_samples --check`). The .msg texts of standard types are also compared
field by field with the definitions rosbags ships for ROS 2 Humble and Jazzy.

Binary: $AGRISIM_MSGS_WRITE_SAMPLES if set, else `cargo run -p agrisim-msgs --example
write_samples` from the repository root.
Requires: pip install mcap-ros2-support==0.6.0 rosbags==0.11.9 pytest
"""

from __future__ import annotations

import io
import math
import os
import shutil
import struct
import subprocess
from pathlib import Path

import pytest

import mcap_ros2._dynamic as mcap_ros2_dynamic  # noqa: E402  (a missing checker must fail, not skip)
import rosbags.typesys as typesys  # noqa: E402
import numpy as np  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
MSG_DIR = REPO / "models" / "msgs"
SEP = "=" * 80

# ----------------------------------------------------------------------------- expected


def hdr(sec, nanosec, frame):
    return {"stamp": {"sec": sec, "nanosec": nanosec}, "frame_id": frame}


def v3(x, y, z):
    return {"x": x, "y": y, "z": z}


def q(x, y, z, w):
    return {"x": x, "y": y, "z": z, "w": w}


IDENT = q(0.0, 0.0, 0.0, 1.0)
H = math.sqrt(0.5)  # 0.7071067811865476, same double as Rust FRAC_1_SQRT_2
assert H == 0.7071067811865476


def pose(x, y, z, o):
    return {"position": v3(x, y, z), "orientation": o}


TWIST = {"linear": v3(0.5, 0.0, 0.0), "angular": v3(0.0, 0.0, -0.25)}
POSE_COV = {
    "pose": pose(1.0, 2.0, 3.0, q(0.5, 0.5, 0.5, 0.5)),
    "covariance": [i * 0.5 for i in range(36)],
}
_tcov = [0.0] * 36
for _i in range(6):
    _tcov[_i * 7] = (_i + 1) * 0.01
TWIST_COV = {"twist": TWIST, "covariance": _tcov}


def tf(sec, parent, child, x):
    return {
        "header": hdr(sec, 2, parent),
        "child_frame_id": child,
        "transform": {"translation": v3(x, 0.0, 0.45), "rotation": IDENT},
    }


def field(name, offset, datatype=7):  # 7 = PointField.FLOAT32
    return {"name": name, "offset": offset, "datatype": datatype, "count": 1}


MAP_META = {
    "map_load_time": {"sec": 0, "nanosec": 5},
    "resolution": 0.25,
    "width": 3,
    "height": 2,
    "origin": pose(-1.5, -0.5, 0.0, IDENT),
}


def contact(oid, name, link):
    return {
        "object_id": oid,
        "object_name": name,
        "object_kind": "post",
        "robot_link": link,
        "position": v3(2.5, -1.0, 0.25),
        "normal": v3(-1.0, 0.0, 0.0),
        "depth": 0.125,
    }


EXPECTED = {
    "time": {"sec": 1_700_000_000, "nanosec": 123_456_789},
    "time_negative": {"sec": -2, "nanosec": 300_000_000},
    "header": hdr(12, 500_000_000, "odom"),
    "header_empty_frame": hdr(0, 1, ""),
    "float64": {"data": -0.125},
    "vector3": v3(1.5, -2.25, 1e-300),
    "point": v3(0.1, 0.2, 0.3),
    "quaternion": q(0.0, 0.0, H, H),
    "pose": pose(1.0, 2.0, 3.0, q(0.5, 0.5, 0.5, 0.5)),
    "pose_stamped": {"header": hdr(3, 0, "map"), "pose": pose(-1.0, 0.5, 0.0, IDENT)},
    "pose_with_covariance": POSE_COV,
    "twist": TWIST,
    "twist_stamped": {"header": hdr(7, 20_000_000, "base_link"), "twist": TWIST},
    "twist_with_covariance": TWIST_COV,
    "transform": {"translation": v3(0.2, 0.0, 0.45), "rotation": IDENT},
    "transform_stamped": tf(1, "base_link", "camera_optical_frame", 0.2),
    "odometry": {
        "header": hdr(10, 0, "odom"),
        "child_frame_id": "base_link",
        "pose": POSE_COV,
        "twist": TWIST_COV,
    },
    "path": {
        "header": hdr(5, 0, "map"),
        "poses": [
            {"header": hdr(5, 0, "map"), "pose": pose(0.0, 0.0, 0.0, IDENT)},
            {"header": hdr(5, 1, "m"), "pose": pose(1.0, 0.0, 0.0, q(0.0, 0.0, H, H))},
            {"header": hdr(6, 2, ""), "pose": pose(1.0, 1.0, 0.0, q(0.0, 0.0, 1.0, 0.0))},
        ],
    },
    "path_empty": {"header": hdr(0, 0, "map"), "poses": []},
    "tf_message": {
        "transforms": [
            tf(1, "odom", "base_link", 1.25),
            tf(1, "base_link", "lift_link", -0.125),
        ]
    },
    "tf_message_empty": {"transforms": []},
    "clock": {"clock": {"sec": 42, "nanosec": 999_999_999}},
    "joint_state": {
        "header": hdr(2, 40_000_000, ""),
        "name": ["lift_joint", "wheel_fl", "gr\u00fcn"],
        "position": [0.1, 0.2, 0.3],
        "velocity": [],
        "effort": [1.0],
    },
    "signals": {
        "header": hdr(0, 20_000_000, "chassis"),
        "names": ["v_x", "omega", "collided"],
        "values": [0.5, -0.1, 1.0],
    },
    "fmu_status": {
        "header": hdr(1, 240_000_000, "lift"),
        "instance": "lift",
        "status": "Error",
        "message": "fmi3DoStep returned fmi3Error at t=1.24 s: wheel slip > 1",
    },
    "point_field": field("intensity", 12),
    "point_cloud2": {
        "header": hdr(4, 100_000_000, "lidar_link"),
        "height": 1,
        "width": 2,
        "fields": [field("x", 0), field("y", 4), field("z", 8), field("intensity", 12)],
        "is_bigendian": False,
        "point_step": 16,
        "row_step": 32,
        "data": list(struct.pack("<8f", 1.0, 2.0, 3.0, 0.5, -1.0, 0.25, 0.0, 100.0)),
        "is_dense": True,
    },
    "point_cloud2_empty": {
        "header": hdr(0, 0, "l"),
        "height": 0,
        "width": 0,
        "fields": [],
        "is_bigendian": False,
        "point_step": 0,
        "row_step": 0,
        "data": [],
        "is_dense": False,
    },
    "imu": {
        "header": hdr(9, 5_000_000, "imu_link"),
        "orientation": q(0.0, 0.0, H, H),
        "orientation_covariance": [-1.0] + [0.0] * 8,
        "angular_velocity": v3(0.001, -0.002, 0.5),
        "angular_velocity_covariance": [1e-6, 0.0, 0.0, 0.0, 1e-6, 0.0, 0.0, 0.0, 1e-6],
        "linear_acceleration": v3(0.125, 0.0, 9.80665),
        "linear_acceleration_covariance": [4e-4, 0.0, 0.0, 0.0, 4e-4, 0.0, 0.0, 0.0, 4e-4],
    },
    "pose_array": {
        "header": hdr(8, 0, "map"),
        "poses": [pose(1.0, 2.0, 0.75, IDENT), pose(-0.5, 0.0, 1.25, q(0.0, 0.0, H, H))],
    },
    "map_meta_data": MAP_META,
    "occupancy_grid": {
        "header": hdr(0, 0, "map"),
        "info": MAP_META,
        "data": [0, 100, -1, 0, 50, 100],
    },
    "contact": contact(7, "row3/post2", "base_link"),
    "collision_state": {
        "header": hdr(11, 20_000_000, "map"),
        "in_collision": True,
        "count": 2,
        "contacts": [contact(7, "row3/post2", "base_link"), contact(42, "", "arm_l_link4")],
    },
    "collision_state_empty": {
        "header": hdr(0, 0, "map"),
        "in_collision": False,
        "count": 0,
        "contacts": [],
    },
    "navigation_status": {
        "header": hdr(13, 0, "map"),
        "state": "failed",
        "detail": "no_path",
        "goal": {"header": hdr(12, 900_000_000, "map"), "pose": pose(4.0, 2.0, 0.0, q(0.0, 0.0, 1.0, 0.0))},
    },
    "image": {
        "header": hdr(3, 100_000_000, "camera_color_optical_frame"),
        "height": 2,
        "width": 2,
        "encoding": "rgb8",
        "is_bigendian": 0,
        "step": 6,
        "data": [255, 0, 0, 0, 255, 0, 0, 0, 255, 10, 20, 30],
    },
    "region_of_interest": {"x_offset": 3, "y_offset": 5, "height": 7, "width": 11, "do_rectify": True},
    "camera_info": {
        "header": hdr(3, 100_000_000, "camera_color_optical_frame"),
        "height": 480,
        "width": 640,
        "distortion_model": "plumb_bob",
        "d": [0.0] * 5,
        "k": [400.5, 0.0, 319.5, 0.0, 400.5, 239.5, 0.0, 0.0, 1.0],
        "r": [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
        "p": [400.5, 0.0, 319.5, 0.0, 0.0, 400.5, 239.5, 0.0, 0.0, 0.0, 1.0, 0.0],
        "binning_x": 0,
        "binning_y": 0,
        "roi": {"x_offset": 0, "y_offset": 0, "height": 0, "width": 0, "do_rectify": False},
    },
}



def tpoint(positions, velocities, sec, nanosec, accelerations=()):
    return {
        "positions": positions,
        "velocities": velocities,
        "accelerations": list(accelerations),
        "effort": [],
        "time_from_start": {"sec": sec, "nanosec": nanosec},
    }


def p32(x, y, z):
    return {"x": x, "y": y, "z": z}


def solid(type_, dims, points=()):
    return {"type": type_, "dimensions": dims, "polygon": {"points": list(points)}}


STEM = {
    "id": "stem_3",
    "kind": "stem",
    "primitive": solid(3, [1.5, 0.0125]),
    "pose": pose(2.0, -0.75, 0.75, IDENT),
}

# Arm / manipulation types (issue 4); mirrors manipulation_samples() in samples.rs.
EXPECTED.update({
    "duration": {"sec": 3, "nanosec": 250_000_000},
    "duration_negative": {"sec": -2, "nanosec": 300_000_000},
    "joint_trajectory_point": tpoint([0.5, -1.25, 0.0], [0.125, 0.0, -0.5], 1, 500_000_000, [1.0, 2.0, 3.0]),
    "joint_trajectory": {
        "header": hdr(5, 0, "base_link"),
        "joint_names": ["left_joint1", "left_joint2"],
        "points": [tpoint([0.0, 0.25], [], 0, 0), tpoint([0.5, -0.25], [0.0, 0.0], 2, 5)],
    },
    "joint_trajectory_empty": {"header": hdr(0, 0, ""), "joint_names": [], "points": []},
    "gripper_command": {"position": 0.04, "max_effort": 70.0},
    "point32": p32(1.5, -0.25, 0.125),
    "polygon": {"points": [p32(0.0, 0.0, 0.0), p32(1.0, 0.0, 0.5), p32(0.0, -1.0, 0.25)]},
    "solid_primitive_box": solid(1, [0.1, 0.2, 0.3]),
    "solid_primitive_prism": solid(5, [0.5], [p32(0.0, 0.0, 0.0), p32(1.0, 0.0, 0.0), p32(0.0, 1.0, 0.0)]),
    "gripper_state": {
        "header": hdr(4, 20_000_000, "left_hand"),
        "position": 0.035,
        "effort": 70.0,
        "stalled": True,
        "reached_goal": False,
    },
    "trajectory_status": {
        "header": hdr(6, 0, "left"),
        "state": 3,
        "trajectory_count": 3,
        "rejected_count": 1,
        "reason": "point 2: time_from_start not strictly increasing",
        "rms_tracking_error": 0.0025,
        "max_tracking_error": 0.0078125,
    },
    "collision_object": STEM,
    "planning_scene": {
        "header": hdr(7, 500_000_000, "base_link"),
        "objects": [
            STEM,
            {"id": "floor", "kind": "floor", "primitive": solid(1, [10.0, 10.0, 0.01]),
             "pose": pose(0.0, 0.0, -0.005, IDENT)},
            {"id": "fruit_12", "kind": "fruit", "primitive": solid(2, [0.035]),
             "pose": pose(0.75, 0.5, 1.25, IDENT)},
        ],
    },
    "planning_scene_empty": {"header": hdr(0, 0, ""), "objects": []},
    "harvest_status": {
        "header": hdr(30, 0, "map"),
        "stage": "handover",
        "target_id": 12,
        "target_name": "fruit_12",
        "outcome": "failure",
        "failure_category": "handover",
        "detail": "right gripper stalled at 0 m",
        "plans": 7,
    },
    "plant_damage": {
        "header": hdr(41, 250_000_000, "map"),
        "bruised_by_grip": 1,
        "bruised_by_impact": 2,
        "unripe_detached": 1,
        "stems_broken": 0,
        "detached_by_pull": 3,
        "detached_by_bend": 4,
        "detached_by_twist": 0,
        "last_detach_mode": "bend",
        "last_detach_force": 6.5,
        "last_detach_moment": 0.375,
        "leaf_pushes": 5,
        "peak_leaf_force": 1.25,
        "peak_stem_load": 0.5,
    },
    "moved_objects": {
        "header": hdr(41, 500_000_000, "map"),
        "ids": [7, 1024, 70000],
        "poses": [
            pose(1.5, -2.0, 0.75, q(0.0, 0.0, 0.0, 1.0)),
            pose(0.25, 0.5, 1.125, q(0.5, 0.5, 0.5, 0.5)),
            pose(-3.0, 4.0, 0.0625, q(0.0, 0.0, 1.0, 0.0)),
        ],
    },
    "plan_result": {
        "header": hdr(12, 500_000_000, "map"),
        "stage": "pre_grasp",
        "arm": "left",
        "kind": "pregrasp",
        "ok": False,
        "optional": False,
        "detail": "no IK solution for any of 6 grasps",
        "planning_time": 0.0123,
    },
})

# Perception types (vision_msgs 4.x); mirrors vision_samples() in samples.rs.
_VCOV = [0.0] * 36
for _i in range(3):
    _VCOV[_i * 7] = 2.5e-5 * (_i + 1)


def hypothesis(class_id, score, x, y, z):
    return {"hypothesis": {"class_id": class_id, "score": score},
            "pose": {"pose": pose(x, y, z, IDENT), "covariance": list(_VCOV)}}


def tomato(id_, class_id, score):
    return {
        "header": hdr(9, 100_000_000, "camera_color_optical_frame"),
        "results": [hypothesis(class_id, score, 0.125, -0.25, 0.75)],
        "bbox": {"center": pose(0.125, -0.25, 0.75, IDENT), "size": v3(0.0625, 0.0625, 0.0625)},
        "id": id_,
    }


EXPECTED.update({
    "object_hypothesis": {"class_id": "ripe", "score": 0.875},
    "object_hypothesis_with_pose": hypothesis("stage_6", 0.5, 1.0, 2.0, 0.5),
    "bounding_box3d": {"center": pose(1.0, 2.0, 3.0, IDENT), "size": v3(0.5, 0.25, 0.125)},
    "detection3d": tomato("17", "stage_5", 0.75),
    "detection3d_array": {
        "header": hdr(9, 100_000_000, "camera_color_optical_frame"),
        "detections": [tomato("17", "stage_5", 0.75), tomato("", "stage_1", 0.25)],
    },
    "detection3d_array_empty": {"header": hdr(0, 0, ""), "detections": []},
})

# Viewer types (std_msgs String/ColorRGBA, visualization_msgs); mirrors
# visualization_samples() in samples.rs. float32 values are exact in binary.
RED = {"r": 0.75, "g": 0.125, "b": 0.0, "a": 1.0}


def _marker_defaults():
    return {
        "lifetime": {"sec": 0, "nanosec": 0},
        "frame_locked": False,
        "points": [],
        "colors": [],
        "texture_resource": "",
        "texture": {"header": hdr(0, 0, ""), "format": "", "data": []},
        "uv_coordinates": [],
        "text": "",
        "mesh_resource": "",
        "mesh_file": {"filename": "", "data": []},
        "mesh_use_embedded_materials": False,
    }


MARKER_LIST = {
    "header": hdr(3, 0, "map"),
    "ns": "fruit",
    "id": 7,
    "type": 7,
    "action": 0,
    "pose": pose(0.0, 0.0, 0.0, IDENT),
    "scale": v3(0.0625, 0.0625, 0.0625),
    "color": {"r": 1.0, "g": 1.0, "b": 1.0, "a": 1.0},
    **_marker_defaults(),
}
MARKER_LIST.update({
    "frame_locked": True,
    "points": [v3(1.5, -2.0, 0.75), v3(1.5, -2.25, 1.0)],
    "colors": [RED, {"r": 0.25, "g": 0.5, "b": 0.0, "a": 0.5}],
})
MARKER_EVERYTHING = {
    "header": hdr(4, 250_000_000, "base_link"),
    "ns": "robot",
    "id": -1,
    "type": 11,
    "action": 0,
    "pose": pose(1.0, 2.0, 3.0, q(0.5, 0.5, 0.5, 0.5)),
    "scale": v3(1.0, 1.0, 1.0),
    "color": RED,
    "lifetime": {"sec": 2, "nanosec": 500_000_000},
    "frame_locked": False,
    "points": [v3(0.0, 0.0, 0.0), v3(1.0, 0.0, 0.0), v3(0.0, 1.0, 0.0)],
    "colors": [],
    "texture_resource": "embedded://leaf.png",
    "texture": {"header": hdr(4, 0, "camera"), "format": "png", "data": [137, 80, 78, 71]},
    "uv_coordinates": [{"u": 0.0, "v": 0.0}, {"u": 1.0, "v": 0.0}, {"u": 0.0, "v": 1.0}],
    "text": "tomato",
    "mesh_resource": "package://agrisim/leaf.stl",
    "mesh_file": {"filename": "leaf.stl", "data": [1, 2, 3]},
    "mesh_use_embedded_materials": True,
}

EXPECTED.update({
    "string": {"data": '<robot name="r"/>'},
    "color_rgba": RED,
    "compressed_image": {"header": hdr(5, 0, "camera"), "format": "jpeg", "data": [255, 216, 255]},
    "uv_coordinate": {"u": 0.25, "v": 0.75},
    "mesh_file": {"filename": "a.dae", "data": [9, 8]},
    "marker_sphere_list": MARKER_LIST,
    "marker_everything": MARKER_EVERYTHING,
    "marker_array": {"markers": [MARKER_LIST, MARKER_EVERYTHING]},
    "marker_array_empty": {"markers": []},
})

# Constants a later distro added to a type, which our (Humble) text leaves out.
DISTRO_EXTRA_CONSTANTS = {
    ("ROS2_JAZZY", "visualization_msgs/msg/Marker"): [("ARROW_STRIP", "int32", 12)],
}

# control_msgs is not in rosbags' stores; its definition (ros-controls/control_msgs,
# msg/GripperCommand.msg, identical in ROS 1 and ROS 2) is checked here instead.
# vision_msgs is not in them either; its field layout (ros-perception/vision_msgs 4.x, the
# ROS 2 Humble/Jazzy release) is written out here from that package's msg/ files.
NOT_IN_ROSBAGS_STORES = {
    "control_msgs/msg/GripperCommand": [("position", "float64"), ("max_effort", "float64")],
    "vision_msgs/msg/ObjectHypothesis": [("class_id", "string"), ("score", "float64")],
    "vision_msgs/msg/ObjectHypothesisWithPose": [
        ("hypothesis", "vision_msgs/msg/ObjectHypothesis"),
        ("pose", "geometry_msgs/msg/PoseWithCovariance"),
    ],
    "vision_msgs/msg/BoundingBox3D": [("center", "geometry_msgs/msg/Pose"), ("size", "geometry_msgs/msg/Vector3")],
    "vision_msgs/msg/Detection3D": [
        ("header", "std_msgs/msg/Header"),
        ("results", "vision_msgs/msg/ObjectHypothesisWithPose[]"),
        ("bbox", "vision_msgs/msg/BoundingBox3D"),
        ("id", "string"),
    ],
    "vision_msgs/msg/Detection3DArray": [("header", "std_msgs/msg/Header"), ("detections", "vision_msgs/msg/Detection3D[]")],
}

# ----------------------------------------------------------------------------- helpers


def _field_type(d):
    """A rosbags field definition as .msg spells its type: `float64`, `pkg/msg/Type`, `T[]`."""
    kind, rest = d
    if kind == typesys.base.Nodetype.BASE:
        return rest[0]
    if kind == typesys.base.Nodetype.NAME:
        return rest
    if kind == typesys.base.Nodetype.SEQUENCE:
        return _field_type(rest[0]) + "[]"
    raise AssertionError(f"field kind {kind} not expected here")


def _samples_cmd(*args: str) -> list[str]:
    exe = os.environ.get("AGRISIM_MSGS_WRITE_SAMPLES")
    if exe:
        return [exe, *args]
    if shutil.which("cargo") is None:
        pytest.skip("cargo not found and AGRISIM_MSGS_WRITE_SAMPLES not set")
    return ["cargo", "run", "-q", "-p", "agrisim-msgs", "--example", "write_samples", "--", *args]


def plain(obj):
    """Decoded message (mcap_ros2 slots class or rosbags dataclass) -> dicts and lists.

    Byte arrays become lists of ints: mcap-ros2-support decodes uint8[] as bytes, rosbags as
    a numpy array."""
    if isinstance(obj, (bytes, bytearray, memoryview)):
        return list(bytes(obj))
    if isinstance(obj, (str, int, float, bool)) or obj is None:
        return obj
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, (list, tuple)):
        return [plain(v) for v in obj]
    if isinstance(obj, dict):
        return {k: plain(v) for k, v in obj.items()}
    fields = getattr(obj, "__dataclass_fields__", None)
    names = list(fields) if fields is not None else list(getattr(obj, "__slots__", ()))
    # rosbags lists .msg constants (PointField.FLOAT32) as fields; ROS 2 field names are
    # lower case and constant names upper case, so drop the latter.
    names = [n for n in names if not n.isupper()]
    if not names:
        raise TypeError(f"cannot convert {type(obj)!r}")
    return {n: plain(getattr(obj, n)) for n in names if n != "__msgtype__"}


def msg_files() -> dict[str, str]:
    """'pkg/msg/Type' -> .msg text, for every file in models/msgs."""
    out = {}
    for p in sorted(MSG_DIR.glob("*/msg/*.msg")):
        out[f"{p.parts[-3]}/msg/{p.stem}"] = p.read_text()
    return out


@pytest.fixture(scope="session")
def samples(tmp_path_factory):
    """name -> (type_name, cdr bytes, schema text)."""
    out = tmp_path_factory.mktemp("msgs-samples")
    subprocess.run(_samples_cmd(str(out)), cwd=REPO, check=True)
    result = {}
    for line in (out / "index.tsv").read_text().splitlines():
        name, type_name = line.split("\t")
        result[name] = (
            type_name,
            (out / f"{name}.cdr").read_bytes(),
            (out / f"{name}.ros2msg").read_text(),
        )
    return result


@pytest.fixture(scope="session")
def rosbags_store():
    """Typestore with every type registered from our individual .msg files."""
    store = typesys.get_typestore(typesys.Stores.EMPTY)
    for name, text in msg_files().items():
        store.register(typesys.get_types_from_msg(text, name))
    return store


SAMPLE_NAMES = sorted(EXPECTED)

# ----------------------------------------------------------------------------- tests


def test_samples_cover_every_msg_file(samples):
    assert set(samples) == set(EXPECTED)
    assert {t for t, _, _ in samples.values()} == set(msg_files())
    assert len(msg_files()) == 60


@pytest.mark.parametrize("name", SAMPLE_NAMES)
def test_mcap_ros2_decodes_with_our_schema(samples, name):
    type_name, data, schema = samples[name]
    decoders = mcap_ros2_dynamic.generate_dynamic(type_name, schema)
    assert plain(decoders[type_name](data)) == EXPECTED[name]


@pytest.mark.parametrize("name", SAMPLE_NAMES)
def test_rosbags_decodes_and_reencodes_identically(samples, rosbags_store, name):
    type_name, data, _ = samples[name]
    msg = rosbags_store.deserialize_cdr(data, type_name)
    assert plain(msg) == EXPECTED[name]
    assert bytes(rosbags_store.serialize_cdr(msg, type_name)) == data


@pytest.mark.parametrize("name", SAMPLE_NAMES)
def test_rosbags_parses_our_concatenated_schema(samples, name):
    type_name, data, schema = samples[name]
    types = typesys.get_types_from_msg(schema, type_name)
    store = typesys.get_typestore(typesys.Stores.EMPTY)
    store.register(types)
    assert plain(store.deserialize_cdr(data, type_name)) == EXPECTED[name]


def test_schema_format(samples):
    for name, (type_name, _, schema) in samples.items():
        own = msg_files()[type_name]
        assert schema.startswith(own), name
        blocks = schema.split(SEP + "\n")
        for block in blocks[1:]:
            head, _, body = block.partition("\n")
            assert head.startswith("MSG: "), (name, head)
            dep = head[len("MSG: "):]
            assert dep.count("/") == 1, dep  # rosbag2 style: pkg/Type
            pkg, ty = dep.split("/")
            assert body == msg_files()[f"{pkg}/msg/{ty}"], (name, dep)


def test_mcap_ros2_encoder_bytes_decode_in_rust(samples, tmp_path):
    """Other direction: a foreign encoder's bytes must decode to our sample values."""
    for name, (type_name, data, schema) in samples.items():
        enc = mcap_ros2_dynamic.serialize_dynamic(type_name, schema)[type_name]
        foreign = bytes(enc(EXPECTED[name]))
        # Same layout; mcap_ros2 may add trailing alignment padding, which we accept.
        assert foreign[: len(data)] == data, name
        assert set(foreign[len(data):]) <= {0}, name
        (tmp_path / f"{name}.cdr").write_bytes(foreign)
    out = subprocess.run(
        _samples_cmd("--check", str(tmp_path)), cwd=REPO, capture_output=True, text=True
    )
    assert out.returncode == 0, out.stdout + out.stderr
    assert f"checked {len(samples)} files, 0 failed" in out.stdout


def test_mcap_file_round_trip(samples):
    """Our schema + bytes in a real MCAP file, read back via mcap-ros2-support's decoder."""
    import mcap.writer as writer_mod
    reader_mod = pytest.importorskip("mcap.reader")
    decoder_mod = pytest.importorskip("mcap_ros2.decoder")
    buf = io.BytesIO()
    w = writer_mod.Writer(buf)
    w.start(profile="ros2", library="agrisim-crosscheck")
    order = []
    for i, (name, (type_name, data, schema)) in enumerate(sorted(samples.items())):
        sid = w.register_schema(name=type_name, encoding="ros2msg", data=schema.encode())
        cid = w.register_channel(
            topic=f"/{name}",
            message_encoding="cdr",
            schema_id=sid,
            metadata={"offered_qos_profiles": ""},
        )
        w.add_message(channel_id=cid, log_time=i, publish_time=i, data=data)
        order.append(name)
    w.finish()
    buf.seek(0)
    reader = reader_mod.make_reader(buf, decoder_factories=[decoder_mod.DecoderFactory()])
    got = {ch.topic[1:]: plain(msg) for _, ch, _, msg in reader.iter_decoded_messages()}
    assert got == {n: EXPECTED[n] for n in order}


@pytest.mark.parametrize("store_name", ["ROS2_HUMBLE", "ROS2_JAZZY"])
def test_msg_texts_match_ros2_distro(rosbags_store, store_name):
    """Field names and types of our standard .msg files equal the real ROS 2 ones."""
    ref = typesys.get_typestore(getattr(typesys.Stores, store_name))
    checked = 0
    for name in msg_files():
        if name.startswith("agrisim_msgs/"):
            continue
        if name in NOT_IN_ROSBAGS_STORES:
            assert name not in ref.fielddefs, name  # if rosbags gains it, compare there
            got = [(f, _field_type(d)) for f, d in rosbags_store.fielddefs[name][1]]
            assert got == NOT_IN_ROSBAGS_STORES[name], name
            continue
        ours, theirs = rosbags_store.fielddefs[name], ref.fielddefs[name]
        extra = DISTRO_EXTRA_CONSTANTS.get((store_name, name), [])
        if extra:  # a later distro's constants sit among the others: compare as sets
            assert sorted(list(ours[0]) + extra) == sorted(theirs[0]) and ours[1] == theirs[1], name
        else:
            assert ours == theirs, name
        checked += 1
    assert checked == 41


@pytest.mark.parametrize("name", SAMPLE_NAMES)
def test_python_package_codec_agrees(samples, name):
    """The Python package's run-time codec (agrisim.decode / agrisim.encode, driven by the
    .msg texts) gives the values the independent decoders give, and encodes them back to
    the very bytes; EXPECTED (written by hand) encodes to them too."""
    import agrisim

    type_name, data, _ = samples[name]
    decoded = agrisim.decode(type_name, data)
    assert plain(decoded) == EXPECTED[name]
    assert agrisim.encode(type_name, decoded) == data
    assert agrisim.encode(type_name, EXPECTED[name]) == data
