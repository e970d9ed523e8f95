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
    libweatherrouting); pass ``speed_unit``/``wind_unit`` otherwise.
    Empty cells are filled (see :func:`fill_empty_cells`).
``csv`` long format
    A header naming a TWS, a TWA and a speed column (``tws``, ``twa``,
    ``speed``/``bsp``/``boat_speed``/``stw``, in any order), each optionally with
    a unit suffix (``tws_kn``, ``speed_ms``, ``bsp_kmh``, ``twa_deg``); one row
    per (TWS, TWA) pair.  Without a suffix the unit is knots.
``json``
    sailroute's own format (written by :func:`write_polar_json`, units stated
    in the file) or an ORC certificate JSON (``jieter/orc-data``; knots), see
    :func:`read_orc_json`.

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

from sailroute.boat.polar import Polar
from sailroute.errors import InputError
from sailroute.units import speed_factor

FORMATS: Final = ("pol", "csv", "json")
"""Values of the ``format`` argument of :func:`read_polar`."""

_HEADER_LABELS: Final = {"twa\\tws", "twa/tws", "twa", "tws\\twa", "tws/twa", "twa\\\\tws", ""}
_SPEED_NAMES: Final = ("speed", "bsp", "boat_speed", "boatspeed", "stw", "v", "vb")
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


# --- public entry points --------------------------------------------------------


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
    format : {"pol", "csv", "json"}, optional
        Force a format; by default it is chosen from the suffix (``.json`` ->
        json; ``.csv`` -> long CSV unless the header is a ``TWA/TWS`` table;
        anything else -> pol).
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
    fs, fw = _units(src, speed_unit, wind_unit, "kn")
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
        raise InputError(f"{src}:{lineno}: header has no wind speeds after {head[0]!r}")
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
    tab = fill_empty_cells(np.asarray(twa), tws_arr, np.asarray(rows, dtype=float))
    return Polar(np.asarray(twa), tws_arr * fw, tab * fs, name=Path(src).stem,
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
    rows = list(csv.reader(io.StringIO(text)))
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
            f"boat_speed, stw), optionally with a unit suffix like tws_kn; missing "
            f"{', '.join(missing)} in header {rows[start]!r}"
        )
    if cols["twa"][1] not in (None, "deg"):
        raise InputError(f"{src}:{start + 1}: TWA must be in degrees; got column "
                         f"{header[cols['twa'][0]]!r}")
    s_unit = _merge_unit(src, start + 1, "speed", cols["speed"][1], speed_unit)
    w_unit = _merge_unit(src, start + 1, "wind", cols["tws"][1], wind_unit or
                         (speed_unit if cols["tws"][1] is None and cols["speed"][1] is None
                          else None))
    fs, fw = speed_factor(s_unit), speed_factor(w_unit)
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
    for (w, a), (v, _) in values.items():
        tab[np.searchsorted(twa_ax, a), np.searchsorted(tws_ax, w)] = v
    tab = fill_empty_cells(twa_ax, tws_ax, tab)
    return Polar(twa_ax, tws_ax * fw, tab * fs, name=Path(src).stem, interpolation=interpolation)


# --- JSON -----------------------------------------------------------------------------


def _read_json_text(
    text: str, p: Path, speed_unit: str | None, wind_unit: str | None, interpolation: str
) -> Polar:
    try:
        doc = json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(f"{p}:{exc.lineno}: not valid JSON ({exc.msg})") from None
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
    s_unit = _merge_unit(str(p), None, "speed", file_speed, speed_unit)
    w_unit = _merge_unit(str(p), None, "wind", file_wind, wind_unit)
    try:
        twa = np.asarray(doc["twa_deg"], dtype=float)
        tws = np.asarray(doc["tws"], dtype=float)
        tab = np.asarray(doc["speed"], dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{p}: twa_deg, tws and speed must be numbers ({exc})") from None
    try:
        return Polar(twa, tws * speed_factor(w_unit), tab * speed_factor(s_unit),
                     name=str(doc.get("name") or p.stem), interpolation=interpolation)
    except InputError as exc:
        raise InputError(f"{p}: {exc}") from None


def _orc_from_doc(doc: Any, p: Path, include_optima: bool, interpolation: str) -> Polar:
    try:
        vpp = doc["vpp"]
        angles = [float(a) for a in vpp["angles"]]
        tws = np.asarray([float(v) for v in vpp["speeds"]])
        tab = np.asarray([[float(v) for v in vpp[_orc_key(vpp, a)]] for a in angles])
        optima = {k: np.asarray(vpp[k], dtype=float)
                  for k in ("beat_angle", "beat_vmg", "run_angle", "run_vmg")}
    except (KeyError, TypeError, ValueError) as exc:
        raise InputError(
            f"{p}: not an ORC certificate polar: need vpp.angles, vpp.speeds, one speed list "
            f"per angle and beat/run angle and VMG lists ({type(exc).__name__}: {exc})"
        ) from None
    if tab.shape != (len(angles), tws.size) or any(v.shape != tws.shape for v in optima.values()):
        raise InputError(f"{p}: ORC vpp block: every list must have one value per wind speed "
                         f"({tws.size})")
    name = str(doc.get("boat", {}).get("type") or doc.get("name") or p.stem)
    if not include_optima:
        return Polar(np.asarray(angles), tws * speed_factor("kn"), tab * speed_factor("kn"),
                     name=name, interpolation=interpolation)
    cols: list[tuple[NDArray, NDArray]] = []
    for j in range(tws.size):
        a_b, a_r = optima["beat_angle"][j], optima["run_angle"][j]
        pts = {round(a, 1): v for a, v in zip(angles, tab[:, j], strict=True)}
        pts[round(a_b, 1)] = optima["beat_vmg"][j] / math.cos(math.radians(a_b))
        pts[round(a_r, 1)] = optima["run_vmg"][j] / abs(math.cos(math.radians(a_r)))
        keys = sorted(pts)
        cols.append((np.asarray(keys), np.asarray([pts[k] for k in keys])))
    rows = np.asarray(sorted({a for c in cols for a in c[0]}))
    out = np.empty((rows.size, tws.size))
    for j, (a, v) in enumerate(cols):
        aa = np.concatenate([[0.0], a, [180.0]]) if a[-1] < 180 else np.concatenate([[0.0], a])
        vv = np.concatenate([[0.0], v, [0.0]]) if a[-1] < 180 else np.concatenate([[0.0], v])
        out[:, j] = np.interp(rows, aa, vv)
    return Polar(rows, tws * speed_factor("kn"), out * speed_factor("kn"), name=name,
                 interpolation=interpolation)


def _orc_key(vpp: dict[str, Any], angle: float) -> str:
    for key in (str(int(angle)) if angle == int(angle) else str(angle), str(angle)):
        if key in vpp:
            return key
    raise KeyError(f"no speed list for angle {angle:g}")


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
            f"{src}:{lineno}: cell {col} ({text!r}): expected a number ({what})"
        ) from None
    if not math.isfinite(v):
        raise InputError(f"{src}:{lineno}: cell {col} ({text!r}): {what} must be finite")
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


def _units(src: str, speed_unit: str | None, wind_unit: str | None,
           default: str) -> tuple[float, float]:
    s = speed_unit or default
    w = wind_unit or speed_unit or default
    try:
        return speed_factor(s), speed_factor(w)
    except InputError as exc:
        raise InputError(f"{src}: {exc}") from None


def _merge_unit(src: str, lineno: int | None, what: str, declared: str | None,
                given: str | None) -> str:
    where = f"{src}:{lineno}" if lineno else src
    try:
        if declared and given and speed_factor(declared) != speed_factor(given):
            raise InputError(
                f"{where}: the file declares {what} unit {declared!r} but {given!r} was passed; "
                "drop the option or fix the file"
            )
        unit = declared or given or "kn"
        speed_factor(unit)
    except InputError as exc:
        if str(exc).startswith(where):
            raise
        raise InputError(f"{where}: {exc}") from None
    return unit


def _fmt(v: float, decimals: int | None) -> str:
    x = float(v) if decimals is None else round(float(v), decimals)
    return repr(x + 0.0)  # + 0.0 turns -0.0 into 0.0
