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

FMI 2 (`--fmi 2` or `both`, the default): the FMI 2 builds of the same two FMUs
(target/fmu/fmi2) in a system file written to the temporary directory (FMI 2 has no Binary,
so no /cmd_vel or /odom messages: the lift follows the scenario's set-points, its payload is
copied to the chassis every step, and the chassis gets no command), run by the same
`agrisim bench overhead`, against FMPy's FMU2Slave doing the same per-step work
(setupExperiment, enter/exit initialization, the recorded set-points, the payload copies,
every scalar input/output read one by one, doStep on both), then a bare doStep loop.

Usage: .venv/bin/python python/bench_overhead.py --steps 20000 [--fmi 3|2|both]
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

from fmpy import extract, read_model_description  # noqa: E402
from fmpy.fmi2 import FMU2Slave  # noqa: E402

from agrisim_fmpy import DEFAULT_SCENARIO, FMU2_DIR, FMU_DIR, Slave, run_agrisim  # noqa: E402


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


def fmi3(args, n: int) -> dict:
    """The FMI 3 comparison (see the module doc)."""
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
    return report


# The FMI 2 system: base.ssd's chassis and lift as their FMI 2 builds, scalar ports only.
FMI2_SSD = """<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription version="1.0" name="agrisim_base_fmi2"
    xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon"
    xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues"
    xmlns:agrisim="https://agrisim.dev/ssp">
  <ssd:System name="harvesting_robot_fmi2">
    <ssd:Connectors>
      <ssd:Connector name="lift_setpoint" kind="input"><ssc:Real unit="m"/><ssd:Annotations><ssc:Annotation type="org.agrisim.topic"><agrisim:Topic name="/lift/setpoint"/></ssc:Annotation></ssd:Annotations></ssd:Connector>
    </ssd:Connectors>
    <ssd:Elements>
      <ssd:Component name="chassis" type="application/x-fmu-sharedlibrary" source="{chassis}">
        <ssd:Connectors>
          <ssd:Connector name="payload_mass" kind="input"><ssc:Real unit="kg"/></ssd:Connector>
          <ssd:Connector name="payload_height" kind="input"><ssc:Real unit="m"/></ssd:Connector>
        </ssd:Connectors>
        <ssd:ParameterBindings><ssd:ParameterBinding><ssd:ParameterValues>
          <ssv:ParameterSet version="1.0" name="chassis"><ssv:Parameters>
            <ssv:Parameter name="wheel_base"><ssv:Real value="1.0"/></ssv:Parameter>
            <ssv:Parameter name="track"><ssv:Real value="0.8"/></ssv:Parameter>
            <ssv:Parameter name="wheel_radius"><ssv:Real value="0.1"/></ssv:Parameter>
            <ssv:Parameter name="odom_rate"><ssv:Real value="10"/></ssv:Parameter>
          </ssv:Parameters></ssv:ParameterSet>
        </ssd:ParameterValues></ssd:ParameterBinding></ssd:ParameterBindings>
      </ssd:Component>
      <ssd:Component name="lift" type="application/x-fmu-sharedlibrary" source="{lift}">
        <ssd:Connectors>
          <ssd:Connector name="setpoint" kind="input"><ssc:Real unit="m"/></ssd:Connector>
          <ssd:Connector name="payload_mass" kind="output"><ssc:Real unit="kg"/></ssd:Connector>
          <ssd:Connector name="payload_height" kind="output"><ssc:Real unit="m"/></ssd:Connector>
        </ssd:Connectors>
      </ssd:Component>
    </ssd:Elements>
    <ssd:Connections>
      <ssd:Connection startConnector="lift_setpoint" endElement="lift" endConnector="setpoint"/>
      <ssd:Connection startElement="lift" startConnector="payload_mass" endElement="chassis" endConnector="payload_mass"/>
      <ssd:Connection startElement="lift" startConnector="payload_height" endElement="chassis" endConnector="payload_height"/>
    </ssd:Connections>
  </ssd:System>
  <ssd:DefaultExperiment startTime="0" stopTime="20"/>
</ssd:SystemStructureDescription>
"""

# base.toml's timing, chassis noise and lift script; no base commands (no /cmd_vel port).
FMI2_SCENARIO = """name = "base_fmi2"
seed = 1
duration = 20.0
[timing]
step = 0.02
message_rate = 10.0
[system]
file = "base_fmi2.ssd"
[parameters.chassis]
enc_noise = 0.05
steer_noise = 0.002
slip_mean = 0.01
slip_std = 0.02
cmd_timeout = 0.5
[[lift_commands]]
t = 2.0
position = 0.6
[[lift_commands]]
t = 12.0
position = 0.3
"""

FMI2_SCALARS = ("Real", "Integer", "Boolean")


class Slave2:
    """An FMU2Slave addressed by variable name (the FMI 2 counterpart of agrisim_fmpy.Slave)."""

    def __init__(self, fmu: Path, instance_name: str, unzip_root: Path):
        self.md = read_model_description(str(fmu))
        assert self.md.fmiVersion.startswith("2"), f"{fmu}: not an FMI 2 FMU"
        self._unzip = extract(str(fmu), tempfile.mkdtemp(prefix=f"agrisim-{instance_name}-", dir=unzip_root))
        self.vars = {v.name: v for v in self.md.modelVariables}
        self.slave = FMU2Slave(guid=self.md.guid, unzipDirectory=self._unzip,
                               modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=instance_name)
        self.slave.instantiate()
        self._setters = {"Real": self.slave.setReal, "Integer": self.slave.setInteger, "Boolean": self.slave.setBoolean}

    def var(self, name: str):
        assert name in self.vars, f"{self.md.modelName} has no variable {name!r}"
        return self.vars[name]

    def set_text(self, name: str, text: str) -> None:
        v = self.var(name)
        value = {"Real": float, "Integer": int, "Boolean": lambda x: x == "true"}[v.type](text)
        self._setters[v.type]([v.valueReference], [value])

    def scalar_signals(self) -> list[str]:
        return [v.name for v in self.md.modelVariables
                if v.causality in ("input", "output") and v.type in FMI2_SCALARS]

    def close(self) -> None:
        self.slave.terminate()
        self.slave.freeInstance()


def fmi2(n: int) -> dict:
    """The FMI 2 comparison (see the module doc)."""
    with tempfile.TemporaryDirectory(prefix="agrisim-bench2-") as tmp:
        tmp = Path(tmp)
        fmus = {m: FMU2_DIR / f"{m}.fmu" for m in ("ChassisKinematic", "Lift")}
        for p in fmus.values():
            assert p.exists(), f"{p} not packed: run `agrisim fmu pack`"
        (tmp / "base_fmi2.ssd").write_text(FMI2_SSD.format(chassis=fmus["ChassisKinematic"], lift=fmus["Lift"]))
        scenario = tmp / "base_fmi2.toml"
        scenario.write_text(FMI2_SCENARIO)
        p = run_agrisim("bench", "overhead", "--scenario", str(scenario), "--steps", str(n), "--out", str(tmp / "bench"))
        agrisim = json.loads(p.stdout)
        p = run_agrisim("bench", "overhead", "--scenario", str(scenario), "--steps", str(n), "--record", "none", "--out", str(tmp / "bench_none"))
        agrisim_unrecorded = json.loads(p.stdout)
        meta, _cmd, setpoint, recorded = recorded_inputs(tmp / "bench" / "bench.mcap")
        run = meta["agrisim.run"]
        step_ns = round(float(run["step"]) * 1e9)
        assert run["fmu.chassis"] == "ChassisKinematic" and run["fmu.lift"] == "Lift", run

        chassis = Slave2(fmus["ChassisKinematic"], "chassis", tmp)
        lift = Slave2(fmus["Lift"], "lift", tmp)
        for name, s in (("chassis", chassis), ("lift", lift)):
            for pname, text in meta.get(f"agrisim.parameters.{name}", {}).items():
                s.set_text(pname, text)
        for s in (chassis, lift):
            s.slave.setupExperiment(startTime=0.0)
            s.slave.enterInitializationMode()
        for s in (chassis, lift):
            s.slave.exitInitializationMode()

        c, l = chassis.slave, lift.slave
        vr = lambda s, name: [s.var(name).valueReference]  # noqa: E731
        lift_sp = vr(lift, "setpoint")
        copies = [(vr(lift, a), vr(chassis, a)) for a in ("payload_mass", "payload_height")]
        getter = {"Real": "getReal", "Integer": "getInteger", "Boolean": "getBoolean"}
        readers = [[(getattr(s.slave, getter[s.var(v).type]), vr(s, v)) for v in s.scalar_signals()] for s in (chassis, lift)]
        h = step_ns / 1e9

        last = None
        t0 = time.perf_counter()
        for k in range(n):
            t_ns = k * step_ns
            sp = setpoint.get(t_ns)
            if sp is not None:
                l.setReal(lift_sp, [sp])
            for src, dst in copies:
                c.setReal(dst, l.getReal(src))
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
    return {
        "steps": n,
        "fmus": 2,
        "agrisim": agrisim,
        "fmpy_fmu2slave": fmpy,
        "agrisim_without_recording": agrisim_unrecorded,
        "ratio_fmpy_loop_over_agrisim_master": fmpy["loop_us_per_fmu_step"] / agrisim["master_us_per_fmu_step"],
        "ratio_fmpy_loop_over_agrisim_master_without_recording": fmpy["loop_us_per_fmu_step"] / agrisim_unrecorded["master_us_per_fmu_step"],
        "ratio_fmpy_overhead_over_agrisim_overhead": fmpy["overhead_us_per_fmu_step"] / agrisim["overhead_us_per_fmu_step"],
        "fmpy_loop_records_mcap": False,
        "fmpy_vs_recorded_last_signals_max_abs_error": err,
    }


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--steps", type=int, default=20000)
    ap.add_argument("--scenario", type=Path, default=DEFAULT_SCENARIO, help="the FMI 3 part's scenario")
    ap.add_argument("--fmi", choices=("3", "2", "both"), default="both")
    args = ap.parse_args()
    if args.steps < 2:
        ap.error("--steps must be at least 2")
    report = {}
    if args.fmi in ("3", "both"):
        report["fmi3"] = fmi3(args, args.steps)
    if args.fmi in ("2", "both"):
        report["fmi2"] = fmi2(args.steps)
    print(json.dumps(report, indent=2))
    worst = max(r["fmpy_vs_recorded_last_signals_max_abs_error"] for r in report.values())
    return 0 if worst <= 1e-9 else 1


if __name__ == "__main__":
    sys.exit(main())
