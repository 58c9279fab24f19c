#!/usr/bin/env python3
"""Master overhead: agrisim's orchestrator beside an FMPy loop doing the same per-step work.

Runs `agrisim bench overhead --steps N --out TMP` (the orchestrator's own figures: full master
loop, bare fmi3DoStep, their difference, all in µs per FMU and step), then drives the same two
FMUs (ChassisKinematic, Lift) through FMPy's FMU3Slave with the work the master does per step:

  - at 10 Hz: odom_seq read, odom Binary read when it moved; cmd_vel Binary + cmd_vel_seq set
    when the command script published (the exact bytes and instants of the orchestrator's run,
    read back from TMP/bench.mcap, as are the parameters and the lift set-points);
  - every step: lift setpoint set, payload_mass/payload_height copied lift -> chassis, every
    scalar input/output of both FMUs read one by one (as the recorder does), doStep on both;

then a bare doStep loop on the same instances. The FMPy loop does not write an MCAP; the
orchestrator's figure includes recording, and it is measured a second time without
(`--record none`). As a sanity check, the FMPy loop's last scalar
readings must equal the orchestrator's recorded ones (same work, same answers).

Usage: .venv/bin/python python/bench_overhead.py --steps 20000
Prints one JSON object. Wall-clock timings: a report, not a test.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from mcap.reader import make_reader  # noqa: E402
from mcap_ros2.decoder import DecoderFactory  # noqa: E402

from agrisim_fmpy import DEFAULT_SCENARIO, FMU_DIR, Slave, run_agrisim  # noqa: E402


def recorded_inputs(mcap: Path):
    """Metadata, /cmd_vel raw bytes by log time, lift set-point by log time, last signals."""
    cmd, setpoint, signals = {}, {}, {}
    with open(mcap, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        meta = {m.name: dict(m.metadata) for m in reader.iter_metadata()}
        topics = ["/cmd_vel", "/agrisim/scalars", "/fmu/chassis/signals", "/fmu/lift/signals"]
        for _schema, channel, message, msg in reader.iter_decoded_messages(topics=topics, log_time_order=False):
            if channel.topic == "/cmd_vel":
                cmd[message.log_time] = bytes(message.data)
            elif channel.topic == "/agrisim/scalars":
                setpoint[message.log_time] = dict(zip(msg.names, msg.values))["/lift/setpoint"]
            else:
                signals[(channel.topic, message.log_time)] = list(msg.values)
    return meta, cmd, setpoint, signals


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--steps", type=int, default=20000)
    ap.add_argument("--scenario", type=Path, default=DEFAULT_SCENARIO)
    args = ap.parse_args()
    if args.steps < 2:
        ap.error("--steps must be at least 2")
    n = args.steps

    with tempfile.TemporaryDirectory(prefix="agrisim-bench-") as tmp:
        tmp = Path(tmp)
        p = run_agrisim("bench", "overhead", "--scenario", str(args.scenario), "--steps", str(n), "--out", str(tmp / "bench"))
        agrisim = json.loads(p.stdout)
        # The same run without recording (the inputs the FMPy loop replays come from the one above).
        p = run_agrisim("bench", "overhead", "--scenario", str(args.scenario), "--steps", str(n), "--record", "none", "--out", str(tmp / "bench_none"))
        agrisim_unrecorded = json.loads(p.stdout)
        meta, cmd, setpoint, recorded = recorded_inputs(tmp / "bench" / "bench.mcap")
        step_ns = round(float(meta["agrisim.run"]["step"]) * 1e9)
        message_ticks = round(1e9 / float(meta["agrisim.run"]["message_rate"]) / step_ns)
        assert meta["agrisim.run"]["fmu.chassis"] == "ChassisKinematic" and meta["agrisim.run"]["fmu.lift"] == "Lift"

        chassis = Slave(FMU_DIR / "ChassisKinematic.fmu", "chassis", unzip_root=tmp)
        lift = Slave(FMU_DIR / "Lift.fmu", "lift", unzip_root=tmp)
        for name, s in (("chassis", chassis), ("lift", lift)):
            for pname, text in meta.get(f"agrisim.parameters.{name}", {}).items():
                s.set_text(pname, text)
        for s in (chassis, lift):
            s.slave.enterInitializationMode(startTime=0.0)
        for s in (chassis, lift):
            s.slave.exitInitializationMode()

        # Pre-resolved calls: what a careful FMPy user would write.
        c, l = chassis.slave, lift.slave
        vr = lambda s, name: [s.var(name).valueReference]  # noqa: E731
        odom_seq, odom = vr(chassis, "odom_seq"), vr(chassis, "odom")
        cmd_vel, cmd_vel_seq = vr(chassis, "cmd_vel"), vr(chassis, "cmd_vel_seq")
        lift_sp = vr(lift, "setpoint")
        copies = [(vr(lift, a), vr(chassis, a)) for a in ("payload_mass", "payload_height")]
        getter = {"Float64": "getFloat64", "Int32": "getInt32", "Int64": "getInt64", "Boolean": "getBoolean"}
        readers = [[(getattr(s.slave, getter[s.var(v).type]), vr(s, v)) for v in s.scalar_signals()] for s in (chassis, lift)]
        h = step_ns / 1e9

        seen, written, last = 0, 0, None
        t0 = time.perf_counter()
        for k in range(n):
            t_ns = k * step_ns
            if k % message_ticks == 0:
                m = c.getInt64(odom_seq)[0]
                if m != seen:
                    seen = m
                    c.getBinary(odom)
                b = cmd.get(t_ns)
                if b is not None:
                    c.setBinary(cmd_vel, [b])
                    written += 1
                    c.setInt64(cmd_vel_seq, [written])
            sp = setpoint.get(t_ns)
            if sp is not None:
                l.setFloat64(lift_sp, [sp])
            for src, dst in copies:
                c.setFloat64(dst, l.getFloat64(src))
            last = [[float(get(r)[0]) for get, r in comp] for comp in readers]
            t = t_ns / 1e9
            c.doStep(t, h)
            l.doStep(t, h)
        loop_s = time.perf_counter() - t0

        start = n * step_ns / 1e9
        t1 = time.perf_counter()
        for k in range(n):
            t = start + k * h
            c.doStep(t, h)
            l.doStep(t, h)
        step_s = time.perf_counter() - t1
        chassis.close()
        lift.close()

    t_last = (n - 1) * step_ns
    err = max(abs(a - b) for comp, values in zip(("chassis", "lift"), last)
              for a, b in zip(values, recorded[(f"/fmu/{comp}/signals", t_last)]))
    per = lambda secs: secs * 1e6 / (n * 2)  # noqa: E731
    fmpy = {
        "loop_us_per_fmu_step": per(loop_s),
        "do_step_us_per_fmu_step": per(step_s),
        "overhead_us_per_fmu_step": per(loop_s - step_s),
    }
    report = {
        "steps": n,
        "fmus": 2,
        "agrisim": agrisim,
        "fmpy": fmpy,
        "agrisim_without_recording": agrisim_unrecorded,
        "ratio_fmpy_loop_over_agrisim_master": fmpy["loop_us_per_fmu_step"] / agrisim["master_us_per_fmu_step"],
        "ratio_fmpy_loop_over_agrisim_master_without_recording": fmpy["loop_us_per_fmu_step"] / agrisim_unrecorded["master_us_per_fmu_step"],
        "ratio_fmpy_overhead_over_agrisim_overhead": fmpy["overhead_us_per_fmu_step"] / agrisim["overhead_us_per_fmu_step"],
        "fmpy_loop_records_mcap": False,
        "fmpy_vs_recorded_last_signals_max_abs_error": err,
    }
    print(json.dumps(report, indent=2))
    return 0 if err <= 1e-9 else 1


if __name__ == "__main__":
    sys.exit(main())
