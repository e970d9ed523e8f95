"""A course inferred from a fleet's tracks: marks, gates, lines, roundings, legs, gun, wind.

For a race whose marks are unknown, or were moved, the fleet shows where they were: every
boat turns round each mark, and a mark is where many boats' roundings fall together.
The steps (``docs/analysis.md``, "Marks from the fleet"):

1. **Turns** of every track (:mod:`sailroute.analysis.turns`: boards of the simplified
   track and the turns between them), and the **wind axis** from the boards' courses
   (:func:`sailroute.analysis.infer_wind.wind_axis_deg`, weighted by their durations).
2. **Roundings**: the turns that change the point of sail
   (:func:`~sailroute.analysis.turns.is_rounding`).  A boat passes a mark outside its
   turn, so each rounding puts the mark ``CLEAR_S`` of sailing inside its apex.
3. **Clusters**: those points gathered by a density rule (DBSCAN, Ester et al. 1996,
   counting boats rather than points): two roundings the same way within ``eps`` are
   neighbours, a rounding with neighbours from ``MIN_SHARE`` of the fleet (and at least
   two boats) is a core, and the cores that are neighbours, with the roundings next to
   them, form one cluster.  ``eps`` is ``CLUSTER_S`` of sailing at the fleet's speed, at
   least ``CLUSTER_MIN_M``.  Two clusters rounded opposite ways within ``eps`` are one
   mark (boats that turned the other way round it).  Roundings of nobody's cluster (a
   boat's own detour) are left out.
4. **Sequence**: each boat's roundings in time order as a list of marks and gates; the
   course is the list among them with the most support (each item a boat's list shares
   counts +1/2, each it lacks −1/2: an item half the fleet misses does not count), and
   every boat's roundings are aligned to it (longest common subsequence).
5. **Gates**: two clusters rounded opposite ways, less than ``GATE_S`` of sailing apart
   (at least ``GATE_MIN_M``), that hardly a boat rounds one right after the other
   (``GATE_BOTH``), are the two marks of one gate when the course counted with them as
   one item has more support than without (the boats round one or the other at the same
   places in the course); the nearest pairs first.  A gate mark
   most of the fleet leaves alone may be rounded by fewer boats than a cluster needs:
   among the roundings left over, a group of ``GATE_SHARE`` of the fleet (two boats at
   least) is the partner of a mark of the course rounded the other way, more than
   ``eps`` and less than the gate distance away, when ``GATE_FILL`` of its boats or more
   round it where they miss that mark (between their roundings of the marks before and
   after it), and is nothing else.
6. **Start and gun**: steps 2-5 on every turn give the first mark; the fleet's
   departure towards it, the start line it crosses together and the gun
   (:func:`~sailroute.analysis.infer_lines.infer_gun`,
   :func:`~sailroute.analysis.infer_lines.start_line`; a given gun places the line
   only).  Each boat's race runs from its start crossing to its **end of racing**
   (:func:`~sailroute.analysis.infer_lines.race_ends`), and steps 2-5 again on the turns
   in it give the course: pre-start manoeuvres, returns of boats over early and luffs
   after the finish are left out.
7. **Marks**: the median of a cluster's points; its **spread** the median distance of
   them from it.  A mark at two places in the race (moved between laps) is two clusters
   and two marks.
8. **Finish line** (:func:`~sailroute.analysis.infer_lines.finish_line`), and the wind:
   its axis from step 1, the direction it blows from
   (:func:`~sailroute.analysis.infer_wind.infer_wind` over the race, within
   ``TWD_AXIS_DEG`` of the axis; else the end the slower boards sail towards).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Final

import numpy as np
from numpy.typing import NDArray

from sailroute.analysis.infer_lines import (
    GunEstimate,
    LineEstimate,
    finish_line,
    infer_gun,
    race_ends,
    start_line,
)
from sailroute.analysis.turns import (
    EPS_MIN_M,
    EPS_S,
    MIN_BOARD_S,
    BoatPath,
    Turn,
    find_turns,
    is_rounding,
    typical_speed_ms,
)
from sailroute.errors import InputError
from sailroute.geo import LocalFrame
from sailroute.timeutil import iso
from sailroute.track.model import Track
from sailroute.units import circular_mean_deg, wrap180, wrap360

__all__ = [
    "CLEAR_S",
    "CLUSTER_MIN_M",
    "CLUSTER_S",
    "FIRST_LEG_S",
    "GATE_BOTH",
    "GATE_FILL",
    "GATE_MIN_M",
    "GATE_S",
    "GATE_SHARE",
    "MAX_APART_M",
    "MIN_SHARE",
    "TWD_AXIS_DEG",
    "InferredCourse",
    "InferredMark",
    "infer_course",
]

CLUSTER_S: Final = 2.0
"""Roundings within this much sailing at the fleet's speed are neighbours [s]."""

CLUSTER_MIN_M: Final = 30.0
"""Roundings within this are always neighbours [m]."""

MIN_SHARE: Final = 0.2
"""A cluster's cores have neighbours from this share of the fleet (and two boats)."""

GATE_S: Final = 20.0
"""The two marks of a gate lie less than this much sailing apart [s]."""

GATE_MIN_M: Final = 150.0
"""... or less than this [m]."""

GATE_BOTH: Final = 0.1
"""At most this share of the boats that round the less rounded of two gate marks round
both, one right after the other (a gate is passed round one of its marks)."""

GATE_FILL: Final = 0.5
"""... when this share of its boats or more round it where they miss that mark."""

GATE_SHARE: Final = 0.05
"""A gate's second mark may be rounded by as few as this share of the fleet (and two
boats)."""

CLEAR_S: Final = 1.0
"""A boat rounds a mark about this much sailing outside it [s] (4 m for a dinghy at 8 kn,
15 m for a foiling catamaran at 30 kn)."""


FIRST_LEG_S: Final = 15.0
"""The fleet crosses the start line at least this long before it rounds the first mark
(the median boat) [s]."""

TWD_AXIS_DEG: Final = 30.0
"""The wind inferred from the tracks is used within this of the boards' axis [°]."""

MAX_APART_M: Final = 20_000.0
"""Tracks whose middles lie further apart than this are of different races [m]."""

MIN_FIXES: Final = 10
"""A track needs this many fixes in the window to count."""


@dataclass(frozen=True)
class InferredMark:
    """A mark the fleet rounded.

    Attributes
    ----------
    name : str
        ``M1``, ``M2``, ... in the order first rounded; a gate's marks ``G1a``, ``G1b``.
    x, y : float
        Position [m].
    lat, lon : float
        Position [°].
    rounding : {"port", "starboard"}
        The side the fleet left it on (the majority).
    spread_m : float
        Median distance of the single roundings' estimates from the mark [m].
    n_roundings, n_boats : int
        Roundings and boats it is inferred from.
    gate : str or None
        The gate it belongs to.
    """

    name: str
    x: float
    y: float
    lat: float
    lon: float
    rounding: str
    spread_m: float
    n_roundings: int
    n_boats: int
    gate: str | None = None


@dataclass(frozen=True)
class InferredCourse:
    """What :func:`infer_course` found.

    Attributes
    ----------
    frame : LocalFrame
        The frame of ``x, y``.
    boats : tuple of str
        The tracks used, in input order.
    marks : tuple of InferredMark
        The rounding marks, with the gates' marks.
    gates : tuple of (str, str, str)
        ``(name, mark a, mark b)``.
    start, finish : LineEstimate or None
        The lines (the finish None when the tracks show none).
    legs : tuple of (str, str or None)
        ``(to, rounding)`` of each leg after the start, in sailing order.
    leg_roundings : tuple of tuple of float
        Per leg, each boat's rounding of its mark or gate [epoch s] (NaN: not found).
    gun : GunEstimate
    axis_deg : float
        The wind axis [°, 0-180].
    twd_deg : float
        The wind direction [°, from] over the race.
    twd_how : str
        How the direction's end was decided.
    speed_ms : float
        The fleet's typical speed [m s⁻¹].
    eps_m : float
        The clustering radius [m].
    notes : tuple of str
        What the user should know (tracks left out, a finish not found, ...).
    """

    frame: LocalFrame
    boats: tuple[str, ...]
    marks: tuple[InferredMark, ...]
    gates: tuple[tuple[str, str, str], ...]
    start: LineEstimate
    finish: LineEstimate | None
    legs: tuple[tuple[str, str | None], ...]
    leg_roundings: tuple[tuple[float, ...], ...]
    gun: GunEstimate
    axis_deg: float
    twd_deg: float
    twd_how: str
    speed_ms: float
    eps_m: float
    notes: tuple[str, ...] = field(default=())

    def mark(self, name: str) -> InferredMark:
        """The mark called ``name``."""
        return next(m for m in self.marks if m.name == name)

    def latlon(self, xy: tuple[float, float]) -> tuple[float, float]:
        """``(lat, lon)`` [°] of a point of the frame."""
        lat, lon = self.frame.to_latlon(xy[0], xy[1])
        return float(lat), float(lon)


# ------------------------------------------------------------------------------ input
def _paths(tracks: Sequence[Track], t_from: float, t_until: float) -> list[Track]:
    """The tracks cut to the window; refuses too few, or tracks of different times."""
    if len(tracks) < 2:
        raise InputError(
            f"course infer: {len(tracks)} track given; the marks are where a fleet turns: "
            "give the tracks of two boats or more of the same race (ten or more for a "
            "course you can trust)"
        )
    cut = []
    for tr in tracks:
        part = tr.between(t_from, t_until)
        if len(part) >= MIN_FIXES:
            cut.append(part)
    if len(cut) < 2:
        where = "" if not math.isfinite(t_from) else f" between {iso(t_from)} and {iso(t_until)}"
        raise InputError(
            f"course infer: {len(cut)} of {len(tracks)} tracks have {MIN_FIXES} fixes or "
            f"more{where}; expected the tracks of one race (check --from/--until)"
        )
    lo = max(float(np.median([tr.t_start for tr in cut])), min(tr.t_start for tr in cut))
    hi = min(float(np.median([tr.t_end for tr in cut])), max(tr.t_end for tr in cut))
    overlap = [tr for tr in cut if tr.t_start < hi and tr.t_end > lo]
    if len(overlap) < 2 or hi <= lo:
        raise InputError(
            f"course infer: the tracks do not overlap in time ({iso(min(tr.t_start for tr in cut))}"
            f" .. {iso(max(tr.t_end for tr in cut))}); expected the boats of one race"
        )
    return cut


def _check_place(paths: Sequence[BoatPath]) -> None:
    """Refuse tracks whose middles lie more than ``MAX_APART_M`` apart."""
    mids = [(p.name, float(np.median(p.x)), float(np.median(p.y))) for p in paths]
    cx, cy = float(np.median([m[1] for m in mids])), float(np.median([m[2] for m in mids]))
    far = [(n, math.hypot(x - cx, y - cy)) for n, x, y in mids]
    n, d = max(far, key=lambda f: f[1])
    if d > MAX_APART_M:
        raise InputError(
            f"course infer: track {n!r} lies {d / 1000:.0f} km from the rest of the fleet "
            f"(more than {MAX_APART_M / 1000:.0f} km): expected the tracks of one race; "
            "leave it out"
        )


# ------------------------------------------------------------------------------ turns
@dataclass(frozen=True)
class _Rounding:
    boat: int
    turn: Turn
    est: tuple[float, float]  # where this rounding puts the mark [m]


def _turns(paths: Sequence[BoatPath], eps_dp: float) -> tuple[list[list[Turn]], float]:
    """Every boat's turns, and the wind axis from all boards [°]."""
    per: list[list[Turn]] = []
    courses, weights = [], []
    for p in paths:
        out: list[Turn] = []
        for sl in p.pieces():
            tu, bc, bs = find_turns(p.t[sl], p.x[sl], p.y[sl], eps_dp)
            out.extend(tu)
            courses.append(bc)
            weights.append(bs)
        per.append(out)
    from sailroute.analysis.infer_wind import wind_axis_deg

    c = np.concatenate(courses) if courses else np.zeros(0)
    if c.size == 0:
        raise InputError(
            "course infer: the tracks hold no straight sailing (no board of "
            f"{MIN_BOARD_S:.0f} s or more); expected race tracks with fixes every few seconds"
        )
    axis, _ = wind_axis_deg(c, np.concatenate(weights))
    return per, axis


def _roundings(
    paths: Sequence[BoatPath],
    turns: Sequence[Sequence[Turn]],
    axis: float,
    clear_m: float,
    windows: Sequence[tuple[float, float]],
) -> list[_Rounding]:
    """The turns that round a mark within each boat's window."""
    out = []
    for b, (tu, (lo, hi)) in enumerate(zip(turns, windows, strict=True)):
        for turn in tu:
            if not (lo < turn.t < hi) or not is_rounding(turn, axis):
                continue
            ox, oy = turn.outward
            out.append(_Rounding(b, turn, (turn.x - clear_m * ox, turn.y - clear_m * oy)))
    return out


def _clusters(rs: Sequence[_Rounding], eps: float, min_boats: int) -> NDArray[np.int64]:
    """Cluster label of each rounding (−1: none), by step 3 of the module notes."""
    n = len(rs)
    if n == 0:
        return np.zeros(0, dtype=np.int64)
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import connected_components

    xy = np.array([r.est for r in rs])
    side = np.array([r.turn.turn_deg < 0 for r in rs])
    boat = np.array([r.boat for r in rs])
    d = np.hypot(xy[:, None, 0] - xy[None, :, 0], xy[:, None, 1] - xy[None, :, 1])
    near = (d <= eps) & (side[:, None] == side[None, :])
    onehot = np.zeros((n, int(boat.max()) + 1), dtype=bool)
    onehot[np.arange(n), boat] = True
    boats_near = (near.astype(np.int64) @ onehot.astype(np.int64) > 0).sum(axis=1)
    core = boats_near >= min_boats
    link = near & core[:, None] & core[None, :]
    _, comp = connected_components(csr_matrix(link), directed=False)
    label = np.full(n, -1, dtype=np.int64)
    label[core] = comp[core]
    for i in np.flatnonzero(~core):
        c = np.flatnonzero(near[i] & core)
        if c.size:
            label[i] = comp[c[int(np.argmin(d[i, c]))]]
    used = sorted(set(label[label >= 0].tolist()))
    remap = {v: k for k, v in enumerate(used)}
    return np.array([remap.get(int(v), -1) for v in label], dtype=np.int64)


# --------------------------------------------------------------------------- sequence
def _lcs(a: Sequence[int], b: Sequence[int]) -> list[tuple[int, int]]:
    """Index pairs of a longest common subsequence of ``a`` and ``b``."""
    m, n = len(a), len(b)
    L = np.zeros((m + 1, n + 1), dtype=np.int64)
    for i in range(m - 1, -1, -1):
        for j in range(n - 1, -1, -1):
            L[i, j] = L[i + 1, j + 1] + 1 if a[i] == b[j] else max(L[i + 1, j], L[i, j + 1])
    out, i, j = [], 0, 0
    while i < m and j < n:
        if a[i] == b[j]:
            out.append((i, j))
            i, j = i + 1, j + 1
        elif L[i + 1, j] >= L[i, j + 1]:
            i += 1
        else:
            j += 1
    return out


def _consensus(seqs: Sequence[Sequence[int]]) -> tuple[list[int], float]:
    """The boats' list with the most support, and its support (step 5 of the module
    notes)."""
    best: list[int] = []
    best_score = -math.inf
    for cand in sorted({tuple(s) for s in seqs if s}, key=lambda s: (-len(s), s)):
        score = sum(len(_lcs(cand, s)) - 0.5 * len(cand) for s in seqs)
        if score > best_score:
            best, best_score = list(cand), score
    return best, best_score


def _gate_pairs(
    rs: Sequence[_Rounding],
    label: NDArray[np.int64],
    centres: NDArray,
    sides: Sequence[bool],
    n_boats: int,
    gate_max: float,
) -> dict[int, int]:
    """Cluster -> the item it counts as (a gate's second mark -> its first)."""
    k = centres.shape[0]
    item = {c: c for c in range(k)}

    def lists(it: dict[int, int]) -> list[list[int]]:
        return [[c for c, _ in s] for s in _sequences(rs, label, n_boats, it)]

    seqs = lists(item)
    pairs = []
    for a in range(k):
        for b in range(a + 1, k):
            dist = math.hypot(*(centres[a] - centres[b]))
            if sides[a] == sides[b] or dist > gate_max:
                continue
            both = sum(any({s[i], s[i + 1]} == {a, b} for i in range(len(s) - 1)) for s in seqs)
            fewer = min(sum(a in s for s in seqs), sum(b in s for s in seqs))
            if both <= GATE_BOTH * fewer:
                pairs.append((dist, a, b))
    score = _consensus(seqs)[1]
    taken: set[int] = set()
    for _, a, b in sorted(pairs):
        if a in taken or b in taken:
            continue
        trial = {**item, b: a}
        merged = _consensus(lists(trial))[1]
        if merged > score:
            item, score = trial, merged
            taken |= {a, b}
    return item


def _sequences(
    rs: Sequence[_Rounding], label: NDArray[np.int64], n_boats: int, item: dict[int, int]
) -> list[list[tuple[int, int]]]:
    """Per boat, its roundings in time order as ``(item, rounding index)``, a repeat of
    the same item right after it dropped (a second turn at the same mark)."""
    per: list[list[tuple[int, int]]] = [[] for _ in range(n_boats)]
    for i in sorted(range(len(rs)), key=lambda i: rs[i].turn.t):
        if label[i] < 0:
            continue
        it = item[int(label[i])]
        row = per[rs[i].boat]
        if row and row[-1][0] == it:
            continue
        row.append((it, i))
    return per


@dataclass(frozen=True)
class _Found:
    """Clusters, items and the aligned course of one pass."""

    rs: list[_Rounding]
    label: NDArray[np.int64]
    centres: NDArray
    sides: list[bool]
    item: dict[int, int]
    course: list[int]
    aligned: list[list[int | None]]  # per course position, per boat: rounding index


def _centres_sides(
    rs: Sequence[_Rounding], label: NDArray[np.int64], k: int
) -> tuple[NDArray, list[bool]]:
    """Each cluster's median estimate [m] and whether most of it is rounded to port."""
    members = [np.flatnonzero(label == c).tolist() for c in range(k)]
    centres = np.array([np.median([rs[i].est for i in m], axis=0) for m in members])
    sides = [bool(np.mean([rs[i].turn.turn_deg < 0 for i in m]) > 0.5) for m in members]
    return centres.reshape(k, 2), sides


def _aligned(
    rs: Sequence[_Rounding], label: NDArray[np.int64], n_boats: int, item: dict[int, int]
) -> tuple[list[int], list[list[int | None]]]:
    """The course (items) and, per position and boat, the rounding aligned to it."""
    seqs = _sequences(rs, label, n_boats, item)
    course, _ = _consensus([[c for c, _ in s] for s in seqs])
    aligned: list[list[int | None]] = [[None] * n_boats for _ in course]
    for b, s in enumerate(seqs):
        for p, q in _lcs(course, [c for c, _ in s]):
            aligned[p][b] = s[q][1]
    return course, aligned


def _fills(
    rs: Sequence[_Rounding],
    members: NDArray,
    course: Sequence[int],
    aligned: Sequence[Sequence[int | None]],
    p: int,
) -> int:
    """Boats missing at course position ``p`` that round the cluster ``members`` between
    their roundings of the positions before and after it."""
    n = len(aligned[p])
    out = set()
    for b in range(n):
        if aligned[p][b] is not None:
            continue
        prev = aligned[p - 1][b] if p > 0 else None
        nxt = aligned[p + 1][b] if p + 1 < len(course) else None
        lo = rs[prev].turn.t if prev is not None else -math.inf
        hi = rs[nxt].turn.t if nxt is not None else math.inf
        if any(rs[i].boat == b and lo < rs[i].turn.t < hi for i in members):
            out.add(b)
    return len(out)


def _merge_near(rs: Sequence[_Rounding], label: NDArray[np.int64], eps: float) -> NDArray[np.int64]:
    """``label`` with clusters rounded opposite ways whose centres lie within ``eps`` as
    one (boats that went round the same mark turning the other way)."""
    k = int(label.max()) + 1 if label.size else 0
    centres, _ = _centres_sides(rs, label, k)
    target = list(range(k))
    for a in range(k):
        for b in range(a + 1, k):
            if math.hypot(*(centres[a] - centres[b])) <= eps:
                target[b] = target[a]
    used = sorted(set(target))
    remap = np.array([used.index(target[c]) for c in range(k)] + [-1], dtype=np.int64)
    return remap[label]


def _find(rs: list[_Rounding], n_boats: int, eps: float, min_boats: int, gate_max: float) -> _Found:
    label = _merge_near(rs, _clusters(rs, eps, min_boats), eps)
    k = int(label.max()) + 1 if label.size else 0
    centres, sides = _centres_sides(rs, label, k)
    item = _gate_pairs(rs, label, centres, sides, n_boats, gate_max)
    course, aligned = _aligned(rs, label, n_boats, item)
    # a gate's mark the fleet mostly leaves alone: a group of fewer boats among the rest
    # that rounds it instead of a mark of the course, at its place in the course
    rest = np.flatnonzero(label < 0)
    minor = _clusters([rs[i] for i in rest], eps, max(2, math.ceil(GATE_SHARE * n_boats)))
    singles = {c for c in set(course) if list(item.values()).count(c) == 1}
    found = False
    for m in range(int(minor.max()) + 1 if minor.size else 0):
        members = rest[minor == m]
        centre = np.median([rs[i].est for i in members], axis=0)
        port = bool(np.mean([rs[i].turn.turn_deg < 0 for i in members]) > 0.5)
        boats = len({rs[i].boat for i in members})
        best = None
        for p, c in enumerate(course):
            if c not in singles or sides[c] == port:
                continue
            if not eps < math.hypot(*(centre - centres[c])) <= gate_max:
                continue
            n_fill = _fills(rs, members, course, aligned, p)
            if n_fill >= max(2, GATE_FILL * boats) and (best is None or n_fill > best[0]):
                best = (n_fill, c)
        if best is not None:
            label[members] = k
            item[k] = best[1]
            singles.discard(best[1])
            centres = np.vstack([centres, centre])
            sides.append(port)
            k += 1
            found = True
    if found:
        course, aligned = _aligned(rs, label, n_boats, item)
    return _Found(rs, label, centres, sides, item, course, aligned)


# ------------------------------------------------------------------------------ wind
def _twd(
    tracks: Sequence[Track],
    frame: LocalFrame,
    axis: float,
    gun: float,
    end: float,
    paths: Sequence[BoatPath],
) -> tuple[float, str]:
    """The wind's direction over the race [°, from] and where it comes from: the mean of
    the wind inferred from the tracks when that lies within ``TWD_AXIS_DEG`` of the axis,
    else the end of the axis the slower boards sail towards."""
    from sailroute.analysis.infer_wind import infer_wind

    try:
        iw = infer_wind(list(tracks), frame, t0=gun, t1=end)
        ok = np.isfinite(iw.twd_deg)
        twd = circular_mean_deg(iw.twd_deg[ok]) if ok.any() else math.nan
    except InputError as exc:
        why = str(exc)
    else:
        off = abs(float(wrap180(twd - axis))) if math.isfinite(twd) else math.nan
        if min(off, 180.0 - off) <= TWD_AXIS_DEG:
            return twd, "the mean of the wind inferred from the tracks"
        why = (
            "no direction inferred"
            if not math.isfinite(twd)
            else f"the wind inferred from the tracks, {twd:.0f}°, lies off the boards' axis"
        )
    # the slower boards are the upwind ones
    speeds: dict[int, list[float]] = {0: [], 1: []}
    for p in paths:
        v = p.speed(10.0)
        c = np.degrees(np.arctan2(np.gradient(p.x), np.gradient(p.y)))
        for end_i, e in enumerate((axis, axis + 180.0)):
            m = (np.abs(wrap180(c - e)) < 60.0) & np.isfinite(v)
            if m.any():
                speeds[end_i].append(float(np.median(v[m])))
    s0 = float(np.median(speeds[0])) if speeds[0] else math.inf
    s1 = float(np.median(speeds[1])) if speeds[1] else math.inf
    twd = axis if s0 <= s1 else (axis + 180.0) % 360.0
    return float(wrap360(twd)), f"the end of the boards' axis the slower boards sail to ({why})"


# ------------------------------------------------------------------------------ main
def infer_course(
    tracks: Sequence[Track],
    *,
    gun_t: float | None = None,
    t_from: float = -math.inf,
    t_until: float = math.inf,
) -> InferredCourse:
    """Infer a course from a fleet's tracks (module notes).

    Parameters
    ----------
    tracks : sequence of Track
        Two or more boats of one race.
    gun_t : float, optional
        The gun [epoch s]; inferred when None.
    t_from, t_until : float
        Only the fixes in this window are used [epoch s] (logs holding several races).

    Returns
    -------
    InferredCourse

    Raises
    ------
    InputError
        Fewer than two tracks in the window, tracks of different times or places, no
        roundings shared by the fleet, no gun found (give it), no start found.
    """
    cut = _paths(tracks, t_from, t_until)
    lat = np.concatenate([tr.lat_deg for tr in cut])
    lon = np.concatenate([tr.lon_deg for tr in cut])
    frame = LocalFrame(float(np.median(lat)), float(np.median(lon)))
    paths = [BoatPath.of_track(tr, frame) for tr in cut]
    _check_place(paths)
    n = len(paths)
    notes: list[str] = []
    if len(cut) < len(tracks):
        notes.append(
            f"{len(tracks) - len(cut)} track(s) with fewer than {MIN_FIXES} fixes in the "
            "window left out"
        )
    speed = float(np.median([typical_speed_ms(p.t, p.x, p.y) for p in paths]))
    if not speed > 0.5:
        raise InputError(
            f"course infer: the boats' typical speed is {speed:.1f} m/s; expected racing "
            "tracks (moving boats, positions changing between fixes)"
        )
    eps_dp = max(EPS_MIN_M, EPS_S * speed)
    eps = max(CLUSTER_MIN_M, CLUSTER_S * speed)
    gate_max = max(GATE_MIN_M, GATE_S * speed)
    clear = CLEAR_S * speed
    min_boats = max(2, math.ceil(MIN_SHARE * n))
    turns, axis = _turns(paths, eps_dp)
    t0 = max(float(np.median([p.t[0] for p in paths])), -1e18)
    t_gun_lo = gun_t if gun_t is not None else -math.inf
    pre = _roundings(paths, turns, axis, clear, [(t_gun_lo, math.inf)] * n)
    if not pre:
        raise InputError(
            "course infer: no mark roundings in the tracks (no turn that changes the point "
            "of sail); expected race tracks that round marks"
        )
    found = _find(pre, n, eps, min_boats, gate_max)
    if not found.course:
        raise InputError(
            f"course infer: the boats' roundings fall together nowhere (no place rounded by "
            f"{min_boats} boats or more within {eps:.0f} m); expected tracks of one race"
        )
    # the first mark: the first item the fleet leaves for together, crossing a start line
    # together on the way (a place the fleet turns at before the start is none)
    start_at = _first_mark(found, paths, t0, speed, gun_t)
    if start_at is None:
        raise InputError(
            "course infer: no start found (no moment when the fleet leaves together for a "
            "mark it then rounds, crossing a line together on the way); give the gun with "
            "--start-time (ISO 8601 with offset), or tracks that cover the start"
        )
    start, gun = start_at
    # the race: each boat from its start (the gun when none is found) to its end
    ends, _ = race_ends(paths, gun.t)
    windows = [
        (st if math.isfinite(st) else gun.t, e if math.isfinite(e) else -math.inf)
        for st, e in zip(start.times, ends, strict=True)
    ]
    rs = _roundings(paths, turns, axis, clear, windows)
    found = _find(rs, n, eps, min_boats, gate_max)
    if not found.course:
        raise InputError(
            f"course infer: after the gun ({iso(gun.t)}) the boats' roundings fall together "
            "nowhere; check --start-time"
        )
    return _assemble(cut, paths, frame, found, gun, start, ends, axis, speed, eps, notes)


def _first_mark(
    found: _Found, paths: Sequence[BoatPath], t0: float, speed: float, gun_t: float | None
) -> tuple[LineEstimate, GunEstimate] | None:
    """The start line and gun towards the first item of the course the fleet leaves for
    together (:func:`~sailroute.analysis.infer_lines.infer_gun`) over a line it crosses
    together (:func:`~sailroute.analysis.infer_lines.start_line`), at least
    ``FIRST_LEG_S`` before it rounds it."""
    for p, it in enumerate(found.course):
        rounded = [found.rs[i].turn.t if i is not None else math.nan for i in found.aligned[p]]
        median_first = float(np.nanmedian(rounded))
        dep = infer_gun(paths, _item_centre(found, it), t0, median_first, speed)
        if dep is None and gun_t is None:
            continue
        ref = float(gun_t) if gun_t is not None else dep.t  # type: ignore[union-attr]
        got = start_line(
            paths,
            ref,
            _item_centre(found, it),
            [t if math.isfinite(t) else median_first for t in rounded],
            speed,
        )
        if got is None or got[1] > median_first - FIRST_LEG_S:
            continue
        line, early, early_sd = got
        if gun_t is not None:
            return line, GunEstimate(float(gun_t), 0.0, "given")
        assert dep is not None
        return line, GunEstimate(early, early_sd, "inferred", dep.boats_spread_s, dep.n_boats)
    return None


def _item_centre(found: _Found, it: int) -> tuple[float, float]:
    """A mark's centre, or the middle of a gate's two marks [m]."""
    members = [c for c, v in found.item.items() if v == it]
    c = np.mean(found.centres[members], axis=0)
    return float(c[0]), float(c[1])


def _assemble(
    tracks: Sequence[Track],
    paths: Sequence[BoatPath],
    frame: LocalFrame,
    found: _Found,
    gun: GunEstimate,
    start: LineEstimate,
    ends: Sequence[float],
    axis: float,
    speed: float,
    eps: float,
    notes: list[str],
) -> InferredCourse:
    n = len(paths)
    rs = found.rs
    # names in the order first rounded
    names: dict[int, str] = {}
    gates: list[tuple[str, str, str]] = []
    gate_of: dict[int, str] = {}
    n_mark = n_gate = 0
    for it in found.course:
        if it in names:
            continue
        members = sorted(c for c, v in found.item.items() if v == it)
        if len(members) == 2:
            n_gate += 1
            g = f"G{n_gate}"
            names[it] = g
            a, b = f"{g}a", f"{g}b"
            gates.append((g, a, b))
            gate_of[members[0]], gate_of[members[1]] = a, b
        else:
            n_mark += 1
            names[it] = f"M{n_mark}"
            gate_of[members[0]] = names[it]
    marks = []
    for c, mname in gate_of.items():
        idx = np.flatnonzero(found.label == c)
        est = np.array([rs[i].est for i in idx])
        centre = np.median(est, axis=0)
        spread = float(np.median(np.hypot(*(est - centre).T)))
        port = sum(rs[i].turn.turn_deg < 0 for i in idx)
        lat, lon = frame.to_latlon(centre[0], centre[1])
        marks.append(
            InferredMark(
                mname,
                float(centre[0]),
                float(centre[1]),
                float(lat),
                float(lon),
                "port" if 2 * port >= idx.size else "starboard",
                spread,
                int(idx.size),
                len({rs[i].boat for i in idx}),
                mname[:-1] if mname.startswith("G") else None,
            )
        )
    marks.sort(
        key=lambda m: (m.name[0] != "M", int("".join(ch for ch in m.name if ch.isdigit())), m.name)
    )
    by_name = {m.name: m for m in marks}
    legs: list[tuple[str, str | None]] = []
    rounded: list[tuple[float, ...]] = []
    for p, it in enumerate(found.course):
        nm = names[it]
        legs.append((nm, None if nm.startswith("G") else by_name[nm].rounding))
        rounded.append(tuple(rs[i].turn.t if i is not None else math.nan for i in found.aligned[p]))
    last_c = _item_centre(found, found.course[-1])
    finish = finish_line(paths, ends, last_c, rounded[-1], speed)
    if finish is None:
        notes.append(
            f"no finish line in the tracks (the boats do not stop together after the last "
            f"mark): the course ends at {legs[-1][0]}; add the finish line by hand"
        )
    else:
        legs.append(("finish", None))
        rounded.append(finish.times)
    for p, (nm, _) in enumerate(legs):
        missing = sum(not math.isfinite(t) for t in rounded[p])
        if missing:
            notes.append(f"leg {p + 1} ({nm}): {missing} of {n} boats' roundings not found")
    race_end = float(np.nanmax([e for e in ends if math.isfinite(e)] or [gun.t + 600.0]))
    twd, how = _twd(tracks, frame, axis, gun.t, race_end, paths)
    return InferredCourse(
        frame=frame,
        boats=tuple(p.name for p in paths),
        marks=tuple(marks),
        gates=tuple(gates),
        start=start,
        finish=finish,
        legs=tuple(legs),
        leg_roundings=tuple(rounded),
        gun=gun,
        axis_deg=axis,
        twd_deg=twd,
        twd_how=how,
        speed_ms=speed,
        eps_m=eps,
        notes=tuple(notes),
    )


def summary(ic: InferredCourse) -> dict[str, Any]:
    """The inferred course as a JSON-ready mapping (``docs/output-format.md``)."""

    def pt(xy: tuple[float, float]) -> dict[str, float]:
        lat, lon = ic.latlon(xy)
        return {
            "lat": round(lat, 9),
            "lon": round(lon, 9),
            "x_m": round(xy[0], 2),
            "y_m": round(xy[1], 2),
        }

    def line(le: LineEstimate | None) -> dict[str, Any] | None:
        if le is None:
            return None
        return {
            "pin": pt(le.pin),
            "committee": pt(le.committee),
            "length_m": round(le.length_m, 1),
            "depth_m": round(le.depth_m, 1),
            "n_boats": le.n_boats,
        }

    return {
        "boats": list(ic.boats),
        "gun": {
            "time": iso(ic.gun.t),
            "source": ic.gun.source,
            "sd_s": round(ic.gun.sd_s, 1),
            "boats_spread_s": None
            if not math.isfinite(ic.gun.boats_spread_s)
            else round(ic.gun.boats_spread_s, 1),
        },
        "marks": [
            {
                "name": m.name,
                "lat": round(m.lat, 9),
                "lon": round(m.lon, 9),
                "x_m": round(m.x, 2),
                "y_m": round(m.y, 2),
                "rounding": m.rounding,
                "spread_m": round(m.spread_m, 1),
                "n_roundings": m.n_roundings,
                "n_boats": m.n_boats,
                "gate": m.gate,
            }
            for m in ic.marks
        ],
        "gates": [{"name": g, "marks": [a, b]} for g, a, b in ic.gates],
        "start": line(ic.start),
        "finish": line(ic.finish),
        "legs": [{"to": to, "rounding": r} for to, r in ic.legs],
        "wind": {
            "axis_deg": round(ic.axis_deg, 1),
            "twd_deg": round(ic.twd_deg, 1),
            "how": ic.twd_how,
        },
        "speed_ms": round(ic.speed_ms, 2),
        "cluster_radius_m": round(ic.eps_m, 1),
        "notes": list(ic.notes),
    }
