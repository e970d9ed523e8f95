"""The :class:`Track` type: a sailed track, cleaned, in UTC epoch seconds and degrees.

Measured channels (from instrument logs) are kept in SI units and sailroute's
conventions (``docs/nomenclature.md``): speeds in m s⁻¹, angles in degrees, ``twd``
the direction the wind comes **from**, ``twa``/``awa`` signed with + = wind over the
starboard side (starboard tack).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Final

import numpy as np
from numpy.typing import NDArray

CHANNELS: Final[dict[str, str]] = {
    "sog_ms": "speed over ground [m s⁻¹]",
    "cog_deg": "course over ground [° compass]",
    "hdg_deg": "heading [° compass]",
    "bsp_ms": "boat speed through the water [m s⁻¹]",
    "tws_ms": "true wind speed [m s⁻¹]",
    "twa_deg": "signed true wind angle [°], + = starboard tack",
    "twd_deg": "true wind direction, from [° compass]",
    "aws_ms": "apparent wind speed [m s⁻¹]",
    "awa_deg": "signed apparent wind angle [°], + = wind over starboard",
}
"""Optional measured channels of a :class:`Track` and their units."""


@dataclass(frozen=True, eq=False)
class Track:
    """A sailed track: positions in time, plus optional measured channels.

    Attributes
    ----------
    t_s : ndarray
        Time [UTC epoch s], strictly increasing.
    lat_deg, lon_deg : ndarray
        Position [°] (WGS-84); longitude wrapped to ``[-180, 180)``.
    name : str
        Boat or track name (the GPX ``<trk><name>``, or the file stem).
    source : str
        The file it was read from.
    channels : mapping of str to ndarray
        Measured channels by name (:data:`CHANNELS`), same length as ``t_s``; NaN
        where the log had no value.
    notes : tuple of str
        What cleaning did ("dropped 3 duplicate timestamps", "gap of 125 s at ...").
    """

    t_s: NDArray[np.float64]
    lat_deg: NDArray[np.float64]
    lon_deg: NDArray[np.float64]
    name: str = ""
    source: str = ""
    channels: Mapping[str, NDArray[np.float64]] = field(
        default_factory=lambda: MappingProxyType({})
    )
    notes: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if not isinstance(self.channels, MappingProxyType):
            raise TypeError(
                "Track.channels must be a read-only mapping (types.MappingProxyType), got "
                f"{type(self.channels).__name__}; pass MappingProxyType(dict(channels))"
            )
        if not isinstance(self.notes, tuple):
            raise TypeError(
                f"Track.notes must be a tuple of str, got {type(self.notes).__name__}; "
                "pass tuple(notes)"
            )

    def __len__(self) -> int:
        return int(self.t_s.size)

    @property
    def t_start(self) -> float:
        """First time [epoch s]."""
        return float(self.t_s[0])

    @property
    def t_end(self) -> float:
        """Last time [epoch s]."""
        return float(self.t_s[-1])

    def between(self, t0: float, t1: float) -> Track:
        """The points with ``t0 <= t <= t1`` [epoch s] (same name, source and notes)."""
        m = (self.t_s >= t0) & (self.t_s <= t1)
        return Track(
            self.t_s[m],
            self.lat_deg[m],
            self.lon_deg[m],
            self.name,
            self.source,
            MappingProxyType({k: v[m] for k, v in self.channels.items()}),
            self.notes,
        )
