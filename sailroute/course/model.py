"""The race course: marks, lines, gates, legs, boat, routing settings and wind scenarios.

A :class:`Course` is what :func:`sailroute.course.load.load_course` returns.  Every
position is stored in the course's :class:`~sailroute.geo.LocalFrame` (metres east
``x`` and north ``y`` of the origin) and in latitude/longitude, so that routers work
in metres and reports can write geographic coordinates.

Wind and current specifications are parsed when the course loads, each into its frozen
dataclass (:mod:`sailroute.wind.specs`); the boat specification is kept as the raw YAML
mapping.  They are turned into a :class:`~sailroute.wind.base.WindField` and a
:class:`~sailroute.boat.polar.Polar` by ``sailroute.wind.build.build_wind_field`` and
``sailroute.boat.build`` when a plan is run (see :func:`sailroute.course.load.validate_specs`).
"""

from __future__ import annotations

import copyreg
from collections.abc import Mapping
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path
from types import MappingProxyType
from typing import Any, Literal

import numpy as np

from sailroute.course.chart import ChartFile
from sailroute.course.uncertainty import UncertaintySpec
from sailroute.geo import LocalFrame
from sailroute.routing.obstacles import RaceArea
from sailroute.routing.settings import RoutingSettings
from sailroute.routing.types import Side
from sailroute.timeutil import to_epoch
from sailroute.wind.specs import CURRENT_KINDS, WIND_KINDS, CurrentSpec, WindSpec

LegKind = Literal["mark", "gate", "line"]
"""What ends a leg: round a mark, pass through a gate, or cross a line."""


@dataclass(frozen=True)
class Mark:
    """A buoy (or committee boat) at a fixed position.

    Attributes
    ----------
    name : str
        Name used in ``lines``, ``gates`` and ``legs`` (e.g. ``"1"``, ``"4p"``).
    x, y : float
        Position in the course frame [m east, m north of the origin].
    lat, lon : float
        The same position in degrees (WGS-84).
    """

    name: str
    x: float
    y: float
    lat: float
    lon: float

    @property
    def xy(self) -> tuple[float, float]:
        """Position ``(x, y)`` [m]."""
        return (self.x, self.y)


@dataclass(frozen=True)
class Line:
    """A start or finish line between two marks.

    Attributes
    ----------
    name : str
        Line name (``"start"``, ``"finish"``, ...).
    a, b : Mark
        The two ends, in the order written in the course file.
    """

    name: str
    a: Mark
    b: Mark

    @property
    def length_m(self) -> float:
        """Distance between the two ends [m]."""
        return float(np.hypot(self.b.x - self.a.x, self.b.y - self.a.y))

    @property
    def midpoint(self) -> tuple[float, float]:
        """Midpoint ``(x, y)`` [m]."""
        return (0.5 * (self.a.x + self.b.x), 0.5 * (self.a.y + self.b.y))

    def fraction_of(self, xy: tuple[float, float]) -> float:
        """Position of the projection of ``xy`` on the line, 0 at ``a`` and 1 at ``b``."""
        dx, dy = self.b.x - self.a.x, self.b.y - self.a.y
        den = dx * dx + dy * dy
        if den == 0.0:
            return 0.0
        return float(((xy[0] - self.a.x) * dx + (xy[1] - self.a.y) * dy) / den)


@dataclass(frozen=True)
class Gate(Line):
    """A gate: two marks that boats pass between, then round either one.

    Same attributes as :class:`Line`.
    """


@dataclass(frozen=True)
class LegSpec:
    """One leg of the course as written in the course file.

    Attributes
    ----------
    index : int
        Position in the course, 0-based.
    from_name : str
        Where the leg starts: the first leg's ``from`` (a line or mark); for later
        legs the previous leg's ``to``.
    to_name : str
        The mark, gate or line that ends the leg.
    kind : {"mark", "gate", "line"}
        What ``to_name`` is.
    rounding : {"port", "starboard"} or None
        Side the mark is left on (marks only; None for gates and lines).
    """

    index: int
    from_name: str
    to_name: str
    kind: LegKind
    rounding: Side | None = None

    @property
    def label(self) -> str:
        """``"from -> to"`` for tables."""
        return f"{self.from_name} -> {self.to_name}"


def frozen_mapping(d: Mapping[str, Any] | None) -> Mapping[str, Any]:
    """A read-only copy of ``d`` (``None`` gives an empty one).

    The mapping fields of :class:`ScenarioSpec` and :class:`Course` must be such
    copies (:class:`types.MappingProxyType`): the course builder
    (:mod:`sailroute.course.build`) makes them.
    """
    return MappingProxyType(dict(d or {}))


def _require_frozen(owner: str, field_name: str, value: object) -> None:
    """Raise TypeError unless ``value`` is a read-only mapping (see :func:`frozen_mapping`)."""
    if not isinstance(value, MappingProxyType):
        raise TypeError(
            f"{owner}.{field_name} must be a read-only mapping (types.MappingProxyType), "
            f"got {type(value).__name__}; wrap it with "
            f"sailroute.course.model.frozen_mapping(...), or load the course with "
            "sailroute.course.load.load_course, whose builder does"
        )


def _empty() -> Mapping[str, Any]:
    return MappingProxyType({})


def _reduce_proxy(m: MappingProxyType) -> tuple[Any, tuple[dict[str, Any]]]:
    """Pickle a read-only mapping as a copy of its dict (for process/Dask workers)."""
    return frozen_mapping, (dict(m),)


copyreg.pickle(MappingProxyType, _reduce_proxy)


@dataclass(frozen=True, eq=False)
class ScenarioSpec:
    """A named wind scenario.

    Attributes
    ----------
    name : str
        Scenario name (the key under ``scenarios``).
    wind : WindSpec
        The parsed wind spec (a dataclass of :mod:`sailroute.wind.specs`, one per type
        of :data:`~sailroute.wind.specs.WIND_TYPES`), built into a field by
        ``sailroute.wind.build.build_wind_field``.
    references : mapping of str to tuple of float
        Leg times [s] to compare this scenario with, in addition to the course-wide
        ``references`` (e.g. the thesis's own model output for the same wind).
    description : str
        Free text for reports.
    where : str
        Key path of the wind spec for error messages
        (e.g. ``"courses/hyeres-r1.yaml: scenarios.wrf10.wind"``).
    ensemble : str
        For a member of an ensemble scenario (``members:``), the ensemble's name; the
        member itself is called ``"<ensemble>#<k>"`` (k from 1).  Empty otherwise.
    current : CurrentSpec or None
        The parsed surface-current spec (``scenarios.<name>.current``, built by
        ``sailroute.wind.build.build_current_field``); None: still water.
    current_where : str
        Key path of the current spec for error messages.
    current_given : mapping or None
        The current spec as the file gives it (written to ``plan.json``).
    """

    name: str
    wind: WindSpec
    references: Mapping[str, tuple[float, ...]] = field(default_factory=_empty)
    description: str = ""
    where: str = ""
    ensemble: str = ""
    current: CurrentSpec | None = None
    current_where: str = ""
    current_given: Mapping[str, Any] | None = None

    def __post_init__(self) -> None:
        if self.current_given is not None:
            _require_frozen("ScenarioSpec", "current_given", self.current_given)
        _require_spec("wind", self.wind, WIND_KINDS, "parse_wind_spec")
        _require_frozen("ScenarioSpec", "references", self.references)
        if self.current is not None:
            _require_spec("current", self.current, CURRENT_KINDS, "parse_current_spec")


def _require_spec(field_name: str, value: object, kinds: Mapping[str, Any], parser: str) -> None:
    """Raise TypeError unless ``value`` is a parsed spec of one of ``kinds``."""
    if not any(type(value) is k.spec for k in kinds.values()):
        raise TypeError(
            f"ScenarioSpec.{field_name} must be a parsed {field_name} spec (a dataclass of "
            f"sailroute.wind.specs), got {type(value).__name__}; parse the mapping with "
            f"sailroute.wind.specs.{parser}(...), or load the course with "
            "sailroute.course.load.load_course, which does"
        )


@dataclass(frozen=True, eq=False)
class Course:
    """A validated race course.

    Attributes
    ----------
    name : str
        Course name.
    start_time : datetime
        Start signal, timezone-aware, in UTC.
    frame : LocalFrame
        The local metric frame all ``x, y`` refer to.
    marks : mapping of str to Mark
        All marks by name, in file order.
    lines : mapping of str to Line
        Start/finish lines by name.
    gates : mapping of str to Gate
        Gates by name.
    legs : tuple of LegSpec
        The legs in sailing order.
    boat_spec : mapping
        Raw ``boat`` section (``{builtin: ilca7}``, ``{polar: path}`` or ``{vpp: {...}}``).
    routing : RoutingSettings
        Router and its settings from the ``routing`` section.
    scenarios : mapping of str to ScenarioSpec
        Wind scenarios by name, in file order.
    references : mapping of str to tuple of float
        Course-wide reference leg times [s] (e.g. the race winner's), one per leg.
    source : Path or None
        The course file (relative ``path`` values in specs resolve against its folder).
    description : str
        Free text.
    template : mapping or None
        The raw ``template`` section if the layout was generated from one.
    time_limit_s : float
        Wind data must cover ``[start_time, start_time + time_limit_s]`` [s]; routes
        that take longer run out of wind data (``time_limit_min`` in the file).
    boat_where : str
        ``"file:line"`` of the ``boat`` section, for the boat factory's messages.
    utc_offset_s : float
        The course's local time offset from UTC [s], taken from the offset
        ``start_time`` is written with (``+02:00`` -> 7200); for reports.
    key_lines : mapping of str to int
        1-based line of each key path of the course file (``"scenarios.a.wind.tws_kn"``),
        so that the boat factory reports problems at their lines (the wind and current
        specs were parsed with it at load);
        empty for a course built from a mapping.
    area : RaceArea
        The race area: ``boundary``, ``obstacles`` and ``wind_land_is_obstacle``,
        polygons in the local frame (:mod:`sailroute.routing.obstacles`).
    uncertainty : UncertaintySpec or None
        The ``uncertainty`` section (how far the leg-time bands of ``plan --ensemble``
        spread, :mod:`sailroute.course.uncertainty`); None: not given.
    restart_time : datetime or None
        The start signal of the restart after a general recall (``restart_time`` in the
        file); ``analyze`` times the race from it.  None: no recall.
    chart : ChartFile or None
        The ``chart`` file: coast or land polygons drawn under the maps
        (:mod:`sailroute.course.chart`); None: not given.
    """

    name: str
    start_time: datetime
    frame: LocalFrame
    marks: Mapping[str, Mark]
    lines: Mapping[str, Line]
    gates: Mapping[str, Gate]
    legs: tuple[LegSpec, ...]
    boat_spec: Mapping[str, Any] = field(default_factory=_empty)
    routing: RoutingSettings = field(default_factory=RoutingSettings)
    scenarios: Mapping[str, ScenarioSpec] = field(default_factory=_empty)
    references: Mapping[str, tuple[float, ...]] = field(default_factory=_empty)
    source: Path | None = None
    description: str = ""
    template: Mapping[str, Any] | None = None
    time_limit_s: float = 5400.0
    boat_where: str = ""
    utc_offset_s: float = 0.0
    key_lines: Mapping[str, int] = field(default_factory=dict)
    area: RaceArea = field(default_factory=RaceArea)
    uncertainty: UncertaintySpec | None = None
    restart_time: datetime | None = None
    chart: ChartFile | None = None

    def __post_init__(self) -> None:
        for name in ("marks", "lines", "gates", "boat_spec", "scenarios", "references"):
            _require_frozen("Course", name, getattr(self, name))
        if not isinstance(self.legs, tuple):
            raise TypeError(
                f"Course.legs must be a tuple of LegSpec, got {type(self.legs).__name__}; "
                "pass tuple(legs)"
            )

    @property
    def start_epoch(self) -> float:
        """Start time [epoch s]."""
        return to_epoch(self.start_time)

    @property
    def gun_epoch(self) -> float:
        """The gun a sailed race is timed from [epoch s]: ``restart_time`` after a general
        recall, else ``start_time``."""
        return to_epoch(self.restart_time) if self.restart_time is not None else self.start_epoch

    @property
    def base_dir(self) -> Path:
        """Folder that relative paths in the course file are resolved against."""
        return self.source.parent if self.source is not None else Path.cwd()

    @property
    def n_legs(self) -> int:
        """Number of legs."""
        return len(self.legs)

    @property
    def ensembles(self) -> dict[str, tuple[str, ...]]:
        """Ensemble scenario name -> its member scenario names, in file order."""
        out: dict[str, list[str]] = {}
        for name, sc in self.scenarios.items():
            if sc.ensemble:
                out.setdefault(sc.ensemble, []).append(name)
        return {k: tuple(v) for k, v in out.items()}

    @property
    def scenario_names(self) -> tuple[str, ...]:
        """The scenarios as the file names them: an ensemble once, by its own name."""
        names = (sc.ensemble or name for name, sc in self.scenarios.items())
        return tuple(dict.fromkeys(names))

    def where(self, key_path: str) -> str:
        """Error-message prefix ``"<file>: <key_path>"`` for specs of this course."""
        src = str(self.source) if self.source is not None else "<course>"
        return f"{src}: {key_path}"

    def references_for(self, scenario: str | None = None) -> dict[str, tuple[float, ...]]:
        """Course-wide references plus those of ``scenario`` (scenario wins on a clash)."""
        out = dict(self.references)
        if scenario is not None and scenario in self.scenarios:
            out.update(self.scenarios[scenario].references)
        return out

    def feature(self, name: str) -> Mark | Line | Gate:
        """The mark, line or gate called ``name``.

        Raises
        ------
        KeyError
            If there is none (a validated course only refers to existing names).
        """
        for table in (self.marks, self.gates, self.lines):
            if name in table:
                return table[name]
        raise KeyError(name)
