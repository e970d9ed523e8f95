"""A strategy study in one call: solve, simulate, summarise, write (used by the CLI).

:func:`run_strategy` solves the expected-time SDP for an upwind leg, simulates
it, and -- when deadlines are given -- solves the risk-aware (deadline) and
risk-neutral problems of Wang et al. (2024) for the same leg and simulates both.
:func:`write_outputs` writes ``summary.json`` and the figures.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Final

import numpy as np

from sailroute.boat.polar import Polar
from sailroute.errors import InputError
from sailroute.outdir import check_out_dir, make_out_dir, write_output_set
from sailroute.parallel import TaskRunner, check_scheduler, open_runner
from sailroute.routing.types import SIDE_NAMES, side_name, side_sign
from sailroute.strategy.deadline import (
    DeadlineGrid,
    DeadlinePolicy,
    DeadlineSimulation,
    RiskNeutralPolicy,
    brownian_equivalent,
    resolve_engine,
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
    ra = solve_deadline(polar, st.tws_ms, dd, grid, st.tack_penalty_s,
                        engine=st.deadline_engine)
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
            rn, st.runs, st.seed, start, ra=ra, deadline_s=float(d), t_max_s=t_max,
            n_tracks=100, scheduler=runner,
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


def write_outputs(result: StrategyResult, out_dir: str | Path, plots: bool = True) -> list[Path]:
    """Write ``summary.json`` and (unless ``plots=False``) the PNG figures into ``out_dir``.

    Returns
    -------
    list of Path
        Files written.
    """
    from sailroute.strategy import report

    out = make_out_dir(out_dir)
    written = [report.write_json(result.summary, out / "summary.json")]
    if not plots:
        return written
    pol = result.policy
    written.append(
        report.save_figure(report.plot_policy_map(pol, tack=result.settings.start_tack),
                           out / "policy_map.png")
    )
    written.append(report.save_figure(report.plot_spaghetti(result.sim), out / "spaghetti.png"))
    samples = {"expected-time SDP (lattice, OU/chain wind)": result.sim.leg_time_s}
    curves = None
    study = result.deadline
    if study is not None:
        samples = {"risk-neutral μ*": study.sim_rn.leg_time_s}
        r0, th0, q0 = study.start
        curves = {"w(s): best possible P(T ≤ s)": (study.ra.s_s,
                                                     study.ra.success_curve(r0, th0, q0))}
        for d, sim in study.sims_ra.items():
            samples[f"risk-aware α^{d:g}"] = sim.leg_time_s
    written.append(
        report.save_figure(
            report.plot_leg_times(samples, result.settings.deadlines_s, curves),
            out / "leg_times.png",
        )
    )
    if study is not None:
        d0 = float(result.settings.deadlines_s[0])
        written.append(
            report.save_figure(
                report.plot_deadline_policy(study.ra, d0, result.settings.start_tack,
                                            extent_m=result.settings.length_m * 1.1),
                out / "deadline_policy.png",
            )
        )
        tracks = {"risk-neutral μ*": study.sim_rn}
        tracks.update({f"risk-aware α^{d:g}": s for d, s in study.sims_ra.items()})
        written.append(
            report.save_figure(
                report.plot_deadline_tracks(tracks, result.settings.mark_radius_m),
                out / "deadline_tracks.png",
            )
        )
    return written


@dataclass(frozen=True)
class CommandResult:
    """What the ``strategy`` command prints and wrote."""

    report: str
    files: list[Path]
    result: StrategyResult


def parse_objective(text: str) -> tuple[float, ...]:
    """``"expected"`` -> ``()``; ``"deadline=800"`` or ``"deadline=800,850"`` -> deadlines [s]."""
    t = text.strip().lower()
    if t == "expected":
        return ()
    if t.startswith("deadline="):
        try:
            vals = tuple(float(v) for v in t.split("=", 1)[1].split(",") if v.strip())
        except ValueError:
            vals = ()
        if vals and all(math.isfinite(v) and v > 0 for v in vals):
            return vals
    raise InputError(
        f"--objective {text!r}: expected 'expected' or 'deadline=SECONDS[,SECONDS...]', "
        "e.g. deadline=800"
    )


def load_polar(spec: str) -> Polar:
    """``builtin:NAME`` (shipped ILCA polars) or a polar file path."""
    from sailroute.boat.build import builtin_polar
    from sailroute.boat.io import read_polar

    if spec.startswith("builtin:"):
        return builtin_polar(spec.split(":", 1)[1])
    return read_polar(spec)


def run_strategy_command(
    polar_spec: str = "builtin:ilca7",
    tws_kn: float = 10.0,
    sigma_deg: float = 10.0,
    timescale_min: float = 10.0,
    drift_deg_per_min: float = 0.0,
    fit_from: str | None = None,
    fit_station: str | None = None,
    fit_timezone: str | None = None,
    fit_speed_unit: str | None = None,
    objective: str = "expected",
    out_dir: str | Path = "strategy-out",
    plots: bool = True,
    progress: Progress | None = None,
    start_tack: str = "starboard",
    scheduler: str | None = None,
    n_workers: int | None = None,
    shift: str = "ou",
    diffusion_deg_per_sqrt_min: float | None = None,
    **settings: Any,
) -> CommandResult:
    """The ``sailroute strategy`` command as a function (the CLI only parses and prints).

    Parameters
    ----------
    polar_spec : str
        ``builtin:ilca7`` or a polar file.
    tws_kn : float
        Wind speed [kn].
    sigma_deg, timescale_min : float
        OU shift: stationary sd [°] and time scale [min] (ignored with ``fit_from``).
    drift_deg_per_min : float
        Persistent shift [° min⁻¹] (positive veers): the drift of
        ``shift="drift-diffusion"``, and of the deadline problem's Brownian
        wind when ``shift="ou"``.
    fit_from, fit_station, fit_timezone : str, optional
        Station CSV to fit the shift model from (OU: sigma and the e-fold time
        scale; drift-diffusion: drift and diffusion).
    fit_speed_unit : str, optional
        Unit of the station file's speed column when its header does not say
        (``kn``, ``m/s``, ``km/h``, ``mph``).
    objective : str
        ``expected`` or ``deadline=SECONDS[,SECONDS]``.
    out_dir : str or Path
        Output folder (checked first; written as a set, see :mod:`sailroute.outdir`).
    plots : bool
        Write the PNG figures.
    progress : callable, optional
        Progress messages.
    start_tack : {"starboard", "port"}
        Tack at the start.
    scheduler : str, optional
        ``--scheduler``: ``serial`` (default), ``processes`` (local Dask
        cluster), or a Dask scheduler address ``tcp://HOST:PORT``; only the
        Monte Carlo is distributed and the numbers do not change
        (``docs/scale-out.md``).
    n_workers : int, optional
        Worker processes for ``processes`` (default: one per core).
    shift : {"ou", "drift-diffusion"}
        Wind-shift model of the study: oscillating (Ornstein–Uhlenbeck, from
        ``sigma_deg`` and ``timescale_min``) or persistent (Brownian with
        drift, from ``drift_deg_per_min`` and ``diffusion_deg_per_sqrt_min``).
    diffusion_deg_per_sqrt_min : float, optional
        Diffusion of ``shift="drift-diffusion"`` [° min⁻½]: the sd of the
        change of direction after one minute (``Var = s² t``).
    **settings
        Further :class:`StrategySettings` fields (``length_m``, ``runs``, ...).
    """
    from sailroute.strategy.fit import fit_station_file

    deadlines = parse_objective(objective)
    check_out_dir(out_dir)
    check_command_options(settings, n_workers=n_workers, sigma_deg=sigma_deg,
                          drift_deg_per_min=drift_deg_per_min)
    scheduler = check_scheduler(scheduler)
    kind = parse_shift(shift)
    name = str(start_tack).strip().lower()
    if name not in SIDE_NAMES:
        raise InputError(f"--start-tack {start_tack!r}: expected 'starboard' or 'port'")
    tack = side_sign(name)
    if not (math.isfinite(tws_kn) and tws_kn > 0):
        raise InputError(f"--tws-kn {tws_kn}: must be > 0")
    seed = settings.get("seed", 0)
    if not isinstance(seed, int) or seed < 0:
        raise InputError(f"--seed {seed}: expected an integer >= 0 (NumPy's generators take "
                         "no negative seeds)")
    polar = load_polar(polar_spec)
    check_wind_in_polar(tws_kn, polar, polar_spec)
    fit = None
    if fit_from is not None:
        ou, dd = fit_station_file(fit_from, station=fit_station, timezone=fit_timezone,
                                  speed_unit=fit_speed_unit)
        model: ShiftModel = ou.model() if kind == "ou" else dd.model()
        fit = fit_summary(ou, dd, str(fit_from))
    else:
        model = shift_model(kind, sigma_deg, timescale_min, drift_deg_per_min,
                            diffusion_deg_per_sqrt_min)
    try:
        st = StrategySettings(
            tws_ms=tws_kn * KNOT,
            deadlines_s=deadlines,
            drift_deg_per_s=drift_deg_per_min / 60.0,
            start_tack=tack,
            **settings,
        )
    except TypeError as exc:  # pragma: no cover - programming error in a caller
        raise InputError(f"strategy settings: {exc}") from None
    if deadlines:  # before the expected-time study: say now what cannot run here
        resolve_engine(st.deadline_engine)
    result = run_strategy(
        polar, model, st, progress=progress, fit=fit, scheduler=scheduler, n_workers=n_workers
    )
    files = write_output_set(out_dir, lambda d: write_outputs(result, d, plots=plots))
    return CommandResult(format_report(result), files, result)


MAX_LATTICE_NODES: Final = 100_000_000
"""Most nodes (rows x lateral nodes x shift bins x 2 tacks) of the expected-time lattice
the ``strategy`` command solves: about 2.5 min and 2 GB; the defaults (1600 m x 800 m)
have 4.9 million."""
MAX_RUNS: Final = 1_000_000
"""Most Monte Carlo runs per policy (``--runs``; the default is 4000)."""
MAX_RUN_STEPS: Final = 50_000_000
"""Most Monte Carlo boat-steps per policy (runs x rows; the defaults need 640 000): the
tracks are kept, about 33 bytes per boat-step, so 1.6 GB and tens of seconds."""


def _option(name: str) -> str:
    return "--" + name.replace("_", "-")


def check_command_options(
    settings: Mapping[str, Any], *, n_workers: int | None, sigma_deg: float,
    drift_deg_per_min: float,
) -> None:
    """Refuse bad ``strategy`` options by their command-line names, before any work.

    Checks ``--runs``, ``--workers``, ``--length-m``, ``--half-width-m``,
    ``--tack-penalty-s``, ``--sigma-deg`` and ``--drift-deg-per-min``, and estimates the
    size of the expected-time lattice (:data:`MAX_LATTICE_NODES`) and of the Monte Carlo
    (:data:`MAX_RUNS`, :data:`MAX_RUN_STEPS`) so that a study that would not finish in
    reasonable time or memory is refused with the range that would.

    Parameters
    ----------
    settings : mapping
        The :class:`StrategySettings` fields given (``length_m``, ``runs``, ...).
    n_workers : int or None
        ``--workers``.
    sigma_deg, drift_deg_per_min : float
        ``--sigma-deg`` and ``--drift-deg-per-min``.

    Raises
    ------
    InputError
        Naming the option, the value and the accepted range.
    """
    defaults = StrategySettings()
    runs = settings.get("runs", defaults.runs)
    if isinstance(runs, bool) or not isinstance(runs, int) or not 1 <= runs <= MAX_RUNS:
        raise InputError(f"--runs {runs}: expected a whole number of Monte Carlo runs in "
                         f"1..{MAX_RUNS:,} (default {defaults.runs})")
    if n_workers is not None and (isinstance(n_workers, bool) or not isinstance(n_workers, int)
                                  or n_workers < 1):
        raise InputError(f"--workers {n_workers}: expected a whole number >= 1 of worker "
                         "processes")
    for name, lo in (("tack_penalty_s", 0.0), ("sigma_deg", 0.0)):
        v = sigma_deg if name == "sigma_deg" else settings.get(name, getattr(defaults, name))
        if not (math.isfinite(v) and v >= lo):
            raise InputError(f"{_option(name)} {v}: must be finite and >= {lo:g}")
    if not math.isfinite(drift_deg_per_min):
        raise InputError(f"--drift-deg-per-min {drift_deg_per_min}: must be finite")
    steps = {"length_m": ("row_m", "rows"), "half_width_m": ("lateral_m", "lateral nodes")}
    n = {}
    for name, (step_name, what) in steps.items():
        v = settings.get(name, getattr(defaults, name))
        step = settings.get(step_name, getattr(defaults, step_name))
        if not (math.isfinite(v) and v > 0):
            raise InputError(f"{_option(name)} {v:g}: must be finite and > 0 m")
        k = v / step
        if abs(k - round(k)) > 1e-9 or round(k) < 1:
            raise InputError(f"{_option(name)} {v:g}: expected a whole number (>= 1) of "
                             f"{step:g} m {what}, e.g. {max(1, round(k)) * step:g}")
        n[name] = round(k)
    grid = StrategySettings(**{**asdict(defaults), **settings}).beat_grid()
    n_shift = grid.theta_deg.size
    nodes = (n["length_m"] + 1) * (2 * n["half_width_m"] + 1) * n_shift * 2
    if nodes > MAX_LATTICE_NODES:
        per_row = (2 * n["half_width_m"] + 1) * n_shift * 2
        longest = (MAX_LATTICE_NODES // per_row - 1) * grid.row_m
        raise InputError(
            f"--length-m {grid.length_m:g} with --half-width-m {grid.half_width_m:g}: the "
            f"expected-time lattice would have {nodes:.2g} nodes (about "
            f"{nodes * 8 * 2.5 / 2**30:.3g} GiB), more than {MAX_LATTICE_NODES:.0e} (minutes "
            f"and gigabytes); give a beat of at most {max(longest, 0.0):g} m at this width "
            "(a dinghy beat is 0.5-3 km), or a smaller --half-width-m")
    if runs * n["length_m"] > MAX_RUN_STEPS:
        raise InputError(
            f"--runs {runs} over {n['length_m']} rows of --length-m {grid.length_m:g}: "
            f"{runs * n['length_m']:.2g} Monte Carlo boat-steps per policy, more than "
            f"{MAX_RUN_STEPS:.0e}; use --runs <= {MAX_RUN_STEPS // n['length_m']}")


def check_wind_in_polar(tws_kn: float, polar: Polar, polar_spec: str) -> None:
    """Refuse a ``--tws-kn`` above the polar's highest TWS column.

    The same rule as ``plan`` (:func:`sailroute.boat.sanity.check_wind_range`): above
    its last column the polar is clamped, so the boat would sail as in the last
    column's wind, silently.

    Raises
    ------
    InputError
        Naming ``--tws-kn``, the polar and its TWS range.
    """
    from sailroute.boat.sanity import TOLERANCE_MS

    top = float(polar.tws_ms[-1])
    if tws_kn * KNOT > top + TOLERANCE_MS:
        lo = float(polar.tws_ms[0])
        raise InputError(
            f"--tws-kn {tws_kn:g}: above the highest TWS column of --polar {polar_spec} "
            f"(TWS {lo / KNOT:.1f} .. {top / KNOT:.1f} kn); the boat speed would be clamped "
            f"to that column without notice. Give --tws-kn up to {top / KNOT:.1f}, or a "
            "--polar with higher TWS columns")


SHIFT_KINDS = ("ou", "drift-diffusion")
"""Wind-shift models the ``strategy`` command can use."""


def parse_shift(text: str) -> str:
    """``"ou"`` or ``"drift-diffusion"`` (case and ``_`` insensitive), else an InputError."""
    kind = str(text).strip().lower().replace("_", "-")
    if kind not in SHIFT_KINDS:
        raise InputError(
            f"--shift {text!r}: expected 'ou' (oscillating shifts) or 'drift-diffusion' "
            "(persistent shift)"
        )
    return kind


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


def shift_model_text(model: ShiftModel) -> str:
    """The shift model in words with sensible precision (degrees and minutes), e.g.
    ``"oscillating (OU): sd 10.0°, time scale 10.0 min"``."""
    d = model.describe()
    if d["kind"] == "ou":
        tl = float(d["timescale_s"])
        text = (f"oscillating (OU): sd {float(d['sigma_deg']):.1f}°, time scale "
                + ("infinite (frozen wind)" if math.isinf(tl) else f"{tl / 60:.1f} min"))
        mean = float(d["mean_deg"])
        return text + (f", mean {mean:+.1f}°" if mean else "")
    return (f"persistent (drift-diffusion): drift {60 * float(d['drift_deg_per_s']):+.2f}°/min, "
            f"diffusion {math.sqrt(60) * float(d['sigma_deg_per_sqrt_s']):.2f}°/√min")


def format_report(result: StrategyResult) -> str:
    """Short human-readable summary of a study."""
    s = result.summary
    e = s["expected_time_policy"]
    mc = e["monte_carlo"]
    b = s["boat"]
    lines = [
        f"boat {b['polar']} at {b['tws_kn']:.1f} kn: upwind VMG {b['vmg_upwind_ms']:.3f} m/s "
        f"at TWA {b['vmg_twa_deg']:.1f}°",
        f"shift model: {shift_model_text(result.model)}",
    ]
    if s.get("fit") and result.model.kind == "ou":
        ou = s["fit"]["ou"]
        lines.append(
            f"fitted from {s['fit']['source']}: sigma {ou['sigma_deg']:.1f} ± "
            f"{ou['sigma_se_deg']:.1f}°, time scale {ou['timescale_s'] / 60:.1f} ± "
            f"{ou['timescale_se_s'] / 60:.1f} min"
        )
    elif s.get("fit"):
        dd = s["fit"]["drift_diffusion"]
        lines.append(
            f"fitted from {s['fit']['source']}: drift {60 * dd['drift_deg_per_s']:.2f} ± "
            f"{60 * dd['drift_se_deg_per_s']:.2f}°/min, diffusion "
            f"{math.sqrt(60) * dd['sigma_deg_per_sqrt_s']:.2f} ± "
            f"{math.sqrt(60) * dd['sigma_se_deg_per_sqrt_s']:.2f}°/√min"
        )
    diag = s["chain"]["diagnostics_at_stage_time"]
    sd_err = diag["stationary_sd_deg"] / diag["target_sd_deg"] - 1.0
    if math.isfinite(sd_err) and abs(sd_err) > 0.1:
        lines.append(
            f"note: the shift chain's sd is {diag['stationary_sd_deg']:.1f}° for a target of "
            f"{diag['target_sd_deg']:.1f}° ({100 * sd_err:+.0f} %): the 5° bins are too coarse "
            "or the ±45° range too narrow for this sigma"
        )
    pct = mc.get("percentiles_s", {})
    lines += [
        f"expected-time policy: solved in {e['solve_time_s']:.2f} s; "
        f"E[T] {e['expected_time_s']:.1f} s "
        f"(steady-wind one tack {e['steady_wind_one_tack_s']:.1f} s)",
        f"  Monte Carlo ({mc['n_runs']} runs): mean {mc.get('mean_s', math.nan):.1f} s "
        f"± {mc.get('se_mean_s', math.nan):.1f}, P10 {pct.get('10', math.nan):.1f}, "
        f"P50 {pct.get('50', math.nan):.1f}, P90 {pct.get('90', math.nan):.1f} s, "
        f"tacks {mc['tacks']['mean']:.2f} on average",
    ]
    d = s.get("deadline")
    if d:
        rn = d["risk_neutral"]["monte_carlo"]
        lines.append(
            f"deadline problem ({d['model']['sigma_deg_per_sqrt_s']:.3f}°/√s Brownian shift): "
            f"solved in {d['solve_time_s']['risk_aware']:.1f} s (+ "
            f"{d['solve_time_s']['risk_neutral']:.1f} s risk-neutral)"
        )
        for key, ra in d["risk_aware"].items():
            p_ra = ra["monte_carlo"]["p_within_deadline"][key]
            p_rn = rn["p_within_deadline"][key]
            lines.append(
                f"  deadline {key} s: P(T <= deadline) risk-neutral {100 * p_rn['p']:.1f}% -> "
                f"risk-aware {100 * p_ra['p']:.1f}% (± {100 * p_ra['se']:.1f}); means "
                f"{rn.get('mean_s', math.nan):.1f} -> "
                f"{ra['monte_carlo'].get('mean_s', math.nan):.1f} s"
            )
    return "\n".join(lines)
