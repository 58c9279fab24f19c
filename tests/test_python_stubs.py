"""The package's typing stubs (python/pkg/agrisim/_agrisim.pyi) match the compiled module, as
mypy's stubtest reads it at run time, and the package type-checks with mypy."""

from __future__ import annotations

import subprocess
import sys




def mypy(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", *args], capture_output=True, text=True, cwd="/")


def test_stubs_match_the_compiled_module():
    r = mypy("mypy.stubtest", "agrisim._agrisim")
    assert r.returncode == 0, r.stdout + r.stderr


def test_package_type_checks():
    r = mypy("mypy", "--ignore-missing-imports", "--no-incremental", "-p", "agrisim")
    assert r.returncode == 0, r.stdout + r.stderr
