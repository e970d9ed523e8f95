"""Terminal tables: durations, plan table rows and totals, comparison blocks."""

from __future__ import annotations

import pytest

from sailroute.planning.result import compare
from sailroute.report.tables import (
    comparison_table,
    format_duration,
    plan_table,
    render_table,
)


@pytest.mark.parametrize(
    ("s", "text"),
    [
        (0.0, "0:00.0"),
        (59.96, "1:00.0"),
        (984.0, "16:24.0"),
        (3071.97, "51:12.0"),
        (3600.0, "1:00:00.0"),
        (3822.35, "1:03:42.4"),
        (-61.57, "-1:01.6"),
        (float("nan"), "-"),
    ],
)
def test_format_duration(s, text):
    assert format_duration(s) == text


def test_render_table_alignment():
    out = render_table(["a", "bb"], [["x", "1"], ["yyy", "22"]], footer=[["t", "333"]])
    lines = out.splitlines()
    assert lines[0] == "a     bb"
    assert lines[2] == "x      1"
    assert lines[3] == "yyy   22"
    assert lines[4] == lines[1] == "---  ---"
    assert lines[5] == "t    333"


def test_plan_table(plan):
    out = plan_table(plan)
    lines = out.splitlines()
    assert lines[0].startswith("report test | scenario north | router test | boat ")
    assert " | start " in lines[0]
    header = lines[1].split()
    assert header[:9] == ["leg", "from", "->", "to", "mode", "time", "time", "s", "tacks"]
    assert header[-4:] == ["winner", "err", "model", "err"]
    rows = lines[3:6]
    assert rows[0].split()[:5] == ["1", "start", "->", "top", "upwind"]
    assert "25% along start" in rows[0]
    assert "70% along gate" in rows[2]
    r = plan.legs[0].result
    err = 100 * (r.time_s - 700.0) / 700.0
    assert f"{r.time_s:.1f}" in rows[0] and f"{err:+.1f}%" in rows[0]
    total = lines[-1]
    assert f"{plan.total_time_s:.1f}" in total
    assert f"{100 * (plan.total_time_s - 1100.0) / 1100.0:+.1f}%" in total
    assert total.split()[:1] == ["total"]


def test_comparison_table(plan):
    other = plan.__class__(plan.course, "copy", plan.legs, plan.references, plan.router)
    cmp = compare([plan, other])
    out = comparison_table(cmp)
    assert "report test: leg times" in out
    assert "error vs winner: model - winner, (model - winner)/winner" in out
    assert "error vs model" in out
    pc = cmp.total_percent("winner")[0]
    assert f"{pc:+.1f}%" in out
    # header of the first block: leg, both scenarios, both references
    first = out.splitlines()[1].split()
    assert first == ["leg", "north", "copy", "winner", "model"]
