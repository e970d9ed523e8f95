"""Members of an ensemble routed as one isochrone front.

The members of a leg (wind scenarios or perturbed winds, start times, start points, and
boats) share the target, the settings and the surface current.  :func:`route_leg_batch`
puts all their fronts into one array front, the points of each member consecutive, and
steps it with the kernel of :mod:`sailroute.routing.isochrone_kernel` once per step for
all members: the fixed cost of a step is paid once, not once per member, and with
numba installed the step is compiled (:mod:`sailroute.routing.isochrone_fast`).  Per
member stay apart: the wind, the time, the pruning bins (each member keeps its own best
point per sector and side), the fan of headings, the polar (members with their own boat
read their own polar's rows of stacked tables,
:func:`~sailroute.routing.isochrone_polar.stacked_tables`), the arrival and the errors.
The winds of the members are sampled in one call per step where they are versions of
one wind (:func:`~sailroute.wind.perturbed.sample_perturbed`: the members of a leg-time
band), and the polars looked up in one call per step.

Each member steps its own length in the common front: ``dt_s``, shortened near the
target from its own time to go as the single-member router shortens it.  Where one of a
member's points can reach the target within its step, its own points are tested for the
crossing as the single-member router tests them; a member that arrives leaves the front
with its route.  A member left without a survivor finishes its leg alone, from its own
front, with the isochrone driver (and its error).  Every step a member takes is
therefore the step the single-member router takes, with the same numbers:

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

Array modules other than NumPy and race areas (obstacles) are routed one member at a
time (:func:`batchable`).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from sailroute.boat.model import BoatModel
from sailroute.boat.polar import Polar
from sailroute.errors import InputError
from sailroute.numerics import distinct_objects
from sailroute.routing import isochrone_fast as fast
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
    _arrival_move,
    _check_start_time,
    _check_target_covered,
    _context,
    _moves_back,
    _root_layer,
    _route_on,
    _routing_polar,
    _timeout_error,
    _track,
    check_leg_work,
)
from sailroute.routing.isochrone_inputs import _prepare, _step_length
from sailroute.routing.isochrone_kernel import _candidates, _group_argmin, _survivors
from sailroute.routing.isochrone_polar import (
    PointPolars,
    _device_tables,
    _DeviceTables,
    polar_tables,
    stacked_tables,
)
from sailroute.routing.isochrone_records import (
    Groups,
    _Arrival,
    _Context,
    _Layer,
    _LegFrame,
)
from sailroute.routing.isochrone_togo import _BIG_S
from sailroute.routing.settings import RoutingSettings, check_settings
from sailroute.routing.track import make_leg_result
from sailroute.routing.types import LegResult, Start, Target
from sailroute.wind.base import WindField
from sailroute.wind.current import CurrentField, RelativeWind
from sailroute.wind.perturbed import PerturbedWind, sample_perturbed

__all__ = ["batchable", "route_leg_batch"]


def batchable(settings: RoutingSettings, backend: str, currents: Sequence[object]) -> bool:
    """Whether :func:`~sailroute.planning.route.route_course_batch` can route these
    members: the isochrone router on NumPy, every member in still water or in one
    current (``currents``: each member's, the same object or None)."""
    return (
        settings.router == "isochrone"
        and backend == "numpy"
        and len({id(c) for c in currents}) <= 1
    )


def route_leg_batch(
    start: Start | Sequence[Start],
    target: Target,
    t0s: Sequence[float],
    winds: Sequence[WindField],
    boat: BoatModel | Sequence[BoatModel],
    settings: RoutingSettings,
    *,
    progress: Callable[[float, str], None] | None = None,
    current: CurrentField | None = None,
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
    boat : BoatModel or sequence of BoatModel
        The boat of every member, or one per member (its steady polar is routed, as by
        the isochrone router).
    settings : RoutingSettings
        Isochrone settings, the same for every member.
    progress : callable, optional
        Called with the estimated share of the leg done, in [0, 1] (the members' mean:
        time sailed over time sailed and time to go), and a note saying how many members
        have arrived (``progress(0.4, "37 of 100 members arrived")``; a
        :class:`~sailroute.progress.Progress` is such a callable).
    current : CurrentField, optional
        Surface current of every member (as :func:`~sailroute.routing.isochrone.
        route_isochrone` takes it); None: still water.

    Returns
    -------
    list of LegResult
        One per member, in the order given; each as
        :func:`~sailroute.routing.isochrone.route_isochrone` builds it.

    Raises
    ------
    InputError
        Members given in different numbers (starts, times, winds, boats), no member, or
        what :func:`~sailroute.routing.isochrone.route_isochrone` refuses.
    RoutingError, OutOfCoverageError
        A member's leg cannot be routed (the first such member's error).
    """
    n = len(t0s)
    starts = [start] * n if isinstance(start, Start) else list(start)
    boats = list(boat) if isinstance(boat, Sequence) else [boat] * n
    label = leg_label(starts[0] if starts else Start((0.0, 0.0)), target)
    if n == 0 or len(winds) != n or len(starts) != n or len(boats) != n:
        raise InputError(
            f"leg {label}: route_leg_batch needs one start time, one wind and (unless a "
            f"single one is given) one start and one boat per member; got {n} start "
            f"times, {len(winds)} winds, {len(starts)} starts and {len(boats)} boats"
        )
    check_settings(settings, label)
    # the different polars, in order of first use, and each member's
    polars, which = distinct_objects([_routing_polar(b, label) for b in boats])
    tabs = [polar_tables(p, settings.isochrone.heading_step_deg) for p in polars]
    geom = target_geometry(target, starts[0], settings.zone_m)
    frame = _LegFrame.for_leg(geom.centre, start_centre(starts[0]))
    barriers = leg_barriers(starts[0], target)
    clearances = None
    if starts[0].barrier is not None:  # each member keeps its own clearance from the mark
        clearances = [
            barrier_clearance(dataclasses.replace(st, barrier=starts[0].barrier)) for st in starts
        ]
    members = []
    for k, (t0, wind) in enumerate(zip(t0s, winds, strict=True)):
        _check_start_time(t0, label)
        own = barriers if clearances is None else ((barriers[0][0], clearances[k]), *barriers[1:])
        felt = wind if current is None else RelativeWind(wind, current)
        ctx = _context(label, float(t0), frame, geom, felt, settings, own, current)
        if ctx.box is not None:
            _check_target_covered(geom, ctx.box, felt, label)
        members.append(
            _Member(
                k,
                starts[k],
                felt,
                wind,
                int(which[k]),
                ctx,
                start_points(starts[k], settings.start_line_spacing_m),
                None if clearances is None else clearances[k],
            )
        )
    leg = _Leg(
        target,
        settings,
        tuple(polars),
        frame,
        _device_tables(tabs[0], np) if len(tabs) == 1 else stacked_tables(tabs),
        tuple(_device_tables(t, np) for t in tabs),
        int(tabs[0].twa_deg.size),
        progress,
        target_barrier(target, starts[0], settings.zone_m),
        current,
    )
    results: dict[int, LegResult] = {}
    fronts: dict[Any, list[_Member]] = {}
    for m in members:  # one front per coverage (the moves stay in it, the samples too)
        c = m.wind.coverage
        fronts.setdefault((c.t0, c.t1, c.xmin, c.xmax, c.ymin, c.ymax, m.ctx.box), []).append(m)
    for group in fronts.values():
        _route_front(group, leg, results)
    return [results[k] for k in range(n)]


# --------------------------------------------------------------------------------------
# the members and their common front


@dataclass(frozen=True, eq=False)
class _Leg:
    """What the members of a leg share."""

    target: Target
    settings: RoutingSettings
    polars: tuple[Polar, ...]  # the members' different polars
    frame: _LegFrame
    dev: _DeviceTables  # their tables (stacked_tables where there are several)
    devs: tuple[_DeviceTables, ...]  # each polar's own (a member finishing alone)
    n_angles: int
    progress: Callable[[float, str], None] | None
    barrier: Any  # the rounding ray the legs end on (of the common target geometry)
    current: CurrentField | None


@dataclass(eq=False)
class _Member:
    """One member: its inputs and the state of its route in the common front."""

    index: int
    start: Start
    wind: WindField  # the wind the boat feels (relative to the water in a current)
    true_wind: WindField  # its wind over the ground
    polar: int  # its polar, in _Leg.polars
    ctx: _Context
    world_start: tuple[Any, Any]
    clearance: float | None  # from the mark of the start's barrier [m]; None: no barrier
    calm_since: float | None = None
    tau_hint: float = math.inf
    done: float = 0.0  # share of its leg sailed (estimated, for progress)


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
    (:func:`~sailroute.routing.isochrone_inputs._sample_step`), clipped to the
    coverage the members share; each member's columns go to its own wind: with one
    ``sample`` call of their base for the members whose winds are versions of one wind
    (:func:`~sailroute.wind.perturbed.sample_perturbed`; on the compiled path its
    arithmetic in one compiled pass, ``jit``), else member by member; in a current, less
    the current (one call), as :class:`~sailroute.wind.current.RelativeWind` gives it.
    """

    def __init__(self, front: _Front, current: CurrentField | None, jit: bool) -> None:
        self._front = front
        self._current = current
        self._compiled = fast.kernels().perturbed_winds if jit else None
        self.coverage = front.members[0].wind.coverage
        self.clamp = front.members[0].wind.clamp
        bases: dict[int, list[int]] = {}  # members by the wind their winds perturb
        for k, m in enumerate(front.members):
            w = m.true_wind
            bases.setdefault(id(w.base if isinstance(w, PerturbedWind) else w), []).append(k)
        self._bases = list(bases.values())

    def sample(self, t: Any, x: Any, y: Any) -> tuple[Any, Any]:
        f = self._front
        t, x, y = (np.asarray(a, dtype=float).reshape(-1) for a in (t, x, y))
        rows = t.shape[0] // int(f.layer.x.shape[0])
        position = np.tile(f.groups.member, rows)  # each sample's member, in f.members
        u, v = np.empty_like(t), np.empty_like(t)
        for ks in self._bases:
            winds = [f.members[k].true_wind for k in ks]
            if len(ks) == len(f.members):  # one base: no gathering
                u, v = sample_perturbed(winds, position, t, x, y, compiled=self._compiled)
                continue
            local = np.full(len(f.members), -1, dtype=np.int64)
            local[ks] = np.arange(len(ks))
            idx = np.flatnonzero(local[position] >= 0)
            u[idx], v[idx] = sample_perturbed(
                winds, local[position[idx]], t[idx], x[idx], y[idx], compiled=self._compiled
            )
        if self._current is None:
            return u, v
        cu, cv = self._current.sample(t, x, y)
        return u - cu, v - cv


def _route_front(members: list[_Member], leg: _Leg, results: dict[int, LegResult]) -> None:
    """Route ``members`` (same coverage) as one front until each has finished."""
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
    while history[-1].members:
        front = history[-1]
        ctx = front.members[0].ctx
        jit = fast.compiled(s, np, members=len(front.members))
        winds = _MemberWinds(front, leg.current, jit)
        polar = _front_polar(front, leg)
        dt = _step_lengths(front, s)
        prepared = (
            fast.prepare(front.layer, winds, polar, leg.dev, ctx, s, math.inf, front.groups, dt)
            if jit
            else None
        )
        if prepared is None:
            prepared = _prepare(
                front.layer, winds, polar, leg.dev, ctx, s, math.inf, np, front.groups, dt
            )
        pre, tau_min, dist_min = prepared
        near = np.logical_or.reduceat(pre.near_target, front.groups.starts)
        arrivals: dict[int, _Arrival] = {}
        if near.any():  # the arrival member by member; the common step has none
            for k in np.flatnonzero(near).tolist():
                arrival = _arrival(pre, front, front.members[k], leg, jit)
                if arrival is not None:
                    arrivals[k] = arrival
            pre = pre._replace(near_target=np.zeros_like(pre.near_target))
        out = _common_step(pre, front, ctx, leg, jit)
        if isinstance(out, list):  # members without a survivor: their own error
            _finish_alone(out, history, leg, results)
            continue
        if arrivals:  # they leave: their routes end in this step
            for k, arrival in arrivals.items():
                m = front.members[k]
                results[m.index] = _result(m, history, [_own_front(m, front)], arrival, leg)
            left = np.zeros(len(front.members), dtype=bool)
            left[list(arrivals)] = True
            stay = tuple(m for m, gone in zip(front.members, left, strict=True) if not gone)
            history[-1] = _keep(front, stay)
            if not stay:
                continue
            out = _keep(out, stay, parents_in=front)
            front = history[-1]
            tau_min, dist_min = tau_min[~left], dist_min[~left]
        history.append(out)
        _after_step(front, out, tau_min, dist_min, leg)
        _report(members, results, leg)


def _arrival(pre: Any, front: _Front, m: _Member, leg: _Leg, jit: bool) -> _Arrival | None:
    """Whether member ``m``, one of whose points can reach the target within its step,
    arrives in this step: its candidates tested for the crossing as the single-member
    router tests them (its points ``pre`` prepared with the others, its own time and
    step length), the arrival or None."""
    lo, hi = front.block(m)
    own = pre.rows(lo, hi, np)
    dt = own.dt if isinstance(own.dt, float) else float(own.dt[0])
    own = own._replace(t=float(front.layer.t[lo]), dt=dt)
    arrival, _, _ = _candidates(own, leg.dev, m.ctx, np, jit)
    return arrival


def _step_lengths(front: _Front, s: RoutingSettings) -> float | Any:
    """The step length of the front's points [s]: ``dt_s``, or where a member's step
    shortens near the target (:func:`~sailroute.routing.isochrone_inputs._step_length`
    of its time to go), each point its member's."""
    own = [_step_length(s, m.tau_hint) for m in front.members]
    full = float(s.isochrone.dt_s)
    if all(d == full for d in own):
        return full
    return np.asarray(own)[front.groups.member]


def _report(members: list[_Member], results: dict[int, LegResult], leg: _Leg) -> None:
    """Tell ``leg.progress`` the share of the leg done and how many members arrived."""
    if leg.progress is None:
        return
    share = sum(1.0 if m.index in results else m.done for m in members) / len(members)
    arrived = sum(m.index in results for m in members)
    leg.progress(share, f"{arrived} of {len(members)} members arrived")


def _front_polar(front: _Front, leg: _Leg) -> Polar | PointPolars:
    """The polar of the front's points: the members' one, or each point's own."""
    if len(leg.polars) == 1:
        return leg.polars[0]
    own = np.array([m.polar for m in front.members], dtype=np.int64)
    return PointPolars(leg.polars, own[front.groups.member])


def _groups(members: Sequence[_Member], sizes: Any) -> Groups:
    """The :class:`Groups` of ``members`` with ``sizes`` points each, with their
    clearances from the start's mark (if the leg starts at a rounded mark)."""
    clear = None if members[0].clearance is None else np.array([m.clearance for m in members])
    return Groups.of_sizes(sizes, clear)


def _common_step(
    pre: Any, front: _Front, ctx: _Context, leg: _Leg, jit: bool
) -> _Front | list[_Member]:
    """Candidates, pruning per member and survivors of one common step (no arrival:
    the members within reach of the target have left); ``jit``: compiled
    (:mod:`~sailroute.routing.isochrone_fast`).  Returns the new front, or the members
    left without a survivor."""
    n_columns = pre.n_columns
    per_member = 2 * ctx.n_bins
    _, best, who = _candidates(pre, leg.dev, ctx, np, jit)
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
    if jit:
        layer, moved = fast.survivors(pre, row, block, column, best[won], leg.dev)
    else:
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
        sailed = t_new - m.ctx.t0
        m.done = sailed / (sailed + m.tau_hint) if 0.0 <= m.tau_hint < _BIG_S else 0.0
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
        _report(list(history[0].members), results, leg)
        layers = [_own_front(m, history[-1])]
        arrival = _route_on(
            layers,
            m.wind,
            leg.devs[m.polar],
            m.ctx,
            leg.settings,
            leg.n_angles,
            np,
            polar=leg.polars[m.polar],
            calm_since=m.calm_since,
            tau_hint=m.tau_hint,
            check_work=len(history) == 1,  # else checked after the first common step
        )
        results[m.index] = _result(m, history, layers, arrival, leg)
    history[-1] = _keep(history[-1], tuple(m for m in history[-1].members if m not in leaving))


def _rows(front: _Front, members: Sequence[_Member]) -> Any:
    """The points of ``members`` in ``front``, block after block."""
    if not members:
        return np.zeros(0, dtype=np.int64)
    return np.concatenate([np.arange(*front.block(m)) for m in members])


def _keep(front: _Front, stay: tuple[_Member, ...], parents_in: _Front | None = None) -> _Front:
    """``front`` with the points of the members ``stay`` only (in their order there);
    ``parents_in``: the front before, which keeps the same members too, its rows
    renumbered in the parents."""
    rows = _rows(front, stay)
    sizes = [front.block(m)[1] - front.block(m)[0] for m in stay]
    layer = _Layer(
        **{f.name: getattr(front.layer, f.name)[rows] for f in dataclasses.fields(_Layer)}
    )
    if parents_in is not None:
        kept = _rows(parents_in, stay)
        renumber = np.full(parents_in.layer.x.shape[0], -1, dtype=np.int64)
        renumber[kept] = np.arange(kept.shape[0])
        layer = dataclasses.replace(layer, parent=renumber[layer.parent])
    return _Front(
        layer,
        stay,
        _groups(stay, sizes)
        if stay
        else Groups(np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)),
        None if front.moved is None else front.moved[rows],
    )


def _own_front(m: _Member, front: _Front) -> _Layer:
    """The points of member ``m`` in ``front``, with a float time, as the single-member
    router keeps its fronts (``parent`` still indexes the common front before)."""
    lo, hi = front.block(m)
    own = {f.name: getattr(front.layer, f.name)[lo:hi] for f in dataclasses.fields(_Layer)}
    return _Layer(**{**own, "t": float(front.layer.t[lo])})


def _result(
    m: _Member, history: list[_Front], layers: list[_Layer], arrival: _Arrival, leg: _Leg
) -> LegResult:
    """The member's :class:`LegResult`, as the single-member router assembles it:
    the moves of ``layers`` (its own fronts from its last one in the common ``history``
    to ``arrival``), then those of the common fronts, which are followed by their
    rows (``history[k].layer.parent`` indexes the rows of ``history[k - 1]``)."""
    moves = [_arrival_move(arrival, layers[-1])]
    idx = _moves_back(layers, [lay.t for lay in layers], arrival.parent, moves)
    starts = [front.block(m)[0] for front in history]
    common = [front.layer for front in history]
    times = [float(lay.t[lo]) for lay, lo in zip(common, starts, strict=True)]
    row = _moves_back(common, times, starts[-1] + idx, moves)
    moves.reverse()
    polar = leg.polars[m.polar]
    track = _track(
        moves,
        row - starts[0],
        int(common[0].side[row]),
        arrival,
        leg.frame,
        m.wind,
        polar,
        m.world_start,
        leg.current,
    )
    return make_leg_result(track, "isochrone", leg.barrier)
