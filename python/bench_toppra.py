"""Speed of agrisim's Rust TOPP-RA against the toppra Python package on the same random 7-DoF
paths (those of test_toppra_crosscheck.py), in one run.

Per path both sides build the spline and solve TOPP-RA (velocity + acceleration limits,
interpolation discretization, rest to rest); toppra also builds its output trajectory. Rust is
timed inside the example binary (no process start or JSON), each path solved `--repeat` times.
Two settings: the same explicit gridpoints on both sides, and each side proposing its own grid.

    python python/bench_toppra.py [--paths 240] [--repeat 20]
"""

from __future__ import annotations

import argparse

import numpy as np

from test_toppra_crosscheck import random_paths, run_rust, rust_problem, solve_toppra, trajectory_bin


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--paths", type=int, default=240)
    ap.add_argument("--repeat", type=int, default=20)
    ap.add_argument("--seed", type=int, default=20240604)
    args = ap.parse_args()
    exe = trajectory_bin()
    cases = random_paths(args.paths, seed=args.seed)
    grids = [solve_toppra(c)[1] for c in cases]
    print(f"{args.paths} random 7-DoF paths, mean gridpoints {np.mean([len(g) for g in grids]):.0f}")
    for label, explicit in (("same gridpoints", True), ("own grid proposal", False)):
        py_times, py_durations = [], []
        for c, g in zip(cases, grids):
            dur, _, sec = solve_toppra(c, g if explicit else None)
            py_times.append(sec)
            py_durations.append(dur)
        rust = run_rust(exe, "toppra", [
            rust_problem(c, repeat=args.repeat, **({"gridpoints": g.tolist()} if explicit else {}))
            for c, g in zip(cases, grids)
        ])
        rs_times = [r["seconds"] for r in rust]
        rel = max(abs(r["duration"] - d) / d for r, d in zip(rust, py_durations))
        py_ms, rs_ms = 1e3 * np.mean(py_times), 1e3 * np.mean(rs_times)
        print(f"{label:18s}: toppra {py_ms:8.3f} ms/path, Rust {rs_ms:7.3f} ms/path, "
              f"speed ratio {py_ms / rs_ms:6.1f}x, max duration rel. diff {rel:.1e}")


if __name__ == "__main__":
    main()
