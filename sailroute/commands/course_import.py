"""``sailroute course import``: a course file (YAML) from GPX, CSV, KML or race XML.

The command reads the file (:mod:`sailroute.course.formats`), composes the course file's
text and checks it as ``sailroute plan`` would (:func:`~sailroute.course.load.course_from_mapping`
and the boat and wind factories) before writing it: a course that would not plan is never
written, and what the checks find is reported at the line of the imported file it came
from (the boat at ``--boat``).  The file is written whole or not at all
(:func:`sailroute.outdir.replacing`), and never over one of the command's inputs.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping
from datetime import datetime
from pathlib import Path
from typing import Any

from sailroute.boat.build import boat_from_spec
from sailroute.commands.result import CommandResult
from sailroute.course.formats import ImportedCourse, course_yaml, read_course_source
from sailroute.course.load import course_from_mapping, validate_specs
from sailroute.course.model import Course
from sailroute.errors import InputError
from sailroute.outdir import check_out_file, replacing
from sailroute.textin import excerpt
from sailroute.timeutil import parse_time
from sailroute.yamlfile import parse_yaml

__all__ = ["boat_spec_of", "run_course_import_command", "write_course_file"]


def boat_spec_of(text: str | None, out: Path) -> dict[str, Any] | None:
    """The ``boat`` section of ``--boat``.

    Parameters
    ----------
    text : str or None
        A built-in polar's name (``ilca7``), a polar file (``.pol``/``.csv``, written
        relative to the course file's folder), or a YAML mapping
        (``"{polar: f50.csv, speed_unit: km/h}"``) used as written.
    out : Path
        The course file to be written.

    Returns
    -------
    dict or None
        None when ``text`` is None.

    Raises
    ------
    InputError
        A mapping that does not parse (read as course files are: nesting, size and
        characters checked), or holds a value that is not text, a number, true/false,
        a list or a mapping.
    """
    if text is None:
        return None
    t = text.strip()
    if t.startswith("{"):
        given = f"--boat {excerpt(text)!r}"
        try:
            spec = parse_yaml(t, "--boat").data
        except InputError as exc:  # "--boat:1:6: YAML syntax error: ..."
            raise InputError(
                f"{given}: not a YAML mapping (at {str(exc).removeprefix('--boat:')}); "
                "expected e.g. '{polar: f50.csv, speed_unit: km/h}'"
            ) from None
        if not isinstance(spec, dict):
            raise InputError(f"{given}: expected a mapping such as '{{builtin: ilca7}}'")
        bad = next((k for k in _keys(spec) if not (isinstance(k, str) and k.isprintable())), None)
        if bad is not None:
            raise InputError(
                f"{given}: the key {bad!a} is not a name; expected keys such as polar, "
                "builtin, speed_unit"
            )
        try:
            json.dumps(spec, allow_nan=False)  # as course_yaml writes it
        except (TypeError, ValueError) as exc:
            what = "a date, time or binary value" if isinstance(exc, TypeError) else "NaN or inf"
            raise InputError(
                f"{given}: holds {what}; expected text, numbers, true/false, lists and "
                "mappings (quote a value meant as text)"
            ) from None
        return spec
    p = Path(t)
    if p.suffix.lower() in (".pol", ".csv", ".txt") or p.is_file():
        if not p.is_file():
            raise InputError(
                f"--boat {text!r}: no such polar file; expected a built-in name "
                "(ilca7, ilca6, ...) or an existing .pol/.csv file"
            )
        return {"polar": os.path.relpath(p.resolve(), out.resolve().parent)}
    return {"builtin": t}


def _keys(value: Any) -> list[Any]:
    """Every mapping key in ``value``, at any depth (``value`` is at most 50 deep)."""
    if isinstance(value, dict):
        return [*value, *(k for v in value.values() for k in _keys(v))]
    if isinstance(value, list):
        return [k for v in value for k in _keys(v)]
    return []


def _files_of(boat: Mapping[str, Any] | None, dest: Path) -> list[Path]:
    """The polar file a ``--boat`` names (relative to the course file's folder), if any."""
    polar = (boat or {}).get("polar")
    return [dest.absolute().parent / polar] if isinstance(polar, str) and polar else []


def _checked(
    text: str, dest: Path, src: Path | None, src_lines: Mapping[str, int] | None
) -> Course:
    """Check the course file ``text`` as ``sailroute plan`` reads it, before it is written.

    The course (marks, lines, legs, areas, start time, wind) is checked with the lines of
    the file it came from (``src`` and its key lines, when given), so a problem is
    reported at the line it came from, else at ``dest``'s own lines; the boat on its own,
    at ``--boat``, resolving a polar file against ``dest``'s folder.

    Returns
    -------
    Course
        The course as ``dest`` will load, with ``dest``'s lines.

    Raises
    ------
    InputError
        Whatever the course file's checks or the boat and wind factories refuse.
    """
    doc = parse_yaml(text, str(src or dest))
    data = dict(doc.data)
    boat = data.pop("boat", None)
    lines = dict(src_lines) if src_lines is not None else doc.lines
    validate_specs(course_from_mapping(data, source=src or dest, key_lines=lines))
    if boat is not None:
        boat_from_spec(boat, base_dir=dest.absolute().parent, where="--boat", key="")
    return course_from_mapping(doc.data, source=dest, key_lines=doc.lines)


def write_course_file(
    text: str,
    dest: Path,
    *,
    src: Path | None = None,
    src_lines: Mapping[str, int] | None = None,
) -> Course:
    """Write a course file only if it loads and its boat and wind build; return it.

    ``text`` is checked first (:func:`_checked`; messages name ``src`` and its lines when
    given, else ``dest``), then written through :func:`sailroute.outdir.replacing` (a
    draft with an unpredictable name, never through a link, moved onto ``dest``): a
    course that would not plan is never written, and a failed write leaves ``dest`` as
    it was.

    Raises
    ------
    InputError
        The text does not load, or the file cannot be written.
    """
    course = _checked(text, dest, src, src_lines)
    with replacing(dest) as fh:
        fh.write(text)
    return course


def _summary(ic: ImportedCourse, course: Course, out: Path, fmt: str) -> str:
    """The terminal report: what was read, leg by leg."""
    rows = [
        f"course {course.name!r} from {fmt}: {len(ic.marks)} marks, "
        f"{len(ic.lines)} lines, {len(ic.gates)} gates, {course.n_legs} legs; start "
        f"{course.start_time.isoformat()}"
    ]
    for leg in course.legs:
        side = f" ({leg.rounding})" if leg.rounding else ""
        rows.append(f"  leg {leg.index + 1}: {leg.label} [{leg.kind}]{side}")
    if ic.boundary is not None:
        rows.append(f"boundary: {len(ic.boundary)} points")
    for name, ring in ic.obstacles:
        rows.append(f"obstacle {name!r}: {len(ring)} points")
    rows.append(f"check: {out} loads and its boat and wind build")
    return "\n".join(rows)


def run_course_import_command(
    source: str | Path,
    *,
    out: str | Path | None = None,
    fmt: str = "auto",
    boat: str | None = None,
    wind_twd_deg: float | None = None,
    wind_tws_kn: float | None = None,
    start_time: str | None = None,
) -> CommandResult:
    """Everything ``sailroute course import`` does, minus printing.

    Parameters
    ----------
    source : str or Path
        The GPX, CSV, KML or race XML file.
    out : str or Path, optional
        The course file to write (default ``<source stem>.yaml`` in the working folder).
    fmt : {"auto", "gpx", "csv", "kml", "racexml"}
        The source's format (``auto``: by suffix, or the root element of ``.xml``).
    boat : str, optional
        ``--boat`` (:func:`boat_spec_of`); None writes no ``boat`` section.
    wind_twd_deg, wind_tws_kn : float
        The uniform wind scenario [deg from, kn]; both required.
    start_time : str, optional
        ISO 8601 time with a UTC offset; overrides the file's (required when the file
        has none: GPX, CSV, KML).

    Returns
    -------
    CommandResult
        ``files = {"course": <the YAML>}``, ``data`` the loaded
        :class:`~sailroute.course.model.Course`, ``notes`` what the user should check.

    Raises
    ------
    InputError
        A bad source file, missing wind or start time, or a written course that does not
        load (nothing is written then).
    """
    src = Path(source)
    if wind_twd_deg is None or wind_tws_kn is None:
        raise InputError(
            "--wind-twd and --wind-tws are required: the course file needs a "
            "wind scenario to plan in; give the forecast's direction [deg, from] "
            "and speed [kn] (replace the scenario in the file later if you like)"
        )
    if not (math.isfinite(wind_twd_deg) and 0.0 <= wind_twd_deg <= 360.0):
        raise InputError(f"--wind-twd {wind_twd_deg:g}: expected degrees in [0, 360]")
    if not (math.isfinite(wind_tws_kn) and 0.0 <= wind_tws_kn <= 100.0):
        raise InputError(f"--wind-tws {wind_tws_kn:g}: expected knots in [0, 100]")
    dest = Path(out) if out is not None else Path(f"{src.stem}.yaml")
    if dest.suffix.lower() not in (".yaml", ".yml"):
        raise InputError(f"-o {dest}: expected a .yaml file name")
    boat_spec = boat_spec_of(boat, dest)
    check_out_file(dest, [src, *_files_of(boat_spec, dest)])
    ic, chosen = read_course_source(src, fmt)
    t0: datetime | None = (
        parse_time(start_time, where="--start-time") if start_time is not None else ic.start_time
    )
    if t0 is None:
        raise InputError(
            f"{src}: the file gives no start time; give --start-time "
            "'2025-01-19T16:08:00+13:00' (ISO 8601 with a UTC offset)"
        )
    text = course_yaml(
        ic,
        source=src.name,
        fmt=chosen,
        twd_deg=float(wind_twd_deg),
        tws_kn=float(wind_tws_kn),
        start_time=t0,
        boat=boat_spec,
    )
    course = write_course_file(text, dest, src=src, src_lines=dict(ic.key_lines))
    notes = list(ic.notes)
    if boat is None:
        notes.append(
            f"no boat given (--boat): add a `boat:` section to {dest} for the boat "
            "you race; until then `sailroute plan` routes the default ILCA 7 polar"
        )
    files: Mapping[str, Path] = {"course": dest}
    report = "\n".join([_summary(ic, course, dest, chosen), *(f"note: {n}" for n in notes)])
    return CommandResult(report, files, course, tuple(notes), main=())
