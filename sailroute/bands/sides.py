"""Which side of the course a routed leg used, and whether that side really paid.

The side of a route is the time-mean signed distance of its track from the leg's rhumb
line, labelled as in race analysis (:func:`sailroute.analysis.loss.side_label`: "middle"
within 5 % of the leg length), "left"/"right" looking from the leg's start to its end.
It counts only when the route beats the other side's layline extreme, sailed in the same
wind (:func:`sailroute.routing.sides.layline_times`), by more than the margin; otherwise
the leg is a "tie" (in a steady, uniform wind every path inside the laylines takes the
same time).  Used by the leg-time bands (:mod:`sailroute.bands.route`) and the ensemble
summary (:mod:`sailroute.report.ensemble`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from sailroute.analysis.loss import lateral_offset, side_label, time_mean
from sailroute.boat.model import BoatModel
from sailroute.routing.sides import extreme_times, side_verdict
from sailroute.routing.types import LegResult
from sailroute.wind.base import WindField

__all__ = ["honest_side", "honest_sides", "leg_side"]


def leg_side(res: LegResult) -> str:
    """Side of the course (left, middle, right) that a routed leg used."""
    tr = res.track
    a, b = res.start_xy, res.end_xy
    off = lateral_offset(np.asarray(tr.x), np.asarray(tr.y), a, b)
    length = float(np.hypot(b[0] - a[0], b[1] - a[1]))
    return side_label(time_mean(np.asarray(tr.t), off), length)


def honest_side(
    res: LegResult,
    wind: WindField,
    boat: BoatModel,
    *,
    tack_penalty_s: float = 0.0,
    gybe_penalty_s: float = 0.0,
    margin_s: float = 2.0,
    margin_pct: float = 0.5,
) -> str:
    """The side a routed leg used if it beat the other side by more than the margin, else "tie".

    Parameters
    ----------
    res : LegResult
        The routed leg.
    wind : WindField
        The wind it was routed in.
    boat : BoatModel
        The boat it was routed with.
    tack_penalty_s, gybe_penalty_s : float
        Manoeuvre penalties of the routing settings [s].
    margin_s, margin_pct : float
        Margin ``max(margin_s, margin_pct % of the leg time)``
        (:func:`sailroute.routing.sides.side_verdict`).
    """
    return honest_sides(
        [[res]],
        [wind],
        [boat],
        tack_penalty_s=tack_penalty_s,
        gybe_penalty_s=gybe_penalty_s,
        margin_s=margin_s,
        margin_pct=margin_pct,
    )[0][0]


def honest_sides(
    results: Sequence[Sequence[LegResult]],
    winds: Sequence[WindField],
    boats: Sequence[BoatModel],
    *,
    tack_penalty_s: float = 0.0,
    gybe_penalty_s: float = 0.0,
    margin_s: float = 2.0,
    margin_pct: float = 0.5,
) -> list[tuple[str, ...]]:
    """:func:`honest_side` of every leg of every member, their extremes sailed together
    (:func:`~sailroute.routing.sides.extreme_times`: the members' winds sampled once per
    step).

    Parameters
    ----------
    results : sequence of sequence of LegResult
        Per member, its routed legs.
    winds, boats : sequence
        Each member's wind and boat.
    tack_penalty_s, gybe_penalty_s, margin_s, margin_pct : float
        As :func:`honest_side`.

    Returns
    -------
    list of tuple of str
        Per member, the verdict of each leg.
    """
    legs = [(m, r) for m, rs in enumerate(results) for r in rs]
    if not legs:
        return [() for _ in results]
    times = extreme_times(
        [r.start_xy for _, r in legs for _ in (0, 1)],
        [r.end_xy for _, r in legs for _ in (0, 1)],
        [r.t_start for _, r in legs for _ in (0, 1)],
        [winds[m] for m, _ in legs for _ in (0, 1)],
        [boats[m] for m, _ in legs for _ in (0, 1)],
        [1, -1] * len(legs),
        tack_penalty_s=tack_penalty_s,
        gybe_penalty_s=gybe_penalty_s,
        max_time_s=[max(4.0 * r.time_s, 600.0) for _, r in legs for _ in (0, 1)],
    ).reshape(-1, 2)
    verdicts: list[list[str]] = [[] for _ in results]
    for (m, r), (t_left, t_right) in zip(legs, times.tolist(), strict=True):
        verdicts[m].append(
            side_verdict(
                leg_side(r), r.time_s, t_left, t_right, margin_s=margin_s, margin_pct=margin_pct
            )
        )
    return [tuple(v) for v in verdicts]
