"""``report.html`` in a real browser: headless Chromium loads the page with the real plotly.js
bundle, offline, and must draw it without a console message.

What is checked, per page: Chromium's log has no console line at all (errors, warnings,
failed loads: every host name resolves to nothing, so a fetch would fail loudly); the
page's script marked the body ``data-map="drawn"`` (plotly's promise resolved, frames
added); the DOM holds the map's svg, the legend entries and the slider with the label of
the step asked for in the address (``#step=K``); the screenshot is not blank, shows the sea
colour over a large share of it and the boat marker, which moves from the start to the
finish as the slider goes from the first to the last step.

Chromium is the Debian package ``chromium`` (``.ci/run`` installs it); without one the
tests are skipped, unless ``SAILROUTE_REQUIRE_BROWSER=1`` (set by ``.ci/run``) makes that a
failure.  About 1-2 s per Chromium run.
"""

from __future__ import annotations

import dataclasses
import os
import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np
import pytest

from sailroute.planning.result import compare
from sailroute.report.html import comparison_report, plan_report
from sailroute.report.page import BOAT_COLOUR, N_STEPS, SEA, clock
from sailroute.report.page_render import write_report
from tests.report.cdp import OFFLINE_FLAGS


def find_chromium() -> str | None:
    """Path of a Chromium/Chrome executable, or None."""
    for name in ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable"):
        exe = shutil.which(name)
        if exe:
            return exe
    return "/usr/bin/chromium" if Path("/usr/bin/chromium").exists() else None


CHROMIUM = find_chromium()
REQUIRED = os.environ.get("SAILROUTE_REQUIRE_BROWSER") == "1"

pytestmark = [
    pytest.mark.browser,
    pytest.mark.skipif(
        CHROMIUM is None and not REQUIRED,
        reason="no Chromium installed (apt-get install chromium; "
        ".ci/run installs it and requires this test)",
    ),
]

FLAGS = [
    *OFFLINE_FLAGS,
    "--enable-logging=stderr",
    "--v=0",
    "--virtual-time-budget=10000",
]


def chromium(url: str, *args: str) -> subprocess.CompletedProcess[str]:
    """Run headless Chromium on ``url`` with a fresh profile; the console must stay silent."""
    assert CHROMIUM is not None, "SAILROUTE_REQUIRE_BROWSER=1 but no Chromium found"
    with tempfile.TemporaryDirectory(prefix="sailroute-chromium-") as profile:
        proc = subprocess.run(
            [CHROMIUM, *FLAGS, f"--user-data-dir={profile}", *args, url],
            capture_output=True,
            text=True,
            timeout=90,
        )
    assert proc.returncode == 0, proc.stderr[-2000:]
    console = [ln for ln in proc.stderr.splitlines() if "CONSOLE" in ln or "Uncaught" in ln]
    assert console == [], "\n".join(console)
    return proc


def dom(page: Path, step: int = 0) -> str:
    return chromium(f"{page.as_uri()}#step={step}", "--dump-dom").stdout


def screenshot(page: Path, out: Path, step: int = 0) -> np.ndarray:
    """RGB array [0, 255] of a 1200 x 1000 screenshot."""
    from matplotlib.image import imread

    chromium(f"{page.as_uri()}#step={step}", f"--screenshot={out}", "--window-size=1200,1000")
    img = imread(out)[..., :3]
    return np.round(img * 255.0).astype(int) if img.dtype != np.uint8 else img.astype(int)


def colour_mask(img: np.ndarray, hex_colour: str, tol: int = 12) -> np.ndarray:
    rgb = np.array([int(hex_colour[i : i + 2], 16) for i in (1, 3, 5)])
    return np.all(np.abs(img - rgb) <= tol, axis=-1)


def test_plan_page_draws_offline_with_slider_legend_and_boat(plan, wind, tmp_path):
    page = write_report(tmp_path / "report.html", plan_report(plan, wind))
    html = dom(page, step=N_STEPS - 1)
    assert 'data-map="drawn"' in html
    assert 'id="sailroute-error"></div>' in html  # no error shown
    assert "main-svg" in html and "slider-container" in html
    for entry in ("route: north", "marks", "lines and gates", "wind 9.7 kn from 0°"):
        assert f">{entry}</text>" in html, entry
    # the slider went to the last step: its current-value label is the arrival time
    assert f"time: {clock(plan.t_end, 7200)} local (UTC+02:00)" in html

    first = screenshot(page, tmp_path / "first.png", step=0)
    last = screenshot(page, tmp_path / "last.png", step=N_STEPS - 1)
    assert first.shape == (1000, 1200, 3)
    assert first.std() > 20  # not blank
    assert colour_mask(first, SEA).mean() > 0.15  # the sea background fills the map
    centres = []
    for img in (first, last):
        boat = colour_mask(img, BOAT_COLOUR, tol=30)
        assert boat.sum() > 30, "boat marker not visible"
        ys, xs = np.nonzero(boat)
        centres.append((xs.mean(), ys.mean()))
    # start at x = -50 m, finish line centre at x = +320 m: the boat moved east (right)
    assert centres[1][0] - centres[0][0] > 50


def test_comparison_page_lists_every_scenario(plan, wind, tmp_path):
    other = dataclasses.replace(plan, scenario="second")
    plans = [plan, other]
    page = write_report(
        tmp_path / "report.html", comparison_report(compare(plans), plans, {"north": wind})
    )
    html = dom(page, step=3)
    assert 'data-map="drawn"' in html
    for entry in ("north", "second", "wind 9.7 kn from 0°"):
        assert f">{entry}</text>" in html, entry
    assert html.count('class="traces"') >= 4  # legend rows (plotly draws one group each)
    assert "<summary>Legs: second</summary>" in html
