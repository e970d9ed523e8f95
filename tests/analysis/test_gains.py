"""Gains on the fleet (:mod:`sailroute.analysis.gains`) on generated fleets with a known answer.

A small fleet (6 boats, 14 minutes, one that never starts) checks the bookkeeping: the parts
add up to each leg's gain, the start and the legs to the elapsed-time gain at the finish, the
top three are the leg's fastest, and the outputs and the page carry the same numbers.  The
slow test sails five 40-boat messy fleets (``tests/fleetgen.py``, seeds 1-5) and checks that
each injected cause shows in its part.  Measured there (inferred wind, GPS error, 1-3 s
fixes): the parts add up to 1e-13 s; the rest ("other") is 0.7 s per leg in the median, 2.6
s at the 95th percentile; the speed part follows the boats' skill (Spearman 0.97-1.00),
within 14 % in the median of the time its skill predicts (39 % at the 90th percentile); the
manoeuvres part ranks the boats by their tack cost (Spearman 0.56-0.85) more than by their
finish (-0.15-0.46); the measured cost per tack is 5.0-5.8 s for the 4.2 s class and
7.7-8.6 s for the 7.3 s class.  No boat pinches or foots, yet the height part reaches 20-30 s
on a beat for a few boats: the inferred wind misses the oscillating shift (5.6° RMS) and a
boat's mean angle on a tack keeps the error of the time it sailed it.
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np
import pytest

from sailroute.analysis.fleet import FleetAnalysis
from sailroute.analysis.gains import PARTS, log_mean
from sailroute.commands.analyze import run_analyze_command
from sailroute.commands.result import CommandResult
from tests.fleetgen import FaultPlan, Fleet, messy_fleet


def test_log_mean() -> None:
    assert log_mean(math.e, 1.0) == pytest.approx(math.e - 1.0)
    assert log_mean(3.0, 3.0) == 3.0
    assert math.isnan(log_mean(0.0, 2.0))


def _analyse(f: Fleet, folder: Path) -> CommandResult:
    course, paths = f.write(folder, "csv")
    return run_analyze_command(
        course, paths, out_dir=folder / "out", plots=False, gate_end="rounding"
    )


@pytest.fixture(scope="module")
def small(tmp_path_factory: pytest.TempPathFactory) -> tuple[Fleet, CommandResult]:
    f = messy_fleet(seed=3, n_boats=6, minutes=14, faults=FaultPlan.clean(non_starters=1))
    return f, _analyse(f, tmp_path_factory.mktemp("gains"))


def _fleet(res: CommandResult) -> FleetAnalysis:
    assert isinstance(res.data, FleetAnalysis)
    return res.data


def test_parts_add_up_and_the_start_and_legs_to_the_finish(
    small: tuple[Fleet, CommandResult],
) -> None:
    fleet = _fleet(small[1])
    assert fleet.gains is not None
    tab = fleet.table
    for ref in ("median", "top3"):
        g = fleet.gains.table(ref)
        known = np.isfinite(g.total_s)
        assert known.sum() >= 0.9 * known.size
        assert np.nanmax(np.abs(g.parts_s.sum(axis=2) - g.total_s)) < 0.1
        # leg gain = the reference's leg time minus the boat's own (from the leg table)
        assert np.allclose(g.total_s, g.reference_time_s - tab.time_s, equal_nan=True)
        # start + legs = the reference's elapsed time at the finish minus the boat's
        summed = g.summed(range(len(g.labels)))["total"]
        elapsed_ref = g.reference_start_s + g.reference_time_s.sum()
        fin = np.isfinite(tab.end_s[:, -1])
        assert np.allclose(summed[fin], elapsed_ref - tab.end_s[fin, -1], atol=0.1)
    # the median boat gains about nothing; the rest ("other") stays small
    med = fleet.gains.median
    assert abs(float(np.nanmedian(med.total_s))) < 1.0
    assert np.nanmax(np.abs(med.part("other"))) < 0.05 * np.nanmax(med.reference_time_s)


def test_the_top_three_are_the_legs_fastest(small: tuple[Fleet, CommandResult]) -> None:
    fleet = _fleet(small[1])
    assert fleet.gains is not None
    tab = fleet.table
    top3 = fleet.gains.top3
    for i, top in enumerate(fleet.gains.top):
        times = np.where(tab.ranked, tab.time_s[:, i], np.inf)
        fastest = [tab.boats[k] for k in np.argsort(times)[:3]]
        assert list(top) == fastest
        best = tab.boats.index(top[0])
        assert top3.total_s[best, i] > 0  # faster than the mean of the three


def test_outputs_carry_the_gains(small: tuple[Fleet, CommandResult]) -> None:
    res = small[1]
    fleet = _fleet(res)
    assert fleet.gains is not None
    doc = json.loads(res.files["fleet_json"].read_text(encoding="utf-8"))
    gains = doc["gains"]
    assert gains["parts"] == list(PARTS)
    boat = fleet.gains.median.boats[0]
    entry = gains["median"]["boats"][boat]
    assert entry["summed"]["total_s"] == pytest.approx(
        entry["start_s"] + sum(leg["total_s"] for leg in entry["legs"]), abs=0.05
    )
    with res.files["fleet_csv"].open(encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    for r in rows:
        parts = sum(float(r[f"gain_{p}_s"]) for p in PARTS)
        assert parts == pytest.approx(float(r["gain_s"]), abs=0.1)
    # the terminal table: a row per boat, its total the start plus the parts
    lines = [ln for ln in res.report.splitlines() if ln.startswith(f"  {boat} ")]
    nums = [float(v) for v in lines[-1].split()[1:8]]
    assert nums[0] == pytest.approx(sum(nums[1:]), abs=0.35)


RUNS = ((1, 5.0), (2, 10.0), (3, 7.5), (4, 6.0), (5, 9.0))
"""Seed and tracker clock lag [s] of each 40-boat fleet."""


def _spearman(a: np.ndarray, b: np.ndarray) -> float:
    ra, rb = np.argsort(np.argsort(a)), np.argsort(np.argsort(b))
    return float(np.corrcoef(ra, rb)[0, 1])


@pytest.mark.slow
def test_each_injected_cause_shows_in_its_part(tmp_path: Path) -> None:
    rel_errors, signs = [], []
    for seed, lag in RUNS:
        f = messy_fleet(seed=seed, n_boats=40, clock_lag_s=lag)
        fleet = _fleet(_analyse(f, tmp_path / str(seed)))
        assert fleet.gains is not None
        g = fleet.gains.median
        assert np.nanmax(np.abs(g.parts_s.sum(axis=2) - g.total_s)) < 0.1
        assert np.nanpercentile(np.abs(g.part("other")), 95) < 6.0
        legs = fleet.table.common_legs()
        sm = g.summed(legs)
        truth = [f.truth(b) for b in g.boats]
        skill = np.array([b.skill for b in truth])
        tack = np.array([b.tack_cost_s for b in truth])
        slow_tacker = tack * skill > 5.5  # the 7 s class (4 s: the other)
        ok = np.isfinite(sm["total"]) & np.array(fleet.ranked)
        finish = np.array([{r.boat: r.total_s for r in fleet.results()}[b] for b in g.boats])
        # speed: what the skill predicts, sum over legs of T_R ln(skill / the median skill)
        pred = np.zeros(len(g.boats))
        for i in legs:
            m = ok & np.isfinite(g.total_s[:, i])
            pred += g.reference_time_s[i] * np.log(skill / np.median(skill[m]))
        clean = ok & np.array([b.clean for b in truth]) & (np.abs(pred) > 30.0)
        signs += list(np.sign(sm["speed"][clean]) == np.sign(pred[clean]))
        rel_errors += list(np.abs(sm["speed"][clean] - pred[clean]) / np.abs(pred[clean]))
        assert _spearman(sm["speed"][ok], skill[ok]) > 0.95
        # manoeuvres: the slow tackers lose there, and the part does not restate the finish
        assert np.median(sm["manoeuvres"][ok & slow_tacker]) < np.median(
            sm["manoeuvres"][ok & ~slow_tacker]
        )
        by_cost = _spearman(sm["manoeuvres"][ok], -tack[ok])
        assert by_cost > 0.4 and by_cost > abs(_spearman(sm["manoeuvres"][ok], -finish[ok])) + 0.2
        # the measured cost per manoeuvre of each class, within 40 % of the truth
        cost = np.nanmedian(fleet.gains.manoeuvre_cost_s[:, list(legs)], axis=1)
        for cls in (slow_tacker, ~slow_tacker):
            assert np.nanmedian(cost[ok & cls]) == pytest.approx(np.median(tack[ok & cls]), rel=0.4)
        # nobody pinches or foots here: the height part is what the inferred wind's error
        # (about 5.6 deg RMS, its oscillation smoothed) leaves in each boat's mean angle
        assert np.nanpercentile(np.abs(sm["height"][ok]), 90) < 35.0
    # a boat 30 s or more faster (slower) by its skill gains (loses) in the speed part
    assert np.mean(signs) >= 0.95
    assert np.median(rel_errors) < 0.2


def test_the_page_reads_the_fleets_analysis(small: tuple[Fleet, CommandResult]) -> None:
    from sailroute.report.fleet import fleet_page, fleet_report

    f, res = small
    fleet = _fleet(res)
    assert fleet.gains is not None
    page = fleet_page(fleet.analyses, fleet.rows(), fleet.all_notes(), fleet=fleet)
    # the status, the leader and the tracks not debriefed are the fleet's
    for boat in page.boats:
        assert boat.ranked == fleet.entry(boat.name).status.ranked
    assert page.boats[page.lead()].name == fleet.leader()
    assert [n for n, _ in page.others] == [f.with_status("non_starter")[0].name]
    tables = {t.name: t for t in fleet_report(page).tables}
    gains = tables["gains"]
    assert gains.headers[2:4] == ("total s", "start s")
    # a row's total is its start plus its parts, and the leg tables name the top three
    for row in gains.rows:
        total, *rest = (float(v) for v in row[2:])
        assert total == pytest.approx(sum(rest), abs=0.35)
    assert ", ".join(fleet.gains.top[0]) in tables["gains-1"].caption
    assert tables["not-debriefed"].rows[0][0] == page.others[0][0]
