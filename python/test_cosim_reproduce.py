"""The orchestrator's co-simulation, reproduced with FMPy.

`agrisim run` records a run; here the same FMUs are driven through FMPy's low-level FMU3Slave
by an independent implementation of the master algorithm (python/agrisim_fmpy.py, written
from orchestrator/cosim/src/master.rs: integer ticks, Gauss-Seidel in the order with the fewest
delayed connections (found here by brute force), one-pass initialization in that order, every
message of a framed port once (python/agrisim_frames.py), 10 Hz message instants), fed with the recorded system inputs (/cmd_vel raw CDR
at its log times, /agrisim/scalars) and the recorded parameters (MCAP metadata). Every FMU's
scalar inputs and outputs must match /fmu/<component>/signals to 1e-9 at every tick, and the
chassis' /odom bytes must be identical.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from agrisim_fmpy import DEFAULT_SCENARIO, DEFAULT_SSD, MasterReplay, agrisim_run, annotated_scenario, read_mcap, run_agrisim

TOL = 1e-9


def reproduce(out: Path, *extra: str, overrides: dict[str, str] | None = None, scenario: Path = DEFAULT_SCENARIO,
              ssd: Path = DEFAULT_SSD):
    rec = read_mcap(agrisim_run(out, *extra, scenario=scenario))
    clock = rec.topic("/clock")
    ticks = len(clock) - 1
    assert ticks > 0 and clock[-1].log_time == ticks * round(float(rec.metadata["agrisim.run"]["step"]) * 1e9)
    m = MasterReplay(ssd, rec, overrides)
    try:
        m.initialize()
        m.run(ticks)
    finally:
        m.close()
    return rec, m


def compare_signals(rec, m) -> dict[str, float]:
    worst = {}
    for comp in m.names:
        recorded = rec.topic(f"/fmu/{comp}/signals")
        ours = m.signals[comp]
        assert len(recorded) == len(ours), f"{comp}: {len(recorded)} recorded points, {len(ours)} replayed"
        err, where = 0.0, None
        for r, (t_ns, names, values) in zip(recorded, ours):
            assert r.log_time == t_ns, f"{comp}: recorded point at {r.log_time} ns, replay at {t_ns} ns"
            assert list(r.msg.names) == names, f"{comp}: signal names differ at {t_ns} ns"
            for n, a, b in zip(names, r.msg.values, values):
                e = abs(a - b)
                if not e <= err:  # also catches NaN
                    err, where = e, (t_ns, n, a, b)
        assert err <= TOL, f"{comp}: max abs error {err:.3e} at t={where[0] / 1e9} s, {where[1]}: recorded {where[2]!r}, FMPy {where[3]!r}"
        worst[comp] = err
    return worst


def compare_messages(rec, m) -> int:
    topics = {t for t, _, _ in m.bus_messages}
    assert "/odom" in topics
    recorded = [(r.topic, r.log_time, r.data) for r in rec.records if r.topic in topics]
    recorded.sort(key=lambda x: x[1])  # stable: keeps file order within a log time
    assert len(recorded) == len(m.bus_messages), f"{len(recorded)} recorded FMU messages, {len(m.bus_messages)} replayed"
    for i, (a, b) in enumerate(zip(recorded, m.bus_messages)):
        assert a[0] == b[0] and a[1] == b[1], f"message {i}: recorded {a[0]} at {a[1]}, replay {b[0]} at {b[1]}"
        assert a[2] == b[2], f"message {i} on {a[0]} at {a[1] / 1e9} s: bytes differ"
    return len(recorded)


@pytest.mark.parametrize("chassis", [None, "ChassisDynamic.fmu"], ids=["default", "dynamic"])
def test_fmpy_master_reproduces_recorded_run(tmp_path, chassis):
    extra = ("--fmu", f"chassis={chassis}") if chassis else ()
    rec, m = reproduce(tmp_path, *extra, overrides={"chassis": chassis} if chassis else None)
    want = "ChassisDynamic" if chassis else "ChassisKinematic"
    assert rec.metadata["agrisim.run"]["fmu.chassis"] == want
    worst = compare_signals(rec, m)
    n = compare_messages(rec, m)
    # The replay must have exercised the interesting parts: messages in, messages out, set-points.
    chassis_sig = m.signals["chassis"]
    assert chassis_sig[-1][2][chassis_sig[-1][1].index("cmd_vel_seq")] >= 100
    assert n >= 200
    lift = m.signals["lift"]
    assert max(v[v_names.index("position")] for _, v_names, v in lift) > 0.55
    print(f"{want}: max abs error per component {worst}, {n} /odom messages byte-identical")


def test_fmpy_master_reproduces_decimated_exchange(tmp_path):
    """Connections with their own exchange periods (org.agrisim.exchange annotations): odometry
    out every 0.2 s, commands in every 0.3 s, the lift -> chassis physics coupling every 0.06 s
    (with the dynamic chassis, whose physics uses the payload). The chassis keeps 0.2 s of
    odometry in its port (port_window) so the slower route loses nothing; with the default
    0.1 s the run stops with a sequence-gap error naming the port."""
    periods = {("odom", "odom"): 0.2, ("cmd_vel", "cmd_vel"): 0.3,
               ("payload_mass", "payload_mass"): 0.06, ("payload_height", "payload_height"): 0.06}
    (tmp_path / "short").mkdir()
    scenario, _ = annotated_scenario(tmp_path / "short", periods)
    p = run_agrisim("run", "--scenario", str(scenario), "--out", str(tmp_path / "short" / "out"), check=False)
    assert p.returncode != 0 and "FMU 'chassis': message port 'odom'" in p.stderr and "sequence gap" in p.stderr, p.stderr
    scenario, ssd = annotated_scenario(tmp_path, periods, chassis={"port_window": 0.2})
    rec, m = reproduce(tmp_path / "out", "--fmu", "chassis=ChassisDynamic.fmu", overrides={"chassis": "ChassisDynamic.fmu"},
                       scenario=scenario, ssd=ssd)
    worst = compare_signals(rec, m)
    n = compare_messages(rec, m)
    assert n == 201, "every 10 Hz odometry message, two per exchange"
    assert [r.period_ticks for r in m.routes] == [15, 10, 1, 3, 3]
    print(f"decimated: max abs error per component {worst}, {n} /odom messages byte-identical")


def test_replay_is_sensitive_to_what_it_reproduces(tmp_path):
    """Guards against a vacuous match: the same replay with another chassis seed must differ."""
    rec = read_mcap(agrisim_run(tmp_path))
    params = rec.metadata["agrisim.parameters.chassis"]
    params["seed"] = str(int(params["seed"]) + 1)
    m = MasterReplay(DEFAULT_SSD, rec)
    try:
        m.initialize()
        m.run(len(rec.topic("/clock")) - 1)
    finally:
        m.close()
    with pytest.raises(AssertionError, match="chassis: max abs error"):
        compare_signals(rec, m)
