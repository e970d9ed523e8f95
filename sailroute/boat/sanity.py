"""Does the boat fit the wind?  Checks run once per scenario before routing.

The polar's edge semantics (``docs/design/boat.md``) clamp TWS above the highest
column to that column: a course in 30 kn with a polar that ends at 28 kn would be
routed as if the wind were 28 kn, silently.  :func:`check_wind_range` samples the
scenario's wind over the course area and the race time and refuses that, unless
the course says ``boat: {..., allow_extrapolation: true}`` (then it returns a
warning to print).  :func:`require_speed` refuses a polar without any positive
boat speed.  See ``docs/usage.md``, "Polar sanity".
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final

import numpy as np

from sailroute.boat.polar import Polar
from sailroute.errors import InputError
from sailroute.timeutil import iso
from sailroute.units import KNOT, wind_speed_direction
from sailroute.wind.base import WindField

GRID_POINTS: Final = 25
"""Sample points per side of the course area (a 25 x 25 grid)."""
N_TIMES: Final = 5
"""Fewest sample times, evenly spread over the race time window (ends included)."""
TIME_STEP_S: Final = 300.0
"""Largest spacing of the sample times [s] (more times than :data:`N_TIMES` for long
races), capped at :data:`MAX_TIMES`."""
MAX_TIMES: Final = 49
MARGIN_FRACTION: Final = 0.25
"""Margin around the marks' bounding box, as a fraction of its larger side."""
MIN_MARGIN_M: Final = 200.0
"""Smallest margin around the marks' bounding box [m]."""
TOLERANCE_MS: Final = 1e-6
"""Wind this little above the last column [m s⁻¹] is rounding, not extrapolation."""


@dataclass(frozen=True)
class WindPeak:
    """The strongest wind found by :func:`peak_wind`.

    Attributes
    ----------
    tws_ms : float
        True wind speed [m s⁻¹].
    t : float
        When [epoch s].
    x, y : float
        Where, in the course's local frame [m].
    """

    tws_ms: float
    t: float
    x: float
    y: float


def peak_wind(
    wind: WindField,
    bbox: tuple[float, float, float, float],
    time_window: tuple[float, float],
    *,
    n_points: int = GRID_POINTS,
    n_times: int = N_TIMES,
) -> WindPeak:
    """Strongest TWS on a grid over ``bbox`` (plus a margin) at times over ``time_window``.

    Parameters
    ----------
    wind : WindField
        The scenario's wind.
    bbox : tuple of float
        ``(xmin, xmax, ymin, ymax)`` of the marks [m]; grown by
        ``max(MARGIN_FRACTION * larger side, MIN_MARGIN_M)`` and clipped to the
        field's coverage.
    time_window : tuple of float
        ``(start, end)`` of the race [epoch s], clipped to the coverage.
    n_points : int
        Grid points per side.
    n_times : int
        Fewest sample times; more where the window is longer than
        ``(n_times - 1) * TIME_STEP_S`` (one per :data:`TIME_STEP_S`, at most
        :data:`MAX_TIMES`).

    Returns
    -------
    WindPeak
        The sample with the highest TWS.
    """
    c = wind.coverage
    xmin, xmax, ymin, ymax = bbox
    margin = max(MARGIN_FRACTION * max(xmax - xmin, ymax - ymin), MIN_MARGIN_M)

    def span(lo: float, hi: float, c_lo: float, c_hi: float, n: int, grow: float) -> np.ndarray:
        a, b = max(lo - grow, c_lo), min(hi + grow, c_hi)
        if a > b:  # the data do not reach the margin: stay on what they cover
            a, b = min(max(lo, c_lo), c_hi), max(min(hi, c_hi), c_lo)
        return np.linspace(a, b, n)

    xs = span(xmin, xmax, c.xmin, c.xmax, n_points, margin)
    ys = span(ymin, ymax, c.ymin, c.ymax, n_points, margin)
    t0, t1 = min(time_window), max(time_window)
    n_t = min(max(n_times, int(np.ceil((t1 - t0) / TIME_STEP_S)) + 1), MAX_TIMES)
    ts = span(t0, t1, c.t0, c.t1, n_t, 0.0)
    t, x, y = np.meshgrid(ts, xs, ys, indexing="ij")
    # gridded data with land (NaN) cells near the course: the peak is over the sea; the
    # routers themselves refuse to cross a hole (GridWind.sample)
    sample = getattr(wind, "sample_with_holes", wind.sample)
    u, v = sample(t, x, y)
    tws, _ = wind_speed_direction(u, v)
    if not np.isfinite(tws).any():
        return WindPeak(0.0, float(t.flat[0]), float(x.flat[0]), float(y.flat[0]))
    k = int(np.nanargmax(tws))
    return WindPeak(float(tws.flat[k]), float(t.flat[k]), float(x.flat[k]), float(y.flat[k]))


def check_wind_range(
    polar: Polar,
    peak: WindPeak,
    *,
    allow_extrapolation: bool,
    where: str,
) -> str | None:
    """Refuse (or warn about) wind above the polar's highest TWS column.

    Parameters
    ----------
    polar : Polar
        The boat.
    peak : WindPeak
        The scenario's strongest wind (:func:`peak_wind`).
    allow_extrapolation : bool
        The course's ``boat.allow_extrapolation``: warn instead of refusing.
    where : str
        Message prefix naming the course file and scenario.

    Returns
    -------
    str or None
        None if the wind stays within the polar; the warning text if it does
        not and ``allow_extrapolation`` is true.

    Raises
    ------
    InputError
        The wind exceeds the polar and ``allow_extrapolation`` is false.
    """
    top = float(polar.tws_ms[-1])
    if not peak.tws_ms > top + TOLERANCE_MS:
        return None
    lo = float(polar.tws_ms[0])
    name = f"polar {polar.name!r}" if polar.name else "the polar"
    found = (
        f"the wind reaches {peak.tws_ms:.1f} m/s ({peak.tws_ms / KNOT:.1f} kn) at x "
        f"{peak.x:.0f} m, y {peak.y:.0f} m, {iso(peak.t)}, above the highest TWS column of "
        f"{name} (TWS {lo:.2f} .. {top:.2f} m/s, {lo / KNOT:.1f} .. {top / KNOT:.1f} kn)"
    )
    if allow_extrapolation:
        return (
            f"{where}: {found}; boat.allow_extrapolation is true, so the boat sails in "
            f"stronger wind at the speeds of the {top / KNOT:.1f} kn column"
        )
    raise InputError(
        f"{where}: {found}; the boat speed would be clamped to that column without notice. "
        "Use a polar with higher TWS columns, or accept the clamping with "
        "`boat: {..., allow_extrapolation: true}` in the course file"
    )


def require_speed(polar: Polar, where: str) -> None:
    """Refuse a polar whose boat speeds are all zero.

    Raises
    ------
    InputError
        ``"<where>: this polar has no speed: ..."``.
    """
    if not np.any(polar.speed_ms > 0):
        name = f" ({polar.name})" if polar.name else ""
        raise InputError(
            f"{where}: this polar{name} has no speed: every boat speed in it is 0, so the boat "
            "cannot sail in any wind; give a polar file with the boat speeds filled in"
        )
