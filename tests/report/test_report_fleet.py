"""The fleet's ``report.html`` (``sailroute.report.fleet``): the results, the tables with a
row per boat, colours by place, folded findings, the shared point budget, and in headless
Chromium at 1280 px with 60 boats: no sideways scroll in the results, a picked boat drawn in
its colour over grey ones.

Most tests build the page's input, :class:`FleetPage`, directly: 60 boats sailing the report
course of ``conftest.py`` (the routed track resampled at 1 Hz over 45 min, each boat a
little slower and to one side), their leg times known by construction, so every rank,
place and total is known before the page is built.
"""

from __future__ import annotations

import dataclasses
import html
import math
from pathlib import Path

import numpy as np
import pytest

from sailroute.report.fleet import (
    RANK_STOPS,
    FleetBoat,
    FleetLeg,
    FleetPage,
    boat_points,
    common_legs,
    fleet_report,
    fold_notes,
    leader,
    rank_colours,
    results_order,
)
from sailroute.report.page import (
    FLEET_POINTS,
    GREY,
    MAX_ROUTE_POINTS,
    MIN_BOAT_POINTS,
    NoteGroup,
    Route,
    decimated,
    route_from_plan,
)
from sailroute.report.page_figure import figure
from sailroute.report.page_render import read_figure, render_html, write_report

LEG_S = (1200.0, 900.0, 600.0)
"""Leg times of the first boat [s] (45 min in all); boat k sails each (1 + 0.004 k) as long."""


def _leg(time_s: float, elapsed_s: float, rank: int | None, position: int | None) -> FleetLeg:
    known = math.isfinite(time_s)
    return FleetLeg(
        time_s=time_s,
        rank=rank if known else None,
        elapsed_s=elapsed_s,
        position=position if math.isfinite(elapsed_s) else None,
        loss_s=0.1 * time_s if known else math.nan,
        manoeuvres_s=0.02 * time_s if known else math.nan,
        speed_s=0.03 * time_s if known else math.nan,
        route_s=0.05 * time_s if known else math.nan,
        polar="95",
        tacks=3,
        gybes=1,
        wind="scenario",
        note="" if known else "time unknown",
    )


def _track(course, base: Route, k: int, n_points: int, lag_s: float) -> Route:
    """The base route resampled at ``n_points`` over 45 min, ``lag_s`` behind the first
    boat and ``3 k`` m to its right."""
    s = np.linspace(0.0, sum(LEG_S), n_points)
    tb = base.t[0] + s / sum(LEG_S) * (base.t[-1] - base.t[0])
    x = np.interp(tb, base.t, base.x) + 3.0 * k
    y = np.interp(tb, base.t, base.y)
    lat, lon = course.frame.to_latlon(x, y)
    leg = base.leg[np.clip(np.searchsorted(base.t, tb, side="right") - 1, 0, base.t.size - 1)]
    ones = np.ones(n_points)
    man = tuple(
        (kind, course.start_epoch + lag_s + (t - base.t[0]) / (base.t[-1] - base.t[0]) * 2700, a, b)
        for kind, t, a, b in base.manoeuvres
    )
    return dataclasses.replace(
        base,
        name=f"boat {k + 1:02d}",
        t=course.start_epoch + lag_s + s,
        x=x,
        y=y,
        lat=np.asarray(lat, float),
        lon=np.asarray(lon, float),
        leg=leg.astype(np.int64),
        tws_kn=9.7 * ones,
        twa_deg=40.0 * ones,
        speed_kn=5.0 * ones,
        vmg_kn=3.8 * ones,
        manoeuvres=man,
        lat_shift=None,
        lon_shift=None,
    )


def synthetic_fleet(plan, n: int = 60, points: int = 2700, names=None) -> FleetPage:
    """``n`` boats of ``points`` fixes each (45 min at 1 Hz for 2700), given in a shuffled
    order; the last boat's finish is unknown (its data end in leg 3), the one before it
    lost leg 2's end (legs 2 and 3 unknown), and one boat did not start."""
    course = plan.course
    base = route_from_plan(plan)
    share = boat_points(n)
    boats = []
    for k in range(n):
        f = 1.0 + 0.004 * k
        times = [f * t for t in LEG_S]
        if k == n - 1:
            times[2] = math.nan
        if k == n - 2:
            times[1] = times[2] = math.nan
        elapsed = np.cumsum(times)
        legs = tuple(_leg(times[j], float(elapsed[j]), k + 1, k + 1) for j in range(len(LEG_S)))
        name = names[k] if names else f"boat {k + 1:02d}"
        boats.append(
            FleetBoat(
                name=name,
                route=decimated(
                    dataclasses.replace(_track(course, base, k, points, 2.0 * k), name=name),
                    share,
                ),
                legs=legs,
                start_t=course.start_epoch + 0.5 * k,
                late_s=0.5 * k,
                to_line_m=10.0 + k,
                side="pre-start",
                speed_kn=4.0,
                over_early="no",
                line_offset_m=0.0,
                notes=(f"late start: {0.5 * k:.1f} s after the gun",) if k % 3 == 0 else (),
                status="did not start" if k == 7 else "",
            )
        )
    rng = np.random.default_rng(5)
    order = rng.permutation(n)
    return FleetPage(
        course=course,
        boats=tuple(boats[i] for i in order),
        scenario="north",
        router="test",
        gun_t=course.start_epoch,
        notes=("every boat sailed the same course",),
        wind=("north", plan_wind()),
    )


def plan_wind():
    from sailroute.wind.uniform import UniformWind

    return UniformWind(5.0, 0.0)


@pytest.fixture(scope="module")
def plan_mod():
    """The report course's plan (conftest.py's ``plan``, module-scoped)."""
    from sailroute.course.load import course_from_mapping
    from sailroute.planning.result import make_plan
    from sailroute.routing.track import make_leg_result
    from tests.report.conftest import COURSE, timed_track

    course = course_from_mapping(COURSE)
    wind = plan_wind()
    t0 = course.start_epoch
    r1 = make_leg_result(timed_track([(-50, 0), (-550, 500), (0, 1000)], t0, wind), "test")
    r2 = make_leg_result(timed_track([(0, 1000), (200, 600), (10, 200)], r1.t_end, wind), "test")
    r3 = make_leg_result(timed_track([(10, 200), (320, 100)], r2.t_end, wind), "test")
    return make_plan(course, "north", [r1, r2, r3], wind)


@pytest.fixture(scope="module")
def fleet60(plan_mod) -> FleetPage:
    return synthetic_fleet(plan_mod)


# --- reading the structure ------------------------------------------------------------------


def test_results_finishers_by_time_then_how_far_then_not_ranked(fleet60) -> None:
    boats = fleet60.boats
    names = [boats[k].name for k in results_order(boats)]
    # boats 1..58 finished, in their order (boat 8 did not start); boat 60 reached the end
    # of leg 2, boat 59 only of leg 1; boat 8 last
    finishers = [f"boat {k:02d}" for k in range(1, 59) if k != 8]
    assert names == [*finishers, "boat 60", "boat 59", "boat 08"]
    # totals compare the legs every ranked boat has: leg 1 only (boat 59 lost legs 2, 3)
    assert common_legs(boats) == (0,)
    # the leader: ahead at the last leg end known for every ranked boat (leg 1's)
    assert boats[leader(boats)].name == "boat 01"
    # without the two boats of unknown legs, every leg counts
    ok = [b for b in boats if b.name not in ("boat 59", "boat 60")]
    assert common_legs(ok) == (0, 1, 2)


def test_the_leader_is_ahead_at_the_last_common_leg_end_even_with_its_finish_unknown(
    fleet60,
) -> None:
    # boat 01 leads every leg but its data end before the finish: it is not first of the
    # finishers, yet it is the leader (ahead where every boat's time is known)
    boats = [b for b in fleet60.boats if b.name not in ("boat 59", "boat 60")]
    first = next(b for b in boats if b.name == "boat 01")
    lost = dataclasses.replace(
        first,
        legs=(
            *first.legs[:2],
            dataclasses.replace(first.legs[2], time_s=math.nan, elapsed_s=math.nan),
        ),
    )
    boats = [lost if b is first else b for b in boats]
    order = [boats[k].name for k in results_order(boats)]
    assert order[0] == "boat 02" and order[-2] == "boat 01"  # before boat 08 (not ranked)
    assert boats[leader(boats)].name == "boat 01"
    assert common_legs(boats) == (0, 1)


def test_each_boat_draws_its_share_of_the_points() -> None:
    assert boat_points(60) == FLEET_POINTS // 60 == 666
    assert boat_points(2) == MAX_ROUTE_POINTS  # a small fleet: as a single boat's page
    assert boat_points(1000) == MIN_BOAT_POINTS


def test_rank_colours_run_from_dark_to_light_along_the_scale() -> None:
    cs = rank_colours(60)
    assert cs[0] == RANK_STOPS[0] and cs[-1] == RANK_STOPS[-1]
    assert len(set(cs)) == 60
    rgb = np.array([[int(c[i : i + 2], 16) for i in (1, 3, 5)] for c in cs]) / 255.0
    luma = rgb @ np.array([0.2126, 0.7152, 0.0722])
    assert np.all(np.diff(luma) > 0)  # every place lighter than the one before
    grey = np.array([int(GREY[i : i + 2], 16) for i in (1, 3, 5)])
    assert np.abs(rgb * 255 - grey).sum(axis=1).min() > 60  # never mistaken for the grey
    assert rank_colours(1) == [RANK_STOPS[0]] and rank_colours(0) == []


def test_findings_shared_by_boats_are_said_once() -> None:
    # a time stamp is one number, a mark named B1 is no number, a boat's own name in its
    # note (its file) does not keep it apart
    stamps = [
        ("p", "came back at 2025-06-21T11:23:33.863Z past B1"),
        ("q", "came back at 2025-06-21T11:24:02.100Z past B1"),
        ("p", "no wind in /data/p.csv"),
        ("q", "no wind in /data/q.csv"),
    ]
    assert fold_notes(stamps) == (
        NoteGroup(
            "2 boats: came back at … past B1",
            (
                "p: came back at 2025-06-21T11:23:33.863Z past B1",
                "q: came back at 2025-06-21T11:24:02.100Z past B1",
            ),
        ),
        NoteGroup(
            "2 boats: no wind in /data/….csv",
            ("p: no wind in /data/p.csv", "q: no wind in /data/q.csv"),
        ),
    )
    notes = [
        ("a", "OCS by 9 s: crossed the start line 9 s before the gun"),
        ("b", "gate passed outside its marks"),
        ("c", "OCS by 12 s: crossed the start line 12 s before the gun"),
        ("d", "gate passed outside its marks"),
        ("e", "the data stop 40 m short of 'top'"),
        ("f", "gate passed outside its marks"),
    ]
    assert fold_notes(notes) == (
        NoteGroup(
            "2 boats: OCS by … s: crossed the start line … s before the gun",
            (
                "a: OCS by 9 s: crossed the start line 9 s before the gun",
                "c: OCS by 12 s: crossed the start line 12 s before the gun",
            ),
        ),
        NoteGroup("3 boats: gate passed outside its marks", ("boats: b, d, f",)),
        NoteGroup("e: the data stop 40 m short of 'top'"),
    )


# --- the page -------------------------------------------------------------------------------


def test_tables_have_a_row_per_boat_in_the_results_order(fleet60) -> None:
    report = fleet_report(fleet60)
    results, legs, start, *per_leg = report.tables
    assert [t.name for t in report.tables] == [
        "results",
        "legs",
        "start",
        "leg-1",
        "leg-2",
        "leg-3",
    ]
    assert all(t.collapsed for t in per_leg) and not any(
        t.collapsed for t in (results, legs, start)
    )
    assert len(results.rows) == 60 and results.headers[:3] == ("place", "boat", "finish")
    names = [r[1] for r in results.rows]
    assert [r[1] for r in legs.rows] == names == [r[1] for r in start.rows]
    # places 1..57 for the finishers, "-" for the others; finish times as constructed
    assert [r[0] for r in results.rows] == [*map(str, range(1, 58)), "-", "-", "-"]
    first = results.rows[0]
    assert first[1] == "boat 01" and first[2] == "45:00.0" and first[3] == "0:00.0"
    assert results.rows[1][3] == "0:10.8"  # 2700 s × 0.004
    # sailed and lost over leg 1 only (the legs every ranked boat has)
    assert first[5] == "20:00.0" and first[6] == "+120.0"
    assert "over leg 1, the legs every boat's time is known for" in results.caption
    assert results.rows[-1][-1] == "did not start" and results.headers[-1] == "status"
    # sort keys: numbers where known, None where unknown
    assert results.keys[0][2] == pytest.approx(2700.0) and results.keys[-2][2] is None
    # each row picks its boat: the index of that boat among the routes with a marker
    boat_routes = [r for r in report.routes if r.boat]
    assert [boat_routes[i].name for i in results.boats] == names
    assert [boat_routes[i].name for i in legs.boats] == names
    # a column per leg, boats as rows
    assert legs.headers == ("place", "boat", "1: start → top", "2: top → gate", "3: gate → finish")
    assert legs.rows[0][2:] == ("20:00.0 (1)", "15:00.0 (1)", "10:00.0 (1)")
    assert legs.rows[-3][4] == "unknown" and legs.keys[-3][4] is None  # boat 60, leg 3


def test_routes_are_coloured_by_place_and_share_the_point_budget(fleet60) -> None:
    report = fleet_report(fleet60)
    boats = [r for r in report.routes if r.boat]
    assert len(boats) == len(report.routes) == 60  # no optimal route given
    assert [r.colour for r in boats] == rank_colours(60)
    assert [r.name for r in boats][:3] == ["boat 01", "boat 02", "boat 03"]
    assert all(r.t.size <= boat_points(60) + 2 * len(r.modes) for r in boats)
    assert sum(r.t.size for r in boats) <= FLEET_POINTS + 60 * 2 * 3


def test_the_figure_lets_the_page_pick_a_boat(fleet60) -> None:
    report = fleet_report(fleet60)
    fig = figure(report)
    pick = fig["pick"]
    data = fig["data"]
    assert len(pick["boats"]) == 60 and pick["grey"] == GREY
    for b, r in zip(pick["boats"], [r for r in report.routes if r.boat], strict=True):
        assert data[b["line"]]["name"] == r.name and data[b["line"]]["line"]["color"] == r.colour
        assert data[b["marker"]]["name"] == f"boat: {r.name}" and b["name"] == r.name
        assert b["colour"] == r.colour
    # the picked boat's line, tacks and gybes come last, empty; the course just before them
    hl = [data[i] for i in pick["highlight"]]
    assert pick["highlight"] == [len(data) - 3, len(data) - 2, len(data) - 1]
    assert [t["name"] for t in hl] == ["picked boat", "tacks", "gybes"] and hl[0]["x"] == []
    assert data[len(data) - 4]["name"] == "marks"
    # no tack or gybe traces per boat: they are in the pick entries
    assert sum(t["name"] in ("tacks", "gybes") for t in data) == 2
    base_tacks = sum(m[0] == "tack" for m in fleet60.boats[0].route.manoeuvres)
    assert all(len(b["tacks"]["x"]) == base_tacks for b in pick["boats"])
    # every frame moves the 60 markers
    assert all(len(fr["traces"]) == 60 for fr in fig["frames"])


def test_findings_are_folded_and_the_fleets_notes_kept(fleet60) -> None:
    report = fleet_report(fleet60)
    (late,) = report.folded
    assert late.summary == "20 boats: late start: … s after the gun"
    assert late.items[0] == "boat 01: late start: 0.0 s after the gun" and len(late.items) == 20
    assert "every boat sailed the same course" in report.notes
    page = render_html(report)
    assert page.count('<details class="note">') == 1
    assert page.count("late start: 0.0 s after the gun") == 1


BEATEN = (
    "the course polar (ILCA 7) is beaten by more than 10 % on 7 of 8 legs (each judged in the "
    "wind its boat had): it is not this fleet's boat, and the losses below are its error"
)


def test_a_beaten_course_polar_heads_the_page(fleet60) -> None:
    """The line that disowns every loss on the page is the first thing under the title,
    set apart, above the summary, the map and the tables, and said once."""
    report = fleet_report(dataclasses.replace(fleet60, banner=(BEATEN,)))
    assert report.banner == (BEATEN,) and BEATEN not in report.notes
    page = render_html(report)
    body = page[page.index("<h1>") :]
    first_p = body[body.index("<p") : body.index("</p>")]
    assert first_p == f'<p class="banner" role="note">{html.escape(BEATEN)}'
    assert body.index('class="banner"') < body.index('class="summary"') < body.index("<table")
    assert page.count("is beaten by more than 10 %") == 1
    assert 'class="banner"' not in render_html(fleet_report(fleet60))


def test_a_page_of_60_boats_of_45_min_at_1_hz_stays_small(fleet60) -> None:
    page = render_html(fleet_report(fleet60))
    assert len(page.encode()) < 6_000_000  # 2700 fixes per boat would make ~20 MB
    fig = read_figure(page)
    assert sum(len(fig["data"][b["line"]]["x"]) for b in fig["pick"]["boats"]) <= 40_400


# --- in Chromium ------------------------------------------------------------------------------

EVIL = '<b>x</b><script>document.title="pwned"</script>'


@pytest.mark.browser
def test_sixty_boats_in_chromium_at_1280_px(plan_mod, tmp_path: Path) -> None:
    from tests.report.cdp import browser, page_errors
    from tests.report.test_report_browser import CHROMIUM, REQUIRED

    if CHROMIUM is None and not REQUIRED:
        pytest.skip("no Chromium installed")
    assert CHROMIUM is not None
    names = [f"boat {k + 1:02d}" for k in range(60)]
    names[4] = EVIL  # fifth place
    report = fleet_report(synthetic_fleet(plan_mod, names=names))
    page = write_report(tmp_path / "report.html", report)
    colours = rank_colours(60)
    with browser(CHROMIUM, 1280, 900) as tab:
        tab.open(page.as_uri() + "#boat=boat%2003")
        assert tab.evaluate("document.body.getAttribute('data-map')") == "drawn"
        assert page_errors(tab.console) == []
        # the results table fits: nothing to scroll sideways, nor on the page
        sw, cw = tab.evaluate(
            "(function(){var d=document.getElementById('results').parentElement;"
            "return [d.scrollWidth, d.clientWidth];})()"
        )
        assert sw <= cw and cw > 1000
        assert tab.evaluate(
            "document.documentElement.scrollWidth <= document.documentElement.clientWidth"
        )
        # '#boat=boat 03' picked boat 03 (third): its line in its colour, the others grey
        assert tab.evaluate("document.body.getAttribute('data-boat')") == "boat 03"
        state = tab.evaluate(
            "(function(){var gd=document.getElementById('sailroute-map');"
            "var P=JSON.parse(document.getElementById('sailroute-figure').textContent).pick;"
            "return {lines: P.boats.map(function(b){return gd.data[b.line].line.color;}),"
            "hl: gd.data[P.highlight[0]].line.color, n: gd.data[P.highlight[0]].x.length,"
            "m: gd.data[P.boats[2].line].x.length};})()"
        )
        assert state["lines"][2] == colours[2] == state["hl"]
        assert all(c == GREY for i, c in enumerate(state["lines"]) if i != 2)
        assert state["n"] == state["m"] > 100  # the highlight is the boat's whole track
        # and the screenshot shows it: the picked colour on the map, no other place's colour
        img = _rgb(tab.screenshot(tmp_path / "picked.png"))
        assert _count(img, colours[2]) > 300
        assert sum(_count(img, c) for i, c in enumerate(colours) if abs(i - 2) > 3) < 30
        # a click on the fifth row of the results picks that boat (its name is text)
        tab.evaluate("document.querySelector('#results tbody tr:nth-child(5)').click()")
        tab.wait_for(f"document.body.getAttribute('data-boat') === {EVIL!r}")
        assert tab.evaluate("document.title") != "pwned"
        assert tab.evaluate("document.getElementById('sailroute-pick').value") == "4"
        assert (
            tab.evaluate(
                "document.querySelector('#results tbody tr.picked td:nth-child(2)').textContent"
            )
            == EVIL
        )
        # the legend shows the name as text: no bold, no script element from it
        assert EVIL in tab.evaluate(
            "Array.from(document.querySelectorAll('#sailroute-map .legendtext'))"
            ".map(function(t){return t.textContent;})"
        )
        assert tab.evaluate("document.querySelectorAll('#sailroute-map script').length") == 0
        # sorting: 'finish' descending puts the slowest finisher first, unknowns still last
        tab.evaluate(
            "(function(){var th=document.querySelectorAll('#results thead th')[2];"
            "th.click(); th.click();})()"
        )
        col = tab.evaluate(
            "Array.from(document.querySelectorAll('#results tbody tr'))"
            ".map(function(r){return r.cells[2].textContent;})"
        )
        assert col[0] == max(c for c in col if c != "unknown")
        assert col[-3:] == ["45:00.0", "unknown", "unknown"]  # boats 60 and 59 last
        assert page_errors(tab.console) == []


def _rgb(path: Path) -> np.ndarray:
    from matplotlib.image import imread

    img = imread(path)[..., :3]
    return np.round(img * 255.0).astype(int) if img.dtype != np.uint8 else img.astype(int)


def _count(img: np.ndarray, hex_colour: str, tol: int = 6) -> int:
    rgb = np.array([int(hex_colour[i : i + 2], 16) for i in (1, 3, 5)])
    return int(np.all(np.abs(img - rgb) <= tol, axis=-1).sum())


# --- from the analyses --------------------------------------------------------------------


def test_the_page_is_built_from_the_analyses_in_one_place(tmp_path_factory) -> None:
    """Three boats of the analysis tests' windward-leeward course: ``fast``, ``slow`` (a 360°
    turn on leg 1) and ``short`` (its data end before the first mark)."""
    from sailroute.analysis.debrief import analyze_track, fleet_ranking
    from sailroute.course.load import build_specs
    from sailroute.planning.route import route_course, settings_for
    from sailroute.report.fleet import fleet_page
    from tests.analysis.test_analyze import _course, _sailed

    course = _course(tmp_path_factory.mktemp("wl"))
    boat, winds = build_specs(course, ["steady"])
    legs = route_course(course, winds["steady"], boat, settings_for(course))
    fast = _sailed(course, legs)
    tracks = {
        "fast": fast,
        "slow": _sailed(course, legs, turn_at_s=60.0),
        "short": fast.between(fast.t_start, legs[0].t_end - 60.0),
    }
    analyses = [
        analyze_track(course, dataclasses.replace(tr, name=name), missing="unknown")
        for name, tr in tracks.items()
    ]
    rows = fleet_ranking(analyses)
    notes = [
        "short: no measured wind (/data/short.csv: no usable wind columns)",
        "fast: no measured wind (/data/fast.csv: no usable wind columns)",
        "the start line lay elsewhere",
    ]
    page = fleet_page(analyses, rows, notes)
    # the run's notes with the beaten-polar line first: it goes to the banner, only there
    told = fleet_page(analyses, rows, [BEATEN, *notes], banner=[BEATEN])
    assert told.banner == (BEATEN,) and told.notes == page.notes
    by = {b.name: b for b in page.boats}
    assert [b.name for b in page.boats] == ["fast", "slow", "short"]  # as given
    assert page.notes == ("the start line lay elsewhere",)  # the fleet's own
    assert by["fast"].notes[-1] == "no measured wind (/data/fast.csv: no usable wind columns)"
    assert by["short"].notes[0].startswith("leg 1 (start -> top): the track never rounds 'top'")
    # the leg ranking's ranks and positions, the analyses' times
    r = {(row["leg"], row["boat"]): row for row in rows}
    for b in page.boats:
        for j, leg in enumerate(b.legs):
            assert leg.rank == r[(j + 1, b.name)]["leg_rank"]
            assert leg.position == r[(j + 1, b.name)]["position"]
    a_fast = analyses[0]
    assert [g.time_s for g in by["fast"].legs] == [leg.sailed_time_s for leg in a_fast.legs]
    assert by["slow"].legs[0].rank == 2 and math.isnan(by["short"].finish_s)
    assert by["fast"].late_s == pytest.approx(a_fast.segmentation.start.late_s)
    # results: the finishers by finish time, then short; the leader is fast
    assert [page.boats[k].name for k in results_order(page.boats)] == ["fast", "slow", "short"]
    assert page.optimal is not None and page.optimal.name == "optimal from fast's leg starts"
    assert page.boats[leader(page.boats)].name == "fast"
    # no leg is known for short, so nothing is summed over legs every boat has
    assert common_legs(page.boats) == ()
    report = fleet_report(page)
    assert "over no leg, the legs every boat" in report.tables[0].caption
    assert [row[5] for row in report.tables[0].rows] == ["-", "-", "-"]
    folded = [g.summary for g in report.folded]
    assert "2 boats: no measured wind (/data/….csv: no usable wind columns)" in folded
    assert all(len(b.route.t) <= MAX_ROUTE_POINTS for b in page.boats)
