"""``sailroute.analyze_track`` and ``sailroute analyze`` judge a track in the same wind by
default (``wind="auto"``, the command's ``--wind auto``).

On the shipped Snipe race (a GPS watch: no wind columns) both judge every leg in the
direction inferred from the track with the scenario's speed, and give the same legs to
the millisecond of the JSON; judged in the scenario's wind instead, the optimal side of
leg 1 changes, so the default is not a detail.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

import sailroute
from sailroute.cli import app
from tests.conftest import COURSES, ROOT

COURSE = COURSES / "snipe-valencia-p01.yaml"
GPX = ROOT / "data" / "snipe-valencia-2025-06-21-ESP30782-P01.gpx"


@pytest.fixture(scope="module")
def api() -> sailroute.TrackAnalysis:
    return sailroute.analyze_track(sailroute.load_course(COURSE), sailroute.read_track(GPX))


def test_api_and_cli_give_the_same_snipe_legs(api: sailroute.TrackAnalysis, tmp_path: Path) -> None:
    res = CliRunner().invoke(
        app, ["analyze", str(COURSE), str(GPX), "-o", str(tmp_path / "o"), "-q", "--json"]
    )
    assert res.exit_code == 0, res.output
    cli = json.loads(res.stdout)["legs"]
    assert len(api.legs) == len(cli) == 4
    for leg, doc in zip(api.legs, cli, strict=True):
        assert (leg.wind_source, doc["wind"]["source"]) == ("inferred", "inferred")
        assert leg.wind_label == doc["wind"]["label"]
        for key in ("sailed_time_s", "optimal_time_s", "loss_s"):
            assert getattr(leg, key) == pytest.approx(doc[key], abs=5e-4)  # JSON: 3 decimals
        assert (leg.side_sailed, leg.side_optimal) == (
            doc["side"]["sailed"],
            doc["side"]["optimal"],
        )
        assert leg.optimal_tacks == doc["optimal_tacks"]


def test_the_scenario_wind_is_asked_for_by_name(api: sailroute.TrackAnalysis) -> None:
    course = sailroute.load_course(COURSE)
    scen = sailroute.analyze_track(course, sailroute.read_track(GPX), wind="scenario")
    assert {leg.wind_source for leg in scen.legs} == {"scenario"}
    # the sailed legs are the track's either way; the optimal leg 1 goes another way
    assert [leg.sailed_time_s for leg in scen.legs] == [leg.sailed_time_s for leg in api.legs]
    assert scen.legs[0].side_optimal != api.legs[0].side_optimal
