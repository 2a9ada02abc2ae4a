/* The tables of candidates and links: the hypotheses of a pair against the chosen transform; a project's link
 * graph (scans placed by their poses, links coloured by verdict or residual) with its link table, and the
 * scan table.
 */
(function () {
  'use strict';

  var view = window.K4reg.view;
  var el = view.el, svg = view.svg, num = view.num, prec = view.prec, fixed = view.fixed, intStr = view.intStr,
    yesno = view.yesno, truthy = view.truthy, len = view.len, mat4 = view.mat4, matMul = view.matMul,
    rigidInverse = view.rigidInverse, rotAngleDeg = view.rotAngleDeg, section = view.section,
    basename = view.basename, rampCss = view.rampCss, rampGradientCss = view.rampGradientCss;

  /* ctx: what renderView's panels share (render_view.js). */
  view.tables = function (ctx) {
    var R = ctx.R, colorOfScan = ctx.colorOfScan;

    /* -------------------------------------------------------------- */
    /* hypotheses (pair)                                                */
    /* -------------------------------------------------------------- */

    function hypothesesSection() {
      var s = section('Hypotheses', 'section-hypotheses');
      var hs = Array.isArray(R.hypotheses) ? R.hypotheses : [];
      var amb = truthy(R.ambiguous);
      s.appendChild(el('p', { id: 'ambiguity-text', class: amb ? 'warn-text strong' : 'ok-text' }, amb ?
        'Ambiguous: ' + (R.ambiguity_reason || 'several hypotheses fit almost equally well') + ' (margin ' + prec(R.ambiguity_margin, 3) + '). The chosen transform is one candidate; compare the alternatives below.' :
        'Not ambiguous: the chosen hypothesis is clearly better than the alternatives (margin ' + prec(R.ambiguity_margin, 3) + ').'));
      if (!hs.length) { s.appendChild(el('p', { class: 'muted', text: 'No hypotheses in this result.' })); return s; }
      var T = mat4(R.transform);
      var Tinv = T ? rigidInverse(T) : null;
      var head = el('tr', null, ['Rank', 'Cloud score', 'Refined score', 'Surface agreement', 'Keypoint score', 'Rotation vs chosen (deg)', 'Translation vs chosen (m)', 'Base'].map(function (t) { return el('th', { text: t }); }));
      var tb = el('tbody');
      hs.forEach(function (h, i) {
        var H = mat4(h.transform), ang = NaN, dt = NaN;
        if (H && T) {
          ang = rotAngleDeg(matMul(H, Tinv));
          dt = Math.sqrt(Math.pow(H[3] - T[3], 2) + Math.pow(H[7] - T[7], 2) + Math.pow(H[11] - T[11], 2));
        }
        var hasBase = Array.isArray(h.base_source_m) && h.base_source_m.length === 12;
        tb.appendChild(el('tr', { class: i === 0 ? 'chosen' : '' }, [
          el('td', { text: String(i + 1) + (i === 0 ? ' (best)' : '') }),
          el('td', { class: 'num', text: fixed(h.cloud_score, 4) }),
          el('td', { class: 'num', text: fixed(h.refined_score, 4) }),
          el('td', { class: 'num', text: fixed(h.surface_agreement, 4) }),
          el('td', { class: 'num', text: fixed(h.keypoint_score, 4) }),
          el('td', { class: 'num', text: isFinite(ang) ? ang.toFixed(2) : '\u2013' }),
          el('td', { class: 'num', text: isFinite(dt) ? dt.toPrecision(4) : '\u2013' }),
          el('td', { text: hasBase ? 'yes' : '\u2013' })]));
      });
      s.appendChild(el('div', { class: 'table-wrap' }, el('table', { class: 'data', id: 'hypotheses-table' }, [el('thead', null, head), tb])));
      s.appendChild(el('p', { class: 'small muted', text: 'Rotation: angle of H\u00b7T\u207b\u00b9 (H = hypothesis, T = chosen transform). Translation: distance between the translation parts of H and T.' }));
      return s;
    }

    /* -------------------------------------------------------------- */
    /* project: link graph + link table + scan table                    */
    /* -------------------------------------------------------------- */

    function linkGraphSection() {
      var s = section('Link graph', 'section-links');
      var scans = Array.isArray(R.scans) ? R.scans : [];
      var links = Array.isArray(R.links) ? R.links : [];
      var byResidual = el('input', { type: 'checkbox', id: 'link-color-residual' });
      s.appendChild(el('div', { class: 'toolbar' }, [
        el('label', { class: 'ctl-check' }, [byResidual, ' colour accepted links by residual']),
        el('span', { class: 'legend-inline' }, [lineSwatch('#2e9e44', false), 'accepted', lineSwatch('#d62728', true), 'rejected',
          el('span', { class: 'node-swatch hollow' }), 'not registered'])]));
      var layout = el('div', { class: 'graph-layout' });
      s.appendChild(layout);

      var VW = 560, VH = 440, pad = 46;
      var g = svg('svg', { id: 'link-graph', viewBox: '0 0 ' + VW + ' ' + VH, class: 'link-graph', role: 'img', 'aria-label': 'link graph' });
      layout.appendChild(el('div', { class: 'graph-box' }, g));
      var tableBox = el('div', { class: 'table-wrap graph-table' });
      layout.appendChild(tableBox);

      /* node positions */
      var pos = [], reg = [], unreg = [];
      scans.forEach(function (sc, i) {
        var P = mat4(sc.pose);
        if (P && truthy(sc.registered !== undefined ? sc.registered : true)) reg.push([i, P[3], P[7]]); else unreg.push(i);
      });
      var minx = Infinity, maxx = -Infinity, miny = Infinity, maxy = -Infinity;
      reg.forEach(function (r) { minx = Math.min(minx, r[1]); maxx = Math.max(maxx, r[1]); miny = Math.min(miny, r[2]); maxy = Math.max(maxy, r[2]); });
      var areaW = (unreg.length ? VW - 110 : VW) - 2 * pad, areaH = VH - 2 * pad;
      var ext = Math.max(maxx - minx, maxy - miny);
      if (reg.length > 1 && ext > 1e-9) {
        var sc = Math.min(areaW / Math.max(maxx - minx, 1e-12), areaH / Math.max(maxy - miny, 1e-12));
        var cxp = pad + areaW / 2, cyp = pad + areaH / 2, mx = (minx + maxx) / 2, my = (miny + maxy) / 2;
        reg.forEach(function (r) { pos[r[0]] = [cxp + (r[1] - mx) * sc, cyp - (r[2] - my) * sc]; });
      } else {
        reg.forEach(function (r, k) {
          var a = 2 * Math.PI * k / Math.max(1, reg.length);
          pos[r[0]] = reg.length === 1 ? [pad + areaW / 2, pad + areaH / 2] : [pad + areaW / 2 + Math.cos(a) * areaH / 3, pad + areaH / 2 - Math.sin(a) * areaH / 3];
        });
      }
      /* push apart coincident nodes */
      for (var it = 0; it < 60; it++) {
        var moved = false;
        for (var a1 = 0; a1 < reg.length; a1++) {
          for (var b1 = a1 + 1; b1 < reg.length; b1++) {
            var pa = pos[reg[a1][0]], pb = pos[reg[b1][0]];
            var dx = pb[0] - pa[0], dy = pb[1] - pa[1], dd = Math.sqrt(dx * dx + dy * dy);
            if (dd < 64) {
              if (dd < 1e-6) { dx = 0.3; dy = 1; dd = Math.sqrt(1.09); }
              var push = (64 - dd) / 2;
              pa[0] -= dx / dd * push; pa[1] -= dy / dd * push; pb[0] += dx / dd * push; pb[1] += dy / dd * push;
              moved = true;
            }
          }
        }
        if (!moved) break;
      }
      /* crop the drawing vertically to the registered nodes (equal aspect keeps a flat layout flat) */
      var ylo = Infinity, yhi = -Infinity;
      reg.forEach(function (r) { ylo = Math.min(ylo, pos[r[0]][1]); yhi = Math.max(yhi, pos[r[0]][1]); });
      if (!isFinite(ylo)) { ylo = VH / 2; yhi = VH / 2; }
      ylo -= 40; yhi += 50;
      var minH = Math.max(240, unreg.length * 70 + 50);
      if (yhi - ylo < minH) { var grow = (minH - (yhi - ylo)) / 2; ylo -= grow; yhi += grow; }
      g.setAttribute('viewBox', '0 ' + ylo.toFixed(1) + ' ' + VW + ' ' + (yhi - ylo).toFixed(1));
      unreg.forEach(function (i, k) { pos[i] = [VW - 55, ylo + 60 + k * 70]; });
      if (unreg.length) {
        g.appendChild(svg('line', { x1: VW - 110, y1: ylo + 8, x2: VW - 110, y2: yhi - 8, stroke: '#c9ced6', 'stroke-dasharray': '3 4' }));
        g.appendChild(svg('text', { x: VW - 55, y: ylo + 22, 'text-anchor': 'middle', class: 'g-note', text: 'not registered' }));
      }

      var maxRes = 0;
      links.forEach(function (l) { var r = num(l.residual_m); if (truthy(l.accepted) && r > maxRes) maxRes = r; });
      var lineEls = [], rows = [];
      var linkLayer = svg('g'), nodeLayer = svg('g');
      g.appendChild(linkLayer); g.appendChild(nodeLayer);
      links.forEach(function (l, i) {
        var a = pos[num(l.source)], b = pos[num(l.target)];
        if (!a || !b) { lineEls.push(null); return; }
        var acc = truthy(l.accepted);
        var grp = svg('g', { class: 'link ' + (acc ? 'accepted' : 'rejected'), 'data-link': String(i) });
        var vis = svg('line', { x1: a[0], y1: a[1], x2: b[0], y2: b[1], class: 'link-line', 'stroke-width': 3.5,
          'stroke-dasharray': acc ? null : '7 5' });
        var hit = svg('line', { x1: a[0], y1: a[1], x2: b[0], y2: b[1], stroke: 'transparent', 'stroke-width': 14, class: 'link-hit' });
        var t = svg('title', { text: 'link ' + i + ': ' + num(l.source) + ' \u2192 ' + num(l.target) + ', ' + (l.verdict || '') + (acc ? ', accepted' : ', rejected') + ', rmse ' + len(l.rmse_m) + (l.reason ? ' \u2013 ' + l.reason : '') });
        grp.appendChild(vis); grp.appendChild(hit); grp.appendChild(t);
        grp.addEventListener('mouseenter', function () { highlight(i, false); });
        grp.addEventListener('mouseleave', function () { highlight(-1, false); });
        grp.addEventListener('click', function () { highlight(i, true); });
        linkLayer.appendChild(grp);
        lineEls.push({ grp: grp, vis: vis, link: l, acc: acc });
      });
      scans.forEach(function (scn, i) {
        var p = pos[i]; if (!p) return;
        var isReg = unreg.indexOf(i) < 0;
        var isRef = num(R.reference) === i;
        var ng = svg('g', { class: 'node' + (isReg ? '' : ' unregistered') });
        ng.appendChild(svg('circle', { cx: p[0], cy: p[1], r: 15, fill: isReg ? colorOfScan(i) : '#ffffff', stroke: isReg ? (isRef ? '#111' : '#ffffff') : '#8a8f96',
          'stroke-width': isRef ? 3 : 2, 'stroke-dasharray': isReg ? null : '3 2' }));
        ng.appendChild(svg('text', { x: p[0], y: p[1] + 4.5, 'text-anchor': 'middle', class: 'node-index' + (isReg ? '' : ' grey'), text: String(i) }));
        var crowdedBelow = scans.some(function (o, j) {
          var q = pos[j];
          return j !== i && q && Math.abs(q[0] - p[0]) < 80 && q[1] - p[1] > 0 && q[1] - p[1] < 50;
        });
        ng.appendChild(svg('text', { x: p[0], y: crowdedBelow ? p[1] - 21 : p[1] + 31, 'text-anchor': 'middle', class: 'node-label', text: basename(scn.file || '') + (isRef ? ' (ref)' : '') }));
        ng.appendChild(svg('title', { text: 'scan ' + i + ': ' + (scn.file || '') + (isReg ? '' : ' \u2013 not registered: ' + (scn.reason || '')) }));
        nodeLayer.appendChild(ng);
      });

      function colorLinks() {
        lineEls.forEach(function (o) {
          if (!o) return;
          var c;
          if (!o.acc) c = '#d62728';
          else if (byResidual.checked) {
            var r = num(o.link.residual_m);
            c = r >= 0 && maxRes > 0 ? rampCss(r / maxRes) : '#8a8f96';
          } else c = '#2e9e44';
          o.vis.setAttribute('stroke', c);
        });
        resLegend.style.display = byResidual.checked ? '' : 'none';
      }
      var resLegend = el('div', { class: 'legend small res-legend' }, [
        el('div', { class: 'ramp', style: { background: rampGradientCss() } }),
        el('div', { class: 'ramp-labels' }, [el('span', { text: '0' }), el('span', { text: 'residual_m' }), el('span', { text: len(maxRes) })]),
        el('div', { class: 'legend-row' }, [el('span', { class: 'swatch', style: { background: '#8a8f96' } }), 'accepted, not in refinement (residual -1)'])]);
      s.insertBefore(resLegend, layout);
      byResidual.addEventListener('change', colorLinks);

      /* link table */
      var cols = ['#', 'Source', 'Target', 'Verdict', 'Accepted', 'RMSE (m)', 'Overlap', 'Loops closed', 'Loop residual (m)', 'Residual (m)', 'Reason'];
      var tb = el('tbody');
      links.forEach(function (l, i) {
        var lr = num(l.loop_residual_m), rr = num(l.residual_m);
        var tr = el('tr', { 'data-link': String(i), class: truthy(l.accepted) ? 'accepted' : 'rejected' }, [
          el('td', { text: String(i) }),
          el('td', { text: scanLabel(l.source) }),
          el('td', { text: scanLabel(l.target) }),
          el('td', { text: l.verdict || '\u2013' }),
          el('td', { class: truthy(l.accepted) ? 'ok-text' : 'bad-text', text: yesno(l.accepted) }),
          el('td', { class: 'num', text: prec(l.rmse_m, 4) }),
          el('td', { class: 'num', text: fixed(l.overlap, 3) }),
          el('td', { class: 'num', text: intStr(l.loops_closed) + '/' + intStr(l.loops) }),
          el('td', { class: 'num', text: lr < 0 ? 'in no loop' : prec(l.loop_residual_m, 3) }),
          el('td', { class: 'num', text: rr < 0 ? 'not refined' : prec(l.residual_m, 3) }),
          el('td', { class: 'reason', text: l.reason || '' })]);
        tr.addEventListener('mouseenter', function () { highlight(i, false); });
        tr.addEventListener('mouseleave', function () { highlight(-1, false); });
        tr.addEventListener('click', function () { highlight(i, true); });
        tb.appendChild(tr);
        rows.push(tr);
      });
      tableBox.appendChild(el('table', { class: 'data', id: 'link-table' }, [el('thead', null, el('tr', null, cols.map(function (c) { return el('th', { text: c }); }))), tb]));

      var pinned = -1;
      function highlight(i, click) {
        if (click) pinned = pinned === i ? -1 : i;
        var h = i >= 0 ? i : pinned;
        rows.forEach(function (r, k) { r.classList.toggle('hl', k === h); });
        lineEls.forEach(function (o, k) { if (o) o.grp.classList.toggle('hl', k === h); });
        if (h >= 0 && rows[h] && click) {
          var box = tableBox, r = rows[h];
          if (r.offsetTop < box.scrollTop || r.offsetTop > box.scrollTop + box.clientHeight - r.offsetHeight) box.scrollTop = r.offsetTop - 40;
        }
      }
      colorLinks();
      return s;

      function lineSwatch(c, dashed) {
        return svg('svg', { width: 28, height: 10, class: 'line-swatch' }, svg('line', { x1: 1, y1: 5, x2: 27, y2: 5, stroke: c, 'stroke-width': 3, 'stroke-dasharray': dashed ? '5 3' : null }));
      }
    }

    function scanLabel(i) {
      var sc = (R.scans || [])[num(i)];
      return num(i) + (sc && sc.file ? ' ' + basename(sc.file) : '');
    }

    function scanTableSection() {
      var s = section('Scans', 'section-scans');
      var cols = ['#', 'File', 'Registered', 'Points', 'Strength', 'Links', 'Reason'];
      var tb = el('tbody');
      (R.scans || []).forEach(function (sc, i) {
        var reg = truthy(sc.registered);
        tb.appendChild(el('tr', { class: reg ? '' : 'rejected' }, [
          el('td', null, [el('span', { class: 'swatch', style: { background: colorOfScan(i) } }), String(i)]),
          el('td', { text: String(sc.file || '') + (num(R.reference) === i ? ' (reference)' : '') }),
          el('td', { class: reg ? 'ok-text' : 'bad-text', text: yesno(reg) }),
          el('td', { class: 'num', text: intStr(sc.points) }),
          el('td', { class: 'num', text: fixed(sc.strength, 3) }),
          el('td', { text: Array.isArray(sc.links) ? sc.links.map(Number).join(', ') : '' }),
          el('td', { class: 'reason', text: sc.reason || '' })]));
      });
      s.appendChild(el('div', { class: 'table-wrap' }, el('table', { class: 'data', id: 'scan-table' }, [el('thead', null, el('tr', null, cols.map(function (c) { return el('th', { text: c }); }))), tb])));
      return s;
    }

    return { hypothesesSection: hypothesesSection, linkGraphSection: linkGraphSection,
      scanTableSection: scanTableSection };
  };
})();
