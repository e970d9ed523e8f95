"""Wide polar tables (``.pol``, ``.txt``, wide ``.csv``): a ``TWA\\TWS`` header of wind
speeds, one row of boat speeds per TWA (:mod:`sailroute.boat.io` describes the format);
empty cells filled (:func:`fill_empty_cells`)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Final

import numpy as np
from numpy.typing import NDArray

from sailroute.boat.polar import Polar
from sailroute.boat.polarfile import (
    _check_table,
    _detect_sep,
    _file_units,
    _header_unit,
    _is_number,
    _number,
    _split,
)
from sailroute.errors import InputError
from sailroute.textin import clean_text, excerpt
from sailroute.units import speed_factor

_HEADER_LABELS: Final = {"twa\\tws", "twa/tws", "twa", "tws\\twa", "tws/twa", "twa\\\\tws", ""}


def parse_pol(
    text: str,
    source: str | Path = "<polar>",
    *,
    speed_unit: str | None = None,
    wind_unit: str | None = None,
    interpolation: str = "pchip",
) -> Polar:
    """Parse the text of a wide polar table (see :mod:`sailroute.boat.io`)."""
    src = str(source)
    lines = text.splitlines()
    header_idx = _header_index(lines, src)
    sep = _detect_sep(lines[header_idx].strip())
    head = _split(lines[header_idx].strip(), sep)
    while len(head) > 1 and head[-1].strip() == "":
        head.pop()
    header_line = header_idx + 1
    if len(head) < 2:
        raise InputError(
            f"{src}:{header_line}: header has no wind speeds after {excerpt(head[0])!r}"
        )
    s_unit, w_unit = _file_units(
        src,
        speed_unit,
        wind_unit,
        [
            (
                f"the label cell {excerpt(head[0].strip())!r} (line {header_line})",
                _header_unit(head[0]),
            )
        ],
    )
    tws = _header_speeds(head, src, header_line)
    twa, rows, row_lines = _table_rows(lines, header_idx, sep, tws, src)
    tws_arr = np.asarray(tws, dtype=float)
    raw_tab = np.asarray(rows, dtype=float)
    _check_table(
        src,
        np.asarray(twa),
        tws_arr,
        raw_tab,
        s_unit,
        w_unit,
        at_twa=lambda i: f"{src}:{row_lines[i]}: cell 1",
        at_tws=lambda j: f"{src}:{header_line}: cell {j + 2}",
        at_cell=lambda i, j: f"{src}:{row_lines[i]}: cell {j + 2}",
    )
    tab = fill_empty_cells(np.asarray(twa), tws_arr, raw_tab)
    return Polar.from_arrays(
        np.asarray(twa),
        tws_arr * speed_factor(w_unit),
        tab * speed_factor(s_unit),
        name=clean_text(Path(src).stem),
        interpolation=interpolation,
    )


def _header_index(lines: list[str], src: str) -> int:
    """Index of the header: the first non-comment, non-empty line whose first cell is a
    label; one free-text description line before it is allowed (OpenCPN)."""
    described = False
    for k, raw in enumerate(lines):
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        first = _split(line, _detect_sep(line))[0].strip().lower()
        if first in _HEADER_LABELS or first.startswith("twa"):
            return k
        if described or _is_number(first):
            break
        described = True
    if not any(raw.strip() for raw in lines):
        raise InputError(f"{src}: the polar file is empty")
    raise InputError(
        f"{src}: no header line found; a polar table starts with a line like "
        "'TWA\\TWS<tab>6<tab>8<tab>10' (label cell, then the wind speeds)"
    )


def _header_speeds(head: list[str], src: str, lineno: int) -> list[float]:
    """The wind speeds of the header cells after the label (file units): increasing, >= 0."""
    tws = [_number(c, src, lineno, k + 2, "wind speed") for k, c in enumerate(head[1:])]
    for k in range(1, len(tws)):
        if tws[k] <= tws[k - 1]:
            raise InputError(
                f"{src}:{lineno}: wind speeds must increase; cell {k + 2} ({tws[k]:g}) "
                f"follows {tws[k - 1]:g}"
            )
    if tws[0] < 0:
        raise InputError(f"{src}:{lineno}: cell 2: wind speed {tws[0]:g} is negative")
    return tws


def _table_rows(
    lines: list[str], header_idx: int, sep: str | None, tws: list[float], src: str
) -> tuple[list[float], list[list[float]], list[int]]:
    """TWA [°], boat speeds (file units, NaN for an empty cell) and line number of every
    row after the header; at least 2 rows, TWA increasing, no blank line between rows."""
    twa: list[float] = []
    rows: list[list[float]] = []
    row_lines: list[int] = []
    blank_at = None
    for k in range(header_idx + 1, len(lines)):
        # keep tabs: trailing tab/semicolon cells are empty cells, not padding
        line = lines[k].strip(" \r\n") if sep is not None else lines[k].strip()
        lineno = k + 1
        if not line.strip():
            blank_at = blank_at or lineno
            continue
        if line.startswith("#"):
            continue
        if blank_at is not None:
            raise InputError(
                f"{src}:{blank_at}: empty line inside the table; remove it (rows follow on "
                f"line {lineno})"
            )
        a, row = _table_row(_split(line, sep), len(tws), src, lineno, twa[-1] if twa else None)
        twa.append(a)
        rows.append(row)
        row_lines.append(lineno)
    if len(twa) < 2:
        raise InputError(f"{src}: the table needs at least 2 TWA rows; found {len(twa)}")
    return twa, rows, row_lines


def _table_row(
    cells: list[str], n_tws: int, src: str, lineno: int, previous: float | None
) -> tuple[float, list[float]]:
    """TWA [°] in [0, 180] (above the ``previous`` row's) and the ``n_tws`` boat speeds
    (>= 0, NaN for an empty cell, not all empty) of one table row."""
    while len(cells) > n_tws + 1 and cells[-1].strip() == "":
        cells.pop()
    if len(cells) != n_tws + 1:
        raise InputError(
            f"{src}:{lineno}: {len(cells) - 1} speed cells but the header has {n_tws} wind speeds"
        )
    a = _number(cells[0], src, lineno, 1, "TWA")
    if not 0.0 <= a <= 180.0:
        raise InputError(f"{src}:{lineno}: cell 1: TWA {a:g} is outside [0, 180]")
    if previous is not None and a <= previous:
        raise InputError(
            f"{src}:{lineno}: cell 1: TWA {a:g} does not increase (previous row {previous:g})"
        )
    row = []
    for c, cell in enumerate(cells[1:]):
        if cell.strip() == "":
            row.append(math.nan)
            continue
        v = _number(cell, src, lineno, c + 2, "boat speed")
        if v < 0:
            raise InputError(f"{src}:{lineno}: cell {c + 2}: boat speed {v:g} is negative")
        row.append(v)
    if all(math.isnan(v) for v in row):
        raise InputError(f"{src}:{lineno}: TWA {a:g} has no boat speeds (all cells empty)")
    return a, row


def fill_empty_cells(
    twa_deg: NDArray[np.float64], tws: NDArray[np.float64], table: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Fill NaN cells of a polar table.

    Rules, in order: linear interpolation along TWS between the nearest filled
    cells of the same row; else along TWA between the nearest filled cells of
    the same column; else (a gap at the low-TWS end of its row with no column
    neighbours) the linear taper towards 0 at TWS 0 from the next filled cell
    of the row; else (a gap at the high-TWS end) the last filled cell of the
    row is held.  This follows OpenCPN's order (wind speed first, then angle)
    and the polar's edge semantics.
    """
    tab = np.array(table, dtype=float)
    if not np.isnan(tab).any():
        return tab
    out = tab.copy()
    n_rows = tab.shape[0]
    for i in range(n_rows):
        ok = ~np.isnan(tab[i])
        for j in np.flatnonzero(~ok):
            left = np.flatnonzero(ok[:j])
            right = np.flatnonzero(ok[j + 1 :]) + j + 1
            if left.size and right.size:
                a, b = left[-1], right[0]
                out[i, j] = np.interp(tws[j], [tws[a], tws[b]], [tab[i, a], tab[i, b]])
                continue
            col_ok = ~np.isnan(tab[:, j])
            up = np.flatnonzero(col_ok[:i])
            down = np.flatnonzero(col_ok[i + 1 :]) + i + 1
            if up.size and down.size:
                a, b = up[-1], down[0]
                out[i, j] = np.interp(twa_deg[i], [twa_deg[a], twa_deg[b]], [tab[a, j], tab[b, j]])
            elif right.size:
                b = right[0]
                out[i, j] = tab[i, b] * (tws[j] / tws[b] if tws[b] > 0 else 0.0)
            else:
                out[i, j] = tab[i, left[-1]]
    return out
