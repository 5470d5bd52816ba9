// meshnav live view (docs/view.md): polls /api/state of view_server every 100 ms. On every
// animation frame it draws the top view (x–y of G, y up): a layer with the paths, ellipses and
// anchors, redrawn when new state has come, under the vehicle, which glides from its previous
// pose to the newest over one poll. The residual and height strips are redrawn with new state,
// the tables at most 4 times a second. With ?perf=1 in the URL the page posts its frame counts to /api/perf once a
// second (the measurement of docs/view.md).
'use strict';

const VEHICLE = '#ff00ff';  // the screenshot test looks for this colour: used for nothing else
const STATE_COLOURS = {
  known: '#444444', calibrated: '#2e8b57', estimated: '#17becf', collecting: '#ff7f0e',
  refused: '#d62728', unknown: '#999999',
};
const PALETTE = ['#1f77b4', '#ff7f0e', '#2ca02c', '#d62728', '#9467bd', '#8c564b', '#e377c2', '#7f7f7f',
  '#bcbd22', '#17becf', '#393b79', '#637939', '#8c6d31', '#843c39'];
const POLL_MS = 100;
const RESIDUAL_WINDOW_S = 30;

const S = {
  path: { epoch: -1, rows: [] },
  truth: { epoch: -1, rows: [] },
  res: { epoch: -1, rows: [] },
  j: null,            // the last state
  dirty: false,       // new state since the last redraw of the layer and the strips
  panelsDirty: false, // new state since the last refresh of the tables
  layer: null,        // the top view without the vehicle (drawTopLayer)
  prevP: null,        // where the vehicle's glide starts [m]
  poseAt: 0,          // when the newest pose came [ms, performance.now()]
  bounds: null,       // [xmin, xmax, ymin, ymax] of G shown
  panelsAt: 0,
  frames: 0, drawMs: 0,
  firstFrameMs: null, // ms after navigation start of the first frame that drew the vehicle
  perf: new URLSearchParams(location.search).get('perf') === '1',
};

// ---- data ---------------------------------------------------------------------------------------
function merge(track, t) {
  if (t.epoch !== track.epoch || t.start === 0) {
    track.epoch = t.epoch;
    track.rows = t.rows;
  } else if (t.start === track.rows.length) {
    for (const r of t.rows) track.rows.push(r);
  } else {
    track.epoch = -1;  // out of step: ask for everything next time
  }
}

async function poll() {
  try {
    const q = `pe=${S.path.epoch}&pn=${S.path.rows.length}&te=${S.truth.epoch}&tn=${S.truth.rows.length}` +
              `&re=${S.res.epoch}&rn=${S.res.rows.length}`;
    const r = await fetch('/api/state?' + q, { cache: 'no-store' });
    if (r.ok) {
      const j = await r.json();
      merge(S.path, j.path);
      merge(S.truth, j.truth);
      merge(S.res, j.residuals);
      const before = S.j && S.j.pose;
      if (j.pose && (!before || j.pose.t !== before.t)) {
        // where the vehicle is drawn now becomes the start of its glide to the new pose
        const f = Math.min(1, Math.max(0, (performance.now() - S.poseAt) / POLL_MS));
        S.prevP = before ? (S.prevP ? [0, 1].map((k) => S.prevP[k] + f * (before.p[k] - S.prevP[k])) : before.p) : null;
        S.poseAt = performance.now();
      }
      S.j = j;
      S.dirty = true;
      S.panelsDirty = true;
      growBounds(j);
    }
  } catch (e) {
    document.getElementById('source').textContent = 'view_server not reachable (' + e + ')';
  }
  setTimeout(poll, POLL_MS);
}

// The area shown only grows, so the picture does not jump while the vehicle flies.
function growBounds(j) {
  let b = S.bounds ? S.bounds.slice() : [Infinity, -Infinity, Infinity, -Infinity];
  const add = (x, y) => {
    if (!Number.isFinite(x) || !Number.isFinite(y)) return;
    b[0] = Math.min(b[0], x); b[1] = Math.max(b[1], x); b[2] = Math.min(b[2], y); b[3] = Math.max(b[3], y);
  };
  for (const a of j.anchors) if (a.p) add(a.p[0], a.p[1]);
  if (j.pose) add(j.pose.p[0], j.pose.p[1]);
  if (j.truth_pose) add(j.truth_pose.p[0], j.truth_pose.p[1]);
  for (const r of j.path.rows) add(r[1], r[2]);
  for (const r of j.truth.rows) add(r[1], r[2]);
  if (b[0] === Infinity) return;
  S.bounds = b;
}

// ---- drawing ------------------------------------------------------------------------------------
function fitCanvas(c) {
  const dpr = window.devicePixelRatio || 1;
  const w = Math.max(1, Math.round(c.clientWidth * dpr)), h = Math.max(1, Math.round(c.clientHeight * dpr));
  if (c.width !== w || c.height !== h) { c.width = w; c.height = h; }
  const ctx = c.getContext('2d');
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
  return [ctx, c.clientWidth, c.clientHeight];
}

// World (G, metres) to canvas pixels, equal scale on both axes, y up, 1 m margin.
function transform(w, h) {
  const [x0, x1, y0, y1] = S.bounds ? S.bounds : [-5, 5, -5, 5];
  const cx = (x0 + x1) / 2, cy = (y0 + y1) / 2;
  const span = Math.max(x1 - x0 + 2, (y1 - y0 + 2) * w / h, 2);
  const k = w / span;
  return { k, x: (X) => w / 2 + (X - cx) * k, y: (Y) => h / 2 - (Y - cy) * k };
}

function ellipse(ctx, T, x, y, ell) {
  if (!ell || !(ell[0] > 0)) return;
  ctx.beginPath();
  ctx.ellipse(T.x(x), T.y(y), Math.max(ell[0] * T.k, 0.5), Math.max(ell[1] * T.k, 0.5), -ell[2], 0, 2 * Math.PI);
  ctx.stroke();
}

function polyline(ctx, T, rows) {
  if (rows.length < 2) return;
  ctx.beginPath();
  ctx.moveTo(T.x(rows[0][1]), T.y(rows[0][2]));
  for (let i = 1; i < rows.length; ++i) ctx.lineTo(T.x(rows[i][1]), T.y(rows[i][2]));
  ctx.stroke();
}

// The path's 95 % x–y ellipses, faint, at most about 150 along the whole path.
function pathEllipses(ctx, T) {
  const rows = S.path.rows;
  if (rows.length < 2) return;
  const every = Math.max(1, (rows[rows.length - 1][0] - rows[0][0]) / 150);
  ctx.strokeStyle = 'rgba(31, 119, 180, 0.3)';
  ctx.lineWidth = 1;
  let next = rows[0][0];
  for (const r of rows) {
    if (r[0] < next) continue;
    ellipse(ctx, T, r[1], r[2], [r[4], r[5], r[6]]);
    next = r[0] + every;
  }
}

function grid(ctx, T, w, h) {
  const step = T.k > 25 ? 1 : T.k > 6 ? 5 : 10;  // metres between lines
  ctx.strokeStyle = '#eeeeee';
  ctx.lineWidth = 1;
  ctx.fillStyle = '#999';
  ctx.font = '10px sans-serif';
  const xmin = Math.floor((0 - T.x(0)) / T.k / step) * step, xmax = (w - T.x(0)) / T.k;
  for (let X = xmin; X <= xmax; X += step) {
    ctx.beginPath(); ctx.moveTo(T.x(X), 0); ctx.lineTo(T.x(X), h); ctx.stroke();
    ctx.fillText(X + ' m', T.x(X) + 2, h - 3);
  }
  const ymin = Math.floor((T.y(0) - h) / T.k / step) * step, ymax = T.y(0) / T.k;
  for (let Y = ymin; Y <= ymax; Y += step) {
    ctx.beginPath(); ctx.moveTo(0, T.y(Y)); ctx.lineTo(w, T.y(Y)); ctx.stroke();
    ctx.fillText(Y + ' m', 2, T.y(Y) - 2);
  }
  document.getElementById('scale').textContent = `grid ${step} m; x → right, y ↑ (G)`;
}

// Everything of the top view but the vehicle, into an offscreen layer: redrawn when new state has
// come or the canvas changed size, copied on every frame under the moving vehicle.
function drawTopLayer(w, h, T) {
  const c = S.layer || (S.layer = document.createElement('canvas'));
  const top = document.getElementById('top');
  c.width = top.width;
  c.height = top.height;
  const ctx = c.getContext('2d');
  ctx.setTransform(top.width / w, 0, 0, top.height / h, 0, 0);
  grid(ctx, T, w, h);
  const j = S.j;
  if (!j) return;
  // truth, then the estimate over it
  ctx.lineWidth = 1.5;
  ctx.strokeStyle = '#2ca02c';
  ctx.setLineDash([5, 4]);
  polyline(ctx, T, S.truth.rows);
  ctx.setLineDash([]);
  ctx.strokeStyle = '#1f77b4';
  polyline(ctx, T, S.path.rows);
  pathEllipses(ctx, T);
  // anchors
  ctx.font = '11px sans-serif';
  for (const a of j.anchors) {
    if (!a.p) continue;
    const c = STATE_COLOURS[a.state] || '#999';
    ctx.strokeStyle = c;
    ctx.fillStyle = c;
    ctx.lineWidth = 1;
    ellipse(ctx, T, a.p[0], a.p[1], a.ell);
    const X = T.x(a.p[0]), Y = T.y(a.p[1]);
    ctx.beginPath();
    ctx.moveTo(X, Y - 7); ctx.lineTo(X + 6, Y + 5); ctx.lineTo(X - 6, Y + 5); ctx.closePath();
    if (a.state === 'collecting' || a.state === 'refused') { ctx.lineWidth = 2; ctx.stroke(); } else ctx.fill();
    ctx.fillText(String(a.id), X + 8, Y - 6);
  }
  // truth vehicle
  if (j.truth_pose) {
    ctx.strokeStyle = '#2ca02c';
    ctx.lineWidth = 2;
    ctx.beginPath();
    ctx.arc(T.x(j.truth_pose.p[0]), T.y(j.truth_pose.p[1]), 6, 0, 2 * Math.PI);
    ctx.stroke();
  }
}

// The top view on every frame: the layer, and the vehicle (its 95 % ellipse, a disc and its
// heading) moved from the previous pose to the newest over one poll period, so that it glides
// instead of jumping every poll. True when the vehicle was drawn.
function drawTop(now, redraw) {
  const top = document.getElementById('top');
  const [ctx, w, h] = fitCanvas(top);
  const T = transform(w, h);
  if (redraw || !S.layer || S.layer.width !== top.width || S.layer.height !== top.height) drawTopLayer(w, h, T);
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  ctx.clearRect(0, 0, top.width, top.height);
  ctx.drawImage(S.layer, 0, 0);
  ctx.setTransform(top.width / w, 0, 0, top.height / h, 0, 0);
  const pose = S.j && S.j.pose;
  if (!pose) return false;
  const f = Math.min(1, Math.max(0, (now - S.poseAt) / POLL_MS));
  const from = S.prevP || pose.p;
  const x = from[0] + f * (pose.p[0] - from[0]), y = from[1] + f * (pose.p[1] - from[1]);
  const X = T.x(x), Y = T.y(y);
  ctx.strokeStyle = 'rgba(160, 0, 160, 0.8)';
  ctx.lineWidth = 1.5;
  ellipse(ctx, T, x, y, pose.ell);
  const yaw = pose.yaw_deg * Math.PI / 180;
  ctx.strokeStyle = '#600060';
  ctx.lineWidth = 2;
  ctx.beginPath(); ctx.moveTo(X, Y); ctx.lineTo(X + 18 * Math.cos(yaw), Y - 18 * Math.sin(yaw)); ctx.stroke();
  ctx.fillStyle = VEHICLE;
  ctx.beginPath(); ctx.arc(X, Y, 8, 0, 2 * Math.PI); ctx.fill();
  return true;
}

function drawResiduals() {
  const [ctx, w, h] = fitCanvas(document.getElementById('residuals'));
  ctx.clearRect(0, 0, w, h);
  const rows = S.res.rows;
  const tEnd = S.j ? S.j.t : 0, tStart = tEnd - RESIDUAL_WINDOW_S;
  // y range: the largest |r| of the window, at least 0.2 m, at most 2 m (larger ones are clipped)
  let m = 0.2;
  let first = rows.length;
  while (first > 0 && rows[first - 1][0] >= tStart) --first;
  for (let i = first; i < rows.length; ++i) m = Math.max(m, Math.abs(rows[i][2]));
  m = Math.min(m * 1.1, 2);
  const X = (t) => 40 + (t - tStart) / RESIDUAL_WINDOW_S * (w - 50), Y = (r) => h / 2 - r / m * (h / 2 - 12);
  ctx.strokeStyle = '#ccc';
  ctx.beginPath(); ctx.moveTo(40, Y(0)); ctx.lineTo(w - 10, Y(0)); ctx.stroke();
  ctx.fillStyle = '#666';
  ctx.font = '10px sans-serif';
  ctx.fillText(`+${m.toFixed(2)} m`, 2, 12);
  ctx.fillText(`−${m.toFixed(2)} m`, 2, h - 4);
  ctx.fillText(`range residual z − ‖p_T − p_A‖ per anchor (colours of the table), last ${RESIDUAL_WINDOW_S} s`, 90, 12);
  const ids = S.j ? S.j.anchors.map((a) => a.id) : [];
  for (let i = first; i < rows.length; ++i) {
    const r = rows[i];
    ctx.fillStyle = PALETTE[Math.max(0, ids.indexOf(r[1])) % PALETTE.length];
    ctx.fillRect(X(r[0]) - 1, Y(Math.max(-m, Math.min(m, r[2]))) - 1, 2.5, 2.5);
  }
}

// Height over the last RESIDUAL_WINDOW_S: the estimate with its ±2σz band, the truth dashed.
function drawHeight() {
  const [ctx, w, h] = fitCanvas(document.getElementById('height'));
  ctx.clearRect(0, 0, w, h);
  const tEnd = S.j ? S.j.t : 0, tStart = tEnd - RESIDUAL_WINDOW_S;
  const recent = (rows) => { let i = rows.length; while (i > 0 && rows[i - 1][0] >= tStart) --i; return rows.slice(Math.max(0, i - 1)); };
  const est = recent(S.path.rows), tru = recent(S.truth.rows);
  let lo = Infinity, hi = -Infinity;
  for (const r of est) { lo = Math.min(lo, r[3] - 2 * r[7]); hi = Math.max(hi, r[3] + 2 * r[7]); }
  for (const r of tru) { lo = Math.min(lo, r[3]); hi = Math.max(hi, r[3]); }
  ctx.fillStyle = '#666';
  ctx.font = '10px sans-serif';
  ctx.fillText(`height z [m], estimate ±2σ and truth, last ${RESIDUAL_WINDOW_S} s`, 50, 12);
  if (!(hi > lo)) { lo -= 0.5; hi += 0.5; }
  if (!Number.isFinite(lo)) return;
  const pad = 0.1 * (hi - lo);
  lo -= pad; hi += pad;
  const X = (t) => 40 + (t - tStart) / RESIDUAL_WINDOW_S * (w - 50), Y = (z) => h - 6 - (z - lo) / (hi - lo) * (h - 24);
  ctx.fillText(hi.toFixed(1), 2, 22);
  ctx.fillText(lo.toFixed(1), 2, h - 6);
  if (est.length > 1) {
    ctx.fillStyle = 'rgba(31, 119, 180, 0.2)';
    ctx.beginPath();
    est.forEach((r, i) => (i ? ctx.lineTo : ctx.moveTo).call(ctx, X(r[0]), Y(r[3] + 2 * r[7])));
    for (let i = est.length - 1; i >= 0; --i) ctx.lineTo(X(est[i][0]), Y(est[i][3] - 2 * est[i][7]));
    ctx.fill();
  }
  const line = (rows, colour, dash) => {
    if (rows.length < 2) return;
    ctx.strokeStyle = colour; ctx.setLineDash(dash); ctx.lineWidth = 1.5;
    ctx.beginPath();
    rows.forEach((r, i) => (i ? ctx.lineTo : ctx.moveTo).call(ctx, X(r[0]), Y(r[3])));
    ctx.stroke();
    ctx.setLineDash([]);
  };
  line(tru, '#2ca02c', [5, 4]);
  line(est, '#1f77b4', []);
}

// ---- tables -------------------------------------------------------------------------------------
function fmt(v, d = 3) { return v === null || v === undefined ? '–' : Number(v).toFixed(d); }
function esc(s) { return String(s).replace(/[&<>"]/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;' })[c]); }
function rowsHtml(pairs) { return pairs.map(([k, v]) => `<tr><td>${esc(k)}</td><td>${esc(v)}</td></tr>`).join(''); }

function updatePanels() {
  const j = S.j;
  if (!j) return;
  const src = j.source;
  document.getElementById('source').textContent = src.mode === 'log'
    ? `log ${src.description} ${src.speed > 0 ? 'at ' + src.speed + '×' : 'as fast as it reads'}` +
      (src.done ? ' (played to its end)' : '')
    : `live: ${src.description}`;
  const prog = document.getElementById('progress');
  prog.style.display = src.mode === 'log' ? '' : 'none';
  prog.value = src.progress;
  document.getElementById('time').textContent = `t = ${fmt(j.t, 1)} s`;
  const hb = document.getElementById('health');
  if (j.health) {
    hb.textContent = j.health.state + (j.health.reason ? ': ' + j.health.reason : '');
    hb.className = 'badge ' + j.health.state;
  }
  const v = [];
  if (j.pose) {
    const p = j.pose;
    v.push(['position [m]', p.p.map((x) => fmt(x, 2)).join(', ')], ['yaw [°]', fmt(p.yaw_deg, 1)],
      ['speed [m/s]', fmt(Math.hypot(...p.v), 2)], ['σxy 95 % [m]', `${fmt(p.ell[0])} × ${fmt(p.ell[1])}`],
      ['σz [m]', fmt(p.sigma_z_m)], ['POSE messages', p.n]);
    if (j.truth_pose) v.push(['error xy to truth [m]', fmt(Math.hypot(p.p[0] - j.truth_pose.p[0], p.p[1] - j.truth_pose.p[1]))]);
  } else {
    v.push(['pose', 'no POSE yet']);
  }
  document.getElementById('vehicle').innerHTML = rowsHtml(v);
  document.getElementById('lever').textContent = j.lever_arms === 'setup'
    ? '(residuals with the setup\'s tag lever arms)' : '(residuals with tag lever arms 0: no --setup)';
  document.querySelector('#anchors tbody').innerHTML = j.anchors.map((a, i) => {
    const c = STATE_COLOURS[a.state] || '#999';
    const res = a.n_residuals ? `${fmt(a.mean_residual_m)} / ${fmt(a.rms_residual_m)}` : '–';
    return `<tr><td style="color:${PALETTE[i % PALETTE.length]}">${a.id}</td>` +
      `<td style="color:${c}" title="${esc(a.reason)}">${a.state}${a.reason ? ' *' : ''}</td>` +
      `<td class="num">${a.p ? fmt(a.ell[0]) : '–'}</td><td class="num">${res}</td><td class="num">${a.n_ranges}</td></tr>`;
  }).join('');
  document.getElementById('statuses').innerHTML = j.statuses.map((s) =>
    `<h2>${esc(s.channel)} <small>t = ${fmt(s.t, 1)} s</small></h2><table>${rowsHtml(s.fields)}</table>`).join('');
  const counters = Object.entries(j.counters);
  document.getElementById('counters').innerHTML = counters.length ? rowsHtml(counters) : rowsHtml([['none', '']]);
}

// ---- the loop -----------------------------------------------------------------------------------
function frame(now) {
  const t0 = performance.now();
  const redraw = S.dirty;
  S.dirty = false;
  const drewVehicle = drawTop(now, redraw);
  if (redraw || S.stripsW !== window.innerWidth) {
    drawResiduals();
    drawHeight();
    S.stripsW = window.innerWidth;
  }
  if (S.panelsDirty && now - S.panelsAt > 250) {
    updatePanels();
    S.panelsAt = now;
    S.panelsDirty = false;
  }
  S.drawMs += performance.now() - t0;
  S.frames += 1;
  if (drewVehicle && S.firstFrameMs === null) {
    S.firstFrameMs = performance.now();
    document.body.dataset.vehicleDrawn = '1';
  }
  requestAnimationFrame(frame);
}

function reportPerf() {
  const body = JSON.stringify({
    wall_ms: Math.round(performance.now()), frames: S.frames, draw_ms: +S.drawMs.toFixed(1),
    first_vehicle_frame_ms: S.firstFrameMs === null ? null : Math.round(S.firstFrameMs),
    data_t: S.j ? S.j.t : null, progress: S.j ? S.j.source.progress : null, path_rows: S.path.rows.length,
  });
  S.frames = 0; S.drawMs = 0;
  fetch('/api/perf', { method: 'POST', body }).catch(() => {});
}

poll();
requestAnimationFrame(frame);
if (S.perf) setInterval(reportPerf, 1000);
