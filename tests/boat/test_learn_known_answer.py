"""Known answer: a fleet sailed by sailroute's own router on a known polar gives it back.

``tests/fleetgen.py`` routes a fleet of boats of known skill (each sails ``skill x`` the
ILCA 7 race polar exactly) round a windward-leeward course through a known shifting wind,
and records their tracks with GPS error (0.7 m white plus 1.5 m correlated over 60 s).
Each track gets the wind its boat sailed in as a measured channel, with instrument noise
(TWD 3 deg and TWS 5 %, independent from one second to the next).  The polar is learned
from the tracks and the course as ``sailroute polar fit`` does; the known answer of a
level at percentile ``q`` is the polar times the ``q``-th percentile of the boats' skills.

Every learned cell must hold the answer within three times its stated standard deviation
and nine in ten within twice it (for independent normal errors all of twenty cells lie
within 3 sd with probability 0.95, nine in ten within 2 sd with about that).
"""

from __future__ import annotations

from types import MappingProxyType

import numpy as np
import pytest

from sailroute.analysis.learnsamples import fleet_samples
from sailroute.boat.learn import LearnFit, learn_polar
from sailroute.boat.learn_blocks import steady_blocks
from sailroute.track.kinematics import track_xy
from sailroute.track.model import Track
from sailroute.units import KNOT, wind_speed_direction
from tests.fleetgen import FaultPlan, shared_fleet


def learned_from_fleet(seed: int, n_boats: int = 12) -> tuple[LearnFit, object]:
    fleet = shared_fleet(
        seed, n_boats=n_boats, minutes=40.0, faults=FaultPlan.clean(), sample_s=(1, 1),
        clock_lag_s=0.0,
    )  # fmt: skip
    rng = np.random.default_rng(seed + 100)
    tracks = []
    for tr in fleet.tracks:
        x, y = track_xy(tr, fleet.course.frame)
        tws, twd = wind_speed_direction(*fleet.wind.sample(tr.t_s, x, y))
        n = tr.t_s.size
        channels = {
            "tws_ms": np.asarray(tws) * (1.0 + rng.normal(0.0, 0.05, n)),
            "twd_deg": (np.asarray(twd) + rng.normal(0.0, 3.0, n)) % 360.0,
        }
        tracks.append(
            Track(tr.t_s, tr.lat_deg, tr.lon_deg, tr.name, tr.source, MappingProxyType(channels))
        )
    blocks = steady_blocks(fleet_samples(tracks, [fleet.course]).series)
    fit = learn_polar(
        blocks, tws_bins_ms=np.arange(8.0, 13.0) * KNOT, twa_bins_deg=np.arange(0.0, 181.0, 10.0)
    )
    return fit, fleet


def check(fit: LearnFit, fleet: object) -> None:
    lp = fit.learned
    skills = np.log([b.skill for b in fleet.boats])  # type: ignore[attr-defined]
    polar = fleet.polar  # type: ignore[attr-defined]
    learned = lp.status == "learned"
    assert learned.sum() >= 8
    assert (lp.twa_deg[learned.any(axis=1)] < 90).any() and (
        lp.twa_deg[learned.any(axis=1)] > 90
    ).any()
    for name, t in lp.levels.items():
        want = polar.speed(lp.tws_ms[None, :], lp.twa_deg[:, None]) * np.exp(
            np.percentile(skills, t.percentile)
        )
        z = np.log(t.speed_ms / want)[learned] / t.sd_log[learned]
        assert np.all(t.sd_log[learned] < 0.08), (name, t.sd_log[learned])
        assert np.all(np.abs(z) <= 3.0), (name, z)
        assert np.mean(np.abs(z) <= 2.0) >= 0.9, (name, z)


@pytest.mark.slow
def test_a_fleet_sailed_on_a_known_polar_gives_it_back() -> None:
    fit, fleet = learned_from_fleet(0)
    check(fit, fleet)
    # the boats beat at the polar's best angle: the learned one is its neighbour
    p = fit.learned.polar("median")
    tws = 10.0 * KNOT
    assert abs(p.vmg_upwind(tws)[0] - fleet.polar.vmg_upwind(tws)[0]) < 4.0


@pytest.mark.slow
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_other_fleets_give_it_back_too(seed: int) -> None:
    check(*learned_from_fleet(seed))
