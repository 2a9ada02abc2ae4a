/* The result's text cards: the verdict banner, the summary figures, the transform (pair) or the poses
 * (project) with copy buttons, the parameters and files, and the document's service information.
 */
(function () {
  'use strict';

  var view = window.K4reg.view;
  var el = view.el, svg = view.svg, num = view.num, isNum = view.isNum, prec = view.prec, intStr = view.intStr,
    pct = view.pct, truthy = view.truthy, len = view.len, secs = view.secs, mat4 = view.mat4,
    rotAngleDeg = view.rotAngleDeg, rotAxis = view.rotAxis, copyText = view.copyText, matrixText = view.matrixText,
    section = view.section, kvTable = view.kvTable, basename = view.basename;

  /* ctx: what renderView's panels share (render_view.js). */
  view.cards = function (ctx) {
    var doc = ctx.doc, M = ctx.M, R = ctx.R, colorOfScan = ctx.colorOfScan;

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

    return { pairVerdict: pairVerdict, projectVerdict: projectVerdict, pairSummary: pairSummary,
      projectSummary: projectSummary, transformSection: transformSection, posesSection: posesSection,
      parametersSection: parametersSection, serviceSection: serviceSection };
  };
})();
