"""Polars on paper: the text table, the polar plot and the files of ``vpp`` and ``polar fit``.

matplotlib is imported inside the plotting functions so that importing this module
stays cheap.
"""

from __future__ import annotations

from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np

from sailroute.boat.fit import PolarFit
from sailroute.boat.fit_samples import FitSamples, PolarErrors
from sailroute.boat.io import write_pol, write_polar_csv, write_polar_json
from sailroute.boat.kinetics import STEADY, Kinetics
from sailroute.boat.laser import LaserParams
from sailroute.boat.polar import Polar
from sailroute.outdir import make_out_dir
from sailroute.units import speed_factor

__all__ = [
    "draw_polar",
    "fit_report",
    "plot_fit",
    "plot_polar",
    "polar_report",
    "write_fit_outputs",
    "write_vpp_outputs",
]


def polar_report(polar: Polar, unit: str = "kn") -> str:
    """Text table (rows TWA, columns TWS) and best VMG per TWS, in ``unit``.

    Speeds are printed with 2 decimals; the same numbers come from
    ``polar.speed(tws, twa)`` at the table's nodes.
    """
    f = speed_factor(unit)
    tws = polar.tws_ms
    label = f"TWA\\TWS [{unit}]"
    w = 7
    lines = [f"{polar.name}: boat speed [{unit}] (TWS at the sail's centre of effort)"]
    lines.append(f"{label:>14}" + "".join(f"{v / f:>{w}.1f}" for v in tws))
    for a, row in zip(polar.twa_deg, polar.speed_ms, strict=True):
        lines.append(f"{a:>14.1f}" + "".join(f"{v / f:>{w}.2f}" for v in row))
    up_a, up_v = polar.vmg_upwind(tws)
    dn_a, dn_v = polar.vmg_downwind(tws)
    lines.append("")
    lines.append(f"{'beat TWA [deg]':>14}" + "".join(f"{a:>{w}.1f}" for a in up_a))
    lines.append(f"{'beat VMG':>14}" + "".join(f"{v / f:>{w}.2f}" for v in up_v))
    lines.append(f"{'run TWA [deg]':>14}" + "".join(f"{a:>{w}.1f}" for a in dn_a))
    lines.append(f"{'run VMG':>14}" + "".join(f"{v / f:>{w}.2f}" for v in dn_v))
    return "\n".join(lines)


def plot_polar(polar: Polar, path: str | Path, unit: str = "kn") -> Path:
    """Polar plot (one curve per TWS, VMG points marked) as a PNG.

    Uses matplotlib's object-oriented API (no pyplot, no global state).
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(7, 7))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(projection="polar")
    draw_polar(ax, polar, unit)
    ax.set_title(f"{polar.name}: boat speed [{unit}] vs TWA (dots: best VMG)")
    out = Path(path)
    fig.savefig(out, dpi=110)
    return out


def draw_polar(ax: Any, polar: Polar, unit: str = "kn", colors: list[Any] | None = None) -> None:
    """Draw one curve per TWS column and the best-VMG points on a polar ``ax``.

    ``ax`` is a matplotlib polar axes (set to 0-180°, north up, clockwise);
    ``colors`` gives one colour per TWS column (default: matplotlib's cycle).
    """
    f = speed_factor(unit)
    ax.set_theta_zero_location("N")
    ax.set_theta_direction(-1)
    ax.set_thetamin(0)
    ax.set_thetamax(180)
    a = np.linspace(0.0, 180.0, 361)
    up_a = polar.vmg_upwind(polar.tws_ms)[0]
    dn_a = polar.vmg_downwind(polar.tws_ms)[0]
    for j, tws in enumerate(polar.tws_ms):
        kw = {} if colors is None else {"color": colors[j]}
        (line,) = ax.plot(
            np.radians(a), polar.speed(tws, a) / f, lw=1.2, label=f"{tws / f:g} {unit}", **kw
        )
        for ang in (up_a[j], dn_a[j]):
            ax.plot(np.radians(ang), polar.speed(tws, ang) / f, "o", ms=3, color=line.get_color())
    ax.legend(loc="lower left", fontsize=7, title="TWS", title_fontsize=7)


def write_vpp_outputs(
    polar: Polar,
    params: LaserParams,
    out_dir: str | Path,
    stem: str,
    unit: str = "kn",
    kinetics: Kinetics = STEADY,
) -> dict[str, Path]:
    """Write ``<stem>.pol``, ``.csv``, ``.json`` (with the parameters) and ``.png``."""
    d = make_out_dir(out_dir)
    extra: dict[str, Any] = {
        "tws_reference": "true wind at the sail's centre-of-effort height",
        "vpp_params": _jsonable(asdict(params)),
        "kinetics": "steady" if kinetics == STEADY else _jsonable(asdict(kinetics)),
    }
    return {
        "pol": write_pol(polar, d / f"{stem}.pol", unit=unit),
        "csv": write_polar_csv(polar, d / f"{stem}.csv", unit=unit),
        "json": write_polar_json(polar, d / f"{stem}.json", unit=unit, extra=extra),
        "png": plot_polar(polar, d / f"{stem}.png", unit=unit),
    }


def _jsonable(d: dict[str, Any]) -> dict[str, Any]:
    return {k: list(v) if isinstance(v, tuple) else v for k, v in d.items()}


def fit_report(
    fit: PolarFit,
    samples: FitSamples,
    unit: str = "kn",
    errors: PolarErrors | None = None,
    reference_name: str = "",
) -> str:
    """Text report: table, per-cell counts, coverage, filter counts, reference errors."""
    f = speed_factor(unit)
    p = fit.polar
    lines = [polar_report(p, unit), ""]
    w = 7
    lines.append(
        f"samples per cell (0 = filled from neighbours; covered needs the "
        f"{fit.percentile:g}th percentile of >= min_count samples)"
    )
    label = "TWA\\TWS"
    lines.append(f"{label:>14}" + "".join(f"{v / f:>{w}.1f}" for v in p.tws_ms))
    for a, row in zip(p.twa_deg, fit.counts, strict=True):
        lines.append(f"{a:>14.1f}" + "".join(f"{int(c):>{w}d}" for c in row))
    lines.append("")
    lines.append(f"boat speed: {samples.speed_source}; wind: {samples.wind_source}")
    for note in samples.notes:
        lines.append(f"note: {note}")
    lines.append(
        f"samples: {fit.n_samples}, used {fit.n_used}; dropped: "
        + ", ".join(f"{k} {v}" for k, v in fit.dropped.items())
    )
    lines.append(
        f"coverage: {fit.coverage * 100:.0f} % of {fit.covered.size} cells "
        f"({int(fit.covered.sum())} covered)"
    )
    if fit.empty_tws_ms.size:
        lines.append(
            "TWS columns without data (left out): "
            + ", ".join(f"{v / f:g}" for v in fit.empty_tws_ms)
        )
    if fit.empty_twa_deg.size:
        lines.append(
            "TWA rows without data (left out): " + ", ".join(f"{v:g}" for v in fit.empty_twa_deg)
        )
    if errors is not None:
        lines.append("")
        lines.append(
            f"vs reference {reference_name}: RMS {errors.rms_ms / f:.2f} {unit} "
            f"({errors.rms_pct:.1f} %), mean {errors.mean_ms / f:+.2f} {unit} "
            f"({errors.mean_pct:+.1f} %) over {errors.n_cells} covered cells"
        )
        lines.append(f"{'TWA [deg]':>10}{'mean %':>9}{'RMS %':>8}{'cells':>7}")
        for a, m, r, n in zip(
            errors.twa_deg, errors.row_mean_pct, errors.row_rms_pct, errors.row_cells, strict=True
        ):
            lines.append(f"{a:>10.1f}{m:>+9.1f}{r:>8.1f}{int(n):>7d}")
    return "\n".join(lines)


def plot_fit(
    fit: PolarFit, path: str | Path, unit: str = "kn", reference: Polar | None = None
) -> Path:
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
    ax.scatter(np.radians(fit.twa_deg[~used]), fit.bsp_ms[~used] / f, s=3, c="0.8", label="dropped")
    ax.scatter(
        np.radians(fit.twa_deg[used]),
        fit.bsp_ms[used] / f,
        s=4,
        alpha=0.5,
        c=[cmap[k] for k in col[used]],
    )
    draw_polar(ax, p, unit, colors=cmap)
    if reference is not None:
        a = np.linspace(0.0, 180.0, 361)
        for j, tws in enumerate(p.tws_ms):
            ax.plot(np.radians(a), reference.speed(tws, a) / f, ls="--", lw=0.8, color=cmap[j])
    ax.set_title(
        f"{p.name}: {fit.percentile:g}th percentile fit [{unit}]"
        + (" (dashed: reference)" if reference is not None else ""),
        fontsize=9,
        pad=16,
    )  # clear of the 0° label of the polar axes
    ax2 = fig.add_subplot(1, 2, 2)
    im = ax2.imshow(
        np.where(fit.counts > 0, fit.counts, np.nan), origin="lower", aspect="auto", cmap="viridis"
    )
    for (i, j), c in np.ndenumerate(fit.counts):
        ax2.text(
            j,
            i,
            str(int(c)),
            ha="center",
            va="center",
            fontsize=6,
            color="k" if fit.covered[i, j] else "r",
        )
    ax2.set_xticks(range(p.tws_ms.size), [f"{v / f:g}" for v in p.tws_ms], fontsize=7)
    ax2.set_yticks(range(p.twa_deg.size), [f"{v:g}" for v in p.twa_deg], fontsize=7)
    ax2.set_xlabel(f"TWS [{unit}]")
    ax2.set_ylabel("TWA [deg]")
    ax2.set_title(
        f"samples per cell (red: < min_count, filled); coverage {fit.coverage * 100:.0f} %",
        fontsize=9,
    )
    fig.colorbar(im, ax=ax2, shrink=0.8)
    fig.tight_layout()
    out = Path(path)
    fig.savefig(out, dpi=100, bbox_inches="tight")  # keeps the polar title in
    return out


def _colours(n: int) -> list[Any]:
    from matplotlib import colormaps

    cm = colormaps["viridis"]
    return [cm(k / max(n - 1, 1) * 0.9) for k in range(n)]


def write_fit_outputs(
    fit: PolarFit,
    samples: FitSamples,
    out_dir: Path,
    stem: str,
    unit: str = "kn",
    reference: Polar | None = None,
    errors: PolarErrors | None = None,
) -> dict[str, Path]:
    """Write ``<stem>.pol``, ``.csv``, ``.json`` (with counts, coverage, filters), ``.png``."""
    f = speed_factor(unit)
    extra: dict[str, Any] = {
        "fit": {
            "percentile": fit.percentile,
            "counts": fit.counts.tolist(),
            "raw_percentile": [
                [None if not np.isfinite(v) else float(v / f) for v in row] for row in fit.raw_ms
            ],
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
            "rms": errors.rms_ms / f,
            "mean": errors.mean_ms / f,
            "rms_pct": errors.rms_pct,
            "mean_pct": errors.mean_pct,
            "twa_deg": errors.twa_deg.tolist(),
            "row_mean_pct": errors.row_mean_pct.tolist(),
            "row_rms_pct": errors.row_rms_pct.tolist(),
        }
    return {
        "pol": write_pol(fit.polar, out_dir / f"{stem}.pol", unit=unit),
        "csv": write_polar_csv(fit.polar, out_dir / f"{stem}.csv", unit=unit),
        "json": write_polar_json(fit.polar, out_dir / f"{stem}.json", unit=unit, extra=extra),
        "png": plot_fit(fit, out_dir / f"{stem}.png", unit=unit, reference=reference),
    }
