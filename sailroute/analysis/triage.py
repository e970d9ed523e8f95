"""Which boats of a fleet can be debriefed, and what is wrong with the others.

A fleet's tracks come from many devices and people: a file may be empty, the same data may
come twice, a track may be of another day or place or class, a boat may never start, start
late, retire or lose its data mid-race, a log may run on into the next race, a boat may pass
a gate outside its marks.  :func:`triage_fleet` finds each of these before the debrief and
gives every boat a :class:`BoatStatus` (data, not text); the fleet is debriefed without the
boats that cannot be, and each kind of finding becomes one note naming its boats
(:func:`class_notes`).  Nothing here raises for one boat.

Order (each step sees only the boats the earlier ones kept): unreadable or empty files;
tracks outside the race's time or place; duplicates; the start (the fleet's gun and line,
:mod:`sailroute.analysis.start`, after a general recall detected in the tracks when the
course gives no restart); each boat's legs (:func:`~sailroute.analysis.segment.segment_track`,
never raising); logs cut at a gap longer than the race's legs allow; boats sailing at another
fleet's pace; then each boat's own findings (no start, over early, late, retired, a gate
passed outside).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from enum import StrEnum

import numpy as np
from numpy.typing import NDArray

from sailroute.analysis.segment import (
    DETECT_M,
    LegIssue,
    Segmentation,
    gap_limit_s,
    segment_track,
)
from sailroute.analysis.start import (
    MIN_FLEET,
    PULSE_S,
    RECALL_BEFORE_S,
    RECALL_WINDOW_S,
    FleetStart,
    GeneralRecall,
    detect_general_recall,
    estimate_fleet_start,
    observe_start,
)
from sailroute.course.model import Course
from sailroute.timeutil import iso
from sailroute.track.kinematics import track_xy
from sailroute.track.model import Track

__all__ = [
    "BoatClass",
    "BoatEntry",
    "BoatStatus",
    "Finding",
    "Triage",
    "class_notes",
    "cut_at_gaps",
    "race_window_problem",
    "triage_fleet",
]

NEAR_COURSE_M = 3000.0
"""During the race the track must come this close to a mark [m], or it is another place."""

PRESTART_S = 3600.0
"""A track that ends less than this before the gun [s] is of the race's day: its boat did
not start (a track that ends earlier is of another day or time)."""

DUPLICATE_M = 1.0
"""Two tracks whose positions at the same times lie within this of each other [m] (median
over the race window, overlapping for :data:`DUPLICATE_OVERLAP` of the shorter one) are the
same data: boats racing do not sail within a few metres of each other for a race."""

DUPLICATE_OVERLAP = 0.9
"""Share of the shorter track's race window two tracks must overlap to be compared."""

RACE_GAP_FACTOR = 4.0
"""A gap in a track longer than this many times the race's typical leg (the median over the
legs of the fleet's median leg time) cannot lie inside one race: the log is cut there and
the data beyond it (another race, the next day) are dropped."""

PACE_FACTOR = 2.0
"""A boat whose legs take more than this many times the fleet's median for the same legs
(or less than its inverse) sails at another fleet's pace (needs :data:`PACE_MIN_BOATS`);
so does one far outside the fleet's own spread (:data:`PACE_Z`)."""

PACE_MIN_BOATS = 4
"""Boats with timed legs needed before a boat's pace is compared with the fleet's."""

PACE_Z = 4.0
"""A boat whose pace (:data:`PACE_FACTOR`) lies this many robust standard deviations (1.4826
median absolute deviations of the fleet's log pace) from the fleet's median, and more than
:data:`PACE_MIN_FACTOR` off it, sails at another fleet's pace."""

PACE_MIN_FACTOR = 1.15
"""Smallest pace difference from the fleet's median called another fleet's (a one-design
fleet's pace spread can be tiny)."""


class BoatClass(StrEnum):
    """What triage found about a boat (:class:`Finding`)."""

    EMPTY = "empty or unreadable track"
    DUPLICATE = "duplicate track"
    OTHER_FLEET = "another fleet"
    NON_STARTER = "did not start"
    OCS = "over early at the gun (OCS)"
    OCS_RETURNED = "over early, came back and started"
    LATE_START = "late start"
    DATA_GAP = "data gap during the race"
    MULTI_RACE = "log spans more than the race"
    RETIRED = "retired or data end mid-race"
    GATE_OUTSIDE = "gate passed outside its marks"

    @property
    def analysed(self) -> bool:
        """A boat with this finding is debriefed."""
        return self not in _NOT_ANALYSED

    @property
    def ranked(self) -> bool:
        """A boat with this finding keeps a place in the results (its leg times are ranked
        as long as it is analysed)."""
        return self not in _NOT_RANKED


_NOT_ANALYSED = frozenset(
    {BoatClass.EMPTY, BoatClass.DUPLICATE, BoatClass.OTHER_FLEET, BoatClass.NON_STARTER}
)
_NOT_RANKED = _NOT_ANALYSED | {BoatClass.OCS, BoatClass.RETIRED, BoatClass.GATE_OUTSIDE}


@dataclass(frozen=True)
class Finding:
    """One finding about a boat.

    Attributes
    ----------
    kind : BoatClass
    detail : str
        The boat's own numbers or reason, short (goes after its name in the class note).
    """

    kind: BoatClass
    detail: str = ""


@dataclass(frozen=True)
class BoatStatus:
    """Everything triage found about one boat (no finding: a clean race)."""

    findings: tuple[Finding, ...] = ()

    @property
    def classes(self) -> tuple[BoatClass, ...]:
        """The kinds found, in order."""
        return tuple(f.kind for f in self.findings)

    @property
    def analysed(self) -> bool:
        """The boat is debriefed."""
        return all(k.analysed for k in self.classes)

    @property
    def ranked(self) -> bool:
        """The boat has a place in the results."""
        return all(k.ranked for k in self.classes)

    def has(self, kind: BoatClass) -> bool:
        """True when ``kind`` was found."""
        return kind in self.classes

    def with_finding(self, finding: Finding) -> BoatStatus:
        """This status with ``finding`` added."""
        return BoatStatus((*self.findings, finding))


@dataclass(frozen=True, eq=False)
class BoatEntry:
    """One track of the fleet after triage.

    Attributes
    ----------
    name : str
        The boat (the track file's stem, made unique).
    source : str
        The file.
    track : Track or None
        The track to debrief: cut to the race (``cut``); None when it could not be read.
    status : BoatStatus
    segmentation : Segmentation or None
        Its start and leg ends (None: not segmented, see ``status``).
    cut : tuple of float or None
        ``(first, last)`` time kept [epoch s] when the log was cut at a long gap.
    xy : (x, y) arrays or None
        ``track``'s fixes in the course frame [m] (projected once for the fleet).
    """

    name: str
    source: str
    track: Track | None
    status: BoatStatus = field(default_factory=BoatStatus)
    segmentation: Segmentation | None = None
    cut: tuple[float, float] | None = None
    xy: tuple[NDArray, NDArray] | None = field(default=None, repr=False)

    @property
    def analysed(self) -> bool:
        """The boat is debriefed (a track, segmented, no finding that excludes it)."""
        return self.track is not None and self.segmentation is not None and self.status.analysed


@dataclass(frozen=True, eq=False)
class Triage:
    """A fleet after triage.

    Attributes
    ----------
    entries : tuple of BoatEntry
        Every track, in the order given.
    start : FleetStart
        The fleet's gun and line (:func:`~sailroute.analysis.start.estimate_fleet_start`).
    recall : GeneralRecall or None
        A general recall found in the tracks (the course gave no restart).
    race_end_t : float
        The last leg end found in any boat, plus a minute [epoch s] (the window's end when
        none is): the wind is inferred over the race, not the sail home.
    gap_allow_s : float
        Longest gap a log may have inside the race [s] (:data:`RACE_GAP_FACTOR`); inf
        when no leg was timed.
    restart_estimated : bool
        The gun is the restart after a general recall found in the tracks, estimated from
        the fleet's second start (the course gave none, nor ``--gun``).
    """

    entries: tuple[BoatEntry, ...]
    start: FleetStart
    recall: GeneralRecall | None
    race_end_t: float
    gap_allow_s: float
    restart_estimated: bool = False

    @property
    def analysed(self) -> tuple[BoatEntry, ...]:
        """The entries that are debriefed."""
        return tuple(e for e in self.entries if e.analysed)

    def notes(self) -> tuple[str, ...]:
        """The start's estimate, a general recall, and one note per class of finding."""
        out = []
        r = self.recall
        if r is not None and not self.restart_estimated:
            out.append(
                f"general recall: {len(r.boats)} of {r.n_started} boats started at "
                f"{iso(r.first_t)}, came back and started again at the gun "
                f"({iso(self.start.gun_t)}); the race is timed from it"
            )
        elif r is not None:
            out.append(
                f"general recall: {len(r.boats)} of {r.n_started} boats started at "
                f"{iso(r.first_t)}, came back and started again from {iso(r.restart_t)}; "
                "the restart's gun is not in the course (restart_time) nor given (--gun): "
                f"taken as {iso(self.start.track_gun_t)} in the tracks' clock, its front row "
                "on the line at the gun"
            )
        if (self.start.model != "none" or self.start.n_boats) and not self.restart_estimated:
            out.append(self.start.describe())
        return (*out, *class_notes(self.entries))


def race_window_problem(
    course: Course, track: Track, x: NDArray, y: NDArray, gun_t: float | None = None
) -> str | None:
    """Why a track is not of the race (None: it is).

    No point in the race window ``[start_time, gun + time_limit]``: another day or time
    zone; none of them within :data:`NEAR_COURSE_M` of a mark: another place.
    """
    t0 = course.start_epoch
    t1 = (gun_t if gun_t is not None else course.gun_epoch) + course.time_limit_s
    inside = (track.t_s >= t0) & (track.t_s <= t1)
    if not inside.any():
        return (
            f"the track runs {iso(track.t_start)} .. {iso(track.t_end)} but "
            f"the race ({course.source}) runs {iso(t0)} .. {iso(t1)} (start_time + "
            "time_limit_min): another day or time zone? Check the track's times (time_zone "
            "for naive times) and the course's start_time"
        )
    mx = np.array([m.x for m in course.marks.values()])
    my = np.array([m.y for m in course.marks.values()])
    d = np.hypot(x[inside, None] - mx[None, :], y[inside, None] - my[None, :]).min()
    if d > NEAR_COURSE_M:
        return (
            f"during the race the track never comes within "
            f"{NEAR_COURSE_M / 1000:.0f} km of a mark of {course.source} (closest "
            f"{d / 1000:.1f} km): a track from another place? Check the files"
        )
    return None


def cut_at_gaps(
    t: NDArray, gun_t: float, allow_s: float, end_t: float = math.inf, gap_s: float = math.inf
) -> tuple[int, int]:
    """Index range ``[lo, hi)`` of the part of a track that can belong to the race.

    Around the gun, the part without a gap longer than ``allow_s`` [s] (from the first fix
    after the gun when the gun falls in such a gap or before the track); then cut before
    the first data gap (longer than ``gap_s``) after the gun that ends after the race's end
    ``end_t`` [epoch s], and at ``end_t``: nothing after it is of this race.
    """
    if t.size < 2:
        return 0, t.size
    lo, hi = 0, t.size
    if math.isfinite(allow_s):
        big = np.flatnonzero(np.diff(t) > allow_s)  # a gap between fix k and k + 1
        k = max(int(np.searchsorted(t, gun_t, side="right")) - 1, 0)  # last fix <= gun
        before = big[big < k]
        after = big[big >= k]
        lo = int(before[-1]) + 1 if before.size else 0
        hi = int(after[0]) + 1 if after.size else t.size
        if t[hi - 1] < gun_t and hi < t.size:  # the gun falls in a long gap: the part after
            lo = hi
            nxt = big[big >= hi]
            hi = int(nxt[0]) + 1 if nxt.size else t.size
    if math.isfinite(end_t):
        gaps = lo + np.flatnonzero(np.diff(t[lo:hi]) > gap_s)
        late = gaps[(t[gaps] >= gun_t) & (t[np.minimum(gaps + 1, t.size - 1)] > end_t)]
        if late.size:
            hi = int(late[0]) + 1
        hi = min(hi, max(int(np.searchsorted(t, end_t, side="right")), lo + 2))
    return lo, hi


def _race_end_t(segs: Sequence[Segmentation], gun_t: float, longest_s: float) -> float:
    """When the race is over [epoch s]: the last finish of the fleet (of the boats that took
    at most twice the median boat's time: a log bridged into another race does not count),
    else its last leg end found, plus the longest leg (``longest_s``); inf when nothing is
    timed."""
    fin = np.array([s.ends[-1].t for s in segs if s.ends and s.ends[-1].known])
    if fin.size:
        el = fin - gun_t
        last = float(fin[el <= 2.0 * float(np.median(el))].max())
    else:
        ends = [c.t for s in segs for c in s.ends if c.known]
        if not ends:
            return math.inf
        last = max(ends)
    return last + (longest_s if math.isfinite(longest_s) else 0.0)


def _duplicates(
    tracks: Mapping[str, tuple[NDArray, NDArray, NDArray]], t0: float, t1: float
) -> dict[str, str]:
    """Boat -> the earlier boat whose data it repeats (:data:`DUPLICATE_M`)."""
    names = list(tracks)
    grid = np.linspace(t0, t1, 21)
    coarse = {}
    for n in names:
        t, x, y = tracks[n]
        ok = (grid >= t[0]) & (grid <= t[-1])
        coarse[n] = (
            np.where(ok, np.interp(grid, t, x), np.nan),
            np.where(ok, np.interp(grid, t, y), np.nan),
        )
    out: dict[str, str] = {}
    for j, b in enumerate(names):
        for a in names[:j]:
            if a in out:
                continue
            dx = coarse[a][0] - coarse[b][0]
            dy = coarse[a][1] - coarse[b][1]
            dc = np.hypot(dx, dy)
            if not np.isfinite(dc).any() or np.nanmedian(dc) > 5 * DUPLICATE_M:
                continue
            if _same_data(tracks[a], tracks[b], t0, t1):
                out[b] = a
                break
    return out


def _same_data(
    a: tuple[NDArray, NDArray, NDArray],
    b: tuple[NDArray, NDArray, NDArray],
    t0: float,
    t1: float,
) -> bool:
    ta, xa, ya = a
    tb, xb, yb = b
    lo, hi = max(ta[0], tb[0], t0), min(ta[-1], tb[-1], t1)
    short = min(min(ta[-1], t1) - max(ta[0], t0), min(tb[-1], t1) - max(tb[0], t0))
    if hi <= lo or short <= 0 or hi - lo < DUPLICATE_OVERLAP * short:
        return False
    m = (ta >= lo) & (ta <= hi)
    if m.sum() < 2:
        return False
    d = np.hypot(xa[m] - np.interp(ta[m], tb, xb), ya[m] - np.interp(ta[m], tb, yb))
    return bool(np.median(d) <= DUPLICATE_M)


def _leg_medians(segs: Sequence[Segmentation]) -> NDArray:
    """The fleet's median time of each leg [s] (NaN: no boat timed it)."""
    if not segs:
        return np.zeros(0)
    n = len(segs[0].ends)
    med = np.full(n, np.nan)
    for i in range(n):
        times = [
            s.bounds[i + 1].t - s.bounds[i].t
            for s in segs
            if s.bounds[i].known and s.bounds[i + 1].known
        ]
        if times:
            med[i] = float(np.median(times))
    return med


def _pace(segs: Mapping[str, Segmentation]) -> dict[str, float]:
    """Boat -> the median over its timed legs of its leg time over the fleet's median."""
    names = list(segs)
    if not names:
        return {}
    n = len(segs[names[0]].ends)
    times = np.full((len(names), n), np.nan)
    for r, b in enumerate(names):
        bd = segs[b].bounds
        for i in range(n):
            if bd[i].known and bd[i + 1].known:
                times[r, i] = bd[i + 1].t - bd[i].t
    timed = np.isfinite(times).any(axis=1)
    if timed.sum() < PACE_MIN_BOATS:
        return {}
    med = np.nanmedian(np.where(timed[:, None], times, np.nan), axis=0)
    ratio = times / med[None, :]
    return {
        b: float(np.nanmedian(ratio[r])) for r, b in enumerate(names) if np.isfinite(ratio[r]).any()
    }


@dataclass
class _Fleet:
    """Triage's working state: per boat, its status, file, track and course-frame points."""

    status: dict[str, BoatStatus]
    source: dict[str, str]
    kept: dict[str, Track] = field(default_factory=dict)
    xy: dict[str, tuple[NDArray, NDArray, NDArray]] = field(default_factory=dict)
    gaps: dict[str, float] = field(default_factory=dict)

    def find(self, name: str, finding: Finding) -> None:
        self.status[name] = self.status[name].with_finding(finding)

    def drop(self, name: str, finding: Finding) -> None:
        """Leave ``name`` out with ``finding``."""
        self.find(name, finding)
        self.kept.pop(name, None)
        self.xy.pop(name, None)


def _readable(
    course: Course, tracks: Sequence[tuple[str, str, Track | Exception]], gun: float
) -> _Fleet:
    """The tracks that were read, hold two fixes and lie in the race's time and place."""
    fleet = _Fleet({n: BoatStatus() for n, _, _ in tracks}, {n: s for n, s, _ in tracks})
    for name, _, got in tracks:
        if isinstance(got, Exception):
            fleet.find(name, Finding(BoatClass.EMPTY, str(got)))
            continue
        if len(got) < 2:
            fleet.find(name, Finding(BoatClass.EMPTY, f"{len(got)} fix(es)"))
            continue
        x, y = track_xy(got, course.frame)
        problem = race_window_problem(course, got, x, y, gun)
        if problem is not None and gun - PRESTART_S <= got.t_end < gun:
            end = f"the data end at {iso(got.t_end)}, before the gun"
            fleet.find(name, Finding(BoatClass.NON_STARTER, end))
        elif problem is not None:
            fleet.find(name, Finding(BoatClass.OTHER_FLEET, problem))
        else:
            fleet.kept[name] = got
            fleet.xy[name] = (got.t_s, x, y)
            fleet.gaps[name] = gap_limit_s(got.t_s)
    return fleet


def _fleet_start(
    course: Course, fleet: _Fleet, gun: float, given: bool, estimate: bool
) -> tuple[FleetStart, GeneralRecall | None, bool]:
    """The fleet's start: a general recall after the gun when the course gives no restart
    (the restart's gun then estimated from the fleet: the flag), before it otherwise
    (noted), and the fleet's gun and line."""
    recall = None
    moved = False
    if len(fleet.xy) >= MIN_FLEET:
        if not given:  # the first start from a minute before the gun: a clock lag
            recall = detect_general_recall(course, fleet.xy, gun - PULSE_S, fleet.gaps)
        if recall is None:
            before = gun - RECALL_BEFORE_S
            recall = detect_general_recall(
                course, fleet.xy, before - RECALL_WINDOW_S, fleet.gaps, before
            )
        else:
            gun, moved = round(recall.restart_t), True
    obs = [
        o
        for n, (t, x, y) in fleet.xy.items()
        if (o := observe_start(course, t, x, y, gun, n, fleet.gaps[n])) is not None
    ]
    # a restart found in the tracks: its gun is the estimate's unknown, not the line
    models = ("clock",) if moved else ("line", "clock", "both")
    return estimate_fleet_start(obs if estimate else [], gun, models), recall, moved


def _cut_to_race(
    fleet: _Fleet,
    segs: dict[str, Segmentation],
    start: FleetStart,
    segment: Callable[[str], Segmentation],
) -> tuple[dict[str, tuple[float, float]], float]:
    """Cut every log to the race (:func:`cut_at_gaps`), segmenting again the ones cut; the
    cuts that dropped another race's data, and the longest gap a log may have."""
    med = _leg_medians(list(segs.values()))
    timed = med[np.isfinite(med)]
    allow = RACE_GAP_FACTOR * float(np.median(timed)) if timed.size else math.inf
    longest = float(timed.max()) if timed.size else math.inf
    gun = start.track_gun_t
    end_t = _race_end_t([s for s in segs.values() if s.start.started], gun, longest)
    cut: dict[str, tuple[float, float]] = {}
    for n, (t, x, y) in list(fleet.xy.items()):
        lo, hi = cut_at_gaps(t, gun, allow, end_t, fleet.gaps[n])
        if (lo, hi) == (0, t.size) or hi - lo < 2:
            continue
        dropped = [
            f"a gap of {t[k + 1] - t[k]:.0f} s {where}"
            for k, where in ((lo - 1, "before"), (hi - 1, "after"))
            if 0 <= k < t.size - 1 and t[k + 1] - t[k] > fleet.gaps[n]
        ]
        after = t[-1] - t[hi - 1]
        if not dropped and after > end_t - gun:  # more than a race after the race's end
            dropped = [f"{after:.0f} s of data after the race's end"]
        if dropped:
            kept = f"cut to {iso(float(t[lo]))} .. {iso(float(t[hi - 1]))}, "
            fleet.find(n, Finding(BoatClass.MULTI_RACE, kept + " and ".join(dropped)))
            cut[n] = (float(t[lo]), float(t[hi - 1]))
        fleet.kept[n] = fleet.kept[n].between(float(t[lo]), float(t[hi - 1]))
        fleet.xy[n] = (t[lo:hi], x[lo:hi], y[lo:hi])
        segs[n] = segment(n)
    return cut, allow


def _other_pace(fleet: _Fleet, segs: Mapping[str, Segmentation]) -> None:
    """Leave out the boats that sail at another fleet's pace (:data:`PACE_FACTOR`,
    :data:`PACE_Z`)."""
    pace = _pace({k: v for k, v in segs.items() if v.start.started})
    if not pace:
        return
    lp = np.log(np.array(list(pace.values())))
    med = float(np.median(lp))
    sd = 1.4826 * float(np.median(np.abs(lp - med)))
    for n, ratio in pace.items():
        off = abs(math.log(ratio) - med)
        if off > math.log(PACE_FACTOR) or (off > math.log(PACE_MIN_FACTOR) and off > PACE_Z * sd):
            fleet.find(
                n,
                Finding(
                    BoatClass.OTHER_FLEET,
                    f"its legs take {ratio:.2f} times the fleet's median: another class or fleet?",
                ),
            )


def triage_fleet(
    course: Course,
    tracks: Sequence[tuple[str, str, Track | Exception]],
    *,
    gun_t: float | None = None,
    leg_times: Mapping[str, Sequence[float | None] | None] | None = None,
    detect_m: float = DETECT_M,
    gate_end: str = "line",
    fleet_start: bool = True,
) -> Triage:
    """Classify every track of a fleet and segment the boats that can be debriefed.

    Parameters
    ----------
    course : Course
    tracks : sequence of (name, source, Track or Exception)
        Each file's boat name, path and what reading it gave (the error when it could
        not be read).
    gun_t : float, optional
        The gun [epoch s] (``--gun``); default the course's (:attr:`Course.gun_epoch`).
    leg_times : mapping of str to sequence, optional
        Per boat, given leg boundaries (:func:`~sailroute.analysis.segment.segment_track`).
    detect_m, gate_end
        As :func:`~sailroute.analysis.segment.segment_track`.
    fleet_start : bool
        Estimate the fleet's gun and line (:mod:`sailroute.analysis.start`); False keeps
        the course's (one boat).

    Returns
    -------
    Triage
    """
    gun = gun_t if gun_t is not None else course.gun_epoch
    fleet = _readable(course, tracks, gun)
    window = (course.start_epoch - PRESTART_S, gun + course.time_limit_s)
    for dup, first in _duplicates(fleet.xy, *window).items():
        fleet.drop(dup, Finding(BoatClass.DUPLICATE, f"the same data as {first}"))
    given = gun_t is not None or course.restart_time is not None
    start, recall, moved = _fleet_start(course, fleet, gun, given, fleet_start)
    times = leg_times or {}

    def segment(name: str) -> Segmentation:
        return segment_track(
            course,
            *fleet.xy[name],
            leg_times=times.get(name),
            detect_m=detect_m,
            where=fleet.source[name],
            missing="unknown",
            gate_end=gate_end,
            clock=start.clock(name),
        )

    segs = {n: segment(n) for n in fleet.xy}
    cut, allow = _cut_to_race(fleet, segs, start, segment)
    _other_pace(fleet, segs)
    for n, seg in segs.items():
        if fleet.status[n].analysed:
            fleet.status[n] = _own_findings(fleet.status[n], seg, course, *fleet.xy[n])
    ends = [c.t for s in segs.values() for c in s.bounds[1:] if c.known]
    race_end = min(window[1], max(ends) + 60.0) if ends else window[1]
    entries = tuple(
        BoatEntry(
            n,
            fleet.source[n],
            fleet.kept.get(n),
            fleet.status[n],
            segs.get(n),
            cut.get(n),
            fleet.xy[n][1:] if n in fleet.xy and n in fleet.kept else None,
        )
        for n, _, _ in tracks
    )
    return Triage(entries, start, recall, race_end, allow, moved)


def _own_findings(
    status: BoatStatus, seg: Segmentation, course: Course, t: NDArray, x: NDArray, y: NDArray
) -> BoatStatus:
    """A boat's findings from its own start, legs and data gaps."""
    st = seg.start
    if not st.started:
        reason = st.crossing.note.removeprefix("did not start: ")
        return status.with_finding(Finding(BoatClass.NON_STARTER, reason))
    if st.ocs_s is not None:
        status = status.with_finding(
            Finding(
                BoatClass.OCS_RETURNED if st.ocs_returned else BoatClass.OCS,
                f"{st.ocs_s:.1f} s / {st.distance_at_gun_m:.0f} m over"
                + (f", {st.ocs_sd:.1f} sd, p = {st.ocs_p:.3f}" if math.isfinite(st.ocs_sd) else "")
                + (f", restarted {st.late_s:+.0f} s" if st.ocs_returned else ""),
            )
        )
    elif st.late:
        behind = (
            f", {st.distance_at_gun_m:.0f} m behind the line at the gun"
            if st.side_at_gun == "pre-start"
            else ""
        )
        status = status.with_finding(Finding(BoatClass.LATE_START, f"+{st.late_s:.0f} s{behind}"))
    outside = [i for i, c in enumerate(seg.ends) if c.issue is LegIssue.OUTSIDE]
    if outside:
        status = status.with_finding(
            Finding(
                BoatClass.GATE_OUTSIDE,
                ", ".join(f"leg {i + 1} ({course.legs[i].label})" for i in outside),
            )
        )
    gaps = _race_gaps(seg, t)
    if gaps:
        status = status.with_finding(Finding(BoatClass.DATA_GAP, ", ".join(gaps)))
    stopped = next(
        (
            i
            for i, c in enumerate(seg.ends)
            if c.issue in (LegIssue.NOT_REACHED, LegIssue.WRONG_SIDE)
            or (c.issue is LegIssue.DATA_STOP and c.gap is None)
        ),
        None,
    )
    if stopped is not None:
        why = {
            LegIssue.NOT_REACHED: "never reaches",
            LegIssue.WRONG_SIDE: "rounds on the wrong side",
            LegIssue.DATA_STOP: "its data end before",
        }[seg.ends[stopped].issue]  # type: ignore[index]
        status = status.with_finding(
            Finding(
                BoatClass.RETIRED,
                f"{why} {course.legs[stopped].to_name!r} (leg {stopped + 1})",
            )
        )
    return status


def _race_gaps(seg: Segmentation, t: NDArray) -> list[str]:
    """The data gaps (longer than :func:`gap_limit_s`) between the start and the last leg
    end found, as ``"57 s in leg 2"``."""
    bounds = [c.t_lo for c in seg.bounds if math.isfinite(c.t_lo)]
    if len(bounds) < 2:
        return []
    lim = gap_limit_s(t)
    k = np.flatnonzero(np.diff(t) > lim)
    k = k[(t[k] >= bounds[0]) & (t[k] < bounds[-1])]
    ends = np.array([c.t_hi for c in seg.ends])
    out = []
    for j in k:
        leg = int(np.searchsorted(np.where(np.isfinite(ends), ends, np.inf), t[j], side="left"))
        out.append(f"{t[j + 1] - t[j]:.0f} s in leg {min(leg, len(ends) - 1) + 1}")
    return out


def class_notes(entries: Sequence[BoatEntry]) -> tuple[str, ...]:
    """One note per class of finding, naming its boats with their details; then one per
    kind of leg end (unknown, or timed in an unusual way) naming the boats and legs."""
    out = []
    for kind in BoatClass:
        boats = [
            f"{e.name} ({f.detail})" if f.detail else e.name
            for e in entries
            for f in e.status.findings
            if f.kind is kind
        ]
        if boats:
            effect = (
                "left out"
                if not kind.analysed
                else "analysed, no place in the results"
                if not kind.ranked
                else "analysed and ranked"
            )
            out.append(f"{kind.value} ({effect}): " + "; ".join(boats))
    for issue, text in _LEG_ISSUE_NOTES.items():
        legs = [
            f"{e.name} leg {i + 1}"
            for e in entries
            if e.analysed and e.segmentation is not None
            for i, c in enumerate(e.segmentation.ends)
            if c.issue is issue and (issue is not LegIssue.DATA_STOP or c.gap is not None)
        ]
        if legs:
            out.append(f"{text}: " + ", ".join(legs))
    return tuple(out)


_LEG_ISSUE_NOTES = {
    LegIssue.GAP: "leg end inside a data gap, time unknown",
    LegIssue.DATA_STOP: "the data stop short of a leg's end, time unknown",
    LegIssue.GATE_LINE: "no rounding of a gate mark found, the leg timed at the gate line",
}
"""Leg issues noted for the fleet (the others follow from a class: no start, retired; a
stop at the end of the data, too)."""
