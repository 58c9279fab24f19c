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

import hashlib
import json
import os
import random
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


def interrupt_at(args: list[str], out: Path, watch: Path, delay: float) -> str:
    """Starts agrisim, waits for `watch` to appear, then `delay` s, sends SIGINT; returns stderr."""
    p = start(*args, "--out", str(out))
    try:
        wait_for(watch)
        time.sleep(delay)
        p.send_signal(signal.SIGINT)
        _, err = p.communicate(timeout=300)
    finally:
        p.kill()
    assert p.returncode == 130, err
    return err


def readable_to_the_end(mcap: Path) -> int:
    with mcap.open("rb") as f:
        reader = make_reader(f)
        assert reader.get_summary() is not None, f"{mcap}: no summary"
        n = sum(1 for _ in reader.iter_messages())
    assert n == reader.get_summary().statistics.message_count
    return n


def test_sigint_at_twenty_seeded_moments(tmp_path):
    """12 runs and 8 benchmarks interrupted at seeded random moments: every MCAP readable to
    its last message with a summary, no temporary file left, completed trials intact and
    summary.json written."""
    rng = random.Random(20261124)
    for k in range(12):
        out = tmp_path / f"run{k}"
        interrupt_at(["run", "--duration", "900", "--record", "standard"], out, out / "run.mcap.part", rng.uniform(0.0, 2.0))
        assert readable_to_the_end(out / "run.mcap") > 0
        assert not list(out.glob("*.part"))
    for k in range(8):
        out = tmp_path / f"bench{k}"
        # Enough trials that no seeded moment comes after the last one: with 4, a clean-clone
        # CI run finished the benchmark before its moment (exit 0, not 130).
        interrupt_at(["bench", "nav", "--trials", "40", "--seed", str(k), "--record", "judge", "--jobs", "2"], out, out / "trials", rng.uniform(0.5, 6.0))
        s = json.loads((out / "summary.json").read_text())
        assert s["trials"] == s["interrupted_at_trial"]
        for i in range(s["trials"]):
            assert (out / "trials" / f"{i:04}.json").is_file()
            readable_to_the_end(out / "trials" / f"{i:04}.mcap")
        for m in (out / "trials").glob("*.mcap"):
            readable_to_the_end(m)
        assert not list((out / "trials").glob("*.part")), "workers finish their files too"


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


def outputs(out: Path) -> tuple[list[dict], dict[str, str]]:
    mcaps = {m.name: hashlib.sha256(m.read_bytes()).hexdigest() for m in sorted((out / "trials").glob("*.mcap"))}
    return trials_without_wall(out / "trials.jsonl"), mcaps


def test_sigkill_then_resume_gives_the_uninterrupted_outputs(tmp_path):
    """A benchmark killed outright (SIGKILL to its process group: the machine dies) leaves
    every completed trial's files whole; --resume finishes with trials.jsonl, summary and
    every MCAP identical to an uninterrupted run's."""
    # One trial at a time (--jobs defaults to the core count), so trial 1 under way means
    # trial 0 is complete.
    args = ["bench", "nav", "--trials", "3", "--seed", "6", "--record", "judge", "--jobs", "1"]
    run_agrisim(*args, "--out", str(tmp_path / "whole"))
    cut = tmp_path / "cut"
    p = subprocess.Popen([str(agrisim_bin()), *args, "--out", str(cut)], cwd=REPO, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    try:
        wait_for(cut / "trials" / "0001.mcap.part")
        os.killpg(p.pid, signal.SIGKILL)
        p.wait(timeout=60)
    finally:
        p.kill()
    assert (cut / "trials" / "0000.json").is_file() and not (cut / "trials" / "0001.json").exists()
    readable_to_the_end(cut / "trials" / "0000.mcap")
    run_agrisim(*args, "--resume", "--out", str(cut))
    assert outputs(cut) == outputs(tmp_path / "whole")
    assert summary_without_wall(cut / "summary.json") == summary_without_wall(tmp_path / "whole" / "summary.json")


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
    # standard: every command and pose message, the point clouds every 5 s, the fruit list once.
    assert seen["standard"]["/cmd_vel"] == seen["full"]["/cmd_vel"] and seen["standard"]["/odom"] == seen["full"]["/odom"]
    assert seen["standard"]["/imu"] <= seen["full"]["/imu"] // 4 + 1
    assert seen["standard"]["/points"] <= seen["full"]["/points"] // 50 + 1
    assert sizes["standard"] <= 5_000_000, sizes
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
