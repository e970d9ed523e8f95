"""Read a course from CSV: one mark per row, in sailing order.

Columns (header names in any case): ``name``, ``lat``, ``lon`` (also ``latitude``,
``longitude``, ``lng``), optional ``type`` (``mark``, ``start``, ``finish``, ``gate``:
see :mod:`sailroute.course.formats.model`) and ``rounding`` (``port``/``starboard``).
The separator is ``,``, ``;`` or a tab (the first of them found in the header); ``#``
lines and blank lines are skipped.
"""

from __future__ import annotations

import math
from pathlib import Path

from sailroute.course.formats.model import (
    ImportedCourse,
    Waypoint,
    from_waypoints,
    parse_rounding,
    parse_type,
)
from sailroute.errors import InputError
from sailroute.textin import (
    csv_rows,
    looks_binary,
    looks_like_header,
    quote_header,
    text_lines,
)

__all__ = ["read_csv_course"]

ALIASES = {
    "name": ("name", "mark", "id"),
    "lat": ("lat", "latitude"),
    "lon": ("lon", "longitude", "lng", "long"),
    "type": ("type", "kind"),
    "rounding": ("rounding", "side"),
}
"""Column -> the header names it is read from (compared in lower case)."""


def _columns(header: list[str], src: Path) -> dict[str, int]:
    low = [h.strip().lower() for h in header]
    cols: dict[str, int] = {}
    for canon, names in ALIASES.items():
        hit = next((i for i, h in enumerate(low) if h in names), None)
        if hit is not None:
            cols[canon] = hit
    missing = [c for c in ("name", "lat", "lon") if c not in cols]
    if missing:
        raise InputError(
            f"{src}, line 1: missing column {', '.join(missing)}; expected a "
            f"header with name, lat, lon (optional type, rounding); got "
            f"{quote_header(header)}"
        )
    return cols


def _number(text: str, lo: float, hi: float, what: str, where: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise InputError(f"{where}: {what} {text!r}; expected decimal degrees") from None
    if not (math.isfinite(v) and lo <= v <= hi):
        raise InputError(f"{where}: {what} {text!r}; expected a number in [{lo:g}, {hi:g}]")
    return v


def read_csv_course(path: str | Path) -> ImportedCourse:
    """Read a course from a CSV file of marks in sailing order.

    Parameters
    ----------
    path : str or Path
        The CSV file.

    Returns
    -------
    ImportedCourse

    Raises
    ------
    InputError
        Unreadable or binary file, a missing column, a bad number, type or rounding
        (naming the line), or a course that cannot be assembled.
    """
    src = Path(path)
    try:
        text = src.read_text(encoding="utf-8-sig", errors="replace")
    except OSError as exc:
        raise InputError(
            f"{src}: cannot read the file ({exc.strerror}); expected a CSV file of marks"
        ) from None
    if looks_binary(text):
        raise InputError(f"{src}: a binary file; expected a CSV file of marks (name, lat, lon)")
    numbered = [
        (k + 1, ln)
        for k, ln in enumerate(text_lines(text))
        if ln.strip() and not ln.lstrip().startswith("#")
    ]
    if not numbered:
        raise InputError(f"{src}: no rows; expected a header (name, lat, lon) and one mark per row")
    head = numbered[0][1]
    delim = next((d for d in (",", ";", "\t") if d in head), ",")
    rows = csv_rows(numbered, delim, str(src))
    if not looks_like_header(rows[0]):
        raise InputError(
            f"{src}, line {numbered[0][0]}: the first line is not a header of "
            "column names; expected name, lat, lon (optional type, rounding)"
        )
    cols = _columns(rows[0], src)
    points: list[Waypoint] = []
    width = max(cols.values()) + 1
    for (lineno, _), row in zip(numbered[1:], rows[1:], strict=True):
        where = f"{src}, line {lineno}"
        if len(row) < width:
            raise InputError(
                f"{where}: {len(row)} fields; expected at least {width} (the columns of the header)"
            )
        name = row[cols["name"]].strip()
        if not name:
            raise InputError(f"{where}: empty name; expected the mark's name")
        lat = _number(row[cols["lat"]], -90.0, 90.0, "lat", where)
        lon = _number(row[cols["lon"]], -180.0, 360.0, "lon", where)
        type_text = row[cols["type"]] if "type" in cols else ""
        side_text = row[cols["rounding"]] if "rounding" in cols else ""
        kind = parse_type(type_text, where)
        rounding = parse_rounding(side_text, where)
        if rounding is not None and kind != "mark":
            raise InputError(
                f"{where}: rounding {rounding!r} on a point of type {kind}; "
                "expected a rounding on marks only (leave it empty)"
            )
        typed = bool(type_text.strip() or side_text.strip())
        points.append(Waypoint(name, lat, lon, kind, rounding, where, line=lineno, typed=typed))
    return from_waypoints(
        points, name=src.stem, src=str(src), how_to_type="a type or rounding column in a CSV"
    )
