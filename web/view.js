/* k4reg result view: renders one registration result document (pair or
 * project) as an interactive QA page. Plain ES2017, no dependencies except
 * the global THREE (three.js r111 + OrbitControls) for the 3D panel.
 *
 * API: K4reg.renderView(rootElement, doc) -> {destroy()}
 * Sets window.k4regView = {ready, document, pointsShown, render()} once the
 * view (and its first 3D frame, if any) is drawn.
 */
(function () {
  'use strict';

  var K4reg = window.K4reg = window.K4reg || {};
  var SVGNS = ['http', '//www.w3.org/2000/svg'].join(':'); /* written so that no URL literal appears in the page */

  /* ------------------------------------------------------------------ */
  /* small helpers                                                       */
  /* ------------------------------------------------------------------ */

  function el(tag, attrs, children) {
    var e = document.createElement(tag);
    setAttrs(e, attrs);
    appendAll(e, children);
    return e;
  }

  function svg(tag, attrs, children) {
    var e = document.createElementNS(SVGNS, tag);
    setAttrs(e, attrs);
    appendAll(e, children);
    return e;
  }

  function setAttrs(e, attrs) {
    if (!attrs) return;
    Object.keys(attrs).forEach(function (k) {
      var v = attrs[k];
      if (v === undefined || v === null || v === false) return;
      if (k === 'text') e.textContent = v;
      else if (k.slice(0, 2) === 'on' && typeof v === 'function') e.addEventListener(k.slice(2), v);
      else if (k === 'class') e.setAttribute('class', v);
      else if (k === 'style' && typeof v === 'object') Object.assign(e.style, v);
      else if (k in e && typeof e[k] !== 'function' && e.namespaceURI !== SVGNS && k !== 'list' && k !== 'type') e[k] = v;
      else e.setAttribute(k, v === true ? '' : String(v));
    });
  }

  function appendAll(e, children) {
    if (children === undefined || children === null) return;
    if (!Array.isArray(children)) children = [children];
    children.forEach(function (c) {
      if (c === undefined || c === null || c === false) return;
      e.appendChild(typeof c === 'object' ? c : document.createTextNode(String(c)));
    });
  }

  /* Numbers may come as numbers (CLI) or strings (protobuf JSON int64). */
  function num(x) {
    if (x === null || x === undefined || x === '') return NaN;
    var v = Number(x);
    return v;
  }
  function isNum(x) { return isFinite(num(x)); }
  function prec(x, p) { var v = num(x); return isFinite(v) ? v.toPrecision(p || 6) : '\u2013'; }
  function fixed(x, d) { var v = num(x); return isFinite(v) ? v.toFixed(d) : '\u2013'; }
  function intStr(x) {
    var v = num(x);
    if (!isFinite(v)) return '\u2013';
    return Math.round(v).toString().replace(/\B(?=(\d{3})+(?!\d))/g, '\u202f');
  }
  function pct(x) { var v = num(x); return isFinite(v) ? (100 * v).toFixed(1) + ' %' : '\u2013'; }
  function yesno(b) { return b === true || b === 'true' ? 'yes' : 'no'; }
  function truthy(b) { return b === true || b === 'true' || b === 1; }
  /* A length in metres, human readable (mm below 1 m). */
  function len(m) {
    var v = num(m);
    if (!isFinite(v)) return '\u2013';
    var a = Math.abs(v);
    if (a === 0) return '0 m';
    if (a < 0.001) return (v * 1000).toPrecision(2) + ' mm';
    if (a < 1) return (v * 1000).toPrecision(3) + ' mm';
    return v.toPrecision(4) + ' m';
  }
  function secs(s) {
    var v = num(s);
    if (!isFinite(v)) return '\u2013';
    if (v < 0.01) return (v * 1000).toFixed(1) + ' ms';
    if (v < 100) return v.toFixed(2) + ' s';
    return v.toFixed(0) + ' s';
  }

  /* A 4x4 row-major matrix (16 numbers) or null for null / [] / garbage. */
  function mat4(p) {
    if (!Array.isArray(p) || p.length !== 16) return null;
    var m = p.map(Number);
    for (var i = 0; i < 16; i++) if (!isFinite(m[i])) return null;
    return m;
  }
  function matMul(a, b) {
    var r = new Array(16);
    for (var i = 0; i < 4; i++) {
      for (var j = 0; j < 4; j++) {
        var s = 0;
        for (var k = 0; k < 4; k++) s += a[i * 4 + k] * b[k * 4 + j];
        r[i * 4 + j] = s;
      }
    }
    return r;
  }
  /* Inverse of a rigid transform (rotation part transposed). */
  function rigidInverse(m) {
    var r = [m[0], m[4], m[8], 0, m[1], m[5], m[9], 0, m[2], m[6], m[10], 0, 0, 0, 0, 1];
    r[3] = -(r[0] * m[3] + r[1] * m[7] + r[2] * m[11]);
    r[7] = -(r[4] * m[3] + r[5] * m[7] + r[6] * m[11]);
    r[11] = -(r[8] * m[3] + r[9] * m[7] + r[10] * m[11]);
    return r;
  }
  function rotAngleDeg(m) {
    var c = (m[0] + m[5] + m[10] - 1) / 2;
    c = Math.max(-1, Math.min(1, c));
    return Math.acos(c) * 180 / Math.PI;
  }
  function rotAxis(m) {
    var x = m[9] - m[6], y = m[2] - m[8], z = m[4] - m[1];
    var n = Math.sqrt(x * x + y * y + z * z);
    return n > 1e-12 ? [x / n, y / n, z / n] : null;
  }
  function applyT(m, x, y, z) {
    return [m[0] * x + m[1] * y + m[2] * z + m[3],
            m[4] * x + m[5] * y + m[6] * z + m[7],
            m[8] * x + m[9] * y + m[10] * z + m[11]];
  }

  var LITTLE_ENDIAN = new Uint8Array(new Uint32Array([1]).buffer)[0] === 1;

  /* base64 -> Float32Array (little-endian float32 payload). */
  function decodeF32(s) {
    if (!s || typeof s !== 'string') return new Float32Array(0);
    var bin = atob(s);
    var n = bin.length - (bin.length % 4);
    var buf = new ArrayBuffer(n);
    var u8 = new Uint8Array(buf);
    for (var i = 0; i < n; i++) u8[i] = bin.charCodeAt(i);
    if (LITTLE_ENDIAN) return new Float32Array(buf);
    var dv = new DataView(buf), out = new Float32Array(n / 4);
    for (var j = 0; j < out.length; j++) out[j] = dv.getFloat32(4 * j, true);
    return out;
  }

  function hexToRgb(h) {
    var v = parseInt(h.slice(1), 16);
    return [(v >> 16) & 255, (v >> 8) & 255, v & 255];
  }

  var PAIR_COLORS = ['#f28e2b', '#4e8fd6'];
  var PALETTE = ['#4e8fd6', '#f28e2b', '#59a14f', '#e15759', '#b07aa1', '#edc948',
                 '#76b7b2', '#ff9da7', '#9c755f', '#8cd17d', '#d4a6c8', '#86bcb6'];
  function paletteColor(i) {
    if (i < PALETTE.length) return PALETTE[i];
    var hue = (i * 137.508) % 360;
    return hslHex(hue, 0.65, 0.58);
  }
  function hslHex(h, s, l) {
    var c = (1 - Math.abs(2 * l - 1)) * s, x = c * (1 - Math.abs((h / 60) % 2 - 1)), m = l - c / 2;
    var r = 0, g = 0, b = 0;
    if (h < 60) { r = c; g = x; } else if (h < 120) { r = x; g = c; } else if (h < 180) { g = c; b = x; }
    else if (h < 240) { g = x; b = c; } else if (h < 300) { r = x; b = c; } else { r = c; b = x; }
    function hx(v) { var t = Math.round((v + m) * 255).toString(16); return t.length < 2 ? '0' + t : t; }
    return '#' + hx(r) + hx(g) + hx(b);
  }

  /* Residual colour ramp (blue -> cyan -> green -> yellow -> red). */
  var RAMP = [[0, '#2b59c3'], [0.25, '#12a4d9'], [0.5, '#5cc864'], [0.75, '#f2c230'], [1, '#d7301f']];
  var CAPPED_COLOR = '#8a8f96';
  var RAMP_LUT = (function () {
    var lut = new Float32Array(256 * 3);
    for (var i = 0; i < 256; i++) {
      var t = i / 255, k = 1;
      while (k < RAMP.length - 1 && RAMP[k][0] < t) k++;
      var a = RAMP[k - 1], b = RAMP[k], f = (t - a[0]) / (b[0] - a[0]);
      var ca = hexToRgb(a[1]), cb = hexToRgb(b[1]);
      for (var c = 0; c < 3; c++) lut[i * 3 + c] = (ca[c] + (cb[c] - ca[c]) * f) / 255;
    }
    return lut;
  })();
  function rampCss(t) {
    var i = Math.max(0, Math.min(255, Math.round(t * 255)));
    return 'rgb(' + Math.round(RAMP_LUT[i * 3] * 255) + ',' + Math.round(RAMP_LUT[i * 3 + 1] * 255) + ',' +
      Math.round(RAMP_LUT[i * 3 + 2] * 255) + ')';
  }
  function rampGradientCss() {
    return 'linear-gradient(to right, ' + RAMP.map(function (s) { return s[1] + ' ' + (s[0] * 100) + '%'; }).join(', ') + ')';
  }

  function niceStep(x) {
    if (!(x > 0)) return 1;
    var e = Math.pow(10, Math.floor(Math.log10(x))), f = x / e;
    return (f < 1.5 ? 1 : f < 3.5 ? 2 : f < 7.5 ? 5 : 10) * e;
  }
  function niceFloor(x) {
    if (!(x > 0)) return 1;
    var e = Math.pow(10, Math.floor(Math.log10(x))), f = x / e;
    return (f >= 5 ? 5 : f >= 2 ? 2 : 1) * e;
  }

  function copyText(text, button) {
    function done(ok) {
      if (!button) return;
      var old = button.dataset.label || button.textContent;
      button.dataset.label = old;
      button.textContent = ok ? 'Copied' : 'Copy failed';
      setTimeout(function () { button.textContent = old; }, 1500);
    }
    function fallback() {
      var ta = el('textarea', { value: text, style: { position: 'fixed', left: '-9999px', top: '0' } });
      document.body.appendChild(ta);
      ta.select();
      var ok = false;
      try { ok = document.execCommand('copy'); } catch (e) { ok = false; }
      document.body.removeChild(ta);
      done(ok);
    }
    try {
      if (navigator.clipboard && navigator.clipboard.writeText && window.isSecureContext) {
        navigator.clipboard.writeText(text).then(function () { done(true); }, fallback);
        return;
      }
    } catch (e) { /* fall through */ }
    fallback();
  }

  function matrixText(m) {
    var rows = [];
    for (var r = 0; r < 4; r++) rows.push(m.slice(r * 4, r * 4 + 4).map(function (v) { return String(v); }).join(' '));
    return rows.join('\n');
  }

  function section(title, id, extraClass) {
    var s = el('section', { class: 'card' + (extraClass ? ' ' + extraClass : ''), id: id });
    s.appendChild(el('h2', { text: title }));
    return s;
  }

  function kvTable(rows, cls) {
    var tb = el('tbody');
    rows.forEach(function (r) {
      if (!r) return;
      tb.appendChild(el('tr', null, [el('th', { text: r[0] }), el('td', r[2] ? { id: r[2] } : null, r[1])]));
    });
    return el('table', { class: 'kv ' + (cls || '') }, tb);
  }

  function basename(p) { return String(p).split(/[\\/]/).pop(); }

  /* ------------------------------------------------------------------ */
  /* model: decoded preview                                               */
  /* ------------------------------------------------------------------ */

  function buildModel(doc) {
    var kind = doc.kind === 'project' ? 'project' : 'pair';
    var result = doc.result || {};
    var files = Array.isArray(doc.files) ? doc.files : [];
    var M = { doc: doc, kind: kind, result: result, files: files, clouds: [], preview: null };
    var pv = doc.preview;
    if (!pv || !Array.isArray(pv.clouds) || pv.clouds.length === 0) return M;
    var offset = Array.isArray(pv.offset_m) ? pv.offset_m.map(Number) : [0, 0, 0];
    while (offset.length < 3) offset.push(0);
    var cap = num(pv.distance_cap_m);
    M.preview = { offset: offset, cap: isFinite(cap) && cap > 0 ? cap : NaN };
    var bbox = [Infinity, Infinity, Infinity, -Infinity, -Infinity, -Infinity];
    pv.clouds.forEach(function (c, i) {
      c = c || {};
      var xyz = decodeF32(c.xyz);
      var n = Math.floor(xyz.length / 3);
      if (xyz.length !== n * 3) xyz = xyz.subarray(0, n * 3);
      var dist = decodeF32(c.distance_m);
      if (dist.length < n) dist = null;
      var kp = decodeF32(c.keypoints_xyz);
      if (kp.length % 3) kp = kp.subarray(0, kp.length - (kp.length % 3));
      var name = c.name || (kind === 'pair' ? (i === 0 ? 'source' : 'target') : basename(files[i] || ('scan ' + i)));
      var color = kind === 'pair' && i < 2 ? PAIR_COLORS[i] : paletteColor(i);
      if (kind === 'project') {
        var sc = (result.scans || [])[i];
        if (sc && sc.file) name = basename(sc.file);
      }
      var b = [Infinity, Infinity, Infinity, -Infinity, -Infinity, -Infinity];
      for (var p = 0; p < xyz.length; p += 3) {
        var x = xyz[p], y = xyz[p + 1], z = xyz[p + 2];
        if (x < b[0]) b[0] = x; if (x > b[3]) b[3] = x;
        if (y < b[1]) b[1] = y; if (y > b[4]) b[4] = y;
        if (z < b[2]) b[2] = z; if (z > b[5]) b[5] = z;
      }
      for (var k = 0; k < 3; k++) { bbox[k] = Math.min(bbox[k], b[k]); bbox[k + 3] = Math.max(bbox[k + 3], b[k + 3]); }
      M.clouds.push({ index: i, name: name, fullPoints: c.points, n: n, xyz: xyz, dist: dist, kp: kp,
        color: color, rgb: hexToRgb(color), visible: n > 0, bbox: b });
    });
    M.preview.bbox = isFinite(bbox[0]) ? bbox : null;
    computeResidualStats(M);
    return M;
  }

  function computeResidualStats(M) {
    var cap = M.preview.cap, capEps = isFinite(cap) ? cap * (1 - 1e-6) : Infinity;
    var total = 0, capped = 0, sample = [], sum2 = 0, inside = 0;
    var all = 0;
    M.clouds.forEach(function (c) { if (c.dist) all += c.n; });
    var stride = Math.max(1, Math.floor(all / 200000));
    M.clouds.forEach(function (c) {
      if (!c.dist) return;
      var d = c.dist, cc = 0;
      for (var i = 0; i < c.n; i++) {
        var v = d[i];
        total++;
        if (!(v < capEps)) { capped++; cc++; continue; }
        inside++; sum2 += v * v;
        if (i % stride === 0) sample.push(v);
      }
      c.capped = cc;
    });
    sample.sort(function (a, b) { return a - b; });
    function q(f) { return sample.length ? sample[Math.min(sample.length - 1, Math.floor(f * sample.length))] : NaN; }
    var p95 = q(0.95);
    var scaleMax = isFinite(p95) && p95 > 0 ? 3 * p95 : (isFinite(cap) ? cap : 1);
    if (isFinite(cap)) scaleMax = Math.min(cap, scaleMax);
    if (!(scaleMax > 0)) scaleMax = isFinite(cap) ? cap : 1;
    M.stats = { total: total, capped: capped, inside: inside, median: q(0.5), p95: p95,
      rms: inside ? Math.sqrt(sum2 / inside) : NaN, scaleMax: scaleMax, capEps: capEps, hasDist: total > 0 };
  }

  /* ------------------------------------------------------------------ */
  /* the view                                                            */
  /* ------------------------------------------------------------------ */

  function renderView(root, doc) {
    var cleanup = [];
    var state = { colorMode: 'scan', pointSize: 2, showKeypoints: false, showBase: false };
    var M = buildModel(doc);
    var R = M.result;
    var api = { ready: false, document: doc, pointsShown: 0, render: function () {}, kind: M.kind };
    var listeners = []; /* called when cloud visibility / colour mode changes */

    root.textContent = '';
    var wrap = el('div', { class: 'result-view' });
    root.appendChild(wrap);

    /* --- header meta --- */
    var meta = document.getElementById('doc-meta');
    if (meta) {
      meta.textContent = '';
      appendAll(meta, [
        el('span', { class: 'doc-title', text: doc.title || '(untitled)' }),
        el('span', { text: (doc.generator || '') + (doc.created ? ' \u00b7 ' + doc.created : '') })
      ]);
    }
    wrap.appendChild(el('h1', { class: 'result-title', text: doc.title || (M.kind === 'pair' ? 'Pair registration' : 'Project registration') }));

    /* --- verdict banner --- */
    wrap.appendChild(M.kind === 'pair' ? pairVerdict() : projectVerdict());

    /* --- summary --- */
    wrap.appendChild(M.kind === 'pair' ? pairSummary() : projectSummary());

    /* --- 3D + slice --- */
    var view3d = build3D();
    wrap.appendChild(view3d.section);
    var slice = buildSlice();
    wrap.appendChild(slice.section);

    /* --- pair: hypotheses / project: graph + tables --- */
    if (M.kind === 'pair') wrap.appendChild(hypothesesSection());
    else { wrap.appendChild(linkGraphSection()); wrap.appendChild(scanTableSection()); }

    /* --- plots --- */
    var plots = el('div', { class: 'grid2' });
    plots.appendChild(histogramSection());
    plots.appendChild(timingsSection());
    wrap.appendChild(plots);

    /* --- transform / poses --- */
    wrap.appendChild(M.kind === 'pair' ? transformSection() : posesSection());

    /* --- parameters / service --- */
    var info = el('div', { class: 'grid2' });
    info.appendChild(parametersSection());
    info.appendChild(serviceSection());
    wrap.appendChild(info);

    /* draw */
    view3d.init();
    slice.draw();
    updatePointsShown();
    api.render = function () { view3d.renderNow(); slice.draw(); };
    api.ready = true;
    window.k4regView = api;

    return {
      destroy: function () {
        cleanup.forEach(function (f) { try { f(); } catch (e) { /* ignore */ } });
        root.textContent = '';
        if (window.k4regView === api) window.k4regView = null;
      },
      api: api
    };

    /* ================================================================ */

    function updatePointsShown() {
      var n = 0;
      M.clouds.forEach(function (c) { if (c.visible) n += c.n; });
      api.pointsShown = view3d.ok ? n : 0;
    }
    function changed() {
      updatePointsShown();
      listeners.forEach(function (f) { f(); });
    }

    function pairVerdict() {
      var amb = truthy(R.ambiguous);
      var nh = Array.isArray(R.hypotheses) ? R.hypotheses.length : 0;
      var v = el('div', { id: 'verdict', class: 'verdict ' + (amb ? 'verdict-warn' : 'verdict-ok'), role: 'status' });
      if (amb) {
        v.appendChild(el('div', { class: 'verdict-head' }, [warnIcon(), 'AMBIGUOUS: ' + (R.ambiguity_reason || 'several hypotheses fit almost equally well')]));
        v.appendChild(el('div', { class: 'verdict-detail', text:
          'The transform below is only one candidate among the ' + nh + ' hypotheses (ambiguity margin ' + prec(R.ambiguity_margin, 3) +
          '). Check the hypotheses table and the slice view before accepting it.' }));
      } else {
        v.appendChild(el('div', { class: 'verdict-head' }, [okIcon(), 'Registered']));
      }
      v.appendChild(el('div', { class: 'verdict-detail' }, [
        'RMSE ', el('b', { text: len(R.rmse_m) }), ' \u00b7 overlap ', el('b', { text: pct(R.overlap) }),
        ' \u00b7 ', intStr(R.inliers), ' inliers',
        (R.icp_converged !== undefined && !truthy(R.icp_converged)) ? el('span', { class: 'warn-text', text: ' \u00b7 ICP did not converge' }) : null
      ]));
      return v;
    }

    function projectVerdict() {
      var scans = Array.isArray(R.scans) ? R.scans : [];
      var nreg = isNum(R.scans_registered) ? num(R.scans_registered) : scans.filter(function (s) { return truthy(s.registered); }).length;
      var all = nreg === scans.length && scans.length > 0;
      var inconsistent = num(R.loops_inconsistent);
      var v = el('div', { id: 'verdict', class: 'verdict ' + (all ? 'verdict-ok' : 'verdict-warn'), role: 'status' });
      v.appendChild(el('div', { class: 'verdict-head' }, [all ? okIcon() : warnIcon(), nreg + ' of ' + scans.length + ' scans registered']));
      v.appendChild(el('div', { class: 'verdict-detail' }, [
        'global RMSE ', el('b', { text: len(R.global_rmse_m) }),
        ' \u00b7 loops checked ', intStr(R.loops_checked),
        isFinite(inconsistent) && inconsistent > 0 ? el('span', { class: 'warn-text', text: ' \u00b7 ' + inconsistent + ' inconsistent' }) : ' \u00b7 0 inconsistent'
      ]));
      var unreg = scans.map(function (s, i) { return [s, i]; }).filter(function (p) { return !truthy(p[0].registered); });
      if (unreg.length) {
        var ul = el('ul', { class: 'unreg-list' });
        unreg.forEach(function (p) {
          ul.appendChild(el('li', null, [el('b', { text: 'Scan ' + p[1] + ' (' + basename(p[0].file || '') + ')' }), ' not registered: ' + (p[0].reason || 'no reason given')]));
        });
        v.appendChild(ul);
      }
      return v;
    }

    function warnIcon() {
      return svg('svg', { class: 'icon', viewBox: '0 0 24 24', width: 22, height: 22, 'aria-hidden': 'true' }, [
        svg('path', { d: 'M12 2 L23 21 H1 Z', fill: 'currentColor' }),
        svg('rect', { x: 11, y: 8, width: 2, height: 7, fill: '#fff' }),
        svg('rect', { x: 11, y: 17, width: 2, height: 2, fill: '#fff' })]);
    }
    function okIcon() {
      return svg('svg', { class: 'icon', viewBox: '0 0 24 24', width: 22, height: 22, 'aria-hidden': 'true' }, [
        svg('circle', { cx: 12, cy: 12, r: 11, fill: 'currentColor' }),
        svg('path', { d: 'M6 12.5 L10.5 17 L18 8', stroke: '#fff', 'stroke-width': 2.5, fill: 'none' })]);
    }

    function metric(label, valueNode, sub) {
      return el('div', { class: 'metric' }, [el('div', { class: 'metric-label', text: label }),
        el('div', { class: 'metric-value' }, valueNode), sub ? el('div', { class: 'metric-sub', text: sub }) : null]);
    }

    function fact(label, value, title) {
      return el('span', { class: 'fact', title: title ? String(title) : null }, [el('span', { class: 'muted', text: label + ' ' }), el('b', { text: value })]);
    }

    function pairSummary() {
      var s = section('Summary', 'summary');
      var g = el('div', { class: 'metrics' });
      g.appendChild(metric('RMSE (m)', el('span', { id: 'rmse', text: prec(R.rmse_m, 6) }), len(R.rmse_m)));
      g.appendChild(metric('Overlap', el('span', { id: 'overlap-value', text: prec(R.overlap, 6) }), pct(R.overlap)));
      g.appendChild(metric('Inliers', intStr(R.inliers)));
      g.appendChild(metric('Points src / tgt', intStr(R.source_points) + ' / ' + intStr(R.target_points)));
      g.appendChild(metric('Keypoints src / tgt', intStr(R.source_keypoints) + ' / ' + intStr(R.target_keypoints)));
      g.appendChild(metric('Hypotheses / bases', (Array.isArray(R.hypotheses) ? R.hypotheses.length : 0) + ' / ' + intStr(R.bases_tried)));
      g.appendChild(metric('Ambiguity margin', prec(R.ambiguity_margin, 3)));
      g.appendChild(metric('ICP', truthy(R.icp_converged) ? 'converged' : 'not converged', intStr(R.icp_iterations) + ' iterations'));
      s.appendChild(g);
      var f = M.files;
      s.appendChild(el('div', { class: 'facts' }, [
        fact('Source (moved)', f[0] !== undefined ? basename(f[0]) : '\u2013', f[0]),
        fact('Target (fixed)', f[1] !== undefined ? basename(f[1]) : '\u2013', f[1]),
        fact('Signal', R.signal || '\u2013'),
        fact('Min. scale used', len(R.min_scale_m_used)),
        fact('Overlap used', prec(R.overlap_used, 3)),
        fact('Seed', R.seed !== undefined ? String(R.seed) : '\u2013')]));
      return s;
    }

    function projectSummary() {
      var s = section('Summary', 'summary');
      var scans = R.scans || [], links = R.links || [];
      var nreg = isNum(R.scans_registered) ? num(R.scans_registered) : scans.filter(function (x) { return truthy(x.registered); }).length;
      var acc = links.filter(function (l) { return truthy(l.accepted); }).length;
      var g = el('div', { class: 'metrics' });
      g.appendChild(metric('Global RMSE (m)', el('span', { id: 'global-rmse', text: prec(R.global_rmse_m, 6) }), len(R.global_rmse_m)));
      g.appendChild(metric('Scans registered', [el('span', { id: 'scans-registered', text: String(nreg) }), ' / ' + scans.length]));
      g.appendChild(metric('Links accepted', acc + ' / ' + links.length));
      g.appendChild(metric('Loops checked', intStr(R.loops_checked), intStr(R.loops_inconsistent) + ' inconsistent'));
      var ref = num(R.reference);
      g.appendChild(metric('Reference scan', isFinite(ref) ? String(ref) : '\u2013', isFinite(ref) && scans[ref] ? basename(scans[ref].file || '') : ''));
      s.appendChild(g);
      return s;
    }

    /* -------------------------------------------------------------- */
    /* cloud toggles (shared by 3D and slice)                          */
    /* -------------------------------------------------------------- */

    function cloudToggles() {
      var box = el('div', { class: 'cloud-toggles' });
      var inputs = [];
      M.clouds.forEach(function (c, i) {
        var cb = el('input', { type: 'checkbox', class: 'cloud-toggle', 'data-cloud': String(i), checked: c.visible, disabled: c.n === 0 });
        cb.addEventListener('change', function () { c.visible = cb.checked; changed(); });
        inputs.push(cb);
        var full = num(c.fullPoints);
        var sub = c.n === 0 ? 'no points' : intStr(c.n) + (isFinite(full) && full !== c.n ? ' of ' + intStr(full) : '') + ' pts';
        box.appendChild(el('label', { class: 'cloud-toggle-label' + (c.n === 0 ? ' disabled' : ''), title: c.name }, [
          cb, el('span', { class: 'swatch', style: { background: c.color } }),
          el('span', { class: 'cloud-name', text: (M.kind === 'project' ? i + ' ' : '') + c.name }),
          el('span', { class: 'cloud-sub', text: sub })]));
      });
      listeners.push(function () { inputs.forEach(function (cb, i) { cb.checked = M.clouds[i].visible; }); });
      return box;
    }

    /* -------------------------------------------------------------- */
    /* 3D view                                                          */
    /* -------------------------------------------------------------- */

    function build3D() {
      var sec = section('3D view', 'section-3d');
      var out = { section: sec, ok: false, init: function () {}, renderNow: function () {} };
      if (!M.preview || M.clouds.length === 0 || !M.preview.bbox) {
        sec.appendChild(el('p', { class: 'notice', text: 'This document has no point preview, so the 3D and slice views are not available. All other results are shown below.' }));
        return out;
      }
      var layout = el('div', { class: 'view3d-layout' });
      var side = el('div', { class: 'view-side' });
      var stage = el('div', { class: 'view3d-stage' });
      var canvas = el('canvas', { id: 'view3d', tabIndex: 0 });
      stage.appendChild(canvas);
      stage.appendChild(el('div', { class: 'view-hint', text: 'drag: rotate \u00b7 right-drag / shift-drag: pan \u00b7 wheel: zoom' }));
      layout.appendChild(stage);
      layout.appendChild(side);
      sec.appendChild(layout);

      side.appendChild(el('h3', { text: 'Clouds' }));
      side.appendChild(cloudToggles());

      var modeSel = el('select', { id: 'color-mode' }, [
        el('option', { value: 'scan', text: 'per scan' }),
        el('option', { value: 'distance', text: 'by residual distance', disabled: !M.stats.hasDist })]);
      side.appendChild(el('label', { class: 'ctl' }, [el('span', { text: 'Colouring' }), modeSel]));
      var legend = el('div', { class: 'legend' });
      side.appendChild(legend);

      var sizeIn = el('input', { type: 'range', id: 'point-size', min: 1, max: 8, step: 0.5, value: state.pointSize });
      var sizeVal = el('span', { class: 'ctl-val', text: state.pointSize + ' px' });
      side.appendChild(el('label', { class: 'ctl' }, [el('span', { text: 'Point size' }), sizeIn, sizeVal]));

      var upSel = el('select', { id: 'up-axis' }, [el('option', { value: 'z', text: 'Z up' }), el('option', { value: 'y', text: 'Y up' })]);
      side.appendChild(el('label', { class: 'ctl' }, [el('span', { text: 'Up axis' }), upSel]));

      var kpCb = null, baseCb = null;
      var base = M.kind === 'pair' ? baseQuads() : null;
      var hasKp = M.clouds.some(function (c) { return c.kp.length >= 3; });
      if (M.kind === 'pair') {
        kpCb = el('input', { type: 'checkbox', id: 'show-keypoints', disabled: !hasKp });
        side.appendChild(el('label', { class: 'ctl-check' + (hasKp ? '' : ' disabled') }, [kpCb, ' keypoints' + (hasKp ? '' : ' (not in document)')]));
        baseCb = el('input', { type: 'checkbox', id: 'show-base', disabled: !base });
        side.appendChild(el('label', { class: 'ctl-check' + (base ? '' : ' disabled') }, [baseCb, ' matched 4-point base' + (base ? '' : ' (not in document)')]));
        if (base) {
          side.appendChild(el('div', { class: 'legend small' }, [
            el('div', { class: 'legend-row' }, [el('span', { class: 'swatch', style: { background: '#ff2bd6' } }), 'base points on target']),
            el('div', { class: 'legend-row' }, [el('span', { class: 'swatch', style: { background: '#b6ff1c' } }), 'base points on source (moved)'])]));
        }
      }
      var resetBtn = el('button', { type: 'button', id: 'reset-view', class: 'btn', text: 'Reset view' });
      side.appendChild(el('div', { class: 'ctl' }, resetBtn));
      var off = M.preview.offset;
      side.appendChild(el('p', { class: 'small muted', text: 'Coordinates relative to offset (' + off.map(function (v) { return fixed(v, 3); }).join(', ') + ') m of the ' + (M.kind === 'pair' ? 'target' : 'project') + ' frame.' }));

      function drawLegend() {
        legend.textContent = '';
        if (state.colorMode === 'distance') {
          var mx = M.stats.scaleMax;
          legend.appendChild(el('div', { class: 'legend-title', text: 'Residual distance to the other cloud' + (M.kind === 'project' ? 's' : '') }));
          legend.appendChild(el('div', { class: 'ramp', style: { background: rampGradientCss() } }));
          legend.appendChild(el('div', { class: 'ramp-labels' }, [el('span', { text: '0' }), el('span', { text: len(mx / 2) }), el('span', { text: '\u2265 ' + len(mx) })]));
          legend.appendChild(el('div', { class: 'legend-row' }, [el('span', { class: 'swatch', style: { background: CAPPED_COLOR } }),
            'outside overlap (no neighbour within ' + len(M.preview.cap) + '): ' + intStr(M.stats.capped) + ' pts']));
        } else {
          legend.appendChild(el('div', { class: 'legend-title muted', text: 'Colour per ' + (M.kind === 'pair' ? 'cloud' : 'scan') + ' (see swatches above)' }));
        }
      }
      drawLegend();

      out.init = function () {
        var reason = webglUnavailableReason();
        if (reason) { fail(reason); return; }
        var renderer;
        try {
          renderer = new THREE.WebGLRenderer({ canvas: canvas, antialias: false, preserveDrawingBuffer: true });
        } catch (e) { fail('WebGL could not be initialised (' + (e && e.message ? e.message : e) + ').'); return; }
        out.ok = true;
        renderer.setPixelRatio(window.devicePixelRatio || 1);
        renderer.setClearColor(0x1d2127, 1);
        var scene = new THREE.Scene();
        var bb = M.preview.bbox;
        var center = new THREE.Vector3((bb[0] + bb[3]) / 2, (bb[1] + bb[4]) / 2, (bb[2] + bb[5]) / 2);
        var radius = 0.5 * Math.sqrt(Math.pow(bb[3] - bb[0], 2) + Math.pow(bb[4] - bb[1], 2) + Math.pow(bb[5] - bb[2], 2)) || 1;
        var camera = new THREE.PerspectiveCamera(45, 1, radius / 1000, radius * 100);
        var controls = new THREE.OrbitControls(camera, canvas);
        controls.screenSpacePanning = true;
        controls.enableDamping = false;
        controls.enableKeys = false;

        var VC = THREE.VertexColors !== undefined ? THREE.VertexColors : true;
        var NC = THREE.NoColors !== undefined ? THREE.NoColors : false;
        var pointObjs = [], kpObjs = [];
        M.clouds.forEach(function (c) {
          var geom = new THREE.BufferGeometry();
          setAttr(geom, 'position', new THREE.BufferAttribute(c.xyz, 3));
          var mat = new THREE.PointsMaterial({ size: state.pointSize, sizeAttenuation: false, color: new THREE.Color(c.color), vertexColors: NC });
          var pts = new THREE.Points(geom, mat);
          pts.frustumCulled = false;
          pts.visible = c.visible;
          scene.add(pts);
          pointObjs.push(pts);
          if (c.kp.length >= 3) {
            var kg = new THREE.BufferGeometry();
            setAttr(kg, 'position', new THREE.BufferAttribute(c.kp, 3));
            var kcol = new THREE.Color(c.color).lerp(new THREE.Color(0xffffff), 0.55);
            var km = new THREE.PointsMaterial({ size: 7, sizeAttenuation: false, color: kcol, depthTest: false });
            var ko = new THREE.Points(kg, km);
            ko.renderOrder = 5; ko.visible = false; ko.frustumCulled = false;
            scene.add(ko);
            kpObjs.push([ko, c]);
          }
        });
        var baseGroup = null;
        if (base) {
          baseGroup = new THREE.Group();
          [[base.target, 0xff2bd6], [base.source, 0xb6ff1c]].forEach(function (q) {
            var arr = new Float32Array(q[0]);
            var g1 = new THREE.BufferGeometry(); setAttr(g1, 'position', new THREE.BufferAttribute(arr, 3));
            var loop = new THREE.LineLoop(g1, new THREE.LineBasicMaterial({ color: q[1], depthTest: false }));
            var g2 = new THREE.BufferGeometry(); setAttr(g2, 'position', new THREE.BufferAttribute(arr, 3));
            var mk = new THREE.Points(g2, new THREE.PointsMaterial({ size: 13, sizeAttenuation: false, color: q[1], depthTest: false }));
            loop.renderOrder = 10; mk.renderOrder = 11;
            baseGroup.add(loop); baseGroup.add(mk);
          });
          var links = new Float32Array(24);
          for (var k = 0; k < 4; k++) {
            for (var d = 0; d < 3; d++) { links[k * 6 + d] = base.target[k * 3 + d]; links[k * 6 + 3 + d] = base.source[k * 3 + d]; }
          }
          var g3 = new THREE.BufferGeometry(); setAttr(g3, 'position', new THREE.BufferAttribute(links, 3));
          var ls = new THREE.LineSegments(g3, new THREE.LineBasicMaterial({ color: 0xffffff, depthTest: false }));
          ls.renderOrder = 10;
          baseGroup.add(ls);
          baseGroup.visible = false;
          scene.add(baseGroup);
        }

        var pending = false;
        function renderNow() {
          pending = false;
          renderer.render(scene, camera);
        }
        function requestRender() {
          if (pending) return;
          pending = true;
          requestAnimationFrame(renderNow);
        }
        out.renderNow = renderNow;

        function resize() {
          var w = Math.max(200, stage.clientWidth), h = Math.max(300, Math.round(Math.min(560, w * 0.6)));
          renderer.setSize(w, h, false);
          canvas.style.width = w + 'px';
          canvas.style.height = h + 'px';
          camera.aspect = w / h;
          camera.updateProjectionMatrix();
        }
        function resetView() {
          var up = upSel.value === 'y' ? new THREE.Vector3(0, 1, 0) : new THREE.Vector3(0, 0, 1);
          camera.up.copy(up);
          var dir = upSel.value === 'y' ? new THREE.Vector3(0.6, 0.55, 1.0) : new THREE.Vector3(0.75, -1.0, 0.65);
          dir.normalize();
          var dist = radius / Math.sin((camera.fov / 2) * Math.PI / 180) * 0.9;
          camera.position.copy(center).addScaledVector(dir, dist);
          camera.near = radius / 1000; camera.far = radius * 100;
          camera.updateProjectionMatrix();
          controls.target.copy(center);
          controls.update();
        }

        function applyColors() {
          M.clouds.forEach(function (c, i) {
            var mat = pointObjs[i].material, geom = pointObjs[i].geometry;
            if (state.colorMode === 'distance' && c.dist) {
              if (!geom.getAttribute('color')) setAttr(geom, 'color', new THREE.BufferAttribute(distanceColors(c), 3));
              mat.vertexColors = VC;
              mat.color.set(0xffffff);
            } else {
              mat.vertexColors = NC;
              mat.color.set(c.color);
            }
            mat.needsUpdate = true;
          });
        }
        function applyVisibility() {
          M.clouds.forEach(function (c, i) { pointObjs[i].visible = c.visible; });
          kpObjs.forEach(function (p) { p[0].visible = state.showKeypoints && p[1].visible; });
          if (baseGroup) baseGroup.visible = state.showBase;
        }

        controls.addEventListener('change', requestRender);
        modeSel.addEventListener('change', function () { state.colorMode = modeSel.value; applyColors(); drawLegend(); renderNow(); });
        sizeIn.addEventListener('input', function () {
          state.pointSize = Number(sizeIn.value);
          sizeVal.textContent = state.pointSize + ' px';
          pointObjs.forEach(function (p) { p.material.size = state.pointSize; });
          requestRender();
        });
        upSel.addEventListener('change', function () { resetView(); renderNow(); });
        resetBtn.addEventListener('click', function () { resetView(); renderNow(); });
        if (kpCb) kpCb.addEventListener('change', function () { state.showKeypoints = kpCb.checked; applyVisibility(); renderNow(); });
        if (baseCb) baseCb.addEventListener('change', function () { state.showBase = baseCb.checked; applyVisibility(); renderNow(); });
        listeners.push(function () { applyVisibility(); renderNow(); });
        var onResize = function () { resize(); renderNow(); };
        window.addEventListener('resize', onResize);
        cleanup.push(function () {
          window.removeEventListener('resize', onResize);
          controls.dispose();
          scene.traverse(function (o) { if (o.geometry) o.geometry.dispose(); if (o.material) o.material.dispose(); });
          renderer.dispose();
          if (renderer.forceContextLoss) renderer.forceContextLoss();
        });

        resize();
        resetView();
        applyColors();
        applyVisibility();
        renderNow();

        function fail(msg) {
          out.ok = false;
          stage.textContent = '';
          stage.appendChild(el('p', { class: 'notice', text: msg + ' The slice view and all other results are still shown.' }));
        }
      };
      return out;
    }

    function setAttr(geom, name, attr) {
      if (geom.setAttribute) geom.setAttribute(name, attr); else geom.addAttribute(name, attr);
    }

    function webglUnavailableReason() {
      if (typeof THREE === 'undefined' || !THREE.WebGLRenderer) return 'The 3D library is not available in this page.';
      if (!THREE.OrbitControls) return 'The 3D orbit controls are not available in this page.';
      try {
        var c = document.createElement('canvas');
        var gl = c.getContext('webgl') || c.getContext('experimental-webgl');
        if (!gl) return 'WebGL is not available in this browser, so the 3D view cannot be shown.';
        var lose = gl.getExtension('WEBGL_lose_context');
        if (lose) lose.loseContext();
      } catch (e) {
        return 'WebGL is not available in this browser, so the 3D view cannot be shown.';
      }
      return '';
    }

    function distanceColors(c) {
      var n = c.n, d = c.dist, out = new Float32Array(n * 3);
      var capEps = M.stats.capEps, inv = 255 / M.stats.scaleMax;
      var g = hexToRgb(CAPPED_COLOR).map(function (v) { return v / 255; });
      for (var i = 0; i < n; i++) {
        var v = d[i], o = i * 3;
        if (!(v < capEps)) { out[o] = g[0]; out[o + 1] = g[1]; out[o + 2] = g[2]; continue; }
        var k = Math.round(v * inv); if (k > 255) k = 255; else if (k < 0) k = 0;
        k *= 3;
        out[o] = RAMP_LUT[k]; out[o + 1] = RAMP_LUT[k + 1]; out[o + 2] = RAMP_LUT[k + 2];
      }
      return out;
    }

    /* The chosen 4-point base of the best hypothesis, in preview coords. */
    function baseQuads() {
      var h = (R.hypotheses || [])[0];
      var T = mat4(R.transform);
      if (!h || !T || !M.preview) return null;
      var bs = Array.isArray(h.base_source_m) ? h.base_source_m.map(Number) : [];
      var bt = Array.isArray(h.base_target_m) ? h.base_target_m.map(Number) : [];
      if (bs.length !== 12 || bt.length !== 12) return null;
      if (!bs.concat(bt).every(isFinite)) return null;
      var o = M.preview.offset, src = [], tgt = [];
      for (var k = 0; k < 4; k++) {
        var p = applyT(T, bs[k * 3], bs[k * 3 + 1], bs[k * 3 + 2]);
        for (var d = 0; d < 3; d++) { src.push(p[d] - o[d]); tgt.push(bt[k * 3 + d] - o[d]); }
      }
      return { source: src, target: tgt };
    }

    /* -------------------------------------------------------------- */
    /* top view / horizontal slice (2D canvas)                          */
    /* -------------------------------------------------------------- */

    function buildSlice() {
      var sec = section('Top view and horizontal slice', 'section-slice');
      var out = { section: sec, draw: function () {} };
      if (!M.preview || !M.preview.bbox) {
        sec.appendChild(el('p', { class: 'notice', text: 'No point preview in this document: top view and slices are not available.' }));
        return out;
      }
      var bb = M.preview.bbox, off = M.preview.offset;
      var zr = Math.max(bb[5] - bb[2], 1e-6);
      var st = { mode: 'top', z: (bb[2] + bb[5]) / 2, thick: niceFloor(zr / 40), view: null };
      var layout = el('div', { class: 'view3d-layout' });
      var stage = el('div', { class: 'slice-stage' });
      var canvas = el('canvas', { id: 'slice' });
      stage.appendChild(canvas);
      stage.appendChild(el('div', { class: 'view-hint', text: 'drag: pan \u00b7 wheel: zoom \u00b7 double-click: fit' }));
      var side = el('div', { class: 'view-side' });
      layout.appendChild(stage); layout.appendChild(side);
      sec.appendChild(layout);

      var modeTop = el('input', { type: 'radio', name: 'slice-mode', value: 'top', id: 'slice-mode-top', checked: true });
      var modeSlice = el('input', { type: 'radio', name: 'slice-mode', value: 'slice', id: 'slice-mode-slice' });
      side.appendChild(el('div', { class: 'seg' }, [el('label', null, [modeTop, ' top view (all heights)']), el('label', null, [modeSlice, ' slice'])]));
      var zIn = el('input', { type: 'range', id: 'slice-z', min: bb[2], max: bb[5], step: zr / 1000, value: st.z });
      var zVal = el('span', { class: 'ctl-val' });
      side.appendChild(el('label', { class: 'ctl' }, [el('span', { text: 'Slice height z' }), zIn, zVal]));
      var tIn = el('input', { type: 'number', id: 'slice-thickness', min: 0, step: niceFloor(zr / 200), value: st.thick });
      side.appendChild(el('label', { class: 'ctl' }, [el('span', { text: 'Thickness (m)' }), tIn]));
      var countOut = el('p', { class: 'small muted' });
      side.appendChild(countOut);
      var swatches = el('div', { class: 'legend' });
      M.clouds.forEach(function (c, i) {
        swatches.appendChild(el('div', { class: 'legend-row' }, [el('span', { class: 'swatch', style: { background: c.color } }), (M.kind === 'project' ? i + ' ' : '') + c.name]));
      });
      side.appendChild(swatches);
      side.appendChild(el('p', { class: 'small muted', text: 'Visibility follows the cloud checkboxes of the 3D view. In a slice, a misalignment shows as a doubled wall.' }));

      function updateLabels() {
        zVal.textContent = 'z = ' + (st.z + off[2]).toFixed(3) + ' m';
        zIn.disabled = tIn.disabled = st.mode !== 'slice';
      }

      function fit(W, H) {
        var w = Math.max(bb[3] - bb[0], 1e-6), h = Math.max(bb[4] - bb[1], 1e-6);
        var s = Math.min((W - 40) / w, (H - 40) / h);
        st.view = { cx: (bb[0] + bb[3]) / 2, cy: (bb[1] + bb[4]) / 2, s: s };
      }

      var W = 0, H = 0, dpr = 1;
      function draw() {
        var cssW = Math.max(200, stage.clientWidth), cssH = Math.max(300, Math.round(Math.min(560, cssW * 0.6)));
        dpr = window.devicePixelRatio || 1;
        var nW = Math.round(cssW * dpr), nH = Math.round(cssH * dpr);
        if (nW !== W || nH !== H) {
          var old = st.view ? { s: st.view.s / (W || nW) } : null;
          W = canvas.width = nW; H = canvas.height = nH;
          canvas.style.width = cssW + 'px'; canvas.style.height = cssH + 'px';
          if (!st.view) fit(W, H); else st.view.s = old.s * W;
        }
        var ctx = canvas.getContext('2d');
        var img = ctx.createImageData(W, H);
        var px = new Uint32Array(img.data.buffer);
        var bg = LITTLE_ENDIAN ? 0xff2a2521 : 0x21252aff;
        px.fill(bg);
        var v = st.view, s = v.s, ox = W / 2 - v.cx * s, oy = H / 2 + v.cy * s;
        var zlo = st.z - st.thick / 2, zhi = st.z + st.thick / 2, isSlice = st.mode === 'slice';
        var dot = dpr >= 1.5 ? 2 : 1;
        var shown = 0;
        M.clouds.forEach(function (c) {
          if (!c.visible) return;
          var rgb = c.rgb;
          var col = LITTLE_ENDIAN ? ((255 << 24) | (rgb[2] << 16) | (rgb[1] << 8) | rgb[0]) >>> 0 : ((rgb[0] << 24) | (rgb[1] << 16) | (rgb[2] << 8) | 255) >>> 0;
          var a = c.xyz, n3 = c.n * 3;
          for (var p = 0; p < n3; p += 3) {
            if (isSlice) { var z = a[p + 2]; if (z < zlo || z > zhi) continue; }
            var X = (a[p] * s + ox) | 0, Y = (oy - a[p + 1] * s) | 0;
            if (X < 0 || Y < 0 || X >= W - 1 || Y >= H - 1) continue;
            var o = Y * W + X;
            px[o] = col;
            if (dot === 2) { px[o + 1] = col; px[o + W] = col; px[o + W + 1] = col; }
            shown++;
          }
        });
        ctx.putImageData(img, 0, 0);
        drawOverlay(ctx, s);
        countOut.textContent = intStr(shown) + ' points drawn' + (isSlice ? ' in slice ' + (zlo + off[2]).toFixed(3) + ' \u2026 ' + (zhi + off[2]).toFixed(3) + ' m' : ' (all heights)');
      }

      function drawOverlay(ctx, s) {
        ctx.save();
        ctx.scale(dpr, dpr);
        var w = W / dpr, h = H / dpr;
        /* metric scale bar */
        var target = 120 / s * dpr, L = niceFloor(target), bw = L * s / dpr;
        var x0 = 16, y0 = h - 20;
        ctx.fillStyle = 'rgba(0,0,0,0.45)';
        ctx.fillRect(x0 - 8, y0 - 22, bw + 16 + 70, 32);
        ctx.strokeStyle = '#fff'; ctx.lineWidth = 2;
        ctx.beginPath(); ctx.moveTo(x0, y0 - 5); ctx.lineTo(x0, y0); ctx.lineTo(x0 + bw, y0); ctx.lineTo(x0 + bw, y0 - 5); ctx.stroke();
        ctx.fillStyle = '#fff'; ctx.font = '12px system-ui, sans-serif';
        ctx.fillText(len(L), x0 + bw + 8, y0 + 1);
        /* axes */
        var ax = w - 40, ay = h - 18;
        ctx.beginPath(); ctx.moveTo(ax, ay); ctx.lineTo(ax + 24, ay); ctx.moveTo(ax, ay); ctx.lineTo(ax, ay - 24); ctx.stroke();
        ctx.fillText('x', ax + 26, ay + 4); ctx.fillText('y', ax - 3, ay - 28);
        ctx.fillText(st.mode === 'slice' ? 'slice z = ' + (st.z + off[2]).toFixed(3) + ' m \u00b1 ' + len(st.thick / 2) : 'top view, all heights', 12, 18);
        ctx.restore();
      }

      var raf = 0;
      function schedule() { if (!raf) raf = requestAnimationFrame(function () { raf = 0; draw(); }); }
      function setMode() { st.mode = modeSlice.checked ? 'slice' : 'top'; updateLabels(); draw(); }
      modeTop.addEventListener('change', setMode);
      modeSlice.addEventListener('change', setMode);
      zIn.addEventListener('input', function () { st.z = Number(zIn.value); updateLabels(); schedule(); });
      tIn.addEventListener('input', function () { var t = Number(tIn.value); if (t > 0) { st.thick = t; schedule(); } });
      canvas.addEventListener('wheel', function (e) {
        e.preventDefault();
        var r = canvas.getBoundingClientRect(), mx = (e.clientX - r.left) * dpr, my = (e.clientY - r.top) * dpr;
        var v = st.view, f = Math.exp(-e.deltaY * 0.0015);
        var wx = v.cx + (mx - W / 2) / v.s, wy = v.cy - (my - H / 2) / v.s;
        v.s *= f;
        v.cx = wx - (mx - W / 2) / v.s; v.cy = wy + (my - H / 2) / v.s;
        schedule();
      }, { passive: false });
      var drag = null;
      canvas.addEventListener('mousedown', function (e) { drag = { x: e.clientX, y: e.clientY }; e.preventDefault(); });
      var onMove = function (e) {
        if (!drag) return;
        st.view.cx -= (e.clientX - drag.x) * dpr / st.view.s;
        st.view.cy += (e.clientY - drag.y) * dpr / st.view.s;
        drag = { x: e.clientX, y: e.clientY };
        schedule();
      };
      var onUp = function () { drag = null; };
      window.addEventListener('mousemove', onMove);
      window.addEventListener('mouseup', onUp);
      canvas.addEventListener('dblclick', function () { fit(W, H); draw(); });
      var onResize = function () { draw(); };
      window.addEventListener('resize', onResize);
      cleanup.push(function () {
        window.removeEventListener('mousemove', onMove);
        window.removeEventListener('mouseup', onUp);
        window.removeEventListener('resize', onResize);
      });
      listeners.push(draw);
      updateLabels();
      out.draw = draw;
      return out;
    }

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

    function colorOfScan(i) {
      var c = M.clouds[i];
      return c ? c.color : paletteColor(i);
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

    /* -------------------------------------------------------------- */
    /* transform / poses / parameters / service                         */
    /* -------------------------------------------------------------- */

    function matrixBlock(m, raw, attrs) {
      var text = matrixText(raw);
      var pre = el('pre', Object.assign({ class: 'matrix', text: text }, attrs || {}));
      var btn = el('button', { type: 'button', class: 'btn btn-small copy-btn', text: 'Copy' });
      btn.addEventListener('click', function () { copyText(pre.textContent, btn); });
      var ax = rotAxis(m), ang = rotAngleDeg(m), t = Math.sqrt(m[3] * m[3] + m[7] * m[7] + m[11] * m[11]);
      var desc = 'rotation ' + ang.toFixed(3) + '\u00b0' + (ax ? ' about (' + ax.map(function (v) { return v.toFixed(3); }).join(', ') + ')' : '') +
        ', translation (' + [m[3], m[7], m[11]].map(function (v) { return v.toFixed(4); }).join(', ') + ') m, |t| = ' + len(t);
      return el('div', { class: 'matrix-block' }, [el('div', { class: 'matrix-row' }, [pre, btn]), el('div', { class: 'small muted', text: desc })]);
    }

    function transformSection() {
      var s = section('Transform (source \u2192 target)', 'section-transform');
      var T = mat4(R.transform);
      if (!T) { s.appendChild(el('p', { class: 'notice', text: 'No transform in this result.' })); s.appendChild(el('pre', { id: 'transform' })); return s; }
      s.appendChild(el('p', { class: 'small muted', text: 'Row-major 4\u00d74, p_target = T \u00b7 p_source (metres).' }));
      s.appendChild(matrixBlock(T, R.transform, { id: 'transform' }));
      return s;
    }

    function posesSection() {
      var s = section('Poses (scan \u2192 project frame)', 'section-poses');
      s.appendChild(el('p', { class: 'small muted', text: 'Row-major 4\u00d74 per registered scan, p_project = P \u00b7 p_scan (metres).' }));
      var box = el('div', { id: 'poses', class: 'poses' });
      (R.scans || []).forEach(function (sc, i) {
        var P = mat4(sc.pose);
        if (!P || !truthy(sc.registered !== undefined ? sc.registered : true)) return;
        box.appendChild(el('div', { class: 'pose-item' }, [el('h3', null, [el('span', { class: 'swatch', style: { background: colorOfScan(i) } }), 'Scan ' + i + ': ' + (sc.file || '')]),
          matrixBlock(P, sc.pose, { class: 'matrix pose', 'data-scan': String(i) })]));
      });
      /* scans held too weakly: not registered, both placements the evidence leaves open */
      (R.scans || []).forEach(function (sc, i) {
        if (!truthy(sc.ambiguous) || !Array.isArray(sc.candidate_poses)) return;
        sc.candidate_poses.forEach(function (c, k) {
          var values = c && c.pose, C = mat4(values);
          if (!C) return;
          box.appendChild(el('div', { class: 'pose-item candidate' }, [el('h3', null, [el('span', { class: 'swatch', style: { background: colorOfScan(i) } }),
            'Scan ' + i + ': ' + (sc.file || '') + ' – NOT registered, ambiguous: ' + (k === 0 ? 'placement its links prefer' : 'twin placement')]),
            matrixBlock(C, values, { class: 'matrix candidate-pose', 'data-scan': String(i), 'data-candidate': String(k) })]));
        });
      });
      if (!box.children.length) box.appendChild(el('p', { class: 'muted', text: 'No registered scans.' }));
      s.appendChild(box);
      return s;
    }

    function valueText(v) {
      if (v === null || v === undefined) return '\u2013';
      if (typeof v === 'object') return JSON.stringify(v);
      return String(v);
    }

    function parametersSection() {
      var s = section('Parameters', 'section-parameters');
      var p = doc.parameters;
      var rows = [];
      if (p && typeof p === 'object') Object.keys(p).forEach(function (k) { rows.push([k, valueText(p[k])]); });
      if (!rows.length) s.appendChild(el('p', { class: 'muted', text: 'No parameters recorded.' }));
      else s.appendChild(kvTable(rows, 'params'));
      var files = M.files;
      if (files.length) {
        s.appendChild(el('h3', { text: 'Files' }));
        s.appendChild(el('ol', { class: 'files', start: M.kind === 'project' ? 0 : 1 }, files.map(function (f, i) {
          return el('li', { text: String(f) + (M.kind === 'pair' ? (i === 0 ? ' (source)' : i === 1 ? ' (target)' : '') : '') });
        })));
      }
      return s;
    }

    function serviceSection() {
      var s = section('Document and service', 'section-service');
      var sv = doc.service || null;
      var rows = [['Generator', doc.generator || '\u2013'], ['Created', doc.created || '\u2013'], ['Kind', M.kind]];
      if (sv) {
        rows.push(['Request id', sv.request_id || '\u2013', 'request-id']);
        var srv = sv.server || {};
        rows.push(['Server id', srv.server_id || '\u2013']);
        rows.push(['Server version', srv.version || '\u2013']);
        if (sv.timings && typeof sv.timings === 'object') {
          Object.keys(sv.timings).forEach(function (k) { rows.push(['Server ' + k, secs(typeof sv.timings[k] === 'object' && sv.timings[k] ? sv.timings[k].seconds : sv.timings[k])]); });
        }
      }
      s.appendChild(kvTable(rows, 'compact'));
      if (!sv) s.appendChild(el('p', { class: 'small muted', text: 'No service information (document written by the command-line tool).' }));
      return s;
    }
  }

  K4reg.renderView = renderView;
  K4reg.util = { el: el, num: num, mat4: mat4, matrixText: matrixText, copyText: copyText, decodeF32: decodeF32, basename: basename, len: len, secs: secs };
})();
