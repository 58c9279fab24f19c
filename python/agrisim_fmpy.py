"""Shared helpers of the FMPy checks in python/: where the packed FMUs and the CLI are, a thin
typed wrapper around FMPy's low-level FMU3Slave, an MCAP reader, the system file parser and
an independent re-implementation of the orchestrator's master algorithm (master.rs).

Everything here is written against public interfaces only (FMI 3 C API through FMPy,
modelDescription.xml, SSP .ssd, MCAP), so a match with the orchestrator is evidence, not a
tautology. Imports are plain: a missing package fails the test run instead of skipping it.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import fmpy
from fmpy import read_model_description
from fmpy.fmi3 import FMU3Slave
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

REPO = Path(__file__).resolve().parents[1]
# AGRISIM_FMU_DIR: check FMUs packed elsewhere (e.g. a private target dir).
FMU_DIR = Path(os.environ.get("AGRISIM_FMU_DIR", REPO / "target" / "fmu"))
FMU2_DIR = FMU_DIR / "fmi2"
DEFAULT_SCENARIO = REPO / "models" / "scenarios" / "base.toml"
DEFAULT_SSD = REPO / "models" / "systems" / "base.ssd"
EXPECTED_MODELS = ("ChassisKinematic", "ChassisDynamic", "Lift", "Arm")

NS = {
    "ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
    "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon",
    "ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues",
}
EXCHANGE_ANNOTATION = "org.agrisim.exchange"
SCALAR_TYPES = ("Float64", "Int32", "Int64", "Boolean")


# --------------------------------------------------------------------------------------------
# CLI


def agrisim_bin() -> Path:
    exe = Path(os.environ.get("AGRISIM_BIN", REPO / "target" / "release" / "agrisim"))
    if not exe.is_absolute():
        exe = REPO / exe
    assert exe.exists(), f"{exe} missing: run scripts/setup (cargo build --release && agrisim fmu pack)"
    return exe


def run_agrisim(*args: str, check: bool = True) -> subprocess.CompletedProcess:
    """Runs the CLI from the repository root; returns the completed process."""
    p = subprocess.run([str(agrisim_bin()), *args], cwd=REPO, capture_output=True, text=True)
    if check and p.returncode != 0:
        raise AssertionError(f"agrisim {' '.join(args)} failed ({p.returncode}):\n{p.stderr}")
    return p


def agrisim_run(out: Path, *extra: str, scenario: Path = DEFAULT_SCENARIO) -> Path:
    run_agrisim("run", "--scenario", str(scenario), "--out", str(out), *extra)
    return out / "run.mcap"


def fmu_path(name: str, version: int = 3) -> Path:
    p = (FMU_DIR if version == 3 else FMU2_DIR) / f"{name}.fmu"
    assert p.exists(), f"{p} not packed: run `agrisim fmu pack`"
    return p


# --------------------------------------------------------------------------------------------
# FMI 3 low-level driving


class Slave:
    """An FMU3Slave addressed by variable name, with typed get/set."""

    def __init__(self, fmu: Path | str, instance_name: str, unzip_root: Path | None = None):
        self.md = read_model_description(str(fmu))
        assert self.md.fmiVersion.startswith("3"), f"{fmu}: not an FMI 3 FMU"
        unzip = tempfile.mkdtemp(prefix=f"agrisim-{instance_name}-", dir=unzip_root)
        self._unzip = fmpy.extract(str(fmu), unzip)
        self.vars = {v.name: v for v in self.md.modelVariables}
        self.slave = FMU3Slave(guid=self.md.guid, unzipDirectory=self._unzip,
                               modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=instance_name)
        self.slave.instantiate()
        self._getters = {
            "Float64": self.slave.getFloat64, "Int32": self.slave.getInt32, "Int64": self.slave.getInt64,
            "Boolean": self.slave.getBoolean, "Binary": self.slave.getBinary,
        }
        self._setters = {
            "Float64": self.slave.setFloat64, "Int32": self.slave.setInt32, "Int64": self.slave.setInt64,
            "Boolean": self.slave.setBoolean, "Binary": self.slave.setBinary,
        }

    def var(self, name: str):
        assert name in self.vars, f"{self.md.modelName} has no variable {name!r}"
        return self.vars[name]

    def get(self, name: str):
        v = self.var(name)
        return self._getters[v.type]([v.valueReference])[0]

    def get_many(self, names: list[str]) -> list:
        return [self.get(n) for n in names]

    def set(self, name: str, value) -> None:
        v = self.var(name)
        self._setters[v.type]([v.valueReference], [value])

    def set_text(self, name: str, text: str) -> None:
        """Sets a parameter from its metadata text (Rust `{:?}` floats, decimal integers, true/false)."""
        v = self.var(name)
        if v.type == "Float64":
            self.set(name, float(text))
        elif v.type in ("Int32", "Int64"):
            self.set(name, int(text))
        elif v.type == "Boolean":
            assert text in ("true", "false"), f"{name}: boolean text {text!r}"
            self.set(name, text == "true")
        else:
            raise AssertionError(f"{name}: parameter of type {v.type} not handled")

    def scalar_signals(self) -> list[str]:
        """Scalar inputs and outputs in modelDescription order: what the orchestrator records."""
        return [v.name for v in self.md.modelVariables
                if v.causality in ("input", "output") and v.type in SCALAR_TYPES]

    def initialize(self, start_time: float = 0.0) -> None:
        self.slave.enterInitializationMode(startTime=start_time)
        self.slave.exitInitializationMode()

    def do_step(self, t: float, h: float) -> None:
        _event, terminate, _early, _last = self.slave.doStep(t, h)
        assert not terminate, f"{self.md.modelName} asked to terminate at t={t}"

    def close(self) -> None:
        try:
            self.slave.terminate()
            self.slave.freeInstance()
        finally:
            shutil.rmtree(self._unzip, ignore_errors=True)


def as_float(x) -> float:
    return float(x)  # bool -> 0/1, ints exact below 2**53


# --------------------------------------------------------------------------------------------
# MCAP


@dataclass
class Record:
    topic: str
    log_time: int
    data: bytes
    msg: object


@dataclass
class Recording:
    metadata: dict[str, dict[str, str]]
    records: list[Record]
    schemas: dict[str, str] = field(default_factory=dict)

    def topic(self, name: str) -> list[Record]:
        return [r for r in self.records if r.topic == name]


def read_mcap(path: Path) -> Recording:
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        metadata = {m.name: dict(m.metadata) for m in reader.iter_metadata()}
        records, schemas = [], {}
        for schema, channel, message, ros_msg in reader.iter_decoded_messages(log_time_order=False):
            records.append(Record(channel.topic, message.log_time, bytes(message.data), ros_msg))
            schemas[channel.topic] = schema.name
    return Recording(metadata, records, schemas)


# --------------------------------------------------------------------------------------------
# SSP system structure


@dataclass
class Endpoint:
    element: str | None
    connector: str


@dataclass
class Connection:
    start: Endpoint
    end: Endpoint
    period: float | None


@dataclass
class SystemFile:
    components: list[tuple[str, str]]  # (name, source) in file order
    connections: list[Connection]
    connectors: dict[str, str]  # system connector name -> "Binary" / "Real" / ...


TOPIC_ANNOTATION = "org.agrisim.topic"


def parse_ssd(path: Path) -> SystemFile:
    """The system file as the master needs it. System connectors are named by their topic
    (the `org.agrisim.topic` annotation, as the orchestrator reads it; else their name)."""
    root = ET.parse(path).getroot()
    system = root.find("ssd:System", NS)
    assert system is not None, f"{path}: no ssd:System"
    comps = [(c.get("name"), c.get("source")) for c in system.findall("ssd:Elements/ssd:Component", NS)]
    connectors, topic_of = {}, {}
    for c in system.findall("ssd:Connectors/ssd:Connector", NS):
        topic = c.get("name")
        for ann in c.findall("ssd:Annotations/ssc:Annotation", NS):
            if ann.get("type") == TOPIC_ANNOTATION:
                topic = next(n.get("name") for n in ann.iter() if n is not ann and n.get("name"))
        topic_of[c.get("name")] = topic
        kind = next(iter(c), None)
        connectors[topic] = kind.tag.split("}")[1] if kind is not None else ""
    conns = []
    for c in system.findall("ssd:Connections/ssd:Connection", NS):
        period = None
        for ann in c.findall("ssd:Annotations/ssc:Annotation", NS):
            if ann.get("type") == EXCHANGE_ANNOTATION:
                p = next((n.get("period") for n in ann.iter() if n.get("period") is not None), None)
                assert p is not None, f"{path}: exchange annotation without period"
                period = float(p)

        def endpoint(el: str, conn: str) -> Endpoint:
            element, name = c.get(el) or None, c.get(conn)
            return Endpoint(element, name if element else topic_of.get(name, name))

        conns.append(Connection(endpoint("startElement", "startConnector"), endpoint("endElement", "endConnector"), period))
    return SystemFile(comps, conns, connectors)


def ticks_of(period: float, step: float) -> int:
    n = round(period / step)
    assert n >= 1 and abs(n * step - period) <= 1e-9, f"period {period} s is not a multiple of the step {step} s"
    return n


# --------------------------------------------------------------------------------------------
# The master algorithm, re-implemented from orchestrator/cosim/src/master.rs


@dataclass
class Port:
    comp: int | None  # None: a bus connector
    name: str  # variable name or topic
    seq: str | None = None  # counter of a message port


@dataclass
class Route:
    src: Port
    dst: Port
    period_ticks: int
    is_message: bool
    topic: str
    seen: int = 0
    written: int = 0


class BusReplay:
    """The bus as the FMUs see it, fed from a recording: /cmd_vel-like input topics with their
    raw CDR at their log times, and scalar system inputs from /agrisim/scalars."""

    def __init__(self, rec: Recording, input_topics: set[str]):
        self.incoming: dict[int, list[tuple[str, bytes]]] = {}
        for r in rec.records:
            if r.topic in input_topics:
                self.incoming.setdefault(r.log_time, []).append((r.topic, r.data))
        self.scalar_log = {r.log_time: dict(zip(r.msg.names, r.msg.values)) for r in rec.topic("/agrisim/scalars")}
        self.latest: dict[str, tuple[int, bytes]] = {}  # topic -> (seq, cdr)
        self.scalars: dict[str, float] = {}
        self.published: list[tuple[str, int, bytes]] = []  # FMU outputs reaching the bus

    def publish(self, topic: str, t_ns: int, cdr: bytes) -> None:
        seq = self.latest.get(topic, (0, b""))[0] + 1
        self.latest[topic] = (seq, cdr)

    def nodes_at(self, t_ns: int) -> None:
        """What the algorithm layer published at t_ns, taken from the recording."""
        for topic, cdr in self.incoming.get(t_ns, []):
            self.publish(topic, t_ns, cdr)

    def scalars_at(self, t_ns: int) -> None:
        self.scalars.update(self.scalar_log.get(t_ns, {}))


class MasterReplay:
    """Drives FMU3Slaves exactly like orchestrator/cosim/src/master.rs, with the system inputs taken
    from a recorded run, and collects what the orchestrator records about the FMUs."""

    def __init__(self, ssd: Path, rec: Recording, fmu_overrides: dict[str, str] | None = None):
        run = rec.metadata["agrisim.run"]
        self.step = float(run["step"])
        self.step_ns = round(self.step * 1e9)
        assert abs(self.step_ns / 1e9 - self.step) <= 1e-12
        message_period = 1.0 / float(run["message_rate"])
        self.message_ticks = ticks_of(message_period, self.step)
        sysf = parse_ssd(ssd)
        overrides = fmu_overrides or {}
        self.names = [n for n, _ in sysf.components]
        self.slaves: list[Slave] = []
        for name, source in sysf.components:
            src = overrides.get(name, source)
            self.slaves.append(Slave(FMU_DIR / Path(src).name, name))
        for name, slave in zip(self.names, self.slaves):
            assert run[f"fmu.{name}"] == slave.md.modelName, f"{name}: recorded {run[f'fmu.{name}']}, loaded {slave.md.modelName}"
            for pname, text in rec.metadata.get(f"agrisim.parameters.{name}", {}).items():
                slave.set_text(pname, text)
        self.routes = [self._route(c, message_period) for c in sysf.connections]
        input_topics = {r.src.name for r in self.routes if r.src.comp is None and r.is_message}
        self.bus = BusReplay(rec, input_topics)
        self.signals: dict[str, list[tuple[int, list[str], list[float]]]] = {n: [] for n in self.names}
        self.bus_messages: list[tuple[str, int, bytes]] = []
        self.tick = 0

    def _port(self, e: Endpoint) -> Port:
        if e.element is None:
            return Port(None, e.connector)
        comp = self.names.index(e.element)
        v = self.slaves[comp].var(e.connector)
        seq = None
        if v.type == "Binary":
            seq = f"{v.name}_seq"
            assert self.slaves[comp].var(seq).type == "Int64", f"{e.element}.{seq} must be Int64"
        return Port(comp, e.connector, seq)

    def _route(self, c: Connection, message_period: float) -> Route:
        src, dst = self._port(c.start), self._port(c.end)
        is_message = src.seq is not None or dst.seq is not None
        period = c.period if c.period is not None else (message_period if is_message else self.step)
        if c.start.element is None:
            topic = c.start.connector
        elif c.end.element is None:
            topic = c.end.connector
        else:
            topic = f"/{c.start.element}/{c.start.connector}"
        return Route(src, dst, ticks_of(period, self.step), is_message, topic)

    def t_ns(self, k: int) -> int:
        return k * self.step_ns

    def time(self, k: int) -> float:
        return (k * self.step_ns) / 1e9

    def initialize(self) -> None:
        for s in self.slaves:
            s.slave.enterInitializationMode(startTime=0.0)
        # As master.rs: scalar FMU-to-FMU connections propagate in initialization mode, one
        # pass per component so chains settle.
        for _ in self.slaves:
            for r in self.routes:
                if r.src.comp is None or r.dst.comp is None or r.is_message:
                    continue
                self.slaves[r.dst.comp].set(r.dst.name, self.slaves[r.src.comp].get(r.src.name))
        for s in self.slaves:
            s.slave.exitInitializationMode()

    def run(self, ticks: int) -> None:
        for _ in range(ticks):
            k = self.tick
            self.collect_outputs(k)
            if k % self.message_ticks == 0:
                self.bus.nodes_at(self.t_ns(k))
            self.bus.scalars_at(self.t_ns(k))
            self.deliver_inputs(k)
            self.record_point()
            t, h = self.time(k), self.step_ns / 1e9
            for s in self.slaves:
                s.do_step(t, h)
            self.tick += 1
        self.collect_outputs(self.tick)
        self.bus.scalars_at(self.t_ns(self.tick))
        self.record_point()

    def collect_outputs(self, k: int) -> None:
        t_ns = self.t_ns(k)
        for r in self.routes:
            if k % r.period_ticks or r.src.comp is None or r.dst.comp is not None:
                continue
            s = self.slaves[r.src.comp]
            if r.src.seq is not None:
                n = s.get(r.src.seq)
                if n == r.seen:
                    continue
                r.seen = n
                cdr = s.get(r.src.name)
                self.bus.publish(r.topic, t_ns, cdr)
                self.bus_messages.append((r.topic, t_ns, cdr))
            else:
                self.bus.scalars[r.topic] = as_float(s.get(r.src.name))

    def deliver_inputs(self, k: int) -> None:
        t_ns = self.t_ns(k)
        for r in self.routes:
            if k % r.period_ticks or r.dst.comp is None:
                continue
            value = None
            if r.src.comp is None:
                if r.dst.seq is not None:
                    latest = self.bus.latest.get(r.src.name)
                    if latest is not None and latest[0] > r.seen:
                        r.seen = latest[0]
                        value = latest[1]
                elif r.src.name in self.bus.scalars:
                    value = self._scalar_for(self.slaves[r.dst.comp].var(r.dst.name), self.bus.scalars[r.src.name])
            else:
                s = self.slaves[r.src.comp]
                if r.src.seq is not None:
                    n = s.get(r.src.seq)
                    if n != r.seen:
                        r.seen = n
                        value = s.get(r.src.name)
                        self.bus.publish(r.topic, t_ns, value)
                        self.bus_messages.append((r.topic, t_ns, value))
                else:
                    value = s.get(r.src.name)
            if value is None:
                continue
            d = self.slaves[r.dst.comp]
            d.set(r.dst.name, value)
            if r.dst.seq is not None:
                r.written += 1
                d.set(r.dst.seq, r.written)

    @staticmethod
    def _scalar_for(var, x: float):
        if var.type == "Float64":
            return x
        if var.type in ("Int32", "Int64"):
            return int(x)  # Rust `as` truncates toward zero, like int()
        if var.type == "Boolean":
            return x != 0.0
        raise AssertionError(f"{var.name}: type {var.type} cannot take a scalar")

    def record_point(self) -> None:
        t_ns = self.t_ns(self.tick)
        for name, s in zip(self.names, self.slaves):
            names = s.scalar_signals()
            self.signals[name].append((t_ns, names, [as_float(x) for x in s.get_many(names)]))

    def close(self) -> None:
        for s in self.slaves:
            s.close()


def annotated_scenario(tmp: Path, periods: dict[tuple[str, str], float]) -> tuple[Path, Path]:
    """A copy of the default scenario and system where the connections named by
    (start connector, end connector) carry an `org.agrisim.exchange` period annotation.
    Returns (scenario, system file)."""
    ET.register_namespace("ssd", NS["ssd"])
    ET.register_namespace("ssc", NS["ssc"])
    ET.register_namespace("ssv", NS["ssv"])
    tree = ET.parse(DEFAULT_SSD)
    found = set()
    for c in tree.getroot().iter(f"{{{NS['ssd']}}}Connection"):
        key = (c.get("startConnector"), c.get("endConnector"))
        if key in periods:
            anns = ET.SubElement(c, f"{{{NS['ssd']}}}Annotations")
            ann = ET.SubElement(anns, f"{{{NS['ssc']}}}Annotation", {"type": EXCHANGE_ANNOTATION})
            ET.SubElement(ann, "{urn:agrisim:test}Exchange", {"period": repr(periods[key])})
            found.add(key)
    assert found == set(periods), f"no such connections: {set(periods) - found}"
    ssd = tmp / "annotated.ssd"
    tree.write(ssd, xml_declaration=True, encoding="UTF-8")
    lines = DEFAULT_SCENARIO.read_text().splitlines()
    i = next(i for i, l in enumerate(lines) if l.strip().startswith("file ="))
    lines[i] = f"file = {str(ssd)!r}".replace("'", '"')
    scenario = tmp / "annotated.toml"
    scenario.write_text("\n".join(lines) + "\n")
    return scenario, ssd
