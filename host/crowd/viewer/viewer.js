// The mmvk crowd viewer: decodes the recording embedded in the page (see
// viewer_payload.cpp for the layout) and draws four views of it: 2-D
// canvas, and the crowd in 3D through viewer3d.js (three.js); the "why this
// frame" panel is viewer_why.js. Everything is embedded, no network.
//
// Conventions (as in recording.hpp): world Y-up, metres, ground XZ; a facing
// f looks along (sin f, 0, cos f); character space has +Z forward and the
// character's left at +X. The crowd view looks down from +Y with +X to the
// right and +Z down the screen, which is not mirrored.
'use strict';
(function () {
  const statusEl = document.getElementById('status');
  let failed = false;
  function reportError(message) {
    failed = true;
    statusEl.dataset.state = 'error';
    statusEl.textContent = 'viewer error: ' + message;
    document.title = 'mmvk crowd viewer: error';
  }
  window.addEventListener('error', (e) => reportError(e.message + ' (line ' + e.lineno + ')'));
  window.addEventListener('unhandledrejection', (e) =>
    reportError(String((e.reason && (e.reason.stack || e.reason.message)) || e.reason)));

  // ---- decoding --------------------------------------------------------

  async function inflate(base64) {
    const binary = atob(base64.trim());
    const bytes = new Uint8Array(binary.length);
    for (let i = 0; i < binary.length; i++) bytes[i] = binary.charCodeAt(i);
    if (typeof DecompressionStream === 'undefined') {
      throw new Error('this browser has no DecompressionStream; use a current Chromium, Firefox or Safari');
    }
    const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream('deflate'));
    return new Uint8Array(await new Response(stream).arrayBuffer());
  }

  // LEB128 varints, read with doubles (values stay below 2^53).
  class Reader {
    constructor(bytes, name, start, end) {
      this.bytes = bytes; this.name = name; this.pos = start; this.end = end;
    }
    u() {
      let value = 0, scale = 1, b;
      do {
        if (this.pos >= this.end) throw new Error('section ' + this.name + ' ends early');
        b = this.bytes[this.pos++];
        value += (b & 127) * scale;
        scale *= 128;
      } while (b & 128);
      return value;
    }
    z() {
      const u = this.u();
      return u % 2 ? -(u + 1) / 2 : u / 2;
    }
    finish() {
      if (this.pos !== this.end) throw new Error('section ' + this.name + ' has ' + (this.end - this.pos) + ' bytes left over');
    }
  }

  function decodePayload(meta, bytes) {
    if (meta.format !== 2) throw new Error('unknown payload format ' + meta.format);
    if (bytes.length !== meta.raw_bytes) throw new Error('payload is ' + bytes.length + ' bytes, expected ' + meta.raw_bytes);
    const readers = {};
    let offset = 0;
    for (const s of meta.sections) {
      readers[s.name] = new Reader(bytes, s.name, offset, offset + s.bytes);
      offset += s.bytes;
    }
    const N = meta.agent_count, S = meta.sample_count, K = meta.trajectory_times_s.length;
    const J = meta.joint_parents.length, P = meta.pose_count, legJoints = meta.leg_joints || [], L = legJoints.length;
    const d = {
      N, S, K, J, P, L, legJoints, rate: meta.sample_rate_hz,
      duration: Math.max(0, (S - 1) / meta.sample_rate_hz),
      times: meta.trajectory_times_s,
      parents: meta.joint_parents, names: meta.joint_names,
      rootX: new Float32Array(N * S), rootZ: new Float32Array(N * S),
      facing: new Float32Array(N * S), slot: new Int32Array(N * S),
    };
    let r = readers.roots;
    for (let a = 0; a < N; a++) {
      let x = 0, z = 0;
      for (let s = 0; s < S; s++) {
        x += r.z(); z += r.z();
        d.rootX[a * S + s] = x / 100; d.rootZ[a * S + s] = z / 100;
      }
    }
    r.finish();
    r = readers.facings;
    for (let a = 0; a < N; a++) {
      let q = 0;
      for (let s = 0; s < S; s++) {
        q = (q + r.z() + 4096) % 4096;
        d.facing[a * S + s] = q / 4096 * 2 * Math.PI;
      }
    }
    r.finish();
    r = readers.frames;
    for (let a = 0; a < N; a++) {
      let v = 0;
      for (let s = 0; s < S; s++) { v += r.z(); d.slot[a * S + s] = v - 1; }
    }
    r.finish();
    const trajectory = (reader) => {
      const xs = new Float32Array(N * S * K), zs = new Float32Array(N * S * K);
      const prev = new Float64Array(2 * K);
      for (let a = 0; a < N; a++) {
        prev.fill(0);
        for (let s = 0; s < S; s++) {
          const rx = Math.round(d.rootX[a * S + s] * 100), rz = Math.round(d.rootZ[a * S + s] * 100);
          for (let k = 0; k < K; k++) {
            prev[2 * k] += reader.z(); prev[2 * k + 1] += reader.z();
            xs[(a * S + s) * K + k] = (rx + prev[2 * k]) / 100;
            zs[(a * S + s) * K + k] = (rz + prev[2 * k + 1]) / 100;
          }
        }
      }
      reader.finish();
      return [xs, zs];
    };
    [d.desX, d.desZ] = trajectory(readers.desired);
    if (meta.has_matched) [d.matX, d.matZ] = trajectory(readers.matched);
    r = readers.goals;
    d.goals = [];
    d.goalBox = [];  // per agent [min x, min z, max x, max z] of its goals, to skip paths out of view
    for (let a = 0; a < N; a++) {
      const count = r.u(), g = new Float32Array(2 * count), box = [Infinity, Infinity, -Infinity, -Infinity];
      let x = 0, z = 0;
      for (let i = 0; i < count; i++) {
        x += r.z(); z += r.z(); g[2 * i] = x / 100; g[2 * i + 1] = z / 100;
        box[0] = Math.min(box[0], g[2 * i]); box[1] = Math.min(box[1], g[2 * i + 1]);
        box[2] = Math.max(box[2], g[2 * i]); box[3] = Math.max(box[3], g[2 * i + 1]);
      }
      d.goals.push(g);
      d.goalBox.push(box);
    }
    r.finish();
    r = readers.searches;
    d.searches = [];
    for (let a = 0; a < N; a++) {
      const count = r.u();
      const e = { t: new Float32Array(count), flags: new Uint8Array(count), from: new Int32Array(count),
                  to: new Int32Array(count), cost: new Float32Array(count) };
      let ms = 0, from = 0;
      for (let i = 0; i < count; i++) {
        ms += r.z(); e.t[i] = ms / 1000;
        e.flags[i] = r.u();
        from += r.z(); e.from[i] = from;
        e.to[i] = e.flags[i] & 4 ? from + r.z() : -1;
        e.cost[i] = r.z() / 1000;
      }
      d.searches.push(e);
    }
    r.finish();
    r = readers.pose_frames;
    d.poseFrames = new Int32Array(P);
    for (let p = 0, f = 0; p < P; p++) { f += r.z(); d.poseFrames[p] = f; }
    r.finish();
    r = readers.poses;
    d.poses = new Float32Array(P * J * 3);
    const prev = new Float64Array(J * 3);
    for (let p = 0; p < P; p++) {
      for (let c = 0; c < J * 3; c++) { prev[c] += r.z(); d.poses[p * J * 3 + c] = prev[c] / 1000; }
    }
    r.finish();
    if (L > 0) {
      // The leg joints as displayed (after foot IK), stored as corrections
      // of the played frame's pose in character space; kept in world space.
      r = readers.legs;
      d.legs = new Float64Array(N * S * L * 3);
      for (let a = 0; a < N; a++) {
        for (let s = 0; s < S; s++) {
          const i = a * S + s, slot = d.slot[i], c = Math.cos(d.facing[i]), sn = Math.sin(d.facing[i]);
          for (let l = 0; l < L; l++) {
            const v = [0, 0, 0];
            for (let k = 0; k < 3; k++) {
              const frameMm = slot >= 0 ? Math.round(d.poses[(slot * J + legJoints[l]) * 3 + k] * 1000) : 0;
              v[k] = (frameMm + 2 * r.z()) / 1000;  // corrections in 2 mm steps
            }
            const base = (i * L + l) * 3;
            d.legs[base] = d.rootX[i] + c * v[0] + sn * v[2];
            d.legs[base + 1] = v[1];
            d.legs[base + 2] = d.rootZ[i] - sn * v[0] + c * v[2];
          }
        }
      }
      r.finish();
      // Joints below a recorded one (end sites) move with it.
      const recorded = new Int32Array(J).fill(-1);
      legJoints.forEach((j, l) => { recorded[j] = l; });
      d.legFollow = new Int32Array(J).fill(-1);
      for (let j = 0; j < J; j++) {
        const parent = d.parents[j];
        if (recorded[j] < 0 && parent >= 0) d.legFollow[j] = recorded[parent] >= 0 ? recorded[parent] : d.legFollow[parent];
      }
    }
    if (meta.has_feet) {
      r = readers.feet;
      d.feet = [];
      for (let a = 0; a < N; a++) {
        const count = r.u(), f = { t: new Float32Array(count), state: new Uint8Array(count), anchor: new Float32Array(count * 6) };
        let ms = 0;
        const anchor = new Float64Array(6);
        for (let i = 0; i < count; i++) {
          ms += r.z(); f.t[i] = ms / 1000;
          f.state[i] = r.u();
          for (let foot = 0; foot < 2; foot++) {
            if (!(f.state[i] & (4 << foot))) continue;
            for (let c = 0; c < 3; c++) anchor[3 * foot + c] += r.z();
            for (let c = 0; c < 3; c++) f.anchor[6 * i + 3 * foot + c] = anchor[3 * foot + c] / 1000;
          }
        }
        d.feet.push(f);
      }
      r.finish();
    }
    decodeDetail(meta, readers, d);
    d.channelNames = meta.why ? meta.why.channel_names : [];
    d.clipNames = meta.why ? meta.why.clip_names : [];
    d.exclusionNames = meta.why ? meta.why.exclusion_names : [];
    if (meta.why) d.why = window.MmvkWhy.decode(readers.why, N, d.channelNames.length);
    return d;
  }

  // The whole displayed pose of the detailed characters (any set, by
  // default the first 32) at the tick rate, world metres:
  // [slot][sample][joint][xyz] in d.detail; d.detailIds[slot] is the
  // slot's character and d.detailSlot[a] character a's slot (-1: none).
  function decodeDetail(meta, readers, d) {
    d.detailAgents = meta.detail.agents;
    d.detailS = meta.detail.sample_count;
    d.detailRate = meta.detail.rate_hz;
    d.detailIds = [];
    d.detailSlot = new Int32Array(d.N).fill(-1);
    if (d.detailAgents === 0) return;
    const r = readers.detail, J = d.J, prev = new Float64Array(J * 3), before = new Float64Array(J * 3);
    for (let slot = 0, next = 0; slot < d.detailAgents; slot++) {
      const a = next + r.u();
      if (a >= d.N) throw new Error('detail: character ' + a + ' of ' + d.N);
      d.detailIds.push(a);
      d.detailSlot[a] = slot;
      next = a + 1;
    }
    d.detail = new Float32Array(d.detailAgents * d.detailS * J * 3);
    for (let a = 0; a < d.detailAgents; a++) {
      for (let s = 0; s < d.detailS; s++) {
        const base = (a * d.detailS + s) * J * 3;
        // Residuals of the linear prediction (viewer_payload.cpp, "detail").
        for (let c = 0; c < J * 3; c++) {
          const predicted = s === 0 ? 0 : s === 1 ? prev[c] : 2 * prev[c] - before[c];
          before[c] = prev[c];
          prev[c] = predicted + r.z();
        }
        for (let j = 0; j < J; j++) {
          for (let k = 0; k < 3; k++) d.detail[base + 3 * j + k] = (prev[3 * j + k] + (j > 0 ? prev[k] : 0)) / 1000;
        }
      }
    }
    r.finish();
  }

  // ---- state and sampling ------------------------------------------------

  let D = null;  // the decoded recording
  const state = { t: 0, whyIndex: -1, view3d: false, playing: true, speed: 1, selected: 0, view: null, yaw: -Math.PI / 2 + 0.6, dirty: true,
                  follow: false, hover: -1 };

  // Position of agent a at time t, interpolated between samples.
  function sampleAt(a, t) {
    let u = Math.min(Math.max(t * D.rate, 0), D.S - 1);
    if (Math.abs(u - Math.round(u)) < 1e-3) u = Math.round(u);  // on a sample despite float rates
    const s0 = Math.floor(u), s1 = Math.min(s0 + 1, D.S - 1), w = u - s0;
    const i0 = a * D.S + s0, i1 = a * D.S + s1;
    let df = D.facing[i1] - D.facing[i0];
    if (df > Math.PI) df -= 2 * Math.PI;
    if (df < -Math.PI) df += 2 * Math.PI;
    return { x: D.rootX[i0] + w * (D.rootX[i1] - D.rootX[i0]), z: D.rootZ[i0] + w * (D.rootZ[i1] - D.rootZ[i0]),
             f: D.facing[i0] + w * df, s0, s1, w };
  }

  // A detailed agent's whole displayed pose at time t, world [J*3],
  // interpolated between its ticks; null for an agent not detailed.
  function detailPoseAt(a, t) {
    const slot = a >= 0 && a < D.N ? D.detailSlot[a] : -1;
    if (slot < 0 || D.detailS === 0) return null;
    const u = Math.min(Math.max(t * D.detailRate, 0), D.detailS - 1), s0 = Math.floor(u);
    const s1 = Math.min(s0 + 1, D.detailS - 1), w = u - s0, n = D.J * 3, out = new Float32Array(n);
    const b0 = (slot * D.detailS + s0) * n, b1 = (slot * D.detailS + s1) * n;
    for (let c = 0; c < n; c++) out[c] = D.detail[b0 + c] + w * (D.detail[b1 + c] - D.detail[b0 + c]);
    return out;
  }

  // Agent a's displayed pose at time t in world space ([J*3]): the whole
  // pose at the tick rate for a detailed agent, else its played frame with
  // the legs as displayed (poseAt) at the 10 Hz samples.
  function worldPoseAt(a, t) {
    const detail = detailPoseAt(a, t);
    if (detail) return detail;
    const now = poseAt(a, t);
    if (!now) return null;
    const p = sampleAt(a, t), c = Math.cos(p.f), s = Math.sin(p.f), q = now.pose, out = new Float32Array(D.J * 3);
    for (let j = 0; j < D.J; j++) {
      const x = q[3 * j], z = q[3 * j + 2];
      out[3 * j] = p.x + c * x + s * z; out[3 * j + 1] = q[3 * j + 1]; out[3 * j + 2] = p.z - s * x + c * z;
    }
    return out;
  }

  // The pose of agent a at time t in character space ([J*3]), blending the
  // two neighbouring samples when they play nearby frames of one clip; a
  // detailed agent's is its whole displayed pose, brought into the
  // character space of the interpolated root.
  function poseAt(a, t) {
    const p = sampleAt(a, t);
    const slot0 = D.slot[a * D.S + p.s0], slot1 = D.slot[a * D.S + p.s1];
    if (slot0 < 0) return null;
    const detail = detailPoseAt(a, t);
    if (detail) {
      const c = Math.cos(p.f), sn = Math.sin(p.f), out = new Float32Array(D.J * 3);
      for (let j = 0; j < D.J; j++) {
        const dx = detail[3 * j] - p.x, dz = detail[3 * j + 2] - p.z;
        out[3 * j] = c * dx - sn * dz; out[3 * j + 1] = detail[3 * j + 1]; out[3 * j + 2] = sn * dx + c * dz;
      }
      return { pose: out, frame: D.poseFrames[slot0], whole: true };
    }
    const n = D.J * 3, out = new Float32Array(n);
    const blend = slot1 >= 0 && Math.abs(D.poseFrames[slot1] - D.poseFrames[slot0]) <= 12 ? p.w : 0;
    for (let c = 0; c < n; c++) {
      const v0 = D.poses[slot0 * n + c];
      out[c] = v0 + blend * (D.poses[slot1 * n + c] - v0);
    }
    // The legs as displayed: their recorded world positions, interpolated
    // (the displayed motion is continuous, jumps included) and brought into
    // character space with the interpolated root.
    if (D.legs) {
      const c = Math.cos(p.f), sn = Math.sin(p.f), b0 = (a * D.S + p.s0) * D.L * 3, b1 = (a * D.S + p.s1) * D.L * 3;
      const moved = new Float32Array(D.L * 3);
      for (let l = 0; l < D.L; l++) {
        const at = (k) => D.legs[b0 + 3 * l + k] + p.w * (D.legs[b1 + 3 * l + k] - D.legs[b0 + 3 * l + k]);
        const dx = at(0) - p.x, dz = at(2) - p.z, j = D.legJoints[l];
        const shown = [c * dx - sn * dz, at(1), sn * dx + c * dz];
        for (let k = 0; k < 3; k++) { moved[3 * l + k] = shown[k] - out[3 * j + k]; out[3 * j + k] = shown[k]; }
      }
      for (let j = 0; j < D.J; j++) {
        const l = D.legFollow[j];
        if (l >= 0) for (let k = 0; k < 3; k++) out[3 * j + k] += moved[3 * l + k];
      }
    }
    return { pose: out, frame: D.poseFrames[slot0] };
  }

  // Agent a's feet at time t: the state bits (FootEvent in recording.hpp)
  // and the anchors of locked feet, world [x y z, x y z]; null without.
  function feetAt(a, t) {
    if (!D.feet) return null;
    const f = D.feet[a];
    let lo = 0, hi = f.t.length - 1, found = -1;
    while (lo <= hi) { const mid = (lo + hi) >> 1; if (f.t[mid] <= t + 1e-6) { found = mid; lo = mid + 1; } else hi = mid - 1; }
    if (found < 0) return { state: 0, anchor: null, index: -1 };
    return { state: f.state[found], anchor: f.anchor.subarray(6 * found, 6 * found + 6), index: found };
  }

  const hue = (a) => (a * 137.508) % 360;

  // ---- canvases ----------------------------------------------------------

  function prepare(canvas) {
    const dpr = window.devicePixelRatio || 1;
    const w = canvas.clientWidth, h = canvas.clientHeight;
    if (canvas.width !== Math.round(w * dpr) || canvas.height !== Math.round(h * dpr)) {
      canvas.width = Math.round(w * dpr); canvas.height = Math.round(h * dpr);
    }
    const ctx = canvas.getContext('2d');
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.clearRect(0, 0, w, h);
    return { ctx, w, h };
  }

  function polyline(ctx, pts, color, width, dash) {
    if (pts.length < 2) return;
    ctx.strokeStyle = color; ctx.lineWidth = width; ctx.setLineDash(dash || []);
    ctx.beginPath();
    ctx.moveTo(pts[0][0], pts[0][1]);
    for (let i = 1; i < pts.length; i++) ctx.lineTo(pts[i][0], pts[i][1]);
    ctx.stroke();
    ctx.setLineDash([]);
  }

  // One path for all the discs: a fill per disc costs far more with many.
  function dots(ctx, pts, color, radius) {
    ctx.fillStyle = color;
    ctx.beginPath();
    for (const p of pts) { ctx.moveTo(p[0] + radius, p[1]); ctx.arc(p[0], p[1], radius, 0, 2 * Math.PI); }
    ctx.fill();
  }

  const css = (name) => getComputedStyle(document.documentElement).getPropertyValue(name).trim();
  const colors = {};

  // ---- the crowd from above ---------------------------------------------

  const crowdCanvas = document.getElementById('crowd');

  // Zoom bounds, pixels per metre: a tiny zoom (from the URL or the wheel)
  // made the grid loop run for ever, and neither end shows anything useful.
  const kMinScale = 1e-3, kMaxScale = 1e4;
  const clampScale = (s) => Math.min(kMaxScale, Math.max(kMinScale, Number.isFinite(s) ? s : 1));

  function fitView(w, h) {
    const [x0, z0, x1, z1] = D.bounds;
    const scale = clampScale(Math.min(w / Math.max(x1 - x0 + 4, 1), h / Math.max(z1 - z0 + 4, 1)));
    state.view = { cx: (x0 + x1) / 2, cz: (z0 + z1) / 2, scale };
  }
  const toScreen = (v, w, h, x, z) => [w / 2 + (x - v.cx) * v.scale, h / 2 + (z - v.cz) * v.scale];
  // The world rectangle [xa, xb, za, zb] (metres) a w x h canvas shows.
  const viewRect = (v, w, h) => [v.cx - w / 2 / v.scale, v.cx + w / 2 / v.scale, v.cz - h / 2 / v.scale, v.cz + h / 2 / v.scale];

  // One agent's goal path into the current path, only its segments that
  // cross the view [xa, xb] x [za, zb] (world metres), and at most about
  // one point per pixel: thousands of goals per agent stay cheap to draw.
  function addVisiblePath(ctx, g, v, w, h, xa, xb, za, zb) {
    let lastX = NaN, lastY = NaN;  // the last point added, on screen; NaN: the pen is up
    for (let i = 2; i < g.length; i += 2) {
      const x0 = g[i - 2], z0 = g[i - 1], x1 = g[i], z1 = g[i + 1];
      if ((x0 < xa && x1 < xa) || (x0 > xb && x1 > xb) || (z0 < za && z1 < za) || (z0 > zb && z1 > zb)) {
        lastX = NaN;
        continue;
      }
      const [sx, sy] = toScreen(v, w, h, x1, z1);
      if (Number.isNaN(lastX)) {
        const [px, py] = toScreen(v, w, h, x0, z0);
        ctx.moveTo(px, py); lastX = px; lastY = py;
      }
      if (Math.abs(sx - lastX) + Math.abs(sy - lastY) < 1 && i + 2 < g.length) continue;
      ctx.lineTo(sx, sy); lastX = sx; lastY = sy;
    }
  }

  // The ground, the goal paths of everyone and the selected character's
  // goals stay the same from frame to frame until the view, the canvas or
  // the selection changes: they are drawn into a layer of their own then,
  // and each frame copies the layer. Redrawn every frame, 20,000 goals (a
  // path of as many long segments, stroked twice) cost most of a second a
  // frame in a software canvas; a copy costs the same whatever the goals.
  const groundLayer = { canvas: document.createElement('canvas'), key: '' };
  function drawGroundLayer(ctx, v, w, h) {
    const key = [ctx.canvas.width, ctx.canvas.height, w, h, v.cx, v.cz, v.scale, state.selected].join(',');
    if (groundLayer.key !== key) {
      const layer = groundLayer.canvas;
      layer.width = ctx.canvas.width; layer.height = ctx.canvas.height;
      const g = layer.getContext('2d');
      g.setTransform(ctx.getTransform());
      // Ground grid: 1 m lines when zoomed in, else 10 m, coarser by tens
      // while more than 200 lines would cross the view.
      const [xa, xb, za, zb] = viewRect(v, w, h);
      let step = v.scale > 12 ? 1 : 10;
      while (Math.max(xb - xa, zb - za) / step > 200) step *= 10;
      g.strokeStyle = '#242a33'; g.lineWidth = 1;
      g.beginPath();
      for (let x = Math.ceil(xa / step) * step; x <= xb; x += step) { const sx = toScreen(v, w, h, x, 0)[0]; g.moveTo(sx, 0); g.lineTo(sx, h); }
      for (let z = Math.ceil(za / step) * step; z <= zb; z += step) { const sy = toScreen(v, w, h, 0, z)[1]; g.moveTo(0, sy); g.lineTo(w, sy); }
      g.stroke();
      // Goal paths of everyone, faint, in one path.
      g.strokeStyle = 'rgba(160,170,190,0.16)'; g.lineWidth = 1;
      g.beginPath();
      for (let a = 0; a < D.N; a++) {
        const b = D.goalBox[a];
        if (b[2] < xa || b[0] > xb || b[3] < za || b[1] > zb) continue;
        addVisiblePath(g, D.goals[a], v, w, h, xa, xb, za, zb);
      }
      g.stroke();
      if (state.selected >= 0) drawSelectedGoals(g, D.goals[state.selected], v, w, h);
      groundLayer.key = key;
    }
    ctx.save();
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.drawImage(groundLayer.canvas, 0, 0);
    ctx.restore();
  }

  function drawCrowd() {
    const { ctx, w, h } = prepare(crowdCanvas);
    if (!state.view) {
      fitView(w, h);
      // ?zoom=PX_PER_METRE starts close to the selected character.
      if (state.zoom > 0 && state.selected >= 0) {
        const p = sampleAt(state.selected, state.t);
        state.view = { cx: p.x, cz: p.z, scale: state.zoom };
      }
    }
    const v = state.view;
    if (state.follow && state.selected >= 0) {
      const p = sampleAt(state.selected, state.t);
      v.cx = p.x; v.cz = p.z;
    }
    v.scale = clampScale(v.scale);
    drawGroundLayer(ctx, v, w, h);
    // The characters: a disc (0.3 m, at least 2.5 px) and a facing tick.
    const radius = Math.max(0.3 * v.scale, 2.5);
    let drawn = 0;
    for (let a = 0; a < D.N; a++) {
      const p = sampleAt(a, state.t);
      const [sx, sy] = toScreen(v, w, h, p.x, p.z);
      if (sx < -radius || sy < -radius || sx > w + radius || sy > h + radius) continue;
      // Zoomed in, the disc fades so the pose drawn over it shows.
      ctx.fillStyle = 'hsla(' + hue(a) + ',75%,58%,' + (v.scale >= 40 ? 0.45 : 1) + ')';
      ctx.beginPath(); ctx.arc(sx, sy, radius, 0, 2 * Math.PI); ctx.fill();
      ctx.strokeStyle = '#0b0d10'; ctx.lineWidth = Math.max(1, radius * 0.3);
      ctx.beginPath(); ctx.moveTo(sx, sy);
      ctx.lineTo(sx + Math.sin(p.f) * radius * 1.6, sy + Math.cos(p.f) * radius * 1.6); ctx.stroke();
      drawn++;
      if (v.scale >= 40) drawTopDownPose(ctx, v, w, h, a, p);
      if (v.scale >= 40) drawLockedFeet(ctx, v, w, h, a);
    }
    state.drawn = drawn;
    drawSelectionOnCrowd(ctx, v, w, h, radius);
  }

  // Zoomed in, each character also shows its pose from above.
  function drawTopDownPose(ctx, v, w, h, a, p) {
    const now = poseAt(a, state.t);
    if (!now) return;
    const q = now.pose, c = Math.cos(p.f), s = Math.sin(p.f), pts = [];
    for (let j = 0; j < D.J; j++) {
      const x = q[3 * j], z = q[3 * j + 2];
      pts.push(toScreen(v, w, h, p.x + c * x + s * z, p.z - s * x + c * z));
    }
    ctx.strokeStyle = 'rgba(240,244,250,0.9)'; ctx.lineWidth = Math.max(1, v.scale * 0.025);
    ctx.beginPath();
    for (let j = 0; j < D.J; j++) {
      const parent = D.parents[j];
      if (parent < 0) continue;
      ctx.moveTo(pts[parent][0], pts[parent][1]); ctx.lineTo(pts[j][0], pts[j][1]);
    }
    ctx.stroke();
  }

  // A planted foot held by foot IK: a green mark on the ground where it is
  // locked (left a disc, right a square), a ring for the selected character's.
  function footMark(ctx, x, y, size, foot, fill, stroke) {
    ctx.fillStyle = fill;
    ctx.beginPath();
    if (foot === 0) ctx.arc(x, y, size, 0, 2 * Math.PI); else ctx.rect(x - size, y - size, 2 * size, 2 * size);
    ctx.fill();
    if (stroke) { ctx.strokeStyle = stroke; ctx.lineWidth = 1.5; ctx.stroke(); }
  }

  function drawLockedFeet(ctx, v, w, h, a) {
    const feet = feetAt(a, state.t);
    if (!feet || !feet.anchor) return;
    const size = Math.max(2.5, 0.045 * v.scale);
    for (let foot = 0; foot < 2; foot++) {
      if (!(feet.state & (4 << foot))) continue;
      const [sx, sy] = toScreen(v, w, h, feet.anchor[3 * foot], feet.anchor[3 * foot + 2]);
      footMark(ctx, sx, sy, size, foot, colors.locked, a === state.selected ? '#ffffff' : null);
    }
  }

  // The selected character's footprints: where its feet were locked in the
  // last 2 s, fading with age.
  function drawFootprints(ctx, v, w, h, a) {
    if (!D.feet || v.scale < 40) return;
    const f = D.feet[a], size = Math.max(2, 0.035 * v.scale);
    for (let i = 0; i < f.t.length && f.t[i] <= state.t; i++) {
      const age = state.t - f.t[i];
      if (age > 2) continue;
      for (let foot = 0; foot < 2; foot++) {
        if (!(f.state[i] & (4 << foot))) continue;
        const [sx, sy] = toScreen(v, w, h, f.anchor[6 * i + 3 * foot], f.anchor[6 * i + 3 * foot + 2]);
        footMark(ctx, sx, sy, size, foot, 'rgba(125,255,138,' + (0.1 + 0.25 * (1 - age / 2)).toFixed(3) + ')', null);
      }
    }
  }

  // The selected character's goals: its path and a dot per goal. Drawn
  // every frame, so its cost must not grow with the goal count: 20,000
  // goals, drawn whole with dashes (hundreds of thousands of dashes) and a
  // disc each, took seconds a frame and minutes to open the page. The path
  // takes only its segments in view, about one point per pixel
  // (addVisiblePath); it is dashed only while it is short, and at most one
  // dot is drawn per 6 x 6 pixel cell (the size of a dot).
  const kDashedGoalsMax = 256;
  function drawSelectedGoals(ctx, g, v, w, h) {
    const [xa, xb, za, zb] = viewRect(v, w, h);
    ctx.strokeStyle = 'rgba(255,255,255,0.55)'; ctx.lineWidth = 1.5;
    ctx.setLineDash(g.length / 2 <= kDashedGoalsMax ? [4, 4] : []);
    ctx.beginPath();
    addVisiblePath(ctx, g, v, w, h, xa, xb, za, zb);
    ctx.stroke();
    ctx.setLineDash([]);
    const cells = new Set(), shown = [];
    for (let i = 0; i < g.length; i += 2) {
      const [x, y] = toScreen(v, w, h, g[i], g[i + 1]);
      if (x < -4 || y < -4 || x > w + 4 || y > h + 4) continue;
      const cell = Math.floor(x / 6) * 65536 + Math.floor(y / 6);  // a disc is 6 px across
      if (cells.has(cell)) continue;
      cells.add(cell); shown.push([x, y]);
    }
    dots(ctx, shown, '#fff', 3);
  }

  function drawSelectionOnCrowd(ctx, v, w, h, radius) {
    const a = state.selected;
    if (a < 0) return;
    drawFootprints(ctx, v, w, h, a);
    // Achieved path: 2 s behind (grey) and the samples ahead (cyan).
    const p = sampleAt(a, state.t), past = [], ahead = [];
    for (let s = Math.max(0, p.s0 - Math.round(2 * D.rate)); s <= p.s0; s++) past.push(toScreen(v, w, h, D.rootX[a * D.S + s], D.rootZ[a * D.S + s]));
    past.push(toScreen(v, w, h, p.x, p.z));
    const horizon = D.times.length ? D.times[D.times.length - 1] : 1;
    ahead.push(toScreen(v, w, h, p.x, p.z));
    for (let s = p.s1; s < D.S && s <= p.s0 + Math.ceil(horizon * D.rate); s++) ahead.push(toScreen(v, w, h, D.rootX[a * D.S + s], D.rootZ[a * D.S + s]));
    polyline(ctx, past, 'rgba(200,200,200,0.6)', 2);
    polyline(ctx, ahead, colors.achieved, 2.5);
    const desired = [toScreen(v, w, h, D.rootX[a * D.S + p.s0], D.rootZ[a * D.S + p.s0])];
    for (let k = 0; k < D.K; k++) desired.push(toScreen(v, w, h, D.desX[(a * D.S + p.s0) * D.K + k], D.desZ[(a * D.S + p.s0) * D.K + k]));
    polyline(ctx, desired, colors.desired, 2.5);
    dots(ctx, desired.slice(1), colors.desired, 3);
    const [sx, sy] = toScreen(v, w, h, p.x, p.z);
    ctx.strokeStyle = '#fff'; ctx.lineWidth = 2;
    ctx.beginPath(); ctx.arc(sx, sy, radius + 4, 0, 2 * Math.PI); ctx.stroke();
  }

  function pickAgent(mx, my) {
    const v = state.view, { clientWidth: w, clientHeight: h } = crowdCanvas;
    let best = -1, bestD = Math.max(0.6 * v.scale, 12) ** 2;
    for (let a = 0; a < D.N; a++) {
      const p = sampleAt(a, state.t), [sx, sy] = toScreen(v, w, h, p.x, p.z);
      const dd = (sx - mx) ** 2 + (sy - my) ** 2;
      if (dd < bestD) { bestD = dd; best = a; }
    }
    return best;
  }

  // ---- the selected character's skeleton (orthographic 3-D) ------------

  const skeletonCanvas = document.getElementById('skeleton');

  function drawSkeleton() {
    const { ctx, w, h } = prepare(skeletonCanvas);
    const label = document.getElementById('skeleton-label');
    const a = state.selected;
    if (a < 0) { label.textContent = 'skeleton: click a character'; return; }
    const cy = Math.cos(state.yaw), sy = Math.sin(state.yaw), pitch = 0.3, cp = Math.cos(pitch), sp = Math.sin(pitch);
    const scale = Math.min(h / 2.6, w / 3.2), ox = w / 2, oy = h * 0.82;
    // Character space -> screen: yaw about +Y, then look down by `pitch`.
    const project = (x, y, z) => {
      const xr = cy * x - sy * z, zr = sy * x + cy * z;
      return [ox + xr * scale, oy - (y * cp + zr * sp) * scale];
    };
    ctx.strokeStyle = '#2c323d'; ctx.lineWidth = 1; ctx.beginPath();
    for (let i = -2; i <= 2; i++) {
      let p = project(i * 0.5, 0, -1), q = project(i * 0.5, 0, 1); ctx.moveTo(p[0], p[1]); ctx.lineTo(q[0], q[1]);
      p = project(-1, 0, i * 0.5); q = project(1, 0, i * 0.5); ctx.moveTo(p[0], p[1]); ctx.lineTo(q[0], q[1]);
    }
    ctx.stroke();
    polyline(ctx, [project(0, 0, 0), project(0, 0, 0.8)], '#55606f', 2);  // forward
    const now = poseAt(a, state.t), p = sampleAt(a, state.t);
    label.textContent = 'agent ' + a + (now ? ' \u00b7 frame ' + now.frame : '') + ' \u00b7 facing ' +
      Math.round(p.f * 180 / Math.PI) + '\u00b0 \u00b7 ' + (now && now.whole ? 'whole pose as displayed, ' +
      Number(D.detailRate.toPrecision(4)) + ' Hz' : 'legs as displayed') + ' \u00b7 drag to turn';
    if (!now) {
      ctx.fillStyle = colors.dim; ctx.fillText('no pose recorded for this frame', 10, 40);
      return;
    }
    const q = now.pose, J = D.J, screen = [];
    for (let j = 0; j < J; j++) screen.push(project(q[3 * j], q[3 * j + 1], q[3 * j + 2]));
    // Locked feet: their anchors on the ground, in character space.
    const feet = feetAt(a, state.t);
    if (feet && feet.anchor) {
      const c = Math.cos(p.f), sn = Math.sin(p.f);
      for (let foot = 0; foot < 2; foot++) {
        if (!(feet.state & (4 << foot))) continue;
        const dx = feet.anchor[3 * foot] - p.x, dz = feet.anchor[3 * foot + 2] - p.z;
        const m = project(c * dx - sn * dz, 0, sn * dx + c * dz);
        footMark(ctx, m[0], m[1], Math.max(5, scale * 0.05), foot, colors.locked, null);
      }
      label.textContent += ' \u00b7 ' + feetText(feet.state);
    }
    // Shadows of the joints on the ground, then bones coloured by side.
    ctx.fillStyle = 'rgba(0,0,0,0.35)';
    for (let j = 0; j < J; j++) { const s = project(q[3 * j], 0, q[3 * j + 2]); ctx.fillRect(s[0] - 2, s[1] - 1, 4, 2); }
    ctx.lineCap = 'round';
    for (let j = 0; j < J; j++) {
      const parent = D.parents[j];
      if (parent < 0) continue;
      const side = q[3 * j];
      ctx.strokeStyle = side > 0.03 ? '#5ec8ff' : side < -0.03 ? '#ff8fb1' : '#e8ecf2';
      ctx.lineWidth = Math.max(2, scale * 0.035);
      ctx.beginPath(); ctx.moveTo(screen[parent][0], screen[parent][1]); ctx.lineTo(screen[j][0], screen[j][1]); ctx.stroke();
    }
    dots(ctx, screen, '#fff', Math.max(2, scale * 0.02));
  }

  function feetText(bits) {
    const side = (foot) => (bits & (4 << foot) ? 'locked' : bits & (1 << foot) ? 'planted' : 'free');
    return 'left ' + side(0) + ', right ' + side(1);
  }

  // ---- desired against achieved trajectory (character space) -----------

  const trajectoryCanvas = document.getElementById('trajectory');

  function drawTrajectory() {
    const { ctx, w, h } = prepare(trajectoryCanvas);
    const a = state.selected;
    if (a < 0) return;
    // The latest sample at or before t: its desired trajectory is what the
    // controller searched with; the achieved points are where the root really
    // was that much later.
    const s = sampleAt(a, state.t).s0, i = a * D.S + s;
    const x0 = D.rootX[i], z0 = D.rootZ[i], f = D.facing[i], c = Math.cos(f), sn = Math.sin(f);
    const local = (x, z) => { const dx = x - x0, dz = z - z0; return [c * dx - sn * dz, sn * dx + c * dz]; };
    const desired = [[0, 0]], matched = [[0, 0]], achieved = [[0, 0]], marks = [], past = [];
    for (let k = 0; k < D.K; k++) {
      desired.push(local(D.desX[i * D.K + k], D.desZ[i * D.K + k]));
      if (D.matX) matched.push(local(D.matX[i * D.K + k], D.matZ[i * D.K + k]));
      const p = sampleAt(a, s / D.rate + D.times[k]);
      marks.push(local(p.x, p.z));
    }
    const horizon = D.times.length ? D.times[D.times.length - 1] : 1;
    for (let u = s + 1; u < D.S && u <= s + Math.ceil(horizon * D.rate); u++) achieved.push(local(D.rootX[a * D.S + u], D.rootZ[a * D.S + u]));
    for (let u = Math.max(0, s - Math.round(D.rate)); u <= s; u++) past.push(local(D.rootX[a * D.S + u], D.rootZ[a * D.S + u]));
    let extent = 0.6;
    for (const p of desired.concat(matched, achieved, marks)) extent = Math.max(extent, Math.abs(p[0]), Math.abs(p[1]));
    const scale = Math.min(w, h - 40) / 2 / (extent * 1.15), ox = w / 2, oy = 20 + (h - 40) / 2;
    // Forward is up; the character's left (+X) is on the screen's left.
    const screen = (p) => [ox - p[0] * scale, oy - p[1] * scale];
    // Rings every metre, or every 25 cm around a slow walker.
    const ring = extent > 2 ? 1 : 0.25;
    ctx.strokeStyle = '#2c323d'; ctx.lineWidth = 1;
    for (let r = ring; r <= extent * 1.15; r += ring) { ctx.beginPath(); ctx.arc(ox, oy, r * scale, 0, 2 * Math.PI); ctx.stroke(); }
    ctx.fillStyle = '#4a5261'; ctx.font = '11px system-ui, sans-serif';
    ctx.fillText('rings: ' + (ring * 100) + ' cm', w - 90, 16);
    polyline(ctx, past.map(screen), 'rgba(200,200,200,0.45)', 2);
    if (D.matX) polyline(ctx, matched.map(screen), colors.matched, 2, [5, 4]);
    polyline(ctx, achieved.map(screen), colors.achieved, 2.5);
    dots(ctx, marks.map(screen), colors.achieved, 4);
    polyline(ctx, desired.map(screen), colors.desired, 2.5);
    dots(ctx, desired.slice(1).map(screen), colors.desired, 4);
    ctx.fillStyle = colors.desired; ctx.font = '11px system-ui, sans-serif';
    desired.slice(1).forEach((p, k) => { const q = screen(p); ctx.fillText(D.times[k].toFixed(2) + ' s', q[0] + 6, q[1] - 4); });
    ctx.fillStyle = '#fff';
    ctx.beginPath(); ctx.moveTo(ox, oy - 9); ctx.lineTo(ox - 6, oy + 6); ctx.lineTo(ox + 6, oy + 6); ctx.closePath(); ctx.fill();
    if (D.K > 0) {
      const e = desired[D.K], m = marks[D.K - 1], err = Math.hypot(e[0] - m[0], e[1] - m[1]);
      ctx.fillStyle = colors.dim; ctx.font = '12px system-ui, sans-serif';
      ctx.fillText('sample at ' + (s / D.rate).toFixed(2) + ' s: desired vs achieved after ' + horizon.toFixed(2) + ' s: ' + err.toFixed(2) + ' m', 8, h - 8);
    }
  }

  // ---- searches and jumps on a timeline ---------------------------------

  const timelineCanvas = document.getElementById('timeline');
  const TL = { left: 40, right: 14 };
  const timeToX = (t, w) => TL.left + (D.duration > 0 ? t / D.duration : 0) * (w - TL.left - TL.right);
  const xToTime = (x, w) => Math.min(Math.max((x - TL.left) / (w - TL.left - TL.right), 0), 1) * D.duration;

  function drawTimeline() {
    const { ctx, w, h } = prepare(timelineCanvas);
    const a = state.selected, label = document.getElementById('timeline-label');
    ctx.font = '11px system-ui, sans-serif';
    ctx.fillStyle = colors.dim; ctx.strokeStyle = '#2c323d'; ctx.lineWidth = 1;
    // Bands from the top: the played frame, the feet (when recorded: a row
    // per foot, dim where planted, bright where locked), the searches' axis,
    // the match costs.
    const top = 24, feetH = D.feet ? 16 : 0, frameH = (h - top - 22 - feetH) * 0.55;
    const feetTop = top + frameH + 4, axisY = top + frameH + feetH + 8, costTop = axisY + 6, costH = h - 18 - costTop;
    const tickStep = D.duration > 30 ? 10 : D.duration > 8 ? 2 : 1;
    for (let t = 0; t <= D.duration + 1e-6; t += tickStep) {
      const x = timeToX(t, w);
      ctx.beginPath(); ctx.moveTo(x, top); ctx.lineTo(x, h - 16); ctx.stroke();
      ctx.fillText(t.toFixed(0) + ' s', x - 6, h - 4);
    }
    if (a < 0) { label.textContent = 'searches: click a character'; return; }
    const e = D.searches[a];
    // The played frame over time (upper band): jumps show as breaks.
    let fmin = Infinity, fmax = -Infinity;
    for (let s = 0; s < D.S; s++) { const slot = D.slot[a * D.S + s]; if (slot >= 0) { fmin = Math.min(fmin, D.poseFrames[slot]); fmax = Math.max(fmax, D.poseFrames[slot]); } }
    for (let i = 0; i < e.to.length; i++) if (e.to[i] >= 0) { fmin = Math.min(fmin, e.to[i], e.from[i]); fmax = Math.max(fmax, e.to[i], e.from[i]); }
    const frameY = (f) => top + frameH - (fmax > fmin ? (f - fmin) / (fmax - fmin) : 0.5) * frameH;
    ctx.fillStyle = 'rgba(200,210,230,0.75)';
    for (let s = 0; s < D.S; s++) {
      const slot = D.slot[a * D.S + s];
      if (slot >= 0) ctx.fillRect(timeToX(s / D.rate, w) - 1, frameY(D.poseFrames[slot]) - 1, 2, 2);
    }
    if (D.feet) drawFeetRows(ctx, w, a, feetTop);
    // Searches on the axis: a short grey tick, a tall jump bar from the old
    // frame to the new one, a red cross where no candidate was found.
    let jumps = 0, forced = 0, none = 0, cmax = 0;
    for (let i = 0; i < e.t.length; i++) cmax = Math.max(cmax, e.cost[i]);
    for (let i = 0; i < e.t.length; i++) {
      const x = timeToX(e.t[i], w), jumped = e.flags[i] & 1;
      if (e.flags[i] & 2) forced++;
      if (e.to[i] < 0) {
        none++; ctx.strokeStyle = '#ff3b30'; ctx.lineWidth = 2;
        ctx.beginPath(); ctx.moveTo(x - 4, axisY - 4); ctx.lineTo(x + 4, axisY + 4); ctx.moveTo(x + 4, axisY - 4); ctx.lineTo(x - 4, axisY + 4); ctx.stroke();
        continue;
      }
      if (jumped) {
        jumps++;
        ctx.strokeStyle = e.flags[i] & 2 ? '#ff3b30' : colors.jump; ctx.lineWidth = 2;
        ctx.beginPath(); ctx.moveTo(x, frameY(e.from[i])); ctx.lineTo(x, frameY(e.to[i])); ctx.stroke();
        ctx.fillStyle = colors.jump; ctx.fillRect(x - 1.5, axisY - 6, 3, 12);
      } else {
        ctx.fillStyle = '#6b7483'; ctx.fillRect(x - 0.5, axisY - 3, 1, 6);
      }
      const cy = costTop + costH - (cmax > 0 ? e.cost[i] / cmax : 0) * costH;
      ctx.fillStyle = jumped ? colors.jump : '#8a93a3'; ctx.fillRect(x - 1, cy - 1, 2, 2);
    }
    ctx.fillStyle = colors.dim;
    ctx.fillText('frame', 4, top + 10);
    ctx.fillText('cost', 4, costTop + 10);
    const x = timeToX(state.t, w);
    ctx.strokeStyle = '#fff'; ctx.lineWidth = 1.5; ctx.beginPath(); ctx.moveTo(x, top - 4); ctx.lineTo(x, h - 16); ctx.stroke();
    // The search under the pointer, or else the latest one at or before the
    // cursor, in words.
    let last = -1;
    for (let i = 0; i < e.t.length && e.t[i] <= state.t + 1e-6; i++) last = i;
    if (state.hover >= 0 && state.hover < e.t.length) {
      last = state.hover;
      const hx = timeToX(e.t[last], w);
      ctx.strokeStyle = 'rgba(255,255,255,0.5)'; ctx.lineWidth = 1; ctx.setLineDash([3, 3]);
      ctx.beginPath(); ctx.moveTo(hx, top - 4); ctx.lineTo(hx, h - 16); ctx.stroke(); ctx.setLineDash([]);
    }
    let text = 'agent ' + a + ': ' + e.t.length + ' searches, ' + jumps + ' jumps' + (forced ? ', ' + forced + ' forced' : '') +
      (none ? ', ' + none + ' without candidate' : '') + (D.duration > 0 ? ' (' + (jumps / D.duration).toFixed(2) + ' jumps/s)' : '');
    if (last >= 0) {
      text += ' \u00b7 ' + (last === state.hover ? 'search at ' : 'last search ') + e.t[last].toFixed(2) + ' s: ' + (e.to[last] < 0 ? 'no candidate' :
        (e.flags[last] & 1 ? 'jump ' + e.from[last] + ' \u2192 ' + e.to[last] : 'stay at ' + e.from[last]) + ', cost ' + e.cost[last].toFixed(3));
    }
    label.textContent = text;
  }

  function drawFeetRows(ctx, w, a, y) {
    const f = D.feet[a], end = D.duration;
    ctx.font = '8px system-ui, sans-serif';
    for (let foot = 0; foot < 2; foot++) {
      const rowY = y + foot * 7;
      ctx.fillStyle = colors.dim; ctx.fillText(foot === 0 ? 'L' : 'R', 30, rowY + 6);
      for (let i = 0; i < f.t.length; i++) {
        const bits = f.state[i], until = i + 1 < f.t.length ? f.t[i + 1] : end;
        if (!(bits & ((1 | 4) << foot))) continue;
        ctx.fillStyle = bits & (4 << foot) ? colors.locked : 'rgba(125,255,138,0.3)';
        const x0 = timeToX(f.t[i], w), x1 = timeToX(Math.min(until, end), w);
        ctx.fillRect(x0, rowY, Math.max(1, x1 - x0), 5);
      }
    }
    ctx.font = '11px system-ui, sans-serif';
  }

  // ---- the loop and the controls ----------------------------------------

  const playButton = document.getElementById('play'), slider = document.getElementById('time'), clock = document.getElementById('clock');

  function setTime(t) { state.t = Math.min(Math.max(t, 0), D.duration); state.dirty = true; }
  function setPlaying(on) { state.playing = on; playButton.textContent = on ? 'Pause' : 'Play'; }

  // The 3D view, made on first use (?view=3d or the view selector).
  let view3d = null;
  const crowd3dCanvas = document.getElementById('crowd3d');
  function select(a) { state.selected = a; state.whyIndex = -1; whyPanel.hidden = true; state.dirty = true; }
  function use3d(on) {
    state.view3d = on;
    document.getElementById('view').value = on ? '3d' : 'top';
    crowdCanvas.hidden = on; crowd3dCanvas.hidden = !on;
    document.getElementById('crowd-label').textContent = on
      ? 'crowd in 3D: click a character to select it; drag to orbit, right drag to pan, wheel to zoom; follow: the follow camera'
      : 'crowd, from above: click a character to select it; drag to pan, wheel to zoom';
    if (on && !view3d) {
      if (!window.THREE) throw new Error('three.js is missing from the page');
      view3d = window.MmvkView3d.create(crowd3dCanvas, { D, state, worldPose: worldPoseAt, sampleAt, feetAt, hue, colors, select });
    }
    state.dirty = true;
  }

  // The "why this frame" panel for the selected character's search i.
  const whyPanel = document.getElementById('why');
  function openWhy(i) {
    const a = state.selected;
    if (a < 0 || i < 0 || i >= D.searches[a].t.length) { whyPanel.hidden = true; state.whyIndex = -1; return; }
    state.whyIndex = i;
    statusEl.dataset.why = window.MmvkWhy.show(whyPanel, D, a, i, () => { whyPanel.hidden = true; state.whyIndex = -1; });
  }

  function render() {
    if (state.view3d) {
      const counts = view3d.draw();
      state.drawn3d = counts;
    } else {
      drawCrowd();
    }
    drawSkeleton(); drawTrajectory(); drawTimeline();
    slider.value = D.duration > 0 ? state.t / D.duration : 0;
    clock.textContent = state.t.toFixed(2) + ' / ' + D.duration.toFixed(2) + ' s';
    state.dirty = false;
  }

  let lastFrame = null;
  function frame(now) {
    if (failed) return;
    if (state.playing && lastFrame !== null) {
      let t = state.t + (now - lastFrame) / 1000 * state.speed;
      if (t > D.duration) t = 0;
      setTime(t);
    }
    lastFrame = now;
    if (state.dirty) render();
    requestAnimationFrame(frame);
  }

  function installControls() {
    playButton.onclick = () => setPlaying(!state.playing);
    document.getElementById('speed').onchange = (e) => { state.speed = parseFloat(e.target.value); };
    const follow = document.getElementById('follow');
    follow.onchange = () => {
      state.follow = follow.checked; state.dirty = true;
      if (!state.follow && view3d) view3d.lookAtSelected();
    };
    document.getElementById('view').onchange = (e) => use3d(e.target.value === '3d');
    slider.oninput = () => { setPlaying(false); setTime(parseFloat(slider.value) * D.duration); };
    window.addEventListener('keydown', (e) => {
      if (e.target.tagName === 'SELECT') return;
      if (e.code === 'Space') { e.preventDefault(); setPlaying(!state.playing); }
      if (e.code === 'ArrowRight') { setPlaying(false); setTime(state.t + 1 / D.rate); }
      if (e.code === 'ArrowLeft') { setPlaying(false); setTime(state.t - 1 / D.rate); }
    });
    window.addEventListener('resize', () => { state.dirty = true; });
    // Crowd view: drag pans, wheel zooms about the cursor, a click selects.
    let drag = null;
    crowdCanvas.addEventListener('mousedown', (e) => { drag = { x: e.offsetX, y: e.offsetY, moved: false }; });
    window.addEventListener('mouseup', (e) => {
      if (drag && !drag.moved && e.target === crowdCanvas) {
        const a = pickAgent(e.offsetX, e.offsetY);
        if (a >= 0) select(a);
      }
      drag = null;
    });
    crowdCanvas.addEventListener('mousemove', (e) => {
      if (!drag) return;
      const dx = e.offsetX - drag.x, dy = e.offsetY - drag.y;
      if (Math.abs(dx) + Math.abs(dy) > 3) drag.moved = true;
      if (drag.moved) {
        state.view.cx -= dx / state.view.scale; state.view.cz -= dy / state.view.scale;
        drag.x = e.offsetX; drag.y = e.offsetY; state.dirty = true;
      }
    });
    crowdCanvas.addEventListener('wheel', (e) => {
      e.preventDefault();
      const v = state.view, w = crowdCanvas.clientWidth, h = crowdCanvas.clientHeight;
      const wx = v.cx + (e.offsetX - w / 2) / v.scale, wz = v.cz + (e.offsetY - h / 2) / v.scale;
      v.scale = clampScale(v.scale * Math.exp(-e.deltaY * 0.0015));
      v.cx = wx - (e.offsetX - w / 2) / v.scale; v.cz = wz - (e.offsetY - h / 2) / v.scale;
      state.dirty = true;
    }, { passive: false });
    // Skeleton view: horizontal drag turns the camera.
    let turn = null;
    skeletonCanvas.addEventListener('mousedown', (e) => { turn = e.offsetX; });
    window.addEventListener('mouseup', () => { turn = null; });
    skeletonCanvas.addEventListener('mousemove', (e) => {
      if (turn === null) return;
      state.yaw += (e.offsetX - turn) * 0.01; turn = e.offsetX; state.dirty = true;
    });
    // Timeline: click or drag seeks.
    let seeking = false;
    const seek = (e) => { setPlaying(false); setTime(xToTime(e.offsetX, timelineCanvas.clientWidth)); };
    // A click on a search opens why it chose its frame.
    timelineCanvas.addEventListener('mousedown', (e) => {
      if (state.hover >= 0) { openWhy(state.hover); setPlaying(false); setTime(D.searches[state.selected].t[state.hover]); return; }
      seeking = true; seek(e);
    });
    timelineCanvas.addEventListener('mousemove', (e) => {
      if (seeking) { seek(e); return; }
      // Hovering names the search under the pointer.
      const a = state.selected, w = timelineCanvas.clientWidth;
      let best = -1, bestD = 6;
      if (a >= 0) {
        const ev = D.searches[a];
        for (let i = 0; i < ev.t.length; i++) {
          const d = Math.abs(timeToX(ev.t[i], w) - e.offsetX);
          if (d < bestD || (d === bestD && ev.flags[i] & 1)) { bestD = d; best = i; }
        }
      }
      if (best !== state.hover) { state.hover = best; state.dirty = true; }
    });
    timelineCanvas.addEventListener('mouseleave', () => { state.hover = -1; state.dirty = true; });
    window.addEventListener('mouseup', () => { seeking = false; });
  }

  // URL options, so a page can be opened (or screenshotted) at a known
  // state: ?t=SECONDS&agent=INDEX&paused=1&zoom=PX_PER_METRE&follow=1, and
  // view=3d&cam=DIST,YAW,PITCH[,HEIGHT] (metres, radians) for the 3D view
  // (characters=0: the empty ground), why=I to open the selected
  // character's search I (0-based).
  function applyQuery() {
    const q = new URLSearchParams(window.location.search);
    if (q.has('zoom')) state.zoom = parseFloat(q.get('zoom')) > 0 ? clampScale(parseFloat(q.get('zoom'))) : 0;
    state.follow = q.get('follow') === '1';
    document.getElementById('follow').checked = state.follow;
    if (q.has('t')) setTime(parseFloat(q.get('t')) || 0);
    if (q.has('agent')) {
      const a = parseInt(q.get('agent'), 10);
      state.selected = a >= 0 && a < D.N ? a : -1;
    }
    setPlaying(!(q.get('paused') === '1'));
    if (q.get('view') === '3d') {
      use3d(true);
      // A camera named looks at the selected character; else the whole crowd.
      if (q.has('cam')) {
        view3d.setCamera(...q.get('cam').split(',').map(parseFloat));
        view3d.lookAtSelected();
      }
      if (q.get('characters') === '0') view3d.showCharacters(false);
    }
    if (q.has('why')) openWhy(parseInt(q.get('why'), 10));
  }

  // What the page decoded for the selected character at the current sample,
  // as comma-separated numbers, so a test can compare it with the recording:
  // agent, sample, x, z, facing, frame, last desired x z, last matched x z
  // (0 0 without), searches, the last search's from, to and cost, goals,
  // the last joint's y in the pose played (0 without), the last leg joint's
  // recorded world y (0 without) and the foot events (0 without).
  function probe() {
    const a = state.selected;
    if (a < 0) return '';
    const s = sampleAt(a, state.t).s0, i = a * D.S + s, k = (i + 1) * D.K - 1, e = D.searches[a];
    const slot = D.slot[i], last = e.t.length - 1;
    return [a, s, D.rootX[i], D.rootZ[i], D.facing[i], slot >= 0 ? D.poseFrames[slot] : -1,
      D.K ? D.desX[k] : 0, D.K ? D.desZ[k] : 0, D.matX && D.K ? D.matX[k] : 0, D.matX && D.K ? D.matZ[k] : 0,
      e.t.length, last >= 0 ? e.from[last] : 0, last >= 0 ? e.to[last] : 0, last >= 0 ? e.cost[last] : 0,
      D.goals[a].length / 2, slot >= 0 ? D.poses[(slot + 1) * D.J * 3 - 2] : 0,
      D.legs ? D.legs[(i + 1) * D.L * 3 - 2] : 0, D.feet ? D.feet[a].t.length : 0].join(',');
  }

  // The selected character's pose as the page draws it at the current
  // time, for a test: 1 when it is the whole pose at the tick rate (a
  // detailed character), 0 when the played frame with the legs at 10 Hz,
  // then x, y, z per joint in world metres ('' without a pose).
  function poseProbe() {
    const a = state.selected, pose = a >= 0 ? worldPoseAt(a, state.t) : null;
    if (!pose) return '';
    return [detailPoseAt(a, state.t) ? 1 : 0, ...Array.from(pose, (v) => v.toFixed(4))].join(',');
  }

  async function main() {
    const started = performance.now();
    const meta = JSON.parse(document.getElementById('mmvk-meta').textContent);
    const bytes = await inflate(document.getElementById('mmvk-data').textContent);
    D = decodePayload(meta, bytes);
    D.bounds = meta.bounds;
    for (const name of ['desired', 'achieved', 'matched', 'jump', 'dim', 'locked']) colors[name] = css('--' + name);
    document.getElementById('title').textContent = meta.title || 'mmvk crowd';
    document.getElementById('title').title = meta.title || '';
    if (D.N === 0) state.selected = -1;
    applyQuery();
    installControls();
    render();
    if (failed) return;
    const ms = Math.round(performance.now() - started);
    statusEl.dataset.state = 'ready';
    statusEl.dataset.agents = String(D.N);
    statusEl.dataset.drawn = String(state.drawn);
    statusEl.dataset.decodeMs = String(ms);
    statusEl.dataset.probe = probe();
    statusEl.dataset.pose = poseProbe();
    statusEl.dataset.view = state.view3d ? '3d' : 'top';
    if (state.view3d && state.selected >= 0) {
      // The selected character's hips on the page, CSS px, for a test.
      const [x, y] = view3d.project(state.selected), box = crowd3dCanvas.getBoundingClientRect();
      statusEl.dataset.projected = Math.round(box.left + x) + ',' + Math.round(box.top + y);
    }
    statusEl.dataset.detailAgents = String(D.detailAgents);
    statusEl.textContent = 'ready: ' + D.N + ' agents, ' + D.S + ' samples at ' + Number(D.rate.toPrecision(4)) + ' Hz, ' + D.P + ' poses' +
      (D.detailAgents ? ', ' + D.detailAgents + ' whole poses at ' + Number(D.detailRate.toPrecision(4)) + ' Hz' : '') + '; loaded in ' + ms + ' ms';
    document.title = 'mmvk crowd viewer: ' + (meta.title || 'ready');
    requestAnimationFrame(frame);
  }

  main().catch((e) => reportError(String((e && (e.stack || e.message)) || e)));
})();
