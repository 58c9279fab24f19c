"""`agrisim bench harvest` end to end on the default greenhouse with a few trials: the files
it promises, the statistics recomputed independently, report.html against them, the stages
reported on /harvest/status, and every trial's MCAP decoding with mcap-ros2-support
(JointTrajectory, JointState, GripperCommand, PlanningScene, HarvestStatus)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from conftest import REPO, run_agrisim, wilson
from scenario_variant import write_variant

SCENARIO = REPO / "models" / "scenarios" / "harvest.toml"
TRIALS = 3
STAGES = ["select_target", "position_base", "pre_grasp", "approach", "grasp", "retreat",
          "handover_pose", "handover", "transfer", "release"]


@pytest.fixture(scope="module")
def free_scenario(tmp_path_factory) -> Path:
    # Targets in plain view (the paper's kind): these checks need harvests that get through
    # every stage. The benchmark's default draws hidden fruit too (test_scenes... below).
    return write_variant(SCENARIO, tmp_path_factory.mktemp("scenario"), '[harvest]\nvisibility = ["free"]\n')


@pytest.fixture(scope="module")
def bench(tmp_path_factory, free_scenario) -> Path:
    out = tmp_path_factory.mktemp("harvest")
    run_agrisim("bench", "harvest", "--scenario", str(free_scenario), "--trials", str(TRIALS), "--seed", "3", "--out", str(out))
    return out


def trials(bench: Path) -> list[dict]:
    return [json.loads(l) for l in (bench / "trials.jsonl").read_text().splitlines()]


def test_files_and_summary(bench):
    ts = trials(bench)
    assert [t["trial"] for t in ts] == list(range(TRIALS))
    for t in ts:
        assert t["outcome"] in ("success", "failure")
        assert (t["failure"] is None) == (t["outcome"] == "success")
        assert t["failure"] in (None, "planning", "grasp", "handover", "placement", "timeout", "collision", "damage", "error")
        assert (bench / t["mcap"]).exists()
        assert len(t["planning_times"]) == t["plans"]
    s = json.loads((bench / "summary.json").read_text())
    k = sum(t["outcome"] == "success" for t in ts)
    assert all(t["planning"] in ("ok", "failed", "not_reached") and t["planning_ok"] == (t["planning"] == "ok") for t in ts)
    p = sum(t["planning_ok"] for t in ts)
    decided = sum(t["planning"] != "not_reached" for t in ts)
    kp = sum(t["planning_ok"] and t["outcome"] == "success" for t in ts)
    assert s["trials"] == TRIALS and s["successes"] == k and s["planning_successes"] == p and s["planning_decided"] == decided
    for key, (a, b) in (("wilson95", (k, TRIALS)), ("planning_wilson95", (p, decided)), ("conditional_wilson95", (kp, p))):
        lo, hi = wilson(a, b)
        assert abs(s[key][0] - lo) < 1e-12 and abs(s[key][1] - hi) < 1e-12, key
    assert sum(s["failures"].values()) == TRIALS - k
    # Crop damage (/plant_damage ground truth): totals by kind are the trials' sums; a bruise
    # (grip or impact: IMPACT_BRUISE_FAILS in the bench) or a broken stem is a "damage"
    # failure unless the trial failed before.
    for kind in ("bruised_by_grip", "bruised_by_impact", "unripe_detached", "stems_broken"):
        assert s["damage"][kind] == sum(t["damage"].get(kind, 0) for t in ts), kind
    for t in ts:
        bruised = t["damage"].get("bruised_by_grip", 0) + t["damage"].get("bruised_by_impact", 0)
        assert not (t["outcome"] == "success" and (bruised or t["damage"].get("stems_broken", 0)))
        assert (t["detach_mode"] is None) == (t["detach_force"] is None)
        assert t["detach_mode"] in (None, "pull", "bend", "twist")
    modes = [t["detach_mode"] for t in ts if t["detach_mode"]]
    assert s["detach_modes"] == {m: modes.count(m) for m in set(modes)}
    forces = [t["detach_force"] for t in ts if t["detach_force"] is not None]
    assert (s["detach_force_mean"] is None) == (not forces)
    if forces:
        assert abs(s["detach_force_mean"] - sum(forces) / len(forces)) < 1e-9
    times = sorted(x for t in ts for x in t["planning_times"])
    assert s["plans"] == len(times)
    if times:
        assert s["planning_time_max"] == times[-1]
        assert times[0] <= s["planning_time_p50"] <= s["planning_time_p95"] <= times[-1]


# A rate table's row in report.html: key, count, successes, fraction, Wilson interval.
RATE_ROW = re.compile(r"<tr><td>([^<]*)</td><td>(\d+)</td><td>(\d+)</td><td>([\d.]+)</td><td>\[([\d.]+), ([\d.]+)\]</td></tr>")


def rate_rows(html: str) -> dict[str, tuple[int, int, float, float, float]]:
    return {k: (int(n), int(ok), float(f), float(lo), float(hi)) for k, n, ok, f, lo, hi in RATE_ROW.findall(html)}


def test_report_shows_the_summary_classes_failures_times_and_paths(bench):
    ts = trials(bench)
    s = json.loads((bench / "summary.json").read_text())
    html = (bench / "report.html").read_text()
    summary = dict(re.findall(r"<tr><th>([^<]*)</th><td>([^<]*)</td></tr>", html))
    assert summary["harvested"] == f"{s['successes']} / {TRIALS} = {s['success_rate']:.3f}"
    assert summary["planning (of decided trials)"].startswith(f"{s['planning_successes']} / {s['planning_decided']} = ")
    for key, label in (("wilson95", "harvest Wilson 95 %"), ("planning_wilson95", "planning Wilson 95 %"),
                       ("cluster_bootstrap95", "harvest cluster bootstrap 95 % (over scenes)")):
        lo, hi = map(float, summary[label].strip("[]").split(", "))
        assert abs(lo - s[key][0]) < 6e-4 and abs(hi - s[key][1]) < 6e-4, label
    # The tasks within the hand (a ripe fruit no wider than it opens, from ground truth):
    # the page's row is the summary's, and they are among the trials and successes.
    w = s["within_hand"]
    row = summary["harvested, of the tasks within the hand (a ripe fruit no wider than it opens)"]
    assert row.startswith(f"{w['successes']} / {w['trials']}, Wilson 95 % ["), row
    assert w["trials"] <= TRIALS and w["successes"] <= s["successes"]
    assert w["successes"] >= s["successes"] - (TRIALS - w["trials"])
    # Figures the seed determines only: no wall-clock figure on the page.
    assert "real-time" not in html
    # One row per visibility class, as the summary has it.
    rows = rate_rows(html)
    for k, c in s["per_visibility"].items():
        n, ok, frac, lo, hi = rows[k]
        assert (n, ok) == (c["trials"], c["successes"]) and abs(frac - ok / n) < 6e-4, k
        assert abs(lo - c["wilson95"][0]) < 6e-4 and abs(hi - c["wilson95"][1]) < 6e-4, k
    assert sum(rows[k][0] for k in s["per_visibility"]) == TRIALS
    # The failure taxonomy: every category of the summary with its count, and no other.
    taxonomy = html.split("<h2>Failure taxonomy (trials not harvested)</h2>")[1].split("</table>")[0]
    assert dict(re.findall(r"<tr><td>([^<]*)</td><td>(\d+)</td></tr>", taxonomy)) == {k: str(v) for k, v in s["failures"].items()}
    # The histogram of the time to harvest holds every success, each in its bin.
    bins = [(int(a), int(b), int(c)) for a, b, c in re.findall(r"<title>(\d+)-(\d+): (\d+)</title>", html)]
    times = [t["time_to_harvest"] for t in ts if t["outcome"] == "success"]
    assert sum(c for _, _, c in bins) == len(times)
    for a, b, c in bins:
        assert c == sum(a <= x < b for x in times), (a, b, times)
    # One ground-truth base path per trial, from its start pose, coloured by its outcome,
    # and its target fruit; the failures listed with their category.
    paths = re.findall(r'<polyline points="([^"]*)" fill="none" stroke="([^"]*)"[^>]*><title>trial (\d+) ([^<]*)</title>', html)
    assert [int(i) for _, _, i, _ in paths] == list(range(TRIALS))
    for (points, colour, _, _), t in zip(paths, ts):
        path = json.loads((bench / "trials" / f"{t['trial']:04}.json").read_text())["path"]
        assert "path" not in t and len(path) >= 2 and len(points.split()) == len(path)
        assert abs(path[0][0] - t["start"][0]) < 1e-9 and abs(path[0][1] - t["start"][1]) < 1e-9
        assert colour == ("#1a7f37" if t["outcome"] == "success" else "#cf222e")
        assert f"<title>target of trial {t['trial']}</title>" in html
        if t["failure"]:
            assert f"<li>trial {t['trial']:04}: {t['failure']} (stage " in html
    # The pedicel force until the break: one line per trial that loaded a pedicel (first 6),
    # as many points as the trial recorded.
    loaded = [t for t in ts if t.get("pedicel_force")][:6]
    forces = re.findall(r'<polyline points="([^"]*)"[^>]*><title>pedicel force of trial (\d+) ', html)
    assert [int(i) for _, i in forces] == [t["trial"] for t in loaded]
    for (points, _), t in zip(forces, loaded):
        assert len(points.split()) == len(t["pedicel_force"])


def test_successful_harvests_place_the_fruit_by_ground_truth(bench):
    # The robot localizes from a seeded wrong start and a map without the trial's plants, so
    # a trial may miss its fruit (about 1 in 5 on the benchmark); the judge says why.
    ts = trials(bench)
    ok = [t for t in ts if t["outcome"] == "success"]
    assert ok, [(t["failure"], t["failed_stage"], t["detail"]) for t in ts]
    for t in ok:
        assert t["placed_count"] == 1
        assert t["contacts"]["contact_robot_structure"] == 0 and t["contacts"]["contact_arm_arm"] == 0
        assert t["contacts"]["contact_carried_structure"] == 0
        assert 0 < t["tracking_rms"][0] < 0.05 and 0 < t["tracking_rms"][1] < 0.05
    for t in ts:
        if t["outcome"] != "success":
            assert t["placed_count"] == 0 and t["failed_stage"] and t["detail"], t


def test_trial_mcap_decodes_and_reports_every_stage(bench):
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    t = trials(bench)[0]
    stages, types = [], set()
    with open(bench / t["mcap"], "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for schema, channel, message, decoded in reader.iter_decoded_messages():
            types.add(schema.name)
            if channel.topic == "/harvest/status" and decoded.outcome == "running":
                stages.append(decoded.stage)
            if channel.topic == "/left_arm/joint_trajectory" or channel.topic == "/right_arm/joint_trajectory":
                assert len(decoded.joint_names) == 7 and decoded.points
                for a, b in zip(decoded.points, decoded.points[1:]):
                    ta = a.time_from_start.sec + 1e-9 * a.time_from_start.nanosec
                    tb = b.time_from_start.sec + 1e-9 * b.time_from_start.nanosec
                    assert tb > ta
    assert {"trajectory_msgs/msg/JointTrajectory", "sensor_msgs/msg/JointState", "control_msgs/msg/GripperCommand",
            "agrisim_msgs/msg/PlanningScene", "agrisim_msgs/msg/HarvestStatus", "agrisim_msgs/msg/GripperState",
            "agrisim_msgs/msg/TrajectoryStatus"} <= types
    if t["outcome"] == "success":
        assert [s for s in STAGES if s in stages] == STAGES, stages


def test_planning_time_is_charged_in_simulated_time(bench):
    # Every plan reports the simulated time it took; each trajectory starts no earlier than
    # the step that planned it plus that time (header.stamp after the publication time).
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    t = trials(bench)[0]
    charged, delays = [], []
    with open(bench / t["mcap"], "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for _, channel, message, d in reader.iter_decoded_messages(topics=["/harvest/plans", "/left_arm/joint_trajectory", "/right_arm/joint_trajectory"]):
            if channel.topic == "/harvest/plans":
                charged.append(d.planning_time)
            else:
                delays.append(d.header.stamp.sec + 1e-9 * d.header.stamp.nanosec - message.publish_time * 1e-9)
    assert charged and all(c > 0 for c in charged), charged
    assert abs(sum(charged) - t["thinking_time"]) < 1e-9
    assert delays and all(d > 0 for d in delays), delays
    assert max(delays) <= sum(charged) + 1e-6


def test_same_seed_gives_byte_identical_trial(bench, free_scenario, tmp_path):
    again = tmp_path / "again"
    run_agrisim("bench", "harvest", "--scenario", str(free_scenario), "--trials", "1", "--seed", "3", "--out", str(again))
    first = trials(bench)[0]
    assert (again / "trials" / "0000.mcap").read_bytes() == (bench / first["mcap"]).read_bytes()


def test_scenes_spread_the_trials_and_every_fmu_grows_the_trial_scene(tmp_path):
    out = tmp_path / "scenes"
    run_agrisim("bench", "harvest", "--scenario", str(SCENARIO), "--trials", "2", "--scenes", "2", "--seed", "3",
                "--record", "standard", "--out", str(out))
    ts = trials(out)
    assert [t["scene"] for t in ts] == [0, 1]
    s = json.loads((out / "summary.json").read_text())
    assert s["scenes"] == 2 and [p["trials"] for p in s["per_scene"]] == [1, 1]
    assert [p["scene_seed"] for p in s["per_scene"]] == [1, 2]  # harvest.toml: seed 1, no [greenhouse] seed
    assert [p["successes"] for p in s["per_scene"]] == [int(t["outcome"] == "success") for t in ts]
    rates = [p["successes"] / p["trials"] for p in s["per_scene"]]
    lo, hi = s["cluster_bootstrap95"]
    assert min(rates) <= lo <= hi <= max(rates)
    assert s["distinct_targets"] == 2
    # The world FMU publishes the target from the scene it grew itself; it must be where the
    # orchestrator's copy of the trial's scene puts that fruit (scene 1 is not scene 0).
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory
    for t in ts:
        with open(out / t["mcap"], "rb") as f:
            reader = make_reader(f, decoder_factories=[DecoderFactory()])
            pose = next(d.pose.position for _, _, _, d in reader.iter_decoded_messages(topics=["/target_fruit"]))
        assert max(abs(a - b) for a, b in zip((pose.x, pose.y, pose.z), t["fruit"])) < 1e-6, (t["scene"], pose, t["fruit"])
    assert ts[0]["fruit"] != ts[1]["fruit"]
    # report.html: a row per scene, as the summary counts them.
    rows = rate_rows((out / "report.html").read_text())
    for p in s["per_scene"]:
        assert rows[f"{p['scene']} (greenhouse seed {p['scene_seed']})"][:2] == (p["trials"], p["successes"])


def test_an_unknown_visibility_class_is_refused_by_name(tmp_path):
    bad = write_variant(SCENARIO, tmp_path, '[harvest]\nvisibility = ["free", "hidden"]\n')
    p = run_agrisim("bench", "harvest", "--scenario", str(bad), "--trials", "1", "--out", str(tmp_path / "out"), check=False)
    assert p.returncode != 0
    assert "[harvest] visibility" in p.stderr and '"hidden"' in p.stderr and str(bad) in p.stderr, p.stderr
