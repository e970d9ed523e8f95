"""The fleet's ``report.html``: one page for the whole fleet, read at a glance for 60 boats.

What the page needs from an analysed fleet is one explicit, frozen structure,
:class:`FleetPage` (a :class:`FleetBoat` per boat, a :class:`FleetLeg` per boat and leg),
built from the analyses by one function, :func:`fleet_page`; everything after it
(:func:`results_order`, :func:`common_legs`, :func:`fold_notes`, :func:`fleet_report`) reads
only that structure.  The page (``sailroute analyze`` with several tracks) holds:

* the map: every boat's track coloured by its place (a continuous scale,
  :func:`rank_colours`), its marker moving with the time slider, the optimal legs from the
  leader's leg starts (dashed), the course over the tracks; the reader picks a boat (a
  list above the map, a click on its track or on its row, ``#boat=NAME`` in the address)
  and the others turn grey while its tacks and gybes appear;
* the results: boats that finished by their finish time, then the others by how far
  their known times go (unknown stays unknown, never a guess); sailed and lost times
  summed over the legs every boat's time is known for;
* the leg times (a row per boat, a column per leg), the start, each boat's gains on the
  fleet (:mod:`sailroute.analysis.gains`: a column per part, each leg folded with its top
  three named) and each leg's details (folded), every column sortable by a click on its
  header;
* the notes: the fleet's once, and a finding shared by several boats once with the boats
  named, folded (:func:`fold_notes`).

The tracks share one budget of points (:data:`~sailroute.report.page.FLEET_POINTS`), so
the page's size does not grow with the fleet.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from sailroute.course.model import Course
from sailroute.report.html import (
    HELP,
    _judged_notes,
    _layers,
    _polar_pct,
    _times_note,
    _wind_name,
    _wind_note,
    above_polar_legs,
    page_chart,
)
from sailroute.report.page import (
    FLEET_POINTS,
    FLEET_STEPS,
    MAX_ROUTE_POINTS,
    MIN_BOAT_POINTS,
    NoteGroup,
    Report,
    Route,
    Table,
    clock,
    optimal_route,
    sailed_route,
    slider_times,
    time_label,
)
from sailroute.report.tables import format_duration
from sailroute.timeutil import iso
from sailroute.units import KNOT
from sailroute.wind.base import WindField

if TYPE_CHECKING:  # pragma: no cover
    from sailroute.analysis.fleet import FleetAnalysis
    from sailroute.analysis.gains import FleetGains
    from sailroute.analysis.result import TrackAnalysis

__all__ = [
    "FleetBoat",
    "FleetLeg",
    "FleetPage",
    "boat_points",
    "common_legs",
    "fleet_page",
    "fleet_report",
    "fold_notes",
    "rank_colours",
    "results_order",
]

RANK_STOPS = ("#0d0887", "#6a00a8", "#b12a90", "#e16462", "#fca636")
"""Colour scale of the places, first to last (matplotlib's *plasma* from 0 to 0.8: dark
to light, every colour readable on the sea colour and apart from the grey of the boats
not picked)."""

PICK_HELP = (
    "Pick a boat in the list above the map, click its track or its row in a table (or "
    "open the page as report.html#boat=NAME) to highlight it: the other boats turn grey "
    "and its tacks (▲) and gybes (■) are drawn. Colours go with the place (dark: first, "
    "light: last). Click a column's header to sort a table."
)


@dataclass(frozen=True)
class FleetLeg:
    """One boat's leg, as the fleet's page shows it.

    Attributes
    ----------
    time_s : float
        Sailed time of the leg [s]; NaN when unknown.
    rank : int or None
        Rank of that time among the boats (1 = fastest); None when unknown.
    elapsed_s : float
        Time from the gun to the leg's end [s]; NaN when unknown.
    position : int or None
        Place at the leg's end (by ``elapsed_s``); None when unknown.
    loss_s, manoeuvres_s, speed_s, route_s : float
        Time lost against the optimal leg and its split [s]; NaN when unknown.
    polar : str
        Mean share of the polar speed (``96``, ``112 *`` above the polar, ``-``).
    tacks, gybes : int
        Manoeuvres sailed.
    wind : str
        The wind the leg is judged in (``measured``, ``fleet``, ``inferred``, ``scenario``).
    note : str
        Why the time is unknown, else empty.
    """

    time_s: float
    rank: int | None
    elapsed_s: float
    position: int | None
    loss_s: float
    manoeuvres_s: float
    speed_s: float
    route_s: float
    polar: str = "-"
    tacks: int = 0
    gybes: int = 0
    wind: str = ""
    note: str = ""


@dataclass(frozen=True)
class FleetBoat:
    """One boat on the fleet's page.

    Attributes
    ----------
    name : str
        As given (escaped when drawn).
    route : Route
        Its sailed track, already cut to its share of the page's points.
    legs : tuple of FleetLeg
        One per leg of the course, in order.
    start_t : float
        When it started [epoch s] (NaN: unknown).
    late_s : float
        Start after the gun [s].
    to_line_m : float
        Distance to the start line at the gun [m].
    side : str
        Side of the line at the gun (``pre-start`` or ``course``).
    speed_kn : float
        Speed at the gun [kn] (NaN: unknown).
    over_early : str
        ``no``, ``8 s``, ``8 s, returned``, ...
    line_offset_m : float
        How far off the surveyed line it crossed [m].
    notes : tuple of str
        Findings on this boat (the start, unknown legs), one sentence each.
    status : str
        Empty for a boat racing; else why it is not ranked (``did not start``, ...).
    """

    name: str
    route: Route
    legs: tuple[FleetLeg, ...]
    start_t: float = math.nan
    late_s: float = math.nan
    to_line_m: float = math.nan
    side: str = ""
    speed_kn: float = math.nan
    over_early: str = "no"
    line_offset_m: float = math.nan
    notes: tuple[str, ...] = ()
    status: str = ""

    @property
    def ranked(self) -> bool:
        """True when the boat is in the results (no status)."""
        return not self.status

    @property
    def finish_s(self) -> float:
        """Time from the gun to the finish [s]; NaN when unknown."""
        return self.legs[-1].elapsed_s if self.legs else math.nan

    @property
    def reached(self) -> int:
        """How many leg ends have a known time, counted up to the last known one."""
        known = [k for k, leg in enumerate(self.legs) if math.isfinite(leg.elapsed_s)]
        return known[-1] + 1 if known else 0


@dataclass(frozen=True)
class FleetPage:
    """Everything the fleet's page shows, built by :func:`fleet_page`.

    Attributes
    ----------
    course : Course
    boats : tuple of FleetBoat
        In the order given (the page sorts them: :func:`results_order`).
    scenario, router : str
        What the optimal legs were routed in and with.
    gun_t : float
        The gun [epoch s].
    notes : tuple of str
        About the fleet as a whole (the start line, the wind, the reference polar).
    judged : tuple of str
        What the boats are judged against and in which wind.
    optimal : Route or None
        The reference route drawn dashed (the optimal legs from the leader's leg starts).
    wind : (str, WindField) or None
        The wind drawn: its name and field.
    leader : str or None
        The leader's name as the fleet's analysis decides it (None: :func:`leader`).
    others : tuple of (str, str)
        The tracks that were not debriefed and why (name, status).
    gains : FleetGains or None
        The boats' gains on the fleet (boats named as in :attr:`boats`).
    gain_legs : tuple of int
        The legs the gains are summed over (0-based; every ranked boat's time known).
    banner : tuple of str
        Shown at the top of the page, above the summary and the tables (the course's
        polar beaten on most legs); not among :attr:`notes`.
    """

    course: Course
    boats: tuple[FleetBoat, ...]
    scenario: str = ""
    router: str = ""
    gun_t: float = math.nan
    notes: tuple[str, ...] = ()
    judged: tuple[str, ...] = ()
    optimal: Route | None = None
    wind: tuple[str, WindField] | None = None
    leader: str | None = None
    others: tuple[tuple[str, str], ...] = ()
    gains: FleetGains | None = None
    gain_legs: tuple[int, ...] = ()
    banner: tuple[str, ...] = ()

    def lead(self) -> int:
        """Index of the leader among :attr:`boats` (:attr:`leader`, else :func:`leader`)."""
        names = [b.name for b in self.boats]
        return names.index(self.leader) if self.leader in names else leader(self.boats)


# ---------------------------------------------------------------------------------------------
# reading the structure


def boat_points(n_boats: int, budget: int = FLEET_POINTS) -> int:
    """Points of each boat's track when ``n_boats`` share ``budget`` (within
    :data:`~sailroute.report.page.MIN_BOAT_POINTS` ..
    :data:`~sailroute.report.page.MAX_ROUTE_POINTS`)."""
    return int(np.clip(budget // max(n_boats, 1), MIN_BOAT_POINTS, MAX_ROUTE_POINTS))


def results_order(boats: Sequence[FleetBoat]) -> list[int]:
    """Indices of ``boats`` in the order of the results.

    First the ranked boats whose finish is known, by finish time; then the ranked boats
    whose finish is unknown, by how far their known times go (more leg ends first, then
    the time at the last one); then the boats that are not ranked (a status), in the
    order given.  Ties keep the order given.
    """

    def key(k: int) -> tuple[int, float, float]:
        b = boats[k]
        if not b.ranked:
            return (2, 0.0, 0.0)
        if math.isfinite(b.finish_s):
            return (0, b.finish_s, 0.0)
        last = b.legs[b.reached - 1].elapsed_s if b.reached else math.inf
        return (1, -b.reached, last)

    return sorted(range(len(boats)), key=key)


def common_legs(boats: Sequence[FleetBoat]) -> tuple[int, ...]:
    """0-based indices of the legs whose time is known for every ranked boat: the totals
    that compare boats are sums over these only."""
    ranked = [b for b in boats if b.ranked]
    if not ranked:
        return ()
    n = min(len(b.legs) for b in ranked)
    return tuple(k for k in range(n) if all(math.isfinite(b.legs[k].time_s) for b in ranked))


def leader(boats: Sequence[FleetBoat]) -> int:
    """Index of the boat ahead at the last leg end every ranked boat's time is known at
    (the finish when every boat finished); without one, the first of the results."""
    ranked = [k for k, b in enumerate(boats) if b.ranked]
    if not ranked:
        return 0
    for j in reversed(range(min(len(boats[k].legs) for k in ranked))):
        ends = [boats[k].legs[j].elapsed_s for k in ranked]
        if all(math.isfinite(e) for e in ends):
            return ranked[int(np.argmin(ends))]
    return results_order(boats)[0]


def rank_colours(n: int) -> list[str]:
    """``n`` colours (``#rrggbb``) from the first place to the last, evenly along
    :data:`RANK_STOPS`."""
    stops = np.array([[int(c[i : i + 2], 16) for i in (1, 3, 5)] for c in RANK_STOPS], float)
    f = np.linspace(0.0, 1.0, n) if n > 1 else np.zeros(max(n, 0))
    pos = f * (len(stops) - 1)
    lo = np.minimum(np.floor(pos).astype(int), len(stops) - 2)
    w = (pos - lo)[:, None]
    rgb = np.round(stops[lo] * (1 - w) + stops[lo + 1] * w).astype(int)
    return ["#{:02x}{:02x}{:02x}".format(*c) for c in rgb]


_NUMBER = re.compile(
    r"\d{4}-\d\d-\d\d(?:[T ][\d:.]+(?:Z|[+-]\d\d:\d\d)?)?"  # a date or time stamp
    r"|(?<!\w)[-+]?\d+(?:[.:]\d+)*"  # a number (not one inside a name: B1, P01)
)
"""What :func:`fold_notes` reads as a number: the part that may differ between boats."""


def fold_notes(notes: Sequence[tuple[str, str]]) -> tuple[NoteGroup, ...]:
    """Each boat's findings ``(boat, note)`` grouped: notes that say the same thing
    (the same words, numbers aside) make one group, in the order of their first one.

    A group of one boat is ``"boat: note"``; a note several boats share word for word is
    said once with the boats named; notes that differ only in their numbers (or in the
    boat's own name, as in a file name) are said once with ``…`` for what differs, each
    boat's own wording unfolded.
    """
    groups: dict[str, list[tuple[str, str]]] = {}
    for boat, note in notes:
        # a boat's own name in its note (its file): a word of its own, not inside another
        own = re.sub(rf"(?<!\w){re.escape(boat)}(?!\w)", "…", note) if boat else note
        groups.setdefault(_NUMBER.sub("…", own), []).append((boat, note))
    out = []
    for template, members in groups.items():
        boats = list(dict.fromkeys(b for b, _ in members))
        texts = list(dict.fromkeys(n for _, n in members))
        if len(members) == 1:
            out.append(NoteGroup(f"{members[0][0]}: {members[0][1]}"))
        elif len(texts) == 1:
            out.append(
                NoteGroup(f"{len(boats)} boats: {texts[0]}", (f"boats: {', '.join(boats)}",))
            )
        else:
            out.append(
                NoteGroup(f"{len(boats)} boats: {template}", tuple(f"{b}: {n}" for b, n in members))
            )
    return tuple(out)


# ---------------------------------------------------------------------------------------------
# from the analyses


def _fleet_leg(leg: Any, row: Mapping[str, Any] | None) -> FleetLeg:
    """A :class:`FleetLeg` from a leg analysis and its row of the fleet ranking."""
    known = bool(leg.known)
    nan = math.nan
    return FleetLeg(
        time_s=float(leg.sailed_time_s) if known else nan,
        rank=row["leg_rank"] if row is not None else None,
        elapsed_s=float(row["elapsed_s"]) if row is not None else nan,
        position=row["position"] if row is not None else None,
        loss_s=float(leg.loss_s) if known else nan,
        manoeuvres_s=float(leg.split.manoeuvres) if known else nan,
        speed_s=float(leg.split.speed) if known else nan,
        route_s=float(leg.split.route) if known else nan,
        polar=_polar_pct(leg),
        tacks=int(leg.sailed_tacks),
        gybes=int(leg.sailed_gybes),
        wind=leg.wind_source,
        note=leg.note,
    )


def _over_early(st: Any) -> str:
    if st.ocs_s is not None:
        return f"{st.ocs_s:.0f} s" + (", returned" if st.ocs_returned else "")
    return "returned" if st.ocs_returned else "no"


def _boat_notes(
    notes: Sequence[str], names: Sequence[str]
) -> tuple[list[str], dict[str, list[str]]]:
    """The run's notes split into those about the fleet and those about one boat (written
    ``"<boat>: ..."``), the latter by boat without the prefix."""
    fleet: list[str] = []
    own: dict[str, list[str]] = {}
    by_length = sorted(names, key=len, reverse=True)  # "a-2: ..." is a-2's, not a's
    for n in notes:
        boat = next((b for b in by_length if n.startswith(f"{b}: ")), None)
        if boat is None:
            fleet.append(n)
        else:
            own.setdefault(boat, []).append(n[len(boat) + 2 :])
    return fleet, own


def fleet_page(
    analyses: Sequence[TrackAnalysis],
    rows: Sequence[Mapping[str, Any]],
    notes: Sequence[str] = (),
    wind: tuple[str, WindField] | None = None,
    *,
    budget: int = FLEET_POINTS,
    fleet: FleetAnalysis | None = None,
    banner: Sequence[str] = (),
) -> FleetPage:
    """The fleet's page from its analyses: the one place that reads the analysis model.

    Parameters
    ----------
    analyses : sequence of TrackAnalysis
        One per boat (two or more).
    rows : sequence of mapping
        The leg ranking, :func:`sailroute.analysis.debrief.fleet_ranking` (``leg``,
        ``boat``, ``leg_rank``, ``elapsed_s``, ``position``, ...).
    notes : sequence of str
        The run's notes; one that starts ``"<boat>: "`` is that boat's (folded with the
        other boats' findings on the page), the others are about the fleet.
    wind : (str, WindField), optional
        The wind drawn; default the first boat's first leg's.
    budget : int
        Points of all the tracks together (:func:`boat_points`).
    fleet : FleetAnalysis, optional
        The fleet's analysis: it decides each boat's status (a boat without a place in the
        results carries what triage found), the leader, the tracks not debriefed and the
        gains.
    banner : sequence of str
        Lines for the top of the page (:attr:`FleetPage.banner`); one of them among
        ``notes`` is shown there only.
    """
    course = analyses[0].course
    by = {(r["leg"], r["boat"]): r for r in rows}
    share = boat_points(len(analyses), budget)
    fleet_notes, own = _boat_notes(
        [n for n in notes if n not in banner], [a.track.name for a in analyses]
    )
    boats = []
    for a in analyses:
        st = a.segmentation.start
        entry = fleet.entry(a.track.name).status if fleet is not None else None
        boats.append(
            FleetBoat(
                name=a.track.name,
                route=replace(sailed_route(a, share), name=a.track.name),
                legs=tuple(
                    _fleet_leg(leg, by.get((leg.index + 1, a.track.name))) for leg in a.legs
                ),
                start_t=float(st.crossing.t),
                late_s=float(st.late_s),
                to_line_m=float(st.distance_at_gun_m),
                side=st.side_at_gun,
                speed_kn=float(st.speed_at_gun_ms) / KNOT,
                over_early=_over_early(st),
                line_offset_m=float(st.line_offset_m),
                notes=(
                    *a.notes,
                    *([above] if (above := above_polar_legs(a)) else []),
                    *own.get(a.track.name, ()),
                ),
                status=""
                if entry is None or entry.ranked
                else "; ".join(c.value for c in entry.classes),
            )
        )
    names = [a.track.name for a in analyses]
    told = fleet.leader() if fleet is not None else None
    lead = names.index(told) if told in names else leader(boats)
    opt = replace(
        optimal_route(analyses[lead]),
        name=f"optimal from {analyses[lead].track.name}'s leg starts",
    )
    return FleetPage(
        course=course,
        boats=tuple(boats),
        scenario=analyses[0].scenario,
        router=analyses[0].router,
        gun_t=float(analyses[0].segmentation.start.gun_t),
        notes=tuple(fleet_notes),
        judged=tuple(_judged_notes(analyses, name_legs=False)),
        optimal=opt,
        wind=wind if wind is not None else (_wind_name(analyses[0]), analyses[0].wind),
        leader=told,
        others=()
        if fleet is None
        else tuple(
            (e.name, "; ".join(c.value for c in e.status.classes) or "not debriefed")
            for e in fleet.entries
            if e.name not in names
        ),
        gains=fleet.gains if fleet is not None else None,
        gain_legs=fleet.table.common_legs() if fleet is not None else (),
        banner=tuple(banner),
    )


# ---------------------------------------------------------------------------------------------
# the page


def _legs_text(legs: Sequence[int], n: int) -> str:
    """``1-5, 7`` (1-based) for 0-based leg indices; ``all n`` when every leg."""
    if len(legs) == n:
        return f"all {n} legs"
    if not legs:
        return "no leg"
    runs: list[list[int]] = []
    for k in legs:
        if runs and k == runs[-1][-1] + 1:
            runs[-1].append(k)
        else:
            runs.append([k])
    parts = [f"{r[0] + 1}" if len(r) == 1 else f"{r[0] + 1}-{r[-1] + 1}" for r in runs]
    return ("leg " if len(legs) == 1 else "legs ") + ", ".join(parts)


def _key(v: float) -> float | None:
    return float(v) if math.isfinite(v) else None


def _duration(v: float) -> str:
    return format_duration(v) if math.isfinite(v) else "unknown"


def _signed(v: float, nd: int = 1) -> str:
    return f"{v:+.{nd}f}" if math.isfinite(v) else "-"


def _sum(values: Sequence[float]) -> float:
    return float(sum(values)) if values else math.nan


Cell = tuple[str, float | None]
"""A table cell: its text and the number it sorts by (None: text, or unknown)."""


def _boat_table(
    caption: str,
    headers: Sequence[str],
    page: FleetPage,
    order: Sequence[int],
    places: Mapping[int, int],
    cells: Callable[[FleetBoat], Sequence[Cell]],
    **kw: Any,
) -> Table:
    """A sortable table with a row per boat of ``order``: its place, its name, then
    ``cells(boat)``; a click on a row picks the boat."""
    rows, keys = [], []
    for k in order:
        b = page.boats[k]
        row: list[Cell] = [(str(places[k]) if k in places else "-", places.get(k)), (b.name, None)]
        row += cells(b)
        rows.append(tuple(c for c, _ in row))
        keys.append(tuple(v for _, v in row))
    return Table(
        caption,
        ("place", "boat", *headers),
        tuple(rows),
        keys=tuple(keys),
        boats=tuple(order),
        **kw,
    )


def _results_table(
    page: FleetPage, order: Sequence[int], places: Mapping[int, int], colours: Sequence[str]
) -> Table:
    boats = page.boats
    common = common_legs(boats)
    n_legs = len(page.course.legs)
    best = min((b.finish_s for b in boats if b.ranked and math.isfinite(b.finish_s)), default=None)
    status = any(not b.ranked for b in boats)

    def cells(b: FleetBoat) -> list[Cell]:
        sailed = _sum([b.legs[j].time_s for j in common]) if b.ranked else math.nan
        lost = _sum([b.legs[j].loss_s for j in common]) if b.ranked else math.nan
        behind = b.finish_s - best if best is not None else math.nan
        known = sum(math.isfinite(leg.time_s) for leg in b.legs)
        out = [
            (_duration(b.finish_s), _key(b.finish_s)),
            (format_duration(behind) if math.isfinite(behind) else "-", _key(behind)),
            (f"{known} of {n_legs}", float(known)),
            (_duration(sailed) if common else "-", _key(sailed)),
            (_signed(lost), _key(lost)),
            (_signed(b.late_s), _key(b.late_s)),
            (b.over_early, None),
        ]
        return out + ([(b.status or "racing", None)] if status else [])

    headers = ["finish", "behind", "legs known", "sailed", "lost s", "start late s", "over early"]
    return _boat_table(
        "Results: place at the finish (boats whose finish is unknown come after, by how far "
        "their known times go); finish and behind from the gun; sailed (from the start "
        f"crossing) and lost against the optimal legs over {_legs_text(common, n_legs)}, "
        "the legs every boat's time is known for",
        [*headers, *(["status"] if status else [])],
        page,
        order,
        places,
        cells,
        swatches=tuple(colours[k] for k in order),
        name="results",
    )


def _leg_times_table(page: FleetPage, order: Sequence[int], places: Mapping[int, int]) -> Table:
    legs = page.course.legs

    def cells(b: FleetBoat) -> list[Cell]:
        out: list[Cell] = []
        for j in range(len(legs)):
            leg = b.legs[j] if j < len(b.legs) else None
            if leg is None or not math.isfinite(leg.time_s):
                out.append(("unknown", None))
            else:
                rank = f" ({leg.rank})" if leg.rank else ""
                out.append((format_duration(leg.time_s) + rank, leg.time_s))
        return out

    return _boat_table(
        "Leg times (rank on the leg)",
        [f"{j + 1}: {s.label.replace('->', '→')}" for j, s in enumerate(legs)],
        page,
        order,
        places,
        cells,
        name="legs",
    )


def _start_table(page: FleetPage, order: Sequence[int], places: Mapping[int, int]) -> Table:
    off = page.course.utc_offset_s

    def cells(b: FleetBoat) -> list[Cell]:
        signed_line = b.to_line_m * (-1.0 if b.side == "course" else 1.0)
        return [
            (clock(b.start_t, off) if math.isfinite(b.start_t) else "unknown", _key(b.start_t)),
            (_signed(b.late_s), _key(b.late_s)),
            (
                f"{b.to_line_m:.0f} ({b.side})" if math.isfinite(b.to_line_m) else "-",
                _key(signed_line),
            ),
            (f"{b.speed_kn:.1f}" if math.isfinite(b.speed_kn) else "-", _key(b.speed_kn)),
            (b.over_early, None),
            (
                f"{b.line_offset_m:.0f}" if math.isfinite(b.line_offset_m) else "-",
                _key(b.line_offset_m),
            ),
        ]

    return _boat_table(
        "Start",
        [
            "start (local)",
            "late s",
            "to the line at the gun m",
            "speed at the gun kn",
            "over early",
            "line offset m",
        ],
        page,
        order,
        places,
        cells,
        name="start",
    )


def _leg_table(page: FleetPage, j: int, order: Sequence[int], places: Mapping[int, int]) -> Table:
    spec = page.course.legs[j]

    def cells(b: FleetBoat) -> list[Cell]:
        g = b.legs[j]
        return [
            (_duration(g.time_s), _key(g.time_s)),
            (str(g.rank) if g.rank is not None else "-", g.rank),
            (_duration(g.elapsed_s), _key(g.elapsed_s)),
            (str(g.position) if g.position is not None else "-", g.position),
            (_signed(g.loss_s), _key(g.loss_s)),
            (_signed(g.manoeuvres_s), _key(g.manoeuvres_s)),
            (_signed(g.speed_s), _key(g.speed_s)),
            (_signed(g.route_s), _key(g.route_s)),
            (g.polar, _polar_key(g.polar)),
            (f"{g.tacks}/{g.gybes}", float(g.tacks + g.gybes)),
            (g.wind, None),
            (g.note, None),
        ]

    return _boat_table(
        f"Leg {j + 1}: {spec.label.replace('->', '→')}: time (rank), at its end from the gun "
        "(position), time lost against the optimal leg and its split",
        [
            "time",
            "rank",
            "at the end",
            "position",
            "lost s",
            "manoeuvres s",
            "speed s",
            "route s",
            "polar %",
            "tacks/gybes",
            "wind",
            "note",
        ],
        page,
        [k for k in order if j < len(page.boats[k].legs)],
        places,
        cells,
        collapsed=True,
        name=f"leg-{j + 1}",
    )


GAIN_HEADERS = ("total s", "start s", "speed s", "height s", "side s", "manoeuvres s", "other s")
"""The gains table's columns after place and boat."""


def _gain_cells(values: Sequence[float]) -> list[Cell]:
    return [(_signed(v), _key(v)) for v in values]


def _gains_tables(page: FleetPage, order: Sequence[int], places: Mapping[int, int]) -> list[Table]:
    """The gains on the fleet's median: summed over the legs every ranked boat has, then
    one folded table per leg naming its top three."""
    g = page.gains
    if g is None:
        return []
    t = g.median
    by = {b: k for k, b in enumerate(t.boats)}
    rows = [k for k in order if page.boats[k].name in by]
    summed = t.summed(page.gain_legs)
    names = ("total", "start", "speed", "height", "side", "manoeuvres", "other")

    def total(b: FleetBoat) -> list[Cell]:
        k = by[b.name]
        return _gain_cells([float(summed[n][k]) for n in names])

    n_legs = len(page.course.legs)
    out = [
        _boat_table(
            "Gains on the fleet's median [s, + faster] over the start and "
            f"{_legs_text(page.gain_legs, n_legs)}: total = start + speed (SOG against the "
            "fleet's at the same TWA) + height (the angle sailed against the fleet's) + side "
            "(the wind it had against the leg's axis) + manoeuvres (count × cost against the "
            "fleet's median) + other (distance)",
            GAIN_HEADERS,
            page,
            rows,
            places,
            total,
            name="gains",
        )
    ]
    for j in range(len(t.labels)):

        def leg(b: FleetBoat, j: int = j) -> list[Cell]:
            k = by[b.name]
            return _gain_cells([float(t.total_s[k, j]), math.nan, *map(float, t.parts_s[k, j])])

        top = ", ".join(g.top[j]) or "-"
        out.append(
            _boat_table(
                f"Gains on leg {j + 1}: {t.labels[j].replace('->', '→')} (top three: {top})",
                GAIN_HEADERS,
                page,
                rows,
                places,
                leg,
                collapsed=True,
                name=f"gains-{j + 1}",
            )
        )
    return out


def _others_table(page: FleetPage) -> list[Table]:
    """The tracks that were not debriefed, with what triage found."""
    if not page.others:
        return []
    return [
        Table(
            "Not debriefed (no track to draw, no place)",
            ("boat", "status"),
            tuple((name, status) for name, status in page.others),
            name="not-debriefed",
        )
    ]


def _polar_key(text: str) -> float | None:
    m = _NUMBER.match(text)
    return float(m.group(0)) if m else None


def fleet_report(page: FleetPage) -> Report:
    """The fleet's page (:class:`~sailroute.report.page.Report`) from :class:`FleetPage`.

    Routes in the order of the results, each in its place's colour
    (:func:`rank_colours`), then the optimal legs; tables: the results, the leg times,
    the start and each leg's details (folded), all sortable and a row picks its boat;
    notes: how to read the page, what the boats are judged against, the fleet's notes,
    then each boat's findings folded (:func:`fold_notes`); the banner above the summary.
    """
    course, off = page.course, page.course.utc_offset_s
    order = results_order(page.boats)
    finishers = [k for k in order if page.boats[k].ranked and math.isfinite(page.boats[k].finish_s)]
    places = {k: i + 1 for i, k in enumerate(finishers)}
    colours_in_order = rank_colours(len(order))
    colours = [""] * len(order)
    for i, k in enumerate(order):
        colours[k] = colours_in_order[i]
    sailed = [replace(page.boats[k].route, colour=colours[k], boat=True) for k in order]
    routes = (*sailed, *([page.optimal] if page.optimal is not None else []))
    times = slider_times(sailed, FLEET_STEPS)
    layers = _layers(dict([page.wind]) if page.wind else {}, course, routes, times)
    # the tables' rows pick boats by their index among the routes with a marker
    position = {k: i for i, k in enumerate(order)}
    tables = [
        _results_table(page, order, places, colours),
        _leg_times_table(page, order, places),
        _start_table(page, order, places),
        *_gains_tables(page, order, places),
        *(_leg_table(page, j, order, places) for j in range(len(course.legs))),
    ]
    tables = [replace(t, boats=tuple(position[k] for k in t.boats)) for t in tables]
    tables += _others_table(page)
    ranked = [b for b in page.boats if b.ranked]
    lead = page.boats[page.lead()].name if page.boats else ""
    first = (
        f"; first {page.boats[finishers[0]].name} in "
        f"{format_duration(page.boats[finishers[0]].finish_s)}"
        if finishers
        else ""
    )
    summary = (
        f"{len(page.boats)} boats · scenario {page.scenario} · router {page.router} · gun "
        f"{time_label(page.gun_t, off)} on {iso(page.gun_t + off)[:10]}",
        f"{len(finishers)} of {len(ranked)} ranked boats with a known finish"
        + first
        + (f"; the optimal legs are from {lead}'s leg starts" if page.optimal else ""),
    )
    notes = [
        HELP,
        PICK_HELP,
        *page.judged,
        *page.notes,
        *(
            [
                "The dashed line is the optimal route of each leg from the leader's own leg "
                "start point and time (the leader: the boat ahead at the last leg end every "
                "boat's time is known at)."
            ]
            if page.optimal is not None
            else []
        ),
        _times_note(course),
        _wind_note(layers),
    ]
    folded = fold_notes([(b.name, n) for k in order for b in [page.boats[k]] for n in b.notes])
    return Report(
        f"{course.name} — fleet of {len(page.boats)}",
        summary,
        course,
        tuple(routes),
        tuple(layers),
        times,
        tuple(tables),
        tuple(notes),
        leg_numbers=False,
        legend_beside=True,
        folded=folded,
        pick=True,
        chart=page_chart(course, [page.wind[1]] if page.wind else [], routes),
        banner=page.banner,
    )
