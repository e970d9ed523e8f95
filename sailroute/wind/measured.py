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

from sailroute.errors import InputError, OutOfCoverageError
from sailroute.timeutil import iso
from sailroute.units import wind_components, wind_speed_direction, wrap180, wrap360
from sailroute.wind.base import Coverage, prepare_points
from sailroute.wind.rotation import earth_to_local

if TYPE_CHECKING:
    from sailroute.geo import LocalFrame
    from sailroute.track.model import Track

DEFAULT_SMOOTH_S: Final = 30.0
"""Default smoothing window of :func:`sensor_from_track` [s] (centred vector mean).

Chosen by the leave-one-boat-out measurement on the SailGP 1 Hz logs
(``docs/measured-wind.md``, "Smoothing"): most of the gain of averaging out what
one boat's 1 Hz wind shares with no other boat, while a 6-minute oscillation keeps
99 % of its amplitude."""

DEFAULT_MAX_GAP_S: Final = 30.0
"""Default hole limit [s]: two records of a log further apart than this bound a
hole (sampling inside it raises), never an interpolation.  30 s is 30 records of
a 1 Hz log; it lets through the odd dropped record and refuses every outage
longer than half a minute (the SailGP logs have gaps of 32-592 s between races)."""


# ------------------------------------------------------------------------------ formula
def true_wind(
    aws_ms: ArrayLike,
    awa_deg: ArrayLike,
    speed_ms: ArrayLike,
    course_deg: ArrayLike,
    *,
    heading_deg: ArrayLike | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """True wind speed and direction from apparent wind and the boat's velocity.

    The apparent wind is the air's velocity relative to the boat, so the true
    wind is the apparent wind plus the boat's velocity::

        apparent (from) direction  a = heading + awa
        A = -aws (sin a, cos a)              air velocity relative to the boat
        B =  speed (sin c, cos c)            boat velocity, c = course
        W = A + B  ->  tws = |W|,  twd = direction W comes from

    so that ``tws² = aws² + speed² - 2 aws speed cos(awa)`` when ``heading`` is
    the course.  With SOG/COG the result is the wind over the ground (what
    routing uses); with BSP/heading it is the wind over the water.

    Parameters
    ----------
    aws_ms : array_like
        Apparent wind speed [m s⁻¹].
    awa_deg : array_like
        Signed apparent wind angle [°] from the bow, + = wind over starboard.
    speed_ms : array_like
        Boat speed [m s⁻¹]: SOG (wind over the ground) or BSP (over the water).
    course_deg : array_like
        Direction of that speed [° compass]: COG with SOG, heading with BSP.
    heading_deg : array_like, optional
        The bow's heading [° compass] that ``awa`` is measured from, when it
        differs from ``course_deg`` (SOG/COG with a compass): the difference is
        leeway plus current.  Default: ``course_deg``.

    Returns
    -------
    tws_ms : ndarray
        True wind speed [m s⁻¹].
    twd_deg : ndarray
        Direction the true wind comes from [°], in ``[0, 360)``.

    Notes
    -----
    Not modelled: upwash (the sails bend the flow at the masthead vane, by a few
    degrees upwind), mast-head motion from heel and pitch, the height of the
    sensor (the wind at the masthead, not at 10 m), and, when ``heading_deg`` is
    not given, leeway.  Instrument systems correct some of these with their own
    calibration tables; logged ``tws``/``twd`` channels are preferred for that
    reason (:func:`sensor_from_track`).
    """
    c = np.asarray(course_deg, dtype=float)
    h = c if heading_deg is None else np.asarray(heading_deg, dtype=float)
    au, av = wind_components(aws_ms, h + np.asarray(awa_deg, dtype=float))
    s = np.asarray(speed_ms, dtype=float)
    cr = np.radians(c)
    return wind_speed_direction(au + s * np.sin(cr), av + s * np.cos(cr))


# ------------------------------------------------------------------------------ series
@dataclass(frozen=True, eq=False)
class MeasuredSeries:
    """One boat's measured wind: a moving sensor.

    Attributes
    ----------
    boat : str
        Boat name (the track's name).
    file : str
        The log it was read from.
    t : ndarray
        Epoch seconds [s], strictly increasing.
    lat, lon : ndarray
        Sensor position [°].
    u, v : ndarray
        True east/north components of the wind [m s⁻¹] (direction the air moves TO).
    source : str
        Which channels gave the wind (``"tws/twd"``, ``"tws + twa + hdg"``,
        ``"aws/awa + sog/cog (over the ground)"``, ...).
    notes : tuple of str
        What reading did (rows dropped, smoothing).
    gaps : tuple of (float, float)
        ``(start, end)`` [epoch s] of every stretch between records longer than
        :attr:`max_gap_s`: holes where the wind is unknown.
    max_gap_s : float
        The hole limit the gaps were found with [s].
    """

    boat: str
    file: str
    t: NDArray[np.float64]
    lat: NDArray[np.float64]
    lon: NDArray[np.float64]
    u: NDArray[np.float64]
    v: NDArray[np.float64]
    source: str = ""
    notes: tuple[str, ...] = ()
    gaps: tuple[tuple[float, float], ...] = ()
    max_gap_s: float = DEFAULT_MAX_GAP_S

    def __len__(self) -> int:
        return int(self.t.size)

    @property
    def tws_ms(self) -> NDArray[np.float64]:
        """True wind speed [m s⁻¹]."""
        return wind_speed_direction(self.u, self.v)[0]

    @property
    def twd_deg(self) -> NDArray[np.float64]:
        """True wind direction, from [°]."""
        return wind_speed_direction(self.u, self.v)[1]

    @property
    def label(self) -> str:
        """``"boat (file)"`` for messages."""
        return f"{self.boat} ({self.file})" if self.file else self.boat

    def between(self, t0: float, t1: float) -> MeasuredSeries:
        """The records with ``t0 <= t <= t1`` [epoch s]; gaps clipped to that span."""
        m = (self.t >= t0) & (self.t <= t1)
        gaps = tuple((a, b) for a, b in self.gaps if b > t0 and a < t1)
        return MeasuredSeries(self.boat, self.file, self.t[m], self.lat[m], self.lon[m],
                              self.u[m], self.v[m], self.source, self.notes, gaps,
                              self.max_gap_s)

    def local(self, frame: LocalFrame) -> tuple[NDArray, NDArray, NDArray, NDArray]:
        """Positions ``x, y`` [m] and wind ``u, v`` [m s⁻¹] in the local frame."""
        x, y = frame.to_xy(self.lat, self.lon)
        ul, vl = earth_to_local(self.u, self.v, frame.grid_north_deg(self.lat, self.lon))
        return x, y, np.asarray(ul, float), np.asarray(vl, float)


def find_gaps(t: NDArray, max_gap_s: float) -> tuple[tuple[float, float], ...]:
    """``(start, end)`` of every step of ``t`` longer than ``max_gap_s`` [s]."""
    k = np.nonzero(np.diff(t) > max_gap_s)[0]
    return tuple((float(t[i]), float(t[i + 1])) for i in k)


def smooth_vector(t: NDArray, u: NDArray, v: NDArray, window_s: float, max_gap_s: float
                  ) -> tuple[NDArray, NDArray]:
    """Centred vector mean of ``(u, v)`` over ``window_s`` [s], never across a gap.

    Each record becomes the mean of the records within ``±window_s / 2`` of it in
    the same gap-free stretch (steps no longer than ``max_gap_s``).  Irregular
    spacing is fine; ``window_s <= 0`` returns copies.
    """
    if window_s <= 0 or t.size < 2:
        return u.copy(), v.copy()
    seg = np.concatenate([[0], np.cumsum(np.diff(t) > max_gap_s)])
    starts = np.searchsorted(seg, seg, side="left")
    ends = np.searchsorted(seg, seg, side="right")
    lo = np.maximum(np.searchsorted(t, t - 0.5 * window_s, side="left"), starts)
    hi = np.minimum(np.searchsorted(t, t + 0.5 * window_s, side="right"), ends)
    cu = np.concatenate([[0.0], np.cumsum(u)])
    cv = np.concatenate([[0.0], np.cumsum(v)])
    n = hi - lo
    return (cu[hi] - cu[lo]) / n, (cv[hi] - cv[lo]) / n


def _has(ch: dict[str, NDArray], *names: str) -> bool:
    return all(n in ch and bool(np.isfinite(ch[n]).any()) for n in names)


def sensor_from_track(
    track: Track,
    *,
    smooth_s: float = DEFAULT_SMOOTH_S,
    max_gap_s: float = DEFAULT_MAX_GAP_S,
) -> MeasuredSeries:
    """A boat log as one moving wind sensor.

    The wind comes from the first of these the log has (``Track.channels``):

    1. ``tws_ms`` and ``twd_deg`` (the instrument system's true wind);
    2. ``tws_ms`` and ``twa_deg`` with ``hdg_deg`` (else ``cog_deg``): ``twd = hdg + twa``;
    3. ``aws_ms`` and ``awa_deg`` with ``sog_ms``/``cog_deg`` (the wind over the ground,
       ``awa`` measured from ``hdg_deg`` when logged), else with ``bsp_ms``/``hdg_deg``
       (the wind over the water), through :func:`true_wind`.

    Parameters
    ----------
    track : Track
        The log (:func:`sailroute.track.read_track`).
    smooth_s : float
        Width of the centred vector mean applied to ``(u, v)`` [s]; 0 keeps the
        records as logged.  The default (:data:`DEFAULT_SMOOTH_S`, 30 s) was
        chosen by measurement on the SailGP 1 Hz logs (``docs/measured-wind.md``,
        "Smoothing"): predicting one boat's wind from the others' mean, the speed
        error falls from 2.03 kn (as logged) to 1.87 kn at 30 s, while a 30 s mean
        keeps 99 % of a 6-minute oscillation of the wind (60 s: 95 %, 120 s: 83 %).
    max_gap_s : float
        Records further apart than this bound a hole [s] (:data:`DEFAULT_MAX_GAP_S`).

    Returns
    -------
    MeasuredSeries
        Rows with a NaN in a used channel or the position dropped (counted in
        ``notes``).

    Raises
    ------
    InputError
        The log has no usable wind channels (the message names the file and the
        channels found), or fewer than two usable rows.
    """
    if not (max_gap_s > 0) or not (smooth_s >= 0):
        raise InputError(f"{track.source or track.name}: max_gap_s must be > 0 and smooth_s "
                         f">= 0 (got {max_gap_s}, {smooth_s})")
    ch = dict(track.channels)
    if _has(ch, "tws_ms", "twd_deg"):
        source = "tws/twd"
        tws, twd = ch["tws_ms"], ch["twd_deg"]
    elif _has(ch, "tws_ms", "twa_deg") and (_has(ch, "hdg_deg") or _has(ch, "cog_deg")):
        ref = "hdg_deg" if _has(ch, "hdg_deg") else "cog_deg"
        source = f"tws + twa + {ref[:3]}"
        tws, twd = ch["tws_ms"], wrap360(ch[ref] + ch["twa_deg"])
    elif _has(ch, "aws_ms", "awa_deg") and _has(ch, "sog_ms", "cog_deg"):
        hdg = ch["hdg_deg"] if _has(ch, "hdg_deg") else None
        source = ("aws/awa + sog/cog (over the ground" + (", awa from hdg)" if hdg is not None
                                                          else ", awa from cog)"))
        tws, twd = true_wind(ch["aws_ms"], ch["awa_deg"], ch["sog_ms"], ch["cog_deg"],
                             heading_deg=hdg)
    elif _has(ch, "aws_ms", "awa_deg", "bsp_ms", "hdg_deg"):
        source = "aws/awa + bsp/hdg (over the water)"
        tws, twd = true_wind(ch["aws_ms"], ch["awa_deg"], ch["bsp_ms"], ch["hdg_deg"])
    else:
        found = ", ".join(sorted(k for k in ch if np.isfinite(ch[k]).any())) or "none"
        raise InputError(
            f"{track.source or track.name}: no usable wind columns (channels found: {found}); "
            "a measured-wind sensor needs tws+twd, tws+twa with hdg or cog, or aws+awa with "
            "sog+cog or bsp+hdg"
        )
    tws = np.asarray(tws, float)
    twd = np.asarray(twd, float)
    ok = np.isfinite(tws) & np.isfinite(twd) & np.isfinite(track.lat_deg) & np.isfinite(
        track.lon_deg)
    notes = []
    if (~ok).any():
        notes.append(f"dropped {int((~ok).sum())} of {ok.size} row(s) without a wind value")
    if ok.sum() < 2:
        raise InputError(f"{track.source or track.name}: only {int(ok.sum())} row(s) with a "
                         f"wind value ({source}); a wind sensor needs at least two")
    t = np.asarray(track.t_s[ok], float)
    u, v = wind_components(tws[ok], twd[ok])
    if smooth_s > 0:
        u, v = smooth_vector(t, u, v, smooth_s, max_gap_s)
        notes.append(f"smoothed: centred vector mean over {smooth_s:g} s")
    return MeasuredSeries(track.name, track.source, t, track.lat_deg[ok].astype(float),
                          track.lon_deg[ok].astype(float), u, v, source, tuple(notes),
                          find_gaps(t, max_gap_s), float(max_gap_s))


def _as_series(obj: MeasuredSeries | Track, max_gap_s: float | None) -> MeasuredSeries:
    if isinstance(obj, MeasuredSeries):
        s = obj
    else:
        s = sensor_from_track(obj, max_gap_s=max_gap_s or DEFAULT_MAX_GAP_S)
    if max_gap_s is not None and max_gap_s != s.max_gap_s:
        if not (max_gap_s > 0):
            raise InputError(f"{s.label}: max_gap_s must be > 0 (got {max_gap_s})")
        s = MeasuredSeries(s.boat, s.file, s.t, s.lat, s.lon, s.u, s.v, s.source, s.notes,
                           find_gaps(s.t, max_gap_s), float(max_gap_s))
    return s


def hole_check(series: MeasuredSeries, t: NDArray, name: str) -> None:
    """Raise :class:`OutOfCoverageError` if a time of ``t`` lies inside a gap of the log."""
    if not series.gaps or not t.size:
        return
    g0 = np.array([a for a, _ in series.gaps])
    g1 = np.array([b for _, b in series.gaps])
    k = np.searchsorted(g0, t, side="right") - 1
    kk = np.maximum(k, 0)
    inside = (k >= 0) & (t > g0[kk]) & (t < g1[kk])
    if inside.any():
        j = int(kk[np.argmax(inside)])
        raise OutOfCoverageError(
            f"{name}: {int(inside.sum())} of {t.size} sample points fall in a gap of the log of "
            f"{series.label}: no record from {iso(g0[j])} to {iso(g1[j])} "
            f"({g1[j] - g0[j]:.0f} s > max_gap_s {series.max_gap_s:g} s); the wind there is "
            "unknown and is not interpolated. Use another wind for that time, or raise max_gap_s."
        )


# ------------------------------------------------------------------------------ one boat
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
        return Coverage(float(self.series.t[0]), float(self.series.t[-1]), -inf, inf, -inf,
                        inf, frame=self.frame)

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



# ------------------------------------------------------------------------------ biases
@dataclass(frozen=True)
class BoatBias:
    """One boat's constant bias against the fleet's consensus.

    The boat's log reads ``speed_factor`` times the consensus speed,
    ``direction_offset_deg`` clockwise of the consensus direction, and stamps a
    wind ``time_offset_s`` later than the consensus does (a clock ahead, or a
    sensor that lags).  Correcting divides the speed by the factor, subtracts the
    direction offset and subtracts the time offset from the stamps.

    Attributes
    ----------
    boat : str
        Boat name.
    speed_factor : float
        Measured / consensus speed [-].
    direction_offset_deg : float
        Measured minus consensus direction [°].
    time_offset_s : float
        Measured minus consensus time of the same wind [s].
    n_samples : int
        Compared records (1 s steps, summed over the boats it was compared with) behind the
        estimate; 0 when the boat overlaps no other boat (no correction).
    clock_samples : int
        The part of ``n_samples`` from comparisons whose time offset was identified (a
        correlation peak inside ``±max_lag_s``, not at its edge); 0: the clock offset is
        not identified and is left at 0.
    """

    boat: str
    speed_factor: float = 1.0
    direction_offset_deg: float = 0.0
    time_offset_s: float = 0.0
    n_samples: int = 0
    clock_samples: int = 0

    def describe(self) -> str:
        """One line: ``NZL: speed x1.031, direction +2.4°, time +12.0 s (1612 samples)``."""
        clock = (f"time {self.time_offset_s:+.1f} s" if self.clock_samples else
                 "time not identified")
        return (f"{self.boat}: speed x{self.speed_factor:.3f}, direction "
                f"{self.direction_offset_deg:+.1f}°, {clock} ({self.n_samples} samples)")


def _sample_series(s: MeasuredSeries, t: NDArray) -> tuple[NDArray, NDArray, NDArray]:
    """``(u, v, ok)`` of a series at times ``t`` (linear; ok False outside it and in holes)."""
    ok = (t >= s.t[0]) & (t <= s.t[-1])
    for a, b in s.gaps:
        ok &= ~((t > a) & (t < b))
    return np.interp(t, s.t, s.u), np.interp(t, s.t, s.v), ok


def _pair_offsets(a: MeasuredSeries, b: MeasuredSeries, max_lag_s: float, min_overlap: int
                  ) -> tuple[float, float, float, int, bool] | None:
    """``(log speed ratio, direction offset [°], time offset [s], n, time identified)`` of
    ``a`` against ``b``; a best lag at the edge of the search is not identified (lag 0)."""
    t0, t1 = max(a.t[0], b.t[0]), min(a.t[-1], b.t[-1])
    if t1 - t0 < min_overlap:
        return None
    tg = np.arange(t0, t1 + 0.5)
    ub, vb, okb = _sample_series(b, tg)
    sb, db = wind_speed_direction(ub, vb)
    lags = np.arange(-max_lag_s, max_lag_s + 0.5)
    score = np.full(lags.size, -np.inf)
    for k, lag in enumerate(lags):
        ua, va, oka = _sample_series(a, tg + lag)
        m = oka & okb
        if m.sum() < min_overlap:
            continue
        sa, da = wind_speed_direction(ua[m], va[m])
        # direction anomalies about each series' own circular mean, speed anomalies
        xa = wrap180(da - _circmean(da))
        xb = wrap180(db[m] - _circmean(db[m]))
        score[k] = _corr(xa, xb, 0.05) + _corr(sa, sb[m], 0.005)
    if not np.isfinite(score).any():
        return None
    score = score - 1e-9 * np.abs(lags)  # a flat score (steady wind) gives lag 0
    k = int(np.argmax(score))
    identified = bool(0 < k < lags.size - 1 and np.isfinite(score[k - 1])
                      and np.isfinite(score[k + 1]))
    lag = float(lags[k]) if identified else 0.0
    if identified:
        den = score[k - 1] - 2 * score[k] + score[k + 1]
        if den < 0:
            lag += float(np.clip(0.5 * (score[k - 1] - score[k + 1]) / den, -0.5, 0.5))
    ua, va, oka = _sample_series(a, tg + lag)
    m = oka & okb
    sa, da = wind_speed_direction(ua[m], va[m])
    ddir = _circmean(wrap180(da - db[m]))
    return (float(np.log(np.mean(sa) / np.mean(sb[m]))), float(wrap180(ddir)), lag,
            int(m.sum()), identified)


def _circmean(a: NDArray) -> float:
    r = np.radians(a)
    return float(np.degrees(np.arctan2(np.mean(np.sin(r)), np.mean(np.cos(r)))))


def _corr(a: NDArray, b: NDArray, floor: float) -> float:
    """Pearson correlation; 0 when either series varies less than ``floor`` (std)."""
    a = a - a.mean()
    b = b - b.mean()
    if a.std() < floor or b.std() < floor:
        return 0.0
    den = float(np.sqrt(np.sum(a * a) * np.sum(b * b)))
    return float(np.sum(a * b) / den) if den > 0 else 0.0


def estimate_biases(
    series: Sequence[MeasuredSeries],
    *,
    max_lag_s: float = 60.0,
    min_overlap_s: float = 60.0,
) -> tuple[BoatBias, ...]:
    """Per-boat speed factor, direction offset and time offset against the fleet.

    Every pair of boats that overlaps in time for at least ``min_overlap_s`` is
    compared on a 1 s grid: the time offset maximises the correlation of the
    two direction and speed series (lags up to ``±max_lag_s``, refined to a
    fraction of a second by a parabola; a best lag at the edge of the search is
    not identified and that pair does not enter the clock offsets), then the
    direction offset is the circular mean difference and the speed ratio the
    ratio of mean speeds at that lag.  The per-boat offsets are the weighted
    least-squares solution of the pairwise differences, fixed so that the fleet's
    median boat has no bias: the consensus is the median boat, so one faulty
    sensor out of three does not drag the others.

    Parameters
    ----------
    series : sequence of MeasuredSeries
        The boats (at least two for any estimate).
    max_lag_s : float
        Largest clock offset searched [s].
    min_overlap_s : float
        Shortest common stretch for a pair to count [s].

    Returns
    -------
    tuple of BoatBias
        One per series, in order (identity with ``n_samples = 0`` for a boat that
        overlaps no other).
    """
    n = len(series)
    rows: list[tuple[int, int, float, float, float, int, bool]] = []
    for i in range(n):
        for j in range(i + 1, n):
            r = _pair_offsets(series[i], series[j], max_lag_s, int(min_overlap_s))
            if r is not None:
                rows.append((i, j, *r))
    if not rows:
        return tuple(BoatBias(s.boat) for s in series)
    count = np.zeros(n, int)
    clock = np.zeros(n, int)
    for i, j, *_, m, ident in rows:
        count[i] += m
        count[j] += m
        clock[i] += m * ident
        clock[j] += m * ident
    sol = []
    for q, used in ((0, count), (1, count), (2, clock)):  # log speed ratio, direction, time
        a = np.zeros((len(rows) + 1, n))
        rhs = np.zeros(len(rows) + 1)
        for k, (i, j, *vals, m, ident) in enumerate(rows):
            w = np.sqrt(m) if (q < 2 or ident) else 0.0
            a[k, i], a[k, j], rhs[k] = w, -w, w * vals[q]
        a[-1, used > 0] = 1.0  # gauge (replaced by the median below)
        x = np.linalg.lstsq(a, rhs, rcond=None)[0]
        if (used > 0).any():
            x[used > 0] -= np.median(x[used > 0])
        x[used == 0] = 0.0
        sol.append(x)
    return tuple(BoatBias(s.boat, float(np.exp(sol[0][k])), float(sol[1][k]), float(sol[2][k]),
                          int(count[k]), int(clock[k])) for k, s in enumerate(series))


def apply_bias(series: MeasuredSeries, bias: BoatBias) -> MeasuredSeries:
    """The series corrected for ``bias`` (stamps, direction and speed)."""
    s, d = wind_speed_direction(series.u, series.v)
    u, v = wind_components(s / bias.speed_factor, d - bias.direction_offset_deg)
    dt = bias.time_offset_s
    return MeasuredSeries(series.boat, series.file, series.t - dt, series.lat, series.lon, u, v,
                          series.source, (*series.notes, f"bias corrected: {bias.describe()}"),
                          tuple((a - dt, b - dt) for a, b in series.gaps), series.max_gap_s)


def resample_series(series: MeasuredSeries, interval_s: float) -> MeasuredSeries:
    """Vector means of wind and mean positions in fixed ``interval_s`` bins [s].

    Bins are aligned on multiples of ``interval_s`` (epoch) and stamped at their
    centre; bins without a record are absent (so gaps stay gaps).
    """
    if interval_s <= 0:
        return series
    b = np.floor(series.t / interval_s).astype(np.int64)
    uniq, inv = np.unique(b, return_inverse=True)
    cnt = np.bincount(inv).astype(float)

    def mean(a: NDArray) -> NDArray:
        return np.bincount(inv, weights=a, minlength=uniq.size) / cnt

    t = (uniq + 0.5) * interval_s
    t = np.clip(t, series.t[0], series.t[-1])  # first/last bins stay inside the log
    return MeasuredSeries(series.boat, series.file, t.astype(float), mean(series.lat),
                          mean(series.lon), mean(series.u), mean(series.v), series.source,
                          (*series.notes, f"resampled to {interval_s:g} s means"), series.gaps,
                          series.max_gap_s)


# ------------------------------------------------------------------------------ fleet field
FLEET_METHODS: Final = ("mean", "idw", "st-idw", "oi", "nearest", "constant")
"""Methods of :class:`FleetField`: the candidates ``idw`` (inverse distance between the
sensors at each time), ``st-idw`` (inverse space-time distance over nearby records),
``oi`` (optimal interpolation: the sensors' mean plus a Gaussian-process correction with
fitted length and time scales), and the baselines ``mean`` (the sensors' mean at each
time), ``nearest`` (the nearest sensor at each time), ``constant`` (one mean wind)."""


@dataclass(frozen=True, eq=False)
class _Sensor:
    name: str
    series: MeasuredSeries
    t: NDArray
    x: NDArray
    y: NDArray
    u: NDArray
    v: NDArray


@dataclass(frozen=True, eq=False)
class _OiFit:
    """Fitted optimal-interpolation state: observations, weights and scales."""

    t: NDArray
    x: NDArray
    y: NDArray
    alpha: NDArray  # (n, 2): (K + noise I)^-1 residuals
    sigma2: float
    length_m: float
    time_s: float
    noise2: float


@dataclass(frozen=True, eq=False)
class FleetField:
    """Several moving sensors as one :class:`~sailroute.wind.base.WindField`.

    Built by :func:`fleet_wind` (use that); the sensors are already bias-corrected
    and resampled.  Coverage: the span during which every sensor has logged (the
    intersection; the message on a miss names the logs that limit it) and the
    sensors' box plus ``radius_m``.  At a time where a sensor is in a hole it is
    left out; where every sensor is in a hole, sampling raises.

    Parameters
    ----------
    sensors : sequence of MeasuredSeries
        The sensors.
    frame : LocalFrame
        The course's local frame.
    method : str
        One of :data:`FLEET_METHODS`.
    power : float
        IDW exponent (``idw``, ``st-idw``).
    speed_scale_ms : float
        ``st-idw``: metres per second of time difference in the space-time distance
        [m s⁻¹].
    window_s : float
        ``st-idw``: records within ``±window_s`` of the time are used [s].
    oi_scales : (float, float, float, float), optional
        ``oi``: ``(sigma [m s⁻¹], length [m], time [s], noise [m s⁻¹])``; fitted by
        maximum likelihood when None.
    radius_m : float
        Coverage box margin around every sensor position [m].
    clamp : bool
        Clamp points to the coverage instead of raising.
    name : str
        Label for messages.
    """

    sensors: tuple[MeasuredSeries, ...]
    frame: LocalFrame
    method: str = "mean"
    power: float = 2.0
    speed_scale_ms: float = 5.0
    window_s: float = 60.0
    oi_scales: tuple[float, float, float, float] | None = None
    radius_m: float = 2000.0
    clamp: bool = False
    name: str = "fleet wind"

    def __post_init__(self) -> None:
        self._state  # noqa: B018  (built now: building it checks the inputs)
        self._oi_state  # noqa: B018

    @cached_property
    def _state(self) -> tuple[tuple[_Sensor, ...], Coverage, str]:
        if self.method not in FLEET_METHODS:
            raise InputError(f"{self.name}: method {self.method!r}; expected one of "
                             f"{', '.join(FLEET_METHODS)}")
        if not self.sensors:
            raise InputError(f"{self.name}: no sensors")
        if not (self.power > 0 and self.speed_scale_ms >= 0 and self.window_s >= 0
                and self.radius_m >= 0):
            raise InputError(f"{self.name}: power must be > 0 and speed_scale_ms, window_s, "
                             f"radius_m >= 0 (got {self.power}, {self.speed_scale_ms}, "
                             f"{self.window_s}, {self.radius_m})")
        sens = []
        for s in self.sensors:
            if len(s) < 1:
                raise InputError(f"{self.name}: the log of {s.label} has no wind records")
            x, y, u, v = s.local(self.frame)
            sens.append(_Sensor(s.boat, s, s.t, x, y, u, v))
        starts = [float(s.t[0]) for s in sens]
        ends = [float(s.t[-1]) for s in sens]
        t0, t1 = max(starts), min(ends)
        first = sens[int(np.argmax(starts))].series
        last = sens[int(np.argmin(ends))].series
        limit = (f"the time span is limited by the log of {first.label} (starts "
                 f"{iso(t0)}) and the log of {last.label} (ends {iso(t1)})")
        if t0 > t1:
            raise InputError(f"{self.name}: the logs never overlap in time: {limit}; use "
                             "logs of the same race")
        xs = np.concatenate([s.x for s in sens])
        ys = np.concatenate([s.y for s in sens])
        r = self.radius_m
        cov = Coverage(t0, t1, float(xs.min()) - r, float(xs.max()) + r, float(ys.min()) - r,
                       float(ys.max()) + r, frame=self.frame,
                       source_span=(min(starts), max(ends)))
        return tuple(sens), cov, limit

    @cached_property
    def _oi_state(self) -> _OiFit | None:
        return self._fit_oi(self._state[0]) if self.method == "oi" else None

    @property
    def coverage(self) -> Coverage:
        """Common time span of the sensors; their box plus ``radius_m``."""
        return self._state[1]

    @property
    def limit_note(self) -> str:
        """Which logs limit the time span."""
        return self._state[2]

    @property
    def oi_scales_fitted(self) -> tuple[float, float, float, float] | None:
        """``oi``: ``(sigma [m s⁻¹], length [m], time [s], noise [m s⁻¹])`` in use."""
        oi = self._oi_state
        if oi is None:
            return None
        return (float(np.sqrt(oi.sigma2)), oi.length_m, oi.time_s, float(np.sqrt(oi.noise2)))

    def available(self, t: ArrayLike) -> NDArray[np.bool_]:
        """Mask of times [epoch s] inside the time span where some sensor is not in a hole."""
        t = np.asarray(t, dtype=float).ravel()
        c = self.coverage
        return (t >= c.t0) & (t <= c.t1) & self._at(t)[4].any(axis=-1)

    # ---------------------------------------------------------------- per-sensor values
    def _at(self, t: NDArray) -> tuple[NDArray, NDArray, NDArray, NDArray, NDArray]:
        """Per-sensor ``x, y, u, v, ok`` at times ``t``, each ``(n, S)`` (linear in time)."""
        cols: list[list[NDArray]] = [[], [], [], [], []]
        for s in self._state[0]:
            ts = s.t
            ok = (t >= ts[0]) & (t <= ts[-1])
            if ts.size == 1:
                i = np.zeros(t.size, np.intp)
                j, w = i, np.zeros(t.size)
            else:
                i = np.clip(np.searchsorted(ts, t, side="right") - 1, 0, ts.size - 2)
                j = i + 1
                w = np.clip((t - ts[i]) / (ts[j] - ts[i]), 0.0, 1.0)
            for c, a in zip(cols, (s.x, s.y, s.u, s.v), strict=False):
                c.append(a[i] + w * (a[j] - a[i]))
            if s.series.gaps:
                g0 = np.array([g for g, _ in s.series.gaps])
                g1 = np.array([g for _, g in s.series.gaps])
                k = np.maximum(np.searchsorted(g0, t, side="right") - 1, 0)
                ok &= ~((t > g0[k]) & (t < g1[k]))
            cols[4].append(ok)
        x, y, u, v, okk = (np.stack(c, axis=-1) for c in cols)
        return x, y, u, v, okk.astype(bool)

    def _combine(self, w: NDArray, u: NDArray, v: NDArray, t: NDArray) -> tuple[NDArray, NDArray]:
        tot = w.sum(axis=-1)
        if (tot <= 0).any():
            k = int(np.argmax(tot <= 0))
            raise OutOfCoverageError(
                f"{self.name}: {int((tot <= 0).sum())} of {tot.size} sample points fall where "
                f"every log has a gap (first at {iso(float(t[k]))}; gaps: "
                + "; ".join(f"{s.series.label} {iso(a)} .. {iso(b)}" for s in self._state[0]
                            for a, b in s.series.gaps)
                + "); the wind there is unknown. Use another wind for that time."
            )
        return (w * u).sum(axis=-1) / tot, (w * v).sum(axis=-1) / tot

    def _mean(self, t: NDArray, allow_missing: bool = False) -> tuple[NDArray, NDArray]:
        _, _, u, v, ok = self._at(t)
        if allow_missing:
            n = ok.sum(axis=-1)
            with np.errstate(invalid="ignore", divide="ignore"):
                return (u * ok).sum(axis=-1) / n, (v * ok).sum(axis=-1) / n
        return self._combine(ok.astype(float), u, v, t)

    # ---------------------------------------------------------------- optimal interpolation
    def _fit_oi(self, sens: tuple[_Sensor, ...]) -> _OiFit:
        t = np.concatenate([s.t for s in sens])
        x = np.concatenate([s.x for s in sens])
        y = np.concatenate([s.y for s in sens])
        u = np.concatenate([s.u for s in sens])
        v = np.concatenate([s.v for s in sens])
        mu, mv = self._mean(t, allow_missing=True)
        keep = np.isfinite(mu)
        t, x, y = t[keep], x[keep], y[keep]
        res = np.column_stack([u[keep] - mu[keep], v[keep] - mv[keep]])
        if self.oi_scales is not None:
            sig, lm, ts, nz = self.oi_scales
            p = (sig * sig, lm, ts, nz * nz)
        else:
            p = _fit_gp(t, x, y, res)
        k = _kernel(t, x, y, t, x, y, p[0], p[1], p[2])
        k[np.diag_indices_from(k)] += p[3]
        alpha = np.linalg.solve(k, res)
        return _OiFit(t, x, y, alpha, p[0], p[1], p[2], p[3])

    # ---------------------------------------------------------------- sampling
    def sample(self, t: ArrayLike, x: ArrayLike, y: ArrayLike) -> tuple[NDArray, NDArray]:
        """Wind ``(u, v)`` [m s⁻¹] at epoch ``t`` [s], position ``x, y`` [m] (broadcast)."""
        try:
            t, x, y = prepare_points(self.coverage, t, x, y, clamp=self.clamp, name=self.name)
        except OutOfCoverageError as e:
            raise OutOfCoverageError(f"{e}\n  ({self.limit_note})") from None
        shape = t.shape
        t, x, y = t.ravel(), x.ravel(), y.ravel()
        if not t.size:
            return np.zeros(shape), np.zeros(shape)
        m = self.method
        if m == "constant":
            sens = self._state[0]
            uu = np.concatenate([s.u for s in sens]).mean()
            vv = np.concatenate([s.v for s in sens]).mean()
            u, v = np.full(t.size, uu), np.full(t.size, vv)
        elif m == "mean":
            u, v = self._mean(t)
        elif m in ("idw", "nearest"):
            sx, sy, su, sv, ok = self._at(t)
            d2 = np.maximum((x[:, None] - sx) ** 2 + (y[:, None] - sy) ** 2, 1e-24)
            if m == "idw":
                w = d2 ** (-0.5 * self.power) * ok
            else:
                d2 = np.where(ok, d2, np.inf)
                w = (d2 == d2.min(axis=1, keepdims=True)) & ok
            u, v = self._combine(w.astype(float), su, sv, t)
        elif m == "st-idw":
            u, v = self._st_idw(t, x, y)
        else:
            u, v = self._oi(t, x, y)
        return u.reshape(shape), v.reshape(shape)

    def _st_idw(self, t: NDArray, x: NDArray, y: NDArray) -> tuple[NDArray, NDArray]:
        """Inverse space-time distance over every record within ``±window_s``."""
        c2 = self.speed_scale_ms ** 2
        wsum = np.zeros(t.size)
        usum = np.zeros(t.size)
        vsum = np.zeros(t.size)
        any_ok = np.zeros(t.size, bool)
        for s in self._state[0]:
            ts = s.t
            ok = (t >= ts[0]) & (t <= ts[-1])
            if s.series.gaps:
                g0 = np.array([g for g, _ in s.series.gaps])
                g1 = np.array([g for _, g in s.series.gaps])
                k = np.maximum(np.searchsorted(g0, t, side="right") - 1, 0)
                ok &= ~((t > g0[k]) & (t < g1[k]))
            any_ok |= ok
            lo = np.searchsorted(ts, t - self.window_s, side="left")
            hi = np.searchsorted(ts, t + self.window_s, side="right")
            for m in range(int((hi - lo).max())):
                k = np.minimum(lo + m, ts.size - 1)
                dt = ts[k] - t
                d2 = np.maximum((x - s.x[k]) ** 2 + (y - s.y[k]) ** 2 + c2 * dt * dt, 1e-24)
                w = (1.0 / d2 if self.power == 2.0 else d2 ** (-0.5 * self.power))
                w *= (lo + m < hi) & ok
                wsum += w
                usum += w * s.u[k]
                vsum += w * s.v[k]
        if not any_ok.all():
            self._combine(any_ok[:, None].astype(float), np.zeros((t.size, 1)),
                          np.zeros((t.size, 1)), t)
        return usum / wsum, vsum / wsum

    def _oi(self, t: NDArray, x: NDArray, y: NDArray) -> tuple[NDArray, NDArray]:
        oi = self._oi_state
        assert oi is not None
        u, v = self._mean(t)
        chunk = max(1, 2_000_000 // max(oi.t.size, 1))
        for a in range(0, t.size, chunk):
            sl = slice(a, a + chunk)
            k = _kernel(t[sl], x[sl], y[sl], oi.t, oi.x, oi.y, oi.sigma2, oi.length_m, oi.time_s)
            c = k @ oi.alpha
            u[sl] += c[:, 0]
            v[sl] += c[:, 1]
        return u, v


def _kernel(t1: NDArray, x1: NDArray, y1: NDArray, t2: NDArray, x2: NDArray, y2: NDArray,
            sigma2: float, length_m: float, time_s: float) -> NDArray:
    """Squared-exponential covariance in space and time, ``(n1, n2)``."""
    q = (((x1[:, None] - x2) ** 2 + (y1[:, None] - y2) ** 2) / (length_m * length_m)
         + (t1[:, None] - t2) ** 2 / (time_s * time_s))
    return sigma2 * np.exp(-0.5 * q)


NOISE_FLOOR_MS: Final = 0.05
"""Smallest observation noise of the ``oi`` method [m s⁻¹] (an anemometer's resolution):
keeps the covariance matrix well conditioned when the boats agree to the last digit."""


def _fit_gp(t: NDArray, x: NDArray, y: NDArray, res: NDArray, max_points: int = 400
            ) -> tuple[float, float, float, float]:
    """Maximum-likelihood ``(sigma², length, time, noise²)`` for residuals ``(n, 2)``.

    Both components share the scales; at most ``max_points`` evenly spaced records
    enter the fit (the prediction uses them all).
    """
    from scipy.optimize import minimize

    if t.size > max_points:
        k = np.linspace(0, t.size - 1, max_points).astype(int)
        t, x, y, res = t[k], x[k], y[k], res[k]
    var = max(float(np.mean(res * res)), NOISE_FLOOR_MS ** 2)
    n = t.size

    def nll(p: NDArray) -> float:
        s2, lm, ts, n2 = np.exp(p)
        k = _kernel(t, x, y, t, x, y, s2, lm, ts)
        k[np.diag_indices_from(k)] += n2 + 1e-9
        try:
            c = np.linalg.cholesky(k)
        except np.linalg.LinAlgError:
            return 1e20
        z = np.linalg.solve(c, res)
        return float(0.5 * np.sum(z * z) + 2 * np.sum(np.log(np.diag(c))) + n * np.log(2 * np.pi))

    p0 = np.log([0.5 * var, 500.0, 120.0, 0.5 * var])
    bounds = [(np.log(var * 1e-3), np.log(var * 10)), (np.log(50.0), np.log(2e4)),
              (np.log(10.0), np.log(3600.0)),
              (np.log(max(var * 1e-3, NOISE_FLOOR_MS ** 2)), np.log(var * 10))]
    r = minimize(nll, p0, method="L-BFGS-B", bounds=bounds)
    s2, lm, ts, n2 = (float(a) for a in np.exp(r.x))
    return s2, lm, ts, n2


# ------------------------------------------------------------------------------ hull
def hull_fraction(sensors: Sequence[MeasuredSeries], frame: LocalFrame, t: ArrayLike,
                  x: ArrayLike, y: ArrayLike, window_s: float = 60.0) -> float:
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

    t, x, y = (a.ravel() for a in np.broadcast_arrays(np.asarray(t, float),
                                                      np.asarray(x, float),
                                                      np.asarray(y, float)))
    if not t.size:
        return float("nan")
    st = np.concatenate([s.t for s in sensors])
    sx, sy = frame.to_xy(np.concatenate([s.lat for s in sensors]),
                         np.concatenate([s.lon for s in sensors]))
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


# ------------------------------------------------------------------------------ fleet
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

    def extrapolation_note(self, t: ArrayLike, x: ArrayLike, y: ArrayLike,
                           what: str = "the requested points") -> str:
        """One line saying how much of ``what`` lies outside the sensors' hull."""
        n = int(np.broadcast(np.asarray(t), np.asarray(x), np.asarray(y)).size)
        f = self.coverage_report(t, x, y)
        if not np.isfinite(f):
            return f"{self.field.name}: no points to check"
        return (f"{self.field.name}: {100 * (1 - f):.0f} % of {what} ({n} points) lie outside "
                f"the sensors' hull (±{self.hull_window_s / 2:g} s): the wind there is "
                "extrapolated")


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
    biases = (estimate_biases(series, max_lag_s=max_lag_s) if estimate_bias and len(series) > 1
              else tuple(BoatBias(s.boat) for s in series))
    used = [apply_bias(s, b) if estimate_bias else s
            for s, b in zip(series, biases, strict=True)]
    opts = dict(options or {})
    f = FleetField(tuple(resample_series(s, resample_s) for s in used), frame, method=method,
                   radius_m=radius_m, clamp=clamp, **opts)  # type: ignore[arg-type]
    notes = [f"{f.name}: method {method}, {len(used)} boat(s)"
             + (f", resampled to {resample_s:g} s" if resample_s > 0 else "")]
    if estimate_bias:
        notes += [f"bias {b.describe()}" for b in biases]
    notes.append(f.limit_note)
    sc = f.oi_scales_fitted
    if sc is not None:
        notes.append(f"optimal interpolation: sigma {sc[0]:.2f} m/s, length {sc[1]:.0f} m, "
                     f"time {sc[2]:.0f} s, noise {sc[3]:.2f} m/s")
    return FleetWind(f, biases, tuple(used), frame, tuple(notes), hull_window_s)


# ------------------------------------------------------------------------------ evaluation
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
        fields = {label: fleet_wind(others, frame, clamp=True, **kw)  # type: ignore[arg-type]
                  for label, kw in methods.items()}
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
            per[label].append((LooRow(label, tgt.boat, int(tt.size),
                                      float(np.sqrt(np.mean(ds ** 2))), float(np.mean(dd)), ins),
                               ds, dd))
    rows: list[LooRow] = []
    for label, got in per.items():
        if not got:
            continue
        rows += [g[0] for g in got]
        ds, dd = np.concatenate([g[1] for g in got]), np.concatenate([g[2] for g in got])
        n = sum(g[0].n for g in got)
        rows.append(LooRow(label, "pooled", n, float(np.sqrt(np.mean(ds ** 2))),
                           float(np.mean(dd)), sum(g[0].n * g[0].inside_hull for g in got) / n))
    return rows
