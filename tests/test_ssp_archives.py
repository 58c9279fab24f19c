"""SSP portability: the system files use connector and system names every SSP tool accepts
(identifiers; OMSimulator refuses `/cmd_vel` and `-`), keep the ROS 2 topic in an
`org.agrisim.topic` annotation, and `agrisim fmu pack` writes self-contained .ssp archives that
FMPy's SSP reader validates against the SSP 1.0 schema and that `agrisim run` runs exactly
like the .ssd they came from."""

from __future__ import annotations

import re
import zipfile
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from fmpy.ssp.ssd import read_ssd
from mcap.reader import make_reader

from conftest import REPO, run_agrisim

SYSTEMS = sorted((REPO / "models" / "systems").glob("*.ssd"))
SSP_DIR = REPO / "target" / "ssp"
NS = {"ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription", "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon"}
IDENT = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


@pytest.mark.parametrize("ssd", SYSTEMS, ids=lambda p: p.name)
def test_names_are_identifiers_and_topics_are_annotated(ssd: Path):
    root = ET.parse(ssd).getroot()
    assert IDENT.fullmatch(root.get("name")), root.get("name")
    for el in root.iter(f"{{{NS['ssd']}}}System"):
        assert IDENT.fullmatch(el.get("name")), el.get("name")
    for c in root.iter(f"{{{NS['ssd']}}}Connector"):
        assert IDENT.fullmatch(c.get("name")), f"{ssd.name}: connector {c.get('name')!r}"
    system = root.find("ssd:System", NS)
    for c in system.findall("ssd:Connectors/ssd:Connector", NS):
        anns = [a for a in c.findall("ssd:Annotations/ssc:Annotation", NS) if a.get("type") == "org.agrisim.topic"]
        topics = [n.get("name") for a in anns for n in a.iter() if n.get("name")]
        assert len(topics) == 1 and topics[0].startswith("/"), f"{ssd.name}: connector {c.get('name')} has no topic"


@pytest.mark.parametrize("ssd", SYSTEMS, ids=lambda p: p.name)
def test_packed_ssp_is_self_contained_and_schema_valid(ssd: Path):
    ssp = SSP_DIR / f"{ssd.stem}.ssp"
    assert ssp.exists(), f"{ssp} missing: `agrisim fmu pack` writes it (scripts/setup runs it)"
    desc = read_ssd(str(ssp), validate=True)  # FMPy: SSP 1.0 XSD validation
    with zipfile.ZipFile(ssp) as z:
        names = set(z.namelist())
        sources = {e.source for e in desc.system.elements}
        assert names == {"SystemStructure.ssd"} | sources, names
        for s in sources:
            assert s.startswith("resources/") and s.endswith(".fmu")
            assert zipfile.ZipFile(z.open(s)).read("modelDescription.xml")


def messages(path: Path) -> list:
    with open(path, "rb") as f:
        reader = make_reader(f)
        return [(c.topic, m.log_time, bytes(m.data)) for _, c, m in reader.iter_messages()]


def test_agrisim_runs_an_ssp_like_its_ssd(tmp_path: Path):
    scenario = (REPO / "models" / "scenarios" / "default.toml").read_text()
    variant = tmp_path / "from_ssp.toml"
    assert 'file = "../systems/default.ssd"' in scenario
    variant.write_text(scenario.replace('file = "../systems/default.ssd"', f'file = "{SSP_DIR / "default.ssp"}"'))
    run_agrisim("run", "--scenario", str(REPO / "models" / "scenarios" / "default.toml"), "--duration", "2", "--out", str(tmp_path / "ssd"))
    run_agrisim("run", "--scenario", str(variant), "--duration", "2", "--out", str(tmp_path / "ssp"))
    a, b = messages(tmp_path / "ssd" / "run.mcap"), messages(tmp_path / "ssp" / "run.mcap")
    assert len(a) > 500 and a == b
