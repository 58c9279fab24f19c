"""Timing of a recorded run and of the FMUs' own schedules.

- /clock: one point per 0.02 s step, none missing, log time = simulation time.
- every message lies on its connection's exchange grid (from the .ssd: scalar connections
  every step, Binary ones every 1/message_rate unless an org.agrisim.exchange annotation sets
  a period), node outputs on the message grid, signals every step;
- /odom header stamps lie on the 1/odom_rate grid;
- the chassis schedules odometry on simulation time: driven by FMPy at another communication
  step (0.05 s, 0.01 s, 0.03 s), its odom stamps still land on the 0.1 s grid.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from rosbags.typesys import Stores, get_typestore

import agrisim_frames
from agrisim_fmpy import (DEFAULT_SSD, Slave, agrisim_run, annotated_scenario, fmu_path, parse_ssd, read_mcap,
                          ticks_of)

TYPESTORE = get_typestore(Stores.ROS2_HUMBLE)


def time_ns(stamp) -> int:
    return stamp.sec * 1_000_000_000 + stamp.nanosec


def stamp_ns(header) -> int:
    return time_ns(header.stamp)


def connection_periods(ssd: Path, step: float, message_period: float) -> dict[str, float]:
    """Topic -> exchange period of the connections from an FMU output to the bus: these are
    recorded when the route moves them. (Bus -> FMU topics are recorded when a node publishes;
    their route period shows in the destination's counter, checked separately.)"""
    sysf = parse_ssd(ssd)
    out = {}
    for c in sysf.connections:
        if c.start.element is None or c.end.element is not None:
            continue
        topic = c.end.connector
        is_message = sysf.connectors.get(topic) == "Binary"
        out[topic] = c.period if c.period is not None else (message_period if is_message else step)
    return out


def check_run_timing(mcap: Path, ssd: Path) -> dict[str, int]:
    rec = read_mcap(mcap)
    run = rec.metadata["agrisim.run"]
    step, message_period = float(run["step"]), 1.0 / float(run["message_rate"])
    step_ns = round(step * 1e9)
    assert step_ns == 20_000_000

    clock = rec.topic("/clock")
    assert [r.log_time for r in clock] == [k * step_ns for k in range(len(clock))], "a /clock point is missing or off-grid"
    assert all(time_ns(r.msg.clock) == r.log_time for r in clock)
    end = clock[-1].log_time

    periods = connection_periods(ssd, step, message_period)
    grid_ns = {topic: ticks_of(p, step) * step_ns for topic, p in periods.items()}
    counts = {}
    for topic in sorted({r.topic for r in rec.records}):
        if topic in grid_ns:
            g = None  # an FMU's messages are logged at their own stamps (checked below for /odom)
        elif topic.startswith("/fmu/") or topic in ("/clock", "/agrisim/scalars"):
            g = step_ns  # recorded every step
        else:
            g = ticks_of(message_period, step) * step_ns  # algorithm-layer nodes run at the message rate
        times = [r.log_time for r in rec.topic(topic)]
        off = [t for t in times if g and t % g]
        assert not off, f"{topic}: log times off its {g / 1e9} s grid: {off[:5]}"
        assert all(0 <= t <= end for t in times)
        counts[topic] = len(times)

    # Signals every step, none missing.
    for topic in [t for t in counts if t.startswith("/fmu/")]:
        assert [r.log_time for r in rec.topic(topic)] == [r.log_time for r in clock], topic

    # /odom: header stamps on the 1/odom_rate grid, published at every instant of its route.
    odom_rate = float(rec.metadata["agrisim.parameters.chassis"].get("odom_rate", "10.0"))
    odom_period_ns = round(1e9 / odom_rate)
    odom = rec.topic("/odom")
    assert odom, "no /odom recorded"
    stamps = [stamp_ns(TYPESTORE.deserialize_cdr(r.data, "nav_msgs/msg/Odometry").header) for r in odom]
    assert all(s % odom_period_ns == 0 for s in stamps), f"/odom stamps off the {odom_period_ns} ns grid"
    assert [r.log_time for r in odom] == stamps, "an /odom message is logged at its own stamp"
    # Every message, whatever the route's period (the port keeps them until it is read).
    assert stamps == list(range(0, end + 1, odom_period_ns)), "an /odom message is missing"
    return counts


def test_default_run_timing(tmp_path):
    counts = check_run_timing(agrisim_run(tmp_path), DEFAULT_SSD)
    assert counts["/clock"] == 1001 and counts["/odom"] == 201
    assert counts["/cmd_vel"] == 150  # 0 s .. 15 s at 10 Hz, then silent


def test_annotated_exchange_periods_are_obeyed(tmp_path):
    scenario, ssd = annotated_scenario(tmp_path, {("odom", "odom"): 0.2, ("cmd_vel", "cmd_vel"): 0.3}, chassis={"port_window": 0.2})
    assert parse_ssd(ssd).connections[0].period == 0.3
    counts = check_run_timing(agrisim_run(tmp_path / "out", scenario=scenario), ssd)
    assert counts["/odom"] == 201, "a route every 0.2 s still delivers every 10 Hz message"
    # The command script still publishes at 10 Hz (0 .. 14.9 s); only the route into the chassis
    # is slower: it delivers the latest message every 0.3 s, the last one (14.9 s) at 15.0 s.
    rec = read_mcap(tmp_path / "out" / "run.mcap")
    sig = rec.topic("/fmu/chassis/signals")
    seq = [(r.log_time, r.msg.values[list(r.msg.names).index("cmd_vel_seq")]) for r in sig]
    changes = [t for (_, a), (t, b) in zip(seq, seq[1:]) if b != a]
    assert seq[0][1] == 1 and changes == list(range(300_000_000, 15_000_000_001, 300_000_000)), changes[:5]


@pytest.mark.parametrize("h_ns", [50_000_000, 10_000_000, 30_000_000], ids=["0.05", "0.01", "0.03"])
def test_chassis_odom_stays_on_its_grid_at_other_communication_steps(tmp_path, h_ns):
    s = Slave(fmu_path("ChassisKinematic"), "chassis", unzip_root=tmp_path)
    try:
        s.set("cmd_vx", 0.3)
        s.set("cmd_timeout", 0.0)
        s.initialize(0.0)
        stamps, cursor = [], agrisim_frames.Cursor()
        end_ns = 3_000_000_000
        for k in range(end_ns // h_ns + 1):
            for f in cursor.take(s.get("odom"), s.get("odom_seq")):
                msg = TYPESTORE.deserialize_cdr(f.payload, "nav_msgs/msg/Odometry")
                st = stamp_ns(msg.header)
                assert st == f.stamp_ns, "the frame carries the message's stamp"
                t_ns = k * h_ns
                assert st <= t_ns < st + max(h_ns, 100_000_000), f"stamp {st} at communication point {t_ns}"
                stamps.append(st)
            if k * h_ns < end_ns:
                s.do_step(k * h_ns / 1e9, h_ns / 1e9)
    finally:
        s.close()
    # Every 0.1 s instant once, whatever the step (all steps here are <= 0.1 s).
    assert stamps == list(range(0, end_ns + 1, 100_000_000)), stamps
