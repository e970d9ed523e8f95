"""A fleet debriefed: the boats, what triage found, and leg tables that compare like with like.

:class:`FleetAnalysis` holds every boat's entry (:mod:`sailroute.analysis.triage`), the
analyses of the boats that were debriefed, and a :class:`LegTable` (boats × legs) from
which the rankings come.  The tables say "unknown" where a time is unknown: a total is
over the legs every compared boat has (:meth:`LegTable.common_legs`), a position at a leg
end only among the boats whose time there is known, and the leader is the boat ahead at the
last leg end every ranked boat has (:meth:`LegTable.leader`), not the one whose finish
happens to be known.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, overload

import numpy as np
from numpy.typing import NDArray

from sailroute.analysis.gains import FleetGains
from sailroute.analysis.result import TrackAnalysis
from sailroute.analysis.triage import BoatEntry, Triage
from sailroute.course.model import Course

__all__ = ["FleetAnalysis", "LegTable", "ResultRow", "fleet_ranking", "leg_table"]


@dataclass(frozen=True, eq=False)
class LegTable:
    """The fleet's legs, boats as rows.

    Attributes
    ----------
    boats : tuple of str
        The analysed boats, in the order given.
    labels : tuple of str
        The legs' labels.
    time_s : ndarray
        Sailed leg time [s], boats × legs (NaN: unknown).
    end_s : ndarray
        Elapsed time from the gun at each leg end [s] (NaN: unknown).
    loss_s : ndarray
        Time lost against the optimal leg [s] (NaN: unknown).
    ranked : ndarray of bool
        Per boat: it has a place in the results (:attr:`BoatStatus.ranked`).
    """

    boats: tuple[str, ...]
    labels: tuple[str, ...]
    time_s: NDArray[np.float64]
    end_s: NDArray[np.float64]
    loss_s: NDArray[np.float64]
    ranked: NDArray[np.bool_]

    def common_legs(self, rows: NDArray[np.bool_] | None = None) -> tuple[int, ...]:
        """Indices of the legs whose time every boat of ``rows`` (default: the ranked boats)
        knows."""
        m = self.ranked if rows is None else rows
        if not m.any():
            return ()
        ok = np.isfinite(self.time_s[m]).all(axis=0)
        return tuple(int(i) for i in np.flatnonzero(ok))

    def totals(self, rows: NDArray[np.bool_] | None = None) -> NDArray[np.float64]:
        """Per boat, the sum of its leg times over :meth:`common_legs` [s] (NaN for a boat
        outside ``rows`` that lacks one of them)."""
        legs = list(self.common_legs(rows))
        out: NDArray[np.float64] = self.time_s[:, legs].sum(axis=1)
        return out

    def last_common_end(self) -> int | None:
        """The last leg whose end every ranked boat has a known time for (None: none)."""
        m = self.ranked
        if not m.any():
            return None
        ok = np.flatnonzero(np.isfinite(self.end_s[m]).all(axis=0))
        return int(ok[-1]) if ok.size else None

    def leader(self) -> str | None:
        """The boat ahead at :meth:`last_common_end` (None: no such leg end): the leader
        from the legs whose times are known, not the first boat whose finish is."""
        i = self.last_common_end()
        if i is None:
            return None
        e = np.where(np.isfinite(self.end_s[:, i]), self.end_s[:, i], np.inf)
        return self.boats[int(np.argmin(e))]

    def positions(self, i: int, rows: NDArray[np.bool_] | None = None) -> list[int | None]:
        """Place of each boat of ``rows`` (default: all) at the end of leg ``i`` among those
        whose time there is known (None: unknown, or not in ``rows``)."""
        m = np.ones(len(self.boats), bool) if rows is None else rows
        return _ranks(np.where(m, self.end_s[:, i], np.nan))

    def leg_ranks(self, i: int) -> list[int | None]:
        """Rank of each boat by its time on leg ``i`` (None: unknown)."""
        return _ranks(self.time_s[:, i])


def leg_table(analyses: Sequence[TrackAnalysis], ranked: Sequence[bool] | None = None) -> LegTable:
    """The :class:`LegTable` of analysed boats (``ranked``: default all)."""
    n = min((len(a.legs) for a in analyses), default=0)
    shape = (len(analyses), n)
    time_s, end_s, loss_s = np.full(shape, np.nan), np.full(shape, np.nan), np.full(shape, np.nan)
    for r, a in enumerate(analyses):
        gun = a.segmentation.start.gun_t
        for i, leg in enumerate(a.legs[:n]):
            time_s[r, i] = leg.sailed_time_s
            end_s[r, i] = leg.t_end - gun
            loss_s[r, i] = leg.loss_s
    return LegTable(
        tuple(a.track.name for a in analyses),
        tuple(a.legs[i].label for i in range(n)) if analyses else (),
        time_s,
        end_s,
        loss_s,
        np.array([True] * len(analyses) if ranked is None else list(ranked), bool),
    )


def _ranks(values: Sequence[float] | NDArray[np.float64]) -> list[int | None]:
    """1-based ranks of the finite values (ties in input order), None for the others."""
    v = np.asarray(values, float)
    ok = np.flatnonzero(np.isfinite(v))
    out: list[int | None] = [None] * v.size
    for r, k in enumerate(ok[np.argsort(v[ok], kind="stable")]):
        out[int(k)] = r + 1
    return out


def fleet_ranking(
    analyses: Sequence[TrackAnalysis], ranked: Sequence[bool] | None = None
) -> list[dict[str, Any]]:
    """Rank boats per leg by sailed leg time and by elapsed time at the leg's end.

    A leg of unknown time (:attr:`LegAnalysis.known` False) is left out of that leg's
    ranking (``leg_rank`` None), a leg end of unknown time out of the positions
    (``position`` None).  ``ranked`` (a place in the results) does not change them: a boat
    over early or retired was where it was at each leg end it reached.

    Returns
    -------
    list of dict
        One row per (leg, boat): ``leg`` (1-based), ``label``, ``boat``,
        ``leg_time_s``, ``leg_rank``, ``elapsed_s`` (from the gun), ``position``,
        ``loss_s`` (NaN when unknown), ``note`` (why unknown, else empty).
    """
    rows: list[dict[str, Any]] = []
    if not analyses:
        return rows
    table = leg_table(analyses, ranked)
    for i in range(len(table.labels)):
        leg_rank = table.leg_ranks(i)
        pos = table.positions(i)
        for k, a in enumerate(analyses):
            rows.append(
                {
                    "leg": i + 1,
                    "label": a.legs[i].label,
                    "boat": a.track.name,
                    "leg_time_s": float(table.time_s[k, i]),
                    "leg_rank": leg_rank[k],
                    "elapsed_s": float(table.end_s[k, i]),
                    "position": pos[k],
                    "loss_s": a.legs[i].loss_s,
                    "note": a.legs[i].note,
                }
            )
    return rows


@dataclass(frozen=True)
class ResultRow:
    """One boat in the fleet's results.

    Attributes
    ----------
    boat : str
    position : int or None
        Place at the finish among the ranked boats whose finish is known (None: unknown,
        or no place).
    finish_s : float
        Elapsed time from the gun at the finish [s] (NaN: unknown).
    common_position : int or None
        Place at the last leg end every ranked boat has (:meth:`LegTable.last_common_end`)
        among the boats whose time there is known.
    total_s : float
        Sailed time over the legs every ranked boat has [s] (NaN: the boat lacks one).
    loss_s : float
        Time lost against the optimum over those legs [s].
    known_legs : int
        Legs of known time.
    status : tuple of str
        What triage found (:class:`~sailroute.analysis.triage.BoatClass` values); empty for
        a clean race.
    analysed : bool
        The boat was debriefed.
    ranked : bool
        It has a place in the results.
    """

    boat: str
    position: int | None
    finish_s: float
    common_position: int | None
    total_s: float
    loss_s: float
    known_legs: int
    status: tuple[str, ...]
    analysed: bool
    ranked: bool


@dataclass(frozen=True, eq=False)
class FleetAnalysis(Sequence[TrackAnalysis]):
    """A fleet debriefed: a sequence of the debriefed boats' analyses, plus the fleet.

    Attributes
    ----------
    course : Course
    triage : Triage
        Every track and what was found (:func:`~sailroute.analysis.triage.triage_fleet`).
    analyses : tuple of TrackAnalysis
        The debriefed boats, in the order given.
    notes : tuple of str
        The run's notes besides triage's (the wind, the reference).
    gains : FleetGains or None
        Each boat's gains on the fleet (:func:`sailroute.analysis.gains.fleet_gains`; None:
        not measured, a boat model without a polar).
    """

    course: Course
    triage: Triage
    analyses: tuple[TrackAnalysis, ...]
    notes: tuple[str, ...] = ()
    gains: FleetGains | None = None

    def __len__(self) -> int:
        return len(self.analyses)

    @overload
    def __getitem__(self, k: int) -> TrackAnalysis: ...

    @overload
    def __getitem__(self, k: slice) -> Sequence[TrackAnalysis]: ...

    def __getitem__(self, k: int | slice) -> TrackAnalysis | Sequence[TrackAnalysis]:
        return self.analyses[k]

    @property
    def entries(self) -> tuple[BoatEntry, ...]:
        """Every track's entry."""
        return self.triage.entries

    def entry(self, boat: str) -> BoatEntry:
        """The entry of ``boat`` (KeyError: no such boat)."""
        for e in self.entries:
            if e.name == boat:
                return e
        raise KeyError(boat)

    @property
    def ranked(self) -> tuple[bool, ...]:
        """Per analysis: the boat has a place in the results."""
        return tuple(self.entry(a.track.name).status.ranked for a in self.analyses)

    @property
    def table(self) -> LegTable:
        """The analysed boats' legs."""
        return leg_table(self.analyses, self.ranked)

    def rows(self) -> list[dict[str, Any]]:
        """:func:`fleet_ranking` of the analysed boats (places among the ranked ones)."""
        return fleet_ranking(self.analyses, self.ranked)

    def leader(self) -> str | None:
        """The ranked boat ahead at the last leg end every ranked boat has (None: none)."""
        return self.table.leader()

    def all_notes(self) -> tuple[str, ...]:
        """Triage's notes, then the run's."""
        return (*self.triage.notes(), *self.notes)

    def results(self) -> tuple[ResultRow, ...]:
        """Every boat (analysed or not): finish order where known, then the rest."""
        tab = self.table
        by = {b: k for k, b in enumerate(tab.boats)}
        n = len(tab.labels)
        finish = tab.positions(n - 1, tab.ranked) if n else []
        common = tab.last_common_end()
        cpos = tab.positions(common) if common is not None else [None] * len(tab.boats)
        legs = list(tab.common_legs())
        totals = tab.totals()
        loss = tab.loss_s[:, legs].sum(axis=1)
        rows = []
        for e in self.entries:
            k = by.get(e.name)
            status = tuple(c.value for c in e.status.classes)
            if k is None:
                rows.append(
                    ResultRow(e.name, None, np.nan, None, np.nan, np.nan, 0, status, False, False)
                )
                continue
            rows.append(
                ResultRow(
                    e.name,
                    finish[k] if n else None,
                    float(tab.end_s[k, n - 1]) if n else np.nan,
                    cpos[k],
                    float(totals[k]) if legs else np.nan,
                    float(loss[k]) if legs else np.nan,
                    int(np.isfinite(tab.time_s[k]).sum()),
                    status,
                    True,
                    bool(tab.ranked[k]),
                )
            )
        return tuple(
            sorted(
                rows,
                key=lambda r: (
                    not r.analysed,
                    r.position is None,
                    r.position or 0,
                    r.common_position is None,
                    r.common_position or 0,
                ),
            )
        )
