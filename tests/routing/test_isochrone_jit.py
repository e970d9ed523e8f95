"""The compiled isochrone step (routing.engine = "numba") against the NumPy one, through
numba's just-in-time kernels and through the module compiled ahead of time.

The kernels of sailroute/routing/isochrone_jit.py do the NumPy step's arithmetic in its
order, and the trigonometric functions stay NumPy's, so every route must come out the
same bit for bit: a leg time, an end point and a track column that differ in the last
bit fail these tests.  The cases walk through the kernel's branches: a line start with
the side still free, beats with tacks (a penalty served as time, pending manoeuvres), a
run with gybes, a gate and a finish line, a mark rounded before (its barrier), a wind
that changes in space and time with a coverage box, a current, a race area, a linear
polar, a full heading fan, a front capped at a few points, and members routed together
(winds, start times, boats of their own).
"""

from __future__ import annotations

import dataclasses
import sys

import numpy as np
import pytest

from sailroute.boat.polar import Polar
from sailroute.errors import InputError
from sailroute.routing import isochrone_fast
from sailroute.routing.batch import route_leg_batch
from sailroute.routing.geometry import chain_leg
from sailroute.routing.isochrone import route_isochrone
from sailroute.routing.obstacles import AreaPolygon, Obstacles, RaceArea
from sailroute.routing.settings import RoutingSettings, routing_settings
from sailroute.routing.types import Start, Target
from sailroute.wind.current import UniformCurrent
from sailroute.wind.uniform import UniformWind
from tests.routing.polars import laser_like_polar
from tests.routing.winds import T0, gridded_wind

numba = pytest.importorskip("numba")

POLAR = laser_like_polar()
LINE = Start((-150.0, 0.0), (150.0, 0.0), name="start")
MARK = Target("mark", (60.0, 700.0), rounding="port", name="1")


def with_engine(settings: RoutingSettings, engine: str) -> RoutingSettings:
    return dataclasses.replace(
        settings, isochrone=dataclasses.replace(settings.isochrone, engine=engine)
    )


def same_result(a, b) -> None:
    """Bit-identical leg results: time, ends and every track column."""
    assert (a.time_s, a.end_xy, a.start_xy) == (b.time_s, b.end_xy, b.start_xy)
    for f in ("t", "x", "y", "heading_deg", "bsp_ms", "tws_ms", "twa_deg", "side"):
        np.testing.assert_array_equal(getattr(a.track, f), getattr(b.track, f), err_msg=f)
    for f in ("sog_ms", "cog_deg"):
        if getattr(a.track, f) is not None:
            np.testing.assert_array_equal(getattr(a.track, f), getattr(b.track, f), err_msg=f)
    assert (a.n_tacks, a.n_gybes) == (b.n_tacks, b.n_gybes)


def both(start, target, wind, settings, polar=POLAR, **kw):
    """The leg on the NumPy path and on the compiled path, checked identical."""
    a = route_isochrone(start, target, T0, wind, polar, with_engine(settings, "numpy"), **kw)
    b = route_isochrone(start, target, T0, wind, polar, with_engine(settings, "numba"), **kw)
    same_result(a, b)
    return a


SET = RoutingSettings()
PENALTIES = routing_settings(tack_penalty_s=6.0, gybe_penalty_s=4.0, dt_s=5.0)


@pytest.mark.parametrize(
    ("start", "target", "wind", "settings"),
    [
        (LINE, MARK, UniformWind(4.4, 0.0), SET),  # a beat from a line, the side free
        (LINE, MARK, UniformWind(4.4, 10.0), PENALTIES),  # tacks served as time
        (
            Start((0.0, 700.0), name="1"),
            Target("gate", (-50.0, 0.0), (50.0, 0.0), name="gate"),
            UniformWind(5.0, 0.0),
            PENALTIES,
        ),  # a run with gybes to a gate
        (
            Start((0.0, 0.0)),
            Target("line", (300.0, -40.0), (300.0, 40.0), name="finish"),
            UniformWind(3.5, 0.0),
            SET,
        ),  # a reach to a finish line
        (LINE, MARK, gridded_wind(clamp=False), PENALTIES),  # the coverage box
        (LINE, MARK, gridded_wind(clamp=True), SET),
        (
            LINE,
            MARK,
            UniformWind(4.4, 0.0),
            dataclasses.replace(
                SET, isochrone=dataclasses.replace(SET.isochrone, heading_fan="full")
            ),
        ),
        (
            LINE,
            MARK,
            UniformWind(4.4, 15.0),
            routing_settings(max_front_points=8, prune_sector_deg=0.5, initial_side="port"),
        ),
    ],
    ids=["beat", "penalties", "run-gate", "reach-line", "box", "clamped", "full-fan", "capped"],
)
@pytest.mark.usefixtures("compiled_kernels")
def test_the_compiled_step_routes_every_leg_as_numpy_does(start, target, wind, settings):
    res = both(start, target, wind, settings)
    assert res.time_s > 0 and np.isfinite(res.time_s)


@pytest.mark.usefixtures("compiled_kernels")
def test_a_leg_after_a_rounding_keeps_the_mark_on_its_side_the_same_way():
    # leg 2 of a course: it starts where leg 1 ended, behind the barrier of mark 1
    wind = UniformWind(4.4, 0.0)
    gate = Target("gate", (-40.0, 0.0), (40.0, 0.0), name="gate")
    first = both(*chain_leg(LINE, MARK, None, gate), wind, PENALTIES)
    start, target = chain_leg(Start(MARK.a, name="1"), gate, first, None)
    assert start.barrier is not None
    both(start, target, wind, PENALTIES)


@pytest.mark.usefixtures("compiled_kernels")
def test_a_current_and_a_linear_polar_go_the_same_way():
    current = UniformCurrent(0.5, 120.0)
    both(LINE, MARK, UniformWind(4.4, 20.0), PENALTIES, current=current)
    linear = POLAR.with_interpolation("linear")
    assert linear.dense_table() is None  # looked up by the polar itself
    both(LINE, MARK, UniformWind(4.4, 0.0), SET, polar=linear)


@pytest.mark.usefixtures("compiled_kernels")
def test_a_race_area_goes_round_the_same_way():
    # the candidates' race-area test stays NumPy's; the rest of the step is compiled
    island = AreaPolygon("island", (-40.0, 120.0, 120.0, -40.0), (300.0, 300.0, 420.0, 420.0))
    obstacles = Obstacles.build(RaceArea(obstacles=(island,)))
    res = both(Start((0.0, 0.0)), MARK, UniformWind(4.4, 0.0), SET, obstacles=obstacles)
    assert res.distance_m > 700.0


@pytest.mark.usefixtures("compiled_kernels")
def test_members_routed_together_are_the_same_on_both_paths():
    # winds, start times and boats of their own; the compiled batch against the NumPy
    # batch, and each member against its own route (the first leg: bit for bit)
    faster = Polar.from_arrays(POLAR.twa_deg, POLAR.tws_ms, 1.1 * POLAR.speed_ms, name="faster")
    winds = [UniformWind(4.4, 0.0), UniformWind(3.0, 15.0), gridded_wind(clamp=True)]
    boats = [POLAR, faster, faster]
    t0s = [T0, T0 + 60.0, T0]
    runs = [
        route_leg_batch(LINE, MARK, t0s, winds, boats, with_engine(PENALTIES, e))
        for e in ("numpy", "numba")
    ]
    for a, b in zip(*runs, strict=True):
        same_result(a, b)
    for t0, w, boat, got in zip(t0s, winds, boats, runs[1], strict=True):
        same_result(route_isochrone(LINE, MARK, t0, w, boat, PENALTIES), got)


def test_dense_lookup_is_the_polars_bit_for_bit():
    from sailroute.routing import isochrone_jit

    rng = np.random.default_rng(7)
    tws = np.concatenate([rng.uniform(-1.0, 16.0, 400), POLAR.tws_ms, [np.nan, 0.0]])
    twa = np.concatenate([rng.uniform(0.0, 180.0, 400), np.linspace(0, 180, tws.size - 400)])
    twa = np.stack([twa, 180.0 - twa, np.full(tws.size, 45.0), twa[::-1]], axis=1)
    twa[3, 1] = np.nan
    out = np.empty_like(twa)
    inv_twa, inv_tws, top, n_twa, n_tws, cells = POLAR.dense_table()
    params = np.array([[inv_twa, inv_tws, top, n_twa, n_tws, 0.0]])
    isochrone_jit.dense_speeds(cells, params, np.zeros(0, dtype=np.int64), tws, twa, out)
    np.testing.assert_array_equal(out, POLAR.speed(tws[:, None], twa))


def test_the_engine_setting_is_checked_and_numba_can_be_missing(monkeypatch):
    with pytest.raises(InputError, match=r"isochrone\.engine must be one of 'auto', 'numpy'"):
        route_isochrone(LINE, MARK, T0, UniformWind(4.4, 0.0), POLAR, with_engine(SET, "jit"))
    monkeypatch.setattr(isochrone_fast, "AVAILABLE", False)
    assert not isochrone_fast.compiled(with_engine(SET, "auto"), np, members=50)
    with pytest.raises(InputError, match=r"needs numba.*pip install 'sailroute\[fast\]'"):
        route_isochrone(LINE, MARK, T0, UniformWind(4.4, 0.0), POLAR, with_engine(SET, "numba"))


def test_auto_compiles_for_members_and_after_enough_numpy_steps(monkeypatch):
    monkeypatch.setattr(isochrone_fast._Usage, "kernels", None)
    monkeypatch.setattr(isochrone_fast._Usage, "numpy_s", 0.0)
    monkeypatch.setattr(isochrone_fast._Usage, "cached", False)
    auto = with_engine(SET, "auto")
    assert not isochrone_fast.compiled(auto, np)  # one plan, nothing compiled: NumPy
    assert isochrone_fast.compiled(auto, np, members=2)  # a batch pays for it
    assert not isochrone_fast.compiled(with_engine(SET, "numpy"), np, members=2)
    monkeypatch.setattr(isochrone_fast._Usage, "numpy_s", isochrone_fast.JIT_AFTER_S)
    assert isochrone_fast.compiled(auto, np)
    assert not isochrone_fast.compiled(auto, object())  # another array module
    monkeypatch.setattr(isochrone_fast._Usage, "numpy_s", 0.0)
    monkeypatch.setattr(isochrone_fast._Usage, "cached", True)
    assert isochrone_fast.compiled(auto, np)  # compiled before: loading them pays


def test_kernels_count_as_cached_only_when_every_step_kernel_is_in_numbas_index(
    monkeypatch, tmp_path
):
    from sailroute.routing import isochrone_jit

    monkeypatch.setattr(isochrone_fast._Usage, "kernels", isochrone_fast._just_in_time())
    both(LINE, MARK, UniformWind(4.4, 0.0), SET)  # compiles the step kernels, or loads them
    with monkeypatch.context() as m:
        m.setattr(isochrone_fast, "_numba_bytecode", lambda: True)
        assert isochrone_fast._jit_kernels_in_cache()
        stale = getattr(isochrone_jit, isochrone_fast.STEP_KERNELS[-1])._cache._cache_file
        m.setattr(stale, "_load_index", dict)  # numba's answer for a stale index
        assert not isochrone_fast._jit_kernels_in_cache()
    with monkeypatch.context() as m:
        m.setattr(isochrone_fast, "_numba_bytecode", lambda: True)
        m.delenv("NUMBA_CACHE_DIR", raising=False)
        m.setattr(isochrone_fast, "_PYCACHE", tmp_path)  # nothing compiled there
        assert isochrone_fast._cache_folder() == tmp_path
        assert not isochrone_fast._step_kernels_in_cache()
    with monkeypatch.context() as m:
        m.setenv("NUMBA_CACHE_DIR", str(tmp_path))  # numba's own rule for the folder
        sub = numba.core.caching._CacheLocator.get_suitable_cache_subpath(isochrone_jit.__file__)
        assert isochrone_fast._cache_folder() == tmp_path / sub
        assert not isochrone_fast._step_kernels_in_cache()
    with monkeypatch.context() as m:
        m.setattr(sys, "pycache_prefix", str(tmp_path))  # no .pyc of numba: from source
        m.setattr(isochrone_fast, "_PYCACHE", tmp_path)  # and no module compiled ahead
        assert not isochrone_fast._numba_bytecode()
        assert not isochrone_fast._step_kernels_in_cache()


def test_numba_starts_with_the_collector_paused_and_leaves_it_as_it_was(monkeypatch):
    import gc

    import sailroute.jit
    from sailroute.routing import isochrone_jit

    real, seen = sailroute.jit.load_registries, []

    def load() -> None:
        seen.append(gc.isenabled())
        real()

    monkeypatch.setattr(sailroute.jit, "load_registries", load)
    for enabled in (True, False):
        monkeypatch.setattr(isochrone_fast._Usage, "jit", None)
        (gc.enable if enabled else gc.disable)()
        try:
            assert isochrone_fast._just_in_time() is isochrone_jit
            assert gc.isenabled() is enabled
        finally:
            gc.enable()
    assert seen == [False, False]


@pytest.mark.usefixtures("compiled_kernels")
@pytest.mark.parametrize(
    "wind",
    [UniformWind(0.0, 0.0), gridded_wind(clamp=True)],
    ids=["calm", "gridded"],
)
def test_members_winds_in_one_compiled_pass_are_numpys_bit_for_bit(wind):
    # sample_perturbed's arithmetic compiled: scaled, added to (down to a calm),
    # turned by a constant offset and by a shift series; the base itself as a member
    from sailroute.wind.perturbed import PerturbedWind, sample_perturbed

    times = T0 + np.arange(0.0, 3600.0, 10.0)
    winds = [
        wind,
        PerturbedWind(wind, speed_scale=1.1),
        PerturbedWind(wind, speed_add_ms=-0.7, direction_offset_deg=-5.0),
        PerturbedWind(wind, shift_times=times, shift_deg=6.0 * np.sin(times / 300.0)),
        PerturbedWind(wind, speed_scale=0.9, speed_add_ms=-9.0),
        PerturbedWind(wind, speed_add_ms=0.3, direction_offset_deg=12.5),
    ]
    rng = np.random.default_rng(5)
    which = rng.integers(0, len(winds), 2000)
    t = T0 + rng.uniform(0.0, 3600.0, 2000)
    x, y = rng.uniform(-900.0, 900.0, (2, 2000))
    kernel = isochrone_fast.kernels().perturbed_winds
    for members in (winds, winds[:3], winds[1:2]):  # with and without a series, one member
        w = which % len(members)
        got = sample_perturbed(members, w, t, x, y, compiled=kernel)
        want = sample_perturbed(members, w, t, x, y)
        np.testing.assert_array_equal(got[0], want[0])
        np.testing.assert_array_equal(got[1], want[1])
