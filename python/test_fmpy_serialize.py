"""Serialized FMU states through FMPy (an importer written elsewhere), for every packed FMU,
FMI 3 and FMI 2: a run stopped after 10 steps, its state serialized to bytes, deserialized
into a fresh instance of the FMU (which rebuilds what the parameters fix: scene, URDF) and
stepped on, gives every output bit for bit as the uninterrupted run."""

from __future__ import annotations

import math
import shutil
import tempfile

import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave

from agrisim_fmpy import fmu_path

MODELS = ["ChassisKinematic", "ChassisDynamic", "Lift", "Arm", "Imu", "Lidar", "Camera", "Greenhouse", "TestModel"]
BEFORE, AFTER = 10, 10
# A small camera image keeps the test quick; the state's content does not depend on it.
SMALL = {"Camera": {"width": 64, "height": 48}}


class Run:
    """One instance of an extracted FMU, driven step by step with moving inputs."""

    def __init__(self, md, unzipdir: str, version: int, name: str):
        self.md, self.version = md, version
        self.h = float(md.defaultExperiment.stepSize) if md.defaultExperiment and md.defaultExperiment.stepSize else 0.02
        cls = FMU3Slave if version == 3 else FMU2Slave
        ident = md.coSimulation.modelIdentifier
        token = md.instantiationToken if version == 3 else md.guid
        self.s = cls(guid=token, unzipDirectory=unzipdir, modelIdentifier=ident, instanceName=name)
        self.s.instantiate()
        self.vr = {v.name: v for v in md.modelVariables}
        self.inputs = [v for v in md.modelVariables if v.causality == "input" and v.type in ("Float64", "Real")]
        self.outputs = [v for v in md.modelVariables if v.causality == "output"]
        # Scalar command counters (the chassis' cmd_seq): a new value each step applies the inputs.
        self.counters = [v for v in md.modelVariables if v.causality == "input" and v.type in ("Int32", "Integer") and v.name.endswith("_seq")]
        self.t = 0.0

    def set_real(self, vrs, values):
        (self.s.setFloat64 if self.version == 3 else self.s.setReal)(vrs, values)

    def initialize(self, params: dict):
        for k, v in params.items():
            (self.s.setInt32 if self.version == 3 else self.s.setInteger)([self.vr[k].valueReference], [v])
        if self.version == 3:
            self.s.enterInitializationMode(startTime=0.0)
        else:
            self.s.setupExperiment(startTime=0.0)
            self.s.enterInitializationMode()
        self.s.exitInitializationMode()

    def snapshot_outputs(self) -> list:
        out = []
        for v in self.outputs:
            r = [v.valueReference]
            if v.type in ("Float64", "Real"):
                x = (self.s.getFloat64 if self.version == 3 else self.s.getReal)(r)[0]
                out.append(("f", v.name, x.hex() if isinstance(x, float) else x))
            elif v.type in ("Int32", "Integer"):
                out.append(("i", v.name, (self.s.getInt32 if self.version == 3 else self.s.getInteger)(r)[0]))
            elif v.type == "Int64":
                out.append(("l", v.name, self.s.getInt64(r)[0]))
            elif v.type == "Boolean":
                out.append(("b", v.name, (self.s.getBoolean)(r)[0]))
            elif v.type == "Binary":
                out.append(("y", v.name, bytes(self.s.getBinary(r)[0])))
        return out

    def steps(self, first: int, n: int) -> list:
        seen = []
        for k in range(first, first + n):
            if self.inputs:
                vals = []
                for i, v in enumerate(self.inputs):
                    x = float(v.start or 0.0) + 0.3 * math.sin(0.37 * k + i)
                    lo = float(v.min) if v.min is not None else -math.inf
                    hi = float(v.max) if v.max is not None else math.inf
                    vals.append(min(max(x, lo), hi))
                self.set_real([v.valueReference for v in self.inputs], vals)
            if self.counters:
                (self.s.setInt32 if self.version == 3 else self.s.setInteger)([v.valueReference for v in self.counters], [k + 1] * len(self.counters))
            self.s.doStep(currentCommunicationPoint=self.t, communicationStepSize=self.h)
            self.t = (k + 1) * self.h
            seen.append(self.snapshot_outputs())
        return seen

    def get_state(self):
        return self.s.getFMUState() if self.version == 3 else self.s.getFMUstate()

    def serialize(self, state) -> bytes:
        return bytes(self.s.serializeFMUState(state) if self.version == 3 else self.s.serializeFMUstate(state))

    def restore(self, data: bytes):
        st = self.s.deserializeFMUState(data) if self.version == 3 else self.s.deSerializeFMUstate(data)
        (self.s.setFMUState if self.version == 3 else self.s.setFMUstate)(st)
        (self.s.freeFMUState if self.version == 3 else self.s.freeFMUstate)(st)

    def close(self):
        self.s.terminate()
        self.s.freeInstance()


@pytest.mark.parametrize("version", [3, 2])
@pytest.mark.parametrize("model", MODELS)
def test_serialized_state_restores_in_a_fresh_instance(model, version):
    path = str(fmu_path(model, version))
    md = read_model_description(path)
    assert md.coSimulation.canSerializeFMUstate, f"{model}: canSerializeFMUState not declared"
    unzipdir = extract(path, tempfile.mkdtemp(prefix="agrisim-ser-"))
    try:
        params = SMALL.get(model, {})
        a = Run(md, unzipdir, version, "a")
        a.initialize(params)
        a.steps(0, BEFORE)
        data = a.serialize(a.get_state())
        assert data[:4] == b"AGS\x01" and len(data) > 100
        expected = a.steps(BEFORE, AFTER)
        if version == 3 or model.startswith("Chassis"):
            # (FMI 2 has no message outputs: an arm without trajectories holds still.)
            assert any(x != expected[0] for x in expected[1:]), f"{model}: outputs never change; the check would be empty"
        b = Run(md, unzipdir, version, "b")  # parameters left at their defaults: the state carries them
        b.restore(data)
        b.t = BEFORE * b.h
        got = b.steps(BEFORE, AFTER)
        for k, (e, g) in enumerate(zip(expected, got)):
            diff = [x[1] for x, y in zip(e, g) if x != y]
            assert not diff, f"{model} FMI {version}: outputs {diff} differ {k + 1} steps after the restore"
        assert b.serialize(b.get_state()) == a.serialize(a.get_state()), f"{model}: the two runs end in different states"
        a.close()
        b.close()
        c = Run(md, unzipdir, version, "c")
        with pytest.raises(Exception, match="failed with status 3"):
            c.restore(data[: len(data) // 2])  # truncated: refused (the instance is in Error now)
        c.s.freeInstance()
    finally:
        shutil.rmtree(unzipdir, ignore_errors=True)
