"""Boat factories: built-in polars, VPP polars and the course file's ``boat:`` block.

A course file's ``boat`` value takes one of three forms::

    boat: {builtin: ilca7}                       # shipped race polar (default boat)
    boat: {builtin: ilca7-steady}                # shipped steady VPP polar
    boat: {polar: polars/mine.pol, speed_unit: kn, wind_unit: kn}
    boat: {polar: fleet.json, level: top, pace: race}  # a polar learned by `polar fit`
    boat: {vpp: {class: ilca7, crew_mass_kg: 75}, kinetics: race}  # VPP at load time

The built-in ``ilca7``, ``ilca6`` and ``ilca4`` are race polars (the steady VPP
plus wave riding and pumping, :mod:`sailroute.boat.kinetics`); ``<class>-steady``
are the steady VPP alone.  ``kinetics`` (``race``, the default, ``steady``, or a
mapping of race-model parameters such as ``{sea_age_h: 6}``) picks the same for
the ``vpp`` form.  ``polar`` paths are relative to the course
file's folder.  A polar learned from a fleet (``sailroute polar fit``,
:mod:`sailroute.boat.learnfile`) takes ``level`` (``median``, ``top``, ... as the file
holds; default its first) and ``pace`` (``steady``, the default: the table as learned
from steady sailing; ``race``: scaled by the fleet's race pace per point of sail).
Optional key in every form: ``interpolation`` (``pchip``, the default, or ``linear``).
``allow_extrapolation`` (default false) lets a course route in wind above the polar's
highest TWS column, with a warning instead of an error (:mod:`sailroute.boat.sanity`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from functools import cache, lru_cache
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any, Final

import numpy as np

from sailroute.boat.io import read_polar
from sailroute.boat.kinetics import RACE, STEADY, Kinetics, check_kinetics, race_polar
from sailroute.boat.laser import CLASSES, LaserParams, check_params
from sailroute.boat.polar import INTERPOLATIONS, Polar
from sailroute.checks import Checker, Problems, join_path, quoted, show, split_where, suggest
from sailroute.errors import InputError
from sailroute.units import KNOT, SPEED_UNITS

if TYPE_CHECKING:
    from sailroute.boat.learn import PolarDraw

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
    "polar": {"polar", "speed_unit", "wind_unit", "format", "level", "pace", *_COMMON},
    "vpp": {"vpp", "kinetics", *_COMMON},
}
PACES: Final = ("steady", "race")
"""Values of a learned polar's ``pace`` (:meth:`sailroute.boat.learn.LearnedPolar.polar`)."""
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
    spec: Mapping[str, Any],
    *,
    base_dir: Path,
    where: str,
    key: str = "boat",
    lines: Mapping[str, int] | None = None,
    draw: PolarDraw | None = None,
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
        File label for messages, e.g. ``"courses/x.yaml"``, or ``"file:LINE"`` of
        the ``boat`` key (the line of problems whose own line is not in ``lines``).
    key : str
        Key path of ``spec`` in the file, prefixed to problems (``"boat"``).
    lines : mapping of str to int, optional
        1-based line of each key path of the file (the course's line map): every
        problem (form keys, ``efficiency``, ``kinetics``, ``vpp`` parameters) is
        reported at its own key's line.
    draw : PolarDraw, optional
        A learned polar's level table is this draw of it (before its pace and the
        ``efficiency``; a band's member, :mod:`sailroute.bands.members`); ignored for
        other boats.

    Returns
    -------
    Polar

    Raises
    ------
    InputError
        One error listing every problem of the block at once, each with its key
        path and line, in the wording of :mod:`sailroute.checks` (unknown keys with
        a did-you-mean), e.g. ``courses/x.yaml:14: boat.builtin: expected one of
        'ilca4', ..., 'ilca7-steady'; got 'ilca8' (did you mean 'ilca7'?)``.
    """
    file, line, root = split_where(where)
    path = join_path(root, key) if root else key
    known = dict(lines or {})
    if line is not None:  # ``where`` is "file:LINE" of the block: its line if the map lacks it
        known.setdefault(path, line)
    probs = Problems(file, known, root=path, what="boat spec")
    c = Checker(probs, path)
    if not c.is_mapping(
        spec, "a mapping such as {builtin: ilca7}, {polar: FILE} or {vpp: {class: ilca7}}"
    ):
        probs.raise_if_any()
    form = _form(c, spec)
    if form is not None:
        c.keys(spec, sorted(_ALLOWED[form]), of=f"a {form!r} boat")
    interpolation = c.choice(spec, "interpolation", INTERPOLATIONS, "pchip")
    c.boolean(spec, "allow_extrapolation", False)
    factors = None
    if "efficiency" in spec:
        from sailroute.boat.efficiency import check_efficiency

        factors = check_efficiency(c.child("efficiency"), spec["efficiency"])
    build = {"builtin": _check_builtin, "polar": _check_polar, "vpp": _check_vpp}
    make = build[form](c, spec, Path(base_dir)) if form is not None else None
    if form == "polar" and draw is not None and make is not None:
        make = _learned_draw(c, spec, Path(base_dir), draw) or make
    probs.raise_if_any()
    assert make is not None
    polar = make(interpolation)
    if factors:
        from sailroute.boat.efficiency import scale_polar

        polar = scale_polar(
            polar,
            factors.get("upwind", 1.0),
            factors.get("reach", 1.0),
            factors.get("downwind", 1.0),
        )
    return polar


def _form(c: Checker, spec: Mapping[str, Any]) -> str | None:
    """The one form key of a ``boat`` mapping, or None and a problem."""
    forms = [f for f in _FORMS if f in spec]
    if len(forms) == 1:
        return forms[0]
    if forms:
        c.add(None, f"give exactly one of 'builtin', 'polar' or 'vpp'; got {', '.join(forms)}")
        return None
    known = set().union(*_ALLOWED.values())
    hints = [suggest(str(k), _FORMS).strip() for k in spec if str(k) not in known]
    hint = next((h for h in hints if h), "")
    c.add(
        None,
        f"give exactly one of 'builtin', 'polar' or 'vpp'; got keys "
        f"{sorted(map(str, spec))}" + (f" ({hint})" if hint else ""),
    )
    return None


_Make = Callable[[str], Polar]
"""Builds the checked boat's polar for an interpolation (called once all checks pass)."""


def _check_builtin(c: Checker, spec: Mapping[str, Any], base_dir: Path) -> _Make | None:
    name = spec["builtin"]
    if not isinstance(name, str) or name.lower() not in builtin_names():
        hint = suggest(name.lower(), builtin_names()).strip() if isinstance(name, str) else ""
        c.add(
            "builtin",
            f"expected one of {quoted(builtin_names())}; got {show(name)}"
            + (f" ({hint})" if hint else ""),
        )
        return None
    return lambda interpolation: builtin_polar(name.lower(), interpolation)


def _check_polar(c: Checker, spec: Mapping[str, Any], base_dir: Path) -> _Make | None:
    before = len(c.p)
    path = spec["polar"]
    if not isinstance(path, str) or not path.strip():
        c.add("polar", f"expected a file path; got {show(path)}")
    units = ("kn", "m/s", "km/h", "mph")
    for uk in ("speed_unit", "wind_unit"):
        u = spec.get(uk)
        if u is not None and (not isinstance(u, str) or u.strip().lower() not in SPEED_UNITS):
            hint = suggest(u.strip().lower(), SPEED_UNITS).strip() if isinstance(u, str) else ""
            c.add(
                uk,
                f"expected one of {quoted(units)}; got {show(u)}" + (f" ({hint})" if hint else ""),
            )
    fmt = spec.get("format")
    if fmt is not None:
        fmt = c.choice(spec, "format", ("pol", "csv", "json"))
    if len(c.p) > before:
        return None
    file = c.file(spec, "polar", base_dir, value=path)
    if file is None:
        return None
    if "level" in spec or "pace" in spec:
        return _check_learned(c, spec, file)
    return lambda interpolation: read_polar(
        file,
        speed_unit=spec.get("speed_unit"),
        wind_unit=spec.get("wind_unit"),
        format=fmt,
        interpolation=interpolation,
    )


def _check_learned(c: Checker, spec: Mapping[str, Any], file: Path) -> _Make | None:
    """A learned polar's ``level`` and ``pace`` (the file is read here, once)."""
    from sailroute.boat.learnfile import is_learned, read_learned

    pace = c.choice(spec, "pace", PACES, "steady")
    for uk in ("speed_unit", "wind_unit", "format"):
        if uk in spec:
            c.add(uk, "a learned polar states its units and format: leave this key out")
    key = "level" if "level" in spec else "pace"
    if not is_learned(file):
        c.add(
            key,
            f"{file.name} is not a learned polar (no 'learned' block): level and pace are "
            "keys of the JSON files of `sailroute polar fit`",
        )
        return None
    try:
        learned = read_learned(file)
    except InputError as exc:
        c.add("polar", str(exc))
        return None
    level = spec.get("level")
    if level is not None and (not isinstance(level, str) or level not in learned.levels):
        hint = suggest(level, list(learned.levels)).strip() if isinstance(level, str) else ""
        c.add(
            "level",
            f"expected one of {quoted(list(learned.levels))} (the levels of {file.name}); got "
            f"{show(level)}" + (f" ({hint})" if hint else ""),
        )
        return None
    if pace == "race" and learned.level(level).race_pace is None:
        c.add(
            "pace",
            f"{file.name} has no race pace (it was learned without the races' courses); "
            "use pace: steady or learn it again with --course",
        )
        return None
    if pace not in PACES:
        return None
    return lambda interpolation: learned.polar(level, interpolation, pace)


def learned_boat(spec: Mapping[str, Any], base_dir: Path) -> tuple[Path, str] | None:
    """The learned polar file and level of a course's ``boat`` (a checked spec), or None
    when the boat is not a polar learned by ``sailroute polar fit``."""
    path = spec.get("polar") if isinstance(spec, Mapping) else None
    if not isinstance(path, str):
        return None
    file = Path(path) if Path(path).is_absolute() else Path(base_dir) / path
    from sailroute.boat.learnfile import is_learned, read_learned

    if not is_learned(file):
        return None
    level = spec.get("level")
    return file, read_learned(file).level(level if isinstance(level, str) else None).name


def _learned_draw(
    c: Checker, spec: Mapping[str, Any], base_dir: Path, draw: PolarDraw
) -> _Make | None:
    """A learned polar's level table drawn (``draw``), then at its pace; None: not learned."""
    found = learned_boat(spec, base_dir)
    if found is None:
        return None
    from sailroute.boat.learnfile import read_learned

    learned = read_learned(found[0]).drawn(found[1], draw)
    pace = spec.get("pace", "steady")
    return lambda interpolation: learned.polar(found[1], interpolation, pace)


def boat_label(spec: Mapping[str, Any]) -> str:
    """The boat of a course's ``boat`` block in a few words, for reports and ``plan.json``:
    ``builtin ilca7``, ``polar f50.csv``, ``polar fleet.json, level top, race pace``,
    ``vpp ilca7``; ``efficiency`` is added when given."""
    if "builtin" in spec:
        text = f"builtin {spec['builtin']}"
    elif "polar" in spec:
        text = f"polar {Path(str(spec['polar'])).name}"
        if "level" in spec or "pace" in spec:
            text += f", level {spec.get('level', 'default')}, {spec.get('pace', 'steady')} pace"
    elif "vpp" in spec:
        vpp = spec["vpp"]
        text = f"vpp {vpp.get('class', 'ilca7') if isinstance(vpp, Mapping) else 'ilca7'}"
    else:
        text = "builtin ilca7"
    if "efficiency" in spec:
        text += ", efficiency " + ", ".join(f"{k} {v}" for k, v in dict(spec["efficiency"]).items())
    return text


def _check_vpp(c: Checker, spec: Mapping[str, Any], base_dir: Path) -> _Make | None:
    kinetics = check_kinetics(c.child("kinetics"), spec.get("kinetics", "race"))
    vspec = spec["vpp"]
    params = check_params(c.child("vpp"), {} if vspec is None else vspec)
    if kinetics is None or params is None:
        return None
    return lambda interpolation: vpp_polar(params, interpolation=interpolation, kinetics=kinetics)
