"""Progress reporter: line mode for pipes, in-place updates on a terminal, quiet mode."""

from __future__ import annotations

import io

from sailroute.progress import Progress


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


class _Tty(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_rich_bar_on_a_terminal_plain_lines_elsewhere():
    from sailroute.progress import RichProgress, make_progress

    assert type(make_progress(2, stream=io.StringIO())) is Progress
    assert type(make_progress(2, stream=_Tty(), enabled=False)) is Progress  # -q: no bar
    s = _Tty()
    p = make_progress(2, stream=s)
    assert isinstance(p, RichProgress)
    p.min_interval_s = 0.0
    with p:
        p.start_leg(0, "start -> 1")
        p.update(0.5, "front 120 points")
        p.warn("wind above the polar")
        p.end_leg(984.04, "1 tack")
    out = s.getvalue()
    assert 0 <= out.index("\x1b[?25l") < out.rindex("\x1b[?25h")  # cursor hidden, then back
    assert " 50%" in out and "front 120 points" in out and "━" in out  # the bar
    # the finished leg and the warning are ordinary lines, as in the plain display
    assert "leg 1/2 start -> 1: 984.0 s, 1 tack (computed in " in out
    assert "warning: wind above the polar" in out


def test_rich_tables_keep_every_cell_whole_on_a_narrow_terminal():
    import re

    from rich.console import Console

    from sailroute.report.tables import render_table, rich_tables

    headers, rows = ["leg", "from -> to", "time"], [["1", "start -> windward", "15:46.2"]]
    footer = [["", "total", "49:42.7"]]
    plain = render_table(headers, rows, footer=footer)
    assert plain.splitlines()[2] == "1    start -> windward  15:46.2"
    with rich_tables(Console(file=io.StringIO(), force_terminal=True, width=20)):
        drawn = render_table(headers, rows, footer=footer)
    text = re.sub(r"\x1b\[[0-9;]*m", "", drawn)
    assert "\x1b[1m" in drawn  # styled (bold header and total)
    # a 20-column terminal: still one line per row, nothing cut ("…") or wrapped
    assert text.splitlines()[2] == "1    start -> windward  15:46.2"
    assert "…" not in text and text.splitlines()[4].split() == ["total", "49:42.7"]
    assert render_table(headers, rows, footer=footer) == plain  # plain again outside
