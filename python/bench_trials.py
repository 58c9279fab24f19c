"""Trial throughput of the benchmark backends, one run: the CLI with --jobs 1 and --jobs 2,
and the Python API in this process and as Ray tasks on a local 2-CPU Ray cluster (loopback,
shut down at the end). Also checks that every backend wrote the same trials.

    .venv/bin/python python/bench_trials.py [--trials 6] [--seed 4] [--out /tmp/bench-trials]
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import time
from pathlib import Path

import agrisim


def trials(out: Path) -> list[dict]:
    return [{k: v for k, v in json.loads(line).items() if k != "wall_time"} for line in (out / "trials.jsonl").read_text().splitlines()]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--trials", type=int, default=6)
    ap.add_argument("--seed", type=int, default=4)
    ap.add_argument("--out", type=Path, default=Path("/tmp/bench-trials"))
    a = ap.parse_args()
    scenario = str(agrisim.scenario_path("default"))
    exe = agrisim.root() / "target/release/agrisim"
    times, dirs = {}, {}

    def timed(label, run):
        out = a.out / label
        shutil.rmtree(out, ignore_errors=True)
        t = time.perf_counter()
        run(out)
        times[label], dirs[label] = time.perf_counter() - t, out

    for jobs in (1, 2):
        timed(f"cli_jobs{jobs}", lambda out: subprocess.run([str(exe), "bench", "nav", "--scenario", scenario, "--trials", str(a.trials), "--seed", str(a.seed), "--record", "standard", "--jobs", str(jobs), "--out", str(out)], check=True, stdout=subprocess.DEVNULL))
    timed("python_in_process", lambda out: agrisim.bench.nav(out, scenario=scenario, trials=a.trials, seed=a.seed, record="standard"))
    import ray

    ray.init(num_cpus=2, include_dashboard=False, _node_ip_address="127.0.0.1", log_to_driver=False, configure_logging=False)
    try:
        timed("ray_2cpu", lambda out: agrisim.bench.nav(out, scenario=scenario, trials=a.trials, seed=a.seed, record="standard", backend="ray"))
    finally:
        ray.shutdown()
    ref = dirs["cli_jobs1"]
    same = all(trials(d) == trials(ref) and all((d / f"trials/{i:04}.mcap").read_bytes() == (ref / f"trials/{i:04}.mcap").read_bytes() for i in range(a.trials)) for d in dirs.values())
    print(json.dumps({"seconds": times, "jobs2_speedup": times["cli_jobs1"] / times["cli_jobs2"], "ray_speedup": times["python_in_process"] / times["ray_2cpu"], "identical_trials_and_mcaps": same}, indent=2))


if __name__ == "__main__":
    main()
