"""Output files of ``sailroute plan`` and ``compare-scenarios``.

* ``plan.json``: course, scenario, totals and one record per leg;
* ``track.csv``: one row per track point of every leg;
* ``route.gpx``: GPX 1.1 with the marks (``wpt``), the route through the start, every
  tack and gybe and each leg's end (``rte``) and the timed track (``trk``, one segment
  per leg);
* ``route.kml``, ``route.nmea``: the same route for chart software and plotters
  (:mod:`sailroute.report.route_export`);
* ``comparison.json`` / ``comparison.csv``: legs × scenarios with errors.

:func:`file_label` names a written file for the "wrote ..." lines of the CLI.  The
commands write their files as a set through :func:`sailroute.outdir.write_output_set`.

Schemas, with units, are documented in ``docs/output-format.md``; bump
:data:`SCHEMA_VERSION` on any incompatible change.  Times are ISO 8601 UTC with a
``Z`` suffix; positions are local ``x, y`` [m] and WGS-84 ``lat, lon`` [°].
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any
from xml.etree import ElementTree as ET

import numpy as np

from sailroute._version import __version__
from sailroute.boat.build import boat_label
from sailroute.course.model import Course
from sailroute.outdir import make_out_dir
from sailroute.planning.result import Comparison, Plan, percent_error
from sailroute.report.area import area_to_dict
from sailroute.report.route_export import route_points, write_kml, write_nmea
from sailroute.report.startline import laylines_to_dicts, start_line_to_dict
from sailroute.routing.types import side_name
from sailroute.textin import CleanCsvWriter, clean_text
from sailroute.timeutil import iso
from sailroute.units import KNOT
from sailroute.wind.base import WindField

SCHEMA_VERSION = 1
"""Version of the plan.json / track.csv / comparison.json schemas."""

GPX_NS = "http://www.topografix.com/GPX/1/1"
SR_NS = "urn:x-sailroute:gpx:1"
"""Namespace of the per-point extensions (boat speed, wind) in ``route.gpx``."""

TRACK_COLUMNS = (
    "leg",
    "from",
    "to",
    "time",
    "t_race_s",
    "t_leg_s",
    "x_m",
    "y_m",
    "lat",
    "lon",
    "heading_deg",
    "tws_ms",
    "tws_kn",
    "twd_deg",
    "twa_deg",
    "bsp_ms",
    "bsp_kn",
    "tack",
    "event",
    "sog_ms",
    "sog_kn",
    "cog_deg",
)
"""Columns of ``track.csv`` (see ``docs/output-format.md``)."""


def _num(x: float, nd: int = 3) -> float | None:
    """Round for JSON; non-finite values become null."""
    return round(float(x), nd) if math.isfinite(float(x)) else None


def _point(course: Course, xy: tuple[float, float]) -> dict[str, float | None]:
    lat, lon = course.frame.to_latlon(xy[0], xy[1])
    return {
        "x": _num(xy[0]),
        "y": _num(xy[1]),
        "lat": _num(float(lat), 7),
        "lon": _num(float(lon), 7),
    }


def plan_to_dict(plan: Plan) -> dict[str, Any]:
    """The ``plan.json`` document (a JSON-serialisable dict).

    Parameters
    ----------
    plan : Plan
        A routed course.

    Returns
    -------
    dict
        Keys ``schema_version``, ``sailroute_version``, ``course``, ``source``,
        ``scenario``, ``router``, ``start_time``, ``end_time``, ``total_time_s``,
        ``total_distance_m``, ``total_tacks``, ``total_gybes``, ``start_line``,
        ``area`` (only when the course has a boundary or obstacles:
        :func:`sailroute.report.area.area_to_dict`), ``legs`` (each with its
        ``laylines``), ``references``; see ``docs/output-format.md``.
    """
    c = plan.course
    legs = []
    for k, pl in enumerate(plan.legs):
        r = pl.result
        legs.append(
            {
                "index": pl.spec.index + 1,
                "from": pl.spec.from_name,
                "to": pl.spec.to_name,
                "target_kind": pl.spec.kind,
                "rounding": pl.spec.rounding,
                "mode": pl.mode,
                "time_s": _num(r.time_s),
                "tacks": int(r.n_tacks),
                "gybes": int(r.n_gybes),
                "distance_m": _num(r.distance_m, 2),
                **_speeds(r),
                "start_time": iso(r.t_start),
                "end_time": iso(r.t_end),
                "start_point": _point(c, r.start_xy),
                "start_line_fraction": (
                    None if pl.start_line_fraction is None else _num(pl.start_line_fraction, 4)
                ),
                "end_point": _point(c, r.end_xy),
                "manoeuvres": [
                    {"kind": m.kind, "time": iso(m.t), **_point(c, (m.x, m.y))}
                    for m in r.manoeuvres
                ],
                "reference": {name: _num(times[k]) for name, times in plan.references.items()},
                "reference_error_pct": {
                    name: _num(percent_error(r.time_s, times[k]), 3)
                    for name, times in plan.references.items()
                },
                "laylines": laylines_to_dicts(plan.laylines[k] if plan.laylines else (), c.frame),
            }
        )
    total = plan.total_time_s
    area = area_to_dict(c.area, c.frame)
    return {
        "schema_version": SCHEMA_VERSION,
        "sailroute_version": __version__,
        "course": c.name,
        "source": str(c.source) if c.source is not None else None,
        "scenario": plan.scenario,
        "router": plan.router,
        "boat": {
            "label": boat_label(c.boat_spec),
            "spec": json.loads(json.dumps(dict(c.boat_spec), default=str)),
        },
        "start_time": iso(plan.t_start),
        "end_time": iso(plan.t_end),
        "total_time_s": _num(total),
        "total_distance_m": _num(sum(pl.result.distance_m for pl in plan.legs), 2),
        "total_tacks": int(sum(pl.result.n_tacks for pl in plan.legs)),
        "total_gybes": int(sum(pl.result.n_gybes for pl in plan.legs)),
        "origin": {"lat": c.frame.lat0, "lon": c.frame.lon0},
        "current": _current_of(plan),
        "start_line": start_line_to_dict(plan.start_line, c.frame),
        **({} if area is None else {"area": area}),
        "legs": legs,
        "references": {
            name: {
                "total_time_s": _num(sum(times)),
                "error_pct": _num(percent_error(total, sum(times)), 3),
                "legs_s": [_num(t) for t in times],
            }
            for name, times in plan.references.items()
        },
    }


def _speeds(r: Any) -> dict[str, float | None]:
    """Mean speeds of a leg [kn]: over the ground (distance / time) and through the
    water (boat speed, time-weighted over the track's segments)."""
    tr = r.track
    dt = np.diff(tr.t)
    stw = float(np.sum(tr.bsp_ms[:-1] * dt) / r.time_s) if r.time_s > 0 else float("nan")
    sog = r.distance_m / r.time_s if r.time_s > 0 else float("nan")
    return {"mean_sog_kn": _num(sog / KNOT), "mean_stw_kn": _num(stw / KNOT)}


def _current_of(plan: Plan) -> dict[str, Any] | None:
    """The scenario's surface-current spec as given (None: still water)."""
    sc = plan.course.scenarios.get(plan.scenario)
    cur = getattr(sc, "current_given", None)
    return None if cur is None else json.loads(json.dumps(dict(cur), default=str))


def write_plan_json(path: str | Path, plan: Plan) -> Path:
    """Write ``plan.json`` (see :func:`plan_to_dict`); returns the path."""
    p = Path(path)
    p.write_text(
        json.dumps(plan_to_dict(plan), indent=2, ensure_ascii=False) + "\n", encoding="utf-8"
    )
    return p


def _events(plan_leg_times: np.ndarray, manoeuvres: tuple) -> list[str]:
    ev = [""] * plan_leg_times.size
    for m in manoeuvres:
        i = int(np.clip(np.searchsorted(plan_leg_times, m.t - 1e-6), 0, plan_leg_times.size - 1))
        ev[i] = m.kind
    return ev


def write_track_csv(path: str | Path, plan: Plan) -> Path:
    """Write ``track.csv``: every track point of every leg, in order.

    The last point of a leg and the first of the next are the same place and time
    and both appear (each with its own leg number).  Columns: :data:`TRACK_COLUMNS`.
    """
    p = Path(path)
    t0 = plan.t_start
    with p.open("w", newline="", encoding="utf-8") as fh:
        w = CleanCsvWriter(fh)
        w.writerow(TRACK_COLUMNS)
        for pl in plan.legs:
            tr = pl.result.track
            lat, lon = plan.course.frame.to_latlon(tr.x, tr.y)
            events = _events(tr.t, pl.result.manoeuvres)
            sog, cog = tr.ground_speed_ms, tr.ground_course_deg
            for i in range(len(tr)):
                w.writerow(
                    [
                        pl.spec.index + 1,
                        pl.spec.from_name,
                        pl.spec.to_name,
                        iso(tr.t[i]),
                        f"{tr.t[i] - t0:.3f}",
                        f"{tr.t[i] - tr.t[0]:.3f}",
                        f"{tr.x[i]:.3f}",
                        f"{tr.y[i]:.3f}",
                        f"{lat[i]:.8f}",
                        f"{lon[i]:.8f}",
                        f"{tr.heading_deg[i]:.2f}",
                        f"{tr.tws_ms[i]:.3f}",
                        f"{tr.tws_ms[i] / KNOT:.3f}",
                        f"{tr.twd_deg[i]:.2f}",
                        f"{tr.twa_deg[i]:.2f}",
                        f"{tr.bsp_ms[i]:.3f}",
                        f"{tr.bsp_ms[i] / KNOT:.3f}",
                        side_name(int(tr.side[i])),
                        events[i],
                        f"{sog[i]:.3f}",
                        f"{sog[i] / KNOT:.3f}",
                        f"{cog[i]:.2f}",
                    ]
                )
    return p


def _sub(parent: ET.Element, tag: str, text: str | None = None, **attrib: str) -> ET.Element:
    el = ET.SubElement(parent, f"{{{GPX_NS}}}{tag}", attrib)
    if text is not None:
        el.text = clean_text(text)  # XML 1.0 cannot carry control characters
    return el


def write_gpx(path: str | Path, plan: Plan) -> Path:
    """Write ``route.gpx`` (GPX 1.1).

    * ``wpt``: every mark, named;
    * ``rte``: the route's waypoints (:func:`sailroute.report.route_export.route_points`):
      the start point, each tack (``T1``, ...) and gybe (``G1``, ...) and each leg's
      end, named after its target, each with its ``<time>`` and a ``<type>``
      (``start``, ``tack``, ``gybe``, ``mark``, ``gate``, ``line``);
    * ``trk``: one ``trkseg`` per leg with timed points; each point carries
      ``<extensions>`` in the ``urn:x-sailroute:gpx:1`` namespace with ``bsp_ms``,
      ``tws_ms``, ``twd_deg``, ``twa_deg`` and ``heading_deg``.
    """
    ET.register_namespace("", GPX_NS)
    ET.register_namespace("sr", SR_NS)
    c = plan.course
    root = ET.Element(f"{{{GPX_NS}}}gpx", {"version": "1.1", "creator": f"sailroute {__version__}"})
    meta = _sub(root, "metadata")
    _sub(meta, "name", f"{c.name} - {plan.scenario}")
    _sub(meta, "time", iso(plan.t_start))
    for m in c.marks.values():
        w = _sub(root, "wpt", lat=f"{m.lat:.8f}", lon=f"{m.lon:.8f}")
        _sub(w, "name", m.name)
        _sub(w, "type", "mark")
    rte = _sub(root, "rte")
    _sub(rte, "name", f"{c.name} ({plan.scenario})")
    for wp in route_points(plan):  # start, each tack and gybe, each leg's end
        rp = _sub(rte, "rtept", lat=f"{wp.lat:.8f}", lon=f"{wp.lon:.8f}")
        _sub(rp, "time", iso(wp.t))
        _sub(rp, "name", wp.name)
        _sub(rp, "type", wp.kind)
    trk = _sub(root, "trk")
    _sub(trk, "name", f"{c.name} ({plan.scenario})")
    for pl in plan.legs:
        tr = pl.result.track
        seg = _sub(trk, "trkseg")
        lat, lon = c.frame.to_latlon(tr.x, tr.y)
        for i in range(len(tr)):
            pt = _sub(seg, "trkpt", lat=f"{lat[i]:.8f}", lon=f"{lon[i]:.8f}")
            _sub(pt, "time", iso(tr.t[i]))
            ext = _sub(pt, "extensions")
            for tag, val in (
                ("bsp_ms", tr.bsp_ms[i]),
                ("tws_ms", tr.tws_ms[i]),
                ("twd_deg", tr.twd_deg[i]),
                ("twa_deg", tr.twa_deg[i]),
                ("heading_deg", tr.heading_deg[i]),
            ):
                ET.SubElement(ext, f"{{{SR_NS}}}{tag}").text = f"{val:.3f}"
    tree = ET.ElementTree(root)
    ET.indent(tree, space=" ")
    p = Path(path)
    tree.write(p, encoding="utf-8", xml_declaration=True)
    return p


def comparison_to_dict(cmp: Comparison) -> dict[str, Any]:
    """The ``comparison.json`` document (see ``docs/output-format.md``)."""
    legs = []
    for k, label in enumerate(cmp.leg_labels):
        legs.append(
            {
                "index": k + 1,
                "label": label,
                "time_s": {s: _num(cmp.times[i, k]) for i, s in enumerate(cmp.scenarios)},
                "reference_s": {r: _num(v[k]) for r, v in cmp.references.items()},
                "error_pct": {
                    r: {s: _num(cmp.percent(r)[i, k], 3) for i, s in enumerate(cmp.scenarios)}
                    for r in cmp.references
                },
            }
        )
    return {
        "schema_version": SCHEMA_VERSION,
        "sailroute_version": __version__,
        "course": cmp.course_name,
        "error_convention": "(model - reference) / reference * 100",
        "scenarios": list(cmp.scenarios),
        "legs": legs,
        "totals": {
            "time_s": {s: _num(t) for s, t in zip(cmp.scenarios, cmp.totals, strict=True)},
            "reference_s": {r: _num(v.sum()) for r, v in cmp.references.items()},
            "error_pct": {
                r: {s: _num(e, 3) for s, e in zip(cmp.scenarios, cmp.total_percent(r), strict=True)}
                for r in cmp.references
            },
        },
        "scenario_references": {
            s: {
                r: {
                    "legs_s": [_num(x) for x in v],
                    "total_s": _num(v.sum()),
                    "error_pct": [
                        _num(percent_error(cmp.times[cmp.scenarios.index(s), k], v[k]), 3)
                        for k in range(v.size)
                    ],
                    "total_error_pct": _num(
                        percent_error(float(cmp.totals[cmp.scenarios.index(s)]), float(v.sum())), 3
                    ),
                }
                for r, v in refs.items()
            }
            for s, refs in cmp.scenario_references.items()
        },
    }


def write_comparison(out_dir: str | Path, cmp: Comparison) -> tuple[Path, Path]:
    """Write ``comparison.json`` and ``comparison.csv`` into ``out_dir``.

    The CSV has one row per (leg, scenario) plus ``total`` rows, columns ``leg``,
    ``label``, ``scenario``, ``time_s``, then ``<ref>_s`` and ``<ref>_error_pct``
    for every shared reference.
    """
    d = make_out_dir(out_dir)
    jp = d / "comparison.json"
    jp.write_text(
        json.dumps(comparison_to_dict(cmp), indent=2, ensure_ascii=False) + "\n", encoding="utf-8"
    )
    cp = d / "comparison.csv"
    refs = list(cmp.references)
    with cp.open("w", newline="", encoding="utf-8") as fh:
        w = CleanCsvWriter(fh)
        w.writerow(
            [
                "leg",
                "label",
                "scenario",
                "time_s",
                *[c for r in refs for c in (f"{r}_s", f"{r}_error_pct")],
            ]
        )
        for k, label in enumerate(cmp.leg_labels):
            for i, s in enumerate(cmp.scenarios):
                row: list[Any] = [k + 1, label, s, f"{cmp.times[i, k]:.3f}"]
                for r in refs:
                    row += [f"{cmp.references[r][k]:.3f}", f"{cmp.percent(r)[i, k]:.3f}"]
                w.writerow(row)
        for i, s in enumerate(cmp.scenarios):
            row = ["total", "total", s, f"{cmp.totals[i]:.3f}"]
            for r in refs:
                row += [f"{cmp.references[r].sum():.3f}", f"{cmp.total_percent(r)[i]:.3f}"]
            w.writerow(row)
    return jp, cp


FILE_LABELS: dict[str, str] = {
    "plan": "plan (JSON)",
    "track": "track (CSV)",
    "gpx": "route (GPX)",
    "kml": "route (KML)",
    "nmea": "route (NMEA 0183)",
    "course": "course (YAML)",
    "png": "route map (PNG)",
    "comparison_json": "comparison (JSON)",
    "comparison_csv": "comparison (CSV)",
    "comparison_png": "comparison chart (PNG)",
    "ensemble_json": "ensemble spread (JSON)",
    "ensemble_csv": "ensemble spread (CSV)",
    "bands_json": "leg-time bands (JSON)",
    "bands_csv": "leg-time bands (CSV)",
    "bands_png": "leg-time bands chart (PNG)",
    "analysis_json": "analysis (JSON)",
    "analysis_csv": "analysis per leg (CSV)",
    "points_csv": "analysis per track point (CSV)",
    "legs_png": "leg maps (PNG)",
    "loss_png": "time lost chart (PNG)",
    "fleet_json": "fleet ranking (JSON)",
    "fleet_csv": "fleet ranking (CSV)",
    "html": "interactive report (HTML)",
    "plotly_js": "drawing library of the pages (plotly.js)",
}
"""Human names of the output kinds (the keys of the commands' ``files`` mappings)."""

POLAR_FILE_LABELS: dict[str, str] = {
    "pol": "polar (.pol table)",
    "csv": "polar (CSV)",
    "json": "polar (JSON)",
    "png": "polar plot (PNG)",
}
"""Names of the files of ``sailroute vpp`` and ``sailroute polar fit``."""

_STEM_LABELS = {
    "summary": "summary",
    "policy_map": "policy map",
    "spaghetti": "simulated tracks",
    "leg_times": "leg-time distributions",
    "deadline_policy": "deadline policy map",
    "deadline_tracks": "deadline tracks",
}


def file_label(kind: str | None, path: str | Path, labels: Mapping[str, str] = FILE_LABELS) -> str:
    """A human name for an output file, e.g. ``"plan (JSON)"`` or ``"wrf10: track (CSV)"``.

    Parameters
    ----------
    kind : str or None
        Key in a command's ``files`` mapping (``plan``, ``wrf10/track``, ...); None
        names the file by its stem (``policy_map.png`` -> ``"policy map (PNG)"``).
    path : str or Path
        The file.
    labels : mapping of str to str
        Kind -> name (default :data:`FILE_LABELS`; :data:`POLAR_FILE_LABELS` for the
        polar commands).
    """
    p = Path(path)
    prefix = ""
    if kind is not None and "/" in kind:
        prefix, kind = kind.rsplit("/", 1)
        prefix += ": "
    if kind is not None and kind in labels:
        return prefix + labels[kind]
    stem = p.stem
    name = _STEM_LABELS.get(stem, stem.replace("_", " "))
    return f"{prefix}{name} ({p.suffix.lstrip('.').upper() or 'file'})"


def write_plan_outputs(
    out_dir: str | Path,
    plan: Plan,
    *,
    wind: WindField | None = None,
    plot: bool = True,
    dpi: int = 150,
) -> Mapping[str, Path]:
    """Write ``plan.json``, ``track.csv``, ``route.gpx``, ``route.kml``, ``route.nmea``
    and (if ``plot``) ``route.png``.

    Parameters
    ----------
    out_dir : str or Path
        Folder, created if missing.
    plan : Plan
        The routed course.
    wind : WindField, optional
        Drawn as arrows/field at the start time on ``route.png``.
    plot : bool
        Also write ``route.png``.
    dpi : int
        PNG resolution.

    Returns
    -------
    mapping of str to Path
        ``{"plan": ..., "track": ..., "gpx": ..., "kml": ..., "nmea": ..., "png": ...}``.
    """
    d = make_out_dir(out_dir)
    out = {
        "plan": write_plan_json(d / "plan.json", plan),
        "track": write_track_csv(d / "track.csv", plan),
        "gpx": write_gpx(d / "route.gpx", plan),
    }
    out["kml"] = write_kml(d / "route.kml", plan)
    out["nmea"] = write_nmea(d / "route.nmea", plan)
    if plot:
        from sailroute.report.png_worker import draw_in_process

        out["png"] = draw_in_process(plan, wind, d / "route.png", dpi)
    return out
