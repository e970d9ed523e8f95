"""Leg-time bands routed as one front per leg (bands.route.route_together) against the
members routed one by one, and the pieces that make it fast: one wind sample per step
for members that perturb one wind, the layline extremes sailed together."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from sailroute.bands.members import draw_members
from sailroute.bands.route import route_members, route_together, spec_for
from sailroute.course.load import build_specs, load_course
from sailroute.routing.sides import extreme_times, layline_times
from sailroute.wind.perturbed import PerturbedWind, sample_perturbed
from sailroute.wind.uniform import UniformWind
from tests.routing.polars import laser_like_polar
from tests.routing.winds import T0, gridded_wind
from tests.test_bands import FAST, TEMPLATE


def lap_course(tmp_path: Path, scenario: dict, uncertainty: dict) -> Path:
    """One windward-leeward lap, 600 m legs, coarse routing."""
    data = {k: v for k, v in TEMPLATE.items() if k != "scenarios"}
    data["template"] = {**data["template"], "laps": 1, "leg_length_m": 600}
    data["routing"] = FAST
    data["scenarios"] = {"s": scenario}
    data["uncertainty"] = uncertainty
    p = tmp_path / "lap.yaml"
    p.write_text(yaml.safe_dump(data, sort_keys=False))
    return p


def routed_both_ways(path: Path, n: int):
    course = load_course(path)
    spec, _ = spec_for(course, n)
    members = draw_members(spec, course.time_limit_s)
    boat, winds = build_specs(course, ["s"])
    kw = {"wind": winds["s"], "boat": boat, "settings": course.routing}
    return (
        members,
        route_members(course, "s", members, **kw),
        route_together(course, "s", members, **kw),
    )


SHIFTS = {"model": "oscillating", "amplitude_deg": 6.0, "period_min": 5.0}


@pytest.mark.parametrize(
    "scenario",
    [
        {"wind": {"type": "uniform", "tws_kn": 12, "twd_deg": 250}},
        {
            "wind": {"type": "uniform", "tws_kn": 12, "twd_deg": 250},
            "current": {"type": "uniform", "speed_kn": 1.2, "set_deg": 300},
        },
    ],
    ids=["still", "current"],
)
def test_members_together_sail_the_legs_they_sail_one_by_one(tmp_path, scenario):
    # speed, direction and oscillating shifts (a series per member), in still water and
    # in a current: the first leg starts on the line for every member and is the same
    # bit for bit; the second starts where each member's first ended, and is routed in
    # the first member's leg frame (routing/batch.py): within the pruning's tolerance
    path = lap_course(tmp_path, scenario, {"tws_kn": 1.5, "twd_deg": 8, "shifts": SHIFTS})
    members, alone, together = routed_both_ways(path, 4)
    assert len(together) == len(members) == 4
    assert any(m.shift_deg for m in members)  # the shift series are exercised
    for a, b in zip(alone, together, strict=True):
        assert b[0].time_s == a[0].time_s and b[0].end_xy == a[0].end_xy
        np.testing.assert_array_equal(b[0].track.x, a[0].track.x)
        assert b[1].start_xy == a[1].start_xy
        assert b[1].time_s == pytest.approx(a[1].time_s, rel=2e-3)
    if "current" in scenario:  # the current moved the boats over the ground
        assert together[0][0].track.sog_ms is not None


def test_a_race_area_routes_the_members_one_by_one(tmp_path):
    # the batch routes open water only: with a boundary the members go one by one, with
    # the same results as route_members
    data = yaml.safe_load(
        lap_course(
            tmp_path, {"wind": {"type": "uniform", "tws_kn": 12, "twd_deg": 250}}, {"tws_kn": 1}
        ).read_text()
    )
    corners = [(-2000, -2000), (2000, -2000), (2000, 2000), (-2000, 2000)]
    data["origin"] = data["template"]["centre"]
    data["boundary"] = {"points": [{"x": x, "y": y} for x, y in corners]}
    path = tmp_path / "bounded.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    _, alone, together = routed_both_ways(path, 3)
    assert [[r.time_s for r in legs] for legs in together] == [
        [r.time_s for r in legs] for legs in alone
    ]


@pytest.mark.parametrize(
    "wind",
    [
        UniformWind(5.0, 200.0),
        UniformWind([4.0, 7.0], [190.0, 230.0], times=[T0, T0 + 3600.0], clamp=True),
        gridded_wind(clamp=True),
    ],
    ids=["steady", "in-time", "gridded"],
)
def test_one_sample_of_the_base_is_each_members_wind_bit_for_bit(wind):
    times = T0 + np.arange(0.0, 3600.0, 10.0)
    winds = [
        wind,  # the nominal member is the wind itself
        PerturbedWind(wind, speed_scale=1.1),
        PerturbedWind(wind, speed_add_ms=-0.7, direction_offset_deg=-5.0),
        PerturbedWind(wind, shift_times=times, shift_deg=6.0 * np.sin(times / 300.0)),
        PerturbedWind(wind, speed_add_ms=-9.0),  # calm: held at zero
    ]
    rng = np.random.default_rng(3)
    which = rng.integers(0, len(winds), 500)
    t = T0 + rng.uniform(0.0, 3600.0, 500)
    x, y = rng.uniform(-900.0, 900.0, (2, 500))
    u, v = sample_perturbed(winds, which, t, x, y)
    for k, w in enumerate(winds):
        mine = which == k
        uk, vk = w.sample(t[mine], x[mine], y[mine])
        np.testing.assert_array_equal(u[mine], uk)
        np.testing.assert_array_equal(v[mine], vk)
    assert np.all(u[which == 4] == 0.0)


def test_extremes_sailed_together_are_the_ones_sailed_alone():
    # a beat, a run and a reach in three winds (one with a persistent veer), each sailed
    # alone and all six together: the same times to the last bit
    veer = PerturbedWind(
        UniformWind(5.0, 0.0), shift_times=[T0, T0 + 3600.0], shift_deg=[0.0, 30.0]
    )
    legs = [
        ((0.0, 0.0), (0.0, 800.0), veer),
        ((0.0, 800.0), (0.0, 0.0), UniformWind(6.0, 10.0)),
        ((0.0, 0.0), (700.0, 100.0), UniformWind(4.0, 0.0)),
    ]
    boat = laser_like_polar()
    alone = [layline_times(a, b, T0, w, boat, tack_penalty_s=5.0) for a, b, w in legs]
    together = extreme_times(
        [a for a, _, _ in legs for _ in (0, 1)],
        [b for _, b, _ in legs for _ in (0, 1)],
        [T0] * 6,
        [w for _, _, w in legs for _ in (0, 1)],
        [boat] * 6,
        [1, -1] * 3,
        tack_penalty_s=5.0,
    )
    assert together.reshape(3, 2).tolist() == [list(t) for t in alone]
    (left, right), _, (reach_l, reach_r) = alone
    assert right < left  # a veer pays the right
    assert reach_l == reach_r  # a reach is one straight line


@pytest.mark.slow
def test_members_with_boats_of_their_own_sail_as_one_by_one(tmp_path):
    # race-polar members (the ILCA 7's sea_age_h drawn in [2, 4] h): each member's boat
    # is its own polar (stacked tables in the common front); the first leg the same bit
    # for bit as routed alone, the second within the pruning's tolerance
    path = lap_course(
        tmp_path,
        {"wind": {"type": "uniform", "tws_kn": 12, "twd_deg": 250}},
        {"tws_kn": 1, "boat": {"sea_age_h": [2, 4]}},
    )
    members, alone, together = routed_both_ways(path, 3)
    assert len({dict(m.boat)["sea_age_h"] for m in members}) == 3
    for a, b in zip(alone, together, strict=True):
        assert b[0].time_s == a[0].time_s
        np.testing.assert_array_equal(b[0].track.y, a[0].track.y)
        assert b[1].time_s == pytest.approx(a[1].time_s, rel=2e-3)
    # the members' polars differ, so do their times in one wind
    assert len({legs[0].time_s for legs in together}) == 3
