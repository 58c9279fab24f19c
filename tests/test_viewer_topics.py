"""The viewer topics of `agrisim run` (see docs/reference/formats.md, "Viewer topics"), read from
the recorded MCAP by decoders no one here wrote (mcap-ros2-support, rosbags):

* /robot_description: the URDF (std_msgs/String), once, latched; a valid URDF with only
  primitives, so a viewer needs no files;
* /joint_states: every movable joint (wheels, steering, lift, both arms, fingers);
* /tf + /tf_static: every URDF link reachable from base_link, and base_link from map (map ->
  odom fixed at the start: no localizer), placing the robot at its start pose;
* /scene/markers and /scene/fruit_markers: the greenhouse as instanced MarkerArrays, the
  fruit where the world's ground truth (/fruits) puts them, under 2 MB;
* the recording profiles keep them; and no algorithm node reads the scene markers.
"""

from __future__ import annotations

import bisect
import math
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
import zstandard
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

from conftest import REPO, run_agrisim

SCENARIO = REPO / "models" / "scenarios" / "default.toml"
URDF = REPO / "models" / "robot" / "agrisim_robot.urdf"
VIEWER = ["/robot_description", "/scene/markers", "/scene/fruit_markers"]
# visualization_msgs/Marker types.
LINE_LIST, SPHERE_LIST, TRIANGLE_LIST = 5, 7, 11


def run(out: Path, *extra: str) -> Path:
    run_agrisim("run", "--scenario", str(SCENARIO), "--out", str(out), *extra)
    return out / "run.mcap"


@pytest.fixture(scope="module")
def mcap_file(tmp_path_factory) -> Path:
    return run(tmp_path_factory.mktemp("viewer"), "--duration", "0.5", "--record", "standard")


@pytest.fixture(scope="module")
def messages(mcap_file):
    """topic -> [(log time, decoded message, raw bytes)], and topic -> channel."""
    out, channels = {}, {}
    with open(mcap_file, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for _, channel, message, ros_msg in reader.iter_decoded_messages():
            out.setdefault(channel.topic, []).append((message.log_time, ros_msg, message.data))
            channels[channel.topic] = channel
    return out, channels


def test_robot_description_is_the_urdf_once_and_latched(messages):
    msgs, channels = messages
    assert len(msgs["/robot_description"]) == 1
    t, m, _ = msgs["/robot_description"][0]
    assert t == 0
    assert m.data == URDF.read_text()
    robot = ET.fromstring(m.data)
    assert robot.tag == "robot"
    links = {l.get("name") for l in robot.findall("link")}
    for j in robot.findall("joint"):
        assert j.find("parent").get("link") in links and j.find("child").get("link") in links
    # Primitives only: nothing a viewer would have to find on disk.
    assert robot.findall(".//mesh") == [] and "package://" not in m.data and "file://" not in m.data
    assert robot.findall(".//collision/geometry")
    for topic in VIEWER:
        assert "durability: 1" in channels[topic].metadata["offered_qos_profiles"], topic  # transient local
    assert "durability: 2" in channels["/odom"].metadata["offered_qos_profiles"]  # volatile


def test_joint_states_and_tf_cover_the_whole_robot(messages):
    msgs, _ = messages
    robot = ET.fromstring(URDF.read_text())
    movable = [j.get("name") for j in robot.findall("joint") if j.get("type") != "fixed"]
    states = msgs["/joint_states"]
    assert [t for t, _, _ in states] == [k * 100_000_000 for k in range(5)]  # nodes run at 10 Hz, t = 0 .. 0.4 s
    for _, m, _ in states:
        assert sorted(m.name) == sorted(movable) and len(m.position) == len(movable)
    for j in ("front_left_steer_joint", "rear_right_drive_joint", "lift_joint", "left_joint1", "right_joint7", "left_finger_joint1"):
        assert j in movable
    parent = {}
    for topic in ("/tf", "/tf_static"):
        for _, m, _ in msgs[topic]:
            for tr in m.transforms:
                parent[tr.child_frame_id] = tr.header.frame_id
    assert parent["base_link"] == "odom"
    for link in robot.findall("link"):
        frame, hops = link.get("name"), 0
        while frame != "base_link":
            assert frame in parent, f"no transform to {frame}"
            frame, hops = parent[frame], hops + 1
            assert hops < 50



def _yaw(q) -> float:
    return math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y**2 + q.z**2))


def test_tf_tree_joins_map_to_base_link_at_the_start_pose(mcap_file, messages):
    """A plain run has no localizer: map -> odom is published once, on /tf_static, and odom
    has no other parent; with the first odom -> base_link it puts the robot at the chassis's
    start pose (x0, y0, yaw0 as applied) in the map, where the greenhouse markers are drawn
    (the odometry starts at that pose in map coordinates: map -> odom is then the identity,
    not the start pose again)."""
    msgs, _ = messages
    with open(mcap_file, "rb") as f:
        params = {m.name: m.metadata for m in make_reader(f).iter_metadata() if m.name.startswith("agrisim.parameters.")}
    starts = [p for p in params.values() if {"x0", "y0", "yaw0"} <= p.keys()]
    assert len(starts) == 1, f"one component with a start pose: {params}"
    x0, y0, yaw0 = (float(starts[0][k]) for k in ("x0", "y0", "yaw0"))
    odom_parents = [(topic, tr) for topic in ("/tf", "/tf_static") for _, m, _ in msgs[topic] for tr in m.transforms if tr.child_frame_id == "odom"]
    assert [(topic, tr.header.frame_id) for topic, tr in odom_parents] == [("/tf_static", "map")]
    mo = odom_parents[0][1].transform
    assert mo.translation.z == 0.0
    first = min(((t, tr) for t, m, _ in msgs["/tf"] for tr in m.transforms if tr.child_frame_id == "base_link"), key=lambda x: x[0])[1]
    assert first.header.frame_id == "odom"
    ob = first.transform
    a, b = _yaw(mo.rotation), _yaw(ob.rotation)
    x = mo.translation.x + math.cos(a) * ob.translation.x - math.sin(a) * ob.translation.y
    y = mo.translation.y + math.sin(a) * ob.translation.x + math.cos(a) * ob.translation.y
    assert (x, y) == pytest.approx((x0, y0), abs=1e-6), f"map -> base_link at the start ({x}, {y}), start pose ({x0}, {y0})"
    assert math.remainder(a + b - yaw0, 2 * math.pi) == pytest.approx(0.0, abs=1e-6)
    parent = {tr.child_frame_id: tr.header.frame_id for topic in ("/tf", "/tf_static") for _, m, _ in msgs[topic] for tr in m.transforms}
    frame, chain = "base_link", ["base_link"]
    while frame in parent and len(chain) < 50:
        frame = parent[frame]
        chain.append(frame)
    assert chain == ["base_link", "odom", "map"]


def _points(marker):
    return [(p.x, p.y, p.z) for p in marker.points]


def test_scene_markers_are_instanced_and_match_the_world(messages):
    msgs, _ = messages
    (t, scene, raw), = msgs["/scene/markers"]  # once
    assert t == 0
    assert len(raw) < 2_000_000, len(raw)
    by_ns = {}
    for k in scene.markers:
        assert k.header.frame_id == "map" and k.action == 0
        by_ns.setdefault(k.ns, []).append(k)
        per = {TRIANGLE_LIST: 3, LINE_LIST: 2, SPHERE_LIST: 1}[k.type]
        assert len(k.points) % per == 0 and k.points
    assert {"floor", "walls", "posts", "gutters", "pipes", "stems", "leaves", "trusses"} <= set(by_ns)
    assert len(scene.markers) <= 16  # one per kind and width, not one per leaf
    assert {k.type for k in by_ns["leaves"]} == {TRIANGLE_LIST}
    assert {k.type for k in by_ns["stems"]} == {LINE_LIST}
    stems = [p for k in by_ns["stems"] for p in _points(k)]
    # A stem is a vertical segment from the floor up.
    bases = stems[0::2]
    assert all(a[:2] == b[:2] and a[2] < b[2] for a, b in zip(stems[0::2], stems[1::2]))
    # The default greenhouse: 6 active rows of plants (scenario), each along a line of posts.
    ys = sorted(y for _, y, _ in bases)
    rows = [[ys[0]]]
    for y in ys[1:]:
        if y - rows[-1][-1] > 0.5:
            rows.append([])
        rows[-1].append(y)
    assert len(rows) == 6
    post_rows = {p[1] for k in by_ns["posts"] for p in _points(k)}
    for r in rows:
        assert min(abs(sum(r) / len(r) - y) for y in post_rows) < 0.3
    # The fruit: as many as the world reports on /fruits, where it reports them, by stage.
    (_, fruit, fraw), = msgs["/scene/fruit_markers"]
    assert len(raw) + len(fraw) < 2_000_000
    # What they add to a recording (zstd level 1, as the recorder's chunks): 74 kB for the
    # default greenhouse (docs/reference/formats.md; 105 kB on a 2 mm grid).
    packed = sum(len(zstandard.ZstdCompressor(level=1).compress(b)) for b in (raw, fraw))
    assert packed < 80_000, packed
    assert {k.ns for k in fruit.markers} == {"fruit"} and {k.type for k in fruit.markers} == {SPHERE_LIST}
    assert {k.id for k in fruit.markers} <= set(range(1, 7)) and len(fruit.markers) >= 3
    red = max(fruit.markers, key=lambda k: k.id)
    assert red.color.r > 2 * red.color.g  # the ripest stage is red
    green = min(fruit.markers, key=lambda k: k.id)
    assert green.color.g > green.color.r
    world = msgs["/fruits"][0][1]
    truth = sorted((p.position.x, p.position.y, p.position.z) for p in world.poses)
    drawn = sorted(p for k in fruit.markers for p in _points(k))
    assert len(drawn) == len(truth) > 100
    # Every world fruit has a drawn sphere within half the markers' grid (1/128 m) on each
    # axis, one to one.
    tol = 1 / 256 + 1e-9
    xs = [d[0] for d in drawn]
    used = set()
    for w in truth:
        lo, hi = bisect.bisect_left(xs, w[0] - tol), bisect.bisect_right(xs, w[0] + tol)
        near = [i for i in range(lo, hi) if i not in used and max(abs(a - b) for a, b in zip(drawn[i], w)) <= tol]
        assert near, w
        used.add(near[0])


def test_rosbags_decodes_the_viewer_topics(mcap_file):
    from rosbags.highlevel import AnyReader

    seen = {}
    with AnyReader([mcap_file]) as reader:
        conns = [c for c in reader.connections if c.topic in VIEWER + ["/joint_states"]]
        for conn, _, raw in reader.messages(connections=conns):
            seen[conn.topic] = reader.deserialize(raw, conn.msgtype)
    assert seen["/robot_description"].data.startswith("<?xml") or "<robot" in seen["/robot_description"].data
    assert sum(len(k.points) for k in seen["/scene/fruit_markers"].markers) > 100
    assert len(seen["/scene/markers"].markers) >= 8


def test_judge_profile_keeps_the_viewer_topics(tmp_path):
    path = run(tmp_path / "judge", "--duration", "0.2", "--record", "judge")
    with open(path, "rb") as f:
        counts = {}
        for _, channel, _ in make_reader(f).iter_messages():
            counts[channel.topic] = counts.get(channel.topic, 0) + 1
    assert {t: counts.get(t) for t in VIEWER} == {t: 1 for t in VIEWER}
    assert "/points" not in counts and "/joint_states" not in counts


# Algorithm crates: they read messages only, and never the scene markers (ground truth drawn
# for people). Their sources must not name the viewer topics of the scene.
ALGORITHM_CRATES = ["nodes", "nav", "harvest", "manip", "trajectory", "perception", "mapping"]
SCENE_TOPIC = re.compile(r'"/scene/|SCENE_MARKERS|FRUIT_MARKERS|SceneView')


def scene_readers(root: Path) -> list[str]:
    found = []
    for crate in ALGORITHM_CRATES:
        for f in sorted((root / "orchestrator" / crate).rglob("*.rs")):
            for n, line in enumerate(f.read_text().splitlines(), 1):
                if SCENE_TOPIC.search(line):
                    found.append(f"{f.relative_to(root)}:{n}: {line.strip()}")
    return found


def test_no_algorithm_node_reads_the_scene_markers(tmp_path):
    assert scene_readers(REPO) == []
    # The check can fail: a navigator that subscribes to the markers.
    fake = tmp_path / "orchestrator" / "nav" / "src"
    fake.mkdir(parents=True)
    (fake / "cheat.rs").write_text('let m = bus.take_new::<MarkerArray>("/scene/markers", &mut seen)?;\n')
    assert scene_readers(tmp_path) == [f"orchestrator/nav/src/cheat.rs:1: {(fake / 'cheat.rs').read_text().strip()}"]
