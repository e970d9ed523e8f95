"""A polar learned from a fleet (``sailroute.boat.learn``, ``learn_blocks``, ``learnfile``):
known answers on synthetic blocks, the refusals and their reasons, the VMG cap, the draws of
whole polars, the file, bad input."""

from __future__ import annotations

from pathlib import Path
from types import MappingProxyType

import numpy as np
import pytest

from sailroute.boat.build import boat_from_spec, builtin_polar
from sailroute.boat.io import read_polar
from sailroute.boat.learn import (
    LearnedPolar,
    LevelTable,
    _group_quantile,
    draw_polars,
    learn_polar,
    parse_levels,
    with_sailed_rows,
)
from sailroute.boat.learn_blocks import Blocks, BoatSeries, SteadyRules, steady_blocks
from sailroute.boat.learnfile import read_learned, write_learned
from sailroute.errors import InputError
from sailroute.units import KNOT

POLAR = builtin_polar("ilca7-steady")
TWS = np.array([4.0, 6.0])


def make_blocks(
    boats: dict[str, float],
    cells: list[tuple[float, float, int]],
    *,
    noise: float = 0.002,
    seed: int = 0,
    only: dict[str, list[int]] | None = None,
    speed=None,
) -> Blocks:
    """Blocks of boats sailing ``skill x POLAR`` (or ``speed(tws, twa)``) at the cells'
    exact (TWS, TWA) with ``noise`` relative speed scatter; ``cells`` holds (tws [m/s],
    twa [deg], blocks per boat); ``only`` gives, per boat, the cells it sailed."""
    rng = np.random.default_rng(seed)
    cols: dict[str, list[float]] = {k: [] for k in ("boat", "tws", "twa", "v")}
    names = list(boats)
    for b, name in enumerate(names):
        for c, (tws, twa, n) in enumerate(cells):
            if only is not None and c not in only.get(name, range(len(cells))):
                continue
            base = POLAR.speed(tws, twa) if speed is None else speed(tws, twa)
            v = boats[name] * base * (1.0 + noise * rng.standard_normal(n))
            sign = np.where(np.arange(n) % 2 == 0, 1.0, -1.0)
            cols["boat"] += [b] * n
            cols["tws"] += [tws] * n
            cols["twa"] += list(sign * twa)
            cols["v"] += list(v)
    k = len(cols["boat"])
    return Blocks(
        boat=np.asarray(cols["boat"], dtype=np.int64),
        race=np.zeros(k, dtype=np.int64),
        source=np.zeros(k, dtype=np.int64),
        t_s=np.arange(k, dtype=float) * 20.0,
        dur_s=np.full(k, 20.0),
        tws_ms=np.asarray(cols["tws"]),
        twd_deg=np.zeros(k),
        twa_deg=np.asarray(cols["twa"]),
        speed_ms=np.asarray(cols["v"]),
        boats=tuple(names),
        races=("race",),
        sources=("measured",),
        dropped={},
        n_samples=k * 20,
    )


GRID = [(tws, twa, 8) for tws in TWS for twa in (45.0, 90.0, 150.0)]


def learn(blocks: Blocks, **kw) -> LearnedPolar:
    opts = {"tws_bins_ms": TWS, "twa_bins_deg": np.arange(0.0, 181.0, 15.0), "n_boot": 40}
    opts.update(kw)
    return learn_polar(blocks, sailed_rows=False, **opts).learned


def cell(lp: LearnedPolar, tws: float, twa: float) -> tuple[int, int]:
    return int(np.flatnonzero(lp.twa_deg == twa)[0]), int(np.flatnonzero(lp.tws_ms == tws)[0])


# --- the statistics -----------------------------------------------------------------------


def test_group_quantile_with_equal_weights_is_hazens_quantile() -> None:
    rng = np.random.default_rng(3)
    v = rng.normal(size=40)
    g = np.repeat(np.arange(4), 10)
    o = np.lexsort((v, g))
    for q in (0.1, 0.5, 0.9):
        got = _group_quantile(g[o], v[o], np.ones(40), 4, q)
        want = [np.quantile(v[g == k], q, method="hazen") for k in range(4)]
        np.testing.assert_allclose(got, want, rtol=1e-12)


def test_group_quantile_weights_spread_a_value_over_its_weight() -> None:
    # values 1, 2, 3 with weights 1, 1, 2: weight midpoints at 1/8, 3/8, 3/4 of the total;
    # the median lies a third of the way from 3/8 (value 2) to 3/4 (value 3)
    got = _group_quantile(
        np.zeros(3, np.int64), np.array([1.0, 2, 3]), np.array([1.0, 1, 2]), 1, 0.5
    )
    assert got[0] == pytest.approx(2.0 + 1.0 / 3.0)


def test_parse_levels() -> None:
    assert parse_levels(None) == {"median": 50.0, "top": 90.0}
    assert parse_levels("50,75") == {"median": 50.0, "p75": 75.0}
    assert parse_levels("club=25, top=90") == {"club": 25.0, "top": 90.0}
    with pytest.raises(InputError, match="is not a percentile in"):
        parse_levels("median=0")
    with pytest.raises(InputError, match="given twice"):
        parse_levels("50,median=50")


# --- known answers ----------------------------------------------------------------------------


def test_levels_are_the_percentiles_of_the_boats_speeds() -> None:
    skills = {"a": 0.86, "b": 0.9, "c": 0.95, "d": 1.0, "e": 1.04}
    lp = learn(make_blocks(skills, GRID))
    logs = np.log(list(skills.values()))
    for name, q in (("median", 50.0), ("top", 90.0)):
        t = lp.levels[name]
        for tws, twa, _ in GRID:
            i, j = cell(lp, tws, twa)
            assert lp.status[i, j] == "learned"
            want = POLAR.speed(tws, twa) * np.exp(np.percentile(logs, q))
            assert t.speed_ms[i, j] == pytest.approx(want, rel=3e-3)
            assert 0.0 < t.sd_log[i, j] < 0.1  # five boats: the fleet's spread, a few %
    assert lp.boats.max() == 5 and lp.blocks.max() == 40


def test_winds_spread_over_a_narrow_range_keep_the_polars_slope_in_tws() -> None:
    # six boats (0.95-1.0 of the polar) sail a beat and a run in winds spread uniformly over
    # 17-23.5 kn (the 2 kn columns 18, 20, 22 kn), with 2 deg of wind-angle and 2 % of speed
    # scatter; the known polar rises 5 % per m/s of wind.  The median level's beat and run
    # keep that rise: each cell within 2 sd of the known answer, and the rise from 18 to
    # 22 kn (10.7 %) within 2 sd of both cells (a table held flat across the columns
    # would miss it by 10 %)
    def speed(tws, twa):
        return 6.0 * POLAR.speed(5.0, twa) * (1.0 + 0.05 * (np.asarray(tws) - 10.0))

    rng = np.random.default_rng(0)
    skills = np.linspace(0.95, 1.0, 6)
    n = 120
    tws = rng.uniform(8.75, 12.1, (skills.size, n))
    twa = np.where(rng.random((skills.size, n)) < 0.5, 45.0, 150.0)
    twa = twa + rng.normal(0.0, 2.0, twa.shape)
    v = skills[:, None] * speed(tws, twa) * (1.0 + 0.02 * rng.standard_normal(twa.shape))
    k = tws.size
    blocks = Blocks(
        boat=np.repeat(np.arange(skills.size), n),
        race=np.zeros(k, dtype=np.int64),
        source=np.zeros(k, dtype=np.int64),
        t_s=np.arange(k, dtype=float) * 20.0,
        dur_s=np.full(k, 20.0),
        tws_ms=tws.ravel(),
        twd_deg=np.zeros(k),
        twa_deg=(twa * np.where(np.arange(n) % 2 == 0, 1.0, -1.0)).ravel(),
        speed_ms=v.ravel(),
        boats=tuple(f"b{i}" for i in range(skills.size)),
        races=("race",),
        sources=("measured",),
        dropped={},
        n_samples=k * 20,
    )
    lp = learn_polar(
        blocks, tws_bins_ms=np.array([18.0, 20.0, 22.0]) * KNOT,
        twa_bins_deg=np.arange(0.0, 181.0, 10.0), n_boot=60,
    ).learned  # fmt: skip
    t = lp.levels["median"]
    q = float(np.percentile(skills, 50.0))
    rows = [int(np.argmin(np.abs(lp.twa_deg - a))) for a in (45.0, 150.0)]
    for i in rows:
        assert list(lp.status[i]) == ["learned"] * 3
        want = q * speed(lp.tws_ms, lp.twa_deg[i])
        assert np.all(np.abs(np.log(t.speed_ms[i] / want)) <= 2.0 * t.sd_log[i])
        assert np.all(np.diff(t.speed_ms[i]) > 0)
        rise = np.log(t.speed_ms[i, -1] / t.speed_ms[i, 0])
        known = np.log(want[-1] / want[0])
        assert known > 0.1
        assert abs(rise - known) <= 2.0 * np.hypot(t.sd_log[i, 0], t.sd_log[i, -1])
        assert 2.0 * np.hypot(t.sd_log[i, 0], t.sd_log[i, -1]) < 0.5 * known


def test_a_fleet_of_one_boat_gives_every_level_its_own_speed() -> None:
    lp = learn(make_blocks({"solo": 0.93}, GRID))
    i, j = cell(lp, 6.0, 90.0)
    want = 0.93 * POLAR.speed(6.0, 90.0)
    assert lp.levels["median"].speed_ms[i, j] == pytest.approx(want, rel=2e-3)
    assert lp.levels["top"].speed_ms[i, j] == pytest.approx(want, rel=2e-3)


def test_a_cell_sailed_by_part_of_the_fleet_is_placed_by_the_boats_factors() -> None:
    # the slow boat alone reached at 6 m/s: the median level there is the median boat's
    # speed (x1.0), not the slow boat's (x0.9)
    skills = {"slow": 0.9, "mid": 1.0, "fast": 1.1}
    only = {"mid": [0, 1, 2, 3, 5], "fast": [0, 1, 2, 3, 5]}  # cell 4: (6, 90)
    lp = learn(make_blocks(skills, GRID, only=only), min_boats=1)
    i, j = cell(lp, 6.0, 90.0)
    assert lp.boats[i, j] == 1 and lp.status[i, j] == "learned"
    assert lp.levels["median"].speed_ms[i, j] == pytest.approx(POLAR.speed(6.0, 90.0), rel=3e-3)


def test_cells_without_enough_boats_or_blocks_are_refused_and_listed() -> None:
    skills = {"a": 0.95, "b": 1.0, "c": 1.05}
    cells = [*GRID, (4.0, 120.0, 4), (6.0, 120.0, 2)]  # sailed by b alone
    every = list(range(6))
    only = {"a": every, "c": every, "b": [*every, 6, 7]}
    lp = learn(make_blocks(skills, cells, only=only))
    assert lp.reasons == (
        "TWA 120 deg, TWS 4.00 m/s: 1 boat(s), need 2",
        "TWA 120 deg, TWS 6.00 m/s: 1 boat(s), need 2; 2 block(s), need 3",
    )
    assert 120.0 in lp.provenance["left_out_twa_deg"]  # a row with no learned cell: left out
    # with min_boats 1 the row is kept, one cell refused for its blocks and filled
    lp = learn(make_blocks(skills, cells, only=only), min_boats=1)
    i, j = cell(lp, 6.0, 120.0)
    assert lp.status[i, j] == "refused" and lp.blocks[i, j] == 2 and lp.boats[i, j] == 1
    assert lp.reasons == ("TWA 120 deg, TWS 6.00 m/s: 2 block(s), need 3",)
    assert lp.levels["median"].speed_ms[i, j] > 0
    assert any("1 cell(s) refused (listed)" in v for v in lp.verdict)


def test_a_tail_of_the_beat_is_refused() -> None:
    # 40 blocks per boat at the beat (45 deg), 4 at 60 deg: wind-angle error, not sailing
    cells = [(6.0, 45.0, 40), (6.0, 60.0, 4), (6.0, 150.0, 20)]
    lp = learn(make_blocks({"a": 1.0, "b": 0.97}, cells), tws_bins_ms=[6.0])
    i, j = cell(lp, 6.0, 60.0)
    assert lp.status[i, j] == "refused"
    assert any("a tail of the beat sailed at 45 deg (8 blocks against 80)" in r for r in lp.reasons)


def test_no_cell_promises_more_vmg_than_the_fleet_made_good() -> None:
    # the boats beat at 45 deg; a fifth of their upwind blocks read 28 deg at the same
    # speed (beyond a tail's reach): a VMG 26 % better than any boat made good there.  The
    # cap holds at the cells (between them the table's curve may round over it)
    def speed(tws: float, twa: float) -> float:
        return float(POLAR.speed(tws, 45.0)) if twa < 60 else float(POLAR.speed(tws, twa))

    cells = [(6.0, 45.0, 40), (6.0, 28.0, 10), (6.0, 150.0, 20)]
    lp = learn(
        make_blocks({"a": 1.0, "b": 0.98}, cells, speed=speed),
        tws_bins_ms=[6.0],
        twa_bins_deg=[28.0, 45.0, 90.0, 150.0],
    )
    i, j = cell(lp, 6.0, 28.0)
    assert lp.status[i, j] == "learned"  # sailed by both boats, well off the beat
    made_good = POLAR.speed(6.0, 45.0) * np.cos(np.radians(45.0))  # the better boat's
    top = lp.levels["top"].speed_ms[:, j] * np.cos(np.radians(lp.twa_deg))
    assert np.all(top[lp.twa_deg < 90] <= made_good * 1.005)
    assert lp.levels["top"].speed_ms[i, j] < 0.85 * POLAR.speed(6.0, 45.0)


def test_sailed_rows_are_added_and_their_neighbours_dropped() -> None:
    b = make_blocks({"a": 1.0}, [(6.0, 43.0, 10), (6.0, 171.0, 10)])
    rows = with_sailed_rows(np.arange(0.0, 181.0, 10.0), b)
    assert 43.0 in rows and 171.0 in rows and 180.0 in rows and 0.0 in rows
    assert 40.0 not in rows and 170.0 not in rows and 50.0 in rows and 160.0 in rows


# --- steady blocks ----------------------------------------------------------------------------


def test_steady_blocks_leave_out_the_turn_and_keep_the_straight_lines() -> None:
    # east at 3 m/s for 120 s, a 90 deg turn to the south over 6 s, south for 120 s; wind
    # from the north at 5 m/s
    t = np.arange(0.0, 247.0)
    hdg = np.interp(t, [0, 120, 126, 246], [90.0, 90.0, 180.0, 180.0])
    vx, vy = 3.0 * np.sin(np.radians(hdg)), 3.0 * np.cos(np.radians(hdg))
    x, y = np.cumsum(vx), np.cumsum(vy)
    s = BoatSeries(
        "a",
        "r",
        t,
        x,
        y,
        np.full(t.size, 5.0),
        np.zeros(t.size),
        np.zeros(t.size, np.int64),
        ("m",),
    )
    bl = steady_blocks([s], SteadyRules())
    assert bl.dropped["manoeuvre"] >= 12 and bl.size >= 4
    near = np.abs(bl.t_s - 123.0) - 0.5 * bl.dur_s
    assert np.all(near > 5.0)  # no block reaches into the turn
    np.testing.assert_allclose(bl.speed_ms, 3.0, rtol=1e-9)
    assert np.all(bl.dur_s >= 20.0)  # 60 m at 3 m/s
    np.testing.assert_allclose(np.sort(np.abs(bl.twa_deg))[[0, -1]], [90.0, 180.0], atol=1e-6)


# --- draws and the file ----------------------------------------------------------------------


def _hand_made(seed: int = 1) -> LearnedPolar:
    twa = np.array([45.0, 90.0, 150.0])
    tws = np.array([4.0, 6.0])
    speed = POLAR.speed(tws[None, :], twa[:, None])
    modes = np.zeros((2, 3, 2))
    modes[0] = 0.03  # the whole table together (a boat's level)
    modes[1, 0] = [0.02, 0.02]  # the upwind row together
    resid = np.full((3, 2), 0.01)
    sd = np.sqrt((modes**2).sum(0) + resid**2)
    t = LevelTable(
        "median", 50.0, speed, sd, speed * 0.95, speed * 1.05, modes, resid,
        np.full(2, np.nan), np.full(2, np.nan), (0.9, 1.0, 0.95),
    )  # fmt: skip
    return LearnedPolar(
        "hand",
        twa,
        tws,
        MappingProxyType({"median": t}),
        np.full((3, 2), 9),
        np.full((3, 2), 3),
        np.full((3, 2), 180.0),
        np.full((3, 2), "learned").astype(np.str_),
        (),
        ("verdict line",),
        MappingProxyType({"boats": ["a", "b", "c"]}),
    )


def test_drawn_polars_carry_the_stated_spread_and_the_row_correlation() -> None:
    lp = _hand_made()
    t = lp.levels["median"]
    draws = draw_polars(lp, "median", 3000, np.random.default_rng(7))
    logs = np.array([np.log(p.speed_ms / t.speed_ms) for p in draws]).reshape(3000, -1)
    np.testing.assert_allclose(logs.std(axis=0), t.sd_log.ravel(), rtol=0.06)
    c = np.corrcoef(logs.T)
    # the two cells of the upwind row share both modes: corr = (0.03² + 0.02²) / sd²
    want = (0.03**2 + 0.02**2) / t.sd_log[0, 0] ** 2
    assert c[0, 1] == pytest.approx(want, abs=0.03)
    want_across = 0.03**2 / (t.sd_log[0, 0] * t.sd_log[1, 0])  # rows share the first mode
    assert c[0, 2] == pytest.approx(want_across, abs=0.03)
    assert draws[0].name == "hand (median) #1"


def test_the_file_reads_back_and_any_polar_reader_takes_its_default_level(tmp_path: Path) -> None:
    lp = learn(make_blocks({"a": 0.9, "b": 1.0, "c": 1.1}, GRID))
    path = write_learned(lp, tmp_path / "fleet.json", unit="kn")
    back = read_learned(path)
    assert list(back.levels) == ["median", "top"] and back.reasons == lp.reasons
    for name in lp.levels:
        a, b = lp.levels[name], back.levels[name]
        np.testing.assert_allclose(b.speed_ms, a.speed_ms, rtol=1e-5, atol=1e-5 * KNOT)
        np.testing.assert_allclose(b.sd_log, a.sd_log, atol=1e-5)
        np.testing.assert_allclose(b.modes, a.modes, atol=1e-5)
    np.testing.assert_array_equal(back.status, lp.status)
    plain = read_polar(path)
    np.testing.assert_allclose(plain.speed_ms, lp.levels["median"].speed_ms, atol=1e-5 * KNOT)


def test_a_course_boat_names_the_level_and_the_pace(tmp_path: Path) -> None:
    lp = _hand_made()
    write_learned(lp, tmp_path / "fleet.json")
    boat = boat_from_spec({"polar": "fleet.json", "level": "median"}, base_dir=tmp_path, where="c")
    np.testing.assert_allclose(boat.speed_ms, lp.levels["median"].speed_ms, rtol=1e-5)
    race = boat_from_spec(
        {"polar": "fleet.json", "level": "median", "pace": "race"}, base_dir=tmp_path, where="c"
    )
    assert race.speed(6.0, 45.0) == pytest.approx(0.9 * boat.speed(6.0, 45.0), rel=1e-9)
    assert race.speed(6.0, 150.0) == pytest.approx(0.95 * boat.speed(6.0, 150.0), rel=1e-9)
    assert race.name == "hand (median, race pace)"


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        (
            {"polar": "fleet.json", "level": "medain"},
            "c: boat.level: expected one of 'median' (the levels of fleet.json); got 'medain' "
            "(did you mean 'median'?)",
        ),
        ({"polar": "fleet.json", "pace": "fast"}, "boat.pace: expected one of 'steady', 'race'"),
        ({"polar": "plain.pol", "level": "top"}, "not a learned polar (no 'learned' block)"),
        ({"polar": "nopace.json", "pace": "race"}, "nopace.json has no race pace"),
    ],
)
def test_bad_level_and_pace_say_what_the_file_holds(tmp_path: Path, spec, message) -> None:
    from dataclasses import replace

    from sailroute.boat.io import write_pol

    lp = _hand_made()
    write_learned(lp, tmp_path / "fleet.json")
    steady = MappingProxyType({"median": replace(lp.levels["median"], race_pace=None)})
    write_learned(replace(lp, levels=steady), tmp_path / "nopace.json")
    write_pol(POLAR, tmp_path / "plain.pol")
    with pytest.raises(InputError) as exc:
        boat_from_spec(spec, base_dir=tmp_path, where="c")
    assert message in str(exc.value)


# --- bad input --------------------------------------------------------------------------------


def test_boats_that_cannot_be_one_class_are_refused() -> None:
    skills = {"a": 1.0, "b": 0.97, "c": 1.02, "cat": 1.9}
    with pytest.raises(InputError, match=r"logs of different classes: cat sails 1\.9\dx the speed"):
        learn(make_blocks(skills, GRID))


def test_boats_of_other_winds_and_speeds_are_refused_too() -> None:
    slow = make_blocks({"dinghy": 1.0}, [(3.0, 45.0, 10), (3.0, 150.0, 10)])
    fast = make_blocks(
        {"foiler": 1.0}, [(10.0, 45.0, 10), (10.0, 150.0, 10)], speed=lambda w, a: 3.0 * w
    )
    keys = ("boat", "race", "source", "t_s", "dur_s", "tws_ms", "twd_deg", "twa_deg", "speed_ms")
    both = Blocks(
        **{
            k: np.concatenate([getattr(slow, k), getattr(fast, k) + (1 if k == "boat" else 0)])
            for k in keys
        },
        boats=("dinghy", "foiler"),
        races=("race",),
        sources=("measured",),
        dropped={},
        n_samples=0,
    )
    with pytest.raises(InputError, match=r"foiler sail .*x the speed per knot of wind of dinghy"):
        learn(both, tws_bins_ms=[3.0, 10.0])


def test_a_fleet_too_small_for_the_cells_is_one_line() -> None:
    with pytest.raises(InputError) as exc:
        learn(make_blocks({"a": 1.0, "b": 1.0}, GRID), min_boats=3)
    assert str(exc.value) == (
        "learn_polar: min_boats 3: the fleet has 2 boat(s) (a, b); no cell can be sailed by 3 "
        "boats: give more logs or a lower learn_polar: min_boats"
    )
