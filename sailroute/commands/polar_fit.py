"""``sailroute polar fit``: learn a polar from a fleet's logs and tracks, write its files.

The samples come from :mod:`sailroute.analysis.learnsamples` (each in the wind ``analyze``
would judge it in), the steady blocks from :mod:`sailroute.boat.learn_blocks`, the polar
at levels with its uncertainty from :func:`sailroute.boat.learn.learn_polar`, the race
pace from :mod:`sailroute.analysis.racepace`; the table, plot and files are
:mod:`sailroute.report.polar`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Final

import numpy as np

from sailroute.analysis.fleetlearn import learn_fleet
from sailroute.analysis.learnsamples import FleetSamples
from sailroute.boat.boatfile import slug
from sailroute.boat.fit_samples import DEFAULT_TWS_STEP, PolarErrors, compare_polars
from sailroute.boat.learn import N_BOOT, LearnFit, parse_levels
from sailroute.boat.learn_blocks import SteadyRules
from sailroute.commands.result import CommandResult
from sailroute.commands.vpp import UNITS, parse_speed_list, twa_grid
from sailroute.errors import InputError
from sailroute.outdir import check_out_dir, write_output_set
from sailroute.report.files import POLAR_FILE_LABELS
from sailroute.report.polar import learned_report, write_learned_outputs
from sailroute.track.model import Track
from sailroute.units import speed_factor

if TYPE_CHECKING:
    from sailroute.progress import Progress


@dataclass(frozen=True)
class FitRun:
    """What :func:`run_fit_command` computed (its ``CommandResult.data``).

    Attributes
    ----------
    fit : LearnFit
        The learned polar and its blocks.
    samples : FleetSamples
        The samples, notes and leg times.
    errors : dict of str to PolarErrors
        Per level, the errors against ``--reference`` on the learned cells (empty
        without one).
    notes : tuple of str
        The samples' notes and the race pace's.
    """

    fit: LearnFit
    samples: FleetSamples
    errors: dict[str, PolarErrors]
    notes: tuple[str, ...] = ()


def parse_columns(text: str | None) -> dict[str, str] | None:
    """``"time=Time,bsp=BSP_kn"`` -> ``{"time": "Time", "bsp": "BSP_kn"}``."""
    if text is None or not text.strip():
        return None
    out: dict[str, str] = {}
    for k, item in enumerate(text.split(",")):
        key, sep, col = item.partition("=")
        if not sep or not key.strip() or not col.strip():
            raise InputError(
                f"--columns: item {k + 1} ({item!r}) is not NAME=HEADER; e.g. "
                "'time=Time,bsp=BoatSpeed_kn,tws=TWS,twa=TWA'"
            )
        out[key.strip().lower()] = col.strip()
    return out


FIT_OPTIONS: Final = {
    "percentile": "--percentile",
    "min_boats": "--min-boats",
    "min_blocks": "--min-blocks",
    "n_boot": "--bootstrap",
    "tws_bins_ms": "--tws-bins",
    "twa_bins_deg": "--twa-step",
}
"""The ``polar fit`` options that give :func:`~sailroute.boat.learn.learn_polar`'s
parameters (named in its messages)."""


def read_fleet(
    logs: Sequence[str | Path],
    columns: str | None = None,
    speed_unit: str | None = None,
    time_zone: str | None = None,
) -> list[Track]:
    """Read every log; names made unique (a repeated name gets its file's stem).

    Raises
    ------
    InputError
        No log, or a log given twice.
    """
    from sailroute.track.read import read_track

    if not logs:
        raise InputError("polar fit: no LOG given; give one or more logs or tracks")
    seen: set[Path] = set()
    out: list[Track] = []
    names: set[str] = set()
    for log in logs:
        p = Path(log).resolve()
        if p in seen:
            raise InputError(f"{log}: given twice; give each log once")
        seen.add(p)
        tr = read_track(
            log, columns=parse_columns(columns), speed_unit=speed_unit, time_zone=time_zone
        )
        name = tr.name or Path(log).stem
        if name in names:
            name = f"{name} ({Path(log).stem})" if Path(log).stem != name else f"{name} ({log})"
        names.add(name)
        out.append(Track(tr.t_s, tr.lat_deg, tr.lon_deg, name, tr.source, tr.channels, tr.notes))
    return out


def run_fit_command(
    logs: Sequence[str | Path] | str | Path,
    *,
    courses: Sequence[str | Path] = (),
    scenario: str | None = None,
    columns: str | None = None,
    speed_unit: str | None = None,
    time_zone: str | None = None,
    levels: str | None = None,
    percentile: float = 50.0,
    min_boats: int | None = None,
    min_blocks: int = 3,
    bootstrap: int = N_BOOT,
    seed: int = 0,
    tws_bins: str | None = None,
    twa_step_deg: float = 10.0,
    out_dir: str | Path = "polar-fit-out",
    unit: str = "kn",
    reference: str | Path | None = None,
    reference_unit: str | None = None,
    rules: SteadyRules | None = None,
    name: str | None = None,
    shape: str | None = None,
    progress: Progress | None = None,
) -> CommandResult:
    """Everything ``sailroute polar fit`` does, minus printing.

    Parameters
    ----------
    logs : path or sequence of path
        Instrument logs (CSV with wind columns) and/or GPS tracks (GPX/CSV; need
        ``courses``), one per boat and day.
    courses : sequence of path
        One course per race: each track's part of each race is learned in the wind
        ``analyze`` would judge it in, and the races' legs give the race pace.  Without
        courses every log is learned over its whole length in its own measured wind.
    scenario : str, optional
        Scenario of the courses (default each one's first).
    columns, speed_unit, time_zone : optional
        How to read the logs (:func:`sailroute.track.read.read_track`).
    levels : str, optional
        ``"median=50,top=90"`` (the default): level names and percentiles of the boats.
    percentile : float
        Percentile of a boat's own steady blocks in a cell (50: its typical speed).
    min_boats, min_blocks : int
        Boats and steady blocks a cell needs (default boats: 2, 1 for one log).
    bootstrap : int
        Bootstrap replicates of the uncertainty (0: none).
    seed : int
        Seed of the bootstrap.
    tws_bins : str, optional
        Comma-separated TWS nodes in ``unit``; default every 2 kn (1 m/s) over the data's
        1st-99th percentile.
    twa_step_deg : float
        TWA node spacing [°].
    out_dir : path
        Output folder (checked before the work; written as a set).
    unit : {"kn", "m/s"}
        Unit of the printed table and the written files.
    reference : path, optional
        Polar to compare with (per level: RMS and per-angle errors on the learned cells).
    reference_unit : str, optional
        Unit of the reference file's speeds and TWS.
    rules : SteadyRules, optional
        What counts as steady sailing.
    name : str, optional
        Stem of the output files and polar name (default ``<first log stem>-fleet``, or
        ``-fit`` for one log).
    shape : str, optional
        ``builtin:NAME`` or a polar file whose shape fills the cells the fleet did not
        sail (every requested row and column kept), scaled per point of sail to the
        learned cells.
    progress : Progress, optional
        Counts the boats while their samples are taken (``boat 3 of 12 done (NZL): ...``,
        :func:`~sailroute.analysis.fleetlearn.learn_fleet`); None: silent.  The results and
        the files are the same with or without it.
    """
    from sailroute.boat.io import read_polar
    from sailroute.course.load import load_course

    if unit not in UNITS:
        raise InputError(f"--unit: expected one of 'kn', 'm/s'; got {unit!r}")
    log_list = [logs] if isinstance(logs, (str, Path)) else list(logs)
    if scenario is not None and not courses:
        raise InputError("--scenario needs --course: the scenario's wind comes from a course file")
    lv = parse_levels(levels)
    check_out_dir(out_dir)
    ref = None
    if reference is not None:
        ref = read_polar(reference, speed_unit=reference_unit, wind_unit=reference_unit)
    shape_polar = None
    if shape is not None:
        from sailroute.commands.strategy import load_polar

        shape_polar = load_polar(shape)
    loaded = [load_course(c) for c in courses]
    race_names = [c.name for c in loaded]
    if len(set(race_names)) < len(race_names):
        raise InputError(
            "--course: two courses have the same name ("
            + ", ".join(sorted({n for n in race_names if race_names.count(n) > 1}))
            + "); give each race's course a name of its own"
        )
    tracks = read_fleet(log_list, columns, speed_unit, time_zone)
    first = Path(log_list[0]).stem
    stem = slug(name) if name else slug(first) + ("-fit" if len(log_list) == 1 else "-fleet")
    fit, samples, notes_t = learn_fleet(
        tracks,
        loaded,
        scenario,
        twa_bins_deg=np.asarray(twa_grid(twa_step_deg)),
        tws_bins_ms=(
            np.asarray(parse_speed_list(tws_bins, unit, option="--tws-bins"))
            if tws_bins is not None
            else None
        ),
        tws_step_ms=DEFAULT_TWS_STEP[unit] * speed_factor(unit),
        levels=lv,
        percentile=percentile,
        min_boats=min_boats,
        min_blocks=min_blocks,
        n_boot=bootstrap,
        seed=seed,
        rules=rules,
        name=stem,
        shape=shape_polar,
        options=FIT_OPTIONS,
        provenance={
            "logs": [str(p) for p in log_list],
            "courses": [str(c) for c in courses],
            "scenario": scenario,
            "shape": None if shape_polar is None else f"{shape} ({shape_polar.name})",
        },
        progress=progress,
    )
    notes = list(notes_t)
    errors = {}
    if ref is not None:
        for lname in fit.learned.levels:
            errors[lname] = compare_polars(
                fit.learned.polar(lname), fit.learned.status == "learned", ref
            )
    report = learned_report(fit, unit, errors, ref.name if ref is not None else "", notes)
    files = write_output_set(
        out_dir, lambda d: write_learned_outputs(fit, d, stem, unit, ref, errors, notes)
    )
    return CommandResult(
        report,
        files,
        data=FitRun(fit=fit, samples=samples, errors=errors, notes=tuple(notes)),
        main=("json",),
        labels=POLAR_FILE_LABELS,
    )
