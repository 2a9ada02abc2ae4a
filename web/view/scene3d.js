/* The 3D view of the point preview (three.js r111 and its OrbitControls, the global THREE): colouring per
 * scan or by residual distance, point size, up axis, keypoints and the matched 4-point base (pair); and the
 * cloud checkboxes that the 3D and the slice views share. Without WebGL it says so and the page goes on.
 */
(function () {
  'use strict';

  var view = window.K4reg.view;
  var el = view.el, num = view.num, fixed = view.fixed, intStr = view.intStr, len = view.len, mat4 = view.mat4,
    applyT = view.applyT, section = view.section, hexToRgb = view.hexToRgb, CAPPED_COLOR = view.CAPPED_COLOR,
    RAMP_LUT = view.RAMP_LUT, rampGradientCss = view.rampGradientCss;

  /* ctx: what renderView's panels share (render_view.js). */
  view.scene3d = function (ctx) {
    var M = ctx.M, R = ctx.R, state = ctx.state, cleanup = ctx.cleanup, listeners = ctx.listeners,
      changed = ctx.changed;

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

    return { build3D: build3D };
  };
})();
