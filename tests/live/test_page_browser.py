"""The coach's page in headless Chromium, on a tablet (1024 x 768) and a laptop screen
(1920 x 1080): drawn without a console message, full width, with its legend, scale bar,
north arrow, the sailor's boat, track and COG vector, laylines with their distances, ETA
per mark, the wind trend's axes and units, and mark labels whose boxes do not overlap.

The screenshots are written to the test's temporary folder (printed with ``-s``).
"""

from __future__ import annotations

import html
import itertools
import re
from pathlib import Path

import numpy as np
import pytest

from sailroute.course.load import build_specs
from sailroute.live.engine import LiveEngine, LiveSettings
from sailroute.live.sources import NmeaFileSource
from tests.live.feed import ais_sentence, approach, lines_of, sailed_track, trieste
from tests.report.test_report_browser import CHROMIUM, REQUIRED, chromium

pytestmark = [
    pytest.mark.browser,
    pytest.mark.slow,
    pytest.mark.skipif(
        CHROMIUM is None and not REQUIRED,
        reason="no Chromium installed (apt-get install chromium; .ci/run installs it)",
    ),
]

MMSI = 247000777
# this page is served from 127.0.0.1: every other host still resolves to nothing (the last
# --host-resolver-rules given wins over the report test's)
LOCAL = "--host-resolver-rules=MAP * ~NOTFOUND , EXCLUDE 127.0.0.1"


def build_engine(tmp_path: Path) -> LiveEngine:
    """An engine with a plan: the coach boat idles below the start, the sailor's boat (AIS)
    is half-way up the second beat; 10 minutes of wind veering 10°."""
    course = trieste()
    boat, winds = build_specs(course, ["mean"])
    polar = boat.routing_polar()
    assert polar is not None
    t, x, y = sailed_track(course, winds["mean"], polar, step_s=2.0)
    k_end = int(np.searchsorted(t, t[0] + 0.62 * (t[-1] - t[0])))
    lat, lon = course.frame.to_latlon(x, y)
    eng = LiveEngine(
        course,
        winds["mean"],
        boat,
        course.routing,
        NmeaFileSource(tmp_path / "none.nmea"),
        LiveSettings(stale_s=600.0),
        port=0,
        nmea_port=None,
        sailor=str(MMSI),
    )
    eng._feeds[0].linked = True
    coach = approach(
        course,
        int(t[k_end] - t[0]) + 1,
        speed_ms=0.0,
        start_back_m=250.0,
        t0=float(t[0]),
        twd=lambda s: 60.0 + 10.0 * s / 600.0,
    )
    k = 0
    for row in coach:
        for line in lines_of([row]):
            eng.feed(line)
        while k <= k_end and t[k] <= row.t:
            dx, dy = x[min(k + 1, k_end)] - x[k], y[min(k + 1, k_end)] - y[k]
            cog = float(np.degrees(np.arctan2(dx, dy)) % 360)
            sog = float(np.hypot(dx, dy) / 2.0 / 0.514444)
            eng.feed(ais_sentence(MMSI, lat[k], lon[k], sog, cog, cog, int(t[k]) % 60))
            k += 1
    with eng._lock:
        due = eng._due()
    assert due is not None
    assert eng.replan(due[1]) is not None
    return eng


def _boxes(dom: str) -> list[tuple[str, float, float, float, float]]:
    out = []
    for m in re.finditer(r"<text[^>]*class=\"mark-label\"[^>]*>([^<]*)</text>", dom):
        tag = m.group(0)
        vals = [
            float(re.search(rf'data-{k}="([-\d.]+)"', tag).group(1))
            for k in ("x0", "y0", "x1", "y1")
        ]  # type: ignore[union-attr]
        out.append((html.unescape(m.group(1)), *vals))
    return out


@pytest.mark.parametrize(("width", "height"), [(1024, 768), (1920, 1080)])
def test_live_page_on_a_tablet_and_a_screen(tmp_path: Path, width: int, height: int) -> None:
    eng = build_engine(tmp_path)
    assert eng.page is not None
    try:
        url = eng.page.url
        size = f"--window-size={width},{height}"
        dom = chromium(url, LOCAL, "--dump-dom", size).stdout
        shot = tmp_path / f"live-{width}x{height}.png"
        chromium(url, LOCAL, f"--screenshot={shot}", size)
    finally:
        eng.close()
    print(f"screenshot: {shot}")
    assert 'data-drawn="1"' in dom
    # full width: one column on the tablet, the map beside a 340-px panel on the screen
    map_w = float(re.search(r'data-map-width="(\d+)"', dom).group(1))  # type: ignore[union-attr]
    assert map_w > (0.95 * width - 30 if width < 1100 else 0.95 * (width - 340) - 40), map_w
    for text in (
        "route</span>",
        "starboard layline</span>",
        "port layline</span>",
        "sailor's boat, track, COG",
        "coach boat",
        ">N</text>",
        "TWD from (°)</text>",
        "TWS (kn)</text>",
        "minutes ago</text>",
        "wind from ",
        "0 readings held out",
    ):
        assert text in dom, text
    assert re.search(r'id="scale-label"[^>]*>\d+ m</text>', dom)
    # the laylines in the measured wind, with distance and time; the ETA of every leg left
    assert re.search(r"<td>starboard \(\d+°\)</td><td class=\"n\">(\d+ m|past by \d+ m)", dom)
    assert dom.count("<td>3: 4 -&gt; 1</td>") + dom.count("<td>4: 1 -&gt; finish</td>") == 2
    assert dom.count('fill="#8e44ad"') >= 1  # the sailor's boat
    assert re.search(r'<polyline points="[^"]+" fill="none" stroke="#8e44ad"', dom)  # its track
    boxes = _boxes(dom)
    assert sorted(b[0] for b in boxes) == sorted(eng.course.marks)
    for a, b in itertools.combinations(boxes, 2):
        apart = a[3] <= b[1] or b[3] <= a[1] or a[4] <= b[2] or b[4] <= a[2]
        assert apart, (a, b)
    from matplotlib.image import imread

    img = imread(shot)[..., :3]
    assert img.shape[:2] == (height, width) and img.std() > 0.05  # drawn, not blank
