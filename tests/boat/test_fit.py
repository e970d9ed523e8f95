"""Polar fitting of one series (``sailroute.boat.fit.fit_polar``) and the ``efficiency``
key: known answers from synthetic logs, filter counts, errors; the ORC speed guide as
published.  The fleet learner of ``sailroute polar fit`` is tested in ``test_learn*.py``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from sailroute.boat.build import boat_from_spec, builtin_polar
from sailroute.boat.efficiency import efficiency_factor, scale_polar
from sailroute.boat.fit import FitFilters, fit_polar
from sailroute.boat.io import read_polar
from sailroute.errors import InputError
from tests.conftest import ROOT

ORC_GUIDE = ROOT / "tests" / "data" / "boat" / "ORC_Speed_Guide_Ref_04340002PIL.csv"  # MIT
TWS_BINS = np.arange(2.0, 7.01, 1.0)
TWA_BINS = np.arange(40.0, 170.01, 10.0)
U_LO, U_HI = 0.73, 1.03  # the boat sails uniformly between 73 % and 103 % of the polar


def synthetic_log(target, n_s=50_000, seed=1):
    """A 1 Hz log sailed on ``target``: legs at random TWA on alternating tacks, tacks and
    gybes (6 s turns at half speed, then a 3 s recovery), gusts, 1 % speed noise, 1 % spikes
    at twice the speed, 0.2 % missing values.

    Steady sailing speed is ``u * target * (1 + 0.01 N(0, 1))`` with ``u`` a triangle wave
    (period 31 s) between 0.73 and 1.03: ``u`` is uniform, so its 90th percentile is exactly
    0.73 + 0.9 * 0.30 = 1.00, and the 90th percentile envelope IS the target polar.
    """
    rng = np.random.default_rng(seed)
    t = np.arange(n_s, dtype=float)
    tws = 4.5 + 1.8 * np.sin(2 * np.pi * t / 5003) + 0.9 * np.sin(2 * np.pi * t / 311 + 1)
    twa = np.empty(n_s)
    factor = np.ones(n_s)
    tacking = np.zeros(n_s, bool)
    i, sign, prev, turn = 0, 1.0, 45.0, 6
    while i < n_s:
        ang, seg = rng.uniform(40, 170), int(rng.integers(40, 150))
        new_sign = -sign if rng.random() < 0.6 else sign
        a0, a1 = sign * prev, new_sign * ang
        if new_sign != sign and prev + ang >= 180:  # gybe: through 180
            d = (a1 - a0) % 360 if sign > 0 else -((a0 - a1) % 360)
        else:  # tack through 0, or a turn on the same tack
            d = a1 - a0
        j = slice(i, min(i + turn, n_s))
        twa[j] = ((a0 + d * np.linspace(0, 1, turn))[: j.stop - j.start] + 180) % 360 - 180
        if new_sign != sign:
            tacking[j] = True
            factor[j] = 0.5
            rec = np.arange(min(30, n_s - j.stop))
            factor[j.stop : j.stop + rec.size] = 1 - 0.5 * np.exp(-rec / 3.0)
        i = j.stop
        m = min(seg, n_s - i)
        twa[i : i + m] = new_sign * (ang + 2.0 * np.sin(2 * np.pi * np.arange(m) / 71))
        i, sign, prev = i + m, new_sign, ang
    tri = 2 * np.abs(((t / 31.0 + rng.uniform()) % 1) - 0.5)
    u = U_LO + (U_HI - U_LO) * tri
    bsp = u * target.speed(tws, twa) * (1 + 0.01 * rng.standard_normal(n_s)) * factor
    spikes = rng.random(n_s) < 0.01
    bsp = np.where(spikes, 2.0 * bsp, bsp)
    missing = rng.random(n_s) < 0.002
    bsp = np.where(missing, np.nan, bsp)
    return t, tws, twa, bsp, tacking, spikes, missing


@pytest.fixture(scope="module")
def target():
    return builtin_polar("ilca7-steady")


@pytest.fixture(scope="module")
def synthetic(target):
    log = synthetic_log(target)
    t, tws, twa, bsp = log[:4]
    fit = fit_polar(tws, twa, bsp, t, tws_bins_ms=TWS_BINS, twa_bins_deg=TWA_BINS, min_count=30)
    return log, fit


def test_synthetic_log_gives_the_polar_back(synthetic, target) -> None:
    # Tolerance: a cell's 90th percentile of n uniform samples has a standard error of
    # sqrt(0.09 / n) * 0.30 = 0.09 / sqrt(n) (relative); n is 30-1300 but the samples of a
    # cell come from a few legs (correlated), so the measured RMS is 1.0 % (max 3.8 %,
    # mean +0.03 %).  Bounds: RMS 1.5 %, |mean| 0.5 % (no bias), max 5 % on cells of
    # >= 100 samples.
    _, fit = synthetic
    ref = target.speed(fit.polar.tws_ms[None, :], fit.polar.twa_deg[:, None])
    rel = fit.polar.speed_ms / ref - 1.0
    cov = fit.covered
    assert cov.sum() >= 70  # 14 x 6 cells, nearly all covered
    assert np.sqrt(np.mean(rel[cov] ** 2)) < 0.015
    assert abs(np.mean(rel[cov])) < 0.005
    assert np.max(np.abs(rel[fit.counts >= 100])) < 0.05
    assert np.all(np.isfinite(fit.polar.speed_ms)) and np.all(fit.polar.speed_ms >= 0)


def test_without_the_within_cell_correction_the_upper_corner_biases_the_fit(target) -> None:
    # independent samples over whole cells: the 90th percentile of a cell favours its fast
    # corner (higher TWS); the correction (moving samples to the node along the fit) removes
    # that bias.  Measured: RMS 5.0 % without, 0.7 % with.
    import sailroute.boat.fit as fitmod

    rng = np.random.default_rng(0)
    n = 36_000
    tws, twa = rng.uniform(1.6, 7.4, n), rng.uniform(40, 170, n)
    bsp = rng.uniform(U_LO, U_HI, n) * target.speed(tws, twa)
    fit = fit_polar(tws, twa, bsp, tws_bins_ms=TWS_BINS, twa_bins_deg=TWA_BINS, min_count=30)
    ref = target.speed(fit.polar.tws_ms[None, :], fit.polar.twa_deg[:, None])
    rms = np.sqrt(np.mean((fit.polar.speed_ms / ref - 1)[fit.covered] ** 2))
    assert rms < 0.012
    saved = fitmod._CORRECTION_PASSES
    try:
        fitmod._CORRECTION_PASSES = 0
        raw = fit_polar(tws, twa, bsp, tws_bins_ms=TWS_BINS, twa_bins_deg=TWA_BINS, min_count=30)
    finally:
        fitmod._CORRECTION_PASSES = saved
    rms_raw = np.sqrt(np.mean((raw.polar.speed_ms / ref - 1)[raw.covered] ** 2))
    assert rms_raw > 3 * rms


def test_filters_remove_manoeuvres_spikes_and_missing_values(synthetic) -> None:
    (t, _, _, _, tacking, spikes, missing), fit = synthetic
    assert fit.dropped["non_finite"] == int(missing.sum())
    assert not np.any(fit.used & tacking)  # every tack/gybe sample dropped
    assert np.sum(fit.used & spikes & ~missing) <= 0.01 * spikes.sum()
    assert fit.dropped["manoeuvre"] >= tacking.sum()
    assert sum(fit.dropped.values()) + fit.n_used == fit.n_samples == t.size
    assert fit.counts.sum() == fit.n_used


def test_filter_rules_one_by_one() -> None:
    t = np.arange(100.0)
    twa = np.where(t < 50, 45.0, -45.0)  # one tack at t = 49.5
    bsp = np.full(100, 2.0)
    bsp[80] = 3.0  # +50 % in one second: acceleration
    tws = np.full(100, 4.0)
    tws[5] = 0.5  # below the floor
    fit = fit_polar(
        tws,
        twa,
        bsp,
        t,
        tws_bins_ms=[4.0],
        twa_bins_deg=[40.0, 50.0],
        min_count=1,
        filters=FitFilters(manoeuvre_window_s=5.0),
    )
    # the tack's heading change (90 deg in 1 s) also trips the turn rate at 49, 50
    assert fit.dropped["low_wind"] == 1
    assert fit.dropped["manoeuvre"] == 10  # 45..54: |t - 49.5| <= 5
    # central differences: 79 and 81 accelerate; at the spike itself dV/dt = 0, and the
    # per-cell median + k MAD rule drops it
    assert fit.dropped["acceleration"] == 2
    assert fit.dropped["outlier"] == 1
    np.testing.assert_allclose(fit.polar.speed_ms, 2.0)


def test_monotone_in_tws_unless_the_data_say_otherwise() -> None:
    rng = np.random.default_rng(3)
    n = 400
    tws = np.repeat([3.0, 4.0, 5.0], n)
    twa = np.full(3 * n, 90.0)
    # a small dip at 4 m/s (within noise) is smoothed; a large drop at 5 m/s is kept
    base = np.repeat([2.0, 1.98, 1.5], n)
    bsp = base * rng.uniform(0.8, 1.0, 3 * n)
    fit = fit_polar(
        tws, twa, bsp, tws_bins_ms=[3.0, 4.0, 5.0], twa_bins_deg=[80.0, 90.0], min_count=10
    )
    row = fit.polar.speed_ms[list(fit.polar.twa_deg).index(90.0)]
    assert row[1] >= row[0] - 1e-12  # pooled: non-decreasing 3 -> 4
    assert row[2] < 0.8 * row[1]  # the significant drop survives


def test_empty_cells_are_filled_and_marked() -> None:
    rng = np.random.default_rng(4)
    tws = rng.uniform(2.5, 5.5, 3000)
    twa = rng.choice([45.0, 90.0, 150.0], 3000)
    keep = ~((twa == 90.0) & (tws > 4.5))  # no data at (90, 5)
    tws, twa = tws[keep], twa[keep]
    bsp = np.where(twa == 90.0, 2.5, 2.0) * np.ones_like(tws)
    fit = fit_polar(
        tws,
        twa,
        bsp,
        tws_bins_ms=[3.0, 4.0, 5.0],
        twa_bins_deg=[0.0, 45.0, 90.0, 150.0, 180.0],
        min_count=5,
    )
    np.testing.assert_array_equal(fit.polar.twa_deg, [45.0, 90.0, 150.0])  # empty rows out
    np.testing.assert_array_equal(fit.empty_twa_deg, [0.0, 180.0])
    i = 1
    assert fit.counts[i, 2] == 0 and not fit.covered[i, 2]
    assert fit.polar.speed_ms[i, 2] == pytest.approx(2.5)  # from its row
    assert fit.coverage == pytest.approx(8 / 9)


def test_bad_input_raises_with_a_hint() -> None:
    with pytest.raises(InputError, match="no TWS/TWA cell has 5 samples"):
        fit_polar([4.0], [45.0], [2.0], tws_bins_ms=[4.0], twa_bins_deg=[40.0, 50.0])
    with pytest.raises(InputError, match="twa_deg has 2 samples"):
        fit_polar([4.0], [45.0, 50.0], [2.0], tws_bins_ms=[4.0], twa_bins_deg=[40.0, 50.0])
    with pytest.raises(InputError, match="percentile"):
        fit_polar([4.0], [45.0], [2.0], tws_bins_ms=[4.0], twa_bins_deg=[40, 50], percentile=0)
    with pytest.raises(InputError, match="strictly increasing"):
        fit_polar([4.0], [45.0], [2.0], tws_bins_ms=[4.0, 3.0], twa_bins_deg=[40, 50])


# --- efficiency -------------------------------------------------------------------------


def test_efficiency_bands_and_blend() -> None:
    f = efficiency_factor([0, 60, 70, 80, 95, 110, 120, 130, 180], 0.9, 1.0, 1.1)
    np.testing.assert_allclose(f, [0.9, 0.9, 0.95, 1.0, 1.0, 1.0, 1.05, 1.1, 1.1])
    p = builtin_polar("ilca7")
    s = scale_polar(p, upwind=0.92)
    tws = np.array([3.0, 5.0])
    np.testing.assert_allclose(s.speed(tws, 45.0), 0.92 * p.speed(tws, 45.0), rtol=2e-3)
    np.testing.assert_allclose(s.speed(tws, 95.0), p.speed(tws, 95.0), rtol=2e-3)
    assert scale_polar(p) is p


def test_efficiency_in_the_course_boat_block(tmp_path: Path) -> None:
    base = boat_from_spec({"builtin": "ilca7"}, base_dir=tmp_path, where="c.yaml")
    up = boat_from_spec(
        {"builtin": "ilca7", "efficiency": {"upwind": 0.9, "downwind": 1.05}},
        base_dir=tmp_path,
        where="c.yaml",
    )
    assert up.speed(4.0, 40.0) == pytest.approx(0.9 * base.speed(4.0, 40.0), rel=2e-3)
    assert up.speed(4.0, 160.0) == pytest.approx(1.05 * base.speed(4.0, 160.0), rel=2e-3)
    with pytest.raises(InputError, match=r"c.yaml: boat.efficiency.upwnd: unknown key"):
        boat_from_spec(
            {"builtin": "ilca7", "efficiency": {"upwnd": 0.9}}, base_dir=tmp_path, where="c.yaml"
        )
    with pytest.raises(InputError, match=r"boat.efficiency.reach: expected a speed factor"):
        boat_from_spec(
            {"builtin": "ilca7", "efficiency": {"reach": 1.6}}, base_dir=tmp_path, where="c.yaml"
        )


# --- files, CLI ------------------------------------------------------------------------


# --- real logs (../shared, not redistributable: read in place) ----------------------------


def test_orc_speed_guide_reads_as_published() -> None:
    # TWS,TWA,BTV,VMG,AWS,AWA,Heel,Reef,Flat: BTV (target boat speed) is the speed column,
    # the rest is ignored; knots as published (row "6,52,5.11,3.14,...")
    from sailroute.units import KNOT

    guide = read_polar(ORC_GUIDE)
    assert guide.tws_ms[0] == pytest.approx(6 * KNOT) and guide.tws_ms[-1] == pytest.approx(
        20 * KNOT
    )
    for twa, kn in ((52.0, 5.11), (144.2, 4.11), (180.0, 3.03)):
        i = int(np.flatnonzero(guide.twa_deg == twa)[0])
        assert guide.speed_ms[i, 0] == pytest.approx(kn * KNOT, abs=1e-12)
