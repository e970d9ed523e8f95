"""The coach's page: a local web server on 127.0.0.1 with one page and one JSON endpoint.

``GET /`` is a self-contained page (inline SVG and script, no framework, no network)
that polls ``GET /state.json`` every second and draws the course, the boat, the route
ahead, the laylines into the next mark, the wind trend, the times to the next mark and
to the finish, and the side that pays.  ``/state.json`` is whatever the ``state``
callable returns (:meth:`sailroute.live.engine.LiveEngine.state`).
"""

from __future__ import annotations

import json
import threading
from collections.abc import Callable
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any

PAGE = """<!doctype html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>sailroute live</title>
<style>
body{font-family:system-ui,sans-serif;margin:0;background:#f4f6f8;color:#123}
header{display:flex;flex-wrap:wrap;gap:1.2em;padding:.6em 1em;background:#123;color:#fff}
header div{font-size:1.1em} header b{font-size:1.6em;display:block}
#stale{background:#c0392b;padding:.2em .6em;border-radius:.3em;display:none}
main{display:flex;flex-wrap:wrap;gap:1em;padding:1em}
svg{background:#dbe9f4;border-radius:.4em}
#trend{background:#fff} .note{font-size:.9em;color:#555}
</style></head><body>
<header>
 <div>next mark<b id="tmark">-</b></div><div>finish<b id="tfin">-</b></div>
 <div>wind<b id="wind">-</b></div><div>side that pays<b id="side">-</b></div>
 <div>re-plan<b id="plan">-</b></div><div id="stale">DATA STALE</div>
</header>
<main>
 <svg id="map" width="560" height="560" viewBox="0 0 560 560"></svg>
 <div><svg id="trend" width="360" height="200" viewBox="0 0 360 200"></svg>
 <p class="note" id="info"></p></div>
</main>
<script>
"use strict";
const $ = id => document.getElementById(id);
const mmss = s => s == null ? "-" : (s < 0 ? "-" : "") + Math.floor(Math.abs(s) / 60) + ":"
  + String(Math.round(Math.abs(s) % 60)).padStart(2, "0");
const NS = "http://www.w3.org/2000/svg";
function el(p, tag, attrs) { const e = document.createElementNS(NS, tag);
  for (const k in attrs) e.setAttribute(k, attrs[k]); p.appendChild(e); return e; }
function draw(s) {
  const p = s.plan, pos = s.position, m = $("map"); m.innerHTML = "";
  const pts = s.marks.map(k => [k[1], k[2]]);
  if (p) p.route.forEach(q => pts.push(q));
  if (pos) pts.push([pos.lat, pos.lon]);
  if (!pts.length) return;
  const lat0 = pts.reduce((a, q) => a + q[0], 0) / pts.length, k = Math.cos(lat0 * Math.PI / 180);
  let x0 = 1e9, x1 = -1e9, y0 = 1e9, y1 = -1e9;
  pts.forEach(q => { x0 = Math.min(x0, q[1] * k); x1 = Math.max(x1, q[1] * k);
    y0 = Math.min(y0, q[0]); y1 = Math.max(y1, q[0]); });
  const sc = 500 / Math.max(x1 - x0, y1 - y0, 1e-5);
  const X = q => 30 + (q[1] * k - x0) * sc, Y = q => 530 - (q[0] - y0) * sc;
  if (p && pos) p.laylines.forEach(l => { const t = s.next_mark; if (!t) return;
    const b = (l.bearing_deg + 180) * Math.PI / 180, L = 2000;
    el(m, "line", {x1: X(t), y1: Y(t), x2: X(t) + L * Math.sin(b), y2: Y(t) - L * Math.cos(b),
      stroke: l.tack === "starboard" ? "#2a9d2a" : "#c0392b", "stroke-dasharray": "6 4"}); });
  if (p) el(m, "polyline", {points: p.route.map(q => X(q) + "," + Y(q)).join(" "),
    fill: "none", stroke: "#1565c0", "stroke-width": 2.5});
  s.marks.forEach(q => { el(m, "circle", {cx: X([q[1], q[2]]), cy: Y([q[1], q[2]]), r: 5,
    fill: "#f39c12"}); el(m, "text", {x: X([q[1], q[2]]) + 7, y: Y([q[1], q[2]]) - 7})
    .textContent = q[0]; });
  if (pos) { el(m, "circle", {cx: X([pos.lat, pos.lon]), cy: Y([pos.lat, pos.lon]), r: 7,
    fill: "#123"}); }
  if (s.wind) { const b = s.wind.twd_deg * Math.PI / 180;
    el(m, "line", {x1: 520, y1: 40, x2: 520 - 25 * Math.sin(b), y2: 40 + 25 * Math.cos(b),
      stroke: "#123", "stroke-width": 3}); el(m, "circle", {cx: 520, cy: 40, r: 3}); }
}
function trend(s) {
  const g = $("trend"); g.innerHTML = ""; const w = s.wind_trend; if (w.length < 2) return;
  const t0 = w[0][0], t1 = w[w.length - 1][0], d = w.map(q => q[2]);
  const dm = d[d.length - 1], sp = w.map(q => q[1] * 1.9438);
  const X = t => 10 + (t - t0) / Math.max(t1 - t0, 1) * 340;
  let prev = d[0], un = d.map(v => { let x = v; while (x - prev > 180) x -= 360;
    while (x - prev < -180) x += 360; prev = x; return x; });
  const lo = Math.min(...un), hi = Math.max(...un, lo + 10);
  el(g, "polyline", {points: w.map((q, i) => X(q[0]) + "," + (10 + (hi - un[i]) / (hi - lo)
    * 80)).join(" "), fill: "none", stroke: "#1565c0"});
  const smax = Math.max(...sp, 1);
  el(g, "polyline", {points: w.map((q, i) => X(q[0]) + "," + (190 - sp[i] / smax * 80))
    .join(" "), fill: "none", stroke: "#2a9d2a"});
  el(g, "text", {x: 10, y: 105}).textContent = "TWD " + lo.toFixed(0) + "-" + hi.toFixed(0)
    + "°, TWS up to " + smax.toFixed(1) + " kn (last " + Math.round((t1 - t0) / 60) + " min)";
}
async function poll() {
  try {
    const s = await (await fetch("state.json", {cache: "no-store"})).json(), p = s.plan;
    $("tmark").textContent = p ? mmss(p.time_to_mark_s - (s.t - p.t)) : "-";
    $("tfin").textContent = p ? mmss(p.time_to_finish_s - (s.t - p.t)) : "-";
    $("wind").textContent = s.wind ? (s.wind.tws_ms * 1.9438).toFixed(1) + " kn "
      + s.wind.twd_deg.toFixed(0) + "°" : "-";
    $("side").textContent = p && p.side ? (p.side.side === "none" ? "neither" : p.side.side
      + " by " + p.side.gain_s.toFixed(0) + " s") : "-";
    $("plan").textContent = p ? "#" + p.number + " (" + p.reason + ")" : "-";
    $("stale").style.display = s.stale ? "block" : "none";
    $("info").textContent = (s.error ? "routing: " + s.error + " | " : "") + "source "
      + s.source + ", leg " + (s.leg + 1) + " of " + s.n_legs + ", sentences "
      + s.counts.used + " used, " + s.counts.bad + " bad";
    draw(s); trend(s);
  } catch (e) { $("stale").style.display = "block"; }
  setTimeout(poll, 1000);
}
poll();
</script></body></html>
"""


def _handler(state: Callable[[], dict[str, Any]]) -> type[BaseHTTPRequestHandler]:
    class Handler(BaseHTTPRequestHandler):
        def do_GET(self) -> None:
            path = self.path.split("?", 1)[0]
            if path in ("/", "/index.html"):
                body, ctype = PAGE.encode("utf-8"), "text/html; charset=utf-8"
            elif path == "/state.json":
                body, ctype = json.dumps(state()).encode("utf-8"), "application/json"
            else:
                self.send_error(404, "only / and /state.json")
                return
            self.send_response(200)
            self.send_header("Content-Type", ctype)
            self.send_header("Content-Length", str(len(body)))
            self.send_header("Cache-Control", "no-store")
            self.end_headers()
            self.wfile.write(body)

        def log_message(self, format: str, *args: Any) -> None:
            """Quiet: the terminal shows the re-plans, not every poll."""

    return Handler


class PageServer:
    """The page and ``/state.json`` on ``host:port`` (0: a free port, see :attr:`port`)."""

    def __init__(
        self, state: Callable[[], dict[str, Any]], port: int, host: str = "127.0.0.1"
    ) -> None:
        self._httpd = ThreadingHTTPServer((host, port), _handler(state))
        self._httpd.daemon_threads = True
        self.port: int = self._httpd.server_address[1]
        self._thread = threading.Thread(
            target=self._httpd.serve_forever,
            name="live-page",
            kwargs={"poll_interval": 0.2},
            daemon=True,
        )
        self._thread.start()

    def close(self) -> None:
        """Shut the server down."""
        self._httpd.shutdown()
        self._httpd.server_close()
        self._thread.join(timeout=2.0)
