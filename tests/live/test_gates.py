"""The reading gate: bounds, distance, jumps and the feed's clock."""

from __future__ import annotations

import math

import pytest

from sailroute.course.geometry import course_gap_m
from sailroute.live.decode import Reading
from sailroute.live.gates import CONFIRM, GateLimits, ReadingGate
from sailroute.units import KNOT
from tests.live.feed import trieste


@pytest.fixture
def gate() -> ReadingGate:
    course = trieste()
    frame = course.frame

    def to_xy(lat: float, lon: float) -> tuple[float, float]:
        x, y = frame.to_xy(lat, lon)
        return float(x), float(y)

    return ReadingGate(
        GateLimits.for_polar(28.0 * KNOT), to_xy, lambda x, y: course_gap_m(course, (x, y))
    )


LAT, LON, T0 = 45.566, 13.674, 1518688000.0


def test_bounds(gate: ReadingGate) -> None:
    """Speeds a boat does not sail and winds above the polar's top plus 10 kn are held
    out; 37 kn of wind (the top is 28 kn) and 69 kn of boat speed pass."""
    assert gate.check(Reading(T0, LAT, LON, sog_ms=2.0, timed=True)) == ""
    assert gate.check(Reading(T0 + 1, LAT, LON, sog_ms=5e29, timed=True)) == "bounds"
    assert gate.check(Reading(T0 + 1, sog_ms=69.0 * KNOT)) == ""
    assert gate.check(Reading(T0 + 1, stw_ms=-0.5)) == "bounds"
    assert gate.check(Reading(T0 + 1, tws_ms=80.0 * KNOT, twd_deg=70.0)) == "bounds"
    assert gate.last["bounds"].startswith("a wind speed of 80 kn (tws_ms; at most 38 kn")
    assert gate.check(Reading(T0 + 1, aws_ms=120.0 * KNOT, awa_deg=30.0)) == "bounds"
    assert gate.check(Reading(T0 + 1, twd_deg=math.nan)) == "bounds"
    assert gate.counts["bounds"] == 5 and gate.last["bounds"] == "twd_deg is not a finite number"
    fresh = ReadingGate(gate.limits, gate._to_xy, gate._gap_m)
    assert fresh.check(Reading(T0, tws_ms=37.0 * KNOT, twd_deg=70.0)) == ""


def test_far_from_the_course(gate: ReadingGate) -> None:
    """A fix 30 km from the marks is held out (20 km is the reach); its time still
    moves the clock (the fix's time is the feed's)."""
    assert gate.check(Reading(T0, LAT + 0.27, LON, timed=True)) == "far"
    assert gate.clock == T0 and "km from the course area" in gate.last["far"]
    assert gate.check(Reading(T0 + 1, LAT + 0.1, LON, timed=True)) == ""  # 11 km: in reach


def test_position_jumps_are_held_out_until_they_persist(gate: ReadingGate) -> None:
    """A fix 1 km from the last one a second later (1944 kn) is held out; the same place
    five times in a row is where the boat is (a GPS that found itself)."""
    assert gate.check(Reading(T0, LAT, LON, timed=True)) == ""
    far = LAT + 1000.0 / 111_195.0
    got = [gate.check(Reading(T0 + k, far, LON, timed=True)) for k in range(1, CONFIRM + 1)]
    assert got == ["jump"] * (CONFIRM - 1) + [""]
    assert gate.counts["jump"] == CONFIRM - 1 and gate.counts["jump_accepted"] == 1
    # each vessel has its own last fix: another boat far away is no jump
    assert gate.check(Reading(T0 + 6, LAT, LON, vessel="urn:mrn:imo:mmsi:211000001")) == ""
    # 30 m in one second at 2 m/s is GPS error, not a jump
    assert gate.check(Reading(T0 + 7, far + 30 / 111_195.0, LON, timed=True)) == ""


def test_wind_speed_jumps(gate: ReadingGate) -> None:
    """15 m/s of TWS after ten readings of 2.5 m/s is held out, 6 m/s is not (a jump is
    more than max(5 m/s, the speed itself) from the recent median)."""
    for k in range(10):
        assert gate.check(Reading(T0 + k, tws_ms=2.5, twd_deg=65.0)) == ""
    assert gate.check(Reading(T0 + 10, tws_ms=15.0, twd_deg=65.0)) == "jump"
    assert gate.check(Reading(T0 + 11, tws_ms=6.0, twd_deg=65.0)) == ""


def test_another_clock_is_never_adopted_from_one_fix(gate: ReadingGate) -> None:
    """A fix dated 2030 among 2018 fixes is held out and the clock stays; five fixes in a
    row that agree on another time move the clock (it was the clock that was wrong)."""
    assert gate.check(Reading(T0, LAT, LON, timed=True)) == ""
    y2030 = 1900000000.0
    assert gate.check(Reading(y2030, LAT, LON, timed=True)) == "time"
    assert gate.clock == T0
    assert gate.check(Reading(T0 + 1, LAT, LON, timed=True)) == "" and gate.clock == T0 + 1
    # a run of the other clock interrupted by the right one never reaches CONFIRM
    for k in range(3):
        assert gate.check(Reading(y2030 + k, LAT, LON, timed=True)) == "time"
    assert gate.check(Reading(T0 + 2, LAT, LON, timed=True)) == ""
    got = [gate.check(Reading(y2030 + 10 + k, LAT, LON, timed=True)) for k in range(CONFIRM)]
    assert got == ["time"] * (CONFIRM - 1) + [""] and gate.clock == y2030 + 10 + CONFIRM - 1
    assert gate.counts["time"] == 1 + 3 + CONFIRM - 1 and gate.counts["clock_reset"] == 1
    # another vessel's report from another clock is held out, and never moves the clock
    assert gate.check(Reading(T0, LAT, LON, timed=True, vessel="x")) == "time"
