"""Figures, JSON and text of tack strategies (matplotlib object API, no pyplot).

* :func:`plot_policy_map` -- tack/continue regions of an expected-time policy
  over the course, one panel per wind shift;
* :func:`plot_spaghetti` -- simulated tracks with P10/P30/P70/P90 bands of the
  lateral position;
* :func:`plot_leg_times` -- ECDF and histogram of leg times of several
  policies (optionally with the solver's ``w(s)`` curves and deadlines);
* :func:`plot_deadline_policy` -- the risk-aware policy at one budget over the
  plane around the mark (steering angle colour, switch region grey);
* :func:`plot_deadline_tracks` -- simulated tracks of a target-relative policy;
* :func:`write_json` -- a summary dict as indented JSON (non-finite numbers
  become ``null``).

matplotlib is imported inside the functions so that importing
``sailroute.strategy`` stays cheap.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sailroute.outdir import make_out_dir
from sailroute.routing.types import side_name
from sailroute.strategy.deadline import DeadlinePolicy, DeadlineSimulation
from sailroute.strategy.deadline_grid import _nearest_nodes
from sailroute.strategy.montecarlo import SimulationResult
from sailroute.strategy.sdp import TACKS, ExpectedTimePolicy
from sailroute.strategy.shiftmodel import ShiftModel
from sailroute.strategy.study import StrategyResult

_CONTINUE, _TACK, _NONE = 0, 1, 2
_POLICY_COLOURS = ("#9ecae1", "#fb6a4a", "#e0e0e0")


def _figure(width: float, height: float) -> Any:
    from matplotlib.figure import Figure

    return Figure(figsize=(width, height), layout="constrained")


def policy_classes(policy: ExpectedTimePolicy, theta_deg: float, tack: int) -> NDArray[np.int8]:
    """Decision class per (row, x): 0 continue on ``tack``, 1 tack, 2 no feasible segment."""
    _, ik, it = policy.state_index(0.0, tack, theta_deg)
    act = policy.action[:, ik, it, :].astype(np.int64)
    feasible = (act >= 0) & np.isfinite(policy.value_s[:-1, ik, it, :])
    seg_tack = policy.segments.tack[np.maximum(act, 0), it]
    cls = np.where(seg_tack == tack, _CONTINUE, _TACK)
    return np.where(feasible, cls, _NONE).astype(np.int8)


def plot_policy_map(
    policy: ExpectedTimePolicy,
    thetas_deg: Sequence[float] = (-10.0, 0.0, 10.0),
    tack: int = 1,
) -> Any:
    """Tack/continue regions over the course for a few wind shifts.

    Parameters
    ----------
    policy : ExpectedTimePolicy
    thetas_deg : sequence of float
        Shifts [°] (nearest bins), one panel each; positive = veer.
    tack : int
        Current tack of the boat: +1 starboard, -1 port.

    Returns
    -------
    matplotlib.figure.Figure
        Blue: keep sailing on ``tack``; red: tack now; grey: the mark cannot
        be reached for sure from there (lattice corners near the mark).
    """
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    g = policy.grid
    fig = _figure(3.2 * len(thetas_deg) + 0.6, 5.0)
    axes = fig.subplots(1, len(thetas_deg), sharey=True, squeeze=False)[0]
    cmap = ListedColormap(_POLICY_COLOURS)
    side = side_name(tack)
    for ax, th in zip(axes, thetas_deg, strict=True):
        cls = policy_classes(policy, th, tack)
        _, _, it = policy.state_index(0.0, tack, th)
        ax.imshow(
            cls,
            origin="lower",
            aspect="auto",
            cmap=cmap,
            vmin=-0.5,
            vmax=2.5,
            interpolation="nearest",
            extent=(
                -g.half_width_m - g.lateral_m / 2,
                g.half_width_m + g.lateral_m / 2,
                -g.row_m / 2,
                g.length_m - g.row_m / 2,
            ),
        )
        ax.plot([0.0], [g.length_m], marker="^", color="k", markersize=8)
        ax.set_title(f"shift {g.theta_deg[it]:+.0f}° on {side}")
        ax.set_xlabel("lateral position x [m] (right +)")
    axes[0].set_ylabel("distance up the course y [m]")
    fig.legend(
        handles=[
            Patch(color=_POLICY_COLOURS[0], label=f"continue on {side}"),
            Patch(color=_POLICY_COLOURS[1], label="tack"),
            Patch(color=_POLICY_COLOURS[2], label="mark not reachable for sure"),
        ],
        loc="outside lower center",
        ncols=3,
    )
    fig.suptitle(
        f"Expected-time policy ({policy.model.kind} shift), "
        f"tack penalty λ = {policy.tack_penalty_s:g} s"
    )
    return fig


def plot_spaghetti(
    sim: SimulationResult, n_tracks: int = 200, title: str = "Simulated tracks"
) -> Any:
    """Tracks of the first ``n_tracks`` runs with P10/P30/P70/P90 lateral bands."""
    fig = _figure(6.0, 6.5)
    ax = fig.subplots()
    y = sim.y_m
    k = min(n_tracks, sim.n_runs)
    for i in range(k):
        ax.plot(sim.x_m[i], y, color="#cb181d", lw=0.4, alpha=0.35)
    bands = sim.lateral_bands((10, 30, 50, 70, 90))
    styles = {10: ("k", "--"), 90: ("k", "--"), 30: ("k", "-"), 70: ("k", "-"), 50: ("b", ":")}
    for pct, row in zip((10, 30, 50, 70, 90), bands, strict=True):
        colour, ls = styles[pct]
        ax.plot(row, y, color=colour, ls=ls, lw=1.4, label=f"P{pct}")
    ax.plot([0.0], [y[-1]], marker="^", color="k", markersize=9)
    ax.set_xlabel("lateral position x [m] (right +)")
    ax.set_ylabel("distance up the course y [m]")
    ax.set_title(f"{title} ({k} of {sim.n_runs} runs)")
    ax.legend(loc="lower right", fontsize=8)
    return fig


def ecdf(times_s: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Empirical CDF: sorted finite times and ``F`` at them (failures count as ``> any``)."""
    t = np.asarray(times_s, dtype=float)
    fin = np.sort(t[np.isfinite(t)])
    return fin, np.arange(1, fin.size + 1) / max(t.size, 1)


def plot_leg_times(
    samples: Mapping[str, NDArray[np.float64]],
    deadlines_s: Sequence[float] = (),
    value_curves: Mapping[str, tuple[NDArray[np.float64], NDArray[np.float64]]] | None = None,
) -> Any:
    """ECDF (left) and histogram (right) of leg times of several policies.

    Parameters
    ----------
    samples : mapping of str to ndarray
        Policy label -> simulated leg times [s] (``inf`` = did not finish).
    deadlines_s : sequence of float
        Drawn as vertical lines.
    value_curves : mapping, optional
        Label -> ``(s, w(s))`` from a deadline solve, drawn dotted on the ECDF
        axes (``w`` bounds every policy's ECDF from above).
    """
    fig = _figure(11.0, 4.5)
    ax1, ax2 = fig.subplots(1, 2)
    fin_all = np.concatenate([np.asarray(v)[np.isfinite(v)] for v in samples.values()])
    lo, hi = np.percentile(fin_all, [0.5, 99.5]) if fin_all.size else (0.0, 1.0)
    bins = np.linspace(lo, hi, 50)
    for label, t in samples.items():
        xs, fs = ecdf(t)
        ax1.step(xs, fs, where="post", label=label)
        ax2.hist(np.clip(t[np.isfinite(t)], lo, hi), bins=bins, histtype="step", label=label)
    for label, (s, w) in (value_curves or {}).items():
        ax1.plot(s, w, ls=":", label=label)
    for d in deadlines_s:
        ax1.axvline(d, color="k", lw=0.8, ls="--")
        ax2.axvline(d, color="k", lw=0.8, ls="--")
    ax1.set_xlim(lo, hi)
    ax1.set_ylim(0, 1)
    ax1.set_xlabel("leg time T [s]")
    ax1.set_ylabel("P(T ≤ s)")
    ax1.set_title("ECDF of leg time")
    ax1.legend(fontsize=8, loc="lower right")
    ax2.set_xlabel("leg time T [s]")
    ax2.set_ylabel("runs")
    ax2.set_title("Histogram of leg time")
    return fig


def deadline_policy_image(
    policy: DeadlinePolicy, budget_s: float, tack: int, extent_m: float, n_px: int = 241
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Steering angle [°] (NaN where switching) and ``w`` over a square around the mark.

    The wind blows from ``+y`` (upwind is ``+y``); pixel ``(x, y)`` is a boat
    position relative to the mark.
    """
    g = policy.grid
    xs = np.linspace(-extent_m, extent_m, n_px)
    xx, yy = np.meshgrid(xs, xs)
    r = np.hypot(xx, yy)
    theta = np.mod(-np.arctan2(xx, -yy), 2 * math.pi)
    q = np.full(r.shape, TACKS.index(tack))
    node = _nearest_nodes(g, r.ravel(), theta.ravel(), q.ravel()).reshape(r.shape)
    k = int(np.clip(round(budget_s / g.ds_s), 0, g.n_s))
    u = np.degrees(policy.steering(np.full(node.shape, k), node)[0])
    w = policy.value(k, node).astype(float)
    u = np.where(policy.switches(k, node), np.nan, u)
    outside = (r > g.r_max_m) | (r <= g.target_radius_m)
    return np.where(outside, np.nan, u), np.where(r > g.r_max_m, np.nan, w)


def plot_deadline_policy(
    policy: DeadlinePolicy, budget_s: float, tack: int = 1, extent_m: float | None = None
) -> Any:
    """Risk-aware policy ``α`` and success probability ``w`` at one budget (wind from +y).

    Where ``w = 0`` the deadline cannot be met and a run follows the
    risk-neutral policy instead (dark grey).
    """
    from matplotlib.colors import ListedColormap

    g = policy.grid
    ext = g.r_max_m if extent_m is None else float(extent_m)
    u, w = deadline_policy_image(policy, budget_s, tack, ext)
    fig = _figure(11.0, 5.0)
    ax1, ax2 = fig.subplots(1, 2)
    box = (-ext, ext, -ext, ext)
    ax1.set_facecolor("#bdbdbd")
    im1 = ax1.imshow(u, origin="lower", extent=box, cmap="viridis", vmin=0, vmax=180)
    hopeless = np.where(w <= 0.0, 1.0, np.nan)
    ax1.imshow(
        hopeless, origin="lower", extent=box, cmap=ListedColormap(["#404040"]), vmin=0, vmax=1
    )
    fig.colorbar(
        im1,
        ax=ax1,
        label="steering angle off the wind u [°]\n(light grey: switch tack; dark: w = 0)",
    )
    im2 = ax2.imshow(w, origin="lower", extent=box, cmap="magma", vmin=0, vmax=1)
    fig.colorbar(im2, ax=ax2, label="P(reach the mark within the budget)")
    side = side_name(tack)
    for ax, title in ((ax1, f"policy on {side}"), (ax2, "success probability w")):
        ax.add_patch(_circle(g.target_radius_m))
        ax.set_xlabel("x from the mark [m]")
        ax.set_ylabel("y from the mark [m] (wind from +y)")
        ax.set_title(f"{title}, budget {budget_s:g} s")
    return fig


def _circle(radius: float) -> Any:
    from matplotlib.patches import Circle

    return Circle((0.0, 0.0), radius, fill=False, color="w", lw=1.2)


def plot_deadline_tracks(sims: Mapping[str, DeadlineSimulation], mark_radius_m: float) -> Any:
    """Simulated tracks (first runs) of target-relative policies, one panel each."""
    fig = _figure(5.0 * len(sims) + 0.5, 5.5)
    axes = fig.subplots(1, len(sims), squeeze=False)[0]
    for ax, (label, sim) in zip(axes, sims.items(), strict=True):
        for tr in sim.tracks_xy_m:
            ax.plot(tr[:, 0], tr[:, 1], lw=0.5, alpha=0.5)
        from matplotlib.patches import Circle

        ax.add_patch(Circle((0.0, 0.0), mark_radius_m, fill=False, color="k"))
        ax.set_aspect("equal")
        ax.set_title(label)
        ax.set_xlabel("x from the mark [m]")
        ax.set_ylabel("y from the mark [m] (initial wind from +y)")
    return fig


def save_figure(fig: Any, path: str | Path, dpi: int = 110) -> Path:
    """Write a figure to ``path`` (format from the suffix) and return the path."""
    p = Path(path)
    fig.savefig(p, dpi=dpi)
    return p


def _clean(obj: Any) -> Any:
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, np.floating):
        return _clean(float(obj))
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, Mapping):
        return {str(k): _clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_clean(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return [_clean(v) for v in obj.tolist()]
    return obj


def write_json(summary: Mapping[str, Any], path: str | Path) -> Path:
    """Write ``summary`` as indented JSON; NaN/inf become ``null``."""
    p = Path(path)
    p.write_text(json.dumps(_clean(summary), indent=2, allow_nan=False) + "\n", encoding="utf-8")
    return p


def write_strategy_outputs(
    result: StrategyResult, out_dir: str | Path, plots: bool = True
) -> dict[str, Path]:
    """Write ``summary.json`` and (unless ``plots=False``) the PNG figures into ``out_dir``.

    Returns
    -------
    dict of str to Path
        File stem (``summary``, ``policy_map``, ...) -> file written.
    """
    out = make_out_dir(out_dir)
    written = [write_json(result.summary, out / "summary.json")]
    if not plots:
        return {p.stem: p for p in written}
    pol = result.policy
    written.append(
        save_figure(plot_policy_map(pol, tack=result.settings.start_tack), out / "policy_map.png")
    )
    written.append(save_figure(plot_spaghetti(result.sim), out / "spaghetti.png"))
    samples = {"expected-time SDP (lattice, OU/chain wind)": result.sim.leg_time_s}
    curves = None
    study = result.deadline
    if study is not None:
        samples = {"risk-neutral μ*": study.sim_rn.leg_time_s}
        r0, th0, q0 = study.start
        curves = {
            "w(s): best possible P(T ≤ s)": (study.ra.s_s, study.ra.success_curve(r0, th0, q0))
        }
        for d, sim in study.sims_ra.items():
            samples[f"risk-aware α^{d:g}"] = sim.leg_time_s
    written.append(
        save_figure(
            plot_leg_times(samples, result.settings.deadlines_s, curves),
            out / "leg_times.png",
        )
    )
    if study is not None:
        d0 = float(result.settings.deadlines_s[0])
        written.append(
            save_figure(
                plot_deadline_policy(
                    study.ra,
                    d0,
                    result.settings.start_tack,
                    extent_m=result.settings.length_m * 1.1,
                ),
                out / "deadline_policy.png",
            )
        )
        tracks = {"risk-neutral μ*": study.sim_rn}
        tracks.update({f"risk-aware α^{d:g}": s for d, s in study.sims_ra.items()})
        written.append(
            save_figure(
                plot_deadline_tracks(tracks, result.settings.mark_radius_m),
                out / "deadline_tracks.png",
            )
        )
    return {p.stem: p for p in written}


def shift_model_text(model: ShiftModel) -> str:
    """The shift model in words with sensible precision (degrees and minutes), e.g.
    ``"oscillating (OU): sd 10.0°, time scale 10.0 min"``."""
    d = model.describe()
    if d["kind"] == "ou":
        tl = float(d["timescale_s"])
        text = f"oscillating (OU): sd {float(d['sigma_deg']):.1f}°, time scale " + (
            "infinite (frozen wind)" if math.isinf(tl) else f"{tl / 60:.1f} min"
        )
        mean = float(d["mean_deg"])
        return text + (f", mean {mean:+.1f}°" if mean else "")
    return (
        f"persistent (drift-diffusion): drift {60 * float(d['drift_deg_per_s']):+.2f}°/min, "
        f"diffusion {math.sqrt(60) * float(d['sigma_deg_per_sqrt_s']):.2f}°/√min"
    )


def format_report(result: StrategyResult) -> str:
    """Short human-readable summary of a study."""
    s = result.summary
    e = s["expected_time_policy"]
    mc = e["monte_carlo"]
    b = s["boat"]
    lines = [
        f"boat {b['polar']} at {b['tws_kn']:.1f} kn: upwind VMG {b['vmg_upwind_ms']:.3f} m/s "
        f"at TWA {b['vmg_twa_deg']:.1f}°",
        f"shift model: {shift_model_text(result.model)}",
    ]
    if s.get("fit") and result.model.kind == "ou":
        ou = s["fit"]["ou"]
        lines.append(
            f"fitted from {s['fit']['source']}: sigma {ou['sigma_deg']:.1f} ± "
            f"{ou['sigma_se_deg']:.1f}°, time scale {ou['timescale_s'] / 60:.1f} ± "
            f"{ou['timescale_se_s'] / 60:.1f} min"
        )
    elif s.get("fit"):
        dd = s["fit"]["drift_diffusion"]
        lines.append(
            f"fitted from {s['fit']['source']}: drift {60 * dd['drift_deg_per_s']:.2f} ± "
            f"{60 * dd['drift_se_deg_per_s']:.2f}°/min, diffusion "
            f"{math.sqrt(60) * dd['sigma_deg_per_sqrt_s']:.2f} ± "
            f"{math.sqrt(60) * dd['sigma_se_deg_per_sqrt_s']:.2f}°/√min"
        )
    diag = s["chain"]["diagnostics_at_stage_time"]
    sd_err = diag["stationary_sd_deg"] / diag["target_sd_deg"] - 1.0
    if math.isfinite(sd_err) and abs(sd_err) > 0.1:
        lines.append(
            f"note: the shift chain's sd is {diag['stationary_sd_deg']:.1f}° for a target of "
            f"{diag['target_sd_deg']:.1f}° ({100 * sd_err:+.0f} %): the 5° bins are too coarse "
            "or the ±45° range too narrow for this sigma"
        )
    pct = mc.get("percentiles_s", {})
    lines += [
        f"expected-time policy: solved in {e['solve_time_s']:.2f} s; "
        f"E[T] {e['expected_time_s']:.1f} s "
        f"(steady-wind one tack {e['steady_wind_one_tack_s']:.1f} s)",
        f"  Monte Carlo ({mc['n_runs']} runs): mean {mc.get('mean_s', math.nan):.1f} s "
        f"± {mc.get('se_mean_s', math.nan):.1f}, P10 {pct.get('10', math.nan):.1f}, "
        f"P50 {pct.get('50', math.nan):.1f}, P90 {pct.get('90', math.nan):.1f} s, "
        f"tacks {mc['tacks']['mean']:.2f} on average",
    ]
    d = s.get("deadline")
    if d:
        rn = d["risk_neutral"]["monte_carlo"]
        lines.append(
            f"deadline problem ({d['model']['sigma_deg_per_sqrt_s']:.3f}°/√s Brownian shift): "
            f"solved in {d['solve_time_s']['risk_aware']:.1f} s (+ "
            f"{d['solve_time_s']['risk_neutral']:.1f} s risk-neutral)"
        )
        for key, ra in d["risk_aware"].items():
            p_ra = ra["monte_carlo"]["p_within_deadline"][key]
            p_rn = rn["p_within_deadline"][key]
            lines.append(
                f"  deadline {key} s: P(T <= deadline) risk-neutral {100 * p_rn['p']:.1f}% -> "
                f"risk-aware {100 * p_ra['p']:.1f}% (± {100 * p_ra['se']:.1f}); means "
                f"{rn.get('mean_s', math.nan):.1f} -> "
                f"{ra['monte_carlo'].get('mean_s', math.nan):.1f} s"
            )
    return "\n".join(lines)
