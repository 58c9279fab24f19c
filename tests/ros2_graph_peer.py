"""A ROS 2 graph observer on Cyclone DDS for the bridge's graph test: it starts the agrisim
command given after `--` (so both share this network namespace) and, while it runs, reads
`ros_discovery_info` (rmw_dds_common/msg/ParticipantEntitiesInfo, with the Gid layout of
--distro) as an rmw layer does, and the DDS built-in topics that list every participant,
publication and subscription. Prints what it saw as JSON: the announced nodes with their
reader and writer GIDs, and the discovered endpoints (GUID, participant, topic, type).

With --lan ADDR/LEN it first gives this namespace a LAN interface with that address (one end
of a veth pair: kernels without the dummy device have veth), so a peer that selects a
non-loopback interface (rmw_cyclonedds's LOCALHOST range does) has one. With --after-bridge
it starts agrisim first and joins DDS once the bridge's discovery port is open, as a ROS 2
node started while the simulation runs."""

import argparse
import json
import subprocess
import time
from dataclasses import dataclass, field
from pathlib import Path

from cyclonedds.builtin import BuiltinDataReader, BuiltinTopicDcpsPublication, BuiltinTopicDcpsSubscription
from cyclonedds.core import Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.types import array, sequence, uint8
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

# What rmw_dds_common's graph cache subscribes with.
GRAPH_QOS = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.Durability.TransientLocal, Policy.History.KeepLast(1))


def graph_types(gid_len: int):
    """The rmw_dds_common message types with a Gid of `gid_len` bytes (24: Humble, 16: Jazzy)."""

    @dataclass
    class Gid(IdlStruct, typename="rmw_dds_common::msg::dds_::Gid_"):
        data: array[uint8, gid_len] = field(default_factory=lambda: [0] * gid_len)

    @dataclass
    class NodeEntitiesInfo(IdlStruct, typename="rmw_dds_common::msg::dds_::NodeEntitiesInfo_"):
        node_namespace: str = ""
        node_name: str = ""
        reader_gid_seq: sequence[Gid] = field(default_factory=list)
        writer_gid_seq: sequence[Gid] = field(default_factory=list)

    @dataclass
    class ParticipantEntitiesInfo(IdlStruct, typename="rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_"):
        gid: Gid = field(default_factory=Gid)
        node_entities_info_seq: sequence[NodeEntitiesInfo] = field(default_factory=list)

    return ParticipantEntitiesInfo


def hexid(b) -> str:
    return bytes(b).hex()


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--distro", choices=["humble", "jazzy"], default="jazzy")
    ap.add_argument("--seconds", type=float, default=60.0, help="give up after this long")
    ap.add_argument("--lan", help="add a LAN interface with this address (ADDR/LEN) first")
    ap.add_argument("--after-bridge", action="store_true", help="join DDS after the bridge is up")
    ap.add_argument("agrisim", nargs=argparse.REMAINDER)
    a = ap.parse_args()
    if a.lan:
        for cmd in (["ip", "link", "add", "lan0", "type", "veth", "peer", "name", "lan1"], ["ip", "addr", "add", a.lan, "dev", "lan0"],
                    ["ip", "link", "set", "lan1", "up"], ["ip", "link", "set", "lan0", "multicast", "on", "up"]):
            subprocess.run(cmd, check=True)
    agrisim = a.agrisim[1:] if a.agrisim[:1] == ["--"] else a.agrisim
    proc = None
    if a.after_bridge:
        proc = subprocess.Popen(agrisim, stdout=subprocess.DEVNULL)
        # The bridge's SPDP port for domain 0, participant 0 (7410 = 0x1CF2) in /proc/net/udp.
        deadline = time.monotonic() + 60
        while ":1CF2 " not in Path("/proc/net/udp").read_text():
            if proc.poll() is not None or time.monotonic() > deadline:
                raise SystemExit(f"the bridge's discovery port did not open (exit {proc.poll()})")
            time.sleep(0.05)
    dp = DomainParticipant(0)
    info_type = graph_types(24 if a.distro == "humble" else 16)
    info = DataReader(dp, Topic(dp, "ros_discovery_info", info_type), qos=GRAPH_QOS)
    pubs = BuiltinDataReader(dp, BuiltinTopicDcpsPublication)
    subs = BuiltinDataReader(dp, BuiltinTopicDcpsSubscription)
    nodes, endpoints = {}, {}

    def poll():
        for s in info.take(N=100):
            if isinstance(s, info_type):
                nodes[hexid(s.gid.data)] = [
                    {"namespace": n.node_namespace, "name": n.node_name, "readers": [hexid(g.data) for g in n.reader_gid_seq], "writers": [hexid(g.data) for g in n.writer_gid_seq]}
                    for n in s.node_entities_info_seq
                ]
        for kind, reader in (("writer", pubs), ("reader", subs)):
            for e in reader.take(N=500):
                # An endpoint that goes away comes back as a key alone: keep what was seen.
                if e.topic_name is not None:
                    endpoints[e.key.bytes.hex()] = {"kind": kind, "participant": e.participant_key.bytes.hex(), "topic": e.topic_name, "type": e.type_name}

    if proc is None:
        proc = subprocess.Popen(agrisim, stdout=subprocess.DEVNULL)
    start = time.monotonic()
    while proc.poll() is None and time.monotonic() - start < a.seconds:
        poll()
        time.sleep(0.05)
    if proc.poll() is None:
        proc.kill()
    returncode = proc.wait()
    poll()
    print(json.dumps({"returncode": returncode, "nodes": nodes, "endpoints": endpoints}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
