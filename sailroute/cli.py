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


# --- commands -------------------------------------------------------------------
# Each command parses options and delegates to the package API.  Keep logic out.


def main() -> None:
    """Console-script entry point."""
    try:
        app()
    except SailrouteError as exc:  # pragma: no cover - safety net
        typer.echo(f"error: {exc}", err=True)
        sys.exit(exc.exit_code)
