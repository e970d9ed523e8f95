"""``analyze --reference learned``: a fleet that beats the course's polar is told so at the
top, and judged against the polar learned from its own tracks
(:mod:`sailroute.analysis.fleetlearn`)."""

from __future__ import annotations

import json
import re
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from sailroute.analysis.fleetlearn import BEATEN_PCT, beaten_legs, beaten_note
from sailroute.boat.build import builtin_polar
from sailroute.boat.io import write_polar_json
from sailroute.boat.polar import Polar
from sailroute.commands.analyze import run_analyze_command
from sailroute.commands.result import CommandResult
from sailroute.course.load import load_course
from sailroute.errors import InputError
from tests.conftest import ROOT, requires_shared
from tests.fleetgen import FaultPlan, messy_fleet

FAST = 1.25
"""The fleet's polar: the course's ILCA 7 times this (with the boats' skills of 0.88-1,
they sail 10-25 % faster than the course's polar)."""


def _legs(*pairs: tuple[float, float]) -> SimpleNamespace:
    """An analysis with legs of ``(sailed, optimal)`` times [s]."""
    return SimpleNamespace(
        legs=[
            SimpleNamespace(known=np.isfinite(s), sailed_time_s=s, optimal_time_s=o)
            for s, o in pairs
        ]
    )


def test_a_leg_beats_the_polar_when_sailed_more_than_ten_percent_faster() -> None:
    a = _legs((100.0, 111.0), (100.0, 110.0), (100.0, 95.0), (np.nan, 120.0))
    b = _legs((200.0, 230.0))
    # 111 > 1.1 x 100 beats; 110 does not; the unknown leg does not count
    assert BEATEN_PCT == 10.0
    assert beaten_legs([a, b]) == (2, 4)
    assert beaten_note([a, b], "ILCA 7") is None  # 2 of 4 is not most
    note = beaten_note([a, b, _legs((100.0, 120.0))], "ILCA 7")
    assert note is not None and "beaten by more than 10 % on 3 of 5 legs" in note
    assert "--reference learned" in note


@pytest.fixture(scope="module")
def fast_fleet(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[Path]]:
    """Eight boats sailing a polar 25 % faster than the course's ILCA 7."""
    d = tmp_path_factory.mktemp("fast")
    p = builtin_polar("ilca7")
    pf = write_polar_json(
        Polar.from_arrays(p.twa_deg, p.tws_ms, FAST * p.speed_ms, name="fast"), d / "fast.json"
    )
    fleet = messy_fleet(1, n_boats=8, minutes=20, faults=FaultPlan.clean(), boat=str(pf))
    course, tracks = fleet.write(d / "fleet")
    text = re.sub(r"^boat:.*$", "boat: {builtin: ilca7}", course.read_text(), count=1, flags=re.M)
    course.write_text(text)
    assert load_course(course).boat_spec == {"builtin": "ilca7"}
    return course, tracks


def _relative_losses(res: CommandResult) -> np.ndarray:
    return np.array(
        [leg.loss_s / leg.optimal_time_s for a in res.data for leg in a.legs if leg.known]
    )


@pytest.mark.slow
def test_a_fleet_faster_than_the_course_polar_is_told_and_judged_by_its_own(
    fast_fleet: tuple[Path, list[Path]], tmp_path: Path
) -> None:
    course, tracks = fast_fleet
    res = run_analyze_command(course, tracks, out_dir=tmp_path / "course")
    first = res.report.splitlines()[0]
    assert first.startswith("note: the course polar (ILCA 7) is beaten by more than 10 %")
    doc = json.loads((tmp_path / "course" / "fleet.json").read_text())
    assert any(n.startswith("the course polar (ILCA 7) is beaten") for n in doc["notes"])
    # the fleet's page and one boat's: the line heads the page, above its tables, once
    one = run_analyze_command(course, tracks[:1], out_dir=tmp_path / "one")
    assert one.report.startswith("note: the course polar (ILCA 7) is beaten")
    for page in (tmp_path / "course" / "report.html", tmp_path / "one" / "report.html"):
        body = page.read_text(encoding="utf-8").split("<h1>", 1)[1]
        assert body.split("<p", 1)[1].startswith(' class="banner" role="note">the course polar')
        assert body.index('class="banner"') < body.index("<table")
        assert body.count("is beaten by more than 10 %") == 1
    # against the course's polar the fleet "gains" about a tenth of every leg
    assert np.median(_relative_losses(res)) < -0.1
    learned = run_analyze_command(
        course, tracks, out_dir=tmp_path / "learned", plots=False, reference="learned"
    )
    assert not learned.report.startswith("note: the course polar")
    rel = _relative_losses(learned)
    # the median boat's legs at its race pace: the median leg loss near 0
    assert abs(np.median(rel)) < 0.02
    ref = learned.data.analyses[0].reference
    assert ref.startswith("polar learned from this fleet") and "median boat of 8" in ref
    # --reference fleet: the same fleet, the course polar scaled per point of sail
    fleet = run_analyze_command(
        course, tracks, out_dir=tmp_path / "fleet", plots=False, reference="fleet"
    )
    assert fleet.data.analyses[0].reference.startswith("fleet-relative polar")
    assert not fleet.report.startswith("note: the course polar")


def test_an_unknown_reference_lists_the_three(tmp_path: Path) -> None:
    course = ROOT / "tests" / "data" / "course" / "minimal.yaml"
    with pytest.raises(InputError, match="--reference: expected one of course, fleet, learned"):
        run_analyze_command(course, [tmp_path / "a.gpx"], reference="peers", plots=False)


@pytest.mark.slow
@requires_shared
def test_sailgp_legs_against_the_fleet_learned_polar(tmp_path: Path) -> None:
    """SailGP race 25011905 (three F50s, measured wind): sailed 5-46 % below the F50
    target polar, the median leg loses 12 % of its time against it; against the polar
    learned from the three boats' own race the median leg loses nothing."""
    from tests.analysis.test_sailgp_fleet import BOATS, RACE, XML, course_from_xml

    tracks = [RACE / "Boat_logs" / f"data_{b}.csv" for b in BOATS]
    course = load_course(course_from_xml(XML, 21.4, 61.0, tmp_path / "race.yaml"))
    kw = {"time_zone": "UTC", "plots": False, "gate_end": "rounding"}
    f50 = run_analyze_command(course, tracks, out_dir=tmp_path / "f50", **kw)
    assert not f50.report.startswith("note: the course polar")  # not beaten: too fast
    assert np.median(_relative_losses(f50)) > 0.1
    own = run_analyze_command(course, tracks, out_dir=tmp_path / "own", reference="learned", **kw)
    assert abs(np.median(_relative_losses(own))) < 0.05
    assert "median boat of 3" in own.data.analyses[0].reference
