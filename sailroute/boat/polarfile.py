"""What the polar file formats share: units, cells and sanity checks.

The unit of a file's speeds comes from the options (``speed_unit``, ``wind_unit``), the
file itself (a label cell, a column suffix, a JSON key) or its name
(:func:`unit_from_name`); all that speak must agree, knots when none does.  Cells are read
as finite numbers naming file, line and cell (:func:`_number`); a table is refused when it
is absurd for a sailing boat (:func:`_check_table`).
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any, Final

import numpy as np
from numpy.typing import NDArray

from sailroute.boat.polar import (
    MAX_BOAT_SPEED_KN,
    MAX_BOAT_SPEED_MS,
    MAX_TWS_KN,
    MAX_TWS_MS,
    MIN_AXIS_STEP,
    axis_spacing_problem,
)
from sailroute.errors import InputError
from sailroute.textin import excerpt
from sailroute.units import KNOT, speed_factor

_UNIT_SUFFIX: Final = {
    "kn": "kn",
    "kt": "kn",
    "kts": "kn",
    "knots": "kn",
    "ms": "m/s",
    "mps": "m/s",
    "m/s": "m/s",
    "kmh": "km/h",
    "kph": "km/h",
    "km/h": "km/h",
    "mph": "mph",
}

_NAME_UNITS: Final = {
    "kn": "kn",
    "kt": "kn",
    "kts": "kn",
    "knot": "kn",
    "knots": "kn",
    "ms": "m/s",
    "mps": "m/s",
    "kmh": "km/h",
    "kph": "km/h",
    "mph": "mph",
}


def unit_from_name(path: str | Path) -> str | None:
    """Speed unit that a polar file's name states, or None.

    Only the last word of the stem counts (words split at ``.``, ``_``, ``-`` and
    spaces), and only unambiguous unit words: ``kn``, ``kt``, ``kts``, ``knot``,
    ``knots``, ``ms``, ``mps``, ``kmh``, ``kph``, ``mph``.

    Parameters
    ----------
    path : str or Path
        File name or path.

    Returns
    -------
    str or None
        ``"kn"``, ``"m/s"``, ``"km/h"`` or ``"mph"``; None when the name says nothing.

    Examples
    --------
    >>> unit_from_name("2502_m8_APW_HSB2_HSRW.kph.csv")
    'km/h'
    >>> unit_from_name("j24-polars-knots.csv")
    'kn'
    >>> unit_from_name("msd_polar.pol") is None
    True
    """
    words = [w for w in re.split(r"[._\s-]+", Path(str(path)).stem.lower()) if w]
    return _NAME_UNITS.get(words[-1]) if words else None


_HEADER_UNIT: Final = re.compile(
    r"(?:twa|tws)(?:\s*(?:\\+|/)\s*(?:twa|tws))?(?:[\s_]*[(\[]?\s*([a-z/]+)\s*[)\]]?)?"
)


def _header_unit(label: str) -> str | None:
    """Unit named in a wide table's label cell (``TWA\\TWS (km/h)``, ``twa/tws_ms``)."""
    m = _HEADER_UNIT.fullmatch(label.strip().lower())
    if m is None or m.group(1) is None:
        return None
    return _UNIT_SUFFIX.get(m.group(1))


def _agree(src: str, what: str, claims: list[tuple[str, str | None]], default: str = "kn") -> str:
    """The one unit that every claim names (``default`` if none does), else an error.

    ``claims`` are ``(who, unit)`` pairs, e.g. ``("speed_unit='kn'", "kn")`` or
    ``("the file name 'x.kph.csv'", "km/h")``; None units are skipped.
    """
    known: list[tuple[str, str, float]] = []
    for who, unit in claims:
        if unit is None:
            continue
        try:
            known.append((who, unit, speed_factor(unit)))
        except InputError as exc:
            raise InputError(f"{src}: {exc}") from None
    for who, unit, f in known[1:]:
        if f != known[0][2]:
            raise InputError(
                f"{src}: {known[0][0]} says the {what} unit is {known[0][1]!r} but {who} says "
                f"{unit!r}; make them agree (fix or drop the option, or rename the file)"
            )
    return known[0][1] if known else default


def _in_kn(value_ms: float, unit: str) -> str:
    """`` (12.3 kn)`` after a value given in ``unit``, unless that is knots already."""
    return "" if speed_factor(unit) == KNOT else f" ({value_ms / KNOT:.1f} kn)"


def _unit_hint(unit: str, option: str) -> str:
    """How to fix a value that is too large for the unit it was read in."""
    smaller = [u for u in ("kn", "mph", "km/h") if speed_factor(u) < speed_factor(unit)]
    if not smaller:
        return f"it is read in {unit} already; check the file's values"
    return (
        f"a unit mistake? It is read in {unit}; if the file is in {' or '.join(smaller)}, "
        f"say so with {option}: {smaller[-1]} in the course's boat: block (or end the file "
        "name with .kph, .kmh, .mph, ...)"
    )


def _check_table(
    src: str,
    twa: NDArray[np.float64],
    tws: NDArray[np.float64],
    tab: NDArray[np.float64],
    s_unit: str,
    w_unit: str,
    *,
    at_twa: Any,
    at_tws: Any,
    at_cell: Any,
) -> None:
    """Refuse absurd or degenerate tables, naming the cell (file units).

    Parameters
    ----------
    src : str
        File label.
    twa, tws, tab : ndarray
        TWA rows [°], TWS columns and boat speeds (NaN = empty cell) in the file's
        units ``w_unit`` and ``s_unit``.
    at_twa, at_tws, at_cell : callable
        ``at_twa(i)``, ``at_tws(j)``, ``at_cell(i, j)``: where that value is in the
        file, e.g. ``"x.pol:3: cell 2"``.

    Raises
    ------
    InputError
        TWS above :data:`MAX_TWS_KN`, boat speed above :data:`MAX_BOAT_SPEED_KN`,
        nodes closer than ``MIN_AXIS_STEP`` or no positive speed at all.
    """
    fs, fw = speed_factor(s_unit), speed_factor(w_unit)
    for j, w in enumerate(tws):
        if w * fw > MAX_TWS_MS:
            raise InputError(
                f"{at_tws(j)}: wind speed {w:g} {w_unit}{_in_kn(w * fw, w_unit)} is above "
                f"{MAX_TWS_KN:g} kn, stronger than any wind a polar is made for; "
                + _unit_hint(w_unit, "wind_unit")
            )
    for axis, values, factor, at in (("TWS", tws, fw, at_tws), ("TWA", twa, 1.0, at_twa)):
        v = np.asarray(values, dtype=float) * factor
        problem = axis_spacing_problem(v, axis)
        if problem:
            raise InputError(f"{at(_close_index(v, axis))}: {problem}")
    with np.errstate(invalid="ignore"):
        fast = np.argwhere(tab * fs > MAX_BOAT_SPEED_MS)
    if fast.size:
        i, j = (int(k) for k in fast[0])
        cell = float(tab[i, j])
        raise InputError(
            f"{at_cell(i, j)}: boat speed {cell:g} {s_unit}{_in_kn(cell * fs, s_unit)} at TWA "
            f"{twa[i]:g}, TWS {tws[j]:g} {w_unit} is above {MAX_BOAT_SPEED_KN:g} kn, faster "
            "than any sailing craft has gone (record 65.45 kn); " + _unit_hint(s_unit, "speed_unit")
        )
    if not np.nanmax(tab, initial=0.0) > 0:
        raise InputError(
            f"{src}: this polar has no speed: every boat speed in the table is 0, so the boat "
            f"cannot sail in any wind; fill in the boat speeds ({s_unit}) for each TWA row "
            "and TWS column, or pick the right file"
        )


def _well_formed(twa: NDArray, tws: NDArray, tab: NDArray) -> bool:
    """Axes 1-D, finite and increasing, table finite and of matching shape (else the
    :class:`Polar` constructor reports the problem)."""
    return bool(
        twa.ndim == 1
        and tws.ndim == 1
        and tab.shape == (twa.size, tws.size)
        and twa.size >= 2
        and tws.size >= 1
        and np.all(np.isfinite(twa))
        and np.all(np.isfinite(tws))
        and np.all(np.isfinite(tab))
        and np.all(np.diff(twa) > 0)
        and np.all(np.diff(tws) > 0)
    )


def _close_index(v: NDArray[np.float64], axis: str) -> int:
    """Index of the first node closer than ``MIN_AXIS_STEP`` to its neighbour or edge."""
    for k in range(v.size):
        prev = v[k - 1] if k else 0.0
        if (k or v[0] > 0) and v[k] - prev < MIN_AXIS_STEP:
            return k
    return v.size - 1  # only the TWA 180 edge is left


def _detect_sep(line: str) -> str | None:
    for sep in (";", "\t", ","):
        if sep in line:
            return sep
    return None


def _split(line: str, sep: str | None) -> list[str]:
    if sep is None:
        return line.split()
    return line.split(sep)


def _is_number(cell: str) -> bool:
    try:
        float(cell)
    except ValueError:
        return False
    return True


def _number(cell: str, src: str, lineno: int, col: int, what: str) -> float:
    text = cell.strip()
    try:
        v = float(text)
    except ValueError:
        raise InputError(
            f"{src}:{lineno}: cell {col} ({excerpt(text)!r}): expected a number ({what})"
        ) from None
    if not math.isfinite(v):
        raise InputError(f"{src}:{lineno}: cell {col} ({excerpt(text)!r}): {what} must be finite")
    return v


def _split_unit(name: str) -> tuple[str, str | None]:
    m = re.fullmatch(r"([a-z_]+?)(?:[_ (\[]+([a-z/]+)[)\]]?)?", name.strip())
    if m is None:
        return name, None
    base, unit = m.group(1), m.group(2)
    if unit is None:
        return base, None
    if unit == "deg":
        return base, "deg"
    if unit in _UNIT_SUFFIX:
        return base, _UNIT_SUFFIX[unit]
    return name, None


def _suffix(unit: str) -> str:
    """Column-name suffix of a unit (``kn``, ``ms``, ``kmh``, ``mph``)."""
    f = speed_factor(unit)
    return {
        speed_factor("kn"): "kn",
        1.0: "ms",
        speed_factor("km/h"): "kmh",
        speed_factor("mph"): "mph",
    }[f]


def _file_units(
    src: str, speed_unit: str | None, wind_unit: str | None, claims: list[tuple[str, str | None]]
) -> tuple[str, str]:
    """Speed and wind unit of a wide table: the options, what the file says, else knots.

    ``claims`` are the file's own statements (e.g. its label cell); the file name
    (:func:`unit_from_name`) is added.  A file-wide statement covers both the
    boat speeds and the TWS; any disagreement is an error.
    """
    named = unit_from_name(src)
    claims = [*claims, (f"the file name {Path(src).name!r}", named)]
    s_unit = _agree(src, "boat speed", [(f"speed_unit={speed_unit!r}", speed_unit), *claims])
    given_w = (
        (f"wind_unit={wind_unit!r}", wind_unit)
        if wind_unit
        else (f"speed_unit={speed_unit!r}", speed_unit)
    )
    w_unit = _agree(src, "wind speed", [given_w, *claims])
    return s_unit, w_unit


def _merge_unit(
    src: str,
    lineno: int | None,
    what: str,
    declared: str | None,
    given: str | None,
    default: str = "kn",
) -> str:
    where = f"{src}:{lineno}" if lineno else src
    try:
        if declared and given and speed_factor(declared) != speed_factor(given):
            raise InputError(
                f"{where}: the file declares {what} unit {declared!r} but {given!r} was passed; "
                "drop the option or fix the file"
            )
        unit = declared or given or default
        speed_factor(unit)
    except InputError as exc:
        if str(exc).startswith(where):
            raise
        raise InputError(f"{where}: {exc}") from None
    return unit
