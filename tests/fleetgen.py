"""A messy fleet with a known answer: tracks of N boats and the exact truth behind them.

:func:`messy_fleet` sails ``n_boats`` boats of varied skill round a windward-leeward
course (sailroute's template: start line ``start_pin``/``start_boat``, windward mark
``1``, leeward gate ``4s``/``4p``, leeward finish line, two laps by default) through a
known wind (:class:`FleetWind`: an oscillating and a persistent shift, TWS varying in time
and optionally from one side of the course to the other), injects the faults of a
:class:`FaultPlan` on chosen boats, and returns a :class:`Fleet`: the recorded tracks (what
a tracker delivers), the course (a :class:`~sailroute.course.model.Course` and its YAML
text) and the truth (a :class:`BoatTruth` per track, the wind, the guns, the tracker's
clock lag).  :meth:`Fleet.write` puts the course file and the tracks (GPX or CSV) in a
folder for ``sailroute analyze``; :meth:`Fleet.truth_json` gives the truth as JSON.

How the boats are sailed
------------------------
Every boat is routed by sailroute's own isochrone router, leg by leg, from its own start
point on the line and its own start time; nothing is copied between boats.  A boat's skill
``s`` (1 for the best, down to about 0.88) scales the class polar's speeds.  Instead of one
polar per boat, each boat is routed with the class polar in its own *time-dilated* wind
``W_s(τ, x, y) = W(gun + (τ − gun)/s, x, y)`` and its times are mapped back with
``t = gun + (τ − gun)/s``: it then passes the same points as a boat with the polar
``s × polar`` in the true wind, exactly (``dx/dt = s dx/dτ``), and at every point its
heading is the router's answer to the true wind at its own true time.  Tack and gybe costs
are served in τ, so a boat's cost in true time is ``penalty / s`` (:data:`TACK_CLASSES`:
two manoeuvre classes; a slower boat also tacks slower).  One polar for all lets the batched
router (:func:`~sailroute.routing.batch.route_leg_batch`) route the fleet as one front per
leg and per group of boats that share the router's settings (the manoeuvre class, and on
the first leg the first tack): with the coarse settings :data:`ROUTER` (4° headings and
pruning sectors, 10 s steps) a 40-boat, 45-minute fleet takes about 3.5 s of CPU, a
60-boat one about 5 s, and the best boat's legs stay within 1 % of the router's default settings
(``tests/analysis/test_fleetgen.py``).

The router aims :data:`ROUND_RADIUS_M` (6 m) off each mark along the mark's rounding
segment and through the gate narrowed by as much at each end (:func:`clear_target`), so
that no track touches a mark; the segment it crosses lies on the course target's own, so
detection finds the crossing where the route made it.  Between two legs a rounding is
drawn (:class:`Rounding`): round the mark on a circle through half the turn, or below the
gate and round the gate mark nearer to where the boat passed; the next leg is routed from
where the drawing ends.  Before the start each boat waits below the line (zigzags at
1.5 m s⁻¹) and then sails its approach on the route's first heading into its start point;
after the finish it sails on for a minute or two.  The pre-start, the roundings and the
post-finish are drawn, not routed: the router's headings hold on the legs.

Time
----
All truth times are *true* times [epoch s].  The tracker's clock lags the true time by
``clock_lag_s`` (common to the fleet): a fix taken at true time ``T`` is stamped
``T − clock_lag_s``, so with a positive lag every recorded crossing looks that much
*earlier* (a fleet that looks over the line at the gun).  Fixes are stamped on whole
seconds of the tracker's clock, every 1-3 s per boat (:attr:`BoatTruth.sample_s`).  A
boat's start (:attr:`BoatTruth.start_t`) is when it leaves the line: a route that begins
with a tack on the line starts when the tack is over.

GPS error, per axis: white (``noise_white_m`` sd, default 0.7 m) plus a first-order
autoregressive error (``noise_corr_m`` sd, default 1.5 m, correlation time
``noise_tau_s`` 60 s); the recorded position minus the true one has the RMS
``sqrt(white² + corr²)`` per axis.  That error alone moves a detected crossing by about
0.8 s at 2 m s⁻¹ (more where a path meets a mark's rounding ray at a slant): with the
defaults and ``analysis.segment``, 80-90 % of the clean boats' crossings lie within one
fix interval of the truth and over 95 % within two (seeds 0-2); without the error
(:meth:`Fleet.resampled` with ``noise=False``) every one lies within half an interval.
Fixes, error and SOG/COG come from their own random stream (``[seed, 1]``), so a fleet
recorded again with another lag or without error keeps every other draw.

Pinching, footing, banking
--------------------------
``sailing`` gives a boat of the draw a :class:`Sailing` (recorded in
:attr:`BoatTruth.upwind_twa_offset_deg` and :attr:`BoatTruth.bank`).  A boat that
pinches or foots is routed with its own polar (:func:`offset_polar`), whose best upwind
VMG lies ``upwind_twa_offset_deg`` off the class polar's, at the class polar's speed there.
A boat that banks on a side is routed up the first beat in two pieces, to its side's
waypoint (:func:`bank_waypoint`) on the tack to that side and from there to the mark,
joined into one leg; the router otherwise knows the wind and would go where it pays.
``wind_fields`` sets :class:`FleetWind` fields after the draw (a wind without oscillation,
a persistent shift over the first beat).  Neither draws anything: every other boat, and
the whole fleet without them, comes out as it did, bit for bit.

Faults (each on its own boats, recorded in :attr:`BoatTruth.faults`)
-------------------------------------------------------------------
``non_starter``
    waits below the line and drifts away downwind after the gun; never crosses the line.
``ocs`` (statuses ``ocs_returned`` / ``ocs_not_returned``)
    crosses ``ocs_s`` before the gun and is :attr:`BoatTruth.distance_at_gun_m` over at
    the gun; a returning boat turns back a few seconds after the gun, recrosses the line
    (``returned_t``) and restarts.
``late``
    starts ``late_s`` after the gun, ``-distance_at_gun_m`` metres behind the line at it.
general recall (fleet-wide, :attr:`Fleet.guns` holds both guns)
    the whole fleet crosses the line round a first gun, part of it over
    (:attr:`BoatTruth.distance_at_first_gun_m` > 0); the boats sail on for 30-70 s, come
    back below the line and start again at the restart gun (the race's gun).
``data_gap``
    no fixes between ``t0`` and ``t1`` inside a leg.
``retired`` / ``data_ends`` (status ``retired``)
    leaves the course at ``t`` in the middle of a leg (sails 500 m off), or the log simply
    stops at ``t``; later legs are NaN.
``two_races``
    after the finish the log stops and resumes (``gap``) for a second race of the same
    course at ``gun2`` (its start and leg ends in the fault's parameters).
``duplicate`` (status ``duplicate_of``)
    an extra track: another boat's recorded data, identical, under another name.
``other_fleet``
    an extra boat: of a faster class (``class``: skill 1.22, its own gun 4 min after the
    fleet's), or a boat of this race moved 4 km away (``area``) or a day later (``day``),
    its wind the fleet's carried along.
``gate_outside``
    on the first gate leg the boat passes outside the gate, 20-80 m beyond one of its marks,
    and goes on up the next beat from there (:attr:`BoatTruth.leg_end_t` holds when it
    passed).

Determinism: every random choice comes from ``numpy.random.default_rng(seed)`` (the
recording from ``[seed, 1]``); the same arguments give identical tracks and truth.
:func:`shared_fleet` keeps up to eight fleets for the test run, so that test modules
asking for the same one generate it once.
"""

from __future__ import annotations

import dataclasses
import functools
import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any, Final, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.boat import builtin_polar
from sailroute.boat.io import read_polar
from sailroute.boat.polar import Polar
from sailroute.course.geometry import leg_endpoints, target_of, wind_mode, xy_bearing_deg
from sailroute.course.load import course_from_mapping
from sailroute.course.model import Course
from sailroute.course.templates import CourseLayout, windward_leeward
from sailroute.geo import LocalFrame
from sailroute.routing.batch import route_leg_batch
from sailroute.routing.geometry import chain_leg, start_centre, target_geometry
from sailroute.routing.settings import IsochroneSettings, RoutingSettings
from sailroute.routing.types import (
    LegResult,
    Manoeuvre,
    RouteTrack,
    Side,
    Start,
    Target,
    side_name,
)
from sailroute.timeutil import iso, parse_time, to_epoch
from sailroute.track.model import Track
from sailroute.units import KNOT, bearing_deg, heading_unit, wrap180
from sailroute.wind.base import Coverage

GUN: Final = to_epoch(parse_time("2024-06-01T13:00:00Z"))
"""Default gun [epoch s]."""
CENTRE: Final = (43.05, 6.25)
"""Default course centre ``(lat, lon)`` [°]: open water south-east of Hyères."""
ROUTER: Final = RoutingSettings(
    isochrone=IsochroneSettings(
        dt_s=10.0, heading_step_deg=4.0, prune_sector_deg=4.0, max_front_points=64, min_dt_s=10.0
    )
)
"""Router settings the boats are sailed with (the penalties and first tack are per group)."""
TACK_CLASSES: Final = ((4.0, 2.5), (7.0, 4.0))
"""Tack and gybe penalties [s, in a boat's dilated time] of the two manoeuvre classes."""
STATUSES: Final = (
    "racing",
    "non_starter",
    "retired",
    "late",
    "ocs_returned",
    "ocs_not_returned",
    "two_races",
    "duplicate_of",
    "other_fleet",
    "gate_outside",
)
"""Values of :attr:`BoatTruth.status`."""
LOITER_MS: Final = 1.5
"""Speed of the pre-start zigzags and connections [m s⁻¹]."""


# ------------------------------------------------------------------------------ the wind


class _Everywhere:
    """A wind defined everywhere at all times (the :class:`~sailroute.wind.base.WindField`
    coverage and clamp)."""

    @property
    def coverage(self) -> Coverage:
        """Everywhere, at all times."""
        return Coverage.everywhere()

    @property
    def clamp(self) -> bool:
        """Nothing lies outside: never clamped."""
        return False


@dataclass(frozen=True)
class FleetWind(_Everywhere):
    """The known wind: a :class:`~sailroute.wind.base.WindField` defined everywhere.

    ``TWD(t) = twd_deg + osc_amp_deg sin(2π (t − t0)/osc_period_s + osc_phase) +
    shift_deg ramp((t − t0 − shift_start_s)/shift_over_s)`` (ramp 0 → 1), the same over the
    course; ``TWS(t, x, y) = tws_ms (1 + tws_amp sin(2π (t − t0)/tws_period_s + tws_phase))
    (1 + pressure_left l/1000)`` with ``l`` [m] the distance left of the course axis
    (looking upwind) from ``centre``.

    Attributes
    ----------
    t0 : float
        Reference time [epoch s] (the gun).
    twd_deg, tws_ms : float
        Mean direction (from) [°] and speed [m s⁻¹] at ``t0``.
    axis_deg : float
        Course axis [°] (the direction the course was laid for; left/right of it).
    centre : tuple of float
        Course centre ``(x, y)`` [m].
    osc_amp_deg, osc_period_s, osc_phase : float
        Oscillating shift [°, s, rad].
    shift_deg, shift_start_s, shift_over_s : float
        Persistent shift [°] (+ veers), starting ``shift_start_s`` after ``t0`` and
        complete ``shift_over_s`` later [s].
    tws_amp, tws_period_s, tws_phase : float
        Relative TWS oscillation [-, s, rad].
    pressure_left : float
        Relative TWS change per km to the left of the axis [km⁻¹] (0.1: 10 % more wind
        one kilometre left).
    """

    t0: float
    twd_deg: float
    tws_ms: float
    axis_deg: float
    centre: tuple[float, float] = (0.0, 0.0)
    osc_amp_deg: float = 7.0
    osc_period_s: float = 420.0
    osc_phase: float = 0.0
    shift_deg: float = 8.0
    shift_start_s: float = 600.0
    shift_over_s: float = 1200.0
    tws_amp: float = 0.1
    tws_period_s: float = 780.0
    tws_phase: float = 0.0
    pressure_left: float = 0.0

    def direction(self, t: ArrayLike, x: ArrayLike = 0.0, y: ArrayLike = 0.0) -> NDArray:
        """TWD (from) [°, in [0, 360)] at ``t`` [epoch s], ``x, y`` [m]."""
        t, x, y = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (t, x, y)))
        return self._direction(t)

    def _direction(self, t: NDArray) -> NDArray:
        dt = t - self.t0
        ramp = np.clip((dt - self.shift_start_s) / self.shift_over_s, 0.0, 1.0)
        osc = self.osc_amp_deg * np.sin(2.0 * np.pi * dt / self.osc_period_s + self.osc_phase)
        return (self.twd_deg + osc + self.shift_deg * ramp) % 360.0

    def speed(self, t: ArrayLike, x: ArrayLike = 0.0, y: ArrayLike = 0.0) -> NDArray:
        """TWS [m s⁻¹] at ``t`` [epoch s], ``x, y`` [m]."""
        t, x, y = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (t, x, y)))
        return self._speed(t, x, y)

    def _speed(self, t: NDArray, x: NDArray, y: NDArray) -> NDArray:
        phase = 2.0 * np.pi * (t - self.t0) / self.tws_period_s + self.tws_phase
        tws = self.tws_ms * (1.0 + self.tws_amp * np.sin(phase))
        if self.pressure_left == 0.0:
            return tws
        th = math.radians(self.axis_deg)
        left = -(x - self.centre[0]) * math.cos(th) + (y - self.centre[1]) * math.sin(th)
        return tws * (1.0 + self.pressure_left * left / 1000.0)

    def sample(self, t: ArrayLike, x: ArrayLike, y: ArrayLike) -> tuple[NDArray, NDArray]:
        """Wind ``(u, v)`` [m s⁻¹] (the direction the air moves to)."""
        t, x, y = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (t, x, y)))
        spd, twd = self._speed(t, x, y), np.radians(self._direction(t))
        return -spd * np.sin(twd), -spd * np.cos(twd)

    def dilated(self, gun: float, skill: float) -> DilatedWind:
        """The wind a boat of skill ``skill`` is routed in: ``W(gun + (τ − gun)/skill)``."""
        return DilatedWind(self, gun, skill)


@dataclass(frozen=True)
class DilatedWind(_Everywhere):
    """:class:`FleetWind` in a boat's dilated time ``τ = gun + skill (t − gun)``
    (a :class:`~sailroute.wind.base.WindField`; module docstring)."""

    wind: FleetWind
    gun: float
    skill: float

    def sample(self, t: ArrayLike, x: ArrayLike, y: ArrayLike) -> tuple[NDArray, NDArray]:
        """Wind ``(u, v)`` [m s⁻¹] at dilated time ``t`` [epoch s]."""
        tau = np.asarray(t, dtype=float)
        return self.wind.sample(self.gun + (tau - self.gun) / self.skill, x, y)


# ------------------------------------------------------------------------------ faults


@dataclass(frozen=True)
class FaultPlan:
    """What to inject, and on how many boats (each fault on its own boats).

    Attributes
    ----------
    non_starters, ocs_returned, ocs_not_returned, late, data_gaps, retired, data_ends,
    two_races, duplicates, gate_outside : int
        Boats with that fault (duplicates: extra tracks copying a racing boat).
    other_fleet : tuple of str
        One extra boat per entry: ``"class"``, ``"area"`` or ``"day"``.
    general_recall : bool
        A first gun ``recall_s`` before the race's gun, ``recall_over`` of the fleet over
        at it.
    ocs_margin_m : (float, float)
        Range of the distance over the line at the gun [m].
    late_s : (float, float)
        Range of a late starter's delay [s].
    gap_s : (float, float)
        Range of a data gap's length [s].
    noise_white_m, noise_corr_m, noise_tau_s : float
        GPS error per axis: white sd [m], correlated sd [m], correlation time [s].
    sog_cog : bool
        Write SOG and COG columns (CSV) from the true velocity.
    """

    non_starters: int = 1
    ocs_returned: int = 2
    ocs_not_returned: int = 2
    late: int = 2
    data_gaps: int = 1
    retired: int = 1
    data_ends: int = 1
    two_races: int = 1
    duplicates: int = 1
    gate_outside: int = 1
    other_fleet: tuple[str, ...] = ("class",)
    general_recall: bool = False
    recall_s: float = 300.0
    recall_over: float = 0.35
    ocs_margin_m: tuple[float, float] = (8.0, 35.0)
    late_s: tuple[float, float] = (25.0, 90.0)
    gap_s: tuple[float, float] = (45.0, 120.0)
    noise_white_m: float = 0.7
    noise_corr_m: float = 1.5
    noise_tau_s: float = 60.0
    sog_cog: bool = False

    @classmethod
    def clean(cls, **kw: Any) -> FaultPlan:
        """No fault at all, no GPS error (each keyword overrides one field)."""
        none = {
            f.name: 0
            for f in dataclasses.fields(cls)
            if f.type == "int" or f.name in ("noise_white_m", "noise_corr_m")
        }
        return dataclasses.replace(cls(), **{**none, "other_fleet": (), **kw})

    @property
    def per_boat(self) -> int:
        """Boats of the fleet that get a fault of their own."""
        return (
            self.non_starters
            + self.ocs_returned
            + self.ocs_not_returned
            + self.late
            + self.data_gaps
            + self.retired
            + self.data_ends
            + self.two_races
            + self.gate_outside
        )


@dataclass(frozen=True)
class Fault:
    """One injected fault: its kind and parameters (times [epoch s, true], lengths [m])."""

    kind: str
    params: Mapping[str, Any] = field(default_factory=lambda: MappingProxyType({}))

    def __post_init__(self) -> None:
        if not isinstance(self.params, MappingProxyType):
            object.__setattr__(self, "params", MappingProxyType(dict(self.params)))


# ------------------------------------------------------------------------------ how a boat sails

Bank = Literal["left", "right"]
"""A side of the course, looking upwind."""
BANK_TACK: Final[Mapping[Bank, Side]] = MappingProxyType({"left": "starboard", "right": "port"})
"""The tack that sails to each side."""
PEAK_SLOPE: Final = 0.004
"""How fast the VMG of a pinching or footing boat's polar falls off either side of its
angle [per °] (:func:`offset_polar`): enough for the router to hold the angle, too little to
touch the reaching angles."""
BANK_HEIGHT: Final = 0.45
"""How far up the first beat a banking boat's waypoint lies [-] (:func:`bank_waypoint`)."""


@dataclass(frozen=True)
class Sailing:
    """How one boat sails besides its skill and manoeuvre class (the defaults: as routed).

    Attributes
    ----------
    upwind_twa_offset_deg : float
        It sails its beats this many degrees of TWA off the polar's best VMG angle, at the
        polar's speed for that angle (:func:`offset_polar`): − pinches, + foots [°].  At
        its other angles below 90° it is slower than the class polar (its VMG capped below
        its own best): sent elsewhere than up the wind (a banking boat to its waypoint,
        a boat reaching in to a mark from beyond the layline) it loses speed as well.
    bank : {"left", "right"} or None
        It sails its first beat close-hauled from its start to a waypoint on that side
        (:func:`bank_waypoint`; on starboard to the left, on port to the right) before the
        router takes it on to the windward mark; None: the router's choice all the way.
    """

    upwind_twa_offset_deg: float = 0.0
    bank: Bank | None = None


def offset_polar(polar: Polar, offset_deg: float, slope: float = PEAK_SLOPE) -> Polar:
    """The polar of a boat that pinches (``offset_deg`` < 0) or foots (> 0) upwind.

    At each TWS column its best upwind VMG lies at ``θ_t = α* + offset_deg`` (``α*`` the
    class polar's best VMG angle) with the class polar's speed there; elsewhere below 90°
    its VMG is the class polar's, capped at ``VMG(θ_t) (1 − slope |θ − θ_t|)``, so that
    the router sails ``θ_t``.  Tabulated every 0.5° of TWA on the class polar's TWS columns
    (the same interpolation): on a column ``θ_t`` holds to 0.5°; between two columns the peak
    is the interpolation's (3° off at 4.5 m s⁻¹ for the ILCA 7, whose best angle moves
    from 42° to 38.5° between its 8 and 9 kn columns).
    """
    twa = np.linspace(0.0, 180.0, 361)
    tws = polar.tws_ms
    alpha = np.asarray(polar.vmg_upwind(tws)[0], float) + offset_deg
    spd = polar.speed(tws[None, :], twa[:, None])
    v_t = polar.speed(tws, alpha) * np.cos(np.radians(alpha))
    up = twa < 90.0
    cos = np.cos(np.radians(twa[up]))[:, None]
    cap = v_t[None, :] * np.clip(1.0 - slope * np.abs(twa[up, None] - alpha[None, :]), 0.0, 1.0)
    spd[up] = np.minimum(spd[up], cap / cos)
    return Polar.from_arrays(twa, tws, spd, f"{polar.name} {offset_deg:+g}°", polar.interpolation)


def bank_waypoint(course: Course, polar: Polar, wind: FleetWind, bank: Bank) -> Target:
    """The waypoint of a boat banking on ``bank``: :data:`BANK_HEIGHT` of the first beat
    up the course, on the close-hauled course from the start line's centre in the mean
    wind (``wind.twd_deg ∓ α*``), a point the router passes."""
    start, target = leg_endpoints(course, 0)
    c = start_centre(start)
    alpha = float(polar.vmg_upwind(wind.tws_ms)[0])
    ax, ay = _unit(wind.axis_deg)
    up = (target.centre[0] - c[0]) * ax + (target.centre[1] - c[1]) * ay
    d = BANK_HEIGHT * up / math.cos(math.radians(alpha))
    ux, uy = _unit(wind.twd_deg - alpha if bank == "left" else wind.twd_deg + alpha)
    return Target("mark", (c[0] + d * ux, c[1] + d * uy), name=f"bank {bank}")


# ------------------------------------------------------------------------------ truth


@dataclass(frozen=True, eq=False)
class BoatTruth:
    """What really happened to one track.

    Attributes
    ----------
    name : str
        The track's name (and file stem).
    status : str
        One of :data:`STATUSES`.
    skill : float
        Speed factor on the class polar [-] (1: the best boat).
    tack_cost_s, gybe_cost_s : float
        Time lost per tack / gybe [s, true time].
    first_side : {"port", "starboard"} or None
        The tack it was routed to start on (None: the router's choice).
    start_fraction : float
        Where its planned start lies on the line: 0 at the pin, 1 at the committee boat.
    gun_t : float
        The gun it raced from [epoch s] (a boat of another class: its own).
    start_t : float
        True start crossing [epoch s]: from the pre-start side, after which it raced (an
        OCS boat that did not return: its crossing before the gun); NaN: never started.
    start_delay_s : float
        ``start_t − gun_t`` [s].
    distance_at_gun_m : float
        Signed distance from the start line (the line through its marks) at the gun [m]:
        + on the course side (over), − behind it.
    distance_at_first_gun_m : float
        The same at the first gun of a general recall (NaN: no recall).
    ocs_s : float or None
        Crossed the line this long before the gun [s] and was over at it.
    returned_t : float or None
        An OCS boat that came back: when it recrossed to the pre-start side [epoch s].
    leg_end_t : tuple of float
        End of each leg [epoch s], the router's arrival (mark rounding, gate or line
        crossing); NaN for a leg it did not finish.
    gate_marks : tuple of str
        Per leg it finished, the gate mark it rounded (:class:`Rounding`); "" for a leg to
        a mark or line, and for a gate passed outside.
    gate_round_t : tuple of float
        Per leg it finished, when it passed straight below that gate mark [epoch s] (NaN
        where no gate mark was rounded).
    sample_s : float
        Interval between fixes [s].
    spans : tuple of (float, float)
        The true-time intervals its tracker logged [epoch s] (two around a data gap, two
        for a log of two races).
    faults : tuple of Fault
    duplicate_of : str or None
        For a duplicate: the boat whose data it repeats.
    legs : tuple of LegResult
        The routed legs in true time (the route's headings, TWA, TWD, TWS, boat speed).
    path_t, path_x, path_y : ndarray
        The true path [epoch s, m, m] (pre-start, legs, after the finish), linear between
        points; the track's fixes are taken on it.
    upwind_twa_offset_deg : float
        Its beats sailed this far off the best VMG angle [°] (:class:`Sailing`; − pinches).
    bank : {"left", "right"} or None
        The side it banked on up the first beat (:class:`Sailing`).
    """

    name: str
    status: str
    skill: float
    tack_cost_s: float
    gybe_cost_s: float
    first_side: Side | None
    start_fraction: float
    gun_t: float
    start_t: float
    start_delay_s: float
    distance_at_gun_m: float
    distance_at_first_gun_m: float
    ocs_s: float | None
    returned_t: float | None
    leg_end_t: tuple[float, ...]
    gate_marks: tuple[str, ...]
    gate_round_t: tuple[float, ...]
    sample_s: float
    spans: tuple[tuple[float, float], ...]
    faults: tuple[Fault, ...]
    duplicate_of: str | None
    legs: tuple[LegResult, ...]
    path_t: NDArray[np.float64]
    path_x: NDArray[np.float64]
    path_y: NDArray[np.float64]
    upwind_twa_offset_deg: float = 0.0
    bank: Bank | None = None

    @property
    def kinds(self) -> tuple[str, ...]:
        """The kinds of its faults."""
        return tuple(f.kind for f in self.faults)

    def fault(self, kind: str) -> Fault:
        """Its fault of ``kind`` (KeyError: none)."""
        for f in self.faults:
            if f.kind == kind:
                return f
        raise KeyError(f"{self.name} has no fault {kind!r}; it has {self.kinds}")

    @property
    def clean(self) -> bool:
        """Racing with no fault (GPS error and sampling aside)."""
        return self.status == "racing" and not self.faults

    def position(self, t: ArrayLike) -> tuple[NDArray, NDArray]:
        """True position ``(x, y)`` [m] at true times ``t`` [epoch s] (on the path)."""
        return np.interp(t, self.path_t, self.path_x), np.interp(t, self.path_t, self.path_y)


@dataclass(frozen=True, eq=False)
class Fleet:
    """A generated fleet: tracks, course and truth.

    Attributes
    ----------
    course : Course
        The course (start line ``start`` = ``start_pin``, ``start_boat``; mark ``1``; gate
        ``4`` = ``4s``, ``4p``; line ``finish``; :func:`layout`), its ``start_time`` the
        race's gun.
    course_yaml : str
        The course file's text (``start_time`` the race's gun).
    wind : FleetWind
        The true wind.
    polar : Polar
        The class polar (skill 1).
    gun : float
        The race's gun [epoch s] (after a general recall: the restart).
    guns : tuple of float
        Every gun, in order (two after a general recall).
    clock_lag_s : float
        The tracker's clock lag [s]: recorded time = true time − ``clock_lag_s``.
    marks : mapping of str to (float, float)
        Mark positions [m].
    boats : tuple of BoatTruth
        The truth per track, in the order of :attr:`tracks`.
    tracks : tuple of Track
        The recorded tracks (names unique).
    seed : int
    plan : FaultPlan
    """

    course: Course
    course_yaml: str
    wind: FleetWind
    polar: Polar
    gun: float
    guns: tuple[float, ...]
    clock_lag_s: float
    marks: Mapping[str, tuple[float, float]]
    boats: tuple[BoatTruth, ...]
    tracks: tuple[Track, ...]
    seed: int
    plan: FaultPlan

    def resampled(self, *, clock_lag_s: float | None = None, noise: bool = True) -> Fleet:
        """The same boats recorded again: with another clock lag, or without GPS error
        (the same fixes otherwise; :func:`record_tracks`)."""
        lag = self.clock_lag_s if clock_lag_s is None else clock_lag_s
        plan = (
            self.plan
            if noise
            else dataclasses.replace(self.plan, noise_white_m=0.0, noise_corr_m=0.0)
        )
        tracks = record_tracks(self.boats, lag, self.course.frame, plan, self.seed)
        return dataclasses.replace(self, clock_lag_s=lag, plan=plan, tracks=tracks)

    def truth(self, name: str) -> BoatTruth:
        """The truth of the track ``name``."""
        for b in self.boats:
            if b.name == name:
                return b
        raise KeyError(f"no boat {name!r}; boats: {', '.join(b.name for b in self.boats)}")

    def track(self, name: str) -> Track:
        """The recorded track ``name``."""
        return self.tracks[[b.name for b in self.boats].index(name)]

    def with_status(self, *statuses: str) -> tuple[BoatTruth, ...]:
        """The boats whose status is one of ``statuses``."""
        return tuple(b for b in self.boats if b.status in statuses)

    def with_fault(self, kind: str) -> tuple[BoatTruth, ...]:
        """The boats with a fault of ``kind``."""
        return tuple(b for b in self.boats if kind in b.kinds)

    @property
    def clean(self) -> tuple[BoatTruth, ...]:
        """Boats racing with no fault."""
        return tuple(b for b in self.boats if b.clean)

    def point_of_sail(self, leg: int, t: float | None = None) -> str:
        """``"upwind"``, ``"reach"`` or ``"downwind"`` for leg ``leg`` (0-based).

        The bearing from the leg's nominal start to its target against the true TWD at
        ``t`` (default: the median of the clean boats' leg mid-times), as
        :func:`~sailroute.course.geometry.wind_mode` tells them.
        """
        start, target = leg_endpoints(self.course, leg)
        a = start_centre(start)
        if t is None:
            mids = [
                0.5 * (b.legs[leg].t_start + b.legs[leg].t_end)
                for b in self.clean
                if len(b.legs) > leg
            ]
            t = float(np.median(mids)) if mids else self.gun
        twd = float(self.wind.direction(t, *a))
        return wind_mode(xy_bearing_deg(a, target.centre), twd)

    def truth_json(self) -> dict[str, Any]:
        """The truth as plain JSON values (times ISO 8601 UTC, true clock; NaN: null)."""

        def val(v: Any) -> Any:
            if isinstance(v, float | np.floating):
                return None if math.isnan(v) else float(v)
            if isinstance(v, tuple | list):
                return [val(e) for e in v]
            return v

        def t(v: float) -> str | None:
            return None if math.isnan(v) else iso(v)

        boats = {
            b.name: {
                "status": b.status,
                "duplicate_of": b.duplicate_of,
                "skill": b.skill,
                "tack_cost_s": b.tack_cost_s,
                "first_side": b.first_side,
                "gun": t(b.gun_t),
                "start": t(b.start_t),
                "start_delay_s": val(b.start_delay_s),
                "distance_at_gun_m": val(b.distance_at_gun_m),
                "ocs_s": b.ocs_s,
                "returned": None if b.returned_t is None else t(b.returned_t),
                "leg_ends": [t(v) for v in b.leg_end_t],
                "gate_marks": list(b.gate_marks),
                "gate_rounds": [t(v) for v in b.gate_round_t],
                "sample_s": b.sample_s,
                "faults": [
                    {"kind": f.kind, **{k: val(v) for k, v in f.params.items()}} for f in b.faults
                ],
                **_styled(b),
            }
            for b in self.boats
        }
        return {
            "seed": self.seed,
            "guns": [iso(g) for g in self.guns],
            "clock_lag_s": self.clock_lag_s,
            "clock": "recorded time = true time - clock_lag_s",
            "wind": {k: val(v) for k, v in dataclasses.asdict(self.wind).items()},
            "gps_error_m": {
                "white": self.plan.noise_white_m,
                "correlated": self.plan.noise_corr_m,
                "tau_s": self.plan.noise_tau_s,
            },
            "legs": [self.point_of_sail(i) for i in range(self.course.n_legs)],
            "boats": boats,
        }

    def write(
        self, folder: str | Path, fmt: str = "gpx", *, gun: str = "race"
    ) -> tuple[Path, list[Path]]:
        """Write ``course.yaml`` and one track file per boat (``<name>.gpx`` or ``.csv``).

        Parameters
        ----------
        folder : str or Path
            Created if missing.
        fmt : {"gpx", "csv"}
            Track format (CSV: ``time,lat,lon``, plus ``sog_kn,cog_deg`` with the plan's
            ``sog_cog``).
        gun : {"race", "first"}
            The course's ``start_time``: the race's gun, or the first gun (the one before a
            general recall).

        Returns
        -------
        (Path, list of Path)
            The course file and the track files, in the order of :attr:`tracks`.
        """
        d = Path(folder)
        d.mkdir(parents=True, exist_ok=True)
        yaml_text = self.course_yaml
        if gun == "first":
            yaml_text = yaml_text.replace(iso(self.gun), iso(self.guns[0]), 1)
        elif gun != "race":
            raise ValueError(f"gun {gun!r}: expected 'race' or 'first'")
        course = d / "course.yaml"
        course.write_text(yaml_text, encoding="utf-8")
        spec = self.course.boat_spec
        if "polar" in spec:  # the polar file beside the course, as the course names it
            src = Path(spec["polar"])
            (d / src.name).write_bytes(src.read_bytes())
        writer = {"gpx": write_gpx, "csv": write_csv}[fmt]
        paths = [writer(d / f"{tr.name}.{fmt}", tr) for tr in self.tracks]
        return course, paths


def _styled(b: BoatTruth) -> dict[str, Any]:
    """A boat's :class:`Sailing` in the truth's JSON: only what differs from the default
    (a fleet without styles keeps its JSON)."""
    out: dict[str, Any] = {}
    if b.upwind_twa_offset_deg:
        out["upwind_twa_offset_deg"] = b.upwind_twa_offset_deg
    if b.bank is not None:
        out["bank"] = b.bank
    return out


# ------------------------------------------------------------------------------ writers


def write_gpx(path: str | Path, track: Track) -> Path:
    """A GPX 1.1 file of ``track`` (one ``<trk>`` named as the track; lat, lon, time)."""
    p = Path(path)
    rows = [
        f'<trkpt lat="{la:.8f}" lon="{lo:.8f}"><time>{iso(float(t))}</time></trkpt>'
        for t, la, lo in zip(track.t_s, track.lat_deg, track.lon_deg, strict=True)
    ]
    p.write_text(
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<gpx version="1.1" creator="fleetgen" xmlns="http://www.topografix.com/GPX/1/1">\n'
        f"<trk><name>{track.name}</name><trkseg>\n"
        + "\n".join(rows)
        + "\n</trkseg></trk>\n</gpx>\n",
        encoding="utf-8",
    )
    return p


def write_csv(path: str | Path, track: Track) -> Path:
    """A tracker's CSV of ``track``: ``time,lat,lon`` (+ ``sog_kn,cog_deg`` when the track
    carries ``sog_ms``/``cog_deg``)."""
    p = Path(path)
    sog = track.channels.get("sog_ms")
    cog = track.channels.get("cog_deg")
    head = "time,lat,lon" + (",sog_kn,cog_deg" if sog is not None and cog is not None else "")
    lines = [head]
    for k, (t, la, lo) in enumerate(zip(track.t_s, track.lat_deg, track.lon_deg, strict=True)):
        row = f"{iso(float(t))},{la:.8f},{lo:.8f}"
        if sog is not None and cog is not None:
            row += f",{sog[k] / KNOT:.2f},{cog[k]:.1f}"
        lines.append(row)
    p.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return p


# ------------------------------------------------------------------------------ course

XY = tuple[float, float]
Knot = tuple[float, float, float]
"""A point of a drawn path: ``(t, x, y)`` [epoch s, m, m]."""


@dataclass(frozen=True)
class _Line:
    """The start line: centre, unit vector pin → committee, unit normal to the course side."""

    centre: XY
    along: XY
    normal: XY
    half_m: float

    def point(self, a: float) -> XY:
        """The point ``a`` metres from the centre towards the committee boat."""
        return (self.centre[0] + a * self.along[0], self.centre[1] + a * self.along[1])

    def side(self, x: ArrayLike, y: ArrayLike) -> NDArray:
        """Signed distance from the line [m], + on the course side."""
        return (np.asarray(x) - self.centre[0]) * self.normal[0] + (
            np.asarray(y) - self.centre[1]
        ) * self.normal[1]

    def shift(self, p: XY, d: float, a: float = 0.0) -> XY:
        """``p`` moved ``d`` m along the normal and ``a`` m along the line."""
        return (
            p[0] + d * self.normal[0] + a * self.along[0],
            p[1] + d * self.normal[1] + a * self.along[1],
        )


def _unit(deg: float) -> XY:
    """The unit vector of a compass heading [°] (:func:`~sailroute.units.heading_unit`)."""
    ux, uy = heading_unit(deg)
    return float(ux), float(uy)


def layout(axis_deg: float, leg_m: float, laps: int) -> CourseLayout:
    """The windward-leeward course of sailroute's template, centred on the origin, laid
    for ``axis_deg`` (:func:`~sailroute.course.templates.windward_leeward`; docs/course-format.md,
    "Templates"): mark ``1``, gate ``4`` (``4s`` left looking upwind, ``4p``), start line
    ``start`` (``start_pin`` left, ``start_boat``) 50 m under the gate, leeward finish line
    ``finish`` on its centre; marks rounded to the millimetre."""
    lay = windward_leeward((0.0, 0.0), axis_deg, leg_m, laps)
    marks = {k: (round(v[0], 3), round(v[1], 3)) for k, v in lay.marks.items()}
    return dataclasses.replace(lay, marks=marks)


def boat_spec(boat: str) -> dict[str, str]:
    """The course's ``boat`` section: a built-in polar's name, or a polar file (its absolute
    path; :meth:`Fleet.write` copies it beside the course file)."""
    if Path(boat).suffix.lower() in (".json", ".pol", ".csv"):
        return {"polar": str(Path(boat).resolve())}
    return {"builtin": boat}


def course_yaml_boat(spec: Mapping[str, str]) -> dict[str, str]:
    """The ``boat`` section as written: a polar file by its name (copied beside it)."""
    return {"polar": Path(spec["polar"]).name} if "polar" in spec else dict(spec)


def course_mapping(
    name: str,
    gun: float,
    lay: CourseLayout,
    origin: tuple[float, float],
    wind: FleetWind,
    boat: str,
    time_limit_min: float,
) -> dict[str, Any]:
    """The course file's content (a mapping for the course loader)."""
    return {
        "name": name,
        "start_time": iso(gun),
        "time_limit_min": time_limit_min,
        "origin": {"lat": origin[0], "lon": origin[1]},
        "marks": {k: {"x": v[0], "y": v[1]} for k, v in lay.marks.items()},
        "lines": {k: list(v) for k, v in lay.lines.items()},
        "gates": {k: list(v) for k, v in lay.gates.items()},
        "legs": [
            {"to": leg.to} if leg.rounding is None else {"to": leg.to, "rounding": leg.rounding}
            for leg in lay.legs
        ],
        "boat": boat_spec(boat),
        "routing": {"router": "isochrone", "tack_penalty_s": 5.0, "gybe_penalty_s": 3.0},
        "scenarios": {
            "mean": {
                "type": "uniform",
                "tws_kn": round(wind.tws_ms / KNOT, 2),
                "twd_deg": round(wind.twd_deg, 1),
            }
        },
    }


def course_yaml(data: Mapping[str, Any], comment: str) -> str:
    """The course mapping as YAML (block keys, JSON flow values: YAML 1.2)."""
    import json

    out = [f"# {line}" if line else "#" for line in comment.splitlines()]
    for key, value in data.items():
        if isinstance(value, Mapping) and key in ("marks", "lines", "gates", "scenarios"):
            out.append(f"{key}:")
            out += [f"  {json.dumps(k)}: {json.dumps(v)}" for k, v in value.items()]
        elif key == "boat":
            out.append(f"boat: {json.dumps(course_yaml_boat(value))}")
        elif key == "legs":
            out.append("legs:")
            out += [f"  - {json.dumps(v)}" for v in value]
        else:
            out.append(f"{key}: {json.dumps(value)}")
    return "\n".join(out) + "\n"


# ------------------------------------------------------------------------------ routing


@dataclass(frozen=True)
class _Plan:
    """One boat's race as routed: where and when it starts, how it sails."""

    key: str
    gun: float
    t_start: float
    start_xy: XY
    skill: float
    tack: int
    side: Side | None
    overrides: Mapping[int, Target] = field(default_factory=lambda: MappingProxyType({}))
    twa_offset: float = 0.0
    bank: Bank | None = None

    def tau(self, t: float) -> float:
        """Dilated time of true time ``t``."""
        return self.gun + self.skill * (t - self.gun)


def _true_time(res: LegResult, plan: _Plan) -> LegResult:
    """A leg routed in dilated time, in true time (times stretched, speeds scaled)."""
    g, s = plan.gun, plan.skill
    tr = dataclasses.replace(res.track, t=g + (res.track.t - g) / s, bsp_ms=res.track.bsp_ms * s)
    man = tuple(Manoeuvre(m.kind, g + (m.t - g) / s, m.x, m.y) for m in res.manoeuvres)
    return dataclasses.replace(
        res,
        t_start=g + (res.t_start - g) / s,
        t_end=g + (res.t_end - g) / s,
        manoeuvres=man,
        track=tr,
    )


ROUND_RADIUS_M: Final = 6.0
"""How far from a mark boats round it [m]: the router aims this far off each mark
(:func:`clear_target`), and the drawn roundings circle the mark at least this far off."""
ROUND_ON_M: Final = 8.0
"""After passing a gate outside its marks a boat sails this far on before its next leg
[m]."""


def clear_target(target: Target, start: Start, zone_m: float) -> Target:
    """The target the boats are routed to: a mark moved :data:`ROUND_RADIUS_M` out along
    its rounding segment, a gate narrowed by it at both ends (a line as it is), so that no
    route touches a mark.  The segment crossed lies on the course target's own segment
    (detection finds the crossing at the same place)."""
    r = ROUND_RADIUS_M
    if target.kind == "mark" and target.rounding is not None:
        g = target_geometry(target, start, zone_m)
        ex, ey = g.b[0] - g.a[0], g.b[1] - g.a[1]
        n = math.hypot(ex, ey)
        return dataclasses.replace(target, a=(g.a[0] + r * ex / n, g.a[1] + r * ey / n))
    if target.kind == "gate" and target.b is not None:
        (ax, ay), (bx, by) = target.a, target.b
        n = math.hypot(bx - ax, by - ay)
        ux, uy = (bx - ax) / n, (by - ay) / n
        return dataclasses.replace(
            target, a=(ax + r * ux, ay + r * uy), b=(bx - r * ux, by - r * uy)
        )
    return target


@dataclass(frozen=True)
class Rounding:
    """What a boat sailed between two routed legs (drawn, not routed).

    After a mark it goes on round the mark, on a circle through its arrival point (at least
    :data:`ROUND_RADIUS_M` off), through half the turn to the next leg; after a gate it
    goes on below the gate and round the gate mark nearer to where it passed, on a circle of
    :data:`ROUND_RADIUS_M`, to the mark's outer side; after a gate passed outside it sails
    :data:`ROUND_ON_M` straight on.  The next leg starts where the drawing ends.

    Attributes
    ----------
    t, x, y : tuple of float
        The drawn path after the leg's arrival [epoch s, m, m] (true time).
    mark : str
        The gate mark rounded ("" after a mark).
    apex_t : float
        When it passed straight below that gate mark [epoch s] (NaN after a mark).
    """

    t: tuple[float, ...]
    x: tuple[float, ...]
    y: tuple[float, ...]
    mark: str = ""
    apex_t: float = math.nan


def _arc(
    t0: float, p0: XY, centre: XY, sweep_deg: float, v: float
) -> tuple[NDArray, NDArray, NDArray]:
    """Points every 15° (or less) on the circle round ``centre`` through ``p0``, turned
    ``sweep_deg`` (+ anticlockwise: a port rounding), and their times at ``v`` [m s⁻¹]."""
    r = math.hypot(p0[0] - centre[0], p0[1] - centre[1])
    a0 = math.atan2(p0[1] - centre[1], p0[0] - centre[0])
    steps = max(2, math.ceil(abs(sweep_deg) / 15.0))
    ang = a0 + np.radians(sweep_deg) * np.arange(1, steps + 1) / steps
    x, y = centre[0] + r * np.cos(ang), centre[1] + r * np.sin(ang)
    t = t0 + r * np.abs(np.radians(sweep_deg)) * np.arange(1, steps + 1) / steps / v
    return t, x, y


def _rounding(res: LegResult, target: Target, course: Course, i: int) -> Rounding:
    """The drawn path after leg ``i``'s arrival (times as in ``res``)."""
    tr = res.track
    t0, x0, y0 = float(tr.t[-1]), float(tr.x[-1]), float(tr.y[-1])
    mv = np.flatnonzero(np.hypot(np.diff(tr.x), np.diff(tr.y)) > 1e-6)
    k = int(mv[-1]) if mv.size else 0
    dx, dy = float(tr.x[k + 1] - tr.x[k]), float(tr.y[k + 1] - tr.y[k])
    n = math.hypot(dx, dy) or 1.0
    v = 0.7 * float(tr.bsp_ms[k]) if tr.bsp_ms[k] > 0 else 1.0
    spec = course.legs[i]
    if target.name != spec.to_name:  # a gate passed outside
        step = ROUND_ON_M / v
        return Rounding((t0 + step,), (x0 + ROUND_ON_M * dx / n,), (y0 + ROUND_ON_M * dy / n,))
    if spec.kind == "mark":
        m = course.marks[spec.to_name]
        nxt = target_of(course, i + 1).centre
        turn = float(wrap180(bearing_deg(nxt[0] - m.x, nxt[1] - m.y) - bearing_deg(dx, dy)))
        sweep = 0.5 * abs(turn) * (1.0 if spec.rounding == "port" else -1.0)
        t, x, y = _arc(t0, (x0, y0), (m.x, m.y), sweep, v)
        return Rounding(tuple(t.tolist()), tuple(x.tolist()), tuple(y.tolist()))
    gate = course.gates[spec.to_name]
    ends = (gate.a, gate.b)
    m = min(ends, key=lambda e: math.hypot(e.x - x0, e.y - y0))
    o = ends[1] if m is ends[0] else ends[0]
    gx, gy = m.x - o.x, m.y - o.y
    gn = math.hypot(gx, gy)
    gx, gy = gx / gn, gy / gn
    nx, ny = -gy, gx  # across the gate, in the direction the boat passed it
    if nx * dx + ny * dy < 0:
        nx, ny = -nx, -ny
    r = ROUND_RADIUS_M
    phis = np.radians(np.arange(45.0, 161.0, 23.0))
    px = m.x + r * (-np.cos(phis) * gx + np.sin(phis) * nx)
    py = m.y + r * (-np.cos(phis) * gy + np.sin(phis) * ny)
    xs, ys = np.concatenate([[x0], px]), np.concatenate([[y0], py])
    ts = t0 + np.cumsum(np.hypot(np.diff(xs), np.diff(ys))) / v
    apex = float(np.interp(math.pi / 2.0, phis, ts))
    return Rounding(tuple(ts.tolist()), tuple(px.tolist()), tuple(py.tolist()), m.name, apex)


@dataclass(frozen=True)
class Routed:
    """One boat's race as sailed between its start and finish (true time).

    Attributes
    ----------
    legs : tuple of LegResult
        The routed legs.
    roundings : tuple of Rounding
        What it sailed after each leg but the last.
    """

    legs: tuple[LegResult, ...]
    roundings: tuple[Rounding, ...]

    @property
    def start_t(self) -> float:
        """When the boat leaves the start line [epoch s]: a route that begins with a tack
        on the line starts when the tack is over."""
        tr = self.legs[0].track
        moved = np.flatnonzero((tr.x != tr.x[0]) | (tr.y != tr.y[0]))
        return float(tr.t[moved[0] - 1]) if moved.size else float(tr.t[0])

    def knots(self) -> list[Knot]:
        """The path from the start (:attr:`start_t`) to the finish (repeated times
        dropped)."""
        out: list[Knot] = []
        t0 = self.start_t
        for k, leg in enumerate(self.legs):
            pts = zip(leg.track.t.tolist(), leg.track.x.tolist(), leg.track.y.tolist(), strict=True)
            if k == 0:
                pts = itertools.dropwhile(lambda p: p[0] < t0, pts)
            if k > 0:
                r = self.roundings[k - 1]
                pts = itertools.chain(zip(r.t, r.x, r.y, strict=True), pts)
            for p in pts:
                if not out or p[0] > out[-1][0] + 1e-9:
                    out.append(p)
        return out


GroupKey = tuple[int, Side | None, str, float, Bank | None]
"""What the boats routed in one front share (:func:`_group_key`)."""


def _group_key(p: _Plan, i: int) -> GroupKey:
    """Boats routed in one front share the penalties, on the first leg the first tack and
    the side they bank on, the target (a boat with its own target is routed alone) and the
    polar (its upwind TWA offset)."""
    return (
        p.tack,
        p.side if i == 0 else None,
        p.key if i in p.overrides else "",
        p.twa_offset,
        p.bank if i == 0 else None,
    )


def _joined(a: LegResult, b: LegResult) -> LegResult:
    """Two routed pieces of one leg as one leg (``b`` starts where ``a`` ends)."""
    ta, tb = a.track, b.track
    skip = 1 if tb.t[0] <= ta.t[-1] + 1e-9 else 0

    def cat(name: str) -> Any:
        u, v = getattr(ta, name), getattr(tb, name)
        return None if u is None or v is None else np.concatenate([u, v[skip:]])

    track = RouteTrack(**{f.name: cat(f.name) for f in dataclasses.fields(RouteTrack)})
    return dataclasses.replace(
        b,
        t_start=a.t_start,
        start_xy=a.start_xy,
        distance_m=a.distance_m + b.distance_m,
        n_tacks=a.n_tacks + b.n_tacks,
        n_gybes=a.n_gybes + b.n_gybes,
        manoeuvres=a.manoeuvres + b.manoeuvres,
        track=track,
    )


def _banked(
    starts: Sequence[Start],
    way: Target,
    target: Target,
    t0s: Sequence[float],
    winds: Sequence[DilatedWind],
    polar: Polar,
    settings: RoutingSettings,
) -> list[LegResult]:
    """A first leg routed to the waypoint ``way`` and from there to ``target``, joined
    (:func:`_joined`); the second piece starts on the tack the first ended on, so a tack at
    the waypoint costs its penalty."""
    first = route_leg_batch(starts, way, t0s, winds, polar, settings)
    out: dict[int, LegResult] = {}
    ends = [int(leg.track.side[-1]) for leg in first]
    for sd in sorted(set(ends)):
        idx = [k for k, e in enumerate(ends) if e == sd]
        res = route_leg_batch(
            [Start(first[k].end_xy, None, "start") for k in idx],
            target,
            [first[k].t_end for k in idx],
            [winds[k] for k in idx],
            polar,
            dataclasses.replace(settings, initial_side=side_name(sd)),
        )
        out.update({k: _joined(first[k], leg) for k, leg in zip(idx, res, strict=True)})
    return [out[k] for k in range(len(first))]


def route_plans(
    course: Course,
    plans: Sequence[_Plan],
    polar: Polar,
    wind: FleetWind,
    router: RoutingSettings = ROUTER,
) -> dict[str, Routed]:
    """Route every plan's race leg by leg, one batched front per leg and group of boats that
    share the router settings (:func:`_group_key`), with drawn roundings between the legs.

    Returns the routes in true time per plan key.
    """
    n = course.n_legs
    done: dict[str, list[LegResult]] = {p.key: [] for p in plans}  # dilated time
    turns: dict[str, list[Rounding]] = {p.key: [] for p in plans}  # dilated time
    winds = {p.key: wind.dilated(p.gun, p.skill) for p in plans}
    polars = {p.twa_offset: offset_polar(polar, p.twa_offset) for p in plans if p.twa_offset}
    polars[0.0] = polar
    for i in range(n):
        following = target_of(course, i + 1) if i + 1 < n else None
        ends = leg_endpoints(course, i)
        groups: dict[GroupKey, list[_Plan]] = {}
        for p in plans:
            groups.setdefault(_group_key(p, i), []).append(p)
        for (tack, side, own, offset, bank), members in groups.items():
            target = (
                members[0].overrides[i]
                if own
                else clear_target(chain_leg(*ends, None, following)[1], ends[0], router.zone_m)
            )
            starts, t0s = [], []
            for p in members:
                if not done[p.key]:
                    starts.append(Start(p.start_xy, None, "start"))
                    t0s.append(p.tau(p.t_start))
                else:
                    r = turns[p.key][-1]
                    starts.append(
                        Start((r.x[-1], r.y[-1]), None, ends[0].name, done[p.key][-1].barrier)
                    )
                    t0s.append(r.t[-1])
            settings = dataclasses.replace(
                router,
                tack_penalty_s=TACK_CLASSES[tack][0],
                gybe_penalty_s=TACK_CLASSES[tack][1],
                initial_side=side,
            )
            felt = [winds[p.key] for p in members]
            if bank is None:
                res = route_leg_batch(starts, target, t0s, felt, polars[offset], settings)
            else:
                way = bank_waypoint(course, polar, wind, bank)
                res = _banked(starts, way, target, t0s, felt, polars[offset], settings)
            for p, leg in zip(members, res, strict=True):
                done[p.key].append(leg)
                if i + 1 < n:
                    turns[p.key].append(_rounding(leg, target, course, i))
    out = {}
    for p in plans:
        g, s = p.gun, p.skill
        rounds = tuple(
            dataclasses.replace(
                r, t=tuple(g + (v - g) / s for v in r.t), apex_t=g + (r.apex_t - g) / s
            )
            for r in turns[p.key]
        )
        out[p.key] = Routed(tuple(_true_time(leg, p) for leg in done[p.key]), rounds)
    return out


# ------------------------------------------------------------------------------ drawn paths


def _dist(a: XY, b: XY) -> float:
    return math.hypot(b[0] - a[0], b[1] - a[1])


def _go(k: list[Knot], p: XY, v: float) -> None:
    """Sail straight from the last point to ``p`` at ``v`` [m s⁻¹]."""
    t0, x0, y0 = k[-1]
    k.append((t0 + _dist((x0, y0), p) / v, p[0], p[1]))


def _zigzag(k: list[Knot], t1: float, p1: XY, line: _Line, v: float = LOITER_MS) -> None:
    """Fill the time from the last point to ``(t1, p1)`` with zigzags along the line at
    about ``v`` [m s⁻¹], no closer to the line than the nearer end (both must lie below)."""
    t0, x0, y0 = k[-1]
    n = max(1, math.ceil((t1 - t0) / 80.0))
    for j in range(n):
        fa, fb = j / n, (j + 1) / n
        qa = (x0 + fa * (p1[0] - x0), y0 + fa * (p1[1] - y0))
        qb = (x0 + fb * (p1[0] - x0), y0 + fb * (p1[1] - y0))
        budget = v * (t1 - t0) / n
        mid = ((qa[0] + qb[0]) / 2.0, (qa[1] + qb[1]) / 2.0)
        depth = float(min(line.side(*qa), line.side(*qb))) - float(line.side(*mid)) - 5.0
        sign = 1.0 if j % 2 else -1.0
        lo, hi = 0.0, budget
        for _ in range(40):  # the offset along the line that uses the budget
            o = 0.5 * (lo + hi)
            w = line.shift(mid, depth, sign * o)
            if _dist(qa, w) + _dist(w, qb) > budget:
                hi = o
            else:
                lo = o
        w = line.shift(mid, depth, sign * lo)
        tw = t0 + (j + 0.5) * (t1 - t0) / n
        k.append((tw, w[0], w[1]))
        k.append((t0 + (j + 1) * (t1 - t0) / n, qb[0], qb[1]))


def _approach(heading_deg: float, speed: float, p: XY, t: float, seconds: float) -> Knot:
    """Where a boat sailing ``heading_deg`` at ``speed`` into ``p`` at ``t`` was
    ``seconds`` earlier."""
    ux, uy = _unit(heading_deg)
    return (t - seconds, p[0] - speed * seconds * ux, p[1] - speed * seconds * uy)


def _first_heading(legs: Sequence[LegResult]) -> tuple[float, float]:
    """Heading [°] and mean speed [m s⁻¹] of the route's first 30 s."""
    tr = legs[0].track
    dx, dy = np.diff(tr.x), np.diff(tr.y)
    k = int(np.flatnonzero(np.hypot(dx, dy) > 1e-6)[0])
    m = tr.t <= tr.t[0] + 30.0
    dist = float(np.sum(np.hypot(np.diff(tr.x[m]), np.diff(tr.y[m]))))
    return float(bearing_deg(dx[k], dy[k])), dist / float(tr.t[m][-1] - tr.t[0])


def _cross_time(a: Knot, b: Knot, line: _Line) -> float:
    """When the straight move ``a`` → ``b`` crosses the line (the two on either side)."""
    da, db = float(line.side(a[1], a[2])), float(line.side(b[1], b[2]))
    return a[0] + (b[0] - a[0]) * da / (da - db)


def _tail(legs: Sequence[LegResult], line: _Line, rng: np.random.Generator) -> list[Knot]:
    """After the finish: on for 20 s, then slowly off to one side for 60-120 s."""
    tr = legs[-1].track
    t, x, y = float(tr.t[-1]), float(tr.x[-1]), float(tr.y[-1])
    h, v = float(tr.heading_deg[-1]), 0.7 * float(np.median(tr.bsp_ms))
    ux, uy = _unit(h)
    k: list[Knot] = [(t, x, y), (t + 20.0, x + 20.0 * v * ux, y + 20.0 * v * uy)]
    side = 1.0 if rng.random() < 0.5 else -1.0
    _go(k, line.shift((k[-1][1], k[-1][2]), -10.0, side * rng.uniform(70.0, 140.0)), 1.2)
    return k[1:]


def _close_hauled(
    polar: Polar, wind: FleetWind, t: float, p: XY, side: Side | None
) -> tuple[float, float]:
    """Heading [°] close-hauled on ``side`` (None: starboard) and the polar's speed there."""
    tws = float(wind.speed(t, *p))
    alpha = float(polar.vmg_upwind(tws)[0])
    twd = float(wind.direction(t, *p))
    h = twd + alpha if side == "port" else twd - alpha
    return h % 360.0, float(polar.speed(tws, alpha))


@dataclass(frozen=True)
class _Run:
    """A drawn run over the line and back: crossed at ``t_cross``, back over at ``t_back``."""

    t_cross: float
    t_back: float


def _over_and_back(
    k: list[Knot],
    line: _Line,
    rng: np.random.Generator,
    *,
    heading: float,
    speed: float,
    a: float,
    t_cross: float,
    t_turn: float,
) -> _Run:
    """Zigzag, approach and cross the line at ``a`` at ``t_cross``, sail on until
    ``t_turn``, then bear away back below the line (appended to ``k``)."""
    x = line.point(a)
    k_in = _approach(heading, speed, x, t_cross, 25.0)
    _zigzag(k, k_in[0], (k_in[1], k_in[2]), line)
    k.append(k_in)
    k.append((t_cross, x[0], x[1]))
    ux, uy = _unit(heading)
    run = speed * (t_turn - t_cross)
    y = (x[0] + run * ux, x[1] + run * uy)
    k.append((t_turn, y[0], y[1]))
    q = line.shift(y, -float(line.side(*y)) - rng.uniform(15.0, 35.0), rng.uniform(-25.0, 25.0))
    _go(k, q, 1.8)
    return _Run(t_cross, _cross_time(k[-2], k[-1], line))


# ------------------------------------------------------------------------------ the fleet

NATIONS: Final = (
    "ITA", "FRA", "ESP", "GBR", "GER", "NED", "POL", "DEN", "SWE", "AUS",
    "USA", "CRO", "GRE", "POR", "SUI", "NOR", "BEL", "IRL", "CAN", "NZL",
)  # fmt: skip
ROLES: Final = (
    "non_starter",
    "ocs_returned",
    "ocs_not_returned",
    "late",
    "data_gap",
    "retired",
    "data_ends",
    "two_races",
    "gate_outside",
)
"""Per-boat faults, in the order boats are drawn for them (:class:`FaultPlan` counts)."""


def _names(rng: np.random.Generator, n: int) -> list[str]:
    """``n`` unique sail numbers (``ITA214``)."""
    out: list[str] = []
    while len(out) < n:
        s = f"{NATIONS[int(rng.integers(len(NATIONS)))]}{int(rng.integers(10, 4000))}"
        if s not in out:
            out.append(s)
    return out


@dataclass(frozen=True)
class _Boat:
    """The draw of one boat."""

    name: str
    role: str
    skill: float
    tack: int
    side: Side | None
    frac: float
    sample_s: float
    twa_offset: float = 0.0
    bank: Bank | None = None


@dataclass(frozen=True)
class _Race:
    """What the generator knows of the race while it builds it."""

    course: Course
    line: _Line
    wind: FleetWind
    polar: Polar
    plan: FaultPlan
    gun: float
    first_gun: float | None
    marks: Mapping[str, XY]

    @property
    def earliest(self) -> float:
        """The first gun."""
        return self.first_gun if self.first_gun is not None else self.gun


def _draw_boats(
    rng: np.random.Generator, n: int, plan: FaultPlan, sample_s: tuple[int, int]
) -> list[_Boat]:
    if plan.per_boat > n - 1:
        raise ValueError(
            f"the fault plan puts faults on {plan.per_boat} boats; a fleet of {n} has "
            f"{n - 1} besides the best boat: give more boats or fewer faults"
        )
    roles = ["racing"] * n
    order = list(rng.permutation(np.arange(1, n)))
    for role in ROLES:
        for _ in range(
            getattr(plan, {"data_gap": "data_gaps", "non_starter": "non_starters"}.get(role, role))
        ):
            roles[int(order.pop(0))] = role
    names = _names(rng, n)
    sides: tuple[Side | None, ...] = ("starboard", "port", None)
    out = []
    for k in range(n):
        out.append(
            _Boat(
                names[k],
                roles[k],
                1.0 if k == 0 else round(1.0 - 0.12 * float(rng.random()) ** 1.2, 4),
                0 if k == 0 else int(rng.integers(2)),
                sides[int(rng.choice(3, p=[0.55, 0.25, 0.2]))],
                float(rng.uniform(0.05, 0.95)),
                float(rng.integers(sample_s[0], sample_s[1] + 1)),
            )
        )
    return out


@dataclass(frozen=True)
class _Drawn:
    """A boat's start as drawn before routing: its plan and the path up to its final
    zigzag and approach."""

    boat: _Boat
    plan: _Plan | None
    head: tuple[Knot, ...]
    approach_s: float
    ocs_s: float | None = None
    returned_t: float | None = None
    first_gun_over: bool = False


def _head(race: _Race, b: _Boat, rng: np.random.Generator, a: float) -> list[Knot]:
    """The path from the first fix: below the line, and over it and back at a first gun."""
    start = race.line.shift(race.line.point(a), -rng.uniform(40.0, 90.0), rng.uniform(-80.0, 80.0))
    k: list[Knot] = [(race.earliest - rng.uniform(150.0, 300.0), start[0], start[1])]
    if race.first_gun is not None:
        g1 = race.first_gun
        over = b.role != "non_starter" and rng.random() < race.plan.recall_over
        h, v = _close_hauled(race.polar, race.wind, g1, race.line.point(a), b.side)
        dt = -rng.uniform(2.0, 8.0) if over else rng.uniform(1.0, 8.0)
        if b.role != "non_starter":
            _over_and_back(
                k,
                race.line,
                rng,
                heading=h,
                speed=0.9 * v * b.skill,
                a=a,
                t_cross=g1 + dt,
                t_turn=g1 + rng.uniform(30.0, 70.0),
            )
    return k


def _draw_start(race: _Race, b: _Boat, rng: np.random.Generator, key: str, gun: float) -> _Drawn:
    """The plan (start time and point) and drawn pre-start of one boat's race."""
    half = race.line.half_m
    a = (b.frac - 0.5) * 2.0 * half
    head = (
        _head(race, b, rng, a)
        if gun == race.gun
        else [(gun - rng.uniform(150.0, 240.0), *race.line.shift(race.line.point(a), -60.0, 40.0))]
    )
    approach = rng.uniform(20.0, 40.0)
    ocs_s = returned = None
    if b.role == "non_starter":
        return _Drawn(b, None, tuple(head), 0.0)
    if b.role == "late" and gun == race.gun:
        t0 = gun + rng.uniform(*race.plan.late_s)
        approach += t0 - gun
    elif b.role == "ocs_not_returned" and gun == race.gun:
        h, v = _close_hauled(race.polar, race.wind, gun, race.line.point(a), b.side)
        margin = rng.uniform(*race.plan.ocs_margin_m)
        t0 = gun - margin / (0.75 * v * b.skill)
        ocs_s = gun - t0
    elif b.role == "ocs_returned" and gun == race.gun:
        h, v = _close_hauled(race.polar, race.wind, gun, race.line.point(a), b.side)
        margin = rng.uniform(*race.plan.ocs_margin_m)
        v = 0.9 * v * b.skill
        e = margin / (v * math.cos(math.radians(30.0)))
        run = _over_and_back(
            head,
            race.line,
            rng,
            heading=h,
            speed=v,
            a=a,
            t_cross=gun - e,
            t_turn=gun + rng.uniform(3.0, 8.0),
        )
        ocs_s, returned = gun - run.t_cross, run.t_back
        a = float(np.clip(a + rng.uniform(-40.0, 40.0), -half + 10.0, half - 10.0))
        q = (head[-1][1], head[-1][2])
        t0 = head[-1][0] + 10.0 + _dist(q, race.line.point(a)) / LOITER_MS + approach
    else:
        t0 = gun + 0.5 + min(abs(float(rng.normal(0.0, 2.5))), 8.0)
    plan = _Plan(
        key,
        gun,
        t0,
        race.line.point(a),
        b.skill,
        b.tack,
        b.side,
        twa_offset=b.twa_offset,
        bank=b.bank,
    )
    return _Drawn(b, plan, tuple(head), approach, ocs_s, returned)


def _prestart(d: _Drawn, r: Routed, line: _Line) -> list[Knot]:
    """The drawn path up to the start: head, zigzags, the approach on the route's first
    heading."""
    assert d.plan is not None
    h, v = _first_heading(r.legs)
    k = list(d.head)
    e = _approach(h, 0.8 * v, d.plan.start_xy, r.start_t, d.approach_s)
    _zigzag(k, e[0], (e[1], e[2]), line)
    k.append(e)
    return k


def _non_starter(d: _Drawn, race: _Race, rng: np.random.Generator, t_end: float) -> list[Knot]:
    """Waits below the line until after the gun, then drifts away downwind."""
    k = list(d.head)
    w = race.line.shift((k[-1][1], k[-1][2]), 0.0, 0.0)
    w = race.line.shift(w, -float(race.line.side(*w)) - rng.uniform(15.0, 40.0), 0.0)
    t_w = race.gun + rng.uniform(20.0, 90.0)
    _zigzag(k, t_w, w, race.line)
    th = math.atan2(-race.line.normal[0], -race.line.normal[1]) + math.radians(rng.uniform(-30, 30))
    v = rng.uniform(0.1, 0.35)
    k.append(
        (t_end, w[0] + v * (t_end - t_w) * math.sin(th), w[1] + v * (t_end - t_w) * math.cos(th))
    )
    return k


def _line_of(marks: Mapping[str, XY]) -> _Line:
    pin, com, top = marks["start_pin"], marks["start_boat"], marks["1"]
    ex, ey = com[0] - pin[0], com[1] - pin[1]
    n = math.hypot(ex, ey)
    ex, ey = ex / n, ey / n
    c = ((pin[0] + com[0]) / 2.0, (pin[1] + com[1]) / 2.0)
    nx, ny = -ey, ex
    if (top[0] - c[0]) * nx + (top[1] - c[1]) * ny < 0:
        nx, ny = -nx, -ny
    return _Line(c, (ex, ey), (nx, ny), n / 2.0)


def _cut(k: Sequence[Knot], t: float) -> list[Knot]:
    """The path up to ``t`` (its last point interpolated at ``t``)."""
    ts = np.array([p[0] for p in k])
    x, y = np.interp(t, ts, [p[1] for p in k]), np.interp(t, ts, [p[2] for p in k])
    return [p for p in k if p[0] < t] + [(t, float(x), float(y))]


def _shifted(leg: LegResult, dt: float, dx: float = 0.0, dy: float = 0.0) -> LegResult:
    """A leg moved by ``dt`` [s] and ``(dx, dy)`` [m]."""
    tr = dataclasses.replace(leg.track, t=leg.track.t + dt, x=leg.track.x + dx, y=leg.track.y + dy)
    man = tuple(Manoeuvre(m.kind, m.t + dt, m.x + dx, m.y + dy) for m in leg.manoeuvres)
    return dataclasses.replace(
        leg,
        t_start=leg.t_start + dt,
        t_end=leg.t_end + dt,
        start_xy=(leg.start_xy[0] + dx, leg.start_xy[1] + dy),
        end_xy=(leg.end_xy[0] + dx, leg.end_xy[1] + dy),
        manoeuvres=man,
        track=tr,
    )


def _moved(r: Routed, dt: float, dx: float, dy: float) -> Routed:
    """A route moved by ``dt`` [s] and ``(dx, dy)`` [m]."""
    rounds = tuple(
        dataclasses.replace(
            q,
            t=tuple(v + dt for v in q.t),
            x=tuple(v + dx for v in q.x),
            y=tuple(v + dy for v in q.y),
            apex_t=q.apex_t + dt,
        )
        for q in r.roundings
    )
    return Routed(tuple(_shifted(leg, dt, dx, dy) for leg in r.legs), rounds)


@dataclass(frozen=True)
class _Sailed:
    """A boat's path and truth before sampling."""

    status: str
    knots: list[Knot]
    spans: tuple[tuple[float, float], ...]
    routed: Routed
    faults: tuple[Fault, ...]

    @property
    def legs(self) -> tuple[LegResult, ...]:
        return self.routed.legs


def _race_path(d: _Drawn, r: Routed, race: _Race, rng: np.random.Generator) -> list[Knot]:
    return _prestart(d, r, race.line) + r.knots() + _tail(r.legs, race.line, rng)


def _whole(k: Sequence[Knot]) -> tuple[tuple[float, float], ...]:
    return ((k[0][0], k[-1][0]),)


def _until(r: Routed, j: int) -> Routed:
    """The legs finished before leg ``j``."""
    return Routed(r.legs[:j], r.roundings[:j])


def _sail(
    d: _Drawn,
    routes: Mapping[str, Routed],
    race: _Race,
    rng: np.random.Generator,
    t_end: float,
    extra: Mapping[str, Any],
) -> _Sailed:
    """The boat's whole path, with its fault applied."""
    b = d.boat
    if d.plan is None:
        k = _non_starter(d, race, rng, t_end)
        return _Sailed("non_starter", k, _whole(k), Routed((), ()), (Fault("non_starter"),))
    r = routes[d.plan.key]
    k = _race_path(d, r, race, rng)
    if b.role in ("racing", "late", "ocs_returned", "ocs_not_returned"):
        faults: tuple[Fault, ...] = ()
        if b.role == "late":
            faults = (Fault("late", {"late_s": r.start_t - race.gun}),)
        elif b.role.startswith("ocs"):
            ocs = d.ocs_s if b.role == "ocs_returned" else race.gun - r.start_t
            faults = (Fault("ocs", {"ocs_s": ocs, "returned": b.role == "ocs_returned"}),)
        return _Sailed(b.role, k, _whole(k), r, faults)
    if b.role == "data_gap":
        return _data_gap(k, r, race.plan, rng)
    if b.role in ("retired", "data_ends"):
        return _retired(b.role, k, r, race.line, rng)
    if b.role == "two_races":
        second = routes[b.name + "#2"]
        k2 = _race_path(extra["second"][b.name], second, race, rng)
        f = Fault(
            "two_races",
            {
                "gun2": extra["gun2"],
                "start2_t": second.start_t,
                "leg_end2_t": tuple(leg.t_end for leg in second.legs),
                "gap": (k[-1][0], k2[0][0]),
            },
        )
        return _Sailed("two_races", k + k2, (_whole(k)[0], _whole(k2)[0]), r, (f,))
    if b.role == "gate_outside":
        i = next(iter(d.plan.overrides))
        f = Fault(
            "gate_outside",
            {"leg": i, "mark": extra["outside"][b.name], "passed_t": r.legs[i].t_end},
        )
        return _Sailed("gate_outside", k, _whole(k), r, (f,))
    return _other_fleet(b, k, r, extra["kinds"][b.name], d.plan.gun)


def _data_gap(k: list[Knot], r: Routed, plan: FaultPlan, rng: np.random.Generator) -> _Sailed:
    """No fixes for 45-120 s inside a leg (at least 20 s from its ends)."""
    j = int(rng.integers(len(r.legs)))
    leg = r.legs[j]
    g = min(rng.uniform(*plan.gap_s), leg.time_s - 40.0)
    t0 = leg.t_start + 20.0 + rng.uniform(0.0, leg.time_s - 40.0 - g)
    f = Fault("data_gap", {"leg": j, "t0": t0, "t1": t0 + g})
    return _Sailed("racing", k, ((k[0][0], t0), (t0 + g, k[-1][0])), r, (f,))


def _retired(kind: str, k: list[Knot], r: Routed, line: _Line, rng: np.random.Generator) -> _Sailed:
    """The log stops 30-70 % into a leg between the first and the last; a retired boat
    first sails 500 m off to its side of the course."""
    n = len(r.legs)
    j = int(rng.integers(1, max(2, n - 1)))
    t = r.legs[j].t_start + rng.uniform(0.3, 0.7) * r.legs[j].time_s
    k = _cut(k, t)
    if kind == "retired":
        p = (k[-1][1], k[-1][2])
        side = 1.0 if float(np.dot(np.subtract(p, line.centre), line.along)) > 0 else -1.0
        _go(k, line.shift(p, 0.0, side * 500.0), 2.2)
    return _Sailed("retired", k, _whole(k), _until(r, j), (Fault(kind, {"leg": j, "t": t}),))


def _other_fleet(b: _Boat, k: list[Knot], r: Routed, kind: str, gun: float) -> _Sailed:
    """A boat of another fleet: its own class and gun, or the race moved to another area or
    day."""
    if kind == "class":
        f = Fault("other_fleet", {"kind": kind, "gun": gun, "skill": b.skill})
        return _Sailed("other_fleet", k, _whole(k), r, (f,))
    dt, dx, dy = (86400.0, 0.0, 0.0) if kind == "day" else (0.0, 2828.4, 2828.4)
    k = [(t + dt, x + dx, y + dy) for t, x, y in k]
    f = Fault("other_fleet", {"kind": kind, "shift_s": dt, "offset_m": (dx, dy)})
    return _Sailed("other_fleet", k, _whole(k), _moved(r, dt, dx, dy), (f,))


def _gps_error(
    rng: np.random.Generator, n: int, dt: float, white: float, corr: float, tau: float
) -> NDArray:
    """GPS error along one axis [m]: white plus first-order autoregressive (sd ``corr``,
    correlation time ``tau``) at a fix every ``dt`` s."""
    e = white * rng.normal(0.0, 1.0, n)
    a = math.exp(-dt / tau)
    z = (corr * math.sqrt(1.0 - a * a) * rng.normal(0.0, 1.0, n)).tolist()
    if corr > 0 and n:
        z[0] = corr * z[0] / math.sqrt(1.0 - a * a)
        for k in range(1, n):
            z[k] += a * z[k - 1]
    return e + np.array(z)


def _record(
    b: BoatTruth, lag: float, frame: LocalFrame, plan: FaultPlan, rng: np.random.Generator
) -> Track:
    """The tracker's record of a boat's path: fixes every ``b.sample_s`` s on whole seconds
    of a clock ``lag`` s behind, over its spans, with GPS error and optionally SOG/COG."""
    dt = b.sample_s
    phase = float(rng.integers(int(dt)))
    rec = []
    for lo, hi in b.spans:
        r0 = math.ceil((lo - lag - phase) / dt) * dt + phase
        r = np.arange(r0, hi - lag + 1e-9, dt)
        rec.append(r[(r + lag >= lo) & (r + lag <= hi)])
    r = np.concatenate(rec)
    t = r + lag
    kt, kx, ky = b.path_t, b.path_x, b.path_y
    noise = (plan.noise_white_m, plan.noise_corr_m, plan.noise_tau_s)
    x = np.interp(t, kt, kx) + _gps_error(rng, t.size, dt, *noise)
    y = np.interp(t, kt, ky) + _gps_error(rng, t.size, dt, *noise)
    lat, lon = frame.to_latlon(x, y)
    channels: dict[str, NDArray] = {}
    if plan.sog_cog:
        seg = np.clip(np.searchsorted(kt, t, side="right") - 1, 0, kt.size - 2)
        span = np.maximum(np.diff(kt)[seg], 1e-9)
        vx, vy = np.diff(kx)[seg] / span, np.diff(ky)[seg] / span
        channels["sog_ms"] = np.hypot(vx, vy) + rng.normal(0.0, 0.1, t.size)
        channels["cog_deg"] = (bearing_deg(vx, vy) + rng.normal(0.0, 2.0, t.size)) % 360.0
    return Track(r.astype(float), lat, lon, b.name, b.name, MappingProxyType(channels), ())


def record_tracks(
    boats: Sequence[BoatTruth], lag: float, frame: LocalFrame, plan: FaultPlan, seed: int
) -> tuple[Track, ...]:
    """Every boat's track (:func:`_record`; a duplicate: its source's data under its own
    name), from the random stream ``[seed, 1]``: the same fixes and error whatever the
    routing drew."""
    rng = np.random.default_rng([seed, 1])
    own = {b.name: _record(b, lag, frame, plan, rng) for b in boats if b.duplicate_of is None}
    return tuple(
        own[b.name]
        if b.duplicate_of is None
        else dataclasses.replace(own[b.duplicate_of], name=b.name, source=b.name)
        for b in boats
    )


OTHER_CLASS_SKILL: Final = 1.22
"""Speed of the faster class against the fleet's best boat [-]."""
OTHER_CLASS_AFTER_S: Final = 240.0
"""The faster class's gun after the fleet's [s]."""


def _leg_length(polar: Polar, tws: float, minutes: float, laps: int) -> float:
    """Leg length [m] for a race of about ``minutes`` for the median boat."""
    vu, vd = float(polar.vmg_upwind(tws)[1]), float(polar.vmg_downwind(tws)[1])
    return 10.0 * round(0.94 * minutes * 60.0 / (laps / vu + laps / vd) / 10.0)


def _outside_gate(race: _Race, rng: np.random.Generator) -> tuple[str, Target]:
    """A gate 20-80 m beyond one of the leeward gate's marks, on the gate's line."""
    m = "4s" if rng.random() < 0.5 else "4p"
    other = race.marks["4p" if m == "4s" else "4s"]
    p = race.marks[m]
    ux, uy = p[0] - other[0], p[1] - other[1]
    n = math.hypot(ux, uy)
    ux, uy = ux / n, uy / n
    return m, Target(
        "gate",
        (p[0] + 20.0 * ux, p[1] + 20.0 * uy),
        (p[0] + 80.0 * ux, p[1] + 80.0 * uy),
        name=f"outside {m}",
    )


def _truth(d: _Drawn, s: _Sailed, race: _Race, name: str, n_legs: int) -> BoatTruth:
    kt = np.array([p[0] for p in s.knots])
    kx, ky = np.array([p[1] for p in s.knots]), np.array([p[2] for p in s.knots])
    gun = d.plan.gun if d.plan is not None else race.gun
    shift = float(
        next((f.params.get("shift_s", 0.0) for f in s.faults if f.kind == "other_fleet"), 0.0)
    )
    gun += shift

    def side_at(t: float | None) -> float:
        if t is None or not kt[0] <= t <= kt[-1]:
            return math.nan
        return float(race.line.side(np.interp(t, kt, kx), np.interp(t, kt, ky)))

    ends = [leg.t_end for leg in s.legs] + [math.nan] * (n_legs - len(s.legs))
    start = s.routed.start_t if s.legs else math.nan
    b = d.boat
    pen = TACK_CLASSES[b.tack]
    rounds = [*s.routed.roundings, Rounding((), (), ())][: len(s.legs)]
    return BoatTruth(
        name=name,
        status=s.status,
        skill=b.skill,
        tack_cost_s=pen[0] / b.skill,
        gybe_cost_s=pen[1] / b.skill,
        first_side=b.side,
        start_fraction=b.frac,
        gun_t=gun,
        start_t=start,
        start_delay_s=start - gun,
        distance_at_gun_m=side_at(gun),
        distance_at_first_gun_m=side_at(race.first_gun),
        ocs_s=next((f.params["ocs_s"] for f in s.faults if f.kind == "ocs"), None),
        returned_t=d.returned_t,
        leg_end_t=tuple(float(v) for v in ends),
        gate_marks=tuple(q.mark for q in rounds),
        gate_round_t=tuple(q.apex_t for q in rounds),
        sample_s=d.boat.sample_s,
        spans=s.spans,
        faults=s.faults,
        duplicate_of=None,
        legs=s.legs,
        path_t=kt,
        path_x=kx,
        path_y=ky,
        upwind_twa_offset_deg=b.twa_offset,
        bank=b.bank,
    )


def messy_fleet(
    seed: int = 0,
    n_boats: int = 40,
    minutes: float = 45.0,
    faults: FaultPlan | None = None,
    sample_s: tuple[int, int] = (1, 3),
    clock_lag_s: float = 7.0,
    *,
    boat: str = "ilca7",
    laps: int = 2,
    tws_kn: float = 10.0,
    twd_deg: float | None = None,
    pressure_left: float = 0.0,
    gun: float = GUN,
    centre: tuple[float, float] = CENTRE,
    router: RoutingSettings = ROUTER,
    sailing: Mapping[int, Sailing] | None = None,
    wind_fields: Mapping[str, float] | None = None,
) -> Fleet:
    """Sail a fleet and record it (module docstring).

    Parameters
    ----------
    seed : int
        Seed of every random choice.
    n_boats : int
        Boats of the fleet (duplicates and boats of other fleets come on top).
    minutes : float
        About how long the median boat races [min] (sets the leg length).
    faults : FaultPlan, optional
        What to inject (default :class:`FaultPlan`'s defaults; ``FaultPlan.clean()``: none).
    sample_s : (int, int)
        Range of the boats' fix intervals [s] (each boat one whole number in it).
    clock_lag_s : float
        The tracker's clock lag [s]: recorded time = true time − lag.
    boat : str
        The class polar: a built-in name (``ilca7``, ...; they run dead downwind), or a
        polar file (``tests/data/boat/ITA_ITA455J70.json``: a J/70, which gybes at TWA
        145-150°).
    laps : int
        Beats (the gate is passed ``laps − 1`` times).
    tws_kn : float
        Mean TWS [kn].
    twd_deg : float, optional
        Mean TWD and course axis [°] (default drawn).
    pressure_left : float
        Relative TWS change per km left of the axis [km⁻¹].
    gun : float
        The race's gun [epoch s].
    centre : (float, float)
        Course centre ``(lat, lon)`` [°].
    router : RoutingSettings
        Router settings (the penalties and first tack are set per group).
    sailing : mapping of int to Sailing, optional
        How boat ``k`` of the draw sails (0: the best boat; the others in the order drawn,
        faults included); a banking boat starts on the tack to its side.  Nothing else is
        drawn differently.
    wind_fields : mapping of str to float, optional
        :class:`FleetWind` fields set after the wind is drawn (``{"osc_amp_deg": 0.0,
        "shift_deg": 12.0, "shift_start_s": 60.0}``); the other draws stay as they are.
    """
    plan = FaultPlan() if faults is None else faults
    rng = np.random.default_rng(seed)
    polar = read_polar(boat) if "polar" in boat_spec(boat) else builtin_polar(boat)
    twd = float(5 * rng.integers(72)) if twd_deg is None else float(twd_deg)
    wind = FleetWind(
        gun,
        twd,
        tws_kn * KNOT,
        twd,
        osc_amp_deg=float(rng.uniform(5.0, 9.0)),
        osc_period_s=float(rng.uniform(300.0, 540.0)),
        osc_phase=float(rng.uniform(0.0, 2.0 * math.pi)),
        shift_deg=float(rng.choice([-1.0, 1.0]) * rng.uniform(5.0, 10.0)),
        tws_phase=float(rng.uniform(0.0, 2.0 * math.pi)),
        pressure_left=pressure_left,
    )
    if wind_fields:
        wind = dataclasses.replace(wind, **wind_fields)
    lay = layout(twd, _leg_length(polar, wind.tws_ms, minutes, laps), laps)
    marks = lay.marks
    data = course_mapping(
        f"messy fleet (seed {seed})", gun, lay, centre, wind, boat, max(90.0, 3.0 * minutes)
    )
    course = course_from_mapping(data)
    first_gun = gun - plan.recall_s if plan.general_recall else None
    race = _Race(course, _line_of(marks), wind, polar, plan, gun, first_gun, marks)
    boats = _draw_boats(rng, n_boats, plan, sample_s)
    for k, how in (sailing or {}).items():
        boats[k] = dataclasses.replace(
            boats[k],
            twa_offset=float(how.upwind_twa_offset_deg),
            bank=how.bank,
            side=boats[k].side if how.bank is None else BANK_TACK[how.bank],
        )
    drawn = [_draw_start(race, b, rng, b.name, gun) for b in boats]
    gun2 = gun + 60.0 * math.ceil(1.3 * minutes + 15.0)
    second = {
        b.name: _draw_start(race, b, rng, b.name + "#2", gun2)
        for b in boats
        if b.role == "two_races"
    }
    kinds: dict[str, str] = {}
    taken = {b.name for b in boats}
    for kind, name in zip(
        plan.other_fleet, (n for n in _names(rng, 4 * n_boats) if n not in taken), strict=False
    ):
        cls = kind == "class"
        b = _Boat(
            name,
            "other_fleet",
            OTHER_CLASS_SKILL if cls else round(float(rng.uniform(0.9, 0.98)), 4),
            int(rng.integers(2)),
            "starboard",
            float(rng.uniform(0.1, 0.9)),
            float(rng.integers(sample_s[0], sample_s[1] + 1)),
        )
        kinds[name] = kind
        drawn.append(_draw_start(race, b, rng, name, gun + OTHER_CLASS_AFTER_S if cls else gun))
    outside: dict[str, str] = {}
    gate_leg = (
        next(i for i, leg in enumerate(course.legs) if leg.kind == "gate") if laps > 1 else None
    )
    for k, d in enumerate(drawn):
        if d.boat.role == "gate_outside" and d.plan is not None and gate_leg is not None:
            m, target = _outside_gate(race, rng)
            outside[d.boat.name] = m
            drawn[k] = dataclasses.replace(
                d, plan=dataclasses.replace(d.plan, overrides=MappingProxyType({gate_leg: target}))
            )
    plans = [d.plan for d in [*drawn, *second.values()] if d.plan is not None]
    routes = route_plans(course, plans, polar, wind, router)
    t_end = max(r.legs[-1].t_end for k, r in routes.items() if not k.endswith("#2")) + 120.0
    extra = {"second": second, "gun2": gun2, "outside": outside, "kinds": kinds}
    truths = [
        _truth(d, _sail(d, routes, race, rng, t_end, extra), race, d.boat.name, course.n_legs)
        for d in drawn
    ]
    truths += _duplicates(truths, plan, rng)
    truths.sort(key=lambda b: b.name)
    comment = (
        f"A generated fleet (tests/fleetgen.py, seed {seed}): {n_boats} boats, about "
        f"{minutes:.0f} min.\nWind: TWD {twd:.0f}° ± shifts, TWS {tws_kn:.1f} kn.\n"
        + (f"General recall: first gun {iso(first_gun)}.\n" if first_gun is not None else "")
    )
    fleet = Fleet(
        course=course,
        course_yaml=course_yaml(data, comment),
        wind=wind,
        polar=polar,
        gun=gun,
        guns=(gun,) if first_gun is None else (first_gun, gun),
        clock_lag_s=clock_lag_s,
        marks=MappingProxyType(dict(marks)),
        boats=tuple(truths),
        tracks=(),
        seed=seed,
        plan=plan,
    )
    return fleet.resampled()


def _duplicates(
    boats: Sequence[BoatTruth], plan: FaultPlan, rng: np.random.Generator
) -> list[BoatTruth]:
    """``plan.duplicates`` copies of clean boats under new names."""
    clean = [b for b in boats if b.clean]
    taken = {b.name for b in boats}
    fresh = (n for n in _names(rng, 4 * len(boats) + 8) if n not in taken)
    pick = rng.choice(len(clean), size=min(plan.duplicates, len(clean)), replace=False)
    return [
        dataclasses.replace(
            clean[int(k)],
            name=next(fresh),
            status="duplicate_of",
            duplicate_of=clean[int(k)].name,
            faults=(Fault("duplicate", {"of": clean[int(k)].name}),),
        )
        for k in pick
    ]


@functools.lru_cache(maxsize=8)
def shared_fleet(seed: int = 0, **kwargs: Any) -> Fleet:
    """:func:`messy_fleet` computed once per test run for the same arguments (keyword
    arguments only besides ``seed``; all hashable), for test modules that use the same
    fleet.  The fleet is shared: do not change its arrays."""
    return messy_fleet(seed, **kwargs)
