"""Names on the pages are text, never markup: marks named like HTML, a plotly placeholder or
an entity, through ``sailroute plan`` (marks, start line, laylines, favoured end) and in
Chromium (the labels, the legend and the hover read the names as written; nothing they
hold runs or renders as bold or a link)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
import yaml
from typer.testing import CliRunner

from sailroute.cli import app
from sailroute.report.page_render import read_figure
from tests.test_startline_outputs import course_mapping

NAMES = {
    "pin": '<b>pin</b><script>document.title="pwned"</script>',
    "boat": '<a href="http://example.invalid/">boat</a>',
    "top": "top %{y} &amp; <br>",
    "bottom": "<i>bottom</i>",
}
"""Each mark of the start-line course renamed."""

RAW = ("<b>pin", "<script", "<a href", "%{y}", "&amp; <br>", "<i>bottom")
"""What must never reach plotly as it stands (it would be markup or a placeholder)."""


def _strings(obj: Any) -> list[str]:
    if isinstance(obj, str):
        return [obj]
    if isinstance(obj, dict):
        return [s for v in obj.values() for s in _strings(v)]
    if isinstance(obj, list):
        return [s for v in obj for s in _strings(v)]
    return []


@pytest.fixture(scope="module")
def planned(tmp_path_factory: pytest.TempPathFactory) -> Path:
    text = json.dumps(course_mapping())
    for old, new in NAMES.items():
        text = text.replace(f'"{old}"', json.dumps(new))
    d = tmp_path_factory.mktemp("evil")
    course = d / "evil.yaml"
    course.write_text(yaml.safe_dump(json.loads(text)), encoding="utf-8")
    out = d / "out"
    res = CliRunner().invoke(app, ["plan", str(course), "-q", "--out", str(out)])
    assert res.exit_code == 0, res.output
    return out / "report.html"


def test_no_name_reaches_plotly_as_markup(planned: Path) -> None:
    fig = read_figure(planned.read_text(encoding="utf-8"))
    names = [t.get("name") for t in fig["data"]]
    assert "favoured end" in names and "laylines" in names  # the overlays are there
    texts = _strings({k: fig[k] for k in ("data", "layout", "frames")})
    for raw in RAW:
        assert not [s for s in texts if raw in s], raw
    marks = next(t for t in fig["data"] if t["name"] == "marks")
    assert any("&lt;b&gt;pin&lt;/b&gt;&lt;script&gt;" in t for t in marks["text"])
    assert any("layline to &lt;i&gt;bottom&lt;/i&gt;" in s for s in texts)
    assert any("favoured end &lt;a href=" in s for s in texts)
    assert any("top &#37;{y} &amp;amp; &lt;br&gt;" in s for s in texts)


@pytest.mark.browser
def test_names_read_as_written_in_chromium(planned: Path) -> None:
    from tests.report.cdp import browser, page_errors
    from tests.report.test_report_browser import CHROMIUM, REQUIRED

    if CHROMIUM is None and not REQUIRED:
        pytest.skip("no Chromium installed")
    assert CHROMIUM is not None
    with browser(CHROMIUM, 1280, 900) as tab:
        tab.open(planned.as_uri())
        assert tab.evaluate("document.body.getAttribute('data-map')") == "drawn"
        labels = tab.evaluate(
            "Array.from(document.querySelectorAll("
            "'#sailroute-map .textpoint text, #sailroute-map .annotation-text'))"
            ".map(function(t){return t.textContent;})"
        )
        assert set(NAMES.values()) <= set(labels)  # with the leg numbers
        # nothing of the names became an element: no link, no bold or italic run, no script
        assert tab.evaluate("document.querySelectorAll('#sailroute-map a').length") == 0
        assert (
            tab.evaluate(
                "Array.from(document.querySelectorAll('#sailroute-map tspan'))"
                ".filter(function(t){var s=t.getAttribute('style')||'';"
                "return /font-weight|font-style/.test(s);}).length"
            )
            == 0
        )
        # the hover of a layline and of the favoured end name the marks as written (plotly
        # ignores a hover within 50 ms of the last: one every 150 ms)
        hovers = [
            tab.evaluate(
                "new Promise(function(done){setTimeout(function(){"
                "var gd=document.getElementById('sailroute-map');"
                f"var i=gd.data.findIndex(function(t){{return t.name==={name!r};}});"
                "Plotly.Fx.hover(gd,[{curveNumber:i,pointNumber:0}]);"
                "done(document.querySelector('#sailroute-map .hoverlayer').textContent);"
                "},150);})"
            )
            for name in ("laylines", "favoured end")
        ]
        assert hovers[0].endswith(f"layline to {NAMES['top']}"), hovers
        assert hovers[1].startswith(f"favoured end {NAMES['boat']}: bias"), hovers
        assert tab.evaluate("document.title") != "pwned"
        assert page_errors(tab.console) == []
