"""Build :class:`~sailroute.routing.types.RouteTrack` and :class:`LegResult` from a polyline.

Every router ends with a time-stamped polyline; this module turns it into the
common output (wind and angles at each point, tack side, manoeuvre counts), so
that all routers report the same quantities computed the same way.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.boat.polar import Polar
from sailroute.routing.types import Barrier, LegResult, Manoeuvre, RouteTrack
from sailroute.units import bearing_deg, signed_twa, wind_speed_direction
from sailroute.wind.base import WindField


def segment_headings(x: NDArray, y: NDArray) -> NDArray[np.float64]:
    """Heading [°] of each vertex: bearing to the next vertex (last repeats the previous).

    Zero-length segments (a boat stopped for a tack) inherit the next non-zero
    heading, so that a stop does not create a spurious heading.
    """
    n = x.size
    if n < 2:
        return np.zeros(n)
    dx = np.diff(x)
    dy = np.diff(y)
    h = bearing_deg(dx, dy)
    moving = np.hypot(dx, dy) > 1e-9
    if not moving.any():
        return np.zeros(n)
    # back-fill stationary segments from the next moving one, then forward-fill the tail
    idx = np.where(moving, np.arange(n - 1), n)
    nxt = np.minimum.accumulate(idx[::-1])[::-1]
    last_moving = np.flatnonzero(moving)[-1]
    nxt = np.where(nxt >= n, last_moving, nxt)
    h = h[nxt]
    return np.concatenate([h, h[-1:]])


def build_track(
    t: ArrayLike,
    x: ArrayLike,
    y: ArrayLike,
    wind: WindField,
    polar: Polar | None = None,
    *,
    heading_deg: ArrayLike | None = None,
    bsp_ms: ArrayLike | None = None,
    side: ArrayLike | None = None,
) -> RouteTrack:
    """Sample wind along a time-stamped polyline and assemble a :class:`RouteTrack`.

    Parameters
    ----------
    t, x, y : array_like, shape (n,)
        Vertex times [epoch s] and positions [m].
    wind : WindField
        Wind used for TWS/TWD at each vertex.
    polar : Polar, optional
        Gives boat speed when ``bsp_ms`` is not passed.
    heading_deg : array_like, optional
        Heading sailed from each vertex [°]; default: bearing to the next vertex.
    bsp_ms : array_like, optional
        Boat speed at each vertex [m s⁻¹]; default: polar speed at the vertex.
    side : array_like, optional
        Tack side (+1 starboard, −1 port); default: sign of the signed TWA
        (TWA = 0 counts as starboard).

    Returns
    -------
    RouteTrack
    """
    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    h = segment_headings(x, y) if heading_deg is None else np.asarray(heading_deg, float)
    u, v = wind.sample(t, x, y)
    tws, twd = wind_speed_direction(u, v)
    twa = signed_twa(twd, h)
    if bsp_ms is None:
        if polar is None:
            raise ValueError("build_track needs either polar or bsp_ms")
        bsp = polar.speed(tws, twa)
    else:
        bsp = np.asarray(bsp_ms, dtype=float)
    sd = np.where(twa >= 0, 1, -1) if side is None else np.asarray(side)
    return RouteTrack(
        t=t,
        x=x,
        y=y,
        heading_deg=h,
        tws_ms=tws,
        twd_deg=twd,
        twa_deg=twa,
        bsp_ms=bsp,
        side=sd.astype(np.int8),
    )


def find_manoeuvres(track: RouteTrack) -> tuple[Manoeuvre, ...]:
    """Tacks and gybes along a track: every change of ``side`` between vertices.

    A change is a tack when the mean |TWA| of the two vertices is below 90°,
    otherwise a gybe.  It is located at the first vertex on the new side.
    """
    s = track.side
    if s.size < 2:
        return ()
    change = np.flatnonzero(s[1:] != s[:-1]) + 1
    out = []
    for i in change:
        mean_abs = 0.5 * (abs(track.twa_deg[i - 1]) + abs(track.twa_deg[i]))
        kind: Literal["tack", "gybe"] = "tack" if mean_abs < 90.0 else "gybe"
        out.append(Manoeuvre(kind, float(track.t[i]), float(track.x[i]), float(track.y[i])))
    return tuple(out)


def make_leg_result(track: RouteTrack, router: str, barrier: Barrier | None = None) -> LegResult:
    """Assemble the :class:`LegResult` of a finished track (first/last rows = start/arrival).

    ``barrier`` is the rounding ray the leg ended on, handed on to the next leg
    (:func:`~sailroute.routing.geometry.target_barrier`).
    """
    man = find_manoeuvres(track)
    return LegResult(
        t_start=float(track.t[0]),
        t_end=float(track.t[-1]),
        start_xy=(float(track.x[0]), float(track.y[0])),
        end_xy=(float(track.x[-1]), float(track.y[-1])),
        distance_m=track.distance_m,
        n_tacks=sum(m.kind == "tack" for m in man),
        n_gybes=sum(m.kind == "gybe" for m in man),
        manoeuvres=man,
        track=track,
        router=router,
        barrier=barrier,
    )
