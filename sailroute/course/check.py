"""Check a parsed course file against its schema: every problem at once, plain values out.

The schema is documented key by key in ``docs/course-format.md``; this module is
its only implementation.  :func:`check_course` walks the parsed YAML with a
:class:`~sailroute.checks.Checker`, records every problem (``file:line: key.path:
expected ...; got ...``, unknown keys with a did-you-mean) and returns a
:class:`CheckedCourse` of validated plain values (numbers in SI units, names, mark
positions in the local frame), from which :mod:`sailroute.course.build` makes the
model objects.

Wind and current specs are parsed here, each into its frozen dataclass
(:mod:`sailroute.wind.specs`), their problems listed with the course's; the boat spec
is stored raw and checked by its factory (:mod:`sailroute.course.specs`).
"""

from __future__ import annotations

import dataclasses
import math
import typing
from collections.abc import Mapping
from dataclasses import dataclass
from datetime import date, datetime
from pathlib import Path
from typing import Any

import numpy as np

from sailroute.checks import (
    Checker,
    Problems,
    finite,
    join_path,
    missing_file_message,
    show,
    suggest,
)
from sailroute.course.area import AREA_KEYS, check_area
from sailroute.course.chart import ChartFile, check_chart
from sailroute.course.model import LegKind
from sailroute.course.routing_section import load_routing
from sailroute.course.templates import TEMPLATES, CourseLayout
from sailroute.course.uncertainty import UncertaintySpec, check_uncertainty
from sailroute.errors import InputError
from sailroute.geo import LocalFrame, wrap_lon
from sailroute.outdir import path_part_problem
from sailroute.routing.obstacles import RaceArea
from sailroute.routing.settings import RoutingSettings
from sailroute.routing.types import Side
from sailroute.timeutil import parse_time, utc_offset_s
from sailroute.units import KNOT
from sailroute.wind.specs import (
    CURRENT_TYPES,
    WIND_TYPES,
    CurrentSpec,
    NetcdfWindSpec,
    WindSpec,
    check_current_spec,
    check_wind_spec,
)

__all__ = ["TOP_KEYS", "CheckedCourse", "check_course"]

TOP_KEYS = (
    "name",
    "description",
    "start_time",
    "restart_time",
    "time_limit_min",
    "origin",
    "marks",
    "lines",
    "gates",
    "legs",
    "template",
    "boat",
    "routing",
    "scenarios",
    "references",
    "uncertainty",
    "chart",
    *AREA_KEYS,
)
"""Keys allowed at the top level of a course file."""

LAYOUT_KEYS = ("marks", "lines", "gates", "legs")
SIDES = typing.get_args(Side)  # ("port", "starboard")
BOAT_SOURCES = ("builtin", "polar", "vpp")
DEFAULT_BOAT = {"builtin": "ilca7"}
DEFAULT_TIME_LIMIT_MIN = 90.0
MIN_SEPARATION_M = 1.0
"""Two marks of a line or gate, or the two ends of a leg, must be at least this far apart [m]."""
MAX_OFFSET_M = 100_000.0
"""Every mark lies within this distance of the local frame's origin [m] (a buoy course
spans a few km; far-off values are typing errors that the routers cannot use)."""

Position = tuple[str, tuple[float, float]]
"""``("ll", (lat, lon))`` [deg] or ``("xy", (x, y))`` [m], as the file gives it."""
XY = Mapping[str, tuple[float, float]]
"""Mark name -> local-frame position ``(x, y)`` [m]."""
Leg = tuple[int, str, str, LegKind, Side | None]
"""``(index, from, to, kind, rounding)``: the fields of a ``LegSpec``."""


@dataclass(frozen=True)
class CheckedCourse:
    """A course file's validated values, before the model objects are built.

    Attributes
    ----------
    name, description : str
        As in the file (``""`` when absent).
    start_time : datetime
        The start signal, timezone-aware.
    utc_offset_s : float
        The offset ``start_time`` was written with [s].
    time_limit_min : float
        Time limit [min].
    frame : LocalFrame
        The local frame (``origin``, or the mean of the marks' lat/lon).
    marks : dict of str to tuple of float
        Mark name -> ``(x, y, lat, lon)`` [m, m, deg, deg].
    lines, gates : dict of str to tuple of str
        Name -> its two mark names.
    legs : tuple of tuple
        ``(index, from, to, kind, rounding)`` of each leg (the fields of
        :class:`~sailroute.course.model.LegSpec`).
    boat : dict
        The raw ``boat`` spec (``{builtin: ilca7}`` when absent).
    boat_where : str
        ``"file:line"`` of the ``boat`` key, for the boat factory's messages.
    routing : RoutingSettings
        ``routing`` over the defaults.
    scenarios : dict of str to dict
        Scenario name -> the keyword arguments of its
        :class:`~sailroute.course.model.ScenarioSpec`.
    references : dict of str to tuple of float
        Course-wide reference leg times [s].
    template : dict or None
        The ``template`` mapping, if the layout came from one.
    area : RaceArea
        ``boundary``, ``obstacles`` and ``wind_land_is_obstacle`` in the local frame
        (:mod:`sailroute.course.area`).
    uncertainty : UncertaintySpec or None
        The ``uncertainty`` section (leg-time bands), if given.
    restart_time : datetime or None
        The restart's signal after a general recall, if given (after ``start_time``).
    chart : ChartFile or None
        The ``chart`` file (coast or land drawn under the maps), if given.
    """

    name: str
    description: str
    start_time: datetime
    utc_offset_s: float
    time_limit_min: float
    frame: LocalFrame
    marks: dict[str, tuple[float, float, float, float]]
    lines: dict[str, tuple[str, str]]
    gates: dict[str, tuple[str, str]]
    legs: tuple[Leg, ...]
    boat: dict[str, Any]
    boat_where: str
    routing: RoutingSettings
    scenarios: dict[str, dict[str, Any]]
    references: dict[str, tuple[float, ...]]
    template: dict[str, Any] | None
    area: RaceArea = dataclasses.field(default_factory=RaceArea)
    uncertainty: UncertaintySpec | None = None
    restart_time: datetime | None = None
    chart: ChartFile | None = None


# ----------------------------------------------------------------------------- sections
def _start_time(c: Checker, data: Mapping[str, Any], key: str = "start_time") -> datetime | None:
    if key not in data:
        c.p.add(
            key,
            "missing required key; expected an ISO 8601 time with a UTC "
            "offset, e.g. '2018-04-24T12:10:00+02:00'",
        )
        return None
    v = data[key]
    if isinstance(v, date) and not isinstance(v, datetime):
        c.p.add(
            key,
            f"expected a date and time with a UTC offset, e.g. "
            f"'{v.isoformat()}T12:00:00+02:00'; got the date {v.isoformat()}",
        )
        return None
    if not isinstance(v, str | datetime):
        c.p.add(key, f"expected an ISO 8601 time with a UTC offset; got {show(v)}")
        return None
    try:
        return parse_time(v, where=c.p.prefix(key))
    except InputError as exc:
        c.p.extend([str(exc)])
        return None


def _restart_time(c: Checker, data: Mapping[str, Any], start: datetime | None) -> datetime | None:
    """``restart_time``: the restart's signal after a general recall, after ``start_time``."""
    if data.get("restart_time") is None:
        return None
    restart = _start_time(c, data, "restart_time")
    if restart is not None and start is not None and restart <= start:
        c.p.add(
            "restart_time",
            f"the restart after a general recall must come after start_time "
            f"({start.isoformat()}); got {restart.isoformat()}",
        )
        return None
    return restart


def _latlon(c: Checker, d: Mapping[str, Any], path: str) -> tuple[float, float] | None:
    lat = c.at(path).number(d, "lat", lo=-90.0, hi=90.0, what="a latitude in [-90, 90] degrees")
    lon = c.at(path).number(
        d, "lon", lo=-180.0, hi=360.0, what="a longitude in [-180, 360] degrees"
    )
    # 0..360 longitudes are accepted and wrapped to [-180, 180), as GPX and plan.json use
    return None if lat is None or lon is None else (lat, float(wrap_lon(lon)))


def _position(c: Checker, value: Any, path: str, what: str) -> Position | None:
    """``("ll", (lat, lon))`` or ``("xy", (x, y))`` from ``{lat, lon}`` / ``{x, y}``."""
    if not c.at(path).is_mapping(value, f"{what} as {{lat, lon}} (degrees) or {{x, y}} (metres)"):
        return None
    c.at(path).keys(value, ("lat", "lon", "x", "y"))
    has_ll = "lat" in value or "lon" in value
    has_xy = "x" in value or "y" in value
    if has_ll and has_xy:
        c.p.add(path, "give either {lat, lon} or {x, y}, not both")
        return None
    if not has_ll and not has_xy:
        c.p.add(
            path,
            f"expected {what} as {{lat, lon}} (degrees) or {{x, y}} (metres east/"
            "north of the origin); got neither",
        )
        return None
    if has_ll:
        ll = _latlon(c, value, path)
        return None if ll is None else ("ll", ll)
    span = f"in [{-MAX_OFFSET_M:.0f}, {MAX_OFFSET_M:.0f}]"
    x = c.at(path).number(
        value, "x", lo=-MAX_OFFSET_M, hi=MAX_OFFSET_M, what=f"metres east of the origin, {span}"
    )
    y = c.at(path).number(
        value, "y", lo=-MAX_OFFSET_M, hi=MAX_OFFSET_M, what=f"metres north of the origin, {span}"
    )
    return None if x is None or y is None else ("xy", (x, y))


def _frame(
    c: Checker, data: Mapping[str, Any], latlons: list[tuple[float, float]], needs: list[str]
) -> LocalFrame | None:
    """The local frame: ``origin`` if given, else the mean of the lat/lon positions.

    Marks on both sides of the antimeridian (longitudes more than 180° apart) are
    averaged across it (179.9995 and -179.9985 give 180.0005), not around the globe.
    """
    if "origin" in data:
        if not c.at("origin").is_mapping(data["origin"], "{lat, lon} of the local frame's origin"):
            return None
        c.at("origin").keys(data["origin"], ("lat", "lon"), ("lat", "lon"))
        ll = _latlon(c, data["origin"], "origin")
        return None if ll is None else LocalFrame(*ll)
    if needs:
        c.p.add(
            needs[0],
            "positions in {x, y} metres need `origin: {lat, lon}` at the top "
            "level of the course file (the point x = y = 0)",
        )
        return None
    if latlons:
        a = np.array(latlons)
        lon = a[:, 1]  # in [-180, 180)
        if lon.max() - lon.min() > 180.0:  # across the antimeridian: average east of it
            lon = np.where(lon < 0.0, lon + 360.0, lon)
        return LocalFrame(float(a[:, 0].mean()), float(lon.mean()))
    return None


def _marks(c: Checker, raw: Any) -> dict[str, Position]:
    out: dict[str, Position] = {}
    if not c.at("marks").is_mapping(raw, "a mapping of mark name to {lat, lon} or {x, y}"):
        return out
    if not raw:
        c.p.add("marks", "expected at least two marks; got none")
    for name, value in c.at("marks").named_items(raw, "a mark name"):
        c.declared.add(name)
        pos = _position(c, value, join_path("marks", name), f"the position of mark {name!r}")
        if pos is not None:
            out[name] = pos
    return out


def _pairs(
    c: Checker,
    raw: Any,
    section: str,
    marks: XY,
    taken: set[str],
) -> dict[str, tuple[str, str]]:
    """``lines``/``gates``: name → two mark names, checked against the marks."""
    out: dict[str, tuple[str, str]] = {}
    what = "line" if section == "lines" else "gate"
    if not c.at(section).is_mapping(raw, f"a mapping of {what} name to [mark, mark]"):
        return out
    for name, value in c.at(section).named_items(raw, f"a {what} name"):
        path = join_path(section, name)
        if name not in taken:
            c.declared.add(name)
        if name in taken:
            c.p.add(
                path,
                f"the name {name!r} is already used by a mark, line or gate; names must be unique",
            )
            continue
        if not isinstance(value, list) or len(value) != 2:
            c.p.add(
                path,
                f"expected a list of two mark names, e.g. [{what}_a, {what}_b]; got {show(value)}",
            )
            continue
        e0, e1 = (c.at(join_path(path, i)).name(v, "a mark name") for i, v in enumerate(value))
        if e0 is None or e1 is None:
            continue
        ends = (e0, e1)
        ok = True
        for i, m in enumerate(ends):
            if m not in marks:
                if m not in c.declared:
                    c.p.add(
                        join_path(path, i),
                        f"unknown mark {m!r}; {suggest(m, marks)}"
                        f"marks are: {', '.join(marks) or '(none)'}",
                    )
                ok = False
        if not ok:
            continue
        (ax, ay), (bx, by) = marks[ends[0]], marks[ends[1]]
        if ends[0] == ends[1]:
            c.p.add(path, f"a {what} needs two different marks; got {ends[0]!r} twice")
            continue
        d = math.hypot(bx - ax, by - ay)
        if d < MIN_SEPARATION_M:
            c.p.add(
                path,
                f"marks {ends[0]!r} and {ends[1]!r} are {d:.2f} m apart; a {what} "
                f"needs its two marks at least {MIN_SEPARATION_M:g} m apart",
            )
            continue
        out[name] = (ends[0], ends[1])
        taken.add(name)
    return out


def _centre(table: Mapping[str, Any], marks: XY, name: str) -> tuple[float, float]:
    if name in marks:
        return marks[name]
    (ax, ay), (bx, by) = marks[table[name][0]], marks[table[name][1]]
    return (0.5 * (ax + bx), 0.5 * (ay + by))


def _legs(
    c: Checker,
    raw: Any,
    marks: XY,
    lines: Mapping[str, tuple[str, str]],
    gates: Mapping[str, tuple[str, str]],
) -> list[Leg]:
    out: list[Leg] = []
    if not isinstance(raw, list):
        c.p.add(
            "legs",
            f"expected a list of legs, e.g. [{{to: '1', rounding: port}}, "
            f"{{to: finish}}]; got {show(raw)}",
        )
        return out
    if not raw:
        c.p.add("legs", "expected at least one leg; got an empty list")
        return out
    features: dict[str, LegKind] = {
        **{m: "mark" for m in marks},
        **{g: "gate" for g in gates},
        **{n: "line" for n in lines},
    }
    centres = {**gates, **lines}
    prev: str | None = None
    for i, item in enumerate(raw):
        path = join_path("legs", i)
        if isinstance(item, str | int) and not isinstance(item, bool):
            item = {"to": item}
        if not c.at(path).is_mapping(item, "a leg {to: NAME, rounding: port|starboard}"):
            prev = None
            continue
        c.at(path).keys(item, ("from", "to", "rounding"), ("to",))
        frm = (
            _leg_from(c, item, path, features, lines)
            if i == 0
            else _later_from(c, item, path, prev)
        )
        to = _feature(c, item, "to", path, features, "mark, gate or line")
        kind = features.get(to) if to is not None else None
        rounding = _rounding(c, item, path, to, kind)
        if to is not None and frm is not None:
            _check_leg_length(
                c, path, i, frm, to, _centre(centres, marks, frm), _centre(centres, marks, to)
            )
        if to is not None and kind is not None and frm is not None:
            out.append((i, frm, to, kind, rounding))
        prev = to
    return out


def _feature(
    c: Checker,
    item: Mapping[str, Any],
    key: str,
    path: str,
    features: Mapping[str, LegKind],
    what: str,
) -> str | None:
    """The mark, gate or line named by ``item[key]``, or None (a problem recorded)."""
    if key not in item:
        return None
    name = c.at(join_path(path, key)).name(item[key], f"a {what} name")
    if name is not None and name not in features:
        if name not in c.declared:
            c.p.add(
                join_path(path, key),
                f"unknown {what} {name!r}; {suggest(name, features)}known: {', '.join(features)}",
            )
        return None
    return name


def _leg_from(
    c: Checker,
    item: Mapping[str, Any],
    path: str,
    features: Mapping[str, LegKind],
    lines: Mapping[str, tuple[str, str]],
) -> str | None:
    """Where the first leg starts: its ``from``, else the line named ``start``."""
    if "from" in item:
        return _feature(c, item, "from", path, features, "line or mark")
    if "start" in lines:
        return "start"
    if "start" not in c.declared:  # (an invalid start line is reported there)
        c.p.add(
            path,
            "the first leg needs `from: LINE_OR_MARK`, or define a line "
            "named 'start' under `lines`",
        )
    return None


def _later_from(c: Checker, item: Mapping[str, Any], path: str, prev: str | None) -> str | None:
    """Where a later leg starts: where the previous one ended (``from`` is refused)."""
    if "from" in item:
        c.p.add(
            join_path(path, "from"),
            "only the first leg may give `from`; later legs start where the previous leg ended",
        )
    return prev


def _rounding(
    c: Checker, item: Mapping[str, Any], path: str, to: str | None, kind: LegKind | None
) -> Side | None:
    """The side a mark is rounded on (default port); gates and lines take none."""
    if kind == "mark" or (kind is None and "rounding" in item):
        side: Side | None = c.at(path).choice(item, "rounding", SIDES, "port")
        return side
    if kind is not None and "rounding" in item:
        c.p.add(
            join_path(path, "rounding"),
            f"{to!r} is a {kind}; boats pass through a "
            f"{kind}, so `rounding` applies to marks only (remove it)",
        )
    return None


def _check_leg_length(
    c: Checker, path: str, i: int, frm: str, to: str, a: tuple[float, float], b: tuple[float, float]
) -> None:
    """A leg goes somewhere else, at least :data:`MIN_SEPARATION_M` away."""
    if to == frm:
        what = "the previous leg ends" if i > 0 else "the leg starts"
        c.p.add(
            join_path(path, "to"),
            f"{to!r} is where {what}; a leg must go to a different mark, gate or line",
        )
        return
    d = math.hypot(b[0] - a[0], b[1] - a[1])
    if d < MIN_SEPARATION_M:
        c.p.add(
            path,
            f"the leg {frm!r} -> {to!r} is {d:.2f} m long; "
            f"expected at least {MIN_SEPARATION_M:g} m",
        )


def _boat(c: Checker, raw: Any) -> dict[str, Any]:
    if raw is None:
        return dict(DEFAULT_BOAT)
    if not c.at("boat").is_mapping(raw, "{builtin: NAME}, {polar: PATH} or {vpp: {...}}"):
        return dict(DEFAULT_BOAT)
    given = [k for k in BOAT_SOURCES if k in raw]
    if len(given) != 1:
        got = ", ".join(given) if given else "none of them"
        c.p.add("boat", f"expected exactly one of 'builtin', 'polar', 'vpp'; got {got}")
    return dict(raw)


def _leg_times(c: Checker, value: Any, path: str, n_legs: int | None) -> tuple[float, ...] | None:
    if not isinstance(value, list) or not value:
        c.p.add(path, f"expected a list of leg times in seconds, one per leg; got {show(value)}")
        return None
    out = []
    ok = True
    for i, v in enumerate(value):
        if isinstance(v, bool) or not isinstance(v, int | float) or not v > 0 or not finite(v):
            c.p.add(join_path(path, i), f"expected a leg time in seconds > 0; got {show(v)}")
            ok = False
        else:
            out.append(float(v))
    if n_legs is not None and len(value) != n_legs:
        c.p.add(path, f"expected {n_legs} leg times (one per leg); got {len(value)}")
        ok = False
    return tuple(out) if ok else None


def _references(
    c: Checker, raw: Any, path: str, n_legs: int | None
) -> dict[str, tuple[float, ...]]:
    out: dict[str, tuple[float, ...]] = {}
    if raw is None:
        return out
    if not c.at(path).is_mapping(raw, "a mapping of reference name to a list of leg times [s]"):
        return out
    for name, value in c.at(path).named_items(raw, "a reference name"):
        times = _leg_times(c, value, join_path(path, name), n_legs)
        if times is not None:
            out[name] = times
    return out


def _wind_spec(c: Checker, value: Any, path: str) -> bool:
    if not c.at(path).is_mapping(value, "a wind spec {type: " + "|".join(WIND_TYPES) + ", ...}"):
        return False
    if "type" not in value:
        c.p.add(
            path,
            "the wind spec has no `type`; expected one of "
            + ", ".join(repr(t) for t in WIND_TYPES)
            + " (see docs/design/wind.md)",
        )
        return False
    if not isinstance(value["type"], str):
        c.p.add(
            join_path(path, "type"),
            f"expected text such as 'uniform' or 'wrf'; got {show(value['type'])}",
        )
        return False
    return True


def _parse_wind(c: Checker, value: Any, path: str) -> WindSpec | None:
    """The parsed wind spec at ``path`` (:mod:`sailroute.wind.specs`); None after a problem."""
    if not _wind_spec(c, value, path):
        return None
    return check_wind_spec(value, c.at(path), _base_dir(c))


def _base_dir(c: Checker) -> Path:
    """Folder that relative paths of the file resolve against (the working folder for a
    course built from a mapping, as :attr:`Course.base_dir`)."""
    return Path.cwd() if c.p.file == "<course>" else Path(c.p.file).parent


_Current = tuple[CurrentSpec | None, str, dict[str, Any] | None]
"""A scenario's current: the parsed spec, its key path, the mapping as given."""


def _scenarios(c: Checker, raw: Any, n_legs: int | None) -> dict[str, dict[str, Any]]:
    """Scenario name -> the keyword arguments of its ``ScenarioSpec`` (an ensemble:
    one scenario ``NAME#k`` per member)."""
    out: dict[str, dict[str, Any]] = {}
    if raw is None:
        c.p.add(
            "scenarios",
            "missing required key; add at least one wind scenario, e.g. "
            "`scenarios: {steady: {type: uniform, tws_kn: 10, twd_deg: 270}}`",
        )
        return out
    if not c.at("scenarios").is_mapping(raw, "a mapping of scenario name to a wind spec"):
        return out
    if not raw:
        c.p.add("scenarios", "expected at least one scenario; got none")
    for name, value in c.at("scenarios").named_items(raw, "a scenario name"):
        path = join_path("scenarios", name)
        why = path_part_problem(name)
        if why is not None:  # it names a folder of the output (out/<course>/<scenario>)
            c.p.add(
                path,
                f"the scenario name {name!r} cannot name an output folder: {why}; "
                "use letters, digits, '-', '_' or '#'",
            )
            continue
        if not c.at(path).is_mapping(
            value,
            "a wind spec {type: ...} or {wind: {type: ...}, references: ..., description: ...}",
        ):
            continue
        keys = ("wind", "members", "references", "description", "current")
        current: _Current = (None, "", None)
        if "type" in value or not any(k in value for k in keys):
            # shorthand: the scenario is the wind spec itself
            wind, wpath, refs, desc = value, path, {}, ""
        else:
            c.at(path).keys(value, keys)
            if ("wind" in value) == ("members" in value):
                c.p.add(
                    path,
                    "give exactly one of `wind: {type: ...}` (one wind) or "
                    "`members: [...]` (an ensemble of winds)",
                )
                continue
            refs = _references(c, value.get("references"), join_path(path, "references"), n_legs)
            desc = c.at(path).string(value, "description", "") or ""
            cchk = c.at(join_path(path, "current"))
            if value.get("current") is not None and cchk.is_mapping(
                value["current"], "a current spec {type: " + "|".join(CURRENT_TYPES) + ", ...}"
            ):
                cur = check_current_spec(value["current"], cchk, _base_dir(c))
                current = (cur, cchk.where(), dict(value["current"]))
            if "members" in value:
                mpath = join_path(path, "members")
                for k, (spec, where) in enumerate(_members(c, value["members"], mpath), 1):
                    out[f"{name}#{k}"] = _scenario(
                        f"{name}#{k}", spec, refs, desc, c.p.prefix(where), str(name), current
                    )
                continue
            wind, wpath = value["wind"], join_path(path, "wind")
        parsed = _parse_wind(c, wind, wpath)
        if parsed is not None:
            out[name] = _scenario(name, parsed, refs, desc, c.p.prefix(wpath), "", current)
    return out


def _scenario(
    name: str,
    wind: WindSpec,
    refs: dict[str, tuple[float, ...]],
    desc: str,
    where: str,
    ensemble: str,
    current: _Current,
) -> dict[str, Any]:
    """The keyword arguments of one ``ScenarioSpec`` (its field names)."""
    return {
        "name": name,
        "wind": wind,
        "references": refs,
        "description": desc,
        "where": where,
        "ensemble": ensemble,
        "current": current[0],
        "current_where": current[1],
        "current_given": current[2],
    }


def _members(c: Checker, raw: Any, path: str) -> list[tuple[WindSpec, str]]:
    """The parsed member wind specs of an ensemble scenario, each with its key path.

    ``members`` is a list of wind specs, or ``{dim: NAME, wind: {type: netcdf, ...}}``:
    one member per index of the NetCDF dimension ``NAME`` (the spec's ``select`` picks it).
    """
    if isinstance(raw, list):
        if len(raw) < 2:
            c.p.add(path, f"an ensemble needs at least 2 members; got {len(raw)}")
            return []
        items = [
            (_parse_wind(c, spec, f"{path}[{k}]"), f"{path}[{k}]") for k, spec in enumerate(raw)
        ]
        return [(s, w) for s, w in items if s is not None]
    if not c.at(path).is_mapping(
        raw,
        "a list of wind specs, or {dim: NAME, wind: {type: "
        "netcdf, path: FILE}} (one member per index of that dimension)",
    ):
        return []
    c.at(path).keys(raw, ("dim", "wind"), ("dim", "wind"))
    dim, wpath = raw.get("dim"), join_path(path, "wind")
    wind = raw.get("wind")
    if not isinstance(dim, str) or not _wind_spec(c, wind, wpath):
        if "dim" in raw and not isinstance(dim, str):
            c.p.add(join_path(path, "dim"), f"expected a dimension name; got {show(dim)}")
        return []
    if wind.get("type") != "netcdf" or not isinstance(wind.get("path"), str):
        c.p.add(wpath, "members along a dimension need `type: netcdf` with a `path`")
        return []
    spec = check_wind_spec(wind, c.at(wpath), _base_dir(c))
    if not isinstance(spec, NetcdfWindSpec):
        return []
    n = _dimension_size(c, spec.path, _base_dir(c), dim, wpath)
    if n is None:
        return []
    return [
        (
            dataclasses.replace(spec, select=tuple({**dict(spec.select or ()), dim: k}.items())),
            wpath,
        )
        for k in range(n)
    ]


def _dimension_size(c: Checker, file: Path, base: Path, dim: str, path: str) -> int | None:
    """Size of dimension ``dim`` in a NetCDF file (a problem at ``path`` if it has none)."""
    from sailroute.wind.cf import dimension_sizes

    if not file.is_file():
        c.p.add(join_path(path, "path"), missing_file_message(file, base))
        return None
    try:
        dims = dimension_sizes(file)
    except OSError as exc:
        c.p.add(join_path(path, "path"), f"{file.name} cannot be read as NetCDF ({exc})")
        return None
    if dim not in dims:
        c.p.add(
            path,
            f"{file.name} has no dimension {dim!r}; it has "
            + ", ".join(f"{k} ({v})" for k, v in dims.items()),
        )
        return None
    return dims[dim]


# ----------------------------------------------------------------------------- template
_DIR = "direction"  # a compass direction, [0, 360] deg (nomenclature)
_POS = "positive"
_NONNEG = "nonnegative"
_TEMPLATE_KEYS: dict[str, dict[str, Any]] = {
    "windward-leeward": {
        "twd_deg": _DIR,
        "leg_length_m": _POS,
        "laps": "int",
        "gate_width_m": _POS,
        "start_line_length_m": _POS,
        "start_offset_m": _NONNEG,
        "finish": ("leeward", "windward"),
        "finish_line_length_m": _POS,
        "finish_offset_m": _NONNEG,
    },
    "trapezoid": {
        "twd_deg": _DIR,
        "leg_length_m": _POS,
        "laps": "int",
        "loop": ("inner", "outer"),
        "reach_angle_deg": _POS,
        "reach_length_m": _POS,
        "gate_width_m": _POS,
        "start_line_length_m": _POS,
        "start_offset_m": _NONNEG,
        "finish_line_length_m": _POS,
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
    c: Checker, raw: Any, time_limit_min: float | None = None
) -> tuple[CourseLayout | None, Position | None]:
    """Validate ``template`` and build its layout around ``centre`` (in a provisional frame)."""
    t = c.at("template")
    if not t.is_mapping(
        raw, "{type: windward-leeward|trapezoid, twd_deg, leg_length_m, centre, ...}"
    ):
        return None, None
    kind = t.choice(raw, "type", list(_TEMPLATE_KEYS))
    if kind is None:
        return None, None
    spec = _TEMPLATE_KEYS[kind]
    t.keys(raw, ("type", "centre", *spec), ("twd_deg", "leg_length_m", "centre"))
    centre = (
        _position(c, raw["centre"], "template.centre", "the course centre")
        if ("centre" in raw)
        else None
    )
    kw: dict[str, Any] = {}
    for key, rule in spec.items():
        if key not in raw:
            continue
        if rule == _DIR:
            v = t.number(raw, key, lo=0.0, hi=360.0)
        elif rule == _POS:
            v = t.number(raw, key, lo=0.0, lo_open=True)
        elif rule == _NONNEG:
            v = t.number(raw, key, lo=0.0)
        elif rule == "int":
            v = t.integer(raw, key, None, lo=1)
        else:
            v = t.choice(raw, key, rule)
        if v is not None and key.endswith("_m") and v > MAX_OFFSET_M:
            t.add(
                key,
                f"expected at most {MAX_OFFSET_M:.0f} m (a buoy course spans a few km); got {v:g}",
            )
            v = None
        elif v is not None and rule == _POS and key.endswith("_m") and v < MIN_SEPARATION_M:
            t.add(key, f"expected at least {MIN_SEPARATION_M:g} m; got {v:g}")
            v = None
        if v is not None:
            kw[key] = v
    if (
        centre is None
        or any(k not in kw for k in ("twd_deg", "leg_length_m"))
        or any(k in raw and k not in kw for k in spec)
    ):
        return None, centre
    twd, length = kw.pop("twd_deg"), kw.pop("leg_length_m")
    laps = kw.pop("laps", 2)
    most = _max_laps(length, time_limit_min)
    if laps > most:
        c.p.add(
            "template.laps",
            f"{laps} laps of 2 × {length:g} m cannot be sailed within "
            f"time_limit_min {time_limit_min or DEFAULT_TIME_LIMIT_MIN:g} even at 70 kn; "
            f"expected an integer in [1, {most}] (or raise time_limit_min)",
        )
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


# ----------------------------------------------------------------------------- the walk
def check_course(data: Any, problems: Problems) -> CheckedCourse:
    """Check a parsed course mapping; every problem goes to ``problems``.

    Parameters
    ----------
    data : Any
        The parsed YAML (what :func:`sailroute.course.read.read_course_file` returns).
    problems : Problems
        The course file's collector (its file name, line map and any problems found
        while reading, e.g. duplicate keys); relative NetCDF paths of ensemble
        members resolve against the folder of ``problems.file``.

    Returns
    -------
    CheckedCourse

    Raises
    ------
    InputError
        Listing every problem found (:meth:`~sailroute.checks.Problems.raise_if_any`).
    """
    probs = problems
    c = Checker(probs)
    if not isinstance(data, Mapping):
        what = "an empty file" if data is None else show(data)
        probs.add(
            "",
            "expected a course mapping with keys name, start_time, marks, legs, "
            f"scenarios, ...; got {what}",
        )
        probs.raise_if_any()
    c.keys(data, TOP_KEYS, ("name", "start_time"))
    name = c.string(data, "name", "") or ""
    description = data.get("description", "")
    if not isinstance(description, str):
        probs.add("description", f"expected text; got {show(description)}")
        description = ""
    start_time = _start_time(c, data) if "start_time" in data else None
    restart_time = _restart_time(c, data, start_time)
    time_limit = c.number(data, "time_limit_min", DEFAULT_TIME_LIMIT_MIN, lo=0.0, lo_open=True)

    # -- layout: explicit marks/lines/gates/legs, or a template
    template = data.get("template")
    layout_raw: dict[str, Any] = {k: data[k] for k in LAYOUT_KEYS if k in data}
    positions: dict[str, Position] = {}
    centre = None
    if template is not None:
        clash = [k for k in LAYOUT_KEYS if k in data]
        if clash:
            probs.add(
                clash[0],
                "a course with `template` gets its marks, lines, gates and "
                f"legs from the template; remove {', '.join(clash)} or the template",
            )
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
    needs = [join_path("marks", k) for k, (kind, _) in positions.items() if kind == "xy"]
    if template is not None:  # template marks are relative to the centre, not the origin
        needs = ["template.centre"] if centre is not None and centre[0] == "xy" else []
        latlons = [centre[1]] if centre is not None and centre[0] == "ll" else []
    frame = _frame(c, data, latlons, needs)
    marks = _place(positions, centre, frame) if frame is not None else {}
    if frame is not None:
        _near_origin(c, marks, frame, "origin" in data, template is not None)
    xy = {k: (m[0], m[1]) for k, m in marks.items()}

    taken = set(marks)
    lines_raw = layout_raw.get("lines")
    gates_raw = layout_raw.get("gates")
    lines = _pairs(c, lines_raw, "lines", xy, taken) if lines_raw is not None else {}
    gates = _pairs(c, gates_raw, "gates", xy, taken) if gates_raw is not None else {}
    legs: list[Leg] = []
    if "legs" in layout_raw and frame is not None:
        legs = _legs(c, layout_raw["legs"], xy, lines, gates)
    n_legs = (
        len(legs)
        if legs and "legs" in layout_raw and len(legs) == len(layout_raw["legs"])
        else None
    )

    boat = _boat(c, data.get("boat"))
    routing = load_routing(c, data.get("routing"))
    scenarios = _scenarios(c, data.get("scenarios"), n_legs)
    references = _references(c, data.get("references"), "references", n_legs)
    area = check_area(c, data, frame, xy, _position)
    chart = check_chart(c, data)
    uncertainty = (
        check_uncertainty(c.at("uncertainty"), data["uncertainty"], Path(probs.file).parent)
        if data.get("uncertainty") is not None
        else None
    )
    probs.raise_if_any()

    assert frame is not None and start_time is not None  # guaranteed when no problems
    return CheckedCourse(
        name=name,
        description=description,
        start_time=start_time,
        utc_offset_s=utc_offset_s(data["start_time"]),
        time_limit_min=float(time_limit),
        frame=frame,
        marks=marks,
        lines=lines,
        gates=gates,
        legs=tuple(legs),
        boat=boat,
        boat_where=probs.prefix("boat").removesuffix(": boat"),
        routing=routing,
        scenarios=scenarios,
        references=references,
        template=dict(template) if template is not None else None,
        area=area,
        uncertainty=uncertainty,
        restart_time=restart_time,
        chart=chart,
    )


def _near_origin(
    c: Checker,
    marks: Mapping[str, tuple[float, float, float, float]],
    frame: LocalFrame,
    given: bool,
    template: bool,
) -> None:
    """A problem for each mark farther than :data:`MAX_OFFSET_M` from the frame's origin
    (``given``: the file has ``origin``, else the origin is the mean of the marks; a
    ``template`` course gets one problem, at ``template.centre``)."""
    origin = (
        f"the origin ({frame.lat0:.6f}, {frame.lon0:.6f})"
        if given
        else f"the course's centre ({frame.lat0:.6f}, {frame.lon0:.6f}, the mean of the "
        "marks' lat/lon)"
    )
    for k, m in marks.items():
        d = math.hypot(m[0], m[1])
        if d <= MAX_OFFSET_M:  # False for NaN
            continue
        far = f"{d / 1000.0:.0f} km" if d < 1e7 else "more than 10000 km"
        where = "template.centre" if template else join_path("marks", k)
        c.p.add(
            where,
            f"mark {k!r} ({m[2]:.6f}, {m[3]:.6f}) lies {far} from {origin}; "
            f"expected every mark within {MAX_OFFSET_M / 1000.0:.0f} km of it (check the "
            "marks for a typing error)",
        )
        if template:
            return


def _place(
    positions: Mapping[str, Position], centre: Position | None, frame: LocalFrame
) -> dict[str, tuple[float, float, float, float]]:
    """Mark name -> ``(x, y, lat, lon)`` in ``frame``.

    A template's layout is built around (0, 0) and moved to its ``centre`` here.
    """
    if centre is not None:
        cx, cy = (
            centre[1] if centre[0] == "xy" else tuple(float(v) for v in frame.to_xy(*centre[1]))
        )
        positions = {k: ("xy", (x + cx, y + cy)) for k, (_, (x, y)) in positions.items()}
    out: dict[str, tuple[float, float, float, float]] = {}
    for k, (kind, (p, q)) in positions.items():
        if kind == "ll":
            x, y = (float(v) for v in frame.to_xy(p, q))
            out[k] = (x, y, p, q)
        else:
            lat, lon = (float(v) for v in frame.to_latlon(p, q))
            out[k] = (p, q, lat, lon)
    return out
