"""Gains on the fleet (:mod:`sailroute.analysis.gains`) on generated fleets with a known answer.

A small fleet (6 boats, 14 minutes, one that never starts) checks the bookkeeping: the parts
add up to each leg's gain, the start and the legs to the elapsed-time gain at the finish, the
top three are the leg's fastest, and the outputs and the page carry the same numbers.  The
slow test sails five 40-boat messy fleets (``tests/fleetgen.py``, seeds 1-5) and checks that
each injected cause shows in its part.  Measured there (inferred wind, GPS error, 1-3 s
fixes): the parts add up to 1e-13 s; the rest ("other") is 0.7 s per leg in the median, 2.5
s at the 95th percentile; the speed part follows the boats' skill (Spearman 0.97-1.00),
within 15 % in the median of the time its skill predicts (35 % at the 90th percentile); the
manoeuvres part ranks the boats by their tack cost (Spearman 0.62-0.80) more than by their
finish (-0.19-0.44); the measured cost per tack is 3.8-5.3 s for the 4.2 s class and
5.1-8.1 s for the 7.3 s class.  No boat pinches or foots, yet the height part reaches 20-39 s
(90th percentile over a race) for a few boats: the inferred wind misses the oscillating
shift (5.6° RMS) and a boat's mean angle on a tack keeps the error of the time it sailed it.

The styled fleet (:func:`styled_fleet`, 16 boats, seed 0; seeds 0-3 measured) checks the
height and side parts against their causes.  Every boat banks up the first beat, eight on
each side, while the wind veers 12°; two boats pinch and two foot by 10° on a square,
steady second beat.  There the height part of the pinching boats is −16 to −38 s (truth
from the polar, ``T_R ln VMG(θ)/VMG*`` against the median: −30 to −33 s) and of the footing
boats −32 to −38 s (−31 to −33 s), each within the time that 2° of error in its measured
angle moves (12 s per degree pinching at 32°, 6 s footing at 52°), and at most 3.3 s for
the others.  On the first beat the side part is +40 to +44 s on average on the right (the
side the veer favours) and −35 to −39 s on the left, against 47-49 s from the geometry
(``y sin Δ`` at the fleet's VMG, ``y`` 400 m to the side).  "Other" stays under 4 s per
leg.  Over the race each part ranks the boats by its cause more than the finish does
(Spearman, cause vs finish): speed by skill 0.97-1.00 vs 0.78-0.93 (the boats at the best
angle; a pinching or footing boat is slower than its skill off its angle), height by the
offset 0.72-0.75 vs 0.35-0.60, side by the side banked 0.87 vs 0.51-0.68.
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np
import pytest
from numpy.typing import NDArray
from scipy.stats import spearmanr

from sailroute.analysis.fleet import FleetAnalysis
from sailroute.analysis.gains import PARTS, log_mean
from sailroute.boat.polar import Polar
from sailroute.commands.analyze import run_analyze_command
from sailroute.commands.result import CommandResult
from sailroute.routing.types import RouteTrack
from sailroute.units import heading_unit
from tests.fleetgen import BANK_HEIGHT, FaultPlan, Fleet, Sailing, messy_fleet


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


def _spearman(a: NDArray[np.float64], b: NDArray[np.float64]) -> float:
    """Spearman's rank correlation (ties: mean ranks)."""
    return float(spearmanr(a, b)[0])


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
        # (90th percentile 2-39 s over the five fleets)
        assert np.nanpercentile(np.abs(sm["height"][ok]), 90) < 45.0
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


# ------------------------------------------------------------------ pinching, footing, a side

OFFSET_DEG = 10.0
"""How far the pinching (−) and footing (+) boats sail off the best VMG angle [°]."""
SHIFT_DEG = 12.0
"""The persistent veer over the first beat [°]: the right side pays."""
ANGLE_ERROR_DEG = 2.0
"""How far a boat's measured median angle on a tack may lie from the truth [°]: the
inferred wind's direction (about 1°) and the correlated GPS error over a tack (about 1°)."""


def styled_fleet(seed: int = 0) -> Fleet:
    """16 boats, every one banking up the first beat (even draws right, odd left) in a wind
    that veers :data:`SHIFT_DEG` from 150 to 300 s after the gun, to a square and steady
    second beat (no oscillation, TWS the course's 10 kn); draws 1 and 2 pinch, 3 and 4 foot
    by :data:`OFFSET_DEG` (one of each on each side); GPS error as by default."""
    sailing = {
        k: Sailing(
            {1: -OFFSET_DEG, 2: -OFFSET_DEG, 3: OFFSET_DEG, 4: OFFSET_DEG}.get(k, 0.0),
            "right" if k % 2 == 0 else "left",
        )
        for k in range(16)
    }
    wind = {
        "twd_deg": 180.0 - SHIFT_DEG,
        "shift_deg": SHIFT_DEG,
        "shift_start_s": 150.0,
        "shift_over_s": 150.0,
        "osc_amp_deg": 0.0,
        "tws_amp": 0.0,
    }
    plan = FaultPlan.clean(
        noise_white_m=FaultPlan.noise_white_m, noise_corr_m=FaultPlan.noise_corr_m
    )
    return messy_fleet(seed, 16, 30.0, plan, twd_deg=180.0, sailing=sailing, wind_fields=wind)


@pytest.fixture(scope="module")
def styled(tmp_path_factory: pytest.TempPathFactory) -> tuple[Fleet, FleetAnalysis]:
    f = styled_fleet()
    return f, _fleet(_analyse(f, tmp_path_factory.mktemp("styled")))


def _ln_vmg(polar: Polar, tws: NDArray[np.float64], twa: NDArray[np.float64]) -> NDArray:
    """``ln(VMG(twa) / best VMG)`` at ``tws`` [m s⁻¹], ``|twa|`` [°] (< 90°)."""
    best = polar.vmg_upwind(tws)[1]
    return np.log(polar.speed(tws, twa) * np.cos(np.radians(twa)) / best)


def _vmg_loss(polar: Polar, track: RouteTrack) -> float:
    """Time mean of :func:`_ln_vmg` over a routed beat (its upwind points) [-]."""
    up = np.abs(track.twa_deg) < 90.0
    dt = np.gradient(track.t)[up]
    return float(
        np.sum(_ln_vmg(polar, track.tws_ms[up], np.abs(track.twa_deg[up])) * dt) / dt.sum()
    )


@pytest.mark.slow
def test_height_takes_the_pinching_and_footing(styled: tuple[Fleet, FleetAnalysis]) -> None:
    f, fleet = styled
    assert fleet.gains is not None and f.point_of_sail(2) == "upwind"
    g = fleet.gains.median
    truth = [f.truth(b) for b in g.boats]
    t_r = float(g.reference_time_s[2])
    # the truth: the time its angle costs on the second beat at the polar's speed,
    # ``T_R ln(VMG(θ_k) / VMG*)`` against the fleet's median
    loss = np.array([_vmg_loss(f.polar, b.legs[2].track) for b in truth])
    pred = t_r * (loss - np.median(loss))
    height = g.part("height")[:, 2]
    offset = np.array([b.upwind_twa_offset_deg for b in truth])
    assert (offset < 0).sum() == 2 and (offset > 0).sum() == 2
    tws = f.wind.tws_ms
    for k in np.flatnonzero(offset != 0):
        tr = truth[k].legs[2].track
        theta = float(np.median(np.abs(tr.twa_deg[np.abs(tr.twa_deg) < 90.0])))
        slope = abs(
            float(_ln_vmg(f.polar, tws, theta + 0.05) - _ln_vmg(f.polar, tws, theta - 0.05)) / 0.1
        )
        assert pred[k] < -20.0  # the injected deficit: 30-35 s on a 9-minute beat
        assert height[k] < 0
        # within what an angle error of ANGLE_ERROR_DEG moves it (2.2 %/° pinching at 32°,
        # 1.1 %/° footing at 52°)
        assert abs(height[k] - pred[k]) <= t_r * slope * ANGLE_ERROR_DEG, truth[k].name
    # the boats at the best angle: nothing (the VMG is flat there)
    assert np.max(np.abs(height[offset == 0])) < 5.0


@pytest.mark.slow
def test_side_takes_the_favoured_side_of_a_shift(styled: tuple[Fleet, FleetAnalysis]) -> None:
    f, fleet = styled
    assert fleet.gains is not None
    g = fleet.gains.median
    truth = [f.truth(b) for b in g.boats]
    right = np.array([b.bank == "right" for b in truth])
    assert right.sum() == 8 and all(b.bank is not None for b in truth)
    # the geometry: a boat y metres to the side of the course when the wind veers by Δ
    # gains y sin Δ of progress on one in the middle, at the fleet's VMG; y: its waypoint,
    # BANK_HEIGHT of the beat up the close-hauled course from the line
    pin, boat = f.marks["start_pin"], f.marks["start_boat"]
    c = ((pin[0] + boat[0]) / 2.0, (pin[1] + boat[1]) / 2.0)
    ax, ay = heading_unit(f.wind.axis_deg)
    up = (f.marks["1"][0] - c[0]) * ax + (f.marks["1"][1] - c[1]) * ay
    alpha, vmg = (float(v) for v in f.polar.vmg_upwind(f.wind.tws_ms))
    y = BANK_HEIGHT * up * math.tan(math.radians(alpha))
    skill = float(np.median([b.skill for b in truth]))
    expected = y * math.sin(math.radians(SHIFT_DEG)) / (vmg * skill)
    side = g.part("side")[:, 0]
    assert np.all(side[right] > 0) and np.all(side[~right] < 0)
    assert 0.5 * expected < np.mean(side[right]) < 1.5 * expected
    assert 0.5 * expected < -np.mean(side[~right]) < 1.5 * expected
    assert np.max(np.abs(side)) < 2.0 * expected


@pytest.mark.slow
def test_each_part_ranks_by_its_cause_not_the_finish(
    styled: tuple[Fleet, FleetAnalysis],
) -> None:
    f, fleet = styled
    assert fleet.gains is not None
    g = fleet.gains.median
    truth = [f.truth(b) for b in g.boats]
    assert np.nanmax(np.abs(g.parts_s.sum(axis=2) - g.total_s)) < 0.1
    other = np.abs(g.part("other"))
    assert np.nanmax(other) < 6.0 and np.nanpercentile(other, 95) < 3.0
    sm = g.summed(fleet.table.common_legs())
    finish = -np.array([{r.boat: r.total_s for r in fleet.results()}[b] for b in g.boats])
    causes = {
        "speed": np.array([b.skill for b in truth]),
        "height": -np.abs([b.upwind_twa_offset_deg for b in truth]),
        "side": np.array([1.0 if b.bank == "right" else -1.0 for b in truth]),
    }
    # a pinching or footing boat is slower than its skill off its angle (its polar's VMG is
    # capped there: on the way to its waypoint), so its speed part is not its skill's alone
    plain = np.array([b.upwind_twa_offset_deg == 0.0 for b in truth])
    # margins over the finish measured on seeds 0-3: speed 0.04-0.20 (0.20 here), height
    # 0.15-0.40, side 0.19-0.36
    margin = {"speed": 0.1, "height": 0.1, "side": 0.1}
    for part, cause in causes.items():
        m = plain if part == "speed" else np.ones(len(truth), bool)
        by_cause, by_finish = _spearman(sm[part][m], cause[m]), _spearman(sm[part][m], finish[m])
        assert by_cause > by_finish + margin[part], (part, by_cause, by_finish)
    assert _spearman(sm["height"], causes["height"]) > 0.7  # 0.75: the four boats last
    assert _spearman(sm["side"], causes["side"]) > 0.85  # 0.87: the two sides apart
