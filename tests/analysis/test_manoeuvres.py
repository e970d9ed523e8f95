"""Sailed tacks and gybes: a wobble across dead downwind is not a gybe, a real gybe is."""

from __future__ import annotations

import numpy as np

from sailroute.analysis.manoeuvres import MIN_TURN_DEG, find_sailed_manoeuvres


def _run(cog_deg: np.ndarray) -> tuple:
    t = np.arange(cog_deg.size, dtype=float)
    return find_sailed_manoeuvres(t, np.zeros_like(t), cog_deg, np.full(t.size, 2.0))[0]


def test_wobble_across_dead_downwind_is_not_a_gybe() -> None:
    # wind from 0°: dead downwind is COG 180°; the course swings ±8° across it every 12 s
    # (each side held 6 s > hold_s), so the side flips 20 times but the boat never gybes
    t = np.arange(240.0)
    cog = 180.0 + 8.0 * np.sign(np.sin(2 * np.pi * t / 24.0) + 1e-9)
    assert _run(cog) == ()


def test_a_gybe_and_a_tack_are_found() -> None:
    gybe = np.r_[np.full(60, 160.0), np.full(60, 200.0)]  # TWA -160 -> +160: 40° turn
    (m,) = _run(gybe)
    assert m.kind == "gybe" and m.index == 60
    tack = np.r_[np.full(60, 45.0), np.full(60, 315.0)]  # 90° turn through the wind
    (m,) = _run(tack)
    assert m.kind == "tack" and m.index == 60
    # a change of side with a turn just under the threshold is not counted
    small = np.r_[
        np.full(60, 180.0 - MIN_TURN_DEG / 2 + 1), np.full(60, 180.0 + MIN_TURN_DEG / 2 - 1)
    ]
    assert _run(small) == ()
