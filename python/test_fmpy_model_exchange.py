"""The Oscillator FMU (model exchange only, FMI 3 and FMI 2) against importers nobody here
wrote: FMPy's validator, FMPy's CVode-driven model-exchange simulation and fmi-sim's
forward-Euler model-exchange simulation, all compared with the closed-form solution.

The closed form is re-derived here on purpose (not imported from the Rust crate): a mistake
in the crate's formula must not cancel out. The oscillator is x'' + 2 zeta omega x' +
omega^2 x = 0 with v += kick_dv at t = kick_time (a time event the FMU announces).
"""

from __future__ import annotations

import csv
import math
import os
import subprocess
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.validation import validate_fmu

from agrisim_fmpy import fmu_path

VERSIONS = [3, 2]
DEFAULTS = {"omega": 2.0, "zeta": 0.1, "x0": 1.0, "v0": 0.0, "kick_time": 1.0, "kick_dv": 0.5}
FMI_SIM = Path(os.environ.get("AGRISIM_FMI_SIM", Path.home() / ".local/share/agrisim-tools/fmi-sim-0.7.0/bin/fmi-sim"))
# CVode at relative tolerance 1e-10 (FMPy derives the absolute tolerance from it and the
# states' nominals, 1.0 here): over 5 s the states stay within 1e-7 of the exact values
# (measured: 2e-8 at most).
CVODE_TOL = 1e-7


def free(omega, zeta, x0, v0, dt):
    """Free response after dt, by case (the crate uses one unified basis instead)."""
    a = zeta * omega
    e = np.exp(-a * dt)
    if zeta < 1:
        w = omega * math.sqrt(1 - zeta * zeta)
        c, s = np.cos(w * dt), np.sin(w * dt)
        x = e * (x0 * c + (v0 + a * x0) / w * s)
        v = e * (v0 * c - (omega * omega * x0 + a * v0) / w * s)
    elif zeta == 1:
        x = e * (x0 + (v0 + omega * x0) * dt)
        v = e * (v0 - omega * (v0 + omega * x0) * dt)
    else:
        r1 = -a + omega * math.sqrt(zeta * zeta - 1)
        r2 = -a - omega * math.sqrt(zeta * zeta - 1)
        c1 = (v0 - r2 * x0) / (r1 - r2)
        c2 = (r1 * x0 - v0) / (r1 - r2)
        x = c1 * np.exp(r1 * dt) + c2 * np.exp(r2 * dt)
        v = c1 * r1 * np.exp(r1 * dt) + c2 * r2 * np.exp(r2 * dt)
    return x, v


def exact(p: dict, t):
    """(x, v) at times t >= 0 (start 0); right-continuous at the kick."""
    t = np.asarray(t, dtype=float)
    x, v = free(p["omega"], p["zeta"], p["x0"], p["v0"], t)
    tk = p["kick_time"]
    if tk > 0:
        xk, vk = free(p["omega"], p["zeta"], p["x0"], p["v0"], tk)
        xa, va = free(p["omega"], p["zeta"], xk, vk + p["kick_dv"], np.maximum(t - tk, 0.0))
        x, v = np.where(t >= tk, xa, x), np.where(t >= tk, va, v)
    return x, v


def test_closed_form_here_is_right():
    """The reference itself: initial values, the ODE by finite differences, the jump."""
    p = {**DEFAULTS, "kick_time": 0.0}
    for zeta in (0.1, 1.0, 1.7):
        q = {**p, "zeta": zeta}
        t = np.linspace(0.1, 3, 50)
        h = 1e-5
        x, v = exact(q, t)
        xp, _ = exact(q, t + h)
        xm, _ = exact(q, t - h)
        assert np.allclose((xp - xm) / (2 * h), v, atol=1e-6)
        acc = (xp - 2 * x + xm) / (h * h)
        assert np.allclose(acc + 2 * zeta * q["omega"] * v + q["omega"] ** 2 * x, 0, atol=1e-3)
        assert np.allclose(exact(q, [0.0]), [[q["x0"]], [q["v0"]]], rtol=0, atol=1e-15)
    x1, v1 = exact(DEFAULTS, [1.0 - 1e-12, 1.0])
    assert abs(x1[1] - x1[0]) < 1e-9 and abs(v1[1] - v1[0] - 0.5) < 1e-9


@pytest.mark.parametrize("version", VERSIONS)
def test_validation_has_no_problems(version):
    fmu = fmu_path("Oscillator", version)
    assert validate_fmu(str(fmu)) == []


@pytest.mark.parametrize("version", VERSIONS)
def test_model_description_is_model_exchange_only_with_two_states(version):
    fmu = fmu_path("Oscillator", version)
    md = read_model_description(str(fmu))
    assert md.coSimulation is None and md.modelExchange is not None
    assert md.modelExchange.modelIdentifier == "Oscillator"
    assert [d.variable.derivative.name for d in md.derivatives] == ["x", "v"]
    assert [d.variable.name for d in md.derivatives] == ["der(x)", "der(v)"]
    assert md.numberOfEventIndicators == 0
    with zipfile.ZipFile(fmu) as z:
        root = ET.fromstring(z.read("modelDescription.xml"))
    assert root.find("CoSimulation") is None


def simulate(version: int, params: dict, stop: float, record_events: bool = False):
    return simulate_fmu(
        str(fmu_path("Oscillator", version)),
        fmi_type="ModelExchange",
        solver="CVode",
        relative_tolerance=1e-10,
        stop_time=stop,
        output_interval=0.01,
        start_values={k: v for k, v in params.items() if v != DEFAULTS[k]},
        output=["x", "v"],
        record_events=record_events,
    )


CASES = {
    "defaults": {},
    "kick_off_grid": {"kick_time": 1.234, "kick_dv": -2.0, "v0": 0.7},
    "critical": {"zeta": 1.0, "omega": 3.0, "x0": -0.5, "kick_time": 2.5},
    "overdamped": {"zeta": 2.5, "kick_time": 0.33},
    "no_kick": {"kick_time": 0.0},
}


@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize("case", CASES)
def test_cvode_matches_the_closed_form_across_the_kick(version, case):
    p = {**DEFAULTS, **CASES[case]}
    r = simulate(version, p, 5.0)
    t = r["time"]
    assert t[0] == 0.0 and abs(t[-1] - 5.0) < 1e-9 and len(t) == 501
    x, v = exact(p, t)
    err = max(np.max(np.abs(r["x"] - x)), np.max(np.abs(r["v"] - v)))
    assert err < CVODE_TOL, f"max |state - exact| = {err:.2e}"
    if p["kick_time"] > 0:
        # The jump really happened: right after it, v is off the unkicked solution by ~kick_dv.
        unkicked = free(p["omega"], p["zeta"], p["x0"], p["v0"], t)[1]
        after = np.searchsorted(t, p["kick_time"] + 1e-9)
        assert abs(r["v"][after] - unkicked[after]) > 0.5 * abs(p["kick_dv"]) * math.exp(-p["zeta"] * p["omega"] * 0.02)


@pytest.mark.parametrize("version", VERSIONS)
def test_event_is_handled_exactly_at_kick_time(version):
    """With events recorded, FMPy samples the left and right limits at t = kick_time."""
    p = {**DEFAULTS, "kick_time": 1.234, "kick_dv": -2.0}
    r = simulate(version, p, 2.0, record_events=True)
    at = np.flatnonzero(np.abs(r["time"] - 1.234) < 1e-12)
    assert len(at) >= 2, f"no event rows at 1.234: {r['time'][(r['time'] > 1.2) & (r['time'] < 1.3)]}"
    before, after = r[at[0]], r[at[-1]]
    xk, vk = free(p["omega"], p["zeta"], p["x0"], p["v0"], 1.234)
    assert abs(before["v"] - vk) < CVODE_TOL and abs(after["v"] - (vk - 2.0)) < CVODE_TOL
    assert abs(before["x"] - xk) < CVODE_TOL and abs(after["x"] - xk) < CVODE_TOL


def fmi_sim(fmu: Path, out: Path, interval: float, stop: float) -> dict[str, np.ndarray]:
    assert FMI_SIM.exists(), f"{FMI_SIM} missing: run scripts/setup (it builds fmi-sim)"
    # fmi-sim 0.7 takes its forward-Euler step from the output interval (--step is ignored).
    args = [str(FMI_SIM), "--model", str(fmu), "-o", str(out), "model-exchange", "-s", "0", "-f", str(stop),
            "--output-interval", str(interval)]
    p = subprocess.run(args, capture_output=True, text=True, env={**os.environ, "RUST_BACKTRACE": "0"}, timeout=600)
    assert p.returncode == 0, f"fmi-sim {fmu}: exit {p.returncode}\n{p.stderr[-2000:]}"
    with out.open(newline="") as f:
        rows = list(csv.DictReader(f))
    return {k: np.array([float(r[k]) for r in rows]) for k in ("time", "x", "v")}


@pytest.mark.parametrize("version", VERSIONS)
def test_fmi_sim_forward_euler_converges_to_the_closed_form(tmp_path, version):
    """fmi-sim integrates with forward Euler: the error must shrink ~10x per 10x smaller
    step, and at the kick it prints both limits, v jumping by exactly kick_dv."""
    errors = []
    for h in (1e-2, 1e-3):
        r = fmi_sim(fmu_path("Oscillator", version), tmp_path / "out.csv", h, 3.0)
        assert abs(r["time"][-1] - 3.0) < 1e-6
        at = np.flatnonzero(np.abs(r["time"] - DEFAULTS["kick_time"]) < 1e-9)
        assert len(at) == 2, f"the kick time appears {len(at)} times"
        assert r["x"][at[1]] == r["x"][at[0]] and abs(r["v"][at[1]] - r["v"][at[0]] - DEFAULTS["kick_dv"]) < 1e-12
        keep = np.ones(len(r["time"]), bool)
        keep[at[0]] = False  # the left limit; the closed form is right-continuous
        x, v = exact(DEFAULTS, r["time"][keep])
        errors.append(max(np.max(np.abs(r["x"][keep] - x)), np.max(np.abs(r["v"][keep] - v))))
    assert errors[1] < 1e-2, errors
    assert errors[1] < errors[0] / 5, f"no first-order convergence: {errors}"
