"""What every matplotlib map ends with: the scale bar, the north arrow and placed labels.

:func:`finish_map` is called once a map's lines are drawn (land, course, routes): it puts
the scale bar and the north arrow in the emptiest corner, then the favoured start end,
the tack and gybe symbols, the leg numbers and the mark names where they overlap
nothing (:func:`sailroute.report.labels.place_labels`), with a leader line to their
point when they had to move.  The map must be in metres of the course frame, equal
aspect.  Gids: ``scale-bar``, ``north-arrow``, ``mark-name:<name>``, ``tacks``, ``gybes``
(one marker line each, a point per manoeuvre), ``legno:<n>``, ``favoured-end``,
``favoured-label``, ``leaders``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sailroute.report.labels import Label, best_box, place_labels

__all__ = ["MapItem", "finish_map", "nice_length"]

MAX_SEGMENTS = 4000
"""Route segments the placer looks at (longer routes are thinned evenly)."""
TACK_STYLE = {"marker": "^", "color": "crimson", "ms": 6.0}
GYBE_STYLE = {"marker": "s", "color": "royalblue", "ms": 5.0}
BADGE = {"boxstyle": "circle,pad=0.2", "fc": "white", "ec": "0.3", "lw": 0.6}
"""The circle round a leg number."""
FAVOURED_STYLE = {"marker": "*", "color": "#2ca02c", "ms": 15.0, "mec": "black", "mew": 0.6}


@dataclass(frozen=True)
class MapItem:
    """A thing to place: ``kind`` is ``tack``, ``gybe``, ``legno`` (``text`` the number),
    ``mark`` (``text`` the name) or ``favoured`` (``text`` its label); ``x``, ``y`` its
    true position [m]."""

    kind: str
    x: float
    y: float
    text: str = ""


def nice_length(limit: float) -> float:
    """The largest 1, 2 or 5 × 10^k not above ``limit`` (> 0)."""
    k = math.floor(math.log10(limit))
    for m in (5.0, 2.0, 1.0):
        if m * 10**k <= limit:
            return m * 10**k
    return 10.0**k  # pragma: no cover - limit >= 10**k always


def _px(ax: Any, xy: Any) -> NDArray:
    return np.asarray(ax.transData.transform(np.asarray(xy, float).reshape(-1, 2)))


def _segments(
    ax: Any, lines: Sequence[NDArray], shifts: Sequence[tuple[float, float]] = ()
) -> NDArray:
    """The lines' segments [px] (each line moved by its shift [px], if given)."""
    segs = []
    for k, ln in enumerate(lines):
        p = _px(ax, ln) + (np.asarray(shifts[k]) if k < len(shifts) else 0.0)
        p = p[np.all(np.isfinite(p), axis=1)]
        if len(p) >= 2:
            segs.append(np.column_stack([p[:-1], p[1:]]))
    if not segs:
        return np.zeros((0, 4))
    s = np.vstack(segs)
    step = max(1, math.ceil(len(s) / MAX_SEGMENTS))
    if step > 1:  # thin evenly: join every step-th point
        s = np.column_stack([s[:-step:step, :2], s[step::step, :2]])
    return s


def _text_size(fig: Any, text: str, size: float) -> tuple[float, float]:
    from matplotlib.font_manager import FontProperties

    r = fig.canvas.get_renderer()
    w, h, _ = r.get_text_width_height_descent(text, FontProperties(size=size), ismath=False)
    return w + 4.0, h + 4.0


def _furniture(fig: Any, ax: Any, segs: NDArray, fixed: NDArray, bounds: Any) -> NDArray:
    """The scale bar and north arrow in the emptiest corner; returns their box [px]."""
    px_per_pt = fig.dpi / 72.0
    (x0, _), (x1, _) = _px(ax, [[ax.get_xlim()[0], 0.0], [ax.get_xlim()[1], 0.0]])
    m_per_px = (ax.get_xlim()[1] - ax.get_xlim()[0]) / (x1 - x0)
    length = nice_length(70.0 * px_per_pt * m_per_px)
    bar_px = length / m_per_px
    label = f"{length / 1000:g} km" if length >= 1000 else f"{length:g} m"
    tw, th = _text_size(fig, label, 7)
    w = max(bar_px, tw) + 26.0 * px_per_pt
    h = max(th + 12.0 * px_per_pt, 30.0 * px_per_pt)
    b = bounds
    inset = 4.0
    corners = np.array(
        [
            (b[0] + inset + w / 2, b[1] + inset + h / 2),
            (b[2] - inset - w / 2, b[1] + inset + h / 2),
            (b[0] + inset + w / 2, b[3] - inset - h / 2),
            (b[2] - inset - w / 2, b[3] - inset - h / 2),
        ]
    )
    k = best_box(corners, np.arange(4) * 0.1, w, h, False, segs, fixed, bounds)
    cx, cy = corners[k]
    left, bottom, top = cx - w / 2 + 4.0, cy - h / 2 + 4.0, cy + h / 2 - 3.0
    inv = ax.transData.inverted()
    (bx0, by), (bx1, _), (tx, ty), (nx, n0), (_, n1), (_, nt) = inv.transform(
        [
            (left, bottom + 2 * px_per_pt),
            (left + bar_px, 0.0),
            (left + bar_px / 2, bottom + 4 * px_per_pt),
            (cx + w / 2 - 9.0 * px_per_pt, bottom),
            (0.0, top - 10.0 * px_per_pt),
            (0.0, top - 9.0 * px_per_pt),
        ]
    )
    half = 0.5 * (bx1 - bx0)
    ax.plot([bx0, bx1], [by, by], "-", color="black", lw=4.2, zorder=9.9, gid="scale-bar",
            solid_capstyle="butt")  # fmt: skip
    ax.plot([bx0 + half, bx1], [by, by], "-", color="white", lw=2.4, zorder=10,
            gid="scale-bar", solid_capstyle="butt")  # fmt: skip
    ax.text(tx, ty, label, ha="center", va="bottom", fontsize=7, zorder=10, gid="scale-bar")
    ax.annotate("", xy=(nx, n1), xytext=(nx, n0), zorder=10, gid="north-arrow",
                arrowprops={"arrowstyle": "-|>,head_width=0.3,head_length=0.6",
                            "color": "black", "lw": 1.2})  # fmt: skip
    ax.text(nx, nt, "N", ha="center", va="bottom", fontsize=8, fontweight="bold", zorder=10,
            gid="north-arrow")  # fmt: skip
    return np.array([[cx - w / 2, cy - h / 2, cx + w / 2, cy + h / 2]])


def finish_map(
    fig: Any,
    ax: Any,
    *,
    marks: Sequence[tuple[str, float, float]],
    routes: Sequence[NDArray],
    lines: Sequence[NDArray] = (),
    items: Sequence[MapItem] = (),
    mark_ms: float = 7.0,
    shifts_pt: Sequence[tuple[float, float]] = (),
) -> None:
    """Scale bar, north arrow and the placed items on a map (see the module docstring).

    Parameters
    ----------
    fig, ax : matplotlib Figure and Axes
        The map, its lines drawn, its extent and layout final.
    marks : sequence of (str, float, float)
        Name and position [m] of each mark (their names are placed; the mark symbols,
        ``mark_ms`` points wide, are not covered).
    routes : sequence of ndarray, shape (n, 2)
        Route lines [m] that names may not cover.
    lines : sequence of ndarray, shape (n, 2)
        More lines that names may not cover (start and finish lines, gates).
    items : sequence of MapItem
        Symbols and leg numbers; the mark names are added from ``marks``.
    mark_ms : float
        Size of the mark symbols [pt].
    shifts_pt : sequence of (float, float)
        Per route, where it is drawn on screen from its true place [pt] (a leg sailed
        again over the same water is drawn beside the first).
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.collections import LineCollection

    if not isinstance(fig.canvas, FigureCanvasAgg):
        FigureCanvasAgg(fig)
    ax.apply_aspect()
    px_per_pt = fig.dpi / 72.0
    bounds = [float(v) for v in np.asarray(ax.bbox.extents, float) + np.array([2, 2, -2, -2])]
    shifts = [(a * px_per_pt, b * px_per_pt) for a, b in shifts_pt]
    segs = _segments(ax, [*routes, *lines], shifts)
    route_segs = _segments(ax, routes, shifts)
    mr = 0.5 * mark_ms * px_per_pt + 1.0
    mp = _px(ax, [(x, y) for _, x, y in marks]) if marks else np.zeros((0, 2))
    fixed = np.column_stack([mp[:, 0] - mr, mp[:, 1] - mr, mp[:, 0] + mr, mp[:, 1] + mr])
    fixed = np.vstack([fixed, _furniture(fig, ax, route_segs, fixed, bounds)])

    order = {"favoured": 0, "tack": 1, "gybe": 1, "legno": 2}
    todo = sorted(items, key=lambda it: order.get(it.kind, 3))
    todo += [MapItem("mark", x, y, name) for name, x, y in marks]
    labels = []
    for it in todo:
        ((ax_, ay_),) = _px(ax, [(it.x, it.y)])
        if it.kind in ("tack", "gybe", "favoured"):
            style = {"tack": TACK_STYLE, "gybe": GYBE_STYLE}.get(it.kind, FAVOURED_STYLE)
            s = float(style["ms"]) * px_per_pt + 2.0  # type: ignore[arg-type]
            labels.append(Label(ax_, ay_, s, s, 0.0, on_route=it.kind != "favoured"))
        elif it.kind == "legno":
            d = 13.0 * px_per_pt
            labels.append(Label(ax_, ay_, d, d, 0.0, on_route=True))
        else:
            w, h = _text_size(fig, it.text, 8)
            labels.append(Label(ax_, ay_, w, h, mr + 1.0, on_route=False))
    placed = place_labels(labels, segs, fixed, bounds)
    # the favoured end's text goes beside its star, once the star is placed
    fav = [(it, p) for it, p in zip(todo, placed, strict=True) if it.kind == "favoured"]
    for it, p in fav:
        w, h = _text_size(fig, it.text, 7)
        taken = np.vstack(
            [
                fixed,
                [
                    [q.cx - lb.w / 2, q.cy - lb.h / 2, q.cx + lb.w / 2, q.cy + lb.h / 2]
                    for q, lb in zip(placed, labels, strict=True)
                ],
            ]
        )
        s = float(FAVOURED_STYLE["ms"]) * px_per_pt / 2  # type: ignore[arg-type]
        (q,) = place_labels([Label(p.cx, p.cy, w, h, s, False)], segs, taken, bounds)
        labels.append(Label(p.cx, p.cy, w, h))
        placed.append(q)
        todo.append(MapItem("favoured-label", it.x, it.y, it.text))

    inv = ax.transData.inverted()
    leaders = []
    tacks: list[tuple[float, float]] = []
    gybes: list[tuple[float, float]] = []
    for it, lab, p in zip(todo, labels, placed, strict=True):
        at_anchor = lab.gap <= 0 and (p.cx, p.cy) == (lab.x, lab.y)
        x, y = (it.x, it.y) if at_anchor else inv.transform((p.cx, p.cy))
        if p.leader:
            # from the true point to the box's edge
            dx, dy = lab.x - p.cx, lab.y - p.cy
            t = min(
                (lab.w / 2) / abs(dx) if dx else math.inf,
                (lab.h / 2) / abs(dy) if dy else math.inf,
                1.0,
            )
            leaders.append(inv.transform([(lab.x, lab.y), (p.cx + t * dx, p.cy + t * dy)]))
        if it.kind == "tack":
            tacks.append((x, y))
        elif it.kind == "gybe":
            gybes.append((x, y))
        elif it.kind == "favoured":
            ax.plot([x], [y], linestyle="none", zorder=8, gid="favoured-end",
                    label="favoured start end", **FAVOURED_STYLE)  # fmt: skip
        elif it.kind == "legno":
            ax.text(x, y, it.text, ha="center", va="center", fontsize=7, zorder=9,
                    gid=f"legno:{it.text}", bbox=BADGE)  # fmt: skip
        elif it.kind == "favoured-label":
            ax.text(x, y, it.text, ha="center", va="center", fontsize=7, color="#1b5e20",
                    zorder=9, gid="favoured-label")  # fmt: skip
        else:
            ax.text(x, y, it.text, ha="center", va="center", fontsize=8, zorder=9,
                    gid=f"mark-name:{it.text}")  # fmt: skip
    for pts, style, kind in ((tacks, TACK_STYLE, "tacks"), (gybes, GYBE_STYLE, "gybes")):
        n = sum(1 for it in items if it.kind == kind[:-1])
        ax.plot(
            [q[0] for q in pts],
            [q[1] for q in pts],
            linestyle="none",
            zorder=7,
            gid=kind,
            label=f"{kind} ({n})",
            **style,
        )
    if leaders:
        lc = LineCollection(leaders, colors="0.35", linewidths=0.6, zorder=6.5)
        lc.set_gid("leaders")
        ax.add_collection(lc, autolim=False)
