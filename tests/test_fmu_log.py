"""FMU debug logging from the CLI: off by default (a run prints nothing of the FMUs'),
`--fmu-log` turns it on for every category or the listed ones, so does the scenario's
`[logging] fmu`, and a category no FMU declares is an error that names it. The run itself
(the MCAP) is the same with logging on or off."""

from __future__ import annotations

from pathlib import Path

from conftest import REPO, run_agrisim

SCENARIO = REPO / "models" / "scenarios" / "base.toml"


def run(tmp: Path, name: str, *extra: str, scenario: Path = SCENARIO, check: bool = True):
    return run_agrisim("run", "--scenario", str(scenario), "--duration", "1", "--out", str(tmp / name), *extra, check=check)


def fmu_lines(stderr: str) -> list[str]:
    return [line for line in stderr.splitlines() if line.startswith("FMU '")]


def test_off_by_default_on_by_flag_and_category(tmp_path, fmu_dir):
    quiet = run(tmp_path, "quiet")
    assert fmu_lines(quiet.stderr) == [], quiet.stderr
    loud = run(tmp_path, "all", "--fmu-log")
    lines = fmu_lines(loud.stderr)
    assert any(line.startswith("FMU 'chassis' [logCalls]: fmi3DoStep") for line in lines), loud.stderr[:2000]
    assert any(line.startswith("FMU 'lift' ") for line in lines)
    calls = run(tmp_path, "calls", "--fmu-log", "logCalls")
    assert fmu_lines(calls.stderr) and all("[logCalls]" in line for line in fmu_lines(calls.stderr))
    # Logging changes what is printed, never what is simulated.
    assert (tmp_path / "quiet" / "run.mcap").read_bytes() == (tmp_path / "all" / "run.mcap").read_bytes()


def test_scenario_key_and_unknown_category(tmp_path, fmu_dir):
    text = SCENARIO.read_text().replace('file = "../systems/base.ssd"', f'file = "{REPO / "models" / "systems" / "base.ssd"}"')
    sc = tmp_path / "logged.toml"
    sc.write_text(text + '\n[logging]\nfmu = ["logCalls"]\n')
    p = run(tmp_path, "scenario", scenario=sc)
    assert fmu_lines(p.stderr) and all("[logCalls]" in line for line in fmu_lines(p.stderr))
    bad = run(tmp_path, "bad", "--fmu-log", "logCall", check=False)
    assert bad.returncode != 0 and "FMU log category 'logCall'" in bad.stderr and "logCalls" in bad.stderr, bad.stderr
    sc.write_text(text + "\n[logging]\nfmu = 3\n")
    bad = run(tmp_path, "bad2", scenario=sc, check=False)
    assert bad.returncode != 0 and "fmu = 3" in bad.stderr and "expected true, false" in bad.stderr, bad.stderr


def test_world_builds_its_scene_at_most_twice_while_initializing(tmp_path, fmu_dir):
    """Propagating unchanged values in Initialization Mode keeps the FMU's initialization
    preview: the world (scene + physics) was built 14 times for harvest.ssd before, once per
    read after a write; now only when an input really changed (2: the lift -> chassis ->
    world chain settles in the master's second pass)."""
    harvest = REPO / "models" / "scenarios" / "harvest.toml"
    p = run_agrisim("run", "--scenario", str(harvest), "--duration", "0.02", "--fmu-log", "logModel", "--out", str(tmp_path / "h"))
    builds = [line for line in fmu_lines(p.stderr) if line.startswith("FMU 'world' [logModel]: greenhouse:")]
    assert 1 <= len(builds) <= 2, p.stderr[:3000]
