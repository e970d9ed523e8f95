"""Members of an ensemble routed as one front (sailroute.routing.batch)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from sailroute.errors import InputError, RoutingError
from sailroute.routing.batch import batchable, route_leg_batch
from sailroute.routing.isochrone import route_isochrone
from sailroute.routing.settings import RoutingSettings
from sailroute.routing.types import Start, Target
from sailroute.wind.uniform import UniformWind
from tests.routing.polars import laser_like_polar

POLAR = laser_like_polar()
T0 = 1_524_567_600.0  # 2018-04-24T11:00Z
SET = RoutingSettings()
LINE = Start((-150.0, 0.0), (150.0, 0.0), name="start")


def same_result(a, b):
    """Bit-identical leg results: time, end point and every track column."""
    assert a.time_s == b.time_s and a.end_xy == b.end_xy and a.start_xy == b.start_xy
    for f in ("t", "x", "y", "heading_deg", "bsp_ms", "tws_ms", "twa_deg", "side"):
        np.testing.assert_array_equal(getattr(a.track, f), getattr(b.track, f), err_msg=f)
    assert (a.n_tacks, a.n_gybes) == (b.n_tacks, b.n_gybes)


@pytest.mark.parametrize(
    "target",
    [
        Target("mark", (40.0, 700.0), rounding="port", name="1"),
        Target("line", (-60.0, 650.0), (60.0, 650.0), name="finish"),
    ],
)
def test_a_batch_gives_each_member_its_own_route_bit_for_bit(target):
    # beats and reaches in different winds and at different start times, from one start
    # line: every member steps exactly as it would alone
    winds = [
        UniformWind(4.4, 0.0),
        UniformWind(3.0, 20.0),
        UniformWind(6.0, 80.0),
        UniformWind([3.0, 6.0], [350.0, 10.0], times=[T0, T0 + 600.0], clamp=True),
    ]
    t0s = [T0, T0 + 50.0, T0, T0 + 120.0]
    batch = route_leg_batch(LINE, target, t0s, winds, POLAR, SET)
    assert len(batch) == len(winds)
    for t0, w, got in zip(t0s, winds, batch, strict=True):
        same_result(route_isochrone(LINE, target, t0, w, POLAR, SET), got)


def test_members_shorten_their_steps_and_arrive_in_the_common_front(monkeypatch):
    # near the target each member's steps shorten (dt_s down to min_dt_s) inside the
    # common front, and a member whose points can reach the target is tested for the
    # arrival on its own points there: none is routed alone with the single-member
    # driver, and each still gets its own route bit for bit
    from sailroute.routing import batch as batch_module

    def alone(*args, **kwargs):
        pytest.fail("a member was routed alone")

    monkeypatch.setattr(batch_module, "_route_on", alone)
    winds = [UniformWind(4.4, 0.0), UniformWind(3.0, 20.0), UniformWind(6.0, 80.0)]
    t0s = (T0, T0 + 50.0, T0)
    for target in (
        Target("mark", (40.0, 700.0), rounding="port", name="1"),
        Target("line", (-60.0, 650.0), (60.0, 650.0), name="finish"),
    ):
        batch = route_leg_batch(LINE, target, list(t0s), winds, POLAR, SET)
        for t0, w, got in zip(t0s, winds, batch, strict=True):
            same_result(route_isochrone(LINE, target, t0, w, POLAR, SET), got)


def test_members_in_a_stronger_wind_finish_in_the_closed_form_order():
    # a reach north to a wide line, the wind from the east (no manoeuvre): the leg time
    # is L / max_a S(tws, a) sin(a), the best speed towards the line (0.01° scan), so the
    # members finish in the order of that speed
    L = 500.0
    finish = Target("line", (-300.0, L), (300.0, L), name="finish")
    tws = [2.5, 3.5, 4.5, 5.5, 6.5]
    batch = route_leg_batch(
        Start((0.0, 0.0)), finish, [T0] * len(tws), [UniformWind(w, 90.0) for w in tws], POLAR, SET
    )
    twa = np.arange(30.0, 150.0, 0.01)
    closed = np.array(
        [L / np.max(POLAR.speed(np.full_like(twa, w), twa) * np.sin(np.radians(twa))) for w in tws]
    )
    times = np.array([r.time_s for r in batch])
    np.testing.assert_allclose(times, closed, rtol=1e-5)
    assert np.all(np.diff(times) < 0)  # the speed towards the line rises with the wind
    assert all((r.n_tacks, r.n_gybes) == (0, 0) for r in batch)


def test_members_starting_elsewhere_stay_within_the_pruning_tolerance():
    # a later leg of a course: each member starts where its previous leg ended, a few
    # metres apart; routed in the first member's leg frame, they lose or gain at most
    # 1e-3 of the leg time against their own routes
    mark = Target("mark", (0.0, 800.0), rounding="starboard", name="1")
    starts = [Start((dx, dy), name="2") for dx, dy in ((0.0, 0.0), (6.0, -3.0), (-4.0, 5.0))]
    wind = UniformWind(4.4, 10.0)
    batch = route_leg_batch(starts, mark, [T0] * 3, [wind] * 3, POLAR, SET)
    same_result(route_isochrone(starts[0], mark, T0, wind, POLAR, SET), batch[0])
    for st, got in zip(starts[1:], batch[1:], strict=True):
        alone = route_isochrone(st, mark, T0, wind, POLAR, SET)
        assert got.start_xy == alone.start_xy
        assert got.time_s == pytest.approx(alone.time_s, rel=1e-3)


def test_a_member_that_cannot_arrive_raises_its_own_error():
    # member 2 is becalmed: its error names the calm, as the single router's does
    winds = [UniformWind(4.4, 90.0), UniformWind(0.0, 90.0)]
    settings = dataclasses.replace(SET, max_leg_time_s=300.0)
    finish = Target("line", (-100.0, 400.0), (100.0, 400.0), name="finish")
    with pytest.raises(RoutingError, match="boat speed was zero on the whole front"):
        route_leg_batch(Start((0.0, 0.0)), finish, [T0, T0], winds, POLAR, settings)


def test_members_given_in_different_numbers_are_refused():
    finish = Target("line", (-100.0, 400.0), (100.0, 400.0), name="finish")
    with pytest.raises(InputError, match=r"got 2 start times, 1 winds, 2 starts and 2 boats"):
        route_leg_batch(Start((0.0, 0.0)), finish, [T0, T0], [UniformWind(4.0, 90.0)], POLAR, SET)


def test_only_the_isochrone_router_on_numpy_in_still_water_is_batched():
    assert batchable(SET, "numpy", [None, None])
    assert not batchable(SET, "cupy", [None])
    assert not batchable(dataclasses.replace(SET, router="griddp"), "numpy", [None])
    assert not batchable(SET, "numpy", [None, object()])
