"""The coach's page: a local web server with one page, one JSON endpoint and the page's
commands.

``GET /`` is a self-contained page for a tablet (inline SVG and script, no framework, no
network beyond this server) that polls ``GET /state.json`` every second and draws, full
width: the course with its marks (labels placed so that none overlaps another), lines and
gate, a legend, a scale bar and a north arrow; the sailor's boat, its track and its COG
vector; the coach boat and the other vessels heard; the route ahead; the laylines into
the next mark in the measured wind, with the time and distance to each; the time to the
next mark and to the finish and the ETA at every mark; the measured wind and its trend
with axes and units (directions are where the wind comes *from*); the side that pays.
Banners say when the data are stale, when the route is older than it should be because
re-plans fail, and when the scenario's wind has run out and the route is in the
measured wind only.

``POST /api/boat``, ``/api/position``, ``/api/leg`` (JSON bodies) are the coach's
changes: which boat is the sailor's, a position typed or tapped on the map, the leg being
sailed.  They go to the ``command`` callable
(:meth:`sailroute.live.engine.LiveEngine.command`).

Access: the server listens on 127.0.0.1 unless a host is given.  Every change needs the
page's token (``?token=``, written into the page it serves), so another web page open
in the tablet's browser cannot post to it; with ``token_for_all`` (a host other than
127.0.0.1) every request needs it, the page itself included.  A client that closes its
connection early (a tab closed mid-poll) is not an error.
"""

from __future__ import annotations

import json
import secrets
import socket
import threading
from collections.abc import Callable, Mapping
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any
from urllib.parse import parse_qs, urlsplit

from sailroute.errors import InputError

MAX_BODY: int = 4096
"""Longest command body read [bytes]."""

PAGE = """<!doctype html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>sailroute live</title>
<style>
*{box-sizing:border-box}
body{font-family:system-ui,sans-serif;margin:0;background:#f4f6f8;color:#123}
header{display:flex;flex-wrap:wrap;gap:.4em 1.4em;padding:.5em 1em;background:#123;color:#fff}
header div{font-size:1em} header b{font-size:1.7em;display:block;font-variant-numeric:tabular-nums}
.banner{display:none;padding:.5em 1em;font-size:1.15em;font-weight:600}
#stale{background:#c0392b;color:#fff} #failing{background:#e74c3c;color:#fff}
#measured{background:#f39c12;color:#123} #waiting{background:#2c3e50;color:#fff}
main{display:grid;grid-template-columns:minmax(0,1fr) 340px;gap:.8em;padding:.8em}
@media (max-width:1100px){main{grid-template-columns:minmax(0,1fr)}}
#map{width:100%;height:calc(100vh - 11em);min-height:400px;background:#dbe9f4;
 border-radius:.4em;display:block;touch-action:none}
#map.tapping{outline:4px solid #f39c12;cursor:crosshair}
.panel{background:#fff;border-radius:.4em;padding:.6em .8em;margin-bottom:.8em}
.panel h2{font-size:1em;margin:.1em 0 .4em}
table{border-collapse:collapse;width:100%} td,th{padding:.15em .3em;text-align:left}
td.n{text-align:right;font-variant-numeric:tabular-nums}
#legend{display:flex;flex-wrap:wrap;gap:.3em 1em;font-size:.9em;padding:.3em 0}
#legend span{display:inline-flex;align-items:center;gap:.3em}
button,select,input{font-size:1em;padding:.35em .6em;margin:.15em}
#trend{width:100%;height:auto;background:#fff}
.note{font-size:.85em;color:#555}
</style></head><body>
<header>
 <div>leg<b id="leg">-</b></div><div>next mark<b id="tmark">-</b></div>
 <div>finish<b id="tfin">-</b></div><div>wind (from)<b id="wind">-</b></div>
 <div>side that pays<b id="side">-</b></div><div>re-plan<b id="plan">-</b></div>
</header>
<div class="banner" id="stale">DATA STALE: no instrument data</div>
<div class="banner" id="failing"></div>
<div class="banner" id="measured"></div>
<div class="banner" id="waiting"></div>
<main>
 <div>
  <svg id="map"></svg>
  <div id="legend">
   <span><svg width="26" height="10"><line x1="0" y1="5" x2="26" y2="5" stroke="#1565c0"
    stroke-width="3"/></svg>route</span>
   <span><svg width="26" height="10"><line x1="0" y1="5" x2="26" y2="5" stroke="#2a9d2a"
    stroke-width="2" stroke-dasharray="6 4"/></svg>starboard layline</span>
   <span><svg width="26" height="10"><line x1="0" y1="5" x2="26" y2="5" stroke="#c0392b"
    stroke-width="2" stroke-dasharray="6 4"/></svg>port layline</span>
   <span><svg width="14" height="14"><circle cx="7" cy="7" r="6" fill="#8e44ad"/></svg>
    sailor's boat, track, COG</span>
   <span><svg width="14" height="14"><rect x="2" y="2" width="10" height="10" fill="#123"/>
    </svg>coach boat</span>
   <span><svg width="14" height="14"><path d="M7 1 L13 13 L1 13 Z" fill="#7f8c8d"/></svg>
    other vessels</span>
   <span><svg width="14" height="14"><circle cx="7" cy="7" r="5" fill="#f39c12"/></svg>
    marks</span>
  </div>
 </div>
 <div>
  <div class="panel"><h2>Marks ahead</h2><table id="eta"></table></div>
  <div class="panel"><h2>Laylines (measured wind)</h2><table id="lay"></table></div>
  <div class="panel"><h2>Measured wind</h2>
   <svg id="trend" viewBox="0 0 340 230"></svg></div>
  <div class="panel"><h2>Sailor's boat</h2>
   <div><select id="boats"></select><button id="setboat">route this boat</button></div>
   <div><input id="lat" size="9" placeholder="lat" inputmode="decimal">
    <input id="lon" size="9" placeholder="lon" inputmode="decimal">
    <button id="setpos">set position</button>
    <button id="tap">tap on map</button></div>
   <div>leg <select id="legs"></select><button id="setleg">set leg</button></div>
   <p class="note" id="said"></p>
  </div>
  <p class="note" id="info"></p>
 </div>
</main>
<script>
"use strict";
const TOKEN = "__TOKEN__";
const q = "?token=" + encodeURIComponent(TOKEN);
const $ = id => document.getElementById(id);
const mmss = s => s == null || !isFinite(s) ? "-" : (s < 0 ? "-" : "") + Math.floor(Math.abs(s)
  / 60) + ":" + String(Math.round(Math.abs(s) % 60)).padStart(2, "0");
const KN = 1.9438445;
const NS = "http://www.w3.org/2000/svg";
let W = 1000, H = 700;
let view = null, tapping = false, last = null;
function el(p, tag, attrs, text) { const e = document.createElementNS(NS, tag);
  for (const k in attrs) e.setAttribute(k, attrs[k]); if (text != null) e.textContent = text;
  p.appendChild(e); return e; }
function fit(s) {
  const pts = s.marks.map(k => [k[1], k[2]]);
  if (s.plan) s.plan.route.forEach(p => pts.push(p));
  if (s.boat.where) pts.push([s.boat.where.lat, s.boat.where.lon]);
  if (s.position) pts.push([s.position.lat, s.position.lon]);
  const lat0 = pts.reduce((a, p) => a + p[0], 0) / pts.length;
  const k = Math.cos(lat0 * Math.PI / 180), m = 111195;
  let x0 = 1e18, x1 = -1e18, y0 = 1e18, y1 = -1e18;
  pts.forEach(p => { const x = p[1] * k * m, y = p[0] * m; x0 = Math.min(x0, x);
    x1 = Math.max(x1, x); y0 = Math.min(y0, y); y1 = Math.max(y1, y); });
  const pad = 110, sc = Math.min((W - 2 * pad) / Math.max(x1 - x0, 50),
    (H - 2 * pad) / Math.max(y1 - y0, 50));
  const cx = (x0 + x1) / 2, cy = (y0 + y1) / 2;
  return {k: k, m: m, sc: sc, X: p => W / 2 + (p[1] * k * m - cx) * sc,
    Y: p => H / 2 - (p[0] * m - cy) * sc,
    ll: (x, y) => [((H / 2 - y) / sc + cy) / m, ((x - W / 2) / sc + cx) / (k * m)]};
}
function arrow(g, x, y, brg, len, attrs) { const b = brg * Math.PI / 180;
  return el(g, "line", Object.assign({x1: x, y1: y, x2: x + len * Math.sin(b),
    y2: y - len * Math.cos(b)}, attrs)); }
function overlaps(a, b) { return a.x0 < b.x1 && b.x0 < a.x1 && a.y0 < b.y1 && b.y0 < a.y1; }
function labels(g, items) {
  // each label goes to the first of its candidate places whose box overlaps no label
  // placed before it and no mark: 8 directions at growing distances
  const boxes = [], marks = items.map(it => ({x0: it.x - 6, y0: it.y - 6, x1: it.x + 6,
    y1: it.y + 6}));
  items.forEach(it => {
    const t = el(g, "text", {x: it.x, y: it.y, "font-size": 15, "font-weight": 600,
      fill: "#123", class: "mark-label"}, it.name);
    const bb = t.getBBox(), w = bb.width + 4, h = bb.height;
    let best = null;
    outer: for (const r of [10, 22, 36, 52, 72, 96]) {
      for (let a = 0; a < 8; a++) {
        const ang = (a * 45 + 45) * Math.PI / 180, dx = r * Math.cos(ang),
          dy = -r * Math.sin(ang);
        const bx = it.x + dx + (dx < -1 ? -w : dx > 1 ? 0 : -w / 2);
        const by = it.y + dy + (dy < -1 ? -h : dy > 1 ? 0 : -h / 2);
        const box = {x0: bx, y0: by, x1: bx + w, y1: by + h};
        if (!boxes.some(b => overlaps(b, box)) && !marks.some(b => overlaps(b, box))) {
          best = box; break outer; }
        if (best == null) best = box;
      }
    }
    t.setAttribute("x", best.x0 + 2); t.setAttribute("y", best.y0 + h * 0.8);
    if (Math.hypot((best.x0 + best.x1) / 2 - it.x, (best.y0 + best.y1) / 2 - it.y) > 30)
      el(g, "line", {x1: it.x, y1: it.y, x2: (best.x0 + best.x1) / 2, y2: (best.y0 +
        best.y1) / 2, stroke: "#123", "stroke-width": 0.7});
    const r = t.getBBox();
    ["x0", "y0", "x1", "y1"].forEach((k, i) => t.setAttribute("data-" + k,
      [r.x, r.y, r.x + r.width, r.y + r.height][i].toFixed(1)));
    boxes.push(best);
  });
}
function scalebar(g, v) {
  const want = 200 / v.sc, p = Math.pow(10, Math.floor(Math.log10(want)));
  const len = [1, 2, 5, 10].map(f => f * p).filter(d => d <= want).pop();
  const px = len * v.sc, x = 30, y = H - 30;
  el(g, "rect", {x: x - 8, y: y - 26, width: px + 16, height: 40, fill: "#fff",
    opacity: 0.8, rx: 4});
  el(g, "line", {x1: x, y1: y, x2: x + px, y2: y, stroke: "#123", "stroke-width": 4});
  [x, x + px].forEach(xx => el(g, "line", {x1: xx, y1: y - 7, x2: xx, y2: y + 7,
    stroke: "#123", "stroke-width": 2}));
  el(g, "text", {x: x + px / 2, y: y - 10, "text-anchor": "middle", "font-size": 15,
    id: "scale-label"}, len >= 1000 ? len / 1000 + " km" : len + " m");
}
function draw(s) {
  const m = $("map"); m.innerHTML = ""; if (!s.marks.length) return;
  W = Math.max(m.clientWidth, 300); H = Math.max(m.clientHeight, 300);
  m.setAttribute("viewBox", "0 0 " + W + " " + H);
  const v = fit(s); view = v; const X = v.X, Y = v.Y;
  const g = el(m, "g", {});
  (s.lines || []).forEach(l => el(g, "line", {x1: X([l[1], l[2]]), y1: Y([l[1], l[2]]),
    x2: X([l[3], l[4]]), y2: Y([l[3], l[4]]), stroke: "#34495e", "stroke-width": 2}));
  const t = s.next_mark;
  if (t) s.laylines.forEach(l => arrow(g, X(t), Y(t), l.bearing_deg + 180, 2000,
    {stroke: l.tack === "starboard" ? "#2a9d2a" : "#c0392b", "stroke-width": 2,
     "stroke-dasharray": "10 6"}));
  if (s.plan) el(g, "polyline", {points: s.plan.route.map(p => X(p) + "," + Y(p)).join(" "),
    fill: "none", stroke: "#1565c0", "stroke-width": 3.5, opacity: s.stale_plan ? 0.45 : 1});
  const b = s.boat;
  if (b.track.length > 1) el(g, "polyline", {points: b.track.map(p => X(p) + "," + Y(p))
    .join(" "), fill: "none", stroke: "#8e44ad", "stroke-width": 2, opacity: 0.6});
  s.vessels.forEach(o => { if (o.id === b.id) return; const x = X([o.lat, o.lon]),
    y = Y([o.lat, o.lon]); el(g, "path", {d: `M${x} ${y - 7} L${x + 6} ${y + 5} L${x - 6}
    ${y + 5} Z`, fill: "#7f8c8d"}); });
  if (s.position) { const p = [s.position.lat, s.position.lon];
    el(g, "rect", {x: X(p) - 6, y: Y(p) - 6, width: 12, height: 12, fill: "#123"}); }
  s.marks.forEach(k => el(g, "circle", {cx: X([k[1], k[2]]), cy: Y([k[1], k[2]]), r: 6,
    fill: "#f39c12", stroke: "#123", "stroke-width": 1}));
  if (b.where) { const p = [b.where.lat, b.where.lon], x = X(p), y = Y(p);
    if (b.sog_ms != null && b.cog_deg != null) arrow(g, x, y, b.cog_deg, b.sog_ms * 60 * v.sc,
      {stroke: "#8e44ad", "stroke-width": 3});
    if (b.hdg_deg != null) arrow(g, x, y, b.hdg_deg, 22, {stroke: "#123", "stroke-width": 2});
    el(g, "circle", {cx: x, cy: y, r: 8, fill: "#8e44ad", stroke: "#fff", "stroke-width": 2}); }
  labels(el(m, "g", {id: "labels"}), s.marks.map(k => ({name: k[0], x: X([k[1], k[2]]),
    y: Y([k[1], k[2]])})));
  const n = el(m, "g", {});  // north arrow (the map's up is true north)
  el(n, "path", {d: "M40 18 L52 58 L40 50 L28 58 Z", fill: "#123"});
  el(n, "text", {x: 40, y: 76, "text-anchor": "middle", "font-size": 17, "font-weight": 700},
    "N");
  if (s.wind) { const w = el(m, "g", {}), c = [W - 70, 60], b = s.wind.twd_deg * Math.PI
      / 180, sn = Math.sin(b), cs = Math.cos(b);
    el(w, "circle", {cx: c[0], cy: c[1], r: 36, fill: "#fff", opacity: 0.85});
    // from the side the wind comes from, blowing across the circle, head downwind
    arrow(w, c[0] + 28 * sn, c[1] - 28 * cs, s.wind.twd_deg + 180, 48,
      {stroke: "#123", "stroke-width": 3});
    const hx = c[0] - 20 * sn, hy = c[1] + 20 * cs;  // the head: base across the shaft
    el(w, "path", {d: `M${hx - 7 * cs} ${hy - 7 * sn} L${hx + 7 * cs} ${hy + 7 * sn}
      L${hx - 13 * sn} ${hy + 13 * cs} Z`, fill: "#123"});
    el(w, "text", {x: c[0], y: c[1] + 54, "text-anchor": "middle", "font-size": 14},
      "wind from " + s.wind.twd_deg.toFixed(0) + "°"); }
  scalebar(el(m, "g", {}), v);
}
function axis(g, x0, y0, x1, y1, lo, hi, n, fmt, side, title) {
  el(g, "line", {x1: x0, y1: y0, x2: x1, y2: y1, stroke: "#123"});
  for (let i = 0; i <= n; i++) { const f = i / n, v = lo + f * (hi - lo);
    const x = x0 + f * (x1 - x0), y = y0 + f * (y1 - y0);
    if (side === "b") { el(g, "line", {x1: x, y1: y, x2: x, y2: y + 4, stroke: "#123"});
      el(g, "text", {x: x, y: y + 16, "text-anchor": "middle", "font-size": 11}, fmt(v)); }
    else { const d = side === "l" ? -4 : 4;
      el(g, "line", {x1: x, y1: y, x2: x + d, y2: y, stroke: "#123"});
      el(g, "text", {x: x + 3 * d, y: y + 4, "text-anchor": side === "l" ? "end" : "start",
        "font-size": 11}, fmt(v)); } }
  el(g, "text", {x: side === "l" ? 4 : side === "r" ? 336 : (x0 + x1) / 2,
    y: side === "b" ? 226 : 12, "text-anchor": side === "l" ? "start" : side === "r" ?
    "end" : "middle", "font-size": 11, fill: "#555"}, title);
}
function trend(s) {
  const g = $("trend"); g.innerHTML = ""; const w = s.wind_trend;
  if (w.length < 2) { el(g, "text", {x: 170, y: 115, "text-anchor": "middle"},
    "waiting for wind"); return; }
  const t1 = w[w.length - 1][0], t0 = Math.min(w[0][0], t1 - 300);
  let prev = w[0][2]; const un = w.map(q => { let x = q[2]; while (x - prev > 180) x -= 360;
    while (x - prev < -180) x += 360; prev = x; return x; });
  const lo = Math.floor((Math.min(...un) - 3) / 5) * 5, hi = Math.ceil((Math.max(...un) + 3)
    / 5) * 5, sp = w.map(q => q[1] * KN), smax = Math.ceil(Math.max(...sp, 2) + 1);
  const L = 46, R = 300, T = 20, B = 200;
  const X = t => L + (t - t0) / Math.max(t1 - t0, 1) * (R - L);
  axis(g, L, B, R, B, -(t1 - t0) / 60, 0, 4, v => Math.abs(v).toFixed(0), "b", "minutes ago");
  axis(g, L, B, L, T, lo, hi, 4, v => ((v % 360 + 360) % 360).toFixed(0) + "°", "l",
    "TWD from (°)");
  axis(g, R, B, R, T, 0, smax, 4, v => v.toFixed(1), "r", "TWS (kn)");
  el(g, "polyline", {points: w.map((q, i) => X(q[0]) + "," + (B - (un[i] - lo) / (hi - lo) *
    (B - T))).join(" "), fill: "none", stroke: "#1565c0", "stroke-width": 2});
  el(g, "polyline", {points: w.map((q, i) => X(q[0]) + "," + (B - sp[i] / smax * (B - T)))
    .join(" "), fill: "none", stroke: "#2a9d2a", "stroke-width": 2});
}
function tables(s) {
  const p = s.plan, e = $("eta"); e.innerHTML = "<tr><th>leg</th><th>ETA</th><th>in</th></tr>";
  if (p) p.leg_labels.forEach((l, i) => { const r = e.insertRow();
    r.insertCell().textContent = (p.leg + i + 1) + ": " + l;
    const c = r.insertCell(); c.className = "n";
    c.textContent = new Date(p.mark_eta[i] * 1000).toLocaleTimeString();
    const d = r.insertCell(); d.className = "n"; d.textContent = mmss(p.mark_eta[i] - s.t); });
  const y = $("lay"); y.innerHTML = "<tr><th>layline</th><th>distance</th><th>time</th></tr>";
  s.laylines.forEach(l => { const r = y.insertRow();
    r.insertCell().textContent = l.tack + " (" + l.bearing_deg.toFixed(0) + "°)";
    const d = r.insertCell(); d.className = "n"; const t = r.insertCell(); t.className = "n";
    if (l.distance_m == null) { d.textContent = "-"; t.textContent = "-"; }
    else if (l.distance_m < 0) { d.textContent = "past by " + (-l.distance_m).toFixed(0) +
      " m"; t.textContent = ""; }
    else { d.textContent = l.distance_m.toFixed(0) + " m"; t.textContent = mmss(l.time_s); } });
}
function pickers(s) {
  const sel = $("boats"); if (document.activeElement !== sel) { const cur = sel.value;
    sel.innerHTML = ""; const o = document.createElement("option"); o.value = "self";
    o.textContent = "coach boat's own position"; sel.appendChild(o);
    s.vessels.forEach(v => { const o = document.createElement("option"); o.value = v.id;
      o.textContent = v.label + (v.age_s != null ? " (" + Math.round(v.age_s) + " s ago)" : "");
      sel.appendChild(o); });
    sel.value = cur || s.boat.id || "self"; }
  const lg = $("legs"); if (document.activeElement !== lg && lg.options.length !== s.n_legs) {
    lg.innerHTML = ""; s.leg_labels.forEach((l, i) => { const o = document.createElement(
      "option"); o.value = i + 1; o.textContent = (i + 1) + ": " + l; lg.appendChild(o); }); }
  if (document.activeElement !== lg) lg.value = Math.min(s.leg + 1, s.n_legs);
}
async function post(cmd, body) {
  try { const r = await fetch("api/" + cmd + q, {method: "POST", body: JSON.stringify(body),
      headers: {"Content-Type": "application/json"}});
    const a = await r.json(); $("said").textContent = a.done || a.error; }
  catch (e) { $("said").textContent = "no answer from the laptop"; }
}
$("setboat").onclick = () => post("boat", {boat: $("boats").value});
$("setleg").onclick = () => post("leg", {leg: parseInt($("legs").value, 10)});
$("setpos").onclick = () => post("position", {lat: parseFloat($("lat").value),
  lon: parseFloat($("lon").value)});
$("tap").onclick = () => { tapping = !tapping; $("map").classList.toggle("tapping", tapping); };
$("map").addEventListener("click", ev => { if (!tapping || !view) return;
  const m = $("map"), pt = m.createSVGPoint(); pt.x = ev.clientX; pt.y = ev.clientY;
  const p = pt.matrixTransform(m.getScreenCTM().inverse()), ll = view.ll(p.x, p.y);
  tapping = false; m.classList.remove("tapping");
  post("position", {lat: ll[0], lon: ll[1]}); });
function banners(s) {
  const p = s.plan, show = (id, text) => { $(id).style.display = text ? "block" : "none";
    if (text) $(id).textContent = text; };
  $("stale").style.display = s.stale ? "block" : "none";
  show("failing", s.error ? "RE-PLANS FAILING: " + s.error.split("\\n")[0].slice(0, 160) +
    (p ? " | the route shown is " + mmss(s.plan_age_s) + " old" : "") : "");
  show("measured", s.measured_only && p ? "MEASURED WIND ONLY: " + p.wind_note : "");
  show("waiting", !p || s.waiting ? (s.waiting || s.boat.why_not || "waiting for data") : "");
}
function header(s) {
  const p = s.plan, age = p ? s.t - p.t : 0;
  $("leg").textContent = Math.min(s.leg + 1, s.n_legs) + " of " + s.n_legs;
  $("tmark").textContent = p ? mmss(p.time_to_mark_s - age) : "-";
  $("tfin").textContent = p ? mmss(p.time_to_finish_s - age) : "-";
  $("wind").textContent = s.wind ? (s.wind.tws_ms * KN).toFixed(1) + " kn "
    + s.wind.twd_deg.toFixed(0) + "°" : "-";
  $("side").textContent = p && p.side ? (p.side.side === "none" ? "neither" : p.side.side
    + " by " + p.side.gain_s.toFixed(0) + " s") : "-";
  $("plan").textContent = p ? "#" + p.number + " " + p.reason + " (" + mmss(age) + " ago)" : "-";
  const c = s.counts, kinds = ["bounds", "far", "jump", "time"].filter(k => c["gate_" + k])
    .map(k => c["gate_" + k] + " " + k);
  $("info").textContent = "source " + s.source + " | messages " + c.used + " used, " + c.bad
    + " broken (" + (c.bad_checksum || 0) + " bad checksum, " + (c.no_checksum || 0)
    + " without, " + (c.malformed || 0) + " malformed), " + c.held_out + " readings held out"
    + (kinds.length ? " (" + kinds.join(", ") + ")" : "") + (c.error ? ", " + c.error
    + " raised" : "") + (s.notes.length ? " | " + s.notes.join("; ") : "");
}
async function poll() {
  try {
    const s = await (await fetch("state.json" + q, {cache: "no-store"})).json();
    s.stale_plan = !!s.error; last = s;
    header(s); banners(s); draw(s); trend(s); tables(s); pickers(s);
    document.body.dataset.drawn = "1";
    document.body.dataset.mapWidth = $("map").getBoundingClientRect().width.toFixed(0);
  } catch (e) { $("stale").style.display = "block"; }
  setTimeout(poll, 1000);
}
poll();
</script></body></html>
"""


def page_html(token: str) -> str:
    """The page with its token written in."""
    return PAGE.replace("__TOKEN__", json.dumps(token)[1:-1])


def _handler(
    state: Callable[[], dict[str, Any]],
    command: Callable[[str, Mapping[str, Any]], str] | None,
    token: str,
    token_for_all: bool,
) -> type[BaseHTTPRequestHandler]:
    class Handler(BaseHTTPRequestHandler):
        def _allowed(self, need: bool) -> bool:
            given = parse_qs(urlsplit(self.path).query).get("token", [""])[0]
            if need and not secrets.compare_digest(given, token):
                self._send(
                    403,
                    b"a token is needed: open the address the command printed",
                    "text/plain; charset=utf-8",
                )
                return False
            return True

        def _send(self, code: int, body: bytes, ctype: str) -> None:
            try:
                self.send_response(code)
                self.send_header("Content-Type", ctype)
                self.send_header("Content-Length", str(len(body)))
                self.send_header("Cache-Control", "no-store")
                self.end_headers()
                self.wfile.write(body)
            except (BrokenPipeError, ConnectionResetError):
                pass  # the tab went away

        def do_GET(self) -> None:
            path = urlsplit(self.path).path
            if not self._allowed(token_for_all):
                return
            if path in ("/", "/index.html"):
                self._send(200, page_html(token).encode("utf-8"), "text/html; charset=utf-8")
            elif path == "/state.json":
                self._send(200, json.dumps(state()).encode("utf-8"), "application/json")
            else:
                self._send(404, b"only / and /state.json", "text/plain; charset=utf-8")

        def do_POST(self) -> None:
            path = urlsplit(self.path).path
            if not self._allowed(True):
                return
            name = path.removeprefix("/api/")
            try:
                n = int(self.headers.get("Content-Length") or 0)
                if command is None or not path.startswith("/api/") or not 0 <= n <= MAX_BODY:
                    raise InputError("expected POST /api/boat, /api/position or /api/leg")
                args = json.loads(self.rfile.read(n) or b"{}")
                if not isinstance(args, dict):
                    raise InputError("expected a JSON object")
                answer = {"done": command(name, args)}
                code = 200
            except (InputError, ValueError, RecursionError) as exc:
                answer, code = {"error": str(exc)}, 400
            self._send(code, json.dumps(answer).encode("utf-8"), "application/json")

        def log_message(self, format: str, *args: Any) -> None:
            """Quiet: the terminal shows the re-plans, not every poll."""

    return Handler


class _Server(ThreadingHTTPServer):
    daemon_threads = True

    def handle_error(self, request: Any, client_address: Any) -> None:
        """A client gone mid-answer, or any other error of one request: not printed (the
        next poll asks again)."""


class _Server6(_Server):
    address_family = socket.AF_INET6


def loopback(host: str) -> bool:
    """True for an address only this machine reaches."""
    return host in ("127.0.0.1", "localhost", "::1") or host.startswith("127.")


class PageServer:
    """The page, ``/state.json`` and the page's commands on ``host:port`` (0: a free port,
    see :attr:`port`).

    Parameters
    ----------
    state : callable
        What ``/state.json`` serves.
    port : int
        TCP port.
    host : str
        Address to listen on.
    token : str, optional
        The page's token (default: a new random one).
    command : callable, optional
        ``command(name, args) -> str`` for ``POST /api/<name>``; raises
        :class:`~sailroute.errors.InputError` for a bad one.
    token_for_all : bool
        Every request needs the token (a page served beyond this machine).
    """

    def __init__(
        self,
        state: Callable[[], dict[str, Any]],
        port: int,
        host: str = "127.0.0.1",
        token: str | None = None,
        command: Callable[[str, Mapping[str, Any]], str] | None = None,
        token_for_all: bool = False,
    ) -> None:
        self.token = token or secrets.token_urlsafe(16)
        cls = _Server6 if ":" in host else _Server
        self._httpd = cls((host, port), _handler(state, command, self.token, token_for_all))
        self.host = host
        self.port: int = self._httpd.server_address[1]
        self._thread = threading.Thread(
            target=self._httpd.serve_forever,
            name="live-page",
            kwargs={"poll_interval": 0.2},
            daemon=True,
        )
        self._thread.start()

    @property
    def url(self) -> str:
        """The page's address with its token."""
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"http://{host}:{self.port}/?token={self.token}"

    def close(self) -> None:
        """Shut the server down."""
        self._httpd.shutdown()
        self._httpd.server_close()
        self._thread.join(timeout=2.0)
