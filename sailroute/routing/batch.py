"""Members of an ensemble routed as one isochrone front.

The members of a leg (wind scenarios or perturbed winds, start times, start points)
share the target, the settings and the boat.  :func:`route_leg_batch` puts all their
fronts into one array front, the points of each member consecutive, and steps it with
the kernel of :mod:`sailroute.routing.isochrone_kernel` once per step for all members:
the fixed cost of a step (a few hundred array calls) is paid once, not once per member.
Per member stay apart: the wind (one ``sample`` call per member and step), the time,
the pruning bins (each member keeps its own best point per sector and side), the fan of
headings, the arrival and the errors.

A member leaves the common front when its next step would be shorter than ``dt_s``
(near the target) or one of its points can reach the target within the step; it
finishes its leg alone, from its own front, with the isochrone driver.  Every step a
member takes is therefore the step the single-member router takes, with the same
numbers:

* when every member starts from the same :class:`~sailroute.routing.types.Start` (the
  first leg of a course; an ensemble of winds or of start times), each gets the
  :class:`~sailroute.routing.types.LegResult` that
  :func:`~sailroute.routing.isochrone.route_isochrone` gives, bit for bit;
* a member starting elsewhere (a later leg of a course, each member starting where its
  previous leg ended) is routed in the leg frame, target geometry and barriers of the
  first member's start: the rounding segment of a mark (and the barrier the leg hands on
  to the next leg, so that every member ends on the segment it starts the next leg
  behind) and the sectors of the pruning turn by the small angle between the two starts
  seen from the target (each keeps its own clearance from the mark just rounded,
  :func:`~sailroute.routing.geometry.barrier_clearance`).  Its leg time then
  differs from its single-member route by the pruning's own tolerance
  (``docs/design/routing.md``; measured on Hyères R1 in ``docs/performance.md``).

Surface currents and array modules other than NumPy are routed one member at a time.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from sailroute.boat.model import BoatModel
from sailroute.errors import InputError
from sailroute.numerics import clip
from sailroute.routing.geometry import (
    barrier_clearance,
    leg_barriers,
    leg_label,
    start_centre,
    start_points,
    target_barrier,
    target_geometry,
)
from sailroute.routing.isochrone import (
    _backtrack,
    _check_start_time,
    _check_target_covered,
    _context,
    _root_layer,
    _route_on,
    _routing_polar,
    _timeout_error,
    check_leg_work,
)
from sailroute.routing.isochrone_inputs import _prepare, _step_length
from sailroute.routing.isochrone_kernel import _expand, _group_argmin, _survivors
from sailroute.routing.isochrone_polar import _device_tables, _DeviceTables, polar_tables
from sailroute.routing.isochrone_records import (
    _CHUNK_ELEMENTS,
    Groups,
    _Arrival,
    _Context,
    _Layer,
    _LegFrame,
)
from sailroute.routing.settings import RoutingSettings, check_settings
from sailroute.routing.track import make_leg_result
from sailroute.routing.types import LegResult, Start, Target
from sailroute.wind.base import Coverage, WindField

__all__ = ["batchable", "route_leg_batch"]


def batchable(settings: RoutingSettings, backend: str, currents: Sequence[object]) -> bool:
    """Whether :func:`~sailroute.planning.route.route_course_batch` can route these
    members: the isochrone router on NumPy, every member in still water (``currents`` all
    None)."""
    return (
        settings.router == "isochrone" and backend == "numpy" and all(c is None for c in currents)
    )


def route_leg_batch(
    start: Start | Sequence[Start],
    target: Target,
    t0s: Sequence[float],
    winds: Sequence[WindField],
    boat: BoatModel,
    settings: RoutingSettings,
    *,
    progress: Callable[[float], None] | None = None,
) -> list[LegResult]:
    """Fastest route of one leg for every member of an ensemble, as one front.

    Parameters
    ----------
    start : Start or sequence of Start
        The leg start of every member, or one per member.  The leg frame and the
        target geometry are those of the first member's start (see the module
        docstring for what that means for the others).
    target : Target
        Mark (with rounding side), gate or line: the same for every member.
    t0s : sequence of float
        Start time of each member [epoch s].
    winds : sequence of WindField
        Wind of each member (the same object may appear several times).
    boat : BoatModel
        The boat (its steady polar is routed, as by the isochrone router).
    settings : RoutingSettings
        Isochrone settings, the same for every member.
    progress : callable, optional
        Called with the fraction of members that have arrived, in [0, 1].

    Returns
    -------
    list of LegResult
        One per member, in the order given; each as
        :func:`~sailroute.routing.isochrone.route_isochrone` builds it.

    Raises
    ------
    InputError
        Members given in different numbers (starts, times, winds), no member, or
        what :func:`~sailroute.routing.isochrone.route_isochrone` refuses.
    RoutingError, OutOfCoverageError
        A member's leg cannot be routed (the first such member's error).
    """
    n = len(t0s)
    starts = [start] * n if isinstance(start, Start) else list(start)
    label = leg_label(starts[0] if starts else Start((0.0, 0.0)), target)
    if n == 0 or len(winds) != n or len(starts) != n:
        raise InputError(
            f"leg {label}: route_leg_batch needs one start time, one wind and (unless a "
            f"single start is given) one start per member; got {n} start times, "
            f"{len(winds)} winds and {len(starts)} starts"
        )
    check_settings(settings, label)
    polar = _routing_polar(boat, label)
    tab = polar_tables(polar, settings.isochrone.heading_step_deg)
    geom = target_geometry(target, starts[0], settings.zone_m)
    frame = _LegFrame.for_leg(geom.centre, start_centre(starts[0]))
    barriers = leg_barriers(starts[0], target)
    clearances = None
    if starts[0].barrier is not None:  # each member keeps its own clearance from the mark
        clearances = [
            barrier_clearance(dataclasses.replace(st, barrier=starts[0].barrier)) for st in starts
        ]
    ctxs = []
    for k, (t0, wind) in enumerate(zip(t0s, winds, strict=True)):
        _check_start_time(t0, label)
        own = barriers if clearances is None else ((barriers[0][0], clearances[k]), *barriers[1:])
        ctx = _context(label, float(t0), frame, geom, wind, settings, own)
        if ctx.box is not None:
            _check_target_covered(geom, ctx.box, wind, label)
        ctxs.append(ctx)
    leg = _Leg(
        target,
        settings,
        polar,
        frame,
        _device_tables(tab, np),
        int(tab.twa_deg.size),
        progress,
        n,
        target_barrier(target, starts[0], settings.zone_m),
    )
    members = [
        _Member(
            k,
            starts[k],
            winds[k],
            ctxs[k],
            start_points(starts[k], settings.start_line_spacing_m),
            None if clearances is None else clearances[k],
        )
        for k in range(n)
    ]
    results: dict[int, LegResult] = {}
    by_box: dict[Any, list[_Member]] = {}
    for m in members:  # one front per coverage box (the moves must stay in it)
        by_box.setdefault(m.ctx.box, []).append(m)
    for group in by_box.values():
        _route_front(group, leg, results)
    return [results[k] for k in range(n)]


# --------------------------------------------------------------------------------------
# the members and their common front


@dataclass(frozen=True, eq=False)
class _Leg:
    """What the members of a leg share."""

    target: Target
    settings: RoutingSettings
    polar: Any
    frame: _LegFrame
    dev: _DeviceTables
    n_angles: int
    progress: Callable[[float], None] | None
    n_members: int
    barrier: Any  # the rounding ray the legs end on (of the common target geometry)


@dataclass(eq=False)
class _Member:
    """One member: its inputs and the state of its route in the common front."""

    index: int
    start: Start
    wind: WindField
    ctx: _Context
    world_start: tuple[Any, Any]
    clearance: float | None  # from the mark of the start's barrier [m]; None: no barrier
    calm_since: float | None = None
    tau_hint: float = math.inf


@dataclass(frozen=True, eq=False)
class _Front:
    """One front of the common route: the layer, which member owns which points
    (``groups``, in the order of ``members``) and which points moved into it."""

    layer: _Layer
    members: tuple[_Member, ...]
    groups: Groups
    moved: Any = None
    blocks: dict[int, tuple[int, int]] = dataclasses.field(default_factory=dict)

    def __post_init__(self) -> None:
        if not self.members:
            return
        ends = [*self.groups.starts[1:].tolist(), int(self.layer.x.shape[0])]
        for m, lo, hi in zip(self.members, self.groups.starts.tolist(), ends, strict=True):
            self.blocks[m.index] = (lo, hi)

    def block(self, member: _Member) -> tuple[int, int]:
        """The points ``lo:hi`` of ``member`` (which must be in this front)."""
        return self.blocks[member.index]


class _MemberWinds:
    """The members' winds behind one ``sample`` call of the kernel.

    The kernel samples ``PATH_SAMPLES + 1`` rows of the ``n`` front points at once
    (:func:`~sailroute.routing.isochrone_inputs._sample_step`); each member's columns
    go to its own wind, clipped to its own coverage, in the order the single-member
    router passes them.  The coverage seen by the kernel is unbounded (each member's
    is applied here).
    """

    def __init__(self, front: _Front) -> None:
        self._front = front
        self.coverage = Coverage.everywhere()
        self.clamp = True

    def sample(self, t: Any, x: Any, y: Any) -> tuple[Any, Any]:
        f = self._front
        n = int(f.layer.x.shape[0])
        t, x, y = (np.asarray(a, dtype=float).reshape(-1, n) for a in (t, x, y))
        u = np.empty_like(t)
        v = np.empty_like(t)
        for m in f.members:
            lo, hi = f.block(m)
            cov = m.wind.coverage
            uu, vv = m.wind.sample(
                clip(t[:, lo:hi].ravel(), cov.t0, cov.t1),
                clip(x[:, lo:hi].ravel(), cov.xmin, cov.xmax),
                clip(y[:, lo:hi].ravel(), cov.ymin, cov.ymax),
            )
            u[:, lo:hi] = np.asarray(uu, dtype=float).reshape(-1, hi - lo)
            v[:, lo:hi] = np.asarray(vv, dtype=float).reshape(-1, hi - lo)
        return u.ravel(), v.ravel()


def _route_front(members: list[_Member], leg: _Leg, results: dict[int, LegResult]) -> None:
    """Route ``members`` (same coverage box) as one front until each has finished."""
    s = leg.settings
    x0, y0, t0 = [], [], []
    for m in members:
        wx, wy = m.world_start
        lx, ly = leg.frame.to_leg(np.asarray(wx), np.asarray(wy))
        x0.append(lx)
        y0.append(ly)
        t0.append(np.full(lx.shape[0], m.ctx.t0))
    sizes = [a.shape[0] for a in x0]
    root = _root_layer(np.concatenate(t0), np.concatenate(x0), np.concatenate(y0), s, np)
    history = [_Front(root, tuple(members), _groups(members, sizes))]
    dt = float(s.isochrone.dt_s)
    while history[-1].members:
        front = history[-1]
        # a member whose step shortens near the target finishes alone
        short = [m for m in front.members if _step_length(s, m.tau_hint) != dt]
        if short:
            _finish_alone(short, history, leg, results)
            continue
        ctx = front.members[0].ctx
        pre, tau_min, dist_min = _prepare(
            front.layer, _MemberWinds(front), leg.polar, leg.dev, ctx, s, math.inf, np, front.groups
        )
        near = np.logical_or.reduceat(pre.near_target, front.groups.starts)
        if near.any():  # the arrival is tested member by member
            _finish_alone(
                [m for m, k in zip(front.members, near, strict=True) if k], history, leg, results
            )
            continue
        out = _common_step(pre, front, ctx, leg)
        if isinstance(out, list):  # members without a survivor: their own error
            _finish_alone(out, history, leg, results)
            continue
        history.append(out)
        _after_step(front, out, tau_min, dist_min, leg)


def _groups(members: Sequence[_Member], sizes: Any) -> Groups:
    """The :class:`Groups` of ``members`` with ``sizes`` points each, with their
    clearances from the start's mark (if the leg starts at a rounded mark)."""
    clear = None if members[0].clearance is None else np.array([m.clearance for m in members])
    return Groups.of_sizes(sizes, clear)


def _common_step(pre: Any, front: _Front, ctx: _Context, leg: _Leg) -> _Front | list[_Member]:
    """Candidates, pruning per member and survivors of one common step (no arrival:
    the members within reach of the target have left).  Returns the new front, or the
    members left without a survivor."""
    n, n_columns = pre.n, pre.n_columns
    chunk = max(1, _CHUNK_ELEMENTS // (n_columns + 3))
    per_member = 2 * ctx.n_bins
    n_keys = per_member * len(front.members)
    best = np.full(n_keys, np.inf)
    who = np.zeros(n_keys, dtype=np.int64)
    for r0 in range(0, n, chunk):
        r1 = min(n, r0 + chunk)
        _, win = _expand(pre, r0, r1, leg.dev, ctx, np, want_winners=True)
        if win is None:
            continue
        key, score, wid = win
        better = score < best[key]
        best[key[better]] = score[better]
        who[key[better]] = wid[better]
    won = np.flatnonzero(best < np.inf)
    owner = won // per_member
    counts = np.bincount(owner, minlength=len(front.members))
    if not counts.all():
        return [m for m, c in zip(front.members, counts, strict=True) if c == 0]
    if (counts > ctx.max_points).any():  # widen the sectors of those members
        parts = []
        for k in range(len(front.members)):
            mine = won[owner == k]
            if mine.shape[0] > ctx.max_points:
                local = mine - k * per_member
                merge = -(-int(mine.shape[0]) // ctx.max_points)
                coarse = (local // 2 // merge) * 2 + local % 2
                mine = np.sort(mine[_group_argmin(coarse, best[mine], int(coarse.max()) + 1, np)])
            parts.append(mine)
        won = np.concatenate(parts)
        counts = np.bincount(won // per_member, minlength=len(front.members))
    wid = who[won]
    column = wid % n_columns
    block = (wid // n_columns) % 2
    row = wid // (2 * n_columns)
    layer, moved = _survivors(pre, row, block, column, best[won], leg.dev, np)
    return _Front(layer, front.members, _groups(front.members, counts), moved)


def _after_step(front: _Front, new: _Front, tau_min: Any, dist_min: Any, leg: _Leg) -> None:
    """Each member's calm clock, time to go, work check and time limit after a step."""
    s = leg.settings
    first_step = bool(np.all(front.layer.parent < 0))
    moved = np.logical_or.reduceat(new.moved, new.groups.starts)
    for k, m in enumerate(front.members):
        lo = int(new.groups.starts[k])
        t_new, t_old = float(new.layer.t[lo]), float(front.layer.t[front.block(m)[0]])
        if moved[k]:
            m.calm_since = None
        elif m.calm_since is None:
            m.calm_since = t_old
        m.tau_hint = float(tau_min[k]) - (t_new - t_old)
        if first_step:
            check_leg_work(m.ctx.label, s, m.ctx, leg.n_angles, m.tau_hint)
        elapsed = t_new - m.ctx.t0
        if elapsed >= s.max_leg_time_s:
            raise _timeout_error(m.ctx.label, s, elapsed, float(dist_min[k]), m.calm_since, t_new)


def _finish_alone(
    leaving: list[_Member], history: list[_Front], leg: _Leg, results: dict[int, LegResult]
) -> None:
    """Finish the legs of ``leaving`` one by one from their own fronts, and take them
    out of the common front (``history[-1]``)."""
    for m in leaving:
        layers = _own_layers(m, history)
        arrival = _route_on(
            layers,
            m.wind,
            leg.dev,
            m.ctx,
            leg.settings,
            leg.n_angles,
            np,
            polar=leg.polar,
            calm_since=m.calm_since,
            tau_hint=m.tau_hint,
        )
        results[m.index] = _result(m, layers, arrival, leg)
        if leg.progress is not None:
            leg.progress(len(results) / leg.n_members)
    front = history[-1]
    stay = tuple(m for m in front.members if m not in leaving)
    rows = (
        np.concatenate([np.arange(*front.block(m)) for m in stay])
        if stay
        else np.zeros(0, dtype=np.int64)
    )
    sizes = [front.block(m)[1] - front.block(m)[0] for m in stay]
    layer = _Layer(
        **{f.name: getattr(front.layer, f.name)[rows] for f in dataclasses.fields(_Layer)}
    )
    history[-1] = _Front(
        layer,
        stay,
        _groups(stay, sizes)
        if stay
        else Groups(np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)),
    )


def _own_layers(m: _Member, history: list[_Front]) -> list[_Layer]:
    """The fronts of member ``m`` alone, as the single-member router keeps them (its
    points, parents counted within its own previous front, a float time)."""
    out: list[_Layer] = []
    prev_lo = 0
    for front in history:
        lo, hi = front.block(m)
        lay = front.layer
        parent = lay.parent[lo:hi] - prev_lo if out else lay.parent[lo:hi]
        out.append(
            _Layer(
                t=float(lay.t[lo]),
                x=lay.x[lo:hi],
                y=lay.y[lo:hi],
                side=lay.side[lo:hi],
                debt=lay.debt[lo:hi],
                abs_twa=lay.abs_twa[lo:hi],
                pend_old=lay.pend_old[lo:hi],
                pend_pen=lay.pend_pen[lo:hi],
                parent=parent,
                heading=lay.heading[lo:hi],
                bsp=lay.bsp[lo:hi],
                delay=lay.delay[lo:hi],
                tau_est=lay.tau_est[lo:hi],
            )
        )
        prev_lo = lo
    return out


def _result(m: _Member, layers: list[_Layer], arrival: _Arrival, leg: _Leg) -> LegResult:
    """The member's :class:`LegResult`, as the single-member router assembles it."""
    track = _backtrack(layers, arrival, leg.frame, m.wind, leg.polar, m.world_start)
    return make_leg_result(track, "isochrone", leg.barrier)
