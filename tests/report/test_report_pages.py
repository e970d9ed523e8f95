"""The pages of an output folder share one plotly.js, written with the folder's other files
as one set; ``analyze`` on a fleet writes the boats' pages only with ``--pages boat``.

The fleet: the shipped Snipe track (``data/``) and two copies of it, 5 s and 10 s behind and
4 m and 8 m to the north, as GPX files.
"""

from __future__ import annotations

import json
import os
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from sailroute.cli import app
from sailroute.outdir import MANIFEST_NAME, write_output_set
from sailroute.report.html import plan_report
from sailroute.report.page_render import PLOTLY_FILE, plotly_js, write_plotly_js, write_report
from tests.conftest import ROOT

COURSE = ROOT / "courses" / "snipe-valencia-p01.yaml"
TRACK = ROOT / "data" / "snipe-valencia-2025-06-21-ESP30782-P01.gpx"
BOATS = ("ESP1", "ESP2", "ESP3")


@pytest.fixture(scope="module")
def tracks(tmp_path_factory: pytest.TempPathFactory) -> list[Path]:
    from benchmarks.bench_analyze import write_gpx
    from sailroute.course.load import load_course
    from sailroute.track.read import read_track

    course = load_course(COURSE)
    tr = read_track(TRACK)
    keep = tr.t_s >= course.start_epoch - 60.0
    t, lat, lon = tr.t_s[keep], tr.lat_deg[keep], tr.lon_deg[keep]
    d = tmp_path_factory.mktemp("snipe")
    return [
        write_gpx(d / f"{name}.gpx", t + 5.0 * k, lat + 4.0 * k / 111_320.0, lon)
        for k, name in enumerate(BOATS)
    ]


def _analyze(tracks: list[Path], out: Path, *extra: str):
    res = CliRunner().invoke(
        app, ["analyze", str(COURSE), *map(str, tracks), "-q", "-o", str(out), *extra]
    )
    return res


def _script_src(page: Path) -> str:
    (src,) = re.findall(r'<script src="([^"]*)"', page.read_text(encoding="utf-8"))
    return src


def _files(out: Path) -> set[str]:
    return {p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file()}


@pytest.fixture(scope="module")
def fleet_default(tracks, tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("fleet") / "out"
    res = _analyze(tracks, out)
    assert res.exit_code == 0, res.output
    return out


def test_a_fleet_writes_one_page_and_the_boats_data(fleet_default: Path) -> None:
    out = fleet_default
    per_boat = {"analysis.json", "analysis.csv", "points.csv"}
    assert _files(out) == {
        "fleet.csv",
        "fleet.json",
        "report.html",
        PLOTLY_FILE,
        MANIFEST_NAME,
        *(f"{b}/{f}" for b in BOATS for f in per_boat),
    }
    assert _script_src(out / "report.html") == PLOTLY_FILE
    assert (out / PLOTLY_FILE).read_text(encoding="utf-8") == plotly_js()
    listed = json.loads((out / MANIFEST_NAME).read_text())["files"]
    assert PLOTLY_FILE in listed  # part of the run's set


@pytest.fixture(scope="module")
def fleet_pages(tracks, tmp_path_factory) -> tuple[Path, str]:
    out = tmp_path_factory.mktemp("fleet") / "out"
    res = _analyze(tracks, out, "--pages", "boat")
    assert res.exit_code == 0, res.output
    return out, res.output


def test_boat_pages_on_request_share_the_folders_plotly(fleet_pages, tracks, tmp_path) -> None:
    written, output = fleet_pages
    out = tmp_path / "out"
    shutil.copytree(written, out)
    files = _files(out)
    assert [f for f in files if f.endswith(".js")] == [PLOTLY_FILE]  # one copy
    for b in BOATS:
        assert {f"{b}/report.html", f"{b}/legs.png", f"{b}/loss.png"} <= files
        page = out / b / "report.html"
        assert _script_src(page) == f"../{PLOTLY_FILE}"
        assert (page.parent / _script_src(page)).resolve() == (out / PLOTLY_FILE).resolve()
        assert page.stat().st_size < 1_000_000  # the bundle is not inside
    # the "wrote" lines name the bundle once
    assert output.count(PLOTLY_FILE) == 1, output
    # a run without pages replaces the set: the bundle and the pages go, a user's file stays
    (out / "mine.txt").write_text("notes", encoding="utf-8")
    res = _analyze(tracks, out, "--no-plots")
    assert res.exit_code == 0, res.output
    assert not (out / PLOTLY_FILE).exists() and not (out / "report.html").exists()
    assert not (out / BOATS[0] / "report.html").exists()
    assert (out / "mine.txt").read_text(encoding="utf-8") == "notes"


def test_pages_option_is_checked(tracks, tmp_path: Path) -> None:
    res = _analyze(tracks, tmp_path / "o", "--pages", "every")
    assert res.exit_code == 2 and "--pages" in res.output and "'fleet'" in res.output
    assert not (tmp_path / "o").exists()


def test_a_failed_run_leaves_the_folders_bundle_as_it_was(plan, wind, tmp_path: Path) -> None:
    out = tmp_path / "out"
    write_output_set(out, lambda d: write_report(d / "report.html", plan_report(plan, wind)))
    before = (out / PLOTLY_FILE).stat()

    def half(d: Path) -> None:
        write_plotly_js(d)
        raise KeyboardInterrupt  # interrupted after the bundle, before the page

    with pytest.raises(KeyboardInterrupt):
        write_output_set(out, half)
    assert _files(out) == {"report.html", PLOTLY_FILE, MANIFEST_NAME}
    after = (out / PLOTLY_FILE).stat()
    assert (after.st_ino, after.st_mtime_ns) == (before.st_ino, before.st_mtime_ns)


def test_the_bundle_is_written_whole_and_never_through_a_link(tmp_path: Path) -> None:
    theirs = tmp_path / "theirs.js"
    theirs.write_text("someone else's file", encoding="utf-8")
    d = tmp_path / "pages"
    d.mkdir()
    os.symlink(theirs, d / PLOTLY_FILE)
    p = write_plotly_js(d)
    assert not p.is_symlink() and p.read_text(encoding="utf-8") == plotly_js()
    assert theirs.read_text(encoding="utf-8") == "someone else's file"
    assert sorted(x.name for x in d.iterdir()) == [PLOTLY_FILE]  # no temporary file left
    # a second page of the folder leaves the bundle alone
    mtime = p.stat().st_mtime_ns
    assert write_plotly_js(d) == p and p.stat().st_mtime_ns == mtime


@pytest.mark.browser
def test_pages_open_offline_from_disk_and_say_when_the_bundle_is_missing(
    fleet_pages, tmp_path: Path
) -> None:
    from tests.report.cdp import browser, page_errors
    from tests.report.test_report_browser import CHROMIUM, REQUIRED

    if CHROMIUM is None and not REQUIRED:
        pytest.skip("no Chromium installed")
    assert CHROMIUM is not None
    out = fleet_pages[0]
    with browser(CHROMIUM) as tab:
        for page in (out / "report.html", out / BOATS[1] / "report.html"):
            tab.open(page.as_uri())
            assert tab.evaluate("document.body.getAttribute('data-map')") == "drawn"
            assert tab.evaluate("document.querySelectorAll('#sailroute-map .scatterlayer').length")
        assert page_errors(tab.console) == []
        # the page copied away from its folder says what is missing
        alone = tmp_path / "alone"
        alone.mkdir()
        (alone / "report.html").write_bytes((out / "report.html").read_bytes())
        tab.open((alone / "report.html").as_uri())
        assert tab.evaluate("document.body.getAttribute('data-map')") == "failed"
        msg = tab.evaluate("document.getElementById('sailroute-error').textContent")
        assert "plotly.min.js did not load" in msg and "output folder" in msg
        # the tables still sort without the map
        tab.evaluate("document.querySelectorAll('#results thead th')[1].click()")
        names = tab.evaluate(
            "Array.from(document.querySelectorAll('#results tbody tr'))"
            ".map(function(r){return r.cells[1].textContent;})"
        )
        assert names == sorted(BOATS)


@pytest.mark.slow
def test_sixty_boats_of_45_min_at_1_hz_write_under_50_mb(tmp_path: Path) -> None:
    """60 copies of the Snipe track slowed to 1.8 times its duration (50 min from a minute
    before the gun, resampled at 1 Hz), 1.5 s apart and 0.3 m to the side of each other:
    1.5-3 m apart along the track at any time, more than the 1 m within which two tracks
    are one boat's data twice."""
    from benchmarks.bench_analyze import write_gpx
    from sailroute.commands.analyze import run_analyze_command
    from sailroute.course.load import load_course
    from sailroute.track.read import read_track

    course = load_course(COURSE)
    tr = read_track(TRACK)
    gun = course.start_epoch
    keep = tr.t_s >= gun - 60.0
    ts = gun + (tr.t_s[keep] - gun) * 1.8
    t = np.arange(np.ceil(ts[0]), ts[-1], 1.0)
    lat, lon = np.interp(t, ts, tr.lat_deg[keep]), np.interp(t, ts, tr.lon_deg[keep])
    assert t.size > 2700
    boats = [
        write_gpx(tmp_path / f"b{k:02d}.gpx", t + 1.5 * k, lat + 0.3 * k / 111_320.0, lon)
        for k in range(60)
    ]
    out = tmp_path / "out"
    res = run_analyze_command(course, boats, out_dir=out)
    assert sum(a.complete for a in res.data) >= 55  # the copies finish: a real fleet's page
    sizes = {p.relative_to(out).as_posix(): p.stat().st_size for p in out.rglob("*") if p.is_file()}
    assert sum(sizes.values()) < 50_000_000
    assert sizes["report.html"] < 8_000_000
    pages = sorted(f for f in sizes if f.endswith((".html", ".js", ".png")))
    assert pages == sorted(["report.html", PLOTLY_FILE])  # no page per boat by default
