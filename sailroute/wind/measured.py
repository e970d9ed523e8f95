"""Measured wind from boat logs: each log is a moving wind sensor.

* :func:`true_wind` — true wind from apparent wind and the boat's velocity;
* :func:`sensor_from_track` -> :class:`MeasuredSeries` — a :class:`~sailroute.track.Track`
  with wind channels as one moving sensor (smoothed, NaN rows dropped, gaps listed);
* :func:`boat_wind` -> :class:`BoatWind` — one boat's own measured wind as a
  :class:`~sailroute.wind.base.WindField`, uniform in space, linear in time, with
  holes where the log has gaps;
* :func:`fleet_wind` -> :class:`FleetWind` — several boats as one field, with
  per-boat biases (speed factor, direction offset, clock offset) estimated
  against the fleet and a coverage report against the sensors' hull;
* :func:`leave_one_out` — build from all boats but one, predict the one left out.

The defaults (``smooth_s``, ``method``, ``resample_s``) were chosen by the
leave-one-boat-out measurement on the SailGP Auckland 2025 logs; the table and
the command that produces it are in ``docs/measured-wind.md``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING, Final

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.errors import InputError
from sailroute.units import wind_speed_direction, wrap180
from sailroute.wind.base import Coverage, prepare_points

if TYPE_CHECKING:
    from sailroute.geo import LocalFrame
    from sailroute.track.model import Track

from sailroute.wind.boatbias import BoatBias, apply_bias, estimate_biases
from sailroute.wind.fleetfield import FLEET_METHODS, NOISE_FLOOR_MS, FleetField
from sailroute.wind.measuredseries import (
    DEFAULT_MAX_GAP_S,
    DEFAULT_SMOOTH_S,
    MeasuredSeries,
    _as_series,
    find_gaps,
    hole_check,
    resample_series,
    sensor_from_track,
    smooth_vector,
    true_wind,
)

__all__ = [
    "DEFAULT_MAX_GAP_S",
    "DEFAULT_METHOD",
    "DEFAULT_RESAMPLE_S",
    "DEFAULT_SMOOTH_S",
    "FLEET_METHODS",
    "NOISE_FLOOR_MS",
    "BoatBias",
    "BoatWind",
    "FleetField",
    "FleetWind",
    "LooRow",
    "MeasuredSeries",
    "apply_bias",
    "boat_wind",
    "estimate_biases",
    "find_gaps",
    "fleet_wind",
    "hole_check",
    "hull_fraction",
    "leave_one_out",
    "resample_series",
    "sensor_from_track",
    "smooth_vector",
    "true_wind",
]


@dataclass(frozen=True, eq=False)
class BoatWind:
    """One boat's measured wind: uniform in space, linear in time, holes at gaps.

    Parameters
    ----------
    series : MeasuredSeries
        The boat's sensor (:func:`sensor_from_track`).
    frame : LocalFrame
        The course's local frame; the wind is rotated into it at the boat's position.
    clamp : bool
        Clamp times before/after the log to its ends instead of raising (holes
        inside the log raise in both modes).
    name : str, optional
        Label for messages (default: ``"measured wind of <boat>"``).
    """

    series: MeasuredSeries
    frame: LocalFrame
    clamp: bool = False
    name: str = ""

    def __post_init__(self) -> None:
        self._local  # noqa: B018  (built now: building it checks the inputs)

    @cached_property
    def _local(self) -> tuple[NDArray, NDArray]:
        s = self.series
        if len(s) < 1:
            raise InputError(f"{self.label}: the measured series is empty")
        _, _, ul, vl = s.local(self.frame)
        return ul, vl

    @property
    def label(self) -> str:
        """Name used in messages."""
        return self.name or f"measured wind of {self.series.boat}"

    @property
    def coverage(self) -> Coverage:
        """The log's time span; unbounded in space."""
        inf = float("inf")
        return Coverage(
            float(self.series.t[0]),
            float(self.series.t[-1]),
            -inf,
            inf,
            -inf,
            inf,
            frame=self.frame,
        )

    def sample(self, t: ArrayLike, x: ArrayLike, y: ArrayLike) -> tuple[NDArray, NDArray]:
        """Wind ``(u, v)`` [m s⁻¹] at epoch ``t`` [s], position ``x, y`` [m] (broadcast).

        Raises
        ------
        OutOfCoverageError
            Outside the log's time span (unless ``clamp``), or inside a hole
            (always), naming the boat and the gap.
        """
        t, x, y = prepare_points(self.coverage, t, x, y, clamp=self.clamp, name=self.label)
        hole_check(self.series, t.ravel(), self.label)
        ul, vl = self._local
        if ul.size == 1:
            return np.full(t.shape, ul[0]), np.full(t.shape, vl[0])
        return np.interp(t, self.series.t, ul), np.interp(t, self.series.t, vl)


def boat_wind(
    series_or_track: MeasuredSeries | Track,
    frame: LocalFrame,
    *,
    max_gap_s: float | None = None,
    clamp: bool = False,
) -> BoatWind:
    """One boat's own measured wind as a :class:`~sailroute.wind.base.WindField`.

    Parameters
    ----------
    series_or_track : MeasuredSeries or Track
        The boat's sensor, or its log (read with :func:`sensor_from_track` defaults).
    frame : LocalFrame
        The course's local frame.
    max_gap_s : float, optional
        Hole limit [s]; default: the series' own (:data:`DEFAULT_MAX_GAP_S`, 30 s,
        for a track).
    clamp : bool
        Clamp times outside the log to its ends (holes still raise).

    Returns
    -------
    BoatWind
        Uniform in space, linear in time in the local-frame components; sampling
        inside a gap longer than ``max_gap_s`` raises
        :class:`~sailroute.errors.OutOfCoverageError` naming the boat and the gap.
    """
    return BoatWind(_as_series(series_or_track, max_gap_s), frame, clamp=clamp)


def hull_fraction(
    sensors: Sequence[MeasuredSeries],
    frame: LocalFrame,
    t: ArrayLike,
    x: ArrayLike,
    y: ArrayLike,
    window_s: float = 60.0,
) -> float:
    """Fraction of points inside the sensors' convex hull in space and time.

    A point counts as inside when its time lies within the sensors' common span
    and its position inside the convex hull of every sensor position recorded
    within ``±window_s / 2`` of its time (evaluated on time bins of
    ``window_s / 2``; the bin's hull takes the positions within ``window_s / 2``
    of the bin).  Fewer than three non-collinear positions make no hull (outside).

    Parameters
    ----------
    sensors : sequence of MeasuredSeries
    frame : LocalFrame
    t, x, y : array_like
        Points [epoch s, m, m] (broadcast).
    window_s : float
        Time window of the hull [s].

    Returns
    -------
    float
        In ``[0, 1]``; NaN for no points.
    """
    from scipy.spatial import Delaunay, QhullError

    t, x, y = (
        a.ravel()
        for a in np.broadcast_arrays(
            np.asarray(t, float), np.asarray(x, float), np.asarray(y, float)
        )
    )
    if not t.size:
        return float("nan")
    st = np.concatenate([s.t for s in sensors])
    sx, sy = frame.to_xy(
        np.concatenate([s.lat for s in sensors]), np.concatenate([s.lon for s in sensors])
    )
    t0 = max(float(s.t[0]) for s in sensors)
    t1 = min(float(s.t[-1]) for s in sensors)
    half = 0.5 * window_s
    inside = np.zeros(t.size, bool)
    b = np.floor(t / half).astype(np.int64)
    for bb in np.unique(b):
        m = (b == bb) & (t >= t0) & (t <= t1)
        if not m.any():
            continue
        lo, hi = bb * half - half, (bb + 1) * half + half
        k = (st >= lo) & (st <= hi)
        pts = np.column_stack([sx[k], sy[k]])
        if pts.shape[0] < 3:
            continue
        try:
            tri = Delaunay(pts)
        except QhullError:
            continue
        inside[m] = tri.find_simplex(np.column_stack([x[m], y[m]])) >= 0
    return float(inside.mean())


@dataclass(frozen=True, eq=False)
class FleetWind:
    """The fleet's measured wind: a field, the per-boat biases and coverage checks.

    Attributes
    ----------
    field : FleetField
        The wind field (a :class:`~sailroute.wind.base.WindField`).
    biases : tuple of BoatBias
        Per boat, in input order (identity when ``estimate_bias`` was False).
    sensors : tuple of MeasuredSeries
        The sensors, bias-corrected (before resampling: the hull uses every record).
    frame : LocalFrame
    notes : tuple of str
        Biases, the logs that limit the time span, resampling, fitted scales.
    hull_window_s : float
        Time window of the hull in :meth:`coverage_report` [s].
    """

    field: FleetField
    biases: tuple[BoatBias, ...]
    sensors: tuple[MeasuredSeries, ...]
    frame: LocalFrame
    notes: tuple[str, ...] = ()
    hull_window_s: float = 60.0

    def coverage_report(self, t: ArrayLike, x: ArrayLike, y: ArrayLike) -> float:
        """Fraction of the points ``(t [epoch s], x, y [m])`` inside the sensors' hull.

        See :func:`hull_fraction`; the rest is extrapolated.
        """
        return hull_fraction(self.sensors, self.frame, t, x, y, self.hull_window_s)

    def extrapolation_note(
        self, t: ArrayLike, x: ArrayLike, y: ArrayLike, what: str = "the requested points"
    ) -> str:
        """One line saying how much of ``what`` lies outside the sensors' hull."""
        n = int(np.broadcast(np.asarray(t), np.asarray(x), np.asarray(y)).size)
        f = self.coverage_report(t, x, y)
        if not np.isfinite(f):
            return f"{self.field.name}: no points to check"
        return (
            f"{self.field.name}: {100 * (1 - f):.0f} % of {what} ({n} points) lie outside "
            f"the sensors' hull (±{self.hull_window_s / 2:g} s): the wind there is "
            "extrapolated"
        )


DEFAULT_METHOD: Final = "st-idw"
"""Default :func:`fleet_wind` method (chosen by leave-one-boat-out, ``docs/measured-wind.md``)."""


DEFAULT_RESAMPLE_S: Final = 10.0
"""Default :func:`fleet_wind` resampling interval [s]."""


def fleet_wind(
    tracks_or_series: Sequence[MeasuredSeries | Track],
    frame: LocalFrame,
    *,
    method: str = DEFAULT_METHOD,
    estimate_bias: bool = True,
    resample_s: float = DEFAULT_RESAMPLE_S,
    max_gap_s: float | None = None,
    max_lag_s: float = 60.0,
    radius_m: float = 2000.0,
    hull_window_s: float = 60.0,
    clamp: bool = False,
    options: Mapping[str, object] | None = None,
) -> FleetWind:
    """Several boats' measured wind as one field.

    Parameters
    ----------
    tracks_or_series : sequence of MeasuredSeries or Track
        The boats (tracks are read with :func:`sensor_from_track` defaults).
    frame : LocalFrame
        The course's local frame.
    method : str
        One of :data:`FLEET_METHODS`; default :data:`DEFAULT_METHOD`, chosen by the
        leave-one-boat-out table in ``docs/measured-wind.md``.
    estimate_bias : bool
        Estimate each boat's speed factor, direction offset and clock offset
        against the fleet (:func:`estimate_biases`) and correct the sensors before
        building the field.
    resample_s : float
        Vector means over this interval before building the field [s]; 0: none.
    max_gap_s : float, optional
        Hole limit [s] (default: each series' own, 30 s for tracks).
    max_lag_s : float
        Largest clock offset searched [s].
    radius_m : float
        Coverage box margin around the sensors' positions [m].
    hull_window_s : float
        Time window of the hull in :meth:`FleetWind.coverage_report` [s].
    clamp : bool
        Clamp points to the coverage instead of raising.
    options : mapping, optional
        Further :class:`FleetField` parameters (``power``, ``speed_scale_ms``,
        ``window_s``, ``oi_scales``, ``name``).

    Returns
    -------
    FleetWind
    """
    series = [_as_series(s, max_gap_s) for s in tracks_or_series]
    if not series:
        raise InputError("fleet wind: no boats given")
    biases = (
        estimate_biases(series, max_lag_s=max_lag_s)
        if estimate_bias and len(series) > 1
        else tuple(BoatBias(s.boat) for s in series)
    )
    used = [apply_bias(s, b) if estimate_bias else s for s, b in zip(series, biases, strict=True)]
    opts = dict(options or {})
    f = FleetField(
        tuple(resample_series(s, resample_s) for s in used),
        frame,
        method=method,
        radius_m=radius_m,
        clamp=clamp,
        **opts,  # type: ignore[arg-type]
    )
    notes = [
        f"{f.name}: method {method}, {len(used)} boat(s)"
        + (f", resampled to {resample_s:g} s" if resample_s > 0 else "")
    ]
    if estimate_bias:
        notes += [f"bias {b.describe()}" for b in biases]
    notes.append(f.limit_note)
    sc = f.oi_scales_fitted
    if sc is not None:
        notes.append(
            f"optimal interpolation: sigma {sc[0]:.2f} m/s, length {sc[1]:.0f} m, "
            f"time {sc[2]:.0f} s, noise {sc[3]:.2f} m/s"
        )
    return FleetWind(f, biases, tuple(used), frame, tuple(notes), hull_window_s)


@dataclass(frozen=True)
class LooRow:
    """One row of :func:`leave_one_out`: one method predicting one boat left out.

    Attributes
    ----------
    label : str
        The method's label.
    boat : str
        The boat left out (``"pooled"`` for the pooled row).
    n : int
        Records compared.
    speed_rms_kn : float
        RMS of predicted minus measured speed [kn].
    dir_mae_deg : float
        Mean absolute direction error [°].
    inside_hull : float
        Fraction of the compared records inside the other boats' hull.
    """

    label: str
    boat: str
    n: int
    speed_rms_kn: float
    dir_mae_deg: float
    inside_hull: float


def leave_one_out(
    series_list: Sequence[MeasuredSeries],
    frame: LocalFrame,
    methods: Mapping[str, Mapping[str, object]],
    *,
    targets: Sequence[MeasuredSeries] | None = None,
) -> list[LooRow]:
    """Build from all boats but one, predict the one left out; every boat in turn.

    Parameters
    ----------
    series_list : sequence of MeasuredSeries
        The sensors (at least two).
    frame : LocalFrame
    methods : mapping of str to mapping
        Label -> keyword arguments of :func:`fleet_wind` (``method``, ``resample_s``,
        ``estimate_bias``, ``options``, ...).
    targets : sequence of MeasuredSeries, optional
        What each boat measured (default: ``series_list``), e.g. the unsmoothed logs.

    Returns
    -------
    list of LooRow
        Per method: one row per boat left out, then a ``"pooled"`` row over all
        compared records.  Every method is compared on the same records: those
        where every method's field is defined (:meth:`FleetField.available`; the
        fields are clamped in space).
    """
    from sailroute.units import KNOT

    targets = list(series_list if targets is None else targets)
    per: dict[str, list[tuple[LooRow, NDArray, NDArray]]] = {k: [] for k in methods}
    for k, tgt in enumerate(targets):
        others = [s for j, s in enumerate(series_list) if j != k]
        fields = {
            label: fleet_wind(others, frame, clamp=True, **kw)  # type: ignore[arg-type]
            for label, kw in methods.items()
        }
        m = np.ones(tgt.t.size, bool)
        for fw in fields.values():
            m &= fw.field.available(tgt.t)
        if not m.any():
            continue
        x, y, ul, vl = tgt.local(frame)
        x, y, ul, vl, tt = x[m], y[m], ul[m], vl[m], tgt.t[m]
        ms, md = wind_speed_direction(ul, vl)
        for label, fw in fields.items():
            ps, pd = wind_speed_direction(*fw.field.sample(tt, x, y))
            ds, dd = (ps - ms) / KNOT, np.abs(wrap180(pd - md))
            ins = fw.coverage_report(tt, x, y)
            per[label].append(
                (
                    LooRow(
                        label,
                        tgt.boat,
                        int(tt.size),
                        float(np.sqrt(np.mean(ds**2))),
                        float(np.mean(dd)),
                        ins,
                    ),
                    ds,
                    dd,
                )
            )
    rows: list[LooRow] = []
    for label, got in per.items():
        if not got:
            continue
        rows += [g[0] for g in got]
        ds, dd = np.concatenate([g[1] for g in got]), np.concatenate([g[2] for g in got])
        n = sum(g[0].n for g in got)
        rows.append(
            LooRow(
                label,
                "pooled",
                n,
                float(np.sqrt(np.mean(ds**2))),
                float(np.mean(dd)),
                sum(g[0].n * g[0].inside_hull for g in got) / n,
            )
        )
    return rows
