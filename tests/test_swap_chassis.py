"""A chassis built with another tool, swapped in: PyChassis (models/thirdparty/PyChassis.py)
is a plain Python class exported by pythonfmu as an FMI 2.0 co-simulation FMU with Real
ports and no ROS types. models/systems/thirdparty/swap_chassis.ssd puts it where the built-in chassis
was, behind the TwistToScalars and ScalarsToOdometry adapter FMUs, and the navigation
benchmark is judged on it exactly as on the built-in chassis.

pythonfmu's binary leaves Python's C API unresolved: the CLI (not a Python process) loads
libpython itself (agrisim_cosim's embedded Python), which this test relies on by running
the CLI with no virtual environment activated and no LD_PRELOAD.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from mcap.reader import make_reader

from conftest import REPO, agrisim_bin

SCENARIO = REPO / "models/scenarios/swap_chassis.toml"


def build_py_chassis(out: Path) -> Path:
    pythonfmu = Path(sys.executable).parent / "pythonfmu"
    subprocess.run([str(pythonfmu), "build", "-f", str(REPO / "models/thirdparty/PyChassis.py"), "-d", str(out)], check=True, capture_output=True)
    fmu = out / "PyChassis.fmu"
    assert fmu.exists()
    return fmu


def bench_nav(out: Path, *extra: str) -> dict:
    env = {k: v for k, v in os.environ.items() if k not in ("VIRTUAL_ENV", "LD_PRELOAD", "PYTHONHOME", "PYTHONPATH")}
    args = [str(agrisim_bin()), "bench", "nav", "--trials", "10", "--seed", "1", "--out", str(out), *extra]
    p = subprocess.run(args, cwd=REPO, env=env, capture_output=True, text=True, timeout=1800)
    assert p.returncode == 0, f"{' '.join(args)}: exit {p.returncode}\n{p.stderr[-3000:]}"
    return json.loads((out / "summary.json").read_text())


def test_a_pythonfmu_chassis_navigates_like_the_built_in_one(tmp_path):
    fmu = build_py_chassis(tmp_path / "fmu")
    swapped = bench_nav(tmp_path / "swapped", "--scenario", str(SCENARIO), "--fmu", f"chassis={fmu}")
    built_in = bench_nav(tmp_path / "built_in")
    assert swapped["trials"] == built_in["trials"] == 10
    # The swap must not cost navigation: success within one trial of the built-in chassis.
    assert swapped["successes"] >= built_in["successes"] - 1, (swapped, built_in)
    # The trials really ran the Python model behind the adapters.
    with open(tmp_path / "swapped/trials/0000.mcap", "rb") as f:
        meta = {m.name: m.metadata for m in make_reader(f).iter_metadata()}
    run = meta["agrisim.run"]
    assert (run["fmu.chassis"], run["fmu.cmd"], run["fmu.odometry"]) == ("PyChassis", "TwistToScalars", "ScalarsToOdometry")
    assert meta["agrisim.run"]["scenario"] == "swap_chassis"
