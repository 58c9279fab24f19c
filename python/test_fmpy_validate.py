"""Every packed FMU (FMI 3 in target/fmu, FMI 2 in target/fmu/fmi2) passes FMPy's validator
and carries the model-description facts other importers rely on."""

from __future__ import annotations

import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import pytest
from fmpy import read_model_description
from fmpy.validation import validate_fmu

from agrisim_fmpy import EXPECTED_MODELS, FMU2_DIR, FMU_DIR

FMI3 = sorted(FMU_DIR.glob("*.fmu"))
FMI2 = sorted(FMU2_DIR.glob("*.fmu"))
ALL = FMI3 + FMI2


def ids(paths):
    return [f"fmi{'2' if p.parent == FMU2_DIR else '3'}-{p.stem}" for p in paths]


@pytest.mark.parametrize("fmi_dir", [FMU_DIR, FMU2_DIR], ids=["fmi3", "fmi2"])
def test_expected_fmus_are_packed(fmi_dir: Path):
    have = {p.stem for p in fmi_dir.glob("*.fmu")}
    missing = set(EXPECTED_MODELS) - have
    assert not missing, f"{fmi_dir}: {sorted(missing)} not packed (run `agrisim fmu pack`)"


@pytest.mark.parametrize("fmu", ALL, ids=ids(ALL))
def test_fmpy_validation_has_no_problems(fmu: Path):
    problems = validate_fmu(str(fmu))
    assert problems == [], f"{fmu}: {problems}"


@pytest.mark.parametrize("fmu", ALL, ids=ids(ALL))
def test_default_experiment_step_is_0_02(fmu: Path):
    md = read_model_description(str(fmu))
    assert md.defaultExperiment is not None, f"{fmu}: no DefaultExperiment"
    assert md.defaultExperiment.stepSize is not None and float(md.defaultExperiment.stepSize) == 0.02
    # Every FMU offers co-simulation, except the model-exchange test model (Oscillator).
    assert (md.coSimulation is not None) != (fmu.stem == "Oscillator"), f"{fmu}: interfaces"
    assert md.coSimulation is not None or md.modelExchange is not None
    assert md.modelName == fmu.stem


@pytest.mark.parametrize("fmu", FMI3, ids=ids(FMI3))
def test_fmi3_has_exactly_one_independent_time(fmu: Path):
    md = read_model_description(str(fmu))
    assert md.fmiVersion == "3.0"
    independent = [v for v in md.modelVariables if v.causality == "independent"]
    assert [(v.name, v.type) for v in independent] == [("time", "Float64")]


def mime_types(fmu: Path) -> dict[str, str]:
    """Binary variable name -> mimeType, from the XML (FMPy 0.3.32 does not parse mimeType)."""
    with zipfile.ZipFile(fmu) as z:
        root = ET.fromstring(z.read("modelDescription.xml"))
    return {b.get("name"): b.get("mimeType") for b in root.iter("Binary")}


@pytest.mark.parametrize("fmu", FMI3, ids=ids(FMI3))
def test_fmi3_inputs_have_start_values(fmu: Path):
    md = read_model_description(str(fmu))
    for v in md.modelVariables:
        if v.causality == "input":
            assert v.start is not None, f"{fmu.stem}.{v.name}: input without start value"


@pytest.mark.parametrize("name", EXPECTED_MODELS)
def test_fmi3_message_ports_have_ros2_mime_and_counter(name: str):
    fmu = FMU_DIR / f"{name}.fmu"
    md = read_model_description(str(fmu))
    names = {v.name: v for v in md.modelVariables}
    mimes = mime_types(fmu)
    for v in md.modelVariables:
        if v.type == "Binary":
            seq = names.get(f"{v.name}_seq")
            assert seq is not None and seq.type == "Int64" and seq.causality == v.causality, f"{name}.{v.name}: no Int64 counter"
            assert (mimes.get(v.name) or "").startswith("application/x-ros2-cdr-frames; version=1; type="), f"{name}.{v.name}: mimeType {mimes.get(v.name)!r}"


@pytest.mark.parametrize("fmu", FMI2, ids=ids(FMI2))
def test_fmi2_exposes_no_binary_or_int64(fmu: Path):
    md = read_model_description(str(fmu))
    assert md.fmiVersion == "2.0"
    # Binary and Int64 do not exist in FMI 2 (String does: e.g. the scene text parameter).
    bad = [(v.name, v.type) for v in md.modelVariables if v.type in ("Binary", "Int64") and v.name != "time"]
    assert not bad, f"{fmu}: {bad}"
    assert {v.type for v in md.modelVariables} <= {"Real", "Integer", "Boolean", "String", "Enumeration"}
    # FMPy's FMI 2 parser would not show FMI 3 elements at all: look at the XML itself.
    with zipfile.ZipFile(fmu) as z:
        root = ET.fromstring(z.read("modelDescription.xml"))
    fmi3_tags = {e.tag for e in root.iter()} & {"Binary", "Int64", "UInt64", "Float64", "Float32", "Clock"}
    assert not fmi3_tags, f"{fmu}: FMI 3 elements {sorted(fmi3_tags)} in an FMI 2 model description"


def signature(fmu: Path):
    md = read_model_description(str(fmu))
    mimes = mime_types(fmu)
    return [(v.name, v.type, v.causality, v.variability, v.valueReference, mimes.get(v.name)) for v in md.modelVariables]


@pytest.mark.parametrize("fmi_dir", [FMU_DIR, FMU2_DIR], ids=["fmi3", "fmi2"])
def test_chassis_models_are_swappable(fmi_dir: Path):
    """Identical names, types, causalities and value references: one replaces the other."""
    kin = signature(fmi_dir / "ChassisKinematic.fmu")
    dyn = signature(fmi_dir / "ChassisDynamic.fmu")
    assert len(kin) > 40
    assert kin == dyn, "\n".join(f"{a} != {b}" for a, b in zip(kin, dyn) if a != b) or "different lengths"


def test_fmi2_and_fmi3_chassis_share_their_scalar_table():
    """The FMI 2 build is the FMI 3 table minus the message ports (Binary and Int64 counters)."""
    v3 = read_model_description(str(FMU_DIR / "ChassisKinematic.fmu")).modelVariables
    v2 = read_model_description(str(FMU2_DIR / "ChassisKinematic.fmu")).modelVariables
    scalar3 = [(v.name, v.causality) for v in v3 if v.type not in ("Binary", "Int64")]
    scalar2 = [(v.name, v.causality) for v in v2]
    assert scalar2 == scalar3
