"""python/harvest_modes.py: the by-sight and ground-truth harvest runs paired trial by trial,
on hand-made trial records whose comparison is known."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "python"))
import harvest_modes  # noqa: E402


def trial(i, sight, outcome, failure=None, err=None, tth=30.0, fruit=None):
    return {"trial": i, "scene": i % 3, "seed": 1000 + i, "fruit_index": fruit if fruit is not None else 10 * i,
            "sight": sight, "outcome": outcome, "failure": failure, "target_error_mm": err,
            "time_to_harvest": tth}


def write(d: Path, trials) -> Path:
    d.mkdir()
    (d / "trials.jsonl").write_text("".join(json.dumps(t) + "\n" for t in trials))
    return d


def runs(tmp_path):
    sight = write(tmp_path / "sight", [
        trial(0, True, "success", err=4.0, tth=40.0),
        trial(1, True, "success", err=6.0, tth=44.0),
        trial(2, True, "failure", "planning", err=5.0),
        trial(3, True, "failure", "mislocalized", err=95.0),
        trial(4, True, "success", err=8.0, tth=38.0),
        trial(5, True, "failure", "planning", err=7.0),
    ])
    truth = write(tmp_path / "truth", [
        trial(0, False, "success", tth=30.0),
        trial(1, False, "success", tth=32.0),
        trial(2, False, "success"),
        trial(3, False, "success"),
        trial(4, False, "failure", "grasp"),
        trial(5, False, "failure", "planning"),
        trial(6, False, "success"),  # not run by sight: left out
    ])
    return sight, truth


def test_pairs_trials_and_splits_by_sight_outcome(tmp_path):
    sight, truth = runs(tmp_path)
    c = harvest_modes.compare(sight, truth)
    assert c["trials"] == 6
    assert c["sight"]["successes"] == 3 and c["ground_truth"]["successes"] == 4
    assert c["difference"] == pytest.approx(1 / 6)
    assert c["failed_by_sight_only"] == [2, 3] and c["failed_with_ground_truth_only"] == [4]
    rows = {r["sight_outcome"]: r for r in c["by_sight_outcome"]}
    assert [r["sight_outcome"] for r in c["by_sight_outcome"]] == ["success", "planning", "mislocalized"]
    assert rows["success"]["ground_truth"] == {"grasp": 1, "success": 2}
    assert rows["planning"]["ground_truth"] == {"planning": 1, "success": 1}
    assert rows["mislocalized"]["ground_truth"] == {"success": 1}
    # Errors: median of 4, 6, 8 and its interpolated 95th percentile.
    assert rows["success"]["target_error_mm_p50"] == 6.0
    assert rows["success"]["target_error_mm_p95"] == pytest.approx(7.8)
    # Time to harvest over the trials both modes harvested (0 and 1).
    assert rows["success"]["time_to_harvest_sight"] == 42.0
    assert rows["success"]["time_to_harvest_ground_truth"] == 31.0
    assert rows["planning"]["time_to_harvest_sight"] is None


def test_wilson_matches_the_benchmarks_interval():
    # `agrisim bench harvest` printed Wilson [0.801, 0.974] for 37/40.
    lo, hi = harvest_modes.wilson(37, 40)
    assert round(lo, 3) == 0.801 and round(hi, 3) == 0.974
    assert harvest_modes.wilson(0, 0) == (0.0, 1.0)
    assert harvest_modes.wilson(5, 5)[1] == 1.0


def test_command_prints_the_table_and_writes_json(tmp_path):
    sight, truth = runs(tmp_path)
    out = tmp_path / "c.json"
    r = subprocess.run([sys.executable, str(ROOT / "python/harvest_modes.py"), str(sight), str(truth), "--json",
                        str(out)], capture_output=True, text=True, check=True)
    assert "by sight:     3/6" in r.stdout and "ground truth: 4/6" in r.stdout
    assert "| planning | 2 | planning 1, success 1 |" in r.stdout
    assert json.loads(out.read_text())["failed_by_sight_only"] == [2, 3]


@pytest.mark.parametrize("change,said", [
    ({"fruit_index": 999}, "trial 1: fruit_index 10 in"),
    ({"seed": 5}, "trial 1: seed 1001 in"),
])
def test_different_trials_are_refused_naming_the_files(tmp_path, change, said):
    sight, _ = runs(tmp_path)
    bad = [trial(0, False, "success"), {**trial(1, False, "success"), **change}]
    truth = write(tmp_path / "other", bad)
    with pytest.raises(SystemExit) as e:
        harvest_modes.compare(sight, truth)
    assert said in str(e.value) and "sight/trials.jsonl" in str(e.value) and "other/trials.jsonl" in str(e.value)


def test_runs_in_the_wrong_mode_or_missing_are_refused(tmp_path):
    sight, truth = runs(tmp_path)
    with pytest.raises(SystemExit, match="not a by-sight run"):
        harvest_modes.compare(truth, truth)
    with pytest.raises(SystemExit, match="not a ground-truth run"):
        harvest_modes.compare(sight, sight)
    with pytest.raises(SystemExit, match="no such file"):
        harvest_modes.compare(tmp_path / "nowhere", truth)
    (tmp_path / "broken").mkdir()
    (tmp_path / "broken" / "trials.jsonl").write_text("{\"trial\": 0}\nnot json\n")
    with pytest.raises(SystemExit, match="broken/trials.jsonl:2: not a trial record"):
        harvest_modes.compare(tmp_path / "broken", truth)
