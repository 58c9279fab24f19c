#!/usr/bin/env python3
"""Camera and sensor-suite speed: a benchmark script, not a test.

1. Camera frames per second at 1280x720 (and 640x480) on 1 and 2 render threads: the Rust
   example `camera_fps` of agrisim-fmu-camera (whole frames: render + CDR encoding).
2. Real-time factor of the full sensor suite (models/systems/sensors.ssd: chassis, lift,
   world, LiDAR, IMU, camera at 1280x720 and 10 Hz): `agrisim run` of
   models/scenarios/sensors.toml for --seconds of simulated time; RTF = simulated / wall time
   (wall time includes loading the FMUs and building the scene).

    python3 python/bench_camera_suite.py [--seconds 5] [--frames 5] [--agrisim PATH] [--fmu-dir DIR]

Wall times on a shared machine vary; run it on an idle one for figures to quote.
"""

import argparse
import os
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seconds", type=float, default=5.0, help="simulated seconds of the suite run")
    ap.add_argument("--frames", type=int, default=5, help="timed frames per camera configuration")
    ap.add_argument("--agrisim", default=os.path.join(ROOT, "target", "release", "agrisim"))
    ap.add_argument("--fmu-dir", help="packed FMUs (default: the CLI's)")
    args = ap.parse_args()

    cmd = ["cargo", "run", "--release", "-q", "-p", "agrisim-fmu-camera", "--example", "camera_fps", "--", str(args.frames)]
    print("$", " ".join(cmd), flush=True)
    subprocess.run(cmd, cwd=ROOT, check=True)

    with tempfile.TemporaryDirectory() as out:
        cmd = [args.agrisim, "run", "--scenario", os.path.join(ROOT, "models", "scenarios", "sensors.toml"),
               "--duration", str(args.seconds), "--out", out]
        if args.fmu_dir:
            cmd[2:2] = ["--fmu-dir", args.fmu_dir]
        print("$", " ".join(cmd), flush=True)
        t = time.perf_counter()
        subprocess.run(cmd, cwd=ROOT, check=True)
        wall = time.perf_counter() - t
    print(f"sensor suite: {args.seconds:g} s simulated in {wall:.1f} s wall: real-time factor {args.seconds / wall:.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
