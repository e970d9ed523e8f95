"""Routing settings: the fields every router reads, and one settings class per router.

:class:`RoutingSettings` holds the router's name and the rules of the race that every
router honours (penalties, the tack at the start, the rounding zone, the start-line
spacing, the time limit), and one group per router, named as the router:
``settings.isochrone`` (:class:`IsochroneSettings`), ``settings.griddp``
(:class:`GridDPSettings`) and ``settings.spline`` (:class:`SplineSettings`).  Each
router's entry in :data:`sailroute.routing.api.ROUTERS` declares its class
(``RouterEntry.settings_type``).

Each class checks its own fields (``problems()``); :func:`settings_problems` checks
them all, whichever router is chosen (a course may switch router on the command line),
and :func:`check_settings` raises with its lines.

Course files and older code name the fields flat (``dt_s``, ``dp_cols``,
``spline_slopes``, ...): :func:`routing_settings` sorts those names into the groups
(:data:`FLAT_NAMES`; ``dp_rows`` and ``dp_half_width_m`` set both the grid-DP and the
multi-spline rows and corridor, which share them).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, ClassVar, Final, get_args

import numpy as np

from sailroute.checks import real_number, suggest
from sailroute.errors import InputError
from sailroute.routing.types import SIDE_NAMES, RouterName, Side

Namer = Callable[[str], str]
"""How a problem line names a field, given its path in :class:`RoutingSettings`
(``"griddp.cols"``, ``"zone_m"``): the course loader names the key the file used."""

MIN_DT_S: Final = 0.5
"""Smallest isochrone time step :attr:`IsochroneSettings.dt_s` [s]: halving the default
10 s down to 1.25 s moved a 1809 m beat by < 2e-5 (``docs/design/routing.md``), while
the work grows as 1/dt (0.05 s took over 30 s for a 300 m leg; 1e-9 s never ends)."""
MIN_MIN_DT_S: Final = 0.01
"""Smallest :attr:`IsochroneSettings.min_dt_s` [s] (the refined step near the target)."""
MIN_HEADING_STEP_DEG: Final = 0.1
"""Finest heading resolution :attr:`IsochroneSettings.heading_step_deg` [°]: the polar is
tabulated at ``180 / step`` angles and each front point tries them all (1e-4° hung,
1e-9° asked for 1.3 TiB)."""
MAX_FRONT_POINTS: Final = 100_000
"""Largest :attr:`IsochroneSettings.max_front_points` (the default is 2000)."""
MAX_DP_SEGMENT_SAMPLES: Final = 200_000_000
"""Most wind samples along grid-DP segments per leg: ``(rows - 1) * cols**2 * samples *
(refinements + 1)`` of :class:`GridDPSettings`, an upper bound [-].  About 1 µs each, so
minutes; the defaults need 2.4e6, Dębski's C = 128 with 30 rows 4.8e5."""
MAX_SPLINE_ROW_EDGES: Final = 20_000_000
"""Most multi-spline edges between two rows, ``(cols * slopes)**2`` of
:class:`SplineSettings`: each costed edge array holds this many float64 (160 MB); the
defaults have 30 625."""
MAX_SPLINE_EDGES: Final = 2_000_000_000
"""Most multi-spline edges per leg, ``(rows - 1) * (cols * slopes)**2 * (refinements + 1)``
of :class:`SplineSettings` (the defaults: 1.5e6)."""


ENGINES: Final = ("auto", "numpy", "numba")
"""Values of :attr:`IsochroneSettings.engine`."""


class _Problems(list[str]):
    """The problems of one settings object, with the two common checks."""

    def __init__(self, s: object, name: Namer) -> None:
        super().__init__()
        self.s = s
        self.name = name

    def number(self, attr: str, *, strict: bool = True) -> None:
        v = getattr(self.s, attr)
        if not (real_number(v) and (v > 0 if strict else v >= 0)):
            self.append(
                f"{self.name(attr)} must be a number {'>' if strict else '>='} 0, got {v!r}"
            )

    def integer(self, attr: str, lo: int, hi: int, text: str) -> None:
        v = getattr(self.s, attr)
        if not (isinstance(v, int | np.integer) and not isinstance(v, bool) and lo <= v <= hi):
            self.append(f"{self.name(attr)} must be an integer {text}, got {v!r}")

    def boolean(self, attr: str) -> None:
        v = getattr(self.s, attr)
        if not isinstance(v, bool | np.bool_):
            self.append(f"{self.name(attr)} must be true or false, got {v!r}")

    def half_width(self, attr: str) -> None:
        hw = getattr(self.s, attr)
        if hw is not None and not (real_number(hw) and hw > 0):
            self.append(f"{self.name(attr)} must be > 0 m or None (automatic), got {hw!r}")


def _group_namer(group: str, name: Namer | None) -> Namer:
    """Field -> its name in a problem line: ``name("group.field")``, by default the path."""
    if name is None:
        return lambda attr: f"{group}.{attr}"
    return lambda attr: name(f"{group}.{attr}")


@dataclass(frozen=True)
class IsochroneSettings:
    """Settings of the isochrone router (``routing/isochrone.py``, its kernel and the
    ensemble batch ``routing/batch.py``).

    Attributes
    ----------
    dt_s : float
        Time step [s] (default 10 s: with mid-step wind sampling, halving it down to
        1.25 s moved a 1809 m beat by < 2e-5; see docs/design/routing.md).
    heading_step_deg : float
        Heading resolution [°]: the polar is tabulated every this many degrees of TWA.
    min_dt_s : float
        Smallest time step of the refinement near the target [s] (steps shrink from
        ``dt_s`` once the target is a few steps away).
    prune_sector_deg : float
        Width of the pruning sectors, in bearing seen from the target [°]; one point
        per sector and tack side survives each step.
    max_front_points : int
        Cap on the points kept per step (sectors widen to respect it).
    heading_fan : {"hull", "full"}
        ``"hull"`` tries grid TWAs between the upwind and downwind VMG angles only
        (the rest of the polar is never optimal without a tack penalty; the exact VMG
        angles and the direct bearing to the target are always tried); ``"full"``
        tries the whole circle.
    engine : {"auto", "numpy", "numba"}
        Kernels of a step: ``"numba"`` compiled (``sailroute/routing/isochrone_jit.py``,
        the extra ``fast``), ``"numpy"`` NumPy calls, ``"auto"`` compiled where numba is
        installed and the work pays for its start-up (an ensemble, a process that has
        routed a while, or kernels already in numba's cache:
        :func:`~sailroute.routing.isochrone_fast.compiled`).  The routes are the same
        bit for bit.
    """

    FLAT: ClassVar[Mapping[str, str]] = {
        "dt_s": "dt_s",
        "heading_step_deg": "heading_step_deg",
        "min_dt_s": "min_dt_s",
        "prune_sector_deg": "prune_sector_deg",
        "max_front_points": "max_front_points",
        "heading_fan": "heading_fan",
        "engine": "engine",
    }
    """Field -> its flat name in a course file's ``routing:`` section."""

    dt_s: float = 10.0
    heading_step_deg: float = 2.0
    min_dt_s: float = 1.0
    prune_sector_deg: float = 1.0
    max_front_points: int = 2000
    heading_fan: str = "hull"
    engine: str = "auto"

    def problems(self, name: Namer | None = None) -> list[str]:
        """What is wrong with these settings, one line per field (empty when valid).

        Parameters
        ----------
        name : callable, optional
            Names a field in the lines, given its path (``"isochrone.dt_s"``); default
            the path itself.
        """
        p = _Problems(self, _group_namer("isochrone", name))
        for attr in ("dt_s", "heading_step_deg", "min_dt_s", "prune_sector_deg"):
            p.number(attr)
        step = self.heading_step_deg
        if real_number(step) and step > 45:
            p.append(f"{p.name('heading_step_deg')} must be <= 45, got {step!r}")
        if real_number(step) and 0 < step < MIN_HEADING_STEP_DEG:
            p.append(
                f"{p.name('heading_step_deg')} must be in [{MIN_HEADING_STEP_DEG:g}, 45] "
                f"(default 2; finer steps only slow the router), got {step!r}"
            )
        if real_number(self.dt_s) and 0 < self.dt_s < MIN_DT_S:
            p.append(
                f"{p.name('dt_s')} must be >= {MIN_DT_S:g} s (default 10; finer steps hardly "
                f"change the route and make it slow), got {self.dt_s!r}"
            )
        if real_number(self.min_dt_s) and 0 < self.min_dt_s < MIN_MIN_DT_S:
            p.append(
                f"{p.name('min_dt_s')} must be >= {MIN_MIN_DT_S:g} s (default 1), "
                f"got {self.min_dt_s!r}"
            )
        p.integer("max_front_points", 8, MAX_FRONT_POINTS, f"in [8, {MAX_FRONT_POINTS}]")
        if self.heading_fan not in ("hull", "full"):
            p.append(f"{p.name('heading_fan')} must be 'hull' or 'full', got {self.heading_fan!r}")
        if self.engine not in ENGINES:
            p.append(
                f"{p.name('engine')} must be one of {', '.join(repr(e) for e in ENGINES)} "
                "(the same routes; 'auto': compiled where numba is installed and the work "
                f"pays for its start-up), got {self.engine!r}"
            )
        return list(p)


@dataclass(frozen=True)
class GridDPSettings:
    """Settings of the grid dynamic-programming router (``routing/griddp.py``).

    Attributes
    ----------
    rows : int
        Rows of nodes including the start and target rows (Dębski: 10-16).
    cols : int
        Nodes per row, C (Dębski: up to 128).
    refinements : int
        Mesh refinements after the first pass (each centred on the best route so far,
        band scaled by ``shrink``).
    half_width_m : float or None
        Half-width of the node rows [m]; None derives it from the one-tack laylines
        (see ``docs/design/griddp.md``).
    shrink : float
        Band scale factor per refinement (0.5 halves the node spacing).
    samples : int
        Pieces per segment along which the wind is sampled.
    """

    FLAT: ClassVar[Mapping[str, str]] = {
        "rows": "dp_rows",
        "cols": "dp_cols",
        "refinements": "dp_refinements",
        "half_width_m": "dp_half_width_m",
        "shrink": "dp_shrink",
        "samples": "dp_samples",
    }
    """Field -> its flat name in a course file's ``routing:`` section."""

    rows: int = 13
    cols: int = 64
    refinements: int = 2
    half_width_m: float | None = None
    shrink: float = 0.5
    samples: int = 4

    def problems(self, name: Namer | None = None) -> list[str]:
        """What is wrong with these settings, one line per field, then the work of a leg
        if it would take minutes (empty when valid; ``name`` as for
        :meth:`IsochroneSettings.problems`, paths ``"griddp.cols"``)."""
        p = _Problems(self, _group_namer("griddp", name))
        p.integer("rows", 3, 200, "in [3, 200]")
        p.integer("cols", 2, 1024, "in [2, 1024]")
        p.integer("refinements", 0, 20, "in [0, 20]")
        p.integer("samples", 1, 64, "in [1, 64]")
        if not (real_number(self.shrink) and 0 < self.shrink <= 1):
            p.append(f"{p.name('shrink')} must be in (0, 1], got {self.shrink!r}")
        p.half_width("half_width_m")
        if not p:  # every count a valid integer: estimate the work
            p += self._work(p.name)
        return list(p)

    def _work(self, name: Namer) -> list[str]:
        """The wind samples of a leg, estimated from the settings alone (the leg's length
        does not change it): one line if they would take too long."""
        rows, cols, ref, smp = self.rows - 1, self.cols, self.refinements + 1, self.samples
        dp = float(rows) * cols * cols * smp * ref
        if dp <= MAX_DP_SEGMENT_SAMPLES:
            return []
        return [
            f"{name('cols')} = {cols} with {name('rows')} = {self.rows}, {name('samples')} = "
            f"{smp} and {name('refinements')} = {ref - 1} needs about {dp:.1e} wind samples "
            f"per leg (rows x cols^2 x samples x passes), more than "
            f"{MAX_DP_SEGMENT_SAMPLES:.0e} (minutes of work); lower them (defaults 64 "
            "columns, 13 rows, 4 samples, 2 refinements)"
        ]


@dataclass(frozen=True)
class SplineSettings:
    """Settings of the multi-spline router (``routing/multispline.py``).

    Attributes
    ----------
    rows : int
        Rows of nodes including the start and target rows (as :attr:`GridDPSettings.rows`;
        the flat name ``dp_rows`` sets both).
    half_width_m : float or None
        Half-width of the node rows [m]; None derives it from the one-tack laylines
        (the flat name ``dp_half_width_m`` sets both routers').
    cols, slopes, refinements : int
        Nodes per row, tangent slopes per node (n_ts) and refinements (ranges shrink
        by 1/3 each).
    carry_speed : bool
        Dynamic boat: enter each edge at the end speed of the best previous edge (the
        DP carries it, as Dębski's) instead of the steady speed of the node's tangent.
        No effect with a polar.
    start_from_rest : bool
        Dynamic boat: the first edge starts from rest instead of at the steady speed
        (a flying start).  No effect with a polar.
    """

    FLAT: ClassVar[Mapping[str, str]] = {
        "rows": "dp_rows",
        "half_width_m": "dp_half_width_m",
        "cols": "spline_cols",
        "slopes": "spline_slopes",
        "refinements": "spline_refinements",
        "carry_speed": "spline_carry_speed",
        "start_from_rest": "spline_start_from_rest",
    }
    """Field -> its flat name in a course file's ``routing:`` section."""

    rows: int = 13
    half_width_m: float | None = None
    cols: int = 25
    slopes: int = 7
    refinements: int = 3
    carry_speed: bool = False
    start_from_rest: bool = False

    def problems(self, name: Namer | None = None) -> list[str]:
        """What is wrong with these settings, one line per field, then the work of a leg
        if it would take minutes or too much memory (empty when valid; ``name`` as for
        :meth:`IsochroneSettings.problems`, paths ``"spline.cols"``)."""
        p = _Problems(self, _group_namer("spline", name))
        p.integer("rows", 3, 200, "in [3, 200]")
        for attr, lo in (("cols", 2), ("slopes", 1), ("refinements", 0)):
            p.integer(attr, lo, 1000, f">= {lo}")
        p.half_width("half_width_m")
        p.boolean("carry_speed")
        p.boolean("start_from_rest")
        if not p:
            p += self._work(p.name)
        return list(p)

    def _work(self, name: Namer) -> list[str]:
        """The edges of a leg, estimated from the settings alone: one line if they would
        take too long or too much memory."""
        per_row = float(self.cols * self.slopes) ** 2
        total = per_row * (self.rows - 1) * (self.refinements + 1)
        if per_row <= MAX_SPLINE_ROW_EDGES and total <= MAX_SPLINE_EDGES:
            return []
        cols, slopes, ref = name("cols"), name("slopes"), name("refinements")
        return [
            f"{cols} = {self.cols} with {slopes} = {self.slopes} needs {per_row:.1e} edges "
            f"between two rows and {total:.1e} per leg, more than {MAX_SPLINE_ROW_EDGES:.0e} "
            f"and {MAX_SPLINE_EDGES:.0e} (memory and minutes of work); lower {cols}, "
            f"{slopes} or {ref} (defaults 25, 7, 3)"
        ]


@dataclass(frozen=True)
class RoutingSettings:
    """Router choice, the race rules every router honours, and each router's settings.

    Attributes
    ----------
    router : {"isochrone", "griddp", "spline"}
        Which router to use.
    tack_penalty_s, gybe_penalty_s : float
        Time lost per tack / gybe [s], independent of the time step.
    initial_side : {"port", "starboard"} or None
        Tack at the start of a leg; None lets the router choose freely.
    zone_m : float
        Length of a mark's rounding segment [m] (see ``routing/geometry.py``):
        the leg ends when the boat crosses it, so it is how close a rounding
        must pass.  Default 13 m, about three Laser hull lengths.
    start_line_spacing_m : float
        Spacing of the candidate start points along a start line [m].
    max_leg_time_s : float
        A leg not finished after this much race time [s] fails with
        :class:`~sailroute.errors.RoutingError`.
    isochrone : IsochroneSettings
        Time step, heading resolution and front pruning of the isochrone router.
    griddp : GridDPSettings
        Mesh of the grid DP router.
    spline : SplineSettings
        Mesh, slopes and dynamic-boat switches of the multi-spline router.
    """

    router: RouterName = "isochrone"
    tack_penalty_s: float = 5.0
    gybe_penalty_s: float = 3.0
    initial_side: Side | None = None
    zone_m: float = 13.0
    start_line_spacing_m: float = 5.0
    max_leg_time_s: float = 10800.0
    isochrone: IsochroneSettings = field(default_factory=IsochroneSettings)
    griddp: GridDPSettings = field(default_factory=GridDPSettings)
    spline: SplineSettings = field(default_factory=SplineSettings)

    def problems(self, name: Namer | None = None) -> list[str]:
        """What is wrong, one line per field: the common fields, then each router's
        (:func:`settings_problems`)."""
        return settings_problems(self, name)


GROUPS: Final[Mapping[str, type[IsochroneSettings | GridDPSettings | SplineSettings]]] = {
    "isochrone": IsochroneSettings,
    "griddp": GridDPSettings,
    "spline": SplineSettings,
}
"""Router name -> its settings class, the :class:`RoutingSettings` field of that name."""
COMMON_FIELDS: Final[tuple[str, ...]] = tuple(
    f.name for f in dataclasses.fields(RoutingSettings) if f.name not in GROUPS
)
"""The fields of :class:`RoutingSettings` that every router reads."""


def _flat_names() -> dict[str, tuple[str, ...]]:
    out: dict[str, tuple[str, ...]] = {}
    for group, cls in GROUPS.items():
        for attr, flat in cls.FLAT.items():
            out[flat] = (*out.get(flat, ()), f"{group}.{attr}")
    return out


FLAT_NAMES: Final[Mapping[str, tuple[str, ...]]] = _flat_names()
"""Flat name of a router's field (``dp_cols``) -> its paths in :class:`RoutingSettings`
(``("griddp.cols",)``; ``dp_rows`` and ``dp_half_width_m`` name two)."""


def flat_name(path: str) -> str:
    """The flat name of a field path (``"griddp.cols"`` -> ``"dp_cols"``; a common field
    or a path without one is returned as it is)."""
    group, _, attr = path.partition(".")
    cls = GROUPS.get(group)
    return cls.FLAT.get(attr, path) if cls is not None and attr else path


def routing_settings(base: RoutingSettings | None = None, /, **flat: Any) -> RoutingSettings:
    """Routing settings from flat names, as a course file's ``routing:`` section gives them.

    Parameters
    ----------
    base : RoutingSettings, optional
        The settings to change (default :class:`RoutingSettings()`).
    **flat
        Common fields (``router``, ``zone_m``, ...), flat names of the routers' fields
        (:data:`FLAT_NAMES`: ``dt_s``, ``dp_cols``, ``spline_slopes``, ...) or whole
        groups (``griddp=GridDPSettings(...)``, applied before the flat names).  Values
        are not checked (see :func:`check_settings`).

    Returns
    -------
    RoutingSettings

    Raises
    ------
    InputError
        For an unknown name, with a did-you-mean and the valid names.
    """
    values: dict[str, Any] = {}
    for key, value in flat.items():
        if key in COMMON_FIELDS or key in GROUPS:
            values[key] = value
        elif key in FLAT_NAMES:
            values.update(dict.fromkeys(FLAT_NAMES[key], value))
        else:
            valid = [*COMMON_FIELDS, *FLAT_NAMES, *GROUPS]
            raise InputError(
                f"routing setting {key!r}: unknown name; {suggest(key, valid)}valid names: "
                + ", ".join(valid)
            )
    return with_paths(RoutingSettings() if base is None else base, values)


def with_paths(base: RoutingSettings, values: Mapping[str, Any]) -> RoutingSettings:
    """``base`` with the fields at the paths of ``values`` replaced: common fields and whole
    groups (``"zone_m"``, ``"griddp"``) first, then the groups' fields (``"griddp.cols"``).
    Values are not checked (see :func:`check_settings`)."""
    groups: dict[str, dict[str, Any]] = {}
    for path, v in values.items():
        group, _, attr = path.partition(".")
        if attr:
            groups.setdefault(group, {})[attr] = v
    out = dataclasses.replace(base, **{p: v for p, v in values.items() if "." not in p})
    changed = {g: dataclasses.replace(getattr(out, g), **kw) for g, kw in groups.items()}
    return dataclasses.replace(out, **changed)


def _common_problems(s: RoutingSettings, p: _Problems) -> None:
    """The router name, the time limit, the penalties and the start-line spacing."""
    if s.router not in get_args(RouterName):
        p.append(
            f"{p.name('router')} must be one of "
            + ", ".join(repr(r) for r in get_args(RouterName))
            + f", got {s.router!r}"
        )
    for attr in ("max_leg_time_s", "start_line_spacing_m", "zone_m"):
        p.number(attr)
    for attr in ("tack_penalty_s", "gybe_penalty_s"):
        p.number(attr, strict=False)
    if s.initial_side is not None and s.initial_side not in SIDE_NAMES:
        p.append(
            f"{p.name('initial_side')} must be 'port', 'starboard' or None, got {s.initial_side!r}"
        )


def settings_problems(s: RoutingSettings, name: Namer | None = None) -> list[str]:
    """What is wrong with ``s``, one line per field (empty when every field is valid).

    The one place that validates :class:`RoutingSettings`: every router calls
    :func:`check_settings`, which raises with these lines.  Every field is checked,
    whichever router is chosen (a course may switch router on the command line): the
    common fields, then each router's own (``IsochroneSettings.problems()``, ...), with
    the work a grid-DP or spline leg would take.

    Parameters
    ----------
    s : RoutingSettings
        The settings.
    name : callable, optional
        Names a field in the lines, given its path (``"zone_m"``, ``"griddp.cols"``);
        default the path itself.
    """
    namer: Namer = (lambda path: path) if name is None else name
    p = _Problems(s, namer)
    _common_problems(s, p)
    for group, cls in GROUPS.items():
        value = getattr(s, group)
        if isinstance(value, cls):
            # a field two routers share (``dp_rows`` in a course file) is named once
            p += [line for line in value.problems(namer) if line not in p]
        else:
            p.append(f"{namer(group)} must be a {cls.__name__}, got {value!r}")
    return list(p)


def check_settings(s: RoutingSettings, label: str) -> None:
    """Refuse invalid routing settings (see :func:`settings_problems`).

    Parameters
    ----------
    s : RoutingSettings
        The settings.
    label : str
        The leg, for the message (``"start -> 1"``).

    Raises
    ------
    InputError
        ``leg LABEL: invalid routing settings:`` and one line per bad field, with the
        expected range and the value given.
    """
    problems = settings_problems(s)
    if problems:
        raise InputError(
            f"leg {label}: invalid routing settings:\n" + "\n".join(f"  - {p}" for p in problems)
        )
