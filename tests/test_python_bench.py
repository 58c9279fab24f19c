"""Benchmarks from Python: agrisim.bench.nav runs the CLI's benchmark (same files), and the
same trials spread over Ray tasks on a local Ray cluster (started here on loopback, shut
down at the end) give the same trials.jsonl and byte-identical trial MCAPs as a serial run.
Only wall-clock figures (wall_time, rtf) may differ."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import agrisim
from conftest import run_agrisim
from scenario_variant import write_variant

TRIALS = 8
SEED = 21
WALL = {"wall_time", "rtf"}


@pytest.fixture(scope="module")
def short_nav(tmp_path_factory) -> Path:
    """The default scenario with 6 s trials: most time out, which is as deterministic a
    verdict as any and keeps 8 trials to seconds."""
    d = tmp_path_factory.mktemp("short-nav")
    path = write_variant(agrisim.root() / "models/scenarios/default.toml", d, "")
    text = path.read_text()
    assert "trial_timeout = 120.0" in text
    path.write_text(text.replace("trial_timeout = 120.0", "trial_timeout = 6.0"))
    return path


@pytest.fixture(scope="module")
def serial(short_nav, tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("serial")
    run_agrisim("bench", "nav", "--scenario", str(short_nav), "--trials", str(TRIALS), "--seed", str(SEED), "--record", "judge", "--in-process", "--out", str(out))
    return out


def trials(out: Path) -> list[dict]:
    return [{k: v for k, v in json.loads(line).items() if k not in WALL} for line in (out / "trials.jsonl").read_text().splitlines()]


def assert_same_trials(a: Path, b: Path) -> None:
    assert trials(a) == trials(b)
    for i in range(TRIALS):
        assert (a / f"trials/{i:04}.mcap").read_bytes() == (b / f"trials/{i:04}.mcap").read_bytes(), f"trial {i}"
    sa, sb = (json.loads((p / "summary.json").read_text()) for p in (a, b))
    assert {k: v for k, v in sa.items() if k not in WALL} == {k: v for k, v in sb.items() if k not in WALL}


def test_python_bench_is_the_cli_benchmark(short_nav, serial, tmp_path):
    result = agrisim.bench.nav(tmp_path, scenario=short_nav, trials=TRIALS, seed=SEED, record="judge")
    assert result.summary["trials"] == TRIALS
    assert [t["trial"] for t in result.trials] == list(range(TRIALS))
    assert result.summary["successes"] == sum(t["outcome"] == "success" for t in result.trials)
    assert_same_trials(serial, tmp_path)


def test_ray_trials_equal_the_serial_run(short_nav, serial, tmp_path):
    ray = pytest.importorskip("ray", reason="Ray is the optional extra agrisim[ray]; scripts/setup installs it")
    ray.init(num_cpus=2, include_dashboard=False, _node_ip_address="127.0.0.1", log_to_driver=False, configure_logging=False)
    try:
        result = agrisim.bench.nav(tmp_path, scenario=short_nav, trials=TRIALS, seed=SEED, record="judge", backend="ray")
    finally:
        ray.shutdown()
    assert len(result.trials) == TRIALS
    assert_same_trials(serial, tmp_path)


def test_single_trial_then_resume(short_nav, serial, tmp_path):
    """Trials run one at a time anywhere (what a Ray task does), summed up by a resumed run."""
    for i in reversed(range(TRIALS)):
        agrisim.bench.run_trial("nav", tmp_path, i, scenario=short_nav, trials=TRIALS, seed=SEED, record="judge")
    agrisim.bench.nav(tmp_path, scenario=short_nav, trials=TRIALS, seed=SEED, record="judge", resume=True)
    assert_same_trials(serial, tmp_path)
    with pytest.raises(agrisim.AgrisimError, match="trial 8 is not among the 8 trials"):
        agrisim.bench.run_trial("nav", tmp_path, TRIALS, scenario=short_nav, trials=TRIALS, seed=SEED)
