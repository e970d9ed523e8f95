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


class _Clock:
    """A stand-in for time.perf_counter that moves only when told."""

    def __init__(self) -> None:
        self.now = 1000.0

    def __call__(self) -> float:
        return self.now


def test_counted_members_say_k_of_n_the_elapsed_time_and_the_time_left(monkeypatch):
    import sailroute.progress as progress_module

    clock = _Clock()
    monkeypatch.setattr(progress_module.time, "perf_counter", clock)
    s = io.StringIO()
    p = Progress(2, s)
    p.start_count(4, "member")
    p.start_item(1, "constant m2")  # the second of four members, its first leg
    p.start_leg(0, "start -> 1")
    clock.now += 30.0  # 30 s for a member and a half: 3/8 of the run
    p.end_leg(900.0, "1 tack")
    p.set_prefix("")
    clock.now += 10.0
    p.item_done(2, "constant m2")  # two of four in 40 s: 40 s left at this pace
    lines = s.getvalue().splitlines()
    assert lines[0] == "constant m2 (member 2 of 4): leg 1/2 start -> 1: routing..."
    assert lines[1] == (
        "constant m2 (member 2 of 4): leg 1/2 start -> 1: 900.0 s, 1 tack "
        "(computed in 30.0 s; 30 s elapsed, about 50 s left)"
    )
    assert lines[2] == "member 2 of 4 done (constant m2): 40 s elapsed, about 40 s left"


def test_members_routed_together_show_how_many_arrived(monkeypatch):
    import sailroute.progress as progress_module

    clock = _Clock()
    monkeypatch.setattr(progress_module.time, "perf_counter", clock)
    s = io.StringIO()
    p = Progress(5, s, live=True, min_interval_s=0.0)
    p.start_count(100, "member", together=True)
    p.start_leg(1, "1 -> gate4")  # the second of five legs
    clock.now += 12.0
    p.update(0.5, "37 of 100 members arrived")  # 1.5 of 5 legs done in 12 s
    assert "leg 2/5 1 -> gate4:  50% 37 of 100 members arrived" in s.getvalue()
    assert "12 s elapsed, about 28 s left" in s.getvalue()


def test_durations_read_as_people_say_them():
    from sailroute.progress import duration

    assert [duration(v) for v in (3.25, 42.4, 185.0, 3725.0)] == [
        "3.2 s",
        "42 s",
        "3 min 5 s",
        "1 h 02 min",
    ]
