"""Read a course file: the YAML document, the line of every key path, duplicate keys.

Reading is the first of the three steps of :func:`sailroute.course.load.load_course`
(read, :mod:`~sailroute.course.check`, :mod:`~sailroute.course.build`).  It fails
only on what stops the file from being parsed (missing, not UTF-8, YAML syntax);
keys written twice are returned as problems for the check step to report with the
others.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sailroute.yamlfile import read_yaml

__all__ = ["CourseText", "read_course_file"]


@dataclass(frozen=True, eq=False)
class CourseText:
    """A parsed course file.

    Attributes
    ----------
    data : Any
        The parsed YAML (None for an empty file).
    lines : dict of str to int
        1-based line of each key path (``"legs[2].to"``).
    duplicates : tuple of str
        One problem per key written twice in the same mapping, each naming its
        key path and both lines.
    """

    data: Any
    lines: dict[str, int]
    duplicates: tuple[str, ...]


def read_course_file(path: str | Path) -> CourseText:
    """Read a course file (YAML 1.2 scalars, see :mod:`sailroute.yamlfile`).

    Parameters
    ----------
    path : str or Path
        The course file.

    Returns
    -------
    CourseText

    Raises
    ------
    InputError
        File missing or unreadable, not UTF-8, or a YAML syntax error (with line and
        column).
    """
    doc = read_yaml(Path(path), what="course file")
    dup = tuple(
        f"{d.path}: the key {d.key!r} appears twice in the same mapping "
        f"(lines {d.first_line} and {d.line}); keep one"
        for d in doc.duplicates
    )
    return CourseText(doc.data, doc.lines, dup)
