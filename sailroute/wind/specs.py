"""Wind and current specs: parsed once into frozen dataclasses, built into fields from them.

A course file's ``scenarios.<name>.wind`` (or an ensemble's ``members``) and
``scenarios.<name>.current`` are YAML mappings.  Each spec type has three things,
held together in one registry (:data:`WIND_KINDS`, :data:`CURRENT_KINDS`):

* its **dataclass** (:class:`UniformWindSpec`, :class:`WrfWindSpec`, ...): the checked
  values in SI units inside (m s⁻¹, degrees, seconds, epoch seconds, resolved
  :class:`~pathlib.Path`\\ s), and ``where``, the key path its messages start with;
* its **parser**: every check that needs no file content (required and unknown keys,
  types, ranges, units, paths resolved and "file not found"), each problem recorded
  by a :class:`~sailroute.checks.Checker` at its own key's line;
* its **builder**: reads the files and makes the field from the dataclass alone.

:func:`parse_wind_spec` / :func:`parse_current_spec` parse a mapping (raising every
problem at once); :func:`check_wind_spec` / :func:`check_current_spec` record the
problems in a course file's checker instead (the course loader parses every scenario
when it loads).  :func:`sailroute.wind.build.build_wind_field` builds a field from a
spec; :func:`sailroute.wind.build.wind_from_spec` does both.  Spec keys are documented
in ``docs/course-format.md`` and ``docs/design/wind.md``.

The types live in :mod:`sailroute.wind.spec_gridded` (``uniform``, ``wrf``, ``netcdf``,
``grib``), :mod:`sailroute.wind.spec_stations` (``stations``, ``blended``, ``measured``)
and :mod:`sailroute.wind.spec_current` (the currents), on the shared
:mod:`sailroute.wind.spec_base`; this module holds the registry and the entry points and
re-exports the dataclasses.  A new spec type goes in the module of its kind: its
dataclass, its parser and its builder, and one entry of the registry here that pairs
them (``WIND_TYPES`` follows from it).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from sailroute.checks import Checker, Problems
from sailroute.wind.spec_base import BuildContext, SpecKind
from sailroute.wind.spec_current import (
    DiamondCurrentSpec,
    NetcdfCurrentSpec,
    UniformCurrentSpec,
    _build_diamond_current,
    _build_netcdf_current,
    _build_uniform_current,
    _parse_diamond_current,
    _parse_netcdf_current,
    _parse_uniform_current,
)
from sailroute.wind.spec_gridded import (
    GribWindSpec,
    NetcdfWindSpec,
    UniformWindSpec,
    WrfWindSpec,
    _build_grib,
    _build_netcdf,
    _build_uniform,
    _build_wrf,
    _parse_grib,
    _parse_netcdf,
    _parse_uniform,
    _parse_wrf,
)
from sailroute.wind.spec_stations import (
    MEASURED_MARGIN_S,
    BlendedWindSpec,
    MeasuredWindSpec,
    StationReadSpec,
    StationsWindSpec,
    _build_blended,
    _build_measured,
    _build_stations,
    _parse_blended,
    _parse_measured,
    _parse_stations,
)

__all__ = [
    "CURRENT_KINDS",
    "CURRENT_TYPES",
    "MEASURED_MARGIN_S",
    "WIND_KINDS",
    "WIND_TYPES",
    "BlendedWindSpec",
    "BuildContext",
    "CurrentSpec",
    "DiamondCurrentSpec",
    "GribWindSpec",
    "MeasuredWindSpec",
    "NetcdfCurrentSpec",
    "NetcdfWindSpec",
    "SpecKind",
    "StationReadSpec",
    "StationsWindSpec",
    "UniformCurrentSpec",
    "UniformWindSpec",
    "WindSpec",
    "WrfWindSpec",
    "check_current_spec",
    "check_wind_spec",
    "parse_current_spec",
    "parse_wind_spec",
]


WindSpec = (
    UniformWindSpec
    | WrfWindSpec
    | NetcdfWindSpec
    | GribWindSpec
    | StationsWindSpec
    | BlendedWindSpec
    | MeasuredWindSpec
)
"""A parsed wind spec: one of the dataclasses of :data:`WIND_KINDS`."""


CurrentSpec = UniformCurrentSpec | DiamondCurrentSpec | NetcdfCurrentSpec
"""A parsed current spec: one of the dataclasses of :data:`CURRENT_KINDS`."""


WIND_KINDS: dict[str, SpecKind] = {
    k.spec.type: k  # type: ignore[attr-defined]
    for k in (
        SpecKind(UniformWindSpec, _parse_uniform, _build_uniform),
        SpecKind(WrfWindSpec, _parse_wrf, _build_wrf),
        SpecKind(NetcdfWindSpec, _parse_netcdf, _build_netcdf),
        SpecKind(GribWindSpec, _parse_grib, _build_grib),
        SpecKind(StationsWindSpec, _parse_stations, _build_stations),
        SpecKind(BlendedWindSpec, _parse_blended, _build_blended),
        SpecKind(MeasuredWindSpec, _parse_measured, _build_measured),
    )
}
"""Wind spec ``type`` -> its dataclass, parser and builder: the one registry of wind types."""


CURRENT_KINDS: dict[str, SpecKind] = {
    k.spec.type: k  # type: ignore[attr-defined]
    for k in (
        SpecKind(UniformCurrentSpec, _parse_uniform_current, _build_uniform_current),
        SpecKind(DiamondCurrentSpec, _parse_diamond_current, _build_diamond_current),
        SpecKind(NetcdfCurrentSpec, _parse_netcdf_current, _build_netcdf_current),
    )
}
"""Current spec ``type`` -> its dataclass, parser and builder."""


WIND_TYPES: tuple[str, ...] = tuple(WIND_KINDS)
"""Values of a wind spec's ``type``."""


CURRENT_TYPES: tuple[str, ...] = tuple(CURRENT_KINDS)
"""Values of a current spec's ``type``."""


def _check(
    kinds: Mapping[str, SpecKind], spec: Any, chk: Checker, base_dir: Path, what: str
) -> Any:
    """Parse ``spec`` (at ``chk.path``) with the parser of its ``type``; None after a problem."""
    if not chk.is_mapping(spec, what):
        return None
    n0 = len(chk.p)
    kind = chk.choice(spec, "type", list(kinds))
    if kind is None:
        return None
    out = kinds[kind].parse(spec, chk, Path(base_dir))
    return out if len(chk.p) == n0 else None


def check_wind_spec(spec: Any, chk: Checker, base_dir: Path) -> WindSpec | None:
    """Parse the wind spec at ``chk.path``, its problems recorded by ``chk``.

    Parameters
    ----------
    spec : mapping
        The wind spec as the YAML gives it.
    chk : Checker
        A checker of the spec's own key path (``scenarios.a.wind``); the course loader
        passes its own, so that the spec's problems are listed with the course's.
    base_dir : Path
        Folder that relative paths resolve against (the course file's).

    Returns
    -------
    WindSpec or None
        None when a problem was recorded.
    """
    return _check(WIND_KINDS, spec, chk, base_dir, "a wind spec mapping (type: ...)")


def check_current_spec(spec: Any, chk: Checker, base_dir: Path) -> CurrentSpec | None:
    """Parse the current spec at ``chk.path``, as :func:`check_wind_spec`."""
    return _check(
        CURRENT_KINDS,
        spec,
        chk,
        base_dir,
        "a current spec mapping, e.g. {type: uniform, speed_kn: 1.5, set_deg: 90}",
    )


def parse_wind_spec(
    spec: Any, *, base_dir: Path, where: str = "", lines: Mapping[str, int] | None = None
) -> WindSpec:
    """Parse a wind spec mapping into its dataclass, every problem raised at once.

    Parameters
    ----------
    spec : mapping
        E.g. ``{"type": "uniform", "tws_kn": 10, "twd_deg": 108}``; ``type`` is one of
        :data:`WIND_TYPES`.
    base_dir : Path
        Folder that relative ``path`` values resolve against.
    where : str
        Message prefix, e.g. ``"courses/x.yaml:12: scenarios.a.wind"``.
    lines : mapping of str to int, optional
        1-based line of each key path of the file ``where`` names: each problem is
        then reported at its own key's line.

    Returns
    -------
    WindSpec

    Raises
    ------
    InputError
        Unknown type, unknown/missing/invalid keys, files not found (all listed at once).

    Examples
    --------
    >>> from pathlib import Path
    >>> s = parse_wind_spec({"type": "uniform", "tws_kn": 10, "twd_deg": 108}, base_dir=Path())
    >>> round(s.tws_ms, 4), s.twd_deg
    (5.1444, 108.0)
    """
    probs = Problems.below(where, lines, what="wind spec")
    out = check_wind_spec(spec, Checker(probs, probs.root), base_dir)
    probs.raise_if_any()
    assert out is not None  # None only with a problem, raised just above
    return out


def parse_current_spec(
    spec: Any, *, base_dir: Path, where: str = "", lines: Mapping[str, int] | None = None
) -> CurrentSpec:
    """Parse a current spec mapping into its dataclass, as :func:`parse_wind_spec`.

    ``type`` is one of :data:`CURRENT_TYPES`; e.g. ``{type: uniform, speed_kn: 1.5,
    set_deg: 90}`` or ``{type: diamonds, high_water, table: [[hour, set_deg, rate_kn],
    ...]}`` (``docs/course-format.md``).
    """
    probs = Problems.below(where, lines, what="current spec")
    out = check_current_spec(spec, Checker(probs, probs.root), base_dir)
    probs.raise_if_any()
    assert out is not None  # None only with a problem, raised just above
    return out
