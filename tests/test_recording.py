"""Interrupt-safe, right-sized recording and resumable benchmarks, end to end through the CLI.

- Ctrl-C (SIGINT) on a long run: exit status 130, run.mcap complete (summary and index), the
  interruption recorded on /agrisim/status; no temporary file left.
- SIGKILL: the file stays under its temporary name (run.mcap.part) and a streaming reader
  salvages the messages of every chunk written.
- A benchmark interrupted in trial 1 writes summary.json and trials.jsonl for trial 0 and
  marks trial 1; `--resume` then runs trials 1 and 2 only and sums up exactly as an
  uninterrupted benchmark (wall-clock fields aside).
- Recording profiles change what is recorded, never the verdict.
"""

from __future__ import annotations

import json
import signal
import subprocess
import time
from pathlib import Path

from mcap.exceptions import McapError
from mcap.reader import make_reader
from mcap.stream_reader import StreamReader
from mcap.records import Message

from agrisim_fmpy import REPO, agrisim_bin, run_agrisim

WALL_FIELDS = {"wall_time", "rtf"}


def start(*args: str) -> subprocess.Popen:
    return subprocess.Popen([str(agrisim_bin()), *args], cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def wait_for(path: Path, timeout: float = 120.0) -> None:
    t0 = time.monotonic()
    while not path.exists():
        assert time.monotonic() - t0 < timeout, f"{path} did not appear within {timeout} s"
        time.sleep(0.05)


def topics(mcap: Path) -> dict[str, int]:
    counts: dict[str, int] = {}
    with mcap.open("rb") as f:
        for _, ch, _ in make_reader(f).iter_messages():
            counts[ch.topic] = counts.get(ch.topic, 0) + 1
    return counts


def test_sigint_finishes_the_mcap(tmp_path):
    out = tmp_path / "run"
    p = start("run", "--duration", "900", "--out", str(out))
    try:
        wait_for(out / "run.mcap.part")
        time.sleep(1.5)
        p.send_signal(signal.SIGINT)
        _, err = p.communicate(timeout=120)
    finally:
        p.kill()
    assert p.returncode == 130, err
    assert "interrupted at t=" in err
    assert not (out / "run.mcap.part").exists()
    with (out / "run.mcap").open("rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        assert summary is not None and summary.statistics.message_count > 100
        status = [m for _, _, m in reader.iter_messages(topics=["/agrisim/status"])]
    assert len(status) == 1 and b"interrupted" in status[0].data


def test_sigkill_leaves_a_salvageable_part_file(tmp_path):
    out = tmp_path / "run"
    p = start("run", "--duration", "900", "--out", str(out))
    try:
        part = out / "run.mcap.part"
        wait_for(part)
        # Wait until a few chunks are on disk.
        t0 = time.monotonic()
        while part.stat().st_size < 8_000_000 and time.monotonic() - t0 < 60:
            time.sleep(0.1)
        p.send_signal(signal.SIGKILL)
        p.communicate(timeout=60)
    finally:
        p.kill()
    assert not (out / "run.mcap").exists(), "an incomplete file never takes the final name"
    salvaged = 0
    with part.open("rb") as f:
        try:
            for record in StreamReader(f).records:
                if isinstance(record, Message):
                    salvaged += 1
        except (McapError, EOFError, ValueError):
            pass  # the torn end of the file
    assert salvaged > 1000, f"only {salvaged} messages salvaged"


def summary_without_wall(path: Path) -> dict:
    d = json.loads(path.read_text())
    return {k: v for k, v in d.items() if k not in WALL_FIELDS}


def trials_without_wall(path: Path) -> list[dict]:
    return [{k: v for k, v in json.loads(l).items() if k != "wall_time"} for l in path.read_text().splitlines()]


def test_interrupted_benchmark_resumes_to_the_same_summary(tmp_path):
    args = ["bench", "nav", "--trials", "3", "--seed", "5", "--record", "none"]
    run_agrisim(*args, "--out", str(tmp_path / "whole"))
    cut = tmp_path / "cut"
    p = start(*args, "--out", str(cut))
    try:
        wait_for(cut / "trials" / "0000.json")
        p.send_signal(signal.SIGINT)
        _, err = p.communicate(timeout=300)
    finally:
        p.kill()
    assert p.returncode == 130, err
    s = json.loads((cut / "summary.json").read_text())
    assert s["trials"] == 1 and s["interrupted_at_trial"] == 1
    lines = [json.loads(l) for l in (cut / "trials.jsonl").read_text().splitlines()]
    assert [l["outcome"] for l in lines][1] == "interrupted" and len(lines) == 2
    assert not (cut / "trials" / "0001.json").exists()

    r = run_agrisim(*args, "--resume", "--out", str(cut))
    assert summary_without_wall(cut / "summary.json") == summary_without_wall(tmp_path / "whole" / "summary.json")
    assert trials_without_wall(cut / "trials.jsonl") == trials_without_wall(tmp_path / "whole" / "trials.jsonl")
    assert json.loads(r.stdout)["trials"] == 3


def test_profiles_change_the_recording_not_the_verdict(tmp_path):
    verdicts, sizes, seen = {}, {}, {}
    for profile in ("full", "standard", "judge", "none"):
        out = tmp_path / profile
        run_agrisim("bench", "nav", "--trials", "1", "--seed", "2", "--record", profile, "--out", str(out))
        verdicts[profile] = trials_without_wall(out / "trials.jsonl")
        mcap = out / "trials" / "0000.mcap"
        sizes[profile] = mcap.stat().st_size
        seen[profile] = topics(mcap)
    assert all(v == verdicts["full"] for v in verdicts.values())
    assert sizes["full"] > 5 * sizes["standard"] > 5 * sizes["none"]
    assert seen["none"] == {}
    assert set(seen["judge"]) <= {"/navigate/status", "/collision", "/agrisim/status", "/fmu/world/signals", "/fmu/chassis/signals"}
    # standard: every command and pose message, the point clouds at 1 Hz, the fruit list once.
    assert seen["standard"]["/cmd_vel"] == seen["full"]["/cmd_vel"] and seen["standard"]["/odom"] == seen["full"]["/odom"]
    assert seen["standard"]["/points"] <= seen["full"]["/points"] // 10 + 1
    assert seen["standard"]["/fruits"] == 1


def test_a_trial_whose_process_dies_is_an_error_and_the_benchmark_goes_on(tmp_path):
    """Trials run in worker processes: an abort in one (here SIGABRT sent to the worker, as a
    foreign FMU's failed C assertion raises) is that trial's error outcome. (An external
    SIGSEGV would not do: Rust's stack-overflow handler ignores a SIGSEGV that is not a fault.)"""
    out = tmp_path / "bench"
    p = start("bench", "nav", "--trials", "3", "--seed", "5", "--record", "none", "--jobs", "1", "--out", str(out))
    try:
        wait_for(out / "trials" / "0001.mcap.part")
        worker = subprocess.run(["pgrep", "-f", "--", f"--out {out} --worker-trial 1"], capture_output=True, text=True).stdout.split()
        assert len(worker) == 1, worker
        subprocess.run(["kill", "-ABRT", worker[0]], check=True)
        stdout, err = p.communicate(timeout=300)
    finally:
        p.kill()
    assert p.returncode == 0, err
    trials = [json.loads(l) for l in (out / "trials.jsonl").read_text().splitlines()]
    assert [t["trial"] for t in trials] == [0, 1, 2]
    assert trials[1]["outcome"] == "failure" and "signal 6 (SIGABRT)" in trials[1]["reason"], trials[1]
    assert trials[2]["sim_time"] > 0, "the benchmark went on after the crash"
    assert json.loads(stdout)["trials"] == 3
