"""Long ("tidy") polar CSV: one row per (TWS, TWA) pair, the columns named with optional
unit suffixes (:mod:`sailroute.boat.io` describes the format)."""

from __future__ import annotations

from pathlib import Path
from typing import Final

import numpy as np

from sailroute.boat.polar import Polar
from sailroute.boat.polarfile import (
    _agree,
    _check_table,
    _merge_unit,
    _number,
    _split_unit,
    unit_from_name,
)
from sailroute.boat.poltable import fill_empty_cells
from sailroute.errors import InputError
from sailroute.textin import clean_text, csv_rows, quote_header
from sailroute.units import speed_factor

_SPEED_NAMES: Final = ("speed", "bsp", "boat_speed", "boatspeed", "stw", "v", "vb", "btv")
"""Boat-speed column names of a long polar CSV (``btv``: the target boat speed of an ORC
speed guide, read as published)."""


def parse_long_csv(
    text: str,
    source: str | Path = "<polar>",
    *,
    speed_unit: str | None = None,
    wind_unit: str | None = None,
    interpolation: str = "pchip",
) -> Polar:
    """Parse a long ("tidy") polar CSV (see :mod:`sailroute.boat.io`)."""
    src = str(source)
    rows = csv_rows(list(enumerate(text.splitlines(), 1)), ",", src)
    start = next(
        (
            k
            for k, r in enumerate(rows)
            if r and any(c.strip() for c in r) and not r[0].lstrip().startswith("#")
        ),
        None,
    )
    if start is None:
        raise InputError(f"{src}: the polar file is empty")
    header = [c.strip().lower() for c in rows[start]]
    cols = _long_columns(header, rows[start], src, start + 1)
    s_unit, w_unit = _long_units(header, cols, speed_unit, wind_unit, src, start + 1)
    values = _long_values(rows, start, cols, src)
    tws_ax = np.array(sorted({k[0] for k in values}))
    twa_ax = np.array(sorted({k[1] for k in values}))
    if twa_ax.size < 2:
        raise InputError(f"{src}: need at least 2 distinct TWA values; found {twa_ax.size}")
    tab = np.full((twa_ax.size, tws_ax.size), np.nan)
    line_of = np.zeros(tab.shape, dtype=int)
    for (w, a), (v, ln) in values.items():
        ij = np.searchsorted(twa_ax, a), np.searchsorted(tws_ax, w)
        tab[ij], line_of[ij] = v, ln

    def first_line(axis: int, value: float) -> int:  # (only on error)
        return min(ln for key, (_, ln) in values.items() if key[axis] == value)

    _check_table(
        src,
        twa_ax,
        tws_ax,
        tab,
        s_unit,
        w_unit,
        at_twa=lambda i: f"{src}:{first_line(1, float(twa_ax[i]))}: cell {cols['twa'][0] + 1}",
        at_tws=lambda j: f"{src}:{first_line(0, float(tws_ax[j]))}: cell {cols['tws'][0] + 1}",
        at_cell=lambda i, j: f"{src}:{line_of[i, j]}: cell {cols['speed'][0] + 1}",
    )
    tab = fill_empty_cells(twa_ax, tws_ax, tab)
    return Polar.from_arrays(
        twa_ax,
        tws_ax * speed_factor(w_unit),
        tab * speed_factor(s_unit),
        name=clean_text(Path(src).stem),
        interpolation=interpolation,
    )


def _long_columns(
    header: list[str], raw: list[str], src: str, lineno: int
) -> dict[str, tuple[int, str | None]]:
    """``role -> (index, unit suffix)`` of the ``tws``, ``twa`` and ``speed`` columns of the
    lower-case ``header`` (the file's cells ``raw``, on line ``lineno``)."""
    cols: dict[str, tuple[int, str | None]] = {}
    for k, name in enumerate(header):
        base, unit = _split_unit(name)
        role = (
            "tws"
            if base == "tws"
            else "twa"
            if base == "twa"
            else "speed"
            if base in _SPEED_NAMES
            else None
        )
        if role is None:
            continue
        if role in cols:
            first = header[cols[role][0]]
            raise InputError(f"{src}:{lineno}: two {role.upper()} columns ({first!r} and {name!r})")
        cols[role] = (k, unit)
    missing = [r for r in ("tws", "twa", "speed") if r not in cols]
    if missing:
        raise InputError(
            f"{src}:{lineno}: long polar CSV needs columns tws, twa and speed (or bsp, "
            f"boat_speed, stw, btv), optionally with a unit suffix like tws_kn; missing "
            f"{', '.join(missing)} in the header ({quote_header(raw)})"
        )
    if cols["twa"][1] not in (None, "deg"):
        raise InputError(
            f"{src}:{lineno}: TWA must be in degrees; got column {header[cols['twa'][0]]!r}"
        )
    return cols


def _long_units(
    header: list[str],
    cols: dict[str, tuple[int, str | None]],
    speed_unit: str | None,
    wind_unit: str | None,
    src: str,
    lineno: int,
) -> tuple[str, str]:
    """Boat-speed and wind-speed units: the column suffixes, the options and the file name
    must agree; knots when none says."""
    named = unit_from_name(src)
    given_w = wind_unit or (
        speed_unit if cols["tws"][1] is None and cols["speed"][1] is None else None
    )
    if named is not None:  # the file name covers both columns
        name_claim = (f"the file name {Path(src).name!r}", named)
        for what, role, given, opt in (
            ("boat speed", "speed", speed_unit, "speed_unit"),
            ("wind speed", "tws", given_w, "wind_unit"),
        ):
            _agree(
                src,
                what,
                [
                    (f"column {header[cols[role][0]]!r}", cols[role][1]),
                    (f"{opt}={given!r}", given),
                    name_claim,
                ],
            )
    s_unit = _merge_unit(src, lineno, "speed", cols["speed"][1], speed_unit, default=named or "kn")
    w_unit = _merge_unit(src, lineno, "wind", cols["tws"][1], given_w, default=named or "kn")
    return s_unit, w_unit


def _long_values(
    rows: list[list[str]], start: int, cols: dict[str, tuple[int, str | None]], src: str
) -> dict[tuple[float, float], tuple[float, int]]:
    """``(TWS, TWA) -> (boat speed, line)`` of the data rows after the header row
    ``start`` (file units; each pair once)."""
    values: dict[tuple[float, float], tuple[float, int]] = {}
    need = max(c[0] for c in cols.values()) + 1
    for k in range(start + 1, len(rows)):
        r = rows[k]
        lineno = k + 1
        if not r or not any(c.strip() for c in r) or r[0].lstrip().startswith("#"):
            continue
        if len(r) < need:
            raise InputError(f"{src}:{lineno}: {len(r)} cells; expected at least {need}")
        tws = _number(r[cols["tws"][0]], src, lineno, cols["tws"][0] + 1, "TWS")
        twa = _number(r[cols["twa"][0]], src, lineno, cols["twa"][0] + 1, "TWA")
        sp = _number(r[cols["speed"][0]], src, lineno, cols["speed"][0] + 1, "boat speed")
        if tws < 0:
            raise InputError(f"{src}:{lineno}: TWS {tws:g} is negative")
        if not 0 <= twa <= 180:
            raise InputError(f"{src}:{lineno}: TWA {twa:g} is outside [0, 180]")
        if sp < 0:
            raise InputError(f"{src}:{lineno}: boat speed {sp:g} is negative")
        if (tws, twa) in values:
            raise InputError(
                f"{src}:{lineno}: duplicate (TWS {tws:g}, TWA {twa:g}); first on "
                f"line {values[(tws, twa)][1]}"
            )
        values[(tws, twa)] = (sp, lineno)
    return values
