"""The many-trial benchmarks from Python: every benchmark ``agrisim bench <name>`` offers
(:func:`names`), run by :func:`run` through the same registry and dispatch as the CLI, writing
the same files (summary.json, trials.jsonl, trials/NNNN.mcap and .json, report.html). Trials
run in this process (``jobs=0``), in N local worker processes (``jobs=N``), or as Ray tasks on
a Ray cluster (``backend="ray"``, after ``ray.init(...)``). Trial i depends only on (seed, i),
so trials.jsonl and every trial MCAP are the same whatever the backend; only wall-clock
figures (wall_time, rtf) differ."""

from __future__ import annotations

import json
import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from . import _agrisim


@dataclass
class Result:
    """A finished benchmark: summary.json as a dict, and trials.jsonl's records."""

    summary: dict
    trials: list[dict] = field(default_factory=list)
    out: Path = Path(".")


def _result(out: Path, summary_text: str) -> Result:
    lines = (out / "trials.jsonl").read_text().splitlines()
    return Result(summary=json.loads(summary_text), trials=[json.loads(x) for x in lines if x.strip()], out=out)


@dataclass(frozen=True)
class Benchmark:
    """A registered benchmark: its name, what it is, its default scenario and its own
    options (name -> default; a keyword of :func:`run`)."""

    name: str
    about: str
    default_scenario: str
    options: dict


def benchmarks() -> list[Benchmark]:
    """Every registered benchmark, in the order ``agrisim bench --help`` lists them."""
    return [Benchmark(n, a, s, dict(o)) for n, a, s, o in _agrisim.benchmarks()]


def names() -> list[str]:
    """The names :func:`run` takes: the subcommands of ``agrisim bench`` (``overhead`` aside)."""
    return [b.name for b in benchmarks()]


def run(benchmark: str, out, scenario=None, trials: int = 50, seed: int = 1, scenes: int = 1, record: str | None = None, jobs: int = 0, backend: str = "local", resume: bool = False, **options) -> Result:
    """Benchmark ``benchmark`` (one of :func:`names`), as ``agrisim bench <benchmark>`` runs it.

    ``record``: full, standard (default), judge or none. ``jobs``: 0 = in this process,
    N = N worker processes. ``backend="ray"``: one Ray task per trial on the cluster
    ``ray.init`` joined. ``options``: the benchmark's own (e.g. ``length=2.0`` for row)."""
    out = Path(out)
    plan: dict[str, Any] = dict(scenario=None if scenario is None else str(scenario), trials=trials, seed=seed, scenes=scenes, record=record, options=options)
    if backend == "local":
        return _result(out, _agrisim.bench_run(benchmark, str(out), jobs=jobs, resume=resume, **plan))
    if backend == "ray":
        _ray_trials(benchmark, out, plan, resume)
        # Every trial's files are in place: the benchmark sums them up as a resumed run does.
        return _result(out, _agrisim.bench_run(benchmark, str(out), jobs=0, resume=True, **plan))
    raise ValueError(f"unknown backend {backend!r} (local or ray)")


def nav(out, scenario=None, trials: int = 50, seed: int = 1, scenes: int = 1, record: str | None = None, jobs: int = 0, backend: str = "local", resume: bool = False) -> Result:
    """``run("nav", ...)``: the navigation benchmark (default scenario: models/scenarios/default.toml)."""
    return run("nav", out, scenario, trials, seed, scenes, record, jobs, backend, resume)


def harvest(out, scenario=None, trials: int = 50, seed: int = 1, scenes: int = 1, record: str | None = None, jobs: int = 0, backend: str = "local", resume: bool = False) -> Result:
    """``run("harvest", ...)``: the dual-arm harvest benchmark (default scenario:
    models/scenarios/harvest_sight.toml, by sight; models/scenarios/harvest.toml is the
    ground-truth mode)."""
    return run("harvest", out, scenario, trials, seed, scenes, record, jobs, backend, resume)


def run_trial(benchmark: str, out, index: int, scenario=None, trials: int = 50, seed: int = 1, scenes: int = 1, record: str | None = None, **options) -> None:
    """Trial ``index`` alone, into ``out/trials/NNNN.mcap`` and ``.json`` (as the benchmark
    writes them); a later ``run(..., resume=True)`` sums the trials up."""
    _agrisim.run_trial(benchmark, str(out), index, scenario=None if scenario is None else str(scenario), trials=trials, seed=seed, scenes=scenes, record=record, options=options)


def _trial_files(kind: str, index: int, plan: dict) -> tuple[bytes, bytes]:
    """One trial on whichever machine runs it; its files travel back as bytes."""
    with tempfile.TemporaryDirectory(prefix="agrisim-trial-") as d:
        _agrisim.run_trial(kind, d, index, **plan)
        t = Path(d) / "trials"
        return (t / f"{index:04}.json").read_bytes(), (t / f"{index:04}.mcap").read_bytes()


def _write_atomic(path: Path, data: bytes) -> None:
    part = path.with_name(path.name + ".part")
    part.write_bytes(data)
    os.replace(part, path)


def _ray_trials(kind: str, out: Path, plan: dict, resume: bool) -> None:
    try:
        import ray
    except ImportError as e:  # pragma: no cover - depends on the optional extra
        raise ImportError("backend='ray' needs Ray: pip install './python[ray]'") from e
    if not ray.is_initialized():
        raise RuntimeError("backend='ray' needs a Ray cluster: call ray.init(...) first")
    trials_dir = out / "trials"
    trials_dir.mkdir(parents=True, exist_ok=True)
    remote = ray.remote(num_cpus=1, max_retries=0)(_trial_files)
    pending = {}
    for i in range(plan["trials"]):
        json_path, mcap_path = trials_dir / f"{i:04}.json", trials_dir / f"{i:04}.mcap"
        if resume and json_path.is_file() and mcap_path.is_file():
            continue
        json_path.unlink(missing_ok=True)
        pending[remote.remote(kind, i, plan)] = i
    while pending:
        done, _ = ray.wait(list(pending), num_returns=1)
        for ref in done:
            i = pending.pop(ref)
            result, mcap = ray.get(ref)
            _write_atomic(trials_dir / f"{i:04}.mcap", mcap)
            _write_atomic(trials_dir / f"{i:04}.json", result)
