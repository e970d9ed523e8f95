"""Where the TWS of a track-inferred wind comes from: an explicit choice.

The tracks give the wind's direction; its speed needs another source (:class:`TwsSource`):

* ``scenario``, ``measured``, ``station``: a TWS series from the course's scenario, the
  boats' instruments or a shore station (:meth:`TwsSource.from_series`,
  :meth:`TwsSource.from_field`), taken as it is;
* ``polar``: the speed in which a polar sails the observed speeds at their TWA
  (:meth:`TwsSource.polar`, :func:`invert_polar`): right only for a boat that sails to
  that polar, and circular where the polar is itself learned from the same tracks;
* ``none``: no speed (NaN).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.boat.model import BoatModel
from sailroute.errors import InputError
from sailroute.units import wind_speed_direction
from sailroute.wind.base import WindField

TWS_KINDS: Final = ("scenario", "measured", "station", "polar", "none")
"""Kinds of TWS source."""


@dataclass(frozen=True, eq=False)
class TwsSource:
    """Where the TWS of an inferred wind comes from.

    Attributes
    ----------
    kind : str
        One of :data:`TWS_KINDS`.
    label : str
        What it is, for notes ("scenario 'race-mean'", "station SR-520").
    t : ndarray or None
        Times of the series [epoch s] (series kinds).
    tws_ms : ndarray or None
        TWS at ``t`` [m s⁻¹].
    sd_ms : ndarray or None
        Its standard error [m s⁻¹] (NaN: unknown).
    boat : BoatModel or None
        The polar to invert (``polar``).
    """

    kind: str
    label: str = ""
    t: NDArray[np.float64] | None = None
    tws_ms: NDArray[np.float64] | None = None
    sd_ms: NDArray[np.float64] | None = None
    boat: BoatModel | None = None

    def __post_init__(self) -> None:
        if self.kind not in TWS_KINDS:
            raise InputError(f"TWS source: kind {self.kind!r} is not one of {', '.join(TWS_KINDS)}")
        if self.kind == "polar" and self.boat is None:
            raise InputError("TWS source 'polar': give the boat whose polar is inverted")
        series = self.kind in ("scenario", "measured", "station")
        if series and (self.t is None or self.tws_ms is None):
            raise InputError(
                f"TWS source {self.kind!r}: give the series (TwsSource.from_series or "
                "TwsSource.from_field)"
            )

    @classmethod
    def polar(cls, boat: BoatModel) -> TwsSource:
        """TWS by inverting ``boat``'s polar at the observed speeds."""
        return cls("polar", f"the polar {getattr(boat, 'name', '')!r}", boat=boat)

    @classmethod
    def none(cls) -> TwsSource:
        """No TWS (NaN)."""
        return cls("none", "none")

    @classmethod
    def from_series(
        cls,
        kind: str,
        t: ArrayLike,
        tws_ms: ArrayLike,
        sd_ms: ArrayLike | None = None,
        label: str = "",
    ) -> TwsSource:
        """A TWS series (``scenario``, ``measured`` or ``station``).

        Parameters
        ----------
        kind : str
            ``scenario``, ``measured`` or ``station``.
        t : array_like
            Increasing times [epoch s].
        tws_ms, sd_ms : array_like
            TWS and its standard error at ``t`` [m s⁻¹] (``sd_ms`` optional).
        label : str
            What it is, for notes.

        Raises
        ------
        InputError
            Another kind, arrays of different lengths, times not increasing, negative or
            non-finite speeds.
        """
        if kind not in ("scenario", "measured", "station"):
            raise InputError(
                f"TWS source from a series: kind must be scenario, measured or station, "
                f"got {kind!r} (use TwsSource.polar(boat) or TwsSource.none())"
            )
        tt = np.atleast_1d(np.asarray(t, float))
        s = np.atleast_1d(np.asarray(tws_ms, float))
        sd = np.full(s.shape, np.nan) if sd_ms is None else np.atleast_1d(np.asarray(sd_ms, float))
        if tt.ndim != 1 or s.shape != tt.shape or sd.shape != tt.shape or tt.size == 0:
            raise InputError(
                f"TWS source {kind!r}: t, tws_ms and sd_ms must be 1-D of one length "
                f"(got {tt.shape}, {s.shape}, {sd.shape})"
            )
        if tt.size > 1 and not np.all(np.diff(tt) > 0):
            raise InputError(f"TWS source {kind!r}: times must increase strictly")
        if not (np.all(np.isfinite(s)) and np.all(s >= 0)):
            raise InputError(f"TWS source {kind!r}: speeds must be finite and >= 0 m/s")
        return cls(kind, label or kind, tt, s, sd)

    @classmethod
    def from_field(
        cls,
        kind: str,
        field: WindField,
        t: ArrayLike,
        xy: tuple[float, float] = (0.0, 0.0),
        label: str = "",
    ) -> TwsSource:
        """The speed of a wind field at one point ``xy`` [m] at times ``t`` [epoch s]."""
        tt = np.atleast_1d(np.asarray(t, float))
        u, v = field.sample(tt, np.full(tt.shape, xy[0]), np.full(tt.shape, xy[1]))
        s, _ = wind_speed_direction(u, v)
        return cls.from_series(kind, tt, np.asarray(s, float), label=label)

    def at(self, t: NDArray) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """TWS and its sd [m s⁻¹] at times ``t`` of a series source (NaN outside its
        span; a single value holds at all times)."""
        if self.t is None or self.tws_ms is None or self.sd_ms is None:
            nan = np.full(np.shape(t), np.nan)
            return nan, nan.copy()
        if self.t.size == 1:
            return np.full(np.shape(t), self.tws_ms[0]), np.full(np.shape(t), self.sd_ms[0])
        out = (t < self.t[0]) | (t > self.t[-1])
        s = np.where(out, np.nan, np.interp(t, self.t, self.tws_ms))
        sd = np.where(out, np.nan, np.interp(t, self.t, self.sd_ms))
        return s, sd


def invert_polar(boat: BoatModel, twa_deg: NDArray, sog_ms: NDArray) -> NDArray[np.float64]:
    """TWS [m s⁻¹] at which the boat's polar sails ``sog_ms`` at ``twa_deg`` (NaN where it
    cannot: faster than the polar's top speed at that angle, or slower than at 0.5 m/s)."""
    grid = np.arange(0.5, 25.01, 0.1)
    ang = np.arange(0.0, 181.0)
    table = np.asarray(boat.steady_speed(grid[None, :], ang[:, None]), float)
    table = np.maximum.accumulate(table, axis=1)  # the rising part of each column
    a = np.clip(np.rint(np.abs(twa_deg)).astype(int), 0, 180)
    sog_ms = np.asarray(sog_ms, float)
    # per point, the speeds of its angle's row below its SOG: the row rises, so they
    # are the first c (one search per angle, not a row of the table per point)
    c = np.zeros(a.size, dtype=np.intp)
    order = np.argsort(a, kind="stable")
    angles, first = np.unique(a[order], return_index=True)
    for k, lo, hi in zip(angles, first, [*first[1:], a.size], strict=True):
        idx = order[lo:hi]
        c[idx] = np.searchsorted(table[k], sog_ms[idx], side="left")
    ok = (c > 0) & (c < grid.size)
    ci = np.clip(c, 1, grid.size - 1)
    s0 = table[a, ci - 1]
    s1 = table[a, ci]
    with np.errstate(invalid="ignore", divide="ignore"):
        f = np.where(s1 > s0, (sog_ms - s0) / (s1 - s0), 0.0)
    return np.where(ok, grid[ci - 1] + f * (grid[ci] - grid[ci - 1]), np.nan)


__all__ = ["TWS_KINDS", "TwsSource", "invert_polar"]
