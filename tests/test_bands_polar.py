"""Leg-time bands of a course whose boat is a polar learned from a fleet: the members draw
the table from its uncertainty (``sailroute.bands.members``, ``polar`` source)."""

from __future__ import annotations

import json
from pathlib import Path
from types import MappingProxyType

import numpy as np
import pytest
import yaml
from scipy.special import ndtr, ndtri

from sailroute.analysis.racepace import pace_scatter
from sailroute.bands.members import draw_members, member_boat, one_at_a_time
from sailroute.bands.route import spec_for
from sailroute.boat.build import builtin_polar
from sailroute.boat.learn import LearnedPolar, LevelTable, PolarDraw
from sailroute.boat.learnfile import read_learned, write_learned
from sailroute.commands.bands import run_bands_command
from sailroute.course.load import load_course
from sailroute.report.bands import bands_table
from tests.test_bands import reach_course

MODE_SD = 0.04  # the one bootstrap mode: the whole table together [log speed]
PACE_SD = 0.03  # the legs' scatter about the race pace [log speed]
TWA = np.arange(30.0, 181.0, 15.0)
TWS = np.array([3.0, 5.0, 7.0])


def learned(pace: tuple[float, float, float] = (0.9, 0.8, 0.95)) -> LearnedPolar:
    """A learned table whose only uncertainty is one mode moving every cell together."""
    speed = builtin_polar("ilca7-steady").speed(TWS[None, :], TWA[:, None])
    shape = speed.shape
    t = LevelTable(
        "median", 50.0, speed, np.full(shape, MODE_SD), speed * 0.95, speed * 1.05,
        np.full((1, *shape), MODE_SD), np.zeros(shape), np.full(3, np.nan), np.full(3, np.nan),
        pace, PACE_SD,
    )  # fmt: skip
    return LearnedPolar(
        "fleet", TWA, TWS, MappingProxyType({"median": t}),
        np.full(shape, 9), np.full(shape, 3), np.full(shape, 180.0),
        np.full(shape, "learned").astype(np.str_), (), (), MappingProxyType({}),
    )  # fmt: skip


def reach(tmp_path: Path, boat: dict, uncertainty: dict) -> Path:
    """The 800 m beam reach of ``tests/test_bands.py`` (10 kn from the north), its boat a
    learned polar."""
    write_learned(learned(), tmp_path / "fleet.json")
    p = reach_course(tmp_path, uncertainty)
    data = yaml.safe_load(p.read_text())
    data["boat"] = {"polar": "fleet.json", **boat}
    p.write_text(yaml.safe_dump(data, sort_keys=False))
    return p


def test_the_file_keeps_the_pace_scatter(tmp_path: Path) -> None:
    back = read_learned(write_learned(learned(), tmp_path / "fleet.json"))
    assert back.levels["median"].pace_sd_log == pytest.approx(PACE_SD)


def test_a_draw_moves_the_table_by_its_modes_rest_and_pace() -> None:
    t = learned().levels["median"]
    d = PolarDraw(modes_z=(1.5,), pace_z=-2.0)
    np.testing.assert_allclose(d.log_offset(t), 1.5 * MODE_SD - 2.0 * PACE_SD)
    q = PolarDraw(quantile_z=1.0)  # every cell at one sd of bootstrap and pace together
    np.testing.assert_allclose(q.log_offset(t), np.hypot(MODE_SD, PACE_SD))


def test_members_draw_the_learned_polar_and_the_reach_time_follows(tmp_path: Path) -> None:
    c = load_course(reach(tmp_path, {"level": "median", "pace": "race"}, {"members": 7}))
    spec, notes = spec_for(c)
    assert spec.sources() == ("polar",)
    assert spec.polar is not None and spec.polar.pace_sd_log == pytest.approx(PACE_SD)
    assert any("fleet.json, level median" in n for n in notes)
    members = draw_members(spec, c.time_limit_s)
    assert members == draw_members(spec, c.time_limit_s)  # the seed fixes the draws
    # Latin hypercube on the first mode: one member in each seventh of its distribution
    u = ndtr(np.array([m.polar.modes_z[0] for m in members]))
    assert sorted(np.floor(u * 7).astype(int).tolist()) == list(range(7))
    res = run_bands_command(c, out_dir=tmp_path / "out", plots=False)
    (b,) = res.data
    # a beam reach is sailed straight: time = L / (reach pace x drawn speed); one mode
    # moving every cell together and the pace factor scale the whole table
    nominal = 800.0 / (0.8 * float(builtin_polar("ilca7-steady").speed(10 * 0.514444, 90.0)))
    scale = np.array(
        [np.exp(MODE_SD * m.polar.modes_z[0] + PACE_SD * m.polar.pace_z) for m in members]
    )
    np.testing.assert_allclose(b.times_s[:, 0], nominal / scale, rtol=0.01)
    # the one-at-a-time polar members: every cell at its P10 / P50 / P90
    z90 = float(ndtri(0.9))
    width = nominal * (
        np.exp(z90 * np.hypot(MODE_SD, PACE_SD)) - np.exp(-z90 * np.hypot(MODE_SD, PACE_SD))
    )
    assert b.oat_widths()["polar"][0] == pytest.approx(width, rel=0.02)
    doc = json.loads((tmp_path / "out" / "bands.json").read_text())["scenarios"][0]
    assert doc["uncertainty"]["polar"]["level"] == "median"
    assert doc["legs"][0]["widest_source"] == "polar"
    assert "polar" in bands_table(b).split("width by source")[1]


def test_the_polar_source_sits_beside_the_wind_and_can_be_switched_off(tmp_path: Path) -> None:
    c = load_course(reach(tmp_path, {}, {"tws_kn": 1, "members": 5}))
    spec, _ = spec_for(c)
    assert spec.sources() == ("tws", "polar")
    oat = one_at_a_time(spec, c.time_limit_s)
    assert [m.polar for m in oat["tws"]] == [None] * 3
    assert [m.polar.quantile_z for m in oat["polar"]] == pytest.approx(
        [-1.2816, 0.0, 1.2816], abs=1e-4
    )
    # a member's boat is the drawn table (steady pace: no race scaling)
    m = draw_members(spec, c.time_limit_s)[0]
    boat = member_boat(c.boat_spec, None, m, base_dir=c.base_dir, where="c")
    want = np.exp(MODE_SD * m.polar.modes_z[0] + PACE_SD * m.polar.pace_z)
    assert float(boat.speed(5.0, 90.0)) == pytest.approx(
        want * float(learned().polar("median").speed(5.0, 90.0)), rel=1e-6
    )
    off = load_course(reach(tmp_path, {}, {"tws_kn": 1, "members": 5, "polar": False}))
    assert spec_for(off)[0].sources() == ("tws",)


def test_pace_scatter_is_the_robust_sd_of_the_legs_log_factors() -> None:
    # legs whose own factors are 0.9 x e^{0.1, -0.1, 0, 0, 0}, and one leg three times
    # too long (a start sailed in the leg): the absolute deviations 0.1, 0.1, 0, 0, 0 and
    # 1.1 have the median 0.05; the long leg does not widen it
    sailed = np.array([100.0, 100.0, 200.0, 200.0, 100.0, 100.0])
    f = 0.9 * np.exp(np.array([0.1, -0.1, 0.0, 0.0, 0.0, 0.0]))
    route = f * sailed
    sailed[-1] *= 3.0
    band = np.array([0, 0, 2, 2, 0, 0])
    sd = pace_scatter(route, np.zeros(6), sailed, band, np.array([0.9, 1.0, 0.9]))
    assert sd == pytest.approx(1.4826 * 0.05, rel=1e-9)
    assert pace_scatter(route[:2], np.zeros(2), sailed[:2], np.zeros(2, int), np.ones(3)) is None
