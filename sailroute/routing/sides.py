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
from typing import Final

import numpy as np

from sailroute.boat.model import BoatModel
from sailroute.errors import SailrouteError
from sailroute.units import wind_speed_direction, wrap180
from sailroute.wind.base import WindField

__all__ = ["TIE", "layline_times", "side_verdict"]

TIE: Final = "tie"
"""The verdict when neither side beats the other by more than the margin."""


def _sail_extreme(
    start: tuple[float, float],
    target: tuple[float, float],
    t0: float,
    wind: WindField,
    boat: BoatModel,
    first: int,
    *,
    tack_penalty_s: float,
    gybe_penalty_s: float,
    dt_s: float,
    max_time_s: float,
) -> float:
    """Time [s] of the extreme path that goes first to the side ``first`` (+1 left, -1 right)."""
    x, y = float(start[0]), float(start[1])
    t = t0
    tack = 0  # +1 / -1: the side the wind comes over (sign of the TWA); 0: not yet
    vmg: dict[float, tuple[float, float]] = {}  # best-VMG angles per TWS (0.01 m/s bins)
    reached = False  # reached the first layline
    while t - t0 < max_time_s:
        dx, dy = target[0] - x, target[1] - y
        dist = math.hypot(dx, dy)
        u, v = wind.sample(t, x, y)
        tws_a, twd_a = wind_speed_direction(u, v)
        tws, twd = float(tws_a), float(twd_a)
        bearing = math.degrees(math.atan2(dx, dy))
        off = float(wrap180(bearing - twd))  # TWA of the bearing, signed
        key = round(tws, 2)
        if key not in vmg:
            vmg[key] = boat.vmg_angles_deg(key)
        beat, run = vmg[key]
        if dist < 1e-6:
            return t - t0
        if abs(off) < beat or abs(off) > run:
            upwind = abs(off) < beat
            angle = beat if upwind else run
            # the two tacks' headings; the one on the side to go (left of the bearing:
            # counter-clockwise from it) until the layline, then the other one
            cand = [twd + angle, twd - angle]
            lefts = [float(wrap180(h - bearing)) < 0 for h in cand]
            want_left = (first > 0) != reached
            heading = next(
                (h for h, lf in zip(cand, lefts, strict=True) if lf == want_left), cand[0]
            )
        else:
            reached = True
            upwind = abs(off) < 90.0
            heading = bearing
        twa = float(wrap180(heading - twd))
        side = 1 if twa > 0 else -1
        if tack and side != tack:
            t += tack_penalty_s if upwind else gybe_penalty_s
        tack = side
        speed = float(boat.steady_speed(tws, abs(twa)))
        if not speed > 0:
            return math.inf
        step = speed * dt_s
        if heading == bearing and dist <= step:
            return t + dist / speed - t0
        h = math.radians(heading)
        nx, ny = x + step * math.sin(h), y + step * math.cos(h)
        x, y = nx, ny
        t += dt_s
    return math.inf


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
        straight line's time.
    """
    out = []
    for first in (1, -1):
        try:
            out.append(
                _sail_extreme(
                    start,
                    target,
                    t0,
                    wind,
                    boat,
                    first,
                    tack_penalty_s=tack_penalty_s,
                    gybe_penalty_s=gybe_penalty_s,
                    dt_s=dt_s,
                    max_time_s=max_time_s,
                )
            )
        except SailrouteError:  # the extreme leaves the wind data: no verdict from it
            out.append(math.inf)
    return out[0], out[1]


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
