"""``sailroute strategy``: check the options, solve and simulate the study, write.

The study is :mod:`sailroute.strategy.study`; the figures, JSON and text are
:mod:`sailroute.report.strategy`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict
from pathlib import Path
from typing import Any, Final

from sailroute.boat.polar import Polar
from sailroute.commands.result import CommandResult
from sailroute.errors import InputError
from sailroute.outdir import check_out_dir, write_output_set
from sailroute.parallel import check_scheduler
from sailroute.report.strategy import format_report, write_strategy_outputs
from sailroute.routing.types import SIDE_NAMES, side_sign
from sailroute.strategy.deadline import resolve_engine
from sailroute.strategy.shiftmodel import ShiftModel
from sailroute.strategy.study import (
    Progress,
    StrategySettings,
    fit_summary,
    run_strategy,
    shift_model,
)
from sailroute.units import KNOT

__all__ = [
    "SHIFT_KINDS",
    "check_command_options",
    "parse_objective",
    "parse_shift",
    "run_strategy_command",
]


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
    check_command_options(
        settings, n_workers=n_workers, sigma_deg=sigma_deg, drift_deg_per_min=drift_deg_per_min
    )
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
        raise InputError(
            f"--seed {seed}: expected an integer >= 0 (NumPy's generators take no negative seeds)"
        )
    polar = load_polar(polar_spec)
    check_wind_in_polar(tws_kn, polar, polar_spec)
    fit = None
    if fit_from is not None:
        ou, dd = fit_station_file(
            fit_from, station=fit_station, timezone=fit_timezone, speed_unit=fit_speed_unit
        )
        model: ShiftModel = ou.model() if kind == "ou" else dd.model()
        fit = fit_summary(ou, dd, str(fit_from))
    else:
        model = shift_model(
            kind, sigma_deg, timescale_min, drift_deg_per_min, diffusion_deg_per_sqrt_min
        )
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
    files = write_output_set(out_dir, lambda d: write_strategy_outputs(result, d, plots=plots))
    return CommandResult(format_report(result), files, data=result, main=("summary",))


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
    settings: Mapping[str, Any],
    *,
    n_workers: int | None,
    sigma_deg: float,
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
        raise InputError(
            f"--runs {runs}: expected a whole number of Monte Carlo runs in "
            f"1..{MAX_RUNS:,} (default {defaults.runs})"
        )
    if n_workers is not None and (
        isinstance(n_workers, bool) or not isinstance(n_workers, int) or n_workers < 1
    ):
        raise InputError(f"--workers {n_workers}: expected a whole number >= 1 of worker processes")
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
            raise InputError(
                f"{_option(name)} {v:g}: expected a whole number (>= 1) of "
                f"{step:g} m {what}, e.g. {max(1, round(k)) * step:g}"
            )
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
            "(a dinghy beat is 0.5-3 km), or a smaller --half-width-m"
        )
    if runs * n["length_m"] > MAX_RUN_STEPS:
        raise InputError(
            f"--runs {runs} over {n['length_m']} rows of --length-m {grid.length_m:g}: "
            f"{runs * n['length_m']:.2g} Monte Carlo boat-steps per policy, more than "
            f"{MAX_RUN_STEPS:.0e}; use --runs <= {MAX_RUN_STEPS // n['length_m']}"
        )


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
            "--polar with higher TWS columns"
        )


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
