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
from sailroute.checks import Checker, Problems, join_path, split_where
from sailroute.errors import InputError

BANDS: Final = ("upwind", "reach", "downwind")
"""Keys of an ``efficiency`` mapping."""
BOUNDARIES_DEG: Final = (70.0, 120.0)
"""TWA boundaries upwind|reach and reach|downwind [°]."""
BLEND_HALF_WIDTH_DEG: Final = 10.0
"""Half-width of the linear blend around each boundary [°]."""
MAX_FACTOR: Final = 1.5
"""Largest accepted factor."""


def efficiency_factor(
    twa_deg: ArrayLike, upwind: float = 1.0, reach: float = 1.0, downwind: float = 1.0
) -> NDArray[np.float64]:
    """Speed factor at TWA [°] (sign ignored) for the given band factors."""
    a = np.abs(np.asarray(twa_deg, dtype=float))
    b1, b2 = BOUNDARIES_DEG
    h = BLEND_HALF_WIDTH_DEG
    w_up = np.clip((b1 + h - a) / (2 * h), 0.0, 1.0)
    w_dn = np.clip((a - (b2 - h)) / (2 * h), 0.0, 1.0)
    return w_up * upwind + w_dn * downwind + (1.0 - w_up - w_dn) * reach


def scale_polar(
    polar: Polar,
    upwind: float = 1.0,
    reach: float = 1.0,
    downwind: float = 1.0,
    *,
    max_factor: float = MAX_FACTOR,
    key: str = "efficiency",
) -> Polar:
    """A new :class:`Polar` with speeds scaled by point of sail (module docstring).

    Parameters
    ----------
    polar : Polar
        The polar to scale.
    upwind, reach, downwind : float
        Factors in (0, ``max_factor``] for TWA < 70°, 70-120° and > 120°.
    max_factor : float
        Largest accepted factor (a course's ``efficiency``: :data:`MAX_FACTOR`).
    key : str
        Names the factors in the error message.

    Returns
    -------
    Polar
        Same TWS columns and interpolation; TWA rows plus the blend corners
        inside the table's range.  All factors 1 returns ``polar`` itself.
    """
    for k, v in (("upwind", upwind), ("reach", reach), ("downwind", downwind)):
        if not (np.isfinite(v) and 0.0 < v <= max_factor):
            raise InputError(f"{key}.{k}: expected a factor in (0, {max_factor:g}]; got {v}")
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
    return Polar.from_arrays(
        twa, polar.tws_ms, tab * f[:, None], name=polar.name, interpolation=polar.interpolation
    )


def check_efficiency(c: Checker, value: Any) -> dict[str, float] | None:
    """Check an ``efficiency`` value (the mapping at ``c.path``), recording problems in ``c``.

    Parameters
    ----------
    c : Checker
        Checker of the ``efficiency`` key path (e.g. ``boat.efficiency``); its
        :class:`~sailroute.checks.Problems` collects the problems with the rest
        of the file's.
    value : Any
        The parsed value.

    Returns
    -------
    dict of str to float or None
        The given factors by band (``upwind``, ``reach``, ``downwind``; absent or
        null ones left out, so they count as 1.0), or None after a problem.
    """
    if not c.is_mapping(value, "a mapping like {upwind: 0.92, reach: 1.0, downwind: 1.0}"):
        return None
    before = len(c.p)
    c.keys(value, BANDS)
    out = {}
    for k in BANDS:
        v = c.number(
            value,
            k,
            None,
            lo=0.0,
            hi=MAX_FACTOR,
            lo_open=True,
            what=f"a speed factor in (0, {MAX_FACTOR:g}] (1.0 = the polar as is)",
        )
        if v is not None:
            out[k] = v
    return out if len(c.p) == before else None


def efficiency_from_spec(
    value: Any, *, where: str, key: str = "boat.efficiency", lines: Mapping[str, int] | None = None
) -> dict[str, float]:
    """Check a course file's ``efficiency`` value and return the given factors.

    Parameters
    ----------
    value : Any
        The parsed value, e.g. ``{upwind: 0.92}``.
    where : str
        File label for messages (``"courses/x.yaml"``, or ``"file:LINE"``).
    key : str
        Key path of ``value`` in the file.
    lines : mapping of str to int, optional
        1-based line of each key path of the file (the course's line map).

    Returns
    -------
    dict of str to float
        Factors by band; absent bands are left out (1.0).

    Raises
    ------
    InputError
        Not a mapping, an unknown key (with a did-you-mean), or a factor that is not
        a number in (0, 1.5]; every problem listed with its key path and line, in
        the wording of :mod:`sailroute.checks`.
    """
    file, line, root = split_where(where)
    known = dict(lines or {})
    path = join_path(root, key) if root else key
    if line is not None:
        known.setdefault(path, line)
    probs = Problems(file, known, root=path, what="efficiency spec")
    out = check_efficiency(Checker(probs, path), value)
    probs.raise_if_any()
    assert out is not None
    return out


def band_factors(
    twa_deg: NDArray, ratio: NDArray, *, percentile: float = 75.0, min_count: int = 30
) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Upwind, reach and downwind percentiles of speed ratios (a polar's scale to data).

    The factors a polar is scaled by to match what was sailed, band by band
    (:data:`BANDS`): ``analyze --reference fleet``
    (:mod:`sailroute.analysis.fleetpolar`) from the fleet's points, ``polar fit --shape``
    (:mod:`sailroute.boat.learn`) from the learned cells.

    Parameters
    ----------
    twa_deg : ndarray
        TWA of each point [°] (sign ignored).
    ratio : ndarray
        SOG / polar at each point [-]; non-finite and non-positive values are left out.
    percentile : float
        Percentile of each band's ratios [%].
    min_count : int
        Points a band needs to set its own factor.

    Returns
    -------
    factor, count : ndarray, shape (3,)
        Factors (a band with fewer than ``min_count`` points: the mean of the others)
        and point counts.

    Raises
    ------
    InputError
        A bad percentile, or no band with enough points.
    """
    if not 0.0 < percentile <= 100.0:
        raise InputError(f"fleet polar: percentile must be in (0, 100]; got {percentile}")
    a = np.abs(np.asarray(twa_deg, float))
    r = np.asarray(ratio, float)
    ok = np.isfinite(a) & np.isfinite(r) & (r > 0)
    band = np.digitize(a[ok], BOUNDARIES_DEG)  # 0 upwind, 1 reach, 2 downwind
    count = np.bincount(band, minlength=3).astype(np.int64)
    factor = np.array(
        [
            float(np.percentile(r[ok][band == k], percentile)) if count[k] >= min_count else np.nan
            for k in range(3)
        ]
    )
    if not np.isfinite(factor).any():
        raise InputError(
            f"fleet polar: no point of sail has {min_count} straight-line points "
            f"(upwind {count[0]}, reach {count[1]}, downwind {count[2]}); analyse more or "
            "longer tracks, or judge against the course's polar (--reference course)"
        )
    return np.where(np.isfinite(factor), factor, np.nanmean(factor)), count
