"""Load a course file (YAML) into a :class:`~sailroute.course.model.Course`: read, check, build.

Three steps, one module each:

1. :mod:`sailroute.course.read`: the YAML, the line of every key path, keys given twice;
2. :mod:`sailroute.course.check`: the schema walk (``docs/course-format.md``), every
   problem collected by :mod:`sailroute.checks` and raised once, each as
   ``file:line: key.path: expected ...; got ...``; validated plain values out;
3. :mod:`sailroute.course.build`: the model objects (marks, lines, gates, legs,
   scenarios, the course).

The wind and current specs are parsed in step 2 (:mod:`sailroute.wind.specs`), so their
problems are reported with the course's; the boat spec stays raw.  The fields and the boat
are built on demand by :mod:`sailroute.course.specs` (re-exported here: :func:`build_boat`,
:func:`build_wind`, :func:`build_current`, :func:`build_specs`, :func:`validate_specs`).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from sailroute.checks import Problems
from sailroute.course.build import build_course
from sailroute.course.check import TOP_KEYS, check_course
from sailroute.course.model import Course
from sailroute.course.read import read_course_file
from sailroute.course.specs import (
    build_boat,
    build_current,
    build_specs,
    build_wind,
    validate_specs,
)

__all__ = [
    "TOP_KEYS",
    "build_boat",
    "build_current",
    "build_specs",
    "build_wind",
    "course_from_mapping",
    "load_course",
    "validate_specs",
]


def course_from_mapping(
    data: Any,
    *,
    source: Path | str | None = None,
    key_lines: Mapping[str, int] | None = None,
    extra_problems: Iterable[str] = (),
) -> Course:
    """Validate a parsed course mapping and build the :class:`Course`.

    Parameters
    ----------
    data : mapping
        The parsed YAML (what ``yaml.safe_load`` returns).
    source : Path or str, optional
        The file it came from; names the file in messages and is the folder that
        relative paths resolve against.
    key_lines : mapping of str to int, optional
        1-based YAML line of each key path, for messages.
    extra_problems : iterable of str
        Problems found before (e.g. duplicate keys), reported together.

    Returns
    -------
    Course

    Raises
    ------
    InputError
        Listing every problem found, one per line, with its key path.
    """
    src = Path(source) if source is not None else None
    problems = Problems(str(src) if src is not None else "<course>", key_lines)
    for message in extra_problems:
        problems.add("", message)
    checked = check_course(data, problems)
    return build_course(checked, source=src, key_lines=key_lines)


def load_course(path: str | Path) -> Course:
    """Read, validate and build a course from a YAML file.

    Parameters
    ----------
    path : str or Path
        The course file (see ``docs/course-format.md``).

    Returns
    -------
    Course

    Raises
    ------
    InputError
        File missing or unreadable, YAML syntax error (with line and column), or
        invalid content (every problem listed, each with its line and key path).
    """
    p = Path(path)
    text = read_course_file(p)
    return course_from_mapping(
        text.data, source=p, key_lines=text.lines, extra_problems=text.duplicates
    )
