"""Several cameras in one system (models/systems/sensors.ssd: the lift camera and a wrist
camera on each hand), each a Camera.fmu instance with its own parameters: every camera
publishes on its own namespaced topics in its own optical frame, at its own resolution, and
hangs its frames on the robot's TF tree on /tf_static. A mount on a link the robot does not
have stops the run with an error naming the component and the parameter."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import REPO, agrisim_run, decoded_messages, run_agrisim
from scenario_variant import write_variant

SENSORS = REPO / "models" / "scenarios" / "sensors.toml"

# component -> (topic namespace, optical frame, body frame, parent link, size): the sizes
# differ, so a message on the wrong camera's topic would show.
CAMERAS = {
    "camera": ("/camera", "camera_color_optical_frame", "camera_link", "lift_link", (64, 36)),
    "left_wrist_camera": ("/left_wrist_camera", "left_wrist_camera_color_optical_frame", "left_wrist_camera_link", "left_hand", (48, 30)),
    "right_wrist_camera": ("/right_wrist_camera", "right_wrist_camera_color_optical_frame", "right_wrist_camera_link", "right_hand", (40, 24)),
}


def small(extra: str = "") -> str:
    return "".join(f"[parameters.{c}]\nwidth = {w}\nheight = {h}\n" for c, (*_, (w, h)) in CAMERAS.items()) + extra


@pytest.fixture(scope="module")
def run(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("cameras")
    scenario = write_variant(SENSORS, out, small(), name="sensors_cameras.toml")
    return agrisim_run(out, "--duration", "0.3", scenario=scenario)


@pytest.mark.parametrize("name", list(CAMERAS))
def test_each_camera_publishes_on_its_own_topics(run, name):
    ns, optical, _, _, (w, h) = CAMERAS[name]
    topics = {
        "rgb": f"{ns}/color/image_raw",
        "depth": f"{ns}/aligned_depth_to_color/image_raw",
        "info": f"{ns}/color/camera_info",
        "labels": f"{ns}/labels",
    }
    got = {k: [m for _, _, m in decoded_messages(run, t)] for k, t in topics.items()}
    # 10 Hz over 0.3 s: frames stamped 0.0 .. 0.3 s on every topic.
    assert {k: len(v) for k, v in got.items()} == {k: 4 for k in topics}
    for rgb, depth, info, labels in zip(got["rgb"], got["depth"], got["info"], got["labels"]):
        for m in (rgb, depth, info, labels):
            assert m.header.frame_id == optical
            assert (m.width, m.height) == (w, h)
        assert (rgb.encoding, depth.encoding, labels.encoding) == ("rgb8", "32FC1", "32SC1")
        stamp = lambda m: (m.header.stamp.sec, m.header.stamp.nanosec)  # noqa: E731
        assert stamp(rgb) == stamp(depth) == stamp(info) == stamp(labels)


def test_every_camera_hangs_its_frames_on_the_robot_tf_tree(run):
    edges = {}
    for _, _, m in decoded_messages(run, "/tf_static"):
        for t in m.transforms:
            tr = t.transform.translation
            edges[t.child_frame_id] = (t.header.frame_id, (tr.x, tr.y, tr.z))
    for name, (_, optical, body, parent, _) in CAMERAS.items():
        assert edges[body][0] == parent, name
        assert edges[optical] == (body, (0.0, 0.0, 0.0)), name
    # The lift camera as the URDF's camera_joint; the wrist cameras beside the grippers (sensors.ssd).
    assert edges["camera_link"][1] == pytest.approx((0.12, 0.0, 0.15))
    assert edges["left_wrist_camera_link"][1] == pytest.approx((0.065, 0.0, 0.03))


def test_unknown_mount_parent_names_the_component_and_the_parameter(tmp_path):
    extra = '[parameters.left_wrist_camera]\nmount_parent = "left_nose"\n'
    text = small().replace("[parameters.left_wrist_camera]\n", "[parameters.left_wrist_camera]\nmount_parent = \"left_nose\"\n")
    assert extra.splitlines()[1] in text
    scenario = write_variant(SENSORS, tmp_path, text, name="bad_mount.toml")
    p = run_agrisim("run", "--scenario", str(scenario), "--out", str(tmp_path / "out"), "--duration", "0.1", check=False)
    assert p.returncode != 0
    assert "left_wrist_camera" in p.stderr and "mount_parent" in p.stderr and "left_nose" in p.stderr, p.stderr


def test_the_worlds_moved_objects_reach_every_sensor_and_the_bus_once(run):
    """sensors.ssd wires the world's moved_objects to the LiDAR and the three cameras: four
    FMU-to-FMU routes from one output. The recording has the message once per instant (not a
    copy per route), here the empty list at the start (nothing has moved in 0.3 s)."""
    msgs = list(decoded_messages(run, "/world/moved_objects"))
    assert len(msgs) == 1, [m.header.stamp for _, _, m in msgs]
    m = msgs[0][2]
    assert (list(m.ids), list(m.poses), m.header.frame_id) == ([], [], "map")
