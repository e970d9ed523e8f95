"""``sailroute course infer``: a course file (YAML) from a fleet's tracks, for a race
whose marks are unknown or moved.

The course is inferred by :func:`sailroute.analysis.infer_marks.infer_course`; this module
reads the tracks, writes the course file (checked as ``course import`` checks its own:
:func:`~sailroute.commands.course_import.write_course_file`) and a JSON file beside it
with each mark's spread, and gives ``sailroute analyze --marks infer`` the course it
analyses in (:func:`course_for_analysis`).
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from sailroute.analysis.infer_marks import InferredCourse, infer_course, summary
from sailroute.commands.course_import import boat_spec_of, write_course_file
from sailroute.commands.result import CommandResult
from sailroute.course.formats import ImportedCourse, course_yaml
from sailroute.course.load import course_from_mapping
from sailroute.course.model import Course
from sailroute.course.read import read_course_file
from sailroute.errors import InputError
from sailroute.outdir import check_out_file, replacing
from sailroute.report.tables import render_table
from sailroute.timeutil import from_epoch, iso, parse_time, to_epoch
from sailroute.track.model import Track
from sailroute.track.read import read_track

__all__ = [
    "Inference",
    "course_for_analysis",
    "infer_for_analyze",
    "inferred_text",
    "read_fleet",
    "run_course_infer_command",
]

TIME_LIMIT_MARGIN_MIN = 10.0
"""The course's time limit is the race's length (gun to the last finish or rounding) plus
this [min], and at least the loader's default of 90 min."""


def read_fleet(
    paths: Sequence[str | Path],
    *,
    columns: Mapping[str, str] | None = None,
    speed_unit: str | None = None,
    time_zone: str | None = None,
) -> tuple[list[Track], list[str]]:
    """The tracks, a file given twice (the same fixes) kept once.

    Returns
    -------
    tracks : list of Track
    notes : list of str
        One line naming the files left out as copies, if any.
    """
    tracks: list[Track] = []
    seen: dict[str, str] = {}
    copies = []
    for p in paths:
        tr = read_track(
            p, columns=columns, speed_unit=speed_unit, time_zone=time_zone, name=Path(p).stem
        )
        h = hashlib.sha256()
        for a in (tr.t_s, tr.lat_deg, tr.lon_deg):
            h.update(a.tobytes())
        key = h.hexdigest()
        if key in seen:
            copies.append(f"{p} (the same fixes as {seen[key]})")
            continue
        seen[key] = str(p)
        tracks.append(tr)
    notes = [f"left out as copies: {', '.join(copies)}"] if copies else []
    return tracks, notes


def _epoch(text: str | None, option: str) -> float | None:
    return None if text is None else to_epoch(parse_time(text, where=option))


def _check_tws(tws_kn: float | None, why: str) -> float:
    if tws_kn is None:
        raise InputError(
            f"--wind-tws is required: {why}; give the wind speed the race was sailed in [kn] "
            "(the direction comes from the tracks)"
        )
    if not (math.isfinite(tws_kn) and 0.0 <= tws_kn <= 100.0):
        raise InputError(f"--wind-tws {tws_kn:g}: expected knots in [0, 100]")
    return float(tws_kn)


def _mark_notes(ic: InferredCourse) -> dict[str, str]:
    """The comment of each mark line: spread and support, or the line end it is."""
    out = {
        m.name: (
            f"rounded to {m.rounding} by {m.n_boats} boats ({m.n_roundings} roundings); "
            f"spread {m.spread_m:.0f} m"
        )
        for m in ic.marks
    }
    for line, le in (("start", ic.start), ("finish", ic.finish)):
        if le is not None:
            for end in ("pin", "committee"):
                out[f"{line}-{end}"] = (
                    f"{end} end of the {line} line ({le.n_boats} boats crossed it; "
                    f"fleet {le.depth_m:.0f} m deep across it)"
                )
    return out


def _imported(ic: InferredCourse, name: str) -> ImportedCourse:
    """The inferred course in the form the course writer takes."""
    marks = [(m.name, m.lat, m.lon) for m in ic.marks]
    lines = []
    for line, le in (("start", ic.start), ("finish", ic.finish)):
        if le is not None:
            for end, xy in (("pin", le.pin), ("committee", le.committee)):
                marks.append((f"{line}-{end}", *ic.latlon(xy)))
            lines.append((line, f"{line}-pin", f"{line}-committee"))
    return ImportedCourse(
        name=name,
        marks=tuple(marks),
        lines=tuple(lines),
        gates=ic.gates,
        start_from="start",
        legs=ic.legs,  # type: ignore[arg-type]
        start_time=from_epoch(round(ic.gun.t)),
    )


def _gun_text(ic: InferredCourse) -> str:
    g = ic.gun
    if g.source == "given":
        return f"gun {iso(g.t)} (given)"
    return (
        f"gun {iso(round(g.t))} inferred from the fleet's start crossings (± {g.sd_s:.1f} s, 1 sd)"
    )


def _race_minutes(ic: InferredCourse) -> float:
    last = [t for row in ic.leg_roundings for t in row if math.isfinite(t)]
    return (max(last) - ic.gun.t) / 60.0 if last else 0.0


def inferred_text(
    ic: InferredCourse,
    *,
    tws_kn: float,
    boat: Mapping[str, Any] | None,
    name: str,
    n_tracks: int,
) -> str:
    """The course file of an inferred course (``docs/course-format.md``)."""
    header = [
        f"Inferred by `sailroute course infer` from the turns of {n_tracks} tracks "
        f"({len(ic.boats)} used) of the race of {iso(ic.gun.t)[:10]}.",
        f"{_gun_text(ic)}.",
        "The marks are where the fleet turned, not surveyed positions; each mark's comment",
        "gives its spread (median distance of the single roundings from it) and support.",
        f"Wind direction {ic.twd_deg:.0f} deg from the tracks ({ic.twd_how}).",
    ]
    text = course_yaml(
        _imported(ic, name),
        source="",
        fmt="",
        twd_deg=round(ic.twd_deg, 1),
        tws_kn=tws_kn,
        start_time=from_epoch(round(ic.gun.t)),
        boat=boat,
        header=header,
        mark_notes=_mark_notes(ic),
    )
    minutes = _race_minutes(ic) + TIME_LIMIT_MARGIN_MIN
    if minutes > 90.0:
        text = text.replace("\nmarks:\n", f"\ntime_limit_min: {math.ceil(minutes)}\nmarks:\n", 1)
    return text


def _report(ic: InferredCourse) -> str:
    """The terminal report: gun, marks, lines, legs."""
    rows = [
        [
            m.name,
            f"{m.lat:.6f}",
            f"{m.lon:.6f}",
            m.rounding if m.gate is None else f"{m.rounding} ({m.gate})",
            f"{m.spread_m:.0f}",
            f"{m.n_boats}/{len(ic.boats)}",
        ]
        for m in ic.marks
    ]
    out = [
        _gun_text(ic),
        render_table(["mark", "lat", "lon", "rounded", "spread m", "boats"], rows, align="lrrlrr"),
    ]
    for line, le in (("start", ic.start), ("finish", ic.finish)):
        if le is not None:
            out.append(
                f"{line} line: {le.length_m:.0f} m, crossed by {le.n_boats} boats "
                f"(fleet {le.depth_m:.0f} m deep across it)"
            )
    legs = " -> ".join(["start", *(f"{to} ({r})" if r else to for to, r in ic.legs)])
    out.append(f"legs: {legs}")
    out.append(
        f"wind: from {ic.twd_deg:.0f}° (axis {ic.axis_deg:.0f}°/{(ic.axis_deg + 180) % 360:.0f}°; "
        f"{ic.twd_how})"
    )
    return "\n".join(out)


def _gun_notes(ic: InferredCourse) -> list[str]:
    """A note on the gun: how sure, and a whole minute it could be."""
    g = ic.gun
    if g.source != "inferred":
        return []
    minute = round(g.t / 60.0) * 60.0
    notes = [
        f"the gun is inferred ({iso(round(g.t))} ± {g.sd_s:.1f} s): the fleet's first 10 % "
        "cross the start line then; over-early calls within a few seconds of it are not sure"
    ]
    if abs(minute - g.t) <= max(2.0 * g.sd_s, 5.0):
        notes.append(
            f"the whole minute {iso(minute)} lies {abs(minute - g.t):.0f} s from it: if the "
            f"race started on the minute, give --start-time {iso(minute).replace('.000', '')}"
        )
    return notes


def run_course_infer_command(
    tracks: Sequence[str | Path],
    *,
    out: str | Path,
    start_time: str | None = None,
    t_from: str | None = None,
    t_until: str | None = None,
    wind_tws_kn: float | None = None,
    boat: str | None = None,
    name: str | None = None,
    columns: Mapping[str, str] | None = None,
    speed_unit: str | None = None,
    time_zone: str | None = None,
) -> CommandResult:
    """Everything ``sailroute course infer`` does, minus printing.

    Parameters
    ----------
    tracks : sequence of str or Path
        GPX or CSV tracks of two boats or more of one race.
    out : str or Path
        The course file to write (``.yaml``); the JSON file ``<stem>.marks.json`` goes
        beside it.
    start_time : str, optional
        The gun (ISO 8601 with offset); inferred when not given.
    t_from, t_until : str, optional
        Use only the fixes in this window (ISO 8601 with offset): logs of several races.
    wind_tws_kn : float
        Wind speed of the scenario [kn] (required).
    boat : str, optional
        ``--boat`` (:func:`~sailroute.commands.course_import.boat_spec_of`).
    name : str, optional
        Course name (default ``inferred course``).
    columns, speed_unit, time_zone
        How to read CSV tracks (:func:`sailroute.track.read.read_track`).

    Returns
    -------
    CommandResult
        ``files = {"course": ..., "marks_json": ...}``, ``data`` the
        :class:`~sailroute.analysis.infer_marks.InferredCourse`.

    Raises
    ------
    InputError
        A bad track, fewer than two tracks, no roundings shared by the fleet, no gun
        found, a missing ``--wind-tws``, or an output that cannot be written.
    """
    dest = check_out_file(out, tracks)
    if dest.suffix.lower() not in (".yaml", ".yml"):
        raise InputError(f"-o {dest}: expected a .yaml file name")
    check_out_file(dest.with_name(f"{dest.stem}.marks.json"), tracks)
    tws = _check_tws(wind_tws_kn, "the course file needs a wind scenario to plan in")
    gun = _epoch(start_time, "--start-time")
    lo = _epoch(t_from, "--from")
    hi = _epoch(t_until, "--until")
    trs, notes = read_fleet(tracks, columns=columns, speed_unit=speed_unit, time_zone=time_zone)
    if len(trs) < 2 <= len(tracks):
        raise InputError(
            f"course infer: the {len(tracks)} files hold one track ({notes[0]}); the marks "
            "are where a fleet turns: give the tracks of two boats or more of the same race"
        )
    ic = infer_course(
        trs,
        gun_t=gun,
        t_from=-math.inf if lo is None else lo,
        t_until=math.inf if hi is None else hi,
    )
    text = inferred_text(
        ic,
        tws_kn=tws,
        boat=boat_spec_of(boat, dest),
        name=name or "inferred course",
        n_tracks=len(tracks),
    )
    write_course_file(text, dest)
    notes += [*ic.notes, *_gun_notes(ic)]
    if boat is None:
        notes.append(
            f"no boat given (--boat): add a `boat:` section to {dest} for the boat "
            "the fleet sailed; until then `sailroute plan` routes the default ILCA 7 polar"
        )
    js = dest.with_name(f"{dest.stem}.marks.json")
    doc = summary(ic)
    doc["course_file"] = dest.name
    doc["notes"] = notes
    with replacing(js) as fh:
        fh.write(json.dumps(doc, indent=1, ensure_ascii=False) + "\n")
    report = "\n".join([_report(ic), *(f"note: {n}" for n in notes)])
    return CommandResult(
        report,
        {"course": dest, "marks_json": js},
        ic,
        tuple(notes),
        main=("marks_json",),
        labels={"course": "course file", "marks_json": "inferred marks (JSON)"},
    )


def course_for_analysis(
    course: str | Path | None,
    tracks: Sequence[Track],
    *,
    wind_tws_kn: float | None = None,
) -> tuple[Course, str, list[str]]:
    """The course ``sailroute analyze --marks infer`` analyses in.

    Parameters
    ----------
    course : str or Path or None
        A course file whose boat, wind scenarios, gun, time limit and settings are kept
        and whose marks, lines, gates and legs are replaced by the inferred ones (its
        ``references``, timed on its own legs, are dropped); None: a course of its own,
        the gun inferred, the wind from the tracks at ``wind_tws_kn``, the default boat.
    tracks : sequence of Track
        The fleet.
    wind_tws_kn : float, optional
        Wind speed [kn] (required without ``course``).

    Returns
    -------
    (Course, str, list of str)
        The course, the inference's report, its notes.
    """
    if course is None:
        tws = _check_tws(
            wind_tws_kn, "--marks infer without a course file takes the wind from the tracks"
        )
        ic = infer_course(tracks)
        src = Path("inferred-course.yaml")
        data = _parse(inferred_text(ic, tws_kn=tws, boat=None, name=src.stem, n_tracks=len(tracks)))
        return course_from_mapping(data, source=src), _report(ic), [*ic.notes, *_gun_notes(ic)]
    src = Path(course)
    base = read_course_file(src).data
    if not isinstance(base, Mapping):
        raise InputError(f"{src}: expected a course file (a YAML mapping, docs/course-format.md)")
    data = dict(base)
    start = data.get("start_time")
    gun = None if start is None else to_epoch(parse_time(start, where=f"{src}: start_time"))
    ic = infer_course(tracks, gun_t=gun)
    inferred = _parse(inferred_text(ic, tws_kn=0.0, boat=None, name="", n_tracks=len(tracks)))
    notes = list(ic.notes)
    if "references" in data:
        notes.append(f"{src}: its `references` are timed on its own legs: left out")
    for key in ("marks", "lines", "gates", "legs", "origin", "template", "references"):
        data.pop(key, None)
    for key in ("marks", "lines", "gates", "legs"):
        if key in inferred:
            data[key] = inferred[key]
    data.setdefault("start_time", inferred["start_time"])
    return course_from_mapping(data, source=src), _report(ic), notes


def _parse(text: str) -> Any:
    """A course file's text parsed as the loader parses files (YAML 1.2 scalars)."""
    import yaml

    from sailroute.yamlfile import YamlLoader

    return yaml.load(text, Loader=YamlLoader)


@dataclass(frozen=True)
class Inference:
    """What ``analyze --marks infer`` prints before the analysis: the inferred course
    and its notes."""

    report: str
    notes: tuple[str, ...]

    def before(self, res: CommandResult) -> CommandResult:
        """``res`` with the inferred course's report in front and its notes added."""
        text = "\n".join(["course inferred from the tracks:", self.report])
        return replace(
            res,
            report="\n\n".join([text, res.report]),
            notes=(*self.notes, *res.notes),
        )


def infer_for_analyze(
    course: str,
    tracks: Sequence[str],
    wind_tws_kn: float | None,
    *,
    columns: Mapping[str, str] | None = None,
    speed_unit: str | None = None,
    time_zone: str | None = None,
) -> tuple[Course, Inference, list[str]]:
    """``sailroute analyze --marks infer COURSE TRACK...``: the course to analyse in.

    ``COURSE`` is a course file (``.yaml``/``.yml``: :func:`course_for_analysis` keeps
    all but its marks) or else the first track.

    Returns
    -------
    (Course, Inference, list of str)
        The course, the report to print before the analysis, and the track files.
    """
    base = course if Path(course).suffix.lower() in (".yaml", ".yml") else None
    paths = list(tracks) if base is not None else [course, *tracks]
    trs, copies = read_fleet(paths, columns=columns, speed_unit=speed_unit, time_zone=time_zone)
    built, report, notes = course_for_analysis(base, trs, wind_tws_kn=wind_tws_kn)
    return built, Inference(report, (*copies, *notes)), paths
