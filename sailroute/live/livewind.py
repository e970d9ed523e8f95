"""The wind a live re-plan routes in: the measured wind now, fading to the forecast ahead.

The measured wind now comes from :class:`sailroute.live.windest.WindEstimator`.
:class:`LiveWind` is a :class:`~sailroute.wind.base.WindField`: the course scenario's
wind (the forecast) corrected by the measured wind, the correction fading with the time
ahead::

    r = |measured| / |forecast(now, boat)|      δ = TWD_measured − TWD_forecast(now, boat)
    w(t) = exp(−max(t − now, 0) / τ)
    wind(t, x, y) = forecast(t, x, y) scaled by r^w and turned clockwise by w δ

so the route starts in the measured wind (w = 1) and ends in the forecast (w → 0)
after a few ``τ`` (``fade_s``, default 600 s: a shift measured now is trusted for about
ten minutes, roughly one beat of a dinghy windward leg).  The correction is uniform in
space, like the wind of one moving sensor (:func:`sailroute.wind.measured.boat_wind`),
and keeps the forecast's spatial pattern and its trend.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.geo import LocalFrame
from sailroute.units import wind_components, wind_speed_direction, wrap180
from sailroute.wind.base import Coverage, WindField
from sailroute.wind.measured import true_wind
from sailroute.wind.rotation import earth_to_local, rotate_clockwise

DEFAULT_FADE_S: float = 600.0
"""Default e-folding time of the measured wind's weight ahead [s] (:class:`LiveWind`)."""
MIN_SPEED_MS: float = 0.2
"""Floor of the forecast speed in the speed ratio [m s⁻¹] (no division by a calm)."""


def apparent_to_true(
    aws_ms: float, awa_deg: float, sog_ms: float, cog_deg: float, hdg_deg: float | None
) -> tuple[float, float]:
    """True wind over the ground from apparent wind, SOG/COG and heading.

    The formula (``docs/nomenclature.md``, "Apparent and true wind") is
    :func:`sailroute.wind.measured.true_wind`: the apparent wind vector, turned from the
    bow (heading, or COG when no heading is known) by ``awa``, plus the boat's velocity
    over the ground.

    Returns
    -------
    tws_ms : float
        True wind speed [m s⁻¹].
    twd_deg : float
        Direction it comes from [° true].
    """
    tws, twd = true_wind(aws_ms, awa_deg, sog_ms, cog_deg, heading_deg=hdg_deg)
    return float(tws), float(twd)


@dataclass(frozen=True, eq=False)
class LiveWind:
    """The forecast corrected by the wind measured now, the correction fading ahead.

    Parameters
    ----------
    forecast : WindField
        The course scenario's wind.
    now : float
        Time of the measurement [epoch s].
    x, y : float
        Where it was measured (the boat) [m, course frame].
    tws_ms, twd_deg : float
        The measured wind [m s⁻¹, ° from, earth-true].
    frame : LocalFrame
        The course frame (turns the measured direction into the frame's north).
    fade_s : float
        E-folding time of the correction ahead [s].
    """

    forecast: WindField
    now: float
    x: float
    y: float
    tws_ms: float
    twd_deg: float
    frame: LocalFrame
    fade_s: float = DEFAULT_FADE_S

    @cached_property
    def _correction(self) -> tuple[float, float]:
        """``(ln r, δ [°])`` at the boat now."""
        mu, mv = wind_components(self.tws_ms, self.twd_deg)
        lat, lon = self.frame.to_latlon(self.x, self.y)
        ul, vl = earth_to_local(mu, mv, self.frame.grid_north_deg(lat, lon))
        ms, md = wind_speed_direction(ul, vl)
        fu, fv = self.forecast.sample(self.now, self.x, self.y)
        fs, fd = wind_speed_direction(fu, fv)
        log_r = np.log(max(float(ms), MIN_SPEED_MS) / max(float(fs), MIN_SPEED_MS))
        return float(log_r), float(wrap180(float(md) - float(fd)))

    @property
    def coverage(self) -> Coverage:
        """The forecast's coverage."""
        return self.forecast.coverage

    @property
    def clamp(self) -> bool:
        """The forecast's clamp mode."""
        return self.forecast.clamp

    def weight(self, t: ArrayLike) -> NDArray[np.float64]:
        """Weight ``w`` of the measured correction at epoch ``t`` (1 now and before)."""
        dt = np.maximum(np.asarray(t, dtype=float) - self.now, 0.0)
        return np.exp(-dt / self.fade_s)

    def sample(self, t: ArrayLike, x: ArrayLike, y: ArrayLike) -> tuple[NDArray, NDArray]:
        """Wind ``(u, v)`` [m s⁻¹] at epoch ``t`` [s], position ``x, y`` [m] (broadcast)."""
        u, v = self.forecast.sample(t, x, y)
        log_r, delta = self._correction
        w = np.broadcast_to(self.weight(t), np.shape(u))
        scale = np.exp(w * log_r)
        ru, rv = rotate_clockwise(u, v, w * delta)
        return np.asarray(ru * scale, float), np.asarray(rv * scale, float)
