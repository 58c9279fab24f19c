"""rmw_zenoh's wire format, written for the tests from rmw_zenoh's description (docs/design.md,
liveliness_utils, attachment_helpers of ros2/rmw_zenoh) and the Zenoh serialization format
RFC, independently of agrisim's Rust code (orchestrator/zenoh/src/wire.rs), so the two can
be held against each other:

* data keys `<domain>/<topic without leading slash>/<pkg>::msg::dds_::<Type>_/RIHS01_<hex>`;
* attachments: i64 sequence number, i64 source timestamp [ns], the 16-byte GID as a Zenoh
  sequence (LEB128 length, bytes), all little-endian;
* liveliness tokens `@ros2_lv/<domain>/<zid>/<nid>/<id>/<NN|MP|MS|SS|SC>/<enclave>/<ns>/<node>`
  and, for publishers and subscriptions, `/<topic>/<type>/<hash>/<qos>`, `/` written `%`.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

ADMIN_SPACE = "@ros2_lv"


def dds_type(ros_type: str) -> str:
    pkg, kind, name = ros_type.split("/")
    assert kind == "msg", ros_type
    return f"{pkg}::msg::dds_::{name}_"


def topic_key(domain: int, topic: str, ros_type: str, type_hash: str) -> str:
    return f"{domain}/{topic.strip('/')}/{dds_type(ros_type)}/{type_hash}"


def parse_topic_key(key: str) -> tuple[int, str, str, str]:
    """(domain, absolute topic, DDS type name, type hash) of a data key."""
    domain, rest = key.split("/", 1)
    rest, type_hash = rest.rsplit("/", 1)
    topic, ty = rest.rsplit("/", 1)
    return int(domain), "/" + topic, ty, type_hash


def _leb128(n: int) -> bytes:
    out = bytearray()
    while True:
        b = n & 0x7F
        n >>= 7
        out.append(b | (0x80 if n else 0))
        if not n:
            return bytes(out)


def _read_leb128(b: bytes, at: int) -> tuple[int, int]:
    n = shift = 0
    while True:
        byte = b[at]
        at += 1
        n |= (byte & 0x7F) << shift
        shift += 7
        if not byte & 0x80:
            return n, at


@dataclass
class Attachment:
    sequence: int
    timestamp_ns: int
    gid: bytes

    def encode(self) -> bytes:
        return struct.pack("<qq", self.sequence, self.timestamp_ns) + _leb128(len(self.gid)) + self.gid

    @staticmethod
    def decode(b: bytes) -> "Attachment":
        seq, ts = struct.unpack_from("<qq", b, 0)
        n, at = _read_leb128(b, 16)
        gid = bytes(b[at:at + n])
        if len(gid) != n or at + n != len(b):
            raise ValueError(f"attachment of {len(b)} bytes is not i64, i64, a {n}-byte sequence")
        return Attachment(seq, ts, gid)


def mangle(name: str) -> str:
    return name.replace("/", "%")


def demangle(name: str) -> str:
    return name.replace("%", "/")


# rmw QoS enum values (rmw/types.h) and rmw_zenoh's defaults, which a token leaves empty.
DEFAULT_QOS = {"reliability": 1, "durability": 2, "history": 1, "depth": 42}


def qos_key(reliability: int = 1, durability: int = 2, history: int = 1, depth: int = 42) -> str:
    v = {"reliability": reliability, "durability": durability, "history": history, "depth": depth}
    f = {k: "" if v[k] == DEFAULT_QOS[k] else str(v[k]) for k in v}
    return f"{f['reliability']}:{f['durability']}:{f['history']},{f['depth']}:,:,:,,"


def parse_qos(s: str) -> dict:
    parts = s.split(":")
    assert len(parts) == 6, s
    hist, depth = parts[2].split(",")
    val = lambda x, k: int(x) if x else DEFAULT_QOS[k]  # noqa: E731
    return {"reliability": val(parts[0], "reliability"), "durability": val(parts[1], "durability"),
            "history": val(hist, "history"), "depth": val(depth, "depth")}


def token(domain: int, zid: str, nid: int, eid: int, kind: str, node: str, namespace: str = "/",
          topic: str | None = None, ros_type: str | None = None, type_hash: str | None = None, qos: str = "") -> str:
    key = f"{ADMIN_SPACE}/{domain}/{zid}/{nid}/{eid}/{kind}/{mangle('/')}/{mangle(namespace)}/{mangle(node)}"
    if topic is not None:
        key += f"/{mangle(topic)}/{mangle(dds_type(ros_type))}/{type_hash}/{qos}"
    return key


@dataclass
class Token:
    domain: int
    zid: str
    kind: str
    namespace: str
    node: str
    topic: str | None = None
    dds_type: str | None = None
    type_hash: str | None = None
    qos: dict | None = None


def parse_token(key: str) -> Token:
    p = key.split("/")
    if p[0] != ADMIN_SPACE or len(p) < 9 or any(not x for x in p):
        raise ValueError(f"not an rmw_zenoh liveliness token: {key}")
    t = Token(int(p[1]), p[2], p[5], demangle(p[7]), demangle(p[8]))
    if t.kind in ("MP", "MS", "SS", "SC"):
        if len(p) != 13:
            raise ValueError(f"a {t.kind} token without topic, type, hash and QoS: {key}")
        t.topic, t.dds_type, t.type_hash, t.qos = demangle(p[9]), demangle(p[10]), p[11], parse_qos(p[12])
    return t


def twist_cdr(linear_x: float, angular_z: float = 0.0) -> bytes:
    """geometry_msgs/msg/Twist in CDR (little-endian encapsulation): six float64."""
    return b"\x00\x01\x00\x00" + struct.pack("<6d", linear_x, 0.0, 0.0, 0.0, 0.0, angular_z)
