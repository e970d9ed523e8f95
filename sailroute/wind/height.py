"""Wind speed versus height: power and log laws, shear-exponent fit, WRF level heights.

Pure vectorised functions.  Heights are metres above the surface (sea level
over water).  Thesis eq 2.1: ``V(z) = V(z_r) (z / z_r)^α``; the log law
``V(z) = V(z_r) ln(z / z0) / ln(z_r / z0)`` is offered as an alternative.
"""

from __future__ import annotations

from typing import Final

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.errors import InputError

G_WRF: Final = 9.81
"""Gravity used by WRF to turn geopotential into height [m s⁻²]."""

DEFAULT_EXPONENT: Final = 1.0 / 7.0
"""Fallback power-law exponent (neutral surface layer, thesis §1.2) [-]."""

DEFAULT_EXPONENT_RANGE: Final = (0.0, 0.6)
"""Fitted exponents outside this range are replaced by the fallback [-]."""

DEFAULT_ROUGHNESS_M: Final = 2.0e-4
"""Sea-surface roughness length for the log law [m] (open sea, moderate wind)."""

MIN_FIT_SPEED_MS: Final = 0.5
"""Below this speed at either level the exponent fit is not trusted [m s⁻¹]."""


def power_law_factor(z_ref: ArrayLike, z: ArrayLike, alpha: ArrayLike) -> NDArray[np.float64]:
    """Factor ``(z / z_ref)^α`` that turns a speed at ``z_ref`` into one at ``z``.

    Parameters
    ----------
    z_ref, z : array_like
        Reference and target heights [m], > 0.
    alpha : array_like
        Shear exponent [-].

    Returns
    -------
    ndarray
        Multiplicative factor [-].
    """
    z_ref, z = _positive_heights(z_ref, z)
    return np.power(z / z_ref, np.asarray(alpha, dtype=float))


def power_law(
    speed: ArrayLike, z_ref: ArrayLike, z: ArrayLike, alpha: ArrayLike
) -> NDArray[np.float64]:
    """Speed at height ``z`` from the speed at ``z_ref``: ``V (z / z_ref)^α`` [same unit]."""
    return np.asarray(speed, dtype=float) * power_law_factor(z_ref, z, alpha)


def log_law_factor(
    z_ref: ArrayLike, z: ArrayLike, roughness_m: ArrayLike = DEFAULT_ROUGHNESS_M
) -> NDArray[np.float64]:
    """Factor ``ln(z / z0) / ln(z_ref / z0)`` of the neutral logarithmic profile.

    Parameters
    ----------
    z_ref, z : array_like
        Reference and target heights [m], both > ``roughness_m``.
    roughness_m : array_like
        Roughness length ``z0`` [m] (about 2e-4 m over open sea).

    Returns
    -------
    ndarray
        Multiplicative factor [-].
    """
    z_ref, z = _positive_heights(z_ref, z)
    z0 = np.asarray(roughness_m, dtype=float)
    if np.any(z0 <= 0) or np.any(z <= z0) or np.any(z_ref <= z0):
        raise InputError(
            "log law: heights must exceed the roughness length "
            f"(z0 = {np.min(z0):g} m); use a smaller roughness_m or the power law"
        )
    return np.log(z / z0) / np.log(z_ref / z0)


def log_law(
    speed: ArrayLike, z_ref: ArrayLike, z: ArrayLike, roughness_m: ArrayLike = DEFAULT_ROUGHNESS_M
) -> NDArray[np.float64]:
    """Speed at ``z`` from the speed at ``z_ref`` with the log law [same unit]."""
    return np.asarray(speed, dtype=float) * log_law_factor(z_ref, z, roughness_m)


def power_law_exponent(
    s1: ArrayLike, z1: ArrayLike, s2: ArrayLike, z2: ArrayLike
) -> NDArray[np.float64]:
    """Exponent through two (height, speed) points: ``ln(s2/s1) / ln(z2/z1)``.

    NaN where either speed is not positive or the heights coincide.
    """
    s1 = np.asarray(s1, dtype=float)
    s2 = np.asarray(s2, dtype=float)
    z1 = np.asarray(z1, dtype=float)
    z2 = np.asarray(z2, dtype=float)
    ok = (s1 > 0) & (s2 > 0) & (z1 > 0) & (z2 > 0) & (z1 != z2)
    with np.errstate(divide="ignore", invalid="ignore"):
        a = np.log(np.where(ok, s2, 1.0) / np.where(ok, s1, 1.0)) / np.log(
            np.where(ok, z2, 2.0) / np.where(ok, z1, 1.0)
        )
    return np.where(ok, a, np.nan)


def fit_power_exponent(
    s1: ArrayLike,
    z1: ArrayLike,
    s2: ArrayLike,
    z2: ArrayLike,
    *,
    exponent_range: tuple[float, float] = DEFAULT_EXPONENT_RANGE,
    min_speed_ms: float = MIN_FIT_SPEED_MS,
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Per-point shear exponent from two levels, with a usability mask.

    Parameters
    ----------
    s1, s2 : array_like
        Speeds [m s⁻¹] at the lower and upper level.
    z1, z2 : array_like
        Heights [m] of the two levels.
    exponent_range : (float, float)
        Accepted ``[α_min, α_max]``; fits outside are unusable.
    min_speed_ms : float
        Fits where either speed is below this are unusable (ratio of two small,
        noisy speeds) [m s⁻¹].

    Returns
    -------
    alpha : ndarray
        Fitted exponents (NaN where the heights/speeds make no fit).
    usable : ndarray of bool
        True where ``alpha`` is finite, inside the range and both speeds are large enough.
    """
    lo, hi = exponent_range
    a = power_law_exponent(s1, z1, s2, z2)
    usable = (
        np.isfinite(a)
        & (a >= lo)
        & (a <= hi)
        & (np.asarray(s1, dtype=float) >= min_speed_ms)
        & (np.asarray(s2, dtype=float) >= min_speed_ms)
    )
    return a, usable


def destagger(a: ArrayLike, axis: int) -> NDArray[np.float64]:
    """Average neighbours along a staggered axis (thesis eqs 3.5/3.6).

    ``out[..., i, ...] = (a[..., i, ...] + a[..., i + 1, ...]) / 2``; the axis
    shrinks by one.
    """
    a = np.asarray(a, dtype=float)
    n = a.shape[axis]
    lo = np.take(a, np.arange(n - 1), axis=axis)
    hi = np.take(a, np.arange(1, n), axis=axis)
    return 0.5 * (lo + hi)


def mass_level_heights(
    ph: ArrayLike, phb: ArrayLike, hgt: ArrayLike, *, axis: int = -3, g: float = G_WRF
) -> NDArray[np.float64]:
    """Heights above ground [m] of WRF mass (half) levels.

    ``z = destagger((PH + PHB) / g, vertical) − HGT``.

    Parameters
    ----------
    ph, phb : array_like
        Perturbation and base geopotential on full (``bottom_top_stag``) levels [m² s⁻²].
    hgt : array_like
        Terrain height [m], broadcastable to one vertical level.
    axis : int
        Vertical axis of ``ph``/``phb`` (default: third from last, WRF layout).
    g : float
        Gravity [m s⁻²] (WRF uses 9.81).

    Returns
    -------
    ndarray
        Heights above ground on mass levels [m]; the vertical axis shrinks by one.
    """
    z_full = (np.asarray(ph, dtype=float) + np.asarray(phb, dtype=float)) / g
    z_mass = destagger(z_full, axis=axis)
    h = np.expand_dims(np.asarray(hgt, dtype=float), axis=axis)
    return z_mass - h


def _positive_heights(z_ref: ArrayLike, z: ArrayLike) -> tuple[NDArray, NDArray]:
    z_ref = np.asarray(z_ref, dtype=float)
    z = np.asarray(z, dtype=float)
    if np.any(~(z_ref > 0)) or np.any(~(z > 0)):
        raise InputError(
            "wind height correction: heights must be positive metres above the surface, got "
            f"reference {np.min(z_ref):g} m and target {np.min(z):g} m"
        )
    return z_ref, z
