"""A wind whose speed comes from one field and whose direction comes from another.

Tracks without instruments tell the wind's *direction* well (tacking angles, upwind
courses) and its *speed* poorly (only through a polar, which may be a stand-in); a
forecast, a station or a sailor's estimate gives a speed.  :class:`SpeedDirectionWind`
joins the two: TWS from ``speed_from``, TWD from ``direction_from``, both sampled at the
same points.  It covers what both cover.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.units import wind_components, wind_speed_direction
from sailroute.wind.base import Coverage, WindField


@dataclass(frozen=True, eq=False)
class SpeedDirectionWind:
    """TWS of one field with the TWD of another.

    Parameters
    ----------
    speed_from : WindField
        Gives the speed [m s⁻¹].
    direction_from : WindField
        Gives the direction (from, °); its speed is ignored.
    name : str
        Label for messages.
    """

    speed_from: WindField
    direction_from: WindField
    name: str = "combined wind"

    @property
    def coverage(self) -> Coverage:
        """The intersection of the coverages of the parts that do not clamp."""
        parts = [
            f.coverage
            for f in (self.speed_from, self.direction_from)
            if not getattr(f, "clamp", False)
        ] or [self.speed_from.coverage]
        return Coverage(
            max(c.t0 for c in parts),
            min(c.t1 for c in parts),
            max(c.xmin for c in parts),
            min(c.xmax for c in parts),
            max(c.ymin for c in parts),
            min(c.ymax for c in parts),
            frame=self.speed_from.coverage.frame or self.direction_from.coverage.frame,
        )

    @property
    def clamp(self) -> bool:
        """Clamps only when both parts do."""
        return bool(
            getattr(self.speed_from, "clamp", False)
            and getattr(self.direction_from, "clamp", False)
        )

    def sample(
        self, t: ArrayLike, x: ArrayLike, y: ArrayLike
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Wind ``(u, v)`` [m s⁻¹] at epoch ``t`` [s], local ``x, y`` [m] (broadcast).

        Raises
        ------
        OutOfCoverageError
            Either part does not cover a point (its own message).
        """
        su, sv = self.speed_from.sample(t, x, y)
        du, dv = self.direction_from.sample(t, x, y)
        speed, _ = wind_speed_direction(su, sv)
        _, direction = wind_speed_direction(du, dv)
        return wind_components(speed, direction)


__all__ = ["SpeedDirectionWind"]
