"""Leg-time bands (plan --ensemble N): members, bands, the breakdown by source, honest sides."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from sailroute.bands.members import (
    NOMINAL,
    Member,
    draw_members,
    member_wind,
    one_at_a_time,
    resolve_shifts,
)
from sailroute.bands.route import spec_for
from sailroute.bands.sides import honest_side
from sailroute.bands.summary import BandSummary
from sailroute.cli import app
from sailroute.commands.bands import run_bands_command
from sailroute.course.load import load_course
from sailroute.course.specs import build_boat
from sailroute.course.uncertainty import UncertaintySpec, uncertainty_from_mapping
from sailroute.errors import InputError
from sailroute.planning.route import plan_course
from sailroute.routing.sides import layline_times, side_verdict
from sailroute.units import KNOT
from sailroute.wind.perturbed import PerturbedWind
from sailroute.wind.uniform import UniformWind
from tests.conftest import ROOT

TEMPLATE = yaml.safe_load((ROOT / "courses" / "windward-leeward-template.yaml").read_text())
FAST = {
    "router": "isochrone",
    "tack_penalty_s": 5.0,
    "gybe_penalty_s": 3.0,
    "dt_s": 10.0,
    "heading_step_deg": 4.0,
}


def beat_course(tmp_path: Path, uncertainty: dict | None = None, twd: float = 270.0) -> Path:
    """One windward-leeward lap, 600 m legs, coarse routing: about 1 s per member."""
    data = {k: v for k, v in TEMPLATE.items() if k != "scenarios"}
    data["template"] = {**data["template"], "laps": 1, "leg_length_m": 600}
    data["routing"] = FAST
    data["scenarios"] = {"steady": {"type": "uniform", "tws_kn": 12, "twd_deg": twd}}
    if uncertainty is not None:
        data["uncertainty"] = uncertainty
    p = tmp_path / "beat.yaml"
    p.write_text(yaml.safe_dump(data, sort_keys=False))
    return p


def reach_course(tmp_path: Path, uncertainty: dict) -> Path:
    """One 800 m beam reach east, wind from the north."""
    data = {
        "name": "reach",
        "start_time": "2024-05-01T10:00:00Z",
        "origin": {"lat": 45.0, "lon": 13.0},
        "marks": {"a": {"x": 0.0, "y": 0.0}, "b": {"x": 800.0, "y": 0.0}},
        "legs": [{"from": "a", "to": "b", "rounding": "port"}],
        "routing": FAST,
        "scenarios": {"north": {"type": "uniform", "tws_kn": 10, "twd_deg": 0}},
        "uncertainty": uncertainty,
    }
    p = tmp_path / "reach.yaml"
    p.write_text(yaml.safe_dump(data, sort_keys=False))
    return p


# --- the wrapper wind --------------------------------------------------------------------


def test_perturbed_wind_scales_adds_and_veers_analytically() -> None:
    base = UniformWind(5.0, 270.0)  # from the west: air moves east, (u, v) = (5, 0)
    w = PerturbedWind(base, speed_scale=1.2, speed_add_ms=0.5, direction_offset_deg=90.0)
    u, v = w.sample(0.0, 0.0, 0.0)
    # speed 1.2 * 5 + 0.5 = 6.5, from 360 (north): air moves south
    assert float(u) == pytest.approx(0.0, abs=1e-12)
    assert float(v) == pytest.approx(-6.5)
    shifted = PerturbedWind(
        base, shift_times=np.array([0.0, 100.0]), shift_deg=np.array([0.0, 20.0])
    )
    np.testing.assert_allclose(shifted.turn_deg([0.0, 50.0, 100.0, 500.0]), [0, 10, 20, 20])
    with pytest.raises(InputError, match="2 shift times but 1 shifts"):
        PerturbedWind(base, shift_times=np.array([0.0, 1.0]), shift_deg=np.array([1.0]))


# --- members ------------------------------------------------------------------------------


SPEC = UncertaintySpec(
    tws_add_ms=1.5 * KNOT, twd_deg=10.0, members=12, seed=3, boat=(("sea_age_h", 2.0, 4.0),)
)


def test_same_seed_same_members_and_latin_hypercube_strata() -> None:
    a = draw_members(SPEC, 3600.0)
    assert a == draw_members(SPEC, 3600.0)
    assert a != draw_members(SPEC, 3600.0, seed=4)
    # one member per probability stratum of each source: the sea ages fall one in each
    # twelfth of [2, 4] h
    ages = np.sort([dict(m.boat)["sea_age_h"] for m in a])
    assert np.all(np.floor((ages - 2.0) / (2.0 / 12)) == np.arange(12))
    assert sorted(m.name for m in a) == sorted(f"m{k}" for k in range(1, 13))


def test_shift_members_are_deterministic_and_fitted_from_measured_wind() -> None:
    osc = uncertainty_from_mapping(
        {"shifts": {"model": "oscillating", "amplitude_deg": 8, "period_min": 6}, "members": 4}
    )
    a = draw_members(osc, 1200.0)
    assert a == draw_members(osc, 1200.0)
    for m in a:  # amplitude 8°, one value every 10 s over the 20 min
        assert len(m.shift_deg) == 121 and max(np.abs(m.shift_deg)) <= 8.0 + 1e-9
    ou = resolve_shifts(
        uncertainty_from_mapping(
            {"shifts": {"fit": "trieste-coach-2018-02-15.csv", "speed_unit": "kn"}},
            base_dir=ROOT / "data",
        )
    )
    assert ou.shifts is not None and ou.shifts.model == "ou"
    # the Trieste coach boat's directions (docs/strategy.md): 28.4° and 1.9 min
    assert ou.shifts.sigma_deg == pytest.approx(28.4, abs=0.1)
    assert ou.shifts.timescale_s / 60 == pytest.approx(1.9, abs=0.1)
    b = draw_members(ou, 600.0)
    assert b == draw_members(ou, 600.0)
    # the OU paths keep the stationary spread (40 members x 61 values)
    many = draw_members(
        uncertainty_from_mapping(
            {"shifts": {"model": "ou", "sigma_deg": 10, "timescale_min": 3}, "members": 40}
        ),
        600.0,
    )
    assert np.std([m.shift_deg for m in many]) == pytest.approx(10.0, rel=0.15)
    with pytest.raises(InputError, match=r"uncertainty\.shifts\.fit: no station CSV at "):
        uncertainty_from_mapping({"shifts": {"fit": "nowhere.csv"}}, base_dir=ROOT)


def test_one_at_a_time_varies_only_its_source() -> None:
    oat = one_at_a_time(SPEC, 3600.0)
    assert list(oat) == ["tws", "twd", "boat.sea_age_h"]
    for m in oat["twd"]:
        assert (m.tws_add_ms, m.boat, m.shift_deg) == (0.0, (), ())
    # the 10th and 90th percentiles of a 10° (1 sigma) offset: ±12.8°
    offs = [m.twd_offset_deg for m in oat["twd"]]
    np.testing.assert_allclose(offs, [-12.8155, 0.0, 12.8155], atol=1e-3)
    base = UniformWind(5.0, 0.0)
    assert member_wind(base, NOMINAL, 0.0) is base


# --- bands --------------------------------------------------------------------------------


def test_bands_are_ordered_percentiles_of_the_members() -> None:
    rng = np.random.default_rng(0)
    times = rng.uniform(100.0, 200.0, size=(9, 3))
    b = BandSummary(
        "s",
        ("a", "b", "c"),
        tuple(f"m{k}" for k in range(9)),
        times,
        times.mean(axis=0),
        oat_s={"tws": times[:3], "twd": times[3:6] * 0 + 150},
    )
    bd = b.bands()
    assert bd.shape == (4, 3)
    assert np.all(bd[:, 0] <= bd[:, 1]) and np.all(bd[:, 1] <= bd[:, 2])
    np.testing.assert_allclose(bd[-1], np.percentile(times.sum(axis=1), [10, 50, 90]))
    # "twd" has zero width: "tws" widens every leg most
    assert b.dominant() == ["tws"] * 4
    assert b.oat_widths()["twd"].tolist() == [0.0] * 4
    share, inside = b.coverage(bd[:-1, 1])
    assert share == 1.0 and inside.all()


def test_uniform_speed_members_follow_the_closed_form_reach_time(tmp_path) -> None:
    path = reach_course(tmp_path, {"tws_kn": 1.5, "members": 5, "seed": 2})
    c = load_course(path)
    res = run_bands_command(c, out_dir=tmp_path / "out", plots=False)
    (b,) = res.data
    boat = build_boat(c)
    members = draw_members(c.uncertainty, c.time_limit_s)
    tws = 10 * KNOT + np.array([m.tws_add_ms for m in members])
    # a beam reach is sailed straight: time = L / polar speed (the router's 10 s steps
    # end at the mark within a fraction of a step)
    expected = 800.0 / boat.speed(tws, 90.0)
    np.testing.assert_allclose(b.times_s[:, 0], expected, rtol=0.01)
    # faster wind -> shorter time: the members' order is the reverse of their speeds'
    assert np.argsort(b.times_s[:, 0]).tolist() == np.argsort(-tws).tolist()
    bd = b.bands()
    assert np.all(bd[:, 0] <= bd[:, 1]) and np.all(bd[:, 1] <= bd[:, 2])
    assert b.nominal_s[0] == pytest.approx(800.0 / float(boat.speed(10 * KNOT, 90.0)), rel=0.01)
    doc = json.loads((tmp_path / "out" / "bands.json").read_text())
    leg = doc["scenarios"][0]["legs"][0]
    assert leg["time_s"]["p10"] == pytest.approx(bd[0, 0])
    assert leg["widest_source"] == "tws"
    assert doc["scenarios"][0]["uncertainty"]["tws_add_sd_ms"] == pytest.approx(1.5 * KNOT)


def test_default_uncertainty_is_stated(tmp_path) -> None:
    c = load_course(beat_course(tmp_path))
    spec, notes = spec_for(c, 4)
    assert spec.members == 4 and spec.sources() == ("tws", "twd", "shifts")
    assert "no `uncertainty:` section" in notes[0]


# --- bad input ----------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("raw", "key", "message"),
    [
        ({"tws_knots": 1}, "uncertainty.tws_knots", "unknown key; did you mean 'tws_kn'?"),
        ({"twd_deg": -3}, "uncertainty.twd_deg", "expected a number in [0, 90]; got -3"),
        ({"members": 2}, "uncertainty.members", "expected a whole number >= 3; got 2"),
        ({"shifts": {"model": "wobbly"}}, "uncertainty.shifts.model", "expected one of"),
        (
            {"shifts": {"model": "oscillating", "amplitude_deg": 5}},
            "uncertainty.shifts.period_min",
            "missing required key",
        ),
        ({"boat": {"sea_age": [2, 4]}}, "uncertainty.boat.sea_age", "did you mean 'sea_age_h'"),
        ({"boat": {"sea_age_h": [4, 2]}}, "uncertainty.boat.sea_age_h", "low <= high"),
        ({"tws_kn": 1, "tws_pct": 5}, "uncertainty.tws_pct", "give one of tws_kn, tws_ms, tws_pct"),
    ],
)
def test_bad_uncertainty_keys_are_one_line_errors_naming_the_key(
    tmp_path, raw, key, message
) -> None:
    with pytest.raises(InputError) as e:
        load_course(beat_course(tmp_path, raw))
    text = str(e.value)
    assert "\n" not in text
    assert f": {key}: " in text and message in text
    assert text.startswith(str(tmp_path / "beat.yaml") + ":")
    with pytest.raises(InputError, match=key.replace(".", r"\.")):
        uncertainty_from_mapping(raw)


def test_boat_parameters_need_a_race_polar(tmp_path) -> None:
    p = beat_course(tmp_path, {"boat": {"sea_age_h": [2, 4]}, "members": 3})
    data = yaml.safe_load(p.read_text())
    data["boat"] = {"builtin": "ilca7-steady"}
    p.write_text(yaml.safe_dump(data))
    with pytest.raises(
        InputError,
        match=r"uncertainty\.boat: race-polar parameters need a "
        "race polar",
    ):
        run_bands_command(p, out_dir=tmp_path / "o", plots=False)
    assert not (tmp_path / "o" / "bands.json").exists()


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (
            ["plan", "--ensemble", "2"],
            "error: --ensemble 2: a band needs at least 3 members; give N >= 3",
        ),
        (
            ["compare-scenarios", "--ensemble", "3", "--scheduler", "processes"],
            "error: --scheduler processes: --ensemble routes its members here",
        ),
    ],
)
def test_cli_ensemble_option_bad_values_exit_2_and_write_nothing(tmp_path, args, message) -> None:
    r = CliRunner().invoke(
        app, [args[0], str(beat_course(tmp_path)), *args[1:], "-q", "-o", str(tmp_path / "o")]
    )
    assert r.exit_code == 2
    assert message in r.output
    assert not (tmp_path / "o").exists()


def test_cli_plan_ensemble_writes_the_bands_and_prints_them_as_json(tmp_path) -> None:
    out = tmp_path / "o"
    course = beat_course(tmp_path, {"tws_kn": 1.0, "twd_deg": 5.0, "members": 8})
    r = CliRunner().invoke(
        app, ["plan", str(course), "--ensemble", "3", "-q", "-o", str(out), "--json", "--no-plots"]
    )
    assert r.exit_code == 0, r.output
    doc = json.loads(r.stdout)
    assert doc == json.loads((out / "bands.json").read_text())
    (sc,) = doc["scenarios"]
    assert sc["members"] == ["m1", "m2", "m3"] and len(sc["legs"]) == 2
    assert set(sc["total"]["width_by_source_s"]) == {"tws", "twd"}
    assert sc["uncertainty"]["twd_sd_deg"] == 5.0
    for leg in [*sc["legs"], sc["total"]]:
        t = leg["time_s"]
        assert t["p10"] <= t["p50"] <= t["p90"]
    assert not (out / "bands.png").exists()
    rows = list(csv.DictReader((out / "bands.csv").open()))
    assert [r["leg"] for r in rows] == ["1", "2", "total"]
    assert float(rows[-1]["width_tws_s"]) == pytest.approx(
        sc["total"]["width_by_source_s"]["tws"], abs=1e-3
    )


@pytest.mark.slow
def test_bands_page_and_chart(tmp_path) -> None:
    c = load_course(beat_course(tmp_path, {"tws_kn": 1.0, "members": 3}))
    res = run_bands_command(c, out_dir=tmp_path / "o")
    page = res.files["html"].read_text()
    assert "Leg-time bands, steady: 3 members; TWS ±1 kn" in page
    assert res.files["bands_png"].read_bytes()[:4] == b"\x89PNG"


# --- sides --------------------------------------------------------------------------------


def test_side_verdict_margin() -> None:
    assert side_verdict("right", 600.0, 603.0, 590.0) == "tie"  # 3 s < 0.5 % of 600 s
    assert side_verdict("right", 600.0, 604.0, 590.0) == "right"
    assert side_verdict("left", 100.0, 100.0, 101.9) == "tie"  # under the 2 s floor
    assert side_verdict("middle", 600.0, 640.0, 650.0) == "middle"
    assert side_verdict("left", 600.0, 600.0, float("inf")) == "left"  # no evidence


def test_steady_beat_is_a_tie_and_a_persistent_right_shift_pays_right(tmp_path) -> None:
    c = load_course(beat_course(tmp_path))
    boat = build_boat(c)
    run = plan_course(c)
    beat = run.plan.legs[0].result
    t_left, t_right = layline_times(
        beat.start_xy, beat.end_xy, beat.t_start, run.wind, boat, tack_penalty_s=5.0
    )
    assert t_left == pytest.approx(t_right, abs=0.5)  # the same parallelogram
    assert honest_side(beat, run.wind, boat, tack_penalty_s=5.0) == "tie"
    # the wind veers 1.5° per minute from the start: go right, towards the new wind
    t0 = c.start_epoch
    veer = Member("veer", shift_t_s=(0.0, 3600.0), shift_deg=(0.0, 90.0))
    wind = member_wind(run.wind, veer, t0)
    from sailroute.planning.route import route_course

    legs = route_course(c, wind, boat, c.routing)
    t_left, t_right = layline_times(
        legs[0].start_xy, legs[0].end_xy, legs[0].t_start, wind, boat, tack_penalty_s=5.0
    )
    assert t_right < t_left - 10.0
    assert honest_side(legs[0], wind, boat, tack_penalty_s=5.0) == "right"
