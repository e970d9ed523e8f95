"""Exception hierarchy.

Every error a user can cause derives from :class:`SailrouteError` and carries a
message that says what failed, where (file, key path or line), what was expected
and how to fix it.  The CLI maps these to exit codes (see ``docs/usage.md``):

=====================  =========
exception              exit code
=====================  =========
InputError             2
WindDataError          2
OutOfCoverageError     2
RoutingError           3
=====================  =========
"""

from __future__ import annotations


class SailrouteError(Exception):
    """Base class of all errors raised deliberately by sailroute."""

    exit_code: int = 1


class InputError(SailrouteError, ValueError):
    """Bad user input: a file, key, column or value that cannot be used as given."""

    exit_code = 2


class WindDataError(InputError):
    """A wind source (WRF NetCDF, station CSV) is malformed or unusable."""


class OutOfCoverageError(InputError):
    """A wind field was sampled outside its time span or bounding box.

    The message names both the requested range and the covered range.  Sampling
    outside coverage is an error unless the field was built with ``clamp=True``.
    """


class RoutingError(SailrouteError):
    """A leg could not be routed (target unreachable, front died out, ...)."""

    exit_code = 3


def format_problems(title: str, problems: list[str]) -> str:
    """Join several problems into one message, one per line.

    Parameters
    ----------
    title : str
        First line, e.g. ``"courses/x.yaml: 3 problems"``.
    problems : list of str
        One entry per problem, each already naming its key path.

    Returns
    -------
    str
        The message.
    """
    return title + "\n" + "\n".join(f"  - {p}" for p in problems)
