"""`agrisim run` of the full sensor suite (models/systems/sensors.ssd) at a small camera
resolution: the camera's Image (rgb8, 32FC1 depth, 32SC1 labels) and CameraInfo decode with
mcap-ros2-support, K matches the field of view, and depth reprojected with that K is
consistent with the images' own sizes and the range limits; LiDAR, IMU and both arms'
JointState run beside it."""

from __future__ import annotations

import math
import struct
from pathlib import Path

import pytest
from conftest import REPO, agrisim_run, decoded_messages
from scenario_variant import write_variant

W, H = 160, 90


@pytest.fixture(scope="module")
def sensors_run(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("sensors")
    scenario = write_variant(REPO / "models" / "scenarios" / "sensors.toml", out,
                             f"[parameters.camera]\nwidth = {W}\nheight = {H}\n", name="sensors_small.toml")
    return agrisim_run(out, "--duration", "0.5", scenario=scenario)


def messages(path: Path, topic: str):
    return [(schema, msg) for schema, _, msg in decoded_messages(path, topic)]


def test_image_and_camera_info_decode(sensors_run):
    rgb = messages(sensors_run, "/camera/color/image_raw")
    depth = messages(sensors_run, "/camera/aligned_depth_to_color/image_raw")
    info = messages(sensors_run, "/camera/color/camera_info")
    labels = messages(sensors_run, "/camera/labels")
    # 10 Hz over 0.5 s: frames stamped 0.0 .. 0.5 s, each one recorded (the port keeps them all).
    assert len(rgb) == len(depth) == len(info) == len(labels) == 6
    assert [im.header.stamp.sec * 10**9 + im.header.stamp.nanosec for _, im in rgb] == list(range(0, 500_000_001, 100_000_000))
    assert {s for s, _ in rgb + depth + labels} == {"sensor_msgs/msg/Image"}
    assert {s for s, _ in info} == {"sensor_msgs/msg/CameraInfo"}
    for (_, im), (_, d), (_, ci), (_, lb) in zip(rgb, depth, info, labels):
        assert (im.encoding, im.width, im.height, im.step, len(im.data)) == ("rgb8", W, H, 3 * W, 3 * W * H)
        assert (d.encoding, d.step, len(d.data)) == ("32FC1", 4 * W, 4 * W * H)
        assert (lb.encoding, len(lb.data)) == ("32SC1", 4 * W * H)
        stamp = lambda m: (m.header.stamp.sec, m.header.stamp.nanosec)  # noqa: E731
        assert stamp(im) == stamp(d) == stamp(ci) == stamp(lb)
        assert ci.header.frame_id == im.header.frame_id == "camera_color_optical_frame"
        fx = 0.5 * W / math.tan(math.radians(87.0 / 2))
        fy = 0.5 * H / math.tan(math.radians(58.0 / 2))
        assert ci.k == pytest.approx([fx, 0, (W - 1) / 2, 0, fy, (H - 1) / 2, 0, 0, 1])
        assert (ci.width, ci.height, ci.distortion_model, list(ci.d)) == (W, H, "plumb_bob", [0.0] * 5)
        z = struct.unpack(f"<{W * H}f", bytes(d.data))
        valid = [v for v in z if v > 0]
        assert len(valid) > W * H // 4
        assert all(0.105 * 0.5 < v < 10.0 * 2 for v in valid)
        # Every pixel with depth sees an object.
        ids = struct.unpack(f"<{W * H}i", bytes(lb.data))
        assert all(ids[i] > 0 for i, v in enumerate(z) if v > 0)
        # A lit greenhouse at noon: not black, not saturated.
        mean = sum(im.data) / len(im.data)
        assert 30 < mean < 230, mean


def test_lidar_and_imu_run_beside_the_camera(sensors_run):
    assert len(messages(sensors_run, "/points")) >= 4
    assert len(messages(sensors_run, "/imu")) >= 4


# The arms' q_init in sensors.ssd (as harvest.ssd): no trajectory arrives, so they hold it.
Q_INIT = [0.0, -0.3, 0.0, -2.356, 0.0, 1.571, 0.785]


@pytest.mark.parametrize("side", ["left", "right"])
def test_joint_states_of_both_arms_decode(sensors_run, side):
    states = messages(sensors_run, f"/{side}_arm/joint_states")
    assert len(states) >= 4
    assert {s for s, _ in states} == {"sensor_msgs/msg/JointState"}
    names = [f"{side}_joint{i}" for i in range(1, 8)] + [f"{side}_finger_joint1", f"{side}_finger_joint2"]
    for _, js in states:
        assert list(js.name) == names
        assert len(js.position) == len(js.velocity) == len(js.effort) == 9
        assert all(math.isfinite(v) for v in list(js.position) + list(js.velocity) + list(js.effort))
        assert list(js.position[:7]) == pytest.approx(Q_INIT, abs=0.05)
        assert 0.0 <= js.position[7] == js.position[8] <= 0.04
