"""Read and write polar files: ``.pol`` tables, long CSV, sailroute JSON and ORC JSON.

Formats
-------
``pol`` (wide table; also ``.txt`` and wide ``.csv``)
    First line (after optional ``#`` comments and at most one free-text
    description line) is the header: a label cell (``TWA\\TWS``, ``TWA/TWS``,
    ``twa/tws``, ``twa``; case-insensitive) then the TWS values.  Each further
    line is a TWA followed by one boat speed per TWS.  Cells are separated by
    semicolons, tabs, commas or runs of spaces (detected from the header line);
    CRLF line endings are accepted.  **Units default to knots** for both TWS
    and boat speed (the de-facto convention of OpenCPN, qtVlm and
    libweatherrouting); pass ``speed_unit``/``wind_unit`` otherwise, or name
    the unit in the label cell (``TWA\\TWS (km/h)``, ``twa/tws_ms``) or the
    file name (see below).  Empty cells are filled (see :func:`fill_empty_cells`).
``csv`` long format
    A header naming a TWS, a TWA and a speed column (``tws``, ``twa``,
    ``speed``/``bsp``/``boat_speed``/``stw``, or ``btv`` as in an ORC speed guide's
    ``TWS,TWA,BTV,VMG,...``, in any order), each optionally with a unit suffix
    (``tws_kn``, ``speed_ms``, ``bsp_kmh``, ``twa_deg``); one row per (TWS, TWA) pair;
    other columns (``VMG``, ``AWS``, ``Heel``, ...) are ignored.  Without a suffix the
    unit is knots.
``json``
    sailroute's own format (written by :func:`write_polar_json`, units stated
    in the file) or an ORC certificate JSON (``jieter/orc-data``; knots), see
    :func:`read_orc_json`.

Units named by the file
    The last ``.``/``_``/``-``-separated word of the file's stem may name the
    unit of the whole file: ``kn``, ``kt``, ``kts``, ``knot``, ``knots``, ``ms``,
    ``mps``, ``kmh``, ``kph``, ``mph`` (e.g. ``f50.kph.csv``, ``polar_kmh.pol``;
    see :func:`unit_from_name`).  The file is then read in that unit; a
    ``speed_unit``/``wind_unit``, a label cell or a column suffix that says
    otherwise is an error.

Sanity (see ``docs/usage.md``, "Polar sanity"): boat speeds above
:data:`~sailroute.boat.polar.MAX_BOAT_SPEED_KN`, TWS columns above
:data:`~sailroute.boat.polar.MAX_TWS_KN`, TWA/TWS nodes closer than
:data:`~sailroute.boat.polar.MIN_AXIS_STEP` (counting TWA 0/180 and TWS 0) and a
table without any positive speed are refused.

Every error names the file, the line and the cell.
"""

from __future__ import annotations

import csv
import io
import json
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
    Polar,
    axis_spacing_problem,
)
from sailroute.errors import InputError
from sailroute.textin import clean_text, csv_rows, excerpt, quote_header
from sailroute.units import KNOT, speed_factor

FORMATS: Final = ("pol", "csv", "json")
"""Values of the ``format`` argument of :func:`read_polar`."""

_HEADER_LABELS: Final = {"twa\\tws", "twa/tws", "twa", "tws\\twa", "tws/twa", "twa\\\\tws", ""}
_SPEED_NAMES: Final = ("speed", "bsp", "boat_speed", "boatspeed", "stw", "v", "vb", "btv")
"""Boat-speed column names of a long polar CSV (``btv``: the target boat speed of an ORC
speed guide, read as published)."""
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
JSON_FORMAT_TAG: Final = "sailroute-polar"
_NAME_UNITS: Final = {
    "kn": "kn", "kt": "kn", "kts": "kn", "knot": "kn", "knots": "kn",
    "ms": "m/s", "mps": "m/s", "kmh": "km/h", "kph": "km/h", "mph": "mph",
}


# --- public entry points --------------------------------------------------------

_TOO_DEEP = ("not a polar: its JSON nests lists or objects too deeply to read (a polar file "
             "has 3 levels)")


def read_polar(
    path: str | Path,
    *,
    speed_unit: str | None = None,
    wind_unit: str | None = None,
    format: str | None = None,
    interpolation: str = "pchip",
) -> Polar:
    """Read a polar file into a :class:`~sailroute.boat.polar.Polar` (SI units).

    Parameters
    ----------
    path : str or Path
        The file.
    speed_unit : str, optional
        Unit of the boat speeds in the file (``kn``, ``m/s``, ``km/h``, ``mph``).
        Default: knots for ``.pol`` and CSV; the declared unit for JSON.
    wind_unit : str, optional
        Unit of the TWS values.  Default: ``speed_unit`` if that is given,
        else as for ``speed_unit``.
    format : str, optional
        Force a format: ``"pol"``, ``"csv"`` or ``"json"``; by default it is
        chosen from the suffix (``.json`` -> json; ``.csv`` -> long CSV unless the
        header is a ``TWA/TWS`` table; anything else -> pol).
    interpolation : {"pchip", "linear"}
        Interpolation method of the returned polar.

    Returns
    -------
    Polar
        Named after the file stem.

    Raises
    ------
    InputError
        Unreadable file, unknown format or unit, or bad content (the message
        names the file, line and cell).
    """
    p = Path(path)
    if format is not None and format not in FORMATS:
        raise InputError(
            f"{p}: unknown polar format {format!r}; expected one of "
            + ", ".join(map(repr, FORMATS))
        )
    try:
        text = p.read_text(encoding="utf-8-sig")
    except FileNotFoundError:
        raise InputError(f"{p}: polar file not found") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{p}: cannot read polar file ({exc})") from None
    fmt = format or _guess_format(p, text)
    if fmt == "json":
        return _read_json_text(text, p, speed_unit, wind_unit, interpolation)
    if fmt == "csv" and not _looks_wide(text):
        return parse_long_csv(text, p, speed_unit=speed_unit, wind_unit=wind_unit,
                              interpolation=interpolation)
    return parse_pol(text, p, speed_unit=speed_unit, wind_unit=wind_unit,
                     interpolation=interpolation)


def write_pol(
    polar: Polar,
    path: str | Path,
    unit: str = "kn",
    *,
    wind_unit: str | None = None,
    decimals: int | None = 6,
    separator: str = "\t",
) -> Path:
    """Write a polar as a ``.pol`` table (header ``TWA\\TWS``, LF line endings).

    Parameters
    ----------
    polar : Polar
        The polar.
    path : str or Path
        Output file.
    unit : str
        Unit of the boat speeds (default knots, the ``.pol`` convention).
    wind_unit : str, optional
        Unit of the TWS header; default ``unit``.
    decimals : int or None
        Round values to this many decimals; ``None`` writes the shortest text
        that reads back to the identical float (exact round trip).
    separator : str
        Cell separator (tab by default; ``";"`` for OpenCPN's other dialect).

    Returns
    -------
    Path
        The path written.
    """
    fs, fw = speed_factor(unit), speed_factor(wind_unit or unit)
    out = Path(path)
    lines = [separator.join(["TWA\\TWS", *(_fmt(v / fw, decimals) for v in polar.tws_ms)])]
    for a, row in zip(polar.twa_deg, polar.speed_ms, strict=True):
        lines.append(separator.join([_fmt(a, decimals), *(_fmt(v / fs, decimals) for v in row)]))
    out.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return out


def write_polar_csv(
    polar: Polar,
    path: str | Path,
    unit: str = "kn",
    *,
    wind_unit: str | None = None,
    decimals: int | None = 6,
) -> Path:
    """Write a polar as long CSV: ``tws_<u>,twa_deg,speed_<u>``, one row per node.

    Units are carried in the column names (``kn``, ``ms``, ``kmh``, ``mph``), so
    :func:`read_polar` reads the file back without options.  Rows are ordered
    by TWS, then TWA.
    """
    fs, fw = speed_factor(unit), speed_factor(wind_unit or unit)
    out = Path(path)
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow([f"tws_{_suffix(wind_unit or unit)}", "twa_deg", f"speed_{_suffix(unit)}"])
    for j, tws in enumerate(polar.tws_ms):
        for i, twa in enumerate(polar.twa_deg):
            w.writerow(
                [_fmt(tws / fw, decimals), _fmt(twa, decimals),
                 _fmt(polar.speed_ms[i, j] / fs, decimals)]
            )
    out.write_text(buf.getvalue(), encoding="utf-8")
    return out


def write_polar_json(
    polar: Polar,
    path: str | Path,
    unit: str = "m/s",
    *,
    decimals: int | None = None,
    extra: dict[str, Any] | None = None,
) -> Path:
    """Write sailroute's JSON polar format.

    The file holds ``format`` (``"sailroute-polar"``), ``version`` (1), ``name``,
    ``speed_unit``, ``wind_unit``, ``twa_deg`` (rows), ``tws`` (columns),
    ``speed`` (rows of boat speeds), and the best VMG per TWS under ``vmg``
    (``beat_angle_deg``, ``beat_vmg``, ``run_angle_deg``, ``run_vmg``, in
    ``speed_unit``; informational, ignored when reading).  ``extra`` adds
    top-level keys (e.g. the VPP parameters).
    """
    f = speed_factor(unit)
    up_a, up_v = polar.vmg_upwind(polar.tws_ms)
    dn_a, dn_v = polar.vmg_downwind(polar.tws_ms)

    def num(v: float) -> float:
        return float(v) if decimals is None else round(float(v), decimals)

    doc: dict[str, Any] = {
        "format": JSON_FORMAT_TAG,
        "version": 1,
        "name": polar.name,
        "speed_unit": unit,
        "wind_unit": unit,
        "twa_deg": [num(a) for a in polar.twa_deg],
        "tws": [num(v / f) for v in polar.tws_ms],
        "speed": [[num(v / f) for v in row] for row in polar.speed_ms],
        "vmg": {
            "beat_angle_deg": [num(a) for a in up_a],
            "beat_vmg": [num(v / f) for v in up_v],
            "run_angle_deg": [num(a) for a in dn_a],
            "run_vmg": [num(v / f) for v in dn_v],
        },
    }
    if extra:
        doc.update(extra)
    out = Path(path)
    out.write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")
    return out


def read_orc_json(
    path: str | Path,
    *,
    include_optima: bool = True,
    interpolation: str = "pchip",
) -> Polar:
    """Read an ORC certificate JSON (``jieter/orc-data`` layout; knots).

    Parameters
    ----------
    path : str or Path
        The file: ``vpp.angles`` (TWA rows), ``vpp.speeds`` (TWS columns, kn),
        one list of boat speeds (kn) per angle under ``vpp["<angle>"]``, and
        ``beat_angle``/``beat_vmg``/``run_angle``/``run_vmg`` per TWS.
    include_optima : bool
        Add each TWS column's beat and run points (speed = VMG / |cos angle|)
        to the table.  ORC's optima lie outside the 52-150° rows (beats at
        37-44°), so without them the table cannot reproduce the certificate's
        VMG.  The rows of the result are the union of all angles; each column
        is filled by linear interpolation along its own points, and tapers
        linearly to 0 at TWA 0 / 180 outside them.
    interpolation : {"pchip", "linear"}
        Interpolation method of the returned polar.
    """
    p = Path(path)
    try:
        doc = json.loads(p.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise InputError(f"{p}: ORC JSON file not found") from None
    except (OSError, json.JSONDecodeError) as exc:
        raise InputError(f"{p}: not valid JSON ({exc})") from None
    except RecursionError:
        raise InputError(f"{p}: {_TOO_DEEP}") from None
    return _orc_from_doc(doc, p, include_optima, interpolation)


# --- .pol -----------------------------------------------------------------------


def parse_pol(
    text: str,
    source: str | Path = "<polar>",
    *,
    speed_unit: str | None = None,
    wind_unit: str | None = None,
    interpolation: str = "pchip",
) -> Polar:
    """Parse the text of a wide polar table (see the module docstring)."""
    src = str(source)
    lines = text.splitlines()
    # header: first non-comment, non-empty line whose first cell is a label;
    # one free-text description line before it is allowed (OpenCPN)
    header_idx = None
    described = False
    for k, raw in enumerate(lines):
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        sep = _detect_sep(line)
        first = _split(line, sep)[0].strip().lower()
        if first in _HEADER_LABELS or first.startswith("twa"):
            header_idx = k
            break
        if described or _is_number(first):
            break
        described = True
    if header_idx is None:
        if not any(raw.strip() for raw in lines):
            raise InputError(f"{src}: the polar file is empty")
        raise InputError(
            f"{src}: no header line found; a polar table starts with a line like "
            "'TWA\\TWS<tab>6<tab>8<tab>10' (label cell, then the wind speeds)"
        )
    sep = _detect_sep(lines[header_idx].strip())
    head = _split(lines[header_idx].strip(), sep)
    while len(head) > 1 and head[-1].strip() == "":
        head.pop()
    lineno = header_idx + 1
    if len(head) < 2:
        raise InputError(f"{src}:{lineno}: header has no wind speeds after "
                         f"{excerpt(head[0])!r}")
    s_unit, w_unit = _file_units(src, speed_unit, wind_unit, [
        (f"the label cell {excerpt(head[0].strip())!r} (line {lineno})", _header_unit(head[0]))])
    header_line = lineno
    tws = [_number(c, src, lineno, k + 2, "wind speed") for k, c in enumerate(head[1:])]
    for k in range(1, len(tws)):
        if tws[k] <= tws[k - 1]:
            raise InputError(
                f"{src}:{lineno}: wind speeds must increase; cell {k + 2} ({tws[k]:g}) "
                f"follows {tws[k - 1]:g}"
            )
    if tws[0] < 0:
        raise InputError(f"{src}:{lineno}: cell 2: wind speed {tws[0]:g} is negative")
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
        cells = _split(line, sep)
        while len(cells) > len(tws) + 1 and cells[-1].strip() == "":
            cells.pop()
        if len(cells) != len(tws) + 1:
            raise InputError(
                f"{src}:{lineno}: {len(cells) - 1} speed cells but the header has "
                f"{len(tws)} wind speeds"
            )
        a = _number(cells[0], src, lineno, 1, "TWA")
        if not 0.0 <= a <= 180.0:
            raise InputError(f"{src}:{lineno}: cell 1: TWA {a:g} is outside [0, 180]")
        if twa and a <= twa[-1]:
            raise InputError(
                f"{src}:{lineno}: cell 1: TWA {a:g} does not increase (previous row {twa[-1]:g})"
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
        twa.append(a)
        rows.append(row)
        row_lines.append(lineno)
    if len(twa) < 2:
        raise InputError(f"{src}: the table needs at least 2 TWA rows; found {len(twa)}")
    tws_arr = np.asarray(tws, dtype=float)
    raw_tab = np.asarray(rows, dtype=float)
    _check_table(src, np.asarray(twa), tws_arr, raw_tab, s_unit, w_unit,
                 at_twa=lambda i: f"{src}:{row_lines[i]}: cell 1",
                 at_tws=lambda j: f"{src}:{header_line}: cell {j + 2}",
                 at_cell=lambda i, j: f"{src}:{row_lines[i]}: cell {j + 2}")
    tab = fill_empty_cells(np.asarray(twa), tws_arr, raw_tab)
    return Polar.from_arrays(np.asarray(twa), tws_arr * speed_factor(w_unit),
                             tab * speed_factor(s_unit),
                             name=clean_text(Path(src).stem),
                             interpolation=interpolation)


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
            right = np.flatnonzero(ok[j + 1:]) + j + 1
            if left.size and right.size:
                a, b = left[-1], right[0]
                out[i, j] = np.interp(tws[j], [tws[a], tws[b]], [tab[i, a], tab[i, b]])
                continue
            col_ok = ~np.isnan(tab[:, j])
            up = np.flatnonzero(col_ok[:i])
            down = np.flatnonzero(col_ok[i + 1:]) + i + 1
            if up.size and down.size:
                a, b = up[-1], down[0]
                out[i, j] = np.interp(twa_deg[i], [twa_deg[a], twa_deg[b]], [tab[a, j], tab[b, j]])
            elif right.size:
                b = right[0]
                out[i, j] = tab[i, b] * (tws[j] / tws[b] if tws[b] > 0 else 0.0)
            else:
                out[i, j] = tab[i, left[-1]]
    return out


# --- long CSV -----------------------------------------------------------------------


def parse_long_csv(
    text: str,
    source: str | Path = "<polar>",
    *,
    speed_unit: str | None = None,
    wind_unit: str | None = None,
    interpolation: str = "pchip",
) -> Polar:
    """Parse a long ("tidy") polar CSV (see the module docstring)."""
    src = str(source)
    rows = csv_rows(list(enumerate(text.splitlines(), 1)), ",", src)
    start = next((k for k, r in enumerate(rows) if r and any(c.strip() for c in r)
                  and not r[0].lstrip().startswith("#")), None)
    if start is None:
        raise InputError(f"{src}: the polar file is empty")
    header = [c.strip().lower() for c in rows[start]]
    cols: dict[str, tuple[int, str | None]] = {}
    for k, name in enumerate(header):
        base, unit = _split_unit(name)
        role = ("tws" if base == "tws" else "twa" if base == "twa"
                else "speed" if base in _SPEED_NAMES else None)
        if role is None:
            continue
        if role in cols:
            first = header[cols[role][0]]
            raise InputError(
                f"{src}:{start + 1}: two {role.upper()} columns ({first!r} and {name!r})"
            )
        cols[role] = (k, unit)
    missing = [r for r in ("tws", "twa", "speed") if r not in cols]
    if missing:
        raise InputError(
            f"{src}:{start + 1}: long polar CSV needs columns tws, twa and speed (or bsp, "
            f"boat_speed, stw, btv), optionally with a unit suffix like tws_kn; missing "
            f"{', '.join(missing)} in the header ({quote_header(rows[start])})"
        )
    if cols["twa"][1] not in (None, "deg"):
        raise InputError(f"{src}:{start + 1}: TWA must be in degrees; got column "
                         f"{header[cols['twa'][0]]!r}")
    named = unit_from_name(src)
    given_w = wind_unit or (speed_unit if cols["tws"][1] is None and cols["speed"][1] is None
                            else None)
    if named is not None:  # the file name covers both columns
        name_claim = (f"the file name {Path(src).name!r}", named)
        for what, role, given, opt in (("boat speed", "speed", speed_unit, "speed_unit"),
                                       ("wind speed", "tws", given_w, "wind_unit")):
            _agree(src, what, [(f"column {header[cols[role][0]]!r}", cols[role][1]),
                               (f"{opt}={given!r}", given), name_claim])
    s_unit = _merge_unit(src, start + 1, "speed", cols["speed"][1], speed_unit,
                         default=named or "kn")
    w_unit = _merge_unit(src, start + 1, "wind", cols["tws"][1], given_w, default=named or "kn")
    values: dict[tuple[float, float], tuple[float, int]] = {}
    for k in range(start + 1, len(rows)):
        r = rows[k]
        lineno = k + 1
        if not r or not any(c.strip() for c in r) or r[0].lstrip().startswith("#"):
            continue
        need = max(c[0] for c in cols.values()) + 1
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
            raise InputError(f"{src}:{lineno}: duplicate (TWS {tws:g}, TWA {twa:g}); first on "
                             f"line {values[(tws, twa)][1]}")
        values[(tws, twa)] = (sp, lineno)
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

    _check_table(src, twa_ax, tws_ax, tab, s_unit, w_unit,
                 at_twa=lambda i: f"{src}:{first_line(1, float(twa_ax[i]))}: "
                                  f"cell {cols['twa'][0] + 1}",
                 at_tws=lambda j: f"{src}:{first_line(0, float(tws_ax[j]))}: "
                                  f"cell {cols['tws'][0] + 1}",
                 at_cell=lambda i, j: f"{src}:{line_of[i, j]}: cell {cols['speed'][0] + 1}")
    tab = fill_empty_cells(twa_ax, tws_ax, tab)
    return Polar.from_arrays(twa_ax, tws_ax * speed_factor(w_unit), tab * speed_factor(s_unit),
                             name=clean_text(Path(src).stem), interpolation=interpolation)


# --- JSON -----------------------------------------------------------------------------


def _read_json_text(
    text: str, p: Path, speed_unit: str | None, wind_unit: str | None, interpolation: str
) -> Polar:
    try:
        doc = json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(f"{p}:{exc.lineno}: not valid JSON ({exc.msg})") from None
    except RecursionError:
        raise InputError(f"{p}: {_TOO_DEEP}") from None
    if isinstance(doc, dict) and "vpp" in doc:
        if speed_unit not in (None, "kn") or wind_unit not in (None, "kn"):
            raise InputError(f"{p}: ORC JSON polars are in knots; do not pass another unit")
        return _orc_from_doc(doc, p, True, interpolation)
    if not isinstance(doc, dict) or doc.get("format") != JSON_FORMAT_TAG:
        raise InputError(
            f"{p}: unknown JSON polar; expected sailroute's format (\"format\": "
            f"\"{JSON_FORMAT_TAG}\") or an ORC certificate (with a \"vpp\" block)"
        )
    problems = [f"missing key {k!r}" for k in ("twa_deg", "tws", "speed", "speed_unit")
                if k not in doc]
    if problems:
        raise InputError(f"{p}: " + "; ".join(problems))
    file_speed = str(doc["speed_unit"])
    file_wind = str(doc.get("wind_unit", file_speed))
    name_claim = (f"the file name {p.name!r}", unit_from_name(p))
    _agree(str(p), "boat speed", [(f"its speed_unit {file_speed!r}", file_speed), name_claim])
    _agree(str(p), "wind speed", [(f"its wind_unit {file_wind!r}", file_wind), name_claim])
    s_unit = _merge_unit(str(p), None, "speed", file_speed, speed_unit)
    w_unit = _merge_unit(str(p), None, "wind", file_wind, wind_unit)
    try:
        twa = np.asarray(doc["twa_deg"], dtype=float)
        tws = np.asarray(doc["tws"], dtype=float)
        tab = np.asarray(doc["speed"], dtype=float)
    except (TypeError, ValueError, OverflowError) as exc:
        raise InputError(f"{p}: twa_deg, tws and speed must be numbers ({exc})") from None
    if _well_formed(twa, tws, tab):
        _check_table(str(p), twa, tws, tab, s_unit, w_unit,
                     at_twa=lambda i: f"{p}: twa_deg[{i}]", at_tws=lambda j: f"{p}: tws[{j}]",
                     at_cell=lambda i, j: f"{p}: speed[{i}][{j}]")
    try:
        return Polar.from_arrays(twa, tws * speed_factor(w_unit), tab * speed_factor(s_unit),
                                 name=clean_text(str(doc.get("name") or p.stem)),
                                 interpolation=interpolation)
    except InputError as exc:
        raise InputError(f"{p}: {exc}") from None


def _orc_from_doc(doc: Any, p: Path, include_optima: bool, interpolation: str) -> Polar:
    named = unit_from_name(p)
    if named not in (None, "kn"):
        raise InputError(f"{p}: the file name says {named}, but ORC certificate polars are in "
                         "knots; rename the file")
    what = ("not an ORC certificate polar: need vpp.angles, vpp.speeds, one speed list per "
            "angle and beat/run angle and VMG lists")
    try:
        vpp = doc["vpp"]
        angles = [float(a) for a in vpp["angles"]]
    except (KeyError, TypeError, ValueError, OverflowError) as exc:
        raise InputError(f"{p}: {what} ({type(exc).__name__}: {exc})") from None
    _orc_check(p, "vpp.angles", np.asarray(angles), 0.0, 180.0, "an angle in [0, 180] deg")
    try:
        tws = np.asarray([float(v) for v in vpp["speeds"]])
        keys = [_orc_key(vpp, a) for a in angles]
        tab = np.asarray([[float(v) for v in vpp[k]] for k in keys])
        optima = {k: np.asarray(vpp[k], dtype=float)
                  for k in ("beat_angle", "beat_vmg", "run_angle", "run_vmg")}
    except (KeyError, TypeError, ValueError, OverflowError) as exc:
        raise InputError(f"{p}: {what} ({type(exc).__name__}: {exc})") from None
    if tab.shape != (len(angles), tws.size) or any(v.shape != tws.shape for v in optima.values()):
        raise InputError(f"{p}: ORC vpp block: every list must have one value per wind speed "
                         f"({tws.size})")
    _orc_check(p, "vpp.speeds", tws, 0.0, math.inf, "a wind speed >= 0 kn")
    for i, k in enumerate(keys):
        _orc_check(p, f"vpp[{k!r}]", tab[i], 0.0, math.inf, "a boat speed >= 0 kn")
    _orc_check(p, "vpp.beat_angle", optima["beat_angle"], 0.0, 90.0, "an angle in (0, 90) deg",
               open_ends=True)
    _orc_check(p, "vpp.run_angle", optima["run_angle"], 90.0, 180.0, "an angle in (90, 180] deg",
               open_ends=(True, False))
    for k in ("beat_vmg", "run_vmg"):
        _orc_check(p, f"vpp.{k}", optima[k], 0.0, math.inf, "a VMG >= 0 kn")
    if _well_formed(np.asarray(angles), tws, tab):
        _check_table(str(p), np.asarray(angles), tws, tab, "kn", "kn",
                     at_twa=lambda i: f"{p}: vpp.angles[{i}]",
                     at_tws=lambda j: f"{p}: vpp.speeds[{j}]",
                     at_cell=lambda i, j: f"{p}: vpp[{keys[i]!r}][{j}]")
    name = str(doc.get("boat", {}).get("type") or doc.get("name") or p.stem)
    if not include_optima:
        return _orc_polar(p, np.asarray(angles), tws, tab, name, interpolation)
    cols: list[tuple[NDArray, NDArray]] = []
    for j in range(tws.size):
        a_b, a_r = optima["beat_angle"][j], optima["run_angle"][j]
        pts = {round(a, 1): v for a, v in zip(angles, tab[:, j], strict=True)}
        pts[round(a_b, 1)] = optima["beat_vmg"][j] / math.cos(math.radians(a_b))
        pts[round(a_r, 1)] = optima["run_vmg"][j] / abs(math.cos(math.radians(a_r)))
        nodes = sorted(pts)
        cols.append((np.asarray(nodes), np.asarray([pts[k] for k in nodes])))
    for k, a_key, v_key in (("beat", "beat_angle", "beat_vmg"), ("run", "run_angle", "run_vmg")):
        v = optima[v_key] / np.abs(np.cos(np.radians(optima[a_key])))
        if np.any(v > MAX_BOAT_SPEED_KN):
            j = int(np.argmax(v))
            raise InputError(
                f"{p}: vpp.{v_key}[{j}] / cos(vpp.{a_key}[{j}]) gives a {k} boat speed of "
                f"{v[j]:.4g} kn, above {MAX_BOAT_SPEED_KN:g} kn (faster than any sailing craft); "
                "check the VMG and angle"
            )
    rows = np.asarray(sorted({a for c in cols for a in c[0]}))
    out = np.empty((rows.size, tws.size))
    for j, (a, v) in enumerate(cols):
        aa = np.concatenate([[0.0], a, [180.0]]) if a[-1] < 180 else np.concatenate([[0.0], a])
        vv = np.concatenate([[0.0], v, [0.0]]) if a[-1] < 180 else np.concatenate([[0.0], v])
        out[:, j] = np.interp(rows, aa, vv)
    return _orc_polar(p, rows, tws, out, name, interpolation)


def _orc_polar(p: Path, twa: NDArray, tws_kn: NDArray, tab_kn: NDArray, name: str,
               interpolation: str) -> Polar:
    try:
        return Polar.from_arrays(twa, tws_kn * speed_factor("kn"), tab_kn * speed_factor("kn"),
                                 name=name, interpolation=interpolation)
    except InputError as exc:
        raise InputError(f"{p}: {exc}") from None


def _orc_check(p: Path, key: str, values: NDArray, lo: float, hi: float, expected: str,
               open_ends: bool | tuple[bool, bool] = False) -> None:
    """Every value of ``values`` finite and in ``[lo, hi]`` (open ends if asked), else an error."""
    lo_open, hi_open = (open_ends, open_ends) if isinstance(open_ends, bool) else open_ends
    v = np.asarray(values, dtype=float)
    with np.errstate(invalid="ignore"):
        bad = ~np.isfinite(v) | (v <= lo if lo_open else v < lo) | (v >= hi if hi_open else v > hi)
    if np.any(bad):
        k = int(np.flatnonzero(bad)[0])
        raise InputError(
            f"{p}: {key}[{k}]: expected {expected}; got {float(v[k])!r}"
            + (" (JSON 1e400, Infinity or NaN)" if not math.isfinite(v[k]) else "")
        )


def _orc_key(vpp: dict[str, Any], angle: float) -> str:
    for key in (str(int(angle)) if angle == int(angle) else str(angle), str(angle)):
        if key in vpp:
            return key
    raise KeyError(f"no speed list for angle {angle:g}")


# --- units and sanity ------------------------------------------------------------------


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


def _agree(src: str, what: str, claims: list[tuple[str, str | None]],
           default: str = "kn") -> str:
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
    return (f"a unit mistake? It is read in {unit}; if the file is in {' or '.join(smaller)}, "
            f"say so with {option}: {smaller[-1]} in the course's boat: block (or end the file "
            "name with .kph, .kmh, .mph, ...)")


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
            "than any sailing craft has gone (record 65.45 kn); "
            + _unit_hint(s_unit, "speed_unit")
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
        twa.ndim == 1 and tws.ndim == 1 and tab.shape == (twa.size, tws.size)
        and twa.size >= 2 and tws.size >= 1
        and np.all(np.isfinite(twa)) and np.all(np.isfinite(tws)) and np.all(np.isfinite(tab))
        and np.all(np.diff(twa) > 0) and np.all(np.diff(tws) > 0)
    )


def _close_index(v: NDArray[np.float64], axis: str) -> int:
    """Index of the first node closer than ``MIN_AXIS_STEP`` to its neighbour or edge."""
    for k in range(v.size):
        prev = v[k - 1] if k else 0.0
        if (k or v[0] > 0) and v[k] - prev < MIN_AXIS_STEP:
            return k
    return v.size - 1  # only the TWA 180 edge is left


# --- helpers --------------------------------------------------------------------------


def _guess_format(p: Path, text: str) -> str:
    suffix = p.suffix.lower()
    if suffix == ".json":
        return "json"
    if suffix == ".csv":
        return "csv"
    if text.lstrip().startswith("{"):
        return "json"
    return "pol"


def _looks_wide(text: str) -> bool:
    for raw in text.splitlines():
        line = raw.strip()
        if line and not line.startswith("#"):
            first = _split(line, _detect_sep(line))[0].strip().lower()
            return first.startswith("twa") and first not in ("twa", "twa_deg")
    return False


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
        raise InputError(f"{src}:{lineno}: cell {col} ({excerpt(text)!r}): {what} must be "
                         "finite")
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
    return {speed_factor("kn"): "kn", 1.0: "ms", speed_factor("km/h"): "kmh",
            speed_factor("mph"): "mph"}[f]


def _file_units(src: str, speed_unit: str | None, wind_unit: str | None,
                claims: list[tuple[str, str | None]]) -> tuple[str, str]:
    """Speed and wind unit of a wide table: the options, what the file says, else knots.

    ``claims`` are the file's own statements (e.g. its label cell); the file name
    (:func:`unit_from_name`) is added.  A file-wide statement covers both the
    boat speeds and the TWS; any disagreement is an error.
    """
    named = unit_from_name(src)
    claims = [*claims, (f"the file name {Path(src).name!r}", named)]
    s_unit = _agree(src, "boat speed", [(f"speed_unit={speed_unit!r}", speed_unit), *claims])
    given_w = (f"wind_unit={wind_unit!r}", wind_unit) if wind_unit else (
        f"speed_unit={speed_unit!r}", speed_unit)
    w_unit = _agree(src, "wind speed", [given_w, *claims])
    return s_unit, w_unit


def _merge_unit(src: str, lineno: int | None, what: str, declared: str | None,
                given: str | None, default: str = "kn") -> str:
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


def _fmt(v: float, decimals: int | None) -> str:
    x = float(v) if decimals is None else round(float(v), decimals)
    return repr(x + 0.0)  # + 0.0 turns -0.0 into 0.0
