"""Estimated time to go of the isochrone kernel: what ranks the candidate moves.

:func:`_time_to_go` is ``τ``, the time from a point to its aim point on the target
segment (straight, or two boards at the VMG angles inside the VMG cone, plus the
manoeuvre the point still needs), with its gradient ``G``; a move ``v`` over ``dt`` then
scores ``τ - dt G·v``.  :func:`_time_to_go_current` solves the same time in a surface
current, and :func:`_fastest_aim` picks, per side, the aim point on the segment that the
local wind reaches soonest.  The method and its accuracy: ``docs/design/routing.md``.

Used by the step inputs (:func:`~sailroute.routing.isochrone_inputs._prepare`, which
computes ``τ`` and ``G`` of both sides of every front point); the candidate kernel
(:mod:`~sailroute.routing.isochrone_kernel`) scores the moves with them, and the driver
(:mod:`sailroute.routing.isochrone`) takes :data:`_BIG_S`, the time to go of a calm.
"""

from __future__ import annotations

import math
from types import ModuleType
from typing import Any

import numpy as np

from sailroute.numerics import clip
from sailroute.routing.geometry import AIM_MARGIN_M, TargetGeometry, segment_frame
from sailroute.routing.isochrone_polar import _DeviceTables, _support
from sailroute.routing.isochrone_records import _Context, _PointWind

_BIG_S = 1e12  # time-to-go standing in for "unknown" (calm) [s]


def _time_to_go(
    wind: _PointWind,
    ex: Any,
    ey: Any,
    dist: Any,
    sides: Any,
    free: Any,
    tack_s: float,
    gybe_s: float,
    dev: _DeviceTables,
    xp: ModuleType,
) -> tuple[Any, Any, Any]:
    """Time to go over ``dist`` [m] along the unit vector ``(ex, ey)``, and its gradient.

    Two ways to get there, the faster counts:

    * straight, at ``S(beta)`` (``beta``: angle between the way and the upwind unit
      vector ``ŵ``), plus a tack or gybe if the way lies on the other side of the
      wind than the point's side (``sides``);
    * inside the upwind (downwind) VMG cone, two boards at the VMG angles,
      ``v·ŵ / VMG_up`` (``-v·ŵ / VMG_dn``), plus one tack (gybe).

    Points with no side yet (``free``) pay no penalty; then this is the time on the
    convex VMG hull of the polar.  The gradient ``G`` (``tau = v·G + penalty``) gives the
    change of ``tau`` for a small move ``d``: ``tau(P + d) ≈ tau(P) - d·G``.  Speeds come
    from the polar tables (this only ranks candidates).  Calm: ``tau`` is huge and
    ``G = 0``.  ``sides`` and the way may have a leading axis (2, n) over the wind's (n,).

    Returns ``tau`` [s] and ``G`` [s m⁻¹] (x and y).
    """
    up_x, up_y, node, weight = wind.up_x, wind.up_y, wind.row, wind.weight
    cos_b = clip(up_y * ey + up_x * ex, -1.0, 1.0, xp=xp)
    sin_b = up_x * ey - up_y * ex
    beta_deg = xp.degrees(xp.arccos(cos_b))
    vmg_up = dev.up_vmg_ms[node] + weight * (dev.up_vmg_ms[node + 1] - dev.up_vmg_ms[node])
    vmg_dn = dev.down_vmg_ms[node] + weight * (dev.down_vmg_ms[node + 1] - dev.down_vmg_ms[node])
    # polar speed and slope dS/dbeta at the direct angle, from the grid table
    na = dev.twa_deg.shape[0]
    step = 180.0 / na
    pos = beta_deg * (1.0 / step) - 1.0
    col = clip(xp.floor(pos).astype(xp.int64), 0, na - 2, xp=xp)
    frac = clip(pos - col, 0.0, 1.0, xp=xp)
    sp = dev.speed_ms
    s_l = sp[node, col] + weight * (sp[node + 1, col] - sp[node, col])
    s_r = sp[node, col + 1] + weight * (sp[node + 1, col + 1] - sp[node, col + 1])
    spd = s_l + frac * (s_r - s_l)
    slope = (s_r - s_l) * (1.0 / math.radians(step))
    cone_up = (beta_deg <= wind.up_deg) & (vmg_up > 0)
    cone_dn = (beta_deg >= wind.down_deg) & (vmg_dn > 0) & ~cone_up
    cone = cone_up | cone_dn
    inv_s = 1.0 / xp.where(spd > 0, spd, 1.0)
    inv_v = xp.where(
        cone_up, 1.0 / xp.where(cone_up, vmg_up, 1.0), -1.0 / xp.where(cone_dn, vmg_dn, 1.0)
    )
    t_straight = xp.where(spd > 0, dist * inv_s, np.inf)
    t_cone = xp.where(cone, dist * cos_b * inv_v, np.inf)
    own = free | (sides * sin_b >= 0)
    paid = ~free
    t_straight = t_straight + xp.where(own | ~paid, 0.0, xp.where(beta_deg < 90.0, tack_s, gybe_s))
    t_cone = t_cone + xp.where(paid, xp.where(cone_up, tack_s, gybe_s), 0.0)
    use_cone = t_cone < t_straight
    tau = xp.minimum(t_cone, t_straight)
    sin_abs = xp.sqrt(xp.maximum(1.0 - cos_b * cos_b, 1e-18))
    k = slope * inv_s * inv_s / sin_abs
    along_up = xp.where(use_cone, inv_v, k)  # G = along_up ŵ + along_way e
    along_way = xp.where(use_cone, 0.0, inv_s - k * cos_b)
    ok = tau < np.inf
    tau = xp.where(dist > 0, xp.where(ok, tau, _BIG_S), 0.0)
    along_up = xp.where(ok, along_up, 0.0)
    along_way = xp.where(ok, along_way, 0.0)
    return tau, along_up * up_x + along_way * ex, along_up * up_y + along_way * ey


def _fastest_aim(
    x: Any,
    y: Any,
    ex: Any,
    ey: Any,
    dist: Any,
    side: Any,
    wind: _PointWind,
    g: TargetGeometry,
    dev: _DeviceTables,
    xp: ModuleType,
    cur: tuple[Any, Any] | None = None,
) -> tuple[Any, Any, Any]:
    """Aim points on the target segment that the local wind reaches soonest, per side.

    The heading that reaches the segment's line soonest maximises the speed component
    along the segment normal ``n`` (:func:`_support`).  For side ``σ = side`` (block
    ``_KEEP``) and side ``-σ`` (block ``_SWITCH``) that heading is taken on the side
    itself if it approaches the line at all, else on the other side.  Followed from
    ``P = (x, y)`` it meets the line at ``Q*``; the aim point is ``Q*`` kept
    ``AIM_MARGIN_M`` inside the segment.  Where no heading approaches the line, the
    projection of ``P`` (``ex, ey, dist`` passed in) is kept.  This makes the direct
    candidate the exact best heading to a line or gate in uniform wind.  In a current
    ``cur`` (leg frame) the same heading is fastest (the current adds the same normal
    speed to every heading) but its track over the ground, ``S·d + C``, meets the line
    elsewhere.

    Returns the unit vectors ``(ex, ey)`` to the aim points and their distances [m],
    each of shape (2, n): row 0 for side ``σ``, row 1 for side ``-σ``.
    """
    up_x, up_y = wind.up_x, wind.up_y
    nx, ny = g.normal
    p = up_x * nx + up_y * ny  # cos and sin of the angle from ŵ to n
    q = up_x * ny - up_y * nx
    sides = xp.stack([side, -side])
    best, ang = _support(wind.row, wind.weight, xp.degrees(xp.arctan2(sides * q, p)), dev, xp)
    use_own = best > 0  # else take the heading of the other side (needs a manoeuvre)
    sig = xp.where(use_own, sides, -sides)
    best = xp.where(use_own, best, best[::-1])
    rb = xp.radians(xp.where(use_own, ang, ang[::-1]))
    ca_b, sa_b = xp.cos(rb), xp.sin(rb)
    dx = up_x * ca_b - sig * up_y * sa_b  # heading unit vector on side sig
    dy = up_y * ca_b + sig * up_x * sa_b
    ax0, ay0 = g.a
    ahead = (ax0 - x) * nx + (ay0 - y) * ny  # distance to the segment's line along n
    dn = dx * nx + dy * ny
    ok = (best > 0) & (dn > 1e-9) & (ahead > 0)
    if cur is not None:  # ground track: speed S = best / dn along d, plus the current
        spd = best / xp.where(ok, dn, 1.0)
        dx, dy = spd * dx + cur[0], spd * dy + cur[1]
        dn = dx * nx + dy * ny
        ok = ok & (dn > 1e-9)
    t = xp.where(ok, ahead / xp.where(ok, dn, 1.0), 0.0)
    _, _, ux, uy, m, length = segment_frame(g, AIM_MARGIN_M)
    r = clip((x + t * dx - ax0) * ux + (y + t * dy - ay0) * uy, m, length - m, xp=xp)
    vx = ax0 + r * ux - x
    vy = ay0 + r * uy - y
    d2 = xp.sqrt(vx * vx + vy * vy)
    use = ok & (d2 > 0)
    inv = 1.0 / xp.where(use, d2, 1.0)
    return xp.where(use, vx * inv, ex), xp.where(use, vy * inv, ey), xp.where(use, d2, dist)


# --------------------------------------------------------------------------------------
# in a surface current

_TTG_ITERATIONS = 4
"""Newton iterations of the time to go in a current."""


def _time_to_go_current(
    tau: Any,
    gx: Any,
    gy: Any,
    wind: _PointWind,
    ex: Any,
    ey: Any,
    dist: Any,
    cx: Any,
    cy: Any,
    sides: Any,
    free: Any,
    ctx: _Context,
    dev: _DeviceTables,
    xp: ModuleType,
) -> tuple[Any, Any, Any]:
    """Time to go in a current ``C`` (averaged along the way, leg frame) and its gradient.

    In the water the target drifts by ``-C`` per second, so the time to go solves
    ``tau = T(D - C tau)`` with ``T`` the still-water :func:`_time_to_go` and ``D``
    the way over the ground (Newton iterations from the still-water ``tau``; a plain
    fixed-point step where ``1 + G·C`` is small).  The gradient is
    ``G / (1 + G·C)`` (implicit differentiation).
    """
    dx, dy = dist * ex, dist * ey
    for _ in range(_TTG_ITERATIONS):
        ok = tau < _BIG_S
        tt = xp.where(ok, tau, 0.0)
        wx, wy = dx - cx * tt, dy - cy * tt
        dw = xp.sqrt(wx * wx + wy * wy)
        pos = dw > 0
        inv = 1.0 / xp.where(pos, dw, 1.0)
        t_w, gx, gy = _time_to_go(
            wind,
            xp.where(pos, wx * inv, ex),
            xp.where(pos, wy * inv, ey),
            dw,
            sides,
            free,
            ctx.tack_s,
            ctx.gybe_s,
            dev,
            xp,
        )
        der = 1.0 + gx * cx + gy * cy
        newton = der > 0.25
        tau = xp.where(ok, tt - (tt - t_w) / xp.where(newton, der, 1.0), t_w)
        tau = xp.where(t_w >= _BIG_S, _BIG_S, xp.maximum(tau, 0.0))
    scale = 1.0 / xp.maximum(1.0 + gx * cx + gy * cy, 0.25)
    return tau, gx * scale, gy * scale
