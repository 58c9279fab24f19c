"""Architecture check: no import cycles between the modules of a crate.

For every workspace crate (from `cargo metadata --no-deps`), the module tree of each of its
source targets (lib, bin) is read from the crate root by following `mod x;` declarations
(and inline `mod x { ... }` blocks). Every path reference is resolved to the module it names:
`use` trees and paths in code that start with `crate::`, `$crate::`, `super::` or `self::`.
A reference from module `a::b::x` to `a::b::y::...` is an edge x -> y between the siblings x
and y at level `a::b` (the children of one module); references between a module and its own
ancestors or descendants are not edges (a parent declares and re-exports its children, a child
may use its parent's items). Names a module re-exports (`pub use child::Name;` or
`pub use child::*;`) are followed to the child that defines them, so `crate::Store` counts as
a use of the module `store` when the crate root re-exports `store::Store`.

Each level's graph must be acyclic; a failure prints every cycle with the crate, the level and
one reference (file:line) for each edge. Comments, string and character literals are removed
before scanning, so prose like "see crate::x" does not count. Test-only code counts too: a
`#[cfg(test)] mod tests` that uses a sibling is part of its module. Standard library only.
"""

from __future__ import annotations

import json
import re
import subprocess
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
SOURCE_KINDS = {"lib", "rlib", "cdylib", "dylib", "staticlib", "proc-macro", "bin"}
IDENT = r"[A-Za-z_][A-Za-z0-9_]*"
PATH_START = re.compile(r"(?<![A-Za-z0-9_:])(\$crate|crate|super|self)\s*::")
MOD_DECL = re.compile(rf"(?<![A-Za-z0-9_])mod\s+(r#)?({IDENT})\s*([;{{])")


# ---------------------------------------------------------------------------- lexing


def strip_comments_and_literals(src: str) -> str:
    """`src` with comments, string, byte-string, raw-string and char literals replaced by
    spaces (newlines kept, so offsets and line numbers stay valid). Lifetimes are kept."""
    out = list(src)
    n = len(src)
    i = 0

    def blank(a: int, b: int) -> None:
        for k in range(a, min(b, n)):
            if out[k] != "\n":
                out[k] = " "

    while i < n:
        c = src[i]
        if src.startswith("//", i):
            j = src.find("\n", i)
            j = n if j < 0 else j
            blank(i, j)
            i = j
        elif src.startswith("/*", i):
            depth, j = 1, i + 2
            while j < n and depth:
                if src.startswith("/*", j):
                    depth, j = depth + 1, j + 2
                elif src.startswith("*/", j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            blank(i, j)
            i = j
        elif (m := re.compile(r'(b|c)?r(#*)"').match(src, i)) and (i == 0 or not (src[i - 1].isalnum() or src[i - 1] == "_")):
            end = '"' + m.group(2)
            j = src.find(end, m.end())
            j = n if j < 0 else j + len(end)
            blank(i, j)
            i = j
        elif c == '"' or (c in "bc" and src.startswith('"', i + 1) and (i == 0 or not (src[i - 1].isalnum() or src[i - 1] == "_"))):
            j = i + (1 if c == '"' else 2)
            while j < n and src[j] != '"':
                j += 2 if src[j] == "\\" else 1
            blank(i, j + 1)
            i = j + 1
        elif c == "'" or (c == "b" and src.startswith("'", i + 1) and (i == 0 or not (src[i - 1].isalnum() or src[i - 1] == "_"))):
            q = i if c == "'" else i + 1
            if src.startswith("\\", q + 1):  # escaped char literal: '\n', '\'', '\u{..}'
                j = q + 3
                while j < n and src[j] != "'":
                    j += 1
                blank(i, j + 1)
                i = j + 1
            elif q + 2 < n and src[q + 2] == "'":  # plain char literal 'x'
                blank(i, q + 3)
                i = q + 3
            else:  # a lifetime or label: 'a
                i = q + 1
        else:
            i += 1
    return "".join(out)


def matching_brace(text: str, open_at: int) -> int:
    depth = 0
    for k in range(open_at, len(text)):
        if text[k] == "{":
            depth += 1
        elif text[k] == "}":
            depth -= 1
            if depth == 0:
                return k
    return len(text)


USE_ITEM = re.compile(rf"(?<![A-Za-z0-9_])(pub\s*(\([^)]*\))?\s*)?use\s+([^;]*);")
ALIAS = re.compile(rf"^(.*?)\s+as\s+({IDENT}|_)$")


def use_paths(tree: str) -> list[tuple[list[str], str | None]]:
    """Expanded paths of a `use` tree, each with the name it binds (None for globs)."""
    tree = tree.strip().lstrip(":")
    result: list[tuple[list[str], str | None]] = []

    def parse(s: str, prefix: list[str]) -> None:
        s = s.strip()
        if not s:
            return
        brace = s.find("{")
        if brace < 0:
            alias = None
            if m := ALIAS.match(s):
                s, alias = m.group(1), m.group(2)
            parts = [p.strip() for p in s.split("::") if p.strip()]
            if parts and parts[-1] == "self":
                parts = parts[:-1]
                bind = alias or (parts[-1] if parts else (prefix[-1] if prefix else None))
            elif parts and parts[-1] == "*":
                bind = None
            else:
                bind = alias or (parts[-1] if parts else None)
            result.append((prefix + parts, bind))
            return
        head = [p.strip() for p in s[:brace].split("::") if p.strip()]
        inner = s[brace + 1 : s.rfind("}")]
        depth, start = 0, 0
        for k, ch in enumerate(inner + ","):
            if ch == "{":
                depth += 1
            elif ch == "}":
                depth -= 1
            elif ch == "," and depth == 0:
                parse(inner[start:k], prefix + head)
                start = k + 1

    parse(tree, [])
    return result


# ---------------------------------------------------------------------------- module tree


@dataclass
class Module:
    path: tuple[str, ...]
    file: Path
    children: set[str] = field(default_factory=set)
    # name -> absolute path it re-exports (`pub use`), and globs re-exported (`pub use x::*`).
    reexports: dict[str, tuple[str, ...]] = field(default_factory=dict)
    glob_reexports: list[tuple[str, ...]] = field(default_factory=list)
    items: set[str] = field(default_factory=set)


@dataclass
class Ref:
    source: tuple[str, ...]
    target: tuple[str, ...]
    file: Path
    line: int


ITEM_DEF = re.compile(rf"(?<![A-Za-z0-9_])(?:struct|enum|union|trait|type|fn|const|static|macro_rules!)\s+({IDENT})")


class Crate:
    """The module tree and path references of one crate target."""

    def __init__(self, root_file: Path):
        self.root_file = root_file
        self.modules: dict[tuple[str, ...], Module] = {}
        self.refs: list[Ref] = []
        self.pending_uses: list[tuple[tuple[str, ...], list[str], str | None, bool, Path, int]] = []
        self._load_file(root_file, (), owner_dir=root_file.parent)
        for mod_path, raw, bind, public, file, line in self.pending_uses:
            target = self._absolute(mod_path, raw)
            if target is None:
                continue
            if public:
                module = self.modules[mod_path]
                if bind is None and raw and raw[-1] == "*":
                    module.glob_reexports.append(tuple(target[:-1]))
                elif bind not in (None, "_"):
                    module.reexports[bind] = tuple(target)
            self.refs.append(Ref(mod_path, tuple(t for t in target if t != "*"), file, line))

    # -- loading

    def _load_file(self, file: Path, path: tuple[str, ...], owner_dir: Path) -> None:
        raw = file.read_text(encoding="utf-8", errors="replace")
        text = strip_comments_and_literals(raw)
        self._load_span(raw, text, 0, len(text), file, path, owner_dir)

    def _load_span(self, raw: str, text: str, start: int, end: int, file: Path, path: tuple[str, ...], owner_dir: Path) -> None:
        module = self.modules.setdefault(path, Module(path, file))
        # Inline modules: scanned as their own modules; their spans are skipped here.
        inline: list[tuple[int, int]] = []
        pos = start
        while (m := MOD_DECL.search(text, pos, end)) is not None:
            name = m.group(2)
            module.children.add(name)
            if m.group(3) == ";":
                child_file = self._child_file(raw, m.start(), owner_dir, name)
                if child_file is not None:
                    # mod.rs and #[path] files own their directory; x.rs owns x/.
                    mod_rs = child_file.name == "mod.rs" or self._path_attr(raw, m.start()) is not None
                    self._load_file(child_file, path + (name,), child_file.parent if mod_rs else child_file.parent / child_file.stem)
                pos = m.end()
            else:
                close = matching_brace(text, m.end() - 1)
                self._load_span(raw, text, m.end(), close, file, path + (name,), owner_dir / name)
                inline.append((m.start(), close + 1))
                pos = close + 1
        for a, b in _complement(start, end, inline):
            self._scan(text[a:b], a, text, file, path, module)

    @staticmethod
    def _path_attr(raw: str, at: int) -> str | None:
        """The `#[path = "..."]` right before the `mod` at `at` (read from the raw text: the
        stripped one has no strings)."""
        attr = re.search(r'#\[\s*path\s*=\s*"([^"]+)"\s*\]\s*(pub\s*(\([^)]*\))?\s*)?$', raw[max(0, at - 300) : at])
        return attr.group(1) if attr else None

    @classmethod
    def _child_file(cls, raw: str, at: int, owner_dir: Path, name: str) -> Path | None:
        attr = cls._path_attr(raw, at)
        candidates = [owner_dir / attr] if attr else [owner_dir / f"{name}.rs", owner_dir / name / "mod.rs"]
        return next((c for c in candidates if c.is_file()), None)

    def _scan(self, chunk: str, offset: int, text: str, file: Path, path: tuple[str, ...], module: Module) -> None:
        def line_of(k: int) -> int:
            return text.count("\n", 0, offset + k) + 1

        chunk_wo_use = list(chunk)
        for m in USE_ITEM.finditer(chunk):
            public = m.group(1) is not None  # any `pub(...)`: visible to siblings as a re-export
            for raw_path, bind in use_paths(m.group(3)):
                self.pending_uses.append((path, raw_path, bind, public, file, line_of(m.start())))
            for k in range(m.start(), m.end()):
                if chunk_wo_use[k] != "\n":
                    chunk_wo_use[k] = " "
        rest = "".join(chunk_wo_use)
        rest = re.sub(r"pub\s*\(\s*in\s+[^)]*\)", lambda mm: " " * len(mm.group(0)), rest)
        for m in ITEM_DEF.finditer(rest):
            module.items.add(m.group(1))
        for m in PATH_START.finditer(rest):
            segs = [m.group(1)]
            k = m.end()
            while True:
                mm = re.compile(rf"\s*({IDENT})\s*(::)?").match(rest, k)
                if not mm:
                    break
                if mm.group(1) in ("super", "self", "crate") and not (mm.group(1) == "super" and segs[-1] == "super"):
                    break
                segs.append(mm.group(1))
                k = mm.end()
                if not mm.group(2):
                    break
                nxt = re.compile(r"\s*<").match(rest, k)
                if nxt:  # turbofish `x::<T>`
                    break
            self.pending_uses.append((path, segs, None, False, file, line_of(m.start())))

    # -- resolution

    def _absolute(self, here: tuple[str, ...], raw: list[str]) -> list[str] | None:
        """The absolute module path a reference starts with, or None for other crates."""
        if not raw:
            return None
        head = raw[0]
        if head in ("crate", "$crate"):
            return list(raw[1:])
        if head == "super":
            base = list(here)
            k = 0
            while k < len(raw) and raw[k] == "super":
                if not base:
                    return None
                base.pop()
                k += 1
            return base + list(raw[k:])
        if head == "self":
            return list(here) + list(raw[1:])
        if here in self.modules and head in self.modules[here].children:
            return list(here) + list(raw)  # a child of the current module
        return None

    def resolve(self, target: tuple[str, ...], depth: int = 0) -> tuple[str, ...]:
        """Follows re-exports: the deepest module path `target` leads to."""
        cur: tuple[str, ...] = ()
        for k, seg in enumerate(target):
            module = self.modules.get(cur)
            if module is None:
                return cur
            if seg in module.children:
                cur = cur + (seg,)
                continue
            if depth < 16 and seg in module.reexports:
                return self.resolve(module.reexports[seg] + tuple(target[k + 1 :]), depth + 1)
            if depth < 16 and seg not in module.items:
                for glob in module.glob_reexports:
                    g = self.resolve(glob, depth + 1)
                    gm = self.modules.get(g)
                    if gm is not None and (seg in gm.items or seg in gm.reexports or seg in gm.children) and g != cur:
                        return self.resolve(g + (seg,) + tuple(target[k + 1 :]), depth + 1)
            return cur
        return cur

    def sibling_edges(self) -> dict[tuple[str, ...], dict[tuple[str, str], Ref]]:
        """level -> {(from child, to child): one reference}."""
        levels: dict[tuple[str, ...], dict[tuple[str, str], Ref]] = {}
        for ref in self.refs:
            target = self.resolve(ref.target)
            common = 0
            while common < min(len(ref.source), len(target)) and ref.source[common] == target[common]:
                common += 1
            if common == len(ref.source) or common == len(target):
                continue  # ancestor or descendant, not a sibling
            level = ref.source[:common]
            a, b = ref.source[common], target[common]
            levels.setdefault(level, {}).setdefault((a, b), ref)
        return levels


def _complement(start: int, end: int, holes: list[tuple[int, int]]) -> list[tuple[int, int]]:
    out, pos = [], start
    for a, b in sorted(holes):
        if a > pos:
            out.append((pos, a))
        pos = max(pos, b)
    if pos < end:
        out.append((pos, end))
    return out


# ---------------------------------------------------------------------------- cycles


def cycles(edges: dict[tuple[str, str], Ref]) -> list[list[str]]:
    """One simple cycle per strongly connected component with more than one node."""
    graph: dict[str, set[str]] = {}
    for a, b in edges:
        graph.setdefault(a, set()).add(b)
        graph.setdefault(b, set())
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    comps: list[list[str]] = []
    counter = [0]

    def strong(v: str) -> None:  # Tarjan (graphs here are small: recursion is fine)
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                strong(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                comps.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            strong(v)

    result = []
    for comp in comps:
        members = set(comp)
        start = comp[0]
        # Shortest cycle through `start` inside the component (BFS back to start).
        prev: dict[str, str] = {}
        frontier = [start]
        found = None
        while frontier and found is None:
            nxt = []
            for v in frontier:
                for w in sorted(graph[v] & members):
                    if w == start:
                        found = v
                        break
                    if w not in prev:
                        prev[w] = v
                        nxt.append(w)
                if found is not None:
                    break
            frontier = nxt
        path = [found]
        while path[-1] != start:
            path.append(prev[path[-1]])
        result.append(list(reversed(path)) + [start])
    return result


# ---------------------------------------------------------------------------- the test


@lru_cache(maxsize=1)
def workspace_targets() -> list[tuple[str, str, Path]]:
    """(package, target, crate root file) of every source target of every workspace crate."""
    out = subprocess.run(
        ["cargo", "metadata", "--format-version", "1", "--no-deps"],
        cwd=REPO,
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    meta = json.loads(out)
    targets = []
    for pkg in meta["packages"]:
        seen = set()
        for t in pkg["targets"]:
            if SOURCE_KINDS & set(t["kind"]) and t["src_path"] not in seen:
                seen.add(t["src_path"])
                targets.append((pkg["name"], t["name"], Path(t["src_path"])))
    return sorted(targets)


def find_cycles(root_file: Path) -> list[str]:
    """One report per cycle found: the cycle, then every edge among the modules it strongly
    connects (each with one reference), since breaking the cycle shown may leave another."""
    crate = Crate(root_file)
    problems = []
    for level, edges in sorted(crate.sibling_edges().items()):
        for cycle in cycles(edges):
            where = "crate root" if not level else "::".join(level)
            lines = [f"  {' -> '.join(cycle)}  (modules under {where})"]
            component = strongly_connected_with(edges, cycle[0])
            for (a, b), ref in sorted(edges.items()):
                if a in component and b in component:
                    rel = ref.file.relative_to(REPO) if ref.file.is_relative_to(REPO) else ref.file
                    lines.append(f"      {a} -> {b}: {rel}:{ref.line} ({'::'.join(ref.source) or 'crate'} uses {'::'.join(ref.target)})")
            problems.append("\n".join(lines))
    return problems


def strongly_connected_with(edges: dict[tuple[str, str], Ref], node: str) -> set[str]:
    """The modules that both reach `node` and are reached from it."""

    def reach(forward: bool) -> set[str]:
        seen, todo = {node}, [node]
        while todo:
            v = todo.pop()
            for a, b in edges:
                u, w = (a, b) if forward else (b, a)
                if u == v and w not in seen:
                    seen.add(w)
                    todo.append(w)
        return seen

    return reach(True) & reach(False)


def _package_ids() -> list[str]:
    try:
        return sorted({p for p, _, _ in workspace_targets()})
    except (subprocess.CalledProcessError, FileNotFoundError, json.JSONDecodeError) as e:
        return [f"<cargo metadata failed: {e}>"]


@pytest.mark.parametrize("package", _package_ids())
def test_module_graph_is_acyclic(package: str) -> None:
    targets = [(t, root) for p, t, root in workspace_targets() if p == package]
    assert targets, f"no source targets for {package}"
    problems = []
    for target, root in targets:
        for cycle in find_cycles(root):
            problems.append(f"{package} (target {target}):\n{cycle}")
    assert not problems, "module import cycles:\n" + "\n".join(problems)


def test_scanner_ignores_comments_and_strings_and_follows_reexports(tmp_path: Path) -> None:
    src = tmp_path / "src"
    (src / "d").mkdir(parents=True)
    (src / "lib.rs").write_text(
        "//! see crate::b\nmod a;\nmod b;\nmod c;\nmod d;\npub use c::Thing;\n"
        'const S: &str = "crate::b::x";\nconst C: char = \'"\';\n'
    )
    (src / "a.rs").write_text("/* crate::b */ use crate::Thing; fn f<'a>(x: &'a str) {}\n")
    (src / "b.rs").write_text('// crate::a\nconst S: &str = r#"crate::a"#;\n#[cfg(test)]\nmod tests { use super::super::d::y; }\n')
    (src / "c.rs").write_text("pub struct Thing; fn g() { crate::b::h(); }\n")
    (src / "d" / "mod.rs").write_text("mod x;\nmod y;\n")
    (src / "d" / "x.rs").write_text("use super::y::Y;\n")
    (src / "d" / "y.rs").write_text("pub struct Y; fn f() { let _ = super::x::X; }\n")
    edges = Crate(src / "lib.rs").sibling_edges()
    assert set(edges[()]) == {("a", "c"), ("c", "b"), ("b", "d")}
    assert set(edges[("d",)]) == {("x", "y"), ("y", "x")}
    assert cycles(edges[("d",)]) == [["x", "y", "x"]]
    assert cycles(edges[()]) == []
