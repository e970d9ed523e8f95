"""Gains against the fleet: per leg, where each boat won or lost time on the others.

The loss against the optimal route (:mod:`sailroute.analysis.loss`) measures every boat
against one router's answer; timed from the gun it mostly restates the finish order.  A
gain measures a boat against the boats that sailed the same leg in the same wind: the
fleet's median, or the leg's top three.

Notation for one leg ``i`` and a boat ``k`` that sailed it (its own leg start to its own
leg end): ``T_k`` its leg time [s], ``D_k`` its progress along the leg's axis (the centre
of the leg's start — line or mark — to the centre of its target) [m], ``C_k`` what its
manoeuvres cost (:func:`~sailroute.analysis.loss.manoeuvre_cost`: each window's time minus
its progress at the straight-line rate) and ``n_k`` their number.  A reference ``R`` (the
boats that sailed the leg for ``"median"``, the leg's three fastest for ``"top3"``: a boat
without a place in the results, over early or whose data end on the last leg, sailed its
known legs like the others) gives
``T_R``, ``D_R``, ``n_R``, ``c_R`` (median, or mean for the top three, over its boats; ``c``
the cost per manoeuvre of the boats that manoeuvred) and ``C_R = n_R c_R``.

total
    ``G = T_R − T_k`` (+: the boat was faster than the reference).  With the start part
    ``G_0 = δ_R − δ_k`` (``δ`` the start crossing after the gun), ``G_0 + Σ_i G_i`` is
    the gain in elapsed time at the finish on a reference that started at ``δ_R`` and
    sailed every leg in ``T_R``.
manoeuvres
    ``C_R − C_k = n_R c_R − n_k c_k``: fewer or cheaper tacks and gybes than the
    reference's count at its cost.

The rest, ``T'_R − T'_k`` with ``T' = T − C`` (the leg sailed straight), is split by a
log-mean (LMDI) split of the straight-line progress rate ``v̄ = D / T'`` into factors
measured on the points outside the manoeuvre windows (time means over them, ``θ`` the
signed TWA from COG in the wind the leg was judged in, ``ω`` the wind's direction minus the
axis's bearing, so that progress per second is ``SOG cos(ω − θ)``).  The fleet's speed at a
TWA is ``f(θ) = g(|θ|) · polar(TWS, |θ|)``: the polar scaled, per 5° of TWA, by the
median ``SOG / polar`` of the boats whose median ``|θ|`` on a tack lies in that bin (their
points on that tack; bins held by fewer than a third of the boats take the leg's median
ratio), so that a change of TWS along the leg is the polar's.  ``f`` is read at a boat's
median angle on each tack, so it is measured there: binned point by point instead, the
points whose angle noise puts them at 32° while their boats sail 42° (at the speed of 42°)
would set the fleet's speed at 32°, and a boat that pinches to 32° at the polar's speed
would show a speed loss and a height gain (docs/analysis.md, "Gains on the fleet").  The
fleet's angle ``θ_σ`` on each tack ``σ`` is the median over the boats of their median
``|θ|`` on it.

* ``P1 = ⟨f(θ) cos(ω − θ)⟩``: the boat's angles and wind at the fleet's speed;
* ``P2 = ⟨f(σ θ_σ) cos(ω − σ θ_σ)⟩``: the fleet's angle on the boat's tack, in the wind
  the boat had (on a reach, ``⟨f(θ)⟩``: the speed its wind angle gave);

speed ``S = v̄ / P1``, height ``H = P1 / P2``, side / shifts ``W = P2``; each against the
median over the reference's boats (``S_R``, ...).  With ``L`` the logarithmic mean of
``T'_R`` and ``T'_k``, the parts are ``L ln(S/S_R)``, ``L ln(H/H_R)``, ``L ln(W/W_R)``,
and **other** (distance and the rest) ``T'_R − T'_k`` minus these three: ``L ln(D_R/D_k)``
(the leg's start and end points) plus ``L ln(S_R H_R W_R / v̄_R)``, the gap between the
product of the medians and the reference's rate.  The parts add up to the total exactly.

The wind the leg was judged in enters the height and side parts only (the total, the
manoeuvres and ``v̄`` do not depend on it; the speed part only through ``f``).  A constant
error ``e`` of its direction cancels: it moves ``θ`` and ``ω`` by ``e`` alike, so
``ω − θ`` (the course against the axis) stays, and it moves the fleet's signed angle
``σ θ_σ`` by ``e`` on both tacks, so ``P2`` stays.  An error that changes along the leg
does not: a shift the wind misses (an inferred wind smooths over its time window) leaves
``ω`` where it was while the boats' courses follow the real wind, and the gain of the
lifted boats moves from the side part into the height part, by about ``L`` times the missed
shift [rad] times ``tan(θ_σ)`` for the time spent in it.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Final

import numpy as np
from numpy.typing import NDArray

from sailroute.analysis.loss import (
    POLAR_MIN_MS,
    axis_progress,
    manoeuvre_cost,
    manoeuvre_mask,
    time_mean,
)
from sailroute.analysis.result import TrackAnalysis
from sailroute.course.geometry import leg_endpoints
from sailroute.course.model import Course
from sailroute.units import wrap180

__all__ = [
    "PARTS",
    "REFERENCES",
    "FleetGains",
    "GainTable",
    "fleet_gains",
    "log_mean",
]

PARTS: Final = ("speed", "height", "side", "manoeuvres", "other")
"""The parts of a leg's gain, in the order of :attr:`GainTable.parts_s`."""
REFERENCES: Final = ("median", "top3")
"""The references a boat is measured against: the fleet's median, the leg's top three."""
BIN_DEG: Final = 5.0
"""Width of the TWA bins of the fleet's speed curve [°]."""
BIN_MIN_SAMPLES: Final = 10
"""A TWA bin needs this many points (and a third of the fleet's boats, at least 2, with
their median angle on a tack in it) to have a ratio of its own."""
TOP: Final = 3
"""Boats in the leg's top group."""

Speed = Callable[[NDArray[np.float64], NDArray[np.float64]], NDArray[np.float64]]
"""A polar's speed ``(tws_ms, |twa_deg|) -> m s⁻¹``."""


def log_mean(a: float, b: float) -> float:
    """Logarithmic mean ``(a − b) / (ln a − ln b)`` of two positive numbers (``a`` if equal)."""
    if a <= 0 or b <= 0:
        return math.nan
    if abs(a - b) <= 1e-12 * max(a, b):
        return 0.5 * (a + b)
    return (a - b) / (math.log(a) - math.log(b))


@dataclass(frozen=True, eq=False)
class GainTable:
    """Gains against one reference, boats × legs.

    Attributes
    ----------
    reference : str
        One of :data:`REFERENCES`.
    boats : tuple of str
    labels : tuple of str
        The legs' labels.
    start_s : ndarray
        Per boat, the start part ``δ_R − δ_k`` [s] (NaN: start unknown).
    total_s : ndarray
        Boats × legs, ``T_R − T_k`` [s] (NaN: the leg's time unknown).
    parts_s : ndarray
        Boats × legs × :data:`PARTS` [s]; they add up to ``total_s``.
    reference_time_s : ndarray
        Per leg ``T_R`` [s]; ``reference_start_s`` the reference's ``δ_R`` [s].
    reference_start_s : float
    """

    reference: str
    boats: tuple[str, ...]
    labels: tuple[str, ...]
    start_s: NDArray[np.float64]
    total_s: NDArray[np.float64]
    parts_s: NDArray[np.float64]
    reference_time_s: NDArray[np.float64]
    reference_start_s: float

    def part(self, name: str) -> NDArray[np.float64]:
        """Boats × legs of one part [s] (``"total"`` and :data:`PARTS`)."""
        if name == "total":
            return self.total_s
        return self.parts_s[:, :, PARTS.index(name)]

    def summed(self, legs: Sequence[int]) -> dict[str, NDArray[np.float64]]:
        """Per boat, ``"start"``, each part and ``"total"`` (start included) summed over
        ``legs`` [s] (NaN where one of them is unknown)."""
        sel = list(legs)
        out = {"start": self.start_s.copy()}
        for k, name in enumerate(PARTS):
            out[name] = self.parts_s[:, sel, k].sum(axis=1)
        out["total"] = self.start_s + self.total_s[:, sel].sum(axis=1)
        return out


@dataclass(frozen=True, eq=False)
class FleetGains:
    """A fleet's gains against both references, and what the fleet did per leg.

    Attributes
    ----------
    median, top3 : GainTable
    top : tuple of tuple of str
        Per leg, its three fastest boats (fewer where fewer sailed it).
    fleet_angle_deg : ndarray
        Legs × 2: the fleet's ``|TWA|`` on port and on starboard (``θ_σ``) [°].
    manoeuvres : ndarray
        Boats × legs: tacks and gybes counted.
    manoeuvre_cost_s : ndarray
        Boats × legs: cost per manoeuvre [s] (NaN: none).
    wind_sources : tuple of str
        Per leg, the wind sources the boats' legs were judged in (``"inferred"`` ...).
    """

    median: GainTable
    top3: GainTable
    top: tuple[tuple[str, ...], ...]
    fleet_angle_deg: NDArray[np.float64]
    manoeuvres: NDArray[np.int64]
    manoeuvre_cost_s: NDArray[np.float64]
    wind_sources: tuple[tuple[str, ...], ...]

    def table(self, reference: str) -> GainTable:
        """The :class:`GainTable` of ``reference`` (:data:`REFERENCES`)."""
        if reference not in REFERENCES:
            raise ValueError(f"reference {reference!r}: expected one of {REFERENCES}")
        return self.median if reference == "median" else self.top3


@dataclass(frozen=True)
class _Leg:
    """One boat's leg, measured (NaN where unknown)."""

    time_s: float
    dist_m: float
    cost_s: float
    n: int
    rate: float
    p1: float
    p2: float


_NAN_LEG = _Leg(math.nan, math.nan, math.nan, 0, math.nan, math.nan, math.nan)


def fleet_gains(
    course: Course,
    analyses: Sequence[TrackAnalysis],
    speed: Speed,
    ranked: Sequence[bool] | None = None,
) -> FleetGains:
    """The gains of every debriefed boat on every leg (module notes).

    Parameters
    ----------
    course : Course
    analyses : sequence of TrackAnalysis
        The debriefed boats.
    speed : callable
        A polar's speed ``(tws [m s⁻¹], |TWA| [°]) -> [m s⁻¹]`` (the shape of the fleet's
        speed curve).
    ranked : sequence of bool, optional
        Per boat: it is part of the references and of the fleet's speed curve (default
        all: every boat whose leg time is known).

    Returns
    -------
    FleetGains
    """
    nb = len(analyses)
    n_legs = min((len(a.legs) for a in analyses), default=0)
    rank = np.array([True] * nb if ranked is None else list(ranked), bool)
    legs = [[_NAN_LEG] * n_legs for _ in range(nb)]
    angles = np.full((n_legs, 2), np.nan)
    tops: list[tuple[str, ...]] = []
    for i in range(n_legs):
        angles[i], rows = _leg_measures(course, analyses, speed, rank, i)
        for k in range(nb):
            legs[k][i] = rows[k]
        t = np.array([rows[k].time_s for k in range(nb)])
        ok = np.flatnonzero(np.isfinite(t) & rank)
        tops.append(tuple(analyses[k].track.name for k in ok[np.argsort(t[ok])][:TOP]))
    delay = np.array([_start_delay(a) for a in analyses])
    tables = tuple(_table(ref, analyses, legs, delay, rank) for ref in REFERENCES)
    n = np.array([[legs[k][i].n for i in range(n_legs)] for k in range(nb)], np.int64)
    cost = np.array([[legs[k][i].cost_s for i in range(n_legs)] for k in range(nb)], float)
    per = np.where(n > 0, cost / np.maximum(n, 1), np.nan).reshape(nb, n_legs)
    sources = tuple(tuple(sorted({a.legs[i].wind_source for a in analyses})) for i in range(n_legs))
    return FleetGains(tables[0], tables[1], tuple(tops), angles, n, per, sources)


def _start_delay(a: TrackAnalysis) -> float:
    """Start crossing after the gun [s] (NaN: unknown)."""
    if not a.legs:
        return math.nan
    return float(a.legs[0].t_start - a.segmentation.start.gun_t)


def _axis(course: Course, i: int) -> tuple[tuple[float, float], tuple[float, float]]:
    """The leg's axis: the centre of its start (line or mark) to its target's centre [m]."""
    start, target = leg_endpoints(course, i)
    a = (
        start.a
        if start.b is None
        else (0.5 * (start.a[0] + start.b[0]), 0.5 * (start.a[1] + start.b[1]))
    )
    return (float(a[0]), float(a[1])), (float(target.centre[0]), float(target.centre[1]))


def _leg_points(a: TrackAnalysis, i: int) -> dict[str, NDArray[np.float64]] | None:
    """The points of leg ``i`` (None: unknown leg or fewer than 3 points)."""
    leg = a.legs[i]
    if not leg.known:
        return None
    p = a.points
    m = p.leg == i + 1
    if int(m.sum()) < 3:
        return None
    cols = ("t", "x", "y", "sog_ms", "cog_deg", "twa_deg", "tws_ms", "polar_ms")
    return {c: np.asarray(getattr(p, c)[m], float) for c in cols}


def _leg_measures(
    course: Course,
    analyses: Sequence[TrackAnalysis],
    speed: Speed,
    rank: NDArray[np.bool_],
    i: int,
) -> tuple[NDArray[np.float64], list[_Leg]]:
    """The fleet's angles on leg ``i`` (port, starboard) and every boat's measures."""
    a_xy, b_xy = _axis(course, i)
    axis_deg = math.degrees(math.atan2(b_xy[0] - a_xy[0], b_xy[1] - a_xy[1]))
    pts = [_leg_points(a, i) for a in analyses]
    straight = [
        None
        if p is None
        else ~manoeuvre_mask(p["t"], np.array([m.t for m in a.legs[i].manoeuvres]))
        for a, p in zip(analyses, pts, strict=True)
    ]
    # the fleet's speed curve: median SOG / polar per TWA bin, over the ranked boats, each
    # boat's points on a tack in the bin of its median angle on that tack (where f is read)
    nbins = math.ceil(180.0 / BIN_DEG)
    ratios: list[list[NDArray]] = [[] for _ in range(nbins)]
    owners: list[set[int]] = [set() for _ in range(nbins)]
    boat_angle: list[list[float]] = [[], []]
    for k, (p, s) in enumerate(zip(pts, straight, strict=True)):
        if p is None or s is None or not rank[k]:
            continue
        ok = s & np.isfinite(p["polar_ms"]) & (p["polar_ms"] > POLAR_MIN_MS)
        ab = np.abs(p["twa_deg"])
        for side, sign in enumerate((-1.0, 1.0)):
            on = s & (np.sign(p["twa_deg"]) == sign)
            if on.sum() < 3:
                continue
            boat_angle[side].append(float(np.median(ab[on])))
            sel = on & ok
            if sel.any():
                j = min(int(boat_angle[side][-1] / BIN_DEG), nbins - 1)
                ratios[j].append(p["sog_ms"][sel] / p["polar_ms"][sel])
                owners[j].add(k)
    n_ref = max(2, math.ceil(int(rank.sum()) / 3))
    everything = [r for rs in ratios for r in rs]
    g0 = float(np.median(np.concatenate(everything))) if everything else 1.0
    g = np.array(
        [
            float(np.median(np.concatenate(rs)))
            if len(who) >= n_ref and sum(r.size for r in rs) >= BIN_MIN_SAMPLES
            else g0
            for rs, who in zip(ratios, owners, strict=True)
        ]
    )
    ang = np.array([float(np.median(v)) if v else math.nan for v in boat_angle])
    ang = np.where(np.isfinite(ang), ang, np.nanmean(ang) if np.isfinite(ang).any() else 45.0)
    reach = analyses[0].legs[i].mode == "reach" if analyses else False

    def f(tws: NDArray, twa_abs: NDArray) -> NDArray:
        b = np.minimum((twa_abs / BIN_DEG).astype(int), nbins - 1)
        return g[b] * speed(tws, twa_abs)

    out = []
    for a, p, s in zip(analyses, pts, straight, strict=True):
        if p is None or s is None:
            out.append(_NAN_LEG)
            continue
        leg = a.legs[i]
        prog = axis_progress(p["x"], p["y"], a_xy, b_xy)
        cost, _ = manoeuvre_cost(p["t"], prog, np.array([m.t for m in leg.manoeuvres]))
        dist = float(prog[-1] - prog[0])
        rate = dist / (leg.sailed_time_s - cost) if leg.sailed_time_s > cost else math.nan
        theta = p["twa_deg"]
        sigma = np.where(theta >= 0, 1.0, -1.0)
        tack = (sigma > 0).astype(int)
        # the boat's own angle per tack over the leg, and the fleet's
        own = np.array(
            [
                float(np.median(np.abs(theta[s & (tack == j)])))
                if (s & (tack == j)).sum() >= 3
                else ang[j]
                for j in (0, 1)
            ]
        )
        course_off = np.radians(wrap180(p["cog_deg"] - axis_deg))
        fk = f(p["tws_ms"], own[tack])
        f_ref = f(p["tws_ms"], ang[tack])
        ok = s & np.isfinite(fk) & np.isfinite(f_ref) & np.isfinite(course_off)
        p1 = time_mean(p["t"], fk * np.cos(course_off), ok)
        if reach:
            w = time_mean(p["t"], fk, ok)
        else:
            at_fleet = course_off + sigma * np.radians(own[tack] - ang[tack])
            w = time_mean(p["t"], f_ref * np.cos(at_fleet), ok)
        out.append(
            _Leg(
                float(leg.sailed_time_s),
                dist,
                cost,
                len(leg.manoeuvres),
                rate,
                p1 if p1 > 0 else math.nan,
                w if w > 0 else math.nan,
            )
        )
    return ang, out


def _stat(v: NDArray[np.float64], reference: str) -> float:
    """Median (``"median"``) or mean (``"top3"``) of the finite values (NaN: none)."""
    v = v[np.isfinite(v)]
    if not v.size:
        return math.nan
    return float(np.median(v)) if reference == "median" else float(np.mean(v))


def _members(t: NDArray[np.float64], rank: NDArray[np.bool_], reference: str) -> NDArray[np.bool_]:
    """The boats of the reference: ranked with a known value; the top three for ``top3``."""
    ok = np.isfinite(t) & rank
    if reference == "median":
        return ok
    idx = np.flatnonzero(ok)
    m = np.zeros(t.size, bool)
    m[idx[np.argsort(t[idx], kind="stable")][:TOP]] = True
    return m


def _table(
    reference: str,
    analyses: Sequence[TrackAnalysis],
    legs: Sequence[Sequence[_Leg]],
    delay: NDArray[np.float64],
    rank: NDArray[np.bool_],
) -> GainTable:
    """The :class:`GainTable` against ``reference``."""
    nb = len(analyses)
    n_legs = len(legs[0]) if legs else 0
    total = np.full((nb, n_legs), np.nan)
    parts = np.full((nb, n_legs, len(PARTS)), np.nan)
    ref_t = np.full(n_legs, np.nan)
    d0 = _stat(delay[_members(delay, rank, reference)], reference)
    for i in range(n_legs):
        col = [legs[k][i] for k in range(nb)]
        t = np.array([c.time_s for c in col])
        m = _members(t, rank, reference)
        if not m.any():
            continue

        def ref(name: str, col: list[_Leg] = col, sel: NDArray[np.bool_] = m) -> float:
            return _stat(np.array([getattr(c, name) for c in col], float)[sel], reference)

        n_arr = np.array([c.n for c in col], float)
        per = np.array([c.cost_s / c.n if c.n else math.nan for c in col])
        c_ref = _stat(n_arr[m], reference) * (
            _stat(per[m], reference) if np.isfinite(per[m]).any() else 0.0
        )
        t_ref = ref("time_s")
        ref_t[i] = t_ref
        p1_ref, p2_ref = ref("p1"), ref("p2")
        rate_ref = ref("dist_m") / (t_ref - c_ref)
        for k, c in enumerate(col):
            if not np.isfinite(c.time_s):
                continue
            total[k, i] = t_ref - c.time_s
            man = c_ref - c.cost_s
            lm = log_mean(t_ref - c_ref, c.time_s - c.cost_s)
            speed = lm * math.log((c.rate / c.p1) / (rate_ref / p1_ref))
            height = lm * math.log((c.p1 / c.p2) / (p1_ref / p2_ref))
            side = lm * math.log(c.p2 / p2_ref)
            vals = (speed, height, side)
            if not all(np.isfinite(vals)):
                speed = height = side = 0.0
            other = total[k, i] - man - speed - height - side
            parts[k, i] = (speed, height, side, man, other)
    return GainTable(
        reference,
        tuple(a.track.name for a in analyses),
        tuple(analyses[0].legs[i].label for i in range(n_legs)) if analyses else (),
        d0 - delay,
        total,
        parts,
        ref_t,
        d0,
    )
