"""Command-line interface (thin): parse arguments, call the API, render, map errors.

Exit codes: 0 success, 1 unexpected internal error, 2 bad input
(:class:`~sailroute.errors.InputError` and subclasses), 3 routing failure
(:class:`~sailroute.errors.RoutingError`).  ``--debug`` re-raises with the full
traceback instead.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from typing import Annotated, Any, TypeVar

import click
import typer

from sailroute import __version__
from sailroute.errors import SailrouteError

app = typer.Typer(
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    add_completion=False,
    help="Race routing for buoy courses: fastest way round, leg by leg.",
)

_STATE = {"debug": False}
T = TypeVar("T")


def _version_callback(value: bool) -> None:
    if value:
        typer.echo(f"sailroute {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: Annotated[
        bool,
        typer.Option("--version", callback=_version_callback, is_eager=True, help="Show version."),
    ] = False,
    debug: Annotated[
        bool, typer.Option("--debug", help="Show full tracebacks instead of short errors.")
    ] = False,
) -> None:
    """Race routing for buoy courses: fastest way round, leg by leg."""
    _STATE["debug"] = debug


def run_guarded(fn: Callable[..., T], *args: Any, **kwargs: Any) -> T:
    """Call ``fn``; turn sailroute errors into a one-paragraph message and exit code."""
    try:
        return fn(*args, **kwargs)
    except SailrouteError as exc:
        if _STATE["debug"]:
            raise
        typer.echo(f"error: {exc}", err=True)
        raise typer.Exit(code=exc.exit_code) from None
    except KeyboardInterrupt:
        typer.echo("interrupted", err=True)
        raise typer.Exit(code=130) from None
    except (typer.Exit, typer.Abort, click.exceptions.ClickException):
        raise
    except Exception as exc:  # anything else is a bug: one short paragraph, exit 1
        if _STATE["debug"]:
            raise
        typer.echo(f"internal error: {type(exc).__name__}: {exc}\nThis is a bug in sailroute; "
                   "rerun with --debug (sailroute --debug COMMAND ...) for the traceback and "
                   "please report it.", err=True)
        raise typer.Exit(code=1) from None


# --- commands -------------------------------------------------------------------
# Each command parses options and delegates to the package API.  Keep logic out.


_ROUTER_HELP = "Router: isochrone | griddp | spline (default: the course's routing.router)."
_BACKEND_HELP = "Array backend: numpy | cupy | auto (cupy needs an NVIDIA GPU)."


def _progress(n_legs: int, quiet: bool) -> Any:
    from sailroute.report.progress import Progress

    return Progress(n_legs, enabled=not quiet)


def _echo_result(res: Any) -> None:
    typer.echo(res.report)
    typer.echo("")
    for kind, path in res.files.items():
        typer.echo(f"wrote {kind}: {path}")


@app.command("plan")
def plan_command(
    course: Annotated[str, typer.Argument(help="Course file (YAML, see docs/course-format.md).")],
    scenario: Annotated[
        str | None,
        typer.Option("--scenario", "-s", help="Wind scenario name (default: the first)."),
    ] = None,
    router: Annotated[str | None, typer.Option("--router", "-r", help=_ROUTER_HELP)] = None,
    out: Annotated[
        str | None,
        typer.Option("--out", "-o", help="Output folder (default: out/<course>/<scenario>)."),
    ] = None,
    no_plots: Annotated[
        bool, typer.Option("--no-plots", help="Skip route.png and report.html.")
    ] = False,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No progress display.")] = False,
    backend: Annotated[str, typer.Option("--backend", help=_BACKEND_HELP)] = "numpy",
) -> None:
    """Route a course leg by leg: leg times, start points, tacks; writes JSON/CSV/GPX/PNG/HTML."""
    from sailroute.plan import run_plan_command

    def run() -> Any:
        from sailroute.course.load import load_course

        loaded = load_course(course)
        return run_plan_command(loaded, scenario=scenario, router=router, out_dir=out,
                                plots=not no_plots, backend=backend,
                                progress=_progress(loaded.n_legs, quiet))

    _echo_result(run_guarded(run))


@app.command("compare-scenarios")
def compare_command(
    course: Annotated[str, typer.Argument(help="Course file (YAML, see docs/course-format.md).")],
    scenario: Annotated[
        list[str] | None,
        typer.Option("--scenario", "-s", help="Scenario to include (repeat; default: all)."),
    ] = None,
    router: Annotated[str | None, typer.Option("--router", "-r", help=_ROUTER_HELP)] = None,
    out: Annotated[
        str | None,
        typer.Option("--out", "-o", help="Output folder (default: out/<course>/comparison)."),
    ] = None,
    no_plots: Annotated[
        bool, typer.Option("--no-plots", help="Skip comparison.png and report.html.")
    ] = False,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No progress display.")] = False,
    backend: Annotated[str, typer.Option("--backend", help=_BACKEND_HELP)] = "numpy",
    scheduler: Annotated[
        str | None,
        typer.Option("--scheduler", help="serial (default) | processes (local Dask cluster) | "
                     "tcp://HOST:PORT (existing Dask scheduler); results are identical."),
    ] = None,
) -> None:
    """Route a course in every wind scenario; legs x scenarios table with reference errors."""
    from sailroute.plan import run_compare_command

    def run() -> Any:
        from sailroute.course.load import load_course

        loaded = load_course(course)
        return run_compare_command(loaded, scenarios=scenario, router=router, out_dir=out,
                                   plots=not no_plots, backend=backend,
                                   progress=_progress(loaded.n_legs, quiet), scheduler=scheduler)

    _echo_result(run_guarded(run))


@app.command("vpp")
def vpp_command(
    boat: Annotated[
        str | None,
        typer.Argument(help="Boat YAML (class, crew_mass_kg, parameter overrides); "
                       "default: the shipped ILCA 7."),
    ] = None,
    crew_mass: Annotated[
        float | None, typer.Option("--crew-mass", help="Sailor mass in kg (overrides the file).")
    ] = None,
    tws: Annotated[
        str | None,
        typer.Option("--tws", help="Comma-separated TWS list in --unit, e.g. '4,6,8,10'."),
    ] = None,
    twa_step: Annotated[float, typer.Option("--twa-step", help="TWA row step in degrees.")] = 5.0,
    out: Annotated[str, typer.Option("--out", help="Output folder.")] = "vpp-out",
    unit: Annotated[str, typer.Option("--unit", help="Speed unit: kn or m/s.")] = "kn",
    kinetics: Annotated[
        str, typer.Option("--kinetics", help="steady: the VPP alone; race: with wave riding "
                          "and pumping, as the built-in ilca7 (docs/vpp.md).")
    ] = "steady",
) -> None:
    """Run the Laser/ILCA VPP: print the polar and best VMG, write .pol/.csv/.json/.png."""
    from sailroute.boat.vpp_outputs import run_vpp_command

    res = run_guarded(
        run_vpp_command, boat, crew_mass_kg=crew_mass, tws=tws, twa_step_deg=twa_step,
        out_dir=out, unit=unit, kinetics=kinetics,
    )
    typer.echo(res.report)
    typer.echo("")
    for kind, path in res.files.items():
        typer.echo(f"wrote {kind}: {path}")


@app.command("strategy")
def strategy_command(
    tws_kn: Annotated[float, typer.Option("--tws-kn", help="Wind speed, kn.")] = 10.0,
    polar: Annotated[
        str, typer.Option("--polar", help="builtin:ilca7 | builtin:ilca6 | builtin:ilca4 "
                          "(race polars; add -steady for the steady VPP) | PATH.")
    ] = "builtin:ilca7",
    length_m: Annotated[float, typer.Option("--length-m", help="Beat length, m.")] = 1600.0,
    half_width_m: Annotated[
        float, typer.Option("--half-width-m", help="Course half-width, m.")
    ] = 800.0,
    sigma_deg: Annotated[
        float, typer.Option("--sigma-deg", help="Standard deviation of the wind direction, deg.")
    ] = 10.0,
    timescale_min: Annotated[
        float, typer.Option("--timescale-min", help="Time scale (e-folding) of the shifts, min.")
    ] = 10.0,
    drift_deg_per_min: Annotated[
        float,
        typer.Option("--drift-deg-per-min", help="Persistent shift for the deadline "
                     "objective, deg/min (+ veers)."),
    ] = 0.0,
    fit_from: Annotated[
        str | None,
        typer.Option("--fit-from", help="Station CSV: fit sigma and time scale from it."),
    ] = None,
    fit_station: Annotated[
        str | None, typer.Option("--fit-station", help="Station id in --fit-from.")
    ] = None,
    fit_timezone: Annotated[
        str | None,
        typer.Option("--fit-timezone", help="UTC offset for naive times in --fit-from, "
                     "e.g. +01:00."),
    ] = None,
    fit_speed_unit: Annotated[
        str | None,
        typer.Option("--fit-speed-unit", help="Unit of the speed column of --fit-from when "
                     "its header does not say: kn | m/s | km/h | mph."),
    ] = None,
    tack_penalty_s: Annotated[
        float, typer.Option("--tack-penalty-s", help="Time lost per tack, s.")
    ] = 5.0,
    objective: Annotated[
        str,
        typer.Option("--objective", help="expected | deadline=SECONDS[,SECONDS...]"),
    ] = "expected",
    runs: Annotated[int, typer.Option("--runs", help="Monte Carlo runs per policy.")] = 4000,
    seed: Annotated[int, typer.Option("--seed", help="Random seed.")] = 1,
    start_tack: Annotated[
        str, typer.Option("--start-tack", help="starboard | port.")
    ] = "starboard",
    shift: Annotated[
        str,
        typer.Option("--shift", help="Wind-shift model of the expected-time policy: ou "
                     "(mean-reverting) | drift-diffusion."),
    ] = "ou",
    diffusion_deg_per_sqrt_min: Annotated[
        float | None,
        typer.Option("--diffusion-deg-per-sqrt-min", help="Diffusion of the direction for "
                     "--shift drift-diffusion, deg/sqrt(min) (default: fitted or from sigma)."),
    ] = None,
    deadline_interpolation: Annotated[
        str,
        typer.Option("--deadline-interpolation", help="Deadline solver interpolation: linear "
                     "(bilinear, reproduces Wang et al. 2024) | cubic."),
    ] = "linear",
    deadline_refine: Annotated[
        str,
        typer.Option("--deadline-refine", help="Deadline solver steering: none (49 angles) | "
                     "golden (golden-section refinement per node)."),
    ] = "none",
    out: Annotated[str, typer.Option("--out", help="Output folder.")] = "strategy-out",
    no_plots: Annotated[bool, typer.Option("--no-plots", help="JSON summary only.")] = False,
    scheduler: Annotated[
        str | None,
        typer.Option("--scheduler", help="Monte Carlo on: serial (default) | processes (local "
                     "Dask cluster) | tcp://HOST:PORT; results are identical."),
    ] = None,
    workers: Annotated[
        int | None, typer.Option("--workers", help="Worker processes for --scheduler processes.")
    ] = None,
) -> None:
    """Tack strategy on an upwind leg under wind shifts: expected-time or deadline policies."""
    from sailroute.strategy.api import run_strategy_command

    res = run_guarded(
        run_strategy_command,
        polar_spec=polar, tws_kn=tws_kn, sigma_deg=sigma_deg, timescale_min=timescale_min,
        drift_deg_per_min=drift_deg_per_min, fit_from=fit_from, fit_station=fit_station,
        fit_timezone=fit_timezone, fit_speed_unit=fit_speed_unit, objective=objective,
        out_dir=out, plots=not no_plots,
        progress=lambda msg: typer.echo(msg, err=True),
        length_m=length_m, half_width_m=half_width_m, tack_penalty_s=tack_penalty_s,
        runs=runs, seed=seed, start_tack=start_tack, scheduler=scheduler, n_workers=workers,
        shift=shift, diffusion_deg_per_sqrt_min=diffusion_deg_per_sqrt_min,
        interpolation=deadline_interpolation, refine_controls=deadline_refine,
    )
    typer.echo(res.report)
    for path in res.files:
        typer.echo(f"wrote {path}")


polar_app = typer.Typer(no_args_is_help=True, help="Boat polars: fit one from logged data.")
app.add_typer(polar_app, name="polar")


@polar_app.command("fit")
def polar_fit_command(
    log: Annotated[str, typer.Argument(help="Instrument log (CSV with tws, twa, bsp or sog) "
                                       "or GPS track (GPX/CSV, with --course).")],
    course: Annotated[
        str | None,
        typer.Option("--course", help="Course file whose scenario wind gives TWS/TWA at the "
                     "track points (GPS track input)."),
    ] = None,
    scenario: Annotated[
        str | None, typer.Option("--scenario", "-s", help="Scenario of --course (default: "
                                 "the first).")
    ] = None,
    columns: Annotated[
        str | None,
        typer.Option("--columns", help="Log columns the reader does not recognise, e.g. "
                     "'time=Time,bsp=BSP,tws=TWS,twa=TWA'."),
    ] = None,
    speed_unit: Annotated[
        str | None,
        typer.Option("--speed-unit", help="Unit of the log's unsuffixed speed columns: "
                     "kn | m/s | km/h | mph."),
    ] = None,
    time_zone: Annotated[
        str | None,
        typer.Option("--time-zone", help="Zone of naive log times: UTC, +02:00, "
                     "Europe/Tallinn."),
    ] = None,
    percentile: Annotated[
        float, typer.Option("--percentile", help="Envelope percentile per cell.")
    ] = 90.0,
    min_count: Annotated[
        int, typer.Option("--min-count", help="Samples a cell needs to count as covered.")
    ] = 5,
    tws_bins: Annotated[
        str | None,
        typer.Option("--tws-bins", help="Comma-separated TWS columns in --unit (default: "
                     "every 2 kn / 1 m/s over the data)."),
    ] = None,
    twa_step: Annotated[float, typer.Option("--twa-step", help="TWA row step in degrees.")
                        ] = 10.0,
    out: Annotated[str, typer.Option("--out", help="Output folder.")] = "polar-fit-out",
    unit: Annotated[str, typer.Option("--unit", help="Speed unit: kn or m/s.")] = "kn",
    reference: Annotated[
        str | None,
        typer.Option("--reference", help="Polar to compare with: RMS and per-angle errors."),
    ] = None,
    reference_unit: Annotated[
        str | None,
        typer.Option("--reference-unit", help="Speed unit of --reference (default: the "
                     "reader's, knots for .pol/CSV)."),
    ] = None,
) -> None:
    """Fit a polar to a logged race: filtered percentile envelope; writes .pol/.csv/.json/.png."""
    from sailroute.boat.fit_outputs import run_fit_command

    res = run_guarded(
        run_fit_command, log, course=course, scenario=scenario, columns=columns,
        speed_unit=speed_unit, time_zone=time_zone, percentile=percentile,
        min_count=min_count, tws_bins=tws_bins, twa_step_deg=twa_step, out_dir=out,
        unit=unit, reference=reference, reference_unit=reference_unit,
    )
    _echo_result(res)


@app.command("analyze")
def analyze_command(
    course: Annotated[str, typer.Argument(help="Course file the boats sailed (YAML).")],
    tracks: Annotated[
        list[str], typer.Argument(help="Track file(s): GPX or CSV; several = a fleet.")
    ],
    scenario: Annotated[
        str | None,
        typer.Option("--scenario", "-s", help="Wind scenario name (default: the first)."),
    ] = None,
    out: Annotated[
        str | None,
        typer.Option("--out", "-o", help="Output folder (default: out/<course>/analysis-<track>)."),
    ] = None,
    leg_times: Annotated[
        str | None,
        typer.Option("--leg-times", help="Override detection: n_legs+1 comma-separated ISO "
                     "times with offset (start crossing, each leg's end); '-' = detect."),
    ] = None,
    speed_unit: Annotated[
        str | None,
        typer.Option("--speed-unit", help="Unit of unsuffixed CSV speed columns: kn | m/s | "
                     "km/h | mph."),
    ] = None,
    time_zone: Annotated[
        str | None,
        typer.Option("--time-zone", help="Zone of naive track times: '+02:00', 'UTC' or an "
                     "IANA name."),
    ] = None,
    column: Annotated[
        list[str] | None,
        typer.Option("--column", help="CSV column mapping CANON=NAME, e.g. time=when (repeat)."),
    ] = None,
    router: Annotated[str | None, typer.Option("--router", "-r", help=_ROUTER_HELP)] = None,
    no_plots: Annotated[
        bool, typer.Option("--no-plots", help="Skip legs.png, loss.png and report.html.")
    ] = False,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No progress display.")] = False,
) -> None:
    """Race analysis: a sailed track against the optimal route, leg by leg (time lost where)."""
    from sailroute.analyze import run_analyze_command

    def run() -> Any:
        from sailroute.course.load import load_course
        from sailroute.errors import InputError

        columns = {}
        for item in column or []:
            canon, sep, name = item.partition("=")
            if not sep or not canon.strip() or not name.strip():
                raise InputError(f"--column {item!r}: expected CANON=NAME, e.g. time=when")
            columns[canon.strip()] = name.strip()
        loaded = load_course(course)
        return run_analyze_command(
            loaded, tracks, scenario=scenario, router=router, out_dir=out, leg_times=leg_times,
            columns=columns or None, speed_unit=speed_unit, time_zone=time_zone,
            plots=not no_plots, progress=_progress(loaded.n_legs, quiet))

    _echo_result(run_guarded(run))


def main() -> None:
    """Console-script entry point."""
    try:
        app()
    except SailrouteError as exc:  # pragma: no cover - safety net
        typer.echo(f"error: {exc}", err=True)
        sys.exit(exc.exit_code)
