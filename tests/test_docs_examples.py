"""The examples in the docs run, and print what the pages say they print.

Every fenced block of ``docs/**/*.md`` and ``README.md`` that is a console session
(```` ```console ````: lines ``$ command`` followed by the output it prints) or Python
(```` ```python ````) is run here, in a copy of the project's example folders placed in a
temporary folder (never the checkout): each page's examples in order, in one folder, so a
later command may use the files an earlier one wrote.  A command's standard output must
match the lines under it, where ``...`` stands for any text (as doctest's ELLIPSIS), and
its exit status must be 0; Python blocks must run without an error.  The rules and the
``<!-- docs-test: ... -->`` markers are in docs/design.md (Examples in the docs run).
A failure names the page and line of the command, what the page shows and what the
command printed.
"""

from __future__ import annotations

import difflib
import os
import re
import shutil
import subprocess
import sys
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from tests.conftest import ROOT, SHARED_REAL

PAGES = (*sorted((ROOT / "docs").rglob("*.md")), ROOT / "README.md")
"""The pages whose examples run."""

COPIED = ("courses", "data", "docs", "benchmarks", "tests/data")
"""Folders of the project copied into each example folder (what the examples read)."""

SHELL_LANGS = frozenset({"", "bash", "sh", "shell", "zsh", "console"})
"""Fence languages of shell text: a ``console`` block runs; the others need a marker."""

MARKER_KEYS = frozenset({"skip", "slow", "shared", "file", "exit"})
"""``skip REASON``: not run (why, in words); ``slow``: run under ``-m slow`` only;
``shared``: reads ``../shared`` (skipped without it); ``file NAME``: the block is the
content of file NAME in the page's example folder; ``exit N``: the block's last command
exits N and prints what is shown on stderr."""

TIMEOUT_S = 300.0
"""Longest a command may run before it counts as failed [s]."""

_FENCE = re.compile(r"^(?P<indent>[ \t]*)(?P<ticks>`{3,})(?P<lang>[\w+-]*)[ \t]*$")
_MARKER = re.compile(r"<!--[ \t]*docs-test:(?P<body>.*?)-->[ \t]*$")


@dataclass(frozen=True)
class Block:
    """A fenced block of a page.

    Attributes
    ----------
    page : str
        The page, relative to the project root.
    line : int
        1-based line of the opening fence.
    lang : str
        The fence's language (``""`` when none).
    text : tuple of str
        The block's lines, the fence's indentation removed.
    marks : Mapping of str to str
        The ``<!-- docs-test: ... -->`` marker on the line before the fence
        (blank lines between allowed): key -> value (``""`` without one).
    """

    page: str
    line: int
    lang: str
    text: tuple[str, ...]
    marks: Mapping[str, str] = field(default_factory=dict)

    @property
    def where(self) -> str:
        return f"{self.page}:{self.line}"


@dataclass(frozen=True)
class Command:
    """One ``$ command`` of a console block and the output shown under it.

    ``line`` is the page line of the ``$``; ``output_line`` that of the first output line.
    """

    text: str
    line: int
    output: tuple[str, ...]
    output_line: int


def parse_marker(body: str, where: str) -> dict[str, str]:
    """``"slow; file marks.gpx"`` -> ``{"slow": "", "file": "marks.gpx"}``; ``skip`` takes
    the rest of the marker as its reason.

    Raises
    ------
    ValueError
        An unknown key, or ``skip`` without a reason.
    """
    marks: dict[str, str] = {}
    items = body.strip()
    while items:
        item, _, items = items.partition(";")
        key, _, value = item.strip().partition(" ")
        if key == "skip" and items:  # the reason is the rest, semicolons and all
            value, items = f"{value};{items}", ""
        if key not in MARKER_KEYS:
            raise ValueError(
                f"{where}: unknown docs-test marker {key!r}; expected one of "
                f"{', '.join(sorted(MARKER_KEYS))}"
            )
        marks[key] = value.strip()
    if "skip" in marks and not marks["skip"]:
        raise ValueError(f"{where}: 'skip' needs a reason, e.g. <!-- docs-test: skip why -->")
    return marks


def parse_blocks(text: str, page: str) -> list[Block]:
    """The fenced blocks of a Markdown page's ``text``, with their markers."""
    lines = text.splitlines()
    blocks = []
    i = 0
    while i < len(lines):
        m = _FENCE.match(lines[i])
        if m is None:
            i += 1
            continue
        indent, ticks = len(m["indent"]), m["ticks"]
        end = next(
            (j for j in range(i + 1, len(lines)) if lines[j].strip().startswith(ticks)),
            len(lines),
        )
        body = (_dedent(s, indent) for s in lines[i + 1 : end])
        k = i - 1
        while k >= 0 and not lines[k].strip():
            k -= 1
        marker = _MARKER.search(lines[k]) if k >= 0 else None
        marks = parse_marker(marker["body"], f"{page}:{i + 1}") if marker else {}
        blocks.append(Block(page, i + 1, m["lang"], tuple(body), marks))
        i = end + 1
    return blocks


def _dedent(line: str, indent: int) -> str:
    """``line`` without the fence's indentation (less when it has less)."""
    return line[indent:] if not line[:indent].strip() else line.lstrip()


def read_blocks(path: Path) -> list[Block]:
    """The fenced blocks of a page of the project (:func:`parse_blocks`)."""
    return parse_blocks(path.read_text(encoding="utf-8"), path.relative_to(ROOT).as_posix())


def console_commands(block: Block) -> list[Command]:
    """The ``$ command`` lines of a console block (a line ending in ``\\`` continues on
    the next) and the output lines under each."""
    commands: list[Command] = []
    lines = list(block.text)
    i = 0
    if lines and not lines[0].startswith("$ "):
        raise ValueError(f"{block.where}: a console block starts with a `$ command` line")
    while i < len(lines):
        start = i
        cmd = [lines[i][2:]]
        while cmd[-1].endswith("\\") and i + 1 < len(lines):
            i += 1
            cmd.append(lines[i])
        i += 1
        out_start = i
        while i < len(lines) and not lines[i].startswith("$ "):
            i += 1
        commands.append(
            Command(
                "\n".join(cmd),
                block.line + 1 + start,
                tuple(lines[out_start:i]),
                block.line + 1 + out_start,
            )
        )
    return commands


def ellipsis_match(expected: str, actual: str) -> bool:
    """Whether ``actual`` is ``expected`` with each ``...`` standing for any text (none,
    or several lines), as doctest's ELLIPSIS option."""
    pieces = expected.split("...")
    if len(pieces) == 1:
        return expected == actual
    first, *middle, last = pieces
    if not actual.startswith(first) or not actual.endswith(last):
        return False
    pos, stop = len(first), len(actual) - len(last)
    if pos > stop:
        return False
    for piece in middle:
        found = actual.find(piece, pos, stop)
        if found < 0:
            return False
        pos = found + len(piece)
    return True


def normalized(text: str) -> str:
    """Lines without trailing blanks, no blank lines at the end."""
    return "\n".join(s.rstrip() for s in text.splitlines()).rstrip("\n")


def mismatch(block: Block, cmd: Command, status: int, want: int, got: str, same: bool) -> str:
    """The failure text of one command: page and line, the status when it is not
    ``want``, and unless ``same`` the page's output, the command's (``got``) and their
    difference."""
    shown = "\n".join(cmd.output)
    parts = [f"{block.page}:{cmd.line}: $ {cmd.text}"]
    if status != want:
        parts.append(f"exit status {status}, the page expects {want}")
    if not same:
        end = cmd.output_line + len(cmd.output) - 1
        stream = "stderr" if want else "stdout"
        diff = difflib.unified_diff(
            normalized(shown).splitlines(),
            normalized(got).splitlines(),
            f"{block.page}:{cmd.output_line}-{end}",
            f"what the command printed ({stream})",
            lineterm="",
        )
        parts += [
            f"the page shows ({block.page}:{cmd.output_line}-{end}):",
            shown,
            f"the command printed ({stream}):",
            got,
            "difference ('...' on the page stands for any text):",
            *diff,
        ]
    return "\n".join(parts)


def example_env(bin_dir: Path) -> dict[str, str]:
    """The commands' environment: this interpreter's ``sailroute`` and ``python`` first
    on PATH, importing the package of this tree (as tests/test_gallery.py), matplotlib
    without a display."""
    env = {k: v for k, v in os.environ.items() if not k.startswith("SAILROUTE_")}
    env["PATH"] = f"{bin_dir}{os.pathsep}{env.get('PATH', '')}"
    env["PYTHONPATH"] = str(ROOT)
    env["MPLBACKEND"] = "Agg"
    return env


def run_console(block: Block, work: Path, env: Mapping[str, str]) -> list[str]:
    """Run a console block's commands in ``work``; the failures' texts."""
    problems = []
    commands = console_commands(block)
    for k, cmd in enumerate(commands):
        want = int(block.marks.get("exit", 0) or 0) if k == len(commands) - 1 else 0
        try:
            res = subprocess.run(
                ["bash", "-o", "pipefail", "-c", cmd.text],
                cwd=work,
                env=dict(env),
                capture_output=True,
                text=True,
                timeout=TIMEOUT_S,
            )
        except subprocess.TimeoutExpired:
            problems.append(f"{block.page}:{cmd.line}: $ {cmd.text}\nran over {TIMEOUT_S:g} s")
            continue
        got = res.stderr if want else res.stdout
        same = not cmd.output or ellipsis_match(normalized("\n".join(cmd.output)), normalized(got))
        if res.returncode != want or not same:
            text = mismatch(block, cmd, res.returncode, want, got, same)
            if res.returncode != want and not want:
                text += f"\nstderr:\n{res.stderr}"
            problems.append(text)
    return problems


def run_python(block: Block, work: Path, env: Mapping[str, str], script: Path) -> list[str]:
    """Run a Python block as a script with ``work`` as the working folder."""
    script.write_text("\n".join(block.text) + "\n", encoding="utf-8")
    res = subprocess.run(
        [sys.executable, str(script)],
        cwd=work,
        env=dict(env),
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
    )
    if res.returncode == 0:
        return []
    return [f"{block.where}: the Python example fails (exit {res.returncode}):\n{res.stderr}"]


# --- which blocks run, in which groups ------------------------------------------------


def runnable(block: Block) -> bool:
    """A console or Python block not marked ``skip`` (an mkdocs snippet include, a
    gallery script, runs in tests/test_gallery.py)."""
    if "skip" in block.marks or "file" in block.marks:
        return False
    if block.lang == "python":
        return not (block.text and block.text[0].startswith("--8<--"))
    return block.lang == "console"


@dataclass(frozen=True)
class Group:
    """A page's examples that run together, in order, in one folder: those with the
    same ``slow`` and ``shared`` marks."""

    page: str
    slow: bool
    shared: bool
    blocks: tuple[Block, ...]
    files: tuple[Block, ...]

    @property
    def id(self) -> str:
        tags = [t for t, on in (("slow", self.slow), ("shared", self.shared)) if on]
        return self.page + (f"[{','.join(tags)}]" if tags else "")


def example_groups(pages: Sequence[Path] = PAGES) -> list[Group]:
    """Every page's runnable blocks, grouped by their ``slow``/``shared`` marks."""
    out = []
    for path in pages:
        blocks = read_blocks(path)
        files = tuple(b for b in blocks if "file" in b.marks)
        keys: dict[tuple[bool, bool], list[Block]] = {}
        for b in blocks:
            if runnable(b):
                keys.setdefault(("slow" in b.marks, "shared" in b.marks), []).append(b)
        for (slow, shared), group in sorted(keys.items()):
            out.append(Group(path.relative_to(ROOT).as_posix(), slow, shared, tuple(group), files))
    return out


def _params() -> Iterator[object]:
    for g in example_groups():
        marks: list[pytest.MarkDecorator] = []
        if g.slow:
            marks.append(pytest.mark.slow)
        if g.shared:
            marks += [
                pytest.mark.shared,
                pytest.mark.skipif(
                    not SHARED_REAL.is_dir(), reason="../shared/data/real not present"
                ),
            ]
        yield pytest.param(g, id=g.id, marks=marks)


def example_folder(tmp: Path) -> Path:
    """A folder with copies of :data:`COPIED`, ``../shared`` beside it when the project
    has one, and ``.venv/bin`` pointing at this interpreter's scripts."""
    work = tmp / "work"
    for name in COPIED:
        shutil.copytree(ROOT / name, work / name, ignore=shutil.ignore_patterns("__pycache__"))
    shared = ROOT.parent / "shared"
    if shared.is_dir():
        (tmp / "shared").symlink_to(shared, target_is_directory=True)
    (work / ".venv").mkdir()
    (work / ".venv" / "bin").symlink_to(Path(sys.executable).parent, target_is_directory=True)
    return work


@pytest.mark.cli
@pytest.mark.parametrize("group", list(_params()))
def test_docs_examples(group: Group, tmp_path: Path) -> None:
    work = example_folder(tmp_path)
    env = example_env(Path(sys.executable).parent)
    for f in group.files:
        (work / f.marks["file"]).write_text("\n".join(f.text) + "\n", encoding="utf-8")
    problems: list[str] = []
    for b in group.blocks:
        if b.lang == "console":
            problems += run_console(b, work, env)
        else:
            problems += run_python(b, work, env, tmp_path / f"example-{b.line}.py")
    assert not problems, "\n\n".join(problems)


# --- every shell block runs or says why -----------------------------------------------


def test_every_shell_block_runs_or_says_why() -> None:
    """A block of shell text is a ``console`` block (it runs), or says with a marker why
    it does not; ``text`` is for what is not typed at a prompt (synopses, diagrams)."""
    unmarked = [
        f"{b.where}: ```{b.lang} block: write it as ```console with `$ ` before each "
        "command (it then runs), as ```text when it is not typed at a prompt, or put "
        "<!-- docs-test: skip WHY --> before it"
        for path in PAGES
        for b in read_blocks(path)
        if b.lang in SHELL_LANGS and b.lang != "console" and not b.marks
    ]
    assert not unmarked, "\n".join(unmarked)


# --- the runner itself ----------------------------------------------------------------


@pytest.mark.parametrize(
    ("expected", "actual", "match"),
    [
        ("a\nb", "a\nb", True),
        ("a\nb", "a\nc", False),
        ("a ... c", "a b b c", True),
        ("...\nwrote x", "notes\nmore\nwrote x", True),
        ("...\nwrote x", "wrote x", False),  # the line break before `wrote` is text
        ("start\n...\nend", "start\nend", False),
        ("start\n...\nend", "start\n\nend", True),
        ("ab...ba", "aba", False),  # the two ends may not overlap
        ("x...y...z", "x1y2z", True),
        ("x...y...z", "x1z2y", False),
    ],
)
def test_ellipsis_match_is_doctests(expected: str, actual: str, match: bool) -> None:
    assert ellipsis_match(expected, actual) is match


def test_a_page_is_read_into_commands_outputs_and_markers() -> None:
    text = (
        "Intro\n\n<!-- docs-test: slow; exit 2 -->\n\n```console\n"
        "$ sailroute plan a.yaml \\\n      -o out\nline 1\n...\n$ ls\n```\n"
        "\n   ```text\n   synopsis\n   ```\n"
    )
    blocks = parse_blocks(text, "docs/x.md")
    assert [(b.line, b.lang, b.marks) for b in blocks] == [
        (5, "console", {"slow": "", "exit": "2"}),
        (13, "text", {}),
    ]
    assert blocks[1].text == ("synopsis",)
    cmds = console_commands(blocks[0])
    assert [(c.text, c.line, c.output, c.output_line) for c in cmds] == [
        ("sailroute plan a.yaml \\\n      -o out", 6, ("line 1", "..."), 8),
        ("ls", 10, (), 11),
    ]


@pytest.mark.parametrize(
    ("body", "message"),
    [
        ("slw", "docs/x.md:3: unknown docs-test marker 'slw'; expected one of exit, file,"),
        ("skip", "docs/x.md:3: 'skip' needs a reason"),
    ],
)
def test_a_bad_marker_is_named(body: str, message: str) -> None:
    with pytest.raises(ValueError, match=re.escape(message)):
        parse_blocks(f"x\n<!-- docs-test: {body} -->\n```console\n$ ls\n```\n", "docs/x.md")


def test_a_failure_names_the_page_line_and_both_outputs(tmp_path: Path) -> None:
    text = "# Page\n\n```console\n$ printf 'one\\ntwo\\n'\none\nthree\n$ exit 3\n```\n"
    (block,) = parse_blocks(text, "docs/x.md")
    problems = run_console(block, tmp_path, example_env(Path(sys.executable).parent))
    assert len(problems) == 2
    first = problems[0].splitlines()
    assert first[0] == "docs/x.md:4: $ printf 'one\\ntwo\\n'"
    assert first[1:7] == [
        "the page shows (docs/x.md:5-6):",
        "one",
        "three",
        "the command printed (stdout):",
        "one",
        "two",
    ]
    assert "-three" in first and "+two" in first
    assert problems[1].splitlines()[:2] == [
        "docs/x.md:7: $ exit 3",
        "exit status 3, the page expects 0",
    ]
