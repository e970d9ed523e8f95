"""A strategy study in one call: solve, simulate, summarise, write (used by the CLI).

:func:`run_strategy` solves the expected-time SDP for an upwind leg, simulates
it, and -- when deadlines are given -- solves the risk-aware (deadline) and
risk-neutral problems of Wang et al. (2024) for the same leg and simulates both.
:func:`write_outputs` writes ``summary.json`` and the figures.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from sailroute.boat.polar import Polar
from sailroute.errors import InputError
from sailroute.parallel import TaskRunner, open_runner
from sailroute.routing.types import side_name
from sailroute.strategy.deadline import (
    DeadlineGrid,
    DeadlinePolicy,
    DeadlineSimulation,
    RiskNeutralPolicy,
    brownian_equivalent,
    simulate_deadline,
    solve_deadline,
    solve_risk_neutral,
    start_budget,
)
from sailroute.strategy.montecarlo import SimulationResult, simulate, time_summary
from sailroute.strategy.sdp import (
    BeatGrid,
    Clock,
    ExpectedTimePolicy,
    quantised_vmg,
    solve_expected_time,
)
from sailroute.strategy.shiftmodel import (
    ChainMethod,
    DriftDiffusionShift,
    ShiftModel,
    chain_diagnostics,
    transition_matrix,
)
from sailroute.units import KNOT

Progress = Callable[[str], None]


@dataclass(frozen=True)
class StrategySettings:
    """Inputs of a strategy study other than the boat and the wind-shift model.

    Attributes
    ----------
    tws_ms : float
        Wind speed [m s⁻¹] (constant).
    length_m, half_width_m : float
        Beat length and course half-width [m].
    tack_penalty_s : float
        Time lost per tack [s]: added time in the SDP (Shepherd et al.), time standing
        still while the wind moves in the deadline problem (Wang et al. (2024)).
    runs, seed : int
        Monte Carlo runs per policy and seed.
    row_m, lateral_m, shift_step_deg, shift_max_deg, max_heading_deg : float
        SDP lattice (:class:`~sailroute.strategy.sdp.BeatGrid`).
    clock : {"time", "stage"}
        SDP wind clock.
    chain_method : {"generator", "integrate"}
        SDP shift discretisation.
    start_tack : int
        +1 starboard, -1 port.
    deadlines_s : tuple of float
        Deadlines [s] for the risk-aware policy; empty: expected time only.
    drift_deg_per_s : float
        Persistent shift [° s⁻¹] of the deadline problem's Brownian wind (positive veers).
    mark_radius_m : float
        Radius of the mark disc in the deadline problem [m].
    n_r, n_theta : int
        Deadline grid intervals in distance and angle.
    interpolation : {"linear", "cubic"}
        Deadline solver interpolation: bilinear (default; the monotone scheme of
        Wang et al. (2024), whose probabilities it reproduces within 1 percentage
        point, ``docs/strategy.md``) or bicubic Lagrange (less numerical diffusion of
        ``w``, but its non-monotone weights make the risk-aware policies worse:
        means 5.5-7.9 % above the risk-neutral one instead of < 2.8 %; 4x the memory).
    refine_controls : {"none", "golden"}
        Deadline solver steering: the 49 fixed angles, or a golden-section search
        between the best angle's neighbours (:class:`DeadlineGrid`).
    deadline_engine : {"auto", "numpy", "numba", "cupy"}
        Deadline solver kernels (:func:`~sailroute.strategy.deadline.solve_deadline`):
        numba where installed (``auto``), NumPy, or the GPU (``cupy``); the same policy
        bit for bit.
    r_max_factor : float
        Outer radius of the deadline grid as a multiple of the leg length.
    s_max_factor : float
        Largest budget solved for, as a multiple of the nominal leg time
        ``L / VMG*`` (raised to cover the deadlines).
    """

    tws_ms: float = 10.0 * KNOT
    length_m: float = 1600.0
    half_width_m: float = 800.0
    tack_penalty_s: float = 5.0
    runs: int = 4000
    seed: int = 1
    row_m: float = 10.0
    lateral_m: float = 2.0
    shift_step_deg: float = 5.0
    shift_max_deg: float = 45.0
    max_heading_deg: float = 80.0
    clock: Clock = "time"
    chain_method: ChainMethod = "generator"
    start_tack: int = 1
    deadlines_s: tuple[float, ...] = ()
    drift_deg_per_s: float = 0.0
    mark_radius_m: float = 20.0
    n_r: int = 100
    n_theta: int = 128
    r_max_factor: float = 1.25
    s_max_factor: float = 1.6
    interpolation: str = "linear"
    refine_controls: str = "none"
    deadline_engine: str = "auto"

    def beat_grid(self) -> BeatGrid:
        """The SDP lattice."""
        return BeatGrid(
            length_m=self.length_m,
            half_width_m=self.half_width_m,
            row_m=self.row_m,
            lateral_m=self.lateral_m,
            shift_step_deg=self.shift_step_deg,
            shift_max_deg=self.shift_max_deg,
            max_heading_deg=self.max_heading_deg,
        )


@dataclass(frozen=True, eq=False)
class DeadlineStudy:
    """Risk-aware and risk-neutral solutions for the leg and their simulations."""

    model: DriftDiffusionShift
    ra: DeadlinePolicy
    rn: RiskNeutralPolicy
    start: tuple[float, float, int]
    sim_rn: DeadlineSimulation
    sims_ra: dict[float, DeadlineSimulation]


@dataclass(frozen=True, eq=False)
class StrategyResult:
    """Everything a strategy study produced."""

    settings: StrategySettings
    polar: Polar
    model: ShiftModel
    policy: ExpectedTimePolicy
    sim: SimulationResult
    deadline: DeadlineStudy | None
    summary: dict[str, Any] = field(default_factory=dict)


def deadline_grid_for(
    settings: StrategySettings, f_max_ms: float, nominal_s: float
) -> DeadlineGrid:
    """Deadline grid for a leg: ``Δs = C/n`` with ``f_max Δs <= Δr``; budget covers deadlines."""
    c = settings.tack_penalty_s
    if not c > 0:
        raise InputError(
            "the deadline objective needs a tack penalty > 0 s (the boat stands still for it)"
        )
    r_max = settings.r_max_factor * settings.length_m
    dr = r_max / settings.n_r
    n = max(1, math.ceil(c * f_max_ms / dr - 1e-9))
    ds = c / n
    s_need = max([settings.s_max_factor * nominal_s, *(1.05 * d for d in settings.deadlines_s)])
    s_max = ds * math.ceil(s_need / ds)
    return DeadlineGrid(
        r_max_m=r_max,
        n_r=settings.n_r,
        n_theta=settings.n_theta,
        target_radius_m=settings.mark_radius_m,
        ds_s=ds,
        s_max_s=s_max,
        interpolation=settings.interpolation,
        refine_controls=settings.refine_controls,
    )


def deadline_model(
    model: ShiftModel, drift_deg_per_s: float, horizon_s: float
) -> DriftDiffusionShift:
    """Brownian shift for the deadline problem (an OU model is matched over ``horizon_s``)."""
    if isinstance(model, DriftDiffusionShift):
        return model
    sigma_b = brownian_equivalent(model.sigma_deg, model.timescale_s, horizon_s)
    return DriftDiffusionShift(drift_deg_per_s, sigma_b)


def run_strategy(
    polar: Polar,
    model: ShiftModel,
    settings: StrategySettings | None = None,
    progress: Progress | None = None,
    fit: dict[str, Any] | None = None,
    scheduler: str | TaskRunner | None = None,
    n_workers: int | None = None,
) -> StrategyResult:
    """Solve and simulate the expected-time policy, and the deadline policies if asked.

    Parameters
    ----------
    polar : Polar
        Boat polar (read at ``settings.tws_ms``).
    model : OUShift or DriftDiffusionShift
        Wind-shift process relative to the course axis.
    settings : StrategySettings, optional
    progress : callable, optional
        Receives one-line progress messages.
    fit : dict, optional
        Description of a parameter fit, copied into the summary.
    scheduler : str, TaskRunner or None
        Where the Monte Carlo chunks run (:func:`sailroute.parallel.map_tasks`):
        ``None``/``"serial"`` (default), ``"processes"`` (local Dask cluster),
        or a Dask scheduler address.  The solves always run here; the results
        (and ``summary``) are identical for every scheduler.
    n_workers : int, optional
        Worker processes for ``scheduler="processes"`` (default: one per core).
    """
    st = StrategySettings() if settings is None else settings
    if st.runs < 1:
        raise InputError(f"runs = {st.runs}: need at least one Monte Carlo run")
    # connect first: a wrong address fails before minutes of solving, and one cluster
    # serves all the simulations of the study
    with open_runner(scheduler, n_workers) as runner:
        return _run_study(polar, model, st, progress, fit, runner)


def _run_study(
    polar: Polar,
    model: ShiftModel,
    st: StrategySettings,
    progress: Progress | None,
    fit: dict[str, Any] | None,
    runner: TaskRunner,
) -> StrategyResult:
    say = progress or (lambda _msg: None)
    grid = st.beat_grid()
    say(f"solving the expected-time SDP ({grid.n_x} x {grid.n_rows} x 2 x {grid.theta_deg.size})")
    policy = solve_expected_time(
        polar, st.tws_ms, model, grid, st.tack_penalty_s, st.clock, st.chain_method
    )
    where = "" if runner.client is None else f" on {runner.description}"
    say(f"  solved in {policy.solve_time_s:.2f} s; simulating {st.runs} runs{where}")
    sim = simulate(policy, st.runs, st.seed, tack0=st.start_tack, scheduler=runner)
    vmg_angle_arr, vmg_arr = polar.vmg_upwind(st.tws_ms)
    vmg_angle, vmg = float(vmg_angle_arr), float(vmg_arr)
    q_heading, q_vmg = quantised_vmg(grid, polar, st.tws_ms)
    nominal = st.length_m / vmg
    m_stage = transition_matrix(model, grid.theta_deg, policy.stage_dt_s, st.chain_method)
    diag = chain_diagnostics(m_stage, grid.theta_deg, model, policy.stage_dt_s)
    summary: dict[str, Any] = {
        "boat": {
            "polar": polar.name,
            "tws_ms": st.tws_ms,
            "tws_kn": st.tws_ms / KNOT,
            "vmg_upwind_ms": vmg,
            "vmg_twa_deg": vmg_angle,
        },
        "settings": {**asdict(st), "start_tack": side_name(st.start_tack)},  # names in files
        "shift_model": model.describe(),
        "fit": fit,
        "chain": {
            "method": st.chain_method,
            "clock": st.clock,
            "diagnostics_at_stage_time": {"stage_dt_s": policy.stage_dt_s, **asdict(diag)},
        },
        "expected_time_policy": {
            "solve_time_s": policy.solve_time_s,
            "expected_time_s": policy.expected_time(0.0, st.start_tack, 0.0),
            "steady_wind_one_tack_s": st.length_m / vmg + st.tack_penalty_s,
            "lattice_one_tack_s": st.length_m / q_vmg + st.tack_penalty_s,
            "lattice_best_heading_deg": q_heading,
            "monte_carlo": sim.summary(tuple(st.deadlines_s)),
            "lateral_bands_m": {
                f"P{p}": row
                for p, row in zip(
                    (10, 30, 50, 70, 90), sim.lateral_bands((10, 30, 50, 70, 90)), strict=True
                )
            },
        },
        "runs": st.runs,
        "seed": st.seed,
    }
    study = None
    if st.deadlines_s:
        study = _run_deadline(polar, model, st, nominal, say, runner)
        summary["deadline"] = _deadline_summary(study, st)
    return StrategyResult(st, polar, model, policy, sim, study, summary)


def _run_deadline(
    polar: Polar,
    model: ShiftModel,
    st: StrategySettings,
    nominal: float,
    say: Progress,
    runner: TaskRunner,
) -> DeadlineStudy:
    f_max = float(polar.max_speed(st.tws_ms)[1])
    grid = deadline_grid_for(st, f_max, nominal)
    dd = deadline_model(model, st.drift_deg_per_s, nominal)
    say(
        f"solving the deadline problem ({grid.n_r + 1} x {grid.n_theta} x 2 nodes, "
        f"{grid.n_s} budget steps of {grid.ds_s:g} s)"
    )
    ra = solve_deadline(polar, st.tws_ms, dd, grid, st.tack_penalty_s, engine=st.deadline_engine)
    say(f"  solved in {ra.solve_time_s:.1f} s; solving the risk-neutral problem")
    rn = solve_risk_neutral(polar, st.tws_ms, dd, grid, st.tack_penalty_s, tol_s=1e-3)
    say(f"  solved in {rn.solve_time_s:.1f} s ({rn.iterations} sweeps); simulating")
    start = (st.length_m, 0.0, st.start_tack)
    t_max = 3.0 * grid.s_max_s
    sim_rn = simulate_deadline(
        rn, st.runs, st.seed, start, t_max_s=t_max, n_tracks=100, scheduler=runner
    )
    sims = {
        float(d): simulate_deadline(
            rn,
            st.runs,
            st.seed,
            start,
            ra=ra,
            deadline_s=float(d),
            t_max_s=t_max,
            n_tracks=100,
            scheduler=runner,
        )
        for d in st.deadlines_s
    }
    return DeadlineStudy(dd, ra, rn, start, sim_rn, sims)


def _deadline_summary(study: DeadlineStudy, st: StrategySettings) -> dict[str, Any]:
    g = study.ra.grid
    r0, th0, q0 = study.start
    curve = study.ra.success_curve(r0, th0, q0)
    deadlines = tuple(float(d) for d in st.deadlines_s)
    out: dict[str, Any] = {
        "model": study.model.describe(),
        "note": (
            "target-relative problem of Wang et al. (2024): Brownian wind direction, no course "
            "boundary, the boat stands still for the tack penalty"
        ),
        "grid": asdict(g),
        "engine": st.deadline_engine,
        "solve_time_s": {
            "risk_aware": study.ra.solve_time_s,
            "risk_neutral": study.rn.solve_time_s,
        },
        "risk_neutral": {
            "value_at_start_s": study.rn.expected_time(r0, th0, q0),
            "sweeps": study.rn.iterations,
            "monte_carlo": time_summary(
                study.sim_rn.leg_time_s, study.sim_rn.n_switches, deadlines
            ),
        },
        "risk_aware": {},
    }
    for d, sim in study.sims_ra.items():
        k = min(round(d / g.ds_s), g.n_s)
        out["risk_aware"][f"{d:g}"] = {
            "w_at_start": float(curve[k]),
            "budget_after_upgrade_s": start_budget(study.ra, r0, th0, q0, d),
            "fell_back_fraction": float(np.mean(sim.fell_back)),
            "monte_carlo": time_summary(sim.leg_time_s, sim.n_switches, deadlines),
        }
    return out


def shift_model(
    kind: str,
    sigma_deg: float,
    timescale_min: float,
    drift_deg_per_min: float,
    diffusion_deg_per_sqrt_min: float | None,
) -> ShiftModel:
    """The shift model given directly on the command line (minutes converted to seconds).

    Parameters
    ----------
    kind : {"ou", "drift-diffusion"}
    sigma_deg, timescale_min : float
        OU: stationary sd [°] and e-folding time [min].
    drift_deg_per_min, diffusion_deg_per_sqrt_min : float
        Drift-diffusion: drift [° min⁻¹] (positive veers) and diffusion [° min⁻½].
    """
    from sailroute.strategy.shiftmodel import OUShift

    if kind == "ou":
        if not timescale_min > 0:
            raise InputError(f"--timescale-min {timescale_min}: must be > 0")
        return OUShift(sigma_deg, timescale_min * 60.0)
    if diffusion_deg_per_sqrt_min is None:
        raise InputError(
            "--shift drift-diffusion needs --diffusion-deg-per-sqrt-min (the sd of the change "
            "of direction after one minute, e.g. 3), or --fit-from a station file"
        )
    if not (math.isfinite(diffusion_deg_per_sqrt_min) and diffusion_deg_per_sqrt_min >= 0):
        raise InputError(
            f"--diffusion-deg-per-sqrt-min {diffusion_deg_per_sqrt_min}: must be finite and >= 0"
        )
    return DriftDiffusionShift(
        drift_deg_per_min / 60.0, diffusion_deg_per_sqrt_min / math.sqrt(60.0)
    )


def fit_summary(ou: Any, dd: Any, source: str) -> dict[str, Any]:
    """Summary dict of a station fit (both models) for the JSON output."""
    return {"source": source, "ou": ou.describe(), "drift_diffusion": dd.describe()}
