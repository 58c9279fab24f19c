"""The layer rules of the workspace, read from `cargo metadata`: which crate may depend on
which (normal dependencies, followed transitively through the workspace).

  fmus/ (environment, robot, sensors)  <-  orchestrator/cosim (engine)
  orchestrator/bus (messages)  <-  algorithm nodes (nodes, nav, manip, trajectory, harvest, perception)
  session (engine + bus)  <-  bench  <-  cli, python (the pyo3 package; siblings on top)
  bus  <-  bridges (link: what the ROS 2 links share; ros2: DDS; zenoh: Zenoh; foxglove: WebSocket):
           they carry messages, like a node

The engine and the message layer do not know each other; algorithms never link the engine,
the FMU export layer or scene generation, so any of them can be swapped for a ROS 2 node.

Which crates are FMUs is read from their Cargo.toml (`[package.metadata.agrisim] fmu = "<Id>"`,
packages[].metadata in `cargo metadata`), never from their names; the FMU crates sit in
fmus/<name>, the libraries they share in fmus/lib/<name>, and the markers must agree with that.
"""
import json
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

ALGORITHMS = {"agrisim-nodes", "agrisim-nav", "agrisim-harvest", "agrisim-manip", "agrisim-trajectory", "agrisim-perception", "agrisim-mapping"}
# The perception node sees images, depth, CameraInfo and TF only: besides the algorithm rule,
# it must reach no FMU crate at all (the world, the camera: their ground truth).
PERCEPTION = "agrisim-perception"
# The depth mapper (the sensed collision scene) likewise: depth, CameraInfo and TF in; the
# robot's links come from its owner, never from a world output.
MAPPING = "agrisim-mapping"
SENSING = (PERCEPTION, MAPPING)
ENGINE = "agrisim-cosim"
# The greenhouse libraries: scene generation, ray casting, sun and weather, glTF export.
SCENE = {"agrisim-scene", "agrisim-raycast", "agrisim-sky", "agrisim-gltf"}
FMI_EXPORT = "agrisim-fmi"
FMI_TESTING = "agrisim-fmi-testing"
MATH = "agrisim-math"
MESSAGES = "agrisim-msgs"
BUS = "agrisim-bus"
PYTHON = "agrisim-python"
BRIDGES = {"agrisim-link", "agrisim-ros2", "agrisim-zenoh", "agrisim-foxglove"}
ABOVE = {"agrisim-session", "agrisim-bench", "agrisim-dataset", "agrisim", PYTHON}

# crate -> crates it must not reach (directly or through other workspace crates), and why.
FORBIDDEN = {
    **{a: ({ENGINE, FMI_EXPORT} | SCENE | BRIDGES | ABOVE, "an algorithm speaks only messages (node API)") for a in ALGORITHMS},
    **{b: ({ENGINE, FMI_EXPORT} | SCENE | ALGORITHMS | ABOVE, "a bridge carries messages: no FMI, no algorithm") for b in BRIDGES},
    ENGINE: ({MESSAGES, BUS, FMI_EXPORT} | SCENE | ALGORITHMS | BRIDGES | ABOVE, "the engine knows no ROS, no greenhouse, no algorithm"),
    BUS: ({ENGINE, FMI_EXPORT} | SCENE | ALGORITHMS | BRIDGES | ABOVE, "the message layer has no FMI inside"),
    **{s: ({FMI_EXPORT, ENGINE, BUS} | ALGORITHMS | ABOVE, "the greenhouse libraries are plain libraries") for s in SCENE},
    "agrisim-session": ({"agrisim-bench", "agrisim", PYTHON, "agrisim-nav", "agrisim-harvest"} | BRIDGES, "a session runs any nodes; it picks none"),
    "agrisim-bench": ({"agrisim", PYTHON}, "the CLI and the Python package are on top"),
    PYTHON: ({"agrisim"}, "the Python package and the CLI are siblings: neither links the other"),
    MATH: ({MESSAGES}, "math links no ROS types (the Pose2 <-> message conversions live in agrisim-msgs)"),
    FMI_EXPORT: ({MESSAGES}, "the FMI export layer links no ROS types"),
}

# The FMU crates' folder, and the folder of the libraries they share inside it.
FMU_DIR = "fmus"
FMU_LIB_DIR = "fmus/lib"


def fmu_crates(metadata):
    """crate name -> FMU identifier, for the workspace crates marked as FMUs in their Cargo.toml."""
    members = set(metadata["workspace_members"])
    out = {}
    for p in metadata["packages"]:
        marker = ((p.get("metadata") or {}).get("agrisim") or {}).get("fmu")
        if p["id"] in members and marker is not None:
            out[p["name"]] = marker
    return out


def workspace_graph(metadata):
    """crate name -> set of workspace crates it depends on (normal dependencies only)."""
    members = {p["id"] for p in metadata["packages"]} & set(metadata["workspace_members"])
    names = {p["name"] for p in metadata["packages"] if p["id"] in members}
    graph = {}
    for p in metadata["packages"]:
        if p["id"] in members:
            graph[p["name"]] = {d["name"] for d in p["dependencies"] if d["kind"] is None and d["name"] in names}
    return graph


def reach(graph, start):
    """Every crate reachable from `start`, with one path to each (for the error message)."""
    paths, todo = {}, [(start, [start])]
    while todo:
        node, path = todo.pop()
        for d in sorted(graph.get(node, ())):
            if d not in paths:
                paths[d] = path + [d]
                todo.append((d, path + [d]))
    return paths


def violations(graph, fmus):
    """Broken layer rules; `fmus` names the FMU crates (from their markers)."""
    out = []
    for crate, (forbidden, why) in sorted(FORBIDDEN.items()):
        assert crate in graph, f"layer rule names {crate}, which is not a workspace crate"
        for target, path in sorted(reach(graph, crate).items()):
            if target in forbidden:
                out.append(f"{crate} depends on {target} ({' -> '.join(path)}): {why}")
    fmu_side = set(fmus) | SCENE | {FMI_EXPORT, MESSAGES}
    orchestrator = {ENGINE, BUS} | ALGORITHMS | BRIDGES | ABOVE
    for crate in sorted(fmu_side):
        for target, path in sorted(reach(graph, crate).items()):
            if target in orchestrator:
                out.append(f"{crate} depends on {target} ({' -> '.join(path)}): the FMU layer is at the bottom")
    return out


def harness_violations(metadata):
    """Crates that link the FMI test harness into a product: it is a dev-dependency only."""
    members = set(metadata["workspace_members"])
    return sorted(
        f"{p['name']} has {FMI_TESTING} as a {d['kind'] or 'normal'} dependency: it is a dev-dependency only"
        for p in metadata["packages"]
        if p["id"] in members
        for d in p["dependencies"]
        if d["name"] == FMI_TESTING and d["kind"] != "dev"
    )


def marker_violations(metadata):
    """Crates whose FMU marker disagrees with their folder: every crate in fmus/<name> is an
    FMU and says which (a non-empty identifier, each once); no other crate is marked."""
    members = set(metadata["workspace_members"])
    fmus = fmu_crates(metadata)
    out = []
    for p in metadata["packages"]:
        if p["id"] not in members:
            continue
        folder = Path(p["manifest_path"]).parent.relative_to(ROOT).as_posix()
        in_fmu_dir = folder.startswith(FMU_DIR + "/") and not folder.startswith(FMU_LIB_DIR + "/")
        marker = fmus.get(p["name"])
        if in_fmu_dir and not (isinstance(marker, str) and marker):
            out.append(f"{p['name']} ({folder}) is in {FMU_DIR}/ but has no [package.metadata.agrisim] fmu = \"<Id>\"")
        elif not in_fmu_dir and marker is not None:
            out.append(f"{p['name']} ({folder}) is marked fmu = {marker!r}, but only crates in {FMU_DIR}/<name> (not {FMU_LIB_DIR}/) are FMUs")
    ids = sorted(m for m in fmus.values() if isinstance(m, str))
    out += [f"two crates are marked fmu = {a!r}" for a, b in zip(ids, ids[1:]) if a == b]
    return out


@pytest.fixture(scope="module")
def metadata():
    return json.loads(subprocess.run(["cargo", "metadata", "--format-version", "1", "--no-deps", "--offline"], cwd=ROOT, check=True, capture_output=True, text=True).stdout)


@pytest.fixture(scope="module")
def graph(metadata):
    return workspace_graph(metadata)


@pytest.fixture(scope="module")
def fmus(metadata):
    return fmu_crates(metadata)


def test_layers_hold(graph, fmus):
    assert violations(graph, fmus) == []


def test_the_fmi_test_harness_is_a_dev_dependency_only(metadata):
    assert harness_violations(metadata) == []
    users = {p["name"] for p in metadata["packages"] for d in p["dependencies"] if d["name"] == FMI_TESTING}
    assert "agrisim-fmu-lift" in users, "the FMU crates' tests use the harness"


def test_fmu_markers_match_the_folders(metadata):
    assert marker_violations(metadata) == []


def test_every_fmu_is_marked(fmus):
    """The FMUs the packer and the SSP systems know, each marked with its modelIdentifier."""
    expected = {
        "agrisim-fmu-chassis-kinematic": "ChassisKinematic",
        "agrisim-fmu-chassis-dynamic": "ChassisDynamic",
        "agrisim-fmu-lift": "Lift",
        "agrisim-fmu-greenhouse": "Greenhouse",
        "agrisim-fmu-lidar": "Lidar",
        "agrisim-fmu-imu": "Imu",
        "agrisim-fmu-camera": "Camera",
        "agrisim-fmu-arm": "Arm",
        "agrisim-fmu-testmodel": "TestModel",
    }
    assert {k: fmus.get(k) for k in expected} == expected


def test_every_layer_crate_exists(graph):
    for crate in ALGORITHMS | BRIDGES | SCENE | {ENGINE, BUS, "agrisim-session", "agrisim-bench", "agrisim", PYTHON}:
        assert crate in graph, crate


def test_checker_catches_a_broken_rule(graph, fmus):
    """The rule check can fail: an algorithm reaching the engine through the bus is caught."""
    broken = {k: set(v) for k, v in graph.items()}
    broken[BUS].add(ENGINE)
    found = violations(broken, fmus)
    assert any(v.startswith("agrisim-nav depends on agrisim-cosim (agrisim-nav -> agrisim-bus -> agrisim-cosim)") for v in found), found
    broken = {k: set(v) for k, v in graph.items()}
    broken["agrisim-scene"].add(FMI_EXPORT)
    found = violations(broken, fmus)
    # Every greenhouse library over the scene inherits the break.
    for lib in SCENE - {"agrisim-sky"}:
        assert any(v.startswith(f"{lib} depends on agrisim-fmi") for v in found), (lib, found)
    broken = {k: set(v) for k, v in graph.items()}
    broken["agrisim-harvest"].add("agrisim-raycast")
    assert any(v.startswith("agrisim-harvest depends on agrisim-raycast") for v in violations(broken, fmus))
    # Math reaching the messages again (the old pose2 import) is caught, in the FMI layer too.
    broken = {k: set(v) for k, v in graph.items()}
    broken[FMI_EXPORT].add(MATH)
    broken[MATH].add(MESSAGES)
    found = violations(broken, fmus)
    assert any(v.startswith("agrisim-math depends on agrisim-msgs") for v in found), found
    assert any(v.startswith("agrisim-fmi depends on agrisim-msgs (agrisim-fmi -> agrisim-math -> agrisim-msgs)") for v in found), found


def test_the_fmu_rule_goes_by_the_marker_not_the_name(graph, fmus):
    """A marked crate of any name is held to the FMU layer's rule; the same crate unmarked is not."""
    broken = {k: set(v) for k, v in graph.items()}
    broken["lift-model"] = {FMI_EXPORT, BUS}
    found = violations(broken, {**fmus, "lift-model": "Lift2"})
    assert any(v.startswith("lift-model depends on agrisim-bus") and "the FMU layer is at the bottom" in v for v in found), found
    assert not any(v.startswith("lift-model") for v in violations(broken, fmus))


def doctored(metadata, edits):
    """A deep copy of `metadata` with edits = {crate: {"fmu": marker or None (removed)} or
    {"dep": (name, kind)} (a dependency added)}."""
    meta = json.loads(json.dumps(metadata))
    for p in meta["packages"]:
        e = edits.get(p["name"], {})
        if "fmu" in e:
            agrisim = dict(((p.get("metadata") or {}).get("agrisim") or {}))
            agrisim.pop("fmu", None)
            if e["fmu"] is not None:
                agrisim["fmu"] = e["fmu"]
            p["metadata"] = {**(p.get("metadata") or {}), "agrisim": agrisim}
        if "dep" in e:
            p["dependencies"].append({"name": e["dep"][0], "kind": e["dep"][1]})
    return meta


def test_marker_check_can_fail(metadata):
    """An FMU crate without its marker, a library and an orchestrator crate with one, and two
    crates claiming one identifier are each reported, and nothing else."""
    meta = doctored(metadata, {
        "agrisim-fmu-lift": {"fmu": None},
        "agrisim-chassis": {"fmu": "Chassis"},
        "agrisim-bus": {"fmu": "Bus"},
        "agrisim-fmu-imu": {"fmu": "Arm"},
    })
    found = marker_violations(meta)
    assert any(v.startswith("agrisim-fmu-lift (fmus/lift) is in fmus/ but has no") for v in found), found
    assert any(v.startswith("agrisim-chassis (fmus/lib/chassis) is marked fmu = 'Chassis'") for v in found), found
    assert any(v.startswith("agrisim-bus (orchestrator/bus) is marked fmu = 'Bus'") for v in found), found
    assert "two crates are marked fmu = 'Arm'" in found, found
    assert len(found) == 4, found
    empty = doctored(metadata, {"agrisim-fmu-camera": {"fmu": ""}})
    assert [v for v in marker_violations(empty) if v.startswith("agrisim-fmu-camera (fmus/camera) is in fmus/ but has no")], marker_violations(empty)


def test_harness_check_can_fail(metadata):
    """The harness as a normal or a build dependency of a product crate is reported."""
    meta = doctored(metadata, {"agrisim-fmu-lift": {"dep": (FMI_TESTING, None)}, "agrisim": {"dep": (FMI_TESTING, "build")}})
    assert harness_violations(meta) == [
        f"agrisim has {FMI_TESTING} as a build dependency: it is a dev-dependency only",
        f"agrisim-fmu-lift has {FMI_TESTING} as a normal dependency: it is a dev-dependency only",
    ]


def perception_violations(graph, fmus, crates=SENSING):
    """What the perception and mapping nodes link that could hand them ground truth: the
    engine, scene generation or any FMU crate (the world FMU above all)."""
    banned = {ENGINE} | SCENE | set(fmus)
    return [
        f"{crate} depends on {t} ({' -> '.join(path)}): perception sees only messages"
        for crate in crates
        for t, path in sorted(reach(graph, crate).items())
        if t in banned
    ]


def test_perception_links_no_engine_scene_or_world(graph, fmus):
    assert PERCEPTION in graph
    assert perception_violations(graph, fmus) == []
    # The check can fail: a dependency on the world FMU, direct or through another crate.
    world = next(name for name, ident in fmus.items() if ident == "Greenhouse")
    broken = {k: set(v) for k, v in graph.items()}
    broken[PERCEPTION].add(world)
    assert any(v.startswith(f"{PERCEPTION} depends on {world}") for v in perception_violations(broken, fmus))
    broken = {k: set(v) for k, v in graph.items()}
    broken[MESSAGES].add("agrisim-scene")
    found = perception_violations(broken, fmus)
    assert any("agrisim-perception -> agrisim-msgs -> agrisim-scene" in v for v in found), found


def test_mapping_links_no_engine_scene_or_world(graph, fmus):
    """The sensed collision scene (agrisim-mapping) is held to the perception rule."""
    assert MAPPING in graph
    assert perception_violations(graph, fmus, (MAPPING,)) == []
    world = next(name for name, ident in fmus.items() if ident == "Greenhouse")
    for bad in (world, "agrisim-scene", ENGINE, "agrisim-raycast"):
        broken = {k: set(v) for k, v in graph.items()}
        broken[MAPPING].add(bad)
        assert any(v.startswith(f"{MAPPING} depends on {bad}") for v in perception_violations(broken, fmus)), bad
    # Through another crate too: the bus reaching the engine.
    broken = {k: set(v) for k, v in graph.items()}
    broken[BUS].add(ENGINE)
    found = perception_violations(broken, fmus)
    assert any("agrisim-mapping -> agrisim-bus -> agrisim-cosim" in v for v in found), found
