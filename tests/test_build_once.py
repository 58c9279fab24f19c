"""The workspace compiles once. scripts/setup builds the Python package (maturin runs cargo for
agrisim-python alone), then `cargo build --release --workspace`, both into target/release.
Cargo unifies features per invocation, and a crate built with other features is another unit:
any crate the two graphs share but build with different features would be compiled twice (with
every crate above it: 72 crates, 6.5 minutes, before python/Cargo.toml asked for the workspace's
features). Read from `cargo tree` and `cargo metadata`, which compile nothing:

- every crate of the extension's graph is built with the features the workspace build gives it;
- the dependencies python/Cargo.toml declares only for that (its code does not use them) ask for
  no feature that no other member uses, so they change nothing in the workspace build, and go
  when the crate that needed them stops needing them.

A unit is (package, host or target, features): build scripts, proc-macros and what they link
are compiled for the host with a feature set of their own (and the build-override profile), so
the two kinds are compared apart. Dev-dependencies are left out: `cargo build` does not unify
them (`cargo test` is a build of its own).
"""
from __future__ import annotations

import json
import re
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PYTHON = "agrisim-python"
# What `cargo tree` draws its tree with, before each package.
TREE_CHARS = "│├└─ \u00a0"
BUILD_HEADER = "[build-dependencies]"

Units = dict[tuple[str, str], set[frozenset[str]]]


def units(tree: str) -> Units:
    """("name vX.Y.Z", "host" | "target") -> the feature sets it is built with, read from
    `cargo tree -e normal,build --no-dedupe -f '{p}|{f}'` (indented, one tree per root).

    A package is built for the host when it is a proc-macro, or it hangs below a proc-macro or
    below a [build-dependencies] header."""
    out: Units = {}
    # stack[d] = [host?, below its [build-dependencies] header?] for the node drawn at depth d
    stack: list[list[bool]] = []
    for line in tree.splitlines():
        if not line.strip():
            stack = []
            continue
        col = len(line) - len(line.lstrip(TREE_CHARS))
        text, depth = line[col:], col // 4
        if text == BUILD_HEADER:
            # drawn where the children of the node at depth col/4 are
            stack[depth][1] = True
            continue
        package, _, features = text.removesuffix(" (*)").partition("|")
        del stack[depth:]
        proc_macro = package.endswith(" (proc-macro)")
        host = proc_macro or (bool(stack) and (stack[-1][0] or stack[-1][1]))
        stack.append([host, False])
        name = package.removesuffix(" (proc-macro)").strip()
        out.setdefault((name, "host" if host else "target"), set()).add(
            frozenset(f for f in features.strip().split(",") if f)
        )
    return out


def differences(workspace: Units, python: Units) -> list[str]:
    """Each unit of the extension's graph that the workspace build builds with other features
    (so maturin compiles it, and all above it, a second time), with the features that differ."""
    problems = []
    for (name, kind), sets in sorted(python.items()):
        if name.startswith(PYTHON + " ") or (name, kind) not in workspace:
            continue
        for features in sorted(sets, key=sorted):
            if features in workspace[(name, kind)]:
                continue
            wanted = frozenset().union(*workspace[(name, kind)])
            lacks, adds = sorted(wanted - features), sorted(features - wanted)
            problems.append(
                f"{name} ({kind}):"
                + (f" lacks {lacks}" if lacks else "")
                + (" and" if lacks and adds else "")
                + (f" has {adds} the workspace build has not" if adds else "")
            )
    return problems


def enabled(asked: set[str], table: dict[str, list[str]]) -> set[str]:
    """The features of one crate that asking for `asked` turns on (its [features] table followed;
    `dep:x` and `x/feature` entries name other crates)."""
    out, todo = set(), list(asked)
    while todo:
        f = todo.pop()
        if f in out:
            continue
        out.add(f)
        todo += [e for e in table.get(f, []) if not e.startswith("dep:") and "/" not in e]
    return out


def over_asked(asked: dict[tuple[str, str], set[str]], others: Units) -> list[str]:
    """Each crate declared only for the union whose features (as `enabled` expands them) are not
    all among those the other members build it with."""
    problems = []
    for (name, kind), features in sorted(asked.items()):
        if (name, kind) not in others:
            problems.append(f"{name} ({kind}): no other member builds it; drop it")
            continue
        extra = sorted(features - frozenset().union(*others[(name, kind)]))
        if extra:
            problems.append(f"{name} ({kind}): asks for {extra}, which no other member uses")
    return problems


def declared_for_the_union(metadata: dict, sources: str) -> dict[tuple[str, str], set[str]]:
    """The extension's dependencies that are neither workspace crates nor named in its code:
    ("name vX.Y.Z", kind) -> the features they turn on."""
    packages = {p["id"]: p for p in metadata["packages"]}
    python = next(p for p in metadata["packages"] if p["name"] == PYTHON)
    node = next(n for n in metadata["resolve"]["nodes"] if n["id"] == python["id"])
    out = {}
    for dep in python["dependencies"]:
        if dep.get("path") or dep["kind"] == "dev":
            continue
        crate = dep["name"].replace("-", "_")
        if re.search(rf"\b{crate}::|\buse {crate}\b", sources):
            continue
        resolved = next(
            packages[d["pkg"]]
            for d in node["deps"]
            if packages[d["pkg"]]["name"] == dep["name"] and any(k["kind"] == dep["kind"] for k in d["dep_kinds"])
        )
        asked = set(dep["features"]) | ({"default"} if dep["uses_default_features"] and "default" in resolved["features"] else set())
        key = (f"{resolved['name']} v{resolved['version']}", "host" if dep["kind"] == "build" else "target")
        out[key] = enabled(asked, resolved["features"])
    return out


def cargo(*args: str) -> str:
    return subprocess.run(["cargo", *args, "--locked"], cwd=ROOT, check=True, capture_output=True, text=True).stdout


def cargo_tree(*selection: str) -> Units:
    return units(cargo("tree", *selection, "-e", "normal,build", "--no-dedupe", "-f", "{p}|{f}"))


def test_extension_shares_every_crate_with_the_workspace_build():
    problems = differences(cargo_tree("--workspace"), cargo_tree("-p", PYTHON))
    assert not problems, (
        f"maturin (cargo -p {PYTHON}) builds these crates with other features than "
        "`cargo build --release --workspace` does, so scripts/setup compiles them twice; in "
        "python/Cargo.toml, ask for the features they lack ([build-dependencies] for host "
        "crates):\n  " + "\n  ".join(problems)
    )


def test_the_union_asks_for_nothing_new():
    sources = "\n".join(p.read_text() for p in sorted((ROOT / "python" / "src").rglob("*.rs")))
    asked = declared_for_the_union(json.loads(cargo("metadata", "--format-version", "1")), sources)
    assert asked, "python/Cargo.toml declares no crate for the union (read the dependencies wrong?)"
    problems = over_asked(asked, cargo_tree("--workspace", "--exclude", PYTHON))
    assert not problems, (
        "python/Cargo.toml declares these crates only so that maturin builds them as the "
        "workspace does, but asks for more than the other members use: that changes the "
        "workspace build; drop what is named:\n  " + "\n  ".join(problems)
    )


# Doctored `cargo tree` output: the workspace builds serde with "rc" and, for the host, syn with
# "visit"; the extension asks for neither.
WORKSPACE_TREE = """\
agrisim-x v0.1.0 (/w/x)|
├── anyhow v1.0.0|std
├── serde v1.0.0|default,derive,rc,std
│   └── serde_derive v1.0.0 (proc-macro)|default
│       └── syn v2.0.0|full,parsing,visit
└── zstd v0.13.0|
    [build-dependencies]
    └── cc v1.0.0|parallel

agrisim-python v0.1.0 (/w/python)|
└── serde v1.0.0|default,derive,rc,std
"""
PYTHON_TREE = """\
agrisim-python v0.1.0 (/w/python)|
├── anyhow v1.0.0|std
├── pyo3 v0.30.0|default
├── serde v1.0.0|default,derive,std
│   └── serde_derive v1.0.0 (proc-macro)|default
│       └── syn v2.0.0|full,parsing
└── zstd v0.13.0|
    [build-dependencies]
    └── cc v1.0.0|parallel
"""


def test_units_tell_host_from_target():
    got = units(WORKSPACE_TREE)
    assert got[("serde v1.0.0", "target")] == {frozenset({"default", "derive", "rc", "std"})}
    assert got[("serde_derive v1.0.0", "host")] == {frozenset({"default"})}
    assert got[("syn v2.0.0", "host")] == {frozenset({"full", "parsing", "visit"})}
    assert got[("cc v1.0.0", "host")] == {frozenset({"parallel"})}
    assert got[("zstd v0.13.0", "target")] == {frozenset()}
    assert ("syn v2.0.0", "target") not in got and ("cc v1.0.0", "target") not in got


def test_a_lacking_feature_fails_and_is_named():
    assert differences(units(WORKSPACE_TREE), units(PYTHON_TREE)) == [
        "serde v1.0.0 (target): lacks ['rc']",
        "syn v2.0.0 (host): lacks ['visit']",
    ]
    mended = PYTHON_TREE.replace("derive,std", "derive,rc,std").replace("full,parsing", "full,parsing,visit")
    assert differences(units(WORKSPACE_TREE), units(mended)) == []


def test_asking_for_more_than_the_others_fails_and_is_named():
    table = {"default": ["std"], "std": ["alloc"], "alloc": [], "serde": ["dep:serde", "alloc"], "rc": ["serde_core/rc"]}
    assert enabled({"default", "rc"}, table) == {"default", "std", "alloc", "rc"}
    others = units(WORKSPACE_TREE.split("\n\n")[0])
    asked = {("serde v1.0.0", "target"): {"rc", "unstable"}, ("syn v2.0.0", "host"): {"visit"}, ("glam v0.33.0", "target"): set()}
    assert over_asked(asked, others) == [
        "glam v0.33.0 (target): no other member builds it; drop it",
        "serde v1.0.0 (target): asks for ['unstable'], which no other member uses",
    ]
