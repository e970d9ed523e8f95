"""``report.html``: an interactive page that works offline; its builders.

The page holds the course and the routes on a latitude/longitude map (a plain sea-coloured
background: no chart, no coastline, no web tiles), the scenario's wind as arrows, a time
slider over the race that moves the wind and a marker for the boat's position, hover text
at every track point (local time and UTC, TWS, TWA, speed, VMG) and the leg table.  A
comparison puts every scenario's route on the same map; clicking a legend entry hides or
shows it.

The drawing is `plotly.js <https://plotly.com/javascript/>`_, one copy per output folder
(``plotly.min.js`` beside the pages, about 4.8 MB; no CDN, no network).  The page's
content is :mod:`sailroute.report.page`, its figure, built as plain JSON (traces, layout,
animation frames) without plotly's Python figure classes,
:mod:`sailroute.report.page_figure`, and its text and files
:mod:`sailroute.report.page_render`.  Everything but
:func:`~sailroute.report.page_render.write_report` is pure: data in, dict or string out,
and the same input gives the same bytes (fixed element ids, rounded numbers, no
timestamps).

Three builders make a :class:`Report`: :func:`plan_report` (``sailroute plan``),
:func:`comparison_report` (``compare-scenarios`` and ``plan`` on an ensemble) and
:func:`analysis_report` (``sailroute analyze``, one track); the fleet's page (``sailroute
analyze`` with several tracks) is :mod:`sailroute.report.fleet`;
:func:`~sailroute.report.page_render.render_html` turns a report into the page.

Conventions: times are the course's local time (``Course.utc_offset_s``, the offset its
``start_time`` is written with) and UTC; speeds in knots, angles in degrees.  VMG is the
velocity made good as in ``sailroute analyze``: against the wind on an upwind leg, with it
on a downwind leg, towards the target's centre on a reach.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from sailroute.analysis.windsource import ABOVE_POLAR_PCT
from sailroute.course.model import Course
from sailroute.planning.result import Comparison, Plan, percent_error
from sailroute.report.chart import Chart
from sailroute.report.page import (
    LEG_COLOURS,
    MAX_WIND_LAYERS,
    N_STEPS,
    WIND_GRID,
    Report,
    Route,
    Table,
    WindLayer,
    clock,
    course_area,
    lighter,
    route_from_plan,
    routes_from_analysis,
    slider_times,
    time_label,
    wind_layer,
)
from sailroute.report.tables import format_duration, start_point_text
from sailroute.timeutil import iso, offset_text
from sailroute.units import KNOT
from sailroute.wind.base import WindField

if TYPE_CHECKING:  # pragma: no cover
    from sailroute.analysis.result import TrackAnalysis


# ---------------------------------------------------------------------------------------------
# routes


# ---------------------------------------------------------------------------------------------
# builders


def _plan_table(plan: Plan, caption: str, collapsed: bool = False) -> Table:
    """The leg table of a plan: times in local time, durations, distances, references."""
    off = plan.course.utc_offset_s
    refs = list(plan.references.items())
    headers = [
        "leg",
        "from → to",
        "mode",
        "start",
        "arrival",
        "time",
        "distance m",
        "tacks",
        "gybes",
        "mean boat speed kn",
        "start point",
    ]
    for name, _ in refs:
        headers += [name, f"vs {name}"]
    rows = []
    for k, pl in enumerate(plan.legs):
        r = pl.result
        dt = np.diff(r.track.t)
        stw = (
            float(np.sum(r.track.bsp_ms[:-1] * dt) / r.time_s) / KNOT
            if r.time_s > 0
            else float("nan")
        )
        row = [
            str(pl.spec.index + 1),
            pl.spec.label.replace("->", "→"),
            pl.mode or "-",
            clock(r.t_start, off),
            clock(r.t_end, off),
            format_duration(r.time_s),
            f"{r.distance_m:.0f}",
            str(r.n_tacks),
            str(r.n_gybes),
            f"{stw:.2f}",
            start_point_text(pl),
        ]
        for _, times in refs:
            row += [format_duration(times[k]), f"{percent_error(r.time_s, times[k]):+.1f}%"]
        rows.append(tuple(row))
    total = [
        "",
        "total",
        "",
        clock(plan.t_start, off),
        clock(plan.t_end, off),
        format_duration(plan.total_time_s),
        f"{sum(pl.result.distance_m for pl in plan.legs):.0f}",
        str(sum(pl.result.n_tacks for pl in plan.legs)),
        str(sum(pl.result.n_gybes for pl in plan.legs)),
        "",
        "",
    ]
    for _, times in refs:
        total += [
            format_duration(sum(times)),
            f"{percent_error(plan.total_time_s, sum(times)):+.1f}%",
        ]
    return Table(caption, tuple(headers), tuple(rows), (tuple(total),), collapsed)


def _times_note(course: Course) -> str:
    return (
        f"Times: local time of the course ({offset_text(course.utc_offset_s)}, the offset "
        "its start_time is written with) and UTC."
    )


def _wind_note(layers: Sequence[WindLayer]) -> str:
    if not layers:
        return "No wind drawn: the wind data do not cover the course area."
    steady = all(w.steady for w in layers)
    return (
        f"Wind: arrows point where the air goes, their length in proportion to the "
        f"speed (hover over an arrowhead for its speed and direction); the field sampled on "
        f"{WIND_GRID} × {WIND_GRID} points over the course area"
        + (", the same all race." if steady else f" at each of the slider's {N_STEPS} times.")
    )


HELP = (
    "Drag the time slider (or press ▶) to move the boat and the wind; click a legend "
    "entry to hide or show it; hover over a route for its time, wind and speed; scroll "
    "to zoom, drag to pan, double-click to reset the view. Labels that had to move off "
    "their point have a thin line to it; positions WGS-84."
)


def page_chart(course: Course, winds: Sequence[WindField | None], routes: Sequence[Route]) -> Chart:
    """The land under a page's map (:func:`sailroute.report.chart.chart_for`)."""
    from sailroute.report.chart import chart_for

    return chart_for(course, [w for w in winds if w is not None], course_area(course, routes))


def plan_report(plan: Plan, wind: WindField | None = None) -> Report:
    """The page of ``sailroute plan``: one route, coloured by boat speed, its leg table."""
    c, off = plan.course, plan.course.utc_offset_s
    route = route_from_plan(plan, f"route: {plan.scenario}")
    times = slider_times([route])
    layers = _layers({plan.scenario: wind} if wind is not None else {}, c, [route], times)
    summary = (
        f"Scenario {plan.scenario} · router {plan.router or '-'} · "
        f"start {time_label(plan.t_start, off)} on {iso(plan.t_start + off)[:10]}",
        f"Race time {format_duration(plan.total_time_s)} ({plan.total_time_s:.0f} s), "
        f"{sum(pl.result.distance_m for pl in plan.legs):.0f} m sailed, "
        f"{sum(pl.result.n_tacks for pl in plan.legs)} tacks, "
        f"{sum(pl.result.n_gybes for pl in plan.legs)} gybes; arrival "
        f"{time_label(plan.t_end, off)}",
    )
    # the start line numbers, laylines and favoured end (report/startline.py)
    from sailroute.report.startline import plotly_traces
    from sailroute.report.tables import start_line_rows

    start = (
        ()
        if plan.start_line is None
        else (Table("Start line", ("", "at the gun"), tuple(start_line_rows(plan.start_line))),)
    )
    return Report(
        f"{c.name} — {plan.scenario}",
        summary,
        c,
        (route,),
        tuple(layers),
        times,
        (_plan_table(plan, "Legs"), *start),
        (HELP, _times_note(c), _wind_note(layers)),
        colour_by_speed=True,
        overlays=tuple(plotly_traces(plan.start_line, plan.laylines, c.frame)),
        chart=page_chart(c, [wind], [route]),
    )


def _layers(
    winds: Mapping[str, WindField], course: Course, routes: Sequence[Route], times: NDArray
) -> list[WindLayer]:
    area = course_area(course, routes)
    out = []
    for name, w in list(winds.items())[:MAX_WIND_LAYERS]:
        layer = wind_layer(name, w, course, area, times)
        if layer is not None:
            out.append(layer)
    return out


def comparison_report(
    cmp: Comparison, plans: Sequence[Plan], winds: Mapping[str, WindField] | None = None
) -> Report:
    """The page of ``compare-scenarios``: every scenario's route (legend toggles them),
    each scenario's wind (the first shown), the legs × scenarios times and each
    scenario's leg table (folded)."""
    course = plans[0].course
    off = course.utc_offset_s
    routes = tuple(route_from_plan(p) for p in plans)
    times = slider_times(routes)
    layers = _layers(dict(winds or {}), course, routes, times)
    refs = list(cmp.references)
    rows = []
    for k, label in enumerate(cmp.leg_labels):
        rows.append(
            (
                f"{k + 1}",
                label.replace("->", "→"),
                *(format_duration(cmp.times[i, k]) for i in range(len(cmp.scenarios))),
                *(format_duration(cmp.references[r][k]) for r in refs),
            )
        )
    footer = (
        (
            "",
            "total",
            *(format_duration(t) for t in cmp.totals),
            *(format_duration(float(cmp.references[r].sum())) for r in refs),
        ),
    )
    tables = [
        Table(
            "Leg times by scenario",
            ("leg", "from → to", *cmp.scenarios, *refs),
            tuple(rows),
            footer,
        )
    ]
    tables += [_plan_table(p, f"Legs: {p.scenario}", collapsed=True) for p in plans]
    best = int(np.argmin(cmp.totals))
    summary = (
        f"{len(plans)} scenarios, start {time_label(plans[0].t_start, off)} on "
        f"{iso(plans[0].t_start + off)[:10]}",
        "Race times: "
        + ", ".join(
            f"{s} {format_duration(t)}" for s, t in zip(cmp.scenarios, cmp.totals, strict=True)
        )
        + f"; fastest {cmp.scenarios[best]}",
    )
    notes = [HELP, _times_note(course), _wind_note(layers)]
    if winds and len(winds) > len(layers):
        notes.append(
            f"The wind of {len(winds) - len(layers)} scenarios is not drawn (at most "
            f"{MAX_WIND_LAYERS} are; or their data miss the course area)."
        )
    return Report(
        f"{cmp.course_name} — scenario comparison",
        summary,
        course,
        routes,
        tuple(layers),
        times,
        tuple(tables),
        tuple(notes),
        leg_numbers=False,
        legend_beside=True,
        chart=page_chart(course, list((winds or {}).values()), routes),
    )


def analysis_report(a: TrackAnalysis, banner: Sequence[str] = ()) -> Report:
    """The page of ``sailroute analyze``: the sailed track, the optimal legs from the
    boat's own leg starts (dashed) and the leg table with the time lost; ``banner`` at
    the top (the course's polar beaten on most legs: :attr:`Report.banner`)."""
    course, off = a.course, a.course.utc_offset_s
    sailed, optimal = routes_from_analysis(a)
    colours = tuple(LEG_COLOURS[k % len(LEG_COLOURS)] for k in range(len(a.legs)))
    sailed = dataclasses.replace(sailed, leg_colours=colours)
    optimal = dataclasses.replace(optimal, leg_colours=tuple(lighter(c) for c in colours))
    times = slider_times([sailed])
    layers = _layers({_wind_name(a): a.wind}, course, [sailed, optimal], times)
    rows = []
    for leg in a.legs:
        if not leg.known:
            rows.append(
                (
                    str(leg.index + 1),
                    leg.label.replace("->", "→"),
                    leg.mode,
                    clock(leg.t_start, off) if np.isfinite(leg.t_start) else "unknown",
                    "unknown",
                    format_duration(leg.optimal_time_s),
                    "-",
                    "-",
                    "-",
                    "-",
                    "-",
                    "-",
                    leg.note,
                    leg.wind_source,
                )
            )
            continue
        rows.append(
            (
                str(leg.index + 1),
                leg.label.replace("->", "→"),
                leg.mode,
                clock(leg.t_start, off),
                format_duration(leg.sailed_time_s),
                format_duration(leg.optimal_time_s),
                f"{leg.loss_s:+.1f}",
                f"{leg.split.manoeuvres:+.1f}",
                f"{leg.split.speed:+.1f}",
                f"{leg.split.route:+.1f}",
                f"{leg.sailed_tacks}/{leg.sailed_gybes} : {leg.optimal_tacks}/{leg.optimal_gybes}",
                _polar_pct(leg),
                f"{leg.side_sailed} / {leg.side_optimal}",
                leg.wind_source,
            )
        )
    tot = [
        sum(getattr(leg.split, k) for leg in a.known_legs) for k in ("manoeuvres", "speed", "route")
    ]
    footer = (
        (
            "",
            "total" if a.complete else f"{len(a.known_legs)} legs of known time",
            "",
            "",
            format_duration(a.sailed_time_s),
            format_duration(a.optimal_time_s),
            f"{a.loss_s:+.1f}",
            *(f"{v:+.1f}" for v in tot),
            "",
            "",
            "",
            "",
        ),
    )
    table = Table(
        "Legs: sailed against optimal from the same point and time",
        (
            "leg",
            "from → to",
            "mode",
            "start",
            "sailed",
            "optimal",
            "lost s",
            "manoeuvres s",
            "speed s",
            "route s",
            "tacks/gybes sailed : optimal",
            "polar %",
            "side sailed / optimal",
            "wind",
        ),
        tuple(rows),
        footer,
    )
    t0 = a.legs[0].t_start if a.legs else course.start_epoch
    above = above_polar_legs(a)
    summary = (
        f"Track {a.track.name} · scenario {a.scenario} · router {a.router} · start "
        f"{time_label(t0, off)} on {iso(t0 + off)[:10]}",
        f"Sailed {format_duration(a.sailed_time_s)}, optimal "
        f"{format_duration(a.optimal_time_s)}, "
        # a loss the notes disown is not stated in the header
        + (
            f"no time lost stated: the boat {above}, so the losses are not a debrief "
            "(see the notes)"
            if above
            else f"lost {a.loss_s:+.1f} s"
        ),
    )
    return Report(
        f"{course.name} — {a.track.name}",
        summary,
        course,
        (sailed, optimal),
        tuple(layers),
        times,
        (table,),
        (
            HELP,
            "Each leg in its colour: the sailed track solid, the optimal leg from the same "
            "point and time dashed, in a lighter shade of it.",
            *_judged_notes([a]),
            *a.notes,
            _times_note(course),
            _wind_note(layers),
        ),
        chart=page_chart(course, [a.wind], [sailed, optimal]),
        banner=tuple(banner),
    )


def _wind_name(a: TrackAnalysis) -> str:
    """Name of the wind drawn for an analysis: its first leg's source."""
    return a.legs[0].wind_label if a.legs and a.legs[0].wind_label else a.scenario


def _polar_pct(leg: Any) -> str:
    """A leg's mean polar %, marked ``*`` above the polar."""
    if not math.isfinite(leg.mean_polar_pct):
        return "-"
    return f"{leg.mean_polar_pct:.0f}" + (" *" if leg.above_polar else "")


def _judged_notes(analyses: Sequence[TrackAnalysis], *, name_legs: bool = True) -> list[str]:
    """What the boats are judged against and in which wind, and the above-polar warning
    (naming every boat and leg sailed above the polar; with ``name_legs`` False the
    warning alone, the legs said per boat elsewhere: :func:`above_polar_legs`)."""
    out = []
    refs = dict.fromkeys(a.reference for a in analyses if a.reference)
    out += [
        f"Judged against the {r}." if r.startswith("course") else f"Judged against a {r}."
        for r in refs
    ]
    winds = dict.fromkeys(
        f"{leg.wind_source} ({leg.wind_label})"
        for a in analyses
        for leg in a.legs
        if leg.wind_label
    )
    if winds:
        out.append("Wind of the legs: " + "; ".join(winds) + ".")
    above = [
        f"{a.track.name} leg {leg.index + 1}" for a in analyses for leg in a.legs if leg.above_polar
    ]
    if above:
        out.append(
            f"* Sailed above {ABOVE_POLAR_PCT:.0f} % of the polar"
            + (f" ({', '.join(above)})" if name_legs else f" ({len(above)} legs of the boats)")
            + ": the polar stands in for another class, or the wind is wrong (too light); "
            "those losses are not a debrief (analyze --reference fleet judges the boats "
            "against what the fleet sails)."
        )
    return out


def above_polar_legs(a: TrackAnalysis) -> str:
    """``sailed above 110 % of the polar on legs 1, 2`` for a boat, or empty."""
    legs = [str(leg.index + 1) for leg in a.legs if leg.above_polar]
    if not legs:
        return ""
    return (
        f"sailed above {ABOVE_POLAR_PCT:.0f} % of the polar on leg"
        + ("s " if len(legs) > 1 else " ")
        + ", ".join(legs)
    )


# ---------------------------------------------------------------------------------------------
# page


__all__ = ["analysis_report", "comparison_report", "plan_report"]
