"""Expected-time tack strategy on an upwind leg: stochastic dynamic programming.

Shepherd, Haydon & Vermillion with the defects of its text fixed
(``docs/design/strategy.md``).  The leg is a lattice of rows ``y = 0, δy, ...,
L`` along the course axis and lateral positions ``x = -x_max, ..., x_max``
(``δx`` apart).  State: (row, ``x``, tack ``k``, shift bin ``θ``).  A decision
picks the lateral position ``x'`` on the next row; the segment is sailed at the
polar speed for its true wind angle, and costs the tack penalty ``λ`` if its
tack differs from ``k``.  The wind shift follows a Markov chain on the bins.

Frame and signs (``docs/nomenclature.md``): ``y`` points up the course, towards
the mark and into the mean wind; ``x`` points to the right looking up the
course.  A segment's heading offset ``ψ = atan2(x' - x, δy)`` is positive to the
right (clockwise); the shift ``θ`` is positive for a veer (clockwise), so the
signed true wind angle is ``TWA = wrap180(θ - ψ)``, positive on starboard tack.
The mark is ``x = 0`` on the last row (the terminal set, an assumption the paper
leaves open); reaching any other lateral position there is infeasible.

Wind clock (``clock="time"``, the default): the chain advances by the sailing
time of the chosen segment -- each candidate segment has its own exact
transition row ``M(Δt_seg)[θ, :]``; the tack penalty is a pure additive time
(the wind does not move during it).  ``clock="stage"`` reproduces Shepherd et al.'s
per-row clock with one matrix over a nominal stage time ``δy / VMG*``.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from sailroute.boat.polar import Polar
from sailroute.errors import InputError
from sailroute.strategy.shiftmodel import (
    ChainMethod,
    ShiftModel,
    shift_bins,
    transition_rows,
)

Clock = Literal["time", "stage"]
TACKS: tuple[int, int] = (1, -1)
"""Tack values in index order: index 0 = starboard (+1), index 1 = port (-1)."""
INFEASIBLE_S = 1.0e9
"""Cost [s] standing for "cannot reach the mark" inside the expectation."""
MIN_SPEED_MS = 1.0e-3
"""Segments slower than this [m s⁻¹] (the no-go zone) are excluded."""


def _whole(value: float, step: float, what: str) -> int:
    n = value / step
    if abs(n - round(n)) > 1e-9 or round(n) < 1:
        raise InputError(
            f"beat grid: {what} = {value} m is not a whole (>= 1) number of {step} m steps"
        )
    return round(n)


@dataclass(frozen=True)
class BeatGrid:
    """Lattice of an upwind leg (defaults: Shepherd et al.'s resolution).

    Parameters
    ----------
    length_m : float
        Leg length ``L`` along the course axis [m]; a whole number of rows.
    half_width_m : float
        Course half-width ``x_max`` [m]; a whole number of lateral steps.
    row_m : float
        Row spacing ``δy`` [m].
    lateral_m : float
        Lateral node spacing ``δx`` [m].
    shift_step_deg, shift_max_deg : float
        Shift bins ``-max, ..., max`` [°] in steps of ``shift_step_deg``.
    max_heading_deg : float
        Widest heading offset ``|ψ|`` [°] a segment may take (window
        ``|x' - x| <= δy tan ψ_max``).  Headings near ±90° make almost no
        progress up the course; bounding them makes the DP cost linear in the
        width of the course instead of quadratic.
    """

    length_m: float = 1600.0
    half_width_m: float = 800.0
    row_m: float = 10.0
    lateral_m: float = 2.0
    shift_step_deg: float = 5.0
    shift_max_deg: float = 45.0
    max_heading_deg: float = 80.0

    def __post_init__(self) -> None:
        for name in ("length_m", "half_width_m", "row_m", "lateral_m"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0):
                raise InputError(f"beat grid: {name} = {v} must be finite and > 0")
        _whole(self.length_m, self.row_m, "length_m")
        _whole(self.half_width_m, self.lateral_m, "half_width_m")
        if not 0 < self.max_heading_deg < 90:
            raise InputError(
                f"beat grid: max_heading_deg = {self.max_heading_deg} must be in (0, 90)"
            )
        shift_bins(self.shift_step_deg, self.shift_max_deg)

    @property
    def n_rows(self) -> int:
        """Number of stages (segments) from start to mark."""
        return _whole(self.length_m, self.row_m, "length_m")

    @property
    def n_x(self) -> int:
        """Number of lateral nodes."""
        return 2 * _whole(self.half_width_m, self.lateral_m, "half_width_m") + 1

    @property
    def x_m(self) -> NDArray[np.float64]:
        """Lateral node positions [m]."""
        h = (self.n_x - 1) // 2
        return self.lateral_m * np.arange(-h, h + 1, dtype=float)

    @property
    def y_m(self) -> NDArray[np.float64]:
        """Row positions along the course [m], ``n_rows + 1`` of them."""
        return self.row_m * np.arange(self.n_rows + 1, dtype=float)

    @property
    def theta_deg(self) -> NDArray[np.float64]:
        """Shift bin centres [°]."""
        return shift_bins(self.shift_step_deg, self.shift_max_deg)

    @property
    def d_max(self) -> int:
        """Largest lateral step ``|x' - x|`` per row, in nodes."""
        reach = self.row_m * math.tan(math.radians(self.max_heading_deg)) / self.lateral_m
        return max(1, min(math.floor(reach + 1e-9), self.n_x - 1))


@dataclass(frozen=True, eq=False)
class SegmentTable:
    """Segment times per (lateral step, shift bin) for a uniform wind speed.

    Attributes
    ----------
    d : ndarray of int, shape (n_d,)
        Lateral steps ``(x' - x)/δx``, ``-d_max .. d_max``.
    heading_deg : ndarray, shape (n_d,)
        Heading offsets ``ψ`` [°] from the course axis (positive right).
    twa_deg : ndarray, shape (n_d, n_θ)
        Signed true wind angle ``θ - ψ`` [°].
    speed_ms : ndarray, shape (n_d, n_θ)
        Polar boat speed [m s⁻¹].
    time_s : ndarray, shape (n_d, n_θ)
        Sailing time of the segment [s]; ``inf`` if excluded (no-go).
    tack : ndarray of int8, shape (n_d, n_θ)
        Tack of the segment (+1 starboard, -1 port; 0 if excluded).
    """

    d: NDArray[np.int64]
    heading_deg: NDArray[np.float64]
    twa_deg: NDArray[np.float64]
    speed_ms: NDArray[np.float64]
    time_s: NDArray[np.float64]
    tack: NDArray[np.int8]


def segment_table(grid: BeatGrid, polar: Polar, tws_ms: float) -> SegmentTable:
    """Tabulate segment times ``hypot(δy, d δx) / u(TWS, |θ - ψ_d|)`` [s].

    Segments slower than :data:`MIN_SPEED_MS` (the no-go zone) get ``inf``.
    """
    d = np.arange(-grid.d_max, grid.d_max + 1)
    dx = d * grid.lateral_m
    heading = np.degrees(np.arctan2(dx, grid.row_m))
    twa = grid.theta_deg[None, :] - heading[:, None]
    speed = np.asarray(polar.speed(tws_ms, twa), dtype=float)
    length = np.hypot(grid.row_m, dx)[:, None]
    ok = speed > MIN_SPEED_MS
    with np.errstate(divide="ignore"):
        t = np.where(ok, length / np.where(ok, speed, 1.0), np.inf)
    tack = np.where(ok, np.sign(twa), 0).astype(np.int8)
    ok &= tack != 0
    t = np.where(ok, t, np.inf)
    return SegmentTable(d, heading, twa, speed, t, tack)


def quantised_vmg(grid: BeatGrid, polar: Polar, tws_ms: float) -> tuple[float, float]:
    """Best VMG on the lattice's headings ``ψ_n = atan(n δx / δy)`` in steady wind.

    Returns
    -------
    heading_deg, vmg_ms : float
        Best quantised heading offset [°] and its VMG [m s⁻¹].  A one-tack
        route on the lattice (layline inside the course) takes exactly
        ``L / vmg + λ`` (the steady-wind one-tack limit).
    """
    n = np.arange(1, grid.d_max + 1)
    psi = np.degrees(np.arctan2(n * grid.lateral_m, grid.row_m))
    vmg = polar.speed(tws_ms, psi) * np.cos(np.radians(psi))
    k = int(np.argmax(vmg))
    return float(psi[k]), float(vmg[k])


@dataclass(frozen=True, eq=False)
class ExpectedTimePolicy:
    """Solution of the expected-time SDP: value table and feedback policy.

    Attributes
    ----------
    grid : BeatGrid
    polar_name : str
    tws_ms : float
        Wind speed the polar was read at [m s⁻¹].
    model : OUShift or DriftDiffusionShift
        Shift process the policy was optimised for.
    tack_penalty_s : float
        Tack penalty ``λ`` [s].
    clock : {"time", "stage"}
        Wind clock (module docstring).
    chain_method : {"generator", "integrate"}
        Discretisation of the shift.
    stage_dt_s : float
        Nominal stage time [s] (used by ``clock="stage"``).
    segments : SegmentTable
    transitions : ndarray, shape (n_d, n_θ, n_θ)
        Shift transition row for each (segment, current bin).
    value_s : ndarray, shape (n_rows + 1, 2, n_θ, n_x)
        Expected time to the mark [s] from (row, tack index, θ, x); tack index
        0 is starboard, 1 port (:data:`TACKS`); ``inf`` where the mark cannot
        be reached for sure.
    action : ndarray of int16, shape (n_rows, 2, n_θ, n_x)
        Index into ``segments.d`` of the optimal segment; ``-1`` if infeasible.
    solve_time_s : float
        Wall time of the backward recursion [s].
    """

    grid: BeatGrid
    polar_name: str
    tws_ms: float
    model: ShiftModel
    tack_penalty_s: float
    clock: str
    chain_method: str
    stage_dt_s: float
    segments: SegmentTable
    transitions: NDArray[np.float64]
    value_s: NDArray[np.float64]
    action: NDArray[np.int16]
    solve_time_s: float

    def expected_time(self, x_m: float = 0.0, tack: int = 1, theta_deg: float = 0.0) -> float:
        """Expected leg time [s] from the first row at (``x``, tack, nearest shift bin)."""
        ix, ik, it = self.state_index(x_m, tack, theta_deg)
        return float(self.value_s[0, ik, it, ix])

    def state_index(self, x_m: float, tack: int, theta_deg: float) -> tuple[int, int, int]:
        """Indices (x, tack, θ) of the lattice state nearest to the arguments."""
        g = self.grid
        ix = int(np.clip(round((x_m + g.half_width_m) / g.lateral_m), 0, g.n_x - 1))
        if tack not in TACKS:
            raise InputError(f"tack must be +1 (starboard) or -1 (port), got {tack}")
        ik = TACKS.index(tack)
        th = g.theta_deg
        it = int(np.argmin(np.abs(th - theta_deg)))
        return ix, ik, it

    def decision(self, row: int, x_m: float, tack: int, theta_deg: float) -> dict[str, float]:
        """The policy's segment from one state: next ``x`` [m], heading [°], TWA, tack."""
        ix, ik, it = self.state_index(x_m, tack, theta_deg)
        a = int(self.action[row, ik, it, ix])
        if a < 0:
            raise InputError(
                f"no feasible segment from row {row}, x = {x_m} m, tack {tack}, "
                f"shift {theta_deg}°: the mark cannot be reached for sure from there"
            )
        s = self.segments
        return {
            "x_next_m": float(self.grid.x_m[ix] + s.d[a] * self.grid.lateral_m),
            "heading_offset_deg": float(s.heading_deg[a]),
            "twa_deg": float(s.twa_deg[a, it]),
            "tack": int(s.tack[a, it]),
            "time_s": float(s.time_s[a, it]),
        }


def nominal_stage_time(grid: BeatGrid, polar: Polar, tws_ms: float) -> float:
    """Time [s] to make one row ``δy`` good at the polar's best upwind VMG."""
    _, vmg_ms = polar.vmg_upwind(tws_ms)
    vmg = float(vmg_ms)
    if vmg <= 0:
        raise InputError(f"polar {polar.name!r} makes no VMG upwind at TWS {tws_ms} m/s")
    return grid.row_m / vmg


def segment_transitions(
    model: ShiftModel,
    grid: BeatGrid,
    segments: SegmentTable,
    clock: Clock = "time",
    chain_method: ChainMethod = "generator",
    stage_dt_s: float | None = None,
) -> NDArray[np.float64]:
    """Transition rows ``M(Δt)[θ, :]`` for every (segment, current bin).

    ``clock="time"``: ``Δt`` is the segment's sailing time (excluded segments
    get ``Δt = 0``, never used).  ``clock="stage"``: ``Δt = stage_dt_s`` for all.
    """
    n_d, n_t = segments.time_s.shape
    if clock == "time":
        dt = np.where(np.isfinite(segments.time_s), segments.time_s, 0.0)
    elif clock == "stage":
        if stage_dt_s is None or not stage_dt_s > 0:
            raise InputError("stage clock needs a stage time stage_dt_s > 0 [s]")
        dt = np.full((n_d, n_t), float(stage_dt_s))
    else:
        raise InputError(f"unknown wind clock {clock!r}; expected 'time' or 'stage'")
    i_from = np.broadcast_to(np.arange(n_t)[None, :], (n_d, n_t))
    return transition_rows(model, grid.theta_deg, i_from, dt, chain_method)


def solve_expected_time(
    polar: Polar,
    tws_ms: float,
    model: ShiftModel,
    grid: BeatGrid | None = None,
    tack_penalty_s: float = 5.0,
    clock: Clock = "time",
    chain_method: ChainMethod = "generator",
) -> ExpectedTimePolicy:
    """Solve the expected-time SDP by backward recursion over the rows.

    Parameters
    ----------
    polar : Polar
        Boat polar; read at ``tws_ms``.
    tws_ms : float
        True wind speed [m s⁻¹] (constant over the leg).
    model : OUShift or DriftDiffusionShift
        Wind-shift process (shift relative to the course axis).
    grid : BeatGrid, optional
        Lattice; default Shepherd et al.'s (1600 m x ±800 m, 10 m x 2 m, 5° bins).
    tack_penalty_s : float
        Time added per tack ``λ`` [s], ``>= 0``.
    clock : {"time", "stage"}
        Wind clock: per-segment sailing time (default) or Shepherd et al.'s per row.
    chain_method : {"generator", "integrate"}
        Shift discretisation (:mod:`sailroute.strategy.shiftmodel`).

    Returns
    -------
    ExpectedTimePolicy

    Notes
    -----
    Per row: ``Q[(θ, d), x'] = Σ_j M_{d,θ}[j] G_next[k'(d,θ), j, x']`` is one
    matrix product per segment tack ``k'``; the candidate cost
    ``T[d, θ] + Q[(θ, d), x + d]`` is a slice of ``Q`` padded in ``x``; a
    running minimum over the ``n_d = 2 d_max + 1`` segments, kept separately
    for the two segment tacks, is vectorised over ``(θ, x)``, and the tack
    penalty is applied once after it.  Work per row: ``O(n_x n_d n_θ)``.
    """
    grid = BeatGrid() if grid is None else grid
    if not (math.isfinite(tack_penalty_s) and tack_penalty_s >= 0):
        raise InputError(f"tack penalty {tack_penalty_s} s must be finite and >= 0")
    if not (math.isfinite(tws_ms) and tws_ms > 0):
        raise InputError(f"wind speed {tws_ms} m/s must be finite and > 0")
    t0 = time.perf_counter()
    seg = segment_table(grid, polar, tws_ms)
    stage_dt = nominal_stage_time(grid, polar, tws_ms)
    rows = segment_transitions(model, grid, seg, clock, chain_method, stage_dt)
    value, action = _backward(grid, seg, rows, float(tack_penalty_s))
    return ExpectedTimePolicy(
        grid=grid,
        polar_name=polar.name,
        tws_ms=float(tws_ms),
        model=model,
        tack_penalty_s=float(tack_penalty_s),
        clock=clock,
        chain_method=chain_method,
        stage_dt_s=stage_dt,
        segments=seg,
        transitions=rows,
        value_s=value,
        action=action,
        solve_time_s=time.perf_counter() - t0,
    )


def _backward(
    grid: BeatGrid, seg: SegmentTable, rows: NDArray, lam: float
) -> tuple[NDArray[np.float64], NDArray[np.int16]]:
    n_rows, n_x = grid.n_rows, grid.n_x
    n_d, n_t = seg.time_s.shape
    dmax = (n_d - 1) // 2
    value = np.empty((n_rows + 1, 2, n_t, n_x))
    action = np.empty((n_rows, 2, n_t, n_x), dtype=np.int16)
    value[n_rows] = np.inf
    value[n_rows, :, :, (n_x - 1) // 2] = 0.0

    # For segment i the shift bins above its heading are starboard, those below port
    # (TWA = θ - ψ_i); excluded segments have infinite time and never win.
    split = np.searchsorted(grid.theta_deg, seg.heading_deg, side="right")
    valid = np.isfinite(seg.time_s)
    is_stbd = np.arange(n_t)[None, :] >= split[:, None]
    if np.any(valid & (seg.tack == 1) & ~is_stbd) or np.any(valid & (seg.tack == -1) & is_stbd):
        raise AssertionError("segment tacks are not split by heading")  # pragma: no cover
    rows_s = np.flatnonzero((valid & is_stbd).T.ravel())  # (θ, i) flat indices
    rows_p = np.flatnonzero((valid & ~is_stbd).T.ravel())
    # W[(θ, i), j] = M_{i,θ}[j]
    w = rows.transpose(1, 0, 2).reshape(n_t * n_d, n_t)
    w_s, w_p = w[rows_s], w[rows_p]
    t_col = seg.time_s.T[:, :, None]  # (n_t, n_d, 1)
    # expected cost-to-go on the segment's own tack, padded by d_max on both sides in x
    qpad = np.full((n_t * n_d, n_x + 2 * dmax), np.inf)
    qin = qpad[:, dmax : dmax + n_x]
    q3 = qpad.reshape(n_t, n_d, n_x + 2 * dmax)
    m = np.empty((2, n_t, n_x))
    a = np.empty((2, n_t, n_x), dtype=np.int16)
    better = np.empty((n_t, n_x), dtype=bool)
    for r in range(n_rows - 1, -1, -1):
        g = value[r + 1]
        gf = np.where(np.isfinite(g), g, INFEASIBLE_S)
        qin[rows_s] = w_s @ gf[0]
        qin[rows_p] = w_p @ gf[1]
        m.fill(np.inf)
        a.fill(-1)
        for i in range(n_d):
            c = q3[:, i, i : i + n_x] + t_col[:, i]  # (n_t, n_x): x' = x + d_i
            k = split[i]
            for ik, sl in ((0, slice(k, n_t)), (1, slice(0, k))):
                if sl.start == sl.stop:
                    continue
                cs, ms = c[sl], m[ik, sl]
                bt = better[sl]
                np.less(cs, ms, out=bt)
                np.copyto(ms, cs, where=bt)
                np.copyto(a[ik, sl], i, where=bt)
        # current tack k: continue on k, or tack onto the other one (+λ)
        for ik in (0, 1):
            same, other = m[ik], m[1 - ik] + lam
            take_other = other < same
            best = np.where(take_other, other, same)
            value[r, ik] = np.where(best < 0.5 * INFEASIBLE_S, best, np.inf)
            action[r, ik] = np.where(take_other, a[1 - ik], a[ik])
    return value, action
