"""A sensor subscriber on Eclipse Cyclone DDS for the bridge test: it starts the agrisim command
given after `--` (sharing this network namespace), answers every /clock tick with a zero
/cmd_vel (so lockstep waits for it, and it is there from the first instant), and keeps every
sample of the --topic TOPIC=TYPE topics as received (raw CDR, best effort). Writes them as
JSON (hex) to --out."""

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

from cyclonedds._clayer import ddspy_take
from cyclonedds.core import InstanceState, Policy, Qos, SampleState, ViewState
from cyclonedds.domain import DomainParticipant
from cyclonedds.internal import InvalidSample
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic

sys.path.insert(0, str(Path(__file__).parent))
from ros2_external_harvest import opaque  # noqa: E402
from ros2_idl import Clock, Twist  # noqa: E402

ANY = SampleState.Any | ViewState.Any | InstanceState.Any


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", required=True)
    ap.add_argument("--topic", action="append", default=[], help="TOPIC=pkg/msg/Type")
    ap.add_argument("agrisim", nargs=argparse.REMAINDER)
    a = ap.parse_args()
    dp = DomainParticipant(0)
    reliable = Qos(Policy.Reliability.Reliable(1_000_000_000), Policy.History.KeepAll)
    best_effort = Qos(Policy.Reliability.BestEffort, Policy.History.KeepLast(100))
    clock = DataReader(dp, Topic(dp, "rt/clock", Clock), qos=reliable)
    cmd = DataWriter(dp, Topic(dp, "rt/cmd_vel", Twist), qos=reliable)
    readers = {}
    for spec in a.topic:
        name, ty = spec.split("=")
        readers[name] = DataReader(dp, Topic(dp, "rt" + name, opaque(ty)), qos=best_effort)
    got = {name: [] for name in readers}
    proc = subprocess.Popen([x for x in a.agrisim if x != "--"])
    try:
        deadline = time.monotonic() + 300
        while proc.poll() is None and time.monotonic() < deadline:
            for name, r in readers.items():
                ret = ddspy_take(r._ref, ANY, 100)
                got[name] += [bytes(d).hex() for d, info in ([] if isinstance(ret, int) else ret) if info.valid_data]
            ticks = [m for m in clock.take(N=100) if not isinstance(m, InvalidSample)]
            for _ in ticks:
                cmd.write(Twist())
            if not ticks:
                time.sleep(0.0002)
    finally:
        if proc.poll() is None:
            proc.kill()
        proc.wait()
    Path(a.out).write_text(json.dumps(got))
    print(json.dumps({"returncode": proc.returncode, "received": {k: len(v) for k, v in got.items()}}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
