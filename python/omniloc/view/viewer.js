// omniloc view: steps through one run frame by frame. Plain JavaScript and canvas; the data is the
// JSON in <script id="omniloc-data"> (python/omniloc/view/page.py writes it; docs/viewer.md).
// URL hash (parts joined by &): frame=K opens frame K; robot=ID focuses a robot; truth=1 also places
// the line points at the truth; follow=1 keeps the view on the robot; zoom=Z zooms Z times on it;
// test=K1,K2,... steps the slider
// to those frames through the page's own controls and writes what was drawn, as JSON, into
// the pre element with id test-state; &bench=N then steps N frames and times each draw (tests/viewer_test.py).
(function () {
  'use strict';
  var started = performance.now();
  var D = JSON.parse(document.getElementById('omniloc-data').textContent);
  var $ = function (id) { return document.getElementById(id); };
  var COL = {
    carpet: '#2f7d3a', carpetOut: '#276b31', line: '#f5f7f2', truth: '#29d3ff', est: '#ff9a1f', estInvalid: '#b8b8b8',
    lpEst: '#ff2d7a', lpTruth: '#c9a7ff', point: '#ffe600', trajTruth: 'rgba(41,211,255,0.55)', trajEst: 'rgba(255,154,31,0.8)',
    ellipse: '#ffe600', err: '#1f6feb', errTh: '#d9480f', invalid: 'rgba(120,120,120,0.18)', now: '#c62828'
  };
  var BLOB = { yellow: '#ffd600', blue: '#2962ff', red: '#e53935', white: '#ffffff', orange: '#ff6d00', green: '#00c853' };

  // ------------------------------------------------------------------------------ data decoding
  function b64i16(s) {
    var bin = atob(s), n = bin.length, u = new Uint8Array(n);
    for (var i = 0; i < n; i++) u[i] = bin.charCodeAt(i);
    return new Int16Array(u.buffer, 0, n >> 1);
  }
  function packed(p) {
    if (!p) return null;
    var off = new Int32Array(p.counts.length + 1);
    for (var i = 0; i < p.counts.length; i++) off[i + 1] = off[i] + p.counts[i] * p.width;
    return { data: b64i16(p.data), off: off, width: p.width };
  }
  var R = D.robots.map(function (r) {
    return { raw: r, id: r.id, n: r.t.length, lp: packed(r.lp), particles: packed(r.particles), points: packed(r.points) };
  });
  var K = D.frames;

  // --------------------------------------------------------------------------------- page state
  var S = {
    k: 0, focus: 0, playing: false, speed: 1, playT: 0, lastWall: 0,
    show: { traj: true, truthPoints: false, particles: true, rays: true, allRobots: true, follow: false, log: false },
    view: null,  // {cx, cy, scale}: world centre and px per metre; null = whole field
    drawn: null, lastDrawMs: 0
  };
  var testing = false;

  // ------------------------------------------------------------------------------------ helpers
  function fmt(v, d) { return v === null || v === undefined ? '–' : Number(v).toFixed(d); }
  function esc(s) { return String(s).replace(/[&<>"]/g, function (c) { return { '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;' }[c]; }); }
  function pose(arr, k) { return arr ? [arr[3 * k], arr[3 * k + 1], arr[3 * k + 2]] : null; }
  function wrap(a) { a = (a + Math.PI) % (2 * Math.PI); if (a < 0) a += 2 * Math.PI; return a - Math.PI; }
  function frameAt(r, t) {  // the last frame at or before t
    var ts = r.raw.t, lo = 0, hi = ts.length - 1;
    if (t <= ts[0]) return 0;
    while (lo < hi) { var mid = (lo + hi + 1) >> 1; if (ts[mid] <= t) lo = mid; else hi = mid - 1; }
    return lo;
  }
  function focusRobot() { return R[S.focus]; }

  // ------------------------------------------------------------------------------ canvas set-up
  var field = $('field'), fctx = field.getContext('2d');
  var plot = $('plot'), pctx = plot.getContext('2d');
  var fieldLayer = document.createElement('canvas'), plotLayer = document.createElement('canvas');
  var dpr = window.devicePixelRatio || 1;
  var F = D.field, halfL = F.length / 2 + (F.margin || 0), halfW = F.width / 2 + (F.margin || 0);
  var T = { s: 1, ox: 0, oy: 0, cx: 0, cy: 0 };  // world -> css px: X = ox + s (x - cx), Y = oy - s (y - cy)
  function X(x) { return T.ox + T.s * (x - T.cx); }
  function Y(y) { return T.oy - T.s * (y - T.cy); }

  function sizeCanvas(c, layer) {
    var w = Math.max(50, c.clientWidth), h = Math.max(50, c.clientHeight);
    if (c.width !== Math.round(w * dpr) || c.height !== Math.round(h * dpr)) {
      c.width = layer.width = Math.round(w * dpr);
      c.height = layer.height = Math.round(h * dpr);
      return true;
    }
    return false;
  }
  function setTransform() {
    var w = field.clientWidth, h = field.clientHeight;
    var fit = Math.min(w / (2 * halfL), h / (2 * halfW));
    var v = S.view || { cx: 0, cy: 0, scale: fit };
    if (S.show.follow) {
      var r = focusRobot(), p = pose(r.raw.gt, S.k) || pose(r.raw.est, S.k);
      v = { cx: p[0], cy: p[1], scale: S.view ? S.view.scale : fit * 2.5 };
    }
    T = { s: v.scale, ox: w / 2, oy: h / 2, cx: v.cx, cy: v.cy };
  }

  // --------------------------------------------------------- static layer: field and trajectories
  function drawFieldLayer() {
    var c = fieldLayer.getContext('2d');
    c.setTransform(dpr, 0, 0, dpr, 0, 0);
    c.fillStyle = '#1a3d20';
    c.fillRect(0, 0, field.clientWidth, field.clientHeight);
    c.fillStyle = COL.carpetOut;
    c.fillRect(X(-halfL), Y(halfW), 2 * halfL * T.s, 2 * halfW * T.s);
    c.fillStyle = COL.carpet;
    c.fillRect(X(-F.length / 2), Y(F.width / 2), F.length * T.s, F.width * T.s);
    c.strokeStyle = COL.line;
    c.lineWidth = Math.max(1, (F.line_width || 0.125) * T.s);
    c.lineCap = 'round';
    c.beginPath();
    (F.segments || []).forEach(function (s) { c.moveTo(X(s[0]), Y(s[1])); c.lineTo(X(s[2]), Y(s[3])); });
    c.stroke();
    (F.arcs || []).forEach(function (a) {
      c.beginPath();
      c.arc(X(a[0]), Y(a[1]), a[2] * T.s, -a[3], -(a[3] + a[4]), true);
      c.stroke();
    });
    c.fillStyle = COL.line;
    (F.spots || []).forEach(function (p) { c.beginPath(); c.arc(X(p[0]), Y(p[1]), Math.max(1.5, p[2] * T.s), 0, 2 * Math.PI); c.fill(); });
    (F.goals || []).forEach(function (g, i) {
      var sx = g[0] >= 0 ? 1 : -1, colour = (F.goal_colours || [])[i] || 'white';
      c.fillStyle = colour === 'white' ? 'rgba(255,255,255,0.35)' : (BLOB[colour] || '#fff');
      c.fillRect(Math.min(X(g[0]), X(g[0] + sx * g[2])), Y(g[1] / 2), g[2] * T.s, g[1] * T.s);
    });
    (F.landmarks || []).forEach(function (l) {
      if (!l.position) return;
      c.fillStyle = BLOB[l.colour] || '#fff';
      var s = Math.max(4, (l.size || 0.2) * T.s);
      if (l.shape === 'post') { c.beginPath(); c.arc(X(l.position[0]), Y(l.position[1]), s / 2, 0, 2 * Math.PI); c.fill(); }
      else c.fillRect(X(l.position[0]) - s / 2, Y(l.position[1]) - s / 2, s, s);
    });
    if (S.show.traj) {
      R.forEach(function (r, i) {
        if (!S.show.allRobots && i !== S.focus) return;
        var alpha = i === S.focus ? 1 : 0.45;
        c.globalAlpha = alpha;
        c.lineWidth = 1.2;
        if (r.raw.gt) polyline(c, r.raw.gt, r.n, COL.trajTruth, null);
        polyline(c, r.raw.est, r.n, COL.trajEst, r.raw.valid);
        c.globalAlpha = 1;
      });
    }
  }
  function polyline(c, arr, n, colour, valid) {  // broken at invalid frames and at jumps (kidnap, relocalisation)
    c.strokeStyle = colour;
    c.beginPath();
    var pen = false, px = 0, py = 0;
    for (var k = 0; k < n; k++) {
      if (valid && !valid[k]) { pen = false; continue; }
      var wx = arr[3 * k], wy = arr[3 * k + 1], x = X(wx), y = Y(wy);
      if (pen && (wx - px) * (wx - px) + (wy - py) * (wy - py) > JUMP * JUMP) pen = false;
      if (pen) c.lineTo(x, y); else c.moveTo(x, y);
      pen = true; px = wx; py = wy;
    }
    c.stroke();
  }
  var JUMP = 0.5;  // metres between two frames: no robot drives that fast (1 m/s is 3 cm a frame at 30 Hz)

  // ------------------------------------------------------------------------ the frame's drawing
  function arrow(c, p, len, colour, width, dashed) {
    var x = X(p[0]), y = Y(p[1]), ct = Math.cos(p[2]), st = Math.sin(p[2]);
    var L = Math.max(14, len * T.s), ex = x + L * ct, ey = y - L * st;
    c.strokeStyle = colour; c.fillStyle = colour; c.lineWidth = width;
    c.setLineDash(dashed ? [4, 3] : []);
    c.beginPath(); c.moveTo(x, y); c.lineTo(ex, ey); c.stroke();
    c.setLineDash([]);
    var h = Math.min(9, L * 0.4);
    c.beginPath();
    c.moveTo(ex, ey);
    c.lineTo(ex - h * (ct * 1 - st * 0.5), ey + h * (st * 1 + ct * 0.5));
    c.lineTo(ex - h * (ct * 1 + st * 0.5), ey + h * (st * 1 - ct * 0.5));
    c.closePath(); c.fill();
  }
  function robotBody(c, p, radius, colour, dashed) {
    c.strokeStyle = colour; c.lineWidth = 2;
    c.setLineDash(dashed ? [4, 3] : []);
    c.beginPath(); c.arc(X(p[0]), Y(p[1]), Math.max(4, radius * T.s), 0, 2 * Math.PI); c.stroke();
    c.setLineDash([]);
  }
  function placePoints(c, r, k, p, colour, size) {  // robot-frame line points placed through pose p
    if (!r.lp) return 0;
    var a = r.lp.off[k], b = r.lp.off[k + 1], d = r.lp.data, ct = Math.cos(p[2]), st = Math.sin(p[2]);
    c.fillStyle = colour;
    c.beginPath();
    for (var i = a; i < b; i += 2) {
      var px = d[i] / 1000, py = d[i + 1] / 1000;
      c.rect(X(p[0] + ct * px - st * py) - size / 2, Y(p[1] + st * px + ct * py) - size / 2, size, size);
    }
    c.fill();
    return (b - a) / 2;
  }
  var RAMP = ['#0d0887', '#5302a3', '#8b0aa5', '#b83289', '#db5c68', '#f48849', '#febd2a', '#f0f921'];  // plasma
  function drawParticles(c, r, k) {
    if (!r.particles) return 0;
    var a = r.particles.off[k], b = r.particles.off[k + 1], d = r.particles.data, n = (b - a) / 4;
    if (!n) return 0;
    var buckets = RAMP.map(function () { return []; });
    for (var i = a; i < b; i += 4) buckets[Math.min(RAMP.length - 1, Math.floor(d[i + 3] / 32768 * RAMP.length))].push(i);
    var L = 7;
    c.lineWidth = 1.2;
    buckets.forEach(function (idx, bi) {
      if (!idx.length) return;
      c.strokeStyle = RAMP[bi]; c.fillStyle = RAMP[bi];
      c.beginPath();
      idx.forEach(function (i) {
        var x = X(d[i] / 1000), y = Y(d[i + 1] / 1000), th = d[i + 2] / 1000;
        c.moveTo(x, y); c.lineTo(x + L * Math.cos(th), y - L * Math.sin(th));
      });
      c.stroke();
      c.beginPath();
      idx.forEach(function (i) { c.rect(X(d[i] / 1000) - 1.5, Y(d[i + 1] / 1000) - 1.5, 3, 3); });
      c.fill();
    });
    return n;
  }
  function drawExtraPoints(c, r, k) {
    if (!r.points) return 0;
    var a = r.points.off[k], b = r.points.off[k + 1], d = r.points.data;
    c.strokeStyle = COL.point; c.lineWidth = 1.5;
    c.beginPath();
    for (var i = a; i < b; i += 2) {
      var x = X(d[i] / 1000), y = Y(d[i + 1] / 1000);
      c.moveTo(x - 3, y - 3); c.lineTo(x + 3, y + 3); c.moveTo(x - 3, y + 3); c.lineTo(x + 3, y - 3);
    }
    c.stroke();
    return (b - a) / 2;
  }
  function drawBlobs(c, r, k, p) {
    var bl = r.raw.blobs[k];
    if (!bl) return 0;
    bl.forEach(function (b) {
      var th = p[2] + b[2], d = b[3] === null ? 4 : b[3];
      c.strokeStyle = BLOB[b[0]] || '#fff';
      c.lineWidth = b[1] === 'region' ? 2 : 1;
      c.setLineDash(b[3] === null ? [6, 4] : []);
      c.beginPath(); c.moveTo(X(p[0]), Y(p[1])); c.lineTo(X(p[0] + d * Math.cos(th)), Y(p[1] + d * Math.sin(th))); c.stroke();
      if (b[3] !== null) { c.beginPath(); c.arc(X(p[0] + d * Math.cos(th)), Y(p[1] + d * Math.sin(th)), 4, 0, 2 * Math.PI); c.stroke(); }
    });
    c.setLineDash([]);
    return bl.length;
  }

  function drawField() {
    var t0 = performance.now();
    var c = fctx, k = S.k;
    c.setTransform(1, 0, 0, 1, 0, 0);
    c.drawImage(fieldLayer, 0, 0);
    c.setTransform(dpr, 0, 0, dpr, 0, 0);
    var drawn = { k: k, t: null, robots: [] };
    R.forEach(function (r, i) {
      var focus = i === S.focus;
      if (!focus && !S.show.allRobots) return;
      var gt = pose(r.raw.gt, k), est = pose(r.raw.est, k), valid = !!r.raw.valid[k];
      var rec = { id: r.id, truth: gt, est: est, valid: valid, mode: r.raw.modes[r.raw.mode[k]], lineEst: 0, lineTruth: 0,
                  particles: 0, blobs: 0, points: 0, ellipse: null };
      if (focus) {
        drawn.t = r.raw.t[k];
        if (S.show.particles) rec.particles = drawParticles(c, r, k);
        var e = r.raw.cov && r.raw.cov[k];
        if (e) {
          c.strokeStyle = COL.ellipse; c.lineWidth = 1.5;
          c.beginPath(); c.ellipse(X(est[0]), Y(est[1]), Math.max(0.5, e[0] * T.s), Math.max(0.5, e[1] * T.s), -e[2], 0, 2 * Math.PI); c.stroke();
          rec.ellipse = e;
        }
        if (S.show.rays) rec.blobs = drawBlobs(c, r, k, est);
        if (S.show.truthPoints && gt) rec.lineTruth = placePoints(c, r, k, gt, COL.lpTruth, 3);
        rec.lineEst = placePoints(c, r, k, est, COL.lpEst, 3.5);
        rec.points = drawExtraPoints(c, r, k);
      }
      c.globalAlpha = focus ? 1 : 0.6;
      if (gt) { robotBody(c, gt, r.raw.radius, COL.truth, false); arrow(c, gt, 0.6, COL.truth, 2, false); }
      arrow(c, est, 0.6, valid ? COL.est : COL.estInvalid, 2.5, !valid);
      c.globalAlpha = 1;
      if (R.length > 1) {
        c.fillStyle = '#fff'; c.font = '11px system-ui, sans-serif';
        c.fillText('r' + r.id, X(est[0]) + 8, Y(est[1]) - 8);
      }
      drawn.robots.push(rec);
    });
    S.lastDrawMs = performance.now() - t0;
    S.drawn = drawn;
  }

  // ----------------------------------------------------------------------------- the error plot
  var PL = { left: 48, right: 10, top: 6, gap: 16, bottom: 16 };
  function plotGeom() {
    var w = plot.clientWidth, h = plot.clientHeight, ph = (h - PL.top - PL.gap - PL.bottom) / 2;
    return { w: w, h: h, ph: ph, x0: PL.left, x1: w - PL.right, y0a: PL.top, y0b: PL.top + ph + PL.gap };
  }
  function tRange() {
    var r = focusRobot(), ts = r.raw.t;
    return [ts[0], Math.max(ts[ts.length - 1], ts[0] + 1e-6)];
  }
  function plotX(g, t) { var tr = tRange(); return g.x0 + (g.x1 - g.x0) * (t - tr[0]) / (tr[1] - tr[0]); }
  function drawPlotLayer() {
    var c = plotLayer.getContext('2d'), g = plotGeom(), r = focusRobot(), raw = r.raw;
    c.setTransform(dpr, 0, 0, dpr, 0, 0);
    c.fillStyle = '#fff'; c.fillRect(0, 0, g.w, g.h);
    c.font = '10px system-ui, sans-serif';
    var series = [
      { v: raw.errPos, scale: 1, unit: 'm', name: 'position error', colour: COL.err, y0: g.y0a },
      { v: raw.errTh, scale: 180 / Math.PI, unit: 'deg', name: 'heading error', colour: COL.errTh, y0: g.y0b, abs: true }
    ];
    series.forEach(function (s) {
      var vmax = 0, n = raw.t.length;
      for (var k = 0; k < n; k++) if (s.v[k] !== null && raw.valid[k]) vmax = Math.max(vmax, Math.abs(s.v[k]) * s.scale);
      if (vmax === 0) for (var k2 = 0; k2 < n; k2++) if (s.v[k2] !== null) vmax = Math.max(vmax, Math.abs(s.v[k2]) * s.scale);
      vmax = vmax > 0 ? vmax * 1.08 : 1;
      var lo = S.show.log ? Math.max(vmax / 1e4, s.unit === 'm' ? 1e-3 : 1e-2) : 0;
      var yOf = function (v) {
        var f = S.show.log ? (Math.log(Math.max(v, lo)) - Math.log(lo)) / (Math.log(vmax) - Math.log(lo)) : v / vmax;
        return s.y0 + g.ph * (1 - Math.min(1, Math.max(0, f)));
      };
      s.yOf = yOf;
      // invalid frames shaded, mode changes ticked
      c.fillStyle = COL.invalid;
      for (var k3 = 0; k3 < n; k3++) if (!raw.valid[k3]) {
        var xa = plotX(g, raw.t[k3]), xb = plotX(g, k3 + 1 < n ? raw.t[k3 + 1] : raw.t[k3]);
        c.fillRect(xa, s.y0, Math.max(1, xb - xa), g.ph);
      }
      c.strokeStyle = '#c9ced6'; c.lineWidth = 1;
      c.strokeRect(g.x0, s.y0, g.x1 - g.x0, g.ph);
      c.fillStyle = '#5b6270';
      c.textAlign = 'right';
      c.fillText(fmtAxis(vmax) + ' ' + s.unit, g.x0 - 4, s.y0 + 9);
      c.fillText(S.show.log ? fmtAxis(lo) : '0', g.x0 - 4, s.y0 + g.ph);
      c.textAlign = 'left';
      c.fillText(s.name + (s.abs ? ' (absolute)' : '') + (S.show.log ? ', log scale' : ''), g.x0 + 4, s.y0 + 10);
      c.strokeStyle = s.colour; c.lineWidth = 1.2;
      c.beginPath();
      var pen = false;
      for (var k4 = 0; k4 < n; k4++) {
        var v = s.v[k4];
        if (v === null) { pen = false; continue; }
        var x = plotX(g, raw.t[k4]), y = yOf(Math.abs(v) * s.scale);
        if (pen) c.lineTo(x, y); else c.moveTo(x, y);
        pen = true;
      }
      c.stroke();
    });
    // time axis ticks
    var tr = tRange(), step = niceStep((tr[1] - tr[0]) / 10);
    c.fillStyle = '#5b6270'; c.textAlign = 'center';
    for (var t = Math.ceil(tr[0] / step) * step; t <= tr[1] + 1e-9; t += step) c.fillText(fmtAxis(t) + ' s', plotX(g, t), g.h - 3);
    // events as thin lines (modes grey)
    D.events.forEach(function (e) {
      if (e.robot !== null && e.robot !== r.id) return;
      c.strokeStyle = e.type === 'mode' ? 'rgba(106,115,133,0.35)' : 'rgba(198,40,40,0.5)';
      var x = plotX(g, e.t);
      c.beginPath(); c.moveTo(x, g.y0a); c.lineTo(x, g.y0b + g.ph); c.stroke();
    });
    PL.series = series;
  }
  function niceStep(x) { var p = Math.pow(10, Math.floor(Math.log10(x))), m = x / p; return (m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10) * p; }
  function fmtAxis(v) { return v >= 100 ? v.toFixed(0) : v >= 10 ? v.toFixed(1) : v >= 1 ? v.toFixed(2) : v.toPrecision(2); }
  function drawPlot() {
    var c = pctx, g = plotGeom(), r = focusRobot(), k = S.k;
    c.setTransform(1, 0, 0, 1, 0, 0);
    c.drawImage(plotLayer, 0, 0);
    c.setTransform(dpr, 0, 0, dpr, 0, 0);
    var x = plotX(g, r.raw.t[k]);
    c.strokeStyle = COL.now; c.lineWidth = 1.5;
    c.beginPath(); c.moveTo(x, g.y0a); c.lineTo(x, g.y0b + g.ph); c.stroke();
    (PL.series || []).forEach(function (s) {
      var v = s.v[k];
      if (v === null) return;
      c.fillStyle = s.colour;
      c.beginPath(); c.arc(x, s.yOf(Math.abs(v) * s.scale), 3, 0, 2 * Math.PI); c.fill();
    });
  }

  // ------------------------------------------------------------------------- side panel, labels
  var img = $('camera-img'), caption = $('camera-caption'), info = $('info');
  var extraNames = Object.keys(focusRobot().raw.extra || {});
  function row(name, value, cls) { return '<tr><td>' + esc(name) + '</td><td' + (cls ? ' class="' + cls + '"' : '') + '>' + value + '</td></tr>'; }
  function eventsNear(r, k) {
    var t0 = k > 0 ? r.raw.t[k - 1] : -1e9, t1 = r.raw.t[k];
    return D.events.filter(function (e) { return e.t > t0 && e.t <= t1 && (e.robot === null || e.robot === r.id); });
  }
  function updateSide() {
    var r = focusRobot(), raw = r.raw, k = S.k, h = '';
    var gt = pose(raw.gt, k), est = pose(raw.est, k), dr = S.drawn && S.drawn.robots.filter(function (x) { return x.id === r.id; })[0];
    h += '<tr class="head"><td>frame</td><td>' + k + ' of ' + (K - 1) + ', t = ' + fmt(raw.t[k], 3) + ' s</td></tr>';
    h += row('robot', 'r' + r.id + (R.length > 1 ? ' (of ' + R.length + ')' : ''));
    h += row('mode', esc(raw.modes[raw.mode[k]]));
    h += row('valid', raw.valid[k] ? 'yes' : 'no: the localizer gives no pose it stands behind', raw.valid[k] ? '' : 'bad');
    if (raw.camOk[k] !== null) h += row('camera', raw.camOk[k] ? 'ok' : 'unusable (covered, or an exposure trial)', raw.camOk[k] ? '' : 'bad');
    if (gt) h += row('truth', fmt(gt[0], 3) + ', ' + fmt(gt[1], 3) + ' m, ' + fmt(gt[2] * 180 / Math.PI, 1) + '°');
    h += row('estimate', fmt(est[0], 3) + ', ' + fmt(est[1], 3) + ' m, ' + fmt(est[2] * 180 / Math.PI, 1) + '°');
    if (raw.errPos[k] !== null) {
      var ep = raw.errPos[k], eth = raw.errTh[k] * 180 / Math.PI;
      h += row('error', fmt(ep * 100, 1) + ' cm, ' + fmt(eth, 2) + '°', ep > 0.5 || Math.abs(eth) > 20 ? 'bad' : '');
    }
    var e = raw.cov && raw.cov[k];
    if (e) h += row('covariance', '2σ ellipse ' + fmt(e[0] * 100, 1) + ' × ' + fmt(e[1] * 100, 1) + ' cm, σθ ' + fmt(e[3] * 180 / Math.PI, 2) + '°');
    if (D.debugSource) {
      h += row('line points', (raw.lpCount[k] !== null ? raw.lpCount[k] + ' (frames.csv), ' : '') + (dr ? dr.lineEst : 0) + ' drawn at the estimate' +
        (S.show.truthPoints ? ', ' + (dr ? dr.lineTruth : 0) + ' at the truth' : ''));
    } else {
      h += row('line points', (raw.lpCount[k] !== null ? raw.lpCount[k] + ' (frames.csv); ' : '') +
        'no line points: run with --debug-view or pass --recording DIR', 'msg');
    }
    if (r.particles) h += row('particles', (dr ? dr.particles : 0) + ' drawn' + (D.particlesEvery > 1 ? ' (every ' + D.particlesEvery + ' frames)' : ''));
    if (raw.blobs && raw.blobs[k]) h += row('blobs', raw.blobs[k].map(function (b) { return esc(b[0] + ' ' + b[1]); }).join(', '));
    if (r.points) h += row('extra points', dr ? dr.points : 0);
    if (raw.matchErr[k] !== null) h += row('match_error', raw.matchErr[k]);
    if (raw.contact[k]) h += row('contact', 'yes: odometry may slip', 'msg');
    extraNames.forEach(function (n) { var v = raw.extra[n][k]; if (v !== null) h += row(n, v); });
    var ev = eventsNear(r, k);
    if (ev.length) h += row('events', ev.map(function (x) { return esc(x.label); }).join('<br>'), 'msg');
    info.innerHTML = h;
    // the camera image: the last embedded one at or before k
    var ims = raw.images, every = D.imageEvery || 1;
    if (Object.keys(ims).length) {
      var kk = k - (k % every);
      while (kk >= 0 && !ims[kk]) kk -= every;
      if (kk >= 0) {
        var src = 'data:image/png;base64,' + ims[kk];
        if (img.getAttribute('data-k') !== String(kk) || img.getAttribute('data-r') !== String(r.id)) {
          img.src = src; img.setAttribute('data-k', kk); img.setAttribute('data-r', r.id);
        }
        caption.textContent = 'camera of r' + r.id + ', frame ' + kk + (kk !== k ? ' (every ' + every + ' frames embedded)' : '');
      }
    }
    $('time').textContent = 't = ' + fmt(raw.t[k], 3) + ' s  frame ' + k + ' / ' + (K - 1);
  }

  // ---------------------------------------------------------------------------------- rendering
  var layersDirty = true;
  function render() {
    var resized = sizeCanvas(field, fieldLayer) | sizeCanvas(plot, plotLayer);
    setTransform();
    if (layersDirty || resized || S.show.follow) { drawFieldLayer(); drawPlotLayer(); layersDirty = false; }
    drawField();
    drawPlot();
    updateSide();
  }
  function setFrame(k) {
    k = Math.max(0, Math.min(K - 1, Math.round(k)));
    S.k = k;
    slider.value = k;
    render();
  }

  // ----------------------------------------------------------------------------------- controls
  var slider = $('slider');
  slider.max = K - 1;
  slider.addEventListener('input', function () { stop(); setFrame(+slider.value); });
  function step(n) { stop(); setFrame(S.k + n); }
  $('btn-prev').addEventListener('click', function (ev) { step(ev.shiftKey ? -10 : -1); });
  $('btn-next').addEventListener('click', function (ev) { step(ev.shiftKey ? 10 : 1); });
  var playBtn = $('btn-play');
  playBtn.addEventListener('click', function () { if (S.playing) stop(); else play(); });
  $('speed').addEventListener('change', function () { S.speed = +this.value; });
  function play() {
    if (S.k >= K - 1) setFrame(0);
    S.playing = true; playBtn.innerHTML = '&#10074;&#10074;';
    S.playT = focusRobot().raw.t[S.k]; S.lastWall = performance.now();
    requestAnimationFrame(tick);
  }
  function stop() { S.playing = false; playBtn.innerHTML = '&#9654;'; }
  function tick(now) {
    if (!S.playing) return;
    S.playT += S.speed * Math.max(0, now - S.lastWall) / 1000;
    S.lastWall = now;
    var k = frameAt(focusRobot(), S.playT);
    if (k !== S.k) setFrame(k);
    if (S.k >= K - 1) { stop(); return; }
    requestAnimationFrame(tick);
  }
  document.addEventListener('keydown', function (ev) {
    if (ev.target && ev.target.tagName === 'SELECT' && (ev.key === 'ArrowUp' || ev.key === 'ArrowDown')) return;
    var n = ev.shiftKey ? 10 : 1;
    if (ev.key === 'ArrowLeft') step(-n);
    else if (ev.key === 'ArrowRight') step(n);
    else if (ev.key === ' ' || ev.key === 'Spacebar') { if (S.playing) stop(); else play(); }
    else if (ev.key === 'Home') step(-K);
    else if (ev.key === 'End') step(K);
    else return;
    ev.preventDefault();
  });

  // toggles and the robot choice
  var toggles = $('toggles');
  var TOG = [['traj', 'trajectories'], ['truthPoints', 'line points at the truth'], ['particles', 'particles'], ['rays', 'blob rays'],
             ['allRobots', 'all robots'], ['follow', 'follow robot'], ['log', 'log error scale']];
  TOG.forEach(function (t) {
    if (t[0] === 'allRobots' && R.length < 2) return;
    if (t[0] === 'particles' && !R.some(function (r) { return r.particles; })) return;
    if (t[0] === 'truthPoints' && !D.debugSource) return;
    if (t[0] === 'rays' && !R.some(function (r) { return Object.keys(r.raw.blobs).length; })) return;
    var l = document.createElement('label'), cb = document.createElement('input');
    cb.type = 'checkbox'; cb.checked = S.show[t[0]]; cb.id = 'tog-' + t[0];
    cb.addEventListener('change', function () { S.show[t[0]] = cb.checked; layersDirty = true; render(); });
    l.appendChild(cb); l.appendChild(document.createTextNode(' ' + t[1]));
    toggles.appendChild(l);
  });
  if (R.length > 1) {
    var sel = document.createElement('select');
    R.forEach(function (r, i) { var o = document.createElement('option'); o.value = i; o.textContent = 'robot r' + r.id; sel.appendChild(o); });
    sel.id = 'robot';
    sel.addEventListener('change', function () { S.focus = +sel.value; extraNames = Object.keys(focusRobot().raw.extra || {}); layersDirty = true; render(); });
    toggles.insertBefore(sel, toggles.firstChild);
  }

  // zoom and pan
  var drag = null;
  field.addEventListener('wheel', function (ev) {
    ev.preventDefault();
    var rect = field.getBoundingClientRect(), mx = ev.clientX - rect.left, my = ev.clientY - rect.top;
    var wx = T.cx + (mx - T.ox) / T.s, wy = T.cy - (my - T.oy) / T.s, f = Math.exp(-ev.deltaY * 0.0015);
    var s = Math.min(2000, Math.max(5, T.s * f));
    S.view = { scale: s, cx: wx - (mx - T.ox) / s, cy: wy + (my - T.oy) / s };
    layersDirty = true; render();
  }, { passive: false });
  field.addEventListener('mousedown', function (ev) { drag = { x: ev.clientX, y: ev.clientY, cx: T.cx, cy: T.cy, s: T.s }; field.style.cursor = 'grabbing'; });
  window.addEventListener('mouseup', function () { drag = null; field.style.cursor = ''; });
  window.addEventListener('mousemove', function (ev) {
    if (!drag || S.show.follow) return;
    S.view = { scale: drag.s, cx: drag.cx - (ev.clientX - drag.x) / drag.s, cy: drag.cy + (ev.clientY - drag.y) / drag.s };
    layersDirty = true; render();
  });
  field.addEventListener('dblclick', function () { S.view = null; layersDirty = true; render(); });
  window.addEventListener('resize', function () { layersDirty = true; render(); });

  // the plot seeks
  plot.addEventListener('click', function (ev) {
    var g = plotGeom(), rect = plot.getBoundingClientRect(), tr = tRange();
    var t = tr[0] + (tr[1] - tr[0]) * (ev.clientX - rect.left - g.x0) / (g.x1 - g.x0);
    stop(); setFrame(frameAt(focusRobot(), t));
  });

  // event marks on the timeline, named on hover
  var tip = $('tooltip');
  function showTip(ev, text) { tip.textContent = text; tip.hidden = false; tip.style.left = (ev.clientX + 12) + 'px'; tip.style.top = (ev.clientY - 30) + 'px'; }
  (function marks() {
    var box = $('events'), tr = [R[0].raw.t[0], Math.max(R[0].raw.t[R[0].n - 1], R[0].raw.t[0] + 1e-6)];
    D.events.forEach(function (e) {
      var m = document.createElement('div');
      m.className = 'ev' + (e.type === 'mode' ? ' mode' : '');
      m.style.left = Math.max(0, Math.min(100, 100 * (e.t - tr[0]) / (tr[1] - tr[0]))) + '%';
      m.title = e.label;
      m.setAttribute('data-label', e.label);
      m.addEventListener('mousemove', function (ev) { showTip(ev, e.label); });
      m.addEventListener('mouseleave', function () { tip.hidden = true; });
      m.addEventListener('click', function () { stop(); setFrame(frameAt(focusRobot(), e.t)); });
      if (e.duration && e.type !== 'mode') {
        var span = document.createElement('div');
        span.className = 'ev span';
        span.style.left = m.style.left;
        span.style.width = (100 * e.duration / (tr[1] - tr[0])) + '%';
        span.title = e.label;
        box.appendChild(span);
      }
      box.appendChild(m);
    });
  })();

  // header: title, legend, notes
  $('title').textContent = 'omniloc view: ' + D.title;
  var legend = [[COL.truth, 'truth'], [COL.est, 'estimate'], [COL.estInvalid, 'estimate, not valid']];
  if (D.debugSource) legend.push([COL.lpEst, 'line points at the estimate'], [COL.lpTruth, 'line points at the truth (toggle)']);
  if (R.some(function (r) { return r.raw.cov; })) legend.push([COL.ellipse, '2σ position ellipse']);
  if (R.some(function (r) { return r.particles; })) legend.push(['linear-gradient(90deg,' + RAMP.join(',') + ')', 'particles by weight']);
  $('legend').innerHTML = legend.map(function (l) { return '<span><i style="background:' + l[0] + '"></i>' + esc(l[1]) + '</span>'; }).join('');
  var notes = D.notes.slice();
  notes.unshift(D.debugSource === 'view.jsonl' ? 'line points, blobs' + (R.some(function (r) { return r.particles; }) ? ', particles' : '') + ' from view.jsonl'
    : D.debugSource === 'recording' ? 'line points and blobs from the recording ' + (D.recording || '')
    : 'no line points: run with --debug-view or pass --recording DIR');
  if (R.some(function (r) { return r.particles; })) notes.push('particles: at most ' + D.particlesMax + ' per frame' + (D.particlesEvery > 1 ? ', every ' + D.particlesEvery + ' frames' : ''));
  if (D.version) notes.push('omniloc ' + D.version);
  $('notes').innerHTML = notes.map(esc).join('<br>');
  if (!R.some(function (r) { return Object.keys(r.raw.images).length; })) {
    $('camera').style.display = 'none';
  }

  // --------------------------------------------------------------------------- hash: test, bench
  function parseHash() {
    var out = {};
    location.hash.replace(/^#/, '').split('&').forEach(function (kv) {
      if (!kv) return;
      var i = kv.indexOf('=');
      out[decodeURIComponent(i < 0 ? kv : kv.slice(0, i))] = i < 0 ? '' : decodeURIComponent(kv.slice(i + 1));
    });
    return out;
  }
  function median(a) { var s = a.slice().sort(function (x, y) { return x - y; }); return s.length ? s[(s.length - 1) >> 1] : null; }
  function snapshot() { return JSON.parse(JSON.stringify(S.drawn)); }
  var H = parseHash();
  if (H.robot !== undefined) R.forEach(function (r, i) { if (String(r.id) === H.robot) S.focus = i; });
  if (H.truth === '1') S.show.truthPoints = true;
  if (H.follow === '1') S.show.follow = true;
  if (H.zoom !== undefined && +H.zoom > 0) {  // a zoom factor over the whole field, centred on the focus robot's truth
    var r0 = focusRobot(), k0h = Math.max(0, Math.min(K - 1, +(H.frame || 0))), p0 = pose(r0.raw.gt, k0h) || pose(r0.raw.est, k0h);
    var w0 = Math.max(50, field.clientWidth), h0 = Math.max(50, field.clientHeight);
    S.view = { cx: p0[0], cy: p0[1], scale: +H.zoom * Math.min(w0 / (2 * halfL), h0 / (2 * halfW)) };
  }
  var cbs = document.querySelectorAll('#toggles input');
  for (var ci = 0; ci < cbs.length; ci++) cbs[ci].checked = S.show[cbs[ci].id.slice(4)];
  setFrame(H.frame !== undefined ? +H.frame : 0);
  var initMs = performance.now() - started;  // decoding the data and drawing the first frame
  if (H.test !== undefined) {
    testing = true;
    var out = { initMs: initMs, frames: K, robots: R.map(function (r) { return r.id; }), debugSource: D.debugSource, steps: [], controls: {} };
    H.test.split(',').filter(function (s) { return s !== ''; }).forEach(function (s) {
      slider.value = +s;
      slider.dispatchEvent(new Event('input', { bubbles: true }));
      var snap = snapshot();
      snap.slider = +slider.value;
      out.steps.push(snap);
    });
    // the step buttons and the keyboard, from the first test frame
    var k0 = out.steps.length ? out.steps[0].k : 0;
    setFrame(k0);
    $('btn-next').click(); out.controls.next = S.k;
    $('btn-prev').click(); out.controls.prev = S.k;
    document.dispatchEvent(new KeyboardEvent('keydown', { key: 'ArrowRight', bubbles: true })); out.controls.arrowRight = S.k;
    document.dispatchEvent(new KeyboardEvent('keydown', { key: 'ArrowLeft', bubbles: true })); out.controls.arrowLeft = S.k;
    out.controls.from = k0;
    document.dispatchEvent(new KeyboardEvent('keydown', { key: ' ', bubbles: true })); out.controls.spacePlays = S.playing;
    document.dispatchEvent(new KeyboardEvent('keydown', { key: ' ', bubbles: true })); out.controls.spaceAgainPauses = !S.playing;
    var pr = plot.getBoundingClientRect(), pg = plotGeom();
    plot.dispatchEvent(new MouseEvent('click', { clientX: pr.left + pg.x0 + 0.5 * (pg.x1 - pg.x0), clientY: pr.top + 20, bubbles: true }));
    out.controls.plotClickMiddle = S.k;
    out.controls.plotMiddleT = 0.5 * (tRange()[0] + tRange()[1]);
    out.controls.eventMarks = document.querySelectorAll('#events .ev:not(.span)').length;
    out.controls.eventLabels = Array.prototype.map.call(document.querySelectorAll('#events .ev:not(.span)'), function (m) { return m.title; });
    out.controls.linePointsMessage = /no line points: run with --debug-view or pass --recording DIR/.test(info.textContent);
    var nb = +(H.bench || 0);
    if (nb > 0) {
      var ms = [], flushed = [];
      for (var i = 0; i < nb; i++) {
        var k = Math.round(i * (K - 1) / Math.max(1, nb - 1));
        var t0 = performance.now();
        slider.value = k;
        slider.dispatchEvent(new Event('input', { bubbles: true }));
        fctx.getImageData(0, 0, 1, 1);  // makes the canvas rasterize what was drawn before the clock stops
        flushed.push(performance.now() - t0);
        ms.push(S.lastDrawMs);
      }
      out.bench = { steps: nb, draw_ms: ms, draw_median_ms: median(ms), draw_max_ms: Math.max.apply(null, ms),
                    frame_ms: flushed, frame_median_ms: median(flushed), frame_max_ms: Math.max.apply(null, flushed),
                    canvas: [field.width, field.height], dpr: dpr };
    }
    setFrame(out.steps.length ? out.steps[out.steps.length - 1].k : 0);
    $('test-state').textContent = JSON.stringify(out);
  }
})();
