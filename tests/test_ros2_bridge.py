"""The live ROS 2 link (`--ros2`) against an independent DDS implementation: Eclipse Cyclone
DDS (the `cyclonedds` Python package) with ROS 2 type names and QoS, in a private network
namespace with only loopback (tests/netns.py), bounded in time.

* An external navigator (tests/ros2_external_nav.py) replaces the built-in one
  (`--external navigator`) and drives the robot to the nav benchmark's goal in lockstep; the
  harness scores it from messages and ground truth. The point clouds it received are
  byte-equal to the recorded ones, and a second run records the very same MCAP.
* An external harvest node in Python (agrisim.Node("harvest") in its own process) replaces
  the built-in one (`--external harvest`); the harvest harness scores the trial.
* Camera images and camera info received by a Cyclone DDS subscriber equal the recording.
* Garbage and wrongly typed messages on /cmd_vel and on an arm trajectory topic, and a NaN
  on the scalar lift set-point, are rejected and reported (topic, sender, reason); the run
  goes on. Scalars cross as std_msgs/Float64 in both directions.
* The bridge is a node of the ROS 2 graph: its `ros_discovery_info` names node /agrisim with
  exactly the readers and writers DDS discovery shows for it, in the Humble and the Jazzy
  layout.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import netns
from conftest import REPO, agrisim_bin, decoded_messages
from scenario_variant import write_variant

PY = sys.executable
HERE = Path(__file__).parent

pytestmark = pytest.mark.skipif(netns.available() is not None, reason=str(netns.available()))


@pytest.fixture(scope="module")
def exact_odometry(tmp_path_factory) -> Path:
    """The default greenhouse with noise-free wheel odometry: the external navigator follows
    odometry alone (it has no localizer), and this test is about the link, not drift."""
    d = tmp_path_factory.mktemp("ros2-scenario")
    path = write_variant(REPO / "models/scenarios/default.toml", d, "")
    text = path.read_text()
    for old, new in [("enc_noise = 0.05", "enc_noise = 0.0"), ("steer_noise = 0.002", "steer_noise = 0.0"), ("slip_mean = 0.01", "slip_mean = 0.0"), ("slip_std = 0.02", "slip_std = 0.0")]:
        assert old in text
        text = text.replace(old, new)
    path.write_text(text)
    return path


def external_nav_trial(scenario: Path, out: Path, clouds: Path, link: tuple[str, ...] = ("--ros2",), peer: tuple[str, ...] = ()) -> subprocess.CompletedProcess:
    """The nav trial with tests/ros2_external_nav.py as its navigator, over the `link` options
    (DDS by default; `peer` tells the navigator how to reach it)."""
    cmd = [str(agrisim_bin()), "bench", "nav", "--scenario", str(scenario), "--trials", "1", "--seed", "3", "--record", "standard", "--in-process", *link, "--external", "navigator", "--out", str(out)]
    return netns.run([PY, str(HERE / "ros2_external_nav.py"), *peer, "--clouds", str(clouds), "--", *cmd], timeout=300, capture_output=True, text=True)


def assert_navigator_judged(r: subprocess.CompletedProcess, out: Path) -> None:
    """The harness judged the external node: success needs its 'succeeded' status and the true
    base centre within the goal tolerance; every tick answered in time, nothing rejected."""
    assert r.returncode == 0, r.stdout + r.stderr
    report = json.loads(r.stdout.strip().splitlines()[-1])
    trial = json.loads((out / "trials.jsonl").read_text())
    assert trial["outcome"] == "success", trial
    assert trial["time_to_goal"] > 10.0 and trial["path_length"] > 5.0
    assert report["ticks"] == round(trial["sim_time"] / 0.1) + 1
    assert "0 rejected, 0 lockstep timeouts" in r.stderr, r.stderr


def test_external_navigator_over_cyclone_dds(exact_odometry, tmp_path):
    r = external_nav_trial(exact_odometry, tmp_path / "a", tmp_path / "clouds.json")
    assert_navigator_judged(r, tmp_path / "a")
    # The clouds that crossed DDS are the recorded ones, byte for byte (CDR header included).
    received = {k: bytes.fromhex(v) for k, v in json.loads((tmp_path / "clouds.json").read_text()).items()}
    recorded = decoded_messages(tmp_path / "a/trials/0000.mcap", "/points")
    assert len(recorded) >= 5
    raw = {}
    from mcap.reader import make_reader

    with open(tmp_path / "a/trials/0000.mcap", "rb") as f:
        for _, channel, m in make_reader(f).iter_messages(topics=["/points"]):
            raw[m.log_time] = m.data
    compared = 0
    for _, log_time, msg in recorded:
        key = f"{msg.header.stamp.sec}.{msg.header.stamp.nanosec:09d}"
        if key in received:
            assert received[key] == raw[log_time], key
            compared += 1
    assert compared >= len(recorded) - 1, (compared, len(recorded))
    # Lockstep with a deterministic peer is deterministic: the same MCAP again.
    r2 = external_nav_trial(exact_odometry, tmp_path / "b", tmp_path / "clouds2.json")
    assert r2.returncode == 0, r2.stderr
    assert (tmp_path / "a/trials/0000.mcap").read_bytes() == (tmp_path / "b/trials/0000.mcap").read_bytes()


def test_malformed_messages_are_rejected_and_the_run_goes_on(tmp_path):
    out = tmp_path / "run"
    cmd = [str(agrisim_bin()), "run", "--scenario", str(REPO / "models/scenarios/harvest.toml"), "--duration", "4", "--record", "standard", "--ros2", "--external", "command_script", "--out", str(out)]
    r = netns.run([PY, str(HERE / "ros2_bad_peer.py"), "--", *cmd], timeout=180, capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    peer = json.loads(r.stdout.strip().splitlines()[-1])
    assert peer["returncode"] == 0
    err = r.stderr
    # Reported with topic, sender and reason, on stderr and in the run's status log.
    assert "ROS 2 bridge: topic /cmd_vel from writer" in err and "not a valid geometry_msgs/msg/Twist" in err, err
    assert "ROS 2 bridge: topic /left_arm/joint_trajectory from writer" in err and "not a valid trajectory_msgs/msg/JointTrajectory" in err, err
    statuses = [m.message for _, _, m in decoded_messages(out / "run.mcap", "/agrisim/status")]
    assert sum("ROS 2 bridge" in s and "rejected" in s for s in statuses) == peer["bad_sent"]
    assert f"{peer['bad_sent']} rejected" in err
    # The NaN command passed the type check and the chassis refused it (its own rule).
    assert any("chassis" in s or "cmd_vel" in s for s in statuses if "NaN" in s or "finite" in s), statuses
    # The valid commands before and after drove the base: the run went on to the end.
    cmds = decoded_messages(out / "run.mcap", "/cmd_vel")
    assert len(cmds) == peer["good_sent"]
    # Scalars cross as std_msgs/Float64 both ways: the set-point raised the lift, whose
    # position the peer saw rise from 0.2 m to 0.4 m; the NaN set-point was refused and the
    # lift held 0.4 m.
    assert "scalar /lift/setpoint from writer" in err and "not a finite number" in err, err
    lift = peer["lift_positions"]
    assert abs(lift[0] - 0.2) < 1e-9 and abs(lift[-1] - 0.4) < 1e-3 and len(set(lift)) > 5, lift
    odom = decoded_messages(out / "run.mcap", "/odom")
    assert odom[-1][1] >= 3.9e9
    assert odom[-1][2].pose.pose.position.x - odom[0][2].pose.pose.position.x > 0.3


def test_external_harvest_node_in_python(tmp_path):
    """agrisim's harvest node run in a separate Python process (`agrisim.Node`) on the far
    side of the link replaces the built-in one (`--external harvest`): it learns its fruit
    from /harvest/task, gets joint states, statuses, the planning scene, the target and the
    lift position over DDS, and sends trajectories, gripper commands and the lift set-point
    back. The harvest harness scores the trial from messages and ground truth."""
    scenario = write_variant(REPO / "models/scenarios/harvest.toml", tmp_path, '[harvest]\nvisibility = ["free"]\n')
    out = tmp_path / "out"
    cmd = [str(agrisim_bin()), "bench", "harvest", "--scenario", str(scenario), "--trials", "1", "--seed", "1", "--record", "judge", "--in-process", "--ros2", "--external", "harvest", "--out", str(out)]
    r = netns.run([PY, str(HERE / "ros2_external_harvest.py"), "--", *cmd], timeout=300, capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    peer = json.loads(r.stdout.strip().splitlines()[-1])
    assert peer["task_received"] and peer["returncode"] == 0 and peer["sent"] > 20, peer
    assert "0 rejected, 0 lockstep timeouts" in r.stderr, r.stderr
    trial = json.loads((out / "trials.jsonl").read_text())
    assert trial["outcome"] == "success", trial
    assert trial["planning"] == "ok" and trial["plans"] >= 3 and trial["placed_count"] == 1
    # The judge saw the node's messages only: its plans and statuses came over DDS.
    statuses = decoded_messages(out / "trials/0000.mcap", "/harvest/status")
    assert any(m.outcome == "success" for _, _, m in statuses)
    # Across the link, in lockstep, the node harvests the same fruit as the built-in node on
    # the same trial. Its course is not the same: the far side's plans report different work
    # (not yet explained, see the README), so its base stops at another instant and another
    # localized pose; on this trial the built-in node now misses the fruit twice and takes it
    # on the third aim (13 plans, 40.0 s), the far side at once (9 plans). Each missed grasp
    # costs two plans (back off, approach again) and a few seconds, so the plans may differ by
    # two per regrasp and the instants by 5 s per regrasp.
    inside = tmp_path / "inside"
    subprocess.run([str(agrisim_bin()), "bench", "harvest", "--scenario", str(scenario), "--trials", "1", "--seed", "1", "--record", "judge", "--in-process", "--out", str(inside)], check=True, capture_output=True, timeout=300)
    builtin = json.loads((inside / "trials.jsonl").read_text())
    for key in ["outcome", "placed_count", "fruit_index"]:
        assert trial[key] == builtin[key], (key, trial[key], builtin[key])
    def regrasps_of(d):
        # Entries into the regrasp stage (the far side publishes a status every tick).
        stages = [m.stage for _, _, m in decoded_messages(d / "trials/0000.mcap", "/harvest/status")]
        return sum(1 for a, b in zip([""] + stages, stages) if b == "regrasp" and a != "regrasp")
    regrasps = [regrasps_of(out), regrasps_of(inside)]
    assert trial["plans"] - 2 * regrasps[0] == builtin["plans"] - 2 * regrasps[1], (trial["plans"], builtin["plans"], regrasps)
    assert abs(trial["time_to_harvest"] - builtin["time_to_harvest"]) <= 2.0 + 5.0 * sum(regrasps), (trial["time_to_harvest"], builtin["time_to_harvest"], regrasps)


def test_camera_images_over_dds_equal_the_recording(tmp_path):
    """The full sensor suite's images (RGB, aligned depth, labels) and camera info, received
    by a Cyclone DDS subscriber, are byte-equal to what the MCAP recorded (a small camera
    keeps the best-effort images unfragmented enough to arrive)."""
    scenario = write_variant(REPO / "models/scenarios/sensors.toml", tmp_path, "[parameters.camera]\nwidth = 64\nheight = 48\n")
    out, got = tmp_path / "run", tmp_path / "got.json"
    topics = {"/camera/color/image_raw": "sensor_msgs/msg/Image", "/camera/aligned_depth_to_color/image_raw": "sensor_msgs/msg/Image", "/camera/labels": "sensor_msgs/msg/Image", "/camera/color/camera_info": "sensor_msgs/msg/CameraInfo"}
    cmd = [str(agrisim_bin()), "run", "--scenario", str(scenario), "--duration", "2", "--record", "full", "--ros2", "--external", "command_script", "--out", str(out)]
    argv = [PY, str(HERE / "ros2_sensor_peer.py"), "--out", str(got)] + [x for t, ty in topics.items() for x in ("--topic", f"{t}={ty}")] + ["--", *cmd]
    r = netns.run(argv, timeout=300, capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    received = json.loads(got.read_text())
    from mcap.reader import make_reader

    recorded: dict[str, set[bytes]] = {}
    with open(out / "run.mcap", "rb") as f:
        for _, channel, m in make_reader(f).iter_messages(topics=list(topics)):
            recorded.setdefault(channel.topic, set()).add(bytes(m.data))
    for topic in topics:
        samples = [bytes.fromhex(h) for h in received[topic]]
        assert len(samples) >= len(recorded[topic]) - 2 > 10, (topic, len(samples), len(recorded[topic]))
        # DDS pads a sample to 4 bytes; the message is the recorded bytes.
        for s in samples:
            assert any(s == rec or (s.startswith(rec) and len(s) - len(rec) < 4 and not s[len(rec):].strip(b"\0")) for rec in recorded[topic]), topic


@pytest.mark.parametrize("distro", ["jazzy", "humble"])
def test_the_bridge_is_a_node_of_the_ros2_graph(tmp_path, distro):
    cmd = [str(agrisim_bin()), "run", "--scenario", str(REPO / "models/scenarios/default.toml"), "--duration", "2", "--record", "judge",
           "--ros2", "--ros2-mode", "realtime", "--ros2-rate", "4", "--ros2-distro", distro, "--out", str(tmp_path / "run")]
    r = netns.run([PY, str(HERE / "ros2_graph_peer.py"), "--distro", distro, "--", *cmd], timeout=120, capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    peer = json.loads(r.stdout.strip().splitlines()[-1])
    assert peer["returncode"] == 0, r.stderr
    # One participant announced, holding the one node /agrisim.
    (participant, nodes), = peer["nodes"].items()
    assert [(n["namespace"], n["name"]) for n in nodes] == [("/", "agrisim")]
    # Gids: the 16-byte DDS GUID, zero-padded to 24 bytes in the Humble layout.
    width = 48 if distro == "humble" else 32
    gids = [participant, *nodes[0]["readers"], *nodes[0]["writers"]]
    assert all(len(g) == width and g[32:] == "0" * (width - 32) for g in gids), gids
    guid = lambda g: g[:32]  # noqa: E731
    # Exactly the endpoints DDS discovery shows for that participant (the graph topic's own
    # writer is the participant's, not the node's).
    mine = {k: e for k, e in peer["endpoints"].items() if e["participant"] == guid(participant) and e["topic"] != "ros_discovery_info"}
    assert {guid(g) for g in nodes[0]["writers"]} == {k for k, e in mine.items() if e["kind"] == "writer"}
    assert {guid(g) for g in nodes[0]["readers"]} == {k for k, e in mine.items() if e["kind"] == "reader"}
    topics = {(e["kind"], e["topic"]) for e in mine.values()}
    assert {("writer", "rt/clock"), ("writer", "rt/odom"), ("writer", "rt/points"), ("reader", "rt/cmd_vel")} <= topics, topics


@pytest.mark.parametrize("all_interfaces", [False, True])
def test_the_bridge_hears_only_this_machine_unless_asked(tmp_path, all_interfaces):
    """A host on a LAN (another namespace, joined by a veth pair) sends a datagram to each of
    the bridge's well-known DDS ports. By default the kernel drops all four at the bridge's
    sockets (their filter takes only what came in through the loopback device), while the
    same datagrams from this machine, to its loopback address or to its LAN address, are
    taken; with --ros2-all-interfaces the LAN's are taken too (the probe can tell)."""
    cmd = [str(agrisim_bin()), "run", "--scenario", str(REPO / "models/scenarios/default.toml"), "--duration", "8", "--record", "none",
           "--ros2", "--ros2-mode", "realtime", "--ros2-rate", "1", "--out", str(tmp_path / "run")]
    cmd += ["--ros2-all-interfaces"] if all_interfaces else []
    r = netns.run([PY, str(HERE / "ros2_lan_probe.py"), "--", *cmd], timeout=120, capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    seen = json.loads(r.stdout.strip().splitlines()[-1])
    assert seen["returncode"] == 0, seen["stderr"]
    assert len(seen["sockets"]) >= 5, seen["sockets"]
    # Every port has a socket: nothing is refused, whatever the origin.
    assert all(set(seen[o]["ports"].values()) == {"sent"} for o in ("lan", "local", "loopback")), seen
    assert seen["local"]["drops"] == 0 and seen["loopback"]["drops"] == 0, seen
    assert seen["lan"]["drops"] == (0 if all_interfaces else 4), seen


# What rmw_cyclonedds (ROS 2 Jazzy, rmw_node.cpp check_create_domain) gives Cyclone DDS for
# ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST: no multicast, localhost as the one static peer.
# Cyclone then selects the LAN interface and takes discovery packets only if they come in
# addressed to it (the machine's LAN address); what comes to 127.0.0.1 it drops unlogged.
JAZZY_LOCALHOST = ("<CycloneDDS><Domain><General><AllowMulticast>false</AllowMulticast></General><Discovery><ParticipantIndex>auto</ParticipantIndex>"
                   "<MaxAutoParticipantIndex>32</MaxAutoParticipantIndex><Peers><Peer address=\"localhost\"/></Peers></Discovery></Domain></CycloneDDS>")


@pytest.mark.parametrize("order", ["after", "before"])
def test_a_jazzy_localhost_node_finds_the_bridge(tmp_path, order):
    """A ROS 2 Jazzy node with ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST on a machine with a LAN
    interface (Cyclone DDS configured as rmw_cyclonedds configures it) sees the bridge's node,
    whether it starts while the simulation runs ("after") or before it ("before"). After: its
    packets to the LAN address reach the bridge (they come in through the loopback device)
    and the bridge answers there. Before: its own announcements went out before the bridge
    existed, and it hears the bridge only through the announcements the bridge repeats to
    the LAN address (orchestrator/ros2/src/announce.rs)."""
    cmd = [str(agrisim_bin()), "run", "--scenario", str(REPO / "models/scenarios/default.toml"), "--duration", "6", "--record", "none",
           "--ros2", "--ros2-mode", "realtime", "--ros2-rate", "1", "--out", str(tmp_path / "run")]
    env = dict(os.environ, CYCLONEDDS_URI=JAZZY_LOCALHOST)
    peer_args = ["--lan", "10.77.0.1/24"] + (["--after-bridge"] if order == "after" else [])
    r = netns.run([PY, str(HERE / "ros2_graph_peer.py"), *peer_args, "--", *cmd], timeout=120, capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stdout + r.stderr
    peer = json.loads(r.stdout.strip().splitlines()[-1])
    assert peer["returncode"] == 0, r.stderr
    assert [(n["namespace"], n["name"]) for nodes in peer["nodes"].values() for n in nodes] == [("/", "agrisim")], peer["nodes"]
    assert any(e["topic"] == "rt/clock" for e in peer["endpoints"].values()), peer["endpoints"]
