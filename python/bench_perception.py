"""Perception time per 640x480 frame: agrisim's detector (orchestrator/perception, through
its `time_frames` example) beside an OpenCV pipeline (HSV threshold, connected components,
depth median per blob) on the same frames, as a ratio in one run.

The frames come from a perception benchmark trial recorded in full:

    target/release/agrisim bench perception --trials 1 --frames 10 --environment 1 \
        --record full --out out/perception_frames
    .venv/bin/python python/bench_perception.py out/perception_frames/trials/0000.mcap

The OpenCV pipeline does less than agrisim's (no perceptual colour space, no depth
continuity, no sphere fit, no ripeness): it is the classical baseline's cost, not its
accuracy. Requires opencv-python-headless and mcap-ros2-support (python/requirements.txt).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import time
from pathlib import Path

import cv2
import numpy as np
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

REPO = Path(__file__).resolve().parents[1]
RGB = "/camera/color/image_raw"
DEPTH = "/camera/aligned_depth_to_color/image_raw"


def frames(mcap_path: Path):
    rgb, depth = {}, {}
    with open(mcap_path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for _, ch, _, msg in reader.iter_decoded_messages(topics=[RGB, DEPTH]):
            stamp = msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec
            data = np.frombuffer(bytes(msg.data), dtype=np.uint8 if ch.topic == RGB else "<f4")
            shape = (msg.height, msg.width, 3) if ch.topic == RGB else (msg.height, msg.width)
            (rgb if ch.topic == RGB else depth)[stamp] = data.reshape(shape)
    return [(rgb[s], depth[s]) for s in sorted(rgb) if s in depth]


def opencv_pipeline(rgb: np.ndarray, depth: np.ndarray) -> list[tuple[float, float, float]]:
    """Red-to-yellow pixels in HSV, 8-connected blobs, each blob's median depth."""
    hsv = cv2.cvtColor(rgb, cv2.COLOR_RGB2HSV)
    red = cv2.inRange(hsv, (0, 90, 15), (39, 255, 255)) | cv2.inRange(hsv, (170, 90, 15), (180, 255, 255))
    red &= ((depth > 0.15) & (depth < 1.6)).astype(np.uint8) * 255
    n, labels, stats, centroids = cv2.connectedComponentsWithStats(red, connectivity=8)
    out = []
    for i in range(1, n):
        if stats[i, cv2.CC_STAT_AREA] < 30:
            continue
        z = float(np.median(depth[labels == i]))
        out.append((float(centroids[i][0]), float(centroids[i][1]), z))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("mcap", type=Path)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--binary", default=str(REPO / "target/release/examples/time_frames"))
    a = ap.parse_args()
    fr = frames(a.mcap)
    assert fr, "no frames with colour and depth in the recording"
    cv2.setNumThreads(1)
    t = time.perf_counter()
    blobs = 0
    for _ in range(a.repeats):
        blobs = sum(len(opencv_pipeline(rgb, d)) for rgb, d in fr)
    cv_ms = 1000 * (time.perf_counter() - t) / (a.repeats * len(fr))
    ours = json.loads(subprocess.run([a.binary, str(a.mcap), str(a.repeats)], check=True, capture_output=True, text=True).stdout)
    print(json.dumps({
        "frames": len(fr),
        "size": f"{fr[0][0].shape[1]}x{fr[0][0].shape[0]}",
        "opencv_ms_per_frame": round(cv_ms, 3),
        "opencv_blobs": blobs,
        "agrisim_ms_per_frame": ours["ms_per_frame"],
        "agrisim_first_pass_ms_per_frame": ours.get("first_pass_ms_per_frame"),
        "agrisim_detections": ours["detections"],
        # Every detection of the last pass to the bit: equal before and after a change
        # meant to keep the results.
        "agrisim_digest": ours.get("digest"),
        "agrisim_over_opencv": round(ours["ms_per_frame"] / cv_ms, 3),
        "opencv_version": cv2.__version__,
    }))


if __name__ == "__main__":
    main()
