"""The by-sight scenarios are their ground-truth twins with perception in the loop, nothing
else: the same greenhouse, seed, timing, robot parameters and plant physics, so trial i of a
by-sight run and of its ground-truth twin have the same scene and task (the pairing of
python/harvest_modes.py and the per-crop figures in docs/benchmarks.md rest on it)."""

import tomllib
from pathlib import Path

import pytest

SCENARIOS = Path(__file__).resolve().parents[1] / "models" / "scenarios"
TWINS = [
    ("harvest_sight.toml", "harvest.toml"),
    ("crop_truss_sight.toml", "crop_truss.toml"),
    ("crop_cherry_sight.toml", "crop_cherry.toml"),
    ("family_sight.toml", "family.toml"),
]
# What perception in the loop changes: the system (the lift's row cameras and the perception
# and mapping nodes), the [harvest] section, and the cameras' frame rate.
SIGHT_ONLY = {"name", "description", "harvest"}
SIGHT_CAMERAS = {"camera_left", "camera_right"}


def load(name: str) -> dict:
    return tomllib.loads((SCENARIOS / name).read_text())


def without_sight(s: dict) -> dict:
    s = {k: v for k, v in s.items() if k not in SIGHT_ONLY}
    s["system"] = {k: v for k, v in s["system"].items() if k != "file"}
    s["parameters"] = {k: v for k, v in s.get("parameters", {}).items() if k not in SIGHT_CAMERAS}
    return s


@pytest.mark.parametrize("sight, truth", TWINS)
def test_a_by_sight_scenario_differs_from_its_twin_only_by_perception(sight, truth):
    s, t = load(sight), load(truth)
    assert s["harvest"]["sight"] is True, sight
    assert s["system"]["file"] == "../systems/harvest_sight.ssd", sight
    assert t["system"]["file"] == "../systems/harvest.ssd", truth
    assert not t.get("harvest", {}).get("sight", False), truth
    assert without_sight(s) == without_sight(t), f"{sight} and {truth} differ beyond perception"


def test_the_cherry_scenario_tells_perception_the_cultivars_size():
    # The preset's fruit are 25-35 mm across (fmus/lib/scene/src/crop.rs); the detector's
    # default radii (20-45 mm) would fit a cluster of cherries as one fruit.
    lo, hi = load("crop_cherry_sight.toml")["harvest"]["fruit_radius"]
    assert lo <= 0.0125 and hi >= 0.0175 and hi < 0.020
