"""Benchmarks from Python: agrisim.bench.run runs every benchmark the CLI offers, by name
through the same registry (same files), and the same trials spread over Ray tasks on a local
Ray cluster (started here on loopback, shut down at the end) give the same trials.jsonl and
byte-identical trial MCAPs as a serial run. Only wall-clock figures (wall_time, rtf) may
differ."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import agrisim
from conftest import REPO, run_agrisim
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


def assert_same_trials(a: Path, b: Path, n: int = TRIALS) -> None:
    assert trials(a) == trials(b)
    assert len(trials(a)) == n
    for i in range(n):
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


def test_names_are_the_cli_benchmarks():
    """One registry: the names Python runs are the subcommands `agrisim bench --help` lists
    (`overhead`, not a many-trial benchmark, and clap's `help` aside), in its order."""
    text = run_agrisim("bench", "--help").stdout
    commands = text.split("Commands:")[1].split("\n\n")[0]
    listed = [line.split()[0] for line in commands.splitlines() if line.strip()]
    assert listed[:3] == ["nav", "harvest", "row"], text
    assert agrisim.bench.names() == [n for n in listed if n not in ("overhead", "help")]
    row = {b.name: b for b in agrisim.bench.benchmarks()}["row"]
    assert (row.default_scenario, row.options) == ("harvest_sight", {"length": 2.0})


def test_row_runs_by_name_with_its_option(tmp_path):
    """`agrisim.bench.run("row", length=...)` is `agrisim bench row --length ...`: the option
    reaches the trials in this process and in worker processes alike."""
    scenario = REPO / "models/scenarios/harvest.toml"
    cli = tmp_path / "cli"
    run_agrisim("bench", "row", "--scenario", str(scenario), "--trials", "2", "--seed", "2", "--length", "0.3", "--record", "judge", "--out", str(cli))
    for jobs in (0, 2):
        out = tmp_path / f"py-{jobs}"
        result = agrisim.bench.run("row", out, scenario=scenario, trials=2, seed=2, record="judge", jobs=jobs, length=0.3)
        assert (result.summary["segments"], result.summary["segment_length"]) == (2, 0.3)
        assert all(t["x_range"][1] - t["x_range"][0] == pytest.approx(0.3) for t in result.trials)
        assert_same_trials(cli, out, 2)
    with pytest.raises(agrisim.AgrisimError, match="row has no option --width"):
        agrisim.bench.run("row", tmp_path / "bad", trials=1, width=1.0)
    with pytest.raises(agrisim.AgrisimError, match="unknown benchmark 'dice' \\(known: nav, harvest, row, perception\\)"):
        agrisim.bench.run("dice", tmp_path / "bad")


def test_version_is_the_crates():
    import tomllib
    from importlib.metadata import version

    cargo = tomllib.loads((REPO / "Cargo.toml").read_text())
    assert agrisim.__version__ == cargo["workspace"]["package"]["version"]
    assert version("agrisim") == agrisim.__version__
