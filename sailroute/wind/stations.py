"""Measured wind from stations (fixed anemometers, buoys, coach boats): read, resample, field.

* :func:`read_stations` reads a CSV with the canonical columns ``time`` (ISO 8601
  with offset), ``station``, ``lat``, ``lon``, ``speed``, ``direction`` (from,
  °T) and optional ``height_m``, ``gust``; other headers are mapped through
  :data:`COLUMN_ALIASES` or an explicit ``columns`` mapping.  Missing-value
  markers are counted and their rows dropped.
* :func:`resample_stations` averages 1-20 Hz logs into fixed intervals: scalar
  mean speed, vector-mean direction.
* :class:`StationWind` interpolates the stations in space (inverse distance or
  scipy RBF) and linearly in time, inside the stations' box plus ``radius_m``.

A station whose position changes (a coach boat) is one moving station; its
position is interpolated in time like its wind.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.errors import InputError, OutOfCoverageError, WindDataError
from sailroute.geo import LocalFrame
from sailroute.tabular import (
    CANONICAL_COLUMNS,
    COLUMN_ALIASES,
    DEFAULT_MISSING,
    REQUIRED_COLUMNS,
    TIME_PARTS,
    column_speed_unit,
    map_columns,
    parse_offset,
    time_part_columns,
    unit_from_header,
)
from sailroute.timeutil import iso
from sailroute.wind.base import Coverage, prepare_points
from sailroute.wind.height import (
    DEFAULT_EXPONENT,
    DEFAULT_ROUGHNESS_M,
    log_law_factor,
    power_law_factor,
)
from sailroute.wind.rotation import earth_to_local
from sailroute.wind.stationread import StationData, read_stations, resample_stations

__all__ = [
    "CANONICAL_COLUMNS",
    "COLUMN_ALIASES",
    "DEFAULT_MISSING",
    "REQUIRED_COLUMNS",
    "TIME_PARTS",
    "RbfKernel",
    "StationData",
    "StationWind",
    "column_speed_unit",
    "idw_weights",
    "local_records",
    "map_columns",
    "parse_offset",
    "read_stations",
    "resample_stations",
    "time_part_columns",
    "unit_from_header",
]


def local_records(
    data: StationData,
    frame: LocalFrame,
    height_m: float | None,
    name: str,
    *,
    shear: str = "power",
    exponent: float = DEFAULT_EXPONENT,
    roughness_m: float = DEFAULT_ROUGHNESS_M,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Positions and winds of the records in the local frame, at a target height.

    Parameters
    ----------
    data : StationData
        Station records.
    frame : LocalFrame
        The local frame.
    height_m : float or None
        Target height [m]; each record is scaled from its ``height_m`` with the
        power law (``exponent``) or the log law (``shear="log"``, ``roughness_m``).
        ``None``: as measured.
    name : str
        Label for messages.
    shear : {"power", "log"}
        Height-correction law.
    exponent : float
        Power-law exponent [-].
    roughness_m : float
        Log-law roughness length [m].

    Returns
    -------
    x, y : ndarray
        Record positions [m].
    u, v : ndarray
        Record winds, local-frame components [m s⁻¹].

    Raises
    ------
    InputError
        ``height_m`` is set but a record's measurement height is unknown.
    """
    x, y = frame.to_xy(data.lat, data.lon)
    ue, ve = data.u, data.v
    if height_m is not None:
        if np.any(np.isnan(data.height_m)):
            raise InputError(
                f"{name}: a target height_m is set but the measurement height is unknown "
                f"for {data.source or 'the stations'}; add a height_m column or give the "
                "stations' height (`measurement_height_m`)"
            )
        f = (
            power_law_factor(data.height_m, height_m, exponent)
            if shear == "power"
            else log_law_factor(data.height_m, height_m, roughness_m)
        )
        ue, ve = ue * f, ve * f
    u, v = earth_to_local(ue, ve, frame.grid_north_deg(data.lat, data.lon))
    return x, y, u, v


RbfKernel = Literal[
    "thin_plate_spline",
    "linear",
    "cubic",
    "quintic",
    "multiquadric",
    "inverse_multiquadric",
    "inverse_quadratic",
    "gaussian",
]
"""Kernel names of :class:`scipy.interpolate.RBFInterpolator`."""


@dataclass(frozen=True, eq=False)
class _StationState:
    """What a :class:`StationWind` derives from its inputs (built once, when it is made)."""

    series: tuple  # per station: (id, t, x, y, u, v) arrays in the local frame
    cov: Coverage
    moving: bool  # some station moves (coach boat)
    rbf: Any  # RBF interpolator of station weights (method "rbf"), else None
    limit: str = ""  # which station's records limit the common time span ("" if one station)


@dataclass(frozen=True, eq=False)
class StationWind:
    """Wind field interpolated from station records.

    Parameters
    ----------
    data : StationData
        The records (resample high-rate logs first).
    frame : LocalFrame
        The course's local frame.
    method : {"idw", "rbf"}
        Spatial interpolation: inverse-distance weighting (``power``), or a scipy
        :class:`~scipy.interpolate.RBFInterpolator` (``rbf_kernel``; fixed
        stations only).  Both reproduce a station's value at its position and a
        constant wind exactly.
    power : float
        IDW exponent (2: weights ``1/d²``).
    radius_m : float
        Coverage = the stations' bounding box (every recorded position) expanded
        by this [m].  Far from the stations an interpolant is an extrapolation,
        which was the thesis's main failure, so the box is kept tight.
    max_gap_s : float
        A station whose records are further apart than this inside the common
        time span is an error (no silent bridging of outages) [s].
    height_m : float, optional
        Target height [m]; records are scaled from their ``height_m`` with the
        power law (``exponent``) or log law (``shear="log"``).  ``None``: as measured.
    shear : {"power", "log"}
    exponent : float
        Power-law exponent for the height correction [-].
    roughness_m : float
        Log-law roughness length [m].
    rbf_kernel : str
        Kernel for ``method="rbf"`` (see scipy; :data:`RbfKernel`).
    clamp : bool
        Clamp points to the coverage instead of raising.
    name : str
        Label for messages.
    time_window : (float, float), optional
        The race window [epoch s].  Gaps longer than ``max_gap_s`` are then an
        error only inside it: a month-long record with an outage a week before
        the race is usable, and the coverage is the gap-free stretch around the
        window.  ``None``: every gap inside the stations' common span counts.

    Notes
    -----
    Coverage in time is the span during which *every* station reports (the
    intersection), so no station drops out mid-race.  Between records each
    station's ``(u, v)`` (and position) is interpolated linearly in time.
    """

    data: StationData
    frame: LocalFrame
    method: str = "idw"
    power: float = 2.0
    radius_m: float = 2000.0
    max_gap_s: float = 1800.0
    height_m: float | None = None
    shear: str = "power"
    exponent: float = DEFAULT_EXPONENT
    roughness_m: float = DEFAULT_ROUGHNESS_M
    rbf_kernel: RbfKernel = "thin_plate_spline"
    clamp: bool = False
    name: str = "station wind"
    time_window: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        self._state  # noqa: B018  (built now: building it checks the inputs)

    @cached_property
    def _state(self) -> _StationState:
        """Per-station series, coverage and interpolator (checked and built once)."""
        d = self.data
        if len(d) == 0:
            raise WindDataError(f"{self.name}: no station records")
        if self.method not in ("idw", "rbf"):
            raise InputError(f"{self.name}: method {self.method!r}; expected 'idw' or 'rbf'")
        if self.shear not in ("power", "log"):
            raise InputError(f"{self.name}: shear {self.shear!r}; expected 'power' or 'log'")
        if not (self.radius_m >= 0) or not (self.power > 0) or not (self.max_gap_s > 0):
            raise InputError(f"{self.name}: radius_m must be >= 0, power and max_gap_s > 0")
        x, y, ul, vl = local_records(
            d,
            self.frame,
            self.height_m,
            self.name,
            shear=self.shear,
            exponent=self.exponent,
            roughness_m=self.roughness_m,
        )
        series = []
        moving = False
        for s in d.stations:
            m = d.station == s
            ts = d.t[m]
            moving |= bool(np.ptp(x[m]) > 1e-6 or np.ptp(y[m]) > 1e-6)
            series.append((s, ts, x[m], y[m], ul[m], vl[m]))
        spans = [
            _gap_free_span(ts, self.time_window, self.max_gap_s)
            if self.time_window is not None
            else (float(ts[0]), float(ts[-1]))
            for _, ts, *_ in series
        ]
        t0 = max(a for a, _ in spans)
        t1 = min(b for _, b in spans)
        if t0 > t1:
            spans_txt = "; ".join(
                f"{s[0]}: {iso(a)} .. {iso(b)}" for s, (a, b) in zip(series, spans, strict=True)
            )
            raise WindDataError(
                f"{self.name}: the stations never report at the same time ({spans_txt}); "
                "use stations with overlapping records"
            )
        lo, hi = (
            (t0, t1)
            if self.time_window is None
            else (max(t0, self.time_window[0]), min(t1, self.time_window[1]))
        )
        for s, ts, *_ in series:
            if lo > hi:
                break
            if self.time_window is None:
                edges = np.concatenate([[lo], ts[(ts >= lo) & (ts <= hi)], [hi]])
            else:  # the records around the window too: a gap is bridged from record to record
                k0 = max(int(np.searchsorted(ts, lo, side="right")) - 1, 0)
                k1 = int(np.searchsorted(ts, hi, side="left")) + 1
                edges = ts[k0:k1]
            gaps = np.diff(edges)
            if gaps.size and gaps.max() > self.max_gap_s:
                k = int(np.argmax(gaps))
                where = "" if self.time_window is None else " inside the race window"
                raise WindDataError(
                    f"{self.name}: station {s!r} has no record from {iso(edges[k])} to "
                    f"{iso(edges[k + 1])}{where} ({gaps[k] / 60:.0f} min > max_gap_s "
                    f"{self.max_gap_s / 60:.0f} min); the wind there would be a guess. "
                    "Restrict the race window, drop that station, or raise max_gap_s."
                )
        rbf = None
        if self.method == "rbf":
            if moving:
                raise InputError(
                    f"{self.name}: method 'rbf' needs fixed stations; a station "
                    "moves (coach boat?) -- use method 'idw'"
                )
            from scipy.interpolate import RBFInterpolator

            pts = np.array([[s[2][0], s[3][0]] for s in series])
            # A degree-1 polynomial needs 3 non-collinear stations; with fewer, use the
            # linear kernel with a constant term (still exact at the stations).
            kernel: RbfKernel = self.rbf_kernel if len(series) >= 3 else "linear"
            deg = None if len(series) >= 3 else 0
            try:
                rbf = RBFInterpolator(pts, np.eye(len(series)), kernel=kernel, degree=deg)
            except (ValueError, np.linalg.LinAlgError) as exc:
                raise InputError(
                    f"{self.name}: RBF interpolation failed for these stations "
                    f"({exc}); use method 'idw'"
                ) from None
        cov = Coverage(
            t0,
            t1,
            float(x.min()) - self.radius_m,
            float(x.max()) + self.radius_m,
            float(y.min()) - self.radius_m,
            float(y.max()) + self.radius_m,
            frame=self.frame,
            source_span=(float(d.t.min()), float(d.t.max())),
        )
        limit = ""
        if len(series) > 1:
            k0 = max(range(len(spans)), key=lambda k: spans[k][0])
            k1 = min(range(len(spans)), key=lambda k: spans[k][1])
            src = f" of {d.source}" if d.source else ""
            limit = (
                f"the time span is limited by station {series[k0][0]!r}{src} (first record "
                f"{iso(spans[k0][0])}) and station {series[k1][0]!r} (last record "
                f"{iso(spans[k1][1])})"
            )
        return _StationState(tuple(series), cov, moving, rbf, limit)

    @property
    def coverage(self) -> Coverage:
        """Common time span of the stations; their box plus ``radius_m``."""
        return self._state.cov

    def station_values(self, t: NDArray) -> tuple[NDArray, NDArray, NDArray, NDArray]:
        """Per-station ``(x, y, u, v)`` interpolated at times ``t``, each shape ``(n, S)``."""
        cols: list[list[NDArray]] = [[], [], [], []]
        moving = self._state.moving
        for _, ts, xs, ys, us, vs in self._state.series:
            for c, a, moves in zip(
                cols, (xs, ys, us, vs), (moving, moving, True, True), strict=True
            ):
                if not moves or a.size == 1:
                    c.append(np.full(t.shape, a[0]))
                else:
                    c.append(np.interp(t, ts, a))
        x, y, u, v = (np.stack(c, axis=-1) for c in cols)
        return x, y, u, v

    @property
    def station_ids(self) -> tuple[str, ...]:
        """Station ids in the order of the weight columns."""
        return tuple(s[0] for s in self._state.series)

    def weights(self, t: ArrayLike, x: ArrayLike, y: ArrayLike) -> NDArray:
        """Normalised spatial weights ``(n, S)`` of the stations at points ``(t, x, y)``.

        Points are flattened; no coverage check (used by :class:`BlendedWind`-style
        diagnostics).
        """
        t, x, y = (
            a.ravel()
            for a in np.broadcast_arrays(
                np.asarray(t, float), np.asarray(x, float), np.asarray(y, float)
            )
        )
        if self._state.rbf is not None:
            return self._state.rbf(np.column_stack([x, y]))
        sx, sy, _, _ = self.station_values(t)
        return idw_weights(x, y, sx, sy, self.power)

    def sample(self, t: ArrayLike, x: ArrayLike, y: ArrayLike) -> tuple[NDArray, NDArray]:
        """Wind ``(u, v)`` [m s⁻¹] at epoch ``t`` [s] and local ``x, y`` [m] (broadcast).

        Outside the coverage the :class:`~sailroute.errors.OutOfCoverageError` names
        the stations (logs) whose first and last records limit the common time span.
        """
        try:
            t, x, y = prepare_points(self._state.cov, t, x, y, clamp=self.clamp, name=self.name)
        except OutOfCoverageError as e:
            if not self._state.limit:
                raise
            raise OutOfCoverageError(f"{e}\n  ({self._state.limit})") from None
        shape = t.shape
        t, x, y = t.ravel(), x.ravel(), y.ravel()
        sx, sy, su, sv = self.station_values(t)
        if self._state.rbf is not None:
            w = self._state.rbf(np.column_stack([x, y]))
        elif len(self._state.series) == 1:
            w = np.ones((t.size, 1))
        else:
            w = idw_weights(x, y, sx, sy, self.power)
        u = np.einsum("ns,ns->n", w, su)
        v = np.einsum("ns,ns->n", w, sv)
        return u.reshape(shape), v.reshape(shape)


def _gap_free_span(
    ts: NDArray, window: tuple[float, float], max_gap_s: float
) -> tuple[float, float]:
    """The stretch of records around ``window`` without a gap longer than ``max_gap_s``.

    Gaps that overlap the window itself are left in (the caller reports them);
    a window outside the records gives the whole record (the coverage check
    then reports it).
    """
    cut = np.nonzero(np.diff(ts) > max_gap_s)[0]
    starts = np.concatenate([[0], cut + 1])
    ends = np.concatenate([cut, [ts.size - 1]])
    w0, w1 = window
    first = int(np.searchsorted(ts[ends], w0, side="left"))  # first stretch ending >= w0
    last = int(np.searchsorted(ts[starts], w1, side="right")) - 1  # last starting <= w1
    if first >= starts.size or last < 0 or first > last:
        return float(ts[0]), float(ts[-1])
    return float(ts[starts[first]]), float(ts[ends[last]])


def idw_weights(
    x: NDArray, y: NDArray, sx: NDArray, sy: NDArray, power: float = 2.0
) -> NDArray[np.float64]:
    """Inverse-distance weights ``(n, S)`` normalised to sum 1 per point.

    Parameters
    ----------
    x, y : ndarray (n,)
        Points [m].
    sx, sy : ndarray (n, S) or (1, S)
        Station positions [m].
    power : float
        Exponent ``p`` in ``w = 1 / d^p``.

    Returns
    -------
    ndarray (n, S)
        A point on a station gets weight 1 for it (to within 1e-12).
    """
    d2 = (x[:, None] - sx) ** 2 + (y[:, None] - sy) ** 2
    d2 = np.maximum(d2, 1e-24)
    w = d2 ** (-0.5 * power) if power != 2.0 else 1.0 / d2
    return w / w.sum(axis=1, keepdims=True)
