"""An rmw_zenoh-style ROS 2 peer on Eclipse Zenoh's Python binding (`eclipse-zenoh`), for the
Zenoh link's tests: it starts the agrisim command given after `--` (both share this network
namespace), connects to the run's Zenoh endpoint as an rmw_zenoh node would
(tests/zenoh_node.py: tokens, keys with rosbags' type hashes, attachments), and answers each
/clock with one geometry_msgs/Twist on /cmd_vel (`--drive X`: linear.x = X m/s). With `--bad`
it sends, at chosen ticks instead of the Twist, garbage bytes and a Twist on a key whose type
hash is wrong. It keeps every sample of the `--topic`s (key, attachment, payload) and the
other sessions' liveliness tokens, and prints what it sent and saw as JSON on its last line.
With `--late TOPIC=TYPE`, once `--late-after` /clock ticks have come it joins TOPIC as
rmw_zenoh subscribes to a TRANSIENT_LOCAL topic (an AdvancedSubscriber on the topic's exact
key, history of depth 1 with late publisher detection, heartbeat recovery), beside a plain
subscriber declared at the same moment, and keeps what each gets (it waits up to 3 s for the
history before answering the next /clock). It also notes the wall time at which each /clock
came, with its stamp.
The process it starts is stopped before it exits; the whole exchange is bounded in time.
"""

from __future__ import annotations

import argparse
import json
import struct
import subprocess
import sys
import time
from pathlib import Path

import zenoh
import zenoh.ext

sys.path.insert(0, str(Path(__file__).parent))
import rmw_zenoh_wire as w  # noqa: E402
import zenoh_node  # noqa: E402

TWIST = "geometry_msgs/msg/Twist"


def record(s) -> dict:
    att = s.attachment.to_bytes() if s.attachment is not None else b""
    return {"key": str(s.key_expr), "attachment": att.hex(), "payload": s.payload.to_bytes().hex()}


def on_clock(out: dict, s) -> None:
    """A /clock came: count it, with the wall time and its stamp [ns] (CDR: header, sec, nanosec)."""
    out["ticks"] += 1
    b = s.payload.to_bytes()
    sec, nsec = struct.unpack_from("<iI", b, 4)
    out["clock"].append([time.monotonic(), sec * 10**9 + nsec])


def take_late(joined: dict, out: dict) -> None:
    for t, (adv, plain) in joined.items():
        while (s := adv.try_recv()) is not None:
            out["late"][t].append(record(s))
        while (s := plain.try_recv()) is not None:
            out["late_plain"][t].append(record(s))


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--endpoint", default="tcp/127.0.0.1:7447")
    ap.add_argument("--domain", type=int, default=0)
    ap.add_argument("--topic", action="append", default=[], help="keep the samples of this topic")
    ap.add_argument("--drive", type=float, default=None, help="answer each /clock with a Twist of this speed")
    ap.add_argument("--bad", action="store_true")
    ap.add_argument("--late", action="append", default=[], metavar="TOPIC=TYPE", help="join this transient-local topic late")
    ap.add_argument("--late-after", type=int, default=5, help="... after this many /clock ticks")
    ap.add_argument("--timeout", type=float, default=120)
    ap.add_argument("agrisim", nargs=argparse.REMAINDER)
    a = ap.parse_args()
    proc = subprocess.Popen([x for x in a.agrisim if x != "--"], stderr=sys.stderr)
    deadline = time.monotonic() + a.timeout
    out = {"samples": {t: [] for t in a.topic}, "tokens": [], "ticks": 0, "good_sent": 0, "bad_sent": 0, "clock": [],
           "late": {}, "late_plain": {}, "late_at_tick": None}
    late = dict(x.split("=", 1) for x in a.late)
    joined: dict[str, tuple] = {}
    session = None
    try:
        session = zenoh_node.open_session(a.endpoint, proc, a.timeout)
        d = a.domain
        lv = session.liveliness().declare_subscriber(f"{w.ADMIN_SPACE}/{d}/**", history=True)
        seen_tokens: set[str] = set()
        subs = {t: session.declare_subscriber(f"{d}/{t.strip('/')}/*/*") for t in a.topic}
        clock = subs.get("/clock") or session.declare_subscriber(f"{d}/clock/*/*")
        node = zenoh_node.ZenohNode(session, d, "zenoh_peer")
        node.token("MS", "/clock", "rosgraph_msgs/msg/Clock")
        cmd_vel = node.writer("/cmd_vel", TWIST) if a.drive is not None else None
        bad_key = w.topic_key(d, "/cmd_vel", TWIST, "RIHS01_" + "0" * 64)
        ended = None
        while time.monotonic() < deadline:
            # After the run ends, half a second more to take what is still on its way.
            if proc.poll() is not None:
                ended = ended or time.monotonic()
                if time.monotonic() - ended > 0.5:
                    break
            got = False
            for t, sub in subs.items():
                while (s := sub.try_recv()) is not None:
                    got = True
                    out["samples"][t].append(record(s))
                    if t == "/clock":
                        on_clock(out, s)
            while (s := lv.try_recv()) is not None:
                if s.kind == zenoh.SampleKind.PUT:
                    seen_tokens.add(str(s.key_expr))
            if "/clock" not in subs:
                while (s := clock.try_recv()) is not None:
                    got = True
                    on_clock(out, s)
            if late and not joined and out["ticks"] >= a.late_after:
                out["late_at_tick"] = out["ticks"]
                for t, ty in late.items():
                    key = w.topic_key(d, t, ty, zenoh_node.type_hash(ty))
                    # rmw_zenoh's subscription of a reliable TRANSIENT_LOCAL topic
                    # (rmw_subscription_data.cpp), with its token's QoS: transient local, depth 1.
                    adv = zenoh.ext.declare_advanced_subscriber(
                        session, key, history=zenoh.ext.HistoryConfig(detect_late_publishers=True, max_samples=1),
                        recovery=zenoh.ext.RecoveryConfig(heartbeat=True), subscriber_detection=True)
                    node.token("MS", t, ty, w.qos_key(durability=1, depth=1))
                    joined[t] = (adv, session.declare_subscriber(key))
                    out["late"][t], out["late_plain"][t] = [], []
                history_deadline = time.monotonic() + 3.0
                while time.monotonic() < history_deadline and proc.poll() is None:
                    take_late(joined, out)
                    if all(out["late"][t] for t in joined):
                        break
                    time.sleep(0.001)
            take_late(joined, out)
            # One answer per /clock received (lockstep: one at a time).
            while cmd_vel is not None and ended is None and out["good_sent"] + out["bad_sent"] < out["ticks"]:
                tick = out["good_sent"] + out["bad_sent"] + 1
                if a.bad and tick == 10:
                    cmd_vel.put_raw(b"\x00\x01\x00\x00\xff\x13")  # too short for a Twist
                    out["bad_sent"] += 1
                elif a.bad and tick == 20:
                    cmd_vel.put_raw(w.twist_cdr(a.drive), key=bad_key)  # a wrong type hash
                    out["bad_sent"] += 1
                else:
                    cmd_vel.put_raw(w.twist_cdr(a.drive))
                    out["good_sent"] += 1
            if not got:
                time.sleep(0.0002)
        out["tokens"] = sorted(t for t in seen_tokens if t.split("/")[2] != node.zid)
    finally:
        if proc.poll() is None:
            proc.kill()
        proc.wait()
        if session is not None:
            session.close()
    out["returncode"] = proc.returncode
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
