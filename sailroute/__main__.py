"""Allow ``python -m sailroute``; also the ``sailroute`` console script's entry point.

This module imports nothing heavy: :func:`main` imports the command line inside its
Ctrl-C guard, so an interrupt at any point of the start-up (typer, the command's
modules) ends in the same one line ``interrupted`` and exit code 130 as one during the
work, never in a traceback.
"""

from __future__ import annotations

import sys


def main() -> None:
    """Console-script entry point: :func:`sailroute.cli.main` under a Ctrl-C guard."""
    try:
        from sailroute.cli import main as cli_main

        cli_main()
    except KeyboardInterrupt:
        try:
            sys.stderr.write("interrupted\n")
            sys.stderr.flush()
        except (OSError, ValueError):  # pragma: no cover - stderr closed
            pass
        raise SystemExit(130) from None


if __name__ == "__main__":
    main()
