"""Shared helpers of the FMPy checks in python/: where the packed FMUs and the CLI are, a thin
typed wrapper around FMPy's low-level FMU3Slave, an MCAP reader, the system file parser and
an independent re-implementation of the orchestrator's master algorithm (master.rs).

Everything here is written against public interfaces only (FMI 3 C API through FMPy,
modelDescription.xml, SSP .ssd, MCAP), so a match with the orchestrator is evidence, not a
tautology. Imports are plain: a missing package fails the test run instead of skipping it.
"""

from __future__ import annotations

import itertools
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

import agrisim_frames
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
        # FMPy does not expose mimeType: read it from the XML (framed ports, agrisim_frames).
        root = ET.parse(Path(self._unzip) / "modelDescription.xml").getroot()
        self.mimes = {b.get("name"): b.get("mimeType") for b in root.iter("Binary")}
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

    def messages(self, name: str) -> list[bytes]:
        """The messages (CDR) in framed message port `name`, oldest first."""
        return [f.payload for f in agrisim_frames.decode(self.get(name))]

    def latest(self, name: str) -> bytes:
        """The newest message in framed message port `name`."""
        msgs = self.messages(name)
        assert msgs, f"{self.md.modelName}.{name}: no message in the port"
        return msgs[-1]

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
    framed: bool = False  # a frame-list port (agrisim_frames)


@dataclass
class Route:
    src: Port
    dst: Port
    period_ticks: int
    is_message: bool
    topic: str
    cursor: agrisim_frames.Cursor = field(default_factory=agrisim_frames.Cursor)
    bus_seen: int = 0  # bus source: the last bus sequence number delivered
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
        self.history: dict[str, list[tuple[int, int, bytes]]] = {}  # topic -> [(seq, t_ns, cdr)]
        self.scalars: dict[str, float] = {}

    def publish(self, topic: str, t_ns: int, cdr: bytes) -> None:
        h = self.history.setdefault(topic, [])
        h.append((len(h) + 1, t_ns, cdr))

    def since(self, topic: str, seq: int) -> list[tuple[int, int, bytes]]:
        return [m for m in self.history.get(topic, []) if m[0] > seq]

    def nodes_at(self, t_ns: int) -> None:
        """What the algorithm layer published at t_ns, taken from the recording."""
        for topic, cdr in self.incoming.get(t_ns, []):
            self.publish(topic, t_ns, cdr)

    def scalars_at(self, t_ns: int) -> None:
        self.scalars.update(self.scalar_log.get(t_ns, {}))


def step_order(n: int, links: list[tuple[int, int]]) -> list[int]:
    """Gauss-Seidel order: the permutation of components 0..n-1 with the fewest FMU-to-FMU
    connections from a later to an earlier component (those are read one step late), the
    lexicographically smallest among equals. Brute force: systems here have a handful of
    components (the orchestrator solves the same problem by dynamic programming)."""
    assert n <= 9, "brute force: at most 9 components"
    best = None
    for perm in itertools.permutations(range(n)):  # lexicographic order
        pos = {c: i for i, c in enumerate(perm)}
        cost = sum(1 for a, b in links if a != b and pos[a] > pos[b])
        if best is None or cost < best[0]:
            best = (cost, list(perm))
    return best[1]


class MasterReplay:
    """Drives FMU3Slaves like orchestrator/cosim/src/master.rs (integer ticks, Gauss-Seidel in
    the order of `step_order`, delayed connections only in loops, every message of a framed
    port once), with the system inputs taken from a recorded run, and collects what the
    orchestrator records about the FMUs."""

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
        links = [(r.src.comp, r.dst.comp) for r in self.routes if r.src.comp is not None and r.dst.comp is not None]
        self.order = step_order(len(self.slaves), links)
        pos = {c: i for i, c in enumerate(self.order)}
        self.delayed = [r.src.comp is not None and r.dst.comp is not None and pos[r.src.comp] >= pos[r.dst.comp] for r in self.routes]
        input_topics = {r.src.name for r in self.routes if r.src.comp is None and r.is_message}
        self.bus = BusReplay(rec, input_topics)
        self.signals: dict[str, list[tuple[int, list[str], list[float]]]] = {n: [] for n in self.names}
        self.bus_messages: list[tuple[str, int, bytes]] = []
        self.tick = 0

    def _port(self, e: Endpoint) -> Port:
        if e.element is None:
            return Port(None, e.connector)
        comp = self.names.index(e.element)
        slave = self.slaves[comp]
        v = slave.var(e.connector)
        seq = None
        if v.type == "Binary":
            seq = f"{v.name}_seq"
            assert slave.var(seq).type == "Int64", f"{e.element}.{seq} must be Int64"
        return Port(comp, e.connector, seq, agrisim_frames.is_framed_mime(slave.mimes.get(v.name)))

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

    def inputs_of(self, comp: int) -> list[Route]:
        return [r for r in self.routes if r.dst.comp == comp and r.src.comp is not None]

    def initialize(self) -> None:
        """One pass in the step order (a component's inputs set before its outputs are read),
        then passes over every scalar FMU-to-FMU connection until nothing changes."""
        for s in self.slaves:
            s.slave.enterInitializationMode(startTime=0.0)
        last: dict[int, object] = {}

        def propagate(i: int, r: Route) -> bool:
            if r.is_message:
                return False
            v = self.slaves[r.src.comp].get(r.src.name)
            if i in last and last[i] == v:
                return False
            self.slaves[r.dst.comp].set(r.dst.name, v)
            last[i] = v
            return True

        index = {id(r): i for i, r in enumerate(self.routes)}
        for c in self.order:
            for r in self.inputs_of(c):
                if not self.delayed[index[id(r)]]:
                    propagate(index[id(r)], r)
        for _ in range(50):
            if not any([propagate(index[id(r)], r) for c in self.order for r in self.inputs_of(c)]):
                break
        else:
            raise AssertionError("initialization did not converge")
        for s in self.slaves:
            s.slave.exitInitializationMode()

    def run(self, ticks: int) -> None:
        for _ in range(ticks):
            k = self.tick
            self.collect_outputs(k)
            if k % self.message_ticks == 0:
                self.bus.nodes_at(self.t_ns(k))
            self.bus.scalars_at(self.t_ns(k))
            self.deliver_bus_inputs(k)
            self.record_point()
            t, h = self.time(k), self.step_ns / 1e9
            for c in self.order:
                for r in self.inputs_of(c):
                    at = k if self.delayed[self.routes.index(r)] else k + 1
                    if at % r.period_ticks == 0:
                        self.propagate(r, at)
                self.slaves[c].do_step(t, h)
            self.tick += 1
        self.collect_outputs(self.tick)
        self.bus.scalars_at(self.t_ns(self.tick))
        self.record_point()

    def take_messages(self, r: Route, t_ns: int) -> list[agrisim_frames.Frame]:
        """The source port's messages the route has not taken, each once (GapError if lost)."""
        s = self.slaves[r.src.comp]
        n = s.get(r.src.seq)
        if n == r.cursor.last:
            return []
        data = s.get(r.src.name)
        if r.src.framed:
            return r.cursor.take(data, n)
        if n > r.cursor.last + 1:
            raise agrisim_frames.GapError(r.cursor.last + 1, n - 1)
        r.cursor.last = n
        return [agrisim_frames.Frame(n, t_ns, data)]

    def write_messages(self, r: Route, messages: list[tuple[int, bytes]]) -> None:
        if not messages:
            return
        d = self.slaves[r.dst.comp]
        if r.dst.framed:
            first = r.written + 1
            d.set(r.dst.name, agrisim_frames.encode(agrisim_frames.Frame(first + i, t, b) for i, (t, b) in enumerate(messages)))
        else:
            d.set(r.dst.name, messages[-1][1])
        r.written += len(messages)
        d.set(r.dst.seq, r.written)

    def collect_outputs(self, k: int) -> None:
        t_ns = self.t_ns(k)
        for r in self.routes:
            if k % r.period_ticks or r.src.comp is None or r.dst.comp is not None:
                continue
            s = self.slaves[r.src.comp]
            if r.src.seq is not None:
                for f in self.take_messages(r, t_ns):
                    self.bus.publish(r.topic, f.stamp_ns, f.payload)
                    self.bus_messages.append((r.topic, f.stamp_ns, f.payload))
            else:
                self.bus.scalars[r.topic] = as_float(s.get(r.src.name))

    def deliver_bus_inputs(self, k: int) -> None:
        for r in self.routes:
            if k % r.period_ticks or r.dst.comp is None or r.src.comp is not None:
                continue
            d = self.slaves[r.dst.comp]
            if r.dst.seq is not None:
                new = self.bus.since(r.src.name, r.bus_seen)
                if new:
                    r.bus_seen = new[-1][0]
                self.write_messages(r, [(t, b) for _, t, b in new])
            elif r.src.name in self.bus.scalars:
                d.set(r.dst.name, self._scalar_for(d.var(r.dst.name), self.bus.scalars[r.src.name]))

    def propagate(self, r: Route, at: int) -> None:
        """An FMU-to-FMU route: its source's value now (at tick `at`) to its destination."""
        s = self.slaves[r.src.comp]
        if r.src.seq is not None:
            frames = self.take_messages(r, self.t_ns(at))
            for f in frames:
                self.bus.publish(r.topic, f.stamp_ns, f.payload)
                self.bus_messages.append((r.topic, f.stamp_ns, f.payload))
            self.write_messages(r, [(f.stamp_ns, f.payload) for f in frames])
        else:
            self.slaves[r.dst.comp].set(r.dst.name, s.get(r.src.name))

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


def annotated_scenario(tmp: Path, periods: dict[tuple[str, str], float], chassis: dict[str, float] | None = None) -> tuple[Path, Path]:
    """A copy of the default scenario and system where the connections named by
    (start connector, end connector) carry an `org.agrisim.exchange` period annotation, and
    the chassis takes the extra parameters `chassis`. Returns (scenario, system file)."""
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
    if chassis:
        j = lines.index("[parameters.chassis]")
        lines[j + 1:j + 1] = [f"{k} = {v!r}" for k, v in chassis.items()]
    scenario = tmp / "annotated.toml"
    scenario.write_text("\n".join(lines) + "\n")
    return scenario, ssd
