  // The second half of the page's script (viewer.js is the first; page.py inlines both, in order, as one
  // script inside viewer.js's function): the side panel, rendering, the controls, the test hook.
  // ------------------------------------------------------------------------- side panel, labels
  var img = $('camera-img'), caption = $('camera-caption'), info = $('info');
  var shownImage = null;  // the frame whose camera image is shown (null: none)
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
    // <bound> this frame's accuracy limit (standard deviation no unbiased estimator can beat), or why there is none
    if (raw.boundPos) {
      var bp = raw.boundPos[k], bt = raw.boundTh[k];
      h += row(raw.boundKind === 'none' ? 'bound' : raw.boundKind + ' bound',
               bp === null ? 'no bound in this frame' : fmt(bp * 100, 1) + ' cm, ' + fmt(bt * 180 / Math.PI, 2) + '°');
    }
    // </bound>
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
    // the camera image: the last embedded one at or before k (a recording's every N-th frame, or the
    // PNGs omniloc run --frames wrote, which may be at any frames)
    var ims = raw.images;
    if (r.imageKeys === undefined) r.imageKeys = Object.keys(ims).map(Number).sort(function (a, b) { return a - b; });
    var keys = r.imageKeys, kk = -1, lo = 0, hi = keys.length - 1;
    while (lo <= hi) {
      var mid = (lo + hi) >> 1;
      if (keys[mid] <= k) { kk = keys[mid]; lo = mid + 1; } else hi = mid - 1;
    }
    shownImage = kk >= 0 ? kk : null;
    if (kk >= 0) {
      if (img.getAttribute('data-k') !== String(kk) || img.getAttribute('data-r') !== String(r.id)) {
        img.src = 'data:image/png;base64,' + ims[kk]; img.setAttribute('data-k', kk); img.setAttribute('data-r', r.id);
      }
      caption.textContent = 'camera of r' + r.id + ', frame ' + kk + (kk !== k ? ' (the last embedded image before this frame)' : '');
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
  function snapshot() { var s = JSON.parse(JSON.stringify(S.drawn)); s.imageFrame = shownImage; return s; }
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
