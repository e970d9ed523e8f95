"""JSON polars: sailroute's own format (units stated in the file) and ORC certificates
(``jieter/orc-data`` layout, knots)."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any, Final

import numpy as np
from numpy.typing import NDArray

from sailroute.boat.polar import MAX_BOAT_SPEED_KN, Polar
from sailroute.boat.polarfile import (
    _agree,
    _check_table,
    _merge_unit,
    _well_formed,
    unit_from_name,
)
from sailroute.errors import InputError
from sailroute.textin import clean_text
from sailroute.units import speed_factor

JSON_FORMAT_TAG: Final = "sailroute-polar"


_TOO_DEEP = (
    "not a polar: its JSON nests lists or objects too deeply to read (a polar file has 3 levels)"
)


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
            f'{p}: unknown JSON polar; expected sailroute\'s format ("format": '
            f'"{JSON_FORMAT_TAG}") or an ORC certificate (with a "vpp" block)'
        )
    problems = [
        f"missing key {k!r}" for k in ("twa_deg", "tws", "speed", "speed_unit") if k not in doc
    ]
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
        _check_table(
            str(p),
            twa,
            tws,
            tab,
            s_unit,
            w_unit,
            at_twa=lambda i: f"{p}: twa_deg[{i}]",
            at_tws=lambda j: f"{p}: tws[{j}]",
            at_cell=lambda i, j: f"{p}: speed[{i}][{j}]",
        )
    try:
        return Polar.from_arrays(
            twa,
            tws * speed_factor(w_unit),
            tab * speed_factor(s_unit),
            name=clean_text(str(doc.get("name") or p.stem)),
            interpolation=interpolation,
        )
    except InputError as exc:
        raise InputError(f"{p}: {exc}") from None


def _orc_from_doc(doc: Any, p: Path, include_optima: bool, interpolation: str) -> Polar:
    named = unit_from_name(p)
    if named not in (None, "kn"):
        raise InputError(
            f"{p}: the file name says {named}, but ORC certificate polars are in "
            "knots; rename the file"
        )
    what = (
        "not an ORC certificate polar: need vpp.angles, vpp.speeds, one speed list per "
        "angle and beat/run angle and VMG lists"
    )
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
        optima = {
            k: np.asarray(vpp[k], dtype=float)
            for k in ("beat_angle", "beat_vmg", "run_angle", "run_vmg")
        }
    except (KeyError, TypeError, ValueError, OverflowError) as exc:
        raise InputError(f"{p}: {what} ({type(exc).__name__}: {exc})") from None
    if tab.shape != (len(angles), tws.size) or any(v.shape != tws.shape for v in optima.values()):
        raise InputError(
            f"{p}: ORC vpp block: every list must have one value per wind speed ({tws.size})"
        )
    _orc_check(p, "vpp.speeds", tws, 0.0, math.inf, "a wind speed >= 0 kn")
    for i, k in enumerate(keys):
        _orc_check(p, f"vpp[{k!r}]", tab[i], 0.0, math.inf, "a boat speed >= 0 kn")
    _orc_check(
        p,
        "vpp.beat_angle",
        optima["beat_angle"],
        0.0,
        90.0,
        "an angle in (0, 90) deg",
        open_ends=True,
    )
    _orc_check(
        p,
        "vpp.run_angle",
        optima["run_angle"],
        90.0,
        180.0,
        "an angle in (90, 180] deg",
        open_ends=(True, False),
    )
    for k in ("beat_vmg", "run_vmg"):
        _orc_check(p, f"vpp.{k}", optima[k], 0.0, math.inf, "a VMG >= 0 kn")
    if _well_formed(np.asarray(angles), tws, tab):
        _check_table(
            str(p),
            np.asarray(angles),
            tws,
            tab,
            "kn",
            "kn",
            at_twa=lambda i: f"{p}: vpp.angles[{i}]",
            at_tws=lambda j: f"{p}: vpp.speeds[{j}]",
            at_cell=lambda i, j: f"{p}: vpp[{keys[i]!r}][{j}]",
        )
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


def _orc_polar(
    p: Path, twa: NDArray, tws_kn: NDArray, tab_kn: NDArray, name: str, interpolation: str
) -> Polar:
    try:
        return Polar.from_arrays(
            twa,
            tws_kn * speed_factor("kn"),
            tab_kn * speed_factor("kn"),
            name=name,
            interpolation=interpolation,
        )
    except InputError as exc:
        raise InputError(f"{p}: {exc}") from None


def _orc_check(
    p: Path,
    key: str,
    values: NDArray,
    lo: float,
    hi: float,
    expected: str,
    open_ends: bool | tuple[bool, bool] = False,
) -> None:
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
