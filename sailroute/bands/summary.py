"""The bands of a routed ensemble: P10/P50/P90 per leg and race, the breakdown by source, sides.

Percentiles are ``numpy.percentile`` (linear) over the members' leg times; the race
time of a member is the sum of its legs, so the race band is not the sum of the leg
bands.  The one-at-a-time breakdown gives, per source, the range (max - min) of the
times of the members at that source's quantiles 0.1, 0.5 and 0.9 with the other sources at
their nominal values: the source's P10-P90 width when its effect is monotonic.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Final

import numpy as np
from numpy.typing import NDArray

from sailroute.course.uncertainty import UncertaintySpec
from sailroute.routing.types import LegResult

__all__ = ["BAND_STATS", "MEMBER_TRACK_POINTS", "SIDE_LABELS", "BandSummary", "member_track"]

BAND_STATS: Final = ("p10", "p50", "p90")
"""Columns of a band, in order."""
SIDE_LABELS: Final = ("left", "middle", "right", "tie")
"""Side verdicts (:func:`sailroute.routing.sides.side_verdict`), in order."""
_Q: Final = (10.0, 50.0, 90.0)
MEMBER_TRACK_POINTS: Final = 400
"""Most points kept of a member's route for the page's spread."""


def member_track(legs: Any) -> NDArray[np.float64]:
    """A member's route for the spread: its legs' track points joined, thinned evenly to
    at most :data:`MEMBER_TRACK_POINTS` (the last point kept), shape (n, 2) [m]."""
    xy = np.concatenate([np.column_stack([r.track.x, r.track.y]) for r in legs])
    step = max(1, -(-len(xy) // MEMBER_TRACK_POINTS))
    keep = np.unique(np.r_[np.arange(0, len(xy), step), len(xy) - 1])
    return np.asarray(xy[keep], float)


@dataclass(frozen=True, eq=False)
class BandSummary:
    """Leg-time bands of one scenario.

    Attributes
    ----------
    scenario : str
        Scenario name.
    leg_labels : tuple of str
        Leg labels.
    members : tuple of str
        Member names of the main ensemble.
    times_s : ndarray, shape (n_members, n_legs)
        Leg times of the main ensemble [s].
    nominal_s : ndarray, shape (n_legs,)
        Leg times in the scenario as given [s].
    oat_s : mapping of str to ndarray
        Source -> leg times of its one-at-a-time members, shape (n_quantiles, n_legs)
        [s].
    sides : tuple of tuple of str
        ``sides[i][k]``: verdict on leg ``k`` of member ``i`` (:data:`SIDE_LABELS`).
    references : mapping of str to tuple of float
        Reference leg times [s] (the course's and the scenario's).
    uncertainty : UncertaintySpec
        What was uncertain (after fitting a shift model).
    notes : tuple of str
        How the uncertainty was chosen (e.g. defaults used).
    nominal_legs : tuple of LegResult
        The routed legs of the scenario as given (for maps and the page).
    member_tracks : tuple of ndarray, shape (n, 2)
        The route of each member of the main ensemble, all legs joined, ``x, y`` in the
        course frame [m], at most :data:`MEMBER_TRACK_POINTS` points (the page draws them
        as a faint spread).
    """

    scenario: str
    leg_labels: tuple[str, ...]
    members: tuple[str, ...]
    times_s: NDArray[np.float64]
    nominal_s: NDArray[np.float64]
    oat_s: Mapping[str, NDArray[np.float64]] = field(default_factory=dict)
    sides: tuple[tuple[str, ...], ...] = ()
    references: Mapping[str, tuple[float, ...]] = field(default_factory=dict)
    uncertainty: UncertaintySpec = field(default_factory=UncertaintySpec)
    notes: tuple[str, ...] = ()
    nominal_legs: tuple[LegResult, ...] = ()
    member_tracks: tuple[NDArray[np.float64], ...] = ()

    @property
    def totals_s(self) -> NDArray[np.float64]:
        """Race time of each member [s]."""
        return np.asarray(self.times_s, dtype=float).sum(axis=1)

    def bands(self) -> NDArray[np.float64]:
        """P10, P50, P90 per leg and for the race (last row) [s], shape (n_legs + 1, 3)."""
        table = np.column_stack([self.times_s, self.totals_s])
        return np.percentile(table, _Q, axis=0).T

    def oat_widths(self) -> dict[str, NDArray[np.float64]]:
        """Source -> width [s] per leg and for the race (last entry), shape (n_legs + 1,)."""
        out = {}
        for source, t in self.oat_s.items():
            arr = np.asarray(t, dtype=float)
            table = np.column_stack([arr, arr.sum(axis=1)])
            out[source] = table.max(axis=0) - table.min(axis=0)
        return out

    def dominant(self) -> list[str]:
        """Per leg and for the race (last entry): the source with the widest band ("" if none)."""
        widths = self.oat_widths()
        n = len(self.leg_labels) + 1
        if not widths:
            return [""] * n
        names = list(widths)
        stack = np.array([widths[s] for s in names])
        return [names[int(np.argmax(stack[:, k]))] for k in range(n)]

    def side_shares(self) -> NDArray[np.float64]:
        """Share of members per leg for each of :data:`SIDE_LABELS`, shape (n_legs, 4)."""
        n = max(len(self.sides), 1)
        return np.array(
            [
                [sum(s[k] == lab for s in self.sides) / n for lab in SIDE_LABELS]
                for k in range(len(self.leg_labels))
            ]
        )

    def coverage(self, observed_s: np.ndarray) -> tuple[float, NDArray[np.bool_]]:
        """Share of legs whose observed time lies in [P10, P90], and which do.

        Parameters
        ----------
        observed_s : array_like, shape (n_legs,)
            Observed leg times [s] (e.g. the winner's).
        """
        obs = np.asarray(observed_s, dtype=float)
        b = self.bands()[:-1]
        inside = (obs >= b[:, 0]) & (obs <= b[:, 2])
        return float(inside.mean()), inside

    def to_dict(self) -> dict[str, Any]:
        """``bands.json`` content (schema in ``docs/output-format.md``)."""
        b, widths, dom = self.bands(), self.oat_widths(), self.dominant()
        sh = self.side_shares()
        u = self.uncertainty
        shifts = (
            None
            if u.shifts is None
            else {
                "model": u.shifts.model,
                "amplitude_deg": u.shifts.amplitude_deg,
                "period_s": u.shifts.period_s,
                "sigma_deg": u.shifts.sigma_deg,
                "timescale_s": u.shifts.timescale_s,
                "rate_deg_per_s": u.shifts.rate_deg_per_s,
                "fit": None if u.shifts.fit is None else str(u.shifts.fit),
            }
        )
        return {
            "scenario": self.scenario,
            "uncertainty": {
                "tws_add_sd_ms": u.tws_add_ms,
                "tws_rel_sd": u.tws_rel,
                "twd_sd_deg": u.twd_deg,
                "shifts": shifts,
                "boat": {name: [lo, hi] for name, lo, hi in u.boat},
                "polar": None
                if u.polar is None
                else {
                    "file": str(u.polar.file),
                    "level": u.polar.level,
                    "modes": u.polar.modes,
                    "median_cell_sd_log": u.polar.sd_log,
                    "pace_sd_log": u.polar.pace_sd_log,
                },
                "members": len(self.members),
                "seed": u.seed,
                "side_margin_s": u.side_margin_s,
                "side_margin_pct": u.side_margin_pct,
            },
            "notes": list(self.notes),
            "legs": [
                {
                    "label": label,
                    "nominal_s": float(self.nominal_s[k]),
                    "time_s": {s: float(v) for s, v in zip(BAND_STATS, b[k], strict=True)},
                    "width_by_source_s": {s: float(w[k]) for s, w in widths.items()},
                    "widest_source": dom[k],
                    "side_share": {s: float(v) for s, v in zip(SIDE_LABELS, sh[k], strict=True)},
                    "member_time_s": [float(v) for v in self.times_s[:, k]],
                    "member_side": [s[k] for s in self.sides],
                }
                for k, label in enumerate(self.leg_labels)
            ],
            "total": {
                "nominal_s": float(np.sum(self.nominal_s)),
                "time_s": {s: float(v) for s, v in zip(BAND_STATS, b[-1], strict=True)},
                "width_by_source_s": {s: float(w[-1]) for s, w in widths.items()},
                "widest_source": dom[-1],
            },
            "members": list(self.members),
            "references": {k: [float(x) for x in v] for k, v in self.references.items()},
        }
