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
    // <bound> the accuracy limit (the Cramer-Rao bound of each frame) under the error curves; page.py leaves these lines out for runs without it
    if (raw.boundPos) { series[0].bound = raw.boundPos; series[1].bound = raw.boundTh; }
    // </bound>
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
      // <bound> shaded from 0 to the bound, frames without one left blank; the label says which bound and the share of frames it covers
      if (s.bound) {
        var covered = 0;
        c.fillStyle = 'rgba(46,160,67,0.28)';
        for (var k5 = 0; k5 < n; k5++) {
          var bv = s.bound[k5];
          if (bv === null || bv === undefined) continue;
          covered++;
          var xa5 = plotX(g, raw.t[k5]), xb5 = plotX(g, k5 + 1 < n ? raw.t[k5 + 1] : raw.t[k5]), yb = yOf(bv * s.scale);
          c.fillRect(xa5, yb, Math.max(1, xb5 - xa5), s.y0 + g.ph - yb);
        }
        c.fillStyle = '#2e7d32';
        c.textAlign = 'right';
        c.fillText(covered ? 'shaded: ' + raw.boundKind + ' bound, in ' + Math.floor(100 * covered / Math.max(1, n)) + ' % of frames' : 'no bound in any frame',
                   g.x1 - 4, s.y0 + 10);
        c.textAlign = 'left';
      }
      // </bound>
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

  // (the script goes on in viewer_controls.js: page.py inlines the two files, in this order, as one script)
