"""A boat log as a moving wind sensor (:class:`MeasuredSeries`): true wind from the log's
apparent wind (:func:`true_wind`), smoothed as a vector, NaN rows dropped, gaps listed
(:func:`sensor_from_track`), resampled into fixed intervals (:func:`resample_series`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Final

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.errors import InputError, OutOfCoverageError
from sailroute.timeutil import iso
from sailroute.units import wind_components, wind_speed_direction, wrap360
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
        return MeasuredSeries(
            self.boat,
            self.file,
            self.t[m],
            self.lat[m],
            self.lon[m],
            self.u[m],
            self.v[m],
            self.source,
            self.notes,
            gaps,
            self.max_gap_s,
        )

    def local(self, frame: LocalFrame) -> tuple[NDArray, NDArray, NDArray, NDArray]:
        """Positions ``x, y`` [m] and wind ``u, v`` [m s⁻¹] in the local frame."""
        x, y = frame.to_xy(self.lat, self.lon)
        ul, vl = earth_to_local(self.u, self.v, frame.grid_north_deg(self.lat, self.lon))
        return x, y, np.asarray(ul, float), np.asarray(vl, float)


def find_gaps(t: NDArray, max_gap_s: float) -> tuple[tuple[float, float], ...]:
    """``(start, end)`` of every step of ``t`` longer than ``max_gap_s`` [s]."""
    k = np.nonzero(np.diff(t) > max_gap_s)[0]
    return tuple((float(t[i]), float(t[i + 1])) for i in k)


def smooth_vector(
    t: NDArray, u: NDArray, v: NDArray, window_s: float, max_gap_s: float
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
        raise InputError(
            f"{track.source or track.name}: max_gap_s must be > 0 and smooth_s "
            f">= 0 (got {max_gap_s}, {smooth_s})"
        )
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
        source = "aws/awa + sog/cog (over the ground" + (
            ", awa from hdg)" if hdg is not None else ", awa from cog)"
        )
        tws, twd = true_wind(
            ch["aws_ms"], ch["awa_deg"], ch["sog_ms"], ch["cog_deg"], heading_deg=hdg
        )
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
    ok = (
        np.isfinite(tws)
        & np.isfinite(twd)
        & np.isfinite(track.lat_deg)
        & np.isfinite(track.lon_deg)
    )
    notes = []
    if (~ok).any():
        notes.append(f"dropped {int((~ok).sum())} of {ok.size} row(s) without a wind value")
    if ok.sum() < 2:
        raise InputError(
            f"{track.source or track.name}: only {int(ok.sum())} row(s) with a "
            f"wind value ({source}); a wind sensor needs at least two"
        )
    t = np.asarray(track.t_s[ok], float)
    u, v = wind_components(tws[ok], twd[ok])
    if smooth_s > 0:
        u, v = smooth_vector(t, u, v, smooth_s, max_gap_s)
        notes.append(f"smoothed: centred vector mean over {smooth_s:g} s")
    return MeasuredSeries(
        track.name,
        track.source,
        t,
        track.lat_deg[ok].astype(float),
        track.lon_deg[ok].astype(float),
        u,
        v,
        source,
        tuple(notes),
        find_gaps(t, max_gap_s),
        float(max_gap_s),
    )


def _as_series(obj: MeasuredSeries | Track, max_gap_s: float | None) -> MeasuredSeries:
    if isinstance(obj, MeasuredSeries):
        s = obj
    else:
        s = sensor_from_track(obj, max_gap_s=max_gap_s or DEFAULT_MAX_GAP_S)
    if max_gap_s is not None and max_gap_s != s.max_gap_s:
        if not (max_gap_s > 0):
            raise InputError(f"{s.label}: max_gap_s must be > 0 (got {max_gap_s})")
        s = MeasuredSeries(
            s.boat,
            s.file,
            s.t,
            s.lat,
            s.lon,
            s.u,
            s.v,
            s.source,
            s.notes,
            find_gaps(s.t, max_gap_s),
            float(max_gap_s),
        )
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
    return MeasuredSeries(
        series.boat,
        series.file,
        t.astype(float),
        mean(series.lat),
        mean(series.lon),
        mean(series.u),
        mean(series.v),
        series.source,
        (*series.notes, f"resampled to {interval_s:g} s means"),
        series.gaps,
        series.max_gap_s,
    )
