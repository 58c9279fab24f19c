"""Shared fixtures of the end-to-end tests: the built CLI and the packed FMUs."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
FMU_DIR = REPO / "target" / "fmu"


def agrisim_bin() -> Path:
    exe = Path(os.environ.get("AGRISIM_BIN", REPO / "target" / "release" / "agrisim"))
    if not exe.is_absolute():
        exe = REPO / exe
    assert exe.exists(), f"{exe} missing: run scripts/setup (cargo build --release && agrisim fmu pack)"
    return exe


def run_agrisim(*args: str, check: bool = True) -> subprocess.CompletedProcess:
    """Runs the CLI from the repository root; returns the completed process."""
    p = subprocess.run([str(agrisim_bin()), *args], cwd=REPO, capture_output=True, text=True)
    if check and p.returncode != 0:
        raise AssertionError(f"agrisim {' '.join(args)} failed ({p.returncode}):\n{p.stderr}")
    return p


@pytest.fixture(scope="session")
def fmu_dir() -> Path:
    for name in ("ChassisKinematic", "ChassisDynamic", "Lift"):
        assert (FMU_DIR / f"{name}.fmu").exists(), f"{name}.fmu not packed: run scripts/setup"
    return FMU_DIR
