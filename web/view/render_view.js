/* k4reg result view: renders one registration result document (pair or
 * project) as an interactive QA page from the panels of the other view/ files
 * (loaded before this one). Plain ES2017, no dependencies except the global
 * THREE (three.js r111 + OrbitControls) for the 3D panel.
 *
 * API: K4reg.renderView(rootElement, doc) -> {destroy()}
 * Sets window.k4regView = {ready, document, pointsShown, render()} once the
 * view (and its first 3D frame, if any) is drawn.
 */
(function () {
  'use strict';

  var K4reg = window.K4reg;
  var view = K4reg.view;
  var el = view.el, appendAll = view.appendAll, num = view.num, len = view.len, secs = view.secs, mat4 = view.mat4,
    matrixText = view.matrixText, copyText = view.copyText, basename = view.basename, decodeF32 = view.decodeF32,
    paletteColor = view.paletteColor, buildModel = view.buildModel;

  function renderView(root, doc) {
    var cleanup = [];
    var state = { colorMode: 'scan', pointSize: 2, showKeypoints: false, showBase: false };
    var M = buildModel(doc);
    var R = M.result;
    var api = { ready: false, document: doc, pointsShown: 0, render: function () {}, kind: M.kind };
    var listeners = []; /* called when cloud visibility / colour mode changes */
    var ctx = { doc: doc, M: M, R: R, state: state, cleanup: cleanup, listeners: listeners, changed: changed,
      colorOfScan: colorOfScan };
    var cards = view.cards(ctx), tables = view.tables(ctx), charts = view.charts(ctx);

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
    wrap.appendChild(M.kind === 'pair' ? cards.pairVerdict() : cards.projectVerdict());

    /* --- summary --- */
    wrap.appendChild(M.kind === 'pair' ? cards.pairSummary() : cards.projectSummary());

    /* --- 3D + slice --- */
    var view3d = view.scene3d(ctx).build3D();
    wrap.appendChild(view3d.section);
    var slice = view.slice(ctx).buildSlice();
    wrap.appendChild(slice.section);

    /* --- pair: hypotheses / project: graph + tables --- */
    if (M.kind === 'pair') wrap.appendChild(tables.hypothesesSection());
    else { wrap.appendChild(tables.linkGraphSection()); wrap.appendChild(tables.scanTableSection()); }

    /* --- plots --- */
    var plots = el('div', { class: 'grid2' });
    plots.appendChild(charts.histogramSection());
    plots.appendChild(charts.timingsSection());
    wrap.appendChild(plots);

    /* --- transform / poses --- */
    wrap.appendChild(M.kind === 'pair' ? cards.transformSection() : cards.posesSection());

    /* --- parameters / service --- */
    var info = el('div', { class: 'grid2' });
    info.appendChild(cards.parametersSection());
    info.appendChild(cards.serviceSection());
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

    function colorOfScan(i) {
      var c = M.clouds[i];
      return c ? c.color : paletteColor(i);
    }
  }

  K4reg.renderView = renderView;
  K4reg.util = { el: el, num: num, mat4: mat4, matrixText: matrixText, copyText: copyText, decodeF32: decodeF32, basename: basename, len: len, secs: secs };
})();
