"""Inputs and outputs of ``sailroute polar fit``: log samples, report, files, plot.

The CLI command only parses options and calls :func:`run_fit_command`; every
piece is a plain function here (see ``docs/polar-fit.md``).

Two kinds of input give the samples :func:`sailroute.boat.fit.fit_polar` needs:

* an **instrument log** (CSV read by :func:`sailroute.track.read.read_track`) with
  TWS and TWA (or TWD and a heading) and a boat speed: ``bsp`` if the log has
  it, else ``sog`` (the report says which);
* a **GPS track** (GPX or CSV) plus a course file and one of its wind scenarios:
  the scenario's wind is sampled at the track points, and TWA comes from the COG,
  TWS from the wind, boat speed = SOG (from the positions if the file has none).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Final

import numpy as np
from numpy.typing import NDArray

from sailroute.boat.fit import FitFilters, PolarFit, fit_polar, twa_sign_from
from sailroute.boat.io import write_pol, write_polar_csv, write_polar_json
from sailroute.boat.polar import Polar
from sailroute.boat.vpp_outputs import UNITS, _slug, draw_polar, parse_speed_list, polar_report
from sailroute.errors import InputError
from sailroute.outdir import check_out_dir, write_output_set
from sailroute.track.model import Track
from sailroute.units import speed_factor, wind_speed_direction, wrap180

DEFAULT_TWS_STEP: Final = {"kn": 2.0, "m/s": 1.0}
"""Spacing of the automatic TWS columns per display unit."""


@dataclass(frozen=True, eq=False)
class FitSamples:
    """Per-sample arrays for :func:`~sailroute.boat.fit.fit_polar` (SI units).

    Attributes
    ----------
    t_s : ndarray
        Time [epoch s].
    tws_ms, twa_deg, bsp_ms : ndarray
        True wind speed [m s⁻¹], signed TWA [°], boat speed [m s⁻¹].
    heading_deg : ndarray or None
        Heading or COG [°] for the turn-rate filter.
    speed_source : str
        ``"bsp"``, ``"sog"`` or ``"sog (from positions)"``.
    wind_source : str
        ``"log"`` or ``"course <file>, scenario <name>"``.
    notes : tuple of str
        What was derived or dropped on the way.
    """

    t_s: NDArray[np.float64]
    tws_ms: NDArray[np.float64]
    twa_deg: NDArray[np.float64]
    bsp_ms: NDArray[np.float64]
    heading_deg: NDArray[np.float64] | None
    speed_source: str
    wind_source: str
    notes: tuple[str, ...] = ()


@dataclass(frozen=True, eq=False)
class PolarErrors:
    """Fitted polar vs a reference polar on the covered cells.

    Attributes
    ----------
    rms_ms, mean_ms : float
        RMS and mean of ``fitted - reference`` [m s⁻¹].
    rms_pct, mean_pct : float
        The same relative to the reference [%].
    twa_deg : ndarray
        TWA rows that have covered cells [°].
    row_mean_pct, row_rms_pct : ndarray
        Mean and RMS relative error per row [%].
    row_cells : ndarray of int
        Covered cells per row.
    n_cells : int
        Covered cells compared.
    """

    rms_ms: float
    mean_ms: float
    rms_pct: float
    mean_pct: float
    twa_deg: NDArray[np.float64]
    row_mean_pct: NDArray[np.float64]
    row_rms_pct: NDArray[np.float64]
    row_cells: NDArray[np.int64]
    n_cells: int


@dataclass(frozen=True)
class FitRun:
    """Result of :func:`run_fit_command`: the fit, the report text and the files."""

    fit: PolarFit
    samples: FitSamples
    report: str
    files: dict[str, Path]
    errors: PolarErrors | None = None
    extra: dict[str, Any] = field(default_factory=dict)


# --- samples ------------------------------------------------------------------------


def samples_from_log(track: Track) -> FitSamples:
    """Samples from an instrument log: its TWS, TWA and boat speed channels.

    TWA is taken signed from the log; a log that stores only ``|TWA|`` gets its
    sign from ``wrap180(TWD - heading)`` (heading, else COG) when it has those.
    A log with TWD and a heading but no TWA gets ``TWA = wrap180(TWD - heading)``.
    Boat speed is ``bsp`` if the log has it, else ``sog``.

    Raises
    ------
    InputError
        No TWS, no TWA (nor TWD with a heading/COG), or no boat speed.
    """
    ch = track.channels
    src = track.source or track.name
    notes: list[str] = []
    heading = _finite_channel(ch, "hdg_deg")
    hname = "hdg"
    if heading is None:
        heading, hname = _finite_channel(ch, "cog_deg"), "cog"
    tws = _finite_channel(ch, "tws_ms")
    if tws is None:
        raise InputError(
            f"{src}: no true wind speed column (tws); an instrument log needs tws, twa and "
            "bsp or sog (map other headers with --columns tws=...,twa=...), or fit a GPS track "
            "against a course's wind with --course COURSE --scenario NAME"
        )
    twa = _finite_channel(ch, "twa_deg")
    twd = _finite_channel(ch, "twd_deg")
    if twa is None:
        if twd is None or heading is None:
            raise InputError(
                f"{src}: no true wind angle column (twa), nor twd with hdg or cog to derive "
                "it; map the column with --columns twa=HEADER"
            )
        twa = wrap180(twd - heading)
        notes.append(f"TWA from TWD - {hname}")
    elif np.nanmin(twa) >= 0 and twd is not None and heading is not None:
        twa = twa_sign_from(twd, heading, twa)
        notes.append(f"TWA is unsigned in the log; tack (sign) from TWD - {hname}")
    elif np.nanmin(twa) >= 0:
        notes.append("TWA is unsigned and the log has no TWD/heading: tacks and gybes are "
                     "found by the turn-rate rule only")
    bsp = _finite_channel(ch, "bsp_ms")
    source = "bsp"
    if bsp is None:
        bsp, source = _finite_channel(ch, "sog_ms"), "sog"
    if bsp is None:
        raise InputError(f"{src}: no boat speed column (bsp, or sog); map it with "
                         "--columns bsp=HEADER")
    return FitSamples(t_s=np.asarray(track.t_s, float), tws_ms=tws, twa_deg=twa, bsp_ms=bsp,
                      heading_deg=heading, speed_source=source, wind_source="log",
                      notes=tuple(notes))


def samples_from_course_wind(track: Track, course_path: str | Path,
                             scenario: str | None = None) -> FitSamples:
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
    from sailroute.wind.build import wind_from_spec

    course = load_course(course_path)
    names = list(course.scenarios)
    if not names:
        raise InputError(f"{course_path}: the course has no wind scenarios; add one under "
                         "'scenarios:' to fit a GPS track")
    name = names[0] if scenario is None else scenario
    if name not in course.scenarios:
        raise InputError(f"--scenario: the course {str(course_path)!r} has no scenario "
                         f"{name!r}; its scenarios are: {', '.join(names)}")
    frame = course.frame
    x, y = track_xy(track, frame)
    sc = course.scenarios[name]
    wind = wind_from_spec(
        dict(sc.wind), frame=frame, base_dir=course.base_dir,
        where=sc.where or course.where(f"scenarios.{name}"),
        crop_bbox=(float(x.min()), float(x.max()), float(y.min()), float(y.max())),
        lines=course.key_lines,
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
        notes.append(f"{int((~inside).sum())} track points outside the wind's time span "
                     "left out")
    ch = track.channels
    sog, cog = _finite_channel(ch, "sog_ms"), _finite_channel(ch, "cog_deg")
    source = "sog"
    if sog is None or cog is None:
        sog, cog = sog_cog(track, frame)
        source = "sog (from positions)"
    u, v = wind.sample(t[inside], x[inside], y[inside])
    tws, twd_local = wind_speed_direction(u, v)
    # local +y is rotated from true north by the meridian convergence
    twd = twd_local - frame.grid_north_deg(track.lat_deg[inside], track.lon_deg[inside])
    twa = wrap180(twd - cog[inside])
    return FitSamples(t_s=t[inside], tws_ms=tws, twa_deg=twa, bsp_ms=sog[inside],
                      heading_deg=cog[inside], speed_source=source,
                      wind_source=f"course {course_path}, scenario {name}", notes=tuple(notes))


def _finite_channel(ch: Any, key: str) -> NDArray[np.float64] | None:
    a = ch.get(key)
    if a is None:
        return None
    a = np.asarray(a, float)
    return a if np.isfinite(a).any() else None


# --- fit, compare ----------------------------------------------------------------------


def auto_tws_bins(tws_ms: NDArray, step_ms: float) -> NDArray[np.float64]:
    """TWS nodes every ``step_ms`` [m s⁻¹] spanning the 1st-99th percentile of the data."""
    finite = tws_ms[np.isfinite(tws_ms)]
    if finite.size == 0:
        raise InputError("the log has no finite TWS value; check the tws column and its unit")
    lo, hi = np.percentile(finite, [1.0, 99.0])
    first = max(step_ms, np.round(lo / step_ms) * step_ms)
    last = max(first, np.round(hi / step_ms) * step_ms)
    return np.arange(first, last + 0.5 * step_ms, step_ms)


def compare_polars(fit: PolarFit, reference: Polar) -> PolarErrors:
    """Errors of the fitted polar against ``reference`` on the fit's covered cells.

    The fitted speed of each covered cell (``fit.polar.speed_ms``) is compared
    with ``reference.speed`` at the cell's node (TWS, TWA).  Only cells inside
    the reference's own table (its first to last TWA row and TWS column) count:
    outside it the reference is a taper or a clamp, not a measurement.
    """
    p = fit.polar
    ref = reference.speed(p.tws_ms[None, :], p.twa_deg[:, None])
    inside = ((p.twa_deg[:, None] >= reference.twa_deg[0])
              & (p.twa_deg[:, None] <= reference.twa_deg[-1])
              & (p.tws_ms[None, :] >= reference.tws_ms[0])
              & (p.tws_ms[None, :] <= reference.tws_ms[-1]))
    cov = fit.covered & inside
    if not cov.any():
        raise InputError(
            f"reference polar {reference.name!r} covers TWA {reference.twa_deg[0]:g}-"
            f"{reference.twa_deg[-1]:g} deg, TWS {reference.tws_ms[0]:.3g}-"
            f"{reference.tws_ms[-1]:.3g} m/s: no covered cell of the fit lies inside; "
            "check the reference's units (--reference-unit)"
        )
    d = (p.speed_ms - ref)[cov]
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.where(ref > 0, p.speed_ms / ref - 1.0, np.nan) * 100.0
    rows = np.flatnonzero(cov.any(axis=1))
    row_mean = np.array([np.nanmean(rel[i, cov[i]]) for i in rows])
    row_rms = np.array([np.sqrt(np.nanmean(rel[i, cov[i]] ** 2)) for i in rows])
    r = rel[cov]
    return PolarErrors(
        rms_ms=float(np.sqrt(np.mean(d**2))), mean_ms=float(np.mean(d)),
        rms_pct=float(np.sqrt(np.nanmean(r**2))), mean_pct=float(np.nanmean(r)),
        twa_deg=p.twa_deg[rows], row_mean_pct=row_mean, row_rms_pct=row_rms,
        row_cells=cov[rows].sum(axis=1).astype(np.int64), n_cells=int(cov.sum()),
    )


# --- report, plot, files -----------------------------------------------------------------


def fit_report(fit: PolarFit, samples: FitSamples, unit: str = "kn",
               errors: PolarErrors | None = None, reference_name: str = "") -> str:
    """Text report: table, per-cell counts, coverage, filter counts, reference errors."""
    f = speed_factor(unit)
    p = fit.polar
    lines = [polar_report(p, unit), ""]
    w = 7
    lines.append(f"samples per cell (0 = filled from neighbours; covered needs the "
                 f"{fit.percentile:g}th percentile of >= min_count samples)")
    label = "TWA\\TWS"
    lines.append(f"{label:>14}" + "".join(f"{v / f:>{w}.1f}" for v in p.tws_ms))
    for a, row in zip(p.twa_deg, fit.counts, strict=True):
        lines.append(f"{a:>14.1f}" + "".join(f"{int(c):>{w}d}" for c in row))
    lines.append("")
    lines.append(f"boat speed: {samples.speed_source}; wind: {samples.wind_source}")
    for note in samples.notes:
        lines.append(f"note: {note}")
    lines.append(f"samples: {fit.n_samples}, used {fit.n_used}; dropped: "
                 + ", ".join(f"{k} {v}" for k, v in fit.dropped.items()))
    lines.append(f"coverage: {fit.coverage * 100:.0f} % of {fit.covered.size} cells "
                 f"({int(fit.covered.sum())} covered)")
    if fit.empty_tws_ms.size:
        lines.append("TWS columns without data (left out): "
                     + ", ".join(f"{v / f:g}" for v in fit.empty_tws_ms))
    if fit.empty_twa_deg.size:
        lines.append("TWA rows without data (left out): "
                     + ", ".join(f"{v:g}" for v in fit.empty_twa_deg))
    if errors is not None:
        lines.append("")
        lines.append(f"vs reference {reference_name}: RMS {errors.rms_ms / f:.2f} {unit} "
                     f"({errors.rms_pct:.1f} %), mean {errors.mean_ms / f:+.2f} {unit} "
                     f"({errors.mean_pct:+.1f} %) over {errors.n_cells} covered cells")
        lines.append(f"{'TWA [deg]':>10}{'mean %':>9}{'RMS %':>8}{'cells':>7}")
        for a, m, r, n in zip(errors.twa_deg, errors.row_mean_pct, errors.row_rms_pct,
                              errors.row_cells, strict=True):
            lines.append(f"{a:>10.1f}{m:>+9.1f}{r:>8.1f}{int(n):>7d}")
    return "\n".join(lines)


def plot_fit(fit: PolarFit, path: str | Path, unit: str = "kn",
             reference: Polar | None = None) -> Path:
    """PNG: fitted curves over the data scatter (left) and per-cell counts (right)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    f = speed_factor(unit)
    p = fit.polar
    fig = Figure(figsize=(13, 6.5))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 2, 1, projection="polar")
    used = fit.used
    edges = np.concatenate([[0.0], 0.5 * (p.tws_ms[1:] + p.tws_ms[:-1]), [np.inf]])
    col = np.clip(np.searchsorted(edges, fit.tws_ms, side="right") - 1, 0, p.tws_ms.size - 1)
    cmap = _colours(p.tws_ms.size)
    ax.scatter(np.radians(fit.twa_deg[~used]), fit.bsp_ms[~used] / f, s=3, c="0.8",
               label="dropped")
    ax.scatter(np.radians(fit.twa_deg[used]), fit.bsp_ms[used] / f, s=4, alpha=0.5,
               c=[cmap[k] for k in col[used]])
    draw_polar(ax, p, unit, colors=cmap)
    if reference is not None:
        a = np.linspace(0.0, 180.0, 361)
        for j, tws in enumerate(p.tws_ms):
            ax.plot(np.radians(a), reference.speed(tws, a) / f, ls="--", lw=0.8,
                    color=cmap[j])
    ax.set_title(f"{p.name}: {fit.percentile:g}th percentile fit [{unit}]"
                 + (" (dashed: reference)" if reference is not None else ""), fontsize=9,
                 pad=16)  # clear of the 0° label of the polar axes
    ax2 = fig.add_subplot(1, 2, 2)
    im = ax2.imshow(np.where(fit.counts > 0, fit.counts, np.nan), origin="lower",
                    aspect="auto", cmap="viridis")
    for (i, j), c in np.ndenumerate(fit.counts):
        ax2.text(j, i, str(int(c)), ha="center", va="center", fontsize=6,
                 color="k" if fit.covered[i, j] else "r")
    ax2.set_xticks(range(p.tws_ms.size), [f"{v / f:g}" for v in p.tws_ms], fontsize=7)
    ax2.set_yticks(range(p.twa_deg.size), [f"{v:g}" for v in p.twa_deg], fontsize=7)
    ax2.set_xlabel(f"TWS [{unit}]")
    ax2.set_ylabel("TWA [deg]")
    ax2.set_title(f"samples per cell (red: < min_count, filled); coverage "
                  f"{fit.coverage * 100:.0f} %", fontsize=9)
    fig.colorbar(im, ax=ax2, shrink=0.8)
    fig.tight_layout()
    out = Path(path)
    fig.savefig(out, dpi=100, bbox_inches="tight")  # keeps the polar title in
    return out


def _colours(n: int) -> list[Any]:
    from matplotlib import colormaps

    cm = colormaps["viridis"]
    return [cm(k / max(n - 1, 1) * 0.9) for k in range(n)]


def write_fit_outputs(fit: PolarFit, samples: FitSamples, out_dir: Path, stem: str,
                      unit: str = "kn", reference: Polar | None = None,
                      errors: PolarErrors | None = None) -> dict[str, Path]:
    """Write ``<stem>.pol``, ``.csv``, ``.json`` (with counts, coverage, filters), ``.png``."""
    f = speed_factor(unit)
    extra: dict[str, Any] = {
        "fit": {
            "percentile": fit.percentile,
            "counts": fit.counts.tolist(),
            "raw_percentile": [[None if not np.isfinite(v) else float(v / f) for v in row]
                               for row in fit.raw_ms],
            "covered": fit.covered.tolist(),
            "coverage": fit.coverage,
            "dropped": dict(fit.dropped),
            "samples": fit.n_samples,
            "used": fit.n_used,
            "speed_source": samples.speed_source,
            "wind_source": samples.wind_source,
            "notes": list(samples.notes),
        }
    }
    if errors is not None:
        extra["fit"]["reference"] = {
            "rms": errors.rms_ms / f, "mean": errors.mean_ms / f,
            "rms_pct": errors.rms_pct, "mean_pct": errors.mean_pct,
            "twa_deg": errors.twa_deg.tolist(), "row_mean_pct": errors.row_mean_pct.tolist(),
            "row_rms_pct": errors.row_rms_pct.tolist(),
        }
    return {
        "pol": write_pol(fit.polar, out_dir / f"{stem}.pol", unit=unit),
        "csv": write_polar_csv(fit.polar, out_dir / f"{stem}.csv", unit=unit),
        "json": write_polar_json(fit.polar, out_dir / f"{stem}.json", unit=unit, extra=extra),
        "png": plot_fit(fit, out_dir / f"{stem}.png", unit=unit, reference=reference),
    }


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


FIT_OPTIONS: Final = {"percentile": "--percentile", "min_count": "--min-count",
                      "tws_bins_ms": "--tws-bins", "twa_bins_deg": "--twa-step"}
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
) -> FitRun:
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
    from sailroute.boat.vpp_outputs import twa_grid
    from sailroute.track.read import read_track

    if unit not in UNITS:
        raise InputError(f"--unit: expected one of 'kn', 'm/s'; got {unit!r}")
    if scenario is not None and course is None:
        raise InputError("--scenario needs --course: the scenario's wind comes from a course "
                         "file")
    check_out_dir(out_dir)
    ref = None
    if reference is not None:
        ref = read_polar(reference, speed_unit=reference_unit, wind_unit=reference_unit)
    track = read_track(log, columns=parse_columns(columns), speed_unit=speed_unit,
                       time_zone=time_zone)
    samples = (samples_from_log(track) if course is None
               else samples_from_course_wind(track, course, scenario))
    tws_n = (np.asarray(parse_speed_list(tws_bins, unit, option="--tws-bins"))
             if tws_bins is not None else auto_tws_bins(samples.tws_ms, DEFAULT_TWS_STEP[unit]
                                                         * speed_factor(unit)))
    stem = _slug(name) if name else _slug(Path(log).stem) + "-fit"
    fit = fit_polar(samples.tws_ms, samples.twa_deg, samples.bsp_ms, samples.t_s,
                    tws_bins_ms=tws_n, twa_bins_deg=twa_grid(twa_step_deg),
                    heading_deg=samples.heading_deg, percentile=percentile,
                    min_count=min_count, filters=filters, name=stem, options=FIT_OPTIONS)
    errors = compare_polars(fit, ref) if ref is not None else None
    report = fit_report(fit, samples, unit, errors, ref.name if ref is not None else "")
    files = write_output_set(
        out_dir, lambda d: write_fit_outputs(fit, samples, d, stem, unit, ref, errors))
    return FitRun(fit=fit, samples=samples, report=report, files=files, errors=errors)
