"""Isochrone leg router: array fronts, per-side sector pruning, exact arrival.

The front at time ``t`` is a set of points, each with a position, a tack side
(+1 starboard, −1 port, 0 = not chosen yet at the leg start), a time debt
(penalty still to serve) and a parent index into the previous front.  One step
of length ``dt`` (10 s by default, shorter near the target):

1. one ``wind.sample`` call: each point's wind at mid-step time at its predicted
   mid-step position, plus samples along the straight line to the target;
2. candidates per point: keeping its side, a uniform grid of TWAs
   (``heading_step_deg``; with ``heading_fan="hull"`` only between the upwind and
   downwind VMG angles) plus three exact columns (VMG up, VMG down, direct to the
   point of the target reached soonest); changing side, the three exact columns;
3. boat speeds from the polar (grid columns through a cached table, exact columns
   through :meth:`Polar.speed`); every candidate moves in a straight line;
4. a side change owes ``tack_penalty_s`` or ``gybe_penalty_s`` as time: the point
   does not move until its debt is paid, so a 5 s penalty costs exactly 5 s whatever
   ``dt`` is; the penalty is priced with the first heading sailed after it;
5. every move near the target is tested against its crossing segment
   (:func:`~sailroute.routing.geometry.segment_crossing`); the earliest crossing,
   interpolated inside the step, ends the leg; moves that would pass a rounded mark on
   the wrong side (the leg's barriers: the target's entry barrier and
   ``Start.barrier``, :func:`~sailroute.routing.geometry.leg_barriers`) are dropped;
6. pruning: candidates are binned by their bearing seen from the target (sectors of
   ``prune_sector_deg``, symmetric about the leg axis) and side, and per bin the one
   with the least estimated time to go survives (VMG-hull time in the wind averaged
   along the way, with the manoeuvre the point still needs).

The route is then backtracked through the parent indices and turned into a
:class:`~sailroute.routing.types.RouteTrack` with the shared
:func:`~sailroute.routing.track.build_track`.  See ``docs/design/routing.md`` for the
method, the defaults and the measured accuracy and speed.

The per-step array functions (the kernel) are in
:mod:`sailroute.routing.isochrone_kernel` (the step and its candidates), with
:mod:`~sailroute.routing.isochrone_records` (the leg frame and the records),
:mod:`~sailroute.routing.isochrone_polar` (the polar tables),
:mod:`~sailroute.routing.isochrone_togo` (the time to go) and
:mod:`~sailroute.routing.isochrone_inputs` (the inputs of a step); this module is the
driver.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from types import ModuleType
from typing import Any, Final

import numpy as np
from numpy.typing import NDArray

from sailroute.boat.model import BoatModel
from sailroute.boat.polar import Polar
from sailroute.errors import InputError, OutOfCoverageError, RoutingError
from sailroute.routing import isochrone_fast as fast
from sailroute.routing.api import Router
from sailroute.routing.geometry import (
    TargetGeometry,
    leg_barriers,
    leg_label,
    start_centre,
    start_points,
    target_barrier,
    target_geometry,
)
from sailroute.routing.isochrone_inputs import NEAR_TARGET_STEPS, PATH_SAMPLES
from sailroute.routing.isochrone_kernel import _step
from sailroute.routing.isochrone_polar import (
    TABLE_TWS_STEP_MS,
    PolarTables,
    _device_tables,
    _DeviceTables,
    polar_tables,
)
from sailroute.routing.isochrone_records import _Arrival, _Context, _floats, _Layer, _LegFrame
from sailroute.routing.isochrone_togo import _BIG_S
from sailroute.routing.obstacles import Obstacles
from sailroute.routing.settings import RoutingSettings, check_settings
from sailroute.routing.track import build_track, make_leg_result
from sailroute.routing.types import (
    Barrier,
    LegResult,
    RouteTrack,
    Start,
    Target,
    side_sign,
)
from sailroute.wind.base import WindField
from sailroute.wind.current import CurrentField, RelativeWind, current_rate_set

__all__ = [
    "MAX_LEG_WORK",
    "NEAR_TARGET_STEPS",
    "PATH_SAMPLES",
    "TABLE_TWS_STEP_MS",
    "PolarTables",
    "check_leg_work",
    "leg_work",
    "polar_tables",
    "route_isochrone",
]

# --------------------------------------------------------------------------------------
# public entry point


def route_isochrone(
    start: Start,
    target: Target,
    t0: float,
    wind: WindField,
    boat: BoatModel,
    settings: RoutingSettings,
    *,
    progress: Callable[[float], None] | None = None,
    xp: ModuleType = np,
    current: CurrentField | None = None,
    obstacles: Obstacles | None = None,
) -> LegResult:
    """Fastest route of one leg by isochrones.

    Parameters
    ----------
    start : Start
        Start point, or start line (points every ``start_line_spacing_m`` are
        tried; the one the best route leaves from is ``LegResult.start_xy``).
    target : Target
        Mark with rounding side, gate or line (see ``routing/geometry.py``).
    t0 : float
        Start time [epoch s].
    wind : WindField
        Wind, sampled once per step at the front points.
    boat : BoatModel
        The boat: its steady polar (:meth:`~sailroute.boat.model.BoatModel.routing_polar`)
        is routed; a boat without one (the dynamic model) is refused.
    settings : RoutingSettings
        The common fields (penalties, ``initial_side``, ``zone_m``,
        ``start_line_spacing_m``, ``max_leg_time_s``) and ``settings.isochrone``
        (:class:`~sailroute.routing.settings.IsochroneSettings`: ``dt_s``,
        ``heading_step_deg``, ``min_dt_s``, ``prune_sector_deg``, ``max_front_points``,
        ``heading_fan``).
    progress : callable, optional
        Called after each step with the estimated fraction done, in [0, 1].
    xp : module
        Array module of the kernel (NumPy; the kernel uses CuPy-compatible
        operations, the wind and polar are sampled on the host).
    current : CurrentField, optional
        Surface current (water velocity over the ground, towards).  The polar is then
        entered with the wind relative to the water (:class:`~sailroute.wind.current.RelativeWind`),
        each move goes over the ground by (velocity through the water + current) and
        the track carries SOG/COG; a boat stopped by a penalty drifts with the water.
        None (default): still water, the unchanged code path.
    obstacles : Obstacles, optional
        Race-area boundary and obstacles: every candidate move whose segment leaves
        free water (:meth:`~sailroute.routing.obstacles.Obstacles.moves_free`) is
        dropped, so the route stays inside the boundary and round the obstacles.

    Returns
    -------
    LegResult
        Built with :func:`~sailroute.routing.track.make_leg_result`; the track
        has one vertex per step of the chosen route, extra vertices where a
        penalty stops the boat, and the exact arrival point.

    Raises
    ------
    InputError
        Invalid settings or target geometry.
    RoutingError
        The front leaves the wind coverage entirely, every move is blocked by the
        obstacles (the message names the nearest), or no route arrives within
        ``max_leg_time_s``.
    OutOfCoverageError
        The wind field cannot be sampled at the start, or the race outlasts
        its time span (propagated from the wind field).
    """
    label = leg_label(start, target)
    if current is not None:
        wind = RelativeWind(wind, current)
    check_settings(settings, label)
    _check_start_time(t0, label)
    polar = _routing_polar(boat, label)
    geom = target_geometry(target, start, settings.zone_m)
    tab = polar_tables(polar, settings.isochrone.heading_step_deg)
    frame = _LegFrame.for_leg(geom.centre, start_centre(start))
    ctx = _context(
        label,
        float(t0),
        frame,
        geom,
        wind,
        settings,
        leg_barriers(start, target),
        current,
        obstacles,
        start_centre(start),
    )
    if ctx.box is not None:
        _check_target_covered(geom, ctx.box, wind, label)
    dev = _device_tables(tab, xp)

    wx0, wy0 = start_points(start, settings.start_line_spacing_m)
    x0, y0 = frame.to_leg(xp.asarray(wx0), xp.asarray(wy0))
    layers = [_root_layer(float(t0), x0, y0, settings, xp)]
    arrival = _route_on(
        layers, wind, dev, ctx, settings, tab.twa_deg.size, xp, polar=polar, progress=progress
    )
    track = _backtrack(layers, arrival, frame, wind, polar, (wx0, wy0), current)
    if progress is not None:
        progress(1.0)
    return make_leg_result(track, "isochrone", target_barrier(target, start, settings.zone_m))


def _root_layer(t0: Any, x0: Any, y0: Any, settings: RoutingSettings, xp: ModuleType) -> _Layer:
    """The front at the leg start: the start points ``(x0, y0)`` (leg frame) at time
    ``t0`` [epoch s] (a float, or one per point), on ``settings.initial_side``."""
    n0 = int(x0.shape[0])
    nan = xp.full(n0, np.nan)
    return _Layer(
        t=t0,
        x=x0,
        y=y0,
        side=xp.full(n0, float(side_sign(settings.initial_side))),
        debt=xp.zeros(n0),
        abs_twa=nan,
        pend_old=nan,
        pend_pen=xp.zeros(n0),
        parent=xp.full(n0, -1, dtype=xp.int64),
        heading=xp.zeros(n0),
        bsp=xp.zeros(n0),
        delay=xp.zeros(n0),
        tau_est=nan,
    )


def _route_on(
    layers: list[_Layer],
    wind: WindField,
    dev: _DeviceTables,
    ctx: _Context,
    settings: RoutingSettings,
    n_angles: int,
    xp: ModuleType,
    *,
    polar: Polar,
    progress: Callable[[float], None] | None = None,
    calm_since: float | None = None,
    tau_hint: float = np.inf,
    check_work: bool = True,
) -> _Arrival:
    """Step the front ``layers[-1]`` until it arrives; the new fronts are appended to
    ``layers``.

    ``calm_since`` (time since which no point moved, or None) and ``tau_hint`` (the
    front's estimated time to go [s]) carry on a route begun elsewhere (the members of
    :func:`~sailroute.routing.batch.route_leg_batch` finish their legs here);
    ``check_work`` False: the leg's work was checked there (:func:`check_leg_work`,
    else called after the first step where ``layers`` holds one front).

    Raises
    ------
    RoutingError
        No route within ``max_leg_time_s``, or the front left the wind coverage.
    InputError
        The leg needs too much work (:func:`check_leg_work`).
    """
    t0 = ctx.t0
    while True:
        jit = fast.compiled(settings, xp)
        started = None if jit else fast.numpy_step_started()
        out = _step(layers[-1], wind, polar, dev, ctx, settings, tau_hint, xp, jit)
        if started is not None:
            fast.numpy_step_done(started)
        if isinstance(out, _Arrival):
            return out
        layer, moved, tau_min, dist_min = out
        if moved:
            calm_since = None
        elif calm_since is None:
            calm_since = layers[-1].t
        tau_hint = tau_min - (layer.t - layers[-1].t)
        if check_work and len(layers) == 1:  # after the first step: the time to go is known
            check_leg_work(ctx.label, settings, ctx, n_angles, tau_hint)
        layers.append(layer)
        elapsed = layer.t - t0
        if progress is not None:
            progress(float(elapsed / (elapsed + tau_min)) if tau_min < np.inf else 0.0)
        if elapsed >= settings.max_leg_time_s:
            raise _timeout_error(ctx.label, settings, elapsed, dist_min, calm_since, layer.t)


# --------------------------------------------------------------------------------------
# setup

MAX_LEG_WORK: Final = 1e10
"""Most candidate moves (front points x headings tried x steps, an upper bound) one leg
may need [-]: about 20 ns each on one core, so a few minutes.  The defaults need
~1e7 on a 1 km beat; ``dt_s`` 0.5 s with ``heading_step_deg`` 0.1 about 2e9."""


def leg_work(
    settings: RoutingSettings, n_points: int, n_angles: int, time_to_go_s: float
) -> tuple[float, float]:
    """Upper bound of the work of an isochrone leg: ``(steps, candidates per step)``.

    Parameters
    ----------
    settings : RoutingSettings
        ``dt_s`` gives the steps.
    n_points : int
        Most points a front keeps (``max_front_points``, or two per pruning sector).
    n_angles : int
        Grid TWAs of the polar tables (``180 / heading_step_deg``).
    time_to_go_s : float
        Estimated time from the front to the target [s].

    Returns
    -------
    tuple of float
        Steps still to go and candidate moves per step (keep and switch side, each with
        every grid TWA and the exact VMG and direct headings).
    """
    return time_to_go_s / float(settings.isochrone.dt_s), float(n_points) * 2.0 * (n_angles + 4)


def check_leg_work(
    label: str, settings: RoutingSettings, ctx: _Context, n_angles: int, time_to_go_s: float
) -> None:
    """Refuse a leg whose estimated work (:func:`leg_work`) exceeds :data:`MAX_LEG_WORK`.

    Raises
    ------
    InputError
        Naming ``routing.dt_s`` and ``routing.heading_step_deg`` with the values that
        would fit.
    """
    if not math.isfinite(time_to_go_s) or time_to_go_s <= 0 or time_to_go_s >= _BIG_S:
        return  # a calm: no estimate (max_leg_time_s bounds it)
    time_to_go_s = min(time_to_go_s, float(settings.max_leg_time_s))  # then it fails anyway
    n_points = min(ctx.max_points, 2 * ctx.n_bins)
    steps, per_step = leg_work(settings, n_points, n_angles, time_to_go_s)
    if steps * per_step <= MAX_LEG_WORK:
        return
    dt_fit = time_to_go_s * per_step / MAX_LEG_WORK
    raise InputError(
        f"leg {label}: routing.dt_s = {settings.isochrone.dt_s:g} s with "
        f"routing.heading_step_deg = {settings.isochrone.heading_step_deg:g} needs about "
        f"{steps * per_step:.1e} candidate moves "
        f"({steps:.0f} steps to go of up to {per_step:.1e}), more than {MAX_LEG_WORK:.0e} "
        f"(minutes of work per leg); use routing.dt_s >= {dt_fit:.2g} s, a coarser "
        "heading_step_deg or fewer max_front_points (the defaults, 10 s and 2, are accurate "
        "to 3e-4 of the leg time)"
    )


def _check_start_time(t0: float, label: str) -> None:
    if not (isinstance(t0, int | float) and math.isfinite(t0)):
        raise InputError(f"leg {label}: the start time must be finite epoch seconds, got {t0!r}")


def _routing_polar(boat: BoatModel, label: str) -> Polar:
    """The boat's steady polar; refuses a boat without one (the dynamic boat model)."""
    polar = boat.routing_polar() if isinstance(boat, BoatModel) else None
    if polar is not None:
        return polar
    hint = ""
    if isinstance(boat, BoatModel) and boat.dynamics() is not None:
        hint = (
            " For the dynamic boat model use router 'griddp' or 'spline', or route "
            "its steady polar (boat.steady_polar(tws_ms)) with the isochrone router."
        )
    raise InputError(
        f"leg {label}: the isochrone router needs a Polar (with .speed(tws, twa)), got "
        f"{type(boat).__name__}.{hint}"
    )


def _check_target_covered(
    geom: TargetGeometry, box: tuple[float, float, float, float], wind: WindField, label: str
) -> None:
    """Refuse a target that lies wholly outside the wind field's box."""
    inside = [box[0] <= x <= box[1] and box[2] <= y <= box[3] for x, y in (geom.a, geom.b)]
    if not any(inside):
        raise OutOfCoverageError(
            f"leg {label}: the target ({geom.kind} {geom.name!r} at ({geom.a[0]:.0f}, "
            f"{geom.a[1]:.0f}) - ({geom.b[0]:.0f}, {geom.b[1]:.0f}) m) lies outside the wind "
            f"field's coverage ({wind.coverage.describe()}).\n  Try: wind data that covers "
            "the whole course with a margin, or a wind field built with clamp=True."
        )


def _context(
    label: str,
    t0: float,
    frame: _LegFrame,
    geom: TargetGeometry,
    wind: WindField,
    s: RoutingSettings,
    barriers: tuple[tuple[Barrier, float], ...] = (),
    current: CurrentField | None = None,
    obstacles: Obstacles | None = None,
    start_xy: tuple[float, float] = (0.0, 0.0),
) -> _Context:
    cov = wind.coverage
    bounded = any(math.isfinite(v) for v in (cov.xmin, cov.xmax, cov.ymin, cov.ymax))
    box = None
    if bounded and not wind.clamp:
        box = (cov.xmin, cov.xmax, cov.ymin, cov.ymax)
    return _Context(
        label=label,
        t0=t0,
        frame=frame,
        geom=frame.geometry(geom),
        tack_s=float(s.tack_penalty_s),
        gybe_s=float(s.gybe_penalty_s),
        sector_rad=math.radians(s.isochrone.prune_sector_deg),
        n_bins=math.ceil(2.0 * math.pi / math.radians(s.isochrone.prune_sector_deg)) + 3,
        max_points=int(s.isochrone.max_front_points),
        fan_hull=s.isochrone.heading_fan == "hull",
        box=box,
        barriers=tuple((frame.barrier(b), c) for b, c in barriers),
        current=current,
        obstacles=obstacles,
        bin_origin=_detour_origin(frame, geom, obstacles, start_xy),
    )


def _detour_origin(
    frame: _LegFrame,
    geom: TargetGeometry,
    obstacles: Obstacles | None,
    start_xy: tuple[float, float],
) -> tuple[float, float] | None:
    """The start centre in the leg frame if the way round the obstacles that block the
    straight line from it to the target centre is more than :data:`DETOUR_FRACTION`
    longer (then the pruning sectors are seen from it), else None.  Sectors seen from
    the start keep a whole circle of points (several times the work): a small obstacle
    is passed as well with the target's sectors, whose front slides along it."""
    if obstacles is None:
        return None
    cx, cy = geom.centre
    extra = obstacles.detour_m(start_xy, (cx, cy))
    if extra <= DETOUR_FRACTION * math.hypot(cx - start_xy[0], cy - start_xy[1]):
        return None
    return _floats(frame.to_leg(*start_xy))


DETOUR_FRACTION: Final = 0.005
"""Estimated detour (:meth:`~sailroute.routing.obstacles.Obstacles.detour_m`), as a
fraction of the straight start-target distance, above which the pruning sectors are seen
from the start."""


# --------------------------------------------------------------------------------------
# backtracking


_Move = tuple[float, float, float, float, float, float, float, int]
"""One move of a route: start and end time [epoch s], source point x, y (leg frame) [m],
heading (leg frame) [°], boat speed [m s⁻¹], time stopped at its start [s], side."""


def _backtrack(
    layers: list[_Layer],
    arr: _Arrival,
    frame: _LegFrame,
    wind: WindField,
    polar: Polar,
    world_start: tuple[NDArray, NDArray],
    current: CurrentField | None = None,
) -> RouteTrack:
    """Polyline of the chosen route through ``layers`` (the fronts from the start to
    the one ``arr`` left from): :func:`_moves_back` and :func:`_track`."""
    moves = [_arrival_move(arr, layers[-1])]
    root = _moves_back(layers, [lay.t for lay in layers], arr.parent, moves)
    moves.reverse()
    return _track(
        moves, root, int(layers[0].side[root]), arr, frame, wind, polar, world_start, current
    )


def _arrival_move(arr: _Arrival, last: _Layer) -> _Move:
    """The move of ``arr`` from the point ``arr.parent`` of the front ``last``."""
    x, y = float(last.x[arr.parent]), float(last.y[arr.parent])
    return (arr.t_start, arr.t, x, y, arr.heading, arr.bsp, arr.delay, arr.side)


def _moves_back(
    layers: Sequence[_Layer], times: Sequence[float], idx: int, moves: list[_Move]
) -> int:
    """Append to ``moves`` the moves into point ``idx`` of ``layers[-1]``, newest first,
    back to ``layers[0]`` (``layers[k].parent`` indexes ``layers[k - 1]``; ``times[k]``:
    the time of ``layers[k]`` [epoch s]), and return the index in ``layers[0]`` they
    start from."""
    for k in range(len(layers) - 1, 0, -1):
        lay, src = layers[k], layers[k - 1]
        pidx = int(lay.parent[idx])
        moves.append(
            (
                times[k - 1],
                times[k],
                float(src.x[pidx]),
                float(src.y[pidx]),
                float(lay.heading[idx]),
                float(lay.bsp[idx]),
                float(lay.delay[idx]),
                int(lay.side[idx]),
            )
        )
        idx = pidx
    return idx


def _track(
    moves: Sequence[_Move],
    root: int,
    root_side: int,
    arr: _Arrival,
    frame: _LegFrame,
    wind: WindField,
    polar: Polar,
    world_start: tuple[NDArray, NDArray],
    current: CurrentField | None = None,
) -> RouteTrack:
    """Polyline of the route sailing ``moves`` (oldest first, the last one ``arr``'s)
    from start point ``root`` (on side ``root_side``): step starts, penalty stops,
    exact arrival (world frame).

    The vertices at the start point get its world coordinates ``world_start[k][root]``
    exactly (not through the leg frame and back), so a leg starts bit-for-bit where
    the previous one ended.  In a ``current`` the headings and speeds are through the
    water and the track gets SOG/COG (velocity through the water plus the current).
    """
    # a stopped boat (penalty) shows the heading it will sail next
    hd_next = [m[4] for m in moves]
    for i in range(len(moves) - 2, -1, -1):
        if moves[i][6] >= moves[i][1] - moves[i][0]:  # stopped for the whole step
            hd_next[i] = hd_next[i + 1]

    rows: list[tuple[float, float, float, float, float, int]] = []
    for m, (ts, te, px, py, _, b, dl, sd) in enumerate(moves):
        hd = hd_next[m]
        if m == 0 and root_side != 0 and sd != root_side:
            # forced start side, turned at once: show the old side with the mirrored heading
            rows.append((ts, px, py, float("nan"), 0.0, root_side))
        rows.append((ts, px, py, hd, 0.0 if dl > 0 else b, sd))
        if dl > 0 and ts + dl < te:
            rows.append((ts + dl, px, py, hd, b, sd))
    rows.append((arr.t, arr.x, arr.y, moves[-1][4], moves[-1][5], moves[-1][7]))

    a = np.array(rows)
    wx, wy = frame.to_world(a[:, 1], a[:, 2])
    at_start = (a[:, 1] == moves[0][2]) & (a[:, 2] == moves[0][3])
    wx[at_start] = float(world_start[0][root])
    wy[at_start] = float(world_start[1][root])
    heading = np.mod(a[:, 3] + frame.offset_deg, 360.0)
    if np.isnan(heading[0]):
        u, v = wind.sample(a[0, 0], wx[0], wy[0])
        twd = math.degrees(math.atan2(-float(u), -float(v)))
        heading[0] = (2.0 * twd - heading[1]) % 360.0
    track = build_track(
        a[:, 0],
        wx,
        wy,
        wind,
        polar,
        heading_deg=heading,
        bsp_ms=a[:, 4],
        side=a[:, 5].astype(np.int8),
    )
    if current is None:
        return track
    cu, cv = current.sample(track.t, track.x, track.y)
    hr = np.radians(track.heading_deg)
    sog, cog = current_rate_set(track.bsp_ms * np.sin(hr) + cu, track.bsp_ms * np.cos(hr) + cv)
    return dataclasses.replace(track, sog_ms=sog, cog_deg=cog)


def _timeout_error(
    label: str,
    s: RoutingSettings,
    elapsed: float,
    dist_min: float,
    calm_since: float | None,
    t: float,
) -> RoutingError:
    msg = (
        f"leg {label}: no route reached the target within {elapsed:.0f} s of race time "
        f"(max_leg_time_s = {s.max_leg_time_s:g} s); the closest point of the front was "
        f"{dist_min:.0f} m from it."
    )
    if calm_since is not None:
        msg += (
            f"\n  The boat speed was zero on the whole front for the last {t - calm_since:.0f} s: "
            "the wind is calm there (or below the polar's lowest wind speed)."
            "\n  Try: a wind field with wind over the course at this time, a later start, "
            "or a polar that covers light air."
        )
    else:
        msg += (
            "\n  Try: check that the target can be reached (rounding side, wind coverage), "
            "or raise routing.max_leg_time_s."
        )
    return RoutingError(msg)


_ROUTER: Router = route_isochrone  # mypy checks the shared router signature
