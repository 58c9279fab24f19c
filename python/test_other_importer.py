"""Every packed FMU (FMI 3.0 and FMI 2.0) loads and runs 10 s in an FMI importer other than
FMPy: fmi-sim (crates.io `fmi-sim` 0.7.0, a pure-Rust FMI 2/3 simulator), built by
scripts/setup. Its CSV output is checked against what the FMUs must produce: the test
model's analytic solution, every IMU sample in the message port's frames (decoded with
python/agrisim_frames.py), the arm resting at its initial pose.

fmi-sim records every output at every step and keeps the whole table in memory (Binary
values as hex), so the camera runs at 64x48 and the LiDAR with 2,000 points per frame here.
"""

from __future__ import annotations

import csv
import math
import os
import subprocess
import sys
from pathlib import Path

import zipfile

import pytest

import agrisim_frames
from agrisim_fmpy import FMU2_DIR, FMU_DIR

FMI_SIM = Path(os.environ.get("AGRISIM_FMI_SIM", Path.home() / ".local/share/agrisim-tools/fmi-sim-0.7.0/bin/fmi-sim"))
STOP, STEP = 10.0, 0.02
# Keep the recorded table small (see the module doc).
LIGHTER = {"Camera": ["width=64", "height=48"], "Lidar": ["point_rate=20000"]}
csv.field_size_limit(sys.maxsize)


def fmi_sim(fmu: Path, out: Path, init: list[str]) -> list[dict[str, str]]:
    assert FMI_SIM.exists(), f"{FMI_SIM} missing: run scripts/setup (it builds fmi-sim)"
    # A model-exchange-only FMU (Oscillator) runs under fmi-sim's own integrator.
    interface = "co-simulation" if "<CoSimulation" in zipfile.ZipFile(fmu).read("modelDescription.xml").decode() else "model-exchange"
    args = [str(FMI_SIM), "--model", str(fmu), "-o", str(out), interface, "-s", "0", "-f", str(STOP), "--output-interval", str(STEP)]
    for v in init:
        args += ["--init-values", v]
    p = subprocess.run(args, capture_output=True, text=True, env={**os.environ, "RUST_BACKTRACE": "0"}, timeout=600)
    assert p.returncode == 0, f"fmi-sim {fmu.name}: exit {p.returncode}\n{p.stderr[-2000:]}"
    with out.open(newline="") as f:
        rows = list(csv.DictReader(f))
    out.unlink()
    return rows


def packed(d: Path) -> list[Path]:
    fmus = sorted(d.glob("*.fmu"))
    assert len(fmus) >= 9, f"{d}: {len(fmus)} FMUs packed"
    return fmus


@pytest.mark.parametrize("version", [3, 2])
def test_every_fmu_runs_ten_seconds_in_fmi_sim(tmp_path, version):
    for fmu in packed(FMU_DIR if version == 3 else FMU2_DIR):
        rows = fmi_sim(fmu, tmp_path / f"{fmu.stem}.csv", LIGHTER.get(fmu.stem, []))
        # fmi-sim records both sides of the Oscillator's time event (its kick at t = 1 s).
        events = 1 if fmu.stem == "Oscillator" else 0
        assert len(rows) == round(STOP / STEP) + 1 + events, f"{fmu.name}: {len(rows)} rows"
        assert abs(float(rows[-1]["time"]) - STOP) < 1e-9, f"{fmu.name}: ends at {rows[-1]['time']}"
        if fmu.stem == "TestModel":
            # x' = -k x, x0 = 1, k = 1: x(t) = exp(-t), exact at the communication points.
            for r in rows[::50]:
                t = float(r["time"])
                assert abs(float(r["x"]) - math.exp(-t)) <= 1e-12 + 1e-9 * math.exp(-t), f"FMI {version}: x({t}) = {r['x']}"
            assert int(rows[-1]["steps"]) == 500
        if fmu.stem == "Arm":
            q0 = [float(rows[0][f"q{i}"]) for i in range(1, 8)]
            assert all(abs(float(rows[-1][f"q{i}"]) - q0[i - 1]) < 1e-3 for i in range(1, 8)), "the arm holds its pose without a trajectory"
        if fmu.stem == "Imu" and version == 3:
            check_imu(rows)


def check_imu(rows: list[dict[str, str]]) -> None:
    """The imu column holds every 200 Hz sample of the last 0.1 s as frames; across the run
    a cursor takes all 2,001 of them, 5 ms apart, without a gap."""
    cursor, stamps = agrisim_frames.Cursor(), []
    for r in rows:
        for f in cursor.take(bytes.fromhex(r["imu"]), int(r["imu_seq"])):
            stamps.append(f.stamp_ns)
    assert len(stamps) == 2001
    assert all(b - a == 5_000_000 for a, b in zip(stamps, stamps[1:]))
    assert len(agrisim_frames.decode(bytes.fromhex(rows[-1]["imu"]))) == 20
