"""Bad input gives a clear error naming the file, FMU and variable, and whatever MCAP was
written so far is finished and readable (checked with the mcap reader and mcap-ros2-support).
A bad message during a run is refused with a warning and the run goes on."""

from __future__ import annotations

import shutil
import struct
from pathlib import Path

import pytest
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

from conftest import FMU_DIR, REPO, run_agrisim

SSD = REPO / "models" / "systems" / "base.ssd"
SCENARIO = REPO / "models" / "scenarios" / "base.toml"


def scenario_with(tmp: Path, ssd: Path = SSD, extra: str = "") -> Path:
    text = SCENARIO.read_text().replace('file = "../systems/base.ssd"', f'file = "{ssd}"')
    p = tmp / "scenario.toml"
    p.write_text(text + extra)
    return p


def failing_run(*args: str) -> str:
    p = run_agrisim("run", *args, check=False)
    assert p.returncode != 0, "expected failure"
    assert "panicked" not in p.stderr, p.stderr
    return p.stderr


def test_corrupt_fmu_names_file_and_component(tmp_path, fmu_dir):
    bad = tmp_path / "fmus"
    shutil.copytree(FMU_DIR, bad)
    (bad / "ChassisKinematic.fmu").write_bytes(b"PK\x03\x04 this is not a zip archive")
    err = failing_run("--scenario", str(SCENARIO), "--fmu-dir", str(bad), "--cache-dir", str(tmp_path / "cache"), "--out", str(tmp_path / "out"))
    assert "ChassisKinematic.fmu" in err and "chassis" in err, err


def test_missing_fmu_file(tmp_path, fmu_dir):
    err = failing_run("--scenario", str(SCENARIO), "--fmu", "chassis=NoSuchChassis.fmu", "--out", str(tmp_path / "out"))
    assert "NoSuchChassis.fmu" in err and "chassis" in err, err


def test_ssp_naming_missing_variable(tmp_path, fmu_dir):
    ssd = tmp_path / "system.ssd"
    ssd.write_text(SSD.read_text().replace('endConnector="payload_mass"', 'endConnector="payload_mas"').replace('name="payload_mass" kind="input"', 'name="payload_mas" kind="input"'))
    err = failing_run("--scenario", str(scenario_with(tmp_path, ssd)), "--out", str(tmp_path / "out"))
    assert "payload_mas" in err and "chassis" in err and "system.ssd" in err, err


def test_type_mismatched_connection(tmp_path, fmu_dir):
    ssd = tmp_path / "system.ssd"
    text = SSD.read_text().replace(
        '<ssd:Connection startElement="lift" startConnector="payload_mass" endElement="chassis" endConnector="payload_mass"/>',
        '<ssd:Connection startElement="lift" startConnector="payload_mass" endElement="chassis" endConnector="cmd_vel"/>',
    ).replace('<ssd:Connection startConnector="cmd_vel" endElement="chassis" endConnector="cmd_vel"/>', "")
    ssd.write_text(text)
    err = failing_run("--scenario", str(scenario_with(tmp_path, ssd)), "--out", str(tmp_path / "out"))
    assert "payload_mass" in err and "cmd_vel" in err and "lift" in err and "chassis" in err, err


def test_unknown_scenario_parameter(tmp_path, fmu_dir):
    sc = tmp_path / "s.toml"
    sc.write_text(SCENARIO.read_text().replace('file = "../systems/base.ssd"', f'file = "{SSD}"').replace("enc_noise = 0.05", "enc_noize = 0.05"))
    err = failing_run("--scenario", str(sc), "--out", str(tmp_path / "out"))
    assert "enc_noize" in err and "chassis" in err, err


def read_topics(path: Path) -> dict[str, list]:
    topics: dict[str, list] = {}
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        assert reader.get_summary() is not None, "MCAP has no summary: not finished"
        for schema, channel, message in reader.iter_messages():
            topics.setdefault(channel.topic, []).append(message)
    return topics


def decode_all(path: Path, topic: str) -> list:
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        return [m for _, ch, _, m in reader.iter_decoded_messages(topics=[topic])]


def refused_run(tmp_path, extra: str, t_ns: int):
    """A run with a bad /cmd_vel message goes on to its end: the chassis refuses the message
    with a warning naming the port and the time, the last valid command stays in force, and
    the warning is in the log."""
    out = tmp_path / "out"
    p = run_agrisim("run", "--scenario", str(scenario_with(tmp_path, extra=extra)), "--duration", "4", "--out", str(out), check=False)
    assert p.returncode == 0 and "panicked" not in p.stderr, p.stderr
    assert "warning:" in p.stderr and "chassis" in p.stderr and "cmd_vel" in p.stderr and "refused" in p.stderr, p.stderr
    mcap = out / "run.mcap"
    topics = read_topics(mcap)
    assert topics["/clock"][-1].log_time == 4_000_000_000
    status = decode_all(mcap, "/agrisim/status")
    assert len(status) == 1 and status[0].status == "warning" and status[0].instance == "chassis", status
    assert "cmd_vel" in status[0].message and "refused" in status[0].message
    assert status[0].header.stamp.sec * 10**9 + status[0].header.stamp.nanosec >= t_ns
    return status[0].message, decode_all(mcap, "/fmu/chassis/signals")


@pytest.mark.parametrize("payload", ["deadbeef", "000100000000"])
def test_garbage_message_mid_run_is_refused_and_the_run_goes_on(tmp_path, fmu_dir, payload):
    extra = f'\n[[inject]]\nt = 2.0\ntopic = "/cmd_vel"\ntype = "geometry_msgs/msg/Twist"\nhex = "{payload}"\n'
    message, signals = refused_run(tmp_path, extra, 2_000_000_000)
    assert "t=2" in message, message
    # The base keeps the command of 2.0 s (the script publishes 0.5 m/s forward until 6 s).
    vx = [dict(zip(m.names, m.values))["vx"] for m in signals]
    assert min(vx[105:200]) > 0.4


def test_non_finite_command_is_refused(tmp_path, fmu_dir):
    nan = struct.pack("<4B6d", 0, 1, 0, 0, float("nan"), 0, 0, 0, 0, 0).hex()
    extra = f'\n[[inject]]\nt = 1.0\ntopic = "/cmd_vel"\ntype = "geometry_msgs/msg/Twist"\nhex = "{nan}"\n'
    message, _ = refused_run(tmp_path, extra, 1_000_000_000)
    assert "non-finite" in message, message


def test_invalid_parameter_value_fails_at_initialization(tmp_path, fmu_dir):
    sc = tmp_path / "s.toml"
    sc.write_text(SCENARIO.read_text().replace('file = "../systems/base.ssd"', f'file = "{SSD}"').replace("slip_std = 0.02", "slip_std = 0.02\nwheel_radius = -0.1"))
    err = failing_run("--scenario", str(sc), "--out", str(tmp_path / "out"))
    assert "wheel_radius" in err and "chassis" in err, err
