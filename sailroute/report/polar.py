"""Polars on paper: the text table, the polar plot and the files of ``vpp`` and ``polar fit``.

matplotlib is imported inside the plotting functions so that importing this module
stays cheap.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sailroute.boat.fit_samples import PolarErrors
from sailroute.boat.io import write_pol, write_polar_csv, write_polar_json
from sailroute.boat.kinetics import STEADY, Kinetics
from sailroute.boat.laser import LaserParams
from sailroute.boat.learn import BAND_NAMES, LearnedPolar, LearnFit
from sailroute.boat.polar import Polar
from sailroute.outdir import make_out_dir
from sailroute.units import speed_factor

__all__ = [
    "draw_polar",
    "learned_report",
    "plot_learned",
    "plot_polar",
    "polar_report",
    "write_learned_outputs",
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


def _grid_text(learned: LearnedPolar, unit: str, cells: NDArray[np.str_], title: str) -> list[str]:
    """A TWA x TWS text grid of ``cells`` (strings, the table's shape)."""
    f = speed_factor(unit)
    w = 8
    label = f"TWA\\TWS [{unit}]"
    lines = [title, f"{label:>14}" + "".join(f"{v / f:>{w}.1f}" for v in learned.tws_ms)]
    for a, row in zip(learned.twa_deg, cells, strict=True):
        lines.append(f"{a:>14.1f}" + "".join(f"{c:>{w}}" for c in row))
    return lines


def learned_report(
    fit: LearnFit,
    unit: str = "kn",
    errors: Mapping[str, PolarErrors] | None = None,
    reference_name: str = "",
    notes: Sequence[str] = (),
) -> str:
    """Text report of a learned polar: each level's table and uncertainty, the cells
    (blocks/boats, refused ``r``, empty ``.``), the refused cells, the sanity verdict, the
    race pace, the samples and (with a reference) the errors per level."""
    lp = fit.learned
    pv = lp.provenance
    f = speed_factor(unit)
    bl = fit.blocks
    lines = [
        f"{lp.name}: learned from {len(pv.get('boats', []))} boat(s) in "
        f"{len(pv.get('races', []))} race(s); {bl.size} steady blocks "
        f"({bl.dur_s.sum() / 60:.0f} min) of {bl.n_samples} samples; a boat's speed in a cell: "
        f"P{pv.get('percentile', 50):g} of its blocks"
    ]
    lines += [f"wind: {k} ({v:.0f} s)" for k, v in dict(pv.get("wind_source_seconds", {})).items()]
    for name, t in lp.levels.items():
        lines += ["", f"level {name}: P{t.percentile:g} of the boats"]
        lines.append(polar_report(lp.polar(name), unit))
        pct = np.vectorize(lambda v: f"{100 * v:.1f}")(t.sd_log).astype(np.str_)
        lines += _grid_text(lp, unit, pct, "uncertainty (1 sd) [%]")
        if t.race_pace is not None:
            lines.append(
                f"race pace of {name}: "
                + ", ".join(f"{b} x{v:.3f}" for b, v in zip(BAND_NAMES, t.race_pace, strict=True))
            )
    mark = {"learned": "", "refused": "r"}
    counts = np.array(
        [
            [
                "." if st == "empty" else f"{nb}/{nbo}{mark[str(st)]}"
                for st, nb, nbo in zip(srow, brow, borow, strict=True)
            ]
            for srow, brow, borow in zip(lp.status, lp.blocks, lp.boats, strict=True)
        ],
        dtype=np.str_,
    )
    lines += [
        "",
        *_grid_text(
            lp,
            unit,
            counts,
            "steady blocks / boats per cell (r: refused, listed below; .: no data; both filled)",
        ),
    ]
    if lp.reasons:
        lines += ["", f"refused cells ({len(lp.reasons)}):"] + [f"  {r}" for r in lp.reasons]
    left = [
        *(f"TWS {v / f:g}" for v in pv.get("left_out_tws_ms", [])),
        *(f"TWA {v:g}" for v in pv.get("left_out_twa_deg", [])),
    ]
    if left:
        lines.append("left out (no learned cell): " + ", ".join(left))
    lines += ["", "verdict:"] + [f"  {v}" for v in lp.verdict]
    lines.append(
        f"samples: {bl.n_samples}; dropped: " + ", ".join(f"{k} {v}" for k, v in bl.dropped.items())
    )
    lines += [f"note: {n}" for n in notes]
    for name, e in (errors or {}).items():
        lines.append("")
        lines.append(
            f"{name} vs reference {reference_name}: RMS {e.rms_ms / f:.2f} {unit} "
            f"({e.rms_pct:.1f} %), mean {e.mean_ms / f:+.2f} {unit} ({e.mean_pct:+.1f} %) "
            f"over {e.n_cells} learned cells"
        )
        lines.append(f"{'TWA [deg]':>10}{'mean %':>9}{'RMS %':>8}{'cells':>7}")
        for a, m, r, n in zip(e.twa_deg, e.row_mean_pct, e.row_rms_pct, e.row_cells, strict=True):
            lines.append(f"{a:>10.1f}{m:>+9.1f}{r:>8.1f}{int(n):>7d}")
    return "\n".join(lines)


def plot_learned(
    fit: LearnFit, path: str | Path, unit: str = "kn", reference: Polar | None = None
) -> Path:
    """PNG: the levels' curves over the steady blocks (left) and the cells (right)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    f = speed_factor(unit)
    lp = fit.learned
    fig = Figure(figsize=(13, 6.5))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 2, 1, projection="polar")
    cmap = _colours(lp.tws_ms.size)
    bl = fit.blocks
    used = fit.cell >= 0
    edges = np.concatenate([[0.0], 0.5 * (lp.tws_ms[1:] + lp.tws_ms[:-1]), [np.inf]])
    col = np.clip(np.searchsorted(edges, bl.tws_ms, side="right") - 1, 0, lp.tws_ms.size - 1)
    a = np.radians(np.abs(bl.twa_deg))
    ax.scatter(a[~used], bl.speed_ms[~used] / f, s=4, c="0.8", label="outside the TWS bins")
    ax.scatter(a[used], bl.speed_ms[used] / f, s=6, alpha=0.6, c=[cmap[k] for k in col[used]])
    names = list(lp.levels)
    draw_polar(ax, lp.polar(names[0]), unit, colors=cmap)
    grid = np.linspace(0.0, 180.0, 361)
    for name in names[1:]:
        p = lp.polar(name)
        for j, tws in enumerate(lp.tws_ms):
            ax.plot(np.radians(grid), p.speed(tws, grid) / f, ls="--", lw=0.8, color=cmap[j])
    if reference is not None:
        for j, tws in enumerate(lp.tws_ms):
            ax.plot(np.radians(grid), reference.speed(tws, grid) / f, ls=":", lw=0.8, color=cmap[j])
    ax.set_title(
        f"{lp.name}: {names[0]} (solid)"
        + (f", {', '.join(names[1:])} (dashed)" if names[1:] else "")
        + (", reference (dotted)" if reference is not None else "")
        + f" [{unit}]",
        fontsize=9,
        pad=16,
    )
    ax2 = fig.add_subplot(1, 2, 2)
    code = np.where(lp.status == "learned", 2.0, np.where(lp.status == "refused", 1.0, np.nan))
    ax2.imshow(code, origin="lower", aspect="auto", cmap="RdYlGn", vmin=0.0, vmax=2.0)
    for (i, j), c in np.ndenumerate(lp.blocks):
        if lp.status[i, j] != "empty":
            ax2.text(j, i, f"{c}/{lp.boats[i, j]}", ha="center", va="center", fontsize=6)
    ax2.set_xticks(range(lp.tws_ms.size), [f"{v / f:.3g}" for v in lp.tws_ms], fontsize=7)
    ax2.set_yticks(range(lp.twa_deg.size), [f"{v:g}" for v in lp.twa_deg], fontsize=7)
    ax2.set_xlabel(f"TWS [{unit}]")
    ax2.set_ylabel("TWA [deg]")
    ax2.set_title(
        "steady blocks / boats per cell (green learned, red refused, white empty)", fontsize=9
    )
    fig.tight_layout()
    out = Path(path)
    fig.savefig(out, dpi=100, bbox_inches="tight")  # keeps the polar title in
    return out


def _colours(n: int) -> list[Any]:
    from matplotlib import colormaps

    cm = colormaps["viridis"]
    return [cm(k / max(n - 1, 1) * 0.9) for k in range(n)]


def write_learned_outputs(
    fit: LearnFit,
    out_dir: Path,
    stem: str,
    unit: str = "kn",
    reference: Polar | None = None,
    errors: Mapping[str, PolarErrors] | None = None,
    notes: Sequence[str] = (),
) -> dict[str, Path]:
    """Write ``<stem>.pol`` and ``.csv`` (the default level), ``.json`` (every level,
    its uncertainty, the cells, the verdict and the provenance) and ``.png``."""
    from sailroute.boat.learnfile import write_learned

    f = speed_factor(unit)
    lp = fit.learned
    extra: dict[str, Any] = {"notes": list(notes)}
    if errors:
        extra["reference"] = {
            name: {
                "rms": e.rms_ms / f,
                "mean": e.mean_ms / f,
                "rms_pct": e.rms_pct,
                "mean_pct": e.mean_pct,
                "twa_deg": e.twa_deg.tolist(),
                "row_mean_pct": e.row_mean_pct.tolist(),
                "row_rms_pct": e.row_rms_pct.tolist(),
            }
            for name, e in errors.items()
        }
    default = lp.polar(None)
    return {
        "pol": write_pol(default, out_dir / f"{stem}.pol", unit=unit),
        "csv": write_polar_csv(default, out_dir / f"{stem}.csv", unit=unit),
        "json": write_learned(lp, out_dir / f"{stem}.json", unit=unit, extra=extra),
        "png": plot_learned(fit, out_dir / f"{stem}.png", unit=unit, reference=reference),
    }
