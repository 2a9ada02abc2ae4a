/* The document's point preview decoded for drawing: each cloud's points, residual distances and keypoints
 * (base64 float32), its colour and bounding box, and the residual statistics the histogram and the distance
 * colouring share; with the scan palette and the residual colour ramp.
 */
(function () {
  'use strict';

  var view = window.K4reg.view;
  var num = view.num, basename = view.basename;

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

  Object.assign(view, {
    LITTLE_ENDIAN: LITTLE_ENDIAN, decodeF32: decodeF32, hexToRgb: hexToRgb, paletteColor: paletteColor,
    CAPPED_COLOR: CAPPED_COLOR, RAMP_LUT: RAMP_LUT, rampCss: rampCss, rampGradientCss: rampGradientCss,
    buildModel: buildModel
  });
})();
