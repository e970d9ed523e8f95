"""Reader for NOAA NDBC realtime text files (``*.cwind``, standard meteorological ``*.txt``).

Format: whitespace separated, two ``#`` header lines (names, units), newest row
first, times UTC in ``YY MM DD hh mm`` columns, missing values coded as ``MM``
or all-nines (``999`` direction, ``99.0`` speed, ``9999`` time).  Only wind is
kept: ``WDIR`` (from, °T), ``WSPD`` [m s⁻¹] and ``GST`` [m s⁻¹].
"""

from __future__ import annotations

from datetime import UTC, datetime
from pathlib import Path

import numpy as np

from sailroute.errors import InputError, WindDataError
from sailroute.wind.stationread import StationData, _sorted_checked

_MISSING = {"MM", "999", "99.0", "9999", "999.0", "99", "9999.0"}


def is_ndbc_text(path: str | Path) -> bool:
    """True when the file starts with NDBC's ``#YY  MM DD hh mm`` header line."""
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            first = f.readline()
    except OSError:
        return False
    return (
        first.startswith(("#YY", "#yy"))
        and len(first.split()) >= 6
        and ("WDIR" in first.split() or "WSPD" in first.split())
    )


def read_ndbc(
    path: str | Path,
    *,
    position: tuple[float, float],
    station: str | None = None,
    height_m: float | None = None,
) -> StationData:
    """Read the wind columns of an NDBC realtime text file.

    Parameters
    ----------
    path : str or Path
        The ``.cwind`` or ``.txt`` file.
    position : (float, float)
        Buoy ``(lat, lon)`` [°] (the text files do not carry it).
    station : str, optional
        Station id (default: the file name up to the first dot).
    height_m : float, optional
        Anemometer height [m] (see the buoy's NDBC page).

    Returns
    -------
    StationData
        Oldest record first; rows with a missing speed or direction are dropped
        and counted in ``n_missing``.
    """
    p = Path(path)
    name = str(p)
    if not p.is_file():
        raise InputError(f"{name}: NDBC file not found")
    lines = p.read_text(errors="replace").splitlines()
    if not lines or not lines[0].startswith("#"):
        raise WindDataError(
            f"{name}: expected an NDBC header line starting with '#YY  MM DD hh mm'"
        )
    names = lines[0].lstrip("#").split()
    for need in ("YY", "MM", "DD", "hh", "mm", "WDIR", "WSPD"):
        if need not in names:
            raise WindDataError(f"{name}: NDBC header lacks column {need!r} (found {names})")
    col = {n: k for k, n in enumerate(names)}
    rows = [
        (k + 1, ln.split()) for k, ln in enumerate(lines) if ln.strip() and not ln.startswith("#")
    ]
    if not rows:
        raise WindDataError(f"{name}: no data rows")
    n = len(rows)
    t = np.empty(n)
    spd = np.empty(n)
    dirn = np.empty(n)
    gust = np.full(n, np.nan)
    miss = {"speed": 0, "direction": 0, "gust": 0}
    for k, (lineno, f) in enumerate(rows):
        if len(f) != len(names):
            raise WindDataError(f"{name}, line {lineno}: {len(f)} fields, header has {len(names)}")
        try:
            t[k] = datetime(
                int(f[col["YY"]]),
                int(f[col["MM"]]),
                int(f[col["DD"]]),
                int(f[col["hh"]]),
                int(f[col["mm"]]),
                tzinfo=UTC,
            ).timestamp()
        except (ValueError, OverflowError):
            raise WindDataError(
                f"{name}, line {lineno}: cannot read the date/time columns {' '.join(f[:5])!r}"
            ) from None
        for key, arr, c in (
            ("speed", spd, "WSPD"),
            ("direction", dirn, "WDIR"),
            ("gust", gust, "GST"),
        ):
            if c not in col:
                continue
            cell = f[col[c]]
            if cell in _MISSING:
                arr[k] = np.nan
                miss[key] += 1
            else:
                try:
                    arr[k] = float(cell)
                except ValueError:
                    raise WindDataError(
                        f"{name}, line {lineno}, column {c}: cannot read {cell!r} as a number"
                    ) from None
                hi, want = (
                    (360.0, "0..360 degrees")
                    if key == "direction"
                    else (np.inf, "a finite speed >= 0 m/s")
                )
                if not 0.0 <= arr[k] <= hi or np.isinf(arr[k]):
                    raise WindDataError(
                        f"{name}, line {lineno}, column {c}: value {cell!r} is out of range "
                        f"(expected {want}; NDBC codes missing values as MM, 99.0 or 999)"
                    )
    order = np.argsort(t, kind="stable")
    linenos = np.array([r[0] for r in rows])[order]
    t, spd, dirn, gust = t[order], spd[order], dirn[order], gust[order]
    bad = np.isnan(spd) | np.isnan(dirn)
    keep = ~bad
    sid = station if station is not None else p.name.split(".")[0]
    data = StationData(
        station=np.full(int(keep.sum()), sid),
        t=t[keep],
        lat=np.full(int(keep.sum()), float(position[0])),
        lon=np.full(int(keep.sum()), float(position[1])),
        speed_ms=spd[keep],
        direction_deg=np.mod(dirn[keep], 360.0),
        height_m=np.full(int(keep.sum()), np.nan if height_m is None else float(height_m)),
        gust_ms=gust[keep],
        source=name,
        n_raw=n,
        n_missing=int(bad.sum()),
        missing_by_column={k: v for k, v in miss.items() if v},
    )
    return _sorted_checked(data, linenos[keep], name)
