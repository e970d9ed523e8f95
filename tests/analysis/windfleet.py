"""Fleets sailed by sailroute's own router through a known wind, for the inferred-wind tests.

A triangle-and-sausage course in the frame of a wind from ``BASE`` (200°): a beat of
900 m to W, a reach to R (100° off the wind), a broad leg back to L (143°), a second beat
to W and a run to L.  Each boat is routed leg by leg (isochrone router) with its own
polar: the course polar with its upwind angles stretched (pointing from ``ALPHA_SPREAD``)
and its speed scaled per point of sail (skill), its own tack and gybe penalties, start
delay, start point and first tack.  The routed track is then logged: sampled every
``every_s`` seconds (1-3 s) with GPS noise correlated over 20 s.

The truth kept with each fleet: the wind (``twd(t)``) and each boat's legs with their
mode from the course geometry in the true wind at the leg start (``course.geometry``'s
Ω rule).  Routing takes ~1 s per boat; fleets are cached per process.
"""

from __future__ import annotations

import csv
import xml.etree.ElementTree as ET
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from types import MappingProxyType

import numpy as np
from numpy.typing import ArrayLike

from sailroute.analysis.infer_wind import InferredWind
from sailroute.boat import builtin_polar
from sailroute.boat.efficiency import scale_polar
from sailroute.boat.polar import Polar
from sailroute.course.geometry import wind_mode
from sailroute.geo import LocalFrame
from sailroute.routing.api import route_leg
from sailroute.routing.geometry import chain_leg
from sailroute.routing.settings import RoutingSettings
from sailroute.routing.types import Start, Target
from sailroute.timeutil import parse_time, to_epoch
from sailroute.track.model import Track
from sailroute.units import bearing_deg, wind_components, wrap180
from sailroute.wind.analytic import AnalyticWind

T0 = 1_750_000_000.0
BASE = 200.0
TWS = 5.0
FRAME = LocalFrame(39.4, -0.32)
ALPHA_SPREAD = 4.0
"""Sd of the boats' pointing: their upwind angles are stretched by ±this [°] about 42°."""


def _xy(up: float, left: float) -> tuple[float, float]:
    th = np.radians(BASE)
    return (
        float(up * np.sin(th) - left * np.cos(th)),
        float(up * np.cos(th) + left * np.sin(th)),
    )


W = _xy(900.0, 0.0)
R = _xy(900.0 + 600.0 * np.cos(np.radians(100.0)), 600.0 * np.sin(np.radians(100.0)))
L = _xy(0.0, 0.0)
MARKS = (("W", W), ("R", R), ("L", L), ("W", W), ("L", L))


def twd_osc(t: ArrayLike) -> np.ndarray:
    """TWD 200° ± 10°, period 6 min."""
    return BASE + 10.0 * np.sin(2.0 * np.pi * (np.asarray(t, float) - T0) / 360.0)


def twd_shift(t: ArrayLike) -> np.ndarray:
    """A persistent veer of 15° between minutes 6.7 and 16.7."""
    return BASE - 7.5 + 15.0 * np.clip((np.asarray(t, float) - T0 - 400.0) / 600.0, 0.0, 1.0)


def twd_swing(t: ArrayLike) -> np.ndarray:
    """A 25° backing over the first 20 min (the wind turns while the fleet reaches and
    runs), then steady."""
    return BASE + 12.5 - 25.0 * np.clip((np.asarray(t, float) - T0) / 1200.0, 0.0, 1.0)


WINDS: dict[str, Callable] = {"osc": twd_osc, "shift": twd_shift, "swing": twd_swing}


def skiff_polar() -> Polar:
    """A polar whose best downwind VMG lies near 145° (a boat that gybes through ~70°)."""
    twa = np.array([0, 30, 38, 45, 52, 60, 75, 90, 110, 125, 140, 150, 160, 170, 180], float)
    shape = np.array(
        [0, 0.25, 0.52, 0.62, 0.7, 0.77, 0.86, 0.92, 0.97, 0.95, 0.88, 0.78, 0.66, 0.58, 0.55]
    )
    tws = np.array([2.0, 4.0, 6.0, 8.0, 10.0])
    k = np.array([0.85, 0.8, 0.72, 0.62, 0.55])
    return Polar.from_arrays(twa, tws, shape[:, None] * tws[None, :] * k[None, :], "skiff")


def pointing(polar: Polar, dalpha: float) -> Polar:
    """``polar`` with its angles below 90° stretched so that it points ``dalpha`` [°] lower
    (positive) or higher at 42°, by less towards 0° and 120° (unchanged beyond)."""
    a = polar.twa_deg
    w = np.where(a < 42.0, a / 42.0, np.clip((120.0 - a) / 78.0, 0.0, 1.0))
    new = a + dalpha * w
    return Polar.from_arrays(new, polar.tws_ms, polar.speed_ms, polar.name)


@dataclass(frozen=True)
class Boat:
    """One routed boat: its route at 1 Hz and its legs ``(t_start, t_end, mode)``."""

    name: str
    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    legs: tuple[tuple[float, float, str], ...]


@cache
def routed_fleet(wind: str, n: int, seed: int = 0, kind: str = "ilca") -> tuple[Boat, ...]:
    """``n`` boats of varied skill routed through ``WINDS[wind]`` (cached)."""
    twd = WINDS[wind]
    field = AnalyticWind(lambda t, x, y: wind_components(np.full(np.shape(t), TWS), twd(t)))
    rng = np.random.default_rng(seed)
    base = builtin_polar("ilca7") if kind == "ilca" else skiff_polar()
    boats = []
    for k in range(n):
        polar = scale_polar(
            pointing(base, float(rng.normal(0.0, ALPHA_SPREAD))),
            *rng.uniform(0.9, 1.0, 3),
        )
        settings = RoutingSettings(
            tack_penalty_s=float(rng.uniform(4.0, 10.0)),
            gybe_penalty_s=float(rng.uniform(2.0, 6.0)),
            initial_side=("starboard", "port", None)[int(rng.integers(3))],
        )
        start = _xy(-40.0, float(rng.uniform(-120.0, 120.0)))
        dt0 = float(rng.uniform(0.0, 30.0))
        prev = None
        parts, legs = [], []
        targets = [Target("mark", xy, rounding="port", name=nm) for nm, xy in MARKS]
        for i, tg in enumerate(targets):
            st = Start(start if i == 0 else MARKS[i - 1][1], None, "start")
            st, tg2 = chain_leg(st, tg, prev, targets[i + 1] if i + 1 < len(targets) else None)
            s = (
                settings
                if i == 0
                else RoutingSettings(
                    tack_penalty_s=settings.tack_penalty_s, gybe_penalty_s=settings.gybe_penalty_s
                )
            )
            t_start = T0 + dt0 if prev is None else prev.t_end
            prev = route_leg(st, tg2, t_start, field, polar, s)
            a = start if i == 0 else MARKS[i - 1][1]
            b = MARKS[i][1]
            brg = float(bearing_deg(b[0] - a[0], b[1] - a[1]))
            legs.append((t_start, prev.t_end, wind_mode(brg, float(twd(t_start)))))
            parts.append(prev.track)
        t = np.concatenate([p.t for p in parts])
        x = np.concatenate([p.x for p in parts])
        y = np.concatenate([p.y for p in parts])
        keep = np.concatenate([[True], np.diff(t) > 1e-6])
        t, x, y = t[keep], x[keep], y[keep]
        t1 = np.arange(np.ceil(t[0]), np.floor(t[-1]) + 1.0)
        boats.append(
            Boat(f"boat {k + 1}", t1, np.interp(t1, t, x), np.interp(t1, t, y), tuple(legs))
        )
    return tuple(boats)


def ar_noise(n: int, sigma_m: float, tau_s: float, rng: np.random.Generator) -> np.ndarray:
    """First-order autoregressive noise at 1 Hz: sd ``sigma_m``, correlation ``tau_s``."""
    a = np.exp(-1.0 / tau_s)
    z = rng.normal(0.0, sigma_m * np.sqrt(1.0 - a * a), n)
    z[0] = rng.normal(0.0, sigma_m)
    out = np.empty(n)
    out[0] = z[0]
    for i in range(1, n):
        out[i] = a * out[i - 1] + z[i]
    return out


def logged(
    boats: tuple[Boat, ...], every_s: int = 1, gps_m: float = 0.0, seed: int = 0
) -> list[Track]:
    """The boats' routes as logged tracks: every ``every_s`` s, GPS error ``gps_m`` [m]
    (white 1/3, the rest correlated over 20 s)."""
    rng = np.random.default_rng(1000 + seed)
    out = []
    for b in boats:
        x, y = b.x.copy(), b.y.copy()
        if gps_m:
            for arr in (x, y):
                arr += ar_noise(arr.size, gps_m * np.sqrt(2.0 / 3.0), 20.0, rng)
                arr += rng.normal(0.0, gps_m / np.sqrt(3.0), arr.size)
        off = int(rng.integers(every_s))
        sl = slice(off, None, every_s)
        lat, lon = FRAME.to_latlon(x[sl], y[sl])
        out.append(Track(b.t[sl], lat, lon, b.name, "route", MappingProxyType({}), ()))
    return out


def truth_by_mode(
    boats: tuple[Boat, ...], wind: str, t_grid: np.ndarray
) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Per leg mode: the grid indices where a boat sails a leg of that mode and the true
    TWD there (one entry per boat and grid time)."""
    out: dict[str, tuple[list, list]] = {m: ([], []) for m in ("upwind", "reach", "downwind")}
    for b in boats:
        for ta, tb, mode in b.legs:
            i = np.flatnonzero((t_grid >= ta) & (t_grid <= tb))
            out[mode][0].append(i)
            out[mode][1].append(WINDS[wind](t_grid[i]))
    return {
        m: (np.concatenate(a).astype(int), np.concatenate(b))
        if a
        else (np.zeros(0, int), np.zeros(0))
        for m, (a, b) in out.items()
    }


def coverage(
    iw: InferredWind, boats: tuple[Boat, ...], wind: str
) -> dict[str, tuple[float, float, float]]:
    """Per leg mode: RMS error [°], the share of (boat, grid time) whose truth lies within
    2 sd (NaN grid times count as covered: the estimate says it does not know), and the
    share with a direction."""
    out = {}
    for m, (i, true) in truth_by_mode(boats, wind, iw.t).items():
        if i.size == 0:
            continue
        d, sd = iw.twd_deg[i], iw.twd_sd_deg[i]
        ok = np.isfinite(d)
        err = wrap180(d[ok] - true[ok])
        inside = np.ones(i.size, bool)
        inside[ok] = np.abs(err) <= 2.0 * sd[ok]
        out[m] = (
            float(np.sqrt(np.mean(err**2))) if ok.any() else np.nan,
            float(inside.mean()),
            float(ok.mean()),
        )
    return out


def race_xml(path: Path, frame: LocalFrame) -> tuple[float, list[tuple[float, float]], float]:
    """A SailGP race XML's gun [epoch s], mark positions in ``frame`` [m] and course axis
    [°]: the bearing from the leeward to the windward gate, the wind the course was laid
    in."""
    root = ET.parse(path).getroot()
    start = root.find("RaceStartTime")
    assert start is not None
    marks = {}
    for m in root.iterfind("Course/CompoundMark/Mark"):
        x, y = frame.to_xy(
            np.array([float(m.get("TargetLat", ""))]), np.array([float(m.get("TargetLng", ""))])
        )
        marks[m.get("Name", "")] = (float(x[0]), float(y[0]))
    lg = np.mean([marks["LG1"], marks["LG2"]], axis=0)
    wg = np.mean([marks["WG1"], marks["WG2"]], axis=0)
    axis = float(bearing_deg(wg[0] - lg[0], wg[1] - lg[1]))
    return to_epoch(parse_time(start.get("Start", ""))), list(marks.values()), axis


def leg_counter_changes(log: Path, race: str) -> list[float]:
    """Times [epoch s] at which a SailGP boat log's leg counter (``TRK_LEG_NUM``) steps up
    in the race whose number starts with ``race`` (0 -> 1 is the start, then each leg
    change)."""
    out: list[float] = []
    prev = None
    with open(log, newline="") as fh:
        for row in csv.DictReader(fh):
            if not row["TRK_RACE_NUM_unk"].startswith(race):
                continue
            leg = float(row["TRK_LEG_NUM_unk"])
            if prev is not None and leg > prev:
                out.append(to_epoch(parse_time(row["DATETIME"].replace(" ", "T") + "Z", "t")))
            prev = leg
    return out
