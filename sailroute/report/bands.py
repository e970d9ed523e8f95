"""Leg-time bands: the terminal table, ``bands.json``, ``bands.csv`` and ``bands.png``.

One :class:`~sailroute.bands.summary.BandSummary` per scenario: per leg and for the
race the P10 / P50 / P90 of the members' times, the nominal time (the scenario as
given), the source whose one-at-a-time band is widest, the side verdicts, and the
references.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from sailroute.bands.summary import BAND_STATS, SIDE_LABELS, BandSummary
from sailroute.textin import CleanCsvWriter

__all__ = [
    "bands_dict",
    "bands_html_table",
    "bands_page",
    "bands_table",
    "plot_bands",
    "write_bands",
]


def _mmss(seconds: float) -> str:
    m, s = divmod(float(seconds), 60.0)
    return f"{int(m)}:{s:04.1f}"


def _describe(b: BandSummary) -> str:
    u = b.uncertainty
    parts = []
    if u.tws_add_ms:
        parts.append(f"TWS ±{u.tws_add_ms / 0.514444:.2g} kn")
    if u.tws_rel:
        parts.append(f"TWS ±{100 * u.tws_rel:.3g} %")
    if u.twd_deg:
        parts.append(f"TWD ±{u.twd_deg:g}°")
    if u.shifts is not None:
        sh = u.shifts
        if sh.model == "oscillating":
            parts.append(f"shifts ±{sh.amplitude_deg:g}° every {sh.period_s / 60:g} min")
        elif sh.model == "ou":
            src = f", fitted to {Path(sh.fit).name}" if sh.fit is not None else ""
            parts.append(f"OU shifts sd {sh.sigma_deg:.3g}°, {sh.timescale_s:.0f} s{src}")
        else:
            parts.append(f"persistent shift sd {60 * sh.rate_deg_per_s:.3g}°/min")
    if u.polar is not None:
        parts.append(
            f"polar {u.polar.file.name} ({u.polar.level}) sd {100 * u.polar.sd_log:.2g} % "
            f"per cell, pace {100 * u.polar.pace_sd_log:.2g} %"
        )
    parts += [f"{name} {lo:g}..{hi:g}" for name, lo, hi in u.boat]
    return ", ".join(parts) + " (speeds and directions 1 sigma, boat ranges uniform)"


def bands_table(b: BandSummary) -> str:
    """Terminal table of one scenario's bands."""
    bd, dom, sh = b.bands(), b.dominant(), b.side_shares()
    widths = b.oat_widths()
    refs = {k: v for k, v in b.references.items() if len(v) == len(b.leg_labels)}
    head = (
        f"bands {b.scenario}: {len(b.members)} members; {_describe(b)}\n"
        "leg times P10 / P50 / P90, the nominal wind's time, the source widening the band "
        "most (its P10-P90 width, the others nominal), the side verdicts"
    )
    ref_cols = list(refs)
    rows: list[tuple[str, ...]] = [
        ("leg", *(s.upper() for s in BAND_STATS), "nominal", "widest source", *ref_cols, "sides")
    ]
    for k, label in enumerate(b.leg_labels):
        src = f"{dom[k]} {widths[dom[k]][k]:.0f} s" if dom[k] else ""
        shares = " ".join(
            f"{lab} {100 * v:.0f}%" for lab, v in zip(SIDE_LABELS, sh[k], strict=True) if v > 0
        )
        rows.append(
            (
                f"{k + 1} {label}",
                *(_mmss(v) for v in bd[k]),
                _mmss(b.nominal_s[k]),
                src,
                *(_mmss(refs[r][k]) for r in ref_cols),
                shares,
            )
        )
    src = f"{dom[-1]} {widths[dom[-1]][-1]:.0f} s" if dom[-1] else ""
    rows.append(
        (
            "total",
            *(_mmss(v) for v in bd[-1]),
            _mmss(float(np.sum(b.nominal_s))),
            src,
            *(_mmss(sum(refs[r])) for r in ref_cols),
            "",
        )
    )
    w = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    lines = [head]
    for j, r in enumerate(rows):
        lines.append(
            "  ".join(
                c.ljust(x) if i in (0, len(r) - 1) else c.rjust(x)
                for i, (c, x) in enumerate(zip(r, w, strict=True))
            ).rstrip()
        )
        if j == 0:
            lines.append("  ".join("-" * x for x in w))
    if widths:
        lines += ["", "width by source [s] (one source at its P10 / P50 / P90, the others nominal)"]
        wrows = [("source", *(str(k + 1) for k in range(len(b.leg_labels))), "total")]
        wrows += [(src, *(f"{v:.0f}" for v in w)) for src, w in widths.items()]
        ww = [max(len(r[i]) for r in wrows) for i in range(len(wrows[0]))]
        for j, r in enumerate(wrows):
            lines.append(
                "  ".join(
                    c.ljust(x) if i == 0 else c.rjust(x)
                    for i, (c, x) in enumerate(zip(r, ww, strict=True))
                )
            )
            if j == 0:
                lines.append("  ".join("-" * x for x in ww))
    lines += [f"note: {n}" for n in b.notes]
    return "\n".join(lines)


def bands_html_table(b: BandSummary) -> Any:
    """The bands of one scenario as a table of ``report.html``."""
    from sailroute.report.page import Table

    bd, dom, sh, widths = b.bands(), b.dominant(), b.side_shares(), b.oat_widths()
    rows = []
    for k, label in enumerate(b.leg_labels):
        rows.append(
            (
                f"{k + 1} {label}",
                *(_mmss(v) for v in bd[k]),
                _mmss(b.nominal_s[k]),
                f"{dom[k]} {widths[dom[k]][k]:.0f} s" if dom[k] else "",
                " ".join(
                    f"{lab} {100 * v:.0f}%"
                    for lab, v in zip(SIDE_LABELS, sh[k], strict=True)
                    if v > 0
                ),
            )
        )
    foot = (
        (
            "total",
            *(_mmss(v) for v in bd[-1]),
            _mmss(float(np.sum(b.nominal_s))),
            f"{dom[-1]} {widths[dom[-1]][-1]:.0f} s" if dom[-1] else "",
            "",
        ),
    )
    return Table(
        f"Leg-time bands, {b.scenario}: {len(b.members)} members; {_describe(b)}",
        ("leg", "P10", "P50", "P90", "nominal", "widest source", "sides"),
        tuple(rows),
        foot,
    )


SPREAD_COLOUR = "rgba(80, 80, 80, 0.22)"
"""The members' routes on the bands page: a faint grey spread under the nominal route."""


def spread_trace(course: Any, summaries: Sequence[BandSummary]) -> dict[str, Any] | None:
    """The members' routes of every scenario as one faint line trace (lon/lat, a null
    between members); None when the summaries kept none."""
    xs: list[float | None] = []
    ys: list[float | None] = []
    n = 0
    for b in summaries:
        for xy in b.member_tracks:
            lat, lon = course.frame.to_latlon(xy[:, 0], xy[:, 1])
            xs += [round(float(v), 6) for v in np.atleast_1d(lon)] + [None]
            ys += [round(float(v), 6) for v in np.atleast_1d(lat)] + [None]
            n += 1
    if not n:
        return None
    return {
        "type": "scatter",
        "mode": "lines",
        "name": f"members' routes ({n})",
        "x": xs[:-1],
        "y": ys[:-1],
        "line": {"color": SPREAD_COLOUR, "width": 1.2},
        "hoverinfo": "skip",
        "meta": "spread",
    }


def bands_page(
    course: Any,
    summaries: Sequence[BandSummary],
    winds: Mapping[str, Any],
    *,
    router: str = "",
    boat: Any = None,
) -> Any:
    """``report.html`` of a bands run: the nominal route(s) over the members' routes (a
    faint spread), the laylines and start line of the nominal wind (with ``boat``), and
    the band tables (P10 / P50 / P90 per leg)."""
    import dataclasses

    from sailroute.planning.result import compare, make_plan
    from sailroute.report.html import comparison_report, plan_report

    plans = [
        make_plan(course, b.scenario, b.nominal_legs, winds.get(b.scenario), router=router)
        for b in summaries
    ]
    if boat is not None and len(plans) == 1 and winds.get(plans[0].scenario) is not None:
        from sailroute.planning.startline import course_laylines, course_start_line_numbers

        w = winds[plans[0].scenario]
        plans[0] = dataclasses.replace(
            plans[0],
            start_line=course_start_line_numbers(course, w, boat),
            laylines=course_laylines(
                course, [(pl.mode, pl.result) for pl in plans[0].legs], w, boat
            ),
        )
    if len(plans) == 1:
        page = plan_report(plans[0], winds.get(plans[0].scenario))
    else:
        page = comparison_report(
            compare(plans), plans, {p.scenario: winds[p.scenario] for p in plans}
        )
    notes = (
        "Leg-time bands: P10/P50/P90 of the members' leg times; the nominal time is the "
        "scenario as given; the widest source is the one whose one-at-a-time band "
        "(P10-P90, the other sources nominal) is widest; a side counts only when it beats "
        "the other side's layline extreme by more than the margin, else tie. The grey "
        "lines under the route are the members' routes.",
    )
    spread = spread_trace(course, summaries)
    return dataclasses.replace(
        page,
        tables=(*(bands_html_table(b) for b in summaries), *page.tables),
        notes=(*notes, *page.notes),
        overlays=((spread,) if spread else ()) + page.overlays,
    )


def bands_dict(summaries: Sequence[BandSummary], course_name: str = "") -> dict[str, Any]:
    """``bands.json``: ``{"course": ..., "scenarios": [...]}`` (``docs/output-format.md``)."""
    return {"course": course_name, "scenarios": [b.to_dict() for b in summaries]}


def plot_bands(summaries: Sequence[BandSummary]) -> Any:
    """Figure: per leg and scenario the P10-P90 bar, the P50 and the references, as
    a percentage of the nominal time."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    n_legs = len(summaries[0].leg_labels) + 1
    fig, ax = plt.subplots(figsize=(max(6.0, 1.3 * n_legs) + 2.0, 4.0))
    width = 0.8 / len(summaries)
    for i, b in enumerate(summaries):
        nom = np.append(b.nominal_s, np.sum(b.nominal_s))
        bd = b.bands()
        x = np.arange(n_legs) + (i - (len(summaries) - 1) / 2) * width
        lo, mid, hi = (100 * (bd[:, j] / nom - 1) for j in range(3))
        ax.bar(x, hi - lo, width * 0.9, bottom=lo, alpha=0.5, label=f"{b.scenario} P10-P90")
        ax.plot(x, mid, "k_", markersize=12)
        for r, v in b.references.items():
            if len(v) == len(b.leg_labels):
                rv = np.append(np.asarray(v, float), np.sum(v))
                ax.plot(
                    x, 100 * (rv / nom - 1), "o", markersize=4, label=f"{r}" if i == 0 else None
                )
    ax.axhline(0.0, color="grey", lw=0.8)
    ax.margins(y=0.08)
    ax.set_xticks(np.arange(n_legs))
    ax.set_xticklabels([f"{k + 1}" for k in range(n_legs - 1)] + ["total"])
    ax.set_xlabel("leg")
    ax.set_ylabel("time vs the nominal wind [%]")
    ax.set_title("leg-time bands (bar P10-P90, tick P50, dots references)")
    # beside the bars, not over them (the last leg's bar stays whole)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    fig.tight_layout()
    return fig


def write_bands(
    out_dir: Path,
    summaries: Sequence[BandSummary],
    *,
    course_name: str = "",
    plot: bool = True,
) -> dict[str, Path]:
    """Write ``bands.json``, ``bands.csv`` and (``plot``) ``bands.png`` into ``out_dir``."""
    out_dir.mkdir(parents=True, exist_ok=True)
    js = out_dir / "bands.json"
    js.write_text(json.dumps(bands_dict(summaries, course_name), indent=2) + "\n", encoding="utf-8")
    cs = out_dir / "bands.csv"
    sources = list(dict.fromkeys(src for b in summaries for src in b.oat_s))
    with cs.open("w", newline="", encoding="utf-8") as f:
        w = CleanCsvWriter(f)
        w.writerow(
            [
                "scenario",
                "leg",
                "label",
                *(f"{s}_s" for s in BAND_STATS),
                "nominal_s",
                "widest_source",
                *(f"width_{s}_s" for s in sources),
                *(f"share_{s}" for s in SIDE_LABELS),
            ]
        )
        for b in summaries:
            bd, dom, sh, wid = b.bands(), b.dominant(), b.side_shares(), b.oat_widths()

            def widths_at(k: int, wid: dict[str, Any] = wid) -> list[str]:
                return [f"{wid[s][k]:.3f}" if s in wid else "" for s in sources]

            for k, label in enumerate(b.leg_labels):
                w.writerow(
                    [
                        b.scenario,
                        k + 1,
                        label,
                        *(f"{v:.3f}" for v in bd[k]),
                        f"{b.nominal_s[k]:.3f}",
                        dom[k],
                        *widths_at(k),
                        *(f"{v:.4f}" for v in sh[k]),
                    ]
                )
            w.writerow(
                [
                    b.scenario,
                    "total",
                    "",
                    *(f"{v:.3f}" for v in bd[-1]),
                    f"{np.sum(b.nominal_s):.3f}",
                    dom[-1],
                    *widths_at(-1),
                    *("" for _ in SIDE_LABELS),
                ]
            )
    files = {"bands_json": js, "bands_csv": cs}
    if plot:
        import matplotlib.pyplot as plt

        fig = plot_bands(summaries)
        fig.savefig(out_dir / "bands.png", dpi=120)
        plt.close(fig)
        files["bands_png"] = out_dir / "bands.png"
    return files
