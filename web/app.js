/* k4reg page entry point: report mode (document embedded) or app mode
 * (upload form talking to the k4reg HTTP API). Plain ES2017. */
(function () {
  'use strict';

  /* Capture the page exactly as delivered, before anything touches the DOM:
   * the "download report" button re-emits it with the document embedded. */
  var PAGE_HTML = '<!DOCTYPE html>\n' + document.documentElement.outerHTML;

  var K4reg = window.K4reg || {};
  var U = K4reg.util;
  var el = U.el, num = U.num;
  var currentView = null;
  var currentDoc = null;

  function readDocument() {
    var s = document.getElementById('k4reg-document');
    if (!s) return { doc: null };
    var t = (s.textContent || '').trim();
    if (!t || t === 'null' || t.slice(0, 2) === '/*') return { doc: null };
    try {
      return { doc: JSON.parse(t) };
    } catch (e) {
      return { doc: null, error: 'The embedded result document could not be read: ' + e.message };
    }
  }

  function showFatal(msg) {
    var root = document.getElementById('view-root');
    root.textContent = '';
    root.appendChild(el('div', { class: 'error-box', id: 'error', text: msg }));
  }

  /* ------------------------------------------------------------------ */
  /* rendering a document + download bar                                 */
  /* ------------------------------------------------------------------ */

  function showDocument(doc) {
    var root = document.getElementById('view-root');
    if (currentView) { currentView.destroy(); currentView = null; }
    root.textContent = '';
    currentDoc = doc;
    var bar = downloadsBar(doc);
    var viewBox = el('div');
    root.appendChild(viewBox);
    root.appendChild(bar);
    currentView = K4reg.renderView(viewBox, doc);
    /* downloads right after the transform / poses */
    var after = viewBox.querySelector('#section-transform') || viewBox.querySelector('#section-poses');
    if (after && after.parentNode) after.parentNode.insertBefore(bar, after.nextSibling);
    var destroyView = currentView.destroy;
    currentView.destroy = function () { destroyView(); root.textContent = ''; };
  }

  function downloadsBar(doc) {
    var R = doc.result || {};
    var s = el('section', { class: 'card downloads', id: 'downloads' }, el('h2', { text: 'Downloads' }));
    var row = el('div', { class: 'btn-row' });
    s.appendChild(row);
    function btn(id, label, fn, title) {
      var b = el('button', { type: 'button', class: 'btn', id: id, text: label, title: title || '' });
      b.addEventListener('click', fn);
      row.appendChild(b);
      return b;
    }
    if (doc.kind === 'project') {
      btn('download-poses', 'Poses (poses.json)', function () {
        var out = {};
        (R.scans || []).forEach(function (sc, i) {
          var m = U.mat4(sc.pose);
          var key = String(sc.file || ('scan ' + i));
          if (Object.prototype.hasOwnProperty.call(out, key)) key = key + ' #' + i;
          out[key] = m && (sc.registered === undefined || sc.registered === true || sc.registered === 'true') ? m : null;
        });
        download('poses.json', JSON.stringify(out, null, 2) + '\n', 'application/json');
      }, 'scan file -> 4x4 row-major pose (null if not registered)');
    } else {
      btn('download-transform', 'Transform (transform.txt)', function () {
        var m = U.mat4(R.transform);
        if (!m) return;
        download('transform.txt', U.matrixText(R.transform) + '\n', 'text/plain');
      }, 'the 4x4 source -> target transform as 4 lines');
    }
    btn('download-json', 'Result (result.json)', function () {
      download('result.json', JSON.stringify(R, null, 2) + '\n', 'application/json');
    }, 'the registration result as JSON');
    btn('download-report', 'Report (report.html)', function () {
      download('report.html', reportHtml(doc), 'text/html');
    }, 'a self-contained report page that opens offline');
    return s;
  }

  /* Note: this file is inlined in a <script> element, so it must not contain
   * a literal script end tag or an HTML comment opener. */
  function embedJson(doc) {
    return JSON.stringify(doc).replace(/<\//g, '<\\/').replace(/<!-{2}/g, '<\\u0021--');
  }

  function reportHtml(doc) {
    var marker = 'id="k4reg-document"';
    var i = PAGE_HTML.indexOf(marker);
    if (i < 0) throw new Error('document script not found in page');
    var start = PAGE_HTML.indexOf('>', i) + 1;
    var end = PAGE_HTML.indexOf('<\/script>', start);
    return PAGE_HTML.slice(0, start) + embedJson(doc) + PAGE_HTML.slice(end);
  }

  function download(name, text, type) {
    var blob = new Blob([text], { type: type });
    var url = URL.createObjectURL(blob);
    var a = el('a', { href: url, download: name, style: { display: 'none' } });
    document.body.appendChild(a);
    a.click();
    document.body.removeChild(a);
    setTimeout(function () { URL.revokeObjectURL(url); }, 60000);
  }

  /* ------------------------------------------------------------------ */
  /* app mode: form, upload, progress                                     */
  /* ------------------------------------------------------------------ */

  function field(label, input, hint) {
    return el('label', { class: 'field' }, [el('span', { class: 'field-label', text: label }), input, hint ? el('span', { class: 'field-hint', text: hint }) : null]);
  }

  function buildApp() {
    var app = document.getElementById('app');
    app.hidden = false;
    app.textContent = '';
    app.appendChild(el('h2', { text: 'Register scans' }));

    var modePair = el('input', { type: 'radio', name: 'reg-mode', id: 'mode-pair', value: 'pair', checked: true });
    var modeProject = el('input', { type: 'radio', name: 'reg-mode', id: 'mode-project', value: 'project' });
    app.appendChild(el('div', { class: 'seg seg-mode' }, [
      el('label', null, [modePair, ' pair (source \u2192 target)']),
      el('label', null, [modeProject, ' project (several scans)'])]));

    var form = el('form', { id: 'register-form', novalidate: true });
    app.appendChild(form);

    var srcIn = el('input', { type: 'file', id: 'source-file' });
    var tgtIn = el('input', { type: 'file', id: 'target-file' });
    var pairBox = el('div', { class: 'form-grid', id: 'pair-fields' }, [
      field('Source scan (moved)', srcIn), field('Target scan (fixed)', tgtIn)]);
    var scansIn = el('input', { type: 'file', id: 'scan-files', multiple: true });
    var scanList = el('ol', { class: 'scan-list', id: 'scan-list', start: 0 });
    var refIn = el('input', { type: 'number', id: 'reference', min: 0, step: 1, value: 0 });
    var pairsSel = el('select', { id: 'pairs' }, [el('option', { value: 'all', text: 'all pairs' }), el('option', { value: 'sequence', text: 'sequence (i, i+1)' })]);
    var projectBox = el('div', { id: 'project-fields', hidden: true }, [
      el('div', { class: 'form-grid' }, [field('Scans (in order)', scansIn, 'scan index = order of the list below'),
        field('Reference scan', refIn, 'index of the scan that defines the project frame'),
        field('Pairs', pairsSel)]),
      scanList]);
    form.appendChild(pairBox);
    form.appendChild(projectBox);

    var minScale = el('input', { type: 'number', id: 'min-scale', min: 0, step: 'any', placeholder: 'automatic' });
    var overlap = el('input', { type: 'number', id: 'overlap', min: 0, max: 1, step: 'any', placeholder: 'automatic' });
    var seed = el('input', { type: 'number', id: 'seed', step: 1, value: 42 });
    var previewPts = el('input', { type: 'number', id: 'preview-points', min: 0, max: 2000000, step: 1000, value: 1000000 });
    var token = el('input', { type: 'password', id: 'token', autocomplete: 'off', placeholder: 'optional' });
    form.appendChild(el('div', { class: 'form-grid' }, [
      field('Min. scale (m)', minScale, 'blank = automatic'),
      field('Overlap (0..1)', overlap, 'blank = automatic'),
      field('Seed', seed),
      field('Preview points', previewPts, 'max 2 000 000'),
      field('Access token', token, 'sent as Authorization: Bearer')]));

    var submit = el('button', { type: 'submit', id: 'submit', class: 'btn btn-primary', text: 'Upload and register' });
    var cancel = el('button', { type: 'button', id: 'cancel', class: 'btn', text: 'Cancel', disabled: true });
    form.appendChild(el('div', { class: 'btn-row' }, [submit, cancel]));

    var upProg = el('progress', { id: 'upload-progress', max: 1, value: 0 });
    var stageProg = el('progress', { id: 'stage-progress', max: 1, value: 0 });
    var pairsProg = el('progress', { id: 'pairs-progress', max: 1, value: 0 });
    var status = el('div', { id: 'status', class: 'status', text: 'Choose the scans and press \u201cUpload and register\u201d.' });
    var elapsed = el('span', { id: 'elapsed', class: 'muted' });
    var stageLabel = el('span', { id: 'stage-label', class: 'muted', text: '\u2013' });
    var pairsLabel = el('span', { id: 'pairs-label', class: 'muted', text: '\u2013' });
    var pairsRow = el('div', { class: 'prog-row', hidden: true }, [el('span', { class: 'prog-label', text: 'Pairs' }), pairsProg, pairsLabel]);
    var pairLog = el('ul', { id: 'pair-log', class: 'pair-log' });
    var errorBox = el('div', { id: 'error', class: 'error-box', hidden: true });
    app.appendChild(el('div', { class: 'progress-box' }, [
      el('div', { class: 'status-row' }, [status, elapsed]),
      el('div', { class: 'prog-row' }, [el('span', { class: 'prog-label', text: 'Upload' }), upProg, el('span', { id: 'upload-label', class: 'muted', text: '\u2013' })]),
      el('div', { class: 'prog-row' }, [el('span', { class: 'prog-label', text: 'Stage' }), stageProg, stageLabel]),
      pairsRow, pairLog, errorBox]));
    var upLabel = app.querySelector('#upload-label');

    function mode() { return modeProject.checked ? 'project' : 'pair'; }
    function onMode() {
      pairBox.hidden = mode() !== 'pair';
      projectBox.hidden = mode() !== 'project';
    }
    modePair.addEventListener('change', onMode);
    modeProject.addEventListener('change', onMode);

    function refreshScanList() {
      scanList.textContent = '';
      var ref = Number(refIn.value) || 0;
      Array.prototype.forEach.call(scansIn.files || [], function (f, i) {
        scanList.appendChild(el('li', { class: i === ref ? 'ref' : '' }, [f.name + ' ', el('span', { class: 'muted', text: '(' + mb(f.size) + ')' + (i === ref ? ' \u2013 reference' : '') })]));
      });
    }
    scansIn.addEventListener('change', refreshScanList);
    refIn.addEventListener('input', refreshScanList);

    function mb(bytes) { return (bytes / 1048576).toFixed(bytes < 10485760 ? 2 : 1) + ' MB'; }

    var xhr = null, timer = null, t0 = 0, finished = false;

    function setBusy(b) {
      submit.disabled = b;
      cancel.disabled = !b;
      [srcIn, tgtIn, scansIn, modePair, modeProject].forEach(function (i) { i.disabled = b; });
      if (b) {
        t0 = Date.now();
        timer = setInterval(tick, 200);
        tick();
      } else if (timer) { clearInterval(timer); timer = null; tick(); }
    }
    function tick() { elapsed.textContent = 'elapsed ' + ((Date.now() - t0) / 1000).toFixed(1) + ' s'; }
    function setStatus(t, cls) { status.textContent = t; status.className = 'status' + (cls ? ' ' + cls : ''); }
    function showError(t) { errorBox.hidden = false; errorBox.textContent = t; setStatus('Failed', 'bad-text'); }

    cancel.addEventListener('click', function () {
      if (xhr) { finished = true; xhr.abort(); }
    });

    form.addEventListener('submit', function (e) {
      e.preventDefault();
      if (xhr) return;
      errorBox.hidden = true;
      var m = mode();
      var fd = new FormData(), params = {}, names = [];
      function text(name, input, asNumber) {
        var v = String(input.value).trim();
        if (v === '') return true;
        if (asNumber && !isFinite(Number(v))) { showError('Invalid value for ' + name + ': ' + v); return false; }
        fd.append(name, v);
        params[name] = asNumber ? Number(v) : v;
        return true;
      }
      if (m === 'pair') {
        var sf = srcIn.files && srcIn.files[0], tf = tgtIn.files && tgtIn.files[0];
        if (!sf || !tf) { showError('Choose a source and a target scan.'); return; }
        fd.append('source', sf, sf.name);
        fd.append('target', tf, tf.name);
        names = [sf.name, tf.name];
      } else {
        var files = Array.prototype.slice.call(scansIn.files || []);
        if (files.length < 2) { showError('Choose at least two scans.'); return; }
        files.forEach(function (f) { fd.append('scans', f, f.name); });
        names = files.map(function (f) { return f.name; });
      }
      var pp = Number(previewPts.value);
      if (previewPts.value !== '' && (!isFinite(pp) || pp < 0 || pp > 2000000)) { showError('Preview points must be between 0 and 2000000.'); return; }
      if (!text('min_scale_m', minScale, true) || !text('overlap', overlap, true) || !text('seed', seed, true)) return;
      if (m === 'project') {
        var ref = Number(refIn.value || 0);
        if (!(ref >= 0 && ref < names.length && Math.floor(ref) === ref)) { showError('Reference must be a scan index between 0 and ' + (names.length - 1) + '.'); return; }
        if (!text('reference', refIn, true)) return;
        fd.append('pairs', pairsSel.value); params.pairs = pairsSel.value;
      }
      if (!text('preview_points', previewPts, true)) return;
      start(m, fd, params, names);
    });

    function start(m, fd, params, names) {
      if (currentView) { currentView.destroy(); currentView = null; }
      currentDoc = null;
      window.k4regView = null;
      upProg.value = 0; stageProg.value = 0; pairsProg.value = 0;
      upLabel.textContent = '0 %'; stageLabel.textContent = '\u2013'; pairsLabel.textContent = '\u2013';
      pairLog.textContent = '';
      pairsRow.hidden = m !== 'project';
      finished = false;
      var offset = 0, scanFrom = 0, gotTerminal = false;
      xhr = new XMLHttpRequest();
      var x = xhr;
      x.open('POST', m === 'pair' ? '/v1/register' : '/v1/register-project');
      x.setRequestHeader('Accept', 'application/x-ndjson');
      var tok = token.value.trim();
      if (tok) x.setRequestHeader('Authorization', 'Bearer ' + tok);
      x.upload.onprogress = function (e) {
        if (e.lengthComputable && e.total > 0) {
          upProg.value = e.loaded / e.total;
          upLabel.textContent = Math.floor(100 * e.loaded / e.total) + ' % of ' + mb(e.total);
        }
      };
      x.upload.onload = function () {
        upProg.value = 1;
        if (!/%/.test(upLabel.textContent) || upLabel.textContent.indexOf('100') !== 0) upLabel.textContent = '100 %';
        if (!gotTerminal) setStatus('Upload complete, waiting for the server\u2026');
      };
      function pump(final) {
        if (x.status !== 200) return;
        var txt = x.responseText || '';
        var nl;
        /* scanFrom: no newline before it, so a long result line is scanned once */
        while ((nl = txt.indexOf('\n', Math.max(offset, scanFrom))) >= 0) {
          var line = txt.slice(offset, nl);
          offset = nl + 1;
          handleLine(line);
        }
        scanFrom = txt.length;
        if (final && offset < txt.length) { handleLine(txt.slice(offset)); offset = txt.length; }
      }
      function handleLine(line) {
        line = line.trim();
        if (!line || gotTerminal) return;
        var ev;
        try { ev = JSON.parse(line); } catch (e) { showError('Unreadable progress message from the server: ' + line.slice(0, 200)); gotTerminal = true; return; }
        handleEvent(ev);
      }
      function handleEvent(ev) {
        if (ev.queued) {
          setStatus('queued (position ' + (num(ev.queued.position) || 0) + ')');
        } else if (ev.stage) {
          var s = ev.stage, ph = String(s.phase || '');
          var f = num(s.fraction);
          if (/FINISHED/.test(ph)) f = 1; else if (/STARTED/.test(ph) && !isFinite(f)) f = 0;
          if (isFinite(f)) stageProg.value = Math.max(0, Math.min(1, f));
          var st = s.stage || '?';
          stageLabel.textContent = st + (isFinite(f) ? ' ' + Math.round(100 * f) + ' %' : '') + (isFinite(num(s.elapsed_s)) ? ' (' + num(s.elapsed_s).toFixed(1) + ' s)' : '');
          setStatus('running: ' + st + (/FINISHED/.test(ph) ? ' finished' : ''));
        } else if (ev.pair) {
          var p = ev.pair, k = (num(p.index) || 0) + 1, n = num(p.pairs) || 0;
          var line = 'pair ' + k + ' of ' + n + ': scans ' + num(p.source) + '-' + num(p.target) + ' (' + (isFinite(num(p.seconds)) ? num(p.seconds).toFixed(1) : '?') + ' s)' + (p.error ? ' \u2013 ' + p.error : '');
          pairLog.appendChild(el('li', { class: p.error ? 'bad-text' : '', text: line }));
          pairLog.scrollTop = pairLog.scrollHeight;
          if (n > 0) { pairsProg.value = Math.min(1, pairLog.children.length / n); pairsLabel.textContent = pairLog.children.length + ' of ' + n; }
        } else if (ev.result) {
          gotTerminal = true;
          onResult(m, ev.result, params, names);
        } else if (ev.error) {
          gotTerminal = true;
          var er = ev.error;
          showError((er.code || 'ERROR') + ': ' + (er.message || 'registration failed') + (er.request_id ? ' (request id ' + er.request_id + ')' : ''));
        }
      }
      x.onprogress = function () { pump(false); };
      x.onload = function () {
        if (x.status === 200) {
          pump(true);
          if (!gotTerminal) showError('The server closed the progress stream without a result.');
        } else {
          var body = null;
          try { body = JSON.parse(x.responseText); } catch (e) { body = null; }
          var msg = 'HTTP ' + x.status + (x.statusText ? ' ' + x.statusText : '');
          if (body && typeof body === 'object') msg += ': ' + (body.code || '') + (body.message ? ' \u2013 ' + body.message : '') + (body.request_id ? ' (request id ' + body.request_id + ')' : '');
          else if (x.responseText) msg += ': ' + x.responseText.slice(0, 300);
          showError(msg);
        }
        done();
      };
      x.onerror = function () { if (!finished) showError('Network error: the server could not be reached or closed the connection.'); done(); };
      x.onabort = function () { setStatus('Cancelled.', 'warn-text'); done(); };
      setStatus('Uploading\u2026');
      setBusy(true);
      x.send(fd);

      function done() {
        if (xhr === x) { xhr = null; setBusy(false); }
      }
    }

    function onResult(m, r, params, names) {
      var doc = {
        kind: m,
        title: m === 'pair' ? names[0] + ' -> ' + names[1] : names.length + ' scans: ' + names.join(', '),
        generator: 'k4reg page',
        created: new Date().toISOString(),
        files: names,
        parameters: params,
        result: r.result || {},
        preview: r.preview || null,
        service: { timings: r.timings || {}, server: r.server || {}, request_id: r.request_id || '' }
      };
      setStatus('Done.', 'ok-text');
      stageProg.value = 1;
      try {
        showDocument(doc);
        var v = document.getElementById('verdict');
        if (v && v.scrollIntoView) v.scrollIntoView({ behavior: 'smooth', block: 'start' });
      } catch (e) {
        showError('The result could not be displayed: ' + e.message);
      }
    }
  }

  /* ------------------------------------------------------------------ */
  /* entry                                                               */
  /* ------------------------------------------------------------------ */

  function main() {
    if (!K4reg.renderView) { showFatal('The page is incomplete (view code missing).'); return; }
    var r = readDocument();
    if (r.error) { showFatal(r.error); return; }
    if (r.doc) {
      document.body.classList.add('report-mode');
      var app = document.getElementById('app');
      if (app) { app.hidden = true; app.textContent = ''; }
      try {
        showDocument(r.doc);
      } catch (e) {
        showFatal('The result could not be displayed: ' + (e && e.message ? e.message : e));
      }
    } else {
      document.body.classList.add('app-mode');
      buildApp();
      window.k4regApp = { ready: true, reportHtml: function () { return currentDoc ? reportHtml(currentDoc) : null; } };
    }
  }

  main();
})();
