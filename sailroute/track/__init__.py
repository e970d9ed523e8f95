"""Sailed tracks: read GPS tracks and instrument logs, derive speed and course over ground.

* :func:`sailroute.track.read.read_track` reads GPX 1.0/1.1 and CSV logs into a
  :class:`sailroute.track.model.Track` (UTC epoch seconds, degrees, SI channels).
* :func:`sailroute.track.kinematics.sog_cog` gives speed and course over ground from the
  positions (central differences in the course's local frame).
"""

from sailroute.track.kinematics import sog_cog, track_xy
from sailroute.track.model import CHANNELS, Track
from sailroute.track.read import read_track

__all__ = ["CHANNELS", "Track", "read_track", "sog_cog", "track_xy"]
