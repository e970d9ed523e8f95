"""Which side of a leg pays: the two layline extremes, sailed in the wind, and a verdict.

On a beat or a run in a steady, uniform wind every path inside the laylines takes the
same time, so a router's route that happens to go right does not mean the right side
pays.  :func:`layline_times` sails the two extreme paths of a leg: all the way to one
layline on the tack that goes left (or right) of the mark, then to the mark; each step
it reads the wind where and when the boat is (so a persistent shift favours one
side), sails the polar's best-VMG angle while the mark cannot be fetched, steers
straight at it once it can, and pays the tack or gybe penalty at every change of tack.
:func:`side_verdict` counts the route's side only when the route beats the other side's
extreme by more than a margin, ``max(margin_s, margin_pct % of the route's time)``;
otherwise the leg is a ``"tie"``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, Final

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.boat.model import BoatModel
from sailroute.boat.polar import Polar
from sailroute.errors import SailrouteError
from sailroute.numerics import distinct_objects
from sailroute.units import wind_speed_direction, wrap180
from sailroute.wind.base import WindField
from sailroute.wind.perturbed import PerturbedWind, sample_perturbed

__all__ = ["TIE", "extreme_times", "layline_times", "side_verdict"]

TIE: Final = "tie"
"""The verdict when neither side beats the other by more than the margin."""


class _Extremes:
    """The state of extreme paths sailed in lockstep (:func:`extreme_times`)."""

    def __init__(self, start: NDArray, target: NDArray, t0: NDArray, first: NDArray) -> None:
        self.x, self.y = start[:, 0].copy(), start[:, 1].copy()
        self.tx, self.ty = target[:, 0], target[:, 1]
        self.t0 = t0
        self.t = t0.copy()
        self.first = first  # +1: to the left first, -1: to the right
        self.tack = np.zeros(t0.shape[0], dtype=np.int64)  # side the wind comes over; 0: none yet
        self.reached = np.zeros(t0.shape[0], dtype=bool)  # reached the first layline
        self.time = np.full(t0.shape[0], math.inf)  # the result [s]
        self.active = np.ones(t0.shape[0], dtype=bool)

    def finish(self, k: NDArray, time: Any) -> None:
        """Paths ``k`` end with ``time`` [s] (``inf``: cannot be sailed)."""
        self.time[k] = time
        self.active[k] = False


class _Groups:
    """The paths grouped once: by the wind their winds perturb (each group's different
    winds, ``members``, and each path's index among them, ``which``) and by boat."""

    def __init__(self, winds: Sequence[WindField], boats: Sequence[BoatModel]) -> None:
        bases = [w.base if isinstance(w, PerturbedWind) else w for w in winds]
        distinct_bases, self.wind_group = distinct_objects(bases)
        self.members: list[list[WindField]] = []
        self.which = np.empty(len(winds), dtype=np.int64)
        for g in range(len(distinct_bases)):
            paths = np.flatnonzero(self.wind_group == g)
            members, self.which[paths] = distinct_objects([winds[k] for k in paths.tolist()])
            self.members.append(members)
        self.boats, self.boat = distinct_objects(boats)


def _sample(
    winds: Sequence[WindField], act: NDArray, state: _Extremes, groups: _Groups
) -> tuple[NDArray, NDArray, NDArray]:
    """The wind ``(u, v)`` at the active paths ``act`` (one call per wind the others
    perturb, :func:`~sailroute.wind.perturbed.sample_perturbed`), and which of them
    could be sampled (a path that leaves the wind data gives no time)."""
    u, v = np.full(act.shape[0], np.nan), np.full(act.shape[0], np.nan)
    ok = np.ones(act.shape[0], dtype=bool)
    t, x, y = state.t[act], state.x[act], state.y[act]
    group = groups.wind_group[act]
    for j, members in enumerate(groups.members):
        idx = np.flatnonzero(group == j)
        if idx.shape[0] == 0:
            continue
        which = groups.which[act[idx]]
        try:
            u[idx], v[idx] = sample_perturbed(members, which, t[idx], x[idx], y[idx])
        except SailrouteError:  # one by one: only the paths out of the data stop
            for i in idx:
                try:
                    uu, vv = winds[act[i]].sample(t[i], x[i], y[i])
                    u[i], v[i] = float(uu), float(vv)
                except SailrouteError:
                    ok[i] = False
    return u, v, ok


class _VmgAngles:
    """Best-VMG angles of the boats at TWS rounded to 0.01 m/s, computed once per value."""

    def __init__(self) -> None:
        self._known: dict[tuple[int, float], tuple[float, float]] = {}

    def __call__(
        self, boats: Sequence[BoatModel], act: NDArray, tws_ms: NDArray
    ) -> tuple[NDArray, NDArray]:
        """Upwind and downwind best-VMG |TWA| [°] of the paths ``act`` at their TWS."""
        key = np.array([round(v, 2) for v in tws_ms.tolist()])
        missing: dict[int, tuple[BoatModel, set[float]]] = {}  # per boat
        for k, tws in zip(act.tolist(), key.tolist(), strict=True):
            if (id(boats[k]), tws) not in self._known:
                missing.setdefault(id(boats[k]), (boats[k], set()))[1].add(tws)
        for boat, values in missing.values():
            new = sorted(values)
            if isinstance(boat, Polar):  # all the values in one vectorised search
                beat = boat.vmg_upwind(np.asarray(new))[0].tolist()
                run = boat.vmg_downwind(np.asarray(new))[0].tolist()
                for tws, b, r in zip(new, beat, run, strict=True):
                    self._known[(id(boat), tws)] = (float(b), float(r))
            else:
                for tws in new:
                    self._known[(id(boat), tws)] = boat.vmg_angles_deg(tws)
        pairs = [
            self._known[(id(boats[k]), tws)]
            for k, tws in zip(act.tolist(), key.tolist(), strict=True)
        ]
        angles = np.array(pairs, dtype=float).reshape(-1, 2)
        return angles[:, 0], angles[:, 1]


def _speeds(groups: _Groups, act: NDArray, tws: NDArray, twa: NDArray) -> NDArray:
    """Steady speeds of the active paths' boats, one call per boat."""
    out = np.empty(act.shape[0])
    boat = groups.boat[act]
    for j, b in enumerate(groups.boats):
        idx = np.flatnonzero(boat == j)
        if idx.shape[0]:
            out[idx] = b.steady_speed(tws[idx], twa[idx])
    return out


def extreme_times(
    start: ArrayLike,
    target: ArrayLike,
    t0: ArrayLike,
    winds: Sequence[WindField],
    boats: Sequence[BoatModel],
    first: ArrayLike,
    *,
    tack_penalty_s: float = 0.0,
    gybe_penalty_s: float = 0.0,
    dt_s: float = 2.0,
    max_time_s: ArrayLike = 7200.0,
) -> NDArray[np.float64]:
    """Times [s] of extreme paths (see :func:`layline_times`), sailed in lockstep.

    Path ``k`` goes from ``start[k]`` to ``target[k]`` (shape (K, 2), [m]) from time
    ``t0[k]`` [epoch s] in ``winds[k]`` with ``boats[k]``, first to the left of the mark
    (``first[k] = 1``) or to the right (-1); ``max_time_s`` one or per path.  All paths
    take their steps together, so the winds are sampled once per step (one call per
    wind that the others perturb: the members of a band) and the boats' speeds looked up
    once per boat; a path out of its wind data, without speed or too long gets ``inf``.
    """
    st = _Extremes(
        np.asarray(start, dtype=float).reshape(-1, 2),
        np.asarray(target, dtype=float).reshape(-1, 2),
        np.asarray(t0, dtype=float).reshape(-1),
        np.asarray(first, dtype=np.int64).reshape(-1),
    )
    limit = np.broadcast_to(np.asarray(max_time_s, dtype=float), st.t.shape)
    vmg = _VmgAngles()
    groups = _Groups(winds, boats)
    while st.active.any():
        st.finish(np.flatnonzero(st.active & (st.t - st.t0 >= limit)), math.inf)
        act = np.flatnonzero(st.active)
        if act.shape[0] == 0:
            break
        u, v, ok = _sample(winds, act, st, groups)
        st.finish(act[~ok], math.inf)
        act, u, v = act[ok], u[ok], v[ok]
        _extreme_step(st, act, u, v, vmg, boats, groups, tack_penalty_s, gybe_penalty_s, dt_s)
    return st.time


def _extreme_step(
    st: _Extremes,
    act: NDArray,
    u: NDArray,
    v: NDArray,
    vmg: _VmgAngles,
    boats: Sequence[BoatModel],
    groups: _Groups,
    tack_penalty_s: float,
    gybe_penalty_s: float,
    dt_s: float,
) -> None:
    """One step of the active paths ``act`` in the wind ``(u, v)`` sampled there."""
    dx, dy = st.tx[act] - st.x[act], st.ty[act] - st.y[act]
    dist = np.hypot(dx, dy)
    tws, twd = wind_speed_direction(u, v)
    bearing = np.degrees(np.arctan2(dx, dy))
    off = np.abs(wrap180(bearing - twd))  # |TWA| of the bearing
    beat, run = vmg(boats, act, tws)
    there = dist < 1e-6
    st.finish(act[there], st.t[act[there]] - st.t0[act[there]])
    outside = (off < beat) | (off > run)  # the mark cannot be fetched
    upwind = np.where(outside, off < beat, off < 90.0)
    angle = np.where(off < beat, beat, run)
    # the two tacks' headings; the one on the side to go (left of the bearing:
    # counter-clockwise from it) until the layline, then the other one
    want_left = (st.first[act] > 0) != st.reached[act]
    one, two = twd + angle, twd - angle
    pick_two = (wrap180(one - bearing) < 0) != want_left
    pick_two &= (wrap180(two - bearing) < 0) == want_left
    heading = np.where(outside, np.where(pick_two, two, one), bearing)
    st.reached[act[~outside]] = True
    twa = wrap180(heading - twd)
    side = np.where(twa > 0, 1, -1)
    turned = (st.tack[act] != 0) & (side != st.tack[act])
    t = st.t[act] + np.where(turned, np.where(upwind, tack_penalty_s, gybe_penalty_s), 0.0)
    st.tack[act] = side
    speed = _speeds(groups, act, tws, np.abs(twa))
    step = speed * dt_s
    stop = ~(speed > 0)
    arrive = ~stop & (heading == bearing) & (dist <= step) & ~there
    st.finish(act[stop & ~there], math.inf)
    safe = np.where(arrive, speed, 1.0)
    st.finish(act[arrive], t[arrive] + dist[arrive] / safe[arrive] - st.t0[act[arrive]])
    go = ~(stop | arrive | there)
    h = np.radians(heading[go])
    k = act[go]
    st.x[k] = st.x[k] + step[go] * np.sin(h)
    st.y[k] = st.y[k] + step[go] * np.cos(h)
    st.t[k] = t[go] + dt_s


def layline_times(
    start: tuple[float, float],
    target: tuple[float, float],
    t0: float,
    wind: WindField,
    boat: BoatModel,
    *,
    tack_penalty_s: float = 0.0,
    gybe_penalty_s: float = 0.0,
    dt_s: float = 2.0,
    max_time_s: float = 7200.0,
) -> tuple[float, float]:
    """Times of a leg's left and right extremes (layline to layline), sailed in ``wind``.

    Each step (``dt_s``) a path reads the wind where and when the boat is, sails the
    boat's best-VMG angle on the tack that goes towards its side while the mark cannot
    be fetched (to the layline, then the other tack), steers straight at the mark once
    it can, and pays the tack or gybe penalty at every change of tack.

    Parameters
    ----------
    start, target : tuple of float
        Leg start and end ``(x, y)`` [m] (a route's ``start_xy`` and ``end_xy``).
    t0 : float
        Start time [epoch s].
    wind : WindField
        Wind (time-varying wind favours one side).
    boat : BoatModel
        Boat: its best-VMG angles and steady speeds.
    tack_penalty_s, gybe_penalty_s : float
        Time lost per tack / gybe [s].
    dt_s : float
        Time step [s].
    max_time_s : float
        Give up after this long [s] (the time is then ``inf``).

    Returns
    -------
    t_left, t_right : float
        Leg times [s] going first to the left / right of the mark (looking from the
        start); ``inf`` where the path cannot be sailed (no speed, out of the wind
        data, too long).  On a reach (the mark fetchable from the start) both are the
        straight line's time.  :func:`extreme_times` sails many at once.
    """
    times = extreme_times(
        [start, start],
        [target, target],
        [t0, t0],
        [wind, wind],
        [boat, boat],
        [1, -1],
        tack_penalty_s=tack_penalty_s,
        gybe_penalty_s=gybe_penalty_s,
        dt_s=dt_s,
        max_time_s=max_time_s,
    )
    return float(times[0]), float(times[1])


def side_verdict(
    side: str,
    t_route: float,
    t_left: float,
    t_right: float,
    *,
    margin_s: float = 2.0,
    margin_pct: float = 0.5,
) -> str:
    """The side a route took, if it beat the other side by more than the margin, else ``"tie"``.

    Parameters
    ----------
    side : {"left", "middle", "right"}
        The side the route took (its mean offset from the rhumb line).
    t_route : float
        The route's leg time [s].
    t_left, t_right : float
        The extremes' times [s] (:func:`layline_times`).
    margin_s, margin_pct : float
        The margin: ``max(margin_s, margin_pct / 100 * t_route)`` [s].

    Returns
    -------
    str
        ``side`` when the alternative (the other side's extreme; for ``middle`` the
        faster extreme) is slower than the route by more than the margin;
        ``"tie"`` when it is not; ``side`` unchanged when the alternative could not be
        sailed (``inf``: no evidence either way).
    """
    alt = {"left": t_right, "right": t_left}.get(side, min(t_left, t_right))
    if not np.isfinite(alt):
        return side
    margin = max(margin_s, margin_pct / 100.0 * t_route)
    return side if alt - t_route > margin else TIE
