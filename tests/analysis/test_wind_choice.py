"""Which wind a leg is judged in, the above-polar flag, and the fleet-relative polar.

The tracks are sailroute's own routes (tests/analysis/test_analyze.py), so the right
answers are known: a track sailed on the optimal route loses nothing in the wind it
was routed in, and a track sailed 25 % faster than the polar is 125 % of it.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from sailroute.analysis.debrief import analyze_track, fleet_reference
from sailroute.analysis.fleetpolar import band_factors
from sailroute.analysis.windsource import WindSource, first_covering, wind_order
from sailroute.commands.analyze import run_analyze_command
from sailroute.course.load import build_specs
from sailroute.course.model import Course
from sailroute.errors import InputError, OutOfCoverageError
from sailroute.routing.types import LegResult
from sailroute.track.model import Track
from sailroute.units import KNOT, wind_speed_direction
from sailroute.wind.combine import SpeedDirectionWind
from sailroute.wind.uniform import UniformWind
from tests.analysis import test_analyze as wl
from tests.analysis.test_analyze import LOSS_TOL_S, _sailed
from tests.conftest import ROOT

routed = wl.routed  # the module fixture: the routed windward-leeward course

SCENARIO = UniformWind(10 * KNOT, 0.0)


def _faster(track: Track, factor: float, gun: float) -> Track:
    """The same path sailed ``factor`` times faster (time compressed about the gun)."""
    t0 = gun
    return Track(
        t0 + (track.t_s - t0) / factor, track.lat_deg, track.lon_deg, track.name, track.source
    )


def test_speed_from_one_field_direction_from_another() -> None:
    a = UniformWind([4.0, 6.0], [90.0, 90.0], times=[0.0, 100.0])
    b = UniformWind(1.0, 200.0)
    w = SpeedDirectionWind(a, b)
    s, d = wind_speed_direction(*w.sample(np.array([0.0, 50.0, 100.0]), 0.0, 0.0))
    np.testing.assert_allclose(s, [4.0, 5.0, 6.0], atol=1e-12)
    np.testing.assert_allclose(d, 200.0, atol=1e-9)
    assert (w.coverage.t0, w.coverage.t1) == (0.0, 100.0)
    with pytest.raises(OutOfCoverageError):
        w.sample(101.0, 0.0, 0.0)


def test_wind_order_best_first_and_a_missing_kind_is_a_clear_error() -> None:
    scen = WindSource("scenario", SCENARIO, "scenario 'steady'")
    inf = WindSource("inferred", SCENARIO, "inferred")
    own = WindSource("measured", SCENARIO, "measured on board")
    assert [s.kind for s in wind_order("auto", [scen, inf, own])] == [
        "measured",
        "inferred",
        "scenario",
    ]
    assert [s.kind for s in wind_order("scenario", [scen, inf, own])] == ["scenario"]
    with pytest.raises(InputError, match="wind columns"):
        wind_order("measured", [scen, inf])
    with pytest.raises(InputError, match="--wind: expected one of"):
        wind_order("guess", [scen])
    with pytest.raises(ValueError):
        WindSource("forecast", SCENARIO, "x")


def test_first_covering_skips_a_field_with_a_hole() -> None:
    short = WindSource("measured", UniformWind([5.0, 5.0], [0.0, 0.0], times=[0.0, 10.0]), "m")
    scen = WindSource("scenario", SCENARIO, "s")
    t = np.array([0.0, 5.0, 20.0])
    assert first_covering([short, scen], t, t * 0, t * 0) == 1
    assert first_covering([short, scen], t[:2], t[:2] * 0, t[:2] * 0) == 0
    assert first_covering([short], t, t * 0, t * 0) is None


def test_each_leg_is_judged_in_the_first_wind_that_covers_it(
    routed: tuple[Course, list[LegResult]],
) -> None:
    course, legs = routed
    track = _sailed(course, legs)
    base = analyze_track(course, track, wind="scenario")
    # "measured" = the scenario's wind, but its log ends during leg 2
    t_end = 0.5 * (legs[1].t_start + legs[1].t_end)
    measured = UniformWind([10 * KNOT] * 2, [0.0, 0.0], times=[track.t_s[0], t_end])
    srcs = [
        WindSource("measured", measured, "measured on board"),
        WindSource("scenario", SCENARIO, "scenario 'steady'"),
    ]
    a = analyze_track(course, track, winds=srcs)
    assert [leg.wind_source for leg in a.legs] == ["measured", "scenario", "scenario"]
    assert a.legs[0].wind_label == "measured on board"
    for leg, ref in zip(a.legs, base.legs, strict=True):
        assert leg.loss_s == pytest.approx(ref.loss_s, abs=1e-9)
    with pytest.raises(OutOfCoverageError, match="leg 2"):
        analyze_track(course, track, winds=srcs[:1])


def test_a_boat_above_its_polar_is_flagged(routed: tuple[Course, list[LegResult]]) -> None:
    course, legs = routed
    a = analyze_track(course, _faster(_sailed(course, legs), 1.25, course.start_epoch))
    for leg in a.legs:
        assert leg.mean_polar_pct == pytest.approx(125.0, abs=6.0)
        assert leg.above_polar
    b = analyze_track(course, _sailed(course, legs))
    assert not any(leg.above_polar for leg in b.legs)


def test_band_factors_take_the_percentile_per_point_of_sail() -> None:
    twa = np.concatenate([np.full(100, 42.0), np.full(100, -150.0), np.full(5, 95.0)])
    ratio = np.concatenate([np.linspace(0.8, 1.0, 100), np.full(100, 1.3), np.full(5, 2.0)])
    f, n = band_factors(twa, ratio, percentile=75.0, min_count=30)
    assert list(n) == [100, 5, 100]
    assert f[0] == pytest.approx(np.percentile(np.linspace(0.8, 1.0, 100), 75))
    assert f[2] == pytest.approx(1.3)
    assert f[1] == pytest.approx(0.5 * (f[0] + f[2]))  # too few reach points: the mean
    with pytest.raises(InputError, match="no point of sail has 30"):
        band_factors(twa[:5], ratio[:5], min_count=30)
    with pytest.raises(InputError, match="percentile"):
        band_factors(twa, ratio, percentile=0.0)


def test_a_fleet_relative_polar_judges_a_fast_boat_against_itself(
    routed: tuple[Course, list[LegResult]],
) -> None:
    course, legs = routed
    fast = _faster(_sailed(course, legs), 1.25, course.start_epoch)
    boat, winds = build_specs(course, ["steady"])
    first = analyze_track(course, fast)
    assert all(leg.loss_s < -0.1 * leg.sailed_time_s for leg in first.legs)  # "gains"
    fp = fleet_reference([first], boat.routing_polar())
    assert fp.count[0] > 100 and fp.count[2] > 100  # a beat and a run
    np.testing.assert_allclose(fp.factor, 1.25, atol=0.04)
    again = analyze_track(course, fast, built=(fp.polar, winds["steady"]))
    for leg in again.legs:
        # the optimal route at 1.25x polar speed is the sailed one, up to the manoeuvre
        # penalties (fixed in seconds, compressed in the track) and 1 Hz crossings
        assert abs(leg.loss_s) <= LOSS_TOL_S + 3.0, (leg.label, leg.loss_s)
        assert leg.mean_polar_pct == pytest.approx(100.0, abs=5.0)
        assert not leg.above_polar
    assert "fleet-relative polar" in fp.describe()


def test_a_manoeuvre_window_costs_its_time_beyond_straight_sailing_and_never_gains() -> None:
    from sailroute.analysis.loss import split_loss, window_costs

    dt = np.ones(10)
    # straight at 2 m/s, a window of 3 s making 2 m (cost 3 - 2/2 = 2 s), straight again
    dprog = np.array([2, 2, 2, 1, 0.5, 0.5, 2, 2, 2, 2], float)
    win = np.array([0, 0, 0, 1, 1, 1, 0, 0, 0, 0], bool)
    np.testing.assert_allclose(window_costs(dt, dprog, win, 2.0), [2.0])
    # a window faster than the straight-line reference: 0, not a gain
    fast = np.array([1, 1, 1, 3, 3, 3, 1, 1, 1, 1], float)
    np.testing.assert_allclose(window_costs(dt, fast, win, 1.0), [0.0])
    # two windows are two costs
    win2 = np.array([1, 1, 0, 0, 0, 0, 0, 1, 1, 0], bool)
    assert window_costs(dt, dprog, win2, 2.0).shape == (2,)
    # three sailed tacks, each at least as slow as straight sailing, against the optimum's
    # one tack of 5 s: the manoeuvre part is never below -5 s, here 0 + 0 + 0 - 5
    t = np.arange(0.0, 121.0)
    prog = 1.0 * t
    s = split_loss(t, prog, np.ones(t.size), np.array([20.0, 60.0, 100.0]), 10.0, 5.0)
    assert s.manoeuvres == pytest.approx(-5.0)
    assert s.manoeuvres + s.speed + s.route == pytest.approx(10.0)


SNIPE_COURSE = ROOT / "courses" / "snipe-valencia-p01.yaml"
SNIPE_TRACK = ROOT / "data" / "snipe-valencia-2025-06-21-ESP30782-P01.gpx"


def test_the_snipe_example_is_judged_in_the_inferred_wind_and_its_polar_called_out(
    tmp_path: Path,
) -> None:
    # a GPS watch track: no wind in the log, so the direction is inferred from the track;
    # the ILCA polar stands in for the faster Snipe: every leg is flagged
    r = run_analyze_command(SNIPE_COURSE, [SNIPE_TRACK], out_dir=tmp_path / "abs")
    a = r.data[0]
    assert [leg.wind_source for leg in a.legs] == ["inferred"] * 4
    assert all(leg.above_polar for leg in a.legs)
    assert "sailed above 110 % of the polar" in r.report
    assert any(n.startswith("inferred wind: TWD 1") for n in r.notes)
    doc = json.loads(r.files["analysis_json"].read_text())
    assert all(leg["above_polar"] and leg["wind"]["source"] == "inferred" for leg in doc["legs"])
    assert doc["reference"].startswith("course polar")
    page = r.files["html"].read_text()
    assert "Sailed above 110 % of the polar" in page and "inferred" in page
    # against what this fleet (one boat) sails: no leg is a big "gain" any more
    f = run_analyze_command(
        SNIPE_COURSE, [SNIPE_TRACK], out_dir=tmp_path / "fleet", reference="fleet", plots=False
    )
    b = f.data[0]
    assert b.reference.startswith("fleet-relative polar")
    for leg in b.legs:
        assert leg.loss_s >= -0.02 * leg.sailed_time_s, (leg.label, leg.loss_s)
        assert not leg.above_polar


def test_asking_for_a_wind_the_data_do_not_hold_is_a_clear_error(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="--wind measured: no track has usable wind columns"):
        run_analyze_command(
            SNIPE_COURSE, [SNIPE_TRACK], out_dir=tmp_path / "o", wind="measured", plots=False
        )
    assert not (tmp_path / "o").exists()
    with pytest.raises(InputError, match="--reference: expected one of course, fleet, learned"):
        run_analyze_command(
            SNIPE_COURSE, [SNIPE_TRACK], out_dir=tmp_path / "p", reference="peers", plots=False
        )
