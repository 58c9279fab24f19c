"""The export layer's own test model, packed by `agrisim fmu pack`, checked by FMPy: an
analytic simulation in FMI 3 and FMI 2, the Binary echo through FMU3Slave, FMU state, and an
illegal call answered with an error instead of a crash."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import fmpy
import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.fmi3 import FMU3Slave

REPO = Path(__file__).resolve().parents[1]
FMI3 = REPO / "target" / "fmu" / "TestModel.fmu"
FMI2 = REPO / "target" / "fmu" / "fmi2" / "TestModel.fmu"
MIME = "application/x-ros2-cdr; type=std_msgs/msg/String"


@pytest.mark.parametrize("fmu", [FMI3, FMI2], ids=["fmi3", "fmi2"])
def test_decay_matches_closed_form(fmu):
    md = read_model_description(str(fmu))
    starts = {v.name: v.start for v in md.modelVariables}
    k, x0 = float(starts["k"]), float(starts["x0"])
    r = simulate_fmu(str(fmu), stop_time=2.0, output_interval=0.02, output=["x", "steps"])
    assert len(r["time"]) == 101
    err = max(abs(x - x0 * math.exp(-k * t)) for t, x in zip(r["time"], r["x"]))
    assert err < 1e-12, err
    assert int(r["steps"][-1]) == 100
    r = simulate_fmu(str(fmu), stop_time=1.0, output_interval=0.02, output=["x"], start_values={"k": 0.5, "x0": 3.0})
    assert max(abs(x - 3.0 * math.exp(-0.5 * t)) for t, x in zip(r["time"], r["x"])) < 1e-12


def test_binary_echo_state_and_illegal_call():
    md = read_model_description(str(FMI3))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    s = FMU3Slave(guid=md.guid, unzipDirectory=fmpy.extract(str(FMI3)), modelIdentifier=md.coSimulation.modelIdentifier, instanceName="echo")
    s.instantiate()
    s.enterInitializationMode(startTime=0.0)
    s.exitInitializationMode()
    msg = bytes([0, 1, 0, 0, 6, 0, 0, 0]) + b"hello\x00"  # CDR std_msgs/String "hello"
    seq0 = s.getInt64([vr["msg_seq"]])[0]
    s.setBinary([vr["msg_in"]], [msg])
    s.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.02)
    assert s.getBinary([vr["msg_out"]])[0] == msg
    seq1 = s.getInt64([vr["msg_seq"]])[0]
    assert seq1 == seq0 + 1
    s.doStep(currentCommunicationPoint=0.02, communicationStepSize=0.02)
    assert s.getInt64([vr["msg_seq"]])[0] == seq1, "unchanged message, unchanged counter"
    state = s.getFMUState()
    x = s.getFloat64([vr["x"]])[0]
    s.doStep(currentCommunicationPoint=0.04, communicationStepSize=0.02)
    assert s.getFloat64([vr["x"]])[0] != x
    s.setFMUState(state)
    assert s.getFloat64([vr["x"]])[0] == x
    s.freeFMUState(state)
    with pytest.raises(Exception):
        s.setFloat64([vr["x0"]], [2.0])  # a fixed parameter, in Step Mode
    s.reset()
    s.freeInstance()
    with zipfile.ZipFile(FMI3) as z:
        xml = ET.fromstring(z.read("modelDescription.xml"))
    assert {e.get("name"): e.get("mimeType") for e in xml.iter("Binary")} == {"msg_in": MIME, "msg_out": MIME}
