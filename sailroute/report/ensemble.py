"""Ensemble scenarios: the spread of leg times over the members, and which side wins.

An ensemble scenario (``members:`` in the course file) is routed member by member; the
summary gives per leg and for the race the minimum, 10th percentile, median, 90th
percentile and maximum time over the members (``numpy.percentile``, linear), and for each
leg how often the route went left, right or up the middle of the course.  The side of a
route is the time-mean signed distance of its track from the leg's rhumb line, labelled
as in race analysis (:func:`sailroute.analysis.loss.side_label`: "middle" within 5 % of
the leg length): "left"/"right" looking from the leg's start to its end.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Final

import numpy as np
from numpy.typing import NDArray

from sailroute.analysis.loss import lateral_offset, side_label, time_mean
from sailroute.errors import InputError
from sailroute.planning.result import Plan
from sailroute.textin import CleanCsvWriter

STATS: Final = ("min", "p10", "median", "p90", "max")
"""Columns of the spread, in order."""
SIDES: Final = ("left", "middle", "right")
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
        return np.array([[sum(s[k] == side for s in self.sides) / n for side in SIDES]
                         for k in range(len(self.leg_labels))])


def route_side(plan: Plan, k: int) -> str:
    """Side of the course (:data:`SIDES`) that leg ``k`` of ``plan`` used."""
    res = plan.legs[k].result
    tr = res.track
    a, b = res.start_xy, res.end_xy
    off = lateral_offset(np.asarray(tr.x), np.asarray(tr.y), a, b)
    length = float(np.hypot(b[0] - a[0], b[1] - a[1]))
    return side_label(time_mean(np.asarray(tr.t), off), length)


def summarize_ensemble(name: str, plans: Sequence[Plan]) -> EnsembleSummary:
    """The :class:`EnsembleSummary` of an ensemble's member plans (same course)."""
    if len(plans) < 2:
        raise InputError(f"ensemble {name!r}: needs at least 2 routed members; got "
                         f"{len(plans)}")
    n = len(plans[0].legs)
    if any(len(p.legs) != n for p in plans):
        raise InputError(f"ensemble {name!r}: the members have different numbers of legs")
    return EnsembleSummary(
        name=name,
        members=tuple(p.scenario for p in plans),
        leg_labels=tuple(leg.spec.label for leg in plans[0].legs),
        times_s=np.array([[leg.time_s for leg in p.legs] for p in plans], dtype=float),
        sides=tuple(tuple(route_side(p, k) for k in range(n)) for p in plans),
    )


def _mmss(seconds: float) -> str:
    m, s = divmod(float(seconds), 60.0)
    return f"{int(m)}:{s:04.1f}"


def ensemble_table(summary: EnsembleSummary) -> str:
    """Terminal table: per leg the spread of times and the side shares."""
    sp, sh = summary.spread(), summary.side_shares()
    head = (f"ensemble {summary.name}: {len(summary.members)} members; leg times over the "
            "members (min / P10 / median / P90 / max) and the side of the course routes took")
    rows: list[tuple[str, ...]] = [("leg", *STATS, "left", "middle", "right")]
    for k, label in enumerate(summary.leg_labels):
        rows.append((f"{k + 1} {label}", *(_mmss(v) for v in sp[k]),
                     *(f"{100 * v:.0f}%" for v in sh[k])))
    rows.append(("total", *(_mmss(v) for v in sp[-1]), "", "", ""))
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    lines = [head]
    for j, r in enumerate(rows):
        lines.append("  ".join(c.ljust(w) if i == 0 else c.rjust(w)
                               for i, (c, w) in enumerate(zip(r, widths, strict=True))))
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
            {"label": label,
             "time_s": {s: float(v) for s, v in zip(STATS, sp[k], strict=True)},
             "side_share": {s: float(v) for s, v in zip(SIDES, sh[k], strict=True)},
             "member_time_s": [float(v) for v in summary.times_s[:, k]],
             "member_side": [s[k] for s in summary.sides]}
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
        w.writerow(["leg", "label", *(f"{s}_s" for s in STATS),
                    *(f"share_{s}" for s in SIDES)])
        for k, label in enumerate(summary.leg_labels):
            w.writerow([k + 1, label, *(f"{v:.3f}" for v in sp[k]),
                        *(f"{v:.4f}" for v in sh[k])])
        w.writerow(["total", "", *(f"{v:.3f}" for v in sp[-1]), "", "", ""])
    return {"ensemble_json": js, "ensemble_csv": cs}
