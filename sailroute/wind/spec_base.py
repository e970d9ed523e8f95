"""What every wind and current spec shares: the build context, the registry entry, helpers.

:class:`BuildContext` (the course's frame, box and race window a field is built in),
:class:`SpecKind` (one spec type's dataclass, parser and builder: the entries of
:data:`sailroute.wind.specs.WIND_KINDS` and ``CURRENT_KINDS``) and the small parsing
helpers the spec modules share (:mod:`sailroute.wind.spec_gridded`,
:mod:`sailroute.wind.spec_stations`, :mod:`sailroute.wind.spec_current`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from sailroute.checks import Checker, show
from sailroute.errors import InputError
from sailroute.geo import LocalFrame
from sailroute.timeutil import parse_time, to_epoch
from sailroute.units import SPEED_UNITS

BBox = tuple[float, float, float, float]
"""Local-frame box ``(xmin, xmax, ymin, ymax)`` [m] (same order as :class:`Coverage`)."""


Pairs = tuple[tuple[str, Any], ...]
"""A small mapping kept as ``((key, value), ...)`` in file order (hashable, picklable)."""


@dataclass(frozen=True)
class BuildContext:
    """Where a field is built: the course's frame, box and race time.

    Attributes
    ----------
    frame : LocalFrame
        The course's local frame; gridded and station data are mapped into it.
    crop_bbox : tuple of float or None
        Course box ``(xmin, xmax, ymin, ymax)`` [m]; gridded data are cropped to it.
    time_window : tuple of float or None
        Race window ``(t0, t1)`` [epoch s]; slices and records outside it are not read.
    """

    frame: LocalFrame
    crop_bbox: BBox | None = None
    time_window: tuple[float, float] | None = None


def _pairs(d: Mapping[Any, Any] | None) -> Pairs | None:
    return None if d is None else tuple((str(k), v) for k, v in d.items())


def _dict(p: Pairs | None) -> dict[str, Any] | None:
    return None if p is None else dict(p)


def _speed_unit(chk: Checker, spec: Mapping[str, Any]) -> str | None:
    """``speed_unit`` (as written) if it is a known unit; a problem and None if not."""
    unit = chk.string(spec, "speed_unit", None)
    if unit is not None and unit.strip().lower() not in SPEED_UNITS:
        chk.add("speed_unit", f"expected one of 'm/s', 'kn', 'km/h', 'mph'; got {show(unit)}")
        return None
    return unit


def _epoch(chk: Checker, spec: Mapping[str, Any], key: str) -> float | None:
    """``spec[key]`` as an ISO 8601 time [epoch s]; the parser's message recorded if not."""
    try:
        return to_epoch(parse_time(spec[key], where=chk.where(key)))
    except InputError as exc:
        chk.p.extend([str(exc)])
        return None


def _wrapped(where: str, build: Callable[[], Any]) -> Any:
    """``build()``, its :class:`InputError` prefixed with ``where`` (the spec's key path)."""
    try:
        return build()
    except InputError as exc:
        raise type(exc)(f"{where}: {exc}") from None


@dataclass(frozen=True)
class SpecKind:
    """One spec type: its dataclass, its parser and its builder.

    Attributes
    ----------
    spec : type
        The dataclass (its ``type`` class attribute is the YAML ``type``).
    parse : callable
        ``parse(mapping, checker, base_dir) -> spec or None``: every check that needs no
        file content, problems recorded by the checker (None: a required value is
        missing or invalid).
    build : callable
        ``build(spec, BuildContext) -> field``: reads the files, makes the field.
    """

    spec: type
    parse: Callable[[Mapping[str, Any], Checker, Path], Any]
    build: Callable[[Any, BuildContext], Any]
