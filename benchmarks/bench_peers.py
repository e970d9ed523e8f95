"""Benchmark: sailroute against a peer router and a paper, per leg, per course, CLI start-up.

Run (from the repository root, one thread)::

    python benchmarks/bench_peers.py                 # all sections (~4 min on 2 cores)
    python benchmarks/bench_peers.py --quick         # fewer repeats, no C = 128
    python benchmarks/bench_peers.py --only peer     # one section: peer griddp course cli profile
    python benchmarks/bench_peers.py --only profile  # cProfile of one leg (also in the default run)
    python benchmarks/bench_peers.py --smoke         # the profile section, 5 rows (seconds)

Sections (each prints a Markdown table; ``docs/performance.md`` holds one full run):

``peer``
    Four 1809 m legs routed by ``weatherrouting`` 0.2.3 (PyPI, an open isochrone
    router; the ``bench`` extra, ``pip install -e .[bench]``; never vendored) and by
    our isochrone router, on the same polar, wind, start and mark: a beat, a beam
    reach and a dead run in 8.5 kn of uniform wind from 0°, and a beat in the
    synthetic Hyères WRF file (space and time varying).  Wall time of each (ours:
    best of ``--repeat`` after a warm-up run; the peer: best of ``--peer-repeat``
    after a 3-step warm-up, since it caches nothing between runs), the ratio
    peer/ours, each route time and the difference ours − peer (negative: our route
    is faster on the water).  Skipped with a message when weatherrouting is absent.
``griddp``
    Our grid DP (Dębski 2016) at C = 32, 64, 128 nodes per row on the paper's test
    problem (800 m x 500 m, 12 m/s wind 5° off the leg axis, dynamic boat), next to
    the paper's t_f and its 874 s (serial C) / 21 s (OpenCL GPU) for C = 128.
``course``
    Our isochrone router per leg and per full course on ``courses/hyeres-r1.yaml``,
    scenarios ``constant`` and ``wrf10``, with the course's own routing settings;
    plus :func:`sailroute.planning.route.plan_course` end to end (wind and boat built inside).
``cli``
    Wall time of ``python -c "import sailroute.cli"``, ``sailroute --help`` and
    ``sailroute plan courses/hyeres-r1.yaml`` as fresh processes (best of N), with
    and without a bytecode cache (``PYTHONPYCACHEPREFIX`` in a temporary folder, so
    nothing is written into the source tree).
``profile``
    cProfile of ``route_leg`` on Hyères leg 1 in the ``wrf10`` scenario: the top
    functions by own time, with their share of the total.

How the peer comparison is made fair
------------------------------------
* **Polar**: both read ``sailroute/boat/data/ilca7.pol``.  Ours is read with
  ``interpolation="linear"``, plain bilinear interpolation on the table, which is the
  peer's ``Polar.get_speed`` inside the table; the script prints the largest
  difference between the two on a TWS x TWA grid (it is at rounding level).
* **Wind**: the peer's wind callback ``get_wind_at(t, lat, lon) -> (twd, tws)``
  (the ``weatherrouting.Grib`` interface) projects the point to our local frame and
  samples the very same :class:`~sailroute.wind.base.WindField` object.  Its cost is
  inside the peer's wall time and is reported separately (a few % at most).
* **Time step**: equal, ``--dt`` (default 30 s) for both.  The peer is pure Python
  (about 0.5 s per step for a 170-point front), which is why the default is not our
  own 10 s; ``--dt 10`` gives the same picture, only slower.  The row "ours,
  defaults" adds our router at its default 10 s / 2° settings.
* **Headings**: the peer's fan is fixed in its code: every 5° of TWA (72 headings),
  minus those that move away from the mark.  The "same settings" row runs ours with
  ``heading_step_deg=5`` (the same TWA grid); ours keeps the grid TWAs between the
  VMG angles (``heading_fan="hull"``; the others are never optimal without a
  manoeuvre cost) and adds the exact VMG angles and the direct course to the mark,
  which is part of our method.
* **Pruning**: the peer keeps one point per 1° of bearing seen from the start
  (``subdiv=1``); ours one per 1° seen from the target and tack side
  (``prune_sector_deg=1``).
* **Manoeuvres**: the peer has no tack or gybe penalty, so ours is set to 0 s.
* **Arrival**: the peer's own test ends the leg when a front point is within
  ``min_increase`` nm of the mark *and* within 1.1 x one hour of sailing of it,
  which is true after the first step of any dinghy leg.  It is switched off
  (``min_increase = 0``) and this script ends the peer's leg like ours: after each
  step (and at the start), every front point's time to sail straight to the mark
  is computed with the peer's polar in the wind at the point; at the first step
  where some point gets there within ``dt``, the earliest of those times is the
  peer's arrival (interpolated inside the step, as ours is).  Ours must pass within
  1 m of the mark (a 2 m target segment centred on it: ``zone_m=1``, no rounding
  side).  This driver code is inside the peer's wall time.
* **Wind time**: the peer samples the wind at the end time of each step at the
  point's start position, ours at mid-step at the predicted mid-step position (the
  same in uniform wind).
* **Geodesy**: the peer moves along WGS-84 geodesics (pyproj through ``latlon3``),
  ours in the azimuthal-equidistant local frame centred on the start; over 2 km the
  two differ by under 1e-7 in distance and 0.02° in direction.
* **Threads**: both single-threaded (BLAS/OpenMP threads forced to 1; the peer's
  ``concurrent`` option stays off).

The machine's load matters (other processes, turbo, a shared VM): compare numbers
taken in one run on one machine.
"""

from __future__ import annotations

import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMEXPR_NUM_THREADS"):
    os.environ[_v] = "1"

import argparse  # noqa: E402
import cProfile  # noqa: E402
import dataclasses  # noqa: E402
import math  # noqa: E402
import platform  # noqa: E402
import pstats  # noqa: E402
import resource  # noqa: E402
import shutil  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from collections.abc import Callable, Sequence  # noqa: E402
from dataclasses import dataclass  # noqa: E402
from datetime import UTC, datetime  # noqa: E402
from importlib import metadata  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any, TypeVar  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))

import bench_griddp  # noqa: E402
import bench_isochrone  # noqa: E402

from sailroute.boat.io import read_polar  # noqa: E402
from sailroute.boat.polar import Polar, fold_twa  # noqa: E402
from sailroute.geo import LocalFrame  # noqa: E402
from sailroute.routing.api import route_leg  # noqa: E402
from sailroute.routing.settings import RoutingSettings, routing_settings  # noqa: E402
from sailroute.routing.types import LegResult, Start, Target  # noqa: E402
from sailroute.units import KNOT, wind_speed_direction  # noqa: E402
from sailroute.wind.base import WindField  # noqa: E402
from sailroute.wind.uniform import UniformWind  # noqa: E402

try:
    import weatherrouting as wr
except ImportError:  # the `bench` extra is not installed
    wr = None

ROOT = Path(__file__).resolve().parents[1]
COURSE = ROOT / "courses" / "hyeres-r1.yaml"
COURSE_SCENARIOS = ("constant", "wrf10")
ORIGIN = (43.069067, 6.198550)
"""Local-frame origin of the peer legs (Hyères "Echo" area, as in bench_isochrone) [°]."""
T0 = 1524567600.0
"""Start of the uniform-wind legs, 2018-04-24T11:00Z [epoch s]."""
UNIFORM_TWS_KN = 8.5
"""Wind speed of the uniform-wind legs, from 0° [kn]."""
PAPER_SERIAL_S = 874.0
"""Dębski (2016): grid DP, C = 128, serial C on his CPU [s]."""
PAPER_GPU_S = 21.0
"""Dębski (2016): the same on an OpenCL GPU [s]."""
PAPER_ROWS = 30
"""Rows of the paper case here: the paper does not state R; R = 30 reproduces its t_f."""
MARK_TOLERANCE_M = 1.0
"""Both routers must pass within this distance of the mark [m]."""
PEER_WARMUP_STEPS = 3
"""Isochrone steps of the peer's warm-up run."""
MAX_PEER_LEG_S = 10800.0
"""The peer gives up on a leg after this much race time [s]."""

T = TypeVar("T")


# ------------------------------------------------------------------------------------
# small helpers


@dataclass(frozen=True)
class Timing:
    """Best wall and CPU time of repeated runs.

    Attributes
    ----------
    wall : float
        Smallest wall-clock time [s].
    cpu : float
        CPU time (user + system, this process) of that same run [s].
    """

    wall: float
    cpu: float

    def __str__(self) -> str:
        return f"{_fmt_s(self.wall)} ({_fmt_s(self.cpu)})"


def best_of(fn: Callable[[], T], repeat: int, warmup: bool = True) -> tuple[Timing, T]:
    """Best timing of ``repeat`` calls of ``fn`` and the last result.

    Parameters
    ----------
    fn : callable
        The work, called without arguments.
    repeat : int
        Timed calls (at least 1).
    warmup : bool
        Make one untimed call first (caches, imports).

    Returns
    -------
    timing : Timing
        The run with the smallest wall time [s] and its CPU time [s].
    result
        What the last call returned.
    """
    if warmup:
        fn()
    best, out = Timing(math.inf, math.inf), None
    for _ in range(max(1, repeat)):
        w0, c0 = time.perf_counter(), time.process_time()
        out = fn()
        run = Timing(time.perf_counter() - w0, time.process_time() - c0)
        best = min(best, run, key=lambda r: r.wall)
    return best, out  # type: ignore[return-value]


def cpu_model() -> str:
    """CPU model, clock, cache and core count from ``/proc/cpuinfo``, plus total memory."""
    info: dict[str, str] = {}
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            key, _, value = line.partition(":")
            info.setdefault(key.strip(), value.strip())
        mem = Path("/proc/meminfo").read_text().split()
        info["mem"] = f", {int(mem[mem.index('MemTotal:') + 1]) / 2**20:.0f} GiB memory"
    except (OSError, ValueError):
        pass
    name = info.get("model name") or platform.processor() or platform.machine()
    return (
        f"{name} ({info.get('cpu MHz', '?')} MHz, cache "
        f"{info.get('cache size', '?')}), {os.cpu_count()} logical cores{info.get('mem', '')}"
    )


def machine_lines() -> list[str]:
    """Machine and library versions, one ``- key: value`` line each."""

    def version(dist: str) -> str:
        try:
            return metadata.version(dist)
        except metadata.PackageNotFoundError:
            return "not installed"

    load = os.getloadavg() if hasattr(os, "getloadavg") else (float("nan"),) * 3
    return [
        f"- CPU: {cpu_model()}",
        f"- OS: {platform.system()} {platform.release()}",
        f"- Python {platform.python_version()}, numpy {np.__version__}, "
        f"scipy {version('scipy')}, pyproj {version('pyproj')}, "
        f"sailroute {version('sailroute')}, weatherrouting {version('weatherrouting')}",
        f"- threads: 1 (OMP/BLAS forced); load average at start "
        f"{load[0]:.2f} {load[1]:.2f} {load[2]:.2f}",
        f"- date: {datetime.now(UTC).strftime('%Y-%m-%d %H:%M UTC')}",
    ]


def _fmt_s(x: float) -> str:
    """A duration [s] with 3 significant digits (ms below 1 s)."""
    if x < 1.0:
        return f"{1e3 * x:.3g} ms"
    return f"{x:.3g} s"


# ------------------------------------------------------------------------------------
# the peer: weatherrouting


@dataclass(frozen=True)
class PeerLeg:
    """One leg of the peer comparison.

    Attributes
    ----------
    name : str
        Label.
    wind : WindField
        Wind both routers sail in.
    t0 : float
        Start time [epoch s].
    start : Start
        Start point (local frame, [m]).
    target : Target
        The mark, ``rounding=None`` (pass within ``MARK_TOLERANCE_M``).
    frame : LocalFrame
        Local frame of ``start``/``target`` and of ``wind``.
    """

    name: str
    wind: WindField
    t0: float
    start: Start
    target: Target
    frame: LocalFrame


@dataclass(frozen=True)
class PeerRun:
    """Outcome of one peer run.

    Attributes
    ----------
    time_s : float
        Route time to the mark [s].
    steps : int
        Isochrone steps made.
    mean_front : float
        Mean front size [points].
    wind_calls : int
        Calls of the wind callback.
    wind_s : float
        Wall time spent inside the wind callback [s].
    """

    time_s: float
    steps: int
    mean_front: float
    wind_calls: int
    wind_s: float


class PeerWind:
    """The peer's ``Grib`` interface over a sailroute wind field.

    ``get_wind_at(t, lat, lon)`` returns ``(twd [°], tws [m s⁻¹])``, which is what
    ``weatherrouting.Grib`` documents; calls and the time spent are counted.

    Parameters
    ----------
    wind : WindField
        The field (local frame).
    frame : LocalFrame
        Frame used to project the peer's ``(lat, lon)``.
    """

    def __init__(self, wind: WindField, frame: LocalFrame) -> None:
        self.wind, self.frame = wind, frame
        self.calls, self.seconds = 0, 0.0

    def get_wind_at(self, t: datetime, lat: float, lon: float) -> tuple[float, float]:
        """Wind FROM-direction [°] and speed [m s⁻¹] at ``t`` and ``(lat, lon)`` [°]."""
        tic = time.perf_counter()
        x, y = self.frame.to_xy(lat, lon)
        u, v = self.wind.sample(t.timestamp(), x, y)
        tws, twd = wind_speed_direction(u, v)
        self.calls += 1
        self.seconds += time.perf_counter() - tic
        return float(twd), float(tws)


def peer_cases() -> list[PeerLeg]:
    """The four legs: beat, reach and run in uniform wind, beat in the synthetic WRF."""
    frame = LocalFrame(*ORIGIN)
    uni = UniformWind(UNIFORM_TWS_KN * KNOT, 0.0)
    start = Start((0.0, 0.0), name="start")
    L = bench_isochrone.LEG_M

    def mark(bearing_deg: float) -> Target:
        th = math.radians(bearing_deg)
        return Target("mark", (L * math.sin(th), L * math.cos(th)), name="mark")

    legs = [
        PeerLeg(f"beat, {UNIFORM_TWS_KN:g} kn uniform", uni, T0, start, mark(0.0), frame),
        PeerLeg(f"beam reach (TWA 90), {UNIFORM_TWS_KN:g} kn", uni, T0, start, mark(90.0), frame),
        PeerLeg(f"run (TWA 180), {UNIFORM_TWS_KN:g} kn", uni, T0, start, mark(180.0), frame),
    ]
    wrf = bench_isochrone.wrf_field()
    if wrf is None:
        print("WRF reader not available: WRF leg skipped")
        return legs
    c = wrf.coverage
    t_w = c.t0 + 0.25 * (c.t1 - c.t0)  # as bench_isochrone
    st, tg = bench_isochrone.beat(wrf, t_w)
    tg = dataclasses.replace(tg, rounding=None, name="mark")
    legs.append(PeerLeg("beat, synthetic Hyères WRF", wrf, t_w, st, tg, frame))
    return legs


def polar_mismatch(ours: Polar, peer: Any) -> float:
    """Largest |our speed − peer speed| on a TWS 2-24 kn x TWA 0-180° grid [m s⁻¹]."""
    worst = 0.0
    for kn in np.arange(2.0, 24.01, 0.7):
        for twa in np.arange(0.0, 180.01, 1.3):
            a = float(ours.speed(kn * KNOT, twa))
            b = peer.get_speed(float(kn), math.radians(twa)) * KNOT
            worst = max(worst, abs(a - b))
    return worst


def _direct_arrival(
    front_ll: Sequence[tuple[float, float]],
    t: float,
    leg: PeerLeg,
    peer_polar: Any,
) -> tuple[float, float]:
    """Earliest straight-line arrival at the mark from a peer front.

    Parameters
    ----------
    front_ll : sequence of (lat, lon)
        Front points [°].
    t : float
        Time of the front [epoch s].
    leg : PeerLeg
        The leg (mark, wind, frame).
    peer_polar : weatherrouting.Polar
        The peer's polar (knots, radians).

    Returns
    -------
    arrival, reach : float
        Earliest arrival time [epoch s] over the front, and the shortest time to
        the mark from any point [s] (``inf`` if none can sail there).
    """
    lat = np.array([p[0] for p in front_ll])
    lon = np.array([p[1] for p in front_ll])
    x, y = leg.frame.to_xy(lat, lon)
    mx, my = leg.target.a
    dist = np.hypot(mx - x, my - y)
    heading = np.degrees(np.arctan2(mx - x, my - y))
    u, v = leg.wind.sample(t, x, y)
    tws, twd = wind_speed_direction(u, v)
    twa = fold_twa(heading - twd)
    best = math.inf
    for d, w, a in zip(dist, tws, twa, strict=True):
        if d <= MARK_TOLERANCE_M:
            return t, 0.0
        bsp = peer_polar.get_speed(float(w) / KNOT, math.radians(float(a))) * KNOT
        if bsp > 0:
            best = min(best, float(d) / bsp)
    return t + best, best


def run_peer(
    leg: PeerLeg, peer_polar: Any, dt_s: float, max_steps: int | None = None, subdiv: float = 1.0
) -> PeerRun:
    """Route ``leg`` with weatherrouting's ``LinearBestIsoRouter`` (see module docstring).

    Parameters
    ----------
    leg : PeerLeg
        The leg.
    peer_polar : weatherrouting.Polar
        The peer's polar.
    dt_s : float
        Isochrone time step [s].
    max_steps : int, optional
        Stop after this many steps (warm-up); the returned time is then NaN.
    subdiv : float
        Peer pruning sector width [°] (its ``subdiv`` parameter).

    Returns
    -------
    PeerRun
    """
    grib = PeerWind(leg.wind, leg.frame)
    lat0, lon0 = leg.frame.to_latlon(*leg.start.a)
    lat1, lon1 = leg.frame.to_latlon(*leg.target.a)
    start_ll, end_ll = (float(lat0), float(lon0)), (float(lat1), float(lon1))
    t_start = datetime.fromtimestamp(leg.t0, UTC)
    routing = wr.Routing(
        wr.routers.linearbestisorouter.LinearBestIsoRouter,
        peer_polar,
        [end_ll],
        grib,
        t_start,
        start_position=start_ll,
    )
    routing.algorithm.set_param_value("subdiv", subdiv)
    routing.algorithm.set_param_value("concurrent", False)
    routing.algorithm.set_param_value("min_increase", 0.0)  # own arrival test: see docstring
    arrival, reach = _direct_arrival([start_ll], leg.t0, leg, peer_polar)
    sizes: list[int] = []
    while reach > dt_s:
        if max_steps is not None and len(sizes) >= max_steps:
            return PeerRun(math.nan, len(sizes), float(np.mean(sizes)), grib.calls, grib.seconds)
        front = routing.step(timedelta=dt_s / 3600.0).isochrones[-1]
        if not front or len(sizes) * dt_s > MAX_PEER_LEG_S:
            raise RuntimeError(f"peer: no route on {leg.name} after {len(sizes)} steps")
        sizes.append(len(front))
        arrival, reach = _direct_arrival(
            [p.pos for p in front], leg.t0 + len(sizes) * dt_s, leg, peer_polar
        )
    return PeerRun(
        arrival - leg.t0,
        len(sizes),
        float(np.mean(sizes)) if sizes else 0.0,
        grib.calls,
        grib.seconds,
    )


def our_settings(dt_s: float) -> dict[str, RoutingSettings]:
    """Our two configurations of the peer comparison (both without manoeuvre cost)."""
    common = dict(tack_penalty_s=0.0, gybe_penalty_s=0.0, zone_m=MARK_TOLERANCE_M)
    return {
        f"ours, same settings (dt {dt_s:g} s, 5°)": routing_settings(
            dt_s=dt_s, heading_step_deg=5.0, prune_sector_deg=1.0, **common
        ),
        "ours, defaults (dt 10 s, 2°)": routing_settings(**common),
    }


def section_peer(args: argparse.Namespace) -> None:
    """Print the peer comparison table."""
    print("\n## Peer comparison: weatherrouting vs sailroute isochrone router\n")
    if wr is None:
        print(
            "weatherrouting is not installed: peer comparison skipped "
            "(pip install -e '.[bench]' or pip install weatherrouting==0.2.3)"
        )
        return
    ours_polar = read_polar(bench_isochrone.POLAR_FILE, interpolation="linear")
    peer_polar = wr.Polar(str(bench_isochrone.POLAR_FILE))
    print(
        f"Polar {bench_isochrone.POLAR_FILE.name}: bilinear in both; largest speed "
        f"difference {polar_mismatch(ours_polar, peer_polar):.1e} m/s.  Both routers: "
        f"dt {args.dt:g} s (ours also at its defaults), no manoeuvre cost, pass within "
        f"{MARK_TOLERANCE_M:g} m of the mark; peer sectors {args.peer_subdiv:g}°.  Peer: "
        f"best of {args.peer_repeat} after a {PEER_WARMUP_STEPS}-step warm-up; ours: best "
        f"of {args.repeat} after a warm-up.  Times are wall (CPU of that run).\n"
    )
    print(
        "| leg (1809 m) | router | wall (cpu) | peer / ours wall (cpu) | route time s "
        "| ours − peer s "
        "| notes |"
    )
    print("|---|---|---:|---:|---:|---:|---|")
    legs = peer_cases()
    for i in args.legs or range(len(legs)):
        _peer_rows(legs[i], ours_polar, peer_polar, args)


def _peer_rows(leg: PeerLeg, ours_polar: Polar, peer_polar: Any, args: argparse.Namespace) -> None:
    """Print the rows of one leg: the peer, then ours in both configurations."""

    def peer_run(max_steps: int | None = None) -> PeerRun:
        return run_peer(leg, peer_polar, args.dt, max_steps=max_steps, subdiv=args.peer_subdiv)

    peer_run(PEER_WARMUP_STEPS)
    tp, peer = best_of(peer_run, args.peer_repeat, warmup=False)
    print(
        f"| {leg.name} | weatherrouting 0.2.3 | {tp} | | {peer.time_s:.1f} | | "
        f"{peer.steps} steps, front {peer.mean_front:.0f} pts mean; wind callback "
        f"{peer.wind_calls} calls, {100 * peer.wind_s / tp.wall:.1f} % of wall |"
    )
    for label, st in our_settings(args.dt).items():

        def ours(st: RoutingSettings = st) -> LegResult:
            return route_leg(leg.start, leg.target, leg.t0, leg.wind, ours_polar, st)

        to, res = best_of(ours, args.repeat)
        diff = res.time_s - peer.time_s
        print(
            f"| | {label} | {to} | {tp.wall / to.wall:,.0f}x ({tp.cpu / to.cpu:,.0f}x) | "
            f"{res.time_s:.1f} | "
            f"{diff:+.1f} ({100 * diff / peer.time_s:+.2f} %) | {res.n_tacks} tacks, "
            f"{res.n_gybes} gybes, sailed {res.distance_m:.0f} m |"
        )


# ------------------------------------------------------------------------------------
# grid DP on the paper's problem


def section_griddp(args: argparse.Namespace) -> None:
    """Print our grid DP at C = 32, 64, 128 beside Dębski's (2016) numbers."""
    from sailroute.boat.dynamic import DynamicBoat

    print("\n## Grid DP on Dębski's (2016) test problem\n")
    boat = DynamicBoat()
    tic = time.perf_counter()
    boat.table()
    print(
        f"Dynamic boat, 800 m x 500 m, 12 m/s wind 5° off the leg axis, one core.  Segment "
        f"lookup table built once outside the timings ({time.perf_counter() - tic:.2f} s).  "
        f"Paper setup: R = {PAPER_ROWS} rows, one pass, wind sampled once per segment; "
        "defaults: R = 13, 3 passes (2 refinements), 4 wind samples per segment.  Best of "
        f"{args.dp_repeat} after a warm-up.\n"
    )
    print(
        "| setup | C | wall (cpu) | route t_f s | paper t_f s | paper wall (C = 128) "
        "| paper / ours |"
    )
    print("|---|---:|---:|---:|---:|---|---:|")
    wind, target = UniformWind(12.0, 5.0), Target("mark", (0.0, 500.0))
    cols = (32, 64) if args.quick else (32, 64, 128)
    setups = {
        f"paper (R {PAPER_ROWS}, 1 pass)": dict(dp_rows=PAPER_ROWS, dp_refinements=0, dp_samples=1),
        "defaults (R 13, 3 passes)": {},
    }
    for name, kw in setups.items():
        for c in cols:
            st = routing_settings(
                router="griddp",
                dp_cols=c,
                dp_half_width_m=400.0,
                zone_m=bench_griddp.POINT_ZONE_M,
                **kw,
            )
            tm, res = best_of(
                lambda st=st: route_leg(bench_griddp.A, target, 0.0, wind, boat, st), args.dp_repeat
            )
            paper = ratio = ""
            if c == 128:
                paper = f"{PAPER_SERIAL_S:g} s serial / {PAPER_GPU_S:g} s GPU"
                ratio = f"{PAPER_SERIAL_S / tm.wall:,.0f}x / {PAPER_GPU_S / tm.wall:,.1f}x"
            print(
                f"| {name} | {c} | {tm} | {res.time_s:.2f} | "
                f"{bench_griddp.PAPER_TF[c]:.2f} | {paper} | {ratio} |"
            )


# ------------------------------------------------------------------------------------
# isochrone router per leg and per course


class _LegClock:
    """A stand-in for :class:`~sailroute.progress.Progress` that times each leg."""

    def __init__(self) -> None:
        self.times: list[Timing] = []
        self._start = (0.0, 0.0)

    def start_leg(self, index: int, label: str) -> None:
        """Start the clock of leg ``index``."""
        del index, label
        self._start = (time.perf_counter(), time.process_time())

    def update(self, fraction: float | None = None, note: str = "") -> None:
        """Progress within a leg (ignored)."""
        del fraction, note

    def end_leg(self, leg_time_s: float, summary: str = "") -> None:
        """Stop the clock of the current leg."""
        del leg_time_s, summary
        self.times.append(
            Timing(time.perf_counter() - self._start[0], time.process_time() - self._start[1])
        )

    def set_prefix(self, text: str) -> None:
        """Scenario prefix (ignored)."""
        del text


def _route_course(
    course: Any, wind: WindField, boat: Any, st: RoutingSettings
) -> list[tuple[Timing, LegResult]]:
    """Route every leg in order, chained in time and place; ``(timing, result)`` per leg.

    Uses :func:`planning.route.route_course` (the ``plan`` command's leg chaining,
    rounding rules included), timed per leg through its progress hooks.
    """
    from sailroute.planning.route import route_course

    clock = _LegClock()
    results = route_course(course, wind, boat, st, progress=clock)
    return list(zip(clock.times, results, strict=True))


def _plan_course_wall(course: Any, scenario: str, repeat: int) -> str:
    """Best wall time of :func:`sailroute.planning.route.plan_course`, with its route time."""
    from sailroute.planning.route import plan_course

    tm, out = best_of(lambda: plan_course(course, scenario), repeat)
    return f"{tm} wall (cpu), route {out.plan.total_time_s:.1f} s"


def section_course(args: argparse.Namespace) -> None:
    """Print our isochrone router per leg and per full course on Hyères R1."""
    from sailroute.course.load import build_boat, build_wind, load_course

    course = load_course(COURSE)
    st = dataclasses.replace(course.routing, router="isochrone")
    print(f"\n## Isochrone router per leg and per course: {COURSE.relative_to(ROOT)}\n")
    print(
        f"Course settings: dt {st.isochrone.dt_s:g} s, heading step "
        f"{st.isochrone.heading_step_deg:g}°, tack "
        f"{st.tack_penalty_s:g} s, gybe {st.gybe_penalty_s:g} s.  Legs chained in time and "
        f"place by `planning.route.route_course` (as `sailroute plan` does); wind and boat "
        f"built once outside the leg timings.  Best of "
        f"{args.course_repeat} after a warm-up (per leg: best over the runs).\n"
    )
    boat = build_boat(course)
    for scenario in COURSE_SCENARIOS:
        tic = time.perf_counter()
        wind = build_wind(course, scenario)
        built = time.perf_counter() - tic
        runs = [_route_course(course, wind, boat, st) for _ in range(args.course_repeat + 1)][1:]
        totals = [Timing(sum(t.wall for t, _ in r), sum(t.cpu for t, _ in r)) for r in runs]
        legs = runs[-1]
        print(f"### Scenario `{scenario}` (wind built in {_fmt_s(built)})\n")
        print("| leg | from -> to | wall (cpu) | route time s | tacks | gybes |")
        print("|---:|---|---:|---:|---:|---:|")
        for i, spec in enumerate(course.legs):
            tm = min((r[i][0] for r in runs), key=lambda t: t.wall)
            res = legs[i][1]
            print(
                f"| {i + 1} | {spec.label} | {tm} | {res.time_s:.1f} | "
                f"{res.n_tacks} | {res.n_gybes} |"
            )
        route = sum(res.time_s for _, res in legs)
        total = min(totals, key=lambda t: t.wall)
        print(f"| | **course** | **{total}** | **{route:.1f}** | | |")
        print(
            f"\n`plan_course` end to end (validates the specs, builds wind and boat, "
            f"routes, makes the plan): {_plan_course_wall(course, scenario, 1)}\n"
        )


# ------------------------------------------------------------------------------------
# CLI start-up


def _time_process(
    cmd: Sequence[str], env: dict[str, str], repeat: int, cwd: Path = ROOT
) -> tuple[Timing, int]:
    """Best wall time of ``repeat`` fresh processes, its CPU time, and the last exit code."""
    best, rc = Timing(math.inf, math.inf), 0
    for _ in range(repeat):
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        tic = time.perf_counter()
        rc = subprocess.run(
            cmd, env=env, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=False
        ).returncode
        wall = time.perf_counter() - tic
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
        best = min(best, Timing(wall, cpu), key=lambda t: t.wall)
    return best, rc


def _sailroute_exe() -> str:
    """The ``sailroute`` console script next to this interpreter, else on PATH."""
    exe = Path(sys.executable).with_name("sailroute")
    if exe.is_file():
        return str(exe)
    return shutil.which("sailroute") or "sailroute"


def _cli_commands(out: Path) -> dict[str, list[str]]:
    """Label -> command line of the start-up and main-job timings."""
    exe, py = _sailroute_exe(), sys.executable
    course = str(COURSE.relative_to(ROOT))
    imports = {
        m: [py, "-c", f"import {m}"]
        for m in (
            "numpy",
            "scipy.interpolate",
            "matplotlib.pyplot",
            "sailroute.cli",
            "sailroute.planning.route",
        )
    }
    return {
        'python -c "pass"': [py, "-c", "pass"],
        **{f'python -c "import {m}"': c for m, c in imports.items()},
        "sailroute --help": [exe, "--help"],
        "sailroute plan courses/hyeres-r1.yaml --no-plots": [
            exe,
            "plan",
            course,
            "--out",
            str(out / "plan"),
            "--quiet",
            "--no-plots",
        ],
        "sailroute plan courses/hyeres-r1.yaml": [
            exe,
            "plan",
            course,
            "--out",
            str(out / "plan"),
            "--quiet",
        ],
        "sailroute plan courses/hyeres-r1.yaml -s wrf10": [
            exe,
            "plan",
            course,
            "-s",
            "wrf10",
            "--out",
            str(out / "plan"),
            "--quiet",
        ],
    }


def section_cli(args: argparse.Namespace) -> None:
    """Print the wall time of the CLI as fresh processes, cold and warm bytecode cache."""
    out = Path(tempfile.mkdtemp(prefix="bench-peers-"))
    base = {k: v for k, v in os.environ.items() if not k.startswith("PYTHONPYCACHE")}
    cold = dict(base, PYTHONDONTWRITEBYTECODE="1", PYTHONPYCACHEPREFIX=str(out / "empty"))
    warm = {k: v for k, v in base.items() if k != "PYTHONDONTWRITEBYTECODE"}
    warm["PYTHONPYCACHEPREFIX"] = str(out / "pycache")
    print("\n## CLI start-up and the main job (fresh processes)\n")
    print(
        f"Best of {args.cli_repeat} (plan: best of {args.plan_repeat}), wall (CPU of the "
        "child).  *No bytecode cache*: every module is compiled at import (how this "
        "sandbox runs: PYTHONDONTWRITEBYTECODE=1 and no .pyc files in the venv); *with "
        "cache*: a primed .pyc cache in a temporary PYTHONPYCACHEPREFIX, as after a normal "
        "pip install.  `plan` writes JSON/CSV/GPX and, without --no-plots, route.png.\n"
    )
    print("| command | no bytecode cache | with cache | exit |")
    print("|---|---:|---:|---:|")
    for label, cmd in _cli_commands(out).items():
        n = args.plan_repeat if "plan " in label else args.cli_repeat
        t_cold, _ = _time_process(cmd, cold, n)
        _time_process(cmd, warm, 1)  # prime the cache
        t_warm, rc = _time_process(cmd, warm, n)
        print(f"| `{label}` | {t_cold} | {t_warm} | {rc} |")
    if args.cli_baseline:
        _compare_plan(Path(args.cli_baseline).resolve(), warm, out, args.plan_repeat)
    shutil.rmtree(out, ignore_errors=True)


def _compare_plan(baseline: Path, env: dict[str, str], out: Path, rounds: int) -> None:
    """``sailroute plan`` with this tree's code and with ``baseline``'s (a checkout of older
    code), alternating, ``rounds`` each after one warm-up of each; primed bytecode caches.

    Both run as ``python -m sailroute`` from a temporary folder with ``PYTHONPATH`` set to
    their tree (``-m`` would put the working folder first)."""
    trees = {"baseline": baseline, "this tree": ROOT}
    course = str(COURSE)
    print(
        f"\n`sailroute plan {COURSE.relative_to(ROOT)}` against {baseline} "
        f"({_git_rev(baseline)}), alternating, {rounds} runs each (wall s, sorted):\n"
    )
    print("| command | baseline | this tree | ratio of medians |")
    print("|---|---|---|---:|")
    for flags in ([], ["--no-plots"]):
        walls: dict[str, list[float]] = {k: [] for k in trees}
        for i in range(rounds + 1):
            for name, tree in trees.items():
                cmd = [
                    sys.executable,
                    "-m",
                    "sailroute",
                    "plan",
                    course,
                    "--out",
                    str(out / "cmp"),
                    "--quiet",
                    *flags,
                ]
                t, rc = _time_process(cmd, dict(env, PYTHONPATH=str(tree)), 1, cwd=out)
                if rc != 0:
                    raise SystemExit(f"{name}: {' '.join(cmd)} exited with {rc}")
                if i > 0:  # the first round primes the caches
                    walls[name].append(t.wall)
        med = {k: statistics.median(v) for k, v in walls.items()}
        cells = [", ".join(f"{w:.2f}" for w in sorted(walls[k])) for k in trees]
        print(
            f"| `plan {' '.join(flags)}` | {cells[0]} | {cells[1]} | "
            f"{med['this tree'] / med['baseline']:.3f} |"
        )


def _git_rev(tree: Path) -> str:
    """Short commit of ``tree`` (or "?")."""
    res = subprocess.run(
        ["git", "-C", str(tree), "rev-parse", "--short", "HEAD"],
        capture_output=True,
        text=True,
        check=False,
    )
    return res.stdout.strip() or "?"


# ------------------------------------------------------------------------------------
# profile


def section_profile(args: argparse.Namespace) -> None:
    """cProfile ``route_leg`` on Hyères leg 1, scenario wrf10; print the top functions."""
    from sailroute.course.load import build_boat, build_wind, load_course

    course = load_course(COURSE)
    wind, boat = build_wind(course, "wrf10"), build_boat(course)
    st = dataclasses.replace(course.routing, router="isochrone")
    start, target = _first_leg(course)

    def leg() -> LegResult:
        return route_leg(start, target, course.start_epoch, wind, boat, st)

    tm, res = best_of(leg, 3)
    prof = cProfile.Profile()
    prof.runcall(leg)
    stats = pstats.Stats(prof)
    total = sum(v[2] for v in stats.stats.values())  # type: ignore[attr-defined]
    print("\n## Profile: `route_leg`, Hyères R1 leg 1 (start line -> 1), scenario wrf10\n")
    print(
        f"Unprofiled {tm} wall (cpu), best of 3; route {res.time_s:.1f} s.  Under "
        f"cProfile {_fmt_s(total)} of own time in all functions; top {args.top} by own "
        "time (cumulative = with callees):\n"
    )
    print("| function | calls | own s | own % | cumulative % |")
    print("|---|---:|---:|---:|---:|")
    rows = sorted(stats.stats.items(), key=lambda kv: kv[1][2], reverse=True)  # type: ignore[attr-defined]
    for (file, line, func), (_, ncalls, own, cum, _) in rows[: args.top]:
        where = _short_path(file)
        print(
            f"| `{func}` ({where}:{line}) | {ncalls} | {own:.3f} | {100 * own / total:.1f} | "
            f"{100 * cum / total:.1f} |"
        )
    print("\nCumulative share of some entry points (with callees):\n")
    for label, (part, name) in PROFILE_GROUPS.items():
        cum = sum(
            v[3]
            for (f, _, fn), v in stats.stats.items()  # type: ignore[attr-defined]
            if part in f.replace(os.sep, "/") and fn == name
        )
        print(f"- {label}: {100 * cum / total:.1f} %")


def _first_leg(course: Any) -> tuple[Start, Target]:
    """Leg 1 of ``course`` as ``sailroute plan`` routes it (rounding exit towards leg 2)."""
    from sailroute.course.geometry import leg_endpoints, target_of
    from sailroute.routing.geometry import chain_leg

    start, target = leg_endpoints(course, 0)
    following = target_of(course, 1) if course.n_legs > 1 else None
    return chain_leg(start, target, None, following)


PROFILE_GROUPS: dict[str, tuple[str, str]] = {
    "wind sampling (`GridWind.sample`)": ("sailroute/wind/grid.py", "sample"),
    "polar lookups (`Polar.speed`)": ("sailroute/boat/polar.py", "speed"),
    "polar tables (`polar_tables`, cached after the first leg)": (
        "sailroute/routing/isochrone_polar.py",
        "polar_tables",
    ),
    "candidate set-up (`_prepare`)": ("sailroute/routing/isochrone_inputs.py", "_prepare"),
    "expansion and arrival test (`_expand`)": ("sailroute/routing/isochrone_kernel.py", "_expand"),
    "pruning (`_survivors`)": ("sailroute/routing/isochrone_kernel.py", "_survivors"),
    "track building (`_backtrack`)": ("sailroute/routing/isochrone.py", "_backtrack"),
}
"""Profile summary rows: label -> (file path part, function name)."""


def _short_path(file: str) -> str:
    """A profile entry's file relative to its package root (``sailroute/...``, ``numpy/...``)."""
    f = file.replace(os.sep, "/")
    if "site-packages/" in f:
        return f.split("site-packages/", 1)[1]
    if "/sailroute/" in f:
        return "sailroute/" + f.split("/sailroute/", 1)[1]
    if "/lib/python3" in f:  # standard library: drop ".../lib/python3.X/"
        return f.split("/lib/python3", 1)[1].split("/", 1)[-1]
    return f


# ------------------------------------------------------------------------------------


SECTIONS: dict[str, Callable[[argparse.Namespace], None]] = {
    "peer": section_peer,
    "griddp": section_griddp,
    "course": section_course,
    "cli": section_cli,
    "profile": section_profile,
}


def main(argv: Sequence[str] | None = None) -> None:
    """Parse the options and run the chosen sections."""
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("--only", nargs="+", choices=list(SECTIONS), default=list(SECTIONS))
    ap.add_argument("--quick", action="store_true", help="fewer repeats, no C = 128")
    ap.add_argument("--dt", type=float, default=30.0, help="time step of both routers [s]")
    ap.add_argument("--repeat", type=int, default=7, help="our runs per leg")
    ap.add_argument("--peer-repeat", type=int, default=1, help="peer runs per leg")
    ap.add_argument(
        "--peer-subdiv",
        type=float,
        default=1.0,
        help="peer pruning sector width [deg] (its `subdiv`)",
    )
    ap.add_argument(
        "--legs",
        type=int,
        nargs="+",
        default=None,
        help="peer legs to run, by index (0 beat, 1 reach, 2 run, 3 WRF beat)",
    )
    ap.add_argument("--dp-repeat", type=int, default=3)
    ap.add_argument("--course-repeat", type=int, default=3)
    ap.add_argument("--cli-repeat", type=int, default=5)
    ap.add_argument("--plan-repeat", type=int, default=3)
    ap.add_argument(
        "--cli-baseline",
        default=None,
        metavar="DIR",
        help="cli section: also time `plan` against the code in DIR (a checkout "
        "of an older commit), alternating, --plan-repeat runs each",
    )
    ap.add_argument("--top", type=int, default=15, help="profile rows")
    ap.add_argument(
        "--smoke",
        action="store_true",
        help="the profile section only, 5 rows (checks the script runs)",
    )
    args = ap.parse_args(argv)
    if args.smoke:
        args.only, args.top = ["profile"], 5
    if args.quick:
        args.repeat, args.dp_repeat, args.course_repeat = 3, 1, 1
        args.cli_repeat, args.plan_repeat = 3, 1
    print("# sailroute performance benchmark (benchmarks/bench_peers.py)\n")
    print("\n".join(machine_lines()))
    for name in args.only:
        SECTIONS[name](args)
    load = os.getloadavg() if hasattr(os, "getloadavg") else (float("nan"),) * 3
    print(f"\nLoad average at the end: {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")


if __name__ == "__main__":
    main()
