"""The package's layers: no module imports a higher layer, and no import cycle.

The layers, low to high (``docs/design.md``): the base modules (the version, units, errors, geometry
helpers, parsing helpers, progress), then ``track``, ``wind``, ``boat``, ``routing``,
``course``, ``planning``, ``analysis``, ``strategy``, ``bands``, ``live``, ``report``,
``commands`` and, on top, the API facade, the CLI and the package namespace.  A module may
import its own package and any lower layer, lazily (inside a function) or for typing alike.
"""

from __future__ import annotations

import ast
from collections.abc import Iterator
from pathlib import Path

from tests.conftest import ROOT

PACKAGE = ROOT / "sailroute"
BASE = (
    "_version",
    "units",
    "errors",
    "geo",
    "timeutil",
    "textin",
    "yamlfile",
    "numerics",
    "backend",
    "checks",
    "parallel",
    "outdir",
    "progress",
    "tabular",
    "nmea",
    "jit",
)
LAYERS: tuple[tuple[str, ...], ...] = (
    BASE,
    ("track",),
    ("wind",),
    ("boat",),
    ("routing",),
    ("course",),
    ("planning",),
    ("analysis",),
    ("strategy",),
    ("bands",),
    ("live",),
    ("report",),
    ("commands",),
    ("api", "cli", "cli_values", "__main__", "__init__"),
)
RANK = {name: k for k, names in enumerate(LAYERS) for name in names}


def _unit(module: str) -> str:
    """The layer unit of a dotted module name: its top-level package or module."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "__init__"


def _modules() -> Iterator[tuple[str, Path]]:
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(ROOT).with_suffix("")
        parts = rel.parts[:-1] if rel.name == "__init__" else rel.parts
        yield ".".join(parts), path


def _imports(module: str, path: Path) -> Iterator[tuple[int, str, tuple[str, ...]]]:
    """(line, imported module, imported names) of every sailroute import in a file."""
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.split(".")[0] == "sailroute":
                    yield node.lineno, alias.name, ()
        elif isinstance(node, ast.ImportFrom) and node.module is not None:
            target = node.module
            if node.level:  # relative import: resolve against this module's package
                base = module.split(".")
                keep = len(base) - node.level + (path.name == "__init__.py")
                target = ".".join([*base[:keep], node.module])
            if target.split(".")[0] == "sailroute":
                yield node.lineno, target, tuple(a.name for a in node.names)


def test_every_module_belongs_to_a_layer() -> None:
    units = {_unit(m) for m, _ in _modules() if m != "sailroute"}
    assert units <= set(RANK), f"place these in LAYERS: {sorted(units - set(RANK))}"


def test_no_import_goes_up_the_layers() -> None:
    bad = []
    for module, path in _modules():
        src = _unit(module)
        for line, target, _ in _imports(module, path):
            dst = _unit(target)
            if dst == src:
                continue
            peers = src in BASE or src in LAYERS[-1]  # base modules, and the top, use each other
            if RANK[dst] > RANK[src] or (RANK[dst] == RANK[src] and not peers):
                bad.append(f"{path.relative_to(ROOT)}:{line}: {src} imports {target}")
    assert not bad, "imports up the layers:\n" + "\n".join(bad)


def _graph() -> dict[str, set[str]]:
    """Module -> the package modules it imports (a name imported from a package counts as
    its submodule when there is one)."""
    known = {m for m, _ in _modules()}
    graph: dict[str, set[str]] = {}
    for module, path in _modules():
        deps = set()
        for _, target, names in _imports(module, path):
            cands = (*(f"{target}.{n}" for n in names), target)
            dep = next((c for c in cands if c in known and c != module), None)
            if dep is not None:
                deps.add(dep)
        graph[module] = deps
    return graph


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Tarjan's strongly connected components of two or more modules: the import cycles."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    cycles: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                cycles.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return cycles


def test_no_import_cycle_between_modules() -> None:
    assert not _cycles(_graph()), f"import cycles: {_cycles(_graph())}"


def test_the_cycle_finder_finds_a_cycle() -> None:
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
