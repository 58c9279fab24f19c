"""What perception costs the harvest, failure class by failure class: the same trials run by
sight and with ground truth, side by side.

    agrisim bench harvest --scenario models/scenarios/harvest_sight.toml --trials 40 --scenes 10 --seed 1 --out SIGHT
    agrisim bench harvest --scenario models/scenarios/harvest.toml --trials 40 --scenes 10 --seed 1 --out TRUTH
    .venv/bin/python python/harvest_modes.py SIGHT TRUTH [--json FILE]

Trial i of both runs has the same scene and the same target fruit (the by-sight task is the
region around it), so the runs pair by trial index; a pair whose scene seed or target differ
is an error naming both files. Only trials present in both runs are compared.

Printed: each run's success rate with its Wilson 95 % interval, the difference, and for every
outcome of the by-sight run (success or a failure class: not detected, mislocalized,
planning, grasp, handover, placement, ...) how the same trials ended with ground truth, with
the by-sight target error (the node's last estimate against the nearest true fruit) and the
time to harvest of the trials both modes harvested.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path


def wilson(k: int, n: int, z: float = 1.959963984540054) -> tuple[float, float]:
    """Wilson score interval of k successes in n trials (95 % by default)."""
    if n == 0:
        return (0.0, 1.0)
    p = k / n
    d = 1 + z * z / n
    c = (p + z * z / (2 * n)) / d
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return (max(0.0, c - h), min(1.0, c + h))


def quantile(xs: list[float], q: float) -> float | None:
    """The q-quantile by linear interpolation between order statistics, None when empty."""
    if not xs:
        return None
    s = sorted(xs)
    pos = q * (len(s) - 1)
    lo = math.floor(pos)
    hi = min(lo + 1, len(s) - 1)
    return s[lo] + (s[hi] - s[lo]) * (pos - lo)


def load(run: Path) -> dict[int, dict]:
    """The trials of a benchmark's output directory, by index."""
    path = run / "trials.jsonl"
    if not path.is_file():
        raise SystemExit(f"{path}: no such file (the output directory of `agrisim bench harvest`)")
    trials = {}
    for n, line in enumerate(path.read_text().splitlines(), 1):
        if not line.strip():
            continue
        try:
            t = json.loads(line)
            trials[int(t["trial"])] = t
        except (ValueError, KeyError, TypeError) as e:
            raise SystemExit(f"{path}:{n}: not a trial record ({e})")
    return trials


def outcome(t: dict) -> str:
    """"success" or the failure class."""
    return "success" if t.get("outcome") == "success" else (t.get("failure") or t.get("outcome") or "unknown")


def compare(sight_dir: Path, truth_dir: Path) -> dict:
    sight, truth = load(sight_dir), load(truth_dir)
    if any(t.get("sight") is not True for t in sight.values()):
        raise SystemExit(f"{sight_dir / 'trials.jsonl'}: not a by-sight run (a trial has \"sight\" false)")
    if any(t.get("sight") for t in truth.values()):
        raise SystemExit(f"{truth_dir / 'trials.jsonl'}: not a ground-truth run (a trial has \"sight\" true)")
    common = sorted(set(sight) & set(truth))
    if not common:
        raise SystemExit(f"{sight_dir} and {truth_dir} share no trial index")
    for i in common:
        a, b = sight[i], truth[i]
        for key in ("scene", "seed", "fruit_index"):
            if a.get(key) != b.get(key):
                raise SystemExit(
                    f"trial {i}: {key} {a.get(key)} in {sight_dir / 'trials.jsonl'} but {b.get(key)} in "
                    f"{truth_dir / 'trials.jsonl'}: not the same trials (same --seed, --scenes and scenario crop?)")
    n = len(common)
    ks = sum(outcome(sight[i]) == "success" for i in common)
    kt = sum(outcome(truth[i]) == "success" for i in common)
    classes = {}
    for i in common:
        classes.setdefault(outcome(sight[i]), []).append(i)
    rows = []
    for name in sorted(classes, key=lambda c: (c != "success", -len(classes[c]), c)):
        idx = classes[name]
        by_truth: dict[str, int] = {}
        for i in idx:
            o = outcome(truth[i])
            by_truth[o] = by_truth.get(o, 0) + 1
        err = [sight[i]["target_error_mm"] for i in idx if sight[i].get("target_error_mm") is not None]
        both = [i for i in idx if outcome(truth[i]) == "success" and name == "success"]
        rows.append({
            "sight_outcome": name,
            "trials": idx,
            "ground_truth": dict(sorted(by_truth.items())),
            "target_error_mm_p50": quantile(err, 0.5),
            "target_error_mm_p95": quantile(err, 0.95),
            "time_to_harvest_sight": (sum(sight[i]["time_to_harvest"] for i in both) / len(both)) if both else None,
            "time_to_harvest_ground_truth": (sum(truth[i]["time_to_harvest"] for i in both) / len(both)) if both else None,
        })
    only_truth = [i for i in common if outcome(truth[i]) == "success" and outcome(sight[i]) != "success"]
    only_sight = [i for i in common if outcome(sight[i]) == "success" and outcome(truth[i]) != "success"]
    return {
        "sight_run": str(sight_dir),
        "ground_truth_run": str(truth_dir),
        "trials": n,
        "sight": {"successes": ks, "rate": ks / n, "wilson95": wilson(ks, n)},
        "ground_truth": {"successes": kt, "rate": kt / n, "wilson95": wilson(kt, n)},
        "difference": (kt - ks) / n,
        "failed_by_sight_only": only_truth,
        "failed_with_ground_truth_only": only_sight,
        "by_sight_outcome": rows,
    }


def table(c: dict) -> str:
    def pct(r: dict) -> str:
        lo, hi = r["wilson95"]
        return f"{r['successes']}/{c['trials']} ({100 * r['rate']:.1f} %, Wilson [{100 * lo:.1f}, {100 * hi:.1f}])"

    def mm(v):
        return "-" if v is None else f"{v:.1f}"

    lines = [
        f"by sight:     {pct(c['sight'])}",
        f"ground truth: {pct(c['ground_truth'])}",
        f"perception costs {100 * c['difference']:+.1f} points; failed by sight only: trials "
        f"{c['failed_by_sight_only'] or '-'}; failed with ground truth only: trials {c['failed_with_ground_truth_only'] or '-'}",
        "",
        "| by sight | trials | same trials with ground truth | target error p50 / p95 [mm] | time to harvest, both harvested: sight / truth [s] |",
        "|---|---|---|---|---|",
    ]
    for r in c["by_sight_outcome"]:
        gt = ", ".join(f"{k} {v}" for k, v in r["ground_truth"].items())
        tth = "-" if r["time_to_harvest_sight"] is None else (
            f"{r['time_to_harvest_sight']:.1f} / {r['time_to_harvest_ground_truth']:.1f}")
        lines.append(f"| {r['sight_outcome']} | {len(r['trials'])} | {gt} | {mm(r['target_error_mm_p50'])} / "
                     f"{mm(r['target_error_mm_p95'])} | {tth} |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("sight", type=Path, help="output directory of the by-sight run")
    ap.add_argument("ground_truth", type=Path, help="output directory of the ground-truth run")
    ap.add_argument("--json", type=Path, help="also write the comparison here")
    a = ap.parse_args(argv)
    c = compare(a.sight, a.ground_truth)
    print(table(c))
    if a.json:
        a.json.write_text(json.dumps(c, indent=2, sort_keys=True) + "\n")


if __name__ == "__main__":
    main(sys.argv[1:])
