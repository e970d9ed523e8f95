"""Units and angle conventions, decided once (see ``docs/nomenclature.md``).

* Inside the package everything is SI: metres, seconds, m s⁻¹.
* Angles are degrees in files and in the public API.
* Wind direction (TWD) is the compass direction the wind comes FROM, in
  degrees clockwise from true north, in ``[0, 360)``; calm has direction 0.
* Wind vectors ``(u, v)`` are the eastward and northward components of the air
  velocity (the direction the air moves TO), in m s⁻¹, in the local frame.
* Heading/bearing: compass degrees clockwise from north, in ``[0, 360)``.
* Signed true wind angle ``twa = wrap180(twd - heading)``: positive means the
  wind comes over the starboard side (starboard tack), negative over port
  (port tack).  ``|twa|`` in ``[0, 180]``.
"""

from __future__ import annotations

from typing import Final

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.errors import InputError

KNOT: Final = 1852.0 / 3600.0
"""One knot in m s⁻¹ (international nautical mile, 1852 m)."""
KMH: Final = 1000.0 / 3600.0
"""One km h⁻¹ in m s⁻¹."""
MPH: Final = 1609.344 / 3600.0
"""One statute mile per hour in m s⁻¹."""

SPEED_UNITS: Final[dict[str, float]] = {
    "m/s": 1.0,
    "ms": 1.0,
    "mps": 1.0,
    "kn": KNOT,
    "kt": KNOT,
    "kts": KNOT,
    "knots": KNOT,
    "km/h": KMH,
    "kmh": KMH,
    "kph": KMH,
    "mph": MPH,
}
"""Accepted speed-unit spellings and their factor to m s⁻¹."""

CALM_MS: Final = 1e-9
"""Speeds at or below this [m s⁻¹] count as calm (direction reported as 0)."""


def speed_factor(unit: str) -> float:
    """Return the factor that converts ``unit`` to m s⁻¹.

    Parameters
    ----------
    unit : str
        One of ``m/s``, ``kn``, ``km/h``, ``mph`` (aliases in :data:`SPEED_UNITS`).

    Returns
    -------
    float
        Multiply a value in ``unit`` by this to get m s⁻¹.

    Raises
    ------
    InputError
        If the unit is unknown; the message lists the valid spellings.
    """
    key = unit.strip().lower()
    if key not in SPEED_UNITS:
        raise InputError(f"unknown speed unit {unit!r}; expected one of 'm/s', 'kn', 'km/h', 'mph'")
    return SPEED_UNITS[key]


def to_ms(value: ArrayLike, unit: str) -> NDArray[np.float64]:
    """Convert a speed from ``unit`` to m s⁻¹."""
    return np.asarray(value, dtype=float) * speed_factor(unit)


def from_ms(value: ArrayLike, unit: str) -> NDArray[np.float64]:
    """Convert a speed from m s⁻¹ to ``unit``."""
    return np.asarray(value, dtype=float) / speed_factor(unit)


def wrap360(angle_deg: ArrayLike) -> NDArray[np.float64]:
    """Wrap angles to ``[0, 360)`` degrees."""
    a = np.mod(np.asarray(angle_deg, dtype=float), 360.0)
    return np.where(a >= 360.0, 0.0, a)


def wrap180(angle_deg: ArrayLike) -> NDArray[np.float64]:
    """Wrap angles to ``(-180, 180]`` degrees."""
    a = np.asarray(angle_deg, dtype=float)
    w = 180.0 - np.mod(180.0 - a, 360.0)
    return w


def wind_components(speed_ms: ArrayLike, twd_deg: ArrayLike) -> tuple[NDArray, NDArray]:
    """Wind vector ``(u, v)`` from speed and FROM-direction.

    Parameters
    ----------
    speed_ms : array_like
        Wind speed [m s⁻¹].
    twd_deg : array_like
        Direction the wind comes from [° clockwise from north].

    Returns
    -------
    u, v : ndarray
        Eastward and northward air velocity [m s⁻¹].  A north wind
        (``twd = 0``) blows towards the south: ``u = 0, v = -speed``.
    """
    s = np.asarray(speed_ms, dtype=float)
    d = np.radians(np.asarray(twd_deg, dtype=float))
    return -s * np.sin(d), -s * np.cos(d)


def wind_speed_direction(u: ArrayLike, v: ArrayLike) -> tuple[NDArray, NDArray]:
    """Speed and FROM-direction from a wind vector.

    Parameters
    ----------
    u, v : array_like
        Eastward and northward air velocity [m s⁻¹].

    Returns
    -------
    speed : ndarray
        [m s⁻¹].
    twd : ndarray
        Direction the wind comes from [°], in ``[0, 360)``; 0 for calm.
    """
    u = np.asarray(u, dtype=float)
    v = np.asarray(v, dtype=float)
    speed = np.hypot(u, v)
    twd = wrap360(np.degrees(np.arctan2(-u, -v)))
    return speed, np.where(speed <= CALM_MS, 0.0, twd)


def bearing_deg(dx: ArrayLike, dy: ArrayLike) -> NDArray[np.float64]:
    """Compass bearing [°, clockwise from north, ``[0, 360)``] of an (east, north) step."""
    return wrap360(np.degrees(np.arctan2(np.asarray(dx, float), np.asarray(dy, float))))


def heading_unit(heading_deg: ArrayLike) -> tuple[NDArray, NDArray]:
    """East and north components of a unit vector along a compass heading."""
    h = np.radians(np.asarray(heading_deg, dtype=float))
    return np.sin(h), np.cos(h)


def signed_twa(twd_deg: ArrayLike, heading_deg: ArrayLike) -> NDArray[np.float64]:
    """Signed true wind angle ``wrap180(twd - heading)`` [°].

    Positive: wind over the starboard side (starboard tack); negative: port tack.
    """
    return wrap180(np.asarray(twd_deg, float) - np.asarray(heading_deg, float))


def circular_mean_deg(angles_deg: ArrayLike, weights: ArrayLike | None = None) -> float:
    """Weighted circular mean of directions [°], in ``[0, 360)``."""
    a = np.radians(np.asarray(angles_deg, dtype=float))
    w = np.ones_like(a) if weights is None else np.asarray(weights, dtype=float)
    return float(wrap360(np.degrees(np.arctan2(np.sum(w * np.sin(a)), np.sum(w * np.cos(a))))))
