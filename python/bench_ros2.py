"""Benchmarks of the live ROS 2 link, against Eclipse Cyclone DDS peers (the `cyclonedds`
package), in a private network namespace with only loopback (needs `unshare -n`):

* round trip sim -> external node -> sim at 10 Hz, lockstep: the bridge publishes the
  instant's messages and /clock, an echo peer answers each /clock with a /cmd_vel; the wall
  time until the answer is on the bus (p50/p99/max; default greenhouse, LiDAR clouds too);
* jitter of /clock against the wall clock in realtime mode (1x): each tick's arrival at the
  peer minus its due time (sim time since the first tick), p50/p99/max;
* bandwidth and delivered rate of the full sensor suite (camera RGB + depth + labels, LiDAR
  20,000 points, IMU, joint states) over DDS on loopback: a best-effort subscriber counts what
  arrives against what the bridge published.

The round trip and the sensor suite are measured over Zenoh too (`--zenoh`, rmw_zenoh's
format), beside DDS on the same runs: an Eclipse Zenoh peer (the `eclipse-zenoh` package,
tests/zenoh_node.py) plays the same parts on tcp/127.0.0.1:7447.

    .venv/bin/python python/bench_ros2.py [--json OUT]     (runs itself inside `unshare -n`)
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests"))
AGRISIM = os.environ.get("AGRISIM_BIN", str(REPO / "target/release/agrisim"))


def percentiles(v: list[float]) -> dict:
    v = sorted(v)
    if not v:
        return {}
    q = lambda p: v[min(len(v) - 1, max(0, int(round(p * len(v) + 0.5)) - 1))]  # noqa: E731
    return {"n": len(v), "p50": q(0.5), "p99": q(0.99), "max": v[-1]}


def peer(cmd: list[str], mode: str, seconds: float = 600) -> dict:
    """Starts `cmd` and plays the peer: 'echo' answers every /clock with a /cmd_vel; 'clock'
    records /clock arrivals; 'sensors' counts sensor messages and bytes."""
    from cyclonedds._clayer import ddspy_take
    from cyclonedds.core import InstanceState, Policy, Qos, SampleState, ViewState
    from cyclonedds.domain import DomainParticipant
    from cyclonedds.internal import InvalidSample
    from cyclonedds.pub import DataWriter
    from cyclonedds.sub import DataReader
    from cyclonedds.topic import Topic
    from cyclonedds.util import duration
    from ros2_idl import Clock, Twist

    any_state = SampleState.Any | ViewState.Any | InstanceState.Any
    reliable = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepAll)
    best_effort = Qos(Policy.Reliability.BestEffort, Policy.History.KeepLast(50))
    dp = DomainParticipant(0)
    clock = DataReader(dp, Topic(dp, "rt/clock", Clock), qos=reliable)
    cmd_w = DataWriter(dp, Topic(dp, "rt/cmd_vel", Twist), qos=reliable) if mode == "echo" else None
    counters = {}
    if mode == "sensors":
        from ros2_idl import Image, PointCloud2

        readers = {t: DataReader(dp, Topic(dp, "rt" + t, PointCloud2 if t == "/points" else Image), qos=best_effort) for t in ["/points", "/camera/color/image_raw", "/camera/aligned_depth_to_color/image_raw", "/camera/labels"]}
        counters = {t: [0, 0] for t in readers}
    proc = subprocess.Popen(cmd, stderr=subprocess.PIPE, text=True)
    ticks: list[tuple[float, int]] = []
    t_first = None
    deadline = time.monotonic() + seconds
    while proc.poll() is None and time.monotonic() < deadline:
        got = [m for m in clock.take(N=100) if not isinstance(m, InvalidSample)]
        now = time.perf_counter()
        for m in got:
            ticks.append((now, m.clock.sec * 1_000_000_000 + m.clock.nanosec))
            if cmd_w is not None:
                cmd_w.write(Twist())
        if mode == "sensors":
            # Serialized samples as they arrived, not decoded: the peer counts bytes and
            # messages at DDS speed (decoding megabytes into Python lists would be the
            # bottleneck measured instead).
            for t, r in readers.items():
                ret = ddspy_take(r._ref, any_state, 50)
                for data, info in ret if not isinstance(ret, int) else []:
                    if not info.valid_data:
                        continue
                    if t_first is None:
                        t_first = now
                    counters[t][0] += 1
                    counters[t][1] += len(data)
        if not got:
            time.sleep(0.0001)
    stderr = proc.communicate()[1]
    return {"ticks": ticks, "counters": counters, "returncode": proc.returncode, "stderr": stderr, "t_first": t_first, "t_end": time.perf_counter()}


ZENOH = "tcp/127.0.0.1:7447"
SENSOR_TOPICS = ["/points", "/camera/color/image_raw", "/camera/aligned_depth_to_color/image_raw", "/camera/labels"]


def peer_zenoh(cmd: list[str], mode: str, seconds: float = 600) -> dict:
    """The peer of `peer` over Zenoh: 'echo' answers every /clock with a /cmd_vel; 'sensors'
    counts sensor samples and bytes (not decoded)."""
    import zenoh_node
    from ros2_idl import Twist

    proc = subprocess.Popen(cmd, stderr=subprocess.PIPE, text=True)
    session = zenoh_node.open_session(ZENOH, proc, timeout=60)
    node = zenoh_node.ZenohNode(session, 0, "bench_peer")
    clock = session.declare_subscriber("0/clock/*/*")
    node.token("MS", "/clock", "rosgraph_msgs/msg/Clock")
    cmd_w = node.writer("/cmd_vel", "geometry_msgs/msg/Twist") if mode == "echo" else None
    subs = {t: session.declare_subscriber(f"0/{t.strip('/')}/*/*") for t in SENSOR_TOPICS} if mode == "sensors" else {}
    counters = {t: [0, 0] for t in subs}
    t_first = None
    deadline = time.monotonic() + seconds
    while proc.poll() is None and time.monotonic() < deadline:
        got = False
        while clock.try_recv() is not None:
            got = True
            if cmd_w is not None:
                cmd_w.write(Twist())
        now = time.perf_counter()
        for t, sub in subs.items():
            while (smp := sub.try_recv()) is not None:
                got = True
                t_first = t_first or now
                counters[t][0] += 1
                counters[t][1] += len(smp.payload)
        if not got:
            time.sleep(0.0001)
    stderr = proc.communicate()[1]
    session.close()
    return {"counters": counters, "returncode": proc.returncode, "stderr": stderr, "t_first": t_first, "t_end": time.perf_counter()}


def inside(part: str) -> dict:
    out: dict = {}
    with tempfile.TemporaryDirectory() as d:
        stats = Path(d) / "stats.json"
        if part == "sensors":
            return sensors(d, stats)
        if part == "zenoh_sensors":
            return sensors(d, stats, zenoh=True)
        if part == "zenoh_link":
            r = peer_zenoh([AGRISIM, "run", "--duration", "30", "--record", "none", "--zenoh", "--zenoh-listen", ZENOH, "--external", "command_script", "--ros2-stats", str(stats), "--out", d + "/rt"], "echo")
            s = json.loads(stats.read_text())
            return {"round_trip_ms": s["round_trip_ms"] | {"lockstep_timeouts": s["lockstep_timeouts"], "returncode": r["returncode"]}}
        # 1. Round trip, lockstep, default greenhouse (clouds included), 30 s simulated.
        r = peer([AGRISIM, "run", "--duration", "30", "--record", "none", "--ros2", "--external", "command_script", "--ros2-stats", str(stats), "--out", d + "/rt"], "echo")
        s = json.loads(stats.read_text())
        out["round_trip_ms"] = s["round_trip_ms"] | {"lockstep_timeouts": s["lockstep_timeouts"], "returncode": r["returncode"]}
        # 2. /clock jitter in realtime mode (1x), 20 s.
        r = peer([AGRISIM, "run", "--duration", "20", "--record", "none", "--ros2", "--ros2-mode", "realtime", "--out", d + "/clk"], "clock")
        ticks = r["ticks"]
        w0, s0 = ticks[0]
        late = [1e3 * ((w - w0) - (s - s0) * 1e-9) for w, s in ticks]
        out["clock_jitter_ms"] = percentiles([abs(x) for x in late]) | {"ticks": len(ticks), "mean_late_ms": sum(late) / len(late)}
    return out


def sensors(d: str, stats: Path, zenoh: bool = False) -> dict:
    """3. The full sensor suite over DDS or Zenoh (free running: nobody is waited for), 3 s simulated."""
    if True:
        run = [AGRISIM, "run", "--scenario", str(REPO / "models/scenarios/sensors.toml"), "--duration", "3", "--record", "none", "--ros2-stats", str(stats), "--out", d + "/sens"]
        if zenoh:
            r = peer_zenoh(run + ["--zenoh", "--zenoh-listen", ZENOH], "sensors")
        else:
            r = peer(run + ["--ros2"], "sensors")
        s = json.loads(stats.read_text())
        wall = r["t_end"] - (r["t_first"] or r["t_end"])
        per = {}
        total_bytes = 0
        for t, (n, b) in r["counters"].items():
            pub = s["topics"].get(t, {"messages": 0})["messages"]
            per[t] = {"published": pub, "received": n, "delivered": n / pub if pub else None, "MB": b / 1e6}
            total_bytes += b
        return {"topics": per, "received_MB_per_wall_s": total_bytes / 1e6 / wall if wall > 0 else None, "wall_s": wall, "published_MB": s["published_bytes"] / 1e6}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--json")
    ap.add_argument("--inside", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.inside:
        print(json.dumps(inside(a.inside)))
        return
    import netns

    if (why := netns.available()) is not None:
        sys.exit(f"bench_ros2: {why}")

    def part(name: str, env: dict | None = None) -> dict:
        r = netns.run([sys.executable, __file__, "--inside", name], timeout=1800, capture_output=True, text=True, env=env)
        if r.returncode != 0:
            sys.exit(r.stdout + r.stderr)
        return json.loads(r.stdout.strip().splitlines()[-1])

    res = part("link")
    res["zenoh"] = part("zenoh_link")
    # Large best-effort messages need socket buffers to match (as on a real ROS 2 machine):
    # the subscriber's default (the kernel's 208 KB), then 4 MB (this machine's rmem_max).
    res["sensor_suite_default_buffers"] = part("sensors")
    big = '<CycloneDDS><Domain><Internal><SocketReceiveBufferSize min="4MB"/></Internal></Domain></CycloneDDS>'
    res["sensor_suite_4MB_receive_buffer"] = part("sensors", dict(os.environ, CYCLONEDDS_URI=big))
    res["zenoh_sensor_suite"] = part("zenoh_sensors")
    print(json.dumps(res, indent=2))
    if a.json:
        Path(a.json).write_text(json.dumps(res, indent=2))


if __name__ == "__main__":
    main()
