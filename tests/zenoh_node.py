"""A minimal ROS 2 node on Eclipse Zenoh's Python binding, as rmw_zenoh lays it out
(tests/rmw_zenoh_wire.py): it declares its node token, and for each reader and writer a
subscriber or publisher on the topic's key plus the entity's liveliness token; writers attach
rmw_zenoh's attachment to every sample. Type hashes are rosbags' (from the ROS 2 .msg files
in models/msgs), never agrisim's. The readers and writers mimic the `take`/`write` of the
Cyclone DDS ones the DDS tests use, so a test node can run on either."""

from __future__ import annotations

import hashlib
import json
import socket
import subprocess
import time
from functools import lru_cache
from pathlib import Path

import zenoh

import rmw_zenoh_wire as w

MSG_DIR = Path(__file__).resolve().parent.parent / "models" / "msgs"


@lru_cache(maxsize=1)
def _store():
    from rosbags import typesys

    store = typesys.get_typestore(typesys.Stores.EMPTY)
    for p in sorted(MSG_DIR.glob("*/msg/*.msg")):
        store.register(typesys.get_types_from_msg(p.read_text(), f"{p.parts[-3]}/msg/{p.stem}"))
    return store


def type_hash(ros_type: str) -> str:
    """rosbags' REP 2011 hash of `ros_type`, from the .msg definitions."""
    return _store().hash_rihs01(ros_type)


def open_session(endpoint: str, proc: subprocess.Popen, timeout: float) -> zenoh.Session:
    """A peer session connected to `endpoint` (tcp/HOST:PORT) once the run listens there."""
    host, port = endpoint.removeprefix("tcp/").rsplit(":", 1)
    deadline = time.monotonic() + timeout
    while True:
        if proc.poll() is not None or time.monotonic() > deadline:
            raise SystemExit(f"no Zenoh listener on {endpoint}")
        try:
            with socket.create_connection((host, int(port)), timeout=0.2):
                break
        except OSError:
            time.sleep(0.05)
    conf = zenoh.Config()
    conf.insert_json5("mode", '"peer"')
    conf.insert_json5("connect/endpoints", json.dumps([endpoint]))
    conf.insert_json5("listen/endpoints", "[]")
    conf.insert_json5("scouting/multicast/enabled", "false")
    return zenoh.open(conf)


class Reader:
    def __init__(self, node: "ZenohNode", topic: str, cls, ros_type: str):
        self.cls = cls
        self.sub = node.session.declare_subscriber(f"{node.domain}/{topic.strip('/')}/*/*")
        node.token("MS", topic, ros_type, w.qos_key(history=2))

    def take(self, N: int = 100) -> list:
        out = []
        while len(out) < N and (s := self.sub.try_recv()) is not None:
            out.append(self.cls.deserialize(s.payload.to_bytes()))
        return out


class Writer:
    def __init__(self, node: "ZenohNode", topic: str, ros_type: str):
        self.session = node.session
        self.pub = node.session.declare_publisher(w.topic_key(node.domain, topic, ros_type, type_hash(ros_type)))
        self.gid = hashlib.blake2b(node.token("MP", topic, ros_type, w.qos_key(depth=10)).encode(), digest_size=16).digest()
        self.sequence = 0

    def write(self, msg) -> None:
        self.put_raw(msg.serialize())

    def put_raw(self, cdr: bytes, key: str | None = None) -> None:
        """`cdr` as it is, with the attachment; on another key if given (a misbehaving peer)."""
        self.sequence += 1
        att = w.Attachment(self.sequence, time.time_ns(), self.gid).encode()
        if key is None:
            self.pub.put(cdr, attachment=att)
        else:
            self.session.put(key, cdr, attachment=att)


class ZenohNode:
    def __init__(self, session: zenoh.Session, domain: int, name: str):
        self.session, self.domain, self.name = session, domain, name
        self.zid = str(session.zid())
        self.tokens = []
        self.token("NN")

    def token(self, kind: str, topic: str | None = None, ros_type: str | None = None, qos: str | None = None) -> str:
        """Declares the token of an entity of this node (a topic's with rmw_zenoh's default QoS
        unless `qos` is given); returns its key."""
        qos = w.qos_key() if qos is None else qos
        key = w.token(self.domain, self.zid, 0, len(self.tokens), kind, self.name, topic=topic, ros_type=ros_type,
                      type_hash=type_hash(ros_type) if ros_type else None, qos=qos)
        self.tokens.append(self.session.liveliness().declare_token(key))
        return key

    def reader(self, topic: str, cls, ros_type: str) -> Reader:
        return Reader(self, topic, cls, ros_type)

    def writer(self, topic: str, ros_type: str) -> Writer:
        return Writer(self, topic, ros_type)
