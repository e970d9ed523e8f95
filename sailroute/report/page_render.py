"""``report.html`` as text: the page around the figure, its tables, and the files.

The drawing is `plotly.js <https://plotly.com/javascript/>`_: one copy, ``plotly.min.js``
(the bundle of the installed ``plotly`` package, about 4.8 MB), is written once per output
folder (:func:`write_plotly_js`) and every page of the folder loads it with a relative
``<script src>``, so the pages open from disk with no network, as long as the folder stays
together.  The figure's JSON sits in ``<script type="application/json"
id="sailroute-figure">``, so tests and other tools can read exactly what is drawn
(:func:`read_figure`).
"""

from __future__ import annotations

import html
import json
import math
import os
import re
import secrets
from collections.abc import Sequence
from pathlib import Path
from typing import Any
from urllib.parse import quote

import numpy as np

from sailroute._version import __version__
from sailroute.report.markup import html_text as _h
from sailroute.report.page import DIV_ID, FIGURE_ID, NoteGroup, Report, Table, course_area
from sailroute.report.page_figure import figure

__all__ = [
    "PLOTLY_FILE",
    "map_height",
    "plotly_js",
    "read_figure",
    "render_html",
    "write_plotly_js",
    "write_report",
]

PLOTLY_FILE = "plotly.min.js"
"""Name of the plotly.js bundle written beside the pages of an output folder."""

PICK_ID = "sailroute-pick"
"""Id of the ``<select>`` that picks a boat on a fleet's page."""


_CSS = """
body { font-family: Helvetica, Arial, sans-serif; margin: 16px 24px; color: #222; }
h1 { font-size: 20px; margin: 0 0 6px 0; }
h2 { font-size: 16px; margin: 18px 0 6px 0; }
p.summary { margin: 2px 0; }
#sailroute-map { width: 100%; }
p.note, details.note { font-size: 12px; color: #555; margin: 2px 0; }
details.note summary { cursor: pointer; }
details.note ul { margin: 2px 0 6px 0; }
div.table { overflow-x: auto; }
table { border-collapse: collapse; font-size: 13px; margin: 4px 0 12px 0; }
th, td { border: 1px solid #ccc; padding: 3px 7px; text-align: right; white-space: nowrap; }
th { background: #eef3f7; }
td.l, th.l { text-align: left; }
td.w { white-space: normal; overflow-wrap: anywhere; min-width: 8em; }
tfoot td { font-weight: bold; background: #f7f7f7; }
table.sortable th { cursor: pointer; }
table.sortable th[aria-sort=ascending]::after { content: " \\25B2"; font-size: 9px; }
table.sortable th[aria-sort=descending]::after { content: " \\25BC"; font-size: 9px; }
tr[data-boat] { cursor: pointer; }
tr.picked td { background: #fff3c4; }
span.sw { display: inline-block; width: 9px; height: 9px; border-radius: 50%;
          margin-right: 5px; vertical-align: baseline; }
label.pick { font-size: 13px; }
#sailroute-error { color: #b00; font-weight: bold; }
footer { font-size: 11px; color: #777; margin-top: 16px; }
"""


# Draws the figure; ``#step=K`` in the address opens the slider at step K, ``#boat=NAME``
# picks that boat on a fleet's page (both may be given: ``#step=3&boat=NAME``).  The body
# gets data-map="drawn" once everything is done (the browser test reads it), and
# data-boat=NAME while a boat is picked; an error is shown on the page instead of failing
# silently.  The tables sort by a click on a column's header whether or not the map draws.
_JS = """
(function () {
  var box = document.getElementById('sailroute-error');
  function fail(e) { box.textContent = 'The map could not be drawn: ' + e;
                     document.body.setAttribute('data-map', 'failed'); }
  function cellKey(row, col) {
    var c = row.cells[col];
    return c && c.hasAttribute('data-v') ? parseFloat(c.getAttribute('data-v')) : null;
  }
  function sortBy(table, col, th) {
    var up = th.getAttribute('aria-sort') !== 'ascending';
    Array.prototype.forEach.call(table.tHead.rows[0].cells,
                                 function (h) { h.removeAttribute('aria-sort'); });
    th.setAttribute('aria-sort', up ? 'ascending' : 'descending');
    var body = table.tBodies[0], rows = Array.prototype.slice.call(body.rows);
    var numeric = rows.some(function (r) { return cellKey(r, col) !== null; });
    rows.forEach(function (r, i) { r.setAttribute('data-i', i); });
    rows.sort(function (a, b) {
      var d;
      if (numeric) {
        var x = cellKey(a, col), y = cellKey(b, col);
        if (x === null || y === null) { d = (x === null) - (y === null); }
        else { d = up ? x - y : y - x; }
      } else {
        d = a.cells[col].textContent.localeCompare(b.cells[col].textContent);
        d = up ? d : -d;
      }
      return d || a.getAttribute('data-i') - b.getAttribute('data-i');
    });
    rows.forEach(function (r) { body.appendChild(r); });
  }
  Array.prototype.forEach.call(document.querySelectorAll('table.sortable'), function (t) {
    Array.prototype.forEach.call(t.tHead.rows[0].cells, function (th, col) {
      th.addEventListener('click', function () { sortBy(t, col, th); });
    });
  });
  function setUpPick(gd, P) {
    var sel = document.getElementById('%(pick)s');
    function pick(k) {
      var lines = [], markers = [], colours = [];
      P.boats.forEach(function (b, i) {
        lines.push(b.line); markers.push(b.marker);
        colours.push(k < 0 || i === k ? b.colour : P.grey);
      });
      var b = k >= 0 ? P.boats[k] : null, src = b ? gd.data[b.line] : null;
      var none = {x: [], y: [], text: []};
      var tk = b ? b.tacks : none, gb = b ? b.gybes : none;
      var extra = '<extra>' + (b ? b.label : '') + '</extra>';
      return Plotly.restyle(gd, {'line.color': colours}, lines).then(function () {
        return Plotly.restyle(gd, {'marker.color': colours}, markers);
      }).then(function () {
        return Plotly.restyle(gd, {
          x: [b ? src.x : [], tk.x, gb.x], y: [b ? src.y : [], tk.y, gb.y],
          text: [[], tk.text, gb.text],
          'line.color': [b ? b.colour : P.grey, 'white', 'white'],
          hovertemplate: ['', '%%{text}' + extra, '%%{text}' + extra]
        }, P.highlight);
      }).then(function () {
        sel.value = String(k);
        Array.prototype.forEach.call(document.querySelectorAll('tr[data-boat]'), function (r) {
          r.classList.toggle('picked', r.getAttribute('data-boat') === String(k));
        });
        if (b) { document.body.setAttribute('data-boat', b.name); }
        else { document.body.removeAttribute('data-boat'); }
      });
    }
    sel.addEventListener('change', function () { pick(parseInt(sel.value, 10)).catch(fail); });
    Array.prototype.forEach.call(document.querySelectorAll('tr[data-boat]'), function (r) {
      r.addEventListener('click', function () {
        pick(parseInt(r.getAttribute('data-boat'), 10)).catch(fail);
      });
    });
    gd.on('plotly_click', function (ev) {
      var c = ev.points[0].curveNumber;
      P.boats.forEach(function (b, i) {
        if (b.line === c || b.marker === c) { pick(i).catch(fail); }
      });
    });
    var m = /boat=([^&]*)/.exec(window.location.hash);
    if (m) {
      var name = decodeURIComponent(m[1]);
      var k = P.boats.map(function (b) { return b.name; }).indexOf(name);
      if (k >= 0) { return pick(k); }
    }
    return null;
  }
  if (typeof Plotly === 'undefined') {
    fail('the drawing library ' + %(js)s + ' did not load: keep it where it was written ' +
         '(the whole output folder together)');
    return;
  }
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
    }).then(function () {
      return fig.pick ? setUpPick(gd, fig.pick) : null;
    }).then(function () { document.body.setAttribute('data-map', 'drawn'); }, fail);
  } catch (e) { fail(e); }
})();
"""


def _json_for_script(obj: Any) -> str:
    """JSON safe inside a ``<script>`` element (no ``<``, ``>`` or ``&`` characters)."""
    text = json.dumps(obj, ensure_ascii=False, separators=(",", ":"), allow_nan=False)
    return text.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")


_TEXT_COLUMNS = (
    "from → to",
    "mode",
    "start point",
    "tacks/gybes sailed : optimal",
    "side sailed / optimal",
    "boat",
    "note",
    "notes",
    "wind",
    "over early",
    "status",
)
"""Table columns aligned left (text); the others are numbers, aligned right."""

_WRAP_COLUMNS = ("boat", "note", "notes", "over early", "status")
"""Table columns whose text wraps (names and sentences); the others stay on one line."""


def _cell_attrs(header: str, key: float | None) -> str:
    cls = " ".join(
        c for c, on in (("l", header in _TEXT_COLUMNS), ("w", header in _WRAP_COLUMNS)) if on
    )
    attrs = f' class="{cls}"' if cls else ""
    if key is not None and math.isfinite(key):
        attrs += f' data-v="{key:.6g}"'
    return attrs


def _row_html(
    t: Table, row: Sequence[str], tag: str, keys: Sequence[float | None], swatch: str = ""
) -> str:
    cells = []
    for i, c in enumerate(row):
        header = t.headers[i] if i < len(t.headers) else ""
        dot = (
            f'<span class="sw" style="background:{swatch}"></span>'
            if swatch and i == 0 and re.fullmatch(r"#[0-9a-fA-F]{6}", swatch)
            else ""
        )
        key = keys[i] if i < len(keys) else None
        cells.append(f"<{tag}{_cell_attrs(header, key)}>{dot}{_h(c)}</{tag}>")
    return "".join(cells)


def _table_html(t: Table) -> str:
    heads = _row_html(t, t.headers, "th", ())
    body = []
    for k, r in enumerate(t.rows):
        keys = t.keys[k] if k < len(t.keys) else ()
        swatch = t.swatches[k] if k < len(t.swatches) else ""
        boat = f' data-boat="{int(t.boats[k])}"' if k < len(t.boats) else ""
        body.append(f"<tr{boat}>{_row_html(t, r, 'td', keys, swatch)}</tr>")
    foot = "\n".join(f"<tr>{_row_html(t, r, 'td', ())}</tr>" for r in t.footer)
    attrs = (f' id="{t.name}"' if re.fullmatch(r"[A-Za-z][\w-]*", t.name) else "") + (
        ' class="sortable"' if t.keys else ""
    )
    table = (
        f"<table{attrs}>\n<thead><tr>{heads}</tr></thead>\n<tbody>\n"
        + "\n".join(body)
        + "\n</tbody>\n"
        + (f"<tfoot>\n{foot}\n</tfoot>\n" if foot else "")
        + "</table>"
    )
    table = f'<div class="table">\n{table}\n</div>'
    if t.collapsed:
        return f"<details><summary>{_h(t.caption)}</summary>\n{table}\n</details>"
    return f"<h2>{_h(t.caption)}</h2>\n{table}"


def _folded_html(g: NoteGroup) -> str:
    """A finding shared by several boats: a closed ``<details>`` block (a plain note when
    there is nothing to unfold)."""
    if not g.items:
        return f'<p class="note">{_h(g.summary)}</p>'
    items = "".join(f"<li>{_h(i)}</li>" for i in g.items)
    return (
        f'<details class="note"><summary>{_h(g.summary)}</summary>'
        + (f"<ul>{items}</ul>" if items else "")
        + "</details>"
    )


def _pick_html(report: Report) -> str:
    """The list that picks a boat on a fleet's page (option values: boat indices)."""
    boats = [r for r in report.routes if r.boat]
    options = "".join(f'<option value="{k}">{_h(r.name)}</option>' for k, r in enumerate(boats))
    return (
        f'<p><label class="pick">Highlight a boat: <select id="{PICK_ID}">'
        f'<option value="-1">none (every boat in its colour)</option>{options}'
        "</select></label> (or click its track, or its row in a table)</p>"
    )


def map_height(report: Report) -> int:
    """Height of the plot [px]: the course area's shape on a plot about 1000 px wide, plus
    the legend and slider, within 480 .. 1100 px."""
    x0, x1, y0, y1 = course_area(report.course, report.routes)
    return int(np.clip(round(950 * (y1 - y0) / (x1 - x0)) + 230, 480, 1100))


def render_html(report: Report, plotly_src: str = PLOTLY_FILE) -> str:
    """The whole page as a string.

    Parameters
    ----------
    report : Report
        What to show.
    plotly_src : str
        Address of the plotly.js bundle, relative to the page (default
        :data:`PLOTLY_FILE`, beside it: :func:`write_report` writes it there).

    Returns
    -------
    str
        A complete HTML document that needs no network.
    """
    fig = figure(report)
    notes = "\n".join(f'<p class="note">{_h(n)}</p>' for n in report.notes)
    folded = "\n".join(_folded_html(g) for g in report.folded)
    summary = "\n".join(f'<p class="summary">{_h(s)}</p>' for s in report.summary)
    tables = "\n".join(_table_html(t) for t in report.tables)
    src = html.escape(quote(plotly_src, safe="/._-~"))
    js = _JS % {
        "fig": FIGURE_ID,
        "div": DIV_ID,
        "pick": PICK_ID,
        "js": _json_for_script(plotly_src),
    }
    return f"""<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="generator" content="sailroute {_h(__version__)}">
<title>{_h(report.title)}</title>
<style>{_CSS}</style>
<script src="{src}"></script>
</head>
<body>
<h1>{_h(report.title)}</h1>
{summary}
<div id="sailroute-error"></div>
{_pick_html(report) if report.pick else ""}
<div id="{DIV_ID}" style="height: {map_height(report)}px"></div>
{notes}
{folded}
{tables}
<footer>Written by sailroute {_h(__version__)}; drawing: plotly.js (MIT licence), in
{_h(plotly_src)}.</footer>
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


def _write_atomic(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` through a fresh file beside it, renamed over it: a reader
    (or a run interrupted midway) never sees it half-written."""
    tmp = path.with_name(f".{path.name}.{secrets.token_hex(4)}")
    try:
        with open(tmp, "x", encoding="utf-8") as fh:
            fh.write(text)
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


def write_plotly_js(folder: str | Path) -> Path:
    """Write the plotly.js bundle as ``folder/plotly.min.js`` (:data:`PLOTLY_FILE`), once:
    a file there with the same text is left alone; returns its path."""
    p = Path(folder) / PLOTLY_FILE
    text = plotly_js()
    try:
        if p.is_file() and not p.is_symlink() and p.read_text(encoding="utf-8") == text:
            return p
    except (OSError, UnicodeDecodeError):
        pass
    _write_atomic(p, text)
    return p


def write_report(path: str | Path, report: Report, *, scripts: str | Path | None = None) -> Path:
    """Write ``report`` as an HTML page to ``path`` and the plotly.js bundle it loads into
    the folder ``scripts`` (default: the page's own folder; :func:`write_plotly_js`, once
    for all the pages of a folder); returns the page's path.

    The page names the bundle by its path relative to the page (``plotly.min.js``,
    ``../plotly.min.js``), so a folder of pages opens offline wherever it is copied.
    """
    p = Path(path)
    js = write_plotly_js(p.parent if scripts is None else scripts)
    rel = Path(os.path.relpath(js.resolve(), p.parent.resolve())).as_posix()
    _write_atomic(p, render_html(report, rel))
    return p
