"""Data types shared by all routers and by the course/report layers.

A router takes a :class:`Start`, a :class:`Target`, a start time, a wind field,
a boat and :class:`RoutingSettings`, and returns a :class:`LegResult`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from types import ModuleType
from typing import TYPE_CHECKING, Final, Literal, Protocol, get_args

import numpy as np
from numpy.typing import NDArray

from sailroute.checks import real_number
from sailroute.errors import InputError

if TYPE_CHECKING:
    from sailroute.boat.model import BoatModel
    from sailroute.routing.obstacles import Obstacles
    from sailroute.wind.base import WindField
    from sailroute.wind.current import CurrentField

Side = Literal["port", "starboard"]
"""A tack (or a mark's rounding side) at every public boundary: settings, files, JSON,
the CLI.  Arrays hold :func:`side_sign` numbers instead."""
TargetKind = Literal["mark", "gate", "line"]
RouterName = Literal["isochrone", "griddp", "spline"]

SIDE_NAMES: Final[tuple[Side, ...]] = get_args(Side)
"""The valid :data:`Side` names, ``("port", "starboard")``."""
_SIGNS: Final[dict[str, int]] = {"starboard": 1, "port": -1}


def side_sign(name: Side | None) -> int:
    """Array code of a tack: +1 starboard, -1 port, 0 not chosen (``None``).

    Raises
    ------
    InputError
        For any other name (the message lists the valid ones).
    """
    if name is None:
        return 0
    sign = _SIGNS.get(name) if isinstance(name, str) else None
    if sign is None:
        raise InputError(f"side {name!r}: expected 'port' or 'starboard'")
    return sign


def side_name(sign: int | np.integer | float) -> Side:
    """Name of an array tack code: ``"starboard"`` for +1, ``"port"`` for -1.

    The inverse of :func:`side_sign` on ±1; any positive number counts as starboard and
    any negative one as port (e.g. a float array's entries).

    Raises
    ------
    ValueError
        For 0 (no tack chosen) or NaN: there is no name to give.
    """
    if sign > 0:
        return "starboard"
    if sign < 0:
        return "port"
    raise ValueError(f"side code {sign!r} has no name: expected +1 (starboard) or -1 (port)")


@dataclass(frozen=True)
class Barrier:
    """A half-line from a rounded mark that the next leg may not cross backwards.

    A leg to a mark with a rounding side ends on the mark's rounding segment,
    crossed along ``normal``; the next leg starts there.  Crossing the ray
    ``mark + s ray`` (``s >= 0``) against ``normal`` would unwind the rounding
    (the boat would pass the mark on the wrong side), so routers forbid it, and
    they keep moves a small clearance away from the mark itself.

    Attributes
    ----------
    mark : tuple of float
        The mark ``(x, y)`` [m].
    ray : tuple of float
        Unit vector from the mark along the rounding segment.
    normal : tuple of float
        Unit vector of the direction in which the rounding segment was crossed.
    name : str
        The mark's label, for messages.
    """

    mark: tuple[float, float]
    ray: tuple[float, float]
    normal: tuple[float, float]
    name: str = ""


@dataclass(frozen=True)
class Start:
    """Where a leg starts: a point, or anywhere on a line segment.

    Attributes
    ----------
    a : tuple of float
        Point, or first end of the line ``(x, y)`` [m].
    b : tuple of float or None
        Second end of the line [m]; ``None`` for a point start.
    name : str
        Label for reports (e.g. ``"start"``, ``"1"``).
    barrier : Barrier or None
        The rounding ray of the mark the previous leg ended at
        (``LegResult.barrier``): this leg may not cross it backwards, so the
        mark stays on the side it is rounded on.  None: no constraint.
    """

    a: tuple[float, float]
    b: tuple[float, float] | None = None
    name: str = ""
    barrier: Barrier | None = None

    @property
    def is_line(self) -> bool:
        """True if the start is a line segment."""
        return self.b is not None


@dataclass(frozen=True)
class Target:
    """What ends a leg.

    Attributes
    ----------
    kind : {"mark", "gate", "line"}
        ``mark``: round the mark at ``a`` leaving it to ``rounding``;
        ``gate``: pass between the marks ``a`` and ``b``;
        ``line``: cross the line ``a``-``b`` (finish).
    a, b : tuple of float
        Mark position(s) ``(x, y)`` [m]; ``b`` is None for a mark.
    rounding : {"port", "starboard"} or None
        Side on which the mark is left (marks only).
    name : str
        Label for reports.
    exit_xy : tuple of float or None
        Where the course goes after a mark with a rounding side: the next leg's
        target centre ``(x, y)`` [m].  The leg then ends once the mark is rounded
        (the rounding segment lies on the outside of the turn, see
        ``routing/geometry.py``); None: the mark is passed, as for a course that
        goes straight on.
    """

    kind: TargetKind
    a: tuple[float, float]
    b: tuple[float, float] | None = None
    rounding: Side | None = None
    name: str = ""
    exit_xy: tuple[float, float] | None = None

    @property
    def centre(self) -> tuple[float, float]:
        """Mark position, or midpoint of a gate/line [m]."""
        if self.b is None:
            return self.a
        return ((self.a[0] + self.b[0]) / 2.0, (self.a[1] + self.b[1]) / 2.0)


@dataclass(frozen=True)
class RoutingSettings:
    """Numerical and rule settings of a leg route.

    Attributes
    ----------
    router : {"isochrone", "griddp", "spline"}
        Which router to use.
    dt_s : float
        Isochrone time step [s] (default 10 s: with mid-step wind sampling, halving
        it down to 1.25 s moved a 1809 m beat by < 2e-5; see docs/design/routing.md).
    heading_step_deg : float
        Heading resolution [°].
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
    min_dt_s : float
        Isochrone: smallest time step of the refinement near the target [s]
        (steps shrink from ``dt_s`` once the target is a few steps away).
    prune_sector_deg : float
        Isochrone: width of the pruning sectors, in bearing seen from the
        target [°]; one point per sector and tack side survives each step.
    max_front_points : int
        Isochrone: cap on the points kept per step (sectors widen to respect it).
    heading_fan : {"hull", "full"}
        Isochrone: ``"hull"`` tries grid TWAs between the upwind and downwind
        VMG angles only (the rest of the polar is never optimal without a
        tack penalty; the exact VMG angles and the direct bearing to the
        target are always tried); ``"full"`` tries the whole circle.
    dp_rows : int
        Grid DP / multi-spline: rows of nodes including the start and target
        rows (Dębski: 10-16).
    dp_cols : int
        Grid DP: nodes per row, C (Dębski: up to 128).
    dp_refinements : int
        Grid DP: mesh refinements after the first pass (each centred on the
        best route so far, band scaled by ``dp_shrink``).
    dp_half_width_m : float or None
        Grid DP / multi-spline: half-width of the node rows [m]; None derives it
        from the one-tack laylines (see ``docs/design/griddp.md``).
    dp_shrink : float
        Grid DP: band scale factor per refinement (0.5 halves the node spacing).
    dp_samples : int
        Grid DP: pieces per segment along which the wind is sampled.
    spline_cols, spline_slopes, spline_refinements : int
        Multi-spline: nodes per row, tangent slopes per node (n_ts) and
        refinements (ranges shrink by 1/3 each).
    spline_carry_speed : bool
        Multi-spline, dynamic boat: enter each edge at the end speed of the best
        previous edge (the DP carries it, as Dębski's) instead of the steady
        speed of the node's tangent.  No effect with a polar.
    spline_start_from_rest : bool
        Multi-spline, dynamic boat: the first edge starts from rest instead of
        at the steady speed (a flying start).  No effect with a polar.
    """

    router: RouterName = "isochrone"
    dt_s: float = 10.0
    heading_step_deg: float = 2.0
    tack_penalty_s: float = 5.0
    gybe_penalty_s: float = 3.0
    initial_side: Side | None = None
    zone_m: float = 13.0
    start_line_spacing_m: float = 5.0
    max_leg_time_s: float = 10800.0
    min_dt_s: float = 1.0
    prune_sector_deg: float = 1.0
    max_front_points: int = 2000
    heading_fan: str = "hull"
    dp_rows: int = 13
    dp_cols: int = 64
    dp_refinements: int = 2
    dp_half_width_m: float | None = None
    dp_shrink: float = 0.5
    dp_samples: int = 4
    spline_cols: int = 25
    spline_slopes: int = 7
    spline_refinements: int = 3
    spline_carry_speed: bool = False
    spline_start_from_rest: bool = False


MIN_DT_S: Final = 0.5
"""Smallest isochrone time step :attr:`RoutingSettings.dt_s` [s]: halving the default
10 s down to 1.25 s moved a 1809 m beat by < 2e-5 (``docs/design/routing.md``), while
the work grows as 1/dt (0.05 s took over 30 s for a 300 m leg; 1e-9 s never ends)."""
MIN_MIN_DT_S: Final = 0.01
"""Smallest :attr:`RoutingSettings.min_dt_s` [s] (the refined step near the target)."""
MIN_HEADING_STEP_DEG: Final = 0.1
"""Finest heading resolution :attr:`RoutingSettings.heading_step_deg` [°]: the polar is
tabulated at ``180 / step`` angles and each front point tries them all (1e-4° hung,
1e-9° asked for 1.3 TiB)."""
MAX_FRONT_POINTS: Final = 100_000
"""Largest :attr:`RoutingSettings.max_front_points` (the default is 2000)."""
MAX_DP_SEGMENT_SAMPLES: Final = 200_000_000
"""Most wind samples along grid-DP segments per leg: ``(dp_rows - 1) * dp_cols**2 *
dp_samples * (dp_refinements + 1)``, an upper bound [-].  About 1 µs each, so minutes;
the defaults need 2.4e6, Dębski's C = 128 with 30 rows 4.8e5."""
MAX_SPLINE_ROW_EDGES: Final = 20_000_000
"""Most multi-spline edges between two rows, ``(spline_cols * spline_slopes)**2``: each
costed edge array holds this many float64 (160 MB); the defaults have 30 625."""
MAX_SPLINE_EDGES: Final = 2_000_000_000
"""Most multi-spline edges per leg, ``(dp_rows - 1) * (spline_cols * spline_slopes)**2 *
(spline_refinements + 1)`` (the defaults: 1.5e6)."""


def _work_problems(s: RoutingSettings) -> list[str]:
    """The grid-DP and multi-spline work of a leg, estimated from ``s`` alone (the leg's
    length does not change it): one line per router whose work would take too long."""
    problems: list[str] = []
    rows, cols, ref, smp = s.dp_rows - 1, s.dp_cols, s.dp_refinements + 1, s.dp_samples
    dp = float(rows) * cols * cols * smp * ref
    if dp > MAX_DP_SEGMENT_SAMPLES:
        problems.append(
            f"dp_cols = {cols} with dp_rows = {s.dp_rows}, dp_samples = {smp} and "
            f"dp_refinements = {ref - 1} needs about {dp:.1e} wind samples per leg (rows x "
            f"cols^2 x samples x passes), more than {MAX_DP_SEGMENT_SAMPLES:.0e} (minutes of "
            "work); lower them (defaults 64 columns, 13 rows, 4 samples, 2 refinements)"
        )
    per_row = float(s.spline_cols * s.spline_slopes) ** 2
    total = per_row * rows * (s.spline_refinements + 1)
    if per_row > MAX_SPLINE_ROW_EDGES or total > MAX_SPLINE_EDGES:
        problems.append(
            f"spline_cols = {s.spline_cols} with spline_slopes = {s.spline_slopes} needs "
            f"{per_row:.1e} edges between two rows and {total:.1e} per leg, more than "
            f"{MAX_SPLINE_ROW_EDGES:.0e} and {MAX_SPLINE_EDGES:.0e} (memory and minutes of "
            "work); lower spline_cols, spline_slopes or spline_refinements (defaults 25, 7, 3)"
        )
    return problems


class _Problems(list[str]):
    """The problems of one settings object, with the two common checks."""

    def __init__(self, s: RoutingSettings) -> None:
        super().__init__()
        self.s = s

    def number(self, name: str, *, strict: bool = True) -> None:
        v = getattr(self.s, name)
        if not (real_number(v) and (v > 0 if strict else v >= 0)):
            self.append(f"{name} must be a number {'>' if strict else '>='} 0, got {v!r}")

    def integer(self, name: str, lo: int, hi: int, text: str) -> None:
        v = getattr(self.s, name)
        if not (isinstance(v, int | np.integer) and not isinstance(v, bool) and lo <= v <= hi):
            self.append(f"{name} must be an integer {text}, got {v!r}")


def _common_problems(p: _Problems) -> None:
    """The router name, the time limit, the penalties and the start-line spacing."""
    s = p.s
    if s.router not in get_args(RouterName):
        p.append(
            "router must be one of "
            + ", ".join(repr(r) for r in get_args(RouterName))
            + f", got {s.router!r}"
        )
    for name in (
        "dt_s",
        "heading_step_deg",
        "min_dt_s",
        "prune_sector_deg",
        "max_leg_time_s",
        "start_line_spacing_m",
        "zone_m",
    ):
        p.number(name)
    for name in ("tack_penalty_s", "gybe_penalty_s"):
        p.number(name, strict=False)
    if s.initial_side is not None and s.initial_side not in SIDE_NAMES:
        p.append(f"initial_side must be 'port', 'starboard' or None, got {s.initial_side!r}")


def _isochrone_problems(p: _Problems) -> None:
    """The isochrone router's steps, fan and front size."""
    s = p.s
    if real_number(s.heading_step_deg) and s.heading_step_deg > 45:
        p.append(f"heading_step_deg must be <= 45, got {s.heading_step_deg!r}")
    if real_number(s.heading_step_deg) and 0 < s.heading_step_deg < MIN_HEADING_STEP_DEG:
        p.append(
            f"heading_step_deg must be in [{MIN_HEADING_STEP_DEG:g}, 45] (default 2; finer "
            f"steps only slow the router), got {s.heading_step_deg!r}"
        )
    if real_number(s.dt_s) and 0 < s.dt_s < MIN_DT_S:
        p.append(
            f"dt_s must be >= {MIN_DT_S:g} s (default 10; finer steps hardly "
            f"change the route and make it slow), got {s.dt_s!r}"
        )
    if real_number(s.min_dt_s) and 0 < s.min_dt_s < MIN_MIN_DT_S:
        p.append(f"min_dt_s must be >= {MIN_MIN_DT_S:g} s (default 1), got {s.min_dt_s!r}")
    p.integer("max_front_points", 8, MAX_FRONT_POINTS, f"in [8, {MAX_FRONT_POINTS}]")
    if s.heading_fan not in ("hull", "full"):
        p.append(f"heading_fan must be 'hull' or 'full', got {s.heading_fan!r}")


def _griddp_problems(p: _Problems) -> None:
    """The grid-DP router's rows, columns, refinements and corridor."""
    s = p.s
    p.integer("dp_rows", 3, 200, "in [3, 200]")
    p.integer("dp_cols", 2, 1024, "in [2, 1024]")
    p.integer("dp_refinements", 0, 20, "in [0, 20]")
    p.integer("dp_samples", 1, 64, "in [1, 64]")
    if not (real_number(s.dp_shrink) and 0 < s.dp_shrink <= 1):
        p.append(f"dp_shrink must be in (0, 1], got {s.dp_shrink!r}")
    hw = s.dp_half_width_m
    if hw is not None and not (real_number(hw) and hw > 0):
        p.append(f"dp_half_width_m must be > 0 m or None (automatic), got {hw!r}")


def _spline_problems(p: _Problems) -> None:
    """The spline router's columns, slopes, refinements and switches."""
    s = p.s
    for name, lo in (("spline_cols", 2), ("spline_slopes", 1), ("spline_refinements", 0)):
        p.integer(name, lo, 1000, f">= {lo}")
    for name in ("spline_carry_speed", "spline_start_from_rest"):
        v = getattr(s, name)
        if not isinstance(v, bool | np.bool_):
            p.append(f"{name} must be true or false, got {v!r}")


def settings_problems(s: RoutingSettings) -> list[str]:
    """What is wrong with ``s``, one line per field (empty when every field is valid).

    The one place that validates :class:`RoutingSettings`: every router calls
    :func:`check_settings`, which raises with these lines.  Every field is checked,
    whichever router is chosen (a course may switch router on the command line): the
    common fields, then each router's own.
    """
    p = _Problems(s)
    for group in (_common_problems, _isochrone_problems, _griddp_problems, _spline_problems):
        group(p)
    if not p:  # every count a valid integer: estimate the work
        p += _work_problems(s)
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


@dataclass(frozen=True, eq=False)
class RouteTrack:
    """A routed track, one row per point.

    Attributes
    ----------
    t : ndarray
        Time [epoch s].
    x, y : ndarray
        Position in the local frame [m].
    heading_deg : ndarray
        Heading sailed from this point [° compass].
    tws_ms, twd_deg : ndarray
        True wind speed [m s⁻¹] and FROM-direction [°] at the point.
    twa_deg : ndarray
        Signed true wind angle [°] (positive: starboard tack).
    bsp_ms : ndarray
        Boat speed through the water [m s⁻¹].
    side : ndarray of int
        +1 starboard tack, -1 port tack (:func:`side_sign`, :func:`side_name`).
    sog_ms, cog_deg : ndarray or None
        Speed [m s⁻¹] and course [° compass] over the ground, where a surface current
        was routed (``heading_deg``/``bsp_ms`` are then through the water and
        ``tws``/``twd``/``twa`` relative to the water); None in still water, where they
        equal ``bsp_ms``/``heading_deg`` (:attr:`ground_speed_ms`, :attr:`ground_course_deg`).
    """

    t: NDArray[np.float64]
    x: NDArray[np.float64]
    y: NDArray[np.float64]
    heading_deg: NDArray[np.float64]
    tws_ms: NDArray[np.float64]
    twd_deg: NDArray[np.float64]
    twa_deg: NDArray[np.float64]
    bsp_ms: NDArray[np.float64]
    side: NDArray[np.int8]
    sog_ms: NDArray[np.float64] | None = None
    cog_deg: NDArray[np.float64] | None = None

    def __len__(self) -> int:
        return int(self.t.size)

    @property
    def ground_speed_ms(self) -> NDArray[np.float64]:
        """Speed over the ground [m s⁻¹] (boat speed in still water)."""
        return self.bsp_ms if self.sog_ms is None else self.sog_ms

    @property
    def ground_course_deg(self) -> NDArray[np.float64]:
        """Course over the ground [°] (the heading in still water)."""
        return self.heading_deg if self.cog_deg is None else self.cog_deg

    @property
    def distance_m(self) -> float:
        """Length of the polyline [m]."""
        return float(np.sum(np.hypot(np.diff(self.x), np.diff(self.y))))


@dataclass(frozen=True)
class Manoeuvre:
    """A tack or gybe on the route."""

    kind: Literal["tack", "gybe"]
    t: float
    x: float
    y: float


@dataclass(frozen=True, eq=False)
class LegResult:
    """Result of routing one leg.

    Attributes
    ----------
    t_start, t_end : float
        Start and arrival times [epoch s].
    start_xy, end_xy : tuple of float
        Start point (best point on a start line) and arrival point [m].
    distance_m : float
        Distance sailed [m].
    n_tacks, n_gybes : int
        Manoeuvre counts.
    manoeuvres : tuple of Manoeuvre
        Where and when each happened.
    track : RouteTrack
        The route, first row at ``t_start``, last at ``t_end``.
    router : str
        Router that produced it.
    barrier : Barrier or None
        For a leg that ended at a mark with a rounding side: the rounding ray
        the next leg must not cross back (give it to the next leg's
        :class:`Start`, e.g. with :func:`~sailroute.routing.geometry.chain_leg`).
    """

    t_start: float
    t_end: float
    start_xy: tuple[float, float]
    end_xy: tuple[float, float]
    distance_m: float
    n_tacks: int
    n_gybes: int
    manoeuvres: tuple[Manoeuvre, ...]
    track: RouteTrack
    router: str
    barrier: Barrier | None = None

    @property
    def time_s(self) -> float:
        """Leg time [s]."""
        return self.t_end - self.t_start


class Router(Protocol):
    """A leg router: the signature every routing function shares.

    ``(start, target, t0, wind, boat, settings, *, progress=None, xp=numpy, current=None,
    obstacles=None) -> LegResult`` (:mod:`sailroute.routing.api` lists the
    implementations and what each supports; each router module declares
    ``_ROUTER: Router = route_...`` so that mypy checks it against this).  ``current``
    is a surface current (:class:`~sailroute.wind.current.CurrentField`), ``obstacles`` the
    race area (:class:`~sailroute.routing.obstacles.Obstacles`); a router that cannot
    honour one refuses it with an :class:`~sailroute.errors.InputError`.
    """

    def __call__(
        self,
        start: Start,
        target: Target,
        t0: float,
        wind: WindField,
        boat: BoatModel,
        settings: RoutingSettings,
        /,
        *,
        progress: Callable[[float], None] | None = None,
        xp: ModuleType = ...,
        current: CurrentField | None = None,
        obstacles: Obstacles | None = None,
    ) -> LegResult:
        """Fastest route of one leg (see :func:`~sailroute.routing.api.route_leg`)."""
        ...
