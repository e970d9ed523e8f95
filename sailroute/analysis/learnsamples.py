"""A fleet's logs and tracks as samples for a learned polar, each in the wind it is judged in.

``sailroute polar fit LOG... [--course C]...`` learns a polar from whatever the fleet
recorded.  Every sample is taken in the wind ``sailroute analyze`` would judge it in:

* **without a course**, each log in its own measured wind
  (:func:`sailroute.wind.measured.sensor_from_track`: TWS/TWD, TWA with a heading, or
  apparent wind), over the whole log; a track without wind columns is refused;
* **with courses** (one per race), each race's part of each track (from its start to the
  end of its last leg found, :func:`sailroute.analysis.segment.segment_track`), leg by
  leg in the first wind source that covers the leg, in the order ``analyze`` uses
  (:func:`sailroute.analysis.debrief.analysis_winds`: the boat's own instruments, the
  fleet's, the direction inferred from the tracks with the scenario's speed, the
  scenario).  A track that did not sail a race is left out of it (noted).

Positions are projected into the course's frame (a frame at the log's mean position
without a course); the wind direction is in the same frame.

A :class:`~sailroute.progress.Progress` given as ``progress`` counts the boats, a line per
boat (``boat 3 of 12 done (NZL): 0.4 s elapsed, about 2.1 s left``; with several courses
``race 2 of 3, boat 3 of 12 done ...``, each race counted from its own start).  When a
boat has no instruments, the fleet's wind (its direction inferred from all the tracks) is
built before the boats are counted, with a line saying so, so that the time left counts
the boats only.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from sailroute.analysis.windsource import WindSource
from sailroute.boat.learn_blocks import BoatSeries
from sailroute.course.model import Course
from sailroute.errors import InputError
from sailroute.geo import LocalFrame
from sailroute.track.kinematics import track_xy
from sailroute.track.model import Track
from sailroute.units import wind_speed_direction

if TYPE_CHECKING:
    from sailroute.progress import Progress


@dataclass(frozen=True, eq=False)
class RaceLegs:
    """One boat's leg times in one race.

    Attributes
    ----------
    race, boat : str
    bounds : ndarray, shape (legs + 1,)
        The start crossing and each leg's end [epoch s] (NaN: not found).
    """

    race: str
    boat: str
    bounds: NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class FleetSamples:
    """The fleet's samples and what was found on the way.

    Attributes
    ----------
    series : tuple of BoatSeries
        One per boat and race.
    notes : tuple of str
        Tracks left out of a race, wind findings, legs without wind.
    legs : tuple of RaceLegs
        With courses: each boat's leg times in each race it sailed.
    """

    series: tuple[BoatSeries, ...]
    notes: tuple[str, ...]
    legs: tuple[RaceLegs, ...] = ()


def no_wind_message(track: Track, exc: Exception) -> str:
    """The one line for a track that has no wind and no course to take one from."""
    return (
        f"{track.source or track.name}: no wind in the log and no --course ({exc}); a GPS "
        "track is judged in a race's wind: give the race's course with --course COURSE "
        "(its scenario, or the wind inferred from the fleet's tracks)"
    )


def samples_from_logs(tracks: Sequence[Track], *, progress: Progress | None = None) -> FleetSamples:
    """Each log in its own measured wind, over the whole log (no course); ``progress``
    counts the boats (module docstring).

    Raises
    ------
    InputError
        A track without usable wind columns (:func:`no_wind_message`).
    """
    from sailroute.wind.measured import boat_wind, sensor_from_track

    out = []
    notes: list[str] = []
    if progress is not None:
        progress.start_count(len(tracks), "boat")
    for k, tr in enumerate(tracks):
        try:
            sensor = sensor_from_track(tr)
        except InputError as exc:
            raise InputError(no_wind_message(tr, exc)) from None
        frame = LocalFrame(float(np.mean(tr.lat_deg)), float(np.mean(tr.lon_deg)))
        x, y = track_xy(tr, frame)
        t = np.asarray(tr.t_s, float)
        ok = (t >= sensor.t[0]) & (t <= sensor.t[-1])
        for a, b in sensor.gaps:
            ok &= ~((t > a) & (t < b))
        field = boat_wind(sensor, frame)
        label = f"measured on board ({sensor.source})"
        tws, twd = _sample(field, t[ok], x[ok], y[ok])
        if (~ok).any():
            notes.append(f"{tr.name}: {int((~ok).sum())} samples in gaps of its wind left out")
        out.append(
            BoatSeries(
                tr.name,
                tr.source or tr.name,
                t[ok],
                x[ok],
                y[ok],
                tws,
                twd,
                np.zeros(int(ok.sum()), dtype=np.int64),
                (label,),
            )
        )
        if progress is not None:
            progress.item_done(k + 1, tr.name)
    return FleetSamples(tuple(out), tuple(notes))


def _sample(field: object, t: NDArray, x: NDArray, y: NDArray) -> tuple[NDArray, NDArray]:
    u, v = field.sample(t, x, y)  # type: ignore[attr-defined]
    tws, twd = wind_speed_direction(u, v)
    return np.asarray(tws, float), np.asarray(twd, float)


def _own_winds(tracks: Sequence[Track], course: Course) -> dict[str, WindSource]:
    """Each track's own measured wind, as ``analyze`` builds it first
    (:func:`sailroute.analysis.debrief.analysis_winds`); tracks without wind are left out."""
    from sailroute.analysis.debrief import BRIDGE_S
    from sailroute.wind.measured import boat_wind, sensor_from_track

    out = {}
    for tr in tracks:
        try:
            sensor = sensor_from_track(tr)
        except InputError:
            continue
        out[tr.name] = WindSource(
            "measured",
            boat_wind(sensor, course.frame),
            f"measured on board ({sensor.source})",
            route_field=boat_wind(sensor, course.frame, max_gap_s=BRIDGE_S),
        )
    return out


def samples_in_race(
    course: Course,
    tracks: Sequence[Track],
    scenario: str | None = None,
    *,
    progress: Progress | None = None,
    race: str = "",
) -> FleetSamples:
    """Each track's part of one race, leg by leg in the wind ``analyze`` would take.

    Parameters
    ----------
    course : Course
        The race (marks, legs, gun, scenarios).
    tracks : sequence of Track
        The fleet (logs with or without wind).
    scenario : str, optional
        The course's scenario (default its first): the wind of last resort, and the speed
        of an inferred direction.
    progress : Progress, optional
        Counts the boats sailing the race (module docstring); None: silent.
    race : str
        The race's place in the run (``"race 2 of 3"``), put before the lines' ``boat k
        of N``.

    Raises
    ------
    InputError
        An unknown scenario, or bad boat/wind specs of the course.
    """
    from sailroute.analysis.debrief import analysis_winds
    from sailroute.course.load import build_specs
    from sailroute.planning.route import default_scenario

    name = default_scenario(course) if scenario is None else scenario
    if name not in course.scenarios:
        raise InputError(
            f"--scenario: the course {course.source or course.name!r} has no scenario "
            f"{name!r}; its scenarios are: {', '.join(course.scenarios) or 'none'}"
        )
    boat, winds = build_specs(course, [name])
    t0, t1 = course.start_epoch, course.start_epoch + course.time_limit_s
    racing = [tr for tr in tracks if np.any((tr.t_s >= t0) & (tr.t_s <= t1))]
    notes = [
        f"{tr.name}: no fix in the race window of {course.name}: left out of it"
        for tr in tracks
        if tr not in racing
    ]
    own = _own_winds(racing, course)
    built: list[tuple[dict[str, list[WindSource]], list[str]]] = []
    used: list[bool] = []

    def fleet_winds() -> tuple[dict[str, list[WindSource]], list[str]]:
        if not built:
            built.append(analysis_winds(course, racing, name, winds[name], boat))
        return built[0]

    def candidates(tr: Track) -> list[WindSource]:
        # analyze's order; the fleet's and the inferred wind are built before the boats
        # when one has no instruments, else when a leg is not covered by a boat's own (the
        # first of that order); their findings join the notes where they are first used
        sources, found = fleet_winds()
        if not used:
            used.append(True)
            notes.extend(found)
        return sources[tr.name]

    where = f"{race}, " if race else ""
    if len(own) < len(racing):  # a pass over all the tracks: not in any boat's time
        if progress is not None:
            progress.note(
                f"{where}{course.name}: inferring the wind direction from the {len(racing)} "
                f"tracks ({len(racing) - len(own)} without instruments)"
            )
        fleet_winds()
    if progress is not None:
        progress.start_count(len(racing), f"{where}boat")
    out = []
    legs = []
    for k, tr in enumerate(racing):
        got = _race_series(course, tr, own.get(tr.name), candidates, notes)
        if got is not None:
            legs.append(got[0])
            if got[1] is not None:
                out.append(got[1])
        if progress is not None:
            progress.item_done(k + 1, tr.name)
    return FleetSamples(tuple(out), tuple(notes), tuple(legs))


def _race_series(
    course: Course,
    tr: Track,
    mine: WindSource | None,
    candidates: Callable[[Track], list[WindSource]],
    notes: list[str],
) -> tuple[RaceLegs, BoatSeries | None] | None:
    """One track's legs and samples in one race (:func:`samples_in_race`): each leg in its
    own wind ``mine`` where that covers it, else the first of ``candidates(tr)`` that does.
    None: not found sailing the race; no series: no leg with both ends and wind.  What is
    left out is added to ``notes``."""
    from sailroute.analysis.segment import segment_track
    from sailroute.analysis.windsource import covers, first_covering

    x, y = track_xy(tr, course.frame)
    t = np.asarray(tr.t_s, float)
    try:
        seg = segment_track(course, t, x, y, where=tr.name, missing="unknown")
    except InputError as exc:
        notes.append(f"{tr.name}: not found sailing {course.name} ({exc}): left out")
        return None
    labels: list[str] = []
    parts: list[tuple[NDArray, WindSource]] = []
    b = seg.bounds
    legs = RaceLegs(course.name, tr.name, np.array([c.t if c.known else np.nan for c in b]))
    for i in range(len(b) - 1):
        if not (b[i].known and b[i + 1].known):
            continue
        m = np.flatnonzero((t > b[i].t) & (t < b[i + 1].t))
        if m.size < 2:
            continue
        if mine is not None and covers(mine.field, t[m], x[m], y[m]):
            src: WindSource | None = mine
        else:
            srcs = candidates(tr)
            k = first_covering(srcs, t[m], x[m], y[m])
            src = None if k is None else srcs[k]
        if src is None:
            notes.append(f"{tr.name}: {course.name} leg {i + 1}: no wind covers it: left out")
            continue
        if src.label not in labels:
            labels.append(src.label)
        parts.append((m, src))
    if not parts:
        notes.append(f"{tr.name}: no leg of {course.name} with both ends found: left out")
        return legs, None
    idx = np.concatenate([m for m, _ in parts])
    which = np.concatenate(
        [np.full(m.size, labels.index(w.label), dtype=np.int64) for m, w in parts]
    )
    sampled = [_sample(w.field, t[m], x[m], y[m]) for m, w in parts]
    tws = np.concatenate([a for a, _ in sampled])
    twd = np.concatenate([d for _, d in sampled])
    return legs, BoatSeries(
        tr.name, course.name, t[idx], x[idx], y[idx], tws, twd, which, tuple(labels)
    )


def fleet_samples(
    tracks: Sequence[Track],
    courses: Sequence[Course] = (),
    scenario: str | None = None,
    *,
    progress: Progress | None = None,
) -> FleetSamples:
    """The fleet's samples: per race with courses, else each log in its own wind;
    ``progress`` counts the boats (of each race: ``race 2 of 3, boat 3 of 12``).

    Raises
    ------
    InputError
        Without courses, a track without wind; with courses, no track sailing any of them.
    """
    if not courses:
        return samples_from_logs(tracks, progress=progress)
    series: list[BoatSeries] = []
    notes: list[str] = []
    legs: list[RaceLegs] = []
    for r, c in enumerate(courses):
        race = f"race {r + 1} of {len(courses)}" if len(courses) > 1 else ""
        fs = samples_in_race(c, tracks, scenario, progress=progress, race=race)
        series += fs.series
        notes += fs.notes
        legs += fs.legs
    if not series:
        raise InputError(
            "no track sails any of the courses given ("
            + "; ".join(notes[:3])
            + "); check the tracks' times and the courses' start_time"
        )
    return FleetSamples(tuple(series), tuple(notes), tuple(legs))


__all__ = [
    "FleetSamples",
    "RaceLegs",
    "fleet_samples",
    "no_wind_message",
    "samples_from_logs",
    "samples_in_race",
]
