"""agrisim's FMI 2.0 system in another master: libcosim (the Open Simulation Platform's
co-simulation library, through its Python binding libcosimpy) runs the packed FMI 2.0 .ssp
(target/ssp/fmi2/core.ssp, written by `agrisim fmu pack` from models/systems/fmi2/core.ssd) and
must compute what agrisim's engine computes on the very same archive with `[timing] algorithm =
"jacobi"`: every output of every component, every step, to 1e-9 absolute (Real) and exactly
(Integer, Boolean).

Why Jacobi: libcosim's fixed_step_algorithm steps every simulator from the inputs transferred
after the previous step, then transfers all outputs (src/cosim/algorithm/fixed_step_algorithm.cpp,
`do_step` then `calculate_and_transfer`); agrisim's default Gauss-Seidel order lets the world see
the base after this step, which libcosim cannot compute (checked below too).

Both masters get the same parameters (agrisim derives the components' seeds, the start pose
and the scene text from the scenario; the test reads them from the run's `agrisim.parameters.*`
metadata and hands them to libcosim as initial values) and the same inputs from the algorithm
layer (a lift set-point, base velocity commands with their sequence number, a harvest target),
set directly on the components' unconnected inputs before the step they apply to:
`agrisim.Simulation.set` on one side, a libcosim override manipulator on the other.

The two agree to about 1e-14, not bit for bit: libcosim hands fmi2DoStep the step size
t_k+1 - t_k computed in doubles (`to_double_duration` in cosim/time.hpp), e.g.
0.06 - 0.04 = 0.019999999999999997, where agrisim passes 0.02; an FMU alone reproduces each
master's values exactly with the corresponding step size. Hence the 1e-9 absolute tolerance;
`test_comparison_catches_a_changed_input` shows a 1e-6 change of one input is far beyond it."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import pytest
from lxml import etree
from mcap.reader import make_reader

from conftest import REPO

libcosimpy = pytest.importorskip("libcosimpy")
from libcosimpy.CosimEnums import CosimVariableCausality, CosimVariableType  # noqa: E402
from libcosimpy.CosimExecution import CosimExecution  # noqa: E402
from libcosimpy.CosimLogging import CosimLogLevel, log_output_level  # noqa: E402
from libcosimpy.CosimManipulator import CosimManipulator  # noqa: E402
from libcosimpy.CosimObserver import CosimObserver  # noqa: E402

SSD = REPO / "models" / "systems" / "fmi2" / "core.ssd"
SSP = REPO / "target" / "ssp" / "fmi2" / "core.ssp"
STEP = 0.02
STEP_NS = 20_000_000  # libcosim takes its step in nanoseconds
STEPS = 300  # 6 s
ABS_TOL = 1e-9
NS = {"ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription"}


def schedule(k: int, setpoint_offset: float = 0.0) -> list[tuple[str, str, object]]:
    """The inputs of the algorithm layer set before step k (t = k * STEP): (component,
    variable, value). Velocity commands at 10 Hz with a new sequence number each, stopped
    at 4 s (the chassis' command timeout then stops the base); lift set-points; a harvest
    target for the world."""
    out: list[tuple[str, str, object]] = []
    if k == 0:
        out.append(("lift", "setpoint", 0.65 + setpoint_offset))
    if k == 150:
        out.append(("lift", "setpoint", 0.3 + setpoint_offset))
    if k == 20:
        out.append(("world", "target_fruit", 2))
    if k % 5 == 0 and k < 200:
        t = k * STEP
        out += [
            ("chassis", "cmd_vx", 0.5 if t < 2.0 else 0.25),
            ("chassis", "cmd_vy", 0.0),
            ("chassis", "cmd_wz", 0.4 * math.sin(1.5 * t)),
            ("chassis", "cmd_seq", k // 5 + 1),
        ]
    return out


def model_variables(ssp: Path) -> dict[str, dict[str, tuple[int, str, str]]]:
    """Per component of the archive: variable name -> (value reference, type, causality),
    from the modelDescription.xml of its FMU."""
    with zipfile.ZipFile(ssp) as z:
        root = ET.fromstring(z.read("SystemStructure.ssd"))
        out = {}
        for comp in root.iter(f"{{{NS['ssd']}}}Component"):
            with zipfile.ZipFile(z.open(comp.get("source"))) as fmu:
                md = ET.fromstring(fmu.read("modelDescription.xml"))
            assert md.get("fmiVersion") == "2.0", comp.get("source")
            table = {}
            for sv in md.iter("ScalarVariable"):
                ty = next(c.tag for c in sv if c.tag in ("Real", "Integer", "Boolean", "String", "Enumeration"))
                table[sv.get("name")] = (int(sv.get("valueReference")), ty, sv.get("causality"))
            out[comp.get("name")] = table
    return out


def outputs_of(variables: dict) -> list[tuple[str, str, int, str]]:
    return sorted(
        (c, n, vr, ty) for c, table in variables.items() for n, (vr, ty, caus) in table.items() if caus == "output"
    )


def run_agrisim(tmp: Path, variables: dict, algorithm: str) -> tuple[list[dict], dict[str, dict[str, str]]]:
    """Every output after each step in agrisim's engine, and the parameters agrisim set."""
    agrisim = pytest.importorskip("agrisim")
    scenario = tmp / f"core_{algorithm}.toml"
    scenario.write_text(
        f'name = "core_fmi2"\nseed = 1\nduration = {STEPS * STEP}\n\n'
        f'[timing]\nstep = {STEP}\nmessage_rate = 10.0\nalgorithm = "{algorithm}"\n\n'
        f'[system]\nfile = "{SSP}"\n'
    )
    mcap = tmp / f"{algorithm}.mcap"
    outs = outputs_of(variables)
    rows = []
    sim = agrisim.Simulation(str(scenario), record=str(mcap))
    try:
        for k in range(STEPS):
            for comp, name, value in schedule(k):
                sim.set(comp, name, value)
            sim.step(1)
            rows.append({(c, n): sim.get(c, n) for c, n, _, _ in outs})
    finally:
        sim.close()
    with open(mcap, "rb") as f:
        meta = {m.name: dict(m.metadata) for m in make_reader(f).iter_metadata()}
    assert meta["agrisim.run"]["algorithm"] == algorithm
    params = {name.removeprefix("agrisim.parameters."): m for name, m in meta.items() if name.startswith("agrisim.parameters.")}
    return rows, params


def run_libcosim(variables: dict, params: dict[str, dict[str, str]], setpoint_offset: float = 0.0) -> list[dict]:
    """Every output after each step in libcosim (fixed-step algorithm, 0.02 s), with agrisim's
    parameter values as initial values and the same inputs through an override manipulator."""
    log_output_level(CosimLogLevel.ERROR)
    ex = CosimExecution.from_ssp_file(str(SSP), step_size=STEP_NS)
    index = {s.name.decode(): s.index for s in ex.slave_infos()}
    assert set(index) == set(variables), index
    for comp, values in params.items():
        for name, text in values.items():
            vr, ty, caus = variables[comp][name]
            assert caus == "parameter", (comp, name, caus)
            if ty == "Real":
                ex.real_initial_value(index[comp], vr, float(text))
            elif ty == "Integer":
                ex.integer_initial_value(index[comp], vr, int(text))
            elif ty == "Boolean":
                ex.boolean_initial_value(index[comp], vr, text == "true")
            else:
                ex.string_initial_value(index[comp], vr, text)
    observer = CosimObserver.create_last_value()
    ex.add_observer(observer)
    manipulator = CosimManipulator.create_override()
    ex.add_manipulator(manipulator)
    outs = outputs_of(variables)
    rows = []
    for k in range(STEPS):
        for comp, name, value in schedule(k, setpoint_offset):
            vr, ty, caus = variables[comp][name]
            assert caus == "input", (comp, name)
            if ty == "Real":
                assert manipulator.slave_real_values(index[comp], [vr], [value])
            else:
                assert manipulator.slave_integer_values(index[comp], [vr], [value])
        assert ex.step(1)
        row = {}
        for comp, name, vr, ty in outs:
            read = {
                "Real": observer.last_real_values,
                "Integer": observer.last_integer_values,
                "Boolean": observer.last_boolean_values,
            }[ty]
            row[(comp, name)] = read(index[comp], [vr])[0]
        rows.append(row)
    return rows


def differences(a: list[dict], b: list[dict]) -> tuple[float, list[str]]:
    """The largest absolute difference of Real outputs, and every mismatch (Real beyond
    ABS_TOL, Integer or Boolean unequal) as text."""
    worst, bad = 0.0, []
    for k, (ra, rb) in enumerate(zip(a, b, strict=True)):
        for key in ra:
            x, y = ra[key], rb[key]
            if isinstance(x, float) or isinstance(y, float):
                d = abs(float(x) - float(y))
                worst = max(worst, d)
                if not d <= ABS_TOL:
                    bad.append(f"t={(k + 1) * STEP:.2f} {key[0]}.{key[1]}: agrisim {x!r} libcosim {y!r}")
            elif int(x) != int(y):  # Integer, or Boolean (agrisim gives bool, libcosim bool)
                bad.append(f"t={(k + 1) * STEP:.2f} {key[0]}.{key[1]}: agrisim {x!r} libcosim {y!r}")
    return worst, bad


@pytest.fixture(scope="module")
def variables() -> dict:
    assert SSP.exists(), f"{SSP} missing: `agrisim fmu pack` writes it (scripts/setup runs it)"
    return model_variables(SSP)


@pytest.fixture(scope="module")
def jacobi(variables, tmp_path_factory) -> tuple[list[dict], dict]:
    return run_agrisim(tmp_path_factory.mktemp("jacobi"), variables, "jacobi")


def test_fmi2_system_is_valid_ssp_of_scalar_fmi2_fmus(variables):
    """The .ssd validates against FMPy's SSP 1.0 schema, its names are identifiers, every
    connector is a scalar port of an FMI 2.0 FMU, and the archive holds exactly those FMUs."""
    from fmpy.ssp.ssd import read_ssd, validate_tree

    validate_tree(etree.parse(str(SSD)).getroot(), "SystemStructureDescription.xsd")
    desc = read_ssd(str(SSP), validate=True)
    assert {e.name for e in desc.system.elements} == {"chassis", "lift", "world", "arm_left", "arm_right"}
    root = ET.parse(SSD).getroot()
    for el in root.iter():
        if el.tag.endswith("}Connector") or el.tag.endswith("}Component") or el.tag.endswith("}System"):
            assert el.get("name").isidentifier(), el.get("name")
    for comp in root.iter(f"{{{NS['ssd']}}}Component"):
        for c in comp.iter(f"{{{NS['ssd']}}}Connector"):
            vr, ty, caus = variables[comp.get("name")][c.get("name")]
            assert ty in ("Real", "Integer") and caus == c.get("kind"), (comp.get("name"), c.get("name"))
    with zipfile.ZipFile(SSP) as z:
        assert set(z.namelist()) == {"SystemStructure.ssd"} | {e.source for e in desc.system.elements}


def test_libcosim_computes_what_agrisim_jacobi_computes(variables, jacobi):
    rows, params = jacobi
    # agrisim set the seeds, the start pose and the scene: libcosim must get them too.
    assert {"seed", "x0", "y0"} <= set(params["chassis"]) and "scene" in params["world"]
    theirs = run_libcosim(variables, params)
    worst, bad = differences(rows, theirs)
    print(f"max |agrisim - libcosim| over {len(rows[0])} outputs x {STEPS} steps: {worst:.3g}")
    assert not bad, f"{len(bad)} mismatches (max Real difference {worst:.3g}); first: " + "\n".join(bad[:10])
    # The run exercised the system: the base drove and turned, the lift moved, the watchdog
    # stopped the base, the world followed the base.
    last = rows[-1]
    assert last[("chassis", "x")] - float(params["chassis"]["x0"]) > 1.0
    assert abs(last[("chassis", "yaw")]) > 0.05 and abs(last[("chassis", "vx")]) < 1e-9
    assert max(r[("lift", "position")] for r in rows) > 0.6 and abs(last[("lift", "position")] - 0.3) < 0.05
    assert rows[100][("world", "min_clearance")] != rows[0][("world", "min_clearance")]


def test_comparison_catches_a_changed_input(variables, jacobi):
    """The comparison can fail: a lift set-point 1 µm higher on libcosim's side only is found."""
    rows, params = jacobi
    worst, bad = differences(rows, run_libcosim(variables, params, setpoint_offset=1e-6))
    assert any(" lift.position:" in b for b in bad), bad[:5]
    assert worst > ABS_TOL


def test_gauss_seidel_is_not_what_libcosim_computes(variables, jacobi, tmp_path):
    """The algorithm option matters: agrisim's default order differs from libcosim's."""
    rows, params = run_agrisim(tmp_path, variables, "gauss-seidel")
    assert params == jacobi[1]
    _, bad = differences(rows, run_libcosim(variables, params))
    assert bad
