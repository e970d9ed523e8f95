"""Race analysis: a sailed track against the optimal route, leg by leg.

``analyze_track`` is where the layers meet (as :mod:`sailroute.planning.route` for routing):
the track (``sailroute.track``) is projected into the course frame, split into legs
(:mod:`sailroute.analysis.segment`), its tacks and gybes found
(:mod:`sailroute.analysis.manoeuvres`), and each leg is routed from the boat's own
leg start point and time to the same target in the scenario's wind
(:func:`sailroute.routing.api.route_leg`), then compared
(:mod:`sailroute.analysis.loss`); the results are :mod:`sailroute.analysis.result`.
A fleet is debriefed in three steps, so that its boats' optimal legs are routed together
(:func:`analyze_fleet`, :mod:`sailroute.analysis.optimal`): each track prepared
(:func:`prepare_debrief`), every leg routed for all boats, each boat finished
(:func:`finish_debrief`).
Nothing here prints or writes; :func:`sailroute.commands.analyze.run_analyze_command`
adds reading, file output and the terminal table.
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.analysis.fleet import fleet_ranking
from sailroute.analysis.legmode import source_leg_mode
from sailroute.analysis.loss import (
    LossSplit,
    axis_progress,
    lateral_offset,
    manoeuvre_mask,
    progress_loss,
    side_label,
    split_loss,
    time_mean,
)
from sailroute.analysis.manoeuvres import find_sailed_manoeuvres
from sailroute.analysis.optimal import OptimalLeg, leg_start, route_one, route_together
from sailroute.analysis.result import LegAnalysis, PointTable, TrackAnalysis
from sailroute.analysis.segment import (
    DETECT_M,
    Crossing,
    Segmentation,
    StartClock,
    leg_target,
    segment_track,
)
from sailroute.analysis.triage import BoatEntry, race_window_problem
from sailroute.analysis.windsource import WindSource, first_covering
from sailroute.course.geometry import feature_centre
from sailroute.course.load import build_specs, load_course
from sailroute.course.model import Course
from sailroute.errors import InputError, OutOfCoverageError
from sailroute.planning.route import default_scenario, settings_for
from sailroute.progress import Progress
from sailroute.routing.obstacles import Obstacles, constraint_label, obstacles_for
from sailroute.routing.settings import RoutingSettings
from sailroute.routing.types import LegResult
from sailroute.track.kinematics import track_xy, velocity
from sailroute.track.model import Track
from sailroute.track.read import read_track
from sailroute.units import (
    KNOT,
    bearing_deg,
    signed_twa,
    wind_components,
    wind_speed_direction,
)
from sailroute.wind.base import WindField
from sailroute.wind.combine import SpeedDirectionWind
from sailroute.wind.uniform import UniformWind

if TYPE_CHECKING:  # pragma: no cover
    from sailroute.analysis.fleetpolar import FleetPolar
    from sailroute.boat.polar import Polar

BRIDGE_S = 1e9
"""Hole limit of the measured winds the routers sample [s]: no hole (see
:attr:`sailroute.analysis.windsource.WindSource.route_field`)."""
DONE_LINE_S = 2.0
"""Least time between two ``boat k of N done`` lines of a fleet's debrief [s]."""
REFERENCES = ("course", "fleet", "learned")
"""Values of ``analyze --reference``: the course's polar, it scaled to the fleet, or the
polar learned from the fleet (:mod:`sailroute.analysis.fleetlearn`)."""
SMOOTH_S = 3.0
"""Window of the velocity smoothing used for COG, TWA and the manoeuvre detection [s]."""


def check_same_race(course: Course, track: Track, x: NDArray, y: NDArray) -> None:
    """Refuse a track from another day or place than the course and its wind.

    Raises
    ------
    InputError
        No track point inside the race window ``[start_time, gun + time_limit]``, or
        none of them within :data:`~sailroute.analysis.triage.NEAR_COURSE_M` of a mark
        (:func:`~sailroute.analysis.triage.race_window_problem`).
    """
    problem = race_window_problem(course, track, x, y)
    if problem is not None:
        raise InputError(f"{track.source}: {problem}")


def _smoothed_velocity(t: NDArray, x: NDArray, y: NDArray) -> tuple[NDArray, NDArray]:
    vx, vy = velocity(t, x, y)
    if t.size < 3:
        return vx, vy
    cx = np.concatenate([[0.0], np.cumsum(vx)])
    cy = np.concatenate([[0.0], np.cumsum(vy)])
    lo = np.searchsorted(t, t - 0.5 * SMOOTH_S, side="left")
    hi = np.searchsorted(t, t + 0.5 * SMOOTH_S, side="right")
    n = np.maximum(hi - lo, 1)
    return (cx[hi] - cx[lo]) / n, (cy[hi] - cy[lo]) / n


def _wind_at(wind: WindField, t: NDArray, x: NDArray, y: NDArray) -> tuple[NDArray, NDArray]:
    u, v = wind.sample(t, x, y)
    return wind_speed_direction(u, v)


def analyze_track(
    course: Course,
    track: Track,
    scenario: str | None = None,
    *,
    leg_times: Sequence[float | None] | None = None,
    router: str | None = None,
    detect_m: float = DETECT_M,
    built: tuple[Any, WindField] | None = None,
    winds: Sequence[WindSource] | None = None,
    progress: Progress | None = None,
    missing: str = "error",
    gate_end: str = "line",
    wind: str = "auto",
    segmentation: Segmentation | None = None,
    clock: StartClock | None = None,
) -> TrackAnalysis:
    """Analyse a sailed track against the optimal route of each leg.

    Parameters
    ----------
    course : Course
        The course sailed (marks, legs, start time = the gun, boat, wind scenarios).
    track : Track
        The boat's track (:func:`sailroute.track.read.read_track`).
    scenario : str, optional
        Wind scenario (default: the course's first).
    leg_times : sequence of float or None, optional
        ``n_legs + 1`` boundary times [epoch s] overriding the detection (None
        entries are detected).
    router : str, optional
        Overrides the course's router.
    detect_m : float
        Rounding-ray length for mark detection [m].
    built : (boat, wind), optional
        Already built boat and scenario wind (a fleet shares them).
    winds : sequence of WindSource, optional
        Candidate winds, best first (:func:`sailroute.analysis.windsource.wind_order`);
        each leg is judged in the first that covers it.  Default: those ``wind`` chooses
        for this track (:func:`analysis_winds`).
    progress : Progress, optional
        Per-leg progress of the optimal routing.
    missing : {"error", "unknown"}
        A leg end never found: an error (one boat), or that leg and the later ones
        unknown with a note (a fleet; :func:`sailroute.analysis.segment.segment_track`).
    gate_end : {"line", "rounding"}
        A gate leg ends passing between the marks, or having rounded the chosen mark
        (:func:`sailroute.analysis.segment.gate_rounding`; the optimal leg still ends at
        the gate line, so the leg's loss then includes that turn).
    wind : {"auto", "measured", "inferred", "scenario"}
        The candidate winds when ``winds`` is not given, as ``sailroute analyze
        --wind``: ``auto`` (default, as the command) the track's own measured wind, then
        the direction inferred from the track, then the scenario; ``scenario`` the
        scenario's wind alone.
    segmentation : Segmentation, optional
        The track's start and leg ends, already found (a fleet's triage,
        :func:`sailroute.analysis.triage.triage_fleet`): the track is then not checked
        against the race window nor segmented again (``leg_times``, ``detect_m``,
        ``missing`` and ``gate_end`` are not used).
    clock : StartClock, optional
        The gun and start line (:func:`sailroute.analysis.segment.find_start`; default
        the course's gun and surveyed line).

    Returns
    -------
    TrackAnalysis

    Raises
    ------
    InputError
        Track from another day/place, a leg that is never completed or a mark
        rounded on the wrong side, bad leg times, bad scenario/specs.
    OutOfCoverageError
        The scenario's wind does not cover the track.
    RoutingError
        An optimal leg cannot be routed.
    """
    prep = prepare_debrief(
        course,
        track,
        scenario,
        leg_times=leg_times,
        router=router,
        detect_m=detect_m,
        built=built,
        winds=winds,
        missing=missing,
        gate_end=gate_end,
        wind=wind,
        segmentation=segmentation,
        clock=clock,
    )
    routed = [
        None
        if leg is None
        else route_one(course, leg, prep.sources, prep.boat, prep.settings, progress)
        for leg in prep.optimal
    ]
    return finish_debrief(prep, routed)


def analyze_fleet(
    prepared: Sequence[PreparedDebrief], progress: Progress | None = None
) -> list[TrackAnalysis]:
    """The debriefs of a fleet's prepared tracks (:func:`prepare_debrief`, one boat and
    course): each leg's optimal routes of all boats routed as one front
    (:func:`sailroute.analysis.optimal.route_together`), then each boat completed.

    ``progress`` counts the boats: the legs routed together (share of the leg done, boats
    arrived, the time left of the routing), then ``boat k of N done`` while the boats are
    completed (a line every :data:`DONE_LINE_S` and the last).
    """
    if not prepared:
        return []
    first = prepared[0]
    n = len(prepared)
    if progress is not None:
        progress.set_prefix("")
        progress.start_count(n, "boat", together=True)
    routed = route_together(
        first.course,
        [p.optimal for p in prepared],
        [p.sources for p in prepared],
        first.boat,
        first.settings,
        progress,
    )
    if progress is not None:
        progress.start_count(n, "boat")
    last = time.perf_counter()
    out = []
    for k, (p, r) in enumerate(zip(prepared, routed, strict=True)):
        out.append(finish_debrief(p, r))
        now = time.perf_counter()
        if progress is not None and (k + 1 == n or now - last >= DONE_LINE_S):
            progress.item_done(k + 1, p.track.name)
            last = now
    return out


@dataclass(frozen=True)
class PreparedDebrief:
    """A track made ready for its debrief: all but the optimal legs
    (:func:`prepare_debrief`; :func:`finish_debrief` completes it).

    Attributes
    ----------
    course, track, scenario
        The course, the track, the wind scenario's name.
    settings, boat, design
        The routing settings, the boat and the scenario's wind.
    sources : tuple of WindSource
        The candidate winds, best first.
    t, x, y : arrays
        The track's fixes [epoch s] in the course frame [m].
    seg : Segmentation
        Its start and leg ends.
    svx, svy : arrays
        The smoothed velocity [m/s].
    chosen : tuple of int
        Per leg, the source it is judged in.
    manoeuvres : tuple of SailedManoeuvre
        The tacks and gybes over the race.
    optimal : tuple of OptimalLeg or None
        Per leg, the optimal route to compute (None: the leg's start is unknown).
    area_notes : tuple of str
        Per leg, the note of a start inside the race area's clearances (or "").
    """

    course: Course
    track: Track
    scenario: str
    settings: RoutingSettings
    boat: Any
    design: WindField
    sources: tuple[WindSource, ...]
    t: NDArray
    x: NDArray
    y: NDArray
    seg: Segmentation
    svx: NDArray
    svy: NDArray
    chosen: tuple[int, ...]
    manoeuvres: tuple[Any, ...]
    optimal: tuple[OptimalLeg | None, ...]
    area_notes: tuple[str, ...]


def prepare_debrief(
    course: Course,
    track: Track,
    scenario: str | None = None,
    *,
    leg_times: Sequence[float | None] | None = None,
    router: str | None = None,
    detect_m: float = DETECT_M,
    built: tuple[Any, WindField] | None = None,
    winds: Sequence[WindSource] | None = None,
    missing: str = "error",
    gate_end: str = "line",
    wind: str = "auto",
    segmentation: Segmentation | None = None,
    clock: StartClock | None = None,
    xy: tuple[NDArray, NDArray] | None = None,
) -> PreparedDebrief:
    """Everything :func:`analyze_track` does before routing the optimal legs (the same
    parameters): the track projected and segmented, each leg's wind, the manoeuvres and
    the optimal legs to route (:class:`~sailroute.analysis.optimal.OptimalLeg`).
    ``xy``: the track's fixes already in the course frame [m] (a fleet's triage,
    :attr:`~sailroute.analysis.triage.BoatEntry.xy`); default: projected here.

    Raises
    ------
    InputError, OutOfCoverageError
        As :func:`analyze_track`.
    """
    name = default_scenario(course) if scenario is None else scenario
    settings: RoutingSettings = settings_for(course, router)
    if built is None:
        boat, scenario_winds = build_specs(course, [name])
        scen_wind = scenario_winds[name]
    else:
        boat, scen_wind = built
    if winds:
        sources = list(winds)
    else:
        by_track, _ = analysis_winds(course, [track], name, scen_wind, boat, wind)
        sources = by_track[track.name]
    # the optimal legs keep inside the boundary and round the obstacles, as plan's do
    obstacles = obstacles_for(course.area, scen_wind)
    where = f"{track.source or track.name}"
    x, y = xy if xy is not None and xy[0].size == len(track) else track_xy(track, course.frame)
    t = track.t_s
    if segmentation is None:
        check_same_race(course, track, x, y)
        seg = segment_track(
            course,
            t,
            x,
            y,
            leg_times=leg_times,
            detect_m=detect_m,
            where=where,
            missing=missing,
            gate_end=gate_end,
            clock=clock,
        )
    else:
        seg = segmentation
    svx, svy = _smoothed_velocity(t, x, y)
    bounds = seg.bounds
    t_a = bounds[0].t
    t_b = max(c.t_hi for c in bounds if np.isfinite(c.t_hi))
    race = (t >= t_a) & (t <= t_b)
    # each leg's wind: the first source that covers its sailed points
    chosen = [
        _leg_source(
            sources,
            *_leg_points(t, x, y, bounds[i], bounds[i + 1]),
            f"{where}: leg {i + 1} ({spec.label})",
            strict=bounds[i].known and bounds[i + 1].known,
        )
        for i, spec in enumerate(course.legs)
    ]
    # manoeuvres over the race part, with TWA from the smoothed COG
    tr, xr, yr = t[race], x[race], y[race]
    twd_r = np.full(tr.size, np.nan)
    for i, ks in enumerate(chosen):
        m = (tr >= bounds[i].t_hi) & (tr <= bounds[i + 1].t_lo)
        twd_r[m] = _wind_at(sources[ks].field, tr[m], xr[m], yr[m])[1]
    gap = np.isnan(twd_r)  # across a data gap at a leg end: the last leg's wind before it
    if gap.any():
        twd_r[gap] = (
            np.degrees(np.interp(tr[gap], tr[~gap], np.unwrap(np.radians(twd_r[~gap])))) % 360.0
            if (~gap).any()
            else 0.0
        )
    mans, _ = find_sailed_manoeuvres(
        tr, twd_r, bearing_deg(svx[race], svy[race]), np.hypot(svx[race], svy[race])
    )
    optimal: list[OptimalLeg | None] = []
    area_notes: list[str] = []
    for i, spec in enumerate(course.legs):
        a, b = bounds[i], bounds[i + 1]
        if not a.known:
            optimal.append(None)
            area_notes.append("")
            continue
        if b.known:  # routed in the leg's wind, then in the next covering its points
            k, pts = chosen[i], _leg_points(t, x, y, a, b)
        else:  # in the first wind from the leg's own on that covers its start
            pts = (np.array([a.t]), np.array([a.x]), np.array([a.y]))
            found = first_covering(sources, *pts, skip=chosen[i] - 1)
            k = len(sources) - 1 if found is None else found
        leg_obstacles, area_note = _leg_area(obstacles, (a.x, a.y), spec.label)
        start = leg_start(course, i, bounds, settings)
        optimal.append(OptimalLeg(i, start, a.t, k, pts, leg_obstacles))
        area_notes.append(area_note)
    return PreparedDebrief(
        course,
        track,
        name,
        settings,
        boat,
        scen_wind,
        tuple(sources),
        t,
        x,
        y,
        seg,
        svx,
        svy,
        tuple(chosen),
        tuple(mans),
        tuple(optimal),
        tuple(area_notes),
    )


def prepare_fleet(
    course: Course,
    entries: Sequence[BoatEntry],
    scenario: str,
    built: tuple[Any, WindField],
    sources: Mapping[str, Sequence[WindSource]],
    *,
    router: str | None = None,
) -> list[PreparedDebrief]:
    """:func:`prepare_debrief` for each track of a fleet's triage
    (:func:`~sailroute.analysis.triage.triage_fleet`: ``entries``, those with a track),
    with the segmentation and the projection the triage found, judged in ``sources``
    (per boat name, :func:`analysis_winds`)."""
    return [
        prepare_debrief(
            course,
            e.track,
            scenario,
            router=router,
            built=built,
            winds=sources[e.name],
            segmentation=e.segmentation,
            xy=e.xy,
        )
        for e in entries
        if e.track is not None
    ]


def finish_debrief(
    prep: PreparedDebrief, routed: Sequence[tuple[LegResult, WindSource] | None]
) -> TrackAnalysis:
    """The debrief of a prepared track (:func:`prepare_debrief`) given its optimal legs
    (``routed``: per leg, the route and the wind it was routed in; None where
    :attr:`PreparedDebrief.optimal` is None): the legs compared and the point table."""
    course, t, x, y = prep.course, prep.t, prep.x, prep.y
    svx, svy, sources, chosen = prep.svx, prep.svy, prep.sources, prep.chosen
    bounds, boat, settings, mans = prep.seg.bounds, prep.boat, prep.settings, prep.manoeuvres

    legs: list[LegAnalysis] = []
    cols: dict[str, list[NDArray]] = {k: [] for k in _POINT_COLUMNS}
    loss_before = 0.0
    for i, spec in enumerate(course.legs):
        a, b = bounds[i], bounds[i + 1]
        tl, xl, yl = _leg_points(t, x, y, a, b)
        vx = np.interp(tl, t, svx)
        vy = np.interp(tl, t, svy)
        sog = np.hypot(vx, vy)
        cog = bearing_deg(vx, vy)
        chosen_field = sources[chosen[i]].field
        tws, twd = _wind_at(chosen_field, tl, xl, yl)
        twa = signed_twa(twd, cog)
        polar = np.asarray(boat.speed(tws, np.abs(twa)), float)
        ratio = np.where(polar >= 0.3, sog / np.where(polar > 0, polar, 1.0), np.nan)
        target = leg_target(course, i)
        centre = (
            target.centre if target.kind != "mark" else feature_centre(course.feature(spec.to_name))
        )
        if not (a.known and b.known):
            leg = _unknown_leg(
                course,
                i,
                bounds,
                sources[ask.k if (ask := prep.optimal[i]) is not None else chosen[i]],
                routed[i],
                centre,
                prep.area_notes[i],
                design=prep.design,
            )
            legs.append(leg)
            unknown = np.full(tl.size, np.nan)
            _add_points(cols, i, tl, xl, yl, sog, cog, tws, twd, twa, polar, unknown, unknown)
            continue
        src = sources[chosen[i]]
        mode = source_leg_mode(course, i, src, prep.design, a.t, (a.x, a.y), centre).mode
        if mode == "upwind":
            vmg = sog * np.cos(np.radians(twa))
        elif mode == "downwind":
            vmg = -sog * np.cos(np.radians(twa))
        else:
            ux, uy = centre[0] - xl, centre[1] - yl
            vmg = (vx * ux + vy * uy) / np.maximum(np.hypot(ux, uy), 1e-9)
        # the optimal route from the same point and time
        got = routed[i]
        assert got is not None  # a known leg start: routed
        opt, src = got
        area_note = prep.area_notes[i]
        sailed = b.t - a.t
        loss = sailed - opt.time_s
        prog = axis_progress(xl, yl, (a.x, a.y), centre)
        prog_o = axis_progress(opt.track.x, opt.track.y, (a.x, a.y), centre)
        cum = loss_before + progress_loss(tl - a.t, prog, opt.track.t - opt.t_start, prog_o)
        cum[-1] = loss_before + loss
        leg_mans = tuple(m for m in mans if a.t <= m.t < b.t)
        lm_t = np.array([m.t for m in leg_mans])
        penalty = opt.n_tacks * settings.tack_penalty_s + opt.n_gybes * settings.gybe_penalty_s
        split = split_loss(tl, prog, ratio, lm_t, loss, penalty)
        lat_s = time_mean(tl, lateral_offset(xl, yl, (a.x, a.y), centre))
        lat_o = time_mean(opt.track.t, lateral_offset(opt.track.x, opt.track.y, (a.x, a.y), centre))
        length = float(np.hypot(centre[0] - a.x, centre[1] - a.y))
        straight = ~manoeuvre_mask(tl, lm_t)
        legs.append(
            LegAnalysis(
                index=i,
                label=spec.label,
                mode=mode,
                t_start=a.t,
                t_end=b.t,
                start_xy=(a.x, a.y),
                end_xy=(b.x, b.y),
                detected=b.detected,
                sailed_time_s=sailed,
                optimal_time_s=opt.time_s,
                loss_s=loss,
                sailed_distance_m=float(np.sum(np.hypot(np.diff(xl), np.diff(yl)))),
                optimal_distance_m=opt.distance_m,
                sailed_tacks=sum(m.kind == "tack" for m in leg_mans),
                sailed_gybes=sum(m.kind == "gybe" for m in leg_mans),
                optimal_tacks=opt.n_tacks,
                optimal_gybes=opt.n_gybes,
                manoeuvres=leg_mans,
                mean_vmg_ms=time_mean(tl, vmg),
                mean_sog_ms=time_mean(tl, sog),
                mean_polar_pct=100.0 * time_mean(tl, np.clip(ratio, 0, 2), straight),
                split=split,
                side_sailed=side_label(lat_s, length),
                side_optimal=side_label(lat_o, length),
                lateral_sailed_m=lat_s,
                lateral_optimal_m=lat_o,
                optimal=opt,
                wind_source=src.kind,
                wind_label=src.label,
                note="; ".join(n for n in (b.note, area_note) if n),
            )
        )
        loss_before += loss
        _add_points(cols, i, tl, xl, yl, sog, cog, tws, twd, twa, polar, vmg, cum)
    c = {k: np.concatenate(v) if v else np.zeros(0) for k, v in cols.items()}
    lat, lon = course.frame.to_latlon(c["x"], c["y"])
    pct = np.where(c["polar"] >= 0.3, 100.0 * c["sog"] / np.maximum(c["polar"], 1e-9), np.nan)
    points = PointTable(
        c["leg"].astype(np.int64),
        c["t"],
        c["x"],
        c["y"],
        lat,
        lon,
        c["sog"],
        c["cog"],
        c["tws"],
        c["twd"],
        c["twa"],
        c["polar"],
        pct,
        c["vmg"],
        c["loss"],
    )
    return TrackAnalysis(
        course,
        prep.track,
        prep.scenario,
        settings.router,
        prep.seg,
        tuple(legs),
        points,
        sources[chosen[0]].field if chosen else prep.design,
    )


_POINT_COLUMNS = ("leg", "t", "x", "y", "sog", "cog", "tws", "twd", "twa", "polar", "vmg", "loss")
"""The point table's columns as :func:`analyze_track` gathers them, leg by leg."""


def _add_points(cols: dict[str, list[NDArray]], i: int, t: NDArray, *values: NDArray) -> None:
    """Append leg ``i``'s points to ``cols``: ``t`` and ``values`` in the order of
    :data:`_POINT_COLUMNS` after ``leg`` and ``t``."""
    full = (np.full(t.size, i + 1), t, *values)
    for k, v in zip(_POINT_COLUMNS, full, strict=True):
        cols[k].append(v)


def _leg_points(
    t: NDArray, x: NDArray, y: NDArray, a: Crossing, b: Crossing
) -> tuple[NDArray, NDArray, NDArray]:
    """The track points of one leg, with its start and end crossings (when known) as
    first and last; none inside a data gap an end lies in."""
    # the fixes strictly between the crossings; after a gap from its first fix on;
    # none when an end was never found (NaN)
    inner = ((t > a.t) if a.known else (t >= a.t_hi)) & ((t < b.t) if b.known else (t <= b.t_lo))
    ka, kb = [a] if a.known else [], [b] if b.known else []
    return (
        np.concatenate([[c.t for c in ka], t[inner], [c.t for c in kb]]),
        np.concatenate([[c.x for c in ka], x[inner], [c.x for c in kb]]),
        np.concatenate([[c.y for c in ka], y[inner], [c.y for c in kb]]),
    )


def _leg_source(
    sources: Sequence[WindSource],
    t: NDArray,
    x: NDArray,
    y: NDArray,
    where: str,
    strict: bool = True,
) -> int:
    """Index of the first source covering a leg; the last one's own error if none does
    (with ``strict`` False, a leg of unknown time: the last source)."""
    k = first_covering(sources, t, x, y)
    if k is None and not strict:
        return len(sources) - 1
    if k is None:
        try:
            sources[-1].field.sample(t, x, y)
        except OutOfCoverageError as exc:
            raise OutOfCoverageError(
                f"{where}: no wind covers the leg ({', '.join(s.label for s in sources)}): {exc}"
            ) from None
        raise OutOfCoverageError(f"{where}: no wind covers the leg") from None
    return k


def analysis_winds(
    course: Course,
    tracks: Sequence[Track],
    scenario: str,
    wind: WindField,
    boat: Any,
    choice: str = "auto",
    *,
    gun_t: float | None = None,
    race_end_t: float | None = None,
    xy: Sequence[tuple[NDArray, NDArray]] | None = None,
) -> tuple[dict[str, list[WindSource]], list[str]]:
    """The candidate winds each boat is judged in, best first, and what was found.

    * ``measured``: a boat's own log (:func:`sailroute.wind.measured.sensor_from_track`),
      when it has wind columns;
    * ``fleet``: with two or more logs with wind, all of them as one field
      (:func:`sailroute.wind.measured.fleet_wind`, each boat's bias removed);
    * ``inferred``: for tracks without instruments, the direction rebuilt from all the
      tracks of the run (:func:`sailroute.analysis.infer_wind.infer_wind`, the
      scenario's direction at the gun resolving upwind from downwind), with the
      scenario's speed (a polar that stands in for another class would turn the
      speeds on each board into a wrong wind speed);
    * ``scenario``: the course's.

    Parameters
    ----------
    course, tracks, scenario, wind, boat
        The course, the fleet's tracks, the scenario's name and wind, the boat.
    choice : str
        ``analyze --wind`` (:data:`sailroute.analysis.windsource.CHOICES`).
    gun_t : float, optional
        The gun [epoch s] (default the course's): the inferred wind starts a minute before.
    race_end_t : float, optional
        The race's end [epoch s] (a fleet's :attr:`~sailroute.analysis.triage.Triage.race_end_t`);
        default the last leg end found in any track.
    xy : sequence of (x, y) arrays, optional
        Each track's fixes already in the course frame [m], in the order of ``tracks``
        (a fleet's triage projected them); default: projected here.

    Returns
    -------
    sources : dict of str to list of WindSource
        Per track name, in the order :func:`~sailroute.analysis.windsource.wind_order` gives.
    notes : list of str
        One line per finding (biases, coverage, inferred direction, tracks without wind).

    Raises
    ------
    InputError
        ``--wind measured`` with no usable wind columns, ``--wind inferred`` when too
        few tacks and boards, an unknown choice.
    """
    from sailroute.analysis.windsource import CHOICES, wind_order

    if choice not in CHOICES:
        raise InputError(f"--wind: expected one of {', '.join(CHOICES)}; got {choice!r}")
    frame = course.frame
    notes: list[str] = []
    scen = WindSource("scenario", wind, f"scenario {scenario!r}")
    own: dict[str, WindSource] = {}
    fleet: WindSource | None = None
    series = {}
    if choice in ("auto", "measured"):
        from sailroute.wind.measured import boat_wind, fleet_wind, sensor_from_track

        without: dict[str, list[str]] = {}  # why -> boats: one note per reason
        for tr in tracks:
            try:
                series[tr.name] = sensor_from_track(tr)
            except InputError as exc:
                why = str(exc).removeprefix(f"{tr.source}: ")
                without.setdefault(why, []).append(tr.name)
                continue
            own[tr.name] = WindSource(
                "measured",
                boat_wind(series[tr.name], frame),
                f"measured on board ({series[tr.name].source})",
                route_field=boat_wind(series[tr.name], frame, max_gap_s=BRIDGE_S),
            )
        notes.extend(
            f"{', '.join(boats)}: no measured wind ({why})"
            if len(boats) < 4
            else f"no measured wind in {len(boats)} tracks ({why}): {', '.join(boats)}"
            for why, boats in without.items()
        )
        if len(series) >= 2:
            fw = fleet_wind(list(series.values()), frame)
            fleet = WindSource(
                "fleet",
                fw.field,
                f"measured by the fleet ({len(series)} boats, biases removed)",
                route_field=fleet_wind(list(series.values()), frame, max_gap_s=BRIDGE_S).field,
            )
            notes.extend(fw.notes)
            t0, t1 = course.start_epoch, course.gun_epoch + course.time_limit_s
            parts = []
            for k, tr in enumerate(tracks):
                m = (tr.t_s >= t0) & (tr.t_s <= t1)
                x, y = track_xy(tr, frame) if xy is None else xy[k]
                parts.append((tr.t_s[m], x[m], y[m]))
            t_all, x_all, y_all = (np.concatenate(c) for c in zip(*parts, strict=True))
            notes.append(
                fw.extrapolation_note(t_all, x_all, y_all, "the tracks in the race window")
            )
    inferred: WindSource | None = None
    if choice == "inferred" or (choice == "auto" and len(series) < len(tracks)):
        from sailroute.analysis.infer_wind import infer_wind, summary

        gun = course.gun_epoch if gun_t is None else gun_t
        cx = float(np.mean([m.x for m in course.marks.values()]))
        cy = float(np.mean([m.y for m in course.marks.values()]))
        tws0, twd0 = _wind_at(wind, np.array([gun]), np.array([cx]), np.array([cy]))
        try:
            inf = infer_wind(
                list(tracks),
                frame,
                prior_twd_deg=float(twd0[0]),
                boat=boat,
                t0=gun - 60.0,
                t1=_race_end(course, tracks) if race_end_t is None else race_end_t,
                marks=[m.xy for m in course.marks.values()],
                xy=xy,
            )
        except InputError as exc:
            if choice == "inferred":
                raise
            notes.append(f"wind not inferred from the tracks: {exc}")
        else:
            # held at its ends: an optimal route may run past the last tack of the fleet
            field = speed_direction_wind(
                wind, inf.field(frame, tws_ms=float(tws0[0]), clamp=True), "inferred wind"
            )
            sm = summary(inf)
            inferred = WindSource(
                "inferred",
                field,
                f"TWD inferred from {len(tracks)} track(s), TWS of scenario {scenario!r}",
                twd_sd=inf.sd_at,
            )
            notes.append(f"inferred wind: {_summary_text(sm)}")
    out: dict[str, list[WindSource]] = {}
    for tr in tracks:
        avail = [s for s in (own.get(tr.name), fleet, inferred, scen) if s is not None]
        out[tr.name] = wind_order(choice, avail)
    return out, notes


@dataclass(frozen=True, eq=False)
class SteadySpeedWind(SpeedDirectionWind):
    """A :class:`~sailroute.wind.combine.SpeedDirectionWind` whose ``speed_from`` is steady
    and uniform: its speed ``speed_ms`` [m s⁻¹] computed once, not sampled at every point
    (:func:`speed_direction_wind`)."""

    speed_ms: float = 0.0

    def sample(self, t: ArrayLike, x: ArrayLike, y: ArrayLike) -> tuple[NDArray, NDArray]:
        """Wind ``(u, v)`` [m s⁻¹]: the steady speed in the direction of
        ``direction_from`` at the points, as the parent class computes them."""
        du, dv = self.direction_from.sample(t, x, y)
        _, direction = wind_speed_direction(du, dv)
        return wind_components(self.speed_ms, direction)


def speed_direction_wind(
    speed_from: WindField, direction_from: WindField, name: str
) -> SpeedDirectionWind:
    """The speed of one wind with the direction of another: a
    :class:`SteadySpeedWind` where ``speed_from`` is a steady
    :class:`~sailroute.wind.uniform.UniformWind` (the same numbers, without sampling it at
    every point a router asks), else a :class:`~sailroute.wind.combine.SpeedDirectionWind`."""
    if isinstance(speed_from, UniformWind) and speed_from.times is None:
        u, v = speed_from.sample(np.zeros(1), np.zeros(1), np.zeros(1))
        speed, _ = wind_speed_direction(u, v)
        return SteadySpeedWind(speed_from, direction_from, name, float(speed[0]))
    return SpeedDirectionWind(speed_from, direction_from, name)


def _race_end(course: Course, tracks: Sequence[Track]) -> float:
    """The last leg end found in any of the tracks [epoch s] (the race window's end when
    none is): the wind is inferred over the race, not the sail home."""
    end = course.gun_epoch + course.time_limit_s
    found = []
    for tr in tracks:
        x, y = track_xy(tr, course.frame)
        try:
            seg = segment_track(course, tr.t_s, x, y, missing="unknown")
        except InputError:
            continue
        known = [c.t for c in seg.bounds[1:] if c.known]
        if known:
            found.append(max(known))
    return min(end, max(found) + 60.0) if found else end


def _summary_text(sm: Mapping[str, Any]) -> str:
    """``infer_wind``'s summary as one line."""
    if sm.get("twd_mean_deg") is None:
        return "no direction"
    text = (
        f"TWD {sm['twd_mean_deg']:.0f}° (range {sm['twd_range_deg']:.0f}°, shifts RMS "
        f"{sm['twd_shift_rms_deg']:.1f}°, median sd {sm['twd_sd_median_deg']:.1f}°)"
    )
    if sm.get("tws_mean_ms") is not None:
        text += (
            f"; TWS from the polar {sm['tws_mean_ms'] / KNOT:.1f} kn (not used: the "
            "scenario's speed is)"
        )
    return text + f", {sm['t_start']} .. {sm['t_end']}"


def _leg_area(
    obstacles: Obstacles | None, xy: tuple[float, float], label: str
) -> tuple[Obstacles | None, str]:
    """The race area a leg's optimal route keeps to, and a note when it cannot.

    A boat may sail inside a clearance (or over an obstacle a plan avoids); a leg that
    starts there has no optimal route inside the area, so its route ignores the area
    and the note says so (an error would lose the whole analysis for one leg).
    """
    if obstacles is None or bool(obstacles.points_free(xy[0], xy[1])):
        return obstacles, ""
    name = obstacles.nearest_name(xy[0], xy[1])
    what = constraint_label(name)
    return None, (
        f"leg {label} starts inside the clearance of {what} (or outside the boundary's): "
        "its optimal route ignores the race area"
    )


def _unknown_leg(
    course: Course,
    i: int,
    bounds: Sequence[Crossing],
    source: WindSource,
    routed: tuple[LegResult, WindSource] | None,
    centre: tuple[float, float],
    area_note: str,
    *,
    design: WindField | None = None,
) -> LegAnalysis:
    """A leg whose start or end time is unknown: no sailed time, loss or split; the
    optimal route when the start is known (``routed``: the route and the wind it was
    routed in; ``source``: the wind the leg is judged in, its mode from it)."""
    nan = float("nan")
    spec = course.legs[i]
    a, b = bounds[i], bounds[i + 1]
    opt = None
    mode = ""
    if routed is not None:
        mode = source_leg_mode(course, i, source, design, a.t, (a.x, a.y), centre).mode
        opt, source = routed
    note = (
        b.note
        if not b.known
        else f"leg {i + 1} ({spec.label}) starts at an unknown time "
        f"(leg {i} ended in a data gap): sailed time unknown"
    ) + (f"; {area_note}" if area_note else "")
    return LegAnalysis(
        index=i,
        label=spec.label,
        mode=mode,
        t_start=a.t,
        t_end=b.t,
        start_xy=(a.x, a.y),
        end_xy=(b.x, b.y),
        detected=b.detected,
        sailed_time_s=nan,
        optimal_time_s=opt.time_s if opt is not None else nan,
        loss_s=nan,
        sailed_distance_m=nan,
        optimal_distance_m=opt.distance_m if opt is not None else nan,
        sailed_tacks=0,
        sailed_gybes=0,
        optimal_tacks=opt.n_tacks if opt is not None else 0,
        optimal_gybes=opt.n_gybes if opt is not None else 0,
        manoeuvres=(),
        mean_vmg_ms=nan,
        mean_sog_ms=nan,
        mean_polar_pct=nan,
        split=LossSplit(nan, nan, nan, nan),
        side_sailed="",
        side_optimal="",
        lateral_sailed_m=nan,
        lateral_optimal_m=nan,
        optimal=opt,
        note=note,
        wind_source=source.kind,
        wind_label=source.label,
    )


def fleet_reference(analyses: Sequence[TrackAnalysis], reference: Polar) -> FleetPolar:
    """The fleet-relative polar (:func:`sailroute.analysis.fleetpolar.fleet_polar`) from
    tracks analysed against ``reference``: their straight-line points' TWA and SOG/polar."""
    from sailroute.analysis.fleetpolar import fleet_polar, straight_ratios

    samples = [
        straight_ratios(
            a.points.t,
            a.points.twa_deg,
            a.points.sog_ms,
            a.points.polar_ms,
            np.array([m.t for leg in a.legs for m in leg.manoeuvres]),
        )
        for a in analyses
    ]
    return fleet_polar(samples, reference, [a.track.name for a in analyses])


def parse_leg_times(text: str | None, n_legs: int) -> list[float | None] | None:
    """``--leg-times``: ``n_legs + 1`` comma-separated ISO times with offset, ``-`` to detect.

    Raises
    ------
    InputError
        Wrong count or a time without offset.
    """
    if text is None:
        return None
    from sailroute.timeutil import parse_time, to_epoch

    parts = [p.strip() for p in text.split(",")]
    if len(parts) != n_legs + 1:
        raise InputError(
            f"--leg-times: got {len(parts)} times for {n_legs} legs; give {n_legs + 1} "
            "comma-separated ISO times with offset (start crossing, then each leg's end), "
            "'-' for one to detect"
        )
    return [None if p in ("-", "") else to_epoch(parse_time(p, "--leg-times")) for p in parts]


def parse_boat_leg_times(
    items: str | Sequence[str] | None, boats: Sequence[str], n_legs: int
) -> dict[str, list[float | None] | None]:
    """``--leg-times`` for one track (``T0,T1,...``) or per boat (``BOAT=T0,T1,...``, repeated).

    Parameters
    ----------
    items : str or sequence of str or None
        The option's values.
    boats : sequence of str
        Boat names (track file stems, made unique), in track order.
    n_legs : int

    Returns
    -------
    dict
        Boat name to its ``n_legs + 1`` times [epoch s] (None entries detected), or None.

    Raises
    ------
    InputError
        A plain value with several tracks, an unknown boat (the message lists them),
        a boat given twice, or a bad time list (:func:`parse_leg_times`).
    """
    out: dict[str, list[float | None] | None] = dict.fromkeys(boats)
    values = [items] if isinstance(items, str) else list(items or [])
    seen: set[str] = set()
    for item in values:
        boat, sep, text = item.partition("=")
        if not sep:
            if len(boats) > 1:
                raise InputError(
                    f"--leg-times {item!r}: with several tracks name the boat, "
                    f"BOAT=T0,T1,... (boats: {', '.join(boats)})"
                )
            boat, text = boats[0], item
        boat = boat.strip()
        if boat not in out:
            raise InputError(
                f"--leg-times {item!r}: no track named {boat!r}; boats are "
                f"the track file names without extension: {', '.join(boats)}"
            )
        if boat in seen:
            raise InputError(f"--leg-times: boat {boat!r} given twice")
        seen.add(boat)
        try:
            out[boat] = parse_leg_times(text, n_legs)
        except InputError as exc:
            raise InputError(f"{exc} (boat {boat})" if len(boats) > 1 else str(exc)) from None
    return out


def load_and_analyze(
    course_path: str | Path, track_path: str | Path, scenario: str | None = None, **read_kw: Any
) -> TrackAnalysis:
    """Convenience: load a course, read a track, analyse (the Python API in one call)."""
    course = load_course(course_path)
    return analyze_track(course, read_track(track_path, **read_kw), scenario)


__all__ = [
    "LegAnalysis",
    "PointTable",
    "PreparedDebrief",
    "TrackAnalysis",
    "analysis_winds",
    "analyze_fleet",
    "analyze_track",
    "check_same_race",
    "finish_debrief",
    "fleet_ranking",
    "fleet_reference",
    "load_and_analyze",
    "parse_boat_leg_times",
    "parse_leg_times",
    "prepare_debrief",
    "prepare_fleet",
]
