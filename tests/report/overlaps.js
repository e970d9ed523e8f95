// Boxes of what report.html drew, read from the rendered page (the test's side: it uses
// nothing of the page's placer). Returns {items: [[name, x0, y0, x1, y1, onRoute]],
// fixed: [[name, x0, y0, x1, y1]], routes: [[x0, y0, x1, y1], ...] (segments)}, in CSS px.
(function () {
  var gd = document.getElementById('sailroute-map'), fig = JSON.parse(
    document.getElementById('sailroute-figure').textContent);
  var routeIdx = fig.place.routes, out = {items: [], fixed: [], routes: []};
  function box(el) { var r = el.getBoundingClientRect(); return [r.left, r.top, r.right, r.bottom]; }
  gd.querySelectorAll('g.annotation').forEach(function (g) {
    var k = parseInt(g.getAttribute('data-index'), 10), name = fig.layout.annotations[k].name;
    var t = g.querySelector('.annotation-text-g');
    if (t) { out.items.push([name].concat(box(t), [/^legno/.test(name)])); }
  });
  gd.querySelectorAll('g.trace.scatter').forEach(function (g) {
    var cd = g.__data__, tr = cd && cd[0] && cd[0].trace;
    if (!tr || tr.visible !== true) { return; }
    var name = gd.data[tr.index].name || '';
    if (routeIdx.indexOf(tr.index) >= 0) {
      g.querySelectorAll('path.js-line').forEach(function (p) {
        var m = p.getScreenCTM();
        var prev = null;
        (p.getAttribute('d') || '').split(/(?=[ML])/).forEach(function (cmd) {
          var xy = cmd.slice(1).split(',').map(Number);
          if (xy.length !== 2 || isNaN(xy[0])) { return; }
          var q = new DOMPoint(xy[0], xy[1]).matrixTransform(m);
          if (cmd[0] === 'L' && prev) { out.routes.push([prev.x, prev.y, q.x, q.y]); }
          prev = q;
        });
      });
    }
    var kind = name === 'tacks' || name === 'gybes' ? 'symbol' :
               name === 'favoured end' ? 'favoured' :
               name === 'marks' ? 'mark' : /^boat: /.test(name) ? 'boat' : '';
    if (!kind) { return; }
    g.querySelectorAll('path.point').forEach(function (p, i) {
      var b = box(p);
      if (kind === 'mark' || kind === 'boat') { out.fixed.push([kind + ':' + i].concat(b)); }
      else { out.items.push([name + ':' + i].concat(b, [kind === 'symbol'])); }
    });
  });
  var legend = gd.querySelector('g.legend');
  if (legend) { out.items.push(['legend'].concat(box(legend), [false])); }
  var f = document.getElementById('sailroute-furniture');
  out.items.push(['scale bar and north arrow'].concat(box(f), [false]));
  return JSON.stringify(out);
})()
