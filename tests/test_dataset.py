"""`agrisim dataset` (orchestrator/dataset): the synthetic perception dataset.

* The COCO file loads in pycocotools (the reference COCO API); every annotation's RLE decodes
  there to a mask whose area and box are the annotation's, equal to its pixels in the
  instances PNG; the masks evaluated against themselves give AP 1.
* The masks agree pixel for pixel with the Camera FMU's own labels image of the same frame:
  the FMU is run again here under FMPy with the frame's recorded parameters and inputs, and
  its 32SC1 labels are decoded with rosbags, independently of the writer. The depth PNG is
  that frame's depth in mm; reprojected with the recorded intrinsics and extrinsics, every
  depth pixel of a fruit lies on that fruit (recorded map pose and radius).
* Two runs with one seed write identical files; another seed does not.
* SIGINT mid-run leaves complete frames and a valid COCO file of exactly those frames, and
  `--resume` ends with the same bytes as the uninterrupted run.
"""

from __future__ import annotations

import json
import signal
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest
from conftest import REPO, agrisim_bin, run_agrisim
from PIL import Image
from pycocotools import mask as mask_utils
from pycocotools.coco import COCO
from pycocotools.cocoeval import COCOeval

import agrisim_frames
from agrisim_fmpy import Slave, fmu_path

FRAMES, SCENES, SEED = 40, 2, 11
W, H = 160, 120
CATEGORIES = ["green", "breakers", "turning", "pink", "light_red", "red"]

# A small greenhouse (fast to build), no shadows, and exact depth (noise model 0), so the
# reprojection check can be tight.
SCENARIO = f"""
name = "dataset_small"
seed = 4
[system]
file = "{REPO / 'models' / 'systems' / 'default.ssd'}"
[greenhouse]
rows = 4
active_rows = 4
row_length = 8.0
length = 16.0
width = 14.0
[environment]
render_quality = "low"
[parameters.camera]
width = {W}
height = {H}
depth_noise_model = 0
"""


@pytest.fixture(scope="module")
def scenario(tmp_path_factory) -> Path:
    p = tmp_path_factory.mktemp("scenario") / "dataset_small.toml"
    p.write_text(SCENARIO)
    return p


def args(scenario: Path, out: Path, seed: int = SEED, *extra: str) -> list[str]:
    return ["dataset", "--scenario", str(scenario), "--frames", str(FRAMES), "--seed", str(seed),
            "--scenes", str(SCENES), "--out", str(out), *extra]


@pytest.fixture(scope="module")
def full(tmp_path_factory, scenario) -> Path:
    out = tmp_path_factory.mktemp("full") / "ds"
    run_agrisim(*args(scenario, out))
    return out


def tree(root: Path) -> dict[str, bytes]:
    return {p.relative_to(root).as_posix(): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


def frame_record(root: Path, i: int) -> dict:
    return json.loads((root / "frames" / f"{i:06d}.json").read_text())


def png(path: Path) -> np.ndarray:
    return np.array(Image.open(path))


def test_layout_and_coco_load_in_pycocotools(full):
    files = tree(full)
    for d, ext in [("rgb", "png"), ("depth", "png"), ("instances", "png"), ("frames", "json")]:
        assert sorted(k for k in files if k.startswith(d + "/")) == [f"{d}/{i:06d}.{ext}" for i in range(FRAMES)]
    assert not [k for k in files if k.endswith(".part")]
    coco = COCO(str(full / "annotations.json"))
    assert [c["name"] for c in coco.loadCats(coco.getCatIds())] == CATEGORIES
    assert sorted(coco.getImgIds()) == list(range(1, FRAMES + 1))
    anns = coco.loadAnns(coco.getAnnIds())
    assert len(anns) > 5 * FRAMES, "the views should show fruit"
    assert len({a["category_id"] for a in anns}) >= 4, "several ripeness stages"
    assert len({a["id"] for a in anns}) == len(anns)
    manifest = json.loads((full / "dataset.json").read_text())
    assert [s["index"] for s in manifest["scenes"]] == list(range(SCENES))
    for img in coco.loadImgs(coco.getImgIds()):
        assert (img["width"], img["height"]) == (W, H)
        rgb, depth, inst = png(full / img["file_name"]), png(full / img["depth_file"]), png(full / img["instances_file"])
        assert rgb.shape == (H, W, 3) and rgb.dtype == np.uint8
        assert depth.shape == inst.shape == (H, W)
        assert Image.open(full / img["depth_file"]).mode.startswith("I;16")
        rec = frame_record(full, img["id"] - 1)
        ripeness = {f["object_id"]: f["ripeness"] for f in rec["fruits"]}
        union = np.zeros((H, W), bool)
        for a in coco.loadAnns(coco.getAnnIds(imgIds=[img["id"]])):
            m = coco.annToMask(a).astype(bool)
            assert a["iscrowd"] == 0 and a["area"] == int(m.sum()) == int(mask_utils.area(a["segmentation"]))
            assert a["bbox"] == [int(v) for v in mask_utils.toBbox(a["segmentation"])]
            assert np.array_equal(m, inst == a["instance"]), (img["id"], a["name"])
            assert a["category_id"] == ripeness[a["object_id"]]
            union |= m
        assert np.array_equal(union, inst > 0)


def test_coco_eval_of_the_masks_against_themselves_is_perfect(full):
    gt = COCO(str(full / "annotations.json"))
    results = [{"image_id": a["image_id"], "category_id": a["category_id"], "segmentation": a["segmentation"], "score": 1.0}
               for a in gt.loadAnns(gt.getAnnIds())]
    e = COCOeval(gt, gt.loadRes(results), "segm")
    e.params.maxDets = [1, 10, 10000]  # views hold hundreds of small fruit
    e.params.imgIds = sorted(gt.getImgIds())[:8]  # (a few: the evaluation is slow)
    e.evaluate()
    e.accumulate()
    e.summarize()
    # AP at IoU 0.5 and 0.75 (stats[0] is fixed to 100 detections per image in pycocotools).
    assert e.stats[1] == pytest.approx(1.0) and e.stats[2] == pytest.approx(1.0)


def camera_frame(record: dict, tmp: Path) -> tuple[np.ndarray, np.ndarray]:
    """The Camera FMU's labels and depth for a frame's recorded parameters and inputs, run
    under FMPy and decoded with rosbags."""
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE)
    s = Slave(fmu_path("Camera"), "camera", unzip_root=tmp)
    try:
        for name, value in record["camera_parameters"].items():
            v = s.var(name)
            if v.type == "String":
                s.slave.setString([v.valueReference], [value])
            else:
                s.set(name, value)
        s.initialize(0.0)
        t = 0.0
        while s.get("labels_seq") == 0:
            assert t < 1.0, "no frame"
            s.do_step(t, 0.02)
            t += 0.02
        out = []
        for port, dtype in [("labels", "<i4"), ("depth", "<f4")]:
            frames = agrisim_frames.decode(s.get(port))
            msg = store.deserialize_cdr(frames[-1].payload, "sensor_msgs/msg/Image")
            assert (msg.width, msg.height) == (W, H)
            out.append(np.frombuffer(bytes(msg.data), dtype=dtype).reshape(H, W))
        return out[0], out[1]
    finally:
        s.close()


@pytest.mark.parametrize("i", [0, FRAMES // 2 + 1, FRAMES - 1])
def test_masks_and_depth_match_the_camera_fmu(full, tmp_path, i):
    rec = frame_record(full, i)
    labels, depth = camera_frame(rec, tmp_path)
    coco = COCO(str(full / "annotations.json"))
    anns = coco.loadAnns(coco.getAnnIds(imgIds=[i + 1]))
    assert anns, f"frame {i} shows no fruit"
    for a in anns:
        assert np.array_equal(coco.annToMask(a).astype(bool), labels == a["object_id"] + 1), a["name"]
        assert "/fruit" in a["name"]
    # Fruit in the labels that have no annotation would be missing masks: every labelled
    # object the frame's fruit list calls visible has one, and none of the others is a fruit
    # listed in the field of view.
    listed = {f["object_id"]: f for f in rec["fruits"]}
    seen = {int(v) - 1 for v in np.unique(labels) if v > 0}
    assert {a["object_id"] for a in anns} == {o for o in seen if o in listed} == {o for o, f in listed.items() if f["visible_pixels"] > 0}
    # Depth PNG: the camera's depth in mm (rounded half up), 0 = no data.
    mm = np.where(depth > 0, np.floor(depth.astype(np.float64) * 1000.0 + 0.5), 0).astype(np.uint16)
    assert np.array_equal(png(full / f"depth/{i:06d}.png"), mm)
    # Reprojection: K and T_map_camera put each fruit pixel's depth on that fruit: within its
    # collider sphere, no deeper than the camera's drawn fruit (an oblate spheroid 0.10-0.15 r
    # below the poles, fmus/camera/src/crop.rs) and its calyx go; 2 mm for mm rounding.
    k = np.array(rec["camera_info"]["k"]).reshape(3, 3)
    t = np.array(rec["extrinsics"]["matrix"])
    d = png(full / f"depth/{i:06d}.png").astype(np.float64) / 1000.0
    v, u = np.mgrid[0:H, 0:W]
    checked = 0
    for a in anns:
        f = listed[a["object_id"]]
        m = (labels == a["object_id"] + 1) & (d > 0)
        z = d[m]
        cam = np.stack([(u[m] - k[0, 2]) / k[0, 0] * z, (v[m] - k[1, 2]) / k[1, 1] * z, z, np.ones_like(z)])
        world = (t @ cam)[:3].T
        dist = np.linalg.norm(world - np.array(f["position"]), axis=1)
        r = f["radius"]
        assert np.all((dist > 0.8 * r - 0.002) & (dist < r + 0.002)), (a["name"], dist.min(), dist.max(), r)
        checked += len(z)
    assert checked > 0


def test_one_seed_gives_identical_files(full, scenario, tmp_path):
    again = tmp_path / "again"
    run_agrisim(*args(scenario, again))
    a, b = tree(full), tree(again)
    assert sorted(a) == sorted(b)
    assert [k for k in a if a[k] != b[k]] == []
    other = tmp_path / "other"
    run_agrisim(*args(scenario, other, SEED + 1))
    c = tree(other)
    assert c["annotations.json"] != a["annotations.json"]
    assert sum(c[k] != a[k] for k in a if k.startswith("rgb/")) == FRAMES


def test_sigint_leaves_a_valid_partial_dataset_and_resume_completes_it(full, scenario, tmp_path):
    out = tmp_path / "ds"
    p = subprocess.Popen([str(agrisim_bin()), *args(scenario, out)], cwd=REPO,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60
    while not (out / "frames" / "000002.json").exists():
        assert p.poll() is None and time.monotonic() < deadline, p.communicate()
        time.sleep(0.005)
    p.send_signal(signal.SIGINT)
    stdout, stderr = p.communicate(timeout=60)
    assert p.returncode == 130, stderr
    assert "--resume" in stderr
    done = sorted(out.glob("frames/*.json"))
    assert 3 <= len(done) < FRAMES, "interrupted mid-run"
    assert [f.name for f in done] == [f"{i:06d}.json" for i in range(len(done))]
    assert not list(out.rglob("*.part"))
    coco = COCO(str(out / "annotations.json"))
    assert sorted(coco.getImgIds()) == list(range(1, len(done) + 1))
    full_coco = json.loads((full / "annotations.json").read_text())
    partial = json.loads((out / "annotations.json").read_text())
    assert partial["images"] == full_coco["images"][: len(done)]
    assert partial["annotations"] == full_coco["annotations"][: len(partial["annotations"])]
    for img in partial["images"]:
        for key in ("file_name", "depth_file", "instances_file"):
            assert (out / img[key]).read_bytes() == (full / img[key]).read_bytes()
    # Resuming with other settings is refused; with the same ones it completes the set.
    bad = run_agrisim(*args(scenario, out, SEED + 1, "--resume"), check=False)
    assert bad.returncode != 0 and "other settings" in bad.stderr
    fresh = run_agrisim(*args(scenario, out), check=False)
    assert fresh.returncode != 0 and "--resume" in fresh.stderr
    run_agrisim(*args(scenario, out, SEED, "--resume"))
    a, b = tree(full), tree(out)
    assert sorted(a) == sorted(b)
    assert [k for k in a if a[k] != b[k]] == []
