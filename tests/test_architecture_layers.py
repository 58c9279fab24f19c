"""The layer rules of the workspace, read from `cargo metadata`: which crate may depend on
which (normal dependencies, followed transitively through the workspace).

  fmus/ (environment, robot, sensors)  <-  orchestrator/cosim (engine)
  orchestrator/bus (messages)  <-  algorithm nodes (nodes, nav, manip, trajectory, harvest)
  session (engine + bus)  <-  bench  <-  cli, python (the pyo3 package; siblings on top)
  bus  <-  bridges (ros2: DDS, foxglove: WebSocket): they carry messages, like a node

The engine and the message layer do not know each other; algorithms never link the engine,
the FMU export layer or scene generation, so any of them can be swapped for a ROS 2 node.
"""
import json
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

ALGORITHMS = {"agrisim-nodes", "agrisim-nav", "agrisim-harvest", "agrisim-manip", "agrisim-trajectory"}
ENGINE = "agrisim-cosim"
SCENE = "agrisim-greenhouse"
FMI_EXPORT = "agrisim-fmi"
MESSAGES = "agrisim-msgs"
BUS = "agrisim-bus"
PYTHON = "agrisim-python"
BRIDGES = {"agrisim-ros2", "agrisim-foxglove"}
ABOVE = {"agrisim-session", "agrisim-bench", "agrisim", PYTHON}

# crate -> crates it must not reach (directly or through other workspace crates), and why.
FORBIDDEN = {
    **{a: ({ENGINE, SCENE, FMI_EXPORT} | BRIDGES | ABOVE, "an algorithm speaks only messages (node API)") for a in ALGORITHMS},
    **{b: ({ENGINE, SCENE, FMI_EXPORT} | ALGORITHMS | ABOVE, "a bridge carries messages: no FMI, no algorithm") for b in BRIDGES},
    ENGINE: ({MESSAGES, BUS, SCENE, FMI_EXPORT} | ALGORITHMS | BRIDGES | ABOVE, "the engine knows no ROS, no greenhouse, no algorithm"),
    BUS: ({ENGINE, SCENE, FMI_EXPORT} | ALGORITHMS | BRIDGES | ABOVE, "the message layer has no FMI inside"),
    SCENE: ({FMI_EXPORT, ENGINE, BUS} | ALGORITHMS | ABOVE, "scene generation is a plain library"),
    "agrisim-session": ({"agrisim-bench", "agrisim", PYTHON, "agrisim-nav", "agrisim-harvest"} | BRIDGES, "a session runs any nodes; it picks none"),
    "agrisim-bench": ({"agrisim", PYTHON}, "the CLI and the Python package are on top"),
    PYTHON: ({"agrisim"}, "the Python package and the CLI are siblings: neither links the other"),
}


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


def violations(graph):
    out = []
    for crate, (forbidden, why) in sorted(FORBIDDEN.items()):
        assert crate in graph, f"layer rule names {crate}, which is not a workspace crate"
        for target, path in sorted(reach(graph, crate).items()):
            if target in forbidden:
                out.append(f"{crate} depends on {target} ({' -> '.join(path)}): {why}")
    fmu_side = {n for n in graph if n.startswith("agrisim-fmu-")} | {SCENE, FMI_EXPORT, MESSAGES}
    orchestrator = {ENGINE, BUS} | ALGORITHMS | BRIDGES | ABOVE
    for crate in sorted(fmu_side):
        for target, path in sorted(reach(graph, crate).items()):
            if target in orchestrator:
                out.append(f"{crate} depends on {target} ({' -> '.join(path)}): the FMU layer is at the bottom")
    return out


@pytest.fixture(scope="module")
def graph():
    meta = json.loads(subprocess.run(["cargo", "metadata", "--format-version", "1", "--no-deps", "--offline"], cwd=ROOT, check=True, capture_output=True, text=True).stdout)
    return workspace_graph(meta)


def test_layers_hold(graph):
    assert violations(graph) == []


def test_every_layer_crate_exists(graph):
    for crate in ALGORITHMS | BRIDGES | {ENGINE, BUS, SCENE, "agrisim-session", "agrisim-bench", "agrisim", PYTHON}:
        assert crate in graph, crate


def test_checker_catches_a_broken_rule(graph):
    """The rule check can fail: an algorithm reaching the engine through the bus is caught."""
    broken = {k: set(v) for k, v in graph.items()}
    broken[BUS].add(ENGINE)
    found = violations(broken)
    assert any(v.startswith("agrisim-nav depends on agrisim-cosim (agrisim-nav -> agrisim-bus -> agrisim-cosim)") for v in found), found
    broken = {k: set(v) for k, v in graph.items()}
    broken[SCENE].add(FMI_EXPORT)
    assert any(v.startswith("agrisim-greenhouse depends on agrisim-fmi") for v in violations(broken))
