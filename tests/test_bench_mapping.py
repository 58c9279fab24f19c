"""The mapping benchmark's comparison (python/bench_mapping.py) on two camera depth frames:
agrisim-mapping and OctoMap (Debian liboctomap-dev), same resolution and max range, must end
with the same voxel states. A correctness check only: the timings are the benchmark's, not
asserted here.

The agreement is over every voxel either map knows (occupied, free or unknown alike); the
maps are also compared per class, and by their log-odds, which agrisim computes in OctoMap's
arithmetic.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from conftest import REPO

sys.path.insert(0, str(REPO / "python"))
import bench_mapping  # noqa: E402


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    # 320x240 keeps the test in seconds; the rays are the camera's all the same.
    return bench_mapping.render(tmp_path_factory.mktemp("mapping") / "d", 2, 7, 320, 240, None)


@pytest.mark.parametrize("resolution,max_range", [(0.02, 2.0), (0.01, 1.5)])
def test_agrees_with_octomap_on_camera_frames(dataset, tmp_path, resolution, max_range):
    r = bench_mapping.run(dataset, 2, resolution, max_range, 1, tmp_path)
    assert r["frames"] == 2 and r["points"] > 10_000, r
    assert r["occupied"][1] > 1000 and r["free"][1] > 10_000, r
    assert r["agreement_pct"] >= 99.0, r
    assert r["occupied_iou_pct"] >= 99.0 and r["free_iou_pct"] >= 99.0, r


def test_the_comparison_sees_a_difference(tmp_path):
    """compare() is not blind: a map with one voxel flipped and one missing is reported."""
    import numpy as np

    codes = np.arange(1000, dtype=np.int64)
    log = np.full(1000, -0.4, dtype=np.float32)
    log[:10] = 0.85
    other = log.copy()
    other[500] = 0.85
    r = bench_mapping.compare((codes, log), (codes[:-1], other[:-1]))
    assert r["voxels_known_either"] == 1000
    assert r["agreement_pct"] == pytest.approx(99.8)
    assert r["occupied"] == [10, 11] and r["free"] == [990, 988]
    assert r["identical_log_odds_pct"] == pytest.approx(100 * 998 / 999)
