"""The messy-fleet generator (``tests/fleetgen.py``) against its own truth.

The truth must hold before it can judge ``analyze``: every time, distance and fault it
states is checked here on the tracks it wrote, with :mod:`sailroute.analysis.segment`'s
own crossing tests where a crossing is meant, and the boats' headings and speeds against
the class polar in the true wind at each boat's own time.
"""

from __future__ import annotations

import dataclasses
import math
import time
from datetime import timedelta

import numpy as np
import pytest

from sailroute.analysis.segment import LegIssue, find_start, segment_track
from sailroute.boat.polar import Polar
from sailroute.course.geometry import leg_endpoints, target_of
from sailroute.course.load import load_course
from sailroute.errors import InputError
from sailroute.routing.api import route_leg
from sailroute.routing.geometry import chain_leg
from sailroute.routing.settings import RoutingSettings
from sailroute.routing.types import Start
from sailroute.timeutil import iso
from sailroute.track.read import read_track
from sailroute.units import KNOT, bearing_deg, wrap180
from sailroute.wind.base import WindField
from tests.conftest import TESTS_DATA
from tests.fleetgen import (
    GUN,
    OTHER_CLASS_AFTER_S,
    OTHER_CLASS_SKILL,
    STATUSES,
    TACK_CLASSES,
    BoatTruth,
    FaultPlan,
    Fleet,
    FleetWind,
    Sailing,
    bank_waypoint,
    messy_fleet,
    offset_polar,
    shared_fleet,
)

CLEAN = FaultPlan.clean()
MINUTE = timedelta(seconds=60.0)


@pytest.fixture(scope="module")
def fleet() -> Fleet:
    """The default faults and clock lag (7 s) on 24 boats of 30 min (40 of 45 min: slow)."""
    return shared_fleet(0, n_boats=24, minutes=30)


@pytest.fixture(scope="module")
def quiet(fleet: Fleet) -> Fleet:
    """The same fleet recorded without GPS error."""
    return fleet.resampled(noise=False)


@pytest.fixture(scope="module")
def clean() -> Fleet:
    """Ten boats, no fault, no GPS error, no clock lag."""
    return messy_fleet(1, n_boats=10, minutes=25, faults=CLEAN, clock_lag_s=0.0)


@pytest.fixture(scope="module")
def recall() -> Fleet:
    """A general recall, boats of three other fleets, SOG/COG written."""
    plan = FaultPlan(general_recall=True, other_fleet=("class", "area", "day"), sog_cog=True)
    return messy_fleet(2, n_boats=20, minutes=20, faults=plan)


def xy(f: Fleet, name: str) -> tuple[np.ndarray, np.ndarray]:
    tr = f.track(name)
    return f.course.frame.to_xy(tr.lat_deg, tr.lon_deg)


def true_times(f: Fleet, name: str) -> np.ndarray:
    """The track's fix times on the true clock."""
    return f.track(name).t_s + f.clock_lag_s


def side_at_gun(f: Fleet, name: str) -> float:
    """Signed distance of the track from the start line at the gun [m] (+ over)."""
    x, y = xy(f, name)
    t = true_times(f, name)
    return float(line_side(f, np.interp(f.gun, t, x), np.interp(f.gun, t, y)))


def line_side(f: Fleet, x, y) -> np.ndarray:
    """Signed distance from the start line [m], + towards mark 1."""
    pin, com, top = f.marks["start_pin"], f.marks["start_boat"], f.marks["1"]
    ex, ey = com[0] - pin[0], com[1] - pin[1]
    n = math.hypot(ex, ey)
    nx, ny = -ey / n, ex / n
    if (top[0] - pin[0]) * nx + (top[1] - pin[1]) * ny < 0:
        nx, ny = -nx, -ny
    return (np.asarray(x) - pin[0]) * nx + (np.asarray(y) - pin[1]) * ny


# --- the course, the wind, the draw ------------------------------------------------------


def test_fleet_has_every_fault_of_the_plan(fleet: Fleet) -> None:
    plan = fleet.plan
    count = {s: len(fleet.with_status(s)) for s in STATUSES}
    assert count["non_starter"] == plan.non_starters
    assert count["ocs_returned"] == plan.ocs_returned
    assert count["ocs_not_returned"] == plan.ocs_not_returned
    assert count["late"] == plan.late
    assert count["retired"] == plan.retired + plan.data_ends
    assert count["two_races"] == plan.two_races
    assert count["duplicate_of"] == plan.duplicates
    assert count["gate_outside"] == plan.gate_outside
    assert count["other_fleet"] == len(plan.other_fleet)
    assert len(fleet.with_fault("data_gap")) == plan.data_gaps
    assert len(fleet.boats) == 24 + plan.duplicates + len(plan.other_fleet)
    names = [tr.name for tr in fleet.tracks]
    assert len(set(names)) == len(names) and names == [b.name for b in fleet.boats]
    assert max(b.skill for b in fleet.boats if b.status != "other_fleet") == 1.0
    assert len(fleet.clean) == 24 - plan.per_boat  # the best boat among them


def test_course_is_a_windward_leeward_with_a_gate(fleet: Fleet) -> None:
    c = fleet.course
    assert [leg.to_name for leg in c.legs] == ["1", "4", "1", "finish"]
    assert [leg.kind for leg in c.legs] == ["mark", "gate", "mark", "line"]
    assert set(c.gates) == {"4"} and set(c.lines) == {"start", "finish"}
    assert c.start_epoch == fleet.gun == GUN
    assert [fleet.point_of_sail(i) for i in range(4)] == ["upwind", "downwind"] * 2
    # mark 1 lies up the wind axis from the start line's centre
    s = np.mean([fleet.marks["start_pin"], fleet.marks["start_boat"]], axis=0)
    m = fleet.marks["1"]
    axis = float(bearing_deg(m[0] - s[0], m[1] - s[1]))
    assert abs(float(wrap180(axis - fleet.wind.twd_deg))) < 1.0


def test_wind_is_the_stated_formula() -> None:
    w = FleetWind(GUN, 200.0, 5.0, 200.0, osc_amp_deg=6.0, osc_period_s=400.0, shift_deg=10.0,
                  shift_start_s=600.0, shift_over_s=1000.0, tws_amp=0.1, tws_period_s=800.0,
                  pressure_left=0.1)  # fmt: skip
    assert isinstance(w, WindField)
    assert float(w.direction(GUN)) == pytest.approx(200.0)
    assert float(w.direction(GUN + 100.0)) == pytest.approx(206.0)  # a quarter period
    # after the persistent shift: 10° veered, the oscillation over a period averages out
    t = GUN + 2000.0 + np.arange(400.0)
    assert float(np.mean(w.direction(t))) == pytest.approx(210.0, abs=0.05)
    assert float(w.speed(GUN + 400.0)) == pytest.approx(5.0)  # half a period
    left = (-1000.0 * math.cos(math.radians(200.0)), 1000.0 * math.sin(math.radians(200.0)))
    assert float(w.speed(GUN + 400.0, *left)) == pytest.approx(5.5)  # 1 km left: 10 % more
    u, v = w.sample(GUN, 0.0, 0.0)  # from 200°: the air moves towards 20°
    assert float(bearing_deg(u, v)) == pytest.approx(20.0) and math.hypot(u, v) == pytest.approx(
        5.0
    )
    d = w.dilated(GUN, 0.9)
    np.testing.assert_allclose(
        d.sample(GUN + 900.0, 10.0, 20.0), w.sample(GUN + 1000.0, 10.0, 20.0)
    )


def test_too_many_faults_for_the_fleet_is_refused() -> None:
    with pytest.raises(ValueError, match=r"faults on 12 boats; a fleet of 8 has 7 besides"):
        messy_fleet(0, n_boats=8)


# --- the truth holds on the tracks -----------------------------------------------------


def test_clean_boats_cross_each_target_at_the_truth_times(clean: Fleet) -> None:
    for b in clean.boats:
        x, y = xy(clean, b.name)
        t = true_times(clean, b.name)
        seg = segment_track(clean.course, t, x, y)
        got = [c.t for c in seg.bounds]
        np.testing.assert_array_less(
            np.abs(np.subtract(got, [b.start_t, *b.leg_end_t])), b.sample_s
        )
        # at the gate: the mark rounded and when it was passed below it
        seg = segment_track(clean.course, t, x, y, gate_end="rounding")
        assert b.gate_marks[1] in ("4s", "4p") and b.gate_marks[0] == b.gate_marks[2] == ""
        assert abs(seg.ends[1].t - b.gate_round_t[1]) < b.sample_s
        assert b.leg_end_t[1] < b.gate_round_t[1] < b.leg_end_t[1] + 15.0
        assert seg.start.late_s == pytest.approx(b.start_delay_s, abs=b.sample_s)
        assert seg.start.distance_at_gun_m == pytest.approx(-b.distance_at_gun_m, abs=3.0)


def test_messy_fleets_clean_boats_cross_near_the_truth_times(fleet: Fleet, quiet: Fleet) -> None:
    # without GPS error every crossing is found within half the fix interval; the
    # error (0.7 m white, 1.5 m correlated per axis) moves a crossing by about
    # 1.7 m / 2 m s⁻¹ ≈ 0.8 s, more where the path meets a mark's ray at a slant
    for f, within_1, within_2, most_s in ((quiet, 1.0, 1.0, 1.5), (fleet, 0.75, 0.9, 6.0)):
        err, rel = [], []
        for b in f.clean:
            x, y = xy(f, b.name)
            seg = segment_track(f.course, true_times(f, b.name), x, y)
            e = np.abs(np.subtract([c.t for c in seg.bounds], [b.start_t, *b.leg_end_t]))
            err.append(e)
            rel.append(e / b.sample_s)
        r = np.concatenate(rel)
        assert np.mean(r <= 0.5 if f is quiet else r <= 1.0) >= within_1
        assert np.mean(r <= 2.0) >= within_2
        assert float(np.max(np.concatenate(err))) < most_s


def test_top_boat_sails_the_routers_optimum(fleet: Fleet) -> None:
    # the best boat (skill 1, the lighter tack class) against the isochrone router at its
    # default settings (2° headings, 1° sectors) from the same point and time of each leg:
    # within 1 % (the fleet is routed on 4° headings and sectors, fleetgen.ROUTER)
    (top,) = [b for b in fleet.boats if b.skill == 1.0]
    tack, gybe = TACK_CLASSES[0]
    assert top.tack_cost_s == tack and top.gybe_cost_s == gybe
    for i, leg in enumerate(top.legs):
        st, tg = leg_endpoints(fleet.course, i)
        following = target_of(fleet.course, i + 1) if i + 1 < fleet.course.n_legs else None
        tg = chain_leg(st, tg, None, following)[1]
        barrier = top.legs[i - 1].barrier if i else None
        settings = RoutingSettings(
            tack_penalty_s=tack,
            gybe_penalty_s=gybe,
            initial_side=top.first_side if i == 0 else None,
        )
        opt = route_leg(
            Start(leg.start_xy, None, st.name, barrier),
            tg,
            leg.t_start,
            fleet.wind,
            fleet.polar,
            settings,
        )
        assert leg.time_s == pytest.approx(opt.time_s, rel=0.01), i
        assert leg.n_tacks + leg.n_gybes == pytest.approx(opt.n_tacks + opt.n_gybes, abs=1)


def _beats(f: Fleet, boats: tuple[BoatTruth, ...]):
    """Route steps on the upwind legs: heading, TWA and speed against the true wind."""
    for b in boats:
        for i, leg in enumerate(b.legs):
            if f.point_of_sail(i) != "upwind":
                continue
            tr = leg.track
            dt, dx, dy = np.diff(tr.t), np.diff(tr.x), np.diff(tr.y)
            d = np.hypot(dx, dy)
            m = (d > 1.0) & (dt > 1.0)  # moving (not a manoeuvre's stop)
            tm, xm, ym = (0.5 * (a[1:] + a[:-1])[m] for a in (tr.t, tr.x, tr.y))
            twa = np.abs(wrap180(bearing_deg(dx[m], dy[m]) - f.wind.direction(tm, xm, ym)))
            tws = f.wind.speed(tm, xm, ym)
            yield b, twa, tws, d[m] / dt[m]


def test_beating_boats_sail_the_polars_best_vmg_angle_in_the_true_wind(fleet: Fleet) -> None:
    # the router steers on a 4° heading grid and holds a heading for 10 s while the wind
    # turns, and sails free to a mark from the layline: most steps lie within 3°
    err, ratio = [], []
    for b, twa, tws, speed in _beats(fleet, fleet.clean):
        err.append(twa - fleet.polar.vmg_upwind(tws)[0])
        ratio.append(speed / (b.skill * fleet.polar.speed(tws, twa)))
    e, r = np.abs(np.concatenate(err)), np.concatenate(ratio)
    assert e.size > 800
    assert float(np.median(e)) < 1.0 and float(np.percentile(e, 80)) <= 3.5
    # and each boat sails at its skill times the class polar at its own true time
    assert float(np.median(r)) == pytest.approx(1.0, abs=1e-3)
    assert float(np.percentile(r, 5)) > 0.99


def test_a_boat_of_skill_s_sails_the_polar_scaled_by_s(fleet: Fleet) -> None:
    # the dilated-time route of the generator against a plain route of the scaled polar
    # in the true wind: the same leg, the same start, within the step's resolution
    s = 0.9
    p = fleet.polar
    scaled = Polar.from_arrays(p.twa_deg, p.tws_ms, s * p.speed_ms, name="scaled")
    st, tg = leg_endpoints(fleet.course, 0)
    tg = chain_leg(st, tg, None, target_of(fleet.course, 1))[1]
    pin, com = fleet.marks["start_pin"], fleet.marks["start_boat"]
    start = Start(((pin[0] + com[0]) / 2.0, (pin[1] + com[1]) / 2.0), None, "start")
    settings = RoutingSettings()
    plain = route_leg(start, tg, GUN, fleet.wind, scaled, settings)
    dil = route_leg(start, tg, GUN, fleet.wind.dilated(GUN, s), p, settings)
    assert GUN + dil.time_s / s == pytest.approx(GUN + plain.time_s, abs=0.005 * plain.time_s)
    assert dil.n_tacks == pytest.approx(plain.n_tacks, abs=1)


def test_clock_lag_shifts_every_time(clean: Fleet) -> None:
    # a fix stamped t lies where the boat was at t + lag: a lagging tracker clock
    lagged = clean.resampled(clock_lag_s=7.0)
    for b in lagged.boats:
        tr, tr0 = lagged.track(b.name), clean.track(b.name)
        px, py = b.position(tr.t_s + 7.0)
        x, y = xy(lagged, b.name)
        np.testing.assert_allclose(np.hypot(x - px, y - py), 0.0, atol=1e-6)
        if b.sample_s == 1.0:  # the same fixes, each stamped 7 s earlier
            np.testing.assert_array_equal(tr.t_s, tr0.t_s - 7.0)
            np.testing.assert_array_equal(tr.lat_deg, tr0.lat_deg)
        # so the start looks 7 s earlier than it was: over early for a boat that started
        # less than 7 s after the gun
        st = find_start(lagged.course, tr.t_s, x, y)
        if b.start_delay_s < 7.0 - b.sample_s:
            assert st.ocs_s == pytest.approx(7.0 - b.start_delay_s, abs=b.sample_s)
        early = dataclasses.replace(lagged.course, start_time=lagged.course.start_time - MINUTE)
        st = find_start(early, tr.t_s, x, y)
        assert st.crossing.t == pytest.approx(b.start_t - 7.0, abs=b.sample_s)
    assert lagged.boats == clean.boats


def test_gps_error_has_the_stated_rms_and_correlation(fleet: Fleet, quiet: Fleet) -> None:
    plan = fleet.plan
    res, lag10 = [], []
    for b in fleet.boats:
        x, y = xy(fleet, b.name)
        x0, y0 = xy(quiet, b.name)  # the same fixes without the error
        np.testing.assert_array_equal(fleet.track(b.name).t_s, quiet.track(b.name).t_s)
        res.append(np.concatenate([x - x0, y - y0]))
        if b.sample_s == 1.0 and b.duplicate_of is None:
            lag10.append(np.corrcoef((x - x0)[:-10], (x - x0)[10:])[0, 1])
    rms = float(np.sqrt(np.mean(np.concatenate(res) ** 2)))
    want = math.hypot(plan.noise_white_m, plan.noise_corr_m)
    assert rms == pytest.approx(want, rel=0.1)
    # correlation of fixes 10 s apart: the correlated share times exp(-10 s / tau)
    rho = plan.noise_corr_m**2 * math.exp(-10.0 / plan.noise_tau_s) / want**2
    assert float(np.median(lag10)) == pytest.approx(rho, abs=0.1)
    # and without error the fixes lie on the true path
    for b in quiet.boats:
        px, py = b.position(true_times(quiet, b.name))
        x, y = xy(quiet, b.name)
        assert float(np.max(np.hypot(x - px, y - py))) < 1e-6


def test_fixes_are_whole_seconds_1_to_3_apart(fleet: Fleet) -> None:
    for b in fleet.boats:
        t = fleet.track(b.name).t_s
        assert b.sample_s in (1.0, 2.0, 3.0)
        assert np.all(t == np.round(t))
        assert float(np.median(np.diff(t))) == b.sample_s
    assert {b.sample_s for b in fleet.boats} == {1.0, 2.0, 3.0}


def test_a_duplicate_repeats_another_track(fleet: Fleet) -> None:
    (dup,) = fleet.with_status("duplicate_of")
    src = fleet.truth(dup.duplicate_of)
    assert dup.name != src.name and src.clean
    a, b = fleet.track(dup.name), fleet.track(src.name)
    assert a.name == dup.name
    for k in ("t_s", "lat_deg", "lon_deg"):
        np.testing.assert_array_equal(getattr(a, k), getattr(b, k))
    assert dup.leg_end_t == src.leg_end_t and dup.fault("duplicate").params["of"] == src.name


def test_the_non_starter_never_crosses_the_line(quiet: Fleet) -> None:
    (b,) = quiet.with_status("non_starter")
    assert math.isnan(b.start_t) and all(math.isnan(t) for t in b.leg_end_t)
    assert np.all(line_side(quiet, b.path_x, b.path_y) < 0.0)  # never on the course side
    t = true_times(quiet, b.name)
    assert t[-1] > quiet.gun + 1800.0  # logging through the race
    x, y = xy(quiet, b.name)
    with pytest.raises(InputError, match="never crosses the start line"):
        find_start(quiet.course, t, x, y)


def test_ocs_boats_are_over_at_the_gun_and_nobody_else(quiet: Fleet) -> None:
    ocs = quiet.with_status("ocs_returned", "ocs_not_returned")
    assert len(ocs) == 4
    lo, hi = quiet.plan.ocs_margin_m
    for b in ocs:
        assert 0.5 * lo < b.distance_at_gun_m < 1.5 * hi and b.ocs_s > 1.0
        x, y = xy(quiet, b.name)
        st = find_start(quiet.course, true_times(quiet, b.name), x, y)
        assert st.ocs_s == pytest.approx(b.ocs_s, abs=b.sample_s)
        assert side_at_gun(quiet, b.name) == pytest.approx(b.distance_at_gun_m, abs=1.0)
        assert st.ocs_returned == (b.status == "ocs_returned")
        if b.status == "ocs_returned":
            assert quiet.gun < b.returned_t < b.start_t
            assert st.crossing.t == pytest.approx(b.start_t, abs=b.sample_s)
        else:
            assert b.start_t == pytest.approx(quiet.gun - b.ocs_s)
    own = [b for b in quiet.boats if b.status != "other_fleet"]
    assert {b.name for b in own if b.distance_at_gun_m > 0.0} == {b.name for b in ocs}


def test_late_starters_start_late_from_behind(quiet: Fleet) -> None:
    lo, hi = quiet.plan.late_s
    for b in quiet.with_status("late"):
        assert lo <= b.start_delay_s <= hi
        assert b.fault("late").params["late_s"] == pytest.approx(b.start_delay_s)
        assert b.distance_at_gun_m < -20.0
        x, y = xy(quiet, b.name)
        st = find_start(quiet.course, true_times(quiet, b.name), x, y)
        assert st.late_s == pytest.approx(b.start_delay_s, abs=b.sample_s)
        assert side_at_gun(quiet, b.name) == pytest.approx(b.distance_at_gun_m, abs=1.0)
        assert st.distance_at_gun_m >= -b.distance_at_gun_m - 1.0  # from the segment
    # the others left the line 0.5-8.5 s after the gun, after a tack on it if the route
    # began with one
    on_time = [b.start_delay_s for b in quiet.with_status("racing")]
    assert min(on_time) > 0.0 and max(on_time) <= 8.5 + max(TACK_CLASSES)[0] / 0.88


def test_a_data_gap_has_no_fixes_and_fixes_around_it(quiet: Fleet) -> None:
    (b,) = quiet.with_fault("data_gap")
    p = b.fault("data_gap").params
    lo, hi = quiet.plan.gap_s
    assert min(lo, 30.0) <= p["t1"] - p["t0"] <= hi
    leg = b.legs[p["leg"]]
    assert leg.t_start + 20.0 <= p["t0"] < p["t1"] <= leg.t_end - 20.0
    t = true_times(quiet, b.name)
    assert not np.any((t > p["t0"]) & (t < p["t1"]))
    assert np.min(np.abs(t - p["t0"])) < b.sample_s and np.min(np.abs(t - p["t1"])) < b.sample_s
    # the legs are found around it
    x, y = xy(quiet, b.name)
    seg = segment_track(quiet.course, t, x, y)
    np.testing.assert_allclose([c.t for c in seg.ends], b.leg_end_t, atol=b.sample_s)


def test_retired_boats_stop_mid_race(quiet: Fleet) -> None:
    for kind in ("retired", "data_ends"):
        (b,) = quiet.with_fault(kind)
        p = b.fault(kind).params
        j = p["leg"]
        assert b.status == "retired" and 1 <= j < quiet.course.n_legs - 1
        assert all(math.isnan(v) for v in b.leg_end_t[j:])
        assert not any(math.isnan(v) for v in b.leg_end_t[:j])
        assert b.legs[-1].t_end < p["t"]
        t = true_times(quiet, b.name)
        if kind == "data_ends":
            assert p["t"] - b.sample_s <= t[-1] <= p["t"]
        else:  # sailed 500 m off first
            assert t[-1] > p["t"] + 200.0
            x, y = xy(quiet, b.name)
            px, py = b.position(p["t"])
            # (the last fix up to one interval at 2.2 m/s before the end)
            assert math.hypot(x[-1] - px, y[-1] - py) == pytest.approx(500.0, abs=7.0)


def test_a_log_of_two_races(quiet: Fleet) -> None:
    (b,) = quiet.with_status("two_races")
    p = b.fault("two_races").params
    t = true_times(quiet, b.name)
    k = int(np.argmax(np.diff(t)))
    assert t[k + 1] - t[k] > 900.0
    assert t[k] == pytest.approx(p["gap"][0], abs=b.sample_s) and t[k + 1] < p["gun2"]
    assert b.leg_end_t[-1] < t[k]
    # the second race: the same course from its own gun, found at its truth times
    later = timedelta(seconds=p["gun2"] - quiet.gun)
    course2 = dataclasses.replace(quiet.course, start_time=quiet.course.start_time + later)
    x, y = xy(quiet, b.name)
    seg = segment_track(course2, t[k + 1 :], x[k + 1 :], y[k + 1 :])
    want = [p["start2_t"], *p["leg_end2_t"]]
    np.testing.assert_allclose([c.t for c in seg.bounds], want, atol=b.sample_s)


def test_a_gate_passed_outside(quiet: Fleet) -> None:
    (b,) = quiet.with_status("gate_outside")
    p = b.fault("gate_outside").params
    i = p["leg"]
    assert quiet.course.legs[i].kind == "gate" and b.leg_end_t[i] == p["passed_t"]
    assert b.gate_marks[i] == "" and math.isnan(b.gate_round_t[i])
    # never between the marks: where the path crosses the gate's line it lies beyond the
    # mark passed, 20 m or more on its way down
    m = np.array(quiet.marks[p["mark"]])
    o = np.array(quiet.marks["4p" if p["mark"] == "4s" else "4s"])
    width = float(np.linalg.norm(m - o))
    g = (m - o) / width
    k = (b.path_t >= b.legs[i].t_start) & (b.path_t <= b.leg_end_t[i] + 60.0)
    px, py = b.path_x[k] - o[0], b.path_y[k] - o[1]
    across, along = px * -g[1] + py * g[0], px * g[0] + py * g[1]
    flips = np.flatnonzero(np.sign(across[1:]) != np.sign(across[:-1]))
    at = [
        along[j] + across[j] / (across[j] - across[j + 1]) * (along[j + 1] - along[j])
        for j in flips
    ]
    assert len(at) >= 1 and at[0] >= width + 20.0 - 1e-6 and min(at) > width + 5.0
    # so the leg is not found ending between the marks: segmentation ends it where the boat
    # passed, flagged as outside the gate's marks
    x, y = xy(quiet, b.name)
    seg = segment_track(quiet.course, true_times(quiet, b.name), x, y, missing="unknown")
    assert seg.ends[i].issue == LegIssue.OUTSIDE
    assert abs(seg.ends[i].t - p["passed_t"]) < 1.0


def test_boats_of_other_fleets(recall: Fleet) -> None:
    kinds = {b.fault("other_fleet").params["kind"]: b for b in recall.with_status("other_fleet")}
    assert set(kinds) == {"class", "area", "day"}
    cls = kinds["class"]
    assert cls.gun_t == recall.gun + OTHER_CLASS_AFTER_S and cls.skill == OTHER_CLASS_SKILL
    assert 0.0 < cls.start_delay_s < 10.0
    x, y = xy(recall, kinds["area"].name)
    d = min(np.min(np.hypot(x - mx, y - my)) for mx, my in recall.marks.values())
    assert d > 3000.0
    day = recall.track(kinds["day"].name)
    assert day.t_s[0] > recall.gun + 20 * 3600.0
    assert kinds["day"].start_t - 86400.0 == pytest.approx(recall.gun, abs=10.0)


def test_general_recall(recall: Fleet) -> None:
    g1, g = recall.guns
    assert g - g1 == recall.plan.recall_s and recall.gun == g
    fleet = [
        b for b in recall.boats if b.status not in ("other_fleet", "duplicate_of", "non_starter")
    ]
    over = [b for b in fleet if b.distance_at_first_gun_m > 0.0]
    assert 2 <= len(over) < len(fleet)
    # every boat crossed the line round the first gun and came back below it
    for b in fleet:
        t = true_times(recall, b.name)
        x, y = xy(recall, b.name)
        side = line_side(recall, x, y)
        w = (t > g1 - 20.0) & (t < g1 + 90.0)
        assert side[w].max() > 5.0
        assert side[(t > g1 + 150.0) & (t < g - 60.0)].max() < 0.0
    # at the restart only the OCS boats are over
    assert {b.name for b in fleet if b.distance_at_gun_m > 0.0} == {
        b.name for b in recall.with_status("ocs_returned", "ocs_not_returned")
    }


# --- files ---------------------------------------------------------------------------------


def test_written_files_read_back_as_the_tracks(recall: Fleet, tmp_path) -> None:
    course, gpx = recall.write(tmp_path / "gpx", "gpx")
    _, csv = recall.write(tmp_path / "csv", "csv")
    c = load_course(course)
    assert c.start_epoch == recall.gun and [leg.to_name for leg in c.legs] == [
        "1",
        "4",
        "1",
        "finish",
    ]
    for name, m in recall.marks.items():
        assert (c.marks[name].x, c.marks[name].y) == pytest.approx(m, abs=1e-3)
    assert c.frame == recall.course.frame
    for tr, pg, pc in zip(recall.tracks, gpx, csv, strict=True):
        assert pg.stem == pc.stem == tr.name
        for p in (pg, pc):
            back = read_track(p)
            np.testing.assert_array_equal(back.t_s, tr.t_s)
            np.testing.assert_allclose(back.lat_deg, tr.lat_deg, atol=1e-8)
            np.testing.assert_allclose(back.lon_deg, tr.lon_deg, atol=1e-8)
        sog = read_track(pc).channels["sog_ms"]  # written in knots to 0.01 kn
        np.testing.assert_allclose(sog, tr.channels["sog_ms"], atol=0.006 * KNOT)
    first, _ = recall.write(tmp_path / "first", "gpx", gun="first")
    assert load_course(first).start_epoch == recall.guns[0]
    assert f'start_time: "{iso(recall.guns[0])}"' in first.read_text()


def test_sog_and_cog_are_the_true_velocity(recall: Fleet) -> None:
    for b in recall.clean:
        tr = recall.track(b.name)
        t = tr.t_s + recall.clock_lag_s
        vx = np.interp(t + 0.01, b.path_t, b.path_x) - np.interp(t - 0.01, b.path_t, b.path_x)
        vy = np.interp(t + 0.01, b.path_t, b.path_y) - np.interp(t - 0.01, b.path_t, b.path_y)
        speed = np.hypot(vx, vy) / 0.02
        moving = speed > 0.5
        assert float(np.median(np.abs(tr.channels["sog_ms"] - speed)[moving])) < 0.1
        dcog = wrap180(tr.channels["cog_deg"] - bearing_deg(vx, vy))[moving]
        assert float(np.median(np.abs(dcog))) < 2.5


def test_same_seed_same_fleet(clean: Fleet) -> None:
    assert shared_fleet(0, n_boats=24, minutes=30) is shared_fleet(0, n_boats=24, minutes=30)
    again = messy_fleet(1, n_boats=10, minutes=25, faults=CLEAN, clock_lag_s=0.0)
    assert again.course_yaml == clean.course_yaml
    for a, b in zip(clean.tracks, again.tracks, strict=True):
        assert a.name == b.name
        for k in ("t_s", "lat_deg", "lon_deg"):
            np.testing.assert_array_equal(getattr(a, k), getattr(b, k))
    for a, b in zip(clean.boats, again.boats, strict=True):
        assert (a.leg_end_t, a.start_t, a.skill, a.faults) == (
            b.leg_end_t,
            b.start_t,
            b.skill,
            b.faults,
        )
        np.testing.assert_array_equal(a.path_x, b.path_x)
    other = messy_fleet(4, n_boats=10, minutes=10, faults=CLEAN)
    assert {t.name for t in other.tracks}.isdisjoint({t.name for t in clean.tracks})


# --- cost ------------------------------------------------------------------------------


@pytest.mark.slow
@pytest.mark.timing
def test_forty_boats_of_45_min_in_a_few_seconds() -> None:
    messy_fleet(3, n_boats=14, minutes=10)  # warm-up (polar tables)
    tic = time.process_time()
    messy_fleet(3)
    assert time.process_time() - tic < 6.0


@pytest.mark.slow
@pytest.mark.parametrize("seed", [10, 11, 12, 13, 14])
def test_five_seeds_of_forty_boats_hold_their_truth(seed: int) -> None:
    noisy = messy_fleet(seed)
    f = noisy.resampled(noise=False)
    assert len([b for b in f.boats if b.status not in ("duplicate_of", "other_fleet")]) == 40
    assert {b.status for b in f.boats} == set(STATUSES)
    for b in f.clean:  # every crossing where the truth says (no GPS error)
        x, y = xy(f, b.name)
        seg = segment_track(f.course, true_times(f, b.name), x, y)
        got = np.array([c.t for c in seg.bounds])
        np.testing.assert_array_less(np.abs(got - [b.start_t, *b.leg_end_t]), 0.5 * b.sample_s)
    ocs = {b.name for b in f.with_status("ocs_returned", "ocs_not_returned")}
    own = [b for b in f.boats if b.status != "other_fleet"]
    assert {b.name for b in own if b.distance_at_gun_m > 0.0} == ocs


def test_a_gybing_class_runs_at_its_best_downwind_angle(tmp_path) -> None:
    # the J/70 (an ORC certificate in tests/data/boat) gybes at TWA 145-150°: its runs
    # hold information on the wind, where the ILCA's (dead downwind) hold none
    polar = TESTS_DATA / "boat" / "ITA_ITA455J70.json"
    f = messy_fleet(7, n_boats=6, minutes=20, faults=CLEAN, boat=str(polar))
    err, gybes = [], 0
    for b in f.boats:
        for i, leg in enumerate(b.legs):
            if f.point_of_sail(i) != "downwind":
                continue
            gybes += leg.n_gybes
            tr = leg.track
            dt, dx, dy = np.diff(tr.t), np.diff(tr.x), np.diff(tr.y)
            m = (np.hypot(dx, dy) > 1.0) & (dt > 1.0)
            tm, xm, ym = (0.5 * (a[1:] + a[:-1])[m] for a in (tr.t, tr.x, tr.y))
            twa = np.abs(wrap180(bearing_deg(dx[m], dy[m]) - f.wind.direction(tm, xm, ym)))
            err.append(twa - f.polar.vmg_downwind(f.wind.speed(tm, xm, ym))[0])
    e = np.abs(np.concatenate(err))
    assert float(np.median(e)) < 1.5 and gybes >= len(f.boats)
    course, _ = f.write(tmp_path)
    assert load_course(course).boat_spec == {"polar": polar.name}
    assert (tmp_path / polar.name).read_bytes() == polar.read_bytes()


# --- how a boat sails: pinching, footing, banking -----------------------------------------


@pytest.mark.parametrize("offset", [-10.0, -4.0, 6.0, 10.0])
def test_an_offset_polar_peaks_off_the_best_angle_at_the_polars_speed(offset: float) -> None:
    p = messy_fleet(0, n_boats=2, minutes=10, faults=CLEAN).polar
    q = offset_polar(p, offset)
    tws = p.tws_ms[[3, 6, 9, 12]]  # on its columns (between them: the interpolation's peak)
    best = p.vmg_upwind(tws)[0]
    a, _ = q.vmg_upwind(tws)
    assert np.allclose(a, best + offset, atol=0.5)
    assert np.allclose(q.speed(tws, a), p.speed(tws, a), rtol=0.01)
    # the reaches and the runs are the class polar's
    for twa in (75.0, 110.0, 150.0, 175.0):
        assert np.allclose(q.speed(tws, twa), p.speed(tws, twa), rtol=1e-3)


@pytest.fixture(scope="module")
def styled() -> Fleet:
    """Four boats in a wind without oscillation: one pinches 10°, two bank."""
    sailing = {1: Sailing(-10.0), 2: Sailing(bank="left"), 3: Sailing(bank="right")}
    wind = {"osc_amp_deg": 0.0, "tws_amp": 0.0}
    return messy_fleet(3, n_boats=4, minutes=14, faults=CLEAN, sailing=sailing, wind_fields=wind)


def test_a_styled_boat_sails_as_told(styled: Fleet) -> None:
    by = {b.upwind_twa_offset_deg: b for b in styled.boats if b.bank is None}
    assert set(by) == {0.0, -10.0}
    best = float(styled.polar.vmg_upwind(styled.wind.tws_ms)[0])
    for off, b in by.items():  # its beats at the best angle plus its offset
        twa = np.abs(np.concatenate([b.legs[i].track.twa_deg for i in (0, 2)]))
        assert float(np.median(twa[twa < 90.0])) == pytest.approx(best + off, abs=1.0)
    for b in styled.boats:
        if b.bank is None:
            continue
        # it starts on the tack to its side and passes its waypoint up the first beat
        way = bank_waypoint(styled.course, styled.polar, styled.wind, b.bank).a
        tr = b.legs[0].track
        assert b.first_side == ("starboard" if b.bank == "left" else "port")
        assert float(np.min(np.hypot(tr.x - way[0], tr.y - way[1]))) < 25.0
        # the tack sailed out to it: one board from the line
        k = int(np.argmin(np.hypot(tr.x - way[0], tr.y - way[1])))
        assert len(set(tr.side[1:k].tolist())) == 1
    doc = styled.truth_json()["boats"]
    assert {k for b in doc.values() for k in b} >= {"upwind_twa_offset_deg", "bank"}


def test_a_fleet_without_styles_keeps_its_truth(clean: Fleet) -> None:
    # the styles draw nothing: every other boat and the JSON stay as they were
    assert all(b.upwind_twa_offset_deg == 0.0 and b.bank is None for b in clean.boats)
    doc = clean.truth_json()["boats"]
    assert not {k for b in doc.values() for k in b} & {"upwind_twa_offset_deg", "bank"}
    styled = messy_fleet(
        1, n_boats=10, minutes=25, faults=CLEAN, clock_lag_s=0.0, sailing={4: Sailing(-6.0)}
    )
    same = [b.name for b in clean.boats if b.name != styled.boats[0].name]
    for name in [b.name for b in clean.boats]:
        a, c = clean.truth(name), styled.truth(name)
        assert (a.skill, a.tack_cost_s, a.start_fraction) == (
            c.skill,
            c.tack_cost_s,
            c.start_fraction,
        )
    assert same
