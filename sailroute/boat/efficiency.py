"""Scale a polar by point of sail: the ``efficiency`` key of a course's ``boat:`` block.

``efficiency: {upwind: 0.92, reach: 1.0, downwind: 1.0}`` multiplies the polar's
boat speeds by a factor that depends on the TWA only:

* **upwind** below 70°, **reach** from 70° to 120°, **downwind** above 120°;
* between neighbouring bands the factor blends linearly over ±10° around the
  boundary: ``upwind`` up to 60°, ``upwind -> reach`` from 60° to 80°, ``reach``
  from 80° to 110°, ``reach -> downwind`` from 110° to 130°, ``downwind`` from 130°.

Rows at the blend corners (60, 80, 110, 130°) are added to the table where it has
none inside its TWA range (their speeds from the unscaled polar), so that the
factor between rows follows the bands rather than the table's row spacing.
Missing keys count as 1.0; each factor must lie in (0, 1.5].
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Final

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.boat.polar import Polar
from sailroute.errors import InputError, format_problems

BANDS: Final = ("upwind", "reach", "downwind")
"""Keys of an ``efficiency`` mapping."""
BOUNDARIES_DEG: Final = (70.0, 120.0)
"""TWA boundaries upwind|reach and reach|downwind [°]."""
BLEND_HALF_WIDTH_DEG: Final = 10.0
"""Half-width of the linear blend around each boundary [°]."""
MAX_FACTOR: Final = 1.5
"""Largest accepted factor."""


def efficiency_factor(twa_deg: ArrayLike, upwind: float = 1.0, reach: float = 1.0,
                      downwind: float = 1.0) -> NDArray[np.float64]:
    """Speed factor at TWA [°] (sign ignored) for the given band factors."""
    a = np.abs(np.asarray(twa_deg, dtype=float))
    b1, b2 = BOUNDARIES_DEG
    h = BLEND_HALF_WIDTH_DEG
    w_up = np.clip((b1 + h - a) / (2 * h), 0.0, 1.0)
    w_dn = np.clip((a - (b2 - h)) / (2 * h), 0.0, 1.0)
    return w_up * upwind + w_dn * downwind + (1.0 - w_up - w_dn) * reach


def scale_polar(polar: Polar, upwind: float = 1.0, reach: float = 1.0,
                downwind: float = 1.0) -> Polar:
    """A new :class:`Polar` with speeds scaled by point of sail (module docstring).

    Parameters
    ----------
    polar : Polar
        The polar to scale.
    upwind, reach, downwind : float
        Factors in (0, 1.5] for TWA < 70°, 70-120° and > 120°.

    Returns
    -------
    Polar
        Same TWS columns and interpolation; TWA rows plus the blend corners
        inside the table's range.  All factors 1 returns ``polar`` itself.
    """
    for k, v in (("upwind", upwind), ("reach", reach), ("downwind", downwind)):
        if not (np.isfinite(v) and 0.0 < v <= MAX_FACTOR):
            raise InputError(f"efficiency.{k}: expected a factor in (0, {MAX_FACTOR:g}]; got {v}")
    if upwind == reach == downwind == 1.0:
        return polar
    b1, b2 = BOUNDARIES_DEG
    h = BLEND_HALF_WIDTH_DEG
    corners = np.array([b1 - h, b1 + h, b2 - h, b2 + h])
    twa = polar.twa_deg
    new = corners[(corners > twa[0]) & (corners < twa[-1]) & ~np.isin(corners, twa)]
    tab = polar.speed_ms
    if new.size:
        rows = polar.speed(polar.tws_ms[None, :], new[:, None])
        all_twa = np.concatenate([twa, new])
        order = np.argsort(all_twa)
        twa, tab = all_twa[order], np.vstack([tab, rows])[order]
    f = efficiency_factor(twa, upwind, reach, downwind)
    return Polar.from_arrays(twa, polar.tws_ms, tab * f[:, None], name=polar.name,
                             interpolation=polar.interpolation)


def efficiency_from_spec(value: Any, *, where: str, key: str = "boat.efficiency"
                         ) -> dict[str, float]:
    """Check a course file's ``efficiency`` value and return the three factors.

    Raises
    ------
    InputError
        Not a mapping, an unknown key, or a factor that is not a number in
        (0, 1.5]; every problem listed with its key path.
    """
    if not isinstance(value, Mapping):
        raise InputError(f"{where}: {key}: expected a mapping like {{upwind: 0.92, reach: 1.0, "
                         f"downwind: 1.0}}; got {type(value).__name__} {value!r}")
    problems = []
    out = {}
    for k, v in value.items():
        if k not in BANDS:
            problems.append(f"{key}.{k}: unknown key; allowed: "
                            + ", ".join(map(repr, BANDS)))
            continue
        ok = isinstance(v, (int, float)) and not isinstance(v, bool) and np.isfinite(v)
        if not ok or not 0.0 < v <= MAX_FACTOR:
            problems.append(f"{key}.{k}: expected a speed factor in (0, {MAX_FACTOR:g}] "
                            f"(1.0 = the polar as is); got {v!r}")
            continue
        out[k] = float(v)
    if len(problems) == 1:
        raise InputError(f"{where}: {problems[0]}")
    if problems:
        raise InputError(format_problems(f"{where}: {len(problems)} problems", problems))
    return out
