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
p.banner { margin: 4px 0 8px 0; padding: 6px 10px; background: #fff4d6;
           border-left: 4px solid #d99a00; }
#sailroute-map { width: 100%; }
#sailroute-wrap { position: relative; }
#sailroute-furniture { position: absolute; pointer-events: none;
                       background: rgba(255,255,255,0.7); border-radius: 3px; }
#sailroute-osm { position: absolute; right: 32px; font-size: 10px; color: #333;
                 background: rgba(255,255,255,0.75); padding: 0 3px; }
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
  // ---- map furniture, label placement and OSM tiles (sailroute.report.labels: the rules)
  var STEPS = [0, 6, 14, 26, 42, 64, 92, 130], placing = false, timer = null;
  var TILE = 'https://tile.openstreetmap.org/';
  function niceLength(v) {
    var k = Math.pow(10, Math.floor(Math.log10(v)));
    return [5 * k, 2 * k, k].filter(function (x) { return x <= v; })[0] || k;
  }
  function overlap(a, b) {
    var w = Math.min(a[2], b[2]) - Math.max(a[0], b[0]);
    var h = Math.min(a[3], b[3]) - Math.max(a[1], b[1]);
    return w > 0 && h > 0 ? w * h : 0;
  }
  function hits(b, segs) {
    var n = 0;
    for (var i = 0; i < segs.length; i++) {
      var s = segs[i];
      if (Math.max(s[0], s[2]) < b[0] || Math.min(s[0], s[2]) > b[2] ||
          Math.max(s[1], s[3]) < b[1] || Math.min(s[1], s[3]) > b[3]) { continue; }
      var dx = s[2] - s[0], dy = s[3] - s[1], pos = 0, neg = 0;
      [[b[0], b[1]], [b[2], b[1]], [b[0], b[3]], [b[2], b[3]]].forEach(function (c) {
        var v = dx * (c[1] - s[1]) - dy * (c[0] - s[0]);
        if (v > 0) { pos++; } else if (v < 0) { neg++; }
      });
      if (pos < 4 && neg < 4) { n++; }
    }
    return n;
  }
  function best(cands, w, h, onRoute, segs, taken, B) {
    var bi = 0, bc = Infinity;
    cands.forEach(function (c, i) {
      var b = [c[0] - w / 2, c[1] - h / 2, c[0] + w / 2, c[1] + h / 2];
      var out = Math.max(0, B[0] - b[0]) + Math.max(0, b[2] - B[2]) +
                Math.max(0, B[1] - b[1]) + Math.max(0, b[3] - B[3]);
      var over = 0;
      taken.forEach(function (t) { over += overlap(b, t); });
      var v = (out > 0 ? 1e7 : 0) + 1e4 * out + (over > 0 ? 1e5 : 0) + 1e2 * over + c[2];
      if (v < bc && !onRoute) { v += 1e5 * hits(b, segs); }
      if (v < bc) { bc = v; bi = i; }
    });
    return bi;
  }
  function candidates(x, y, w, h, gap) {
    var out = gap <= 0 ? [[x, y, 0]] : [];
    STEPS.forEach(function (d) {
      if (gap <= 0 && d === 0) { return; }
      var r = Math.max(gap, 0) + d;
      for (var k = 0; k < 16; k++) {
        var a = 2 * Math.PI * k / 16, ux = Math.cos(a), uy = Math.sin(a);
        out.push([x + ux * (w / 2 + r), y + uy * (h / 2 + r), d + 0.01 * Math.abs(uy)]);
      }
    });
    return out;
  }
  function shown(tr) { return tr && tr.visible !== false && tr.visible !== 'legendonly'; }
  function furniture(fig, xa, L, T, segs, taken, B) {
    var box = document.getElementById('sailroute-furniture');
    var mPerPx = (xa.range[1] - xa.range[0]) * 111320 *
                 Math.cos(fig.chart.lat0 * Math.PI / 180) / xa._length;
    var len = niceLength(90 * mPerPx), bar = len / mPerPx;
    var text = len >= 1000 ? (len / 1000) + ' km' : len + ' m';
    var w = Math.max(bar, 40) + 34, h = 38, i = 3;
    var cs = [[B[0] + i + w / 2, B[3] - i - h / 2, 0], [B[2] - i - w / 2, B[3] - i - h / 2, 0.1],
              [B[0] + i + w / 2, B[1] + i + h / 2, 0.2], [B[2] - i - w / 2, B[1] + i + h / 2, 0.3]];
    var k = best(cs, w, h, false, segs, taken, B), x0 = cs[k][0] - w / 2, y0 = cs[k][1] - h / 2;
    box.style.left = x0 + 'px'; box.style.top = y0 + 'px';
    box.style.width = w + 'px'; box.style.height = h + 'px';
    box.innerHTML = '<svg width="' + w + '" height="' + h + '">' +
      '<rect x="4" y="24" width="' + bar + '" height="5" fill="#fff" stroke="#000"/>' +
      '<rect x="4" y="24" width="' + bar / 2 + '" height="5" fill="#000"/>' +
      '<text x="' + (4 + bar / 2) + '" y="19" text-anchor="middle" font-size="11">' + text +
      '</text><path d="M' + (w - 13) + ',31 L' + (w - 13) + ',16" stroke="#000" ' +
      'stroke-width="1.5"/><path d="M' + (w - 18) + ',19 L' + (w - 13) + ',8 L' + (w - 8) +
      ',19 Z" fill="#000"/><text x="' + (w - 13) + '" y="7" text-anchor="middle" ' +
      'font-size="9" font-weight="bold">N</text></svg>';
    box.setAttribute('data-scale-m', String(len));
    return [x0, y0, x0 + w, y0 + h];
  }
  function placeAll(gd, fig) {
    var P = fig.place, fl = gd._fullLayout, xa = fl.xaxis, ya = fl.yaxis;
    var L = xa._offset, T = ya._offset;
    function px(lon, lat) { return [L + xa.l2p(lon), T + ya.l2p(lat)]; }
    var B = [L + 2, T + 2, L + xa._length - 2, T + ya._length - 2], segs = [], taken = [];
    P.routes.concat(P.lines).forEach(function (i) {
      var tr = gd.data[i];
      if (!shown(tr)) { return; }
      var n = tr.x.length, step = Math.max(1, Math.ceil(n / 1500)), prev = null;
      for (var k = 0; k < n; k = (k + step < n || k === n - 1) ? k + step : n - 1) {
        if (tr.x[k] === null || tr.y[k] === null) { prev = null; continue; }
        var p = px(tr.x[k], tr.y[k]);
        if (prev) { segs.push([prev[0], prev[1], p[0], p[1]]); }
        prev = p;
      }
    });
    P.fixed.forEach(function (f) {
      var tr = gd.data[f.trace], r = f.size / 2;
      if (!shown(tr)) { return; }
      for (var k = 0; k < (f.first ? Math.min(1, tr.x.length) : tr.x.length); k++) {
        if (tr.x[k] === null) { continue; }
        var p = px(tr.x[k], tr.y[k]);
        taken.push([p[0] - r, p[1] - r, p[0] + r, p[1] + r]);
      }
    });
    taken.push(furniture(fig, xa, L, T, segs, taken, B));
    var anns = gd.layout.annotations || [], upd = {}, moved = {}, lead = [], lx = [], ly = [];
    P.items.forEach(function (it) {
      var x, y, w, h, tr = it.trace !== undefined ? gd.data[it.trace] : null;
      if (tr) {
        if (!shown(tr)) { return; }
        if (it.lon === undefined) { it.lon = tr.x[it.point]; it.lat = tr.y[it.point]; }
        var q = px(it.lon, it.lat);
        x = q[0]; y = q[1]; w = h = it.size;
      } else {
        var a = anns[it.ann], el = gd.querySelector('.annotation[data-index="' + it.ann +
                                                    '"] .annotation-text-g');
        var r = el ? el.getBoundingClientRect() : {width: 30, height: 16};
        var p = px(a.x, a.y);
        x = p[0]; y = p[1]; w = r.width + 2; h = r.height + 2;
      }
      var c = candidates(x, y, w, h, it.gap), k = best(c, w, h, it.route, segs, taken, B);
      var cx = c[k][0], cy = c[k][1], leader = (it.gap <= 0 && k > 0) || c[k][2] > 10;
      taken.push([cx - w / 2, cy - h / 2, cx + w / 2, cy + h / 2]);
      if (tr) {
        var m = moved[it.trace] = moved[it.trace] || {x: tr.x.slice(), y: tr.y.slice()};
        m.x[it.point] = xa.p2l(cx - L); m.y[it.point] = ya.p2l(cy - T);
        if (leader) { lx.push(it.lon, m.x[it.point], null); ly.push(it.lat, m.y[it.point], null); }
      } else {
        upd['annotations[' + it.ann + '].ax'] = cx - x;
        upd['annotations[' + it.ann + '].ay'] = cy - y;
        upd['annotations[' + it.ann + '].arrowcolor'] = leader ? '#555' : 'rgba(0,0,0,0)';
      }
    });
    var ids = Object.keys(moved).map(Number);
    placing = true;
    return Plotly.relayout(gd, upd).then(function () {
      return ids.length ? Plotly.restyle(gd, {x: ids.map(function (i) { return moved[i].x; }),
                                              y: ids.map(function (i) { return moved[i].y; })},
                                         ids) : null;
    }).then(function () {
      return P.leaders >= 0 ? Plotly.restyle(gd, {x: [lx], y: [ly]}, [P.leaders]) : null;
    }).then(function () {
      placing = false;
      document.body.setAttribute('data-placed', String(P.items.length));
    });
  }
  function tileBox(z, x, y) {
    var n = Math.pow(2, z);
    function lat(t) { return Math.atan(Math.sinh(Math.PI * (1 - 2 * t / n))) * 180 / Math.PI; }
    return [x / n * 360 - 180, (x + 1) / n * 360 - 180, lat(y + 1), lat(y)];
  }
  function tileImages(gd) {
    var xa = gd._fullLayout.xaxis, ya = gd._fullLayout.yaxis;
    var z = Math.max(0, Math.min(19, Math.round(Math.log2(
      xa._length / (xa.range[1] - xa.range[0]) * 360 / 256))));
    var n = Math.pow(2, z), out = [];
    function tx(lon) { return Math.floor((lon + 180) / 360 * n); }
    function ty(lat) {
      var r = lat * Math.PI / 180;
      return Math.floor((1 - Math.log(Math.tan(r) + 1 / Math.cos(r)) / Math.PI) / 2 * n);
    }
    for (var x = tx(xa.range[0]); x <= tx(xa.range[1]) && out.length < 120; x++) {
      for (var y = ty(ya.range[1]); y <= ty(ya.range[0]) && out.length < 120; y++) {
        var b = tileBox(z, x, y);
        out.push({source: TILE + z + '/' + x + '/' + y + '.png', xref: 'x', yref: 'y',
                  x: b[0], y: b[3], sizex: b[1] - b[0], sizey: b[3] - b[2],
                  sizing: 'stretch', layer: 'below', xanchor: 'left', yanchor: 'top'});
      }
    }
    return out;
  }
  function tiles(gd, fig, online) {
    var status = document.getElementById('sailroute-tiles');
    if (online) {
      var land = [];
      gd.data.forEach(function (t, i) { if (t.meta === 'land') { land.push(i); } });
      placing = true;
      return Plotly.relayout(gd, {images: tileImages(gd), plot_bgcolor: 'rgba(0,0,0,0)'})
        .then(function () {
          return land.length ? Plotly.restyle(gd, {opacity: 0.35}, land) : null;
        })
        .then(function () { placing = false; });
    }
    var first = tileImages(gd)[0], probe = new Image();
    if (!first) { return null; }
    probe.onload = function () {
      document.body.setAttribute('data-tiles', 'shown');
      status.textContent = 'OSM tiles shown.';
      var osm = document.getElementById('sailroute-osm'), link = document.createElement('a');
      link.href = 'https://www.openstreetmap.org/copyright';
      link.textContent = 'OpenStreetMap';
      osm.append('© ', link, ' contributors');
      osm.hidden = false;
      tiles(gd, fig, true);
    };
    probe.onerror = function () {
      document.body.setAttribute('data-tiles', 'offline');
      status.textContent = 'OSM tiles: not shown (no network).';
    };
    probe.src = first.source;
    return null;
  }
  function watch(gd, fig) {
    function again() {
      clearTimeout(timer);
      timer = setTimeout(function () {
        placeAll(gd, fig).then(function () {
          return document.body.getAttribute('data-tiles') === 'shown' ? tiles(gd, fig, true) : null;
        }).catch(fail);
      }, 150);
    }
    gd.on('plotly_relayout', function (ev) {
      if (placing) { return; }
      if (Object.keys(ev).some(function (k) { return /^(xaxis|yaxis|autosize)/.test(k); })) {
        again();
      }
    });
    gd.on('plotly_restyle', function () { if (!placing) { again(); } });
    window.addEventListener('resize', again);
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
    }).then(function () {
      return fig.place ? placeAll(gd, fig) : null;
    }).then(function () {
      if (fig.place) { watch(gd, fig); tiles(gd, fig, false); }
      document.body.setAttribute('data-map', 'drawn');
    }, fail);
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
    summary = "\n".join(
        [
            *(f'<p class="banner" role="note">{_h(b)}</p>' for b in report.banner),
            *(f'<p class="summary">{_h(s)}</p>' for s in report.summary),
        ]
    )
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
<div id="sailroute-wrap">
<div id="{DIV_ID}" style="height: {map_height(report)}px"></div>
<div id="sailroute-furniture"></div>
<div id="sailroute-osm" style="top: {map_height(report) - 125}px" hidden></div>
</div>
<p class="note" id="sailroute-chart">{_h(fig.get("chart", {}).get("note", ""))} <span
id="sailroute-tiles">OSM tiles: not tried yet.</span></p>
{notes}
{folded}
{tables}
<footer>Written by sailroute {_h(__version__)}; drawing: plotly.js (MIT licence), in
{_h(plotly_src)}; map tiles, when online: © OpenStreetMap contributors (ODbL).</footer>
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
