"""Reading the project's YAML files (courses, boats) with line numbers for error messages.

One reader for every YAML input, so that they share scalar rules and errors:
:class:`YamlLoader` reads YAML 1.2 core-schema scalars, and :func:`read_yaml` returns
the document with the line of every key path and any key given twice.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from sailroute.errors import InputError


class YamlLoader(yaml.SafeLoader):
    """PyYAML's safe loader with YAML 1.2 core-schema scalars.

    YAML 1.1 (PyYAML's default) reads ``4_2`` as the integer 42, ``12:10`` as 730
    (base 60), ``010`` as 8 and ``no``/``off`` as false, which silently renames marks
    such as the thesis's ``4_2``.  Here only decimal numbers are numbers and only
    ``true``/``false`` are booleans; everything else is text.
    """


_DROP = {"tag:yaml.org,2002:int", "tag:yaml.org,2002:float", "tag:yaml.org,2002:bool"}
YamlLoader.yaml_implicit_resolvers = {
    k: [r for r in v if r[0] not in _DROP]
    for k, v in yaml.SafeLoader.yaml_implicit_resolvers.items()
}
YamlLoader.add_implicit_resolver(
    "tag:yaml.org,2002:bool", re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$"), list("tTfF")
)
YamlLoader.add_implicit_resolver(
    "tag:yaml.org,2002:int", re.compile(r"^[-+]?[0-9]+$"), list("-+0123456789")
)
YamlLoader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"^(?:[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?"
               r"|[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))$"),
    list("-+0123456789."),
)


def _construct_int(loader: YamlLoader, node: yaml.ScalarNode) -> int:
    """Decimal integer (the resolver above lets only ``[-+]?[0-9]+`` through)."""
    return int(loader.construct_scalar(node), 10)


YamlLoader.add_constructor("tag:yaml.org,2002:int", _construct_int)


def join_path(path: str, key: str | int) -> str:
    """Dotted key path: ``join_path("legs", 2) == "legs[2]"``, ``join_path("a", "b") == "a.b"``."""
    if isinstance(key, int):
        return f"{path}[{key}]"
    return f"{path}.{key}" if path else str(key)


@dataclass(frozen=True)
class Duplicate:
    """A key given twice in one mapping: its key path and both 1-based lines."""

    path: str
    key: str
    first_line: int
    line: int


@dataclass(frozen=True, eq=False)
class YamlDoc:
    """A parsed YAML file.

    Attributes
    ----------
    data : Any
        The document (None for an empty file).
    lines : dict of str to int
        Key path (``"marks.top.lat"``, ``"legs[2]"``) -> 1-based line.
    duplicates : tuple of Duplicate
        Keys given twice in the same mapping (the later value wins in ``data``).
    """

    data: Any
    lines: dict[str, int]
    duplicates: tuple[Duplicate, ...]


def _key_lines(node: yaml.Node, path: str, out: dict[str, int], dup: list[Duplicate]) -> None:
    if isinstance(node, yaml.MappingNode):
        seen: dict[str, int] = {}
        for k, v in node.value:
            key = str(k.value)
            line = k.start_mark.line + 1
            p = join_path(path, key)
            if key in seen:
                dup.append(Duplicate(p, key, seen[key], line))
            seen[key] = line
            out[p] = line
            _key_lines(v, p, out, dup)
    elif isinstance(node, yaml.SequenceNode):
        for i, item in enumerate(node.value):
            p = join_path(path, i)
            out[p] = item.start_mark.line + 1
            _key_lines(item, p, out, dup)


def read_yaml(path: str | Path, *, what: str = "course file", hint: str = "") -> YamlDoc:
    """Read a YAML file, turning every failure into an :class:`InputError`.

    Parameters
    ----------
    path : str or Path
        The file.
    what : str
        What the file is, for messages (``"course file"``, ``"boat file"``).
    hint : str
        Added to the "not found" message, e.g. what to do instead.

    Returns
    -------
    YamlDoc

    Raises
    ------
    InputError
        Missing file, a folder, not UTF-8, unreadable, or a YAML syntax error (with
        line and column).
    """
    p = Path(path)
    if not p.exists():
        raise InputError(f"{p}: {what} not found" + (f"; {hint}" if hint else ""))
    if p.is_dir():
        raise InputError(f"{p}: is a folder; expected a {what} (.yaml)")
    try:
        text = p.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise InputError(f"{p}: not a UTF-8 text file ({exc.reason}); save it as UTF-8") from None
    except OSError as exc:
        raise InputError(f"{p}: cannot read the {what} ({exc.strerror or exc})") from None
    try:
        node = yaml.compose(text, Loader=YamlLoader)
        data = yaml.load(text, Loader=YamlLoader)  # YamlLoader is a SafeLoader
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        where = f"{p}:{mark.line + 1}:{mark.column + 1}" if mark is not None else str(p)
        problem = exc.problem or "invalid YAML"
        cm = exc.context_mark
        if exc.context and cm is not None and (mark is None or cm.line != mark.line):
            problem += f" ({exc.context} at line {cm.line + 1}, column {cm.column + 1})"
        elif exc.context:
            problem += f" ({exc.context})"
        raise InputError(
            f"{where}: YAML syntax error: {problem}; check indentation, colons, quotes and "
            "brackets on this line and the ones before"
        ) from None
    except yaml.YAMLError as exc:
        raise InputError(f"{p}: YAML syntax error: {exc}") from None
    lines: dict[str, int] = {}
    dup: list[Duplicate] = []
    if node is not None:
        _key_lines(node, "", lines, dup)
    return YamlDoc(data, lines, tuple(dup))
