"""``sailroute start``: from a position before the gun to the start line, and the time to burn.

Loads the course, builds its boat and one scenario's wind, and computes
:func:`sailroute.routing.startline.line_approach` from the given position and time (and
:func:`~sailroute.routing.startline.start_line_numbers` at the gun); writes
``start.json`` (``docs/output-format.md``).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

from sailroute._version import __version__
from sailroute.commands.result import CommandResult
from sailroute.course.geometry import FAR_FROM_COURSE_M, course_gap_m
from sailroute.course.model import Course
from sailroute.errors import InputError
from sailroute.timeutil import iso_datetime, parse_time, to_epoch

__all__ = ["parse_position", "parse_start_time", "position_xy", "run_start_command"]

"""A position further than this from the course area (the marks' box) is refused [m]."""

SCHEMA_VERSION = 1
"""Version of the ``start.json`` schema."""

MAX_FROM_GUN_S = 86400.0
"""Most seconds before or after the gun ``--time`` may be given as [s]."""


def parse_position(text: str, option: str = "--at") -> tuple[float, float]:
    """Two comma-separated numbers, ``"A,B"`` (``"43.06,6.21"``).

    Raises
    ------
    InputError
        Not two finite numbers.
    """
    parts = [p.strip() for p in str(text).split(",")]
    try:
        if len(parts) != 2:
            raise ValueError
        a, b = float(parts[0]), float(parts[1])
    except ValueError:
        example = (
            "43.0645,6.2295 (LAT,LON in degrees)" if option == "--at" else "-150,80 (X,Y in metres)"
        )
        raise InputError(
            f"{option} {text!r}: expected two comma-separated numbers, e.g. {example}"
        ) from None
    if not (math.isfinite(a) and math.isfinite(b)):
        raise InputError(f"{option} {text!r}: the numbers must be finite")
    return a, b


def parse_start_time(text: str, gun: float) -> float:
    """``--time``: an ISO 8601 time with a UTC offset, or seconds relative to the gun.

    Parameters
    ----------
    text : str
        ``"2018-04-24T12:08:30+02:00"``, or ``"-90"`` (90 s before the gun).
    gun : float
        The start signal [epoch s].

    Returns
    -------
    float
        The time [epoch s].

    Raises
    ------
    InputError
        Neither form, seconds without a sign or further than a day from the gun, or a
        time without an offset or out of range.
    """
    s = str(text).strip()
    try:
        rel = float(s)
    except ValueError:
        rel = None
    if rel is not None:
        if not (math.isfinite(rel) and abs(rel) <= MAX_FROM_GUN_S):
            raise InputError(
                f"--time {text!r}: expected seconds from the gun within "
                f"±{MAX_FROM_GUN_S:.0f} (a day), e.g. -90"
            )
        if rel != 0 and not s.startswith(("-", "+")):
            raise InputError(
                f"--time {text!r}: seconds from the gun need a sign: -{s} ({s} s before "
                f"the gun) or +{s} (after it)"
            )
        return gun + rel
    try:
        iso_datetime(s)
    except ValueError:
        raise InputError(
            f"--time {text!r}: expected an ISO 8601 time with a UTC offset "
            "(e.g. 2018-04-24T12:08:30+02:00) or seconds from the gun (e.g. -90)"
        ) from None
    return to_epoch(parse_time(s, "--time"))  # its own words: no offset, out of range


def position_xy(course: Course, at: str | None, xy: str | None) -> tuple[float, float]:
    """The boat's position in the course frame [m] from ``--at LAT,LON`` or ``--xy X,Y``.

    Raises
    ------
    InputError
        Neither or both given, unparsable, or more than
        :data:`~sailroute.course.geometry.FAR_FROM_COURSE_M` from the course area.
    """
    if (at is None) == (xy is None):
        raise InputError(
            "give the boat's position with --at LAT,LON (degrees) or --xy X,Y "
            "(metres east and north of the course origin), one of the two"
        )
    if at is not None:
        lat, lon = parse_position(at, "--at")
        if not (-90.0 <= lat <= 90.0 and -180.0 <= lon <= 360.0):
            raise InputError(
                f"--at {at!r}: latitude must be within -90..90 and longitude "
                "within -180..360 degrees; the order is LAT,LON"
            )
        x, y = (float(v) for v in course.frame.to_xy(lat, lon))
        given = f"--at {at}"
    else:
        x, y = parse_position(str(xy), "--xy")
        given = f"--xy {xy}"
    gap = course_gap_m(course, (x, y))
    if not math.isfinite(gap) or gap > FAR_FROM_COURSE_M:
        far = f"{gap / 1000:.0f} km" if gap < 1e8 else "more than 100 000 km"
        raise InputError(
            f"{given}: the position is {far} from the course area (the marks "
            f"of {course.source or course.name}); it must be within "
            f"{FAR_FROM_COURSE_M / 1000:.0f} km (check the order LAT,LON and the signs)"
        )
    return x, y


def _default_out(course: Course) -> Path:
    from sailroute.commands.plan import default_out_dir

    return default_out_dir(course, "start")


def run_start_command(
    course: Course | str | Path,
    *,
    time: str,
    at: str | None = None,
    xy: str | None = None,
    scenario: str | None = None,
    out_dir: str | Path | None = None,
) -> CommandResult:
    """Everything ``sailroute start`` does, minus printing.

    Parameters
    ----------
    course : Course or path
        The course (its first leg must start from a line).
    time : str
        When the boat is there: ISO 8601 with offset, or seconds from the gun (``-90``).
    at, xy : str, optional
        The position: ``"LAT,LON"`` [°] or ``"X,Y"`` [m in the course frame]; one of them.
    scenario : str, optional
        Wind scenario (default: the first in the file; an ensemble: its first member).
    out_dir : str or Path, optional
        Where ``start.json`` goes (default ``out/<course>/start``).

    Returns
    -------
    CommandResult
        ``report`` the table, ``files`` ``{"json": start.json}``, ``data`` the
        :class:`~sailroute.routing.startline.LineApproach`.

    Raises
    ------
    InputError
        No start line, bad position or time, unknown scenario, bad boat or wind.
    """
    from sailroute.course.load import build_specs, load_course
    from sailroute.outdir import check_out_dir, write_output_set
    from sailroute.planning.startline import require_start_line
    from sailroute.report.startline import approach_to_dict
    from sailroute.report.tables import approach_table
    from sailroute.routing.startline import line_approach, start_line_numbers

    course = course if isinstance(course, Course) else load_course(course)
    line = require_start_line(course)
    gun = course.start_epoch
    t = parse_start_time(time, gun)
    p = position_xy(course, at, xy)
    out = check_out_dir(Path(out_dir) if out_dir is not None else _default_out(course))
    name = course.scenario_names[0] if scenario is None else scenario
    name = course.ensembles.get(name, (name,))[0]
    boat, winds = build_specs(course, [name])
    wind = winds[name]
    names = (line.a.name, line.b.name)
    numbers = start_line_numbers(line.a.xy, line.b.xy, wind, boat, gun, names=names)
    ap = line_approach(p, t, line.a.xy, line.b.xy, wind, boat, gun, names=names)
    doc = {
        "schema_version": SCHEMA_VERSION,
        "sailroute_version": __version__,
        "scenario": name,
        **approach_to_dict(ap, course.frame, course=course.name, line=numbers),
    }
    notes = tuple(n for n in (ap.wind_note,) if n)
    if ap.course_side:
        notes += ("the boat is on the course side of the line: it must come back below it",)
    doc["notes"] = list(notes)

    def write(d: Path) -> dict[str, Path]:
        path = d / "start.json"
        path.write_text(json.dumps(doc, indent=2, ensure_ascii=False) + "\n", encoding="utf-8")
        return {"json": path}

    files = write_output_set(out, write)
    return CommandResult(
        approach_table(ap, course.name, names),
        files,
        ap,
        notes,
        ("json",),
        labels={"json": "start (JSON)"},
    )
