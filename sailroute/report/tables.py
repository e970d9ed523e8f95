"""Tables for the terminal: pure functions that return strings (no printing).

Percent errors are ``(model − reference) / reference`` (positive: model slower).
The tables are plain text, or, inside ``with rich_tables(console):`` (the CLI when
stdout is a terminal), drawn by rich for that console (a string with its styles).
"""

from __future__ import annotations

import io
import math
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Any

from sailroute.boat.build import boat_label
from sailroute.planning.result import Comparison, Plan, PlannedLeg, percent_error
from sailroute.routing.startline import Approach, LineApproach, StartLineNumbers
from sailroute.timeutil import iso
from sailroute.units import KNOT


def format_duration(seconds: float) -> str:
    """``m:ss.s`` (or ``h:mm:ss.s`` from one hour) for a duration [s]."""
    if not math.isfinite(seconds):
        return "-"
    sign = "-" if seconds < 0 else ""
    s = abs(seconds)
    tenths = round(s * 10)
    h, rem = divmod(tenths, 36000)
    m, rem = divmod(rem, 600)
    sec = rem / 10
    if h:
        return f"{sign}{h}:{m:02d}:{sec:04.1f}"
    return f"{sign}{m}:{sec:04.1f}"


_RICH_CONSOLE: ContextVar[Any] = ContextVar("sailroute_rich_tables", default=None)


@contextmanager
def rich_tables(console: Any) -> Iterator[None]:
    """Within the block, :func:`render_table` draws with rich for ``console`` (a
    ``rich.console.Console``; None: plain text)."""
    token = _RICH_CONSOLE.set(console)
    try:
        yield
    finally:
        _RICH_CONSOLE.reset(token)


def _rich_table(
    console: Any,
    headers: Sequence[str],
    rows: Sequence[Sequence[str]],
    align: str,
    footer: Sequence[Sequence[str]],
) -> str:
    from rich.box import Box
    from rich.console import Console
    from rich.table import Table

    rules = Box("    \n    \n ── \n    \n ── \n ── \n    \n    \n")  # under head, above total
    t = Table(box=rules, show_edge=False, header_style="bold", pad_edge=False, padding=(0, 1, 0, 0))
    for h, a in zip(headers, align, strict=True):
        t.add_column(h, justify="left" if a == "l" else "right")
    for r in rows:
        t.add_row(*r)
    if footer:
        t.add_section()
        for r in footer:
            t.add_row(*r, style="bold")
    # drawn at its natural width, never squeezed to the terminal's: numbers stay whole
    buf = io.StringIO()
    wide = Console(
        file=buf,
        width=100_000,
        color_system=console.color_system,
        force_terminal=console.is_terminal,
        no_color=console.no_color,
    )
    wide.print(t)
    return "\n".join(line.rstrip() for line in buf.getvalue().rstrip("\n").split("\n"))


def render_table(
    headers: Sequence[str],
    rows: Sequence[Sequence[str]],
    *,
    align: str | None = None,
    footer: Sequence[Sequence[str]] = (),
) -> str:
    """Align columns of text.

    Parameters
    ----------
    headers : sequence of str
        Column titles.
    rows : sequence of sequence of str
        Cells, one row per item.
    align : str, optional
        One character per column, ``"l"`` or ``"r"``; default: first column left,
        the others right.
    footer : sequence of sequence of str
        Rows printed below a rule (totals).

    Returns
    -------
    str
        The table, lines joined with ``\\n``, no trailing newline.
    """
    ncol = len(headers)
    align = align or "l" + "r" * (ncol - 1)
    console = _RICH_CONSOLE.get()
    if console is not None:
        return _rich_table(console, headers, rows, align, footer)
    allrows = [list(headers), *[list(r) for r in rows], *[list(r) for r in footer]]
    widths = [max(len(r[i]) for r in allrows) for i in range(ncol)]

    def fmt(r: Sequence[str]) -> str:
        cells = [
            c.ljust(w) if a == "l" else c.rjust(w) for c, w, a in zip(r, widths, align, strict=True)
        ]
        return "  ".join(cells).rstrip()

    rule = "  ".join("-" * w for w in widths)
    out = [fmt(headers), rule, *[fmt(r) for r in rows]]
    if footer:
        out.append(rule)
        out += [fmt(r) for r in footer]
    return "\n".join(out)


def start_point_text(leg: PlannedLeg) -> str:
    """Where on the line/gate the leg started, e.g. ``"37% start1->start2"``; ``-`` for a point."""
    if leg.start_line_fraction is None:
        return "-"
    course_feature = leg.spec.from_name
    return f"{100.0 * leg.start_line_fraction:.0f}% along {course_feature}"


def _pct(model: float, ref: float) -> str:
    return f"{percent_error(model, ref):+.1f}%"


def plan_table(plan: Plan) -> str:
    """Leg-by-leg table of a plan with a total row and, per reference, time and error.

    Columns: leg, from -> to, wind mode, time (m:ss.s and seconds), tacks, gybes,
    distance [m], start point on the line/gate the leg started from, then for each
    reference its leg time and ``(model − ref)/ref``; under it the "start line" block
    (:func:`start_line_text`) when the plan has one.
    """
    refs = list(plan.references.items())
    headers = [
        "leg",
        "from -> to",
        "mode",
        "time",
        "time s",
        "tacks",
        "gybes",
        "dist m",
        "start point",
    ]
    for name, _ in refs:
        headers += [name, "err"]
    rows = []
    for k, leg in enumerate(plan.legs):
        r = leg.result
        row = [
            str(leg.spec.index + 1),
            leg.spec.label,
            leg.mode or "-",
            format_duration(r.time_s),
            f"{r.time_s:.1f}",
            str(r.n_tacks),
            str(r.n_gybes),
            f"{r.distance_m:.0f}",
            start_point_text(leg),
        ]
        for _, times in refs:
            row += [format_duration(times[k]), _pct(r.time_s, times[k])]
        rows.append(row)
    total = [
        "",
        "total",
        "",
        format_duration(plan.total_time_s),
        f"{plan.total_time_s:.1f}",
        str(sum(leg.result.n_tacks for leg in plan.legs)),
        str(sum(leg.result.n_gybes for leg in plan.legs)),
        f"{sum(leg.result.distance_m for leg in plan.legs):.0f}",
        "",
    ]
    for _, times in refs:
        total += [format_duration(sum(times)), _pct(plan.total_time_s, sum(times))]
    title = (
        f"{plan.course.name} | scenario {plan.scenario} | router {plan.router or '-'} | "
        f"boat {boat_label(plan.course.boat_spec)} | start {iso(plan.t_start)}"
    )
    align = "rllrrrrrl" + "rr" * len(refs)
    start = start_line_text(plan.start_line)
    return (
        title
        + "\n"
        + render_table(headers, rows, align=align, footer=[total])
        + (f"\n\n{start}" if start else "")
    )


def comparison_table(cmp: Comparison) -> str:
    """Legs × scenarios table of leg times, then one error table per reference.

    The first block lists each scenario's leg times and the references' times.
    Then, for every shared reference, ``model − ref`` [s] and ``(model − ref)/ref``
    [%] per scenario.  Scenario-specific references get one line each.
    """
    n = len(cmp.leg_labels)
    ref_names = list(cmp.references)
    headers = ["leg", *cmp.scenarios, *ref_names]
    rows = []
    for k in range(n):
        rows.append(
            [f"{k + 1} {cmp.leg_labels[k]}"]
            + [format_duration(cmp.times[s, k]) for s in range(len(cmp.scenarios))]
            + [format_duration(cmp.references[r][k]) for r in ref_names]
        )
    footer = [
        ["total"]
        + [format_duration(t) for t in cmp.totals]
        + [format_duration(float(cmp.references[r].sum())) for r in ref_names]
    ]
    blocks = [f"{cmp.course_name}: leg times", render_table(headers, rows, footer=footer)]
    for r in ref_names:
        d = cmp.delta_s(r)
        pc = cmp.percent(r)
        rows = [
            [f"{k + 1} {cmp.leg_labels[k]}"]
            + [f"{d[s, k]:+.1f} s {pc[s, k]:+.1f}%" for s in range(len(cmp.scenarios))]
            for k in range(n)
        ]
        tot = cmp.totals - cmp.references[r].sum()
        tp = cmp.total_percent(r)
        footer = [["total"] + [f"{tot[s]:+.1f} s {tp[s]:+.1f}%" for s in range(len(cmp.scenarios))]]
        blocks += [
            "",
            f"error vs {r}: model - {r}, (model - {r})/{r}",
            render_table(["leg", *cmp.scenarios], rows, footer=footer),
        ]
    if cmp.scenario_references:
        lines = []
        for s, refs in cmp.scenario_references.items():
            i = cmp.scenarios.index(s)
            for r, vals in refs.items():
                legs = " ".join(
                    f"{percent_error(cmp.times[i, k], vals[k]):+.1f}%" for k in range(n)
                )
                lines.append([s, r, legs, _pct(float(cmp.totals[i]), float(vals.sum()))])
        blocks += [
            "",
            "error vs scenario-specific references, (model - ref)/ref",
            render_table(["scenario", "reference", "legs", "total"], lines, align="lllr"),
        ]
    return "\n".join(blocks)


# --- start line numbers (plan) and the approach to the line (start) ---------------------


def _signed(v: float, nd: int = 1) -> str:
    return f"{v:+.{nd}f}" if math.isfinite(v) else "-"


def bias_text(sl: StartLineNumbers) -> str:
    """``"+6.0° (starboard end start2 favoured)"`` or ``"+0.2° (square)"``."""
    if sl.favoured_end is None:
        return f"{_signed(sl.bias_deg)}° (square)"
    return f"{_signed(sl.bias_deg)}° ({sl.favoured_side} end {sl.favoured_end} favoured)"


def start_line_rows(sl: StartLineNumbers) -> list[tuple[str, str]]:
    """The start line numbers as (name, value) rows (terminal block and HTML table)."""
    rows = [
        ("line", f"{sl.a_name} - {sl.b_name}, {sl.length_m:.0f} m"),
        ("wind at the gun", f"{sl.tws_ms / KNOT:.1f} kn from {sl.twd_deg:.0f}°"),
        ("bias", bias_text(sl)),
        ("ends", f"starboard end {sl.starboard_end}, port end {sl.port_end}"),
    ]
    if sl.favoured_end is not None:
        rows.append(
            (
                "gain at the favoured end",
                f"{sl.gain_m:.1f} m upwind, {sl.gain_s:.1f} s at {sl.vmg_ms / KNOT:.2f} kn VMG",
            )
        )
    if sl.window_s > 0:
        steady = sl.bias_min_deg == sl.bias_max_deg
        rows.append(
            (
                f"bias range, {sl.window_s / 60:.0f} min before",
                f"{_signed(sl.bias_min_deg)}° (steady)"
                if steady
                else f"{_signed(sl.bias_min_deg)}° .. {_signed(sl.bias_max_deg)}°",
            )
        )
    return rows


def start_line_text(sl: StartLineNumbers | None) -> str:
    """The "start line" block under the plan table (empty without a start line)."""
    if sl is None:
        return ""
    rows = start_line_rows(sl)
    w = max(len(k) for k, _ in rows)
    return "start line\n" + "\n".join(f"  {k:<{w}}  {v}" for k, v in rows)


def _approach_row(ap: Approach) -> list[str]:
    if not ap.reaches:
        return [
            ap.label,
            ap.tack,
            f"{ap.heading_deg:.0f}",
            f"{ap.twa_deg:.0f}",
            f"{ap.speed_ms / KNOT:.2f}",
            "misses",
            "-",
            "-",
        ]
    return [
        ap.label,
        ap.tack,
        f"{ap.heading_deg:.0f}",
        f"{ap.twa_deg:.0f}",
        f"{ap.speed_ms / KNOT:.2f}",
        f"{ap.distance_m:.0f}",
        f"{ap.time_s:.1f}",
        f"{100 * ap.fraction:.0f}%",
    ]


def approach_table(ap: LineApproach, course_name: str, line_names: tuple[str, str]) -> str:
    """The terminal report of ``sailroute start``."""
    head = [
        f"{course_name} | start line {line_names[0]} - {line_names[1]} | at "
        f"x {ap.p_xy[0]:.0f} m, y {ap.p_xy[1]:.0f} m | {iso(ap.t)}",
        f"wind {ap.tws_ms / KNOT:.1f} kn from {ap.twd_deg:.0f}° | distance to the line "
        f"{ap.distance_m:.0f} m{' (on the course side)' if ap.course_side else ''}",
    ]
    rows = [_approach_row(a) for a in (*ap.close_hauled, *ap.to_ends, *ap.tacks)]
    table = render_table(
        ["approach", "tack", "heading °", "TWA °", "speed kn", "path m", "time s", "on line"],
        rows,
        align="llrrrrrr",
    )
    f = ap.fastest
    tail = [
        f"fastest: {f.tack} tack, heading {f.heading_deg:.0f}°, "
        f"{f.time_s:.1f} s to {100 * f.fraction:.0f}% along the line"
        if f.reaches
        else "fastest: none, the boat has no speed in this wind",
        f"time to the gun {format_duration(ap.time_to_gun_s)}, time to burn "
        f"{format_duration(ap.time_to_burn_s)}"
        + (" (late: the line cannot be reached by the gun)" if ap.time_to_burn_s < 0 else ""),
    ]
    return "\n".join([*head, table, *tail])
