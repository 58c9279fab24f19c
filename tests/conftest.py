"""Shared fixtures of the end-to-end tests: the built CLI (python/agrisim_fmpy.py), the packed
FMUs, and a decoder of recorded topics."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import pytest
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

REPO = Path(__file__).resolve().parents[1]
FMU_DIR = REPO / "target" / "fmu"
# The helpers in python/ (the CLI runner, scenario_variant) are shared with the FMPy checks
# and the benchmark scripts.
sys.path.insert(0, str(REPO / "python"))

from agrisim_fmpy import agrisim_bin, agrisim_run, run_agrisim  # noqa: E402,F401


def wilson(k: int, n: int, z: float = 1.959963984540054) -> tuple[float, float]:
    """Wilson score interval (Wilson 1927), written from the formula: the benchmarks' own
    statistics are checked against it."""
    if n == 0:
        return 0.0, 1.0
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return max(0.0, centre - half), min(1.0, centre + half)


def decoded_messages(path: Path, topic: str) -> list:
    """The messages of one topic of an MCAP, decoded with mcap-ros2-support (the independent
    reader): (schema name, log time [ns], message) in log order."""
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        return [(s.name, m.log_time, msg) for s, _, m, msg in reader.iter_decoded_messages(topics=[topic])]


@pytest.fixture(scope="session")
def fmu_dir() -> Path:
    for name in ("ChassisKinematic", "ChassisDynamic", "Lift"):
        assert (FMU_DIR / f"{name}.fmu").exists(), f"{name}.fmu not packed: run scripts/setup"
    return FMU_DIR
