"""Ensemble scenarios: the spread of leg times over the members, and which side wins.

An ensemble scenario (``members:`` in the course file) is routed member by member; the
summary gives per leg and for the race the minimum, 10th percentile, median, 90th
percentile and maximum time over the members (``numpy.percentile``, linear), and for each
leg how often the route went left, right or up the middle of the course, or whether
the sides were a tie.  The side of a route is the time-mean signed distance of its
track from the leg's rhumb line, labelled as in race analysis
(:func:`sailroute.analysis.loss.side_label`: "middle" within 5 % of the leg length):
"left"/"right" looking from the leg's start to its end.  It counts only when the route
beats the other side's layline extreme, sailed in the member's wind
(:func:`sailroute.routing.sides.layline_times`), by more than
``max(2 s, 0.5 %)`` of the leg time; otherwise the leg is a "tie" (in a steady, uniform
wind every path inside the laylines takes the same time).
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Final

import numpy as np
from numpy.typing import NDArray

from sailroute.bands.sides import honest_side, leg_side
from sailroute.boat.model import BoatModel
from sailroute.errors import InputError
from sailroute.planning.result import Plan
from sailroute.textin import CleanCsvWriter
from sailroute.wind.base import WindField

STATS: Final = ("min", "p10", "median", "p90", "max")
"""Columns of the spread, in order."""
SIDES: Final = ("left", "middle", "right", "tie")
"""Side labels, in order."""
_PERCENTILES: Final = (0.0, 10.0, 50.0, 90.0, 100.0)


@dataclass(frozen=True, eq=False)
class EnsembleSummary:
    """Spread of an ensemble's leg times and the side each member's route took.

    Attributes
    ----------
    name : str
        Ensemble scenario name.
    members : tuple of str
        Member scenario names (``"<name>#<k>"``).
    leg_labels : tuple of str
        Leg labels (``"start -> 1"``).
    times_s : ndarray, shape (n_members, n_legs)
        Leg times [s].
    sides : tuple of tuple of str
        ``sides[i][k]``: side of member ``i``'s route on leg ``k`` (:data:`SIDES`).
    """

    name: str
    members: tuple[str, ...]
    leg_labels: tuple[str, ...]
    times_s: NDArray[np.float64]
    sides: tuple[tuple[str, ...], ...]

    @property
    def totals_s(self) -> NDArray[np.float64]:
        """Race time per member [s]."""
        return self.times_s.sum(axis=1)

    def spread(self) -> NDArray[np.float64]:
        """Per leg and for the race (last row): min, P10, median, P90, max [s].

        Returns
        -------
        ndarray, shape (n_legs + 1, 5)
        """
        table = np.column_stack([self.times_s, self.totals_s])
        return np.percentile(table, _PERCENTILES, axis=0).T

    def side_shares(self) -> NDArray[np.float64]:
        """Share of members per leg going left, up the middle, right, shape (n_legs, 3)."""
        n = len(self.members)
        return np.array(
            [
                [sum(s[k] == side for s in self.sides) / n for side in SIDES]
                for k in range(len(self.leg_labels))
            ]
        )


def route_side(
    plan: Plan, k: int, wind: WindField | None = None, boat: BoatModel | None = None
) -> str:
    """Side of the course (:data:`SIDES`) that leg ``k`` of ``plan`` used.

    With the plan's ``wind`` and ``boat`` the side counts only when it beats the other
    side (:func:`honest_side`; the margin of the course's ``uncertainty`` section, else
    ``max(2 s, 0.5 %)``); without them it is the route's side as sailed.
    """
    res = plan.legs[k].result
    if wind is None or boat is None:
        return leg_side(res)
    st, unc = plan.course.routing, plan.course.uncertainty
    margins = (
        {} if unc is None else {"margin_s": unc.side_margin_s, "margin_pct": unc.side_margin_pct}
    )
    return honest_side(
        res,
        wind,
        boat,
        tack_penalty_s=st.tack_penalty_s,
        gybe_penalty_s=st.gybe_penalty_s,
        **margins,
    )


def summarize_ensemble(
    name: str,
    plans: Sequence[Plan],
    winds: Mapping[str, WindField] | None = None,
    boat: BoatModel | None = None,
) -> EnsembleSummary:
    """The :class:`EnsembleSummary` of an ensemble's member plans (same course).

    Parameters
    ----------
    name : str
        Ensemble name.
    plans : sequence of Plan
        The members' plans.
    winds : mapping of str to WindField, optional
        Member name -> its wind; default: built again from the course
        (:func:`sailroute.course.specs.build_wind`).
    boat : BoatModel, optional
        The boat; default: built from the course.
    """
    if len(plans) < 2:
        raise InputError(f"ensemble {name!r}: needs at least 2 routed members; got {len(plans)}")
    n = len(plans[0].legs)
    if any(len(p.legs) != n for p in plans):
        raise InputError(f"ensemble {name!r}: the members have different numbers of legs")
    return EnsembleSummary(
        name=name,
        members=tuple(p.scenario for p in plans),
        leg_labels=tuple(leg.spec.label for leg in plans[0].legs),
        times_s=np.array([[leg.time_s for leg in p.legs] for p in plans], dtype=float),
        sides=tuple(
            tuple(route_side(p, k, _wind_of(p, winds), _boat_of(p, boat)) for k in range(n))
            for p in plans
        ),
    )


def _wind_of(plan: Plan, winds: Mapping[str, WindField] | None) -> WindField:
    if winds is not None and plan.scenario in winds:
        return winds[plan.scenario]
    from sailroute.course.specs import build_wind

    return build_wind(plan.course, plan.scenario)


def _boat_of(plan: Plan, boat: BoatModel | None) -> BoatModel:
    if boat is not None:
        return boat
    from sailroute.course.specs import build_boat

    return build_boat(plan.course)


def _mmss(seconds: float) -> str:
    m, s = divmod(float(seconds), 60.0)
    return f"{int(m)}:{s:04.1f}"


def ensemble_table(summary: EnsembleSummary) -> str:
    """Terminal table: per leg the spread of times and the side shares."""
    sp, sh = summary.spread(), summary.side_shares()
    head = (
        f"ensemble {summary.name}: {len(summary.members)} members; leg times over the "
        "members (min / P10 / median / P90 / max) and the side of the course routes took "
        "(tie: neither side beat the other by more than max(2 s, 0.5 %))"
    )
    rows: list[tuple[str, ...]] = [("leg", *STATS, *SIDES)]
    for k, label in enumerate(summary.leg_labels):
        rows.append(
            (f"{k + 1} {label}", *(_mmss(v) for v in sp[k]), *(f"{100 * v:.0f}%" for v in sh[k]))
        )
    rows.append(("total", *(_mmss(v) for v in sp[-1]), *("" for _ in SIDES)))
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    lines = [head]
    for j, r in enumerate(rows):
        lines.append(
            "  ".join(
                c.ljust(w) if i == 0 else c.rjust(w)
                for i, (c, w) in enumerate(zip(r, widths, strict=True))
            )
        )
        if j == 0:
            lines.append("  ".join("-" * w for w in widths))
    return "\n".join(lines)


def ensemble_dict(summary: EnsembleSummary) -> dict[str, Any]:
    """``ensemble.json`` content (schema in ``docs/output-format.md``)."""
    sp, sh = summary.spread(), summary.side_shares()
    return {
        "ensemble": summary.name,
        "members": list(summary.members),
        "legs": [
            {
                "label": label,
                "time_s": {s: float(v) for s, v in zip(STATS, sp[k], strict=True)},
                "side_share": {s: float(v) for s, v in zip(SIDES, sh[k], strict=True)},
                "member_time_s": [float(v) for v in summary.times_s[:, k]],
                "member_side": [s[k] for s in summary.sides],
            }
            for k, label in enumerate(summary.leg_labels)
        ],
        "total_s": {s: float(v) for s, v in zip(STATS, sp[-1], strict=True)},
        "member_total_s": [float(v) for v in summary.totals_s],
    }


def write_ensemble(out_dir: Path, summary: EnsembleSummary) -> dict[str, Path]:
    """Write ``ensemble.json`` and ``ensemble.csv`` (one row per leg, then the total)."""
    out_dir.mkdir(parents=True, exist_ok=True)
    js = out_dir / "ensemble.json"
    js.write_text(json.dumps(ensemble_dict(summary), indent=2) + "\n", encoding="utf-8")
    cs = out_dir / "ensemble.csv"
    sp, sh = summary.spread(), summary.side_shares()
    with cs.open("w", newline="", encoding="utf-8") as f:
        w = CleanCsvWriter(f)
        w.writerow(["leg", "label", *(f"{s}_s" for s in STATS), *(f"share_{s}" for s in SIDES)])
        for k, label in enumerate(summary.leg_labels):
            w.writerow([k + 1, label, *(f"{v:.3f}" for v in sp[k]), *(f"{v:.4f}" for v in sh[k])])
        w.writerow(["total", "", *(f"{v:.3f}" for v in sp[-1]), *("" for _ in SIDES)])
    return {"ensemble_json": js, "ensemble_csv": cs}
