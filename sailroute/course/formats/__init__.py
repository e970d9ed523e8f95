"""Course files of other programs: GPX, CSV, KML and SailGP / America's Cup race XML.

:func:`read_course_source` reads any of them into an
:class:`~sailroute.course.formats.model.ImportedCourse`;
:func:`~sailroute.course.formats.write.course_yaml` writes it as a course file
(``sailroute course import``, ``docs/course-format.md``).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path
from typing import Literal

from sailroute.course.formats.csvfile import read_csv_course
from sailroute.course.formats.gpx import read_gpx_course
from sailroute.course.formats.kml import read_kml_course
from sailroute.course.formats.model import ImportedCourse
from sailroute.course.formats.racexml import read_race_xml
from sailroute.course.formats.write import course_yaml
from sailroute.errors import InputError

__all__ = ["FORMATS", "ImportedCourse", "course_yaml", "detect_format", "read_course_source"]

Format = Literal["gpx", "csv", "kml", "racexml"]
FORMATS: tuple[Format, ...] = ("gpx", "csv", "kml", "racexml")
"""The formats read (``--format``)."""

READERS: dict[str, Callable[[Path], ImportedCourse]] = {
    "gpx": read_gpx_course,
    "csv": read_csv_course,
    "kml": read_kml_course,
    "racexml": read_race_xml,
}
SUFFIXES = {".gpx": "gpx", ".csv": "csv", ".txt": "csv", ".tsv": "csv", ".kml": "kml"}
ROOTS = {"gpx": "gpx", "kml": "kml", "race": "racexml"}


def detect_format(path: Path) -> Format:
    """The format of a course file from its suffix, or for ``.xml`` its root element.

    Raises
    ------
    InputError
        A suffix or root element that is none of the formats.
    """
    fmt = SUFFIXES.get(path.suffix.lower())
    if fmt is not None:
        return fmt  # type: ignore[return-value]
    if path.suffix.lower() == ".xml":
        try:
            head = path.read_bytes()[:4096].decode("utf-8", errors="replace")
        except OSError as exc:
            raise InputError(f"{path}: cannot read the file ({exc.strerror})") from None

        m = re.search(
            r"<([A-Za-z_][\w.-]*:)?([A-Za-z_][\w.-]*)[\s>/]", re.sub(r"<[?!][^>]*>", "", head)
        )
        root = m.group(2).lower() if m else ""
        if root in ROOTS:
            return ROOTS[root]  # type: ignore[return-value]
        raise InputError(
            f"{path}: root element <{root or '?'}>; expected <Race> (race XML), "
            "<gpx> or <kml>, or give --format"
        )
    raise InputError(
        f"{path}: cannot tell the format from the suffix {path.suffix!r}; "
        "expected .gpx, .csv, .kml or .xml, or give --format gpx|csv|kml|racexml"
    )


def read_course_source(path: str | Path, fmt: str = "auto") -> tuple[ImportedCourse, Format]:
    """Read a course from a GPX, CSV, KML or race XML file.

    Parameters
    ----------
    path : str or Path
        The file.
    fmt : {"auto", "gpx", "csv", "kml", "racexml"}
        Its format (``auto``: :func:`detect_format`).

    Returns
    -------
    (ImportedCourse, str)
        The course and the format read.

    Raises
    ------
    InputError
        Missing file, unknown format, or whatever the reader refuses.
    """
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such file; expected a GPX, CSV, KML or race XML course file")
    if fmt != "auto" and fmt not in READERS:
        raise InputError(f"--format {fmt!r}: expected auto, {', '.join(FORMATS)}")
    chosen: Format = detect_format(p) if fmt == "auto" else fmt  # type: ignore[assignment]
    return READERS[chosen](p), chosen
