"""A leg's wind mode (upwind / reach / downwind) that does not flip on a noisy wind.

The course sets each leg's mode: its bearing against the wind it was laid in (the
scenario's, ``course.geometry.wind_mode``: upwind when Ω <= 45°, downwind when Ω >= 135°).
A wind estimated during the race (inferred from tracks, or measured at one instant) may
put the leg in another mode; :func:`leg_mode` takes that mode only when the estimate is
sure of it: when Ω ± ``Z`` standard errors lies wholly inside the other mode's band.
Otherwise the course's mode holds, and the result says the estimate could not tell.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final

import numpy as np

from sailroute.analysis.windsource import WindSource
from sailroute.course.geometry import (
    DOWNWIND_MIN_DEG,
    UPWIND_MAX_DEG,
    WindMode,
    nominal_legs,
    omega_deg,
    wind_mode,
    xy_bearing_deg,
)
from sailroute.course.model import Course
from sailroute.errors import InputError
from sailroute.units import wind_speed_direction
from sailroute.wind.base import WindField

Z: Final = 2.0
"""The estimate changes a leg's mode only when Ω lies this many standard errors inside the
new mode's band [-]."""


@dataclass(frozen=True)
class LegMode:
    """A leg's mode and how it was decided.

    Attributes
    ----------
    mode : str
        The mode to use: ``upwind``, ``reach`` or ``downwind``.
    geometric : str or None
        The mode in the wind the course was laid in (None: no such wind given).
    estimated : str or None
        The mode in the estimated wind (None: no estimate).
    sure : bool
        The estimate's Ω ± ``Z`` sd lies wholly inside ``estimated``'s band.
    omega_deg : float
        Ω of the leg in the estimated wind [°] (NaN without an estimate).
    omega_sd_deg : float
        Its standard error [°].
    note : str
        One line when the estimate changed the mode or disagreed without being sure;
        empty otherwise.
    """

    mode: WindMode
    geometric: WindMode | None
    estimated: WindMode | None
    sure: bool
    omega_deg: float
    omega_sd_deg: float
    note: str = ""


def _sure(mode: WindMode, omega: float, sd: float, z: float) -> bool:
    lo, hi = omega - z * sd, omega + z * sd
    if mode == "upwind":
        return hi <= UPWIND_MAX_DEG
    if mode == "downwind":
        return lo >= DOWNWIND_MIN_DEG
    return lo > UPWIND_MAX_DEG and hi < DOWNWIND_MIN_DEG


def leg_mode(
    course: Course,
    leg: int,
    twd_deg: float,
    twd_sd_deg: float,
    *,
    design_twd_deg: float | None = None,
    from_xy: tuple[float, float] | None = None,
    to_xy: tuple[float, float] | None = None,
    z: float = Z,
) -> LegMode:
    """The wind mode of leg ``leg`` of ``course`` with an estimated TWD and its sd.

    Parameters
    ----------
    course : Course
        The course.
    leg : int
        Leg index, 0-based.
    twd_deg, twd_sd_deg : float
        The estimated TWD at the leg start and its standard error [°] (NaN: no estimate).
    design_twd_deg : float, optional
        The TWD the course was laid in (its scenario's at the leg start) [°]: gives the
        geometric mode, which holds unless the estimate is sure of another.  Without it
        the estimate's mode is used, sure or not.
    from_xy, to_xy : tuple of float, optional
        Leg start and target [m] (default: the course's nominal leg, from the start-line
        midpoint or the previous mark to the target's centre).
    z : float
        Standard errors Ω must lie inside a band to change the mode.

    Returns
    -------
    LegMode

    Raises
    ------
    InputError
        ``leg`` outside the course, or a negative sd.
    """
    if not 0 <= leg < len(course.legs):
        raise InputError(
            f"leg_mode: leg {leg} is not a leg of {course.name!r} (0..{len(course.legs) - 1})"
        )
    if twd_sd_deg < 0:
        raise InputError(f"leg_mode: twd_sd_deg must be >= 0, got {twd_sd_deg}")
    nom = nominal_legs(course)[leg]
    a = nom.from_xy if from_xy is None else from_xy
    b = nom.to_xy if to_xy is None else to_xy
    bearing = xy_bearing_deg(a, b)
    geo = None if design_twd_deg is None else wind_mode(bearing, float(design_twd_deg))
    label = f"leg {leg + 1} ({course.legs[leg].label})"
    if not (np.isfinite(twd_deg) and np.isfinite(twd_sd_deg)):
        if geo is None:
            raise InputError(
                f"leg_mode: {label}: neither an estimated TWD nor the course's wind; "
                "give one of them"
            )
        return LegMode(geo, geo, None, False, float("nan"), float("nan"))
    om = float(omega_deg(bearing, float(twd_deg)))
    est = wind_mode(bearing, float(twd_deg))
    sure = _sure(est, om, float(twd_sd_deg), z)
    if geo is None:
        return LegMode(est, None, est, sure, om, float(twd_sd_deg))
    where = f"{label}: Ω {om:.0f} ± {twd_sd_deg:.0f}° in the estimated wind"
    if est == geo:
        return LegMode(geo, geo, est, sure, om, float(twd_sd_deg))
    if sure:
        note = f"{where}: {est}, not {geo} as in the course's wind"
        return LegMode(est, geo, est, True, om, float(twd_sd_deg), note)
    note = f"{where} does not tell {est} from {geo}: {geo} as in the course's wind"
    return LegMode(geo, geo, est, False, om, float(twd_sd_deg), note)


def _twd_at(field: WindField, t: float, xy: tuple[float, float]) -> float:
    u, v = field.sample(t, xy[0], xy[1])
    return float(wind_speed_direction(u, v)[1])


def source_leg_mode(
    course: Course,
    leg: int,
    source: WindSource,
    design: WindField | None,
    t: float,
    from_xy: tuple[float, float],
    to_xy: tuple[float, float],
) -> LegMode:
    """:func:`leg_mode` with the TWD of a wind source at the leg start (its standard error
    from :meth:`~sailroute.analysis.windsource.WindSource.twd_sd_at`) and the course's
    wind ``design`` (its scenario; None: the source's mode alone)."""
    twd = _twd_at(source.field, t, from_xy)
    geo = None if design is None else _twd_at(design, t, from_xy)
    return leg_mode(
        course,
        leg,
        twd,
        source.twd_sd_at(t),
        design_twd_deg=geo,
        from_xy=from_xy,
        to_xy=to_xy,
    )


__all__ = ["LegMode", "Z", "leg_mode", "source_leg_mode"]
