/* Small helpers every part of the result view uses: DOM and SVG elements, cards and key/value tables,
 * numbers from the document (numbers or strings) as text, 4x4 row-major rigid transforms, axis steps and the
 * clipboard. Plain ES2017; what it exports goes on window.K4reg.view, which the other view/ files read.
 */
(function () {
  'use strict';

  var K4reg = window.K4reg = window.K4reg || {};
  var view = K4reg.view = K4reg.view || {};
  var SVGNS = ['http', '//www.w3.org/2000/svg'].join(':'); /* written so that no URL literal appears in the page */

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

  Object.assign(view, {
    el: el, svg: svg, appendAll: appendAll, num: num, isNum: isNum, prec: prec, fixed: fixed, intStr: intStr,
    pct: pct, yesno: yesno, truthy: truthy, len: len, secs: secs, mat4: mat4, matMul: matMul,
    rigidInverse: rigidInverse, rotAngleDeg: rotAngleDeg, rotAxis: rotAxis, applyT: applyT, niceStep: niceStep,
    niceFloor: niceFloor, copyText: copyText, matrixText: matrixText, section: section, kvTable: kvTable,
    basename: basename
  });
})();
