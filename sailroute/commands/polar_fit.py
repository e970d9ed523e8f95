"""``sailroute polar fit``: read a log (and a course's wind), fit a polar, write its files.

The samples come from :mod:`sailroute.boat.fit_samples` (an instrument log) or
:func:`samples_from_course_wind` (a GPS track in a course scenario's wind); the fit
is :func:`sailroute.boat.fit.fit_polar`; the table, plot and files are
:mod:`sailroute.report.polar`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Final

import numpy as np

from sailroute.boat.boatfile import slug
from sailroute.boat.fit import FitFilters, PolarFit, fit_polar
from sailroute.boat.fit_samples import (
    DEFAULT_TWS_STEP,
    FitSamples,
    PolarErrors,
    auto_tws_bins,
    compare_polars,
    finite_channel,
    samples_from_log,
)
from sailroute.commands.result import CommandResult
from sailroute.commands.vpp import UNITS, parse_speed_list, twa_grid
from sailroute.errors import InputError
from sailroute.outdir import check_out_dir, write_output_set
from sailroute.report.files import POLAR_FILE_LABELS
from sailroute.report.polar import fit_report, write_fit_outputs
from sailroute.track.model import Track
from sailroute.units import speed_factor, wind_speed_direction, wrap180


@dataclass(frozen=True)
class FitRun:
    """What :func:`run_fit_command` computed (its ``CommandResult.data``)."""

    fit: PolarFit
    samples: FitSamples
    errors: PolarErrors | None = None


def samples_from_course_wind(
    track: Track, course_path: str | Path, scenario: str | None = None
) -> FitSamples:
    """Samples from a GPS track and a course scenario's wind.

    The scenario's wind field (uniform, stations, WRF, blended; built as for
    ``sailroute plan`` but over the track's extent) is sampled at every track
    point; ``TWA = wrap180(TWD - COG)``, ``TWS`` from the field, boat speed = SOG.
    SOG/COG come from the file if it has them, else from the positions
    (:func:`sailroute.track.kinematics.sog_cog`).  Points outside the wind's time
    span are left out (noted).  Leeway and current are ignored: TWA is relative to
    the course over ground.

    Raises
    ------
    InputError
        Unreadable course, unknown scenario, bad wind spec, or wind data that do
        not cover the track's area.
    """
    from sailroute.course.load import load_course
    from sailroute.track.kinematics import sog_cog, track_xy
    from sailroute.wind.build import build_wind_field

    course = load_course(course_path)
    names = list(course.scenarios)
    if not names:
        raise InputError(
            f"{course_path}: the course has no wind scenarios; add one under "
            "'scenarios:' to fit a GPS track"
        )
    name = names[0] if scenario is None else scenario
    if name not in course.scenarios:
        raise InputError(
            f"--scenario: the course {str(course_path)!r} has no scenario "
            f"{name!r}; its scenarios are: {', '.join(names)}"
        )
    frame = course.frame
    x, y = track_xy(track, frame)
    wind = build_wind_field(
        course.scenarios[name].wind,
        frame=frame,
        crop_bbox=(float(x.min()), float(x.max()), float(y.min()), float(y.max())),
    )
    notes: list[str] = []
    t = np.asarray(track.t_s, float)
    cov = wind.coverage
    inside = (t >= cov.t0) & (t <= cov.t1)
    if not inside.any():
        raise InputError(
            f"{track.source}: no track point lies in the time span of scenario {name!r} "
            f"({cov.describe()}); use a scenario whose wind covers the track's time"
        )
    if not inside.all():
        notes.append(f"{int((~inside).sum())} track points outside the wind's time span left out")
    ch = track.channels
    sog, cog = finite_channel(ch, "sog_ms"), finite_channel(ch, "cog_deg")
    source = "sog"
    if sog is None or cog is None:
        sog, cog = sog_cog(track, frame)
        source = "sog (from positions)"
    u, v = wind.sample(t[inside], x[inside], y[inside])
    tws, twd_local = wind_speed_direction(u, v)
    # local +y is rotated from true north by the meridian convergence
    twd = twd_local - frame.grid_north_deg(track.lat_deg[inside], track.lon_deg[inside])
    twa = wrap180(twd - cog[inside])
    return FitSamples(
        t_s=t[inside],
        tws_ms=tws,
        twa_deg=twa,
        bsp_ms=sog[inside],
        heading_deg=cog[inside],
        speed_source=source,
        wind_source=f"course {course_path}, scenario {name}",
        notes=tuple(notes),
    )


# --- fit, compare ----------------------------------------------------------------------


# --- report, plot, files -----------------------------------------------------------------


# --- the command -----------------------------------------------------------------------


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
    "min_count": "--min-count",
    "tws_bins_ms": "--tws-bins",
    "twa_bins_deg": "--twa-step",
}
"""The ``polar fit`` options that give :func:`~sailroute.boat.fit.fit_polar`'s parameters
(named in its messages)."""


def run_fit_command(
    log: str | Path,
    *,
    course: str | Path | None = None,
    scenario: str | None = None,
    columns: str | None = None,
    speed_unit: str | None = None,
    time_zone: str | None = None,
    percentile: float = 90.0,
    min_count: int = 5,
    tws_bins: str | None = None,
    twa_step_deg: float = 10.0,
    out_dir: str | Path = "polar-fit-out",
    unit: str = "kn",
    reference: str | Path | None = None,
    reference_unit: str | None = None,
    filters: FitFilters | None = None,
    name: str | None = None,
) -> CommandResult:
    """Everything ``sailroute polar fit`` does, minus printing.

    Parameters
    ----------
    log : path
        Instrument log (CSV) or GPS track (GPX/CSV; needs ``course``).
    course, scenario : optional
        Course file and scenario name whose wind gives TWS/TWA at the track
        points (default scenario: the course's first).
    columns : str, optional
        ``NAME=HEADER`` pairs for columns the reader does not recognise.
    speed_unit : str, optional
        Unit of unsuffixed speed columns of the log (``kn``, ``m/s``, ``km/h``, ``mph``).
    time_zone : str, optional
        Zone of naive log times (``UTC``, ``+02:00``, ``Europe/Tallinn``).
    percentile : float
        Envelope percentile (0, 100].
    min_count : int
        Samples a cell needs to count as covered.
    tws_bins : str, optional
        Comma-separated TWS nodes in ``unit``; default every 2 kn (1 m/s) over the
        data's 1st-99th percentile.
    twa_step_deg : float
        TWA node spacing [°] (0 to 180).
    out_dir : path
        Output folder (checked before the work; written as a set, see
        :mod:`sailroute.outdir`).
    unit : {"kn", "m/s"}
        Unit of the printed table and the written files.
    reference : path, optional
        Polar to compare with (RMS and per-angle errors in the report and JSON).
    reference_unit : str, optional
        Unit of the reference file's speeds and TWS (default: the reader's).
    filters : FitFilters, optional
        Filter thresholds.
    name : str, optional
        Stem of the output files and polar name (default ``<log stem>-fit``).
    """
    from sailroute.boat.io import read_polar
    from sailroute.track.read import read_track

    if unit not in UNITS:
        raise InputError(f"--unit: expected one of 'kn', 'm/s'; got {unit!r}")
    if scenario is not None and course is None:
        raise InputError("--scenario needs --course: the scenario's wind comes from a course file")
    check_out_dir(out_dir)
    ref = None
    if reference is not None:
        ref = read_polar(reference, speed_unit=reference_unit, wind_unit=reference_unit)
    track = read_track(
        log, columns=parse_columns(columns), speed_unit=speed_unit, time_zone=time_zone
    )
    samples = (
        samples_from_log(track)
        if course is None
        else samples_from_course_wind(track, course, scenario)
    )
    tws_n = (
        np.asarray(parse_speed_list(tws_bins, unit, option="--tws-bins"))
        if tws_bins is not None
        else auto_tws_bins(samples.tws_ms, DEFAULT_TWS_STEP[unit] * speed_factor(unit))
    )
    stem = slug(name) if name else slug(Path(log).stem) + "-fit"
    fit = fit_polar(
        samples.tws_ms,
        samples.twa_deg,
        samples.bsp_ms,
        samples.t_s,
        tws_bins_ms=tws_n,
        twa_bins_deg=twa_grid(twa_step_deg),
        heading_deg=samples.heading_deg,
        percentile=percentile,
        min_count=min_count,
        filters=filters,
        name=stem,
        options=FIT_OPTIONS,
    )
    errors = compare_polars(fit, ref) if ref is not None else None
    report = fit_report(fit, samples, unit, errors, ref.name if ref is not None else "")
    files = write_output_set(
        out_dir, lambda d: write_fit_outputs(fit, samples, d, stem, unit, ref, errors)
    )
    return CommandResult(
        report,
        files,
        data=FitRun(fit=fit, samples=samples, errors=errors),
        main=("json",),
        labels=POLAR_FILE_LABELS,
    )
