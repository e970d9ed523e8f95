"""Speed and course over ground from track positions (functional core)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from sailroute.geo import LocalFrame
from sailroute.track.model import Track
from sailroute.units import bearing_deg


def track_xy(track: Track, frame: LocalFrame) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Positions of ``track`` in the local frame ``(x, y)`` [m east, m north]."""
    return frame.to_xy(track.lat_deg, track.lon_deg)


def velocity(t_s: NDArray, x: NDArray, y: NDArray) -> tuple[NDArray, NDArray]:
    """Velocity ``(vx, vy)`` [m s⁻¹] by central differences on uneven times.

    Second-order central differences inside (``numpy.gradient`` with the times as
    coordinates), one-sided at the ends; fewer than two points give zeros.
    """
    t = np.asarray(t_s, float)
    if t.size < 2:
        return np.zeros_like(t), np.zeros_like(t)
    return np.gradient(np.asarray(x, float), t), np.gradient(np.asarray(y, float), t)


def sog_cog(track: Track, frame: LocalFrame) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Speed and course over ground from the positions.

    Parameters
    ----------
    track : Track
        The track.
    frame : LocalFrame
        Local metric frame (the course's: ``Course.frame``).

    Returns
    -------
    sog_ms : ndarray
        Speed over ground [m s⁻¹].
    cog_deg : ndarray
        Course over ground [° compass, in [0, 360)]; 0 where the boat stands still.

    Notes
    -----
    Positions are projected to the local frame (:meth:`LocalFrame.to_xy`) and
    differentiated with central differences in time, which are second-order
    accurate also on irregular sampling.  Across a gap in the log the speed is the
    mean over the gap.
    """
    x, y = track_xy(track, frame)
    vx, vy = velocity(track.t_s, x, y)
    return np.hypot(vx, vy), bearing_deg(vx, vy)
