/* The SVG charts: the histogram of residual distances per cloud (points beyond the distance cap left out and
 * counted) and the timings of the registration stages and of the server.
 */
(function () {
  'use strict';

  var view = window.K4reg.view;
  var el = view.el, svg = view.svg, num = view.num, intStr = view.intStr, len = view.len, secs = view.secs,
    niceStep = view.niceStep, section = view.section;

  /* ctx: what renderView's panels share (render_view.js). */
  view.charts = function (ctx) {
    var doc = ctx.doc, M = ctx.M, R = ctx.R;

    /* -------------------------------------------------------------- */
    /* plots                                                            */
    /* -------------------------------------------------------------- */

    function histogramSection() {
      var s = section('Residual distances', 'section-histogram');
      if (!M.preview || !M.stats || !M.stats.hasDist) {
        s.appendChild(el('p', { class: 'notice', text: 'No residual distances in this document.' }));
        return s;
      }
      var st = M.stats, NB = 40, mx = st.scaleMax;
      var counts = M.clouds.map(function (c) {
        var h = new Float64Array(NB);
        if (!c.dist) return h;
        for (var i = 0; i < c.n; i++) {
          var v = c.dist[i];
          if (!(v < st.capEps)) continue;
          var b = Math.floor(v / mx * NB); if (b >= NB) b = NB - 1; if (b < 0) b = 0;
          h[b]++;
        }
        return h;
      });
      var tot = new Float64Array(NB), ymax = 0;
      counts.forEach(function (h) { for (var b = 0; b < NB; b++) tot[b] += h[b]; });
      for (var b = 0; b < NB; b++) ymax = Math.max(ymax, tot[b]);
      var VW = 600, VH = 260, L = 58, Rr = 12, T = 12, B = 40, pw = VW - L - Rr, ph = VH - T - B;
      var g = svg('svg', { viewBox: '0 0 ' + VW + ' ' + VH, class: 'plot', id: 'histogram' });
      var bw = pw / NB;
      var acc = new Float64Array(NB);
      M.clouds.forEach(function (c, ci) {
        var h = counts[ci];
        for (var k = 0; k < NB; k++) {
          if (!h[k]) continue;
          var y0 = acc[k] / ymax * ph, hh = h[k] / ymax * ph;
          g.appendChild(svg('rect', { x: L + k * bw + 0.5, y: T + ph - y0 - hh, width: Math.max(0.5, bw - 1), height: hh, fill: c.color },
            svg('title', { text: c.name + ': ' + intStr(h[k]) + ' points in ' + len(k * mx / NB) + ' \u2013 ' + len((k + 1) * mx / NB) })));
          acc[k] += h[k];
        }
      });
      /* axes */
      g.appendChild(svg('line', { x1: L, y1: T + ph, x2: L + pw, y2: T + ph, class: 'axis' }));
      g.appendChild(svg('line', { x1: L, y1: T, x2: L, y2: T + ph, class: 'axis' }));
      var xs = niceStep(mx / 5);
      for (var xv = 0; xv <= mx * 1.0001; xv += xs) {
        var xx = L + xv / mx * pw;
        g.appendChild(svg('line', { x1: xx, y1: T + ph, x2: xx, y2: T + ph + 4, class: 'axis' }));
        g.appendChild(svg('text', { x: xx, y: T + ph + 16, 'text-anchor': 'middle', class: 'tick', text: len(xv) }));
      }
      var ys = niceStep(ymax / 4);
      for (var yv = 0; yv <= ymax; yv += ys) {
        var yy = T + ph - yv / ymax * ph;
        g.appendChild(svg('line', { x1: L, y1: yy, x2: L + pw, y2: yy, class: 'grid' }));
        g.appendChild(svg('text', { x: L - 5, y: yy + 4, 'text-anchor': 'end', class: 'tick', text: intStr(yv) }));
      }
      g.appendChild(svg('text', { x: L + pw / 2, y: VH - 6, 'text-anchor': 'middle', class: 'axis-label', text: 'distance to nearest point of the other cloud' + (M.kind === 'project' ? 's' : '') }));
      if (isFinite(st.p95)) {
        var px95 = L + Math.min(1, st.p95 / mx) * pw;
        g.appendChild(svg('line', { x1: px95, y1: T, x2: px95, y2: T + ph, class: 'marker' }));
        g.appendChild(svg('text', { x: px95 + 4, y: T + 12, class: 'tick', text: '95 %' }));
      }
      s.appendChild(g);
      var legend = el('div', { class: 'legend-inline' });
      M.clouds.forEach(function (c) { if (c.dist) legend.appendChild(el('span', null, [el('span', { class: 'swatch', style: { background: c.color } }), c.name])); });
      s.appendChild(legend);
      var capPct = st.total ? (100 * st.capped / st.total).toFixed(1) : '0';
      s.appendChild(el('p', { class: 'small', id: 'histogram-summary' }, [
        intStr(st.inside) + ' preview points within the overlap: median ' + len(st.median) + ', 95th percentile ' + len(st.p95) + ', RMS ' + len(st.rms) + '. ',
        el('b', { text: intStr(st.capped) + ' points (' + capPct + ' %)' }),
        ' had no neighbour within the cap of ' + len(M.preview.cap) + ' (outside the overlap) and are excluded. Values above ' + len(mx) + ' are counted in the last bin.']));
      return s;
    }

    function timingsSection() {
      var s = section('Timings', 'section-timings');
      var rows = [];
      (Array.isArray(R.timings) ? R.timings : []).forEach(function (t) { if (t) rows.push({ group: 'registration', label: t.stage || '?', v: num(t.seconds) }); });
      var sv = doc.service && doc.service.timings;
      if (sv && typeof sv === 'object') {
        Object.keys(sv).forEach(function (k) {
          var v = sv[k];
          if (v !== null && typeof v === 'object') v = v.seconds !== undefined ? v.seconds : NaN;
          rows.push({ group: 'server', label: k, v: num(v) });
        });
      }
      rows = rows.filter(function (r) { return isFinite(r.v); });
      if (!rows.length) { s.appendChild(el('p', { class: 'muted', text: 'No timings in this result.' })); return s; }
      var mx = 0;
      rows.forEach(function (r) { mx = Math.max(mx, r.v); });
      var rowH = 20, groups = [];
      rows.forEach(function (r) { if (groups.indexOf(r.group) < 0) groups.push(r.group); });
      var VW = 600, L = 150, Rr = 70, VH = rows.length * rowH + groups.length * 22 + 6;
      var g = svg('svg', { viewBox: '0 0 ' + VW + ' ' + VH, class: 'plot', id: 'timings-chart' });
      var y = 4;
      groups.forEach(function (grp) {
        g.appendChild(svg('text', { x: 4, y: y + 14, class: 'group-label', text: grp === 'server' ? 'server (service timings)' : 'registration stages' + (M.kind === 'pair' ? '' : ' (all pairs)') }));
        y += 22;
        var sum = 0;
        rows.filter(function (r) { return r.group === grp; }).forEach(function (r) {
          sum += r.v;
          var w = mx > 0 ? r.v / mx * (VW - L - Rr) : 0;
          g.appendChild(svg('text', { x: L - 6, y: y + 13, 'text-anchor': 'end', class: 'tick', text: r.label }));
          g.appendChild(svg('rect', { x: L, y: y + 3, width: Math.max(1, w), height: rowH - 6, class: grp === 'server' ? 'bar bar2' : 'bar' }, svg('title', { text: r.label + ': ' + r.v + ' s' })));
          g.appendChild(svg('text', { x: L + w + 5, y: y + 13, class: 'tick', text: secs(r.v) }));
          y += rowH;
        });
      });
      s.appendChild(g);
      var total = rows.filter(function (r) { return r.group === 'registration'; }).reduce(function (a, r) { return a + r.v; }, 0);
      if (total > 0) s.appendChild(el('p', { class: 'small muted', text: 'Sum of registration stages: ' + secs(total) + '.' }));
      return s;
    }

    return { histogramSection: histogramSection, timingsSection: timingsSection };
  };
})();
