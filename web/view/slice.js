/* The top view and horizontal slice of the point preview, drawn point by point on a 2D canvas with pan, zoom,
 * a metric scale bar and the slice height and thickness; a misalignment shows as a doubled wall.
 */
(function () {
  'use strict';

  var view = window.K4reg.view;
  var el = view.el, intStr = view.intStr, len = view.len, niceFloor = view.niceFloor, section = view.section,
    LITTLE_ENDIAN = view.LITTLE_ENDIAN;

  /* ctx: what renderView's panels share (render_view.js). */
  view.slice = function (ctx) {
    var M = ctx.M, cleanup = ctx.cleanup, listeners = ctx.listeners;

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

    return { buildSlice: buildSlice };
  };
})();
