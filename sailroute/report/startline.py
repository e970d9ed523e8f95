"""Start line numbers, laylines and the approach to the line: JSON and drawings.

Pure writers of :class:`~sailroute.routing.startline.StartLineNumbers`,
:class:`~sailroute.routing.laylines.Layline` and
:class:`~sailroute.routing.startline.LineApproach`: the ``start_line`` object and
``legs[].laylines`` of ``plan.json``, ``start.json``, the marks on ``route.png`` and
``report.html``.  Formats: ``docs/output-format.md``; the terminal text is in
:mod:`sailroute.report.tables`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from sailroute.geo import LocalFrame
from sailroute.report.markup import plotly_label
from sailroute.routing.laylines import Layline
from sailroute.routing.startline import Approach, LineApproach, StartLineNumbers
from sailroute.timeutil import iso
from sailroute.units import KNOT

LAYLINE_COLOUR = "#7a7a7a"
"""Colour of the laylines on both maps."""
FAVOURED_COLOUR = "#2ca02c"
"""Colour of the favoured-end marker on both maps."""


def _num(x: float, nd: int = 3) -> float | None:
    """Round for JSON; non-finite values become null."""
    return round(float(x), nd) if math.isfinite(float(x)) else None


def _point(frame: LocalFrame, xy: tuple[float, float]) -> dict[str, float | None]:
    lat, lon = frame.to_latlon(xy[0], xy[1])
    return {
        "x": _num(xy[0]),
        "y": _num(xy[1]),
        "lat": _num(float(lat), 7),
        "lon": _num(float(lon), 7),
    }


# --- plan: the start line -------------------------------------------------------------


def start_line_to_dict(sl: StartLineNumbers | None, frame: LocalFrame) -> dict[str, Any] | None:
    """The ``start_line`` object of ``plan.json`` (None without a start line)."""
    if sl is None:
        return None
    fav = sl.favoured_xy
    return {
        "a": {"name": sl.a_name, **_point(frame, sl.a_xy)},
        "b": {"name": sl.b_name, **_point(frame, sl.b_xy)},
        "time": iso(sl.t_gun),
        "length_m": _num(sl.length_m, 2),
        "tws_ms": _num(sl.tws_ms),
        "tws_kn": _num(sl.tws_ms / KNOT),
        "twd_deg": _num(sl.twd_deg, 2),
        "bias_deg": _num(sl.bias_deg, 2),
        "starboard_end": sl.starboard_end,
        "port_end": sl.port_end,
        "favoured_end": sl.favoured_end,
        "favoured_side": sl.favoured_side,
        "favoured_point": None if fav is None else _point(frame, fav),
        "gain_m": _num(sl.gain_m, 2),
        "gain_s": _num(sl.gain_s, 2),
        "vmg_ms": _num(sl.vmg_ms),
        "bias_min_deg": _num(sl.bias_min_deg, 2),
        "bias_max_deg": _num(sl.bias_max_deg, 2),
        "window_s": _num(sl.window_s, 1),
    }


def laylines_to_dicts(laylines: Sequence[Layline], frame: LocalFrame) -> list[dict[str, Any]]:
    """``legs[].laylines`` of ``plan.json``: one object per layline, points from the mark out."""
    out = []
    for ll in laylines:
        lat, lon = frame.to_latlon(ll.x, ll.y)
        out.append(
            {
                "mark": ll.mark,
                "kind": ll.kind,
                "tack": ll.tack,
                "length_m": _num(ll.length_m, 1),
                "points": [
                    {"x": _num(x, 2), "y": _num(y, 2), "lat": _num(a, 7), "lon": _num(o, 7)}
                    for x, y, a, o in zip(
                        ll.x, ll.y, np.atleast_1d(lat), np.atleast_1d(lon), strict=True
                    )
                ],
            }
        )
    return out


# --- drawings --------------------------------------------------------------------------


def draw_laylines(ax: Any, laylines: Sequence[Sequence[Layline]]) -> None:
    """Laylines (dashed grey) on a matplotlib map, gids ``layline:<leg>:<mark>:<tack>``
    (the favoured end's star is placed with the map's labels:
    :func:`sailroute.report.mapdraw.finish_map`)."""
    first = True
    for k, leg in enumerate(laylines):
        for ll in leg:
            ax.plot(
                ll.x,
                ll.y,
                linestyle=(0, (4, 3)),
                color=LAYLINE_COLOUR,
                lw=0.9,
                zorder=2,
                gid=f"layline:{k + 1}:{ll.mark}:{ll.tack}",
                label="laylines" if first else None,
            )
            first = False


def plotly_traces(
    sl: StartLineNumbers | None, laylines: Sequence[Sequence[Layline]], frame: LocalFrame
) -> list[dict[str, Any]]:
    """Plotly traces (lon/lat) of the laylines and the favoured end for ``report.html``
    (mark names as text: :func:`sailroute.report.markup.plotly_label`)."""
    out: list[dict[str, Any]] = []
    first = True
    for k, leg in enumerate(laylines):
        for ll in leg:
            lat, lon = frame.to_latlon(ll.x, ll.y)
            out.append(
                {
                    "type": "scatter",
                    "mode": "lines",
                    "name": "laylines",
                    "legendgroup": "laylines",
                    "showlegend": first,
                    "x": [round(float(v), 7) for v in np.atleast_1d(lon)],
                    "y": [round(float(v), 7) for v in np.atleast_1d(lat)],
                    "line": {"color": LAYLINE_COLOUR, "width": 1.2, "dash": "dash"},
                    "hovertemplate": f"leg {k + 1}: {ll.tack} {ll.kind} layline to "
                    f"{plotly_label(ll.mark)}<extra></extra>",
                }
            )
            first = False
    if sl is not None and sl.favoured_xy is not None:
        lat, lon = frame.to_latlon(*sl.favoured_xy)
        out.append(
            {
                "type": "scatter",
                "mode": "markers",
                "name": "favoured end",
                "meta": "favoured",
                "x": [round(float(lon), 7)],
                "y": [round(float(lat), 7)],
                "text": [f"favoured +{sl.gain_m:.0f} m"],
                "marker": {
                    "symbol": "star",
                    "size": 16,
                    "color": FAVOURED_COLOUR,
                    "line": {"color": "black", "width": 1},
                },
                "hovertemplate": (
                    f"favoured end {plotly_label(sl.favoured_end or '')}: bias "
                    f"{sl.bias_deg:+.1f}°, {sl.gain_m:.0f} m, "
                    f"{sl.gain_s:.0f} s<extra></extra>"
                ),
            }
        )
    return out


# --- the start command ----------------------------------------------------------------


def _approach_dict(ap: Approach, frame: LocalFrame) -> dict[str, Any]:
    return {
        "label": ap.label,
        "tack": ap.tack,
        "heading_deg": _num(ap.heading_deg, 2),
        "twa_deg": _num(ap.twa_deg, 2),
        "speed_ms": _num(ap.speed_ms),
        "speed_kn": _num(ap.speed_ms / KNOT),
        "reaches_line": ap.reaches,
        "distance_m": _num(ap.distance_m, 2),
        "time_s": _num(ap.time_s, 2),
        "line_fraction": _num(ap.fraction, 4),
        "point": _point(frame, ap.point_xy) if ap.reaches else None,
    }


def approach_to_dict(
    ap: LineApproach, frame: LocalFrame, *, course: str, line: StartLineNumbers
) -> dict[str, Any]:
    """The ``start.json`` document (without the version keys)."""
    return {
        "course": course,
        "position": _point(frame, ap.p_xy),
        "time": iso(ap.t),
        "gun": iso(ap.t_gun),
        "time_to_gun_s": _num(ap.time_to_gun_s, 2),
        "wind": {
            "tws_ms": _num(ap.tws_ms),
            "tws_kn": _num(ap.tws_ms / KNOT),
            "twd_deg": _num(ap.twd_deg, 2),
        },
        "distance_to_line_m": _num(ap.distance_m, 2),
        "course_side": ap.course_side,
        "close_hauled": {a.tack: _approach_dict(a, frame) for a in ap.close_hauled},
        "to_ends": {
            name: _approach_dict(a, frame)
            for name, a in zip((line.a_name, line.b_name), ap.to_ends, strict=True)
        },
        "tacks": {a.tack: _approach_dict(a, frame) for a in ap.tacks},
        "fastest": _approach_dict(ap.fastest, frame),
        "time_to_burn_s": _num(ap.time_to_burn_s, 2),
        "start_line": start_line_to_dict(line, frame),
    }
