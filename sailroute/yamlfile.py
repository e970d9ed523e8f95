"""Reading the project's YAML files (courses, boats) with line numbers for error messages.

One reader for every YAML input, so that they share scalar rules and errors:
:class:`YamlLoader` reads YAML 1.2 core-schema scalars, and :func:`read_yaml` returns
the document with the line of every key path and any key given twice.

Before anything is built, :func:`read_yaml` walks the parser's events once (no
recursion) and refuses, with the line of the offending node:

* nesting deeper than :data:`MAX_DEPTH` levels (aliases count with the depth of
  what they stand for);
* a document of more than :data:`MAX_NODES` values once every alias is expanded
  (the "billion laughs" of nested aliases: a few hundred bytes that expand to
  billions of values);
* an alias inside the node it refers to (``x: &r [*r]``);
* text holding a control character (other than tab, line feed and carriage return),
  a lone surrogate (``"\\ud800"``) or U+FFFE/U+FFFF, which double-quoted escapes can
  write but which no output file (GPX, HTML, CSV) can carry.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from sailroute.errors import InputError
from sailroute.textin import bad_char


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
    re.compile(
        r"^(?:[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?"
        r"|[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))$"
    ),
    list("-+0123456789."),
)


def _construct_int(loader: YamlLoader, node: yaml.ScalarNode) -> int | str:
    """Decimal integer (the resolver above lets only ``[-+]?[0-9]+`` through); one of
    more digits than Python converts (4300) stays text, for the checks to refuse."""
    text = str(loader.construct_scalar(node))
    try:
        return int(text, 10)
    except ValueError:
        return text


YamlLoader.add_constructor("tag:yaml.org,2002:int", _construct_int)


def _construct_timestamp(loader: YamlLoader, node: yaml.ScalarNode) -> Any:
    """An unquoted date or time; one that is not a real instant (``2024-02-30``, second
    60) stays text, so that it gets the same message as when it is quoted."""
    try:
        return yaml.SafeLoader.construct_yaml_timestamp(loader, node)
    except (ValueError, OverflowError):
        return str(loader.construct_scalar(node))


YamlLoader.add_constructor("tag:yaml.org,2002:timestamp", _construct_timestamp)

MAX_DEPTH = 50
"""Deepest nesting of mappings and lists a YAML input may have (course files need 6)."""
MAX_NODES = 100_000
"""Most values (keys, scalars, mappings, lists) a YAML input may expand to, aliases
expanded; a course file has a few hundred."""


def _refuse_bad_chars(value: str, where: str) -> None:
    """An error at ``where`` when the scalar ``value`` holds a character that no output
    file can carry (:func:`~sailroute.textin.bad_char`)."""
    bad = bad_char(value)
    if bad is not None:
        text = value if len(value) <= 40 else value[:37] + "..."
        raise InputError(
            f"{where}: the text {text!a} holds {bad}, which no output "
            "file can carry; remove it (or the escape that writes it)"
        )


def _check_events(events: Iterable[yaml.Event], where: str) -> None:
    """Refuse deep nesting, alias bombs, recursive aliases and bad characters.

    One pass over the parser's events, without recursion: each anchor's expanded
    size and depth are known when its node ends, so an alias adds them without
    being walked.
    """
    n = 0  # values so far, aliases expanded
    # open collections: (anchor or None, n at start, depth at start, deepest inside)
    stack: list[list[Any]] = []
    size: dict[str, int] = {}
    height: dict[str, int] = {}

    def at(ev: yaml.Event) -> str:
        m = ev.start_mark
        return f"{where}:{m.line + 1}:{m.column + 1}" if m is not None else where

    def grow(ev: yaml.Event, count: int, depth: int, alias: str | None = None) -> None:
        nonlocal n
        n += count
        if stack:
            stack[-1][3] = max(stack[-1][3], depth)
        if depth > MAX_DEPTH:
            via = f" through the alias *{alias}" if alias else ""
            raise InputError(
                f"{at(ev)}: nested more than {MAX_DEPTH} levels deep{via}; "
                "a course or boat file needs a few levels"
            )
        if n > MAX_NODES:
            via = f" once the alias *{alias} and those before it are expanded" if alias else ""
            raise InputError(
                f"{at(ev)}: more than {MAX_NODES} values{via}; "
                "a course or boat file has at most a few thousand"
            )

    for ev in events:
        if isinstance(ev, yaml.ScalarEvent):
            _refuse_bad_chars(ev.value, at(ev))
            grow(ev, 1, len(stack) + 1)
            if ev.anchor is not None:
                size[ev.anchor], height[ev.anchor] = 1, 1
        elif isinstance(ev, yaml.MappingStartEvent | yaml.SequenceStartEvent):
            grow(ev, 1, len(stack) + 1)
            stack.append([ev.anchor, n - 1, len(stack), len(stack) + 1])
        elif isinstance(ev, yaml.MappingEndEvent | yaml.SequenceEndEvent):
            anchor, n0, d0, deepest = stack.pop()
            if anchor is not None:
                size[anchor], height[anchor] = n - n0, deepest - d0
            if stack:
                stack[-1][3] = max(stack[-1][3], deepest)
        elif isinstance(ev, yaml.AliasEvent):
            if ev.anchor is not None and any(s[0] == ev.anchor for s in stack):
                raise InputError(
                    f"{at(ev)}: the alias *{ev.anchor} is inside the node &{ev.anchor} "
                    "it refers to (a value that contains itself); refer to a finished node"
                )
            name = ev.anchor or ""
            # an undefined alias is left to the composer's own message
            grow(ev, size.get(name, 1), len(stack) + height.get(name, 1), ev.anchor)


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
        Missing file, a folder, not UTF-8, unreadable, a YAML syntax error (with
        line and column), nesting deeper than :data:`MAX_DEPTH`, more than
        :data:`MAX_NODES` values with aliases expanded, an alias inside its own
        node, or text with a control character (see the module docstring).
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
    return parse_yaml(text, str(p))


def parse_yaml(text: str, where: str) -> YamlDoc:
    """Parse YAML text as :func:`read_yaml` parses a file's (the same checks and messages).

    Parameters
    ----------
    text : str
        The YAML text.
    where : str
        What it is, first in every message (a file, or an option such as ``--boat``).

    Returns
    -------
    YamlDoc

    Raises
    ------
    InputError
        A syntax error (with line and column), nesting deeper than :data:`MAX_DEPTH`,
        more than :data:`MAX_NODES` values, an alias inside its own node, or text with a
        control character.
    """
    try:
        _check_events(yaml.parse(text, Loader=YamlLoader), where)
        loader = YamlLoader(text)  # a SafeLoader
        try:
            node = loader.get_single_node()
            data = loader.construct_document(node) if node is not None else None
        finally:
            loader.dispose()
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        at = f"{where}:{mark.line + 1}:{mark.column + 1}" if mark is not None else where
        problem = exc.problem or "invalid YAML"
        cm = exc.context_mark
        if exc.context and cm is not None and (mark is None or cm.line != mark.line):
            problem += f" ({exc.context} at line {cm.line + 1}, column {cm.column + 1})"
        elif exc.context:
            problem += f" ({exc.context})"
        raise InputError(
            f"{at}: YAML syntax error: {problem}; check indentation, colons, quotes and "
            "brackets on this line and the ones before"
        ) from None
    except yaml.YAMLError as exc:
        raise InputError(f"{where}: YAML syntax error: {exc}") from None
    lines: dict[str, int] = {}
    dup: list[Duplicate] = []
    if node is not None:
        _key_lines(node, "", lines, dup)
    return YamlDoc(data, lines, tuple(dup))
