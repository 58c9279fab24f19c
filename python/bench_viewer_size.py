"""What the viewer topics add to a recording: an `agrisim run --record standard` of a scenario
(default: models/scenarios/default.toml, 10 s), once as it is and once per exclusion with
`[recording] exclude` (the product's own topic filter, so the recorder's chunking and zstd
level are the real ones), then the bytes each viewer topic and each marker namespace takes.

    cargo build --release -p agrisim -j 2
    .venv/bin/python python/bench_viewer_size.py [--duration 10] [--scenario FILE]

Printed: the file sizes, the growth with the viewer topics in (against the same run with
/robot_description, /scene/markers and /scene/fruit_markers excluded, and also with the
robot's /joint_states and /tf_static excluded), the bytes each topic adds to the file, and
each topic and marker namespace compressed alone (zstd level 1, as the recorder's chunks;
an estimate: in the file a message shares its chunk with others).
"""

from __future__ import annotations

import argparse
import re
import struct
import subprocess
import tempfile
from pathlib import Path

import zstandard
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

REPO = Path(__file__).resolve().parents[1]
VIEWER = ["/robot_description", "/scene/markers", "/scene/fruit_markers"]
ROBOT = ["/joint_states", "/tf_static"]


def record(binary: Path, scenario: Path, work: Path, name: str, exclude: list[str], duration: float) -> Path:
    """Runs `scenario` with `exclude` added to its [recording] and returns the MCAP."""
    text = scenario.read_text()
    # The copy lives elsewhere: make its relative paths (the system file) absolute.
    text = re.sub(r'^(file\s*=\s*")(\.\.?/[^"]*)"', lambda m: f'{m[1]}{(scenario.parent / m[2]).resolve()}"', text,
                  flags=re.M)
    if "[recording]" in text:
        raise SystemExit(f"{scenario} has a [recording] table: measure a scenario without one")
    if exclude:
        text += "\n[recording]\nexclude = [" + ", ".join(f'"{t}"' for t in exclude) + "]\n"
    path = work / f"{name}.toml"
    path.write_text(text)
    out = work / name
    subprocess.run([str(binary), "run", "--scenario", str(path), "--duration", str(duration), "--record", "standard",
                    "--out", str(out)], check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return out / "run.mcap"


def alone(path: Path) -> None:
    """Each viewer topic, and each marker namespace's points, compressed alone."""
    z = zstandard.ZstdCompressor(level=1)
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for _, channel, message, decoded in reader.iter_decoded_messages(topics=VIEWER):
            n = len(message.data)
            print(f"  {channel.topic:22s} t={message.log_time / 1e9:5.2f} s  CDR {n:8,d} B  alone {len(z.compress(message.data)):7,d} B")
            for k in getattr(decoded, "markers", []):
                raw = b"".join(struct.pack("<3d", p.x, p.y, p.z) for p in k.points)
                print(f"    {k.ns}/{k.id} type {k.type}: {len(k.points):5d} points, {len(z.compress(raw)):6,d} B alone")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenario", type=Path, default=REPO / "models/scenarios/default.toml")
    ap.add_argument("--duration", type=float, default=10.0)
    ap.add_argument("--binary", type=Path, default=REPO / "target/release/agrisim")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        size = lambda name, exclude: record(a.binary, a.scenario, work, name, exclude, a.duration).stat().st_size
        full = size("all", [])
        base = size("base", VIEWER)
        robot = size("robot", VIEWER + ROBOT)
        print(f"{a.scenario.name}, {a.duration:g} s, --record standard: {full:,d} B")
        print(f"  without {', '.join(VIEWER)}: {base:,d} B; growth +{full - base:,d} B, {100 * (full - base) / base:.2f} %")
        print(f"  also without {', '.join(ROBOT)}: {robot:,d} B; growth +{full - robot:,d} B, "
              f"{100 * (full - robot) / robot:.2f} %")
        for t in VIEWER + ROBOT:
            print(f"  {t}: +{full - size('one', [t]):,d} B in the file")
        alone(work / "all" / "run.mcap")


if __name__ == "__main__":
    main()
