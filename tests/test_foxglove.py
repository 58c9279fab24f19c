"""The Foxglove live view (`--foxglove`) against a client no one here wrote: the `websockets`
package speaking the Foxglove WebSocket protocol (subprotocol foxglove.sdk.v1), in a private
network namespace with only loopback. The run is paced to the wall clock (`--ros2-mode
realtime`, real time) so the client joins while it goes. The client gets serverInfo,
every topic advertised with its ros2msg schema (the MCAP's own text), simulated time, and
messages equal, byte for byte and stamp for stamp, to what the MCAP recorded."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest
from mcap.reader import make_reader

import netns
from conftest import agrisim_bin

HERE = Path(__file__).parent
pytestmark = pytest.mark.skipif(netns.available() is not None, reason=str(netns.available()))


def test_foxglove_client_sees_the_recorded_messages(tmp_path):
    out, got = tmp_path / "run", tmp_path / "client.json"
    cmd = [str(agrisim_bin()), "run", "--duration", "4", "--record", "full", "--ros2", "--ros2-mode", "realtime", "--ros2-rate", "1", "--foxglove", "127.0.0.1:0", "--out", str(out)]
    topics = ["/odom", "/points", "/tf", "/clock"]
    argv = [sys.executable, str(HERE / "foxglove_client.py"), "--out", str(got)] + [x for t in topics for x in ("--topic", t)] + ["--", *cmd]
    r = netns.run(argv, timeout=120, capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    d = json.loads(got.read_text())
    assert d["returncode"] == 0, d["stderr"]
    assert d["url"].startswith("ws://127.0.0.1:"), d["url"]
    assert d["subprotocol"] == "foxglove.sdk.v1"
    assert d["serverInfo"]["name"] == "agrisim" and "time" in d["serverInfo"]["capabilities"]
    # Several messages of a topic may share a log time (/tf: odometry and robot links).
    recorded: dict[str, dict[int, set[bytes]]] = {}
    schemas: dict[str, tuple[str, str, str]] = {}
    with open(out / "run.mcap", "rb") as f:
        for schema, channel, m in make_reader(f).iter_messages():
            recorded.setdefault(channel.topic, {}).setdefault(m.log_time, set()).add(m.data)
            schemas[channel.topic] = (schema.name, schema.encoding, schema.data.decode())
    for topic in topics:
        ch = d["channels"][topic]
        assert ch["encoding"] == "cdr" and ch["schemaEncoding"] == "ros2msg"
        assert (ch["schemaName"], ch["schemaEncoding"], ch["schema"]) == schemas[topic], topic
        msgs = d["messages"][topic]
        # The view runs at message instants (10 Hz); the MCAP has /clock at every step too.
        expected = [t for t in recorded[topic] if topic != "/clock" or t % 100_000_000 == 0]
        # The client joins a moment after the start; from then on it sees every message.
        assert len(msgs) >= len(expected) // 2, (topic, len(msgs), len(expected))
        for t, payload in msgs:
            assert bytes.fromhex(payload) in recorded[topic][t], (topic, t)
    # Time frames carry simulated time, not the wall clock.
    assert d["time"] and max(d["time"]) <= 4_000_000_000 and d["time"] == sorted(d["time"])


def test_layout_names_topics_the_runs_publish():
    """assets/foxglove_layout.json: every panel's topic is one the sensor-suite system
    routes or a built-in node publishes, and every message path names a real field."""
    layout = json.loads((HERE.parent / "assets/foxglove_layout.json").read_text())
    import agrisim

    topics = dict(agrisim.Simulation("sensors").topics())
    topics.update({"/map": "nav_msgs/msg/OccupancyGrid", "/plan": "nav_msgs/msg/Path", "/localization/pose": "geometry_msgs/msg/PoseStamped", "/goal_pose": "geometry_msgs/msg/PoseStamped", "/navigate/status": "agrisim_msgs/msg/NavigationStatus"})
    # The viewer topics of `agrisim run` (robot_state_publisher and the scene view) and the
    # perception node's world-frame detections.
    topics.update({"/robot_description": "std_msgs/msg/String", "/joint_states": "sensor_msgs/msg/JointState", "/scene/markers": "visualization_msgs/msg/MarkerArray", "/scene/fruit_markers": "visualization_msgs/msg/MarkerArray", "/perception/detections_world": "vision_msgs/msg/Detection3DArray"})
    cfg = layout["configById"]
    layers = cfg["3D!robot"]["layers"].values()
    used = set(cfg["3D!robot"]["topics"]) | {l["topic"] for l in layers if l.get("sourceType") == "topic"} | {cfg["Image!rgb"]["imageMode"]["imageTopic"], cfg["Image!rgb"]["imageMode"]["calibrationTopic"], cfg["Image!depth"]["imageMode"]["imageTopic"], cfg["RawMessages!status"]["topicPath"]}
    assert used <= set(topics), used - set(topics)
    # The 3-D view opens on the greenhouse and the robot model.
    assert {"/scene/markers", "/scene/fruit_markers", "/robot_description", "/points", "/plan"} <= set(cfg["3D!robot"]["topics"])
    assert any(l["layerId"] == "foxglove.Urdf" and l.get("topic") == "/robot_description" for l in layers)
    for panel in ("Plot!odom", "Plot!collision"):
        for p in cfg[panel]["paths"]:
            topic, *path = p["value"].split(".")
            msg = agrisim.decode(topics[topic], agrisim.encode(topics[topic], {}))
            for name in path:
                assert name in msg, (p["value"], name)
                msg = msg[name]


def test_a_late_client_gets_the_robot_and_the_greenhouse(tmp_path):
    """The latched viewer topics are published at t = 0, before any client subscribes; the
    view sends a client that subscribes later their last message (as DDS transient local
    does; here: again every simulated second), byte-equal to the recording. Paced by `--realtime` alone, with no bridge (whether
    the pace is right is a unit test of agrisim-nodes' Pace with its clock given in)."""
    out, got = tmp_path / "run", tmp_path / "client.json"
    cmd = [str(agrisim_bin()), "run", "--duration", "2.5", "--record", "standard", "--realtime", "--foxglove", "127.0.0.1:0", "--out", str(out)]
    topics = ["/robot_description", "/scene/markers", "/scene/fruit_markers"]
    argv = [sys.executable, str(HERE / "foxglove_client.py"), "--out", str(got)] + [x for t in topics for x in ("--topic", t)] + ["--", *cmd]
    r = netns.run(argv, timeout=120, capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    d = json.loads(got.read_text())
    assert d["returncode"] == 0, d["stderr"]
    recorded: dict[str, list[bytes]] = {}
    with open(out / "run.mcap", "rb") as f:
        for _, channel, m in make_reader(f).iter_messages():
            recorded.setdefault(channel.topic, []).append(m.data)
    for topic in ["/robot_description", "/scene/markers", "/scene/fruit_markers"]:
        assert len(recorded[topic]) == 1, topic
        msgs = d["messages"].get(topic, [])
        assert msgs, f"{topic}: the late client got nothing"
        assert {bytes.fromhex(p) for _, p in msgs} == {recorded[topic][0]}, topic
