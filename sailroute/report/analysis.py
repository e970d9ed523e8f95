"""Outputs of ``sailroute analyze``: JSON, CSVs, terminal tables and charts.

Schemas in ``docs/output-format.md`` (``analysis.json`` ``schema_version`` 1).
Charts use matplotlib's object-oriented API (no ``pyplot``), imported only when
plotting.  Artists carry a ``gid``: ``sailed:<leg>``, ``optimal:<leg>`` on the leg
maps, ``loss`` on the loss chart.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from sailroute._version import __version__
from sailroute.analysis.gains import PARTS, REFERENCES, FleetGains, GainTable
from sailroute.analysis.windsource import ABOVE_POLAR_PCT
from sailroute.report.files import _num, _point
from sailroute.textin import CleanCsvWriter
from sailroute.timeutil import iso
from sailroute.units import KNOT

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

    from sailroute.analysis.fleet import FleetAnalysis
    from sailroute.analysis.result import TrackAnalysis
    from sailroute.wind.base import WindField

SCHEMA_VERSION = 1

LEG_COLUMNS = (
    "leg",
    "from",
    "to",
    "mode",
    "start_time",
    "end_time",
    "detected",
    "sailed_time_s",
    "optimal_time_s",
    "loss_s",
    "loss_manoeuvres_s",
    "loss_speed_s",
    "loss_route_s",
    "sailed_distance_m",
    "optimal_distance_m",
    "sailed_tacks",
    "optimal_tacks",
    "sailed_gybes",
    "optimal_gybes",
    "mean_vmg_ms",
    "mean_sog_ms",
    "mean_polar_pct",
    "side_sailed",
    "side_optimal",
    "lateral_sailed_m",
    "lateral_optimal_m",
    "note",
    "wind_source",
    "above_polar",
)
"""Columns of ``analysis.csv``."""

POINT_COLUMNS = (
    "leg",
    "time",
    "x_m",
    "y_m",
    "lat",
    "lon",
    "sog_ms",
    "sog_kn",
    "cog_deg",
    "tws_ms",
    "twd_deg",
    "twa_deg",
    "polar_ms",
    "polar_pct",
    "vmg_ms",
    "loss_s",
)
"""Columns of ``points.csv``."""


def analysis_to_dict(a: TrackAnalysis) -> dict[str, Any]:
    """The ``analysis.json`` document (see ``docs/output-format.md``)."""
    c = a.course
    legs = []
    for leg in a.legs:
        spec = c.legs[leg.index]
        legs.append(
            {
                "index": leg.index + 1,
                "from": spec.from_name,
                "to": spec.to_name,
                "target_kind": spec.kind,
                "rounding": spec.rounding,
                "mode": leg.mode,
                "start_time": _iso(leg.t_start),
                "end_time": _iso(leg.t_end),
                "end_detected": leg.detected,
                "known": leg.known,
                "note": leg.note or None,
                "start_point": _point(c, leg.start_xy),
                "end_point": _point(c, leg.end_xy),
                "sailed_time_s": _num(leg.sailed_time_s),
                "optimal_time_s": _num(leg.optimal_time_s),
                "loss_s": _num(leg.loss_s),
                "loss_split_s": {
                    "manoeuvres": _num(leg.split.manoeuvres),
                    "speed": _num(leg.split.speed),
                    "route": _num(leg.split.route),
                },
                "sailed_distance_m": _num(leg.sailed_distance_m, 1),
                "optimal_distance_m": _num(leg.optimal_distance_m, 1),
                "sailed_tacks": leg.sailed_tacks,
                "sailed_gybes": leg.sailed_gybes,
                "optimal_tacks": leg.optimal_tacks,
                "optimal_gybes": leg.optimal_gybes,
                "manoeuvres": [{"kind": m.kind, "time": iso(m.t)} for m in leg.manoeuvres],
                "mean_vmg_ms": _num(leg.mean_vmg_ms),
                "mean_sog_ms": _num(leg.mean_sog_ms),
                "mean_polar_pct": _num(leg.mean_polar_pct, 1),
                "side": {
                    "sailed": leg.side_sailed,
                    "optimal": leg.side_optimal,
                    "lateral_sailed_m": _num(leg.lateral_sailed_m, 1),
                    "lateral_optimal_m": _num(leg.lateral_optimal_m, 1),
                },
                "wind": {"source": leg.wind_source, "label": leg.wind_label},
                "above_polar": leg.above_polar,
            }
        )
    return {
        "schema_version": SCHEMA_VERSION,
        "sailroute_version": __version__,
        "course": c.name,
        "source": str(c.source) if c.source else None,
        "track": {
            "name": a.track.name,
            "source": a.track.source,
            "points": len(a.track),
            "first_time": iso(a.track.t_start),
            "last_time": iso(a.track.t_end),
            "notes": list(a.track.notes),
        },
        "scenario": a.scenario,
        "router": a.router,
        "reference": a.reference,
        "origin": {"lat": c.frame.lat0, "lon": c.frame.lon0},
        "start": start_to_dict(a),
        "finish_time": _iso(a.segmentation.ends[-1].t),
        "complete": a.complete,
        "known_legs": len(a.known_legs),
        "notes": list(a.notes),
        "sailed_time_s": _num(a.sailed_time_s),
        "optimal_time_s": _num(a.optimal_time_s),
        "loss_s": _num(a.loss_s),
        "loss_split_s": {
            k: _num(sum(getattr(leg.split, k) for leg in a.known_legs))
            for k in ("manoeuvres", "speed", "route")
        },
        "legs": legs,
    }


def start_to_dict(a: TrackAnalysis) -> dict[str, Any]:
    """The ``start`` object of ``analysis.json`` (and of each boat in ``fleet.json``)."""
    st = a.segmentation.start
    return {
        "gun_time": iso(st.gun_t),
        "start_time": iso(st.crossing.t),
        "detected": st.crossing.detected,
        "late_s": _num(st.late_s),
        "distance_at_gun_m": _num(st.distance_at_gun_m, 1),
        "side_at_gun": st.side_at_gun,
        "speed_at_gun_kn": _num(speed_at_gun_kn(a), 2),
        "line_fraction": _num(st.line_fraction),
        "ocs_s": None if st.ocs_s is None else _num(st.ocs_s, 1),
        "ocs_returned": st.ocs_returned,
        "over_s": _num(st.over_s, 2),
        "ocs_sd": _num(st.ocs_sd, 2),
        "ocs_p": _num(st.ocs_p, 4),
        "line_shift_m": _num(st.shift_m, 1),
        "line_offset_m": _num(st.line_offset_m, 1),
        "notes": list(st.notes),
        "point": _point(a.course, (st.crossing.x, st.crossing.y)),
    }


def speed_at_gun_kn(a: TrackAnalysis) -> float:
    """Speed over the ground at the gun [kn] (NaN outside the track or across a data gap)."""
    return a.segmentation.start.speed_at_gun_ms / KNOT


def _iso(t: float) -> str | None:
    return iso(t) if math.isfinite(t) else None


def iso_column(t: Any) -> list[str]:
    """:func:`sailroute.timeutil.iso` of every time [epoch s], at once (``""`` where NaN)."""
    t = np.asarray(t, float)
    ok = np.isfinite(t)
    # as datetime.fromtimestamp: the fraction of the second rounded to the microsecond
    # (half to even), then cut to the millisecond by isoformat
    t = np.where(ok, t, 0.0)
    sec = np.floor(t)
    us = sec.astype(np.int64) * 1_000_000 + np.round((t - sec) * 1e6).astype(np.int64)
    ms = (us // 1000).astype("datetime64[ms]")
    text = np.datetime_as_string(ms, unit="ms")
    return [f"{s}Z" if good else "" for s, good in zip(text.tolist(), ok.tolist(), strict=True)]


def _fmt(v: Any) -> Any:
    if isinstance(v, float):
        return "" if not math.isfinite(v) else f"{v:.3f}"
    return v


def write_analysis(
    out_dir: str | Path,
    a: TrackAnalysis,
    *,
    plots: bool = True,
    scripts: str | Path | None = None,
    banner: Sequence[str] = (),
) -> dict[str, Path]:
    """Write ``analysis.json``, ``analysis.csv``, ``points.csv`` and (with ``plots``)
    ``legs.png``, ``loss.png`` and ``report.html`` into ``out_dir`` (created); ``banner``:
    lines at the top of the page (:func:`sailroute.report.html.analysis_report`).

    The page loads plotly.js from the folder ``scripts``
    (:func:`sailroute.report.page_render.write_report`); default ``out_dir``, and then the
    bundle is among the files returned (``plotly_js``)."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    files: dict[str, Path] = {}
    jp = out / "analysis.json"
    jp.write_text(
        json.dumps(analysis_to_dict(a), indent=2, ensure_ascii=False) + "\n", encoding="utf-8"
    )
    files["analysis_json"] = jp
    cp = out / "analysis.csv"
    with cp.open("w", newline="", encoding="utf-8") as fh:
        w = CleanCsvWriter(fh)
        w.writerow(LEG_COLUMNS)
        for leg in a.legs:
            spec = a.course.legs[leg.index]
            w.writerow(
                [
                    _fmt(v)
                    for v in (
                        leg.index + 1,
                        spec.from_name,
                        spec.to_name,
                        leg.mode,
                        _iso(leg.t_start) or "",
                        _iso(leg.t_end) or "",
                        leg.detected,
                        leg.sailed_time_s,
                        leg.optimal_time_s,
                        leg.loss_s,
                        leg.split.manoeuvres,
                        leg.split.speed,
                        leg.split.route,
                        leg.sailed_distance_m,
                        leg.optimal_distance_m,
                        leg.sailed_tacks,
                        leg.optimal_tacks,
                        leg.sailed_gybes,
                        leg.optimal_gybes,
                        leg.mean_vmg_ms,
                        leg.mean_sog_ms,
                        leg.mean_polar_pct,
                        leg.side_sailed,
                        leg.side_optimal,
                        leg.lateral_sailed_m,
                        leg.lateral_optimal_m,
                        leg.note,
                        leg.wind_source,
                        leg.above_polar,
                    )
                ]
            )
    files["analysis_csv"] = cp
    pp = out / "points.csv"
    p = a.points
    # one %-format per row (not per value): 220 000 rows in about a second; then the
    # non-finite values (nan, inf) become empty cells, as _fmt writes them
    row = "%d,%s,%.2f,%.2f,%.8f,%.8f" + ",%.3f" * 10 + "\r\n"
    cols = (
        p.leg.tolist(),
        iso_column(p.t),
        *(
            np.asarray(v, float).tolist()
            for v in (
                p.x,
                p.y,
                p.lat,
                p.lon,
                p.sog_ms,
                p.sog_ms / KNOT,
                p.cog_deg,
                p.tws_ms,
                p.twd_deg,
                p.twa_deg,
                p.polar_ms,
                p.polar_pct,
                p.vmg_ms,
                p.loss_s,
            )
        ),
    )
    body = "".join(row % r for r in zip(*cols, strict=True))
    body = body.replace("-inf", "").replace("inf", "").replace("nan", "")
    pp.write_text(",".join(POINT_COLUMNS) + "\r\n" + body, encoding="utf-8", newline="")
    files["points_csv"] = pp
    if plots:
        plot_legs(a).savefig(out / "legs.png", dpi=120)
        files["legs_png"] = out / "legs.png"
        plot_loss(a).savefig(out / "loss.png", dpi=120)
        files["loss_png"] = out / "loss.png"
        from sailroute.report.html import analysis_report
        from sailroute.report.page_render import PLOTLY_FILE, write_report

        files["html"] = write_report(
            out / "report.html", analysis_report(a, banner), scripts=scripts
        )
        if scripts is None:
            files["plotly_js"] = out / PLOTLY_FILE
    return files


def write_fleet(
    out_dir: str | Path,
    analyses: Sequence[TrackAnalysis],
    rows: Sequence[Mapping[str, Any]],
    *,
    plots: bool = True,
    notes: Sequence[str] = (),
    wind: tuple[str, WindField] | None = None,
    fleet: FleetAnalysis | None = None,
    banner: Sequence[str] = (),
) -> dict[str, Path]:
    """Write ``fleet.csv`` (one row per leg and boat), ``fleet.json`` and (with ``plots``)
    the fleet's ``report.html`` (:mod:`sailroute.report.fleet`) with the plotly.js bundle
    beside it (``plotly.min.js``, which the boats' pages in the folders below load too).

    ``notes`` (the run's findings on the wind and the reference) go into ``fleet.json``
    and the page; ``wind`` is the fleet-wide wind drawn on the page (name, field).
    ``fleet`` (the triaged fleet) adds every track's status (debriefed or not), the
    results, the fleet's start and triage's notes.  ``banner``: lines at the top of the
    page instead of among its notes (:attr:`sailroute.report.fleet.FleetPage.banner`)."""
    out = Path(out_dir)
    cp = out / "fleet.csv"
    cols = (
        "leg",
        "label",
        "boat",
        "leg_time_s",
        "leg_rank",
        "elapsed_s",
        "position",
        "loss_s",
        "note",
    )
    gains = gain_columns(fleet.gains if fleet is not None else None)
    with cp.open("w", newline="", encoding="utf-8") as fh:
        w = CleanCsvWriter(fh)
        w.writerow((*cols, *GAIN_COLUMNS))
        for r in rows:
            g = gains.get((r["boat"], r["leg"] - 1), {})
            w.writerow(
                [_fmt(r[c]) if r[c] is not None else "" for c in cols]
                + [_fmt(g[c]) if c in g else "" for c in GAIN_COLUMNS]
            )
    jp = out / "fleet.json"
    all_notes = [*(fleet.triage.notes() if fleet is not None else ()), *notes]
    doc: dict[str, Any] = {
        "schema_version": SCHEMA_VERSION,
        "sailroute_version": __version__,
        "course": analyses[0].course.name if analyses else None,
        "boats": [
            {
                "name": a.track.name,
                "complete": a.complete,
                "notes": list(a.notes),
                "start": start_to_dict(a),
            }
            for a in analyses
        ],
        "notes": all_notes,
        "legs": [{k: (_num(v) if isinstance(v, float) else v) for k, v in r.items()} for r in rows],
    }
    if fleet is not None:
        doc.update(fleet_to_dict(fleet))
    jp.write_text(json.dumps(doc, indent=2, ensure_ascii=False) + "\n", encoding="utf-8")
    files = {"fleet_csv": cp, "fleet_json": jp}
    if plots:
        from sailroute.report.fleet import fleet_page, fleet_report
        from sailroute.report.page_render import PLOTLY_FILE, write_report

        page = fleet_page(analyses, rows, all_notes, wind, fleet=fleet, banner=banner)
        files["html"] = write_report(out / "report.html", fleet_report(page))
        files["plotly_js"] = out / PLOTLY_FILE
    return files


GAIN_COLUMNS = (
    "gain_s",
    *(f"gain_{p}_s" for p in PARTS),
    "gain_top3_s",
)
"""``fleet.csv``'s gain columns: the leg's gain on the fleet's median, its parts, and the
gain on the leg's top three (:mod:`sailroute.analysis.gains`)."""


def gain_columns(gains: FleetGains | None) -> dict[tuple[str, int], dict[str, float]]:
    """Per (boat, 0-based leg) of known time, the values of :data:`GAIN_COLUMNS` [s]."""
    if gains is None:
        return {}
    med, top = gains.median, gains.top3
    out = {}
    for k, boat in enumerate(med.boats):
        for i in range(len(med.labels)):
            if not math.isfinite(med.total_s[k, i]):
                continue
            out[(boat, i)] = {
                "gain_s": float(med.total_s[k, i]),
                **{f"gain_{p}_s": float(med.parts_s[k, i, j]) for j, p in enumerate(PARTS)},
                "gain_top3_s": float(top.total_s[k, i]),
            }
    return out


def gains_to_dict(gains: FleetGains, legs: Sequence[int]) -> dict[str, Any]:
    """``fleet.json``'s ``gains``: per reference and boat, the start part, each leg's gain
    and parts, and their sums over ``legs`` (0-based; the legs every ranked boat has)."""

    def table(t: GainTable) -> dict[str, Any]:
        summed = t.summed(legs)
        return {
            "reference_start_s": _num(t.reference_start_s, 2),
            "reference_leg_time_s": [_num(float(v), 2) for v in t.reference_time_s],
            "boats": {
                b: {
                    "start_s": _num(float(t.start_s[k]), 2),
                    "legs": [
                        {
                            "leg": i + 1,
                            "total_s": _num(float(t.total_s[k, i]), 2),
                            **{
                                f"{p}_s": _num(float(t.parts_s[k, i, j]), 2)
                                for j, p in enumerate(PARTS)
                            },
                        }
                        for i in range(len(t.labels))
                    ],
                    "summed": {f"{p}_s": _num(float(v[k]), 2) for p, v in summed.items()},
                }
                for k, b in enumerate(t.boats)
            },
        }

    return {
        "parts": list(PARTS),
        "summed_over_legs": [i + 1 for i in legs],
        "top": [list(t) for t in gains.top],
        "fleet_angle_deg": [
            {"port": _num(float(a), 1), "starboard": _num(float(b), 1)}
            for a, b in gains.fleet_angle_deg
        ],
        "wind_sources": [list(w) for w in gains.wind_sources],
        **{ref: table(gains.table(ref)) for ref in REFERENCES},
    }


def fleet_to_dict(fleet: FleetAnalysis) -> dict[str, Any]:
    """``fleet.json``'s ``entries`` (every track: status, findings), ``results``, ``start``
    (the fleet's estimate) and ``leader`` (see ``docs/output-format.md``)."""
    st = fleet.triage.start
    tab = fleet.table
    return {
        "entries": [
            {
                "name": e.name,
                "source": e.source,
                "analysed": e.analysed,
                "ranked": e.status.ranked and e.analysed,
                "status": [f.kind.name.lower() for f in e.status.findings],
                "findings": [
                    {"kind": f.kind.name.lower(), "text": f.kind.value, "detail": f.detail}
                    for f in e.status.findings
                ],
                "cut": None if e.cut is None else [iso(e.cut[0]), iso(e.cut[1])],
            }
            for e in fleet.entries
        ],
        "results": [
            {
                "boat": r.boat,
                "position": r.position,
                "finish_elapsed_s": _num(r.finish_s),
                "common_position": r.common_position,
                "common_total_s": _num(r.total_s),
                "common_loss_s": _num(r.loss_s),
                "known_legs": r.known_legs,
                "status": list(r.status),
                "analysed": r.analysed,
                "ranked": r.ranked,
            }
            for r in fleet.results()
        ],
        "common_legs": [i + 1 for i in tab.common_legs()],
        "gains": None if fleet.gains is None else gains_to_dict(fleet.gains, tab.common_legs()),
        "leader": fleet.leader(),
        "fleet_start": {
            "gun_time": iso(st.gun_t),
            "gun_time_in_tracks": iso(st.track_gun_t),
            "model": st.model,
            "told_apart": st.told_apart,
            "time_offset_s": _num(st.time_offset_s, 2),
            "se_time_offset_s": _num(st.se_time_offset_s, 2),
            "line_shift_m": _num(st.shift_m, 1),
            "se_line_shift_m": _num(st.se_shift_m, 1),
            "front_row_spread_m": _num(st.spread_m, 2),
            "clean_spread_s": _num(st.spread_s, 2),
            "boats": st.n_boats,
        },
        "general_recall": None
        if fleet.triage.recall is None
        else {
            "boats": list(fleet.triage.recall.boats),
            "restart_time": iso(fleet.triage.recall.restart_t),
        },
    }


def _mss(s: float) -> str:
    if not math.isfinite(s):
        return "unknown"
    sign = "-" if s < 0 else ""
    tenths = round(abs(s) * 10)
    return f"{sign}{tenths // 600}:{(tenths % 600) / 10:04.1f}"


def analysis_table(a: TrackAnalysis, legend: bool = True) -> str:
    """Terminal report: start, then one row per leg and a total (``legend``: and the lines
    that explain the columns, once for a fleet)."""
    st = a.segmentation.start
    head = (
        f"{a.track.name} on {a.course.name} ({a.scenario}, {a.router})\n"
        f"start: {'detected' if st.crossing.detected else 'given'} "
        f"{iso(st.crossing.t)}, {st.late_s:+.1f} s after the gun, "
        f"{st.distance_at_gun_m:.0f} m from the line at the gun "
        f"({st.side_at_gun} side), {100 * st.line_fraction:.0f}% along it, "
        f"{speed_at_gun_kn(a):.1f} kn at the gun" + "".join(f"\n  start: {n}" for n in st.notes)
    )
    if a.reference:
        head += f"\njudged against: {a.reference}"
    cols = (
        f"{'leg':<14}{'mode':<9}{'sailed':>9}{'optimal':>9}{'lost':>8}{'man':>7}"
        f"{'speed':>7}{'route':>7}{'dist m':>13}{'tk/gb':>11}{'polar%':>7}{'side s/o':>15}"
        f"  {'wind':<9}"
    )
    rows = [head, "", cols]
    for leg in a.legs:
        if not leg.known:
            rows.append(
                f"{leg.label:<14}{leg.mode:<9}{'unknown':>9}"
                f"{_mss(leg.optimal_time_s):>9}{'?':>8}  ({leg.note})"
            )
            continue
        rows.append(
            f"{leg.label:<14}{leg.mode:<9}{_mss(leg.sailed_time_s):>9}"
            f"{_mss(leg.optimal_time_s):>9}{leg.loss_s:>+8.1f}{leg.split.manoeuvres:>+7.1f}"
            f"{leg.split.speed:>+7.1f}{leg.split.route:>+7.1f}"
            f"{leg.sailed_distance_m:>6.0f}/{leg.optimal_distance_m:<6.0f}"
            f"{leg.sailed_tacks:>3}/{leg.sailed_gybes}:{leg.optimal_tacks}/{leg.optimal_gybes:<3}"
            f"{leg.mean_polar_pct:>6.0f}{'*' if leg.above_polar else ' '}"
            f"{leg.side_sailed:>8}/{leg.side_optimal:<6}  {leg.wind_source:<9}"
            + (f"\n  {leg.note}" if leg.note else "")
        )
    tot = [
        sum(getattr(leg.split, k) for leg in a.known_legs) for k in ("manoeuvres", "speed", "route")
    ]
    label = "total" if a.complete else f"{len(a.known_legs)} of {len(a.legs)}"
    rows.append(
        f"{label:<14}{'':<9}{_mss(a.sailed_time_s):>9}{_mss(a.optimal_time_s):>9}"
        f"{a.loss_s:>+8.1f}{tot[0]:>+7.1f}{tot[1]:>+7.1f}{tot[2]:>+7.1f}"
    )
    if legend:
        rows.append(
            "(lost = sailed - optimal from the same point and time, split into "
            "manoeuvres + speed + route; tk/gb sailed:optimal"
            + ("" if a.complete else "; totals over the legs of known time")
            + ")"
        )
    if legend and any(leg.above_polar for leg in a.legs):
        rows.append(
            f"* sailed above {ABOVE_POLAR_PCT:.0f} % of the polar: the polar stands in "
            "for another class, or the wind is wrong (too light); these losses are not "
            "a debrief (try --reference fleet)"
        )
    winds = dict.fromkeys(
        f"{leg.wind_source}: {leg.wind_label}" for leg in a.legs if leg.wind_label
    )
    if winds:
        rows.append("wind: " + "; ".join(winds))
    if a.track.notes:
        rows.append("track: " + "; ".join(a.track.notes))
    return "\n".join(rows)


def results_table(fleet: FleetAnalysis) -> str:
    """The fleet's results: finish place where known, elapsed time at the finish, the
    sailed time and loss over the legs every ranked boat has, the place at the last leg
    end they all have, and what triage found; every track, debriefed or not."""
    tab = fleet.table
    legs = tab.common_legs()
    span = _leg_span(legs)
    last = tab.last_common_end()
    at = f"at leg {last + 1}" if last is not None else "at -"
    head = "results: place and elapsed time at the finish (from the gun), time and loss over " + (
        f"legs {span}, the legs every ranked boat has" if legs else "no leg every ranked boat has"
    )
    if last is not None:
        head += f"; leader: {fleet.leader()} (ahead at the end of leg {last + 1})"
    out = [
        head,
        f"  {'pos':>4} {'boat':<24}{'finish':>9}{'legs ' + span:>12}{'lost':>8}{at:>9}  status",
    ]
    for r in fleet.results():
        pos = f"{r.position}." if r.position is not None else "-"
        cpos = f"{r.common_position}." if r.common_position is not None else "-"
        if not r.analysed:
            out.append(f"  {'-':>4} {r.boat:<24}{'':>38}  {'; '.join(r.status)}")
            continue
        lost = f"{r.loss_s:+.1f}" if math.isfinite(r.loss_s) else "?"
        out.append(
            f"  {pos:>4} {r.boat:<24}{_mss(r.finish_s):>9}{_mss(r.total_s):>12}{lost:>8}"
            f"{cpos:>9}  {'; '.join(r.status)}"
        )
    return "\n".join(out)


def gains_table(fleet: FleetAnalysis, per_leg: bool = False) -> str:
    """The fleet's gains on its median, one row per debriefed boat in the order of the
    results: the total over the start and the legs every ranked boat has, and its parts;
    ``per_leg`` adds a row per leg under each boat."""
    g = fleet.gains
    if g is None:
        return ""
    t = g.median
    legs = fleet.table.common_legs()
    summed = t.summed(legs)
    names = ("total", "start", *PARTS)
    out = [
        f"gains on the fleet's median over the start and legs {_leg_span(legs)} [s] "
        "(+ faster; total = start + speed + height + side + manoeuvres + other)",
        f"  {'boat':<24}" + "".join(f"{n[:10]:>11}" for n in names),
    ]
    by = {b: k for k, b in enumerate(t.boats)}
    for r in fleet.results():
        k = by.get(r.boat)
        if k is None:
            continue
        out.append(f"  {r.boat:<24}" + "".join(_gain(summed[n][k]) for n in names))
        if per_leg:
            for i in range(len(t.labels)):
                cells = [t.total_s[k, i], math.nan, *t.parts_s[k, i]]
                out.append(f"    leg {i + 1:<18}" + "".join(_gain(v) for v in cells))
    out.append(
        "top three per leg: "
        + "; ".join(f"leg {i + 1} {', '.join(top) or '-'}" for i, top in enumerate(g.top))
    )
    return "\n".join(out)


def _gain(v: float) -> str:
    return f"{v:>+11.1f}" if math.isfinite(v) else f"{'':>11}"


def _leg_span(legs: Sequence[int]) -> str:
    """``(0, 1, 2, 4)`` -> ``"1-3, 5"`` (1-based)."""
    runs: list[list[int]] = []
    for i in legs:
        if runs and runs[-1][1] == i:
            runs[-1][1] = i + 1
        else:
            runs.append([i, i + 1])
    return ", ".join(f"{a + 1}" if b == a + 1 else f"{a + 1}-{b}" for a, b in runs) or "-"


def fleet_table(rows: Sequence[Mapping[str, Any]], notes: Sequence[str] = ()) -> str:
    """Boats ranked per leg: leg time (rank) and elapsed time (position)."""
    out = ["fleet: leg time (rank) | elapsed from the gun (position) | lost vs optimal"]
    out += [f"note: {n}" for n in notes]
    leg = None
    for r in sorted(rows, key=lambda r: (r["leg"], r["leg_rank"] is None, r["leg_rank"] or 0)):
        if r["leg"] != leg:
            leg = r["leg"]
            out.append(f"leg {leg} ({r['label']})")
        rank = f"{r['leg_rank']}." if r["leg_rank"] is not None else "-"
        pos = r["position"] if r["position"] is not None else "-"
        lost = f"{r['loss_s']:+.1f} s" if math.isfinite(r["loss_s"]) else "unknown"
        out.append(
            f"  {rank:>3} {r['boat']:<28}{_mss(r['leg_time_s']):>9}  "
            f"pos {pos} {_mss(r['elapsed_s']):>9}  {lost}"
            + (f"  ({r['note']})" if r.get("note") else "")
        )
    return "\n".join(out)


def _leg_wind(a: TrackAnalysis, leg: Any) -> tuple[float, float] | None:
    """The wind where and when a leg starts: ``(speed [kn], FROM-direction [°])``."""
    from sailroute.errors import OutOfCoverageError
    from sailroute.units import wind_speed_direction

    if a.wind is None or not math.isfinite(leg.t_start):
        return None
    try:
        u, v = a.wind.sample(leg.t_start, leg.start_xy[0], leg.start_xy[1])
    except OutOfCoverageError:
        return None
    spd, twd = wind_speed_direction(u, v)
    if not (np.isfinite(spd) and np.isfinite(twd)):
        return None
    return float(spd) / KNOT, float(twd)


def plot_legs(a: TrackAnalysis) -> Figure:
    """One map per leg, each leg in its colour: the sailed track (solid) and the optimal
    route from the same start (dashed, a lighter shade), with the chart and the course,
    its race area, the sailed manoeuvres, the wind where and when the leg starts (an
    arrow where the air goes and its speed and direction in the title), a scale bar, a
    north arrow and the names placed so that they overlap nothing
    (:func:`sailroute.report.mapdraw.finish_map`)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from sailroute.report.area import draw_area
    from sailroute.report.chart import chart_for, draw_chart
    from sailroute.report.mapdraw import MapItem, finish_map
    from sailroute.report.page import LEG_COLOURS, lighter
    from sailroute.report.plots import course_labels, draw_course

    n = len(a.legs)
    ncol = min(n, 3)
    nrow = math.ceil(n / ncol)
    fig = Figure(figsize=(4.6 * ncol, 4.6 * nrow), layout="constrained")
    p = a.points
    maps = []
    for i, leg in enumerate(a.legs):
        colour = LEG_COLOURS[i % len(LEG_COLOURS)]
        ax = fig.add_subplot(nrow, ncol, i + 1)
        m = p.leg == i + 1
        o = leg.optimal.track if leg.optimal is not None else None
        xs = np.concatenate([p.x[m], o.x if o is not None else [], [leg.start_xy[0]]])
        ys = np.concatenate([p.y[m], o.y if o is not None else [], [leg.start_xy[1]]])
        xs, ys = xs[np.isfinite(xs)], ys[np.isfinite(ys)]
        if xs.size == 0:
            xs, ys = np.array([0.0]), np.array([0.0])
        pad = 0.15 * max(np.ptp(xs), np.ptp(ys), 50.0)
        extent = (xs.min() - pad, xs.max() + pad, ys.min() - pad, ys.max() + pad)
        draw_chart(ax, chart_for(a.course, [a.wind], extent), extent)
        draw_area(ax, a.course.area)
        draw_course(ax, a.course)
        ax.plot(p.x[m], p.y[m], "-", color=colour, lw=1.6, gid=f"sailed:{i + 1}",
                label=f"sailed {_mss(leg.sailed_time_s)}")  # fmt: skip
        if o is not None:
            ax.plot(o.x, o.y, "--", color=lighter(colour), lw=1.6, gid=f"optimal:{i + 1}",
                    label=f"optimal {_mss(leg.optimal_time_s)}")  # fmt: skip
        items = []
        for mm in leg.manoeuvres:
            j = int(np.argmin(np.abs(p.t[m] - mm.t)))
            items.append(MapItem(mm.kind, float(p.x[m][j]), float(p.y[m][j])))
        ax.set_xlim(extent[0], extent[1])
        ax.set_ylim(extent[2], extent[3])
        ax.set_aspect("equal", adjustable="box")
        if not leg.known:
            lost = "time unknown"
        elif leg.above_polar:
            lost = "above the polar: no loss stated"
        else:
            lost = f"lost {leg.loss_s:+.0f} s"
        wind = _leg_wind(a, leg)
        title = f"leg {i + 1}: {leg.label} ({leg.mode}), {lost}"
        if wind is not None:
            title += f"\nwind {wind[0]:.1f} kn from {wind[1]:.0f}° (arrow: where it goes)"
            go = math.radians(wind[1] + 180.0)
            ax.annotate(
                "",
                xy=(0.95 + 0.035 * math.sin(go), 1.075 + 0.035 * math.cos(go)),
                xytext=(0.95 - 0.035 * math.sin(go), 1.075 - 0.035 * math.cos(go)),
                xycoords="axes fraction",
                arrowprops={"arrowstyle": "-|>", "color": "steelblue", "lw": 1.6},
                annotation_clip=False,
                gid=f"wind-leg:{i + 1}",
            )
        ax.set_title(title, fontsize=9)
        ax.set_xlabel("x [m]", fontsize=8)
        ax.set_ylabel("y [m]", fontsize=8)
        ax.tick_params(labelsize=7)
        routes = [np.column_stack([p.x[m], p.y[m]])]
        if o is not None:
            routes.append(np.column_stack([o.x, o.y]))
        maps.append((ax, routes, items))
    fig.suptitle(f"{a.track.name}: sailed vs optimal ({a.scenario})", fontsize=10)
    FigureCanvasAgg(fig).draw()  # type: ignore[no-untyped-call]  # the layout settles, kept
    fig.set_layout_engine("none")
    for ax, routes, items in maps:
        finish_map(fig, ax, routes=routes, items=items, **course_labels(a.course))
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(0.0, -0.12), ncol=2,
                      frameon=False)  # fmt: skip
    return fig


def plot_loss(a: TrackAnalysis) -> Figure:
    """Cumulative time lost against the optimal legs over race time, legs shaded."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(8, 3.8), layout="constrained")
    ax = fig.add_subplot(1, 1, 1)
    p = a.points
    t0 = a.segmentation.start.crossing.t
    ax.plot((p.t - t0) / 60.0, p.loss_s, "-", color="tab:red", lw=1.4, gid="loss")
    for i, leg in enumerate(a.legs):
        if not leg.known:
            continue
        ax.axvspan(
            (leg.t_start - t0) / 60,
            (leg.t_end - t0) / 60,
            alpha=0.08 if i % 2 else 0.0,
            color="grey",
        )
        ax.annotate(
            f"{i + 1}",
            ((0.5 * (leg.t_start + leg.t_end) - t0) / 60, 0.98),
            xycoords=("data", "axes fraction"),
            ha="center",
            va="top",
            fontsize=8,
        )
    ax.axhline(0, color="black", lw=0.6)
    ax.set_xlabel("minutes since the start crossing")
    ax.set_ylabel("time lost vs optimal [s]")
    ax.set_title(f"{a.track.name}: cumulative loss (total {a.loss_s:+.0f} s)", fontsize=10)
    return fig
