"""``sailroute course import``: a course file (YAML) from GPX, CSV, KML or race XML.

The command reads the file (:mod:`sailroute.course.formats`), writes the course file
next to nothing else, and loads what it wrote (:func:`~sailroute.course.load.load_course`
and the boat and wind factories) before keeping it: a course that would not plan is
never written.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from datetime import datetime
from pathlib import Path
from typing import Any

import yaml

from sailroute.commands.result import CommandResult
from sailroute.course.formats import ImportedCourse, course_yaml, read_course_source
from sailroute.course.load import course_from_mapping, load_course, validate_specs
from sailroute.course.model import Course
from sailroute.course.read import read_course_file
from sailroute.errors import InputError
from sailroute.timeutil import parse_time

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
        A mapping that does not parse.
    """
    if text is None:
        return None
    t = text.strip()
    if t.startswith("{"):
        try:
            spec = yaml.safe_load(t)
        except yaml.YAMLError as exc:
            raise InputError(
                f"--boat {text!r}: not a YAML mapping ({exc.__class__.__name__});"
                " expected e.g. '{polar: f50.csv, speed_unit: km/h}'"
            ) from None
        if not isinstance(spec, dict):
            raise InputError(f"--boat {text!r}: expected a mapping such as '{{builtin: ilca7}}'")
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


def write_course_file(text: str, dest: Path) -> Course:
    """Write a course file only if it loads and its boat and wind build; return it.

    The text goes to a draft next to ``dest`` first and is checked there (messages name
    ``dest``), then replaces ``dest``: a course that would not plan is never written.

    Raises
    ------
    InputError
        The folder is missing or not writable, or the text does not load.
    """
    if not dest.parent.is_dir():
        raise InputError(f"-o {dest}: the folder {dest.parent} does not exist; create it first")
    tmp = dest.with_name(f".{dest.name}.sailroute-tmp")
    try:
        tmp.write_text(text, encoding="utf-8")
        doc = read_course_file(tmp)  # messages name the file to be written, not the draft
        validate_specs(course_from_mapping(doc.data, source=dest, key_lines=doc.lines))
        os.replace(tmp, dest)
    except OSError as exc:
        raise InputError(f"-o {dest}: cannot write the file ({exc.strerror})") from None
    finally:
        tmp.unlink(missing_ok=True)
    return load_course(dest)


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
    ic, chosen = read_course_source(src, fmt)
    if dest.exists() and dest.resolve() == src.resolve():
        raise InputError(f"-o {dest}: the same file as the input; choose another name")
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
        boat=boat_spec_of(boat, dest),
    )
    course = write_course_file(text, dest)
    notes = list(ic.notes)
    if boat is None:
        notes.append(
            f"no boat given (--boat): add a `boat:` section to {dest} for the boat "
            "you race; until then `sailroute plan` routes the default ILCA 7 polar"
        )
    files: Mapping[str, Path] = {"course": dest}
    report = "\n".join([_summary(ic, course, dest, chosen), *(f"note: {n}" for n in notes)])
    return CommandResult(report, files, course, tuple(notes), main=())
