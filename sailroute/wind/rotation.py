"""Rotations of wind vectors: WRF grid-relative -> earth-relative -> local frame.

WRF writes ``U``/``V``/``U10``/``V10`` along its grid axes.  On a Lambert or
polar-stereographic grid the grid's +y axis is not true north; the angle is
``COSALPHA``/``SINALPHA`` in the file, or follows from the projection's cone
factor (wrf-python ``uvmet``).  Then the earth-relative vector is rotated by the
local frame's meridian convergence (:meth:`sailroute.geo.LocalFrame.grid_north_deg`).

All angles in degrees; vectors are ``(u, v)`` = (east, north) air motion [m s⁻¹].
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.errors import WindDataError
from sailroute.geo import wrap_lon


def rotate_clockwise(
    u: ArrayLike, v: ArrayLike, angle_deg: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Rotate vectors clockwise (as a compass bearing increases) by ``angle_deg``.

    Parameters
    ----------
    u, v : array_like
        East and north components [any unit].
    angle_deg : array_like
        Clockwise rotation [°]; a vector pointing north rotated by 90 points east.

    Returns
    -------
    u, v : ndarray
        Rotated components (float64, broadcast shape).
    """
    a = np.radians(np.asarray(angle_deg, dtype=float))
    return rotate_by(u, v, np.cos(a), np.sin(a))


def rotate_by(
    u: ArrayLike, v: ArrayLike, cos: ArrayLike, sin: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """:func:`rotate_clockwise` given the cosine and sine of the angle (broadcast): the
    same numbers, with the trigonometry done once per angle rather than per vector."""
    u = np.asarray(u, dtype=float)
    v = np.asarray(v, dtype=float)
    c = np.asarray(cos, dtype=float)
    s = np.asarray(sin, dtype=float)
    return u * c + v * s, v * c - u * s


def grid_to_earth(
    u: ArrayLike, v: ArrayLike, cosalpha: ArrayLike, sinalpha: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Earth-relative wind from WRF grid-relative wind (as wrf-python ``uvmet``).

    ``u_e = u cos α − v sin α``, ``v_e = v cos α + u sin α``.

    Parameters
    ----------
    u, v : array_like
        Grid-relative components [m s⁻¹] (along the grid's x and y axes).
    cosalpha, sinalpha : array_like
        WRF ``COSALPHA``/``SINALPHA`` (or :func:`rotation_from_cone`).

    Returns
    -------
    u_e, v_e : ndarray
        True east/north components [m s⁻¹].
    """
    u = np.asarray(u, dtype=float)
    v = np.asarray(v, dtype=float)
    c = np.asarray(cosalpha, dtype=float)
    s = np.asarray(sinalpha, dtype=float)
    return u * c - v * s, v * c + u * s


def earth_to_grid(
    u_e: ArrayLike, v_e: ArrayLike, cosalpha: ArrayLike, sinalpha: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Inverse of :func:`grid_to_earth` (used to write synthetic wrfout files)."""
    u_e = np.asarray(u_e, dtype=float)
    v_e = np.asarray(v_e, dtype=float)
    c = np.asarray(cosalpha, dtype=float)
    s = np.asarray(sinalpha, dtype=float)
    return u_e * c + v_e * s, v_e * c - u_e * s


def cone_factor(map_proj: int, truelat1: float = 0.0, truelat2: float = 0.0) -> float:
    """Cone factor of a WRF map projection (wrf-python ``uvmet``).

    Parameters
    ----------
    map_proj : int
        WRF ``MAP_PROJ``: 1 Lambert conformal, 2 polar stereographic, 3 Mercator,
        6 regular latitude-longitude (0 is treated like 6).
    truelat1, truelat2 : float
        ``TRUELAT1``/``TRUELAT2`` [°] (Lambert only).

    Returns
    -------
    float
        ``n`` such that grid north deviates from true north by ``n (λ − λ0)``:
        Lambert ``(ln cos φ1 − ln cos φ2) / (ln tan(45 − |φ1|/2) − ln tan(45 − |φ2|/2))``
        (``sin |φ1|`` when the true latitudes coincide), 1 for polar stereographic,
        0 for Mercator and latitude-longitude grids.

    Raises
    ------
    WindDataError
        For an unknown ``MAP_PROJ``.
    """
    if map_proj == 1:
        r = math.pi / 180.0
        if abs(truelat1 - truelat2) > 0.1 and abs(truelat2 - 90.0) > 0.1:
            num = math.log(math.cos(truelat1 * r)) - math.log(math.cos(truelat2 * r))
            den = math.log(math.tan((45.0 - abs(truelat1) / 2.0) * r)) - math.log(
                math.tan((45.0 - abs(truelat2) / 2.0) * r)
            )
            return num / den
        return math.sin(abs(truelat1) * r)
    if map_proj == 2:
        return 1.0
    if map_proj in (0, 3, 6):
        return 0.0
    raise WindDataError(
        f"MAP_PROJ = {map_proj} is not supported; expected 1 (Lambert), 2 (polar "
        "stereographic), 3 (Mercator) or 6 (lat-lon), or COSALPHA/SINALPHA in the file"
    )


def rotation_from_cone(
    lat: ArrayLike, lon: ArrayLike, cone: float, stand_lon: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``COSALPHA``/``SINALPHA`` computed from the cone factor (wrf-python ``uvmet``).

    The grid's +y axis points ``cone (λ − λ0)`` degrees east of true north in the
    northern hemisphere (the sign flips where ``lat < 0``, as in wrf-python), so
    ``α = −cone (λ − λ0)``.

    Parameters
    ----------
    lat, lon : array_like
        Cell-centre coordinates [°].
    cone : float
        From :func:`cone_factor`.
    stand_lon : float
        ``STAND_LON`` [°].

    Returns
    -------
    cosalpha, sinalpha : ndarray
    """
    lat = np.asarray(lat, dtype=float)
    dlon = wrap_lon(np.asarray(lon, dtype=float) - stand_lon)
    a = np.radians(np.where(lat < 0.0, -1.0, 1.0) * dlon * cone)
    return np.cos(a), -np.sin(a)


def earth_to_local(
    u_e: ArrayLike, v_e: ArrayLike, grid_north_deg: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Express a true east/north vector in the local frame.

    Parameters
    ----------
    u_e, v_e : array_like
        True east/north components [m s⁻¹].
    grid_north_deg : array_like
        Angle from local +y to true north [°] at the vector's position
        (:meth:`sailroute.geo.LocalFrame.grid_north_deg`).

    Returns
    -------
    u, v : ndarray
        Local-frame components [m s⁻¹].
    """
    return rotate_clockwise(u_e, v_e, grid_north_deg)
