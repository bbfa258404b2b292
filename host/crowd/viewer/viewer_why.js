// "Why this frame": the panel a search on the timeline opens for the
// selected character. Each explained search (Recording::why, computed by
// mmvk's explain_query from the query and the database's normalized
// features) shows, channel by channel, the weighted cost of the chosen and
// of the continuing frame, the clips and times of both, and the clip's
// multiplier and bias and the query's continuing bias and multiplier.
'use strict';
window.MmvkWhy = (function () {
  const fmt = (v) => (Math.abs(v) >= 100 ? v.toFixed(1) : Math.abs(v) >= 1 ? v.toFixed(3) : v.toFixed(4));
  const esc = (s) => String(s).replace(/[&<>"]/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;' })[c]);

  // The explanation of search `index` of agent a, or null (not explained).
  function find(D, a, index) {
    if (!D.why || a < 0 || a >= D.why.length) return null;
    return D.why[a].find((w) => w.search === index) || null;
  }

  // The detailed characters in words: "the first 32 characters", or their
  // indices and ranges as --detail-agents takes them ("3 characters: 2, 5-6").
  function detailText(D) {
    const ids = D.detailIds || [], n = ids.length;
    if (n === 0) return 'no characters';
    if (ids[n - 1] === n - 1) return 'the first ' + n + (n === 1 ? ' character' : ' characters');
    const ranges = [];
    for (let i = 0; i < n; i++) {
      let j = i;
      while (j + 1 < n && ids[j + 1] === ids[j] + 1) j++;
      ranges.push(j > i ? ids[i] + '-' + ids[j] : String(ids[i]));
      i = j;
    }
    const shown = ranges.length > 8 ? ranges.slice(0, 8).join(', ') + ', \u2026' : ranges.join(', ');
    return n + (n === 1 ? ' character: ' : ' characters: ') + shown;
  }

  function frameLine(D, label, f) {
    if (!f) return '<div>' + label + ': none</div>';
    return '<div>' + label + ': frame ' + f.frame + ', ' + esc(D.clipNames[f.clip] || ('clip ' + f.clip)) + ' at ' +
      f.clipTime.toFixed(3) + ' s' + (f.exclusion ? ' <span style="color:var(--jump)">(not a candidate: ' +
      esc(D.exclusionNames[f.exclusion] || ('rule ' + f.exclusion)) + ')</span>' : '') + '</div>';
  }

  function table(D, w) {
    const c = w.chosen, k = w.continuing, max = Math.max(1e-9, ...D.channelNames.map((_, i) =>
      Math.max(c ? c.weighted[i] : 0, k ? k.weighted[i] : 0)));
    const bar = (v, cls) => '<span class="bar' + cls + '" style="width:' + Math.round(48 * v / max) + 'px"></span>';
    let rows = '<tr><th>channel</th><th>weight</th><th>chosen</th><th></th><th>continuing</th><th></th></tr>';
    D.channelNames.forEach((name, i) => {
      rows += '<tr><td>' + esc(name) + '</td><td>' + fmt(w.weights[i]) + '</td><td>' + (c ? fmt(c.weighted[i]) : '') +
        '</td><td style="text-align:left">' + (c ? bar(c.weighted[i], '') : '') + '</td><td>' + (k ? fmt(k.weighted[i]) : '') +
        '</td><td style="text-align:left">' + (k ? bar(k.weighted[i], ' cont') : '') + '</td></tr>';
    });
    const sum = (f) => (f ? f.weighted.reduce((s, v) => s + v, 0) : 0);
    const cell = (f, text) => '<td>' + (f ? text(f) : '') + '</td><td></td>';
    rows += '<tr><td>sum</td><td></td>' + cell(c, (f) => fmt(sum(f))) + cell(k, (f) => fmt(sum(f))) + '</tr>';
    rows += '<tr><td>\u00d7 clip multiplier</td><td></td>' + cell(c, (f) => fmt(f.multiplier)) + cell(k, (f) => fmt(f.multiplier)) + '</tr>';
    rows += '<tr><td>+ clip bias</td><td></td>' + cell(c, (f) => fmt(f.bias)) + cell(k, (f) => fmt(f.bias)) + '</tr>';
    rows += '<tr><td>continuing: \u00d7 ' + fmt(w.continuingMultiplier) + ' + ' + fmt(w.continuingBias) + '</td><td></td>' +
      cell(c, (f) => (f.frame === (k && k.frame) ? 'applied' : '')) + cell(k, () => 'applied') + '</tr>';
    rows += '<tr><td><b>cost</b></td><td></td>' + cell(c, (f) => '<b>' + fmt(f.cost) + '</b>') + cell(k, (f) => '<b>' + fmt(f.cost) + '</b>') + '</tr>';
    return '<table>' + rows + '</table>';
  }

  // Fills `panel` with agent a's search `index` (of D.searches[a]);
  // returns the probe a test reads: chosen frame, continuing frame, chosen
  // cost, continuing cost, chosen channel sum ('' when not explained).
  function show(panel, D, a, index, close) {
    const e = D.searches[a], w = find(D, a, index);
    const jumped = e.flags[index] & 1, forced = e.flags[index] & 2;
    let html = '<button title="close">\u2715</button><b>why this frame</b> \u00b7 agent ' + a + ', search at ' +
      e.t[index].toFixed(2) + ' s' + (forced ? ' (forced)' : '') + ': ' + (e.to[index] < 0 ? 'no candidate' :
      jumped ? 'jump ' + e.from[index] + ' \u2192 ' + e.to[index] : 'stays at ' + e.from[index]) + '<br>';
    let probe = '';
    if (!w) {
      html += '<div style="color:var(--dim)">not explained: the page explains the searches of ' + detailText(D) +
        ' (mmvk crowd --detail-agents; docs/viewer.md, "Size")</div>';
    } else {
      html += frameLine(D, 'chosen', w.chosen) + frameLine(D, 'continuing', w.continuing) + table(D, w);
      const sum = (f) => (f ? f.weighted.reduce((s, v) => s + v, 0) : 0);
      probe = [w.chosen ? w.chosen.frame : -1, w.continuing ? w.continuing.frame : -1, w.chosen ? w.chosen.cost : 0,
        w.continuing ? w.continuing.cost : 0, sum(w.chosen)].join(',');
    }
    panel.innerHTML = html;
    panel.hidden = false;
    panel.querySelector('button').onclick = close;
    return probe;
  }

  // The `why` section (viewer_payload.cpp documents the layout).
  function decode(r, N, C) {
    const frame = () => {
      if (!r.u()) return null;
      const f = { frame: r.u(), clip: r.u(), clipTime: r.z() / 1000, multiplier: r.z() / 1000, bias: r.z() / 1e5,
                  cost: r.z() / 1e5, exclusion: 0, weighted: new Float64Array(C) };
      f.exclusion = r.u();
      for (let c = 0; c < C; c++) f.weighted[c] = r.z() / 1e5;
      return f;
    };
    const out = [];
    for (let a = 0; a < N; a++) {
      const count = r.u(), list = [];
      let search = 0;
      for (let i = 0; i < count; i++) {
        search += r.z();
        const weights = new Float64Array(C);
        for (let c = 0; c < C; c++) weights[c] = r.z() / 1000;
        const continuingBias = r.z() / 1e5, continuingMultiplier = r.z() / 1000;
        list.push({ search, weights, continuingBias, continuingMultiplier, chosen: frame(), continuing: frame() });
      }
      out.push(list);
    }
    r.finish();
    return out;
  }

  return { show, decode, find, detailText };
})();
