"""``report.html`` as text: the page around the figure, its tables, and the file.

The drawing is `plotly.js <https://plotly.com/javascript/>`_, inlined into the file (about
4.8 MB; no CDN, no network), read only when a page is written (:func:`plotly_js`).  The
figure's JSON sits in ``<script type="application/json" id="sailroute-figure">``, so tests
and other tools can read exactly what is drawn (:func:`read_figure`).
"""

from __future__ import annotations

import html
import json
import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from sailroute._version import __version__
from sailroute.report.page import DIV_ID, FIGURE_ID, Report, Table, course_area
from sailroute.report.page_figure import figure
from sailroute.textin import clean_text

__all__ = ["map_height", "plotly_js", "read_figure", "render_html", "write_report"]


_CSS = """
body { font-family: Helvetica, Arial, sans-serif; margin: 16px 24px; color: #222; }
h1 { font-size: 20px; margin: 0 0 6px 0; }
h2 { font-size: 16px; margin: 18px 0 6px 0; }
p.summary { margin: 2px 0; }
#sailroute-map { width: 100%; }
p.note { font-size: 12px; color: #555; margin: 2px 0; }
div.table { overflow-x: auto; }
table { border-collapse: collapse; font-size: 13px; margin: 4px 0 12px 0; }
th, td { border: 1px solid #ccc; padding: 3px 7px; text-align: right; white-space: nowrap; }
th { background: #eef3f7; }
td.l, th.l { text-align: left; }
tfoot td { font-weight: bold; background: #f7f7f7; }
#sailroute-error { color: #b00; font-weight: bold; }
footer { font-size: 11px; color: #777; margin-top: 16px; }
"""


# Draws the figure; ``#step=K`` in the address opens the slider at step K.  The body gets
# data-map="drawn" once everything is done (the browser test reads it); an error is shown
# on the page instead of failing silently.
_JS = """
(function () {
  var box = document.getElementById('sailroute-error');
  function fail(e) { box.textContent = 'The map could not be drawn: ' + e;
                     document.body.setAttribute('data-map', 'failed'); }
  try {
    var fig = JSON.parse(document.getElementById('%(fig)s').textContent);
    var gd = document.getElementById('%(div)s');
    Plotly.newPlot(gd, fig.data, fig.layout, fig.config).then(function () {
      return fig.frames.length ? Plotly.addFrames(gd, fig.frames) : null;
    }).then(function () {
      var m = /step=(\\d+)/.exec(window.location.hash);
      if (m && fig.frames.length) {
        var k = Math.min(parseInt(m[1], 10), fig.frames.length - 1);
        return Plotly.animate(gd, [String(k)], {mode: 'immediate', transition: {duration: 0},
                                                 frame: {duration: 0, redraw: true}})
          .then(function () { return Plotly.relayout(gd, {'sliders[0].active': k}); });
      }
      return null;
    }).then(function () { document.body.setAttribute('data-map', 'drawn'); }, fail);
  } catch (e) { fail(e); }
})();
"""


def _h(text: str) -> str:
    """User text for the page's HTML: escaped, control characters replaced."""
    return html.escape(clean_text(text))


def _json_for_script(obj: Any) -> str:
    """JSON safe inside a ``<script>`` element (no ``<``, ``>`` or ``&`` characters)."""
    text = json.dumps(obj, ensure_ascii=False, separators=(",", ":"), allow_nan=False)
    return text.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")


_LEFT = ' class="l"'


_TEXT_COLUMNS = (
    "from → to",
    "mode",
    "start point",
    "tacks/gybes sailed : optimal",
    "side sailed / optimal",
    "boat",
    "note",
    "notes",
)
"""Table columns aligned left (text); the others are numbers, aligned right."""


def _table_html(t: Table) -> str:
    left = {i for i, h in enumerate(t.headers) if h in _TEXT_COLUMNS}

    def cells(row: Sequence[str], tag: str) -> str:
        return "".join(
            f"<{tag}{_LEFT if i in left else ''}>{_h(c)}</{tag}>" for i, c in enumerate(row)
        )

    body = "\n".join(f"<tr>{cells(r, 'td')}</tr>" for r in t.rows)
    foot = "\n".join(f"<tr>{cells(r, 'td')}</tr>" for r in t.footer)
    table = (
        f"<table>\n<thead><tr>{cells(t.headers, 'th')}</tr></thead>\n<tbody>\n{body}\n"
        f"</tbody>\n" + (f"<tfoot>\n{foot}\n</tfoot>\n" if foot else "") + "</table>"
    )
    table = f'<div class="table">\n{table}\n</div>'
    if t.collapsed:
        return f"<details><summary>{_h(t.caption)}</summary>\n{table}\n</details>"
    return f"<h2>{_h(t.caption)}</h2>\n{table}"


def map_height(report: Report) -> int:
    """Height of the plot [px]: the course area's shape on a plot about 1000 px wide, plus
    the legend and slider, within 480 .. 1100 px."""
    x0, x1, y0, y1 = course_area(report.course, report.routes)
    return int(np.clip(round(950 * (y1 - y0) / (x1 - x0)) + 230, 480, 1100))


def render_html(report: Report, plotly_source: str) -> str:
    """The whole page as a string.

    Parameters
    ----------
    report : Report
        What to show.
    plotly_source : str
        The plotly.js bundle, inlined as is (:func:`plotly_js`); tests may pass a stub.

    Returns
    -------
    str
        A complete HTML document that needs no network.
    """
    fig = figure(report)
    notes = "\n".join(f'<p class="note">{_h(n)}</p>' for n in report.notes)
    summary = "\n".join(f'<p class="summary">{_h(s)}</p>' for s in report.summary)
    tables = "\n".join(_table_html(t) for t in report.tables)
    js = _JS % {"fig": FIGURE_ID, "div": DIV_ID}
    return f"""<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="generator" content="sailroute {_h(__version__)}">
<title>{_h(report.title)}</title>
<style>{_CSS}</style>
<script>{plotly_source}</script>
</head>
<body>
<h1>{_h(report.title)}</h1>
{summary}
<div id="sailroute-error"></div>
<div id="{DIV_ID}" style="height: {map_height(report)}px"></div>
{notes}
{tables}
<footer>Written by sailroute {_h(__version__)}; drawing: plotly.js (MIT licence),
inlined.</footer>
<script type="application/json" id="{FIGURE_ID}">{_json_for_script(fig)}</script>
<script>{js}</script>
</body>
</html>
"""


def read_figure(page: str) -> dict[str, Any]:
    """The figure JSON embedded in a page written by :func:`render_html`."""
    m = re.search(
        rf'<script type="application/json" id="{FIGURE_ID}">(.*?)</script>', page, flags=re.S
    )
    if m is None:
        raise ValueError(f"no <script id={FIGURE_ID!r}> in the page")
    return json.loads(m.group(1))


def plotly_js() -> str:
    """The plotly.js bundle shipped with the ``plotly`` Python package (imported here only)."""
    from plotly.offline import get_plotlyjs

    return get_plotlyjs()


def write_report(path: str | Path, report: Report) -> Path:
    """Write ``report`` as a self-contained HTML page to ``path``; returns the path."""
    p = Path(path)
    p.write_text(render_html(report, plotly_js()), encoding="utf-8")
    return p
