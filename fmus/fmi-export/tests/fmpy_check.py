#!/usr/bin/env python3
"""End-to-end check of an agrisim FMU shared library against FMPy (0.3.32).

Packs the .so into an FMI 3.0 and an FMI 2.0 .fmu (modelDescription.xml taken from the
library's agrisim_model_description_fmi3/fmi2 symbols), validates both with
fmpy.validation.validate_fmu (expects no problems), simulates both and compares x(t) with
x0 * exp(-k t), and checks the Binary echo of the test model with FMU3Slave low-level calls.

Usage: fmpy_check.py [path/to/libagrisim_fmu_testmodel.so]
Run with the venv that has fmpy==0.3.32 (e.g. /tmp/fmi-venv/bin/python).
"""

import ctypes
import math
import os
import sys
import tempfile
import xml.etree.ElementTree as ET
import zipfile

import fmpy
from fmpy import read_model_description, simulate_fmu
from fmpy.fmi3 import FMU3Slave
from fmpy.validation import validate_fmu

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_LIB = os.path.join(HERE, "..", "..", "..", "target", "debug", "libagrisim_fmu_testmodel.so")

failures = []
fmu_lib = []
MIME = "application/x-ros2-cdr; type=std_msgs/msg/String"


def check(condition, message):
    print(("ok   " if condition else "FAIL ") + message)
    if not condition:
        failures.append(message)


def model_description(lib_path, version):
    lib = ctypes.CDLL(lib_path)
    fn = getattr(lib, f"agrisim_model_description_fmi{version}")
    fn.restype = ctypes.c_char_p
    return fn()


def pack(lib_path, version, out_dir):
    xml = model_description(lib_path, version)
    identifier = ET.fromstring(xml).find("CoSimulation").get("modelIdentifier")
    platform = "x86_64-linux" if version == 3 else "linux64"
    fmu = os.path.join(out_dir, f"{identifier}_fmi{version}.fmu")
    with zipfile.ZipFile(fmu, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("modelDescription.xml", xml)
        z.write(lib_path, f"binaries/{platform}/{identifier}.so")
    return fmu


def check_simulation(fmu, version):
    md = read_model_description(fmu)
    starts = {v.name: v.start for v in md.modelVariables}
    k, x0 = float(starts["k"]), float(starts["x0"])
    result = simulate_fmu(fmu, stop_time=2.0, output_interval=0.02, output=["x", "steps", "above_half"])
    t, x = result["time"], result["x"]
    err = max(abs(xi - x0 * math.exp(-k * ti)) for ti, xi in zip(t, x))
    check(len(t) == 101, f"FMI {version}: 101 samples over [0, 2] s with output_interval 0.02 (got {len(t)})")
    check(err < 1e-12, f"FMI {version}: x(t) matches x0*exp(-k t), max error {err:.3e}")
    check(int(result["steps"][-1]) == 100, f"FMI {version}: 100 steps taken (got {result['steps'][-1]})")
    # with changed parameters
    result = simulate_fmu(fmu, stop_time=1.0, output_interval=0.02, output=["x"], start_values={"k": 0.5, "x0": 3.0})
    err = max(abs(xi - 3.0 * math.exp(-0.5 * ti)) for ti, xi in zip(result["time"], result["x"]))
    check(err < 1e-12, f"FMI {version}: x(t) with k=0.5, x0=3 matches, max error {err:.3e}")


def check_binary_echo(fmu):
    md = read_model_description(fmu)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    unzipped = fmpy.extract(fmu)
    slave = FMU3Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier,
                      instanceName="echo")
    slave.instantiate()
    slave.enterInitializationMode(startTime=0.0)
    slave.exitInitializationMode()
    # CDR of std_msgs/String "hello": header, length 6 (with NUL), bytes, NUL
    msg = bytes([0, 1, 0, 0, 6, 0, 0, 0]) + b"hello\x00"
    seq0 = slave.getInt64([vr["msg_seq"]])[0]
    slave.setBinary([vr["msg_in"]], [msg])
    slave.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.02)
    out = slave.getBinary([vr["msg_out"]])[0]
    seq1 = slave.getInt64([vr["msg_seq"]])[0]
    check(out == msg, f"FMI 3: Binary echo returns the bytes set ({out!r})")
    check(seq1 == seq0 + 1, f"FMI 3: msg_seq advanced from {seq0} to {seq1}")
    slave.doStep(currentCommunicationPoint=0.02, communicationStepSize=0.02)
    check(slave.getInt64([vr["msg_seq"]])[0] == seq1, "FMI 3: msg_seq unchanged when the message is unchanged")
    both = slave.getBinary([vr["msg_in"], vr["msg_out"]])
    check(both == [msg, msg], "FMI 3: two Binary values in one call")
    # FMU state round trip
    state = slave.getFMUState()
    x_before = slave.getFloat64([vr["x"]])[0]
    slave.doStep(currentCommunicationPoint=0.04, communicationStepSize=0.02)
    slave.setFMUState(state)
    check(slave.getFloat64([vr["x"]])[0] == x_before, "FMI 3: Set/GetFMUState restores x")
    slave.freeFMUState(state)
    # an illegal call is an error, not a crash
    try:
        slave.setFloat64([vr["x0"]], [2.0])  # fixed parameter after initialization
        check(False, "FMI 3: setting a fixed parameter in Step Mode must fail")
    except Exception as e:
        check("Error" in str(e) or "3" in str(e), f"FMI 3: setting a fixed parameter in Step Mode fails ({e})")
    slave.reset()
    slave.freeInstance()
    binaries = {e.get("name"): e.get("mimeType") for e in ET.fromstring(model_description(fmu_lib[0], 3)).iter("Binary")}
    check(binaries == {"msg_in": MIME, "msg_out": MIME}, f"FMI 3: Binary variables carry the mimeType ({binaries})")


def main():
    lib_path = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else DEFAULT_LIB)
    print(f"fmpy {fmpy.__version__}, library {lib_path}")
    fmu_lib.append(lib_path)
    with tempfile.TemporaryDirectory() as tmp:
        for version in (3, 2):
            fmu = pack(lib_path, version, tmp)
            problems = validate_fmu(fmu)
            for p in problems:
                print("   problem:", p)
            check(problems == [], f"FMI {version}: validate_fmu reports {len(problems)} problems")
            check_simulation(fmu, version)
            if version == 3:
                check_binary_echo(fmu)
    if failures:
        print(f"{len(failures)} check(s) failed")
        sys.exit(1)
    print("all checks passed")


if __name__ == "__main__":
    main()
