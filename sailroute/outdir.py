"""The output folder of every command (``--out``): checked before the work, written as a set.

Rules (``docs/usage.md``, "The output folder"):

* :func:`check_out_dir` refuses a folder that cannot be used (a file of that name, no
  permission) *before* any routing, with an :class:`~sailroute.errors.InputError`
  (exit 2).  It creates nothing.
* :func:`write_output_set` runs a writer in a fresh staging folder and only then moves
  its files into the output folder, so a run that fails or is interrupted (Ctrl-C)
  leaves the previous run's files as they were and no staging folder behind.
* The run owns the files it wrote: their names (relative paths) are listed in
  ``.sailroute-manifest.json`` in the output folder.  The next run into the same folder
  replaces that set with its own: files of the old set that the new run does not write
  (``route.png`` after a ``--no-plots`` rerun) are deleted, and nothing else is.  A
  user's own files in the folder are never listed, so never deleted (only a file with
  the same name as an output is overwritten, as by any program that writes there).
* A command that writes one file (``course import -o``, ``live-convert -o``) checks it
  with :func:`check_out_file` (not a folder, its folder exists, not one of the
  command's inputs) and writes it with :func:`replacing`: into a draft of an
  unpredictable name beside it, created exclusively (never through a symbolic link
  someone placed there), moved onto the file only once complete.
* Every file lands inside the output folder: a name that becomes a path part (a
  scenario, an ensemble member: :func:`path_part_problem`, checked when the course is
  read) cannot climb out of it, files are never written through a symbolic link to a
  folder inside it, and a manifest entry under such a link is never deleted (the link
  may point anywhere).
"""

from __future__ import annotations

import json
import os
import secrets
import shutil
import signal
import threading
from collections.abc import Callable, Iterable, Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path, PurePosixPath
from typing import IO, Any, TypeVar

from sailroute.errors import InputError

MANIFEST_NAME = ".sailroute-manifest.json"
"""File in an output folder listing the files the last run wrote there (relative paths)."""

STAGE_PREFIX = ".sailroute-tmp-"
"""Name prefix of the staging folders :func:`write_output_set` writes into."""

T = TypeVar("T")


PATH_PART_MAX = 100
"""Longest name (characters) that may become a file or folder name in an output folder."""


def path_part_problem(name: str) -> str | None:
    """Why ``name`` cannot be a file or folder name in an output folder, or None if it can.

    A name that becomes a path part (a scenario's folder in ``compare-scenarios``, the
    default ``out/<course>/<scenario>``) must be one part: not empty, not ``.`` or ``..``,
    no ``/`` or ``\\`` (so never absolute), no ``:`` (a drive on Windows), no control
    characters, at most :data:`PATH_PART_MAX` characters, and not starting with ``.``
    (hidden, and the staging folders' prefix).

    Parameters
    ----------
    name : str
        The name.

    Returns
    -------
    str or None
        A short reason (for an error message), or None when the name is safe.
    """
    if not name:
        return "it is empty"
    if name.startswith("."):
        return "it starts with '.' (a hidden or parent folder)"
    bad = sorted({ch for ch in name if ch in "/\\:" or ord(ch) < 32 or ord(ch) == 127})
    if bad:
        return (
            "it contains " + ", ".join(repr(ch) for ch in bad) + " (a path separator or "
            "a control character)"
        )
    if len(name) > PATH_PART_MAX:
        return f"it is {len(name)} characters long (at most {PATH_PART_MAX})"
    return None


def safe_part(name: str, what: str) -> str:
    """``name`` if it can be a file or folder name in an output folder, else an error.

    Raises
    ------
    InputError
        ``name`` is not safe (:func:`path_part_problem`); the message names ``what``.
    """
    why = path_part_problem(name)
    if why is not None:
        raise InputError(
            f"{what} {name!r} cannot name a folder of the output: {why}; "
            "use letters, digits, '-', '_' or '#'"
        )
    return name


def _cannot(d: Path, why: str, option: str) -> InputError:
    return InputError(
        f"{option}: cannot create the output folder {str(d)!r} ({why}); "
        f"choose another folder with {option}"
    )


def check_out_dir(path: str | Path, option: str = "--out") -> Path:
    """Check that ``path`` can be the output folder, without creating anything.

    It must be a writable folder, or not exist yet below a writable folder (its
    missing parents are created when the files are written).

    Parameters
    ----------
    path : str or Path
        The output folder.
    option : str
        The option named in the error message.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    InputError
        ``path`` is empty, ``path`` or one of its parents is a file, or there is no
        permission to write.
    """
    d = Path(path)
    if not str(path).strip():
        raise InputError(
            f"{option} {str(path)!r}: an empty folder name; give the output folder "
            f"(e.g. {option} out/run, or {option} . for the working folder)"
        )
    if d.exists():
        if not d.is_dir():
            raise _cannot(d, "a file of that name exists", option)
        if not os.access(d, os.W_OK | os.X_OK):
            raise InputError(
                f"{option}: cannot write into the output folder {str(d)!r} (no "
                f"permission); choose another folder with {option}"
            )
        return d
    parent = d.absolute().parent
    while not parent.exists() and parent != parent.parent:
        parent = parent.parent
    if not parent.is_dir():
        raise _cannot(d, f"{str(parent)!r} is a file, not a folder", option)
    if not os.access(parent, os.W_OK | os.X_OK):
        raise _cannot(d, f"no permission to write in {str(parent)!r}", option)
    return d


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
        raise _cannot(d, why, "--out") from None
    return d


# --- writing one file ----------------------------------------------------------------------


def _same_file(a: Path, b: Path) -> bool:
    """Whether ``a`` and ``b`` name one file (through links too); False if either is missing."""
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def check_out_file(path: str | Path, inputs: Iterable[str | Path] = (), option: str = "-o") -> Path:
    """Check that ``path`` can be written as a command's one output file, creating nothing.

    Parameters
    ----------
    path : str or Path
        The file to write.
    inputs : iterable of str or Path
        Every file the command reads: the output may be none of them (writing it would
        replace an input before, or while, it is read).
    option : str
        The option named in messages.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    InputError
        An empty name, a folder, a folder that does not exist, or one of ``inputs``.
    """
    p = Path(path)
    if not str(path).strip():
        raise InputError(f"{option} {str(path)!r}: an empty file name; give the file to write")
    if p.is_dir():
        raise InputError(f"{option} {p}: a folder; expected the name of the file to write")
    if not p.absolute().parent.is_dir():
        raise InputError(
            f"{option} {p}: the folder {p.absolute().parent} does not exist; create it "
            "first or choose another"
        )
    for src in inputs:
        if _same_file(p, Path(src)):
            raise InputError(
                f"{option} {p}: the same file as the input {src}; writing it would replace "
                "the input; choose another name"
            )
    return p


@contextmanager
def replacing(
    path: str | Path, option: str = "-o", *, newline: str | None = None
) -> Iterator[IO[str]]:
    """A text file to write that replaces ``path`` only once the block ends without error.

    The text goes to a draft ``.<name>.<random>.sailroute-tmp`` in the same folder,
    created with ``O_EXCL | O_NOFOLLOW`` (a file or symbolic link already there is an
    error, never followed), then moved onto ``path`` (which replaces a symbolic link at
    ``path`` itself, not its target).  If the block raises (or Ctrl-C interrupts it),
    the draft is removed and ``path`` is left as it was.

    Parameters
    ----------
    path : str or Path
        The file to write (checked with :func:`check_out_file` first).
    option : str
        The option named in messages.
    newline : str, optional
        As :func:`open` (``"\r\n"`` writes CR LF line ends).

    Yields
    ------
    file
        Open for writing text in UTF-8.

    Raises
    ------
    InputError
        The draft cannot be created or the file written (disk full, no permission).
    """
    dest = Path(path)
    draft = dest.with_name(f".{dest.name}.{secrets.token_hex(8)}.sailroute-tmp")
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0)
    try:
        fd = os.open(draft, flags, 0o666)
    except OSError as exc:
        raise InputError(
            f"{option} {dest}: cannot create a file in {dest.absolute().parent} "
            f"({exc.strerror or exc}); choose another folder"
        ) from None
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline=newline) as fh:
            yield fh
        os.replace(draft, dest)
    except OSError as exc:
        raise InputError(
            f"{option} {dest}: cannot write the file ({exc.strerror or exc}); check the "
            "disk space and permissions"
        ) from None
    finally:
        draft.unlink(missing_ok=True)


# --- writing a set of files ---------------------------------------------------------------


def read_manifest(out_dir: str | Path) -> set[str]:
    """Relative paths (POSIX) of the files the last run wrote in ``out_dir``.

    A missing or unreadable manifest gives an empty set (then no file is deleted).
    Entries that are absolute or climb out of the folder (``..``) are ignored.
    """
    p = Path(out_dir) / MANIFEST_NAME
    try:
        doc = json.loads(p.read_text(encoding="utf-8"))
        names = doc["files"]
    except (OSError, ValueError, KeyError, TypeError):
        return set()
    if not isinstance(names, list):
        return set()
    return {n for n in names if isinstance(n, str) and _safe_relative(n)}


def _safe_relative(name: str) -> bool:
    pp = PurePosixPath(name)
    return bool(name) and not pp.is_absolute() and ".." not in pp.parts and "\\" not in name


def _write_manifest(folder: Path, names: set[str]) -> None:
    from sailroute._version import __version__

    tmp = folder / f"{MANIFEST_NAME}.{secrets.token_hex(4)}"
    tmp.write_text(
        json.dumps({"written_by": f"sailroute {__version__}", "files": sorted(names)}, indent=1)
        + "\n",
        encoding="utf-8",
    )
    os.replace(tmp, folder / MANIFEST_NAME)


def _files_under(folder: Path) -> set[str]:
    return {
        p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file() or p.is_symlink()
    }


@contextmanager
def _sigint_deferred() -> Iterator[None]:
    """Hold Ctrl-C while the files are moved into place (milliseconds), then raise it."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.getsignal(signal.SIGINT)
    if previous is None:  # installed outside Python: leave it alone
        yield
        return
    caught: list[int] = []
    signal.signal(signal.SIGINT, lambda signum, frame: caught.append(signum))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
    if caught:
        raise KeyboardInterrupt


def _linked_parent(out: Path, rel: str) -> Path | None:
    """The first folder between ``out`` and ``out/rel`` (exclusive) that is a symbolic
    link (or not a folder), or None when the path stays inside ``out``."""
    d = out
    for part in PurePosixPath(rel).parts[:-1]:
        d = d / part
        if d.is_symlink() or (d.exists() and not d.is_dir()):
            return d
    return None


def _prune_empty_dirs(out: Path, rel: str) -> None:
    """Remove the now-empty folders between ``out/rel`` and ``out`` (not ``out``)."""
    d = (out / rel).parent
    while d != out and out in d.parents:
        try:
            d.rmdir()
        except OSError:  # not empty (a user's file, another output) or gone
            return
        d = d.parent


def _commit(stage: Path, out: Path) -> None:
    """Move the staged files into ``out`` and delete the previous run's other files."""
    new = _files_under(stage)
    if not out.exists():
        _write_manifest(stage, new)
        try:
            stage.rename(out)
            return
        except OSError:
            if not out.is_dir():  # pragma: no cover - a file appeared at out meanwhile
                raise
            # a folder appeared at out meanwhile: merge into it as below
    old = read_manifest(out)
    for rel in sorted(new):
        link = _linked_parent(out, rel)
        if link is not None:
            raise InputError(
                f"--out: cannot write {rel!r} into {str(out)!r}: {str(link)!r} is a symbolic "
                "link or a file, and sailroute writes only inside the output folder; remove "
                "it or choose another folder with --out"
            )
    with _sigint_deferred():
        _write_manifest(out, old | new)  # everything that may be ours, until the swap is done
        for rel in sorted(new):
            dst = out / rel
            dst.parent.mkdir(parents=True, exist_ok=True)
            os.replace(stage / rel, dst)
        for rel in sorted(old - new):
            p = out / rel
            if _linked_parent(out, rel) is not None:  # may point anywhere: not ours
                continue
            if p.is_file() or p.is_symlink():
                p.unlink(missing_ok=True)
                _prune_empty_dirs(out, rel)
        _write_manifest(out, new)


def _relocate(obj: Any, stage: Path, out: Path) -> Any:
    """``obj`` (a path, or a mapping/list/tuple of paths) with ``stage`` replaced by ``out``."""
    if isinstance(obj, Path):
        try:
            return out / obj.relative_to(stage)
        except ValueError:
            return obj
    if isinstance(obj, Mapping):
        return {k: _relocate(v, stage, out) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return type(obj)(_relocate(v, stage, out) for v in obj)
    return obj


def write_output_set(out_dir: str | Path, write: Callable[[Path], T]) -> T:
    """Write one run's files into ``out_dir`` as a set: all of them or none.

    ``write(folder)`` writes every file of the run into ``folder``, a fresh staging
    folder (``.sailroute-tmp-*`` inside ``out_dir`` when it exists, else
    ``.<name>.sailroute-tmp-*`` next to it: on the same disk either way), and returns
    the paths written (a path, or a mapping, list or tuple of paths).  Only when it
    returns are the files moved into ``out_dir``, the previous run's files that this
    run did not write deleted (those listed in ``out_dir/.sailroute-manifest.json``,
    see the module docstring) and the manifest rewritten.  If ``write`` raises (or
    Ctrl-C interrupts it), the staging folder is removed and ``out_dir`` is left
    exactly as it was.

    Parameters
    ----------
    out_dir : str or Path
        The output folder (created with its parents if missing).
    write : callable
        ``write(folder) -> paths``.

    Returns
    -------
    object
        What ``write`` returned, with every path under the staging folder replaced by
        the same path under ``out_dir``.

    Raises
    ------
    InputError
        The folder cannot be created or written (message names the path and why).
    """
    out = Path(out_dir)
    check_out_dir(out)
    token = secrets.token_hex(4)
    try:
        if out.exists():
            stage = out / f"{STAGE_PREFIX}{token}"
        else:
            out.parent.mkdir(parents=True, exist_ok=True)
            stage = out.parent / f".{out.name}{STAGE_PREFIX}{token}"
        stage.mkdir()
    except OSError as exc:
        raise _cannot(out, exc.strerror or str(exc), "--out") from None
    try:
        result = write(stage)
        _commit(stage, out)
    except OSError as exc:
        raise InputError(
            f"--out: cannot write the output files into {str(out)!r} "
            f"({exc.strerror or exc}{': ' + str(exc.filename) if exc.filename else ''}); "
            "check the disk space and permissions, or choose another folder with --out"
        ) from None
    finally:
        shutil.rmtree(stage, ignore_errors=True)
    return _relocate(result, stage, out)
