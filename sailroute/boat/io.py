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
from pathlib import Path
from typing import Any, Final

from sailroute.boat.polar import Polar
from sailroute.boat.polarcsv import parse_long_csv
from sailroute.boat.polarfile import _detect_sep, _split, _suffix, unit_from_name
from sailroute.boat.polarjson import JSON_FORMAT_TAG, _read_json_text, read_orc_json
from sailroute.boat.poltable import fill_empty_cells, parse_pol
from sailroute.errors import InputError
from sailroute.units import speed_factor

__all__ = [
    "FORMATS",
    "JSON_FORMAT_TAG",
    "fill_empty_cells",
    "parse_long_csv",
    "parse_pol",
    "read_orc_json",
    "read_polar",
    "unit_from_name",
    "write_pol",
    "write_polar_csv",
    "write_polar_json",
]


FORMATS: Final = ("pol", "csv", "json")
"""Values of the ``format`` argument of :func:`read_polar`."""


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
        return parse_long_csv(
            text, p, speed_unit=speed_unit, wind_unit=wind_unit, interpolation=interpolation
        )
    return parse_pol(
        text, p, speed_unit=speed_unit, wind_unit=wind_unit, interpolation=interpolation
    )


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
                [
                    _fmt(tws / fw, decimals),
                    _fmt(twa, decimals),
                    _fmt(polar.speed_ms[i, j] / fs, decimals),
                ]
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


def _fmt(v: float, decimals: int | None) -> str:
    x = float(v) if decimals is None else round(float(v), decimals)
    return repr(x + 0.0)  # + 0.0 turns -0.0 into 0.0
