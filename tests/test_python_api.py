"""The Python package (python/: pyo3 extension + pkg/agrisim) end to end: the simulator driven
from Python, messages as Python objects and numpy arrays checked against the MCAP the run
recorded (decoded by mcap-ros2-support, which no one here wrote), FMU variables, snapshots,
and errors as Python exceptions with the engine's message."""

from __future__ import annotations

import math
import struct
import threading
import time

import numpy as np
import pytest

import agrisim
from conftest import decoded_messages


def test_publish_twist_step_read_odometry():
    with agrisim.Simulation("default", seed=1) as sim:
        assert sim.topics()["/cmd_vel"] == "geometry_msgs/msg/Twist"
        x0 = sim.get("chassis", "x")
        for _ in range(20):  # 2 s at 0.3 m/s; the chassis watchdog wants fresh commands
            sim.publish("/cmd_vel", {"linear": {"x": 0.3}})
            sim.step(5)
        assert sim.time == pytest.approx(2.0)
        odom = sim.latest("/odom")
        assert odom["header"]["frame_id"] == "odom" and odom["child_frame_id"] == "base_link"
        assert odom["twist"]["twist"]["linear"]["x"] == pytest.approx(0.3, abs=0.03)
        travelled = sim.get("chassis", "x") - x0
        assert 0.45 < travelled < 0.6, travelled  # ramp-up, slip and noise of the scenario
        # Odometry saw the same motion (within its drift).
        assert odom["pose"]["pose"]["position"]["x"] - x0 == pytest.approx(travelled, abs=0.05)
        stamps = [t for t, _ in sim.messages("/odom")]
        sim.step(10)
        stamps = [t for t, _ in sim.messages("/odom")]
        assert stamps == pytest.approx([2.0, 2.1]), stamps


def test_point_cloud_and_images_match_the_mcap(tmp_path):
    """numpy views of what Python received equal what the MCAP recorded, decoded by
    mcap-ros2-support; the raw bytes are the recorded bytes."""
    mcap = tmp_path / "run.mcap"
    params = {"camera": {"width": 64, "height": 48}}
    with agrisim.Simulation("sensors", seed=2, record=mcap, profile="full", parameters=params, nodes=["script"]) as sim:
        sim.step(10)
        cloud, raw_cloud = sim.latest("/points"), sim.latest("/points", raw=True)
        rgb = sim.latest("/camera/color/image_raw")
        depth = sim.latest("/camera/aligned_depth_to_color/image_raw")
    assert mcap.is_file()

    def recorded(topic, msg):
        """The recorded message with the same header stamp."""
        stamp = msg["header"]["stamp"]
        found = [m for _, _, m in decoded_messages(mcap, topic) if (m.header.stamp.sec, m.header.stamp.nanosec) == (stamp["sec"], stamp["nanosec"])]
        assert len(found) == 1, (topic, stamp)
        return found[0]

    rec = recorded("/points", cloud)
    assert bytes(rec.data) == cloud["data"]
    pts = agrisim.pointcloud_to_array(cloud)
    assert pts.shape == (rec.width * rec.height,)
    # Independent unpacking of every 997th point from the recorded message's own layout.
    offsets = {f.name: f.offset for f in rec.fields}
    for i in range(0, len(pts), 997):
        base = i * rec.point_step
        for name in ("x", "y", "z", "intensity"):
            (v,) = struct.unpack_from("<f", rec.data, base + offsets[name])
            assert pts[name][i] == v or (math.isnan(v) and math.isnan(pts[name][i]))
    assert np.count_nonzero(np.hypot(pts["x"], pts["y"]) > 0.1) > 1000, "the cloud is empty"
    assert isinstance(raw_cloud, bytes) and len(raw_cloud) > len(cloud["data"])

    img = agrisim.image_to_array(rgb)
    assert img.shape == (48, 64, 3) and img.dtype == np.uint8
    rec_rgb = recorded("/camera/color/image_raw", rgb)
    assert rec_rgb.encoding == "rgb8"
    expect = np.frombuffer(bytes(rec_rgb.data), np.uint8).reshape(rec_rgb.height, rec_rgb.step)[:, : rec_rgb.width * 3]
    assert np.array_equal(img.reshape(48, -1), expect)
    assert img.std() > 1.0, "a blank image"
    d = agrisim.image_to_array(depth)
    assert d.shape == (48, 64) and d.dtype == np.float32
    rec_d = recorded("/camera/aligned_depth_to_color/image_raw", depth)
    assert rec_d.encoding == "32FC1"
    assert np.array_equal(d.view(np.uint8).reshape(-1), np.frombuffer(bytes(rec_d.data), np.uint8))
    finite = d[np.isfinite(d) & (d > 0)]
    assert finite.size > 100 and 0.1 < np.median(finite) < 20.0


def test_snapshot_restore_replays_identically():
    with agrisim.Simulation("default", seed=3) as sim:
        sim.step(5)
        snap = sim.snapshot()
        assert snap.time == pytest.approx(0.1)

        def run():
            out = []
            for k in range(10):
                sim.publish("/cmd_vel", {"linear": {"x": 0.2}, "angular": {"z": 0.1 * k}})
                sim.step(5)
                out.append((sim.get("chassis", "x"), sim.get("chassis", "yaw"), sim.latest("/odom", raw=True), sim.latest("/points", raw=True)))
            return out

        first = run()
        sim.restore(snap)
        assert sim.time == pytest.approx(0.1)
        second = run()
        assert first == second
        assert first[0][0] != first[-1][0]  # it moved


def test_snapshot_refused_with_builtin_nodes():
    with agrisim.Simulation("default", nodes=["odom_tf"]) as sim:
        with pytest.raises(agrisim.AgrisimError, match="node 'odom_tf'"):
            sim.snapshot()


def test_set_variable_and_tf_node():
    with agrisim.Simulation("default", nodes=["odom_tf"], parameters={"chassis": {"enc_noise": 0.0}}) as sim:
        sim.step(5)
        tf = sim.latest("/tf")
        assert tf["transforms"][0]["child_frame_id"] == "base_link"
        sim.set("chassis", "cmd_timeout", 0.0)
        assert sim.get("chassis", "cmd_timeout") == 0.0


def test_bad_scenario_names_the_key(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text((agrisim.root() / "models/scenarios/default.toml").read_text().replace("[nav]", "[nav]\ngoal_tolerence = 0.3", 1))
    with pytest.raises(agrisim.AgrisimError, match="goal_tolerence"):
        agrisim.Simulation(str(bad))
    with pytest.raises(agrisim.AgrisimError, match="no_such_scenario"):
        agrisim.Simulation("no_such_scenario")


def test_bad_messages_and_variables_are_named():
    with agrisim.Simulation("default") as sim:
        with pytest.raises(agrisim.AgrisimError, match=r"/cmd_vel.*field linear\.w"):
            sim.publish("/cmd_vel", {"linear": {"w": 1.0}})
        with pytest.raises(agrisim.AgrisimError, match="expected a number, got a string"):
            sim.publish("/cmd_vel", {"linear": {"x": "fast"}})
        with pytest.raises(agrisim.AgrisimError, match="not a valid geometry_msgs/msg/Twist"):
            sim.publish("/cmd_vel", b"\x00\x01\x00\x00\x01")
        with pytest.raises(agrisim.AgrisimError, match="/nowhere.*type_name"):
            sim.publish("/nowhere", {})
        with pytest.raises(agrisim.AgrisimError, match="FMU 'chassis' has no variable 'warp'"):
            sim.get("chassis", "warp")
        with pytest.raises(agrisim.AgrisimError, match="no component 'tractor'"):
            sim.get("tractor", "x")
        with pytest.raises(agrisim.AgrisimError, match="unknown node"):
            agrisim.Simulation("default", nodes=["teleop"])
        sim.step(1)  # still usable after the refusals


def test_step_releases_the_gil():
    """Another Python thread runs while the engine steps."""
    with agrisim.Simulation("default") as sim:
        ticks = []
        stop = threading.Event()

        def count():
            while not stop.is_set():
                ticks.append(1)
                time.sleep(0.001)

        t = threading.Thread(target=count)
        t.start()
        before = len(ticks)
        sim.step(100)
        during = len(ticks) - before
        stop.set()
        t.join()
        assert during > 5, during


def test_arm_model_matches_the_arm_fmu():
    """ArmModel's forward kinematics and the Arm FMU's joints agree on the reach task: a
    joint step moves the FMU's joints, and FK of them moves the tool centre point."""
    arm = agrisim.ArmModel("left")
    assert arm.joint_names == [f"left_joint{i}" for i in range(1, 8)]
    lo, hi = arm.limits
    assert all(a < b for a, b in zip(lo, hi))
    with pytest.raises(agrisim.AgrisimError, match="7 arm joints"):
        arm.fk([0.0] * 6)
    p0, rot = arm.fk([0.0, -0.3, 0.0, -2.356, 0.0, 1.571, 0.785])
    assert np.allclose(np.array(rot) @ np.array(rot).T, np.eye(3), atol=1e-9)
    with agrisim.Simulation("reach") as sim:
        sim.step(5)
        q0 = [sim.get("arm", f"q{i}") for i in range(1, 8)]
        assert np.allclose(arm.fk(q0)[0], p0, atol=1e-3)
