"""A scenario file with extra TOML appended, written elsewhere (a temporary directory): the
benchmarks and end-to-end tests vary one scenario (camera resolution, FMU parameters)
without editing the tracked file. The [system] file, relative to the original scenario,
is made absolute so the copy still finds it."""

from __future__ import annotations

import re
from pathlib import Path


def write_variant(scenario: Path, out_dir: Path, extra_toml: str, name: str | None = None) -> Path:
    """Writes OUT_DIR/NAME (default: the scenario's file name) = the scenario with its
    `file = "..."` system path made absolute and EXTRA_TOML appended; returns the path."""
    scenario = Path(scenario).resolve()
    text = scenario.read_text()

    def absolute(m: re.Match) -> str:
        return f'{m.group(1)}"{(scenario.parent / m.group(2)).resolve()}"'

    text, n = re.subn(r'(?m)^(file\s*=\s*)"([^"]+)"', absolute, text, count=1)
    if n != 1:
        raise ValueError(f"{scenario}: no [system] file = \"...\" line")
    out = Path(out_dir) / (name or scenario.name)
    out.write_text(text + "\n" + extra_toml)
    return out
