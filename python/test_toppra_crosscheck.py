"""agrisim's Rust TOPP-RA (orchestrator/trajectory) against the toppra Python package.

Same path (toppra.SplineInterpolator: scipy CubicSpline, not-a-knot, same s values), same
limits, same gridpoints -> durations within 1 % on 240 random 7-DoF paths within the Panda's
joint ranges and random velocity/acceleration limits up to the Panda's. Every Rust output is
sampled and passes the Rust limit checker; the checker itself catches injected violations.

The Rust side is the example binary `trajectory_json` (JSON on stdin/stdout), built here with
`cargo build --release -p agrisim-trajectory --examples` into target/ (or $AGRISIM_TARGET_DIR).
"""

from __future__ import annotations

import json
import logging
import os
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest

toppra = pytest.importorskip("toppra")
import toppra.algorithm as talgo  # noqa: E402
import toppra.constraint as tcons  # noqa: E402

logging.getLogger("toppra").setLevel(logging.ERROR)

REPO = Path(__file__).resolve().parents[1]

# Franka Panda joint limits (Franka Control Interface docs, "Robot and interface specifications").
PANDA_QMIN = np.array([-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973])
PANDA_QMAX = np.array([2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973])
PANDA_V = np.array([2.175, 2.175, 2.175, 2.175, 2.61, 2.61, 2.61])
PANDA_A = np.array([15.0, 7.5, 10.0, 12.5, 15.0, 20.0, 20.0])
PANDA_J = np.array([7500.0, 3750.0, 5000.0, 6250.0, 7500.0, 10000.0, 10000.0])

N_PATHS = 240


def trajectory_bin() -> Path:
    """Builds (incrementally) and returns the JSON bridge binary."""
    target = Path(os.environ.get("AGRISIM_TARGET_DIR", REPO / "target"))
    env = dict(os.environ, CARGO_TARGET_DIR=str(target))
    subprocess.run(
        ["cargo", "build", "--release", "-q", "-p", "agrisim-trajectory", "--examples"],
        cwd=REPO, env=env, check=True,
    )
    exe = target / "release" / "examples" / "trajectory_json"
    assert exe.exists(), exe
    return exe


def run_rust(exe: Path, op: str, problems: list[dict]) -> list[dict]:
    out = subprocess.run([str(exe)], input=json.dumps({"op": op, "problems": problems}),
                         capture_output=True, text=True, check=True)
    results = json.loads(out.stdout)["results"]
    assert len(results) == len(problems)
    return results


def random_paths(n: int, seed: int) -> list[dict]:
    """Random 7-DoF waypoint paths (2..8 waypoints) with uniform or chord-length s, random limits."""
    rng = np.random.default_rng(seed)
    cases = []
    for k in range(n):
        m = int(rng.integers(2, 9))
        wp = rng.uniform(PANDA_QMIN, PANDA_QMAX, size=(m, 7))
        if k % 2 == 0:
            ss = np.linspace(0.0, 1.0, m)
        else:
            ss = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(wp, axis=0), axis=1))])
        vmax = PANDA_V * rng.uniform(0.2, 1.0, 7)
        amax = PANDA_A * rng.uniform(0.2, 1.0, 7)
        cases.append({"ss": ss, "waypoints": wp, "vmax": vmax, "amax": amax})
    return cases


def solve_toppra(case: dict, gridpoints=None):
    """toppra's duration (rest to rest), its gridpoints and the solve time in seconds."""
    t0 = time.perf_counter()
    path = toppra.SplineInterpolator(case["ss"], case["waypoints"])
    if gridpoints is None:
        gridpoints = toppra.interpolator.propose_gridpoints(path, max_err_threshold=1e-3, min_nb_points=100)
    inst = talgo.TOPPRA(
        [tcons.JointVelocityConstraint(case["vmax"]), tcons.JointAccelerationConstraint(case["amax"])],
        path, gridpoints=np.asarray(gridpoints), solver_wrapper="seidel",
    )
    traj = inst.compute_trajectory(0.0, 0.0)
    seconds = time.perf_counter() - t0
    return (None if traj is None else float(traj.duration)), np.asarray(gridpoints), seconds


def rust_problem(case: dict, **extra) -> dict:
    p = {"ss": list(map(float, case["ss"])), "waypoints": np.asarray(case["waypoints"]).tolist(),
         "vmax": list(map(float, case["vmax"])), "amax": list(map(float, case["amax"]))}
    p.update(extra)
    return p


@pytest.fixture(scope="module")
def exe() -> Path:
    return trajectory_bin()


@pytest.fixture(scope="module")
def solved(exe):
    cases = random_paths(N_PATHS, seed=20240604)
    ref = [solve_toppra(c) for c in cases]
    rust = run_rust(exe, "toppra", [
        rust_problem(c, gridpoints=grid.tolist(), sample_dt=0.002, rel_tol=0.02)
        for c, (_, grid, _) in zip(cases, ref)
    ])
    return cases, ref, rust


def test_durations_match_toppra_within_one_percent(solved):
    cases, ref, rust = solved
    rel = []
    for k, ((dur, _, _), r) in enumerate(zip(ref, rust)):
        assert dur is not None, f"toppra failed on case {k}"
        assert "error" not in r, (k, r)
        rel.append(abs(r["duration"] - dur) / dur)
    rel = np.array(rel)
    print(f"\n{len(rel)} paths: duration rel. diff max {rel.max():.2e}, median {np.median(rel):.2e}")
    assert len(rel) >= 200
    assert rel.max() < 0.01


def test_automatic_grid_matches_toppra(exe):
    """Without explicit gridpoints both sides propose the same grid and agree on duration."""
    cases = random_paths(40, seed=7)
    ref = [solve_toppra(c) for c in cases]
    rust = run_rust(exe, "toppra", [rust_problem(c) for c in cases])
    for (dur, grid, _), r in zip(ref, rust):
        assert r["n_grid"] == len(grid)
        assert abs(r["duration"] - dur) / dur < 0.01


def test_sampled_outputs_pass_the_limit_checker(solved, exe):
    cases, _, rust = solved
    worst_v = max(r["max_velocity_ratio"] for r in rust)
    worst_a = max(r["max_acceleration_ratio"] for r in rust)
    print(f"\nplain TOPP-RA, sampled at 2 ms: max |qd|/vmax {worst_v:.4f}, max |qdd|/amax {worst_a:.4f}")
    for k, (c, r) in enumerate(zip(cases, rust)):
        # Gridpoint-only constraints: between gridpoints at most ~1 % over (checked with 2 %).
        assert r["check"]["ok"], (k, r["check"])
        assert np.allclose(r["end_q"], c["waypoints"][-1], atol=1e-9)
    # The verified variant passes the checker strictly at the send period.
    verified = run_rust(exe, "toppra", [rust_problem(c, sample_dt=0.01, rel_tol=1e-9, verify=True) for c in cases[:60]])
    for (r, plain) in zip(verified, rust[:60]):
        assert "error" not in r, r
        assert r["check"]["ok"], r["check"]
        assert r["max_velocity_ratio"] <= 1.0 + 1e-9 and r["max_acceleration_ratio"] <= 1.0 + 1e-9
        assert plain["duration"] * (1 - 1e-9) <= r["duration"] < 1.05 * plain["duration"]


def test_limit_checker_catches_injected_violations(exe):
    rng = np.random.default_rng(3)
    t = np.arange(0.0, 0.5, 0.001)  # 1 ms: an acceleration step within limits can break jerk
    base_q = 0.1 * np.sin(np.outer(t, np.arange(1, 8)))            # (N, 7)
    base_qd = 0.1 * np.cos(np.outer(t, np.arange(1, 8))) * np.arange(1, 8)
    base_qdd = -0.1 * np.sin(np.outer(t, np.arange(1, 8))) * np.arange(1, 8) ** 2
    base_q[:, 3] -= 1.0  # joint 4 range is negative
    base_q[:, 5] += 1.0
    limits = {"position": [[lo, hi] for lo, hi in zip(PANDA_QMIN, PANDA_QMAX)], "velocity": PANDA_V.tolist(),
              "acceleration": PANDA_A.tolist(), "jerk": PANDA_J.tolist(), "rel_tol": 1e-6}

    def rows(a):  # JSON has no NaN: null stands for it
        return [[None if np.isnan(v) else float(v) for v in r] for r in a]

    def problem(q, qd, qdd, tt=t):
        return {"t": tt.tolist(), "q": rows(q), "qd": rows(qd), "qdd": rows(qdd), **limits}

    problems, expect = [problem(base_q, base_qd, base_qdd)], [None]
    for _ in range(60):
        k, j = int(rng.integers(1, len(t))), int(rng.integers(0, 7))
        q, qd, qdd = base_q.copy(), base_qd.copy(), base_qdd.copy()
        kind = ["position", "velocity", "acceleration", "jerk", "nan"][len(problems) % 5]
        if kind == "position":
            q[k, j] = PANDA_QMAX[j] + 0.01
        elif kind == "velocity":
            qd[k, j] = -PANDA_V[j] * 1.01
        elif kind == "acceleration":
            qdd[k, j] = PANDA_A[j] * 1.01  # also a jerk jump, but acceleration is checked first
        elif kind == "jerk":
            qdd[k:, j] += PANDA_A[j] * 0.9 - qdd[k, j]  # step to 0.9 a: jerk >= (0.9 a - |qdd|) / 1 ms
            qdd[k:, j] = np.clip(qdd[k:, j], -PANDA_A[j] * 0.95, PANDA_A[j] * 0.95)
        else:
            qd[k, j] = float("nan")
        problems.append(problem(q, qd, qdd))
        expect.append((j, float(t[k]), "velocity" if kind == "nan" else kind))
    # Malformed: non-increasing time.
    t_bad = t.copy()
    t_bad[10] = t_bad[9]
    problems.append(problem(base_q, base_qd, base_qdd, t_bad))
    results = run_rust(exe, "check", problems)
    assert results[0] == {"ok": True}
    for r, e in zip(results[1:-1], expect[1:]):
        assert not r["ok"]
        # (serde_json's default float parsing may differ from Python's by an ulp)
        assert (r["joint"], r["quantity"]) == (e[0], e[2]) and r["time"] == pytest.approx(e[1], abs=1e-12), (r, e)
        assert f"joint {e[0]} {e[2]} limit violated" in r["message"]
    assert not results[-1]["ok"] and "malformed" in results[-1]


def test_collocation_and_clamped_variants_match_toppra(exe):
    """The other discretization and spline end condition agree too (30 paths each)."""
    cases = random_paths(30, seed=99)
    for bc, collocation in (("clamped", False), ("not-a-knot", True)):
        durations, problems = [], []
        for c in cases:
            path = toppra.SplineInterpolator(c["ss"], c["waypoints"], bc_type=bc)
            grid = np.linspace(c["ss"][0], c["ss"][-1], 150)
            scheme = tcons.DiscretizationType.Collocation if collocation else tcons.DiscretizationType.Interpolation
            inst = talgo.TOPPRA([tcons.JointVelocityConstraint(c["vmax"]),
                                 tcons.JointAccelerationConstraint(c["amax"], discretization_scheme=scheme)],
                                path, gridpoints=grid, solver_wrapper="seidel")
            durations.append(inst.compute_trajectory(0.0, 0.0).duration)
            problems.append(rust_problem(c, bc=bc, collocation=collocation, gridpoints=grid.tolist()))
        rust = run_rust(exe, "toppra", problems)
        rel = [abs(r["duration"] - d) / d for r, d in zip(rust, durations)]
        print(f"\n{bc}, collocation={collocation}: max duration rel. diff {max(rel):.1e}")
        assert max(rel) < 0.01, (bc, collocation, max(rel))
