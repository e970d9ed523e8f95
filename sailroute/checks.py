"""The one validation mechanism of every input file: courses, wind and current specs, boats.

A :class:`Problems` collects every problem found in one file (or one spec inside it),
each located by its key path and, where the YAML line map knows it, its line, and
raises them once as a single :class:`~sailroute.errors.InputError`.  A :class:`Checker`
reads typed values (number with bounds, whole number, text, choice, mapping, true/false,
time, name) from a parsed mapping and records a problem instead of raising.

Every message has one wording, the course loader's::

    <file>:<line>: <key path>: expected <what>; got <value>[ (did you mean 'x'?)]
    <file>:<line>: <key path>: unknown key; did you mean 'x'? valid keys: a, b, c

and several problems are listed under one title (``format_problems``)::

    <file>[:<line>: <root key path>]: <n> problems in the <what>
      - <file>:<line>: <key path>: ...

:func:`suggest` is the one did-you-mean.
"""

from __future__ import annotations

import difflib
import math
import numbers
import re
from collections.abc import Iterable, Iterator, Mapping
from datetime import datetime
from pathlib import Path
from typing import Any, Final, SupportsFloat

from sailroute.errors import InputError, format_problems
from sailroute.yamlfile import join_path

__all__ = [
    "MISSING",
    "Checker",
    "Problems",
    "finite",
    "join_path",
    "quoted",
    "show",
    "split_where",
    "suggest",
]

MISSING: Final = object()
"""Default of a getter whose key is required (absent: a problem, value None)."""


# ----------------------------------------------------------------------------- wording
def suggest(word: str, choices: Iterable[Any]) -> str:
    """``"did you mean 'x'? "`` for the choice closest to ``word``, or ``""`` if none is close.

    The one did-you-mean of every input file (difflib ratio >= 0.6).

    Parameters
    ----------
    word : str
        What the file says (an unknown key, name or value).
    choices : iterable
        The valid words (compared as text).

    Returns
    -------
    str
        The hint with a trailing space, ready to precede the list of valid choices.
    """
    m = difflib.get_close_matches(str(word), [str(c) for c in choices], n=1, cutoff=0.6)
    return f"did you mean {m[0]!r}? " if m else ""


def quoted(choices: Iterable[Any]) -> str:
    """``'a', 'b', 'c'``: the choices, quoted and comma-separated."""
    return ", ".join(repr(c) for c in choices)


def finite(v: SupportsFloat) -> bool:
    """True for a number that is a finite float (an integer of 400 digits is not)."""
    try:
        return math.isfinite(float(v))
    except OverflowError:
        return False


def real_number(v: Any) -> bool:
    """True for a finite real number given as one: an int or a float (NumPy's too), not a
    bool, not text."""
    if isinstance(v, bool) or not isinstance(v, numbers.Real):
        return False
    return finite(v)


def show(value: Any) -> str:
    """A value for a message: ``a mapping``, ``a list`` (``an empty ...``), or its repr
    cut at 60 characters."""
    if isinstance(value, Mapping):
        return "a mapping" if value else "an empty mapping"
    if isinstance(value, list):
        return "a list" if value else "an empty list"
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


_WHERE = re.compile(r"^(?P<file>.+?)(?::(?P<line>\d+))?(?:: (?P<path>[^:]*))?$")


def split_where(where: str) -> tuple[str, int | None, str]:
    """Split a message prefix ``"file[:line][: key.path]"`` into its three parts.

    The inverse of :meth:`Problems.prefix`: factories called with a prefix string
    (``wind_from_spec(..., where="courses/x.yaml:12: scenarios.a.wind")``) report
    their own problems below that key path.

    Examples
    --------
    >>> split_where("courses/x.yaml:12: scenarios.a.wind")
    ('courses/x.yaml', 12, 'scenarios.a.wind')
    >>> split_where("b.yaml")
    ('b.yaml', None, '')
    """
    m = _WHERE.match(where)
    if m is None:  # (an empty string)
        return where, None, ""
    line = m.group("line")
    return m.group("file"), int(line) if line else None, m.group("path") or ""


# ----------------------------------------------------------------------------- problems
class Problems:
    """Every problem found in one file (or one spec of it), raised once.

    Parameters
    ----------
    file : str
        The file, first in every message (``"courses/x.yaml"``, ``"<course>"``).
    lines : mapping of str to int, optional
        1-based YAML line of each key path (``"legs[2].to"``) of the file; a problem
        is located at the line of its key path or of the nearest key above it.
    root : str
        Key path of the checked part of the file (``"scenarios.a.wind"``; ``""``
        for the whole file); names the part in the title of several problems.
    what : str
        What is checked, for that title (``"course file"``, ``"wind spec"``).
    """

    def __init__(
        self,
        file: str,
        lines: Mapping[str, int] | None = None,
        *,
        root: str = "",
        what: str = "course file",
    ) -> None:
        self.file = file
        self.lines = dict(lines or {})
        self.root = root
        self.what = what
        self.items: list[str] = []

    @classmethod
    def below(cls, where: str, lines: Mapping[str, int] | None = None, *, what: str) -> Problems:
        """Problems of the part of a file that the prefix ``where`` names (:func:`split_where`).

        A line in ``where`` locates the part's own key when ``lines`` does not.
        """
        file, line, root = split_where(where)
        known = dict(lines or {})
        if line is not None and root not in known:
            known[root] = line
        return cls(file, known, root=root, what=what)

    def line_of(self, path: str) -> int | None:
        """Line of ``path``, or of the nearest key above it the line map knows."""
        p = path
        while p:
            if p in self.lines:
                return self.lines[p]
            cut = max(p.rfind("."), p.rfind("["))
            p = p[:cut] if cut > 0 else ""
        return self.lines.get("")

    def prefix(self, path: str) -> str:
        """``"file:line: path"`` (without the line where none is known; ``"file"`` for ``""``)."""
        line = self.line_of(path)
        loc = f"{self.file}:{line}" if line is not None else self.file
        return f"{loc}: {path}" if path else loc

    def add(self, path: str, message: str) -> None:
        """Record ``message`` about the key at ``path``."""
        self.items.append(f"{self.prefix(path)}: {message}")

    def extend(self, messages: Iterable[str]) -> None:
        """Record messages that already name their place (e.g. from ``parse_time``)."""
        self.items.extend(messages)

    def __bool__(self) -> bool:
        return bool(self.items)

    def __len__(self) -> int:
        return len(self.items)

    def raise_if_any(self) -> None:
        """Raise one :class:`InputError` listing every problem (the message alone if one).

        Raises
        ------
        InputError
            ``"<file>[:<line>: <root>]: <n> problems in the <what>"`` and one problem
            per line.
        """
        if not self.items:
            return
        if len(self.items) == 1:
            raise InputError(self.items[0])
        title = f"{self.prefix(self.root)}: {len(self.items)} problems in the {self.what}"
        raise InputError(format_problems(title, self.items))


def resolve_path(base_dir: Path, path: str | Path) -> Path:
    """A path from a spec: as given when absolute, else relative to ``base_dir`` (resolved)."""
    p = Path(path)
    return p if p.is_absolute() else (Path(base_dir) / p).resolve()


def missing_file_message(full: Path, base_dir: Path) -> str:
    """The one wording of a spec's missing file: the path tried and where relative paths start."""
    return f"file not found: {full} (paths are relative to {base_dir}, the course file's folder)"


# ----------------------------------------------------------------------------- checker
class Checker:
    """Typed getters over the mapping at key path ``path``, recording problems.

    Every getter takes the mapping and a key below ``path``, returns the checked
    value (a float for numbers), the default if the key is absent, or None after
    recording a problem.  A default of :data:`MISSING` makes the key required.

    Parameters
    ----------
    problems : Problems
        Where problems go (shared by :meth:`child` and :meth:`at` checkers).
    path : str
        Key path of the mapping this checker reads (``""``: the top level).
    """

    def __init__(self, problems: Problems, path: str = "") -> None:
        self.p = problems
        self.path = path
        self.declared: set[str] = set()
        """Names declared in the file, valid or not (no "unknown name" cascades)."""

    # -- places ----------------------------------------------------------------------
    def at(self, path: str) -> Checker:
        """A checker of the mapping at ``path`` (absolute), sharing problems and names."""
        c = Checker(self.p, path)
        c.declared = self.declared
        return c

    def child(self, key: str | int) -> Checker:
        """A checker of the mapping at ``key`` below this one."""
        return self.at(self.key(key))

    def key(self, key: str | int) -> str:
        """Key path of ``key`` below :attr:`path`."""
        return join_path(self.path, key)

    def where(self, key: str | int | None = None) -> str:
        """Message prefix ``"file:line: path.key"`` of ``key`` (of :attr:`path` if None)."""
        return self.p.prefix(self.path if key is None else self.key(key))

    def add(self, key: str | int | None, message: str) -> None:
        """Record a problem at ``key`` below :attr:`path` (at :attr:`path` itself if None)."""
        self.p.add(self.path if key is None else self.key(key), message)

    # -- structure ---------------------------------------------------------------------
    def keys(
        self,
        d: Mapping[Any, Any],
        allowed: Iterable[str],
        required: Iterable[str] = (),
        *,
        of: str = "",
    ) -> None:
        """Record unknown keys of ``d`` (with a did-you-mean) and missing required ones.

        ``of`` names the owner where it helps: ``of="a 'builtin' boat"`` gives
        ``unknown key for a 'builtin' boat; did you mean ...``.
        """
        allowed = list(allowed)
        unknown = f"unknown key for {of}" if of else "unknown key"
        for key in d:
            if str(key) not in allowed:
                self.add(
                    str(key),
                    f"{unknown}; {suggest(str(key), allowed)}valid keys: " + ", ".join(allowed),
                )
        for key in required:
            if key not in d:
                self.add(key, "missing required key")

    def is_mapping(self, value: Any, what: str = "a mapping (key: value pairs)") -> bool:
        """Whether ``value`` (the value at :attr:`path`) is a mapping; a problem if not."""
        if isinstance(value, Mapping):
            return True
        self.add(None, f"expected {what}; got {show(value)}")
        return False

    def absent(self, key: str, default: Any, expected: str) -> Any:
        """Value of a key that is not there: ``default``, or None and a problem if required.

        ``expected`` says what the key should hold (``"a number"``, ``"text"``, ...).
        """
        if default is MISSING:
            self.add(key, f"missing required key; expected {expected}")
            return None
        return default

    # -- typed getters -----------------------------------------------------------------
    def mapping(
        self,
        d: Mapping[str, Any],
        key: str,
        default: Any = MISSING,
        what: str = "a mapping (key: value pairs)",
    ) -> Any:
        """A nested mapping."""
        if key not in d:
            return self.absent(key, default, what)
        return d[key] if self.child(key).is_mapping(d[key], what) else None

    def number(
        self,
        d: Mapping[str, Any],
        key: str,
        default: Any = MISSING,
        *,
        lo: float | None = None,
        hi: float | None = None,
        lo_open: bool = False,
        what: str | None = None,
    ) -> Any:
        """A finite number (int or float, not a boolean) in ``[lo, hi]`` (``(lo, hi]``
        with ``lo_open``); a null value counts as absent.  ``what`` overrides the
        generated ``"a number in [lo, hi]"`` / ``"a number > lo"`` in messages."""
        if what is None:
            if lo is not None and hi is not None:
                what = f"a number in {'(' if lo_open else '['}{lo:g}, {hi:g}]"
            elif lo is not None:
                what = f"a number {'>' if lo_open else '>='} {lo:g}"
            elif hi is not None:
                what = f"a number <= {hi:g}"
            else:
                what = "a number"
        if key not in d or d[key] is None:
            return self.absent(key, default, what)
        v = d[key]
        if isinstance(v, bool) or not isinstance(v, int | float) or not finite(v):
            self.add(key, f"expected {what}; got {show(v)}")
            return None
        v = float(v)
        if (lo is not None and (v < lo or (lo_open and v == lo))) or (hi is not None and v > hi):
            self.add(key, f"expected {what}; got {v:g}")
            return None
        return v

    def integer(self, d: Mapping[str, Any], key: str, default: Any = MISSING, *, lo: int) -> Any:
        """A whole number >= ``lo``."""
        if key not in d:
            return self.absent(key, default, f"a whole number >= {lo}")
        v = d[key]
        if isinstance(v, bool) or not isinstance(v, int) or v < lo:
            self.add(key, f"expected a whole number >= {lo}; got {show(v)}")
            return None
        return int(v)

    def choice(
        self, d: Mapping[str, Any], key: str, choices: Iterable[Any], default: Any = MISSING
    ) -> Any:
        """One of ``choices`` (with a did-you-mean for a close text)."""
        choices = list(choices)
        if key not in d:
            return self.absent(key, default, f"one of {quoted(choices)}")
        v = d[key]
        if v not in choices:
            hint = suggest(v, choices) if isinstance(v, str) else ""
            self.add(
                key,
                f"expected one of {quoted(choices)}; got {show(v)}"
                + (f" ({hint.strip()})" if hint else ""),
            )
            return None
        return v

    def string(self, d: Mapping[str, Any], key: str, default: Any = MISSING) -> Any:
        """Non-empty text."""
        if key not in d:
            return self.absent(key, default, "text")
        v = d[key]
        if not isinstance(v, str) or not v.strip():
            self.add(key, f"expected non-empty text; got {show(v)}")
            return None
        return v

    def file(self, d: Any, key: str | int, base_dir: Path, value: Any = MISSING) -> Path | None:
        """An existing file named by ``d[key]`` (or ``value``), relative to ``base_dir``.

        Records "file not found" (with the resolved path and the folder relative
        paths start from) and returns None when there is no such file.
        """
        p = self.string(d, str(key)) if value is MISSING else value
        if p is None:
            return None
        full = resolve_path(base_dir, p)
        if not full.is_file():
            self.add(key, missing_file_message(full, base_dir))
            return None
        return full

    def boolean(self, d: Mapping[str, Any], key: str, default: bool) -> bool:
        """``true`` or ``false`` (the default after a problem)."""
        if key not in d:
            return default
        v = d[key]
        if not isinstance(v, bool):
            self.add(key, f"expected true or false; got {show(v)}")
            return default
        return v

    def time(self, d: Mapping[str, Any], key: str) -> datetime | None:
        """An ISO 8601 time with a UTC offset (:func:`sailroute.timeutil.parse_time`);
        None, with the parser's message recorded, if it is not one."""
        from sailroute.timeutil import parse_time

        try:
            return parse_time(d[key], where=self.where(key))
        except InputError as exc:
            self.p.extend([str(exc)])
            return None

    def name(self, value: Any, what: str = "a name") -> str | None:
        """A mark/line/gate/scenario name at :attr:`path`: text, or a whole number as text."""
        if (
            isinstance(value, bool)
            or not isinstance(value, str | int)
            or (isinstance(value, str) and not value.strip())
        ):
            self.add(None, f"expected {what} (text or a whole number); got {show(value)}")
            return None
        return str(value)

    def named_items(self, raw: Mapping[Any, Any], what: str) -> Iterator[tuple[str, Any]]:
        """``(name, value)`` of each entry of the mapping ``raw`` at :attr:`path` whose
        key is a valid name (:meth:`name`, ``what`` for its message); bad keys are
        recorded and skipped."""
        for key, value in raw.items():
            name = self.child(str(key)).name(key, what)
            if name is not None:
                yield name, value
