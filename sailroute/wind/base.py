"""The one contract every wind source implements: :class:`WindField`.

A wind field maps arrays of ``(t, x, y)`` to arrays ``(u, v)``:

* ``t`` epoch seconds [s] (UTC), ``x``/``y`` metres east/north in the course's
  :class:`~sailroute.geo.LocalFrame`;
* ``u``/``v`` eastward/northward air velocity [m s⁻¹] (direction the air moves
  TO; use :func:`sailroute.units.wind_speed_direction` for speed and FROM-direction);
* inputs broadcast against each other (numpy rules); outputs have the
  broadcast shape and dtype float64;
* sampling outside :attr:`WindField.coverage` raises
  :class:`~sailroute.errors.OutOfCoverageError` naming both ranges, unless the
  field was built with ``clamp=True`` (then points are clamped to the edges);
  :attr:`WindField.clamp` says which (routers read it to know whether the coverage
  box bounds the route);
* NaN in ``t``, ``x`` or ``y`` raises :class:`~sailroute.errors.OutOfCoverageError`
  in both modes (never NaN winds out).

``tests/wind/test_field_contract.py`` runs the same checks on every implementation.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.errors import OutOfCoverageError
from sailroute.timeutil import iso

if TYPE_CHECKING:
    from sailroute.geo import LocalFrame


@dataclass(frozen=True)
class Coverage:
    """Where and when a wind field is defined.

    Attributes
    ----------
    t0, t1 : float
        Time span [epoch s]; ``-inf``/``inf`` for time-independent fields.
    xmin, xmax, ymin, ymax : float
        Bounding box in the local frame [m]; infinite for uniform fields.
    frame : LocalFrame, optional
        The local frame, when known: :meth:`describe` then adds the box in
        latitude/longitude (what a user can check against a chart or the file).
    source_span : (float, float), optional
        Time span of the whole source [epoch s] when the field holds only part of
        it (a file cropped to the race window); :meth:`describe` names it.
    """

    t0: float
    t1: float
    xmin: float
    xmax: float
    ymin: float
    ymax: float
    frame: LocalFrame | None = field(default=None, compare=False, repr=False)
    source_span: tuple[float, float] | None = field(default=None, compare=False, repr=False)

    @classmethod
    def everywhere(cls) -> Coverage:
        """Unbounded coverage (uniform, time-independent wind)."""
        inf = float("inf")
        return cls(-inf, inf, -inf, inf, -inf, inf)

    def describe(self) -> str:
        """Human-readable description used in error messages.

        Times in UTC, the box in local metres and, when :attr:`frame` is known, in
        degrees; the source's full time span when it differs from the field's.
        """
        text = f"time {_fmt_t(self.t0)} .. {_fmt_t(self.t1)}, " + (
            f"x {self.xmin:.0f} .. {self.xmax:.0f} m, y {self.ymin:.0f} .. {self.ymax:.0f} m"
        )
        ll = self.latlon_box()
        if ll is not None:
            text += (
                f" (lat {_fmt_lat(ll[0])} .. {_fmt_lat(ll[1])}, "
                f"lon {_fmt_lon(ll[2])} .. {_fmt_lon(ll[3])})"
            )
        if self.source_span is not None and (
            self.source_span[0] != self.t0 or self.source_span[1] != self.t1
        ):
            text += (
                f"; the source holds {_fmt_t(self.source_span[0])} .. {_fmt_t(self.source_span[1])}"
            )
        return text

    def latlon_box(self) -> tuple[float, float, float, float] | None:
        """``(lat_min, lat_max, lon_min, lon_max)`` [°] of the box, or None.

        None without a :attr:`frame` or for an unbounded box.  Computed from the
        box's corners and edge midpoints, so good to a few metres for course-sized boxes.
        """
        if self.frame is None or not all(np.isfinite((self.xmin, self.xmax, self.ymin, self.ymax))):
            return None
        xs = np.array([self.xmin, 0.5 * (self.xmin + self.xmax), self.xmax])
        ys = np.array([self.ymin, 0.5 * (self.ymin + self.ymax), self.ymax])
        lat, lon = self.frame.to_latlon(*np.meshgrid(xs, ys))
        return (float(lat.min()), float(lat.max()), float(lon.min()), float(lon.max()))

    def contains(self, t: ArrayLike, x: ArrayLike, y: ArrayLike) -> NDArray[np.bool_]:
        """Boolean mask of points inside the coverage (edges included)."""
        t = np.asarray(t, dtype=float)
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        return (
            (t >= self.t0)
            & (t <= self.t1)
            & (x >= self.xmin)
            & (x <= self.xmax)
            & (y >= self.ymin)
            & (y <= self.ymax)
        )


def _fmt_t(t: float) -> str:
    return str(t) if not np.isfinite(t) else iso(t)


def _fmt_lat(lat: float) -> str:
    return f"{abs(lat):.4f}°{'N' if lat >= 0 else 'S'}"


def _fmt_lon(lon: float) -> str:
    return f"{abs(lon):.4f}°{'E' if lon >= 0 else 'W'}"


@runtime_checkable
class WindField(Protocol):
    """Protocol of all wind sources (see module docstring for the contract)."""

    @property
    def coverage(self) -> Coverage:
        """Time span and bounding box where :meth:`sample` is defined."""
        ...

    @property
    def clamp(self) -> bool:
        """True: points outside :attr:`coverage` are clamped to its edges; False: they
        raise :class:`~sailroute.errors.OutOfCoverageError`."""
        ...

    def sample(
        self, t: ArrayLike, x: ArrayLike, y: ArrayLike
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Wind ``(u, v)`` [m s⁻¹] at epoch times ``t`` [s] and local positions ``x, y`` [m]."""
        ...


def prepare_points(
    coverage: Coverage,
    t: ArrayLike,
    x: ArrayLike,
    y: ArrayLike,
    *,
    clamp: bool,
    name: str = "wind field",
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Broadcast sample points and enforce coverage.

    Parameters
    ----------
    coverage : Coverage
        The field's coverage.
    t, x, y : array_like
        Requested points [epoch s, m, m].
    clamp : bool
        If True, clip points to the coverage instead of raising.
    name : str
        Field name for the error message.

    Returns
    -------
    t, x, y : ndarray
        Broadcast float64 arrays (clamped if requested).

    Raises
    ------
    OutOfCoverageError
        If any point lies outside and ``clamp`` is False.  The message gives the
        requested range, the covered range and how to opt in to clamping.  NaN
        points raise in both modes: a NaN has no nearest edge to be clamped to,
        and passing it on would give NaN winds (or an invalid grid index).
    """
    t, x, y = np.broadcast_arrays(
        np.asarray(t, dtype=float), np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    )
    c = coverage
    if not t.size:
        return t, x, y
    tmin, xmin, ymin = t.min(), x.min(), y.min()  # NaN-propagating: one pass each
    if np.isnan(tmin) or np.isnan(xmin) or np.isnan(ymin):
        n_bad = int((np.isnan(t) | np.isnan(x) | np.isnan(y)).sum())
        raise OutOfCoverageError(
            f"{name}: {n_bad} of {t.size} sample points contain NaN (time or position); "
            "the caller must pass finite epoch seconds and local metres"
        )
    if clamp:
        return (
            np.clip(t, c.t0, c.t1),
            np.clip(x, c.xmin, c.xmax),
            np.clip(y, c.ymin, c.ymax),
        )
    tmax, xmax, ymax = t.max(), x.max(), y.max()
    if not (
        tmin >= c.t0
        and tmax <= c.t1
        and xmin >= c.xmin
        and xmax <= c.xmax
        and ymin >= c.ymin
        and ymax <= c.ymax
    ):
        bad = ~c.contains(t, x, y)
        requested = Coverage(
            float(tmin),
            float(tmax),
            float(xmin),
            float(xmax),
            float(ymin),
            float(ymax),
            frame=c.frame,
        )
        raise OutOfCoverageError(
            f"{name}: {int(bad.sum())} of {bad.size} sample points lie outside the data.\n"
            f"  requested: {requested.describe()}\n"
            f"  covered:   {c.describe()}\n"
            "  Use wind data that covers the course and race time, or opt in to "
            "clamping at the edges (`clamp: true` in the wind spec)."
        )
    return t, x, y
