"""Figures and JSON for tack strategies (matplotlib object API, no pyplot).

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

from sailroute.routing.types import side_name
from sailroute.strategy.deadline import DeadlinePolicy, DeadlineSimulation
from sailroute.strategy.deadline_grid import _nearest_nodes
from sailroute.strategy.montecarlo import SimulationResult
from sailroute.strategy.sdp import TACKS, ExpectedTimePolicy

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
    lo, hi = (np.percentile(fin_all, [0.5, 99.5]) if fin_all.size else (0.0, 1.0))
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
    ax1.imshow(hopeless, origin="lower", extent=box, cmap=ListedColormap(["#404040"]),
               vmin=0, vmax=1)
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
