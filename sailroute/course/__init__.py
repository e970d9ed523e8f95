"""Race courses: the course file (YAML), its model, templates and geometry.

``load_course(path)`` reads and validates a course file (``docs/course-format.md``);
``leg_endpoints(course, i, previous_end_xy)`` turns leg ``i`` into the routers'
``Start``/``Target``.
"""

from sailroute.course.geometry import leg_endpoints, start_of, target_of
from sailroute.course.load import build_boat, build_wind, load_course, validate_specs
from sailroute.course.model import Course, Gate, LegSpec, Line, Mark, ScenarioSpec

__all__ = [
    "Course",
    "Gate",
    "LegSpec",
    "Line",
    "Mark",
    "ScenarioSpec",
    "build_boat",
    "build_wind",
    "leg_endpoints",
    "load_course",
    "start_of",
    "target_of",
    "validate_specs",
]
