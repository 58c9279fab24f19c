"""Occupancy-map update per depth frame: agrisim-mapping beside OctoMap (Debian
liboctomap-dev 1.9.7) at the same resolution and max range, on the same frames, as a ratio in
one run, with the occupied/free agreement of the two final maps.

The frames are the camera's: `agrisim dataset` renders them (640x480 depth, 16-bit mm, with
their intrinsics and the optical frame's pose in the map), or pass an existing dataset.

    .venv/bin/python python/bench_mapping.py --frames 10 --seed 7
    .venv/bin/python python/bench_mapping.py --dataset out/dataset --frames 10 --resolution 0.02

What is timed:
* agrisim: `agrisim-mapping-bench` (orchestrator/mapping), per frame from the 16UC1
  sensor_msgs/Image to the updated map: decoding, unprojection into the map frame, ray
  clearing and the log-odds update.
* OctoMap: `OcTree::insertPointCloud(cloud, origin, max_range)` per frame on the points
  agrisim unprojected (python/octomap_bench.cpp, compiled here with g++ -O2): the ray casting
  and the update, not the unprojection (OctoMap takes point clouds), so the ratio favours it.
Each is the best of `--repeat` runs of the whole sequence on a fresh map, single-threaded.

Agreement: over every voxel either map knows, the share whose state (occupied, free,
unknown) is the same in both; also per class (occupied and free, intersection over union)
and how many voxels carry bit-identical log-odds.
"""

from __future__ import annotations

import argparse
import json
import os
import struct
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from PIL import Image

REPO = Path(__file__).resolve().parents[1]
RUST_BENCH = REPO / "target" / "release" / "agrisim-mapping-bench"
CPP = REPO / "python" / "octomap_bench.cpp"
CPP_BIN = REPO / "target" / "octomap-bench" / "octomap_bench"
AGRISIM = REPO / "target" / "release" / "agrisim"


def render(out: Path, frames: int, seed: int, width: int, height: int, scenario: str | None) -> Path:
    cmd = [str(AGRISIM), "dataset", "--frames", str(frames), "--seed", str(seed), "--width", str(width), "--height", str(height), "--out", str(out)]
    if scenario:
        cmd += ["--scenario", scenario]
    subprocess.run(cmd, check=True, cwd=REPO, stdout=subprocess.DEVNULL)
    return out


def write_frames(dataset: Path, frames: int, path: Path) -> int:
    """The dataset's first `frames` depth frames in agrisim-mapping-bench's input format."""
    names = sorted((dataset / "frames").glob("*.json"))[:frames]
    if not names:
        raise SystemExit(f"{dataset}/frames: no frames")
    with open(path, "wb") as out:
        out.write(struct.pack("<I", len(names)))
        for name in names:
            meta = json.loads(name.read_text())
            depth = np.asarray(Image.open(dataset / meta["image"]["depth_file"]), dtype=np.uint16)
            k = meta["camera_info"]["k"]
            m = np.asarray(meta["extrinsics"]["matrix"], dtype=np.float64)
            if meta["extrinsics"]["parent_frame"] != "map":
                raise SystemExit(f"{name}: extrinsics in {meta['extrinsics']['parent_frame']!r}, expected the map frame")
            h, w = depth.shape
            out.write(struct.pack("<II4d", w, h, k[0], k[4], k[2], k[5]))
            out.write(m[:3, :4].astype("<f8").tobytes())
            out.write(depth.astype("<u2").tobytes())
    return len(names)


def build_octomap_bench() -> Path:
    """Compiles python/octomap_bench.cpp (again when the source is newer)."""
    if CPP_BIN.exists() and CPP_BIN.stat().st_mtime >= CPP.stat().st_mtime:
        return CPP_BIN
    if not Path("/usr/include/octomap/octomap.h").exists():
        raise SystemExit("OctoMap headers missing: apt-get install liboctomap-dev (scripts/setup does)")
    CPP_BIN.parent.mkdir(parents=True, exist_ok=True)
    tmp = CPP_BIN.with_suffix(".tmp")
    subprocess.run(["g++", "-O2", "-std=c++17", str(CPP), "-o", str(tmp), "-loctomap", "-loctomath"], check=True)
    tmp.replace(CPP_BIN)
    return CPP_BIN


def read_map(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """(key codes sorted, log-odds) of a map file."""
    raw = path.read_bytes()
    (n,) = struct.unpack_from("<Q", raw)
    rec = np.frombuffer(raw, dtype=np.dtype([("x", "<i4"), ("y", "<i4"), ("z", "<i4"), ("l", "<f4")]), count=n, offset=8)
    code = ((rec["x"].astype(np.int64) + 32768) << 32) | ((rec["y"].astype(np.int64) + 32768) << 16) | (rec["z"].astype(np.int64) + 32768)
    order = np.argsort(code, kind="stable")
    return code[order], rec["l"][order]


def compare(a: tuple[np.ndarray, np.ndarray], b: tuple[np.ndarray, np.ndarray]) -> dict:
    """States over the union of known voxels: 0 unknown, 1 free, 2 occupied (log-odds >= 0)."""
    union = np.union1d(a[0], b[0])

    def states(m):
        s = np.zeros(union.size, dtype=np.int8)
        idx = np.searchsorted(union, m[0])
        s[idx] = np.where(m[1] >= 0.0, 2, 1)
        return s

    sa, sb = states(a), states(b)
    both = np.intersect1d(a[0], b[0], assume_unique=True)
    la = a[1][np.searchsorted(a[0], both)]
    lb = b[1][np.searchsorted(b[0], both)]

    def iou(c):
        inter = np.count_nonzero((sa == c) & (sb == c))
        uni = np.count_nonzero((sa == c) | (sb == c))
        return 100.0 * inter / uni if uni else 100.0

    return {
        "voxels_known_either": int(union.size),
        "agreement_pct": 100.0 * np.count_nonzero(sa == sb) / union.size if union.size else 100.0,
        "occupied_iou_pct": iou(2),
        "free_iou_pct": iou(1),
        "occupied": [int(np.count_nonzero(sa == 2)), int(np.count_nonzero(sb == 2))],
        "free": [int(np.count_nonzero(sa == 1)), int(np.count_nonzero(sb == 1))],
        "identical_log_odds_pct": 100.0 * np.count_nonzero(la == lb) / both.size if both.size else 100.0,
    }


def run(dataset: Path, frames: int, resolution: float, max_range: float, repeat: int, work: Path) -> dict:
    if not RUST_BENCH.exists():
        raise SystemExit(f"{RUST_BENCH} missing: cargo build --release -p agrisim-mapping")
    n = write_frames(dataset, frames, work / "frames.bin")
    rust = json.loads(subprocess.run(
        [str(RUST_BENCH), "--frames", str(work / "frames.bin"), "--resolution", str(resolution), "--max-range", str(max_range),
         "--repeat", str(repeat), "--clouds", str(work / "clouds.bin"), "--map", str(work / "agrisim.map")],
        check=True, capture_output=True, text=True).stdout)
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    octo = json.loads(subprocess.run(
        [str(build_octomap_bench()), str(work / "clouds.bin"), str(resolution), str(max_range), str(repeat), str(work / "octomap.map")],
        check=True, capture_output=True, text=True, env=env).stdout)
    agreement = compare(read_map(work / "agrisim.map"), read_map(work / "octomap.map"))
    return {
        "frames": n,
        "width_height": None,
        "resolution_m": resolution,
        "max_range_m": max_range,
        "repeat": repeat,
        "points": rust["points"],
        "agrisim_ms_per_frame": rust["mean_ms"],
        "octomap_ms_per_frame": octo["mean_ms"],
        "speedup_vs_octomap": octo["mean_ms"] / rust["mean_ms"] if rust["mean_ms"] > 0 else None,
        "agrisim_ms": rust["ms_per_frame"],
        "octomap_ms": octo["ms_per_frame"],
        **agreement,
    }


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--dataset", type=Path, help="an `agrisim dataset` directory (default: render one)")
    ap.add_argument("--frames", type=int, default=10)
    ap.add_argument("--seed", type=int, default=7, help="dataset seed when rendering")
    ap.add_argument("--scenario", help="scenario when rendering (default: the dataset command's)")
    ap.add_argument("--width", type=int, default=640)
    ap.add_argument("--height", type=int, default=480)
    ap.add_argument("--resolution", type=float, default=0.01)
    ap.add_argument("--max-range", type=float, default=2.0)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--json", type=Path, help="write the result here too")
    a = ap.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="bench_mapping_") as tmp:
        work = Path(tmp)
        dataset = a.dataset or render(work / "dataset", a.frames, a.seed, a.width, a.height, a.scenario)
        result = run(dataset, a.frames, a.resolution, a.max_range, a.repeat, work)
        meta = json.loads(sorted((dataset / "frames").glob("*.json"))[0].read_text())
        result["width_height"] = [meta["camera_info"]["width"], meta["camera_info"]["height"]]
        result["dataset"] = str(a.dataset) if a.dataset else f"agrisim dataset --frames {a.frames} --seed {a.seed} --width {a.width} --height {a.height}"
    text = json.dumps(result, indent=1)
    print(text)
    if a.json:
        a.json.write_text(text + "\n")
    return result


if __name__ == "__main__":
    sys.exit(0 if main() else 1)
