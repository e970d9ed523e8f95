"""The compiled isochrone step: the NumPy step's inputs, candidates and survivors, through numba.

:func:`prepare` is :func:`~sailroute.routing.isochrone_inputs._prepare` (still water),
:func:`candidates` the candidate loop of :func:`~sailroute.routing.isochrone_kernel._step`
(every candidate move, its score, the arrival and the best per sector and side) and
:func:`survivors` :func:`~sailroute.routing.isochrone_kernel._survivors`, through the
kernels of :mod:`sailroute.routing.isochrone_jit`, with the same results bit for bit: a
few hundred NumPy calls per step become nine compiled calls and about fifteen NumPy calls
(the trigonometric functions, kept NumPy's: :mod:`~sailroute.routing.isochrone_jit`).
The wind and current are sampled as on the NumPy path, in one call per step; the polar is
looked up once per step (a PCHIP polar inside the kernels, from its dense table).

:func:`compiled` says whether a step takes this path (``routing.engine``, NumPy arrays,
numba installed, and for ``auto`` whether the work pays for the kernels' start-up); the
kernels are loaded only then (:func:`kernels`): the module compiled ahead of time
(:mod:`~sailroute.routing.isochrone_aot`, no numba imported) where it is built, else
numba's.  The NumPy functions do what this path leaves to
them: the candidates of a step in a race area (:class:`~sailroute.routing.obstacles.
Obstacles`) and the inputs of a step in a surface current (its candidates are still
compiled, :func:`pack`).
"""

from __future__ import annotations

import gc
import hashlib
import importlib.util
import math
import os
import threading
import time
from pathlib import Path
from types import ModuleType
from typing import Any, Final, NamedTuple

import numpy as np

from sailroute.boat.polar import Polar
from sailroute.errors import InputError
from sailroute.routing import isochrone_aot
from sailroute.routing.geometry import barrier_segment, segment_frame
from sailroute.routing.isochrone_inputs import (
    _barrier_ray,
    _fan,
    _group_fans,
    _segment_params,
    _step_length,
)
from sailroute.routing.isochrone_polar import PointPolars, _DeviceTables, support_rows
from sailroute.routing.isochrone_records import (
    _CHUNK_ELEMENTS,
    Groups,
    _Context,
    _ExactColumns,
    _Layer,
    _ManoeuvreState,
    _PointWind,
    _StepInputs,
    _TimeToGo,
)
from sailroute.routing.settings import ENGINES, RoutingSettings
from sailroute.wind.base import WindField

__all__ = ["candidates", "compiled", "pack", "prepare", "survivors"]

_CALL_CANDIDATES = 60000
"""Candidates per :func:`~sailroute.routing.isochrone_jit.candidates` call (whole NumPy
chunks): their buffers (28 bytes each) stay in the L2 cache."""

_NO_FLOATS = np.zeros((0, 0))
_NO_INTS = np.zeros((0, 0), dtype=np.int64)
_NONE = np.zeros(0)
_NO_MEMBERS = np.zeros(0, dtype=np.int64)
_NO_FLAGS = np.zeros(0, dtype=np.bool_)


AVAILABLE: Final = importlib.util.find_spec("numba") is not None
"""Whether numba is installed (it is imported when a step first takes the compiled
path)."""

JIT_AFTER_S: Final = 1.5
"""With ``routing.engine = "auto"``, the compiled kernels take over once this process
has spent this long [s of CPU] in NumPy steps, for a front that holds several members
(:mod:`sailroute.routing.batch`), or where they are built already
(:func:`kernels_cached`).  Loading them costs a few milliseconds from the ahead-of-time
module (:mod:`~sailroute.routing.isochrone_aot`) and about 0.35 s of CPU from numba's
cache (numba's start-up, :mod:`sailroute.jit`), less than the NumPy steps of one plan of
a course (about 0.8 s); compiling them, about 12-15 s, pays for a batch, a comparison or
a day of live re-plans, not for one plan."""


STEP_KERNELS: Final = tuple(isochrone_aot.SIGNATURES)
"""The kernels of :mod:`~sailroute.routing.isochrone_jit` that a step calls."""

_PYCACHE: Final = Path(__file__).parent / "__pycache__"
"""Where numba caches the kernels, unless ``NUMBA_CACHE_DIR`` says otherwise or the
folder is read-only (:func:`_cache_folder`)."""


_LOADING = threading.Lock()
"""Held while the kernels are loaded or built (:func:`kernels`)."""


class _Usage:
    """What this process has done so far (:func:`compiled`)."""

    numpy_s = 0.0  # CPU time spent in NumPy steps [s]
    kernels: Any = None  # the kernels in use (kernels()), once chosen
    jit: ModuleType | None = None  # isochrone_jit, once imported
    cached: bool | None = None  # kernels_cached(), once asked
    build_failed = False  # an ahead-of-time build failed in this process


def kernels() -> Any:
    """The compiled kernels: the ahead-of-time module of
    :mod:`~sailroute.routing.isochrone_aot` for the current source (no numba to import),
    built now where there is none (about 12 s of CPU, once per install or change of the
    kernels), or, where it cannot be built (no C compiler or no Python headers, or the
    build failed), the kernels numba compiles just in time (:func:`_just_in_time`)."""
    if _Usage.kernels is None:
        with _LOADING:  # threads routing at once build or load them once
            if _Usage.kernels is None:
                _Usage.kernels = _ahead_of_time() or _just_in_time()
    return _Usage.kernels


def _ahead_of_time() -> isochrone_aot.Kernels | None:
    """The ahead-of-time kernels, loaded or built (:func:`kernels`); None where there is
    no module and none can be built."""
    folder = _cache_folder()
    module = isochrone_aot.load(folder)
    if module is None and folder is not None and not _Usage.build_failed:
        if not isochrone_aot.can_build():
            return None
        try:
            isochrone_aot.build(folder, _just_in_time())
        except Exception:  # any compiler failure: the JIT kernels serve
            _Usage.build_failed = True
            return None
        module = isochrone_aot.load(folder)
    return None if module is None else isochrone_aot.Kernels(module, _just_in_time)


def _just_in_time() -> ModuleType:
    """:mod:`sailroute.routing.isochrone_jit`, numba's just-in-time kernels (imports
    numba and loads its registries, :func:`sailroute.jit.load_registries`, with the
    cyclic garbage collector paused: its full passes over numba's new objects cost about
    0.05 s of CPU and find nothing)."""
    if _Usage.jit is None:
        collecting = gc.isenabled()
        gc.disable()  # numba's start-up makes objects that all live on: no cycles to find
        try:
            from sailroute.jit import load_registries
            from sailroute.routing import isochrone_jit

            load_registries()
        finally:
            if collecting:
                gc.enable()
        _Usage.jit = isochrone_jit
    return _Usage.jit


def kernels_cached() -> bool:
    """Whether the compiled step kernels (:data:`STEP_KERNELS`) load without compiling,
    from the ahead-of-time module built for the current source
    (:mod:`~sailroute.routing.isochrone_aot`: a few milliseconds) or from numba's cache
    (about 0.35 s: numba's start-up), rather than being compiled (about 12-15 s).

    A look at the cache folder comes first; numba is imported only where it holds the
    just-in-time kernels (or where the folder is elsewhere).  Those count only where
    numba itself loads from its bytecode (no ``.pyc``: :func:`_numba_bytecode`).  Asked
    once per process.
    """
    if _Usage.cached is None:
        _Usage.cached = _step_kernels_in_cache()
    return _Usage.cached


def _cache_folder() -> Path | None:
    """The folder where numba caches the kernels, by its own rule (``NUMBA_CACHE_DIR``:
    a subfolder named after the source folder and its SHA-1; else ``__pycache__``); None
    where the source tree is read-only (numba's user-wide cache directory)."""
    src = os.path.abspath(_PYCACHE.parent)
    env = os.environ.get("NUMBA_CACHE_DIR")
    if env:
        return Path(env) / f"{os.path.basename(src)}_{hashlib.sha1(src.encode()).hexdigest()}"
    return _PYCACHE if os.access(_PYCACHE if _PYCACHE.exists() else src, os.W_OK) else None


def _numba_bytecode() -> bool:
    """Whether numba's modules load from their compiled bytecode (``.pyc``, under
    ``PYTHONPYCACHEPREFIX`` where it is set): from source its import and first call
    cost about 2 s of CPU more."""
    spec = importlib.util.find_spec("numba")  # does not import it
    if spec is None or spec.origin is None:
        return False
    root = Path(spec.origin).parent
    return all(
        Path(importlib.util.cache_from_source(str(py))).is_file()
        for py in (root / "__init__.py", root / "np" / "arraymath.py")
    )


def _step_kernels_in_cache() -> bool:
    folder = _cache_folder()
    if folder is not None and isochrone_aot.module_path(folder).is_file():
        return True
    return _numba_bytecode() and _jit_kernels_in_cache()


def _jit_kernels_in_cache() -> bool:
    """Whether numba's cache holds every step kernel compiled just in time."""
    folder = _cache_folder()
    if folder is not None and not any(folder.glob("isochrone_jit.candidates-*.nbi")):
        return False  # nothing compiled yet: no need to import numba to know it
    from sailroute.routing import isochrone_jit

    try:  # numba's cache index (private: another numba version may lack it)
        return all(
            bool(getattr(isochrone_jit, name)._cache._cache_file._load_index())
            for name in STEP_KERNELS
        )
    except (AttributeError, OSError, EOFError, ValueError):
        return False


def compiled(settings: RoutingSettings, xp: Any, *, members: int = 1) -> bool:
    """Whether a step takes the compiled path: ``routing.engine`` "numba", or "auto" with
    numba installed once the work pays for its start-up: a front of several
    ``members``, enough NumPy steps already (:data:`JIT_AFTER_S`), or kernels that a
    run has compiled before (:func:`kernels_cached`: loading them costs less than the
    NumPy steps of one plan save); NumPy arrays only.

    Raises
    ------
    InputError
        ``routing.engine`` is "numba" and numba is not installed.
    """
    engine = settings.isochrone.engine
    if engine == "numba" and not AVAILABLE:
        raise InputError(
            "routing.engine = 'numba' needs numba, which is not installed: "
            "pip install 'sailroute[fast]', or use engine 'auto' (numba where installed) "
            f"or 'numpy' (one of {', '.join(ENGINES)}; the routes are the same)"
        )
    if xp is not np or engine == "numpy" or not AVAILABLE:
        return False
    return (
        engine == "numba"
        or members > 1
        or _Usage.kernels is not None
        or _Usage.numpy_s >= JIT_AFTER_S
        or kernels_cached()
    )


def numpy_step_started() -> float:
    """CPU clock at the start of a NumPy step [s] (:func:`numpy_step_done`)."""
    return time.process_time()


def numpy_step_done(started: float) -> None:
    """Count a NumPy step's CPU time towards :data:`JIT_AFTER_S`."""
    _Usage.numpy_s += time.process_time() - started


class Packed(NamedTuple):
    """The arrays of one step as the candidate kernel takes them (views of them make up
    the :class:`~sailroute.routing.isochrone_records._StepInputs`).

    Attributes
    ----------
    move : ndarray, shape (6, n)
        The wind of the move: TWS, upwind unit vector x and y, table weight, upwind and
        downwind VMG angle.
    move_row : ndarray of int, shape (n,)
        Its table rows.
    man : ndarray, shape (4, n)
        Side, |TWA| before a manoeuvre, penalty onto upwind and onto downwind.
    flags : ndarray of bool, shape (2, n)
        Free, pending.
    exact : ndarray, shape (4, n, 4)
        The exact columns: |TWA|, boat speed, cosine and sine.
    direct_sin : ndarray, shape (2, n)
        Signed sines of the direct columns of either block.
    ttg : ndarray, shape (3, 2, n)
        Time to go and its gradient, per block.
    """

    move: Any
    move_row: Any
    man: Any
    flags: Any
    exact: Any
    direct_sin: Any
    ttg: Any

    def front(self, pre: _StepInputs) -> tuple[Any, ...]:
        """The step's arrays as the candidate and survivor kernels take them
        (:data:`~sailroute.routing.isochrone_jit.FRONT`)."""
        m = pre.manoeuvre
        return (
            pre.x,
            pre.y,
            self.move,
            self.move_row,
            self.man,
            self.flags,
            m.debt_s,
            m.charged_s,
            self.exact,
            self.direct_sin,
            self.ttg,
        )


# --------------------------------------------------------------------------------------
# the inputs of a step


def prepare(
    f: _Layer,
    wind: WindField,
    polar: Polar | PointPolars,
    dev: _DeviceTables,
    ctx: _Context,
    s: RoutingSettings,
    tau_hint: float,
    groups: Groups | None = None,
    dt: Any = None,
) -> tuple[_StepInputs, Any, Any] | None:
    """:func:`~sailroute.routing.isochrone_inputs._prepare`, compiled; None in a current
    (the NumPy function prepares those steps)."""
    if ctx.current is not None:
        return None
    x, y = f.x, f.y
    n = int(x.shape[0])
    dt = _step_length(s, tau_hint) if dt is None else dt
    dts = _per_point(dt)
    geo = _geometry(ctx, dev)
    hr = np.radians(f.heading)
    way, pt, px, py = (np.empty((5, n)) for _ in range(4))
    kernels().sample_points(
        x,
        y,
        np.sin(hr),
        np.cos(hr),
        f.debt,
        f.bsp,
        f.tau_est,
        np.asarray(f.t, dtype=float).reshape(-1),
        dts,
        float(s.max_leg_time_s),
        geo.aim,
        geo.frame,
        _cover(wind),
        way,
        pt,
        px,
        py,
    )
    u, v = wind.sample(pt.reshape(-1), px.reshape(-1), py.reshape(-1))
    u = np.ascontiguousarray(np.asarray(u, dtype=float).reshape(5, n))
    v = np.ascontiguousarray(np.asarray(v, dtype=float).reshape(5, n))

    move, mean = np.empty((6, n)), np.empty((6, n))
    move_row, mean_row = np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64)
    man = np.empty((4, n))
    flags = np.empty((2, n), dtype=np.bool_)
    sup_y, sup_x, vmg_rad = np.empty((2, n)), np.empty(n), np.empty((n, 2))
    point_polar = polar.index if isinstance(polar, PointPolars) else None
    node_range = (
        _NO_INTS
        if point_polar is None
        else np.stack([dev.node_start[point_polar], dev.node_count[point_polar]])
    )
    any_pending = kernels().wind_states(
        u,
        v,
        geo.frame,
        dev.tws_ms,
        node_range,
        dev.up_deg,
        dev.down_deg,
        f.side,
        f.pend_old,
        f.abs_twa,
        geo.penalties,
        geo.normal,
        move,
        move_row,
        mean,
        mean_row,
        man,
        flags,
        sup_y,
        sup_x,
        vmg_rad,
    )
    move_wind = _PointWind(move[0], move[1], move[2], move_row, move[3], move[4], move[5])
    if groups is None:
        first, stop = _fan(dev, move_wind, ctx.fan_hull, np)
        fan_lo = fan_hi = None
    else:
        first, stop, fan_lo, fan_hi = _group_fans(dev, move_wind, ctx.fan_hull, groups)

    beta = np.degrees(np.arctan2(sup_y, sup_x))  # the support's bearing, per side
    best, sig, rad = np.empty((2, n)), np.empty((2, n)), np.empty((2, n))
    support_rows(dev, move_row)
    kernels().support_headings(
        move_row, move[3], beta, dev.sup_ms, dev.sup_deg, man[0], best, sig, rad
    )
    aims, cosines, sines = np.empty((3, 2, n)), np.empty((2, 2, n)), np.empty((2, 2, n))
    kernels().aim_directions(
        x,
        y,
        way,
        move,
        mean,
        best,
        sig,
        np.cos(rad),
        np.sin(rad),
        geo.aim,
        geo.normal,
        aims,
        cosines,
        sines,
    )
    angles = np.degrees(np.arccos(cosines))
    exact = np.empty((4, n, 4))
    twa = exact[0]
    twa[:, 0] = move[4]
    twa[:, 1] = move[5]
    twa[:, 2] = angles[0, 0]
    twa[:, 3] = angles[0, 1]
    bsp = exact[1]
    _speeds(polar, move[0], twa, bsp)

    first_clear = (
        _NONE
        if groups is None or groups.clearance is None
        else np.asarray(groups.clearance, dtype=float)[groups.member]
    )
    ttg = np.empty((3, 2, n))
    reach = np.empty(n)
    near = np.empty(n, dtype=np.bool_)
    near_rays = np.empty((len(ctx.barriers), n), dtype=np.bool_)
    n_groups = 1 if groups is None else groups.n_members
    least = np.empty((2, n_groups))
    box_clear = kernels().step_inputs(
        x,
        y,
        f.debt,
        move,
        move_row,
        mean,
        mean_row,
        man,
        flags,
        aims,
        cosines,
        sines,
        angles,
        np.cos(vmg_rad),
        np.sin(vmg_rad),
        bsp,
        geo.vmg,
        dev.vmax_ms,
        dev.speed_ms,
        np.array([ctx.tack_s, ctx.gybe_s, geo.inv_step, geo.inv_rad_step]),
        dts,
        geo.target,
        geo.rays,
        geo.ray_clear,
        first_clear,
        _NONE if ctx.box is None else np.asarray(ctx.box, dtype=float),
        geo.frame,
        _NO_MEMBERS if groups is None else groups.member,
        n_groups,
        exact,
        ttg,
        reach,
        near,
        near_rays,
        least,
    )
    pre = _StepInputs(
        t=f.t,
        dt=dt,
        first=first,
        stop=stop,
        x=x,
        y=y,
        wind=move_wind,
        exact=_ExactColumns(exact[0], exact[1], exact[2], exact[3], sines[0, 0], sines[0, 1]),
        keep=_TimeToGo(ttg[0, 0], ttg[1, 0], ttg[2, 0]),
        switch=_TimeToGo(ttg[0, 1], ttg[1, 1], ttg[2, 1]),
        manoeuvre=_ManoeuvreState(
            man[0], flags[0], flags[1], man[1], man[2], man[3], f.debt, f.pend_pen, any_pending
        ),
        near_target=near,
        near_barrier=tuple(close if close.any() else None for close in near_rays),
        group=None if groups is None else groups.member,
        n_groups=n_groups,
        fan_lo=fan_lo,
        fan_hi=fan_hi,
        box_clear=ctx.box is None or bool(box_clear),
        first_clear=None if groups is None or groups.clearance is None else first_clear,
        starts_free=ctx.obstacles is not None and not bool(np.any(f.parent < 0)),
        reach_m=reach,
        packed=Packed(move, move_row, man, flags, exact, sines[0], ttg),
    )
    if groups is None:
        return pre, float(least[0, 0]), float(least[1, 0])
    return pre, least[0], least[1]


def _per_point(dt: float | Any) -> Any:
    """The step length ``dt`` [s] as the kernels take it: one value, or one per point."""
    if isinstance(dt, float):
        return np.array([dt])
    return np.ascontiguousarray(dt, dtype=np.float64)


def _speeds(polar: Polar | PointPolars, tws: Any, twa: Any, out: Any) -> None:
    """``polar.speed(tws[:, None], twa)`` into ``out``: from the dense tables of PCHIP
    polars in the kernel, else one call of the polar."""
    dense = _dense_tables(polar.polars if isinstance(polar, PointPolars) else (polar,))
    if dense is None:
        out[...] = np.asarray(polar.speed(tws[None, :], twa.T), dtype=float).T
        return
    which = polar.index if isinstance(polar, PointPolars) else _NO_MEMBERS
    kernels().dense_speeds(dense[0], dense[1], which, tws, twa, out)


_DENSE: list[Any] = [((), None)]  # the last (polars, their stacked dense tables)


def _dense_tables(polars: tuple[Polar, ...]) -> tuple[Any, Any] | None:
    """The dense tables of ``polars`` one after the other, and their parameters, as
    :func:`~sailroute.routing.isochrone_jit.dense_speeds` takes them; None if one is not
    a PCHIP polar."""
    last, known = _DENSE[0]  # one read: another thread may replace it
    if len(polars) == len(last) and all(a is b for a, b in zip(polars, last, strict=True)):
        return known
    tables = [p.dense_table() for p in polars]
    cells, params, start = [], [], 0
    for table in tables:
        if table is None:
            return None
        inv_twa, inv_tws, tws_max, n_twa, n_tws, c = table
        cells.append(c)
        params.append((inv_twa, inv_tws, tws_max, n_twa, n_tws, start))
        start += c.shape[0]
    out = (cells[0] if len(cells) == 1 else np.concatenate(cells), np.array(params, dtype=float))
    _DENSE[0] = (polars, out)
    return out


def _cover(wind: WindField) -> Any:
    """The wind's coverage ``(t0, t1, xmin, xmax, ymin, ymax)``, where its samples are
    clipped."""
    c = wind.coverage
    return np.array([c.t0, c.t1, c.xmin, c.xmax, c.ymin, c.ymax], dtype=float)


class _Geometry(NamedTuple):
    """A leg's constants as the kernels take them (:func:`_geometry`)."""

    aim: Any  # geometry.segment_frame of the target
    frame: Any  # (cx, cy, fx, fy) of the leg frame
    normal: Any  # the target's normal
    target: Any  # the target segment (isochrone_inputs._segment_params)
    rays: Any  # (k, 5): the barriers' rays, likewise
    ray_clear: Any  # (k,): their clearances [m]
    bars: Any  # (k, 8): the segments the barriers test moves against, with the mark
    penalties: Any  # (tack, gybe) [s]
    vmg: Any  # (2, n_w): the upwind and downwind VMG of the polar tables [m/s]
    grid: Any  # (3, n_a): the grid's |TWA| [°], cosine and sine
    cross: Any  # the target as geometry.segment_crossing takes it: a, b - a, normal
    inv_step: float  # 1 / the grid's |TWA| step [1/°] (isochrone_togo._time_to_go)
    inv_rad_step: float  # 1 / the grid's |TWA| step [1/rad]


_GEOMETRY: list[Any] = [(None, None, None)]  # the last (ctx, dev, _Geometry)


def _geometry(ctx: _Context, dev: _DeviceTables) -> _Geometry:
    """The kernels' constants of a leg (kept for its next step)."""
    last_ctx, last_dev, known = _GEOMETRY[0]  # one read: another thread may replace it
    if last_ctx is ctx and last_dev is dev:
        return known
    fr = ctx.frame
    bars = []
    for b, _ in ctx.barriers:
        seg = barrier_segment(b)
        ax, ay = seg.a
        bars.append((ax, ay, seg.b[0] - ax, seg.b[1] - ay, *seg.normal, *b.mark))
    step = 180.0 / dev.twa_deg.shape[0]
    geo = _Geometry(
        aim=np.array(segment_frame(ctx.geom)),
        frame=np.array([fr.cx, fr.cy, fr.fx, fr.fy]),
        normal=np.array(ctx.geom.normal, dtype=float),
        target=np.array(_segment_params(ctx.geom)),
        rays=np.array([_segment_params(_barrier_ray(b)) for b, _ in ctx.barriers]).reshape(-1, 5),
        ray_clear=np.array([float(c) for _, c in ctx.barriers]),
        bars=np.array(bars, dtype=float).reshape(-1, 8),
        penalties=np.array([ctx.tack_s, ctx.gybe_s]),
        vmg=np.stack([dev.up_vmg_ms, dev.down_vmg_ms]),
        grid=np.stack([dev.twa_deg, dev.cos_a, dev.sin_a]),
        cross=np.array(
            [
                ctx.geom.a[0],
                ctx.geom.a[1],
                ctx.geom.b[0] - ctx.geom.a[0],
                ctx.geom.b[1] - ctx.geom.a[1],
                *ctx.geom.normal,
            ],
            dtype=float,
        ),
        inv_step=1.0 / step,
        inv_rad_step=1.0 / math.radians(step),
    )
    _GEOMETRY[0] = (ctx, dev, geo)
    return geo


# --------------------------------------------------------------------------------------
# the candidates and the winners


def pack(pre: _StepInputs) -> Packed:
    """The :class:`Packed` arrays of a step the NumPy function prepared."""
    w, m, ex = pre.wind, pre.manoeuvre, pre.exact
    return Packed(
        move=np.stack([w.tws_ms, w.up_x, w.up_y, w.weight, w.up_deg, w.down_deg]),
        move_row=np.ascontiguousarray(w.row, dtype=np.int64),
        man=np.stack([m.side, m.base_twa_deg, m.penalty_up_s, m.penalty_down_s]).astype(float),
        flags=np.stack([m.free, m.pending]).astype(np.bool_),
        exact=np.stack([ex.twa_deg, ex.bsp_ms, ex.cos_twa, ex.sin_twa]),
        direct_sin=np.stack([ex.direct_sin_keep, ex.direct_sin_switch]),
        ttg=np.stack(
            [
                np.stack([pre.keep.tau_s, pre.switch.tau_s]),
                np.stack([pre.keep.grad_x, pre.switch.grad_x]),
                np.stack([pre.keep.grad_y, pre.switch.grad_y]),
            ]
        ),
    )


_BUFFERS = threading.local()  # work arrays, one set per thread


def _buffer(name: str, size: int, dtype: Any) -> Any:
    """A work array of at least ``size`` elements, kept between steps (fresh large
    arrays are mapped and faulted in by the allocator at every step)."""
    buf = getattr(_BUFFERS, name, None)
    if buf is None or buf.shape[0] < size:
        buf = np.empty(max(size, 1024), dtype=dtype)
        setattr(_BUFFERS, name, buf)
    return buf


def candidates(pre: _StepInputs, dev: _DeviceTables, ctx: _Context) -> tuple[Any, Any, Any] | None:
    """Every candidate move of a step (no race area): ``(arrival, best, who)``, where
    ``arrival`` is the earliest crossing of the target or None (:func:`~sailroute.
    routing.isochrone_jit.candidates` writes it: the kernel's :func:`~sailroute.routing.
    isochrone_kernel._arrival_of` makes it an arrival), and ``best, who`` the best
    candidate per key (sector and side, per member) as the candidate loop of
    :func:`~sailroute.routing.isochrone_kernel._step` leaves them (score [s] and
    candidate id, infinite and 0 where a key has none); None where a score is NaN."""
    geo = _geometry(ctx, dev)
    p = pre.packed if pre.packed is not None else pack(pre)
    n, h = pre.n, pre.n_columns
    chunk = max(1, _CHUNK_ELEMENTS // (h + 3))
    rows = chunk * max(1, _CALL_CANDIDATES // (chunk * 2 * h))
    size = min(rows, n) * 2 * h
    score, qx, qy, phi = (
        _buffer("score", size, np.float64),
        _buffer("qx", size, np.float32),
        _buffer("qy", size, np.float32),
        _buffer("phi", size, np.float32),
    )
    segments = _buffer("segments", 2 * min(rows, n) * 4, np.int64).reshape(-1, 4)
    n_keys = 2 * ctx.n_bins * pre.n_groups
    best = np.full(n_keys, np.inf)
    who = np.zeros(n_keys, dtype=np.int64)
    current = _NO_FLOATS if pre.current_x is None else np.stack([pre.current_x, pre.current_y])
    fans = (
        _NO_INTS
        if pre.group is None
        else np.stack([pre.group * (2 * ctx.n_bins), pre.fan_lo, pre.fan_hi]).astype(np.int64)
    )
    near_bars = np.zeros((len(ctx.barriers), n), dtype=np.bool_)
    for k, close in enumerate(pre.near_barrier):
        if close is not None:
            near_bars[k] = close
    box = _NONE if ctx.box is None or pre.box_clear else np.asarray(ctx.box, dtype=float)
    origin = np.zeros(2) if ctx.bin_origin is None else np.asarray(ctx.bin_origin, dtype=float)
    near = pre.near_target if bool(np.any(pre.near_target)) else _NO_FLAGS
    t_step = pre.t if isinstance(pre.t, float) else 0.0  # members: no arrival here
    scale = np.float32(1.0 / ctx.sector_rad)
    off = np.float32(ctx.n_bins // 2 + 0.5)
    arrival: Any = None
    found = np.empty(15)
    front = p.front(pre)
    for r0 in range(0, n, rows):
        n_seg = kernels().candidates(
            r0,
            min(n, r0 + rows),
            chunk,
            pre.first,
            pre.stop,
            _per_point(pre.dt),
            t_step,
            front,
            current,
            fans,
            geo.grid,
            dev.speed_ms,
            geo.bars,
            near_bars,
            geo.ray_clear,
            _NONE if pre.first_clear is None else pre.first_clear,
            box,
            geo.frame,
            origin,
            near,
            geo.cross,
            score,
            qx,
            qy,
            segments,
            found,
        )
        if n_seg < 0:
            return None
        if found[0] > 0 and (arrival is None or t_step + found[1] < t_step + arrival[1]):
            arrival = found.copy()
        if arrival is not None:
            continue  # the step ends at the target: no winners to keep
        m = int(segments[n_seg - 1, 0] + segments[n_seg - 1, 1])
        np.arctan2(qx[:m], qy[:m], out=phi[:m])  # NumPy's float32 bearings, as binned there
        kernels().sector_winners(n_seg, segments, score, phi, scale, off, best, who)
    return arrival, best, who


def survivors(
    pre: _StepInputs, row: Any, block: Any, column: Any, score: Any, dev: _DeviceTables
) -> tuple[_Layer, Any]:
    """:func:`~sailroute.routing.isochrone_kernel._survivors`, compiled: the new front
    from the winning ``(row, block, column)`` and their scores [s], and which moved."""
    p = pre.packed if pre.packed is not None else pack(pre)
    m = int(row.shape[0])
    out = np.empty((11, m))
    moved = np.empty(m, dtype=np.bool_)
    current = _NO_FLOATS if pre.current_x is None else np.stack([pre.current_x, pre.current_y])
    kernels().survivors(
        row,
        block,
        column,
        pre.first,
        pre.n_grid,
        _per_point(pre.dt),
        p.front(pre),
        np.stack([dev.twa_deg, dev.cos_a, dev.sin_a]),
        dev.speed_ms,
        current,
        out,
        moved,
    )
    t_new = pre.t + pre.dt if isinstance(pre.t, float) else pre.t[row] + pre.dt_of(row)
    layer = _Layer(
        t=t_new,
        x=out[0],
        y=out[1],
        side=out[2],
        debt=out[3],
        abs_twa=out[4],
        pend_old=out[5],
        pend_pen=out[6],
        parent=row,
        heading=np.mod(np.degrees(np.arctan2(out[9], out[10])), 360.0),
        bsp=out[7],
        delay=out[8],
        tau_est=score,
    )
    return layer, moved
