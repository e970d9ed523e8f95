"""Boat factories: built-in polars, VPP polars and the course file's ``boat:`` block.

A course file's ``boat`` value takes one of three forms::

    boat: {builtin: ilca7}                       # shipped race polar (default boat)
    boat: {builtin: ilca7-steady}                # shipped steady VPP polar
    boat: {polar: polars/mine.pol, speed_unit: kn, wind_unit: kn}
    boat: {vpp: {class: ilca7, crew_mass_kg: 75}, kinetics: race}  # VPP at load time

The built-in ``ilca7``, ``ilca6`` and ``ilca4`` are race polars (the steady VPP
plus wave riding and pumping, :mod:`sailroute.boat.kinetics`); ``<class>-steady``
are the steady VPP alone.  ``kinetics`` (``race``, the default, ``steady``, or a
mapping of race-model parameters such as ``{sea_age_h: 6}``) picks the same for
the ``vpp`` form.  ``polar`` paths are relative to the course
file's folder.  Optional key in every form: ``interpolation`` (``pchip``, the
default, or ``linear``).  ``allow_extrapolation`` (default false) lets a course
route in wind above the polar's highest TWS column, with a warning instead of an
error (:mod:`sailroute.boat.sanity`).
"""

from __future__ import annotations

from collections.abc import Mapping
from functools import cache, lru_cache
from importlib import resources
from pathlib import Path
from typing import Any, Final

import numpy as np

from sailroute.boat.io import read_polar
from sailroute.boat.kinetics import RACE, STEADY, Kinetics, kinetics_from_spec, race_polar
from sailroute.boat.laser import CLASSES, LaserParams, params_from_mapping
from sailroute.boat.polar import INTERPOLATIONS, Polar
from sailroute.errors import InputError, format_problems
from sailroute.units import KNOT, SPEED_UNITS

BUILTIN_TWS_KN: Final = tuple(float(v) for v in range(1, 29))
"""TWS columns of the shipped polars [kn]: 1-28 kn (0.5-14.4 m s⁻¹), the wind
at the sail's centre-of-effort height (see ``docs/vpp.md``)."""
BUILTIN_TWA_DEG: Final = tuple(float(v) for v in np.arange(0.0, 180.0 + 1e-9, 2.5))
"""TWA rows of the shipped polars [°]: 0-180 in 2.5° steps."""
BUILTIN_DECIMALS: Final = 4
"""Decimals of the shipped ``.pol`` files (knots): 5e-5 kn resolution."""

_FORMS: Final = ("builtin", "polar", "vpp")
_COMMON: Final = ("interpolation", "efficiency", "allow_extrapolation")
_ALLOWED: Final = {
    "builtin": {"builtin", *_COMMON},
    "polar": {"polar", "speed_unit", "wind_unit", "format", *_COMMON},
    "vpp": {"vpp", "kinetics", *_COMMON},
}
STEADY_SUFFIX: Final = "-steady"
"""Suffix of the built-in names of the steady VPP polars (``ilca7-steady``)."""



def builtin_names() -> tuple[str, ...]:
    """Names of the shipped polars: ``ilca4``, ``ilca6``, ``ilca7`` (race) and the
    same with ``-steady`` (steady VPP)."""
    return tuple(sorted([*CLASSES, *(c + STEADY_SUFFIX for c in CLASSES)]))


def builtin_kind(name: str) -> tuple[str, Kinetics]:
    """Class and race model of a built-in name: ``"ilca7-steady"`` -> ``("ilca7", STEADY)``."""
    if name.endswith(STEADY_SUFFIX):
        return name[: -len(STEADY_SUFFIX)], STEADY
    return name, RACE


def builtin_polar(name: str = "ilca7", interpolation: str = "pchip") -> Polar:
    """Shipped polar of an ILCA class (cached).

    Parameters
    ----------
    name : str
        ``ilca7`` (standard rig, 80 kg sailor: the default boat), ``ilca6`` or
        ``ilca4``: race polars (steady VPP plus wave riding and pumping, see
        :mod:`sailroute.boat.kinetics`); ``ilca7-steady``, ``ilca6-steady``,
        ``ilca4-steady``: the steady VPP alone.
    interpolation : {"pchip", "linear"}
        Interpolation method.

    Returns
    -------
    Polar
        Read from ``sailroute/boat/data/<name>.pol`` (knots; written by
        ``data/make_builtin_polars.py`` from :func:`vpp_polar`).

    Raises
    ------
    InputError
        Unknown name.
    """
    key = name.lower() if isinstance(name, str) else name
    if key not in builtin_names():
        raise InputError(
            f"unknown built-in boat {name!r}; expected one of "
            + ", ".join(map(repr, builtin_names()))
        )
    return _builtin(key, interpolation)


@cache
def _builtin(key: str, interpolation: str) -> Polar:
    ref = resources.files("sailroute.boat").joinpath("data", f"{key}.pol")
    with resources.as_file(ref) as path:
        polar = read_polar(path, speed_unit="kn", wind_unit="kn", interpolation=interpolation)
    cls, kinetics = builtin_kind(key)
    return polar.with_name(CLASSES[cls].name + (" steady" if kinetics == STEADY else ""))


@lru_cache(maxsize=4)  # a run uses one or two boats; each polar holds ~3 MB once routed
def vpp_polar(
    params: LaserParams,
    tws_ms: tuple[float, ...] | None = None,
    twa_deg: tuple[float, ...] | None = None,
    interpolation: str = "pchip",
    kinetics: Kinetics = STEADY,
) -> Polar:
    """Run the VPP on a grid (default: the built-in grid) and return its polar (cached).

    Parameters
    ----------
    params : LaserParams
        Boat.
    tws_ms : tuple of float, optional
        TWS columns [m s⁻¹]; default :data:`BUILTIN_TWS_KN` in m s⁻¹.
    twa_deg : tuple of float, optional
        TWA rows [°]; default :data:`BUILTIN_TWA_DEG`.
    interpolation : {"pchip", "linear"}
        Interpolation method.
    kinetics : Kinetics
        :data:`~sailroute.boat.kinetics.STEADY` (default: the steady VPP) or a race
        model such as :data:`~sailroute.boat.kinetics.RACE`.
    """
    tws = np.asarray(tws_ms if tws_ms is not None else BUILTIN_TWS_KN, dtype=float)
    if tws_ms is None:
        tws = tws * KNOT
    twa = np.asarray(twa_deg if twa_deg is not None else BUILTIN_TWA_DEG, dtype=float)
    return race_polar(params, tws, twa, kinetics, interpolation=interpolation)


def boat_from_spec(
    spec: Mapping[str, Any], *, base_dir: Path, where: str, key: str = "boat",
    lines: Mapping[str, int] | None = None,
) -> Polar:
    """Build the boat's polar from a course file's ``boat`` mapping.

    Parameters
    ----------
    spec : mapping
        One of ``{builtin: NAME}``, ``{polar: PATH, speed_unit?, wind_unit?,
        format?}`` or ``{vpp: {class: ..., crew_mass_kg: ..., <parameter>: ...}}``,
        each with an optional ``interpolation`` and ``efficiency`` (speed factors by
        point of sail, :func:`sailroute.boat.efficiency.scale_polar`).
    base_dir : Path
        Folder that relative ``polar`` paths are resolved against (the course
        file's folder).
    where : str
        File label for messages, e.g. ``"courses/x.yaml"``.
    key : str
        Key path of ``spec`` in the file, prefixed to problems (``"boat"``).
    lines : mapping of str to int, optional
        1-based line of each key path of the file (the course's line map): the
        ``vpp`` parameters' problems are reported at their own lines.

    Returns
    -------
    Polar

    Raises
    ------
    InputError
        One error listing every problem with its key path, e.g.
        ``courses/x.yaml: boat.builtin: expected one of 'ilca4', 'ilca6',
        'ilca7'; got 'ilca8'``.
    """
    if not isinstance(spec, Mapping):
        raise InputError(
            f"{where}: {key}: expected a mapping such as {{builtin: ilca7}}, {{polar: FILE}} or "
            f"{{vpp: {{class: ilca7}}}}; got {type(spec).__name__} {spec!r}"
        )
    if "efficiency" in spec:
        from sailroute.boat.efficiency import efficiency_from_spec, scale_polar

        factors = efficiency_from_spec(spec["efficiency"], where=where, key=f"{key}.efficiency")
        rest = {k: v for k, v in spec.items() if k != "efficiency"}
        return scale_polar(boat_from_spec(rest, base_dir=base_dir, where=where, key=key,
                                          lines=lines), **factors)
    forms = [f for f in _FORMS if f in spec]
    if len(forms) != 1:
        found = f"got {', '.join(forms)}" if forms else f"got keys {sorted(map(str, spec))}"
        raise InputError(
            f"{where}: {key}: give exactly one of 'builtin', 'polar' or 'vpp'; {found}"
        )
    form = forms[0]
    problems: list[str] = []
    for k in spec:
        if k not in _ALLOWED[form]:
            problems.append(
                f"{key}.{k}: unknown key for a {form!r} boat; allowed: "
                + ", ".join(map(repr, sorted(_ALLOWED[form])))
            )
    interpolation = spec.get("interpolation", "pchip")
    if interpolation not in INTERPOLATIONS:
        problems.append(
            f"{key}.interpolation: expected one of {', '.join(map(repr, INTERPOLATIONS))}; "
            f"got {interpolation!r}"
        )
    allow = spec.get("allow_extrapolation", False)
    if not isinstance(allow, bool):
        problems.append(f"{key}.allow_extrapolation: expected true or false; got {allow!r}")
    if form == "builtin":
        name = spec["builtin"]
        if not isinstance(name, str) or name.lower() not in builtin_names():
            problems.append(
                f"{key}.builtin: expected one of {', '.join(map(repr, builtin_names()))}; "
                f"got {name!r}"
            )
        _raise(where, problems)
        return builtin_polar(name.lower(), interpolation)
    if form == "polar":
        path = spec["polar"]
        if not isinstance(path, str) or not path.strip():
            problems.append(f"{key}.polar: expected a file path; got {path!r}")
        for uk in ("speed_unit", "wind_unit"):
            u = spec.get(uk)
            if u is not None and (not isinstance(u, str) or u.strip().lower() not in SPEED_UNITS):
                problems.append(
                    f"{key}.{uk}: expected one of 'kn', 'm/s', 'km/h', 'mph'; got {u!r}"
                )
        fmt = spec.get("format")
        if fmt is not None and fmt not in ("pol", "csv", "json"):
            problems.append(f"{key}.format: expected one of 'pol', 'csv', 'json'; got {fmt!r}")
        _raise(where, problems)
        file = Path(path)
        if not file.is_absolute():
            file = Path(base_dir) / file
        if not file.is_file():
            raise InputError(
                f"{where}: {key}.polar: file {str(file)!r} not found (paths are relative to "
                "the course file's folder)"
            )
        return read_polar(
            file,
            speed_unit=spec.get("speed_unit"),
            wind_unit=spec.get("wind_unit"),
            format=fmt,
            interpolation=interpolation,
        )
    # vpp
    kinetics, kproblems = kinetics_from_spec(spec.get("kinetics", "race"), f"{key}.kinetics")
    problems.extend(kproblems)
    vspec = spec["vpp"]
    if vspec is None:
        vspec = {}
    try:
        vkey = f"{key}.vpp"
        vlines = {k.removeprefix(vkey + "."): n for k, n in (lines or {}).items()
                  if k.startswith(vkey + ".")}
        params = params_from_mapping(dict(vspec) if isinstance(vspec, Mapping) else vspec,
                                     where=where, key=vkey, lines=vlines)
    except InputError as exc:
        if not problems:
            raise
        text = str(exc).split("\n")
        extra = [ln.strip()[2:].removeprefix(f"{where}: ") for ln in text[1:]] if len(
            text) > 1 else [text[0].removeprefix(f"{where}: ")]
        problems.extend(extra)
    _raise(where, problems)
    return vpp_polar(params, interpolation=interpolation, kinetics=kinetics)


def _raise(where: str, problems: list[str]) -> None:
    if not problems:
        return
    if len(problems) == 1:
        raise InputError(f"{where}: {problems[0]}")
    raise InputError(format_problems(f"{where}: {len(problems)} problems", problems))
