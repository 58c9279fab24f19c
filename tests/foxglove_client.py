"""A Foxglove WebSocket client (the `websockets` package; protocol foxglove.sdk.v1) for the
live-view test: it starts the agrisim command given after `--` (sharing this network
namespace), reads the server address from its stderr, subscribes to the topics asked for
and saves what it receives: serverInfo, the channel advertisements and every message
(log time, payload) per topic, as JSON."""

import argparse
import asyncio
import json
import re
import struct
import subprocess
import sys
from pathlib import Path

import websockets


async def client(url: str, topics: list[str], out: dict, stop: asyncio.Event) -> None:
    async with websockets.connect(url, subprotocols=["foxglove.sdk.v1"], max_size=None) as ws:
        out["subprotocol"] = ws.subprotocol
        subscribed: dict[int, str] = {}
        next_id = 1
        while not stop.is_set() or True:
            try:
                frame = await asyncio.wait_for(ws.recv(), timeout=1.0)
            except asyncio.TimeoutError:
                if stop.is_set():
                    return
                continue
            except websockets.ConnectionClosed:
                return
            if isinstance(frame, str):
                msg = json.loads(frame)
                if msg["op"] == "serverInfo":
                    out["serverInfo"] = msg
                elif msg["op"] == "status" and msg.get("message", "").startswith("Unknown channel ID: "):
                    # The foxglove crate can advertise a channel a moment before it accepts
                    # subscriptions to it (seen with channels made while a client is connected):
                    # ask again, as a viewer would.
                    cid = int(msg["message"].rsplit(" ", 1)[1])
                    topic = next((t for t, ch in out["channels"].items() if ch["id"] == cid), None)
                    if topic in topics:
                        await asyncio.sleep(0.05)
                        subscribed[next_id] = topic
                        await ws.send(json.dumps({"op": "subscribe", "subscriptions": [{"id": next_id, "channelId": cid}]}))
                        next_id += 1
                elif msg["op"] == "advertise":
                    subs = []
                    for ch in msg["channels"]:
                        out["channels"][ch["topic"]] = ch
                        if ch["topic"] in topics:
                            subscribed[next_id] = ch["topic"]
                            subs.append({"id": next_id, "channelId": ch["id"]})
                            next_id += 1
                    if subs:
                        await ws.send(json.dumps({"op": "subscribe", "subscriptions": subs}))
            else:
                if frame[0] == 1:  # message data: op, subscription id, log time, payload
                    sub, t = struct.unpack_from("<IQ", frame, 1)
                    out["messages"].setdefault(subscribed[sub], []).append([t, frame[13:].hex()])
                elif frame[0] == 2:  # time
                    out["time"].append(struct.unpack_from("<Q", frame, 1)[0])


async def main_async(a) -> int:
    proc = await asyncio.create_subprocess_exec(*[x for x in a.agrisim if x != "--"], stderr=subprocess.PIPE)
    url = None
    lines = []
    while url is None:
        line = (await proc.stderr.readline()).decode()
        if not line:
            break
        lines.append(line)
        m = re.search(r"foxglove: (ws://\S+)", line)
        if m:
            url = m.group(1)
    out = {"channels": {}, "messages": {}, "time": [], "url": url}
    stop = asyncio.Event()

    async def drain_stderr():
        while True:
            line = await proc.stderr.readline()
            if not line:
                return
            lines.append(line.decode())

    task = asyncio.create_task(client(url, a.topic, out, stop)) if url else None
    drainer = asyncio.create_task(drain_stderr())
    rc = await proc.wait()
    await drainer
    stop.set()
    if task:
        await task
    out["returncode"] = rc
    out["stderr"] = "".join(lines)
    Path(a.out).write_text(json.dumps(out))
    return 0


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", required=True)
    ap.add_argument("--topic", action="append", default=[])
    ap.add_argument("agrisim", nargs=argparse.REMAINDER)
    return asyncio.run(main_async(ap.parse_args()))


if __name__ == "__main__":
    sys.exit(main())
