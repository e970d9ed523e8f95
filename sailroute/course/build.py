"""Build the course model (:class:`~sailroute.course.model.Course`) from checked values.

The last of the three steps of :func:`sailroute.course.load.load_course` (read,
check, build): every value here has been validated by :mod:`sailroute.course.check`,
so building cannot fail.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from types import MappingProxyType
from typing import Any

from sailroute.course.check import CheckedCourse
from sailroute.course.model import Course, Gate, LegSpec, Line, Mark, ScenarioSpec, frozen_mapping

__all__ = ["build_course"]


def build_course(
    checked: CheckedCourse,
    *,
    source: Path | None = None,
    key_lines: Mapping[str, int] | None = None,
) -> Course:
    """The :class:`Course` of a checked course file.

    Parameters
    ----------
    checked : CheckedCourse
        What :func:`~sailroute.course.check.check_course` returned.
    source : Path, optional
        The course file (relative spec paths resolve against its folder).
    key_lines : mapping of str to int, optional
        1-based line of each key path of the file, kept on the course so that the
        wind, current and boat factories report their problems at their own lines.

    Returns
    -------
    Course
    """
    marks = {k: Mark(k, x, y, lat, lon) for k, (x, y, lat, lon) in checked.marks.items()}
    return Course(
        name=checked.name,
        start_time=checked.start_time,
        frame=checked.frame,
        marks=frozen_mapping(marks),
        lines=frozen_mapping(
            {k: Line(k, marks[a], marks[b]) for k, (a, b) in checked.lines.items()}
        ),
        gates=frozen_mapping(
            {k: Gate(k, marks[a], marks[b]) for k, (a, b) in checked.gates.items()}
        ),
        legs=tuple(LegSpec(*leg) for leg in checked.legs),
        boat_spec=frozen_mapping(checked.boat),
        routing=checked.routing,
        scenarios=frozen_mapping({k: _scenario(kw) for k, kw in checked.scenarios.items()}),
        references=frozen_mapping(checked.references),
        source=source,
        description=checked.description,
        template=checked.template,
        uncertainty=checked.uncertainty,
        time_limit_s=checked.time_limit_min * 60.0,
        boat_where=checked.boat_where,
        utc_offset_s=checked.utc_offset_s,
        key_lines=MappingProxyType(dict(key_lines or {})),
        area=checked.area,
        restart_time=checked.restart_time,
        chart=checked.chart,
    )


def _scenario(kw: Mapping[str, Any]) -> ScenarioSpec:
    """The :class:`ScenarioSpec` of one checked scenario, its mappings made read-only
    (its wind and current specs are frozen dataclasses already)."""
    given = kw.get("current_given")
    return ScenarioSpec(
        **{
            **kw,
            "references": frozen_mapping(kw.get("references")),
            "current_given": None if given is None else frozen_mapping(given),
        }
    )
