"""Read and validate a course file (YAML) into a :class:`~sailroute.course.model.Course`.

The schema is documented key by key in ``docs/course-format.md``; this module is
its only implementation.  Validation collects every problem in the file and raises
one :class:`~sailroute.errors.InputError` listing them, each as
``file:line: key.path: what was expected; got what``.  Unknown keys are rejected
with a did-you-mean suggestion.

Wind and boat specs are stored raw and checked structurally here; the wind and
boat factories validate their own keys (:func:`validate_specs`, :func:`build_boat`,
:func:`build_wind`).
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import typing
from collections.abc import Callable, Iterable, Iterator, Mapping
from datetime import date, datetime
from pathlib import Path
from typing import Any

import numpy as np

from sailroute.course.model import Course, Gate, LegKind, LegSpec, Line, Mark, ScenarioSpec
from sailroute.course.templates import TEMPLATES, CourseLayout
from sailroute.errors import InputError, format_problems
from sailroute.geo import LocalFrame, wrap_lon
from sailroute.routing.types import RouterName, RoutingSettings
from sailroute.timeutil import parse_time, utc_offset_s
from sailroute.units import KNOT
from sailroute.yamlfile import join_path as _join
from sailroute.yamlfile import read_yaml

TOP_KEYS = (
    "name", "description", "start_time", "time_limit_min", "origin", "marks", "lines", "gates",
    "legs", "template", "boat", "routing", "scenarios", "references",
)
"""Keys allowed at the top level of a course file."""

LAYOUT_KEYS = ("marks", "lines", "gates", "legs")
SIDES = ("port", "starboard")
BOAT_SOURCES = ("builtin", "polar", "vpp")
DEFAULT_BOAT = {"builtin": "ilca7"}
DEFAULT_TIME_LIMIT_MIN = 90.0
MIN_SEPARATION_M = 1.0
"""Two marks of a line or gate, or the two ends of a leg, must be at least this far apart [m]."""

_MISSING = object()


# ----------------------------------------------------------------------------- problems
class _Problems:
    """Collects problems with their key paths; knows the YAML line of each path."""

    def __init__(self, file: str, lines: Mapping[str, int] | None = None) -> None:
        self.file = file
        self.lines = dict(lines or {})
        self.items: list[str] = []

    def line_of(self, path: str) -> int | None:
        p = path
        while p:
            if p in self.lines:
                return self.lines[p]
            cut = max(p.rfind("."), p.rfind("["))
            p = p[:cut] if cut > 0 else ""
        return None

    def prefix(self, path: str) -> str:
        line = self.line_of(path)
        loc = f"{self.file}:{line}" if line is not None else self.file
        return f"{loc}: {path}" if path else loc

    def add(self, path: str, message: str) -> None:
        self.items.append(f"{self.prefix(path)}: {message}")

    def extend(self, messages: Iterable[str]) -> None:
        self.items.extend(messages)

    def raise_if_any(self) -> None:
        if not self.items:
            return
        if len(self.items) == 1:
            raise InputError(self.items[0])
        title = f"{self.file}: {len(self.items)} problems in the course file"
        raise InputError(format_problems(title, self.items))




def _quoted(choices: Iterable[Any]) -> str:
    return ", ".join(repr(c) for c in choices)


def _suggest(word: str, choices: Iterable[str]) -> str:
    m = difflib.get_close_matches(str(word), list(choices), n=1, cutoff=0.6)
    return f"did you mean {m[0]!r}? " if m else ""


def _show(value: Any) -> str:
    if isinstance(value, Mapping):
        return "a mapping"
    if isinstance(value, list):
        return "a list"
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


# ----------------------------------------------------------------------------- YAML
def _read_yaml(path: Path) -> tuple[Any, dict[str, int], list[str]]:
    doc = read_yaml(path, what="course file")
    dup = [f"{d.path}: the key {d.key!r} appears twice in the same mapping "
           f"(lines {d.first_line} and {d.line}); keep one" for d in doc.duplicates]
    return doc.data, doc.lines, dup


# ----------------------------------------------------------------------------- checkers
class _Checker:
    """Typed getters that record problems instead of raising."""

    def __init__(self, problems: _Problems) -> None:
        self.p = problems
        self.declared: set[str] = set()
        """Names declared in the file, valid or not (no "unknown name" cascades)."""

    def keys(
        self,
        d: Mapping[Any, Any],
        path: str,
        allowed: Iterable[str],
        required: Iterable[str] = (),
    ) -> None:
        allowed = list(allowed)
        for key in d:
            if str(key) not in allowed:
                self.p.add(
                    _join(path, str(key)),
                    f"unknown key; {_suggest(str(key), allowed)}valid keys: {', '.join(allowed)}",
                )
        for key in required:
            if key not in d:
                self.p.add(_join(path, key), "missing required key")

    def mapping(self, value: Any, path: str, what: str = "a mapping (key: value pairs)") -> bool:
        if isinstance(value, Mapping):
            return True
        self.p.add(path, f"expected {what}; got {_show(value)}")
        return False

    def absent(self, path: str, default: Any, expected: str) -> Any:
        """Value of a key that is not there: ``default``, or ``None`` and a problem if required.

        ``default`` is ``_MISSING`` for a required key; ``expected`` says what the key
        should hold (``"a number"``, ``"text"``, ...).
        """
        if default is _MISSING:
            self.p.add(path, f"missing required key; expected {expected}")
            return None
        return default

    def number(
        self,
        d: Mapping[str, Any],
        key: str,
        path: str,
        default: Any = _MISSING,
        *,
        lo: float | None = None,
        hi: float | None = None,
        lo_open: bool = False,
        what: str | None = None,
    ) -> Any:
        p = _join(path, key)
        if key not in d or d[key] is None:
            return self.absent(p, default, what or "a number")
        v = d[key]
        if what is None:
            if lo is not None and hi is not None:
                what = f"a number in {'(' if lo_open else '['}{lo:g}, {hi:g}]"
            elif lo is not None:
                what = f"a number {'>' if lo_open else '>='} {lo:g}"
            else:
                what = "a number"
        if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(float(v)):
            self.p.add(p, f"expected {what}; got {_show(v)}")
            return None
        v = float(v)
        if (lo is not None and (v < lo or (lo_open and v == lo))) or (hi is not None and v > hi):
            self.p.add(p, f"expected {what}; got {v:g}")
            return None
        return v

    def integer(self, d: Mapping[str, Any], key: str, path: str, default: Any, lo: int) -> Any:
        p = _join(path, key)
        if key not in d:
            return default
        v = d[key]
        if isinstance(v, bool) or not isinstance(v, int) or v < lo:
            self.p.add(p, f"expected a whole number >= {lo}; got {_show(v)}")
            return None
        return int(v)

    def choice(
        self, d: Mapping[str, Any], key: str, path: str, choices: Iterable[Any],
        default: Any = _MISSING,
    ) -> Any:
        choices = list(choices)
        p = _join(path, key)
        if key not in d:
            return self.absent(p, default, f"one of {_quoted(choices)}")
        v = d[key]
        if v not in choices:
            hint = _suggest(str(v), [str(c) for c in choices]) if isinstance(v, str) else ""
            self.p.add(p, f"expected one of {_quoted(choices)}; got {_show(v)}"
                       + (f" ({hint.strip()})" if hint else ""))
            return None
        return v

    def string(self, d: Mapping[str, Any], key: str, path: str, default: Any = _MISSING) -> Any:
        p = _join(path, key)
        if key not in d:
            return self.absent(p, default, "text")
        v = d[key]
        if not isinstance(v, str) or not v.strip():
            self.p.add(p, f"expected non-empty text; got {_show(v)}")
            return None
        return v

    def boolean(self, d: Mapping[str, Any], key: str, path: str, default: bool) -> bool:
        if key not in d:
            return default
        v = d[key]
        if not isinstance(v, bool):
            self.p.add(_join(path, key), f"expected true or false; got {_show(v)}")
            return default
        return v

    def name(self, value: Any, path: str, what: str = "a name") -> str | None:
        """A mark/line/gate/scenario name: text, or a whole number read as text."""
        if isinstance(value, bool) or not isinstance(value, str | int) or (
            isinstance(value, str) and not value.strip()
        ):
            self.p.add(path, f"expected {what} (text or a whole number); got {_show(value)}")
            return None
        return str(value)

    def named_items(
        self, raw: Mapping[Any, Any], path: str, what: str
    ) -> Iterator[tuple[str, Any]]:
        """``(name, value)`` of each entry of the mapping ``raw`` at ``path`` whose key
        is a valid name (:meth:`name`, ``what`` for its message); bad keys are recorded
        and skipped."""
        for key, value in raw.items():
            name = self.name(key, _join(path, str(key)), what)
            if name is not None:
                yield name, value


# ----------------------------------------------------------------------------- sections
def _start_time(c: _Checker, data: Mapping[str, Any]) -> datetime | None:
    if "start_time" not in data:
        c.p.add("start_time", "missing required key; expected an ISO 8601 time with a UTC "
                "offset, e.g. '2018-04-24T12:10:00+02:00'")
        return None
    v = data["start_time"]
    if isinstance(v, date) and not isinstance(v, datetime):
        c.p.add("start_time", f"expected a date and time with a UTC offset, e.g. "
                f"'{v.isoformat()}T12:00:00+02:00'; got the date {v.isoformat()}")
        return None
    if not isinstance(v, str | datetime):
        c.p.add("start_time", f"expected an ISO 8601 time with a UTC offset; got {_show(v)}")
        return None
    try:
        return parse_time(v, where=c.p.prefix("start_time"))
    except InputError as exc:
        c.p.extend([str(exc)])
        return None


def _latlon(c: _Checker, d: Mapping[str, Any], path: str) -> tuple[float, float] | None:
    lat = c.number(d, "lat", path, lo=-90.0, hi=90.0, what="a latitude in [-90, 90] degrees")
    lon = c.number(d, "lon", path, lo=-180.0, hi=360.0,
                   what="a longitude in [-180, 360] degrees")
    # 0..360 longitudes are accepted and wrapped to [-180, 180), as GPX and plan.json use
    return None if lat is None or lon is None else (lat, float(wrap_lon(lon)))


def _position(
    c: _Checker, value: Any, path: str, what: str
) -> tuple[str, tuple[float, float]] | None:
    """``("ll", (lat, lon))`` or ``("xy", (x, y))`` from ``{lat, lon}`` / ``{x, y}``."""
    if not c.mapping(value, path, f"{what} as {{lat, lon}} (degrees) or {{x, y}} (metres)"):
        return None
    c.keys(value, path, ("lat", "lon", "x", "y"))
    has_ll = "lat" in value or "lon" in value
    has_xy = "x" in value or "y" in value
    if has_ll and has_xy:
        c.p.add(path, "give either {lat, lon} or {x, y}, not both")
        return None
    if not has_ll and not has_xy:
        c.p.add(path, f"expected {what} as {{lat, lon}} (degrees) or {{x, y}} (metres east/"
                "north of the origin); got neither")
        return None
    if has_ll:
        ll = _latlon(c, value, path)
        return None if ll is None else ("ll", ll)
    x = c.number(value, "x", path, what="metres east of the origin")
    y = c.number(value, "y", path, what="metres north of the origin")
    return None if x is None or y is None else ("xy", (x, y))


def _frame(
    c: _Checker, data: Mapping[str, Any], latlons: list[tuple[float, float]], needs: list[str]
) -> LocalFrame | None:
    """The local frame: ``origin`` if given, else the mean of the lat/lon positions.

    Marks on both sides of the antimeridian (longitudes more than 180° apart) are
    averaged across it (179.9995 and -179.9985 give 180.0005), not around the globe.
    """
    if "origin" in data:
        if not c.mapping(data["origin"], "origin", "{lat, lon} of the local frame's origin"):
            return None
        c.keys(data["origin"], "origin", ("lat", "lon"), ("lat", "lon"))
        ll = _latlon(c, data["origin"], "origin")
        return None if ll is None else LocalFrame(*ll)
    if needs:
        c.p.add(needs[0], "positions in {x, y} metres need `origin: {lat, lon}` at the top "
                "level of the course file (the point x = y = 0)")
        return None
    if latlons:
        a = np.array(latlons)
        lon = a[:, 1]  # in [-180, 180)
        if lon.max() - lon.min() > 180.0:  # across the antimeridian: average east of it
            lon = np.where(lon < 0.0, lon + 360.0, lon)
        return LocalFrame(float(a[:, 0].mean()), float(lon.mean()))
    return None


def _marks(c: _Checker, raw: Any) -> dict[str, tuple[str, tuple[float, float]]]:
    out: dict[str, tuple[str, tuple[float, float]]] = {}
    if not c.mapping(raw, "marks", "a mapping of mark name to {lat, lon} or {x, y}"):
        return out
    if not raw:
        c.p.add("marks", "expected at least two marks; got none")
    for name, value in c.named_items(raw, "marks", "a mark name"):
        c.declared.add(name)
        pos = _position(c, value, _join("marks", name), f"the position of mark {name!r}")
        if pos is not None:
            out[name] = pos
    return out


def _pairs(
    c: _Checker, raw: Any, section: str, marks: Mapping[str, Mark], taken: set[str],
) -> dict[str, tuple[str, str]]:
    """``lines``/``gates``: name → two mark names, checked against the marks."""
    out: dict[str, tuple[str, str]] = {}
    what = "line" if section == "lines" else "gate"
    if not c.mapping(raw, section, f"a mapping of {what} name to [mark, mark]"):
        return out
    for name, value in c.named_items(raw, section, f"a {what} name"):
        path = _join(section, name)
        if name not in taken:
            c.declared.add(name)
        if name in taken:
            c.p.add(path, f"the name {name!r} is already used by a mark, line or gate; "
                    "names must be unique")
            continue
        if not isinstance(value, list) or len(value) != 2:
            c.p.add(path, f"expected a list of two mark names, e.g. [{what}_a, {what}_b]; "
                    f"got {_show(value)}")
            continue
        e0, e1 = (c.name(v, _join(path, i), "a mark name") for i, v in enumerate(value))
        if e0 is None or e1 is None:
            continue
        ends = (e0, e1)
        ok = True
        for i, m in enumerate(ends):
            if m not in marks:
                if m not in c.declared:
                    c.p.add(_join(path, i), f"unknown mark {m!r}; {_suggest(m, marks)}"
                            f"marks are: {', '.join(marks) or '(none)'}")
                ok = False
        if not ok:
            continue
        a, b = marks[ends[0]], marks[ends[1]]
        if ends[0] == ends[1]:
            c.p.add(path, f"a {what} needs two different marks; got {ends[0]!r} twice")
            continue
        d = math.hypot(b.x - a.x, b.y - a.y)
        if d < MIN_SEPARATION_M:
            c.p.add(path, f"marks {ends[0]!r} and {ends[1]!r} are {d:.2f} m apart; a {what} "
                    f"needs its two marks at least {MIN_SEPARATION_M:g} m apart")
            continue
        out[name] = (ends[0], ends[1])
        taken.add(name)
    return out


def _centre(
    table: Mapping[str, Any], marks: Mapping[str, Mark], name: str
) -> tuple[float, float]:
    if name in marks:
        return marks[name].xy
    a, b = table[name]
    return (0.5 * (marks[a].x + marks[b].x), 0.5 * (marks[a].y + marks[b].y))


def _legs(
    c: _Checker,
    raw: Any,
    marks: Mapping[str, Mark],
    lines: Mapping[str, tuple[str, str]],
    gates: Mapping[str, tuple[str, str]],
) -> list[LegSpec]:
    out: list[LegSpec] = []
    if not isinstance(raw, list):
        c.p.add("legs", f"expected a list of legs, e.g. [{{to: '1', rounding: port}}, "
                f"{{to: finish}}]; got {_show(raw)}")
        return out
    if not raw:
        c.p.add("legs", "expected at least one leg; got an empty list")
        return out
    features: dict[str, LegKind] = {**{m: "mark" for m in marks}, **{g: "gate" for g in gates},
                                    **{n: "line" for n in lines}}
    centres = {**gates, **lines}
    prev: str | None = None
    for i, item in enumerate(raw):
        path = _join("legs", i)
        if isinstance(item, str | int) and not isinstance(item, bool):
            item = {"to": item}
        if not c.mapping(item, path, "a leg {to: NAME, rounding: port|starboard}"):
            prev = None
            continue
        c.keys(item, path, ("from", "to", "rounding"), ("to",))
        frm: str | None
        if i == 0:
            if "from" in item:
                frm = c.name(item["from"], _join(path, "from"), "a line or mark name")
                if frm is not None and frm not in features:
                    if frm not in c.declared:
                        c.p.add(_join(path, "from"), f"unknown line or mark {frm!r}; "
                                f"{_suggest(frm, features)}known: {', '.join(features)}")
                    frm = None
            elif "start" in lines:
                frm = "start"
            elif "start" in c.declared:
                frm = None  # the start line itself is invalid (reported there)
            else:
                c.p.add(path, "the first leg needs `from: LINE_OR_MARK`, or define a line "
                        "named 'start' under `lines`")
                frm = None
        else:
            if "from" in item:
                c.p.add(_join(path, "from"), "only the first leg may give `from`; later legs "
                        "start where the previous leg ended")
            frm = prev
        to = c.name(item["to"], _join(path, "to"), "a mark, gate or line name") if (
            "to" in item) else None
        if to is not None and to not in features:
            if to not in c.declared:
                c.p.add(_join(path, "to"), f"unknown mark, gate or line {to!r}; "
                        f"{_suggest(to, features)}known: {', '.join(features)}")
            to = None
        kind = features.get(to) if to is not None else None
        rounding = None
        if kind == "mark" or (kind is None and "rounding" in item):
            rounding = c.choice(item, "rounding", path, SIDES, "port")
        elif kind is not None and "rounding" in item:
            c.p.add(_join(path, "rounding"), f"{to!r} is a {kind}; boats pass through a "
                    f"{kind}, so `rounding` applies to marks only (remove it)")
        if to is not None and frm is not None:
            if to == frm:
                what = "the previous leg ends" if i > 0 else "the leg starts"
                c.p.add(_join(path, "to"), f"{to!r} is where {what}; a leg must go to a "
                        "different mark, gate or line")
            else:
                a = _centre(centres, marks, frm)
                b = _centre(centres, marks, to)
                d = math.hypot(b[0] - a[0], b[1] - a[1])
                if d < MIN_SEPARATION_M:
                    c.p.add(path, f"the leg {frm!r} -> {to!r} is {d:.2f} m long; "
                            f"expected at least {MIN_SEPARATION_M:g} m")
        if to is not None and kind is not None and frm is not None:
            out.append(LegSpec(i, frm, to, kind, rounding))
        prev = to
    return out


def _routing(c: _Checker, raw: Any) -> RoutingSettings:
    if raw is None:
        return RoutingSettings()
    if not c.mapping(raw, "routing", "a mapping of routing settings"):
        return RoutingSettings()
    fields = {f.name: f for f in dataclasses.fields(RoutingSettings)}
    c.keys(raw, "routing", list(fields))
    defaults = RoutingSettings()
    kw: dict[str, Any] = {}
    special: dict[str, Callable[[], Any]] = {
        "router": lambda: c.choice(raw, "router", "routing", typing.get_args(RouterName)),
        "dt_s": lambda: c.number(raw, "dt_s", "routing", lo=0.0, lo_open=True),
        "heading_step_deg": lambda: c.number(raw, "heading_step_deg", "routing", lo=0.0,
                                             hi=45.0, lo_open=True),
        "tack_penalty_s": lambda: c.number(raw, "tack_penalty_s", "routing", lo=0.0),
        "gybe_penalty_s": lambda: c.number(raw, "gybe_penalty_s", "routing", lo=0.0),
        "initial_side": lambda: c.choice(raw, "initial_side", "routing", (*SIDES, None)),
    }
    for key in raw:
        if key not in fields:
            continue
        if key in special:
            v = special[key]()
        elif key == "extra":
            v = _extra(c, raw["extra"])
        else:
            v = _generic(c, raw, key, str(fields[key].type))
        if v is not None or raw[key] is None:
            kw[key] = v
    try:
        return dataclasses.replace(defaults, **kw)
    except (TypeError, ValueError) as exc:  # a future field with its own checks
        c.p.add("routing", str(exc))
        return defaults


def _extra(c: _Checker, raw: Any) -> dict[str, float] | None:
    if not c.mapping(raw, "routing.extra", "a mapping of router-specific settings"):
        return None
    out = {}
    for k in raw:
        v = c.number(raw, k, "routing.extra")
        if v is not None:
            out[str(k)] = v
    return out


def _generic(c: _Checker, raw: Mapping[str, Any], key: str, type_text: str) -> Any:
    """Type-check a RoutingSettings field by its annotation (``float``, ``int | None``, ...)."""
    optional = "None" in type_text
    if optional and raw[key] is None:
        return None
    if "bool" in type_text:
        return c.boolean(raw, key, "routing", False)
    if "int" in type_text:
        return c.integer(raw, key, "routing", None, 0)
    if "float" in type_text:
        return c.number(raw, key, "routing", what="a number" + (" or null" if optional else ""))
    if "str" in type_text or "Literal" in type_text:
        return c.string(raw, key, "routing")
    return raw[key]


def _boat(c: _Checker, raw: Any) -> dict[str, Any]:
    if raw is None:
        return dict(DEFAULT_BOAT)
    if not c.mapping(raw, "boat", "{builtin: NAME}, {polar: PATH} or {vpp: {...}}"):
        return dict(DEFAULT_BOAT)
    given = [k for k in BOAT_SOURCES if k in raw]
    if len(given) != 1:
        got = ", ".join(given) if given else "none of them"
        c.p.add("boat", f"expected exactly one of 'builtin', 'polar', 'vpp'; got {got}")
    return dict(raw)


def _leg_times(c: _Checker, value: Any, path: str, n_legs: int | None) -> tuple[float, ...] | None:
    if not isinstance(value, list) or not value:
        c.p.add(path, f"expected a list of leg times in seconds, one per leg; got {_show(value)}")
        return None
    out = []
    ok = True
    for i, v in enumerate(value):
        if isinstance(v, bool) or not isinstance(v, int | float) or not v > 0 or not math.isfinite(
            float(v)
        ):
            c.p.add(_join(path, i), f"expected a leg time in seconds > 0; got {_show(v)}")
            ok = False
        else:
            out.append(float(v))
    if n_legs is not None and len(value) != n_legs:
        c.p.add(path, f"expected {n_legs} leg times (one per leg); got {len(value)}")
        ok = False
    return tuple(out) if ok else None


def _references(
    c: _Checker, raw: Any, path: str, n_legs: int | None
) -> dict[str, tuple[float, ...]]:
    out: dict[str, tuple[float, ...]] = {}
    if raw is None:
        return out
    if not c.mapping(raw, path, "a mapping of reference name to a list of leg times [s]"):
        return out
    for name, value in c.named_items(raw, path, "a reference name"):
        times = _leg_times(c, value, _join(path, name), n_legs)
        if times is not None:
            out[name] = times
    return out


def _wind_spec(c: _Checker, value: Any, path: str) -> bool:
    if not c.mapping(value, path, "a wind spec {type: uniform|wrf|stations|blended, ...}"):
        return False
    if "type" not in value:
        c.p.add(path, "the wind spec has no `type`; expected one of 'uniform', 'wrf', "
                "'stations', 'blended' (see docs/design/wind.md)")
        return False
    if not isinstance(value["type"], str):
        c.p.add(_join(path, "type"), f"expected text such as 'uniform' or 'wrf'; "
                f"got {_show(value['type'])}")
        return False
    return True


def _scenarios(c: _Checker, raw: Any, n_legs: int | None) -> dict[str, ScenarioSpec]:
    out: dict[str, ScenarioSpec] = {}
    if raw is None:
        c.p.add("scenarios", "missing required key; add at least one wind scenario, e.g. "
                "`scenarios: {steady: {type: uniform, tws_kn: 10, twd_deg: 270}}`")
        return out
    if not c.mapping(raw, "scenarios", "a mapping of scenario name to a wind spec"):
        return out
    if not raw:
        c.p.add("scenarios", "expected at least one scenario; got none")
    for name, value in c.named_items(raw, "scenarios", "a scenario name"):
        path = _join("scenarios", name)
        if not c.mapping(value, path, "a wind spec {type: ...} or {wind: {type: ...}, "
                         "references: ..., description: ...}"):
            continue
        keys = ("wind", "members", "references", "description", "current")
        cur, cwhere = None, ""  # surface current spec (sailroute.current), key path
        if "type" in value or not any(k in value for k in keys):
            # shorthand: the scenario is the wind spec itself
            wind, wpath, refs, desc = value, path, {}, ""
        else:
            c.keys(value, path, keys)
            if ("wind" in value) == ("members" in value):
                c.p.add(path, "give exactly one of `wind: {type: ...}` (one wind) or "
                        "`members: [...]` (an ensemble of winds)")
                continue
            refs = _references(c, value.get("references"), _join(path, "references"), n_legs)
            desc = c.string(value, "description", path, "") or ""
            if value.get("current") is not None and c.mapping(
                    value["current"], _join(path, "current"),
                    "a current spec {type: uniform|diamonds|netcdf, ...}"):
                cur, cwhere = dict(value["current"]), c.p.prefix(_join(path, "current"))
            if "members" in value:
                mpath = _join(path, "members")
                for k, (spec, where) in enumerate(_members(c, value["members"], mpath), 1):
                    out[f"{name}#{k}"] = ScenarioSpec(f"{name}#{k}", dict(spec), refs, desc,
                                                      c.p.prefix(where), ensemble=str(name),
                                                      current=cur, current_where=cwhere)
                continue
            wind, wpath = value["wind"], _join(path, "wind")
        if _wind_spec(c, wind, wpath):
            out[name] = ScenarioSpec(name, dict(wind), refs, desc, c.p.prefix(wpath),
                                     current=cur, current_where=cwhere)
    return out


def _members(c: _Checker, raw: Any, path: str) -> list[tuple[Mapping[str, Any], str]]:
    """The member wind specs of an ensemble scenario, each with its key path.

    ``members`` is a list of wind specs, or ``{dim: NAME, wind: {type: netcdf, ...}}``:
    one member per index of the NetCDF dimension ``NAME`` (the spec's ``select`` picks it).
    """
    if isinstance(raw, list):
        if len(raw) < 2:
            c.p.add(path, f"an ensemble needs at least 2 members; got {len(raw)}")
            return []
        items = [(spec, f"{path}[{k}]") for k, spec in enumerate(raw)]
        return [(s, w) for s, w in items if _wind_spec(c, s, w)]
    if not c.mapping(raw, path, "a list of wind specs, or {dim: NAME, wind: {type: netcdf, "
                     "path: FILE}} (one member per index of that dimension)"):
        return []
    c.keys(raw, path, ("dim", "wind"), ("dim", "wind"))
    dim, wpath = raw.get("dim"), _join(path, "wind")
    wind = raw.get("wind")
    if not isinstance(dim, str) or not _wind_spec(c, wind, wpath):
        if "dim" in raw and not isinstance(dim, str):
            c.p.add(_join(path, "dim"), f"expected a dimension name; got {_show(dim)}")
        return []
    if wind.get("type") != "netcdf" or not isinstance(wind.get("path"), str):
        c.p.add(wpath, "members along a dimension need `type: netcdf` with a `path`")
        return []
    n = _dimension_size(c, Path(c.p.file).parent / wind["path"], dim, wpath)
    if n is None:
        return []
    return [({**wind, "select": {**dict(wind.get("select") or {}), dim: k}}, wpath)
            for k in range(n)]


def _dimension_size(c: _Checker, file: Path, dim: str, path: str) -> int | None:
    """Size of dimension ``dim`` in a NetCDF file (a problem at ``path`` if it has none)."""
    import netCDF4

    if not file.is_file():
        c.p.add(_join(path, "path"), f"file {str(file)!r} not found (paths are relative to "
                "the course file's folder)")
        return None
    try:
        with netCDF4.Dataset(str(file), "r") as ds:
            dims = {k: len(v) for k, v in ds.dimensions.items()}
    except OSError as exc:
        c.p.add(_join(path, "path"), f"{file.name} cannot be read as NetCDF ({exc})")
        return None
    if dim not in dims:
        c.p.add(path, f"{file.name} has no dimension {dim!r}; it has "
                + ", ".join(f"{k} ({v})" for k, v in dims.items()))
        return None
    return dims[dim]


# ----------------------------------------------------------------------------- template
_DIR = "direction"  # a compass direction, [0, 360] deg (nomenclature)
_POS = "positive"
_NONNEG = "nonnegative"
_TEMPLATE_KEYS: dict[str, dict[str, Any]] = {
    "windward-leeward": {
        "twd_deg": _DIR, "leg_length_m": _POS, "laps": "int", "gate_width_m": _POS,
        "start_line_length_m": _POS, "start_offset_m": _NONNEG,
        "finish": ("leeward", "windward"), "finish_line_length_m": _POS,
        "finish_offset_m": _NONNEG,
    },
    "trapezoid": {
        "twd_deg": _DIR, "leg_length_m": _POS, "laps": "int", "loop": ("inner", "outer"),
        "reach_angle_deg": _POS, "reach_length_m": _POS, "gate_width_m": _POS,
        "start_line_length_m": _POS, "start_offset_m": _NONNEG, "finish_line_length_m": _POS,
        "finish_reach_m": _POS,
    },
}


_FASTEST_MS = 70.0 * KNOT
"""No sailing boat races faster than 70 kn [m s⁻¹]: bounds what a time limit can hold."""


def _max_laps(leg_length_m: float, time_limit_min: float | None) -> int:
    """Most laps (two legs of ``leg_length_m`` each) a boat at 70 kn sails in the time limit."""
    limit_s = 60.0 * (time_limit_min or DEFAULT_TIME_LIMIT_MIN)
    return max(1, int(limit_s * _FASTEST_MS / (2.0 * leg_length_m)))


def _template(
    c: _Checker, raw: Any, time_limit_min: float | None = None
) -> tuple[CourseLayout | None, tuple[str, tuple[float, float]] | None]:
    """Validate ``template`` and build its layout around ``centre`` (in a provisional frame)."""
    if not c.mapping(raw, "template", "{type: windward-leeward|trapezoid, twd_deg, "
                     "leg_length_m, centre, ...}"):
        return None, None
    kind = c.choice(raw, "type", "template", list(_TEMPLATE_KEYS))
    if kind is None:
        return None, None
    spec = _TEMPLATE_KEYS[kind]
    c.keys(raw, "template", ("type", "centre", *spec), ("twd_deg", "leg_length_m", "centre"))
    centre = _position(c, raw["centre"], "template.centre", "the course centre") if (
        "centre" in raw) else None
    kw: dict[str, Any] = {}
    for key, rule in spec.items():
        if key not in raw:
            continue
        if rule == _DIR:
            v = c.number(raw, key, "template", lo=0.0, hi=360.0)
        elif rule == _POS:
            v = c.number(raw, key, "template", lo=0.0, lo_open=True)
        elif rule == _NONNEG:
            v = c.number(raw, key, "template", lo=0.0)
        elif rule == "int":
            v = c.integer(raw, key, "template", None, 1)
        else:
            v = c.choice(raw, key, "template", rule)
        if v is not None:
            kw[key] = v
    if centre is None or any(k not in kw for k in ("twd_deg", "leg_length_m")) or any(
        k in raw and k not in kw for k in spec
    ):
        return None, centre
    twd, length = kw.pop("twd_deg"), kw.pop("leg_length_m")
    laps = kw.pop("laps", 2)
    most = _max_laps(length, time_limit_min)
    if laps > most:
        c.p.add("template.laps", f"{laps} laps of 2 × {length:g} m cannot be sailed within "
                f"time_limit_min {time_limit_min or DEFAULT_TIME_LIMIT_MIN:g} even at 70 kn; "
                f"expected an integer in [1, {most}] (or raise time_limit_min)")
        return None, centre
    try:
        layout = TEMPLATES[kind]((0.0, 0.0), twd, length, laps, **kw)
    except InputError as exc:
        c.p.add("template", str(exc).removeprefix("course template: "))
        return None, centre
    return layout, centre


def _layout_mapping(layout: CourseLayout) -> dict[str, Any]:
    legs: list[dict[str, Any]] = []
    for i, leg in enumerate(layout.legs):
        d: dict[str, Any] = {"to": leg.to}
        if leg.rounding is not None:
            d["rounding"] = leg.rounding
        if i == 0:
            d["from"] = layout.start_from
        legs.append(d)
    return {
        "lines": {k: list(v) for k, v in layout.lines.items()},
        "gates": {k: list(v) for k, v in layout.gates.items()},
        "legs": legs,
    }


# ----------------------------------------------------------------------------- entry points
def course_from_mapping(
    data: Any,
    *,
    source: Path | str | None = None,
    key_lines: Mapping[str, int] | None = None,
    extra_problems: Iterable[str] = (),
) -> Course:
    """Validate a parsed course mapping and build the :class:`Course`.

    Parameters
    ----------
    data : mapping
        The parsed YAML (what ``yaml.safe_load`` returns).
    source : Path or str, optional
        The file it came from; names the file in messages and is the folder that
        relative paths resolve against.
    key_lines : mapping of str to int, optional
        1-based YAML line of each key path, for messages.
    extra_problems : iterable of str
        Problems found before (e.g. duplicate keys), reported together.

    Returns
    -------
    Course

    Raises
    ------
    InputError
        Listing every problem found, one per line, with its key path.
    """
    src = Path(source) if source is not None else None
    probs = _Problems(str(src) if src is not None else "<course>", key_lines)
    c = _Checker(probs)
    for msg in extra_problems:
        probs.add("", msg)
    if not isinstance(data, Mapping):
        what = "an empty file" if data is None else _show(data)
        probs.add("", "expected a course mapping with keys name, start_time, marks, legs, "
                  f"scenarios, ...; got {what}")
        probs.raise_if_any()
    c.keys(data, "", TOP_KEYS, ("name", "start_time"))
    name = c.string(data, "name", "", "") or ""
    description = data.get("description", "")
    if not isinstance(description, str):
        probs.add("description", f"expected text; got {_show(description)}")
        description = ""
    start_time = _start_time(c, data) if "start_time" in data else None
    time_limit = c.number(data, "time_limit_min", "", DEFAULT_TIME_LIMIT_MIN, lo=0.0,
                          lo_open=True)

    # -- layout: explicit marks/lines/gates/legs, or a template
    template = data.get("template")
    layout_raw: dict[str, Any] = {k: data[k] for k in LAYOUT_KEYS if k in data}
    positions: dict[str, tuple[str, tuple[float, float]]] = {}
    centre = None
    if template is not None:
        clash = [k for k in LAYOUT_KEYS if k in data]
        if clash:
            probs.add(clash[0], "a course with `template` gets its marks, lines, gates and "
                      f"legs from the template; remove {', '.join(clash)} or the template")
        layout, centre = _template(c, template, time_limit)
        if layout is not None:
            layout_raw = _layout_mapping(layout)
            positions = {k: ("xy", xy) for k, xy in layout.marks.items()}
    else:
        for key in ("marks", "legs"):
            if key not in data:
                probs.add(key, "missing required key (or use `template`)")
        positions = _marks(c, data["marks"]) if "marks" in data else {}

    latlons = [p for kind, p in positions.values() if kind == "ll"]
    needs = [_join("marks", k) for k, (kind, _) in positions.items() if kind == "xy"]
    if template is not None:  # template marks are relative to the centre, not the origin
        needs = ["template.centre"] if centre is not None and centre[0] == "xy" else []
        latlons = [centre[1]] if centre is not None and centre[0] == "ll" else []
    frame = _frame(c, data, latlons, needs)

    marks: dict[str, Mark] = {}
    if frame is not None:
        if centre is not None:  # template: layout built around (0, 0); move it to the centre
            cx, cy = centre[1] if centre[0] == "xy" else tuple(
                float(v) for v in frame.to_xy(*centre[1])
            )
            positions = {k: ("xy", (x + cx, y + cy)) for k, (_, (x, y)) in positions.items()}
        for k, (kind, (p, q)) in positions.items():
            if kind == "ll":
                x, y = (float(v) for v in frame.to_xy(p, q))
                marks[k] = Mark(k, x, y, p, q)
            else:
                lat, lon = (float(v) for v in frame.to_latlon(p, q))
                marks[k] = Mark(k, p, q, lat, lon)

    taken = set(marks)
    lines_raw = layout_raw.get("lines")
    gates_raw = layout_raw.get("gates")
    line_names = _pairs(c, lines_raw, "lines", marks, taken) if lines_raw is not None else {}
    gate_names = _pairs(c, gates_raw, "gates", marks, taken) if gates_raw is not None else {}
    legs: list[LegSpec] = []
    if "legs" in layout_raw and frame is not None:
        legs = _legs(c, layout_raw["legs"], marks, line_names, gate_names)
    n_legs = len(legs) if legs and "legs" in layout_raw and len(legs) == len(
        layout_raw["legs"]) else None

    boat = _boat(c, data.get("boat"))
    routing = _routing(c, data.get("routing"))
    scenarios = _scenarios(c, data.get("scenarios"), n_legs)
    references = _references(c, data.get("references"), "references", n_legs)
    probs.raise_if_any()

    assert frame is not None and start_time is not None  # guaranteed when no problems
    return Course(
        name=name,
        start_time=start_time,
        frame=frame,
        marks=marks,
        lines={k: Line(k, marks[a], marks[b]) for k, (a, b) in line_names.items()},
        gates={k: Gate(k, marks[a], marks[b]) for k, (a, b) in gate_names.items()},
        legs=tuple(legs),
        boat_spec=boat,
        routing=routing,
        scenarios=scenarios,
        references=references,
        source=src,
        description=description,
        template=dict(template) if template is not None else None,
        time_limit_s=float(time_limit) * 60.0,
        boat_where=probs.prefix("boat").removesuffix(": boat"),
        utc_offset_s=utc_offset_s(data["start_time"]),
    )


def load_course(path: str | Path) -> Course:
    """Read, validate and build a course from a YAML file.

    Parameters
    ----------
    path : str or Path
        The course file (see ``docs/course-format.md``).

    Returns
    -------
    Course

    Raises
    ------
    InputError
        File missing or unreadable, YAML syntax error (with line and column), or
        invalid content (every problem listed, each with its line and key path).
    """
    p = Path(path)
    data, lines, dup = _read_yaml(p)
    return course_from_mapping(data, source=p, key_lines=lines, extra_problems=dup)


# ----------------------------------------------------------------------------- specs
def build_boat(course: Course) -> Any:
    """Build the boat :class:`~sailroute.boat.polar.Polar` from ``course.boat_spec``.

    Uses ``sailroute.boat.build.boat_from_spec``; relative paths resolve against the
    course file's folder.
    """
    from sailroute.boat.build import boat_from_spec

    where = course.boat_where or (str(course.source) if course.source else "<course>")
    return boat_from_spec(dict(course.boat_spec), base_dir=course.base_dir, where=where,
                          key="boat")


def build_wind(course: Course, scenario: str) -> Any:
    """Build the :class:`~sailroute.wind.base.WindField` of one scenario.

    The field is cropped to the marks' bounding box and must cover the race time
    window ``[start_time, start_time + time_limit_min]`` (see
    :func:`sailroute.course.geometry.race_time_window`).

    Raises
    ------
    InputError
        Unknown scenario name (with the valid ones), or a bad wind spec.
    OutOfCoverageError
        The wind data do not cover the course or the race time.
    """
    from sailroute.course.geometry import course_bbox, race_time_window
    from sailroute.wind.build import wind_from_spec

    if scenario not in course.scenarios:
        names = list(course.scenarios)
        raise InputError(
            f"{course.where('scenarios')}: no scenario {scenario!r}; "
            f"{_suggest(scenario, names)}scenarios are: {', '.join(names)}"
        )
    sc = course.scenarios[scenario]
    return wind_from_spec(
        dict(sc.wind), frame=course.frame, base_dir=course.base_dir,
        where=sc.where or course.where(f"scenarios.{scenario}"),
        crop_bbox=course_bbox(course), time_window=race_time_window(course),
    )


def build_current(course: Course, scenario: str) -> Any:
    """Build the surface current of one scenario (:mod:`sailroute.current`), or None.

    Like :func:`build_wind`: relative paths resolve against the course file's folder
    and the current must cover the course box and the race time window.
    """
    from sailroute.course.geometry import course_bbox, race_time_window
    from sailroute.current import current_from_spec

    sc = course.scenarios.get(scenario)
    if sc is None or sc.current is None:  # (an unknown name is build_wind's error)
        return None
    return current_from_spec(
        dict(sc.current), frame=course.frame, base_dir=course.base_dir,
        where=sc.current_where or course.where(f"scenarios.{scenario}.current"),
        crop_bbox=course_bbox(course), time_window=race_time_window(course),
    )


def build_specs(
    course: Course, scenarios: Iterable[str] | None = None
) -> tuple[Any, dict[str, Any]]:
    """Build the boat and each scenario's wind once, reporting all problems together.

    Parameters
    ----------
    course : Course
        A loaded course.
    scenarios : iterable of str, optional
        Scenario names to build (default: all).

    Returns
    -------
    boat : Polar
        As :func:`build_boat`.
    winds : dict of str to WindField
        Scenario name -> wind field, as :func:`build_wind`.

    Raises
    ------
    InputError
        One error listing every boat/wind spec problem (each with its key path); a
        single problem keeps its own type (e.g. ``OutOfCoverageError``).
    """
    errors: list[InputError] = []
    boat, winds = None, {}
    try:
        boat = build_boat(course)
    except InputError as exc:
        errors.append(exc)
    for name in course.scenarios if scenarios is None else scenarios:
        try:
            winds[name] = build_wind(course, name)
        except InputError as exc:
            errors.append(exc)
        try:  # validated here with the winds; plan.py builds it again to route
            build_current(course, name)
        except InputError as exc:
            errors.append(exc)
    if len(errors) == 1:  # keep its type (e.g. OutOfCoverageError) and message
        raise errors[0]
    problems = [p for exc in errors for p in _flatten(str(exc))]
    if problems:
        raise InputError(format_problems(
            f"{course.source or '<course>'}: {len(problems)} problems in boat/wind specs",
            problems,
        ))
    return boat, winds


def validate_specs(course: Course, scenarios: Iterable[str] | None = None) -> None:
    """:func:`build_specs`, keeping only its errors (check a course without routing it)."""
    build_specs(course, scenarios)


def _flatten(message: str) -> list[str]:
    """Split a ``format_problems`` message back into its problems (else keep it whole)."""
    lines = message.splitlines()
    if len(lines) > 1 and all(ln.startswith("  - ") for ln in lines[1:]):
        return [ln[4:] for ln in lines[1:]]
    return [message]
