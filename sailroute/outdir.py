"""The output folder of every command (``--out``): created once, errors that say what to do."""

from __future__ import annotations

from pathlib import Path

from sailroute.errors import InputError


def make_out_dir(path: str | Path) -> Path:
    """Create the output folder ``path`` (and its parents) if missing; return it.

    Raises
    ------
    InputError
        ``path`` exists as a file, or cannot be created (permissions, read-only disk).
    """
    d = Path(path)
    try:
        d.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        why = "a file of that name exists" if d.is_file() else (exc.strerror or str(exc))
        raise InputError(
            f"--out: cannot create the output folder {str(d)!r} ({why}); "
            "choose another folder with --out"
        ) from None
    return d
