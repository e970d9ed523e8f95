"""Command-line interface (thin): parse arguments, call the API, render, map errors.

Exit codes: 0 success, 1 unexpected internal error, 2 bad input
(:class:`~sailroute.errors.InputError` and subclasses, and options the parser
refuses: an unknown choice, a missing argument), 3 routing failure
(:class:`~sailroute.errors.RoutingError`), 130 interrupted.  ``--debug`` re-raises
with the full traceback instead.

Output: the report (tables) and one ``wrote <what>: <path>`` line per file on stdout,
progress and warnings on stderr.  On a terminal the tables and the progress bar are
drawn with rich; otherwise (pipes, files, tests) they are plain text.  ``--json``
prints the command's main JSON document (e.g. ``plan.json``) on stdout and nothing
else.  Start-up is kept short (``sailroute --help`` < 150 ms): everything heavy is
imported inside the commands.
"""

# No ``from __future__ import annotations`` here: typer reads every command's signature
# twice as it builds the command line (``sailroute --help`` as much as ``plan``), and it
# evaluated each string annotation with ``eval`` both times, about 25 ms of every start.

import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import TYPE_CHECKING, Annotated, Any, Literal, NoReturn, TypeVar

import typer
from typer._click.exceptions import BadParameter
from typer.core import TyperArgument, TyperCommand, TyperGroup, TyperOption

from sailroute._version import __version__
from sailroute.cli_values import use_plain_coercion
from sailroute.errors import SailrouteError

if TYPE_CHECKING:
    from sailroute.commands.result import CommandResult

# --- fixed sets of values (checked by the parser, listed in --help, completed by the shell)
Router = Literal["isochrone", "griddp", "spline"]
"""Routers (``sailroute.routing.api.ROUTERS``; a test keeps them in step)."""
Backend = Literal["numpy", "cupy", "auto"]
SpeedUnit = Literal["kn", "m/s", "km/h", "mph"]
"""Speed units of input files (aliases such as ``knots`` are for files only)."""
TableUnit = Literal["kn", "m/s"]
"""Units of the polar tables the polar commands print and write."""
Kinetics = Literal["steady", "race"]
Tack = Literal["starboard", "port"]
"""Tack names (``sailroute.routing.types.Side``; a test keeps them in step)."""
Shift = Literal["ou", "drift-diffusion"]
DeadlineInterp = Literal["linear", "cubic"]
DeadlineRefine = Literal["none", "golden"]
DeadlineEngine = Literal["auto", "numpy", "numba", "cupy"]


_TYPE_METAVAR = {str: "TEXT", int: "INTEGER", float: "NUMBER"}


def _no_type(ctx: Any) -> None:
    return None


def _tidy(params: list[Any]) -> list[Any]:
    """Help without typer 0.29's type tags (``<bool>``, ``<str>``): flags show nothing,
    options their metavar (choices as ``[a|b|c]``), arguments their upper-case name."""
    for p in params:
        if isinstance(p, TyperArgument):
            if p.metavar is None:
                p.metavar = (p.name or "").upper()
            # an instance attribute hides the type column
            p.display_type_rich = _no_type  # type: ignore[method-assign]
        elif isinstance(p, TyperOption):
            if p.is_flag or p.count:
                p.metavar = ""
            elif p.metavar is None:
                desc = p.type_descriptor
                if desc.is_choice:
                    p.metavar = (
                        "["
                        + "|".join(str(getattr(c, "value", c)) for c in desc.choices or ())
                        + "]"
                    )
                else:
                    p.metavar = _TYPE_METAVAR.get(desc.annotation, "TEXT")
    return params


class _Command(TyperCommand):
    """A command whose help shows metavars instead of type tags."""

    def get_params(self, ctx: Any) -> list[Any]:
        return _tidy(super().get_params(ctx))

    def parse_args(self, ctx: Any, args: list[str]) -> list[str]:
        use_plain_coercion(self.get_params(ctx))  # typer's values without importing pydantic
        try:
            return super().parse_args(ctx, args)
        except BadParameter as exc:  # typer 0.29 prefixes pydantic's "Value error, "
            exc.message = exc.message.removeprefix("Value error, ")
            raise

    def collect_usage_pieces(self, ctx: Any) -> list[str]:
        pieces = [self.options_metavar] if self.options_metavar else []
        for p in self.get_params(ctx):
            if isinstance(p, TyperArgument):
                name = p.metavar or ""
                pieces.append(name if p.required else f"[{name}]")
            else:
                pieces.extend(p.get_usage_pieces(ctx))
        return pieces


class _Group(TyperGroup):
    """A command group whose help shows metavars instead of type tags, and whose
    parsing and dispatch end in ``interrupted`` and exit 130 on Ctrl-C (typer's own
    handler exits 130 silently)."""

    def get_params(self, ctx: Any) -> list[Any]:
        return _tidy(super().get_params(ctx))

    def parse_args(self, ctx: Any, args: list[str]) -> list[str]:
        use_plain_coercion(self.get_params(ctx))
        return super().parse_args(ctx, args)

    def make_context(self, *args: Any, **kwargs: Any) -> Any:
        try:
            return super().make_context(*args, **kwargs)
        except KeyboardInterrupt:
            _interrupted()

    def invoke(self, ctx: Any) -> Any:
        try:
            return super().invoke(ctx)
        except KeyboardInterrupt:
            _interrupted()


app = typer.Typer(
    cls=_Group,
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    add_completion=True,
    # plain (click-style) help: `sailroute --help` takes ~70 ms instead of ~150 ms with
    # typer's rich panels, whose module imports rich.markdown and rich.traceback
    rich_markup_mode=None,
    context_settings={"help_option_names": ["-h", "--help"]},
    help="Race routing for buoy courses: fastest way round, leg by leg.",
)

T = TypeVar("T")


@dataclass(frozen=True)
class _Options:
    """Options of the root command, kept in the click context (``ctx.obj``)."""

    debug: bool = False


def _debug(ctx: typer.Context) -> bool:
    """``--debug`` of the root command that ``ctx`` runs under."""
    obj = ctx.find_root().obj
    return isinstance(obj, _Options) and obj.debug


def _version_callback(value: bool) -> None:
    if value:
        typer.echo(f"sailroute {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    ctx: typer.Context,
    version: Annotated[
        bool,
        typer.Option("--version", callback=_version_callback, is_eager=True, help="Show version."),
    ] = False,
    debug: Annotated[
        bool, typer.Option("--debug", help="Show full tracebacks instead of short errors.")
    ] = False,
) -> None:
    """Race routing for buoy courses: fastest way round, leg by leg."""
    ctx.obj = _Options(debug=debug)


def _interrupted() -> NoReturn:
    """Ctrl-C: one line on stderr, exit 130 (128 + SIGINT, as shells report it)."""
    typer.echo("interrupted", err=True)
    raise typer.Exit(code=130) from None


def run_guarded(fn: Callable[[], T], *, debug: bool) -> T:
    """Call ``fn``; turn sailroute errors into a one-paragraph message and exit code
    (``debug``: re-raise them with the traceback instead)."""
    try:
        return fn()
    except SailrouteError as exc:
        if debug:
            raise
        typer.echo(f"error: {exc}", err=True)
        raise typer.Exit(code=exc.exit_code) from None
    except KeyboardInterrupt:
        _interrupted()
    except (typer.Exit, typer.Abort):
        raise
    except Exception as exc:  # anything else is a bug: one short paragraph, exit 1
        if debug:
            raise
        typer.echo(
            f"internal error: {type(exc).__name__}: {exc}\nThis is a bug in sailroute; "
            "rerun with --debug (sailroute --debug COMMAND ...) for the traceback and "
            "please report it.",
            err=True,
        )
        raise typer.Exit(code=1) from None


# --- output ---------------------------------------------------------------------------


def _check_out(out: str | None) -> None:
    """Refuse an unusable ``--out`` at once, before any input is read (exit 2)."""
    if out is not None:
        from sailroute.outdir import check_out_dir

        check_out_dir(out)


def _progress(n_legs: int, quiet: bool) -> Any:
    """Progress display on stderr: a rich bar on a terminal, plain lines otherwise."""
    from sailroute.progress import make_progress

    return make_progress(n_legs, enabled=not quiet)


@contextmanager
def _terminal_tables(json_out: bool) -> Iterator[None]:
    """Draw the report's tables with rich while stdout is a terminal (plain otherwise)."""
    if json_out or not sys.stdout.isatty():
        yield
        return
    from rich.console import Console

    from sailroute.report.tables import rich_tables

    with rich_tables(Console()):
        yield


def _finish(res: "CommandResult", json_out: bool) -> None:
    """Print the report and the files written, or (``--json``) the main JSON file only."""
    if json_out:
        path = res.main_json()
        if path is not None:
            sys.stdout.write(path.read_text(encoding="utf-8"))
            sys.stdout.flush()
        return
    from sailroute.report.files import FILE_LABELS, file_label

    typer.echo(res.report)
    typer.echo("")
    for kind, path in res.files.items():
        typer.echo(f"wrote {file_label(kind, path, res.labels or FILE_LABELS)}: {path}")


def _columns(column: list[str] | None) -> dict[str, str] | None:
    """``--column CANON=NAME`` options as a mapping (None: none given)."""
    from sailroute.errors import InputError

    columns = {}
    for item in column or []:
        canon, sep, name = item.partition("=")
        if not sep or not canon.strip() or not name.strip():
            raise InputError(f"--column {item!r}: expected CANON=NAME, e.g. time=when")
        columns[canon.strip()] = name.strip()
    return columns or None


# --- commands -------------------------------------------------------------------
# Each command parses options and delegates to the package API.  Keep logic out.

CourseArg = Annotated[
    str, typer.Argument(help="Course file (YAML, see docs/course-format.md).", metavar="COURSE")
]
RouterOpt = Annotated[
    Router | None,
    typer.Option(
        "--router",
        "-r",
        case_sensitive=False,
        help="Router (default: the course's routing.router).",
    ),
]
BackendOpt = Annotated[
    Backend,
    typer.Option(
        "--backend",
        case_sensitive=False,
        help="Array backend of the router kernels (cupy needs an NVIDIA GPU).",
    ),
]
NoPlotsOpt = Annotated[bool, typer.Option("--no-plots", help="Skip the PNG charts.")]
QuietOpt = Annotated[
    bool, typer.Option("--quiet", "-q", help="No progress display (warnings still shown).")
]
JsonOpt = Annotated[
    bool,
    typer.Option(
        "--json",
        help="Print the result as JSON on stdout (the main JSON file "
        "written) and nothing else; for scripts.",
    ),
]
SpeedUnitOpt = Annotated[
    SpeedUnit | None,
    typer.Option(
        "--speed-unit", case_sensitive=False, help="Unit of the input's unsuffixed speed columns."
    ),
]


TimeZoneOpt = Annotated[
    str | None,
    typer.Option(
        "--time-zone",
        metavar="ZONE",
        help="Zone of naive track times: '+02:00', 'UTC' or an IANA name.",
    ),
]
ColumnOpt = Annotated[
    list[str] | None,
    typer.Option(
        "--column", metavar="CANON=NAME", help="CSV column mapping, e.g. time=when (repeat)."
    ),
]


def _complete_scheduler(incomplete: str) -> list[str]:
    return [s for s in ("serial", "processes", "tcp://") if s.startswith(incomplete)]


EnsembleOpt = Annotated[
    int | None,
    typer.Option(
        "--ensemble",
        metavar="N",
        help="Leg-time bands: route N members drawn from the course's `uncertainty:` "
        "(or the defaults, docs/course-format.md) and report P10/P50/P90 per leg, "
        "the widest source and the sides; writes bands.json/csv/png.",
    ),
]
SchedulerOpt = Annotated[
    str | None,
    typer.Option(
        "--scheduler",
        metavar="WHERE",
        autocompletion=_complete_scheduler,
        help="serial (here, default), processes (a local Dask cluster) or "
        "tcp://HOST:PORT (an existing Dask scheduler); results are identical.",
    ),
]


@app.command("plan", cls=_Command, short_help="Route a course leg by leg in one wind scenario.")
def plan_command(
    ctx: typer.Context,
    course: CourseArg,
    scenario: Annotated[
        str | None,
        typer.Option(
            "--scenario",
            "-s",
            metavar="NAME",
            help="Wind scenario (default: the first in the file).",
        ),
    ] = None,
    router: RouterOpt = None,
    out: Annotated[
        str | None,
        typer.Option(
            "--out", "-o", metavar="DIR", help="Output folder (default: out/<course>/<scenario>)."
        ),
    ] = None,
    no_plots: Annotated[
        bool, typer.Option("--no-plots", help="Skip route.png and report.html.")
    ] = False,
    quiet: QuietOpt = False,
    json_out: JsonOpt = False,
    backend: BackendOpt = "numpy",
    ensemble: EnsembleOpt = None,
) -> None:
    """Route a course leg by leg: leg times, start points, tacks; writes JSON/CSV/GPX/PNG/HTML."""
    from sailroute.commands.plan import run_plan_command
    from sailroute.planning.route import RunOptions

    def run() -> Any:
        _check_out(out)
        from sailroute.course.load import load_course

        loaded = load_course(course)
        with _progress(loaded.n_legs, quiet) as progress, _terminal_tables(json_out):
            options = RunOptions(router, backend, progress)
            if ensemble is not None:  # leg-time bands (sailroute/commands/bands.py)
                from sailroute.commands.bands import run_bands_command

                return run_bands_command(
                    loaded,
                    scenarios=[scenario] if scenario else None,
                    members=ensemble,
                    out_dir=out,
                    plots=not no_plots,
                    options=options,
                )
            return run_plan_command(
                loaded, scenario=scenario, out_dir=out, plots=not no_plots, options=options
            )

    _finish(run_guarded(run, debug=_debug(ctx)), json_out)


@app.command(
    "start",
    cls=_Command,
    short_help="Time to the start line from a position, and the time to burn.",
)
def start_command(
    ctx: typer.Context,
    course: CourseArg,
    time: Annotated[
        str,
        typer.Option(
            "--time",
            "-t",
            metavar="T",
            help="When the boat is there: ISO 8601 with offset "
            "(2018-04-24T12:08:30+02:00) or seconds from the gun (-90).",
        ),
    ],
    at: Annotated[
        str | None,
        typer.Option("--at", metavar="LAT,LON", help="The boat's position in degrees."),
    ] = None,
    xy: Annotated[
        str | None,
        typer.Option(
            "--xy",
            metavar="X,Y",
            help="The boat's position in metres east and north of the course origin "
            "(instead of --at).",
        ),
    ] = None,
    scenario: Annotated[
        str | None,
        typer.Option(
            "--scenario",
            "-s",
            metavar="NAME",
            help="Wind scenario (default: the first in the file).",
        ),
    ] = None,
    out: Annotated[
        str | None,
        typer.Option(
            "--out", "-o", metavar="DIR", help="Output folder (default: out/<course>/start)."
        ),
    ] = None,
    json_out: JsonOpt = False,
) -> None:
    """Distance and time to the start line on each tack, the fastest approach, time to burn."""
    from sailroute.commands.start import run_start_command

    def run() -> Any:
        _check_out(out)
        with _terminal_tables(json_out):
            return run_start_command(
                course, time=time, at=at, xy=xy, scenario=scenario, out_dir=out
            )

    res = run_guarded(run, debug=_debug(ctx))
    if not json_out:
        for note in res.notes:
            typer.echo(f"note: {note}", err=True)
    _finish(res, json_out)


@app.command(
    "compare-scenarios",
    cls=_Command,
    short_help="Route a course in several wind scenarios, side by side.",
)
def compare_command(
    ctx: typer.Context,
    course: CourseArg,
    scenario: Annotated[
        list[str] | None,
        typer.Option(
            "--scenario", "-s", metavar="NAME", help="Scenario to include (repeat; default: all)."
        ),
    ] = None,
    router: RouterOpt = None,
    out: Annotated[
        str | None,
        typer.Option(
            "--out", "-o", metavar="DIR", help="Output folder (default: out/<course>/comparison)."
        ),
    ] = None,
    no_plots: Annotated[
        bool, typer.Option("--no-plots", help="Skip comparison.png and report.html.")
    ] = False,
    quiet: QuietOpt = False,
    json_out: JsonOpt = False,
    backend: BackendOpt = "numpy",
    scheduler: SchedulerOpt = None,
    ensemble: EnsembleOpt = None,
) -> None:
    """Route a course in every wind scenario; legs x scenarios table with reference errors."""
    from sailroute.commands.plan import run_compare_command
    from sailroute.planning.route import RunOptions

    def run() -> Any:
        _check_out(out)
        from sailroute.course.load import load_course

        loaded = load_course(course)
        with _progress(loaded.n_legs, quiet) as progress, _terminal_tables(json_out):
            options = RunOptions(router, backend, progress, scheduler)
            if ensemble is not None:  # leg-time bands of every scenario (commands/bands.py)
                from sailroute.commands.bands import run_bands_command

                names = scenario or [n for n in loaded.scenario_names if n not in loaded.ensembles]
                return run_bands_command(
                    loaded,
                    scenarios=names,
                    members=ensemble,
                    out_dir=out,
                    plots=not no_plots,
                    options=options,
                    what="comparison",
                )
            return run_compare_command(
                loaded, scenarios=scenario, out_dir=out, plots=not no_plots, options=options
            )

    _finish(run_guarded(run, debug=_debug(ctx)), json_out)


@app.command("vpp", cls=_Command, short_help="Laser/ILCA velocity prediction: polar and best VMG.")
def vpp_command(
    ctx: typer.Context,
    boat: Annotated[
        str | None,
        typer.Argument(
            help="Boat YAML (class, crew_mass_kg, parameter overrides); "
            "default: the shipped ILCA 7.",
            metavar="BOAT",
        ),
    ] = None,
    crew_mass: Annotated[
        float | None,
        typer.Option("--crew-mass", metavar="KG", help="Sailor mass, kg (overrides the file)."),
    ] = None,
    tws: Annotated[
        str | None,
        typer.Option(
            "--tws", metavar="LIST", help="Comma-separated TWS list in --unit, e.g. '4,6,8,10'."
        ),
    ] = None,
    twa_step: Annotated[
        float, typer.Option("--twa-step", metavar="DEG", help="TWA row step, degrees.")
    ] = 5.0,
    out: Annotated[
        str, typer.Option("--out", "-o", metavar="DIR", help="Output folder.")
    ] = "vpp-out",
    unit: Annotated[
        TableUnit,
        typer.Option("--unit", case_sensitive=False, help="Speed unit of the table and files."),
    ] = "kn",
    kinetics: Annotated[
        Kinetics,
        typer.Option(
            "--kinetics",
            case_sensitive=False,
            help="race (default): with wave riding and pumping, as the built-in "
            "ilca7 that plan routes with; steady: the VPP alone (docs/vpp.md).",
        ),
    ] = "race",
    json_out: JsonOpt = False,
) -> None:
    """Run the Laser/ILCA VPP: print the polar and best VMG, write .pol/.csv/.json/.png."""
    from sailroute.commands.vpp import run_vpp_command

    def run() -> Any:
        _check_out(out)
        return run_vpp_command(
            boat,
            crew_mass_kg=crew_mass,
            tws=tws,
            twa_step_deg=twa_step,
            out_dir=out,
            unit=unit,
            kinetics=kinetics,
        )

    _finish(run_guarded(run, debug=_debug(ctx)), json_out)


def _complete_polar(incomplete: str) -> list[str]:
    from sailroute.boat.build import builtin_names

    return [n for n in (f"builtin:{b}" for b in builtin_names()) if n.startswith(incomplete)]


def _complete_objective(incomplete: str) -> list[str]:
    return [s for s in ("expected", "deadline=") if s.startswith(incomplete)]


@app.command("strategy", cls=_Command, short_help="Tack strategy on a beat under wind shifts.")
def strategy_command(
    ctx: typer.Context,
    tws_kn: Annotated[float, typer.Option("--tws-kn", metavar="KN", help="Wind speed, kn.")] = 10.0,
    polar: Annotated[
        str,
        typer.Option(
            "--polar",
            metavar="POLAR",
            autocompletion=_complete_polar,
            help="builtin:ilca7 | builtin:ilca6 | builtin:ilca4 (race polars; add "
            "-steady for the steady VPP) or a polar file.",
        ),
    ] = "builtin:ilca7",
    length_m: Annotated[
        float, typer.Option("--length-m", metavar="M", help="Beat length, m.")
    ] = 1600.0,
    half_width_m: Annotated[
        float, typer.Option("--half-width-m", metavar="M", help="Course half-width, m.")
    ] = 800.0,
    sigma_deg: Annotated[
        float,
        typer.Option(
            "--sigma-deg", metavar="DEG", help="Standard deviation of the wind direction, deg."
        ),
    ] = 10.0,
    timescale_min: Annotated[
        float,
        typer.Option(
            "--timescale-min", metavar="MIN", help="Time scale (e-folding) of the shifts, min."
        ),
    ] = 10.0,
    drift_deg_per_min: Annotated[
        float,
        typer.Option(
            "--drift-deg-per-min",
            metavar="DEG/MIN",
            help="Persistent shift for the deadline objective, deg/min (+ veers).",
        ),
    ] = 0.0,
    fit_from: Annotated[
        str | None,
        typer.Option(
            "--fit-from", metavar="CSV", help="Station CSV: fit sigma and time scale from it."
        ),
    ] = None,
    fit_station: Annotated[
        str | None, typer.Option("--fit-station", metavar="ID", help="Station id in --fit-from.")
    ] = None,
    fit_timezone: Annotated[
        str | None,
        typer.Option(
            "--fit-timezone",
            metavar="OFFSET",
            help="UTC offset for naive times in --fit-from, e.g. +01:00.",
        ),
    ] = None,
    fit_speed_unit: Annotated[
        SpeedUnit | None,
        typer.Option(
            "--fit-speed-unit",
            case_sensitive=False,
            help="Unit of the speed column of --fit-from when its header does not say.",
        ),
    ] = None,
    tack_penalty_s: Annotated[
        float, typer.Option("--tack-penalty-s", metavar="S", help="Time lost per tack, s.")
    ] = 5.0,
    objective: Annotated[
        str,
        typer.Option(
            "--objective",
            metavar="OBJECTIVE",
            autocompletion=_complete_objective,
            help="expected (minimise the expected time) or deadline=S[,S...] "
            "(maximise the probability of finishing within S seconds).",
        ),
    ] = "expected",
    runs: Annotated[
        int, typer.Option("--runs", metavar="N", help="Monte Carlo runs per policy.")
    ] = 4000,
    seed: Annotated[int, typer.Option("--seed", metavar="N", help="Random seed.")] = 1,
    start_tack: Annotated[
        Tack, typer.Option("--start-tack", case_sensitive=False, help="Tack at the start.")
    ] = "starboard",
    shift: Annotated[
        Shift,
        typer.Option(
            "--shift",
            case_sensitive=False,
            help="Wind-shift model of the expected-time policy: ou (oscillating, "
            "mean-reverting) or drift-diffusion (persistent).",
        ),
    ] = "ou",
    diffusion_deg_per_sqrt_min: Annotated[
        float | None,
        typer.Option(
            "--diffusion-deg-per-sqrt-min",
            metavar="X",
            help="Diffusion of the direction for --shift drift-diffusion, "
            "deg/sqrt(min) (default: fitted or from sigma).",
        ),
    ] = None,
    deadline_interpolation: Annotated[
        DeadlineInterp,
        typer.Option(
            "--deadline-interpolation",
            case_sensitive=False,
            help="Deadline solver interpolation: linear (bilinear, reproduces "
            "Wang et al. 2024) or cubic.",
        ),
    ] = "linear",
    deadline_refine: Annotated[
        DeadlineRefine,
        typer.Option(
            "--deadline-refine",
            case_sensitive=False,
            help="Deadline solver steering: none (49 angles) or golden "
            "(golden-section refinement per node).",
        ),
    ] = "none",
    deadline_engine: Annotated[
        DeadlineEngine,
        typer.Option(
            "--deadline-engine",
            case_sensitive=False,
            help="Deadline solver kernels: auto (numba where installed), numpy, "
            "numba, or cupy (NVIDIA GPU); the same policy either way.",
        ),
    ] = "auto",
    out: Annotated[
        str, typer.Option("--out", "-o", metavar="DIR", help="Output folder.")
    ] = "strategy-out",
    no_plots: Annotated[bool, typer.Option("--no-plots", help="summary.json only.")] = False,
    scheduler: Annotated[
        str | None,
        typer.Option(
            "--scheduler",
            metavar="WHERE",
            autocompletion=_complete_scheduler,
            help="Where the Monte Carlo runs: serial (here, default), processes (a "
            "local Dask cluster) or tcp://HOST:PORT (an existing Dask scheduler); "
            "results are identical.",
        ),
    ] = None,
    workers: Annotated[
        int | None,
        typer.Option("--workers", metavar="N", help="Worker processes for --scheduler processes."),
    ] = None,
    quiet: QuietOpt = False,
    json_out: JsonOpt = False,
) -> None:
    """Tack strategy on an upwind leg under wind shifts: expected-time or deadline policies."""
    from sailroute.commands.strategy import run_strategy_command

    def run() -> Any:
        _check_out(out)
        return run_strategy_command(
            polar_spec=polar,
            tws_kn=tws_kn,
            sigma_deg=sigma_deg,
            timescale_min=timescale_min,
            drift_deg_per_min=drift_deg_per_min,
            fit_from=fit_from,
            fit_station=fit_station,
            fit_timezone=fit_timezone,
            fit_speed_unit=fit_speed_unit,
            objective=objective,
            out_dir=out,
            plots=not no_plots,
            progress=None if quiet else (lambda msg: typer.echo(msg, err=True)),
            length_m=length_m,
            half_width_m=half_width_m,
            tack_penalty_s=tack_penalty_s,
            runs=runs,
            seed=seed,
            start_tack=start_tack,
            scheduler=scheduler,
            n_workers=workers,
            shift=shift,
            diffusion_deg_per_sqrt_min=diffusion_deg_per_sqrt_min,
            interpolation=deadline_interpolation,
            refine_controls=deadline_refine,
            deadline_engine=deadline_engine,
        )

    _finish(run_guarded(run, debug=_debug(ctx)), json_out)


polar_app = typer.Typer(
    cls=_Group,
    no_args_is_help=True,
    rich_markup_mode=None,
    help="Boat polars: learn one from a fleet's logged data.",
)
app.add_typer(polar_app, name="polar")


@polar_app.command(
    "fit", cls=_Command, short_help="Learn a polar from a fleet's logs or tracks, at levels."
)
def polar_fit_command(
    ctx: typer.Context,
    logs: Annotated[
        list[str],
        typer.Argument(
            help="Instrument logs (CSV with wind columns) and/or GPS tracks (GPX/CSV, with "
            "--course); several = a fleet.",
            metavar="LOG...",
        ),
    ],
    course: Annotated[
        list[str] | None,
        typer.Option(
            "--course",
            metavar="COURSE",
            help="Course of a race the logs sailed (repeat for several races): each race "
            "is learned in the wind analyze would judge it in, and its legs give the race "
            "pace.  Needed for GPS tracks.",
        ),
    ] = None,
    scenario: Annotated[
        str | None,
        typer.Option(
            "--scenario", "-s", metavar="NAME", help="Scenario of the courses (default: the first)."
        ),
    ] = None,
    columns: Annotated[
        str | None,
        typer.Option(
            "--columns",
            metavar="MAP",
            help="Log columns the reader does not recognise, e.g. 'time=Time,tws=TWS,twd=TWD'.",
        ),
    ] = None,
    speed_unit: SpeedUnitOpt = None,
    time_zone: Annotated[
        str | None,
        typer.Option(
            "--time-zone",
            metavar="ZONE",
            help="Zone of naive log times: UTC, +02:00, Europe/Tallinn.",
        ),
    ] = None,
    levels: Annotated[
        str | None,
        typer.Option(
            "--levels",
            metavar="LIST",
            help="Levels: percentiles of the boats, e.g. 'median=50,top=90' (the default).",
        ),
    ] = None,
    percentile: Annotated[
        float,
        typer.Option(
            "--percentile", metavar="P", help="Percentile of a boat's own steady speeds per cell."
        ),
    ] = 50.0,
    min_boats: Annotated[
        int | None,
        typer.Option(
            "--min-boats", metavar="N", help="Boats a cell needs (default 2; 1 for one log)."
        ),
    ] = None,
    min_blocks: Annotated[
        int,
        typer.Option("--min-blocks", metavar="N", help="Steady blocks a cell needs."),
    ] = 3,
    bootstrap: Annotated[
        int,
        typer.Option("--bootstrap", metavar="N", help="Bootstrap replicates (0: no uncertainty)."),
    ] = 200,
    seed: Annotated[int, typer.Option("--seed", metavar="N", help="Seed of the bootstrap.")] = 0,
    tws_bins: Annotated[
        str | None,
        typer.Option(
            "--tws-bins",
            metavar="LIST",
            help="Comma-separated TWS columns in --unit "
            "(default: every 2 kn / 1 m/s over the data).",
        ),
    ] = None,
    twa_step: Annotated[
        float, typer.Option("--twa-step", metavar="DEG", help="TWA row step, degrees.")
    ] = 10.0,
    out: Annotated[
        str, typer.Option("--out", "-o", metavar="DIR", help="Output folder.")
    ] = "polar-fit-out",
    unit: Annotated[
        TableUnit,
        typer.Option("--unit", case_sensitive=False, help="Speed unit of the table and files."),
    ] = "kn",
    reference: Annotated[
        str | None,
        typer.Option(
            "--reference", metavar="POLAR", help="Polar to compare with: RMS and per-angle errors."
        ),
    ] = None,
    reference_unit: Annotated[
        SpeedUnit | None,
        typer.Option(
            "--reference-unit",
            case_sensitive=False,
            help="Speed unit of --reference (default: the reader's, knots for .pol/CSV).",
        ),
    ] = None,
    name: Annotated[
        str | None,
        typer.Option(
            "--name",
            metavar="NAME",
            help="Name of the polar and stem of its files (default: <first log>-fleet).",
        ),
    ] = None,
    shape: Annotated[
        str | None,
        typer.Option(
            "--shape",
            metavar="POLAR",
            help="builtin:NAME or a polar file whose shape fills the winds and angles the "
            "fleet did not sail, scaled to it per point of sail.",
        ),
    ] = None,
    quiet: QuietOpt = False,
    json_out: JsonOpt = False,
) -> None:
    """Learn a polar from a fleet's steady sailing: levels, uncertainty, verdict; writes
    .pol/.csv/.json/.png."""
    from sailroute.commands.polar_fit import run_fit_command

    def run() -> Any:
        _check_out(out)
        with _progress(0, quiet) as progress:
            return run_fit_command(
                logs,
                courses=course or (),
                scenario=scenario,
                columns=columns,
                speed_unit=speed_unit,
                time_zone=time_zone,
                levels=levels,
                percentile=percentile,
                min_boats=min_boats,
                min_blocks=min_blocks,
                bootstrap=bootstrap,
                seed=seed,
                tws_bins=tws_bins,
                twa_step_deg=twa_step,
                out_dir=out,
                unit=unit,
                reference=reference,
                reference_unit=reference_unit,
                shape=shape,
                name=name,
                progress=progress,
            )

    _finish(run_guarded(run, debug=_debug(ctx)), json_out)


@app.command(
    "analyze", cls=_Command, short_help="Sailed tracks against the optimal route, leg by leg."
)
def analyze_command(
    ctx: typer.Context,
    course: Annotated[
        str, typer.Argument(help="Course file the boats sailed (YAML).", metavar="COURSE")
    ],
    tracks: Annotated[
        list[str],
        typer.Argument(help="Track file(s): GPX or CSV; several = a fleet.", metavar="TRACK..."),
    ],
    scenario: Annotated[
        str | None,
        typer.Option(
            "--scenario",
            "-s",
            metavar="NAME",
            help="Wind scenario (default: the first in the file).",
        ),
    ] = None,
    out: Annotated[
        str | None,
        typer.Option(
            "--out",
            "-o",
            metavar="DIR",
            help="Output folder (default: out/<course>/analysis-<track>).",
        ),
    ] = None,
    leg_times: Annotated[
        list[str] | None,
        typer.Option(
            "--leg-times",
            metavar="[BOAT=]T0,T1,...",
            help="Override detection: "
            "n_legs+1 comma-separated ISO times with offset (start crossing, each "
            "leg's end); '-' = detect. Several tracks: BOAT=T0,... per boat (BOAT = "
            "track file name without extension; repeat).",
        ),
    ] = None,
    speed_unit: SpeedUnitOpt = None,
    time_zone: TimeZoneOpt = None,
    column: ColumnOpt = None,
    router: RouterOpt = None,
    no_plots: Annotated[
        bool, typer.Option("--no-plots", help="Skip legs.png, loss.png and report.html.")
    ] = False,
    gate_end: Annotated[
        Literal["line", "rounding"],
        typer.Option(
            "--gate-end",
            case_sensitive=False,
            help="A gate leg ends passing between the marks (line) or having "
            "rounded the chosen mark (rounding, as official leg counters).",
        ),
    ] = "line",
    wind: Annotated[
        Literal["auto", "measured", "inferred", "scenario"],
        typer.Option(
            "--wind",
            case_sensitive=False,
            help="Wind each leg is judged in: auto (the boat's measured wind, the "
            "fleet's, the wind inferred from the tracks, then the scenario), "
            "measured, inferred or scenario.",
        ),
    ] = "auto",
    reference: Annotated[
        Literal["course", "fleet", "learned"],
        typer.Option(
            "--reference",
            case_sensitive=False,
            help="Polar the boats are judged against: the course's, it scaled "
            "to what the fleet sails (fleet), or the polar learned from the fleet's "
            "tracks (learned, as `polar fit`).",
        ),
    ] = "course",
    pages: Annotated[
        Literal["fleet", "boat"],
        typer.Option(
            "--pages",
            case_sensitive=False,
            help="Several tracks: the fleet's report.html only (fleet), or also each "
            "boat's report.html, legs.png and loss.png in its folder (boat).",
        ),
    ] = "fleet",
    marks: Annotated[
        Literal["course", "infer"],
        typer.Option(
            "--marks",
            case_sensitive=False,
            help="The course's marks (course), or marks, lines and legs inferred from the "
            "tracks' turns (infer; COURSE keeps its boat, wind and gun, or is the first "
            "track when it is not a .yaml file).",
        ),
    ] = "course",
    wind_tws: Annotated[
        float | None,
        typer.Option(
            "--wind-tws",
            metavar="KN",
            help="With --marks infer and no course file: wind speed, knots.",
        ),
    ] = None,
    gun: Annotated[
        str | None,
        typer.Option(
            "--gun",
            metavar="TIME",
            help="The gun the race is timed from, ISO with offset: the restart after a "
            "general recall (default: the course's restart_time, else start_time).",
        ),
    ] = None,
    quiet: QuietOpt = False,
    json_out: JsonOpt = False,
) -> None:
    """Race analysis: a sailed track against the optimal route, leg by leg (time lost where)."""
    from sailroute.commands.analyze import run_analyze_command

    def run() -> Any:
        _check_out(out)
        from sailroute.course.load import load_course

        columns = _columns(column)
        if marks == "infer":  # the course's marks from the fleet's turns
            from sailroute.commands.course_infer import infer_for_analyze

            loaded, found, tracks_ = infer_for_analyze(
                course,
                tracks,
                wind_tws,
                columns=columns,
                speed_unit=speed_unit,
                time_zone=time_zone,
            )
        else:
            loaded, found, tracks_ = load_course(course), None, tracks
        with _progress(loaded.n_legs, quiet) as progress, _terminal_tables(json_out):
            res = run_analyze_command(
                loaded,
                tracks_,
                scenario=scenario,
                router=router,
                out_dir=out,
                leg_times=leg_times,
                columns=columns,
                speed_unit=speed_unit,
                time_zone=time_zone,
                plots=not no_plots,
                progress=progress,
                gate_end=gate_end,
                wind=wind,
                reference=reference,
                pages=pages,
                gun=gun,
            )
        return res if found is None else found.before(res)

    _finish(run_guarded(run, debug=_debug(ctx)), json_out)


# --- course import (one block: the `course` sub-app) ------------------------------------
course_app = typer.Typer(
    cls=_Group,
    no_args_is_help=True,
    rich_markup_mode=None,
    help="Course files from other programs.",
)
app.add_typer(course_app, name="course")

CourseBoatOpt = Annotated[
    str | None,
    typer.Option(
        "--boat",
        metavar="BOAT",
        help="Built-in polar (ilca7), a polar file, "
        "or a mapping '{polar: f50.csv, speed_unit: km/h}' (default: none).",
    ),
]


@course_app.command(
    "import", cls=_Command, short_help="A course file (YAML) from GPX, CSV, KML or race XML."
)
def course_import_command(
    ctx: typer.Context,
    source: Annotated[
        str, typer.Argument(help="GPX, CSV, KML or SailGP race XML file.", metavar="FILE")
    ],
    out: Annotated[
        str | None,
        typer.Option(
            "--out",
            "-o",
            metavar="COURSE.yaml",
            help="Course file to write (default: <FILE stem>.yaml here).",
        ),
    ] = None,
    fmt: Annotated[
        Literal["auto", "gpx", "csv", "kml", "racexml"],
        typer.Option(
            "--format",
            case_sensitive=False,
            help="Input format (auto: by suffix, or the root element of .xml).",
        ),
    ] = "auto",
    boat: CourseBoatOpt = None,
    wind_twd: Annotated[
        float | None,
        typer.Option(
            "--wind-twd", metavar="DEG", help="Uniform wind direction, degrees (from); required."
        ),
    ] = None,
    wind_tws: Annotated[
        float | None,
        typer.Option("--wind-tws", metavar="KN", help="Uniform wind speed, knots; required."),
    ] = None,
    start_time: Annotated[
        str | None,
        typer.Option(
            "--start-time",
            metavar="TIME",
            help="Start, ISO 8601 with offset "
            "(required unless the file gives it, as race XML does).",
        ),
    ] = None,
) -> None:
    """Import a course: marks, lines, gates, legs, boundary; writes a course file that plans."""
    from sailroute.commands.course_import import run_course_import_command

    def run() -> Any:
        return run_course_import_command(
            source,
            out=out,
            fmt=fmt,
            boat=boat,
            wind_twd_deg=wind_twd,
            wind_tws_kn=wind_tws,
            start_time=start_time,
        )

    _finish(run_guarded(run, debug=_debug(ctx)), False)


@course_app.command(
    "infer",
    cls=_Command,
    short_help="A course file (YAML) from a fleet's tracks: marks where it turned.",
)
def course_infer_command(
    ctx: typer.Context,
    tracks: Annotated[
        list[str],
        typer.Argument(
            help="Track files (GPX/CSV) of two boats or more of one race.", metavar="TRACK..."
        ),
    ],
    out: Annotated[
        str,
        typer.Option("--out", "-o", metavar="COURSE.yaml", help="Course file to write."),
    ],
    wind_tws: Annotated[
        float | None,
        typer.Option(
            "--wind-tws",
            metavar="KN",
            help="Wind speed, knots; required (the direction comes from the tracks).",
        ),
    ] = None,
    start_time: Annotated[
        str | None,
        typer.Option(
            "--start-time",
            metavar="TIME",
            help="The gun, ISO 8601 with offset (default: inferred).",
        ),
    ] = None,
    t_from: Annotated[
        str | None,
        typer.Option(
            "--from", metavar="TIME", help="Use the fixes from this time (logs of several races)."
        ),
    ] = None,
    t_until: Annotated[
        str | None,
        typer.Option("--until", metavar="TIME", help="... up to this time."),
    ] = None,
    boat: CourseBoatOpt = None,
    name: Annotated[
        str | None,
        typer.Option("--name", metavar="TEXT", help="Course name (default: inferred course)."),
    ] = None,
    speed_unit: SpeedUnitOpt = None,
    time_zone: TimeZoneOpt = None,
    column: ColumnOpt = None,
    json_out: JsonOpt = False,
) -> None:
    """Infer a course from a fleet's tracks: marks, gates, lines, legs, gun; writes it."""
    from sailroute.commands.course_infer import run_course_infer_command

    def run() -> Any:
        return run_course_infer_command(
            tracks,
            out=out,
            start_time=start_time,
            t_from=t_from,
            t_until=t_until,
            wind_tws_kn=wind_tws,
            boat=boat,
            name=name,
            columns=_columns(column),
            speed_unit=speed_unit,
            time_zone=time_zone,
        )

    _finish(run_guarded(run, debug=_debug(ctx)), json_out)


# --- live (re-plan from the instruments) ----------------------------------------------
@app.command(
    "live", cls=_Command, short_help="Re-plan the rest of a race from a boat's instruments, live."
)
def live_command(
    ctx: typer.Context,
    course: CourseArg,
    source: Annotated[
        str,
        typer.Option(
            "--source",
            metavar="SOURCE",
            help="signalk://HOST:PORT, nmea+tcp://HOST:PORT, nmea+udp://:PORT "
            "or a recorded .nmea file.",
        ),
    ],
    scenario: Annotated[
        str | None,
        typer.Option(
            "--scenario",
            "-s",
            metavar="NAME",
            help="Forecast scenario (default: the first in the file).",
        ),
    ] = None,
    every: Annotated[
        float, typer.Option("--every", metavar="S", help="Re-plan at least every S seconds.")
    ] = 10.0,
    speed: Annotated[
        float, typer.Option("--speed", metavar="X", help="Replay speed of a recorded file.")
    ] = 1.0,
    boat: Annotated[
        str | None,
        typer.Option(
            "--boat",
            metavar="BOAT",
            help="The sailor's boat: self (the instruments' own position), an AIS MMSI or a "
            "Signal K vessel id (default: chosen on the page).",
        ),
    ] = None,
    boat_source: Annotated[
        str | None,
        typer.Option(
            "--boat-source",
            metavar="SOURCE",
            help="A second feed whose own position is the sailor's boat (as --source).",
        ),
    ] = None,
    port: Annotated[int, typer.Option("--port", help="Port of the page.")] = 8080,
    nmea_port: Annotated[
        int,
        typer.Option("--nmea-port", help="TCP port of the NMEA 0183 output (busy: the next free)."),
    ] = 10110,
    host: Annotated[
        str | None,
        typer.Option(
            "--host",
            metavar="ADDRESS",
            help="Serve the page and NMEA out on this address, not 127.0.0.1 (the page then "
            "needs the token in its address).",
        ),
    ] = None,
    no_checksum: Annotated[
        bool,
        typer.Option(
            "--accept-no-checksum",
            help="Read NMEA 0183 sentences without a checksum (a talker that sends none).",
        ),
    ] = False,
    log: Annotated[
        str | None,
        typer.Option("--log", metavar="FILE", help="JSON-lines log of inputs and re-plans."),
    ] = None,
    duration: Annotated[
        float | None,
        typer.Option(
            "--duration",
            metavar="S",
            help="Run S seconds (default: until Ctrl-C or the end of a recorded file).",
        ),
    ] = None,
    leg: Annotated[int, typer.Option("--leg", help="Leg being sailed now (1-based).")] = 1,
    router: RouterOpt = None,
) -> None:
    """Re-plan the rest of the course for the sailor's boat from live instruments; page,
    NMEA out and a log."""
    from sailroute.commands.live import run_live_command
    from sailroute.live.engine import LiveSettings

    def run() -> Any:
        return run_live_command(
            course,
            source=source,
            scenario=scenario,
            every_s=every,
            speed=speed,
            port=port,
            nmea_port=nmea_port,
            log=log,
            duration_s=duration,
            router=router,
            leg=leg,
            announce=typer.echo,
            settings=LiveSettings(require_checksum=not no_checksum),
            boat=boat,
            boat_source=boat_source,
            host=host,
        )

    _finish(run_guarded(run, debug=_debug(ctx)), False)


@app.command(
    "live-convert", cls=_Command, short_help="Turn an instrument log into an NMEA 0183 replay file."
)
def live_convert_command(
    ctx: typer.Context,
    log: Annotated[str, typer.Argument(help="The instrument log (CSV).", metavar="LOG")],
    fmt: Annotated[
        Literal["trieste", "tallinn"],
        typer.Option("--format", case_sensitive=False, help="Log format (docs/live.md)."),
    ],
    out: Annotated[
        str, typer.Option("--out", "-o", metavar="FILE", help="The .nmea file to write.")
    ],
    utc_offset: Annotated[
        str | None,
        typer.Option(
            "--utc-offset",
            metavar="+HH:MM",
            help="The logger clock's UTC offset, for times without one (trieste; default +01:00).",
        ),
    ] = None,
    start: Annotated[
        str | None, typer.Option("--from", metavar="TIME", help="First time kept (ISO 8601).")
    ] = None,
    end: Annotated[
        str | None, typer.Option("--to", metavar="TIME", help="Last time kept (ISO 8601).")
    ] = None,
) -> None:
    """Convert an instrument log (Trieste coach boat, Tallinn race) to NMEA 0183."""
    from sailroute.commands.live import run_live_convert_command

    def run() -> Any:
        return run_live_convert_command(
            log, fmt=fmt, out=out, utc_offset=utc_offset, start=start, end=end
        )

    _finish(run_guarded(run, debug=_debug(ctx)), False)


def main() -> None:
    """Run the command line (the console script's :func:`sailroute.__main__.main` imports
    this module inside its own Ctrl-C guard)."""
    try:
        app()
    except SailrouteError as exc:  # pragma: no cover - safety net
        typer.echo(f"error: {exc}", err=True)
        sys.exit(exc.exit_code)
    except KeyboardInterrupt:  # outside the commands (typer's set-up): the same line
        typer.echo("interrupted", err=True)
        sys.exit(130)
