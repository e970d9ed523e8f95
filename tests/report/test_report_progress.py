"""Progress reporter: line mode for pipes, in-place updates on a terminal, quiet mode."""

from __future__ import annotations

import io

from sailroute.report.progress import Progress


def test_line_mode_writes_start_and_end_only():
    s = io.StringIO()
    p = Progress(2, s)
    assert not p.live  # StringIO is not a TTY
    p.start_leg(0, "start -> 1")
    p.update(0.5, "front 120 points")
    p.end_leg(984.04, "1 tack")
    lines = s.getvalue().splitlines()
    assert lines[0] == "leg 1/2 start -> 1: routing..."
    assert lines[1].startswith("leg 1/2 start -> 1: 984.0 s, 1 tack (computed in ")
    assert len(lines) == 2


def test_live_mode_updates_in_place():
    s = io.StringIO()
    p = Progress(3, s, live=True, min_interval_s=0.0)
    p.start_leg(1, "1 -> gate")
    p.update(0.25)
    p(0.5, "front")  # usable as a callback
    p.end_leg(500.0)
    out = s.getvalue()
    assert out.count("\r") >= 3
    assert "leg 2/3 1 -> gate:  25%" in out and " 50% front" in out
    assert out.endswith("\n") and "leg 2/3 1 -> gate: 500.0 s" in out


def test_throttled_and_disabled():
    s = io.StringIO()
    p = Progress(1, s, live=True, min_interval_s=3600.0)
    p.start_leg(0, "a -> b")
    p.update(0.1)
    p.update(0.2)  # within the interval: dropped
    assert "10%" in s.getvalue() and "20%" not in s.getvalue()
    q = io.StringIO()
    d = Progress(1, q, enabled=False)
    d.start_leg(0, "a -> b")
    d.update(0.5)
    d.end_leg(1.0)
    assert q.getvalue() == ""
