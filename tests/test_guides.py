"""The documentation is checked like code.

* Every guide in docs/guides/ runs: its fenced blocks whose info string is exactly `sh` are
  joined in order and run by one `bash -euo pipefail` from the repository root, with
  target/release (or the directory of $AGRISIM_BIN) and .venv/bin first on PATH and a fresh
  empty directory in $GUIDE_TMP for the guide's outputs. The run must exit 0 within the
  guide's time limit, and every file a block announces with a `# writes PATH` comment must
  exist afterwards. Blocks meant only to be read use the info string `sh-notest`; they are
  rare (at most two per guide) and the guide says why each is not run.
* README.md has at most 300 lines.
* Every relative link (and image) in README.md and docs/**/*.md points to a file that exists,
  and a `#fragment` into a Markdown file names one of its headings (GitHub's anchors).
* docs/README.md links every page under docs/.

A guide can say, in an HTML comment, what its test needs: `<!-- guide-test: timeout=600 -->`
(seconds; default 300) or `<!-- guide-test: needs=netns -->` (skipped, with the reason, where
a private network namespace cannot be made, as the ROS 2 bridge tests are).
"""

from __future__ import annotations

import os
import re
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
DOCS = REPO / "docs"
GUIDES = sorted((DOCS / "guides").glob("*.md"))
README_MAX_LINES = 300
DEFAULT_TIMEOUT = 300.0
MAX_NOTEST_BLOCKS = 2

FENCE = re.compile(r"^(?P<indent> {0,3})(?P<fence>`{3,}|~{3,})(?P<info>.*)$")
WRITES = re.compile(r"^\s*#\s*writes:?\s+(?P<paths>.+?)\s*$")
DIRECTIVE = re.compile(r"<!--\s*guide-test:(?P<body>.*?)-->", re.S)
INLINE_CODE = re.compile(r"(`+).+?\1")
LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*<?(?P<target>[^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
REFERENCE_LINK = re.compile(r"^\s{0,3}\[[^\]]+\]:\s*<?(?P<target>\S+?)>?(?:\s+\"[^\"]*\")?\s*$")
HEADING = re.compile(r"^\s{0,3}(#{1,6})\s+(?P<text>.*?)\s*#*\s*$")


# -- Markdown helpers -------------------------------------------------------------------------


def fenced_blocks(text: str) -> list[tuple[str, str]]:
    """(info string, body) of every fenced code block, in order."""
    blocks: list[tuple[str, str]] = []
    lines = text.splitlines()
    i = 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m or (m["fence"][0] == "`" and "`" in m["info"]):
            i += 1
            continue
        fence, info, body = m["fence"], m["info"].strip(), []
        i += 1
        while i < len(lines):
            close = FENCE.match(lines[i])
            if close and close["fence"][0] == fence[0] and len(close["fence"]) >= len(fence) and not close["info"].strip():
                break
            body.append(lines[i])
            i += 1
        blocks.append((info, "\n".join(body)))
        i += 1
    return blocks


def sh_blocks(text: str) -> list[str]:
    """The bodies of the blocks whose info string is exactly `sh`: the commands a guide runs."""
    return [body for info, body in fenced_blocks(text) if info == "sh"]


def declared_outputs(blocks: list[str]) -> list[str]:
    """The paths the blocks announce with `# writes PATH [PATH...]` comments (unexpanded)."""
    return [p for b in blocks for line in b.splitlines() if (m := WRITES.match(line)) for p in m["paths"].split()]


def directives(text: str) -> dict[str, str]:
    """`<!-- guide-test: key=value ... -->` settings of a guide."""
    out: dict[str, str] = {}
    for m in DIRECTIVE.finditer(text):
        for item in m["body"].split():
            key, _, value = item.partition("=")
            out[key.strip()] = value.strip()
    return out


def prose_lines(text: str, strip_code: bool = True) -> list[tuple[int, str]]:
    """(line number, line) of the lines outside fenced code blocks, inline code removed
    (or, with `strip_code=False`, kept)."""
    out, fence = [], None
    for n, line in enumerate(text.splitlines(), 1):
        m = FENCE.match(line)
        if fence is None and m:
            fence = m["fence"]
            continue
        if fence is not None:
            if m and m["fence"][0] == fence[0] and len(m["fence"]) >= len(fence) and not m["info"].strip():
                fence = None
            continue
        out.append((n, INLINE_CODE.sub("", line) if strip_code else line))
    return out


def github_anchors(text: str) -> set[str]:
    """The anchors GitHub gives a page's headings: lower case, punctuation dropped, spaces to
    hyphens, a repeated anchor numbered -1, -2, ..."""
    seen: dict[str, int] = {}
    anchors = set()
    for _, line in prose_lines(text, strip_code=False):
        m = HEADING.match(line)
        if not m:
            continue
        title = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", m["text"])  # a link's text only
        slug = re.sub(r"[^\w\- ]", "", title.strip().lower()).replace(" ", "-")
        n = seen.get(slug, 0)
        seen[slug] = n + 1
        anchors.add(slug if n == 0 else f"{slug}-{n}")
    return anchors


def broken_links(page: Path, root: Path = REPO) -> list[str]:
    """The relative links of a Markdown page that do not resolve: a missing file, a path
    that leaves the repository, or a missing heading anchor in a Markdown target."""
    text = page.read_text()
    problems = []
    for n, line in prose_lines(text):
        targets = [m["target"] for m in LINK.finditer(line)]
        if m := REFERENCE_LINK.match(line):
            targets.append(m["target"])
        for target in targets:
            if re.match(r"^[a-zA-Z][a-zA-Z0-9+.-]*:", target):  # http:, https:, mailto:, ...
                continue
            path_part, _, fragment = target.partition("#")
            dest = page if not path_part else (page.parent / path_part).resolve()
            where = f"{page.relative_to(root) if page.is_relative_to(root) else page}:{n}: {target}"
            if not dest.is_relative_to(root.resolve()):
                problems.append(f"{where}: leaves the repository")
            elif not dest.exists():
                problems.append(f"{where}: no such file")
            elif fragment and dest.suffix == ".md" and fragment not in github_anchors(dest.read_text()):
                problems.append(f"{where}: no heading #{fragment} in {dest.name}")
    return problems


def markdown_pages() -> list[Path]:
    return [REPO / "README.md", *sorted(DOCS.rglob("*.md"))]


# -- the checks of the checker ----------------------------------------------------------------


def test_only_blocks_marked_sh_are_run():
    text = "\n".join(
        [
            "```sh",
            "echo one",
            "# writes $GUIDE_TMP/a $GUIDE_TMP/b",
            "```",
            "```sh-notest",
            "ros2 run foo bar",
            "```",
            "````sh",
            "echo two",
            "```",
            "still two",
            "````",
            "```bash",
            "echo never",
            "```",
            "~~~sh",
            "echo three",
            "~~~",
            "```toml",
            "x = 1",
            "```",
        ]
    )
    blocks = sh_blocks(text)
    assert blocks == ["echo one\n# writes $GUIDE_TMP/a $GUIDE_TMP/b", "echo two\n```\nstill two", "echo three"]
    assert declared_outputs(blocks) == ["$GUIDE_TMP/a", "$GUIDE_TMP/b"]


def test_the_link_check_finds_missing_files_and_anchors(tmp_path):
    (tmp_path / "docs").mkdir()
    (tmp_path / "other.md").write_text("# Other page\n\n## A `code` heading, with punctuation!\n")
    page = tmp_path / "docs" / "page.md"
    page.write_text(
        "# Page\n\n"
        "[fine](../other.md) [fine too](../other.md#a-code-heading-with-punctuation) [here](#page)\n"
        "![missing picture](pic.png) [gone](../nowhere.md) [bad anchor](../other.md#nothing)\n"
        "[web](https://example.org/x.md) `[not a link](inline-code.md)`\n"
        "[outside](../../../etc/passwd)\n"
        "```sh\ncat [not](a-link.md)\n```\n"
        "[ref]: ../missing-ref.md\n"
    )
    problems = broken_links(page, root=tmp_path)
    assert [p.split(": ", 1)[1] for p in problems] == [
        "pic.png: no such file",
        "../nowhere.md: no such file",
        "../other.md#nothing: no heading #nothing in other.md",
        "../../../etc/passwd: leaves the repository",
        "../missing-ref.md: no such file",
    ], problems


def test_github_anchors_number_repeated_headings():
    assert github_anchors("# Tour\n## Run it\n## Run it\n```sh\n# not a heading\n```\n### ROS 2: lockstep & realtime\n") == {
        "tour",
        "run-it",
        "run-it-1",
        "ros-2-lockstep--realtime",
    }


# -- the documentation ------------------------------------------------------------------------


def test_readme_is_short():
    n = len((REPO / "README.md").read_text().splitlines())
    assert n <= README_MAX_LINES, f"README.md has {n} lines; move detail into docs/ (limit {README_MAX_LINES})"


def test_relative_links_resolve():
    problems = [p for page in markdown_pages() for p in broken_links(page)]
    assert not problems, "broken links:\n" + "\n".join(problems)


def test_the_docs_index_links_every_page():
    index = DOCS / "README.md"
    linked = set()
    for _, line in prose_lines(index.read_text()):
        for m in LINK.finditer(line):
            target = m["target"].partition("#")[0]
            if target and not re.match(r"^[a-zA-Z][a-zA-Z0-9+.-]*:", target):
                linked.add((index.parent / target).resolve())
    missing = [str(p.relative_to(REPO)) for p in sorted(DOCS.rglob("*.md")) if p != index and p.resolve() not in linked]
    assert not missing, f"docs/README.md does not link: {missing}"


def test_there_are_guides():
    names = {p.stem for p in GUIDES}
    assert {"greenhouse", "swap-component", "ros2-node", "python-policy", "add-fmu", "add-benchmark"} <= names, names


@pytest.mark.parametrize("guide", GUIDES, ids=[p.stem for p in GUIDES])
def test_guide_shape(guide):
    text = guide.read_text()
    blocks = sh_blocks(text)
    assert blocks, f"{guide.name}: no ```sh block to run"
    assert declared_outputs(blocks), f"{guide.name}: no `# writes PATH` comment: say what the guide produces"
    notest = [info for info, _ in fenced_blocks(text) if info == "sh-notest"]
    assert len(notest) <= MAX_NOTEST_BLOCKS, f"{guide.name}: {len(notest)} sh-notest blocks; run the commands instead"
    for info, _ in fenced_blocks(text):
        assert info not in ("bash", "shell", "console"), f"{guide.name}: a ```{info} block: use sh (run) or sh-notest"


# -- running the guides -----------------------------------------------------------------------


def agrisim_binary() -> Path:
    return Path(os.environ.get("AGRISIM_BIN", REPO / "target/release/agrisim")).resolve()


def netns_problem() -> str | None:
    import netns

    return netns.available()


@pytest.mark.parametrize("guide", GUIDES, ids=[p.stem for p in GUIDES])
def test_guide_runs(guide, tmp_path):
    text = guide.read_text()
    settings = directives(text)
    if "netns" in settings.get("needs", "").split(",") and (why := netns_problem()):
        pytest.skip(f"{guide.name} needs a private network namespace: {why}")
    exe = agrisim_binary()
    assert exe.is_file(), f"{exe} not built: run scripts/setup (or set AGRISIM_BIN)"
    blocks = sh_blocks(text)
    out = tmp_path / "guide"
    out.mkdir()
    env = dict(os.environ)
    env["PATH"] = os.pathsep.join([str(exe.parent), str(REPO / ".venv" / "bin"), env.get("PATH", "")])
    env["GUIDE_TMP"] = str(out)
    script = "\n".join(f"# --- block {i + 1} of {guide.name}\n{b}" for i, b in enumerate(blocks))
    timeout = float(settings.get("timeout", DEFAULT_TIMEOUT))
    try:
        r = subprocess.run(["bash", "-euo", "pipefail", "-c", script], cwd=REPO, env=env, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired as e:
        pytest.fail(f"{guide.name}: still running after {timeout:.0f} s\n{e.stdout or ''}\n{e.stderr or ''}")
    tail = f"\n--- stdout (end)\n{r.stdout[-4000:]}\n--- stderr (end)\n{r.stderr[-4000:]}"
    assert r.returncode == 0, f"{guide.name}: exit status {r.returncode}{tail}"
    for declared in declared_outputs(blocks):
        path = Path(declared.replace("${GUIDE_TMP}", str(out)).replace("$GUIDE_TMP", str(out)).strip("\"'"))
        if not path.is_absolute():
            path = REPO / path
        assert path.exists(), f"{guide.name}: says it writes {declared}, but {path} does not exist{tail}"
