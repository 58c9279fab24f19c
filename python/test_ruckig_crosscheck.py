"""agrisim's jerk-limited motions (orchestrator/trajectory, rsruckig: the pure-Rust ruckig port)
against the official ruckig (its Python package, the C++ library).

Random 7-DoF state-to-state problems within the Panda's ranges and limits: same durations
(relative 1e-6), same states along the motion, every Rust motion sampled at 1 ms passes the
limit checker (velocity, acceleration, jerk by finite differences).
"""

from __future__ import annotations

import numpy as np
import pytest

ruckig = pytest.importorskip("ruckig")

from test_toppra_crosscheck import PANDA_A, PANDA_J, PANDA_QMAX, PANDA_QMIN, PANDA_V, run_rust, trajectory_bin  # noqa: E402

N_CASES = 300
FRACTIONS = (0.1, 0.37, 0.5, 0.81, 1.0)


def random_problems(n: int, seed: int) -> list[dict]:
    rng = np.random.default_rng(seed)
    cases = []
    zero = np.zeros(7)
    for k in range(n):
        vmax = PANDA_V * rng.uniform(0.2, 1.0, 7)
        amax = PANDA_A * rng.uniform(0.1, 1.0, 7)
        jmax = PANDA_J * rng.uniform(0.001, 0.1, 7)  # planning jerk well below the hardware's
        q0, q1 = rng.uniform(PANDA_QMIN, PANDA_QMAX), rng.uniform(PANDA_QMIN, PANDA_QMAX)
        v0 = a0 = v1 = a1 = zero
        if k % 2 == 1:  # moving start and target
            v0, v1 = vmax * rng.uniform(-0.5, 0.5, 7), vmax * rng.uniform(-0.3, 0.3, 7)
        if k % 4 == 3:  # accelerating start
            a0 = amax * rng.uniform(-0.3, 0.3, 7)
        cases.append(dict(q0=q0, v0=v0, a0=a0, q1=q1, v1=v1, a1=a1, vmax=vmax, amax=amax, jmax=jmax))
    return cases


def solve_ruckig(c: dict):
    inp = ruckig.InputParameter(7)
    inp.current_position, inp.current_velocity, inp.current_acceleration = c["q0"], c["v0"], c["a0"]
    inp.target_position, inp.target_velocity, inp.target_acceleration = c["q1"], c["v1"], c["a1"]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = c["vmax"], c["amax"], c["jmax"]
    traj = ruckig.Trajectory(7)
    result = ruckig.Ruckig(7).calculate(inp, traj)
    return result, traj


def start_within_limits(c: dict) -> bool:
    """ruckig can only keep the limits if braking the start acceleration does not already
    carry the velocity past them: |v0 + a0·|a0| / (2 j)| <= vmax."""
    v_peak = c["v0"] + c["a0"] * np.abs(c["a0"]) / (2 * c["jmax"])
    return bool(np.all(np.abs(v_peak) <= c["vmax"]))


def test_durations_and_states_match_official_ruckig():
    exe = trajectory_bin()
    cases = random_problems(N_CASES, seed=11)
    ref = [solve_ruckig(c) for c in cases]
    problems = []
    for c, (_, traj) in zip(cases, ref):
        p = {k: list(map(float, v)) for k, v in c.items()}
        p.update(sample_dt=0.001, rel_tol=1e-6, probe_times=[traj.duration * f for f in FRACTIONS])
        problems.append(p)
    rust = run_rust(exe, "ruckig", problems)
    rel, pos_err, vel_err, checked = [], [], [], 0
    for k, (c, (result, traj), r) in enumerate(zip(cases, ref, rust)):
        assert result == ruckig.Result.Working, (k, result)
        assert "error" not in r, (k, r)
        rel.append(abs(r["duration"] - traj.duration) / traj.duration)
        for probe in r["probes"]:
            q, qd, _ = traj.at_time(probe["t"])
            pos_err.append(np.max(np.abs(np.array(q) - probe["q"])))
            vel_err.append(np.max(np.abs(np.array(qd) - probe["qd"])))
        end = r["probes"][-1]
        assert np.allclose(end["q"], c["q1"], atol=1e-8) and np.allclose(end["qd"], c["v1"], atol=1e-8)
        if start_within_limits(c):
            checked += 1
            assert r["check"]["ok"], (k, r["check"])
    rel = np.array(rel)
    print(f"\n{len(rel)} problems: duration rel. diff max {rel.max():.1e}; state diff max "
          f"q {max(pos_err):.1e} rad, qd {max(vel_err):.1e} rad/s; {checked} limit-checked")
    assert rel.max() < 1e-6
    assert max(pos_err) < 1e-8 and max(vel_err) < 1e-8
    assert checked >= 250
