"""Benchmark of the gymnasium environments: environment steps per second, and the Python
side's cost per step (observation decoding, numpy, reward) as a fraction of the engine's own
stepping (Simulation.step, the interpreter lock released), both measured in the same run.
Also the cost of a seeded reset (snapshot restore) against building the simulation.

    .venv/bin/python python/bench_env.py [--steps N] [--json OUT]
"""

from __future__ import annotations

import argparse
import json
import time

import gymnasium as gym
import numpy as np

import agrisim  # noqa: F401


def measure(env_id: str, steps: int, seed: int = 0) -> dict:
    env = gym.make(env_id, disable_env_checker=True).unwrapped
    t = time.perf_counter()
    env.reset(seed=seed)
    first_reset = time.perf_counter() - t
    sim = env._sim
    engine = [0.0]
    inner = sim.step

    class Timed:
        """Times the engine's part of each environment step (Simulation.step)."""

        def __getattr__(self, name):
            return getattr(sim, name)

        def step(self, n=1):
            t0 = time.perf_counter()
            r = inner(n)
            engine[0] += time.perf_counter() - t0
            return r

    env._sim = Timed()
    rng = np.random.default_rng(seed)
    resets, reset_time, total = 0, 0.0, 0.0
    for k in range(steps):
        a = env.action_space.sample() if rng.random() < 0.5 else np.zeros(env.action_space.shape, np.float32)
        t0 = time.perf_counter()
        _, _, term, trunc, _ = env.step(a)
        total += time.perf_counter() - t0
        if term or trunc:
            t0 = time.perf_counter()
            env.reset(seed=seed + k)
            reset_time += time.perf_counter() - t0
            resets += 1
    env._sim = sim
    for k in range(20):  # seeded resets: snapshot restores, no rebuild
        t0 = time.perf_counter()
        env.reset(seed=1000 + k)
        reset_time += time.perf_counter() - t0
        resets += 1
    env.close()
    python = total - engine[0]
    return {
        "env": env_id,
        "steps": steps,
        "steps_per_second": steps / total,
        "ms_per_step": 1e3 * total / steps,
        "engine_ms_per_step": 1e3 * engine[0] / steps,
        "python_ms_per_step": 1e3 * python / steps,
        "python_overhead_fraction": python / engine[0],
        "first_reset_s": first_reset,
        "resets": resets,
        "reset_ms_mean": 1e3 * reset_time / resets if resets else None,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--steps", type=int, default=500)
    ap.add_argument("--json", help="write the figures here too")
    a = ap.parse_args()
    results = [measure("agrisim/Navigate-v0", a.steps), measure("agrisim/Reach-v0", a.steps)]
    for r in results:
        print(json.dumps(r))
    if a.json:
        with open(a.json, "w") as f:
            json.dump(results, f, indent=2)


if __name__ == "__main__":
    main()
