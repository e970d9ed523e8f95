"""Compiled kernels of the isochrone step (optional: ``pip install 'sailroute[fast]'``).

The per-point and per-candidate loops of one isochrone step written out for `numba`_,
each the same arithmetic in the same order as the NumPy code it replaces, so that a
route is the same bit for bit on either path (``tests/routing/test_isochrone_jit.py``
compares them).  The functions that are not exactly rounded (``arctan2``, ``arccos``,
``sin``, ``cos``) stay NumPy calls between the kernels, on the same arrays as the NumPy
path: numba's ``libm`` and NumPy's SIMD loops differ in the last bit of one result in
ten.  The driver is :mod:`sailroute.routing.isochrone_fast`; the kernels, in the order
of a step:

- :func:`sample_points`: the aim points, the direction to them and the points where the
  wind is sampled (``isochrone_inputs._sample_step``);
- :func:`wind_states`: the wind of the move and the wind along the way
  (``_wind_state``), the manoeuvre bookkeeping (``_manoeuvre_state``) and the arguments
  of the bearing of the polar support (``isochrone_togo._fastest_aim``);
- :func:`support_headings`: the polar support towards the target line
  (``isochrone_polar._support``) and the side it is sailed on;
- :func:`aim_directions`: the fastest aim points (``_fastest_aim``) and the cosines of
  the direct headings and of the ways to the aim points;
- :func:`dense_speeds`: :meth:`Polar.speed <sailroute.boat.polar.Polar.speed>` of a PCHIP
  polar (its dense table, bilinear);
- :func:`step_inputs`: the exact columns (``_exact_columns``), the time to go
  (``isochrone_togo._time_to_go``), the reach of the moves and the points within reach
  of the target, a barrier or the coverage box (``_within_reach``, ``_box_holds``);
- :func:`candidates`: every candidate move of a run of rows: speed, velocity, penalty
  timing, end point, score and what forbids it (``isochrone_kernel._expand``), and the
  earliest crossing of the target by the rows within reach of it (``_arrival``,
  :func:`_arrival_row`); :func:`sector_winners` then keeps the best candidate per sector
  and side from the bearings NumPy computed in float32 (``_sector_winners``);
- :func:`survivors`: the new front from the winners (``_winner_columns``,
  ``_survivors``).

Without numba, :data:`AVAILABLE` is False and the router runs its NumPy path.

.. _numba: https://numba.pydata.org
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from sailroute.jit import AVAILABLE as AVAILABLE  # re-exported: numba is installed
from sailroute.jit import inline as _inline
from sailroute.jit import jit as _jit

_BIG_S = 1e12  # isochrone_togo._BIG_S (a calm's time to go [s])
_CALM_MS = 1e-9  # isochrone_inputs._CALM_MS

# --------------------------------------------------------------------------------------
# elementwise helpers: NumPy's semantics, NaN included


@_jit
def _mn(a: Any, b: Any) -> Any:
    """``np.minimum(a, b)`` (a NaN wins)."""
    return a if (a <= b or a != a) else b


@_jit
def _mx(a: Any, b: Any) -> Any:
    """``np.maximum(a, b)`` (a NaN wins)."""
    return a if (a >= b or a != a) else b


@_jit
def _each(a: Any, i: int) -> Any:
    """Point ``i``'s value of ``a``, which holds one value for all points or one per
    point (a front's time, a step's length)."""
    return a[i] if a.shape[0] > 1 else a[0]


@_jit
def _clip(x: Any, lo: Any, hi: Any) -> Any:
    """``sailroute.numerics.clip``: ``minimum(maximum(x, lo), hi)``."""
    return _mn(_mx(x, lo), hi)


@_jit
def _floor_index(x: float) -> int:
    """``np.floor(x).astype(np.int64)``, NaN as NumPy on x86 (the smallest int64)."""
    if x != x:
        return -9223372036854775808
    return int(math.floor(x))  # noqa: RUF046 (numba: math.floor gives a float)


@_jit
def _search_right(nodes: Any, v: float) -> int:
    """``np.searchsorted(nodes, v, side="right")`` (NaN after every node)."""
    if v != v:
        return nodes.shape[0]
    lo, hi = 0, nodes.shape[0]
    while lo < hi:
        mid = (lo + hi) >> 1
        if nodes[mid] <= v:
            lo = mid + 1
        else:
            hi = mid
    return lo


@_jit
def _to_leg(vx: float, vy: float, fx: float, fy: float) -> tuple[float, float]:
    """``_LegFrame.vec_to_leg``."""
    return vx * fy - vy * fx, vx * fx + vy * fy


@_jit
def _segment_distance(x: float, y: float, seg: Any) -> float:
    """``isochrone_inputs._segment_distance`` with ``seg = (ax, ay, ex, ey, ll)``."""
    ax, ay, ex, ey, ll = seg[0], seg[1], seg[2], seg[3], seg[4]
    r = _clip(((x - ax) * ex + (y - ay) * ey) / ll, 0.0, 1.0)
    dx = x - (ax + r * ex)
    dy = y - (ay + r * ey)
    return math.sqrt(dx * dx + dy * dy)


# --------------------------------------------------------------------------------------
# the inputs of a step


@_jit
def sample_points(
    x: Any,
    y: Any,
    heading_sin: Any,
    heading_cos: Any,
    debt: Any,
    bsp: Any,
    tau_est: Any,
    t: Any,
    dt: Any,
    max_leg_s: float,
    aim: Any,
    frame: Any,
    cover: Any,
    out: Any,
    pt: Any,
    px: Any,
    py: Any,
) -> None:
    """Aim points, directions and the wind's sample points of a front.

    ``aim = (ax, ay, ux, uy, m, length)`` of the target segment
    (:func:`~sailroute.routing.geometry.segment_frame`); ``frame = (cx, cy, fx, fy)``;
    ``cover = (t0, t1, xmin, xmax, ymin, ymax)``; ``t`` the front's time and ``dt`` the
    step length [s], each one value or one per point.  Writes ``out`` (5, n): aim point x,
    y, unit direction x, y, distance;
    ``pt, px, py`` (5, n): the clipped sample times and world positions (row 0 mid-step,
    rows 1-4 along the way).
    """
    ax, ay, ux, uy, m, length = aim[0], aim[1], aim[2], aim[3], aim[4], aim[5]
    cx, cy, fx, fy = frame[0], frame[1], frame[2], frame[3]
    n = x.shape[0]
    for i in range(n):
        dt_i = _each(dt, i)
        xi, yi = x[i], y[i]
        r = _clip((xi - ax) * ux + (yi - ay) * uy, m, length - m)
        aim_x = ax + r * ux
        aim_y = ay + r * uy
        dx, dy = aim_x - xi, aim_y - yi
        dist = math.sqrt(dx * dx + dy * dy)
        there = dist > 0
        inv_d = 1.0 / (dist if there else 1.0)
        out[0, i] = aim_x
        out[1, i] = aim_y
        out[2, i] = dx * inv_d if there else 0.0
        out[3, i] = dy * inv_d if there else 1.0
        out[4, i] = dist
        t_mid = _each(t, i) + 0.5 * dt_i
        half = 0.0 if debt[i] > 0 else (0.5 * dt_i) * bsp[i]
        # no time to go yet: at isochrone_inputs._ROOT_SPEED_MS = 2 m/s
        horizon = dist * 0.5 if tau_est[i] != tau_est[i] else _mn(tau_est[i], max_leg_s)
        for k in range(5):
            if k == 0:
                lx = xi + half * heading_sin[i]
                ly = yi + half * heading_cos[i]
                tk = t_mid
            else:
                fk = (k - 0.5) / 4.0
                lx = xi + fk * (aim_x - xi)
                ly = yi + fk * (aim_y - yi)
                tk = t_mid + fk * horizon
            wx = cx + lx * fy + ly * fx
            wy = cy - lx * fx + ly * fy
            pt[k, i] = _clip(tk, cover[0], cover[1])
            px[k, i] = _clip(wx, cover[2], cover[3])
            py[k, i] = _clip(wy, cover[4], cover[5])


@_jit
def _wind_at(
    u: float,
    v: float,
    fx: float,
    fy: float,
    nodes: Any,
    start: int,
    count: int,
    up_tab: Any,
    down_tab: Any,
) -> tuple[float, float, float, int, float, float, float]:
    """``isochrone_inputs._wind_state`` of one wind vector, in the table rows
    ``start : start + count`` (its polar's, ``isochrone_polar.node_rows``)."""
    tws = math.sqrt(u * u + v * v)
    windy = tws > _CALM_MS
    inv = 1.0 / (tws if windy else 1.0)
    up_x, up_y = _to_leg(-u * inv if windy else 0.0, -v * inv if windy else 1.0, fx, fy)
    row = start + _clip(_search_right(nodes[start : start + count], tws) - 1, 0, count - 2)
    weight = _clip((tws - nodes[row]) / (nodes[row + 1] - nodes[row]), 0.0, 1.0)
    up = up_tab[row] + weight * (up_tab[row + 1] - up_tab[row])
    down = down_tab[row] + weight * (down_tab[row + 1] - down_tab[row])
    return tws, up_x, up_y, row, weight, up, down


@_jit
def wind_states(
    u: Any,
    v: Any,
    frame: Any,
    nodes: Any,
    node_range: Any,
    up_tab: Any,
    down_tab: Any,
    side_in: Any,
    pend_old: Any,
    abs_twa: Any,
    penalties: Any,
    normal: Any,
    move: Any,
    move_row: Any,
    mean: Any,
    mean_row: Any,
    man: Any,
    flags: Any,
    aim_y: Any,
    aim_x: Any,
    vmg_rad: Any,
) -> bool:
    """The winds, manoeuvres and support bearings of a front.

    ``u, v`` (5, n): the sampled wind; ``frame = (cx, cy, fx, fy)``; ``node_range``
    (2, n): each point's polar's first table row and its number of rows, or empty (one
    polar); ``penalties = (tack, gybe)`` [s]; ``normal`` of the target.  Writes per
    point: ``move`` and ``mean`` (6, n: TWS, up x, up y, weight, up and down VMG angle)
    with their table rows ``move_row``, ``mean_row`` (the wind of the move, and the
    wind averaged along the way); ``man`` (4, n: side, base |TWA|, penalty onto upwind
    and onto downwind), ``flags`` (2, n: free, pending); the arguments ``aim_y`` (2, n),
    ``aim_x`` (n,) of ``arctan2`` for the support bearing; ``vmg_rad`` (n, 2): the VMG
    angles [rad].
    Returns whether any point is pending.
    """
    fx, fy = frame[2], frame[3]
    tack, gybe = penalties[0], penalties[1]
    mixed = max(tack, gybe)
    nx, ny = normal[0], normal[1]
    to_rad = math.pi / 180.0
    any_pending = False
    own = node_range.shape[0] > 0
    for i in range(u.shape[1]):
        start = node_range[0, i] if own else 0
        count = node_range[1, i] if own else nodes.shape[0]
        tws, upx, upy, row, w, a_up, a_dn = _wind_at(
            u[0, i], v[0, i], fx, fy, nodes, start, count, up_tab, down_tab
        )
        move[0, i], move[1, i], move[2, i], move_row[i] = tws, upx, upy, row
        move[3, i], move[4, i], move[5, i] = w, a_up, a_dn
        um = ((((u[0, i] + u[1, i]) + u[2, i]) + u[3, i]) + u[4, i]) / 5.0
        vm = ((((v[0, i] + v[1, i]) + v[2, i]) + v[3, i]) + v[4, i]) / 5.0
        tws_m, mx_, my_, row_m, w_m, up_m, dn_m = _wind_at(
            um, vm, fx, fy, nodes, start, count, up_tab, down_tab
        )
        mean[0, i], mean[1, i], mean[2, i], mean_row[i] = tws_m, mx_, my_, row_m
        mean[3, i], mean[4, i], mean[5, i] = w_m, up_m, dn_m
        pending = pend_old[i] == pend_old[i]
        any_pending = any_pending or pending
        base = pend_old[i] if pending else abs_twa[i]
        unknown = base != base
        side = -1.0 if side_in[i] < 0 else 1.0
        man[0, i] = side
        man[1, i] = base
        man[2, i] = tack if (unknown or base < 90.0) else mixed
        man[3, i] = gybe if (unknown or base >= 90.0) else mixed
        flags[0, i] = side_in[i] == 0
        flags[1, i] = pending
        q = upx * ny - upy * nx
        aim_x[i] = upx * nx + upy * ny
        aim_y[0, i] = side * q
        aim_y[1, i] = -side * q
        vmg_rad[i, 0] = a_up * to_rad
        vmg_rad[i, 1] = a_dn * to_rad
    return any_pending


@_jit
def support_headings(
    row: Any,
    weight: Any,
    beta_deg: Any,
    sup_ms: Any,
    sup_deg: Any,
    side: Any,
    best_out: Any,
    sig_out: Any,
    rad_out: Any,
) -> None:
    """The polar support towards ``beta_deg`` (2, n) at the rows of the move wind
    (``isochrone_polar._support``), on the point's side where it approaches the line,
    else on the other (``isochrone_togo._fastest_aim``): writes its speed component,
    the side sailed and the |TWA| [rad] (each 2, n)."""
    n_b = sup_ms.shape[1]
    to_rad = math.pi / 180.0
    n = row.shape[0]
    for i in range(n):
        node = row[i]
        w = weight[i]
        best = np.empty(2)
        ang = np.empty(2)
        for s in range(2):
            pos = (beta_deg[s, i] + 180.0) * (n_b - 1) / 360.0
            col = _clip(_floor_index(pos), 0, n_b - 2)
            frac = _clip(pos - col, 0.0, 1.0)
            for which in range(2):
                tab = sup_ms if which == 0 else sup_deg
                below = tab[node, col] + frac * (tab[node, col + 1] - tab[node, col])
                above = tab[node + 1, col] + frac * (tab[node + 1, col + 1] - tab[node + 1, col])
                val = below + w * (above - below)
                if which == 0:
                    best[s] = val
                else:
                    ang[s] = val
        for s in range(2):
            sides = side[i] if s == 0 else -side[i]
            own = best[s] > 0
            sig_out[s, i] = sides if own else -sides
            best_out[s, i] = best[s] if own else best[1 - s]
            rad_out[s, i] = (ang[s] if own else ang[1 - s]) * to_rad


@_jit
def aim_directions(
    x: Any,
    y: Any,
    way: Any,
    move: Any,
    mean: Any,
    best: Any,
    sig: Any,
    cos_rb: Any,
    sin_rb: Any,
    aim: Any,
    normal: Any,
    aims: Any,
    cosines: Any,
    sines: Any,
) -> None:
    """The aim points the local wind reaches soonest (``isochrone_togo._fastest_aim``,
    still water), and the direct headings to them.

    ``way`` (5, n) as :func:`sample_points` writes it; ``move``, ``mean`` as
    :func:`wind_states`; ``best``, ``sig`` and the cosine and sine of the support's
    |TWA| (2, n).  Writes ``aims`` (3, 2, n: unit vector x, y and distance to the aim
    point per side), ``cosines`` (2, 2, n: of the direct heading from the move wind's
    upwind direction, clipped to [-1, 1], and of the way from the mean wind's) and
    ``sines`` (2, 2, n: their signed sines).
    """
    ax0, ay0, ux, uy, m, length = aim[0], aim[1], aim[2], aim[3], aim[4], aim[5]
    nx, ny = normal[0], normal[1]
    for i in range(x.shape[0]):
        xi, yi = x[i], y[i]
        upx, upy = move[1, i], move[2, i]
        ahead = (ax0 - xi) * nx + (ay0 - yi) * ny
        for s in range(2):
            ca, sa, sg = cos_rb[s, i], sin_rb[s, i], sig[s, i]
            dx = upx * ca - sg * upy * sa
            dy = upy * ca + sg * upx * sa
            dn = dx * nx + dy * ny
            ok = best[s, i] > 0 and dn > 1e-9 and ahead > 0
            t = ahead / (dn if ok else 1.0) if ok else 0.0
            r = _clip((xi + t * dx - ax0) * ux + (yi + t * dy - ay0) * uy, m, length - m)
            vx = ax0 + r * ux - xi
            vy = ay0 + r * uy - yi
            d2 = math.sqrt(vx * vx + vy * vy)
            use = ok and d2 > 0
            inv = 1.0 / (d2 if use else 1.0)
            ex = vx * inv if use else way[2, i]
            ey = vy * inv if use else way[3, i]
            aims[0, s, i] = ex
            aims[1, s, i] = ey
            aims[2, s, i] = d2 if use else way[4, i]
            cosines[0, s, i] = _clip(upy * ey + upx * ex, -1.0, 1.0)
            sines[0, s, i] = upx * ey - upy * ex
            mupx, mupy = mean[1, i], mean[2, i]
            cosines[1, s, i] = _clip(mupy * ey + mupx * ex, -1.0, 1.0)
            sines[1, s, i] = mupx * ey - mupy * ex


@_jit
def dense_speeds(cells: Any, params: Any, which: Any, tws: Any, twa: Any, out: Any) -> None:
    """:meth:`Polar.speed <sailroute.boat.polar.Polar.speed>` of PCHIP polars at
    ``tws[i]`` and ``twa[i, j]`` (every |TWA| in [0, 360] or NaN), into ``out[i, j]``:
    the bilinear lookup in their dense tables (:meth:`~sailroute.boat.polar.Polar.
    dense_table`), one after the other in ``cells``; ``params`` (P, 6): per polar
    ``1/TWA step, 1/TWS step, top TWS, TWA nodes, TWS nodes, first cell``; ``which``
    (n,): each point's polar, or empty (polar 0)."""
    for i in range(twa.shape[0]):
        p = which[i] if which.shape[0] > 0 else 0
        inv_twa, inv_tws, tws_max = params[p, 0], params[p, 1], params[p, 2]
        n_twa, n_tws, c0 = int(params[p, 3]), int(params[p, 4]), int(params[p, 5])
        w = _clip(tws[i], 0.0, tws_max) * inv_tws
        j_w = 0 if w != w else max(min(int(w), n_tws - 2), 0)
        fw = w - j_w
        for k in range(twa.shape[1]):
            a = abs(twa[i, k])
            a = _mn(a, 360.0 - a) * inv_twa
            i_a = 0 if a != a else max(min(int(a), n_twa - 2), 0)
            fa = a - i_a
            c = c0 + i_a * (n_tws - 1) + j_w
            lo = cells[c, 0] + fw * (cells[c, 1] - cells[c, 0])
            hi = cells[c, 2] + fw * (cells[c, 3] - cells[c, 2])
            out[i, k] = lo + fa * (hi - lo)


@_jit
def step_inputs(
    x: Any,
    y: Any,
    debt: Any,
    move: Any,
    move_row: Any,
    mean: Any,
    mean_row: Any,
    man: Any,
    flags: Any,
    aims: Any,
    cosines: Any,
    sines: Any,
    angles: Any,
    vmg_cos: Any,
    vmg_sin: Any,
    bsp: Any,
    tables: Any,
    vmax: Any,
    speed_ms: Any,
    consts: Any,
    dt: Any,
    target: Any,
    rays: Any,
    ray_clear: Any,
    first_clear: Any,
    box: Any,
    frame: Any,
    group: Any,
    n_groups: int,
    exact: Any,
    ttg: Any,
    reach: Any,
    near: Any,
    near_rays: Any,
    least: Any,
) -> bool:
    """Exact columns, time to go, reach and the points within reach of a front.

    ``aims``, ``cosines`` and ``sines`` as :func:`aim_directions` writes them;
    ``angles`` (2, 2, n): their arc cosines [°]; ``bsp`` (n, 4): the boat speed of the
    exact columns; the VMG cosines and sines (n, 2); ``tables`` (2, n_w): upwind and downwind VMG;
    ``consts = (tack, gybe, 1 / grid step [1/°], 1 / grid step [1/rad])``; ``target``
    and ``rays`` (k, 5): segments as :func:`_segment_distance` takes them, the rays with
    their clearances ``ray_clear`` (``first_clear`` per point for ray 0 when it has
    any points); ``box = (xmin, xmax, ymin, ymax)`` or empty.  Writes ``exact`` (4, n,
    4: |TWA|, speed, cosine and sine of the columns VMG up, VMG down and direct per
    side), ``ttg`` (3, 2, n: time to go and its gradient per side), ``reach`` (n,: in the
    step ``dt`` [s], one value or one per point),
    ``near`` (n,) and ``near_rays`` (k, n); ``least`` (2, n_groups): each member's
    least time to go and least distance to its aim points.  Returns whether every
    move stays in the box.
    """
    tack, gybe, inv_step, inv_rad_step = consts[0], consts[1], consts[2], consts[3]
    na = speed_ms.shape[1]
    for g in range(n_groups):
        least[0, g] = np.inf
        least[1, g] = np.inf
    box_clear = True
    for i in range(x.shape[0]):
        g = group[i] if n_groups > 1 else 0
        # the exact columns
        exact[0, i, 0] = move[4, i]
        exact[0, i, 1] = move[5, i]
        exact[0, i, 2] = angles[0, 0, i]
        exact[0, i, 3] = angles[0, 1, i]
        for k in range(4):
            exact[1, i, k] = bsp[i, k]
        exact[2, i, 0] = vmg_cos[i, 0]
        exact[2, i, 1] = vmg_cos[i, 1]
        exact[2, i, 2] = cosines[0, 0, i]
        exact[2, i, 3] = cosines[0, 1, i]
        exact[3, i, 0] = vmg_sin[i, 0]
        exact[3, i, 1] = vmg_sin[i, 1]
        exact[3, i, 2] = abs(sines[0, 0, i])
        exact[3, i, 3] = abs(sines[0, 1, i])
        # time to go on either side, in the mean wind (isochrone_togo._time_to_go)
        node = mean_row[i]
        w = mean[3, i]
        vmg_up = tables[0, node] + w * (tables[0, node + 1] - tables[0, node])
        vmg_dn = tables[1, node] + w * (tables[1, node + 1] - tables[1, node])
        free = flags[0, i]
        for s in range(2):
            sides = man[0, i] if s == 0 else -man[0, i]
            beta_deg = angles[1, s, i]
            cos_b = cosines[1, s, i]
            sin_b = sines[1, s, i]
            dist = aims[2, s, i]
            pos = beta_deg * inv_step - 1.0
            col = _clip(_floor_index(pos), 0, na - 2)
            frac = _clip(pos - col, 0.0, 1.0)
            s_l = speed_ms[node, col] + w * (speed_ms[node + 1, col] - speed_ms[node, col])
            s_r = speed_ms[node, col + 1] + w * (
                speed_ms[node + 1, col + 1] - speed_ms[node, col + 1]
            )
            spd = s_l + frac * (s_r - s_l)
            slope = (s_r - s_l) * inv_rad_step
            cone_up = beta_deg <= mean[4, i] and vmg_up > 0
            cone_dn = beta_deg >= mean[5, i] and vmg_dn > 0 and not cone_up
            cone = cone_up or cone_dn
            inv_s = 1.0 / (spd if spd > 0 else 1.0)
            if cone_up:
                inv_v = 1.0 / (vmg_up if cone_up else 1.0)
            else:
                inv_v = -1.0 / (vmg_dn if cone_dn else 1.0)
            t_straight = dist * inv_s if spd > 0 else np.inf
            t_cone = dist * cos_b * inv_v if cone else np.inf
            own = free or sides * sin_b >= 0
            paid = not free
            t_straight = t_straight + (
                0.0 if (own or not paid) else (tack if beta_deg < 90.0 else gybe)
            )
            t_cone = t_cone + ((tack if cone_up else gybe) if paid else 0.0)
            use_cone = t_cone < t_straight
            tau = _mn(t_cone, t_straight)
            sin_abs = math.sqrt(_mx(1.0 - cos_b * cos_b, 1e-18))
            kk = slope * inv_s * inv_s / sin_abs
            along_up = inv_v if use_cone else kk
            along_way = 0.0 if use_cone else inv_s - kk * cos_b
            ok = tau < np.inf
            tau = (tau if ok else _BIG_S) if dist > 0 else 0.0
            if not ok:
                along_up = 0.0
                along_way = 0.0
            ex, ey = aims[0, s, i], aims[1, s, i]
            ttg[0, s, i] = tau
            ttg[1, s, i] = along_up * mean[1, i] + along_way * ex
            ttg[2, s, i] = along_up * mean[2, i] + along_way * ey
            least[1, g] = _mn(least[1, g], dist)
        least[0, g] = _mn(least[0, g], debt[i] + ttg[0, 0, i])
        # the reach of the moves and what is within it
        row = move_row[i]
        top = _mx(vmax[row], vmax[row + 1])
        top_ex = bsp[i, 0]
        for k in range(1, 4):
            top_ex = _mx(top_ex, bsp[i, k])
        reach_i = _mx(top, top_ex) * _each(dt, i) * 1.0001
        reach[i] = reach_i
        near[i] = _segment_distance(x[i], y[i], target) <= reach_i + 1e-6
        for b in range(rays.shape[0]):
            clear = first_clear[i] if (b == 0 and first_clear.shape[0] > 0) else ray_clear[b]
            near_rays[b, i] = _segment_distance(x[i], y[i], rays[b]) <= reach_i + clear + 1e-3
        if box.shape[0] > 0 and box_clear:
            wx = frame[0] + x[i] * frame[3] + y[i] * frame[2]
            wy = frame[1] - x[i] * frame[2] + y[i] * frame[3]
            box_clear = (
                wx - reach_i >= box[0]
                and wx + reach_i <= box[1]
                and wy - reach_i >= box[2]
                and wy + reach_i <= box[3]
            )
    return box_clear


# --------------------------------------------------------------------------------------
# the candidates


@_jit
def _barrier_blocks(px: float, py: float, qx: float, qy: float, bar: Any, clear: float) -> bool:
    """``geometry.barrier_blocks`` of one move; ``bar = (ax, ay, ex, ey, nx, ny, mx,
    my)``: the tested segment behind the ray, its direction normal and the mark."""
    ax, ay, ex, ey, nx, ny = bar[0], bar[1], bar[2], bar[3], bar[4], bar[5]
    dx = qx - px
    dy = qy - py
    wx = ax - px
    wy = ay - py
    den = dx * ey - dy * ex
    sgn = -1.0 if den < 0 else 1.0
    ns = (wx * ey - wy * ex) * sgn
    nr = (wx * dy - wy * dx) * sgn
    ad = den * sgn
    if dx * nx + dy * ny > 0 and ad > 0 and ns >= 0 and ns <= ad and nr >= 0 and nr <= ad:
        return True
    if not clear > 0:  # the test below could not block a move
        return False
    mwx, mwy = bar[6] - px, bar[7] - py
    dd = dx * dx + dy * dy
    f = _clip((mwx * dx + mwy * dy) / (dd if dd > 0 else 1.0), 0.0, 1.0)
    cx, cy = mwx - f * dx, mwy - f * dy
    return cx * cx + cy * cy < clear * clear


FRONT = (
    "x",
    "y",
    "move",
    "move_row",
    "man",
    "flags",
    "debt",
    "charged",
    "exact",
    "direct_sin",
    "ttg",
)
"""The arrays of a step that :func:`candidates` and :func:`survivors` take as one tuple
``front``: positions, the wind of the move (:func:`wind_states`), manoeuvres, penalty
debt and charge, the exact columns, the direct columns' sines and the time to go
(:func:`step_inputs`); ``isochrone_fast.Packed.front`` makes it."""

_PLAIN, _PENDING, _SWITCHED = 0, 1, 2
"""How a row's candidates are timed: a whole step of moving (block ``_KEEP``), a
pending manoeuvre re-priced by the heading sailed (block ``_KEEP``), a new side change
(block ``_SWITCH``)."""


@_inline
def _owed(mode: int, price: float, debt: float, charged: float, free_owes: bool) -> float:
    """Penalty time a timed move owes [s]: a pending manoeuvre re-priced by the heading
    sailed (``price``), less what was charged so far; a new side change its ``price``
    (nothing at a free start)."""
    if mode == _PENDING:
        return _mx(debt + price - charged, 0.0)
    return price if free_owes else 0.0


@_inline
def _grid_moves(
    mode: int,
    xr: float,
    yr: float,
    upx: float,
    upy: float,
    sigma: float,
    w: float,
    lo: Any,
    hi: Any,
    twa: Any,
    cos_a: Any,
    sin_a: Any,
    tau: float,
    gx: float,
    gy: float,
    up_s: float,
    down_s: float,
    debt: float,
    charged: float,
    free_owes: bool,
    dt: float,
    sc: Any,
    qx: Any,
    qy: Any,
) -> None:
    """Score and end of the grid candidates of one row and block (``isochrone_kernel.
    _block``, ``_switch_timing``, ``_keep_timing``, the ends and the scores): ``lo, hi``
    the table's speeds at the row's two TWS nodes, ``twa, cos_a, sin_a`` the columns'
    |TWA| and its cosine and sine; into ``sc``, ``qx``, ``qy`` (slices, one per
    column)."""
    sux, suy = sigma * upx, sigma * upy
    if mode == _PLAIN:
        for j in range(sc.shape[0]):
            s_lo = lo[j]
            b = s_lo + w * (hi[j] - s_lo)
            sx = b * cos_a[j]
            sy = b * sin_a[j]
            vx = upx * sx - suy * sy
            vy = upy * sx + sux * sy
            sc[j] = tau - dt * (gx * vx + gy * vy)
            qx[j] = xr + dt * vx
            qy[j] = yr + dt * vy
        return
    for j in range(sc.shape[0]):
        s_lo = lo[j]
        b = s_lo + w * (hi[j] - s_lo)
        sx = b * cos_a[j]
        sy = b * sin_a[j]
        vx = upx * sx - suy * sy
        vy = upy * sx + sux * sy
        owed = _owed(mode, up_s if twa[j] < 90.0 else down_s, debt, charged, free_owes)
        delay = _mn(owed, dt)
        mv = dt - delay
        sc[j] = tau + (owed - delay) - mv * (gx * vx + gy * vy)
        qx[j] = xr + mv * vx
        qy[j] = yr + mv * vy


@_inline
def _forbid(
    r: int,
    block: int,
    first: int,
    j0: int,
    n_grid: int,
    pending: bool,
    x: Any,
    y: Any,
    man: Any,
    direct_sin: Any,
    fans: Any,
    bars: Any,
    near_bars: Any,
    bar_clear: Any,
    first_clear: Any,
    box: Any,
    frame: Any,
    sc: Any,
    qx: Any,
    qy: Any,
) -> None:
    """Scores ``sc`` of the forbidden candidates of row ``r`` to infinity
    (``isochrone_kernel._drop_forbidden`` with ``_barrier_blocked``); ``sc, qx, qy``:
    the row's candidates from column ``j0`` on."""
    side = man[0, r]
    ds = direct_sin[block, r]
    h = sc.shape[0]
    if not (side * ds >= 0 if block == 0 else side * ds <= 0):
        sc[h - 1] = np.inf  # the direct column exists on its own side only
    if block == 1 and pending:
        sc[:] = np.inf
    if fans.shape[0] > 0:  # members: only the grid columns of each one's own fan
        n_own = n_grid - j0
        lo = min(max(fans[1, r] - first - j0, 0), n_own)
        hi = min(max(fans[2, r] - first - j0, lo), n_own)
        for j in range(lo):
            sc[j] = np.inf
        for j in range(hi, n_own):
            sc[j] = np.inf
    for bi in range(bars.shape[0]):
        if near_bars[bi, r]:
            own = bi == 0 and first_clear.shape[0] > 0
            clear = first_clear[r] if own else bar_clear[bi]
            for j in range(h):
                if _barrier_blocks(x[r], y[r], qx[j], qy[j], bars[bi], clear):
                    sc[j] = np.inf
    if box.shape[0] > 0:
        cx, cy, fx, fy = frame[0], frame[1], frame[2], frame[3]
        for j in range(h):
            wx = cx + qx[j] * fy + qy[j] * fx
            wy = cy - qx[j] * fx + qy[j] * fy
            if not (wx >= box[0] and wx <= box[1] and wy >= box[2] and wy <= box[3]):
                sc[j] = np.inf


@_inline
def _exact_moves(
    mode: int,
    r: int,
    block: int,
    sigma: float,
    free_owes: bool,
    dt: float,
    x: Any,
    y: Any,
    move: Any,
    man: Any,
    debt: Any,
    charged: Any,
    ttg: Any,
    exact: Any,
    sc: Any,
    qx: Any,
    qy: Any,
) -> None:
    """The three exact columns of row ``r`` (VMG up, VMG down, the block's direct
    column) as :func:`_grid_moves` does the grid's, into the last three of ``sc, qx,
    qy``."""
    h = sc.shape[0]
    upx, upy = move[1, r], move[2, r]
    tau, gx, gy = ttg[0, block, r], ttg[1, block, r], ttg[2, block, r]
    for e in range(3):
        col = 3 if (block == 1 and e == 2) else e
        b = exact[1, r, col]
        sx = b * exact[2, r, col]
        sy = b * exact[3, r, col]
        vx = upx * sx - (sigma * upy) * sy
        vy = upy * sx + (sigma * upx) * sy
        rate = gx * vx + gy * vy
        j = h - 3 + e
        if mode == _PLAIN:
            sc[j] = tau - dt * rate
            qx[j] = x[r] + dt * vx
            qy[j] = y[r] + dt * vy
            continue
        price = man[2, r] if exact[0, r, col] < 90.0 else man[3, r]
        owed = _owed(mode, price, debt[r], charged[r], free_owes)
        delay = _mn(owed, dt)
        mv = dt - delay
        sc[j] = tau + (owed - delay) - mv * rate
        qx[j] = x[r] + mv * vx
        qy[j] = y[r] + mv * vy


@_inline
def _column(
    j: int,
    n_grid: int,
    first: int,
    r: int,
    block: int,
    move: Any,
    move_row: Any,
    exact: Any,
    tables: Any,
    speed_ms: Any,
) -> tuple[float, float, float, float]:
    """Boat speed, |TWA|, its cosine and sine of column ``j`` of row ``r`` and block
    ``block`` (the grid's, then VMG up, VMG down, the block's direct column)."""
    if j < n_grid:
        cc = first + j
        node = move_row[r]
        s_lo = speed_ms[node, cc]
        b = s_lo + move[3, r] * (speed_ms[node + 1, cc] - s_lo)
        return b, tables[0, cc], tables[1, cc], tables[2, cc]
    e = j - n_grid
    if block == 1 and e == 2:
        e = 3
    return exact[1, r, e], exact[0, r, e], exact[2, r, e], exact[3, r, e]


@_inline
def _timing(
    mode: int,
    twa: float,
    r: int,
    man: Any,
    debt: Any,
    charged: Any,
    free_owes: bool,
    dt: float,
) -> tuple[float, float]:
    """``(delay, move)`` [s] of a candidate at |TWA| ``twa`` (``isochrone_kernel._Timing``)."""
    owed = 0.0
    if mode != _PLAIN:
        owed = _owed(mode, man[2, r] if twa < 90.0 else man[3, r], debt[r], charged[r], free_owes)
    delay = _mn(owed, dt)
    return delay, dt - delay


@_jit
def _arrival_row(
    r: int,
    block: int,
    j0: int,
    n_grid: int,
    first: int,
    mode: int,
    free_owes: bool,
    dt: float,
    x: Any,
    y: Any,
    move: Any,
    move_row: Any,
    man: Any,
    debt: Any,
    charged: Any,
    exact: Any,
    tables: Any,
    speed_ms: Any,
    current: Any,
    cross: Any,
    sc: Any,
    qx: Any,
    qy: Any,
    best: Any,
) -> None:
    """The earliest crossing of the target by the allowed candidates of row ``r`` (a row
    within reach of it; ``isochrone_kernel._arrival``), into ``best`` if it is earlier:
    ``(found, time into the step, row, block, column, fraction of the move, start x, y
    (after the drift of the block's first column, as there), end x, y, velocity x, y,
    speed, delay, side)``."""
    ax, ay, ex, ey, nx, ny = cross[0], cross[1], cross[2], cross[3], cross[4], cross[5]
    drift = current.shape[0] > 0
    for j in range(sc.shape[0]):
        if not sc[j] < np.inf:  # forbidden (the arrival test's conditions)
            continue
        b, twa, ca, sa = _column(
            j0 + j, n_grid, first, r, block, move, move_row, exact, tables, speed_ms
        )
        delay, mv = _timing(mode, twa, r, man, debt, charged, free_owes, dt)
        px = x[r] + delay * current[0, r] if drift else x[r]
        py = y[r] + delay * current[1, r] if drift else y[r]
        dx = qx[j] - px
        dy = qy[j] - py
        wx = ax - px
        wy = ay - py
        den = dx * ey - dy * ex
        sgn = -1.0 if den < 0 else 1.0
        ns = (wx * ey - wy * ex) * sgn
        nr = (wx * dy - wy * dx) * sgn
        ad = den * sgn
        if not (dx * nx + dy * ny > 0 and ad > 0 and ns >= 0 and ns <= ad and nr >= 0 and nr <= ad):
            continue
        frac = ns / ad
        t_hit = delay + frac * mv
        if not t_hit < best[1]:
            continue
        _, twa0, _, _ = _column(
            j0, n_grid, first, r, block, move, move_row, exact, tables, speed_ms
        )
        delay0, _ = _timing(mode, twa0, r, man, debt, charged, free_owes, dt)
        sigma = man[0, r] if block == 0 else -man[0, r]
        sx, sy = b * ca, b * sa
        upx, upy = move[1, r], move[2, r]
        best[0] = 1.0
        best[1] = t_hit
        best[2] = r
        best[3] = block
        best[4] = j0 + j
        best[5] = frac
        best[6] = x[r] + delay0 * current[0, r] if drift else x[r]
        best[7] = y[r] + delay0 * current[1, r] if drift else y[r]
        best[8] = qx[j]
        best[9] = qy[j]
        best[10] = upx * sx - (sigma * upy) * sy
        best[11] = upy * sx + (sigma * upx) * sy
        best[12] = b
        best[13] = delay
        best[14] = sigma


@_jit
def candidates(
    r0: int,
    r1: int,
    chunk: int,
    first: int,
    stop: int,
    dt: Any,
    t_step: float,
    front: Any,
    current: Any,
    fans: Any,
    tables: Any,
    speed_ms: Any,
    bars: Any,
    near_bars: Any,
    bar_clear: Any,
    first_clear: Any,
    box: Any,
    frame: Any,
    origin: Any,
    near: Any,
    cross: Any,
    score: Any,
    qx32: Any,
    qy32: Any,
    segments: Any,
    arrival: Any,
) -> int:
    """Every candidate move of the rows ``r0:r1`` of a front, in the order the NumPy
    kernel ranks them (chunks of ``chunk`` rows; per chunk block ``_KEEP`` row by row,
    then block ``_SWITCH``), as ``isochrone_kernel._expand`` scores them.

    Per candidate writes its ``score`` (estimated time to go after the move [s],
    infinite where forbidden) and its end point seen from the pruning's origin in
    float32 (``qx32, qy32``); per row and block one row of ``segments``: its first
    candidate, their number, the first one's id (``isochrone_kernel._KEEP``) and the
    side index plus the member's first key.  ``dt``: the step length [s], one value or
    one per row.  ``front``: the step's arrays (:data:`FRONT`;
    ``exact`` (4, n, 4) and ``ttg`` (3, 2, n: time to go, gradient x, y; block ``_KEEP``,
    ``_SWITCH``) as :func:`step_inputs` writes them); ``tables = (twa, cos, sin)`` (3,
    n_a) of the grid; ``current`` (2, n)
    or empty; ``fans`` (3, n: the member's first key, its fan's first and stop column)
    or empty; ``bars`` (k, 8) as :func:`_barrier_blocks` takes them with the rows near
    each ``near_bars`` (k, n) and their clearances.  The rows ``near`` the target (or
    none: empty) are tested for the arrival (``cross``: the target segment's end ``a``,
    its vector to ``b`` and its normal): ``arrival`` (15,) gets the earliest crossing
    (:func:`_arrival_row`; per chunk the earliest into the step ``t_step``, across chunks
    the earliest in time, as the NumPy kernel compares them).  Returns the number of
    segments, or -1 where a score is NaN (the NumPy kernel then decides the step).
    """
    x, y, move, move_row, man, flags, debt, charged, exact, direct_sin, ttg = front
    n_grid = stop - first
    h = n_grid + 3
    tx, ty = np.empty(h), np.empty(h)
    twa, cos_a, sin_a = tables[0, first:stop], tables[1, first:stop], tables[2, first:stop]
    in_chunk = np.empty(15)
    arrival[0] = 0.0
    k = 0
    n_seg = 0
    for c0 in range(r0, r1, chunk):
        c1 = min(r1, c0 + chunk)
        any_free = False
        any_pending = False
        for r in range(c0, c1):
            any_free = any_free or flags[0, r]
            any_pending = any_pending or flags[1, r]
        in_chunk[0] = 0.0
        in_chunk[1] = np.inf
        for block in range(2):
            j0 = 0 if (block == 0 or any_free) else n_grid
            for r in range(c0, c1):
                dt_r = _each(dt, r)
                side = man[0, r]
                sigma = side if block == 0 else -side
                pending = any_pending and flags[1, r]
                mode = _SWITCHED if block == 1 else (_PENDING if pending else _PLAIN)
                free_owes = not (any_free and flags[0, r])
                m = h - j0
                sc, qx, qy = score[k : k + m], tx[j0:], ty[j0:]
                if j0 < n_grid:
                    node = move_row[r]
                    _grid_moves(
                        mode, x[r], y[r], move[1, r], move[2, r], sigma, move[3, r],
                        speed_ms[node, first + j0 : stop], speed_ms[node + 1, first + j0 : stop],
                        twa[j0:], cos_a[j0:], sin_a[j0:], ttg[0, block, r], ttg[1, block, r],
                        ttg[2, block, r], man[2, r], man[3, r], debt[r], charged[r], free_owes,
                        dt_r, sc[: n_grid - j0], qx[: n_grid - j0], qy[: n_grid - j0],
                    )  # fmt: skip
                _exact_moves(
                    mode, r, block, sigma, free_owes, dt_r, x, y, move, man, debt, charged, ttg,
                    exact, sc, qx, qy,
                )  # fmt: skip
                if current.shape[0] > 0:  # drift with the water for the whole step
                    for j in range(m):
                        qx[j] = qx[j] + dt_r * current[0, r]
                        qy[j] = qy[j] + dt_r * current[1, r]
                _forbid(
                    r, block, first, j0, n_grid, pending, x, y, man, direct_sin, fans, bars,
                    near_bars, bar_clear, first_clear, box, frame, sc, qx, qy,
                )  # fmt: skip
                nan = False
                ox, oy = qx32[k : k + m], qy32[k : k + m]
                o0, o1 = origin[0], origin[1]
                for j in range(m):
                    nan |= sc[j] != sc[j]
                    ox[j] = np.float32(qx[j] - o0)
                    oy[j] = np.float32(qy[j] - o1)
                if nan:
                    return -1
                if near.shape[0] > 0 and near[r]:
                    _arrival_row(
                        r, block, j0, n_grid, first, mode, free_owes, dt_r, x, y, move, move_row,
                        man, debt, charged, exact, tables, speed_ms, current, cross, sc, qx, qy,
                        in_chunk,
                    )  # fmt: skip
                sidx = (1 if side < 0 else 0) if block == 0 else (0 if side < 0 else 1)
                segments[n_seg, 0] = k
                segments[n_seg, 1] = m
                segments[n_seg, 2] = (r * 2 + block) * h + j0
                segments[n_seg, 3] = sidx + (fans[0, r] if fans.shape[0] > 0 else 0)
                n_seg += 1
                k += m
        if in_chunk[0] > 0 and (arrival[0] == 0 or t_step + in_chunk[1] < t_step + arrival[1]):
            arrival[:] = in_chunk
    return n_seg


@_jit
def sector_winners(
    n_seg: int,
    segments: Any,
    score: Any,
    phi: Any,
    scale: Any,
    off: Any,
    best: Any,
    who: Any,
) -> None:
    """Keep the best candidate per key of the first ``n_seg`` segments of
    :func:`candidates` (``isochrone_kernel._sector_winners``): key = ``floor(phi scale +
    off)`` (float32, as NumPy) times 2 plus the segment's side index; the first in
    order wins a tie.  A segment's keys come in runs (its candidates in heading order):
    a run's best is kept in registers and written once."""
    for g in range(n_seg):
        k0, m, wid0, sidx = segments[g, 0], segments[g, 1], segments[g, 2], segments[g, 3]
        run = -1  # the key of the current run, its best score and candidate
        run_best = np.inf
        run_who = np.int64(0)
        for j in range(m):
            sc = score[k0 + j]
            if sc < np.inf:
                key = np.int64(phi[k0 + j] * scale + off) * 2 + sidx
                if key != run:
                    if run >= 0:
                        best[run] = run_best
                        who[run] = run_who
                    run = key
                    run_best = best[key]
                    run_who = who[key]
                if sc < run_best:
                    run_best = sc
                    run_who = wid0 + j
        if run >= 0:
            best[run] = run_best
            who[run] = run_who


@_jit
def survivors(
    row: Any,
    block: Any,
    column: Any,
    first: int,
    n_grid: int,
    dt: Any,
    front: Any,
    tables: Any,
    speed_ms: Any,
    current: Any,
    out: Any,
    moved: Any,
) -> None:
    """The new front from the winning candidates ``(row, block, column)``
    (``isochrone_kernel._winner_columns`` and ``_survivors``) of the step's arrays
    ``front`` (:data:`FRONT`): writes ``out`` (11, m: x, y, side, debt, |TWA|, |TWA| before
    a pending manoeuvre or NaN, its penalty so far, boat speed, delay, velocity x and y)
    and ``moved`` (m,); ``dt``: the step length [s], one value or one per row of the
    front."""
    x, y, move, move_row, man, flags, debt, charged, exact, _, _ = front
    for i in range(row.shape[0]):
        r, c = row[i], column[i]
        dt_r = _each(dt, r)
        switch = block[i] == 1
        if c < n_grid:
            cc = c + first
            node = move_row[r]
            s_lo = speed_ms[node, cc]
            bsp = s_lo + move[3, r] * (speed_ms[node + 1, cc] - s_lo)
            twa, ca, sa = tables[0, cc], tables[1, cc], tables[2, cc]
        else:
            e = c - n_grid
            if switch and e == 2:
                e = 3
            bsp, twa, ca, sa = exact[1, r, e], exact[0, r, e], exact[2, r, e], exact[3, r, e]
        sx = bsp * ca
        sy = bsp * sa
        side = man[0, r]
        sigma = -side if switch else side
        upx, upy = move[1, r], move[2, r]
        vx = upx * sx - (sigma * upy) * sy
        vy = upy * sx + (sigma * upx) * sy
        pen = man[2, r] if twa < 90.0 else man[3, r]
        free, pending = flags[0, r], flags[1, r]
        if switch:
            owed = _owed(_SWITCHED, pen, 0.0, 0.0, not free)
        else:
            owed = _owed(_PENDING, pen, debt[r], charged[r], True) if pending else 0.0
        delay = _mn(owed, dt_r)
        mv = dt_r - delay
        in_manoeuvre = (not free if switch else pending) and not (mv > 0)
        px = x[r] + mv * vx
        py = y[r] + mv * vy
        if current.shape[0] > 0:
            px = px + dt_r * current[0, r]
            py = py + dt_r * current[1, r]
        out[0, i] = px
        out[1, i] = py
        out[2, i] = sigma
        out[3, i] = owed - delay
        out[4, i] = twa
        out[5, i] = man[1, r] if in_manoeuvre else np.nan
        out[6, i] = pen if in_manoeuvre else 0.0
        out[7, i] = bsp
        out[8, i] = delay
        out[9, i] = vx
        out[10, i] = vy
        moved[i] = mv > 0 and bsp > 0


# --------------------------------------------------------------------------------------
# the members' winds


@_jit
def perturbed_winds(
    u: Any,
    v: Any,
    speed: Any,
    which: Any,
    scale: Any,
    add: Any,
    turns: Any,
    cos: Any,
    sin: Any,
    series: Any,
    cos_p: Any,
    sin_p: Any,
    out_u: Any,
    out_v: Any,
) -> None:
    """The arithmetic of :func:`~sailroute.wind.perturbed.sample_perturbed` point by
    point, the same operations in the same order: the base wind ``u, v`` (n,) of the
    point's member ``which`` (n,), its speed ``speed = hypot(u, v)`` (NumPy's; empty
    where no member adds speed), per member the speed ``scale`` and ``add`` [m s⁻¹],
    whether it ``turns`` and the cosine and sine of its constant turn; members with a
    shift series (``series``) take the point's own ``cos_p, sin_p`` (n,).  Writes the
    members' winds into ``out_u, out_v``."""
    for i in range(u.shape[0]):
        w = which[i]
        ui, vi = u[i], v[i]
        f = scale[w]
        if add[w] != 0.0:
            s = speed[i]
            new = f * s + add[w]
            if not (new >= 0.0 or new != new):  # np.maximum(new, 0.0)
                new = 0.0
            f = new / s if s > 0.0 else 0.0
        if turns[w]:
            c, sn = (cos_p[i], sin_p[i]) if series[w] else (cos[w], sin[w])
            ui, vi = ui * c + vi * sn, vi * c - ui * sn
        out_u[i] = f * ui
        out_v[i] = f * vi
